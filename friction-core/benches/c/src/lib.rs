//! Host comparison of friction-core's `f64` LuGre step with a hand-written C
//! step (`lugre.c`, compiled by `build.rs` with the system C compiler at
//! `-O2`). Both are called out of line (`#[inline(never)]` on the Rust side;
//! the C object cannot be inlined into Rust), on the same parameters and
//! velocities. `benches/lugre_c.rs` times both with criterion in one run;
//! `src/bin/callgrind.rs` steps both for an instruction count under
//! callgrind (`run.sh`).

#![deny(unsafe_code)]

use friction_core::{
    FixedStepModel, FrictionModel, LuGre, LuGreFixedStep, LuGreFixedStepState, LuGreParams,
    LuGreState,
};

/// The C step's parameters, laid out as `struct lugre_c` in `lugre.h`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct CLuGre {
    fc: f64,
    fs_minus_fc: f64,
    inv_vs: f64,
    sigma0: f64,
    sigma1: f64,
    sigma2: f64,
    inv_vd_sq: f64,
    z_max: f64,
}

impl CLuGre {
    /// The C model of a parameter set with Stribeck exponent 2 (the only
    /// shape the C step implements); `None` for any other exponent.
    pub fn new(p: &LuGreParams) -> Option<Self> {
        if p.curve.exponent != 2.0 {
            return None;
        }
        Some(Self {
            fc: p.curve.fc,
            fs_minus_fc: p.curve.fs - p.curve.fc,
            inv_vs: 1.0 / p.curve.vs,
            sigma0: p.sigma0,
            sigma1: p.sigma1,
            sigma2: p.sigma2,
            inv_vd_sq: p.vd.map_or(0.0, |vd| 1.0 / (vd * vd)),
            z_max: p.curve.fs / p.sigma0,
        })
    }
}

#[allow(unsafe_code)]
mod ffi {
    use super::CLuGre;
    extern "C" {
        pub fn lugre_c_step(m: *const CLuGre, state: *mut f64, v: f64, h: f64) -> f64;
        pub fn lugre_c_ie_step(m: *const CLuGre, state: *mut f64, v: f64, h: f64) -> f64;
    }
}

/// One C step (finite `v`, `h >= 0`: the C step does not check its inputs).
#[inline(never)]
#[allow(unsafe_code)]
pub fn c_step(m: &CLuGre, z: &mut f64, v: f64, h: f64) -> f64 {
    // SAFETY: `m` and `z` are valid, aligned and exclusive for the call; the
    // C function reads `*m`, reads and writes `*z`, and keeps neither.
    unsafe { ffi::lugre_c_step(m, z, v, h) }
}

/// One step of the minimal C implicit-Euler LuGre (`lugre_c_ie_step`: one
/// `exp`, one division, first order in `h`), the figure issue 19 sizes the
/// host step against.
#[inline(never)]
#[allow(unsafe_code)]
pub fn c_ie_step(m: &CLuGre, z: &mut f64, v: f64, h: f64) -> f64 {
    // SAFETY: as in `c_step`.
    unsafe { ffi::lugre_c_ie_step(m, z, v, h) }
}

/// One step of friction-core's LuGre, out of line like the C step.
#[inline(never)]
pub fn rust_step(m: &LuGre<f64>, s: &mut LuGreState<f64>, v: f64, h: f64) -> f64 {
    m.step(s, v, h)
}

/// One step of friction-core's fixed-step LuGre (`build_fixed_step(H)`), out of line.
#[inline(never)]
pub fn rust_fixed_step(m: &LuGreFixedStep<f64>, s: &mut LuGreFixedStepState<f64>, v: f64) -> f64 {
    m.step(s, v)
}

/// The velocities of the core's step benchmark: a 10 mm/s sine through
/// zero, 1024 samples.
pub fn velocities() -> Vec<f64> {
    (0..1024)
        .map(|k| 0.01 * (k as f64 * 0.0123).sin())
        .collect()
}

/// The parameters of the comparison: canudas1995, as in the core's benchmark.
pub const PARAMS: LuGreParams = LuGreParams::CANUDAS_1995;

/// Step length (1 kHz).
pub const H: f64 = 1e-3;
