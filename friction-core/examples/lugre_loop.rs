//! A LuGre step loop at 1 kHz: the friction force as a velocity sweeps
//! through zero (break-away, Stribeck dip, viscous rise), in `f32` as on an
//! FPU-equipped Cortex-M.
//!
//! Run with `cargo run -p friction-core --example lugre_loop`.

use friction_core::{FixedStepModel, LuGreFixedStepState, LuGreParams, ParamError};

fn main() -> Result<(), ParamError> {
    let h = 1e-3; // the control period (s)
                  // Canudas de Wit et al. 1995, Table I; rejected when built if invalid.
    let model = LuGreParams::CANUDAS_1995.build_fixed_step::<f32>(h)?;
    let mut state = LuGreFixedStepState::default();
    println!("   t (s)    v (m/s)      F (N)");
    for k in 0..=4000 {
        let t = k as f64 * h;
        // a slow sine of 20 mm/s amplitude, 0.5 Hz
        let v = 0.02 * (std::f64::consts::PI * t).sin();
        let f = model.step(&mut state, v as f32);
        if k % 250 == 0 {
            println!("{t:8.3} {v:10.5} {f:10.4}");
        }
    }
    Ok(())
}
