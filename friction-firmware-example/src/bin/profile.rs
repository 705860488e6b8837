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
//! 3. GMS(4) (Q16.16, fixed step): the 64 steps of one sweep period;
//! 4. servo-parameter-adaptive (Q16.16): the worst tick of the stress
//!    sequence (`STRESS_WORST`), from rest as the cost table replays it;
//! 5. to 7. servo-parameter-adaptive (Q16.16): sweep ticks `SWEEP_TICKS`
//!    from rest: 600, the row's worst (a supervisor window's close), 598,
//!    an adapting tick, and 599, one that does not adapt (the average is a
//!    mix of about 55 % of the second and 45 % of the third).
//!
//! Before cases 4 and 5, every stress and sweep tick of the servo row runs
//! alone between `probe_begin` and `probe_end` (per-tick counts, outside
//! the cases).

#![no_std]
#![no_main]
#![deny(unsafe_code)]

use core::hint::black_box;
use cortex_m_rt::entry;
use cortex_m_semihosting::debug::{self, EXIT_FAILURE, EXIT_SUCCESS};
use cortex_m_semihosting::hprintln;
use friction_core::{
    CompensatorState, ElastoPlasticParams, Fixed32, FixedStepModel,
    ParameterAdaptiveFixedStepState, ParameterAdaptiveServo, Scalar, Setpoint, SupervisedState,
};

#[path = "../setup.rs"]
#[allow(dead_code)]
mod setup;
use setup::{controller, fallback, parameter_adaptation, supervisor, H, NOMINAL};
// the cost table's sweep, stress sequence and GMS elements
#[path = "../inputs.rs"]
#[allow(dead_code)]
mod inputs;
use inputs::{gms_params, stress_velocity, sweep_velocity, STRESS_LEN};

#[inline(never)]
fn mark_begin() {
    black_box(0);
}

#[inline(never)]
fn mark_end() {
    black_box(1);
}

#[inline(never)]
fn probe_begin() {
    black_box(2);
}

#[inline(never)]
fn probe_end() {
    black_box(3);
}

/// The cost table's worst tick of servo-parameter-adaptive in Q16.16 on the
/// M0 (stress) and a sweep tick near its average.
const STRESS_WORST: usize = 82;
const SWEEP_TICKS: [usize; 3] = [600, 598, 599];
const SWEEP_STEPS: usize = 1024;

type Servo = ParameterAdaptiveServo<Fixed32>;
type ServoState =
    CompensatorState<Fixed32, SupervisedState<ParameterAdaptiveFixedStepState<Fixed32>, Fixed32>>;
type Input = (Fixed32, Setpoint<Fixed32>);

/// The cost table's step function of the row.
#[inline(never)]
fn servo_tick(m: &Servo, s: &mut ServoState, input: Input) -> Fixed32 {
    m.tick(s, input.0, input.1).command
}

fn q(x: f32) -> Fixed32 {
    Fixed32::from_f64(f64::from(x))
}

fn servo_sweep(k: usize) -> Input {
    let x = 1e-3 * libm::sinf((k % 64) as f32 * 0.1963);
    let v = sweep_velocity(k) as f32;
    (
        q(x),
        Setpoint {
            x: q(x + 1e-5),
            v: q(v),
            a: q(0.0),
        },
    )
}

fn servo_stress(k: usize) -> Input {
    let v = stress_velocity(k) as f32;
    (
        q(1e-3 * v),
        Setpoint {
            x: q(0.0),
            v: q(v),
            a: q(0.0),
        },
    )
}

fn parameter_servo() -> Servo {
    let p = controller();
    let law = parameter_adaptation()
        .build_fixed_step::<Fixed32>(&p)
        .unwrap_or_else(|_| fail("per-parameter law"));
    let map = fallback()
        .build::<Fixed32>()
        .unwrap_or_else(|_| fail("fallback"));
    let supervised = supervisor()
        .build(law, map, &p)
        .unwrap_or_else(|_| fail("supervisor"));
    p.build(supervised).unwrap_or_else(|_| fail("servo gains"))
}

/// Every tick of `n` from rest, each replayed alone from a copy of its
/// starting state between the probes; then profiles tick `at`.
fn servo_case(m: &Servo, input: impl Fn(usize) -> Input, n: usize, at: &[usize]) {
    let mut saved = [ServoState::default(); 4];
    let mut inputs = [input(0); 4];
    let mut s = ServoState::default();
    for k in 0..n {
        let v = input(k);
        let mut c = black_box(s);
        probe_begin();
        black_box(servo_tick(black_box(m), &mut c, black_box(v)));
        probe_end();
        black_box(&c);
        for ((&t, slot), i) in at.iter().zip(saved.iter_mut()).zip(inputs.iter_mut()) {
            if t == k {
                (*slot, *i) = (s, v);
            }
        }
        servo_tick(m, &mut s, v);
    }
    // in the order given
    for (s, v) in saved.iter().zip(inputs).take(at.len()) {
        let mut c = black_box(*s);
        mark_begin();
        black_box(servo_tick(black_box(m), &mut c, black_box(v)));
        mark_end();
        black_box(&c);
    }
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
    let servo = parameter_servo();
    servo_case(&servo, servo_stress, STRESS_LEN, &[STRESS_WORST]);
    servo_case(&servo, servo_sweep, SWEEP_STEPS, &SWEEP_TICKS);
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
