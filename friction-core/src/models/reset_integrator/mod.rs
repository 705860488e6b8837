//! The reset integrator (Haessig & Friedland 1991): see [`ResetIntegrator`].

#[cfg(test)]
mod tests;
mod variable_step;

use crate::bits::Flag;
use crate::model::{
    check_force, convert, convert_derived, magnitude, magnitude_or_zero, ParamError,
};
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

pub use variable_step::{ResetIntegrator, ResetIntegratorState};
