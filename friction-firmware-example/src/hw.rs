//! The simulated hardware: a motor drive behind `embedded-hal`'s
//! `SetDutyCycle`, an absolute encoder, and the mechanics they are attached
//! to (an inertia with real friction, whose parameters differ from the
//! controller's model).

use core::cell::RefCell;
use core::convert::Infallible;
use embedded_hal::pwm::{ErrorType, SetDutyCycle};
use friction_core::{FrictionModel, LuGre};

/// Reads an encoder position in counts.
pub trait Encoder {
    /// The sensor's error type.
    type Error;
    /// The absolute position in counts.
    fn read_counts(&mut self) -> Result<i32, Self::Error>;
}

/// The mechanics: `J dv/dt = tau - F_friction`, integrated at `substeps`
/// per control tick with the core's step of the friction model `M` (LuGre
/// by default; semi-implicit Euler). A real transmission's friction is
/// `F (1 ± asymmetry) (1 + load |tau|)`: larger one way than the other
/// (`+` moving forward) and growing with the torque it carries.
pub struct Plant<M: FrictionModel<f32> = LuGre<f32>> {
    pub inertia: f32,
    pub friction: M,
    pub z: M::State,
    pub x: f32,
    pub v: f32,
    /// Motor torque (N m) commanded through the drive.
    pub torque: f32,
    /// Direction factor `|asymmetry| < 1` (0: symmetric).
    pub asymmetry: f32,
    /// Load coefficient `>= 0` (1/N m; 0: no load dependence).
    pub load: f32,
}

impl<M: FrictionModel<f32>> Plant<M> {
    /// Lets `h` seconds pass in `substeps` steps.
    pub fn advance(&mut self, h: f32, substeps: u32) {
        let hs = h / substeps as f32;
        for _ in 0..substeps {
            let side = if self.v >= 0.0 {
                1.0 + self.asymmetry
            } else {
                1.0 - self.asymmetry
            };
            let f = self.friction.step(&mut self.z, self.v, hs)
                * side
                * (1.0 + self.load * libm::fabsf(self.torque));
            self.v += hs * (self.torque - f) / self.inertia;
            self.x += hs * self.v;
        }
    }
}

/// A half-bridge PWM drive in centre-aligned convention: duty `max/2` is zero
/// torque, 0 and `max` are `-torque_max` and `+torque_max`.
pub struct SimDrive<'a, M: FrictionModel<f32> = LuGre<f32>> {
    pub plant: &'a RefCell<Plant<M>>,
    pub max_duty: u16,
    pub torque_max: f32,
}

impl<M: FrictionModel<f32>> ErrorType for SimDrive<'_, M> {
    type Error = Infallible;
}

impl<M: FrictionModel<f32>> SetDutyCycle for SimDrive<'_, M> {
    fn max_duty_cycle(&self) -> u16 {
        self.max_duty
    }
    fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Infallible> {
        let d = duty.min(self.max_duty) as f32 / self.max_duty as f32;
        self.plant.borrow_mut().torque = (2.0 * d - 1.0) * self.torque_max;
        Ok(())
    }
}

/// An absolute encoder: the plant's angle quantised to `counts_per_rad`.
pub struct SimEncoder<'a, M: FrictionModel<f32> = LuGre<f32>> {
    pub plant: &'a RefCell<Plant<M>>,
    pub counts_per_rad: f32,
}

impl<M: FrictionModel<f32>> Encoder for SimEncoder<'_, M> {
    type Error = Infallible;
    fn read_counts(&mut self) -> Result<i32, Infallible> {
        Ok(libm::floorf(self.plant.borrow().x * self.counts_per_rad) as i32)
    }
}
