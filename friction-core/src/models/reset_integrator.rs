//! The reset integrator (Haessig & Friedland 1991): see [`ResetIntegrator`].

use crate::bits::Flag;
use crate::model::{
    check_force, checked_inputs, convert, convert_derived, magnitude, magnitude_or_zero,
    FrictionModel, ParamError,
};
use crate::observer::Observable;
use crate::stribeck::{StribeckCurve, StribeckParams};
use crate::Scalar;

/// Reset-integrator parameters (`model = "reset-integrator"`), in `f64`.
///
/// ```
/// use friction_core::{FrictionModel, ResetIntegratorParams, ResetIntegratorState};
/// let p = ResetIntegratorParams { sigma0: 1e5, sigma1: 300.0, z0: 1e-5, stiction: 0.5, curve: None };
/// let model = p.build::<f32>()?;
/// let mut state = ResetIntegratorState::default();
/// let f = model.step(&mut state, 1e-3, 5e-3); // 5 µm: bonded, with stiction
/// assert!((f - (1.5 * 1e5 * 5e-6 + 300.0 * 1e-3)).abs() < 1e-4);
/// let f = model.step(&mut state, 1e-3, 5e-3); // reaches z0 = 10 µm and slides
/// assert!((f - 1e5 * 1e-5).abs() < 1e-4);
/// # Ok::<(), friction_core::ParamError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ResetIntegratorParams {
    /// Bond stiffness `sigma0 > 0` (N/m).
    pub sigma0: f64,
    /// Damping `sigma1 >= 0` (N s/m).
    pub sigma1: f64,
    /// Breakaway deflection `z0 > 0` (m).
    pub z0: f64,
    /// Stiction factor `a >= 0` (parameter `stiction`).
    pub stiction: f64,
    /// Optional Stribeck curve shaping `sigma0(v) = sigma0 g(v) / Fs`.
    pub curve: Option<StribeckParams>,
}

impl ResetIntegratorParams {
    /// Checks every parameter; the error names the first offending one.
    pub fn validate(&self) -> Result<(), ParamError> {
        magnitude("sigma0", self.sigma0)?;
        magnitude_or_zero("sigma1", self.sigma1)?;
        magnitude("z0", self.z0)?;
        magnitude_or_zero("stiction", self.stiction)?;
        if let Some(c) = &self.curve {
            c.validate()?;
        }
        Ok(())
    }

    /// Validates and builds the run-time model.
    /// Rejects parameters that underflow in the scalar type and force terms
    /// that overflow it at the velocity limit.
    pub fn build<S: Scalar>(&self) -> Result<ResetIntegrator<S>, ParamError> {
        self.validate()?;
        check_force::<S>("sigma0", (1.0 + self.stiction) * self.sigma0 * self.z0)?;
        check_force::<S>("sigma1", self.sigma1 * 2.0 * S::VELOCITY_LIMIT.to_f64())?;
        let (curve, inv_fs) = match &self.curve {
            Some(c) => (c.build()?, convert_derived("fs", 1.0 / c.fs)?),
            None => (StribeckCurve::none(), S::ONE),
        };
        Ok(ResetIntegrator {
            sigma0: convert("sigma0", self.sigma0)?,
            sigma1: convert("sigma1", self.sigma1)?,
            z0: convert("z0", self.z0)?,
            a: convert("stiction", self.stiction)?,
            shaped: Flag::new(self.curve.is_some()),
            curve,
            inv_fs,
        })
    }
}

/// The built reset integrator.
///
/// The reset integrator (Haessig & Friedland 1991).
///
/// ```text
/// dz/dt = 0   if (v > 0 and z >= z0) or (v < 0 and z <= -z0),   else v
/// F     = (1 + a(z)) sigma0(v) z + sigma1 dz/dt,   a(z) = a if |z| < z0, else 0
/// ```
///
/// One bond strain `z` grows with the displacement until the breakaway
/// deflection `z0`, where it stops ("resets" the integrator). While
/// `|z| < z0` the stiction factor `a` raises the force; it drops to
/// `sigma0 z0` once the bond breaks: the force is discontinuous in `z`.
/// With the optional Stribeck curve, `sigma0(v) = sigma0 g(v) / Fs`.
///
/// Discretisation: with `v` held, `z` moves by `v h` and stops exactly at
/// `±z0` within the step (the switching instant is handled inside the
/// step, not at its end). Exact for held `v`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ResetIntegrator<S> {
    sigma0: S,
    sigma1: S,
    z0: S,
    a: S,
    /// The Stribeck curve, if `shaped` (stored as a curve and a flag, not
    /// an `Option`: see `crate::bits`).
    curve: StribeckCurve<S>,
    shaped: Flag,
    inv_fs: S,
}

/// The reset-integrator state: the bond strain `z` (m), within `±z0`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ResetIntegratorState<S> {
    /// Bond strain `z`.
    pub z: S,
}

impl<S: Scalar> ResetIntegrator<S> {
    /// `sigma0(v)`.
    #[inline]
    fn stiffness(&self, v: S) -> S {
        if self.shaped.get() {
            self.sigma0 * (self.curve.eval(v) * self.inv_fs)
        } else {
            self.sigma0
        }
    }

    /// `(1 + a(z)) sigma0(v) z`.
    #[inline]
    fn elastic(&self, z: S, v: S) -> S {
        let a = if z.abs() < self.z0 { self.a } else { S::ZERO };
        (S::ONE + a) * (self.stiffness(v) * z)
    }

    /// The breakaway deflection `z0`.
    pub fn z0(&self) -> S {
        self.z0
    }
}

impl<S: Scalar> ResetIntegrator<S> {
    /// One step of the bond strain driven by `u = v - c` (`c` an observer's
    /// correction, 0 for the model): `z + u h`, stopped at `±z0` inside the
    /// step; the bond rate `dz/dt` is `u`, or 0 once the bond has reset.
    /// `h = 0` leaves the state untouched.
    #[inline]
    fn advance(&self, state: &mut ResetIntegratorState<S>, v: S, c: S, h: S) -> S {
        let u = v - c;
        let z = state.z;
        let (z_next, dz) = if h > S::ZERO {
            let zn = z + u * h;
            let reset = zn.abs() >= self.z0;
            let zn = zn.sat(self.z0);
            state.z = zn;
            (zn, if reset { S::ZERO } else { u })
        } else if z.abs() >= self.z0 && u * z > S::ZERO {
            (z, S::ZERO)
        } else {
            (z, u)
        };
        self.elastic(z_next, v) + self.sigma1 * dz
    }
}

impl<S: Scalar> FrictionModel<S> for ResetIntegrator<S> {
    type State = ResetIntegratorState<S>;

    fn step(&self, state: &mut ResetIntegratorState<S>, v: S, h: S) -> S {
        match checked_inputs(v, h) {
            Some(v) => self.advance(state, v, S::ZERO, h),
            None => self.hold_force(state),
        }
    }

    /// `(1 + a(z)) sigma0 z` at `v = 0`.
    fn hold_force(&self, state: &ResetIntegratorState<S>) -> S {
        self.elastic(state.z, S::ZERO)
    }
}

/// Observer form: the correction offsets the velocity that strains the bond.
/// The bond has no separate damping state: `damping` has no effect (the
/// `sigma1 dz/dt` term is part of the force law).
impl<S: Scalar> Observable<S> for ResetIntegrator<S> {
    fn step_corrected(
        &self,
        state: &mut ResetIntegratorState<S>,
        v: S,
        correction: S,
        h: S,
        _damping: bool,
    ) -> S {
        self.advance(state, v, correction, h)
    }

    /// `(1 + a) sigma0(v) z0 + sigma1 |v|`.
    fn force_bound(&self, v: S) -> S {
        (S::ONE + self.a) * (self.stiffness(v) * self.z0) + self.sigma1 * v.abs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const P: ResetIntegratorParams = ResetIntegratorParams {
        sigma0: 1e5,
        sigma1: 300.0,
        z0: 1e-5,
        stiction: 0.5,
        curve: None,
    };

    #[test]
    fn invalid_parameters_are_named() {
        assert_eq!(
            ResetIntegratorParams { z0: 0.0, ..P }.validate(),
            Err(ParamError::NotPositive("z0"))
        );
        assert_eq!(
            ResetIntegratorParams {
                stiction: -1.0,
                ..P
            }
            .validate(),
            Err(ParamError::Negative("stiction"))
        );
        let bad_curve = StribeckParams {
            fc: 2.0,
            fs: 1.0,
            vs: 1e-3,
            exponent: 2.0,
        };
        assert_eq!(
            ResetIntegratorParams {
                curve: Some(bad_curve),
                ..P
            }
            .validate(),
            Err(ParamError::StaticBelowCoulomb)
        );
    }

    #[test]
    fn switching_inside_the_step_is_exact() {
        let m = P.build::<f64>().unwrap();
        let mut s = ResetIntegratorState { z: 9e-6 };
        // 2 µm of travel: 1 µm to z0, the rest slides
        let f = m.step(&mut s, 2e-3, 1e-3);
        assert_eq!(s.z, 1e-5);
        assert_eq!(f, 1e5 * 1e-5);
        // reversal: bonded again, stiction factor back, damping sigma1 v
        let f = m.step(&mut s, -1e-3, 1e-3);
        assert!((s.z - 9e-6).abs() < 1e-20);
        assert!((f - (1.5 * 1e5 * 9e-6 - 0.3)).abs() < 1e-9);
    }

    #[test]
    fn stribeck_shaped_stiffness() {
        let curve = StribeckParams {
            fc: 1.0,
            fs: 1.5,
            vs: 1e-3,
            exponent: 2.0,
        };
        let m = ResetIntegratorParams {
            curve: Some(curve),
            ..P
        }
        .build::<f64>()
        .unwrap();
        let mut s = ResetIntegratorState::default();
        for _ in 0..100 {
            m.step(&mut s, 1.0, 1e-3);
        }
        // sliding fast: sigma0 (Fc / Fs) z0
        let f = m.step(&mut s, 1.0, 1e-3);
        assert!((f - 1e5 / 1.5 * 1e-5).abs() < 1e-9);
    }

    proptest! {
        #[test]
        fn bounded_and_finite(inputs in proptest::collection::vec((-1.0f64..1.0, 0.0f64..1e-2), 1..80)) {
            let m = P.build::<f32>().unwrap();
            let mut s = ResetIntegratorState::default();
            for (v, h) in inputs {
                let f = m.step(&mut s, v as f32, h as f32);
                prop_assert!(f.is_finite());
                prop_assert!(s.z.abs() <= 1e-5);
            }
        }
    }
}
