//! Per-parameter adaptive friction compensation: a LuGre observer whose
//! friction levels are estimated one by one, each in its own box (after
//! Canudas de Wit & Lischinsky 1997, Int. J. Adapt. Control Signal Process.
//! 11(1); Panteley, Ortega & Gäfvert 1998, Syst. Control Lett. 33(5); robust
//! modifications from Ioannou & Sun 1996, Robust Adaptive Control, Ch. 8:
//! projection, dead zone, leakage): see [`ParameterAdaptive`].

mod fixed_step;
#[cfg(test)]
mod tests;
mod variable_step;

use crate::bits::Flag;
use crate::compensator::CompensatorParams;
use crate::model::{convert, convert_derived, non_negative, positive, ParamError};
use crate::models::lugre::LuGreParams;
use crate::Scalar;
pub use fixed_step::{ParameterAdaptiveFixedStep, ParameterAdaptiveFixedStepState};
use variable_step::Estimate;
pub use variable_step::{ParameterAdaptive, ParameterAdaptiveState};

/// The number of estimates: `Fc+`, `Fc-`, `Ds`, `sigma2`, `mu`.
pub const PARAMETER_ADAPTIVE_ESTIMATES: usize = 5;

/// Design-time parameters of the per-parameter adaptation, in `f64`.
///
/// ```
/// use friction_core::{CompensatorParams, LuGreParams, ParameterAdaptiveParams};
/// let servo = CompensatorParams { h: 1e-3, kp: 60.0, ki: 200.0, kd: 1.2,
///     inertia: 0.0023, torque_constant: 1.02, limit: 10.0 };
/// let p = ParameterAdaptiveParams::new(LuGreParams::OLSSON_1998, 20.0);
/// let adaptive = p.build::<f32>(&servo)?;
/// # let _ = adaptive;
/// # Ok::<(), friction_core::ParamError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ParameterAdaptiveParams {
    /// The nominal model: its `fc` (both directions), `fs - fc` and `sigma2`
    /// start the estimates and are the leakage targets; `vs`, the exponent,
    /// `sigma0` and `sigma1` are used as they are. `vd` is ignored.
    pub model: LuGreParams,
    /// Observer gain `k >= 0` (1/s).
    pub observer_gain: f64,
    /// Adaptation rate `a >= 0` (1/s): `γ = a kc kp`.
    pub rate: f64,
    /// Weight `w >= 0` of the error's rate: `γd = w γ kd / kp`.
    pub derivative_weight: f64,
    /// Leakage `rho >= 0` (1/s) toward the nominal values.
    pub leakage: f64,
    /// Box factor `>= 1` of the projection (see [`ParameterAdaptive`]).
    pub box_factor: f64,
    /// Dead zone `>= 0` on `|e|` (position units).
    pub dead_zone: f64,
    /// Adaptation only while `|v| >= min_speed >= 0`.
    pub min_speed: f64,
    /// Reference speed `> 0` of the viscous estimate (e.g. the peak speed).
    pub speed: f64,
    /// Nominal load coefficient `mu0 >= 0` (friction per unit of
    /// transmitted torque).
    pub load: f64,
    /// Upper bound `load_max >= mu0` of the load coefficient (0: no load term).
    pub load_max: f64,
    /// Rate `>= 0` (1/s) of the prediction-error law (0: off), which
    /// learns from the friction the compensator measures (see
    /// [`ParameterAdaptive`]); `prediction_rate h <= 1`.
    pub prediction_rate: f64,
    /// Rate `>= 0` (1/s) of the stiffness law (0: off), which learns a
    /// factor on `sigma0` from the friction the compensator measures while
    /// the bristle crosses over after a reversal (see [`ParameterAdaptive`]);
    /// `stiffness_rate h <= 1`.
    pub stiffness_rate: f64,
    /// Box factor of the stiffness factor, within `[1, 1000]`: the factor
    /// stays within `[1 / stiffness_box, stiffness_box]`.
    pub stiffness_box: f64,
    /// The bristle's step (see [`ParameterAdaptive`]): `false`, an implicit
    /// Euler step within the sliding level `g^(v) / sigma0`; `true`,
    /// LuGre's own exact step within the level at rest of the side the
    /// bristle ends on (the variable form's build then also refuses a least
    /// level over `sigma0` the scalar cannot hold, as LuGre's does). The
    /// fixed-step form takes its step from its builder:
    /// [`build_fixed_step`](Self::build_fixed_step) (implicit; refuses
    /// `true`) or [`build_fixed_step_exact`](Self::build_fixed_step_exact).
    pub exact_step: bool,
}

impl ParameterAdaptiveParams {
    /// Defaults around `model` with observer gain `k`: rate 4 1/s, `w = 1`,
    /// no leakage, box factor 5, no dead zone, no speed threshold,
    /// reference speed 1, no load term, no prediction-error law, no
    /// stiffness law (its box 10), the implicit step.
    pub const fn new(model: LuGreParams, observer_gain: f64) -> Self {
        Self {
            model,
            observer_gain,
            rate: 4.0,
            derivative_weight: 1.0,
            leakage: 0.0,
            box_factor: 5.0,
            dead_zone: 0.0,
            min_speed: 0.0,
            speed: 1.0,
            load: 0.0,
            load_max: 0.0,
            prediction_rate: 0.0,
            stiffness_rate: 0.0,
            stiffness_box: 10.0,
            exact_step: false,
        }
    }

    /// Checks the model and every setting; the error names the parameter.
    pub fn validate(&self) -> Result<(), ParamError> {
        self.model.validate()?;
        non_negative("observer_gain", self.observer_gain)?;
        non_negative("rate", self.rate)?;
        non_negative("derivative_weight", self.derivative_weight)?;
        non_negative("leakage", self.leakage)?;
        positive("box_factor", self.box_factor)?;
        if self.box_factor < 1.0 {
            return Err(ParamError::BelowOne("box_factor"));
        }
        non_negative("dead_zone", self.dead_zone)?;
        non_negative("min_speed", self.min_speed)?;
        positive("speed", self.speed)?;
        non_negative("load", self.load)?;
        non_negative("load_max", self.load_max)?;
        non_negative("prediction_rate", self.prediction_rate)?;
        non_negative("stiffness_rate", self.stiffness_rate)?;
        positive("stiffness_box", self.stiffness_box)?;
        if self.stiffness_box < 1.0 {
            return Err(ParamError::BelowOne("stiffness_box"));
        }
        if self.stiffness_box > STIFFNESS_BOX_MAX {
            return Err(ParamError::NotBelow {
                name: "stiffness_box",
                limit: "1000",
            });
        }
        if self.load > self.load_max {
            return Err(ParamError::NotBelow {
                name: "load",
                limit: "load_max",
            });
        }
        Ok(())
    }

    /// The nominal estimates `[Fc, Fc, Fs - Fc, sigma2, mu0]`.
    pub fn nominal(&self) -> [f64; PARAMETER_ADAPTIVE_ESTIMATES] {
        let c = &self.model.curve;
        [c.fc, c.fc, c.fs - c.fc, self.model.sigma2, self.load]
    }

    /// The projection boxes `(low, high)` of the estimates.
    pub fn boxes(&self) -> [(f64, f64); PARAMETER_ADAPTIVE_ESTIMATES] {
        let b = self.box_factor;
        let c = &self.model.curve;
        let excess = c.fs - c.fc;
        [
            (c.fc / b, c.fc * b),
            (c.fc / b, c.fc * b),
            (0.0, b * excess.max(c.fc)),
            (0.0, (b * self.model.sigma2).max(c.fs / self.speed)),
            (0.0, self.load_max),
        ]
    }

    /// Validates and builds the compensation for a compensator with
    /// `servo`'s period, gains and torque constant.
    pub fn build<S: Scalar>(
        &self,
        servo: &CompensatorParams,
    ) -> Result<ParameterAdaptive<S>, ParamError> {
        self.validate()?;
        servo.validate()?;
        let h = servo.h;
        let gamma = self.rate * servo.torque_constant * servo.kp;
        let gamma_d = if servo.kp > 0.0 {
            self.derivative_weight * gamma * servo.kd / servo.kp
        } else {
            0.0
        };
        // the regressor sizes: 1 for the levels, the speed for sigma2, a
        // quarter of the largest command torque for mu; sigma2 at a tenth of
        // the rate: on a smooth reference its regressor v is nearly
        // collinear with the Coulomb levels' sign(v), and at equal rates the
        // two shared a level error and parted only slowly
        let torque = 0.25 * servo.torque_constant * servo.limit;
        let size = [1.0, 1.0, 1.0, self.speed * VISCOUS_SLOWDOWN, torque];
        let nominal = self.nominal();
        let boxes = self.boxes();
        if self.exact_step {
            // the exact step divides by the least level over sigma0, as
            // LuGre's build checks Fc / sigma0
            convert_derived::<S>("sigma0", boxes[0].0.min(boxes[1].0) / self.model.sigma0)?;
        }
        if self.prediction_rate * h > 1.0 {
            return Err(ParamError::NotBelow {
                name: "prediction_rate",
                limit: "1 / h",
            });
        }
        if self.stiffness_rate * h > 1.0 {
            return Err(ParamError::NotBelow {
                name: "stiffness_rate",
                limit: "1 / h",
            });
        }
        // the stiffest and softest bristle the law may reach must be
        // numbers in the scalar (the variable form divides by them)
        let (stiffness_low, stiffness_high) = if self.stiffness_rate > 0.0 {
            let b = self.stiffness_box;
            convert_derived::<S>("stiffness_box", self.model.sigma0 * b)?;
            convert_derived::<S>("stiffness_box", self.model.sigma0 * h * b)?;
            convert_derived::<S>("stiffness_box", self.model.sigma0 / b)?;
            if self.exact_step {
                convert_derived::<S>(
                    "stiffness_box",
                    boxes[0].0.min(boxes[1].0) / (self.model.sigma0 * b),
                )?;
            }
            (
                convert("stiffness_box", 1.0 / b)?,
                convert("stiffness_box", b)?,
            )
        } else {
            (S::ONE, S::ONE)
        };
        let zero = Estimate {
            gamma_h: S::ZERO,
            gamma_p: S::ZERO,
            gamma_d: S::ZERO,
            nominal: S::ZERO,
            low: S::ZERO,
            high: S::ZERO,
        };
        let mut per = [zero; PARAMETER_ADAPTIVE_ESTIMATES];
        // the prediction law's sizes: without the slowdown, which helps the
        // tracking law only (its levels and viscous term share one error)
        let predicted_size = [1.0, 1.0, 1.0, self.speed, torque];
        for ((((slot, size), predicted_size), nominal), (low, high)) in per
            .iter_mut()
            .zip(size)
            .zip(predicted_size)
            .zip(nominal)
            .zip(boxes)
        {
            let scale = 1.0 / (size * size);
            *slot = Estimate {
                gamma_h: convert_or_zero("rate", gamma * h * scale)?,
                gamma_d: convert_or_zero("derivative_weight", gamma_d * scale)?,
                gamma_p: convert_or_zero(
                    "prediction_rate",
                    self.prediction_rate * h / (predicted_size * predicted_size),
                )?,
                nominal: convert_or_zero("fc", nominal)?,
                low: convert_or_zero("box_factor", low)?,
                high: convert_or_zero("box_factor", high)?,
            };
        }
        Ok(ParameterAdaptive {
            per,
            leakage_h: convert_or_zero("leakage", (self.leakage * h).min(1.0))?,
            sigma0_h: convert("sigma0", self.model.sigma0 * h)?,
            sigma0: convert("sigma0", self.model.sigma0)?,
            h: convert("h", h)?,
            inv_h: convert("h", 1.0 / h)?,
            exact_step: Flag::new(self.exact_step),
            sigma1: convert_or_zero("sigma1", self.model.sigma1)?,
            observer_gain: convert_or_zero("observer_gain", self.observer_gain)?,
            inv_vs: convert("vs", 1.0 / self.model.curve.vs)?,
            exponent: convert("stribeck_exponent", self.model.curve.exponent)?,
            square: Flag::new(self.model.curve.exponent == 2.0),
            dead_zone: convert_or_zero("dead_zone", self.dead_zone)?,
            min_speed: convert_or_zero("min_speed", self.min_speed)?,
            torque_constant: convert("torque_constant", servo.torque_constant)?,
            torque_limit: convert("limit", 4.0 * servo.torque_constant * servo.limit)?,
            signal_limit: S::from_f64(SIGNAL_LIMIT),
            centre: convert("speed", 0.5 * self.speed)?,
            stiffness_gain: convert_or_zero("stiffness_rate", self.stiffness_rate * h)?,
            stiffness_low,
            stiffness_high,
            params: *self,
            period: h,
        })
    }
}

/// `x` in the scalar, where 0 is allowed.
fn convert_or_zero<S: Scalar>(name: &'static str, x: f64) -> Result<S, ParamError> {
    if x == 0.0 {
        Ok(S::ZERO)
    } else {
        convert(name, x)
    }
}

/// The largest `stiffness_box`: a bristle 1000x stiffer or softer than
/// the model's is no model of it.
const STIFFNESS_BOX_MAX: f64 = 1e3;

/// `sqrt(10)`: the viscous estimate's gain is a tenth of the levels'
/// (relative to its regressor's size).
const VISCOUS_SLOWDOWN: f64 = 3.162_277_660_168_379_5;

/// The bound on the scaled adaptation signal, so that its product with a
/// regressor stays finite.
const SIGNAL_LIMIT: f64 = 1e6;
