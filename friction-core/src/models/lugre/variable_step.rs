//! The variable-step LuGre model: [`LuGre`] and [`LuGreState`].

use crate::fixed_step::carried;
use crate::model::{checked_inputs, FrictionModel};
use crate::observer::Observable;
use crate::stribeck::StribeckCurve;
use crate::Scalar;

/// The built LuGre model: immutable, shared by any number of [`LuGreState`]s.
///
/// The LuGre model (Canudas de Wit, Olsson, Åström, Lischinsky 1995).
///
/// ```text
/// dz/dt = v - sigma0 |v| z / g(v)
/// F     = sigma0 z + sigma1(v) dz/dt + sigma2 v
/// sigma1(v) = sigma1                    (standard)
///           = sigma1 exp(-(v/vd)^2)     (with `vd`: dissipative, Åström & Canudas de Wit 2008)
/// ```
///
/// Discretisation: with `v` held over the step the `z`-equation is linear,
/// `dz/dt = v - a z` with `a = sigma0 |v| / g(v) >= 0`, and is solved exactly
/// (exponential relaxation towards `sign(v) g(v) / sigma0`). The step is
/// unconditionally stable at any `h`, keeps `|z| <= Fs / sigma0`, and its
/// steady state is exactly `g(v) sign(v) + sigma2 v`. The force is evaluated
/// at the end of the step, with `dz/dt = v - a z(t + h)`. The rate `a` is
/// never formed where it could overflow (`sigma0 = 1e305` in `f64` still
/// lands on the steady state).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LuGre<S> {
    pub(super) curve: StribeckCurve<S>,
    pub(super) sigma0: S,
    pub(super) sigma1: S,
    pub(super) sigma2: S,
    pub(super) inv_vd_sq: S,
    pub(super) z_max: S,
    /// `1 + Fs/Fc`: `|dz/dt| <= |v| (1 + Fs/Fc)` within the bound.
    pub(super) rate_factor: S,
}

/// The LuGre state: the mean bristle deflection `z` (m).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LuGreState<S> {
    /// Bristle deflection `z`, within `±Fs/sigma0`.
    pub z: S,
}

impl<S: Scalar> LuGre<S> {
    /// The bound `Fs / sigma0` that `|z|` never exceeds.
    pub fn z_max(&self) -> S {
        self.z_max
    }

    /// The Stribeck curve `g`.
    pub fn curve(&self) -> &StribeckCurve<S> {
        &self.curve
    }

    /// `sigma0`.
    pub(crate) fn sigma0(&self) -> S {
        self.sigma0
    }

    /// `sigma2`.
    pub(crate) fn sigma2(&self) -> S {
        self.sigma2
    }

    /// Steady-state friction `g(v) sign(v) + sigma2 v`.
    pub fn steady_state(&self, v: S) -> S {
        self.curve.eval(v) * v.sign() + self.sigma2 * v
    }

    /// `sigma1(v)`.
    #[inline]
    pub(crate) fn damping(&self, v: S) -> S {
        if self.inv_vd_sq > S::ZERO {
            self.sigma1 * (-(v * v * self.inv_vd_sq)).exp()
        } else {
            self.sigma1
        }
    }

    /// One step of `dz/dt = (v - c) - sigma0 |v| z / g(v)` (`c` is an
    /// observer's correction, 0 for the model), solved exactly for held `v`
    /// and `c`: with `r = g(v)/sigma0` and `a = |v|/r`, `z` relaxes towards
    /// `(v - c)/a`. Written without forming `a` where it may overflow, so a
    /// stiff `sigma0` lands on the equilibrium instead of collapsing to 0.
    /// Returns the force with `dz/dt` at the end of the step; `h = 0` leaves
    /// the state untouched.
    #[inline]
    fn advance(&self, state: &mut LuGreState<S>, v: S, c: S, h: S, damping: bool) -> S {
        let g = self.curve.eval(v);
        let r = g / self.sigma0; // > 0: Fc/sigma0 is checked at build
        let speed = v.abs();
        let u = v - c;
        let mut z = state.z;
        if h > S::ZERO {
            let z_free = relaxed(z, u, speed, r, h, self.z_max + self.z_max);
            z = z_free.sat(self.z_max);
            state.z = z;
        }
        let mut f = self.sigma0 * z + self.sigma2 * v;
        if damping {
            // dz/dt = u - a z, zero while the state is held at its bound
            let mut dz = u - speed * (z / r);
            if z.abs() >= self.z_max && dz * z > S::ZERO {
                dz = S::ZERO;
            }
            f = f + self.damping(v) * dz;
        }
        f
    }
}

/// The bristle `z0` after `h > 0` of `dz/dt = u - a z` with `a = speed / r`
/// held (`r > 0`), solved exactly: relaxation towards the equilibrium
/// `u / a`, formed without `a` (which may overflow at a stiff bristle) and
/// within `±cap` (beyond the bounds it lies only with an observer's
/// correction in `u`). LuGre's step and the bristles that share it (the
/// per-parameter observer's exact step, [`crate::LuGreLoad`]).
#[inline(always)]
pub(crate) fn relaxed<S: Scalar>(z0: S, u: S, speed: S, r: S, h: S, cap: S) -> S {
    let a = speed / r; // possibly +inf
    let x = a * h; // never NaN: h > 0
    if x > S::ONE {
        let z_eq = (u / speed * r).sat(cap);
        z_eq + (z0 - z_eq) * (-x).exp()
    } else if x > S::ZERO {
        z0 + (u - a * z0) * (-(-x).exp_m1() / a)
    } else {
        z0 + u * h
    }
}

impl<S: Scalar> FrictionModel<S> for LuGre<S> {
    type State = LuGreState<S>;

    #[inline]
    fn step(&self, state: &mut LuGreState<S>, v: S, h: S) -> S {
        match checked_inputs(v, h) {
            Some(v) => self.advance(state, v, S::ZERO, h, true),
            None => self.hold_force(state),
        }
    }

    /// `sigma0 z`.
    fn hold_force(&self, state: &LuGreState<S>) -> S {
        self.sigma0 * state.z
    }
}

impl<S: Scalar> Observable<S> for LuGre<S> {
    fn step_corrected(
        &self,
        state: &mut LuGreState<S>,
        v: S,
        correction: S,
        h: S,
        damping: bool,
    ) -> S {
        self.advance(state, v, correction, h, damping)
    }

    fn force_bound(&self, v: S) -> S {
        let speed = v.abs();
        self.curve.fs() + (self.damping(v) * self.rate_factor + self.sigma2) * speed
    }

    /// Keeps the elastic force `sigma0 z`: `z = z_old sigma0_old / sigma0`,
    /// within `±Fs/sigma0`.
    fn carry_over(&self, old: &Self, state: &mut LuGreState<S>) {
        let ratio = old.sigma0.to_f64() / self.sigma0.to_f64();
        state.z = carried(state.z, ratio, self.z_max);
    }
}
