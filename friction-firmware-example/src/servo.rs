//! A position servo written against hardware traits: PD with acceleration
//! feed-forward, plus optional friction compensation.

use crate::hw::Encoder;
use embedded_hal::pwm::SetDutyCycle;
use friction_core::{CoulombViscous, LuGre, LuGreState, Observer};

/// How the servo compensates friction.
#[derive(Clone, Copy, defmt::Format)]
pub enum Compensation {
    /// None: the PD loop alone.
    None,
    /// Static feed-forward `Fc sign(v_ref) + sigma2 v_ref`.
    Coulomb(CoulombViscous<f32>),
    /// The LuGre observer on the measured velocity and position error.
    Observer(Observer<LuGre<f32>, f32>),
}

/// Errors from either device.
#[derive(Debug, defmt::Format)]
pub enum ServoError<D, S> {
    /// The drive failed.
    Drive(D),
    /// The sensor failed.
    Sensor(S),
}

/// The servo loop state.
pub struct Servo<D, E> {
    pub drive: D,
    pub encoder: E,
    pub counts_per_rad: f32,
    pub torque_max: f32,
    pub inertia: f32,
    pub kp: f32,
    pub kd: f32,
    pub h: f32,
    pub compensation: Compensation,
    z_hat: LuGreState<f32>,
    prev_x: Option<f32>,
}

impl<D: SetDutyCycle, E: Encoder> Servo<D, E> {
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        drive: D,
        encoder: E,
        counts_per_rad: f32,
        torque_max: f32,
        inertia: f32,
        (kp, kd): (f32, f32),
        h: f32,
        compensation: Compensation,
    ) -> Self {
        Self {
            drive,
            encoder,
            counts_per_rad,
            torque_max,
            inertia,
            kp,
            kd,
            h,
            compensation,
            z_hat: LuGreState::default(),
            prev_x: None,
        }
    }

    /// One control tick towards `(x_ref, v_ref, a_ref)`; returns the measured position.
    pub fn tick(
        &mut self,
        x_ref: f32,
        v_ref: f32,
        a_ref: f32,
    ) -> Result<f32, ServoError<D::Error, E::Error>> {
        let x =
            self.encoder.read_counts().map_err(ServoError::Sensor)? as f32 / self.counts_per_rad;
        let v = (x - self.prev_x.unwrap_or(x)) / self.h; // encoder difference: a sample late, quantised
        self.prev_x = Some(x);
        let e = x - x_ref; // measured minus desired: the observer's sign convention
        let mut torque = -self.kp * e - self.kd * (v - v_ref) + self.inertia * a_ref;
        torque += match &self.compensation {
            Compensation::None => 0.0,
            Compensation::Coulomb(map) => map.force(v_ref),
            Compensation::Observer(obs) => obs.step(&mut self.z_hat, v, e, self.h),
        };
        let max = self.drive.max_duty_cycle();
        let d = (0.5 + 0.5 * torque / self.torque_max).clamp(0.0, 1.0);
        self.drive
            .set_duty_cycle((d * max as f32 + 0.5) as u16)
            .map_err(ServoError::Drive)?;
        Ok(x)
    }
}
