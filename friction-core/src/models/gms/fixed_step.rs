//! The fixed-step generalized Maxwell-slip model, built for one sample
//! period: [`GmsFixedStep`].

use super::{GmsSlipMode, GmsState};
use crate::fixed_step::{checked_velocity, signed, FixedStepModel, FixedStepObservable};
use crate::models::lugre::phi_series;
use crate::stribeck::StribeckCurve;
use crate::Scalar;

/// One element of [`GmsFixedStep`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(super) struct ElementFixedStep<S> {
    /// `k_i h`.
    pub(super) k_h: S,
    /// Normalised weight.
    pub(super) alpha: S,
    /// `alpha_i Fs`, the bound on `|F_i|`.
    pub(super) f_max: S,
    /// `C h / alpha_i`.
    pub(super) c_h_over_alpha: S,
    /// `sigma1_i C / (alpha_i k_i)` (N, unscaled): the slip damping force
    /// per unit of `(sign(v) b_i - F_i) / g`.
    pub(super) slip_sigma1: S,
    /// `sigma1_i`, times the force scale.
    pub(super) sigma1: S,
}

/// The state of [`GmsFixedStep`]: the variable-step form's [`GmsState`]
/// (element forces, here times the force scale, and modes).
pub type GmsFixedStepState<S, const N: usize> = GmsState<S, N>;

/// GMS built for one sample period `h`
/// ([`GmsParams::build_fixed_step`](super::GmsParams::build_fixed_step)). Its state is the
/// variable-step one, [`GmsFixedStepState`] (= [`GmsState`]: element forces
/// and modes). With `b_i =
/// alpha_i g(v)` and `u = v - c` (`c` an observer's correction, 0 for the
/// model), each element per step:
///
/// ```text
/// sticking: F_i + sign(u) k_i h |u|          while below b_i; reaching it at
///           the fraction s = 1 - room / (k_i h |u|) of the step before the end
/// slipping: F_i+ = sign(v) b_i + (F_i - sign(v) b_i) e^(-(C h / alpha_i) s / g(v))
/// F = sum_i (F_i + sigma1_i dz_i/dt) + sigma2 v
/// ```
///
/// the variable-step form's exact held-velocity step (Lampaert, Al-Bender,
/// Swevers 2003; see [`Gms`](super::Gms)) with `k_i h`, `C h / alpha_i` and
/// `sigma1_i C / (alpha_i k_i)` formed in `f64` at build time, at most one
/// reciprocal `1/g` per step (none while every element sticks, in fixed
/// point and soft float) and, for the relaxation, a series below `x = 0.1` then
/// [`Scalar::exp_neg`]. Forces (the element forces of the state included)
/// are carried times a power of two `k` (the force scale: 1 in
/// floating point), as in [`LuGreFixedStep`](crate::LuGreFixedStep), and the force is
/// returned in newtons.
///
/// `N` must be at least 1:
///
/// ```compile_fail
/// use friction_core::{GmsParams, StribeckParams};
/// let curve = StribeckParams { fc: 1.0, fs: 1.5, vs: 1e-3, exponent: 2.0 };
/// let p = GmsParams::<0> { curve, sigma2: 0.0, c: 100.0, elements: [] };
/// let m = p.build_fixed_step::<f32>(1e-3); // error: N = 0 elements
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GmsFixedStep<S, const N: usize> {
    pub(super) curve: StribeckCurve<S>,
    pub(super) sigma2: S,
    pub(super) elements: [ElementFixedStep<S>; N],
    pub(super) sigma1_sum: S,
    pub(super) slip_damping: S,
    pub(super) inv_scale: S,
    pub(super) scale_s: S,
    pub(super) h: f64,
}

impl<S: Scalar, const N: usize> GmsFixedStep<S, N> {
    /// The Stribeck curve `g`.
    pub fn curve(&self) -> &StribeckCurve<S> {
        &self.curve
    }

    /// The bound `alpha_i Fs` on `|F_i|` of each element, times the force
    /// scale (the units of the state).
    pub fn force_bounds(&self) -> [S; N] {
        let mut out = [S::ZERO; N];
        for (o, e) in out.iter_mut().zip(&self.elements) {
            *o = e.f_max;
        }
        out
    }

    #[inline]
    fn advance(&self, state: &mut GmsFixedStepState<S, N>, v: S, c: S, damping: bool) -> S {
        // g scaled (>= Fc scaled > 0); 1/g unscaled: in fixed point the
        // reciprocal of a scaled g would be a few steps
        let g = self.curve.eval_fast(v);
        // formed only if an element slips: a step where every element sticks
        // (pre-sliding, the servo's holding) takes no division
        let mut inv_g = Reciprocal::new(self.scale_s, g);
        let u = v - c;
        let mut total = self.sigma2 * v;
        // sum of sigma1_i over the sticking elements (at most sigma1_sum,
        // which fits), times u once after the loop
        let mut stuck_sigma1 = S::ZERO;
        for ((e, f), mode) in self
            .elements
            .iter()
            .zip(state.force.iter_mut())
            .zip(state.mode.iter_mut())
        {
            // alpha_i g, alpha_i <= 1 (a fraction but for a single element)
            let b = g.mul_fraction(e.alpha);
            // used only while slipping, so with v != 0
            let target = signed(v, b);
            let (nf, nm) = element_step_fixed(e, *f, *mode, v, u, b, target, &mut inv_g);
            *f = nf;
            *mode = nm;
            total = total + nf;
            if damping {
                if nm.slips_with(v) {
                    // sigma1_i dz_i/dt = sigma1_i C / (alpha_i k_i) (target - F_i) / g:
                    // the scaled force difference times an unscaled ratio
                    total = total + (target - nf) * (e.slip_sigma1 * inv_g.get());
                } else if !((u > S::ZERO && nf >= b) || (u < S::ZERO && -nf >= b)) {
                    // sticking (not held at the bound by a correction
                    // against v): sigma1_i u
                    stuck_sigma1 = stuck_sigma1 + e.sigma1;
                }
            }
        }
        if damping {
            total = total + stuck_sigma1 * u;
        }
        total
    }
}

/// `n / d`, divided on first use and kept (at once where a division is one
/// instruction, [`Kernels::CHEAP_DIVISION`](crate::scalar::sealed::Kernels::CHEAP_DIVISION)):
/// GMS's `1/g`, which only a
/// slipping element needs: a step where every element sticks (the common
/// case) then divides not at all, which matters on a core without a divide
/// instruction (Q16.16 on a Cortex-M0; see the cost guide).
struct Reciprocal<S> {
    n: S,
    d: S,
    quotient: Option<S>,
}

impl<S: Scalar> Reciprocal<S> {
    #[inline(always)]
    fn new(n: S, d: S) -> Self {
        Self {
            n,
            d,
            quotient: if S::CHEAP_DIVISION { Some(n / d) } else { None },
        }
    }

    #[inline(always)]
    fn get(&mut self) -> S {
        match self.quotient {
            Some(q) => q,
            None => {
                let q = self.n / self.d;
                self.quotient = Some(q);
                q
            }
        }
    }
}

/// One element over the period:
/// [`element_step`](super::variable_step::element_step) with the time left
/// for slipping counted in periods.
// always inlined into the model's step: no call and argument shuffle per
// element (cheaper in f32 on a Cortex-M4F and in Q16.16 on a Cortex-M0;
// soft-float f32 on a Cortex-M0 is slightly dearer, a trade the cost
// guide records)
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn element_step_fixed<S: Scalar>(
    e: &ElementFixedStep<S>,
    f: S,
    mode: GmsSlipMode,
    v: S,
    u: S,
    b: S,
    target: S,
    inv_g: &mut Reciprocal<S>,
) -> (S, GmsSlipMode) {
    let mut f = f;
    let mut mode = mode;
    // fraction of the period left for slipping
    let mut left = S::ONE;
    if !mode.slips_with(v) {
        mode = GmsSlipMode::Stick;
        left = S::ZERO;
        if u != S::ZERO {
            // u != 0: `signed(u, x)` is sign(u) x
            let room = b - signed(u, f);
            let travel = e.k_h * u.abs();
            if travel < room {
                f = f + signed(u, travel);
            } else {
                let with_v = if u > S::ZERO {
                    v > S::ZERO
                } else {
                    v < S::ZERO
                };
                if room > S::ZERO {
                    if with_v {
                        left = S::ONE - room / travel;
                    }
                    f = signed(u, b);
                }
                if with_v {
                    mode = GmsSlipMode::of_sign(v);
                    if room <= S::ZERO {
                        left = S::ONE;
                    }
                }
            }
        }
    }
    if mode != GmsSlipMode::Stick && left > S::ZERO {
        // x = (C h / alpha_i) s / g; below 0.1 the increment
        // (target - F_i)(1 - e^-x) = ((target - F_i) C h / alpha_i) (s / g) phi(x),
        // the scaled difference first, so that a slow relaxation is not lost to rounding
        // (the relaxations below are fractions)
        let inv_g = inv_g.get();
        let x = e.c_h_over_alpha * inv_g * left;
        f = if x < S::from_f64(0.1) {
            f + ((target - f) * e.c_h_over_alpha * (inv_g * left)).mul_fraction(phi_series(x))
        } else {
            target + (f - target).mul_fraction(x.exp_neg())
        };
    }
    (f.sat(e.f_max), mode)
}

impl<S: Scalar, const N: usize> FixedStepModel<S> for GmsFixedStep<S, N> {
    type State = GmsFixedStepState<S, N>;

    fn period(&self) -> f64 {
        self.h
    }

    #[inline]
    fn step(&self, state: &mut GmsFixedStepState<S, N>, v: S) -> S {
        match checked_velocity(v) {
            Some(v) => self
                .advance(state, v, S::ZERO, true)
                .rescale(self.inv_scale),
            None => self.hold_force(state),
        }
    }

    /// `sum_i F_i`, within `±Fs` (also after rounding).
    fn hold_force(&self, state: &GmsFixedStepState<S, N>) -> S {
        let mut sum = S::ZERO;
        for &f in &state.force {
            sum = sum + f;
        }
        sum.sat(self.curve.fs()).rescale(self.inv_scale)
    }
}

/// As [`Gms`](super::Gms)'s observer form: sticking elements deflect with `v - c`,
/// slipping follows the measured `v`.
impl<S: Scalar, const N: usize> FixedStepObservable<S> for GmsFixedStep<S, N> {
    fn step_corrected(
        &self,
        state: &mut GmsFixedStepState<S, N>,
        v: S,
        correction: S,
        damping: bool,
    ) -> S {
        self.advance(state, v, correction, damping)
            .rescale(self.inv_scale)
    }

    /// As [`Gms`](super::Gms)'s: `Fs + (sum_i sigma1_i + sigma2) |v|`, plus the fastest
    /// slip's damping when `v != 0`.
    fn force_bound(&self, v: S) -> S {
        let slip = if v != S::ZERO {
            self.slip_damping
        } else {
            S::ZERO
        };
        (self.curve.fs() + (self.sigma1_sum + self.sigma2) * v.abs() + slip).rescale(self.inv_scale)
    }
}
