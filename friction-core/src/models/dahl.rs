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
//! `k = sigma |dx| / Fc`: `y+ = y e^(-k)` for `delta = 1`, and
//! `|y+| = (|y|^(1-delta) + (delta - 1) k)^(-1/(delta-1))` (same sign) for
//! `delta > 1`. Exact in `x`, so rate independence holds to rounding at any
//! step, and `|F| <= Fc` is kept.

use crate::model::{checked_inputs, convert, non_negative, positive, FrictionModel, ParamError};
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
        positive("sigma", self.sigma)?;
        positive("fc", self.fc)?;
        positive("delta", self.delta)?;
        if self.delta < 1.0 {
            return Err(ParamError::BelowOne("delta"));
        }
        non_negative("sigma2", self.sigma2)?;
        Ok(())
    }

    /// Validates and builds the run-time model.
    pub fn build<S: Scalar>(&self) -> Result<Dahl<S>, ParamError> {
        self.validate()?;
        Ok(Dahl {
            fc: convert("fc", self.fc)?,
            sigma_over_fc: convert("sigma", self.sigma / self.fc)?,
            delta_minus_one: convert("delta", self.delta - 1.0)?,
            sigma2: convert("sigma2", self.sigma2)?,
        })
    }
}

/// The built Dahl model.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Dahl<S> {
    fc: S,
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

impl<S: Scalar> FrictionModel<S> for Dahl<S> {
    type State = DahlState<S>;

    fn step(&self, state: &mut DahlState<S>, v: S, h: S) -> S {
        let Some(v) = checked_inputs(v, h) else {
            return self.hold_force(state);
        };
        let s = v.sign();
        let k = self.sigma_over_fc * (v * h).abs();
        let y = S::ONE - state.f * s / self.fc;
        let y_next = if k <= S::ZERO || y == S::ZERO {
            y
        } else if self.delta_minus_one <= S::ZERO {
            y * (-k).exp()
        } else {
            let d = self.delta_minus_one;
            let m = (y.abs().powf(-d) + d * k).powf(-S::ONE / d);
            m * y.sign()
        };
        if s != S::ZERO {
            state.f = (s * self.fc * (S::ONE - y_next)).sat(self.fc);
        }
        state.f + self.sigma2 * v
    }

    /// `F`.
    fn hold_force(&self, state: &DahlState<S>) -> S {
        state.f
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
