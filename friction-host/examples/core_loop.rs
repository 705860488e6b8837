//! The core's own loop, the reference of the Python package's speed
//! benchmark (`friction-py/bench/simulate_speed.py`): the canudas1995
//! LuGre model in `f64` stepped over `N` samples of a velocity array
//! (default 1e6, the benchmark's signal), written into a force array; prints the median of 7 runs
//! in ns per sample.
//!
//! `cargo run --release -p friction-host --example core_loop [N]`

use friction_core::{FrictionModel, LuGreParams, LuGreState};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let n: usize = std::env::args()
        .nth(1)
        .map_or(Ok(1_000_000), |a| a.parse())?;
    // the Python benchmark's signal: t = k 1e-4 s, a 5 Hz sine of 2 mm/s,
    // stepped by the differences of t as `simulate` steps
    let t: Vec<f64> = (0..n).map(|k| k as f64 * 1e-4).collect();
    let v: Vec<f64> = t
        .iter()
        .map(|&t| 2e-3 * (2.0 * std::f64::consts::PI * 5.0 * t).sin())
        .collect();
    let model = LuGreParams::CANUDAS_1995.build::<f64>()?;
    let mut runs = Vec::new();
    let mut checksum = 0.0;
    for _ in 0..7 {
        let start = Instant::now();
        let mut state = LuGreState::default();
        let mut f = Vec::with_capacity(n);
        let mut prev = t[0];
        for (&tk, &vk) in t.iter().zip(&v) {
            f.push(model.step(&mut state, vk, tk - prev));
            prev = tk;
        }
        runs.push(start.elapsed().as_secs_f64() * 1e9 / n as f64);
        checksum += std::hint::black_box(f).iter().sum::<f64>();
    }
    runs.sort_by(f64::total_cmp);
    println!(
        "core loop: {:.2} ns/sample (median of 7, {n} samples; checksum {checksum:.6e})",
        runs[3]
    );
    Ok(())
}
