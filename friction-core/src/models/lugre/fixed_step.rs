//! The fixed-step LuGre model, built for one sample period: [`LuGreFixedStep`]
//! and [`LuGreFixedStepState`].

use crate::bits::Flag;
use crate::fixed_step::{
    carried, checked_velocity, scale_ratio, signed, FixedStepModel, FixedStepObservable,
};
use crate::stribeck::StribeckCurve;
use crate::Scalar;

/// LuGre built for one sample period `h`
/// ([`LuGreParams::build_fixed_step`](super::LuGreParams::build_fixed_step)), with the
/// elastic force `w = sigma0 z` as its state:
///
/// ```text
/// x  = sigma0 h |v| / g(v)                       (= a h)
/// w+ = w + (sign(v) g(v) - w) (1 - e^-x) - sigma0 h c (1 - e^-x) / x
/// F  = w+ + sigma1(v) dz/dt + sigma2 v,   dz/dt = (v - c) - |v| w+ / g(v)
/// ```
///
/// the variable-step form's exact held-velocity solution (`c` is an
/// observer's correction, 0 for the model), with `sigma0 h` formed at build
/// time, one division per step (`1/g`), and `1 - e^-x` from a series below
/// `x = 0.1` (no cancellation at low speed, see `phi_series`) and from [`Scalar::exp_neg`]
/// above. `|w| <= Fs` always. Forces are carried times a power of two,
/// [`LuGreFixedStep::force_scale`] (1 in floating point,
/// chosen to use the range in fixed point).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LuGreFixedStep<S> {
    pub(super) curve: StribeckCurve<S>,
    /// `sigma0 h`, times the force scale.
    pub(super) sigma0_h: S,
    pub(super) sigma1: S,
    /// `sigma1` unscaled (the damping factor's; formed at build).
    pub(super) sigma1_unscaled: S,
    pub(super) sigma2: S,
    pub(super) inv_vd_sq: S,
    pub(super) fs: S,
    pub(super) rate_factor: S,
    /// `log2(1 / k)`: [`Kernels::rescale_pow2`](crate::scalar::sealed::Kernels::rescale_pow2)
    /// by it divides by the force
    /// scale, a shift in fixed point instead of a product with `1 / k`.
    pub(super) inv_scale_exp: i8,
    /// `inv_vd_sq > 0`: `sigma1` fades with speed (a flag, one load and
    /// one branch instead of a floating-point comparison a step).
    pub(super) fades: Flag,
    pub(super) scale_s: S,
    pub(super) scale: f64,
    pub(super) h: f64,
}

/// The state of [`LuGreFixedStep`]: the elastic force `w = sigma0 z` (N), times
/// the model's [`force_scale`](LuGreFixedStep::force_scale) (1 in floating point).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LuGreFixedStepState<S> {
    /// Elastic force `w = sigma0 z` times the force scale, within `±Fs` times it.
    pub w: S,
}

/// `(1 - e^-x) / x` for `0 <= x < 0.1` from the series
/// `sum_n (-x)^n / (n + 1)!` (no cancellation at low speed): to `n = 7`
/// (truncation under `x^8 / 9! < 3e-14`), or to `n = 4` (under
/// `x^5 / 6! < 1.4e-8`, a quarter of `f32`'s half unit) in a scalar that
/// cannot tell `1 + 1e-9` from 1 (`f32`, fixed point): a test the compiler
/// folds away.
#[inline]
pub(crate) fn phi_series<S: Scalar>(x: S) -> S {
    phi_series_inlined(x)
}

/// [`phi_series`], always inlined: LuGre's fixed step (cheaper with it
/// inlined on a Cortex-M0) and the per-parameter observer's exact step
/// (another caller of [`phi_series`] or [`relax`] changes whether the
/// compiler inlines them into Dahl's step, which moved its Q16.16 worst
/// case past its guard). Dahl's and the elasto-plastic step call [`phi_series`]
/// instead: inlined into Dahl's, the compiler evaluates the series on
/// every step rather than only where it is used (see the cost guide).
#[inline(always)]
pub(crate) fn phi_series_inlined<S: Scalar>(x: S) -> S {
    let c = |n: f64| S::from_f64(1.0 / n);
    let coarse = S::from_f64(1.0 + 1e-9) == S::ONE;
    // 1/(n+1)! nested
    // x < 0.1: every product is with a fraction
    let x_times = |a: S| a.mul_fraction(x);
    if coarse {
        S::ONE - x_times(c(2.0) - x_times(c(6.0) - x_times(c(24.0) - x_times(c(120.0)))))
    } else {
        let tail = c(120.0) - x_times(c(720.0) - x_times(c(5040.0) - x_times(c(40320.0))));
        S::ONE - x_times(c(2.0) - x_times(c(6.0) - x_times(c(24.0) - x_times(tail))))
    }
}

/// `1 - e^-x` and `(1 - e^-x) / x` for `x >= 0`: [`phi_series`] below
/// `x = 0.1`, [`Scalar::exp_neg`] above.
#[inline]
pub(crate) fn relax<S: Scalar>(x: S) -> (S, S) {
    if x < S::from_f64(0.1) {
        let phi = phi_series(x);
        (x * phi, phi)
    } else {
        let one_minus_e = S::ONE - x.exp_neg();
        (one_minus_e, one_minus_e / x)
    }
}

/// `sign(v) g - w`, the distance of `w` to its target (any sign at `v = 0`,
/// where it is multiplied by `|v| = 0`).
#[inline]
fn gap_end<S: Scalar>(v: S, g: S, w: S) -> S {
    signed(v, g) - w
}

impl<S: Scalar> LuGreFixedStep<S> {
    /// The power of two the forces inside (the state `w` included) are
    /// carried times: 1 in floating point.
    pub fn force_scale(&self) -> f64 {
        self.scale
    }

    /// The Stribeck curve `g`, times the force scale.
    pub(crate) fn curve(&self) -> &StribeckCurve<S> {
        &self.curve
    }

    /// The force scale `k` as a scalar.
    pub(crate) fn scale_s(&self) -> S {
        self.scale_s
    }

    /// `k / g` for a scaled force `g > 0`: its reciprocal in newtons^-1
    /// ([`Kernels::reciprocal_rescaled`](crate::scalar::sealed::Kernels::reciprocal_rescaled);
    /// the quotient's value).
    #[inline(always)]
    pub(crate) fn inverse_unscaled(&self, g: S) -> S {
        g.reciprocal_rescaled(self.inv_scale_exp)
    }

    /// `x / k`, turning a scaled force back into newtons: a shift in fixed
    /// point ([`Kernels::rescale_pow2`](crate::scalar::sealed::Kernels::rescale_pow2),
    /// rounding to nearest, saturating),
    /// nothing in floating point.
    #[inline(always)]
    pub(crate) fn unscale(&self, x: S) -> S {
        x.rescale_pow2(self.inv_scale_exp)
    }

    /// `sigma0 h`, times the force scale.
    pub(crate) fn sigma0_h(&self) -> S {
        self.sigma0_h
    }

    /// `sigma2`.
    pub(crate) fn sigma2(&self) -> S {
        self.sigma2
    }

    /// `Fs`, the bound on `|w|`.
    pub(crate) fn fs(&self) -> S {
        self.fs
    }

    /// `sigma1(v)`.
    #[inline(always)]
    pub(crate) fn damping(&self, v: S) -> S {
        if self.fades.get() {
            self.sigma1 * (v * v * self.inv_vd_sq).exp_neg()
        } else {
            self.sigma1
        }
    }

    // always inlined: the model's step (c = 0, damping on) then carries no
    // correction or damping-switch branch and no call
    // CORRECTED: the observer's step, with its correction `c` (the model's
    // step has c = 0 and forms none of its terms: in floating point
    // `d * 0` is not folded away, and a run-time test costs the observer)
    #[inline(always)]
    fn advance<const CORRECTED: bool>(
        &self,
        state: &mut LuGreFixedStepState<S>,
        v: S,
        c: S,
        damping: bool,
    ) -> S {
        let g = self.curve.eval_fast(v); // scaled, >= Fc scaled > 0
                                         // 1/g unscaled: in fixed point a scaled g of hundreds has a
                                         // reciprocal of a few hundred steps, this one of hundreds of thousands
        let inv_g = self.inverse_unscaled(g);
        let speed = v.abs();
        // the elastic increment over the step, sigma0 h |v| (scaled): the
        // products below are ordered so that none is a tiny number, which
        // fixed point would round to a few steps
        // within k sigma0 h v_max (checked at build_fixed_step): no overflow test
        let p = self.sigma0_h.mul_bounded(speed);
        let x = self.unscale(p * inv_g); // = sigma0 h |v| / g, finite or +inf
        let w0 = state.w;
        // at v = 0 nothing moves (p = 0): the target's sign is moot
        let gap = signed(v, g) - w0;
        let (mut w, phi) = if x < S::from_f64(0.1) {
            // gap (1 - e^-x) = p (gap / g) phi(x), where p (gap / g) =
            // x gap is within an eighth of the range (the x tested is
            // rounded, and with k = 2^-14 a true x up to 0.125 passes it; a
            // saturated gap / g is only smaller): no overflow test
            let phi = phi_series_inlined(x);
            let rate = p.mul_bounded(self.unscale(gap * inv_g));
            (w0 + rate.mul_fraction(phi), phi)
        } else {
            let one_minus_e = S::ONE - x.exp_neg();
            (w0 + gap.mul_fraction(one_minus_e), one_minus_e / x)
        };
        if CORRECTED {
            // phi = 0 when x is infinite: the product stays a number
            w = w - (self.sigma0_h * c).mul_fraction(phi);
        }
        // w.sat(fs), with the test for the bound kept for the damping term
        // (|w+| >= Fs exactly when |w| >= Fs; a NaN is neither)
        let at_bound = w.abs() >= self.fs;
        let w = if at_bound { signed(w, self.fs) } else { w };
        state.w = w;
        let mut f = w + self.sigma2.mul_bounded(v); // within k sigma2 v_max
        if damping {
            // dz/dt = (v - c) - |v| w / g, zero while held at the bound
            // (formed only at the bound: Q16.16 on a Cortex-M0 saves two
            // products and a rescale a step)
            let held = at_bound && {
                let ratio = self.unscale(w * inv_g);
                let dz = (v - c) - speed * ratio;
                dz * w > S::ZERO
            };
            if !held {
                // sigma1 dz/dt = (sigma1 |v| / g) (sign(v) g - w) - sigma1 c:
                // the small difference of two scaled forces times a
                // dimensionless factor formed from the unscaled sigma1 and
                // 1/g, so that no rounding of a ratio (1.5e-5 in fixed
                // point) is multiplied by sigma1 |v|, and with no division
                let (d, d_unscaled) = if self.fades.get() {
                    let d = self.damping(v);
                    (d, self.unscale(d))
                } else {
                    (self.sigma1, self.sigma1_unscaled)
                };
                // sigma1 / g <= sigma1 / Fc and sigma1 |v| / g, checked
                // at build_fixed_step (about a quarter of the range), and the
                // damping force within twice k sigma1 v_max (1 + Fs/Fc)
                // (|sign(v) g - w| <= g + Fs; a 1/g of one Q16.16 step can
                // be twice the exact one), half the range: no overflow test
                let factor = d_unscaled.mul_bounded(inv_g).mul_bounded(speed);
                let mut damped = factor.mul_bounded(gap_end(v, g, w));
                if CORRECTED {
                    damped = damped - d * c;
                }
                f = f + damped;
            }
        }
        f
    }
}

impl<S: Scalar> FixedStepModel<S> for LuGreFixedStep<S> {
    type State = LuGreFixedStepState<S>;

    fn period(&self) -> f64 {
        self.h
    }

    #[inline]
    fn step(&self, state: &mut LuGreFixedStepState<S>, v: S) -> S {
        match checked_velocity(v) {
            Some(v) => self.unscale(self.advance::<false>(state, v, S::ZERO, true)),
            None => self.hold_force(state),
        }
    }

    /// `w = sigma0 z`.
    fn hold_force(&self, state: &LuGreFixedStepState<S>) -> S {
        self.unscale(state.w)
    }
}

impl<S: Scalar> FixedStepObservable<S> for LuGreFixedStep<S> {
    fn step_corrected(
        &self,
        state: &mut LuGreFixedStepState<S>,
        v: S,
        correction: S,
        damping: bool,
    ) -> S {
        // the step's bounded products need |v| <= VELOCITY_LIMIT, which the
        // caller promises; fixed point, where a broken promise would wrap
        // them, clamps it again
        let v = if S::ALWAYS_FINITE {
            v.sat(S::VELOCITY_LIMIT)
        } else {
            v
        };
        self.unscale(self.advance::<true>(state, v, correction, damping))
    }

    fn force_bound(&self, v: S) -> S {
        let speed = v.abs();
        self.unscale(self.fs + (self.damping(v) * self.rate_factor + self.sigma2) * speed)
    }

    /// Keeps the elastic force `w` (the state is a force): rescaled to this
    /// model's force scale, within `±Fs`.
    fn carry_over(&self, old: &Self, state: &mut LuGreFixedStepState<S>) {
        let ratio = scale_ratio(old.inv_scale_exp, self.inv_scale_exp);
        state.w = carried(state.w, ratio, self.fs);
    }
}
