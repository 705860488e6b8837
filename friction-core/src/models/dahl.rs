//! The Dahl model (Dahl 1968, 1976), with general exponent `delta >= 1`.
//!
//! ```text
//! dF/dx = sigma sign(y) |y|^delta,   y = 1 - (F / Fc) sign(v)
//! dF/dt = dF/dx v;                   friction = F + sigma2 v
//! ```
//!
//! For `delta = 1` this is `dz/dt = v - sigma |v| z / Fc`, `F = sigma z`.
//! The force depends on the path in displacement only, not on its rate:
//! hysteresis without stiction, Stribeck effect or frictional lag.
//!
//! Discretisation: with `v` held the step covers the displacement
//! `dx = v h` and the equation in `x` is solved exactly. With
//! `k = sigma |dx| / Fc` and `d = delta - 1` (here `y >= 0` as `|F| <= Fc`):
//! `y+ = y e^(-L)` with `L = k` for `delta = 1` and
//! `L = ln(1 + d k y^d) / d` for `delta > 1` (the closed form
//! `y+ = (y^(-d) + d k)^(-1/d)` rewritten so that it keeps its accuracy as
//! `d -> 0`, in `f32` too). The force moves by the increment
//! `F+ = F - sign(v) Fc y (e^(-L) - 1)`, so a small step is not lost to
//! rounding. Exact in `x`, so rate independence holds to rounding at any
//! step, and `|F| <= Fc` is kept.

use crate::fixed_step::{
    carried, checked_velocity, period, scale_ratio, signed, FixedStepModel, FixedStepObservable,
};
use crate::model::{
    check_force, checked_inputs, convert, convert_derived, magnitude, magnitude_or_zero,
    FrictionModel, ParamError,
};
use crate::models::lugre::{phi_series, relax};
use crate::observer::Observable;
use crate::Scalar;

/// Dahl parameters (`model = "dahl"`), in `f64`.
///
/// ```
/// use friction_core::{DahlParams, DahlState, FrictionModel};
/// let model = DahlParams { sigma: 1e5, fc: 1.0, delta: 1.0, sigma2: 0.0 }.build::<f32>()?;
/// let mut state = DahlState::default();
/// let mut f = 0.0;
/// for _ in 0..1000 {
///     f = model.step(&mut state, 1e-3, 1e-3); // 1 mm of sliding
/// }
/// assert!((f - 1.0).abs() < 1e-5); // saturated at Fc
/// # Ok::<(), friction_core::ParamError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DahlParams {
    /// Rest stiffness `sigma > 0` (N/m), the slope of `F(x)` at `F = 0`.
    pub sigma: f64,
    /// Coulomb level `Fc > 0` (N).
    pub fc: f64,
    /// Shape exponent `delta >= 1` (parameter `delta`).
    pub delta: f64,
    /// Viscous friction `sigma2 >= 0` (N s/m).
    pub sigma2: f64,
}

impl DahlParams {
    /// Checks every parameter; the error names the first offending one.
    pub fn validate(&self) -> Result<(), ParamError> {
        magnitude("sigma", self.sigma)?;
        magnitude("fc", self.fc)?;
        magnitude("delta", self.delta)?;
        if self.delta < 1.0 {
            return Err(ParamError::BelowOne("delta"));
        }
        magnitude_or_zero("sigma2", self.sigma2)?;
        Ok(())
    }

    /// Validates and builds the run-time model; rejects parameters that
    /// underflow in the scalar type and a `sigma2` whose force overflows it
    /// at the velocity limit.
    pub fn build<S: Scalar>(&self) -> Result<Dahl<S>, ParamError> {
        self.validate()?;
        check_force::<S>("sigma2", self.sigma2 * S::VELOCITY_LIMIT.to_f64())?;
        Ok(Dahl {
            fc: convert("fc", self.fc)?,
            sigma: convert("sigma", self.sigma)?,
            sigma_over_fc: convert_derived("sigma", self.sigma / self.fc)?,
            delta_minus_one: convert("delta", self.delta - 1.0)?,
            sigma2: convert("sigma2", self.sigma2)?,
        })
    }

    /// Validates and builds the fixed-step form for sample period `h` (s):
    /// see [`DahlAt`]. Besides [`Self::build`]'s checks, rejects a bad `h`
    /// and an observer correction term `sigma h c` that overflows the scalar
    /// at `c = VELOCITY_LIMIT` ([`ParamError::ForceOverflow`] naming `sigma`).
    ///
    /// ```
    /// use friction_core::{DahlParams, DahlState, FixedStepModel};
    /// let p = DahlParams { sigma: 1e5, fc: 1.0, delta: 1.0, sigma2: 0.0 };
    /// let model = p.build_at::<f32>(1e-3)?;
    /// let mut state = DahlState::default();
    /// let mut f = 0.0;
    /// for _ in 0..1000 {
    ///     f = model.step(&mut state, 1e-3); // 1 mm of sliding
    /// }
    /// assert!((f - 1.0).abs() < 1e-5); // saturated at Fc
    /// # Ok::<(), friction_core::ParamError>(())
    /// ```
    pub fn build_at<S: Scalar>(&self, h: f64) -> Result<DahlAt<S>, ParamError> {
        self.validate()?;
        let h = period(h)?;
        let v_max = S::VELOCITY_LIMIT.to_f64();
        let sigma_h = self.sigma * h;
        // forces carried times k, as in LuGreAt
        let k = S::force_scale(self.fc.max(sigma_h * v_max).max(self.sigma2 * v_max));
        check_force::<S>("sigma2", k * self.sigma2 * v_max)?;
        check_force::<S>("sigma", k * sigma_h * v_max)?;
        Ok(DahlAt {
            fc: convert("fc", k * self.fc)?,
            inv_fc: convert_derived("fc", 1.0 / self.fc)?,
            sigma_h: convert("sigma", k * sigma_h)?,
            sigma_h_over_fc: convert_derived("sigma", sigma_h / self.fc)?,
            delta_minus_one: convert("delta", self.delta - 1.0)?,
            sigma2: convert("sigma2", k * self.sigma2)?,
            inv_scale_exp: crate::scalar::inverse_scale_exp(k),
            h,
        })
    }
}

/// The built Dahl model.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Dahl<S> {
    fc: S,
    sigma: S,
    sigma_over_fc: S,
    delta_minus_one: S,
    sigma2: S,
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

/// Dahl built for one sample period `h` ([`DahlParams::build_at`]). Its
/// state is the variable-step one, [`DahlState`] (a force, here times the
/// force scale). With `k = sigma h |v| / Fc` (`sigma h / Fc` formed at build time),
/// `y = 1 - sign(v) F / Fc` and `d = delta - 1`:
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
/// ([`Scalar::force_scale`]: 1 in floating point), as in
/// [`LuGreAt`](crate::LuGreAt), and the force is returned in newtons. Below
/// `L = 0.1` the increment is formed as `Fc y (1 - e^-L) = sigma h |v| y
/// y^d (ln(1 + q) / q) (1 - e^-L) / L` with `q = d k y^d`: the scaled
/// `sigma h |v|` first, then factors of order one, so that a small step
/// keeps its precision in fixed point.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DahlAt<S> {
    fc: S,
    inv_fc: S,
    sigma_h: S,
    sigma_h_over_fc: S,
    delta_minus_one: S,
    sigma2: S,
    /// `log2(1 / k)`: dividing by the force scale `k` is a shift by it in
    /// fixed point ([`Scalar::rescale_pow2`]).
    inv_scale_exp: i8,
    h: f64,
}

/// The exponent `L = ln(1 + q) / d` of a step whose `q = d k y^d`
/// overflows (a large `delta` after a reversal, where `y > 1`):
/// `ln(1 + q) ~ ln q`, so `L = ln y + (ln d + ln k) / d`, formed from
/// logarithms that stay finite; never below 0.
#[inline]
fn overflowed_step<S: Scalar>(d: S, k: S, y: S) -> S {
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

impl<S: Scalar> DahlAt<S> {
    #[inline]
    fn advance(&self, state: &mut DahlState<S>, v: S, c: S) -> S {
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

impl<S: Scalar> FixedStepModel<S> for DahlAt<S> {
    type State = DahlState<S>;

    fn period(&self) -> f64 {
        self.h
    }

    #[inline]
    fn step(&self, state: &mut DahlState<S>, v: S) -> S {
        match checked_velocity(v) {
            Some(v) => self
                .advance(state, v, S::ZERO)
                .rescale_pow2(self.inv_scale_exp),
            None => self.hold_force(state),
        }
    }

    /// `F`.
    fn hold_force(&self, state: &DahlState<S>) -> S {
        state.f.rescale_pow2(self.inv_scale_exp)
    }
}

/// As [`Dahl`]'s observer form: the correction strains the contact after
/// the exact step; Dahl has no `sigma1`, `damping` has no effect.
impl<S: Scalar> FixedStepObservable<S> for DahlAt<S> {
    fn step_corrected(&self, state: &mut DahlState<S>, v: S, correction: S, _damping: bool) -> S {
        self.advance(state, v, correction)
            .rescale_pow2(self.inv_scale_exp)
    }

    /// `Fc + sigma2 |v|`.
    fn force_bound(&self, v: S) -> S {
        (self.fc + self.sigma2 * v.abs()).rescale_pow2(self.inv_scale_exp)
    }

    /// Keeps the hysteretic force `F`, rescaled to this model's force
    /// scale, within `±Fc`.
    fn carry_over(&self, old: &Self, state: &mut DahlState<S>) {
        let ratio = scale_ratio(old.inv_scale_exp, self.inv_scale_exp);
        state.f = carried(state.f, ratio, self.fc);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::vec::Vec;

    const P: DahlParams = DahlParams {
        sigma: 1e5,
        fc: 1.0,
        delta: 1.0,
        sigma2: 0.0,
    };

    #[test]
    fn invalid_parameters_are_named() {
        assert_eq!(
            DahlParams { delta: 0.5, ..P }.validate(),
            Err(ParamError::BelowOne("delta"))
        );
        assert_eq!(
            DahlParams { sigma: 0.0, ..P }.validate(),
            Err(ParamError::NotPositive("sigma"))
        );
        assert_eq!(
            DahlParams {
                sigma2: f64::NAN,
                ..P
            }
            .validate(),
            Err(ParamError::NotFinite("sigma2"))
        );
    }

    #[test]
    fn delta_one_matches_the_linear_form() {
        // z form: z+ = z_eq + (z - z_eq) e^(-sigma |dx| / Fc), F = sigma z
        let m = P.build::<f64>().unwrap();
        let mut s = DahlState::default();
        let f = m.step(&mut s, 2e-3, 1e-2); // dx = 2e-5
        let expect = 1.0 - (-1e5 * 2e-5f64).exp();
        assert!((f - expect).abs() < 1e-14);
    }

    #[test]
    fn general_exponent_is_exact_in_displacement() {
        // one step over dx equals many small steps over the same dx
        let m = DahlParams { delta: 2.5, ..P }.build::<f64>().unwrap();
        let (mut a, mut b) = (DahlState::default(), DahlState::default());
        m.step(&mut a, 1e-3, 2e-2);
        for _ in 0..1000 {
            m.step(&mut b, 1e-3, 2e-5);
        }
        assert!((a.f - b.f).abs() < 1e-12, "{} {}", a.f, b.f);
        // and close to the limit delta -> 1
        let m1 = DahlParams {
            delta: 1.0 + 1e-9,
            ..P
        }
        .build::<f64>()
        .unwrap();
        let m0 = P.build::<f64>().unwrap();
        let (mut c, mut d) = (DahlState::default(), DahlState::default());
        m1.step(&mut c, 1e-3, 1e-2);
        m0.step(&mut d, 1e-3, 1e-2);
        assert!((c.f - d.f).abs() < 1e-6);
    }

    #[test]
    fn rate_independent() {
        // the same displacement path at two speeds gives the same F(x)
        let m = DahlParams { delta: 2.0, ..P }.build::<f64>().unwrap();
        let path = |speed: f64| {
            let mut s = DahlState::default();
            let mut out = Vec::new();
            for k in 0..400 {
                let v = if (k / 100) % 2 == 0 { speed } else { -speed };
                m.step(&mut s, v, 1e-5 / speed);
                out.push(s.f);
            }
            out
        };
        let (slow, fast) = (path(1e-4), path(1.0));
        for (a, b) in slow.iter().zip(&fast) {
            assert!((a - b).abs() < 1e-12);
        }
    }

    proptest! {
        #[test]
        fn force_bounded_and_finite(
            delta in 1.0f64..4.0,
            inputs in proptest::collection::vec((-10.0f64..10.0, 0.0f64..1.0), 1..50),
        ) {
            let m = DahlParams { delta, sigma2: 0.3, ..P }.build::<f32>().unwrap();
            let mut s = DahlState::default();
            for (v, h) in inputs {
                let f = m.step(&mut s, v as f32, h as f32);
                prop_assert!(f.is_finite());
                prop_assert!(s.f.abs() <= 1.0);
            }
        }
    }
}
