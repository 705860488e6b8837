//! The inputs the cost table's rows share with the profile (`src/bin/cost.rs`,
//! `src/bin/profile.rs`): the sweep and stress velocities and the GMS / Xiong
//! elements.

use crate::setup::NOMINAL;
use friction_core::{GmsElement, GmsParams};

/// Magnitudes (rad/s) of the stress sequence; 1e7 is clamped to 1e6.
const STRESS: [f64; 14] = [
    1e-4, 1e-3, 3e-3, 0.01, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0, 50.0, 1e3, 1e6, 1e7,
];
/// Signs of the stress sequence at each magnitude: reversing every step,
/// then held.
const PATTERN: [f64; 6] = [1.0, -1.0, 1.0, 1.0, -1.0, -1.0];

/// The sweep: `0.01 sin(0.1963 k)` rad/s, two periods in 64 steps, repeated.
pub fn sweep_velocity(k: usize) -> f64 {
    0.01 * libm::sin((k % 64) as f64 * 0.1963)
}

/// Step `k` of the stress sequence.
pub fn stress_velocity(k: usize) -> f64 {
    let m = STRESS.get(k / PATTERN.len()).copied().unwrap_or(0.0);
    let s = PATTERN.get(k % PATTERN.len()).copied().unwrap_or(1.0);
    m * s
}

pub const STRESS_LEN: usize = STRESS.len() * PATTERN.len();

/// GMS and Xiong elements for `N`: stiffnesses spread geometrically over a
/// factor 8 and summing to sigma0 = 260 N m/rad, weights falling linearly
/// with stiffness, damping (Xiong: viscosity) sharing sigma1 = 0.6 in
/// proportion to stiffness.
pub fn element(i: usize, n: usize) -> (f64, f64, f64) {
    let spread = |j: usize| {
        if n > 1 {
            libm::pow(8.0, j as f64 / (n - 1) as f64)
        } else {
            1.0
        }
    };
    let total: f64 = (0..n).map(spread).sum();
    let k = NOMINAL.sigma0 * spread(i) / total;
    let weight = (n - i) as f64 / (n * (n + 1) / 2) as f64;
    (k, weight, NOMINAL.sigma1 * k / NOMINAL.sigma0)
}

pub fn gms_params<const N: usize>() -> GmsParams<N> {
    let mut elements = [GmsElement::default(); N];
    for (i, e) in elements.iter_mut().enumerate() {
        let (k, alpha, sigma1) = element(i, N);
        *e = GmsElement { k, alpha, sigma1 };
    }
    GmsParams {
        curve: NOMINAL.curve,
        sigma2: NOMINAL.sigma2,
        c: 20.0,
        elements,
    }
}
