//! The elasto-plastic model (Dupont, Hayward, Armstrong, Altpeter 2002): see
//! [`ElastoPlastic`].

mod fixed_step;
#[cfg(test)]
mod tests;
mod variable_step;
mod zone;

use crate::model::{convert, magnitude, ParamError};
use crate::models::lugre::{LuGreFixedStep, LuGreParams};
use crate::Scalar;
pub use fixed_step::{ElastoPlasticFixedStep, ElastoPlasticFixedStepState};
pub use variable_step::{ElastoPlastic, ElastoPlasticState};
use zone::DEFAULT_SUBSTEPS;
pub(crate) use zone::{corrected_shift, zone_curve_series};

/// Elasto-plastic parameters (`model = "elasto-plastic"`): LuGre's and `z_ba`.
///
/// ```
/// use friction_core::{ElastoPlasticParams, ElastoPlasticState, FrictionModel, LuGreParams};
/// let p = ElastoPlasticParams { lugre: LuGreParams::CANUDAS_1995, z_ba: 5e-6 };
/// let model = p.build::<f64>()?;
/// let mut state = ElastoPlasticState::default();
/// // 2 µm of displacement below z_ba: purely elastic, F = sigma0 x
/// let f = model.step(&mut state, 2e-6, 1.0);
/// assert!((state.z - 2e-6).abs() < 1e-18);
/// // F = sigma0 z + (sigma1 + sigma2) v, as dz/dt = v in the elastic regime
/// let (sigma1, sigma2) = (p.lugre.sigma1, p.lugre.sigma2);
/// assert!((f - (0.2 + (sigma1 + sigma2) * 2e-6)).abs() < 1e-9);
/// # Ok::<(), friction_core::ParamError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ElastoPlasticParams {
    /// The LuGre parameters (curve, `sigma0`, `sigma1`, `sigma2`, optional `vd`).
    pub lugre: LuGreParams,
    /// Break-away deflection `0 < z_ba < Fc / sigma0` (m).
    pub z_ba: f64,
}

impl ElastoPlasticParams {
    /// Checks every parameter; the error names the first offending one.
    pub fn validate(&self) -> Result<(), ParamError> {
        self.lugre.validate()?;
        magnitude("z_ba", self.z_ba)?;
        if self.z_ba >= self.lugre.curve.fc / self.lugre.sigma0 {
            return Err(ParamError::NotBelow {
                name: "z_ba",
                limit: "fc / sigma0",
            });
        }
        Ok(())
    }

    /// Validates and builds the run-time model.
    pub fn build<S: Scalar>(&self) -> Result<ElastoPlastic<S>, ParamError> {
        self.validate()?;
        Ok(ElastoPlastic {
            lugre: self.lugre.build()?,
            z_ba: convert("z_ba", self.z_ba)?,
        })
    }

    /// Validates and builds the fixed-step form for sample period `h` (s):
    /// see [`ElastoPlasticFixedStep`]. The checks are [`LuGreParams::build_fixed_step`]'s,
    /// and `sigma0 z_ba` must be representable.
    ///
    /// ```
    /// use friction_core::{ElastoPlasticFixedStepState, ElastoPlasticParams, FixedStepModel, LuGreParams};
    /// let p = ElastoPlasticParams { lugre: LuGreParams::CANUDAS_1995, z_ba: 5e-6 };
    /// let model = p.build_fixed_step::<f64>(1e-3)?;
    /// let mut state = ElastoPlasticFixedStepState::default();
    /// // 2 µm of displacement below z_ba: purely elastic, w = sigma0 x
    /// model.step(&mut state, 2e-3);
    /// assert!((state.w - 0.2).abs() < 1e-12);
    /// # Ok::<(), friction_core::ParamError>(())
    /// ```
    pub fn build_fixed_step<S: Scalar>(
        &self,
        h: f64,
    ) -> Result<ElastoPlasticFixedStep<S>, ParamError> {
        self.validate()?;
        let lugre: LuGreFixedStep<S> = self.lugre.build_fixed_step(h)?;
        Ok(ElastoPlasticFixedStep {
            w_ba: convert("z_ba", lugre.force_scale() * self.lugre.sigma0 * self.z_ba)?,
            lugre,
            max_substeps: DEFAULT_SUBSTEPS,
        })
    }
}
