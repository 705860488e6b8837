//! The variable-step Dahl model: [`Dahl`] and [`DahlState`].

use super::fixed_step::overflowed_step;
use crate::fixed_step::carried;
use crate::model::{checked_inputs, FrictionModel};
use crate::observer::Observable;
use crate::Scalar;

/// The built Dahl model.
///
/// The Dahl model (Dahl 1968, 1976), with general exponent `delta >= 1`.
///
/// ```text
/// dF/dx = sigma sign(y) |y|^delta,   y = 1 - (F / Fc) sign(v)
/// dF/dt = dF/dx v;                   friction = F + sigma2 v
/// ```
///
/// For `delta = 1` this is `dz/dt = v - sigma |v| z / Fc`, `F = sigma z`.
/// The force depends on the path in displacement only, not on its rate:
/// hysteresis without stiction, Stribeck effect or frictional lag.
///
/// Discretisation: with `v` held the step covers the displacement
/// `dx = v h` and the equation in `x` is solved exactly. With
/// `k = sigma |dx| / Fc` and `d = delta - 1` (here `y >= 0` as `|F| <= Fc`):
/// `y+ = y e^(-L)` with `L = k` for `delta = 1` and
/// `L = ln(1 + d k y^d) / d` for `delta > 1` (the closed form
/// `y+ = (y^(-d) + d k)^(-1/d)` rewritten so that it keeps its accuracy as
/// `d -> 0`, in `f32` too). The force moves by the increment
/// `F+ = F - sign(v) Fc y (e^(-L) - 1)`, so a small step is not lost to
/// rounding. Exact in `x`, so rate independence holds to rounding at any
/// step, and `|F| <= Fc` is kept.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Dahl<S> {
    pub(super) fc: S,
    pub(super) sigma: S,
    pub(super) sigma_over_fc: S,
    pub(super) delta_minus_one: S,
    pub(super) sigma2: S,
}

/// The Dahl state: the hysteretic force `F` (N), within `±Fc`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DahlState<S> {
    /// Hysteretic force `F` (without the viscous term).
    pub f: S,
}

impl<S: Scalar> Dahl<S> {
    /// One exact step over the displacement `v h`, then an observer's
    /// correction `F <- F - sigma c h` (`c = 0` for the model), clamped to
    /// `±Fc`. `h = 0` or `v = c = 0` leave the state untouched.
    #[inline]
    fn advance(&self, state: &mut DahlState<S>, v: S, c: S, h: S) -> S {
        let s = v.sign();
        let k = self.sigma_over_fc * (v * h).abs();
        let mut f = state.f;
        if k > S::ZERO {
            let y = S::ONE - f * s / self.fc;
            if y > S::ZERO {
                let d = self.delta_minus_one;
                let l = if d > S::ZERO {
                    let q = d * k * y.powf(d);
                    if q.is_finite() {
                        q.ln_1p() / d
                    } else {
                        overflowed_step(d, k, y)
                    }
                } else {
                    k
                };
                f = (f - s * self.fc * y * (-l).exp_m1()).sat(self.fc);
            }
        }
        if h > S::ZERO && c != S::ZERO {
            f = (f - self.sigma * c * h).sat(self.fc);
        }
        state.f = f;
        f + self.sigma2 * v
    }
}

impl<S: Scalar> FrictionModel<S> for Dahl<S> {
    type State = DahlState<S>;

    fn step(&self, state: &mut DahlState<S>, v: S, h: S) -> S {
        match checked_inputs(v, h) {
            Some(v) => self.advance(state, v, S::ZERO, h),
            None => self.hold_force(state),
        }
    }

    /// `F`.
    fn hold_force(&self, state: &DahlState<S>) -> S {
        state.f
    }
}

/// Observer form: the correction strains the contact, `dF/dt = sigma (v - c)
/// - (plastic part driven by v)`, applied after the exact step (first-order
/// splitting). Dahl has no `sigma1`: `damping` has no effect.
impl<S: Scalar> Observable<S> for Dahl<S> {
    fn step_corrected(
        &self,
        state: &mut DahlState<S>,
        v: S,
        correction: S,
        h: S,
        _damping: bool,
    ) -> S {
        self.advance(state, v, correction, h)
    }

    /// `Fc + sigma2 |v|`.
    fn force_bound(&self, v: S) -> S {
        self.fc + self.sigma2 * v.abs()
    }

    /// Keeps the hysteretic force `F` (the state), within `±Fc`.
    fn carry_over(&self, _old: &Self, state: &mut DahlState<S>) {
        state.f = carried(state.f, 1.0, self.fc);
    }
}
