//! The elasto-plastic model (Dupont, Hayward, Armstrong, Altpeter 2002).
//!
//! LuGre with a purely elastic pre-sliding regime, which removes drift:
//!
//! ```text
//! dz/dt = v - alpha(z, v) sigma0 |v| z / g(v)
//! F     = sigma0 z + sigma1 dz/dt + sigma2 v
//! z_max(v) = g(v) / sigma0,   0 < z_ba < Fc / sigma0 <= z_max(v)
//! alpha = 0                                                       |z| <= z_ba
//!       = 1/2 + 1/2 sin(pi (|z| - (z_max + z_ba)/2) / (z_max - z_ba))   z_ba < |z| < z_max
//!       = 1                                                       |z| >= z_max
//! (each when sign z = sign v; alpha = 0 when they differ)
//! ```
//!
//! Discretisation: with `v` held over the step, write `w = z sign(v)` (the
//! deflection along the motion) and `xi = |v| h` (the distance slid); then
//! `dw/dxi = 1 - alpha(w) w / z_max`, a scalar autonomous equation:
//!
//! - below `z_ba` it is `w + xi`, exact: no drift, `z` follows the displacement;
//! - above `z_max` (`alpha = 1`) it is linear, solved exactly:
//!   `z_max + (w - z_max) e^(-xi / z_max)`;
//! - in the transition zone, with `u = (z_max - w) / (z_max - z_ba)` in `[0, 1]`
//!   and `eps = (z_max - z_ba) / z_max`, `1 - alpha = sin^2(pi u / 2)` and
//!   `du/dxi' = -u r(u)`, `r = eps + b(u) u`, `b = (pi/2)^2 (sin(phi)/phi)^2 (1 - eps u)`,
//!   `phi = pi u / 2`, `xi' = xi / (z_max - z_ba)`. `sin(phi)/phi` is its Taylor
//!   polynomial to `phi^12` (error below 4.3e-10 on the bounded phase), so no
//!   `sin` is called. Classical RK4 sub-steps of length
//!   `0.5 / (r + (pi/2)^2 u)` (so `h r <= 0.5`) run until the distance is used
//!   or `u <= 0.01`, at most 24 of them (from `u = 1` 22 suffice for any
//!   `eps`, which a test checks: where `alpha`'s sine dominates, each
//!   sub-step shrinks `u` by about `1/1.25`). The rest is the tail, where
//!   `r = eps + b u` with `b` frozen at its entry value is a Riccati equation
//!   with the exact solution `u e^(-eps xi') / (1 + b u (1 - e^(-eps xi')) / eps)`;
//!   `b` varies by less than `1e-4 + eps u` relative there.
//!
//! One long step matches many tiny ones, and the sheet's equation with `sin`
//! integrated finely, to `3e-5 (z_max - z_ba)` in `w` for any distance; on
//! the validation signals the step is the exact solution for the held
//! velocity to `5e-6 Fs` RMS in force. The distance past `z_ba` is capped at `1024 z_max`
//! (beyond it `e^(-1024)` rounds to 0), so every step is finite for any
//! finite `v` and `h`, also in `f32`; `|z| <= Fs/sigma0` is kept by a final
//! clamp, and the steady state (`u = 0`, `w = z_max`) is exactly the Stribeck map.
//!
//! Worst-case cost per step: 24 RK4 sub-steps of 4 evaluations of `r(u)` (a
//! degree-6 polynomial in `phi^2`, no `sin`) plus the first, 97 in all, one
//! more for the damping term, one division per sub-step, and one `exp` and
//! one `exp_m1` in the tail. The elastic part and the region above `z_max`
//! cost no evaluation; steady sliding (`u <= 0.01`) one, plus the tail.
//! The cost guide gives the measured worst case, and the former
//! implicit-Euler step's with `sinf`, which was dearer by an order of
//! magnitude.

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
