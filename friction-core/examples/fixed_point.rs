//! LuGre in Q16.16 fixed point (`Fixed32`, feature `fixed`) for cores
//! without an FPU, against the same model in `f64`: the fixed-step form
//! carries its forces times a power of two chosen when built, so the
//! friction force uses Q16.16's range.
//!
//! Run with `cargo run -p friction-core --features fixed --example fixed_point`.

use friction_core::{
    Fixed32, FixedStepModel, LuGreFixedStepState, LuGreParams, ParamError, Scalar,
};

fn main() -> Result<(), ParamError> {
    let h = 1e-3;
    let fixed = LuGreParams::CANUDAS_1995.build_fixed_step::<Fixed32>(h)?;
    let float = LuGreParams::CANUDAS_1995.build_fixed_step::<f64>(h)?;
    let (mut sf, mut sd) = (
        LuGreFixedStepState::default(),
        LuGreFixedStepState::default(),
    );
    let (mut worst, mut sum, n) = (0.0f64, 0.0, 4000);
    for k in 0..n {
        let v = 0.02 * (std::f64::consts::PI * k as f64 * h).sin();
        let vq = Fixed32::from_f64(v); // the velocity as the fixed-point loop sees it
        let ff = fixed.step(&mut sf, vq).to_f64();
        let fd = float.step(&mut sd, vq.to_f64());
        worst = worst.max((ff - fd).abs());
        sum += (ff - fd).powi(2);
    }
    let fs = LuGreParams::CANUDAS_1995.curve.fs;
    println!(
        "Q16.16 against f64 over {n} steps: RMS {:.2e} N ({:.4} % of Fs), worst {:.2e} N",
        (sum / f64::from(n)).sqrt(),
        100.0 * (sum / f64::from(n)).sqrt() / fs,
        worst
    );
    Ok(())
}
