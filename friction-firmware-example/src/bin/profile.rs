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
use friction_core::{ElastoPlasticParams, Fixed32, FixedStepModel, GmsElement, GmsParams, Scalar};

#[path = "../setup.rs"]
#[allow(dead_code)]
mod setup;
use setup::{H, NOMINAL};

#[inline(never)]
fn mark_begin() {
    black_box(0);
}

#[inline(never)]
fn mark_end() {
    black_box(1);
}

fn sweep(k: usize) -> Fixed32 {
    Fixed32::from_f64(0.01 * libm::sin((k % 64) as f64 * 0.1963))
}

const STRESS: [f64; 14] = [
    1e-4, 1e-3, 3e-3, 0.01, 0.03, 0.1, 0.3, 1.0, 3.0, 10.0, 50.0, 1e3, 1e6, 1e7,
];
const PATTERN: [f64; 6] = [1.0, -1.0, 1.0, 1.0, -1.0, -1.0];

fn stress(k: usize) -> Fixed32 {
    Fixed32::from_f64(STRESS[k / PATTERN.len()] * PATTERN[k % PATTERN.len()])
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
        .build_at::<Fixed32>(h)
        .unwrap_or_else(|_| fail("LuGre parameters"));
    period(&lugre);
    for (k, at) in [(1, 56), (0, 48)] {
        let ep = ElastoPlasticParams {
            lugre: NOMINAL,
            z_ba: 0.5 * NOMINAL.curve.fc / NOMINAL.sigma0,
        }
        .build_at::<Fixed32>(h)
        .unwrap_or_else(|_| fail("elasto-plastic parameters"))
        .with_max_substeps(k);
        worst(&ep, at);
    }
    let mut elements = [GmsElement::default(); 4];
    let total: f64 = (0..4).map(|j| libm::pow(8.0, j as f64 / 3.0)).sum();
    for (i, e) in elements.iter_mut().enumerate() {
        let k = NOMINAL.sigma0 * libm::pow(8.0, i as f64 / 3.0) / total;
        *e = GmsElement {
            k,
            alpha: (4 - i) as f64 / 10.0,
            sigma1: NOMINAL.sigma1 * k / NOMINAL.sigma0,
        };
    }
    let gms = GmsParams {
        curve: NOMINAL.curve,
        sigma2: NOMINAL.sigma2,
        c: 20.0,
        elements,
    }
    .build_at::<Fixed32>(h)
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
