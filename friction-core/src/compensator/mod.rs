//! A hardware-free position servo tick: PID with acceleration feed-forward
//! plus the friction compensation the user chooses: see [`Compensator`].

mod compensation;
mod controller;
mod retune;
#[cfg(test)]
mod tests;

use crate::bits::Flag;
use crate::gain::Gain;
use crate::model::{convert, magnitude, magnitude_or_zero, ParamError};
use crate::Scalar;
pub use compensation::{Compensation, FeedForward, FixedPeriod, FrictionSample, NoCompensation};
pub use controller::{Compensator, CompensatorState, CompensatorTick, Setpoint};
use core::fmt::Debug;

/// Design-time parameters of the servo tick, in `f64`.
///
/// Checked by [`CompensatorParams::validate`]; each error names the
/// parameter.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CompensatorParams {
    /// Sample period `h > 0` (s).
    pub h: f64,
    /// Proportional gain `kp >= 0` (command units per unit of position).
    pub kp: f64,
    /// Integral gain `ki >= 0` (command units per unit of position and second).
    pub ki: f64,
    /// Derivative gain `kd >= 0` (command units per unit of velocity).
    pub kd: f64,
    /// Inertia (or mass) `J >= 0` of the acceleration feed-forward `J a_ref`.
    pub inertia: f64,
    /// Torque constant `kc > 0`: force per command unit (1 for a torque command).
    pub torque_constant: f64,
    /// Output limit `limit > 0` (command units): the command stays within `±limit`.
    pub limit: f64,
}

impl CompensatorParams {
    /// Checks `h > 0`, gains and `inertia` `>= 0`, `torque_constant > 0`,
    /// `limit > 0`, all finite and (where not 0) within
    /// [`PARAM_RANGE`](crate::PARAM_RANGE), so that the ratios the tick
    /// carries (`J/kc`, `ki h`, `1/h`) stay normal numbers.
    pub fn validate(&self) -> Result<(), ParamError> {
        magnitude("h", self.h)?;
        magnitude_or_zero("kp", self.kp)?;
        magnitude_or_zero("ki", self.ki)?;
        magnitude_or_zero("kd", self.kd)?;
        magnitude_or_zero("inertia", self.inertia)?;
        magnitude("torque_constant", self.torque_constant)?;
        magnitude("limit", self.limit)?;
        Ok(())
    }

    /// Validates and builds the run-time tick around `compensation`.
    /// Besides [`validate`](Self::validate), rejects values the scalar
    /// cannot hold: `h` (only for a compensation that steps by it,
    /// [`Compensation::USES_H`]), and `32 limit`, the headroom that keeps
    /// the sum of the clamped terms finite. The constant gains (`1/h`,
    /// `kp`, `ki h`, `kd`, `J/kc`, `1/kc`) are carried as a mantissa and a
    /// power of two, so that fixed point holds each within 0.1 % from about
    /// `2.3e-7` to `2.7e8` (Q16.16 alone: 0.015 to 32767): a Q16.16 servo
    /// builds for 1 kHz to 40 kHz loops and inertias down to `1e-6`.
    ///
    /// ```
    /// use friction_core::{CompensatorParams, NoCompensation, ParamError};
    /// let mut p = CompensatorParams {
    ///     h: 1e-3, kp: 60.0, ki: 200.0, kd: 1.2,
    ///     inertia: 0.0023, torque_constant: 1.0, limit: 5.0,
    /// };
    /// p.kd = -1.0;
    /// assert_eq!(p.build::<f32, _>(NoCompensation).err(), Some(ParamError::Negative("kd")));
    /// ```
    pub fn build<S: Scalar, C: Compensation<S>>(
        &self,
        compensation: C,
    ) -> Result<Compensator<S, C>, ParamError> {
        self.validate()?;
        runs_at(&compensation, self.h)?;
        let limit = convert("limit", self.limit)?;
        convert::<S>("limit", 32.0 * self.limit)?;
        let h = if C::USES_H {
            convert("h", self.h)?
        } else {
            S::from_f64(self.h)
        };
        let zero = Gain::new("inertia", 0.0)?;
        // 1/kc first: a torque constant beyond the gains' range is named as
        // such, not as the inertia of the ratio J/kc it also spoils
        let inv_kc = Gain::new("torque_constant", 1.0 / self.torque_constant)?;
        Ok(Compensator {
            compensation,
            h,
            inv_h: Gain::new("h", 1.0 / self.h)?,
            kp: Gain::new("kp", self.kp)?,
            ki_h: Gain::new("ki", self.ki * self.h)?,
            kd: Gain::new("kd", self.kd)?,
            feed_forward: Gain::new("inertia", self.inertia / self.torque_constant)?,
            inv_kc,
            limit,
            term_limit: convert("limit", 4.0 * self.limit)?,
            signal_limit: S::VELOCITY_LIMIT,
            accel_ff: if C::LEARNS {
                Gain::new(
                    "inertia",
                    self.inertia / (self.torque_constant * self.h * self.h),
                )?
            } else {
                zero
            },
            kc: if C::LEARNS || C::LOADED {
                Gain::new("torque_constant", self.torque_constant)?
            } else {
                zero
            },
            velocity_blend: S::ONE,
            filter_velocity: Flag::new(false),
            observer_alpha: S::ZERO,
            observer_beta: zero,
            observer_gamma: zero,
            observer_h: zero,
            inv_inertia: zero,
            params: *self,
        })
    }
}

/// Checks that `compensation` runs at the period `h` (s), if it has one
/// ([`Compensation::period`]).
fn runs_at<S: Scalar, C: Compensation<S>>(compensation: &C, h: f64) -> Result<(), ParamError> {
    match compensation.period() {
        Some(period) if (period - h).abs() > 1e-9 * h => Err(ParamError::PeriodMismatch),
        _ => Ok(()),
    }
}
