//! The Dahl model (Dahl 1968, 1976), with general exponent `delta >= 1`: see
//! [`Dahl`].

mod fixed_step;
#[cfg(test)]
mod tests;
mod variable_step;

use crate::fixed_step::period;
use crate::model::{
    check_force, convert, convert_derived, magnitude, magnitude_or_zero, ParamError,
};
use crate::Scalar;
pub use fixed_step::{DahlFixedStep, DahlFixedStepState};
pub use variable_step::{Dahl, DahlState};

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
    /// see [`DahlFixedStep`]. Besides [`Self::build`]'s checks, rejects a bad `h`
    /// and an observer correction term `sigma h c` that overflows the scalar
    /// at `c = VELOCITY_LIMIT` ([`ParamError::ForceOverflow`] naming `sigma`).
    ///
    /// ```
    /// use friction_core::{DahlParams, DahlState, FixedStepModel};
    /// let p = DahlParams { sigma: 1e5, fc: 1.0, delta: 1.0, sigma2: 0.0 };
    /// let model = p.build_fixed_step::<f32>(1e-3)?;
    /// let mut state = DahlState::default();
    /// let mut f = 0.0;
    /// for _ in 0..1000 {
    ///     f = model.step(&mut state, 1e-3); // 1 mm of sliding
    /// }
    /// assert!((f - 1.0).abs() < 1e-5); // saturated at Fc
    /// # Ok::<(), friction_core::ParamError>(())
    /// ```
    pub fn build_fixed_step<S: Scalar>(&self, h: f64) -> Result<DahlFixedStep<S>, ParamError> {
        self.validate()?;
        let h = period(h)?;
        let v_max = S::VELOCITY_LIMIT.to_f64();
        let sigma_h = self.sigma * h;
        // forces carried times k, as in LuGreFixedStep
        let k = S::force_scale(self.fc.max(sigma_h * v_max).max(self.sigma2 * v_max));
        check_force::<S>("sigma2", k * self.sigma2 * v_max)?;
        check_force::<S>("sigma", k * sigma_h * v_max)?;
        Ok(DahlFixedStep {
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
