//! The variable-step generalized Maxwell-slip model: [`Gms`], its state
//! and the elements' [`GmsSlipMode`].

use crate::model::{checked_inputs, FrictionModel};
use crate::observer::Observable;
use crate::stribeck::StribeckCurve;
use crate::Scalar;

/// One built element.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(super) struct Element<S> {
    pub(super) k: S,
    /// Normalised weight.
    pub(super) alpha: S,
    /// `alpha_i Fs`, the bound on `|F_i|`.
    pub(super) f_max: S,
    /// `C / alpha_i`.
    pub(super) c_over_alpha: S,
    pub(super) sigma1: S,
    /// `sigma1_i C / (alpha_i k_i)`: the slip damping force per unit of
    /// `(sign(v) b_i - F_i) / g`, formed at build time so that no product
    /// of the step overflows where the force itself fits (`C / (alpha_i g)`
    /// times `F_i` can, in `f32`, for `Fs / Fc` near 1e20).
    pub(super) slip_sigma1: S,
}

/// The built GMS model: immutable, shared by any number of [`GmsState`]s.
///
/// The generalized Maxwell-slip model, GMS (Lampaert, Al-Bender, Swevers
/// 2003; Al-Bender, Lampaert, Swevers 2005), with `N` elements.
///
/// ```text
/// sticking: dF_i/dt = k_i v                              until |F_i| reaches alpha_i g(v)
/// slipping: dF_i/dt = C (sign(v) - F_i / (alpha_i g(v)))  until v changes sign
/// F = sum_i (F_i + sigma1_i dz_i/dt) + sigma2 v,   dz_i/dt = v (sticking), dF_i/dt / k_i (slipping)
/// ```
///
/// Each element remembers whether it slips ([`GmsSlipMode`]): that memory is
/// the model. A slipping element keeps slipping while `v` keeps its sign,
/// even when `|F_i|` is below `alpha_i g(v)` because `g` rose as the speed
/// fell; deciding from `|F_i| <= alpha_i g(v)` alone would make it stick
/// and stiffen at once. A velocity of exactly 0 ends a slip like a
/// reversal does: the element sticks and holds its force.
///
/// Discretisation, exact for `v` held over the step:
/// - a sticking element moves linearly, so the instant it reaches its bound
///   `alpha_i g(v)` is found exactly inside the step, and it spends the rest
///   of the step slipping;
/// - a slipping element relaxes exponentially towards `sign(v) alpha_i g(v)`
///   with rate `C / (alpha_i g(v))` (the exact solution for held `v`); one
///   that reached its bound in the step stays on it.
///
/// So one long step equals many short ones, at any `h`. Every `|F_i|` stays
/// within `alpha_i Fs` and the steady state is `g(v) sign(v) + sigma2 v`
/// (the weights are normalised by their sum when the model is built). The
/// force is evaluated at the end of the step, with `dz_i/dt` from the end
/// state: it jumps by `sigma1_i v` when an element starts slipping.
///
/// `N` must be at least 1:
///
/// ```compile_fail
/// use friction_core::{GmsParams, StribeckParams};
/// let curve = StribeckParams { fc: 1.0, fs: 1.5, vs: 1e-3, exponent: 2.0 };
/// let p = GmsParams::<0> { curve, sigma2: 0.0, c: 100.0, elements: [] };
/// let m = p.build::<f32>(); // error: N = 0 elements
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Gms<S, const N: usize> {
    pub(super) curve: StribeckCurve<S>,
    pub(super) sigma2: S,
    pub(super) elements: [Element<S>; N],
    pub(super) sigma1_sum: S,
    /// `sum_i sigma1_i C (1 + Fs/Fc) / k_i`.
    pub(super) slip_damping: S,
}

/// Whether an element sticks or slips, and which way.
///
/// One byte with the discriminants given ([`GmsSlipMode::from_byte`] reads
/// any byte as one): [`GmsState`] holds these in a public field, so a
/// caller that keeps states in memory others may overwrite (the C ABI) can
/// check the bytes before it reads them as `GmsSlipMode`s.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(u8)]
pub enum GmsSlipMode {
    /// Sticking: the element deflects with the velocity.
    #[default]
    Stick = 0,
    /// Slipping with `v > 0`.
    Forward = 1,
    /// Slipping with `v < 0`.
    Backward = 2,
}

impl GmsSlipMode {
    /// The mode a byte holds: its discriminant, and `Stick` for a byte no
    /// mode has (so that any byte is read as some mode).
    pub const fn from_byte(byte: u8) -> Self {
        match byte {
            1 => Self::Forward,
            2 => Self::Backward,
            _ => Self::Stick,
        }
    }

    /// Whether the element slips and `v` still has the sign it slips with.
    #[inline]
    pub(super) fn slips_with<S: Scalar>(self, v: S) -> bool {
        match self {
            Self::Stick => false,
            Self::Forward => v > S::ZERO,
            Self::Backward => v < S::ZERO,
        }
    }

    pub(super) fn of_sign<S: Scalar>(v: S) -> Self {
        if v > S::ZERO {
            Self::Forward
        } else if v < S::ZERO {
            Self::Backward
        } else {
            Self::Stick
        }
    }
}

/// The GMS state: each element's force and mode.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GmsState<S, const N: usize> {
    /// Element forces `F_i = k_i z_i` (N), within `±alpha_i Fs`.
    pub force: [S; N],
    /// Element modes: sticking, or slipping and which way.
    pub mode: [GmsSlipMode; N],
}

impl<S: Scalar, const N: usize> Default for GmsState<S, N> {
    fn default() -> Self {
        Self {
            force: [S::ZERO; N],
            mode: [GmsSlipMode::Stick; N],
        }
    }
}

impl<S: Scalar, const N: usize> Gms<S, N> {
    /// The Stribeck curve `g`.
    pub fn curve(&self) -> &StribeckCurve<S> {
        &self.curve
    }

    /// The bound `alpha_i Fs` on `|F_i|` of each element.
    pub fn force_bounds(&self) -> [S; N] {
        let mut out = [S::ZERO; N];
        for (o, e) in out.iter_mut().zip(&self.elements) {
            *o = e.f_max;
        }
        out
    }

    /// Steady-state friction `g(v) sign(v) + sigma2 v`.
    pub fn steady_state(&self, v: S) -> S {
        self.curve.eval(v) * v.sign() + self.sigma2 * v
    }

    /// Advances every element over `h` (skipped at `h = 0`, which leaves the
    /// state bitwise unchanged) with `u = v - c` straining sticking elements
    /// and `v` driving the slip law; returns the force at the end.
    fn advance(&self, state: &mut GmsState<S, N>, v: S, c: S, h: S, damping: bool) -> S {
        let g = self.curve.eval(v); // >= Fc > 0
        let u = v - c;
        let mut total = self.sigma2 * v;
        for ((e, f), mode) in self
            .elements
            .iter()
            .zip(state.force.iter_mut())
            .zip(state.mode.iter_mut())
        {
            let b = e.alpha * g;
            let target = b * v.sign();
            let rate = e.c_over_alpha / g; // C / (alpha_i g(v))
            if h > S::ZERO {
                let (nf, nm) = element_step(e, *f, *mode, v, u, b, target, rate, h);
                *f = nf;
                *mode = nm;
            }
            total = total + *f;
            if damping {
                // slipping: sigma1_i dz_i/dt = sigma1_i rate (target - F_i) / k_i
                total = total
                    + if mode.slips_with(v) {
                        e.slip_sigma1 * ((target - *f) / g)
                    } else if u != S::ZERO && u.sign() * *f >= b {
                        S::ZERO // held at the bound by a correction against v
                    } else {
                        e.sigma1 * u
                    };
            }
        }
        total
    }
}

/// One element over `h > 0`: the stick phase up to the bound (if the
/// element sticks), then the slip phase for the rest of the step.
#[allow(clippy::too_many_arguments)]
#[inline]
pub(super) fn element_step<S: Scalar>(
    e: &Element<S>,
    f: S,
    mode: GmsSlipMode,
    v: S,
    u: S,
    b: S,
    target: S,
    rate: S,
    h: S,
) -> (S, GmsSlipMode) {
    let mut f = f;
    let mut mode = mode;
    // time left for slipping
    let mut left = h;
    if !mode.slips_with(v) {
        // sticking (a reversal or a stop ends a slip): dF/dt = k u
        mode = GmsSlipMode::Stick;
        left = S::ZERO;
        if u != S::ZERO {
            let dir = u.sign();
            let room = b - dir * f; // to the bound ahead
            let travel = e.k * u.abs() * h; // finite or +inf, never NaN
            if travel < room {
                f = f + dir * travel;
            } else {
                let with_v = dir == v.sign();
                if room > S::ZERO {
                    // the exact instant it reaches the bound: h room / travel
                    if with_v {
                        left = h * (S::ONE - room / travel);
                    }
                    f = dir * b;
                }
                // at or beyond the bound: no further outward motion; moving
                // with v it slips from here, else a correction holds it
                if with_v {
                    mode = GmsSlipMode::of_sign(v);
                    if room <= S::ZERO {
                        left = h;
                    }
                }
            }
        }
    }
    if mode != GmsSlipMode::Stick && left > S::ZERO {
        // exact relaxation towards sign(v) alpha_i g(v)
        f = target + (f - target) * (-(rate * left)).exp();
    }
    (f.sat(e.f_max), mode)
}

impl<S: Scalar, const N: usize> FrictionModel<S> for Gms<S, N> {
    type State = GmsState<S, N>;

    #[inline]
    fn step(&self, state: &mut GmsState<S, N>, v: S, h: S) -> S {
        match checked_inputs(v, h) {
            Some(v) => self.advance(state, v, S::ZERO, h, true),
            None => self.hold_force(state),
        }
    }

    /// `sum_i F_i`, within `±Fs` (also after rounding).
    fn hold_force(&self, state: &GmsState<S, N>) -> S {
        let mut sum = S::ZERO;
        for &f in &state.force {
            sum = sum + f;
        }
        sum.sat(self.curve.fs())
    }
}

/// Observer form: sticking elements deflect with `v - c`; slipping follows
/// the measured `v`. An element driven by the correction to its bound
/// against `v` (or at rest) is held there, sticking, with `dz_i/dt = 0`.
impl<S: Scalar, const N: usize> Observable<S> for Gms<S, N> {
    fn step_corrected(
        &self,
        state: &mut GmsState<S, N>,
        v: S,
        correction: S,
        h: S,
        damping: bool,
    ) -> S {
        self.advance(state, v, correction, h, damping)
    }

    /// `Fs + sum_i sigma1_i |v| + sigma2 |v|`, plus `sum_i sigma1_i C (1 +
    /// Fs/Fc) / k_i` (the fastest slip) when `v != 0`: what the model itself
    /// produces (`|F_i| <= alpha_i Fs`; a sticking element's rate is `|v|`,
    /// a slipping one's at most `C (1 + Fs/Fc) / k_i`; nothing slips at rest).
    fn force_bound(&self, v: S) -> S {
        let speed = v.abs();
        let slip = if v != S::ZERO {
            self.slip_damping
        } else {
            S::ZERO
        };
        self.curve.fs() + (self.sigma1_sum + self.sigma2) * speed + slip
    }
}
