//! A compensated servo tick at 1 kHz, as firmware runs it: PD control,
//! acceleration feed-forward and a LuGre friction observer
//! ([`LuGreServo`]), against a simulated plant (a mass with LuGre
//! friction, Olsson et al. 1998's servo). Prints the tracking error with
//! and without the friction compensation.
//!
//! Run with `cargo run -p friction-core --example observer_servo`.

use friction_core::{
    Compensator, CompensatorParams, CompensatorState, FixedPeriod, FrictionModel, LuGreParams,
    LuGreServo, LuGreState, NoCompensation, Observer, ParamError, Setpoint,
};

const H: f64 = 1e-3;
const INERTIA: f64 = 0.0023; // kg m^2

fn gains() -> CompensatorParams {
    CompensatorParams {
        h: H,
        kp: 9.08,
        ki: 0.0,
        kd: 0.289,
        inertia: INERTIA,
        torque_constant: 1.0,
        limit: 5.0,
    }
}

/// RMS tracking error (rad) of a 0.5 Hz sine of 0.1 rad over `seconds`,
/// with `tick` computing the command from the measured position.
fn track(seconds: f64, mut tick: impl FnMut(f32, Setpoint<f32>) -> f32) -> Result<f64, ParamError> {
    let plant = LuGreParams::OLSSON_1998.build::<f64>()?;
    let mut friction = LuGreState::default();
    let (mut x, mut v, mut sum) = (0.0f64, 0.0f64, 0.0);
    let n = (seconds / H) as usize;
    let w = std::f64::consts::PI;
    for k in 0..n {
        let t = k as f64 * H;
        let r = Setpoint {
            x: (0.1 * (w * t).sin()) as f32,
            v: (0.1 * w * (w * t).cos()) as f32,
            a: (-0.1 * w * w * (w * t).sin()) as f32,
        };
        let u = f64::from(tick(x as f32, r));
        // the plant: 10 sub-steps of the mass with LuGre friction per tick
        for _ in 0..10 {
            let f = plant.step(&mut friction, v, H / 10.0);
            v += (u - f) / INERTIA * H / 10.0;
            x += v * H / 10.0;
        }
        sum += (x - f64::from(r.x)).powi(2);
    }
    Ok((sum / n as f64).sqrt())
}

fn main() -> Result<(), ParamError> {
    let model = LuGreParams::OLSSON_1998.build_fixed_step::<f32>(H)?;
    let servo: LuGreServo<f32> = gains().build(FixedPeriod(Observer::new(model, 200.0)?))?;
    let mut state = CompensatorState::default();
    let with = track(4.0, |x, r| servo.tick(&mut state, x, r).command)?;

    let plain: Compensator<f32, NoCompensation> = gains().build(NoCompensation)?;
    let mut state = CompensatorState::default();
    let without = track(4.0, |x, r| plain.tick(&mut state, x, r).command)?;

    println!(
        "tracking error, RMS: {:.3} mrad without compensation, {:.4} mrad with the LuGre observer",
        without * 1e3,
        with * 1e3
    );
    Ok(())
}
