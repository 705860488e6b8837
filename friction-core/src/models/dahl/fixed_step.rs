//! The fixed-step Dahl model, built for one sample period: [`DahlFixedStep`].

use super::DahlState;
use crate::fixed_step::{
    carried, checked_velocity, scale_ratio, signed, FixedStepModel, FixedStepObservable,
};
use crate::models::lugre::{phi_series, relax};
use crate::Scalar;

/// The state of [`DahlFixedStep`]: the variable-step form's [`DahlState`]
/// (the force `F`, here times the force scale).
pub type DahlFixedStepState<S> = DahlState<S>;

/// Dahl built for one sample period `h`
/// ([`DahlParams::build_fixed_step`](super::DahlParams::build_fixed_step)). Its state is the
/// variable-step one, [`DahlFixedStepState`] (= [`DahlState`]: a force, here
/// times the force scale). With
/// `k = sigma h |v| / Fc` (`sigma h / Fc` formed at build time), `y = 1 -
/// sign(v) F / Fc` and `d = delta - 1`:
///
/// ```text
/// L  = k                      (delta = 1)
///    = ln(1 + d k y^d) / d    (delta > 1)
/// F+ = sat(F + sign(v) Fc y (1 - e^-L) - sigma h c, Fc)
/// ```
///
/// the variable-step form's step, exact in displacement (Dahl 1968, 1976;
/// the reference sheet's `dF/dx = sigma sign(y) |y|^delta`), with `c` an
/// observer's correction (0 for the model). For `delta = 1` it costs one
/// [`Scalar::exp_neg`] (or a series below `L = 0.1`), no division, no
/// `powf`; `delta > 1` keeps `powf`, `ln_1p` and `exp_m1` (in `Fixed32`
/// these go through `f32`, software floating point on a core without an FPU).
///
/// Forces (the state `F` included) are carried times a power of two `k`
/// (the force scale: 1 in floating point), as in
/// [`LuGreFixedStep`](crate::LuGreFixedStep), and the force is returned in newtons. Below
/// `L = 0.1` the increment is formed as `Fc y (1 - e^-L) = sigma h |v| y
/// y^d (ln(1 + q) / q) (1 - e^-L) / L` with `q = d k y^d`: the scaled
/// `sigma h |v|` first, then factors of order one, so that a small step
/// keeps its precision in fixed point.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DahlFixedStep<S> {
    pub(super) fc: S,
    pub(super) inv_fc: S,
    pub(super) sigma_h: S,
    pub(super) sigma_h_over_fc: S,
    pub(super) delta_minus_one: S,
    pub(super) sigma2: S,
    /// `log2(1 / k)`: dividing by the force scale `k` is a shift by it in
    /// fixed point ([`Kernels::rescale_pow2`](crate::scalar::sealed::Kernels::rescale_pow2)).
    pub(super) inv_scale_exp: i8,
    pub(super) h: f64,
}

/// The exponent `L = ln(1 + q) / d` of a step whose `q = d k y^d`
/// overflows (a large `delta` after a reversal, where `y > 1`):
/// `ln(1 + q) ~ ln q`, so `L = ln y + (ln d + ln k) / d`, formed from
/// logarithms that stay finite; never below 0.
#[inline]
pub(super) fn overflowed_step<S: Scalar>(d: S, k: S, y: S) -> S {
    let ln = |x: S| (x - S::ONE).ln_1p();
    let l = ln(y) + (ln(d) + ln(k)) / d;
    if l > S::ZERO {
        l
    } else {
        S::ZERO
    }
}

/// `ln(1 + q) / q` for `q >= 0` (1 at 0): in a coarse scalar (`f32`, fixed point)
/// below `q = 0.1` from the series `sum_n (-q)^n / (n + 1)` to `n = 6`
/// (truncation under `q^7 / 8 < 1.3e-8`), so that a small `q` is not
/// rounded before the logarithm; else `ln_1p(q) / q`.
#[inline]
fn ln_1p_ratio<S: Scalar>(q: S) -> S {
    let coarse = S::from_f64(1.0 + 1e-9) == S::ONE;
    if q <= S::ZERO {
        S::ONE // the limit; q = 0 when k rounds to 0
    } else if coarse && q < S::from_f64(0.1) {
        let c = |n: f64| S::from_f64(1.0 / n);
        S::ONE
            - q * (c(2.0) - q * (c(3.0) - q * (c(4.0) - q * (c(5.0) - q * (c(6.0) - q * c(7.0))))))
    } else {
        q.ln_1p() / q
    }
}

impl<S: Scalar> DahlFixedStep<S> {
    #[inline]
    fn advance(&self, state: &mut DahlFixedStepState<S>, v: S, c: S) -> S {
        let mut f = state.f;
        let speed = v.abs();
        // k = sigma h |v| / Fc; the test is not `k > 0`: in fixed point k
        // rounds to 0 below 7.6e-6 while the scaled increment sigma h |v| y
        // is still thousands of steps
        let k = self.sigma_h_over_fc * speed;
        if speed > S::ZERO {
            // v != 0, so sign(v) is the sign `signed` applies
            // Fc y (scaled), and y = 1 - sign(v) F / Fc from the unscaled 1/Fc
            let gap = self.fc - signed(v, f);
            if gap > S::ZERO {
                let y = (gap * self.inv_fc).rescale_pow2(self.inv_scale_exp);
                let p = self.sigma_h * speed; // sigma h |v|, scaled: Fc k
                let d = self.delta_minus_one;
                let incr = if d > S::ZERO {
                    let y_d = y.powf(d);
                    let q = d * k * y_d;
                    if !q.is_finite() {
                        // a large delta after a reversal (y > 1): y^d overflows
                        gap * -(-overflowed_step(d, k, y)).exp_m1()
                    } else {
                        // L = ln(1 + q) / d = k y^d ln(1 + q) / q
                        let r = ln_1p_ratio(q);
                        let l = k * y_d * r;
                        if l < S::from_f64(0.1) {
                            (p * y * y_d * r).mul_fraction(phi_series(l))
                        } else {
                            gap * -(-l).exp_m1()
                        }
                    }
                } else if k < S::from_f64(0.1) {
                    // Fc y (1 - e^-k) = sigma h |v| y phi(k)
                    (p * y).mul_fraction(phi_series(k))
                } else {
                    gap.mul_fraction(relax(k).0)
                };
                f = (f + signed(v, incr)).sat(self.fc);
            }
        }
        if c != S::ZERO {
            f = (f - self.sigma_h * c).sat(self.fc);
        }
        state.f = f;
        f + self.sigma2 * v
    }
}

impl<S: Scalar> FixedStepModel<S> for DahlFixedStep<S> {
    type State = DahlFixedStepState<S>;

    fn period(&self) -> f64 {
        self.h
    }

    #[inline]
    fn step(&self, state: &mut DahlFixedStepState<S>, v: S) -> S {
        match checked_velocity(v) {
            Some(v) => self
                .advance(state, v, S::ZERO)
                .rescale_pow2(self.inv_scale_exp),
            None => self.hold_force(state),
        }
    }

    /// `F`.
    fn hold_force(&self, state: &DahlFixedStepState<S>) -> S {
        state.f.rescale_pow2(self.inv_scale_exp)
    }
}

/// As [`Dahl`](super::Dahl)'s observer form: the correction strains the contact after
/// the exact step; Dahl has no `sigma1`, `damping` has no effect.
impl<S: Scalar> FixedStepObservable<S> for DahlFixedStep<S> {
    fn step_corrected(
        &self,
        state: &mut DahlFixedStepState<S>,
        v: S,
        correction: S,
        _damping: bool,
    ) -> S {
        self.advance(state, v, correction)
            .rescale_pow2(self.inv_scale_exp)
    }

    /// `Fc + sigma2 |v|`.
    fn force_bound(&self, v: S) -> S {
        (self.fc + self.sigma2 * v.abs()).rescale_pow2(self.inv_scale_exp)
    }

    /// Keeps the hysteretic force `F`, rescaled to this model's force
    /// scale, within `±Fc`.
    fn carry_over(&self, old: &Self, state: &mut DahlFixedStepState<S>) {
        let ratio = scale_ratio(old.inv_scale_exp, self.inv_scale_exp);
        state.f = carried(state.f, ratio, self.fc);
    }
}
