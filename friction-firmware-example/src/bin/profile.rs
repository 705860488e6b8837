//! Where a step's instructions go: runs a few fixed-point steps of the cost
//! table's rows (the same parameters and velocities) between two marker
//! calls, for `profile.sh`, which runs it under QEMU one instruction per
//! translation block and counts the executed instructions by function and
//! source line between the markers.
//!
//! Cases, in order (each between `mark_begin` and `mark_end`):
//!
//! 0. LuGre (Q16.16, fixed step): the 64 steps of one sweep period;
//! 1. elasto-plastic (Q16.16, `k = 1`): its worst step of the stress sequence;
//! 2. elasto-plastic (Q16.16, `k = 0`): its worst step of the stress sequence;
//! 3. GMS(4) (Q16.16, fixed step): the 64 steps of one sweep period.

#![no_std]
#![no_main]
#![deny(unsafe_code)]

use core::hint::black_box;
use cortex_m_rt::entry;
use cortex_m_semihosting::debug::{self, EXIT_FAILURE, EXIT_SUCCESS};
use cortex_m_semihosting::hprintln;
use friction_core::{ElastoPlasticParams, Fixed32, FixedStepModel, Scalar};

#[path = "../setup.rs"]
#[allow(dead_code)]
mod setup;
use setup::{H, NOMINAL};
// the cost table's sweep, stress sequence and GMS elements
#[path = "../inputs.rs"]
#[allow(dead_code)]
mod inputs;
use inputs::{gms_params, stress_velocity, sweep_velocity};

#[inline(never)]
fn mark_begin() {
    black_box(0);
}

#[inline(never)]
fn mark_end() {
    black_box(1);
}

fn sweep(k: usize) -> Fixed32 {
    Fixed32::from_f64(sweep_velocity(k))
}

fn stress(k: usize) -> Fixed32 {
    Fixed32::from_f64(stress_velocity(k))
}

/// Steps `model` through the stress sequence up to `at`, then profiles step `at`.
fn worst<M: FixedStepModel<Fixed32>>(model: &M, at: usize) {
    let mut s = M::State::default();
    for k in 0..at {
        model.step(&mut s, stress(k));
    }
    let v = stress(at);
    mark_begin();
    black_box(model.step(black_box(&mut s), black_box(v)));
    mark_end();
}

/// Profiles one sweep period of `model`, after one period from rest.
fn period<M: FixedStepModel<Fixed32>>(model: &M) {
    let mut s = M::State::default();
    for k in 0..64 {
        model.step(&mut s, sweep(k));
    }
    let vs: [Fixed32; 64] = core::array::from_fn(|k| sweep(64 + k));
    mark_begin();
    for v in vs {
        black_box(model.step(black_box(&mut s), black_box(v)));
    }
    mark_end();
}

#[entry]
fn main() -> ! {
    let h = f64::from(H);
    let lugre = NOMINAL
        .build_fixed_step::<Fixed32>(h)
        .unwrap_or_else(|_| fail("LuGre parameters"));
    period(&lugre);
    for (k, at) in [(1, 56), (0, 48)] {
        let ep = ElastoPlasticParams {
            lugre: NOMINAL,
            z_ba: 0.5 * NOMINAL.curve.fc / NOMINAL.sigma0,
        }
        .build_fixed_step::<Fixed32>(h)
        .unwrap_or_else(|_| fail("elasto-plastic parameters"))
        .with_max_substeps(k);
        worst(&ep, at);
    }
    let gms = gms_params::<4>()
        .build_fixed_step::<Fixed32>(h)
        .unwrap_or_else(|_| fail("GMS parameters"));
    period(&gms);
    debug::exit(EXIT_SUCCESS);
    halt()
}

/// Waits for the debugger's exit to take effect.
fn halt() -> ! {
    loop {
        cortex_m::asm::nop();
    }
}

fn fail(what: &str) -> ! {
    hprintln!("profile: failed: {}", what);
    debug::exit(EXIT_FAILURE);
    halt()
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    fail("panic")
}
