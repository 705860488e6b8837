//! The embedded-hal glue of the servo: encoder read -> the core's
//! compensator tick (PID + acceleration feed-forward + friction
//! compensation) -> `SetDutyCycle`. The control law lives in
//! `friction_core::compensator`.

use crate::hw::Encoder;
use embedded_hal::pwm::SetDutyCycle;
use friction_core::{Compensation, Compensator, CompensatorState, Setpoint};

/// Errors from either device.
#[derive(Debug, defmt::Format)]
pub enum ServoError<D, S> {
    /// The drive failed.
    Drive(D),
    /// The sensor failed.
    Sensor(S),
}

/// One servo axis: the devices, the core's compensator and its state.
pub struct Servo<D, E, C: Compensation<f32>> {
    drive: D,
    encoder: E,
    counts_per_rad: f32,
    torque_max: f32,
    compensator: Compensator<f32, C>,
    state: CompensatorState<f32, C::State>,
}

/// The duty for a torque `command` on a centre-aligned drive (`max / 2` is
/// zero torque, 0 and `max` are `-torque_max` and `+torque_max`). A
/// non-finite command, or a non-finite or non-positive `torque_max`, gives
/// zero torque (`max / 2`), never duty 0, which would be full negative torque.
pub fn duty(command: f32, torque_max: f32, max: u16) -> u16 {
    if !(command.is_finite() && torque_max.is_finite() && torque_max > 0.0) {
        return max / 2;
    }
    let d = (0.5 + 0.5 * command / torque_max).clamp(0.0, 1.0);
    (d * max as f32 + 0.5) as u16
}

impl<D: SetDutyCycle, E: Encoder, C: Compensation<f32>> Servo<D, E, C> {
    /// An axis at rest; the compensator's command is a torque (N m) mapped
    /// onto the drive's `±torque_max`.
    pub fn new(
        drive: D,
        encoder: E,
        counts_per_rad: f32,
        torque_max: f32,
        compensator: Compensator<f32, C>,
    ) -> Self {
        Self {
            drive,
            encoder,
            counts_per_rad,
            torque_max,
            compensator,
            state: CompensatorState::default(),
        }
    }

    /// One control tick towards `r`; returns the measured position (rad).
    pub fn tick(&mut self, r: Setpoint<f32>) -> Result<f32, ServoError<D::Error, E::Error>> {
        let counts = self.encoder.read_counts().map_err(ServoError::Sensor)?;
        let x = counts as f32 / self.counts_per_rad;
        let tick = self.compensator.tick(&mut self.state, x, r);
        let max = self.drive.max_duty_cycle();
        self.drive
            .set_duty_cycle(duty(tick.command, self.torque_max, max))
            .map_err(ServoError::Drive)?;
        Ok(x)
    }
}
