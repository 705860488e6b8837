//! The Cortex-M cost table: instructions per step of every model of the
//! core, under QEMU with `-icount shift=0` (one instruction per virtual
//! nanosecond, so SysTick advances with executed instructions).
//!
//! Built for `thumbv7em-none-eabihf` (f32 in the FPU, run on `mps2-an386`, a
//! Cortex-M4F) and `thumbv6m-none-eabi` (Thumb-1 code with soft-float f32,
//! run on `mps2-an385`, a Cortex-M3 that executes Thumb-1 code unchanged).
//! `cost.sh` builds and runs both and checks the budgets.
//!
//! For each row it prints, through semihosting:
//!
//! ```text
//! cost MODEL SCALAR CORE AVG            average over the sweep, rounded
//! cost-worst MODEL SCALAR CORE WORST    the most expensive single step found
//! cost-detail MODEL SCALAR CORE FORM avg=.. worst=.. ratio=.. worst-at=..
//!     straight-avg=.. model-bytes=.. state-bytes=.. stack-bytes=.. fn=step_..
//! ```
//!
//! - every step is replayed 64 times from its own starting state and
//!   counted alone;
//! - the average is over 1024 steps of a sine sweep through zero velocity
//!   (0.01 rad/s, 32 steps a period at 1 kHz), from the state at rest
//!   (`straight-avg` is the same sweep run straight through, a cross-check);
//! - the worst case is the largest single step of that sweep and of a
//!   stress sequence (velocities from 1e-4 rad/s to beyond the 1e6 clamp,
//!   reversing every step and held, from rest);
//! - the call overhead (loop, state copy, call and return of the same
//!   non-inlined wrapper around an empty body) is measured and subtracted;
//!   inputs and results pass through `black_box`;
//! - SysTick is 24 bits: one measurement must stay under 2^24 ticks (671 M
//!   instructions, 10 M per replayed step); the dearest today, bristle on
//!   the M0, is 0.8 M a step.
//!
//! Each row's step is one `#[inline(never)]` function named `step_<row>`, so
//! `cost.sh` can size its code (and what it calls) in the ELF. Adding a row
//! is one `step_fn!` line and one `row!` line.

#![no_std]
#![no_main]
#![deny(unsafe_code)]

use core::hint::black_box;
use core::sync::atomic::{AtomicU32, Ordering};
use cortex_m::peripheral::{syst::SystClkSource, SYST};
use cortex_m_rt::{entry, exception};
use cortex_m_semihosting::debug::{self, EXIT_FAILURE, EXIT_SUCCESS};
use cortex_m_semihosting::hprintln;
use friction_core::{AdaptiveObserver, AdaptiveState, Leuven, LeuvenState};
use friction_core::{
    Bristle, BristleParams, BristleState, Compensator, CompensatorState, CoulombViscous,
    CoulombViscousParams, Dahl, DahlParams, DahlState, ElastoPlastic, ElastoPlasticParams,
    FrictionModel, Gms, GmsState, LuGre, LuGreState, Observer, ResetIntegrator,
    ResetIntegratorParams, ResetIntegratorState, Scalar, Setpoint, StribeckMap, StribeckMapParams,
    Xiong, XiongElement, XiongParams, XiongState,
};
use friction_core::{
    Commissioning, CommissioningParams, CommissioningPhase, CommissioningState, CommissioningTick,
};
use friction_core::{
    DahlFixedStep, DahlFixedStepState, ElastoPlasticFixedStep, ElastoPlasticFixedStepState,
    ElastoPlasticState, Fixed32, FixedPeriod, FixedStepModel, GmsFixedStep, GmsFixedStepState,
    LuGreFixedStep, LuGreFixedStepState, XiongFixedStep, XiongFixedStepState,
};
use friction_core::{
    ParameterAdaptiveFixedStep, ParameterAdaptiveFixedStepState, ParameterAdaptiveServo,
    Supervised, SupervisedState,
};

// the servo's model, loop period (the variable-step rows pass `H` through
// `black_box`), observer gain and gains, shared with `main.rs`
#[path = "../setup.rs"]
mod setup;
use setup::{
    adaptation, commissioning, controller, fallback, leuven_nominal, parameter_adaptation,
    supervisor, ACTUAL, ENCODER_COUNTS, H, INERTIA, NOMINAL, OBSERVER_GAIN, TORQUE_MAX,
};
// the sweep, the stress sequence and the GMS / Xiong elements, shared with
// the profile (`profile.rs`)
#[path = "../inputs.rs"]
mod inputs;
use inputs::{element, gms_params, stress_velocity, sweep_velocity, STRESS_LEN};

/// The position error the observer rows see.
const OBSERVER_ERROR: f32 = 1e-5;

/// Steps of the average.
const SWEEP_STEPS: usize = 1024;
/// Repetitions of a replayed step (one SysTick tick is 40 instructions, so
/// the worst case is resolved to better than one instruction).
const REPS: u32 = 64;

/// The core label from the target the binary was built for.
const CORE: &str = match env!("COST_TARGET").as_bytes() {
    b"thumbv7em-none-eabihf" => "cortex-m4f",
    b"thumbv6m-none-eabi" => "cortex-m0",
    _ => "unknown-core",
};

/// SysTick ticks spent by `f`, `n` times (counting down, 24 bits).
fn ticks(n: u32, mut f: impl FnMut()) -> u32 {
    let start = SYST::get_current();
    for _ in 0..n {
        f();
    }
    start.wrapping_sub(SYST::get_current()) & 0x00FF_FFFF
}

/// Instructions per SysTick tick, from 16 x 16384 NOPs against the same
/// empty loop (40 under `-icount shift=0`: SysTick runs at the 25 MHz
/// system clock and each instruction takes 1 ns of virtual time).
fn calibrate() -> Option<f32> {
    const N: u32 = 16_384;
    let empty = ticks(N, || {
        for _ in 0..16 {
            black_box(());
        }
    });
    let nops = ticks(N, || {
        for _ in 0..16 {
            cortex_m::asm::nop();
        }
    });
    let t = nops.checked_sub(empty).filter(|&t| t > 0)?;
    let per_tick = (16 * N) as f32 / t as f32;
    // the calibration itself is quantised to a tick: snap to the integer
    let rounded = (per_tick + 0.5) as u32 as f32;
    Some(if (per_tick - rounded).abs() < 0.01 * rounded {
        rounded
    } else {
        per_tick
    })
}

/// The form of a step: `step(&mut state, v, h)` (variable) or, once the
/// core has it, `build_fixed_step(h)` then `step(&mut state, v)` (fixed).
#[derive(Clone, Copy)]
enum Form {
    Variable,
    Fixed,
}

impl Form {
    fn name(self) -> &'static str {
        match self {
            Form::Variable => "variable",
            Form::Fixed => "fixed",
        }
    }

    /// Appended to the row's name in the `cost` and `cost-worst` lines:
    /// nothing, since a model with both forms names its variable-step row
    /// `<model>-var` (the plain name is the fixed-step form, the one the
    /// issue's budgets are for).
    fn suffix(self) -> &'static str {
        ""
    }
}

/// An empty step with the same signature: the measurement overhead.
#[inline(never)]
fn step_none<M, St, I>(_: &M, state: &mut St, input: I) -> I {
    black_box(state);
    input
}

/// Instructions per call of `step` over `reps` calls from a copy of `start`
/// with input `input`, less the same with the empty step.
fn replay<M, St: Copy, I: Copy, O>(
    per_tick: f32,
    model: &M,
    step: impl Fn(&M, &mut St, I) -> O,
    start: St,
    input: I,
) -> f32 {
    let t = ticks(REPS, || {
        let mut s = black_box(start);
        black_box(step(black_box(model), &mut s, black_box(input)));
        black_box(&s);
    });
    let base = ticks(REPS, || {
        let mut s = black_box(start);
        black_box(step_none(black_box(model), &mut s, black_box(input)));
        black_box(&s);
    });
    (t as f32 - base as f32) * per_tick / REPS as f32
}

/// Bytes of stack below the caller's that `step` uses over `n` inputs from
/// `start`, less the same for the empty step: the stack is painted below
/// the stack pointer, the steps run, and the lowest overwritten word marks
/// the depth. No interrupt is enabled, so only these calls touch it.
fn stack_use<M, St: Copy, I: Copy, O>(
    model: &M,
    step: impl Fn(&M, &mut St, I) -> O + Copy,
    start: St,
    input: impl Fn(usize) -> I + Copy,
    n: usize,
) -> u32 {
    let used = stack_depth(model, step, start, input, n);
    let empty = stack_depth(model, step_none, start, input, n);
    used.saturating_sub(empty)
}

#[inline(never)]
#[allow(unsafe_code)]
fn stack_depth<M, St: Copy, I: Copy, O>(
    model: &M,
    step: impl Fn(&M, &mut St, I) -> O,
    start: St,
    input: impl Fn(usize) -> I,
    n: usize,
) -> u32 {
    const SPAN: u32 = 16 * 1024;
    const PAINT: u32 = 0xC057_C057;
    let sp = cortex_m::register::msp::read() & !3;
    let low = sp - SPAN;
    let mut a = low;
    while a < sp {
        // SAFETY: [low, sp) is free stack inside the 4 MiB RAM (the stack
        // starts at its top and nothing else lives within 16 KiB of it);
        // nothing below the stack pointer is live, and no interrupt runs.
        unsafe { core::ptr::write_volatile(a as *mut u32, PAINT) };
        a += 4;
    }
    let mut s = start;
    for k in 0..n {
        black_box(step(black_box(model), &mut s, black_box(input(k))));
    }
    let mut a = low;
    // SAFETY: as above, reading the words just painted.
    while a < sp && unsafe { core::ptr::read_volatile(a as *const u32) } == PAINT {
        a += 4;
    }
    sp - a
}

/// Where the worst step was found.
#[derive(Clone, Copy)]
enum Where {
    Sweep(usize),
    Stress(usize),
}

/// Measures one row and prints its lines.
#[allow(clippy::too_many_arguments)]
fn row<M, St: Copy + Default, I: Copy, O>(
    per_tick: f32,
    name: &str,
    function: &str,
    scalar: &str,
    form: Form,
    model: &M,
    step: impl Fn(&M, &mut St, I) -> O + Copy,
    sweep: impl Fn(usize) -> I + Copy,
    stress: impl Fn(usize) -> I + Copy,
    stress_len: usize,
) -> Row {
    // every step of the sweep (from rest) and of the stress sequence (from
    // rest), replayed from its own starting state: the average is over the
    // sweep, the worst over both
    let (mut sum, mut worst, mut at) = (0.0f32, f32::MIN, Where::Sweep(0));
    let mut s = St::default();
    for k in 0..SWEEP_STEPS {
        let v = sweep(k);
        let c = replay(per_tick, model, step, s, v);
        sum += c;
        if c > worst {
            (worst, at) = (c, Where::Sweep(k));
        }
        step(model, &mut s, v);
    }
    let avg = sum / SWEEP_STEPS as f32;
    let mut s = St::default();
    for k in 0..stress_len {
        let v = stress(k);
        let c = replay(per_tick, model, step, s, v);
        if c > worst {
            (worst, at) = (c, Where::Stress(k));
        }
        step(model, &mut s, v);
    }
    // cross-check: the sweep run straight through (no replay, no copy)
    let mut s = St::default();
    let mut k = 0;
    let t = ticks(SWEEP_STEPS as u32, || {
        let v = sweep(k);
        k += 1;
        black_box(step(black_box(model), &mut s, black_box(v)));
    });
    let mut s = St::default();
    k = 0;
    let base = ticks(SWEEP_STEPS as u32, || {
        let v = sweep(k);
        k += 1;
        black_box(step_none(black_box(model), &mut s, black_box(v)));
    });
    let straight = (t as f32 - base as f32) * per_tick / SWEEP_STEPS as f32;
    let stack = stack_use(model, step, St::default(), sweep, SWEEP_STEPS).max(stack_use(
        model,
        step,
        St::default(),
        stress,
        stress_len,
    ));
    let (model_bytes, state_bytes) = (core::mem::size_of::<M>(), core::mem::size_of::<St>());
    let suffix = form.suffix();
    hprintln!("cost {}{} {} {} {}", name, suffix, scalar, CORE, round(avg));
    hprintln!(
        "cost-worst {}{} {} {} {}",
        name,
        suffix,
        scalar,
        CORE,
        round(worst)
    );
    let (what, index) = match at {
        Where::Sweep(k) => ("sweep", k),
        Where::Stress(k) => ("stress", k),
    };
    hprintln!(
        "cost-detail {} {} {} {} avg={} worst={} ratio={} worst-at={}:{} straight-avg={} model-bytes={} state-bytes={} stack-bytes={} fn={}",
        name,
        scalar,
        CORE,
        form.name(),
        tenths(avg),
        tenths(worst),
        hundredths(worst / avg),
        what,
        index,
        tenths(straight),
        model_bytes,
        state_bytes,
        stack,
        function
    );
    Row { avg, worst }
}

/// What a row measured.
struct Row {
    avg: f32,
    worst: f32,
}

fn round(x: f32) -> i32 {
    if x < 0.0 {
        (x - 0.5) as i32
    } else {
        (x + 0.5) as i32
    }
}

/// `x` with one decimal, without float formatting (smaller on Thumb-1).
struct Fixed(i32, u32);

impl core::fmt::Display for Fixed {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        let (v, d) = (self.0, self.1);
        let p = 10i32.pow(d);
        let sign = if v < 0 { "-" } else { "" };
        let a = v.unsigned_abs();
        write!(
            f,
            "{}{}.{:0w$}",
            sign,
            a / p as u32,
            a % p as u32,
            w = d as usize
        )
    }
}

fn tenths(x: f32) -> Fixed {
    Fixed(round(10.0 * x), 1)
}

fn hundredths(x: f32) -> Fixed {
    Fixed(round(100.0 * x), 2)
}

/// One non-inlined step function per row: `step_fn!(name, Model, State, Input
/// => Output, |model, state, input| body)`.
macro_rules! step_fn {
    ($name:ident, $model:ty, $state:ty, $input:ty => $output:ty, |$m:ident, $s:ident, $v:ident| $body:expr) => {
        #[inline(never)]
        fn $name($m: &$model, $s: &mut $state, $v: $input) -> $output {
            $body
        }
    };
}

/// A model row stepped with a scalar velocity: `row!(per_tick, "name",
/// "scalar", Form, &model, step_fn, Scalar)`.
macro_rules! row {
    ($pt:expr, $name:expr, $scalar:expr, $form:expr, $model:expr, $step:expr, $S:ty) => {
        row(
            $pt,
            $name,
            stringify!($step),
            $scalar,
            $form,
            $model,
            $step,
            |k| <$S as Scalar>::from_f64(sweep_velocity(k)),
            |k| <$S as Scalar>::from_f64(stress_velocity(k)),
            STRESS_LEN,
        )
    };
}

type LuGreObserver = Observer<LuGre<f32>, f32>;
type Servo = Compensator<f32, LuGreObserver>;
type ServoState = CompensatorState<f32, LuGreState<f32>>;

step_fn!(step_coulomb_f32, CoulombViscous<f32>, (), f32 => f32, |m, s, v| m.step(s, v, black_box(H)));
step_fn!(step_stribeck_f32, StribeckMap<f32>, (), f32 => f32, |m, s, v| m.step(s, v, black_box(H)));
step_fn!(step_lugre_f32, LuGre<f32>, LuGreState<f32>, f32 => f32, |m, s, v| m.step(s, v, black_box(H)));
step_fn!(step_lugre_observer_f32, LuGreObserver, LuGreState<f32>, f32 => f32,
    |m, s, v| m.step(s, v, black_box(OBSERVER_ERROR), black_box(H)));
step_fn!(step_dahl_f32, Dahl<f32>, DahlState<f32>, f32 => f32, |m, s, v| m.step(s, v, black_box(H)));
step_fn!(step_elasto_plastic_f32, ElastoPlastic<f32>, ElastoPlasticState<f32>, f32 => f32,
    |m, s, v| m.step(s, v, black_box(H)));
step_fn!(step_reset_integrator_f32, ResetIntegrator<f32>, ResetIntegratorState<f32>, f32 => f32,
    |m, s, v| m.step(s, v, black_box(H)));
step_fn!(step_bristle8_f32, Bristle<f32, 8>, BristleState<f32, 8>, f32 => f32,
    |m, s, v| m.step(s, v, black_box(H)));
step_fn!(step_gms1_f32, Gms<f32, 1>, GmsState<f32, 1>, f32 => f32, |m, s, v| m.step(s, v, black_box(H)));
step_fn!(step_gms4_f32, Gms<f32, 4>, GmsState<f32, 4>, f32 => f32, |m, s, v| m.step(s, v, black_box(H)));
step_fn!(step_gms16_f32, Gms<f32, 16>, GmsState<f32, 16>, f32 => f32, |m, s, v| m.step(s, v, black_box(H)));
step_fn!(step_xiong1_f32, Xiong<f32, 1>, XiongState<f32, 1>, f32 => f32, |m, s, v| m.step(s, v, black_box(H)));
step_fn!(step_xiong4_f32, Xiong<f32, 4>, XiongState<f32, 4>, f32 => f32, |m, s, v| m.step(s, v, black_box(H)));
step_fn!(step_xiong16_f32, Xiong<f32, 16>, XiongState<f32, 16>, f32 => f32,
    |m, s, v| m.step(s, v, black_box(H)));
// the parts the steps spend most on (libm): arguments as in LuGre's step
step_fn!(step_libm_expf_f32, (), (), f32 => f32, |_m, _s, v| libm::expf(v));
step_fn!(step_q16_div, Fixed32, (), Fixed32 => Fixed32, |m, _s, v| *m / v);
step_fn!(step_q16_mul, Fixed32, (), Fixed32 => Fixed32, |m, _s, v| *m * v);
step_fn!(step_q16_exp, (), (), Fixed32 => Fixed32, |_m, _s, v| v.exp_neg());
step_fn!(step_libm_expm1f_f32, (), (), f32 => f32, |_m, _s, v| libm::expm1f(v));
step_fn!(step_servo_lugre_f32, Servo, ServoState, (f32, Setpoint<f32>) => f32,
    |m, s, input| m.tick(s, input.0, input.1).command);

step_fn!(step_leuven8_f32, Leuven<f32, 8>, LeuvenState<f32, 8>, f32 => f32,
    |m, s, v| m.step(s, v, black_box(H)));

// the fixed-step forms (`build_fixed_step(H)`, step without `h`), f32 and Q16.16
type LuGreFixedStepObserver<S> = Observer<LuGreFixedStep<S>, S>;
type ServoFixedStep = Compensator<f32, FixedPeriod<LuGreFixedStepObserver<f32>>>;
type ServoFixedStepState = CompensatorState<f32, LuGreFixedStepState<f32>>;
macro_rules! fixed_step_fns {
    ($S:ty, $lugre:ident, $observer:ident, $dahl:ident, $ep:ident, $gms1:ident,
     $gms4:ident, $gms16:ident, $xiong1:ident, $xiong4:ident, $xiong16:ident) => {
        step_fn!($lugre, LuGreFixedStep<$S>, LuGreFixedStepState<$S>, $S => $S, |m, s, v| m.step(s, v));
        // the position error is an input, as the velocity: a caller has it
        // in a register (a constant behind `black_box` would be stored and
        // reloaded inside the measured function)
        step_fn!($observer, LuGreFixedStepObserver<$S>, LuGreFixedStepState<$S>, ($S, $S) => $S,
            |m, s, input| m.step_fixed(s, input.0, input.1));
        step_fn!($dahl, DahlFixedStep<$S>, DahlFixedStepState<$S>, $S => $S, |m, s, v| m.step(s, v));
        step_fn!($ep, ElastoPlasticFixedStep<$S>, ElastoPlasticFixedStepState<$S>, $S => $S, |m, s, v| m.step(s, v));
        step_fn!($gms1, GmsFixedStep<$S, 1>, GmsFixedStepState<$S, 1>, $S => $S, |m, s, v| m.step(s, v));
        step_fn!($gms4, GmsFixedStep<$S, 4>, GmsFixedStepState<$S, 4>, $S => $S, |m, s, v| m.step(s, v));
        step_fn!($gms16, GmsFixedStep<$S, 16>, GmsFixedStepState<$S, 16>, $S => $S, |m, s, v| m.step(s, v));
        step_fn!($xiong1, XiongFixedStep<$S, 1>, XiongFixedStepState<$S, 1>, $S => $S, |m, s, v| m.step(s, v));
        step_fn!($xiong4, XiongFixedStep<$S, 4>, XiongFixedStepState<$S, 4>, $S => $S, |m, s, v| m.step(s, v));
        step_fn!($xiong16, XiongFixedStep<$S, 16>, XiongFixedStepState<$S, 16>, $S => $S, |m, s, v| m.step(s, v));
    };
}
fixed_step_fns!(
    f32,
    step_lugre_at_f32,
    step_lugre_at_observer_f32,
    step_dahl_at_f32,
    step_elasto_plastic_at_f32,
    step_gms1_at_f32,
    step_gms4_at_f32,
    step_gms16_at_f32,
    step_xiong1_at_f32,
    step_xiong4_at_f32,
    step_xiong16_at_f32
);
fixed_step_fns!(
    Fixed32,
    step_lugre_at_q16,
    step_lugre_at_observer_q16,
    step_dahl_at_q16,
    step_elasto_plastic_at_q16,
    step_gms1_at_q16,
    step_gms4_at_q16,
    step_gms16_at_q16,
    step_xiong1_at_q16,
    step_xiong4_at_q16,
    step_xiong16_at_q16
);
step_fn!(step_servo_lugre_at_f32, ServoFixedStep, ServoFixedStepState, (f32, Setpoint<f32>) => f32,
    |m, s, input| m.tick(s, input.0, input.1).command);
// the same tick with the θ-adaptive observer (issue 16: within the servo tick + 150)
type ServoAdaptive = Compensator<f32, FixedPeriod<AdaptiveObserver<LuGreFixedStep<f32>, f32>>>;
type ServoAdaptiveState = CompensatorState<f32, AdaptiveState<LuGreFixedStepState<f32>, f32>>;
step_fn!(step_servo_adaptive_at_f32, ServoAdaptive, ServoAdaptiveState, (f32, Setpoint<f32>) => f32,
    |m, s, input| m.tick(s, input.0, input.1).command);
// both ticks in Q16.16, for cores without an FPU
type ServoFixedStepQ16 = Compensator<Fixed32, FixedPeriod<LuGreFixedStepObserver<Fixed32>>>;
type ServoFixedStepStateQ16 = CompensatorState<Fixed32, LuGreFixedStepState<Fixed32>>;
step_fn!(step_servo_lugre_at_q16, ServoFixedStepQ16, ServoFixedStepStateQ16,
    (Fixed32, Setpoint<Fixed32>) => Fixed32, |m, s, input| m.tick(s, input.0, input.1).command);
type ServoAdaptiveQ16 =
    Compensator<Fixed32, FixedPeriod<AdaptiveObserver<LuGreFixedStep<Fixed32>, Fixed32>>>;
type ServoAdaptiveStateQ16 =
    CompensatorState<Fixed32, AdaptiveState<LuGreFixedStepState<Fixed32>, Fixed32>>;
step_fn!(step_servo_adaptive_at_q16, ServoAdaptiveQ16, ServoAdaptiveStateQ16,
    (Fixed32, Setpoint<Fixed32>) => Fixed32, |m, s, input| m.tick(s, input.0, input.1).command);
// the per-parameter adaptive observer's fixed-step form under its supervisor
// (issue 32: within the servo tick + 200 on the M4F, + 400 in Q16.16 on the M0)
type ServoParameterState<S> =
    CompensatorState<S, SupervisedState<ParameterAdaptiveFixedStepState<S>, S>>;
step_fn!(step_servo_parameter_adaptive_f32, ParameterAdaptiveServo<f32>,
    ServoParameterState<f32>, (f32, Setpoint<f32>) => f32,
    |m, s, input| m.tick(s, input.0, input.1).command);
step_fn!(step_servo_parameter_adaptive_q16, ParameterAdaptiveServo<Fixed32>,
    ServoParameterState<Fixed32>, (Fixed32, Setpoint<Fixed32>) => Fixed32,
    |m, s, input| m.tick(s, input.0, input.1).command);

// the same with the exact step (`build_fixed_step_exact`): what it costs
type ServoParameterExact<S> =
    Compensator<S, Supervised<ParameterAdaptiveFixedStep<S, true>, CoulombViscous<S>, S>>;
type ServoParameterExactState<S> =
    CompensatorState<S, SupervisedState<ParameterAdaptiveFixedStepState<S>, S>>;
step_fn!(step_servo_parameter_exact_f32, ServoParameterExact<f32>,
    ServoParameterExactState<f32>, (f32, Setpoint<f32>) => f32,
    |m, s, input| m.tick(s, input.0, input.1).command);
step_fn!(step_servo_parameter_exact_q16, ServoParameterExact<Fixed32>,
    ServoParameterExactState<Fixed32>, (Fixed32, Setpoint<Fixed32>) => Fixed32,
    |m, s, input| m.tick(s, input.0, input.1).command);

// the same law without its supervisor: what the supervisor costs
type ServoParameterBare<S> = Compensator<S, ParameterAdaptiveFixedStep<S>>;
type ServoParameterBareState<S> = CompensatorState<S, ParameterAdaptiveFixedStepState<S>>;
step_fn!(step_servo_parameter_bare_f32, ServoParameterBare<f32>,
    ServoParameterBareState<f32>, (f32, Setpoint<f32>) => f32,
    |m, s, input| m.tick(s, input.0, input.1).command);
step_fn!(step_servo_parameter_bare_q16, ServoParameterBare<Fixed32>,
    ServoParameterBareState<Fixed32>, (Fixed32, Setpoint<Fixed32>) => Fixed32,
    |m, s, input| m.tick(s, input.0, input.1).command);

/// The per-parameter servo without its supervisor, in scalar `S`.
fn parameter_servo_bare<S: Scalar>(label: &str) -> ServoParameterBare<S> {
    let p = controller();
    let law = parameter_adaptation()
        .build_fixed_step::<S>(&p)
        .unwrap_or_else(|_| fail(label));
    p.build(law).unwrap_or_else(|_| fail(label))
}

/// The supervised per-parameter servo of the firmware's `main.rs` in scalar `S`.
fn parameter_servo<S: Scalar>(label: &str) -> ParameterAdaptiveServo<S> {
    let p = controller();
    let law = parameter_adaptation()
        .build_fixed_step::<S>(&p)
        .unwrap_or_else(|_| fail(label));
    let map = fallback().build::<S>().unwrap_or_else(|_| fail(label));
    let supervised = supervisor()
        .build(law, map, &p)
        .unwrap_or_else(|_| fail(label));
    p.build(supervised).unwrap_or_else(|_| fail(label))
}

/// [`parameter_servo`] with the exact step of `friction servo`
/// (`build_fixed_step_exact`).
fn parameter_servo_exact<S: Scalar>(label: &str) -> ServoParameterExact<S> {
    let p = controller();
    let law = parameter_adaptation()
        .build_fixed_step_exact::<S>(&p)
        .unwrap_or_else(|_| fail(label));
    let map = fallback().build::<S>().unwrap_or_else(|_| fail(label));
    let supervised = supervisor()
        .build(law, map, &p)
        .unwrap_or_else(|_| fail(label));
    p.build(supervised).unwrap_or_else(|_| fail(label))
}

/// One row per fixed-step form in scalar `$S` (label `$label`).
macro_rules! fixed_step_rows {
    ($pt:expr, $S:ty, $label:expr, $lugre:ident, $observer:ident, $dahl:ident, $ep:ident,
     $gms1:ident, $gms4:ident, $gms16:ident, $xiong1:ident, $xiong4:ident, $xiong16:ident) => {{
        let f = Form::Fixed;
        let h = f64::from(H);
        let lugre = NOMINAL
            .build_fixed_step::<$S>(h)
            .unwrap_or_else(|_| fail("fixed-step LuGre parameters"));
        row!($pt, "lugre", $label, f, &lugre, $lugre, $S);
        let observer =
            Observer::new(lugre, OBSERVER_GAIN).unwrap_or_else(|_| fail("observer gain"));
        let error = <$S as Scalar>::from_f64(f64::from(OBSERVER_ERROR));
        row(
            $pt,
            "lugre-observer",
            stringify!($observer),
            $label,
            f,
            &observer,
            $observer,
            |k| (<$S as Scalar>::from_f64(sweep_velocity(k)), error),
            |k| (<$S as Scalar>::from_f64(stress_velocity(k)), error),
            STRESS_LEN,
        );
        let dahl = DahlParams {
            sigma: NOMINAL.sigma0,
            fc: NOMINAL.curve.fc,
            delta: 1.0,
            sigma2: NOMINAL.sigma2,
        }
        .build_fixed_step::<$S>(h)
        .unwrap_or_else(|_| fail("fixed-step Dahl parameters"));
        row!($pt, "dahl", $label, f, &dahl, $dahl, $S);
        // the default (bounded) step, the full step, and the bounds a
        // real-time loop can choose (`with_max_substeps(k)`: at most k RK4
        // sub-steps of the zone; `None`: as built)
        for (name, frac, k) in [
            ("elasto-plastic", 0.5, None),
            ("elasto-plastic-full", 0.5, Some(24)),
            ("elasto-plastic-z99-full", 0.99, Some(24)),
            ("elasto-plastic-k3", 0.5, Some(3)),
            ("elasto-plastic-z99-k3", 0.99, Some(3)),
            ("elasto-plastic-k1", 0.5, Some(1)),
            ("elasto-plastic-k0", 0.5, Some(0)),
        ] {
            let built = ElastoPlasticParams {
                lugre: NOMINAL,
                z_ba: frac * NOMINAL.curve.fc / NOMINAL.sigma0,
            }
            .build_fixed_step::<$S>(h)
            .unwrap_or_else(|_| fail("fixed-step elasto-plastic parameters"));
            let ep = match k {
                Some(k) => built.with_max_substeps(k),
                None => built,
            };
            row!($pt, name, $label, f, &ep, $ep, $S);
        }
        if let Some(m) = gms_at::<$S, 1>($label) {
            row!($pt, "gms1", $label, f, &m, $gms1, $S);
        }
        if let Some(m) = gms_at::<$S, 4>($label) {
            row!($pt, "gms4", $label, f, &m, $gms4, $S);
        }
        if let Some(m) = gms_at::<$S, 16>($label) {
            row!($pt, "gms16", $label, f, &m, $gms16, $S);
        }
        if let Some(m) = xiong_at::<$S, 1>($label) {
            row!($pt, "xiong1", $label, f, &m, $xiong1, $S);
        }
        if let Some(m) = xiong_at::<$S, 4>($label) {
            row!($pt, "xiong4", $label, f, &m, $xiong4, $S);
        }
        if let Some(m) = xiong_at::<$S, 16>($label) {
            row!($pt, "xiong16", $label, f, &m, $xiong16, $S);
        }
    }};
}

fn gms<const N: usize>() -> Gms<f32, N> {
    gms_params::<N>()
        .build()
        .unwrap_or_else(|_| fail("GMS parameters"))
}

/// The fixed-step GMS in scalar `S`, built for `H`; `None` (and a
/// `cost-skip` line) where the scalar cannot carry the parameter set.
fn gms_at<S: Scalar, const N: usize>(label: &str) -> Option<GmsFixedStep<S, N>> {
    built(
        gms_params::<N>().build_fixed_step(f64::from(H)),
        "gms",
        N,
        label,
    )
}

/// `Some(model)`, or `None` with a `cost-skip MODEL SCALAR CORE reason` line.
fn built<M>(
    model: Result<M, friction_core::ParamError>,
    name: &str,
    n: usize,
    label: &str,
) -> Option<M> {
    model
        .map_err(|e| hprintln!("cost-skip {}{} {} {} {}", name, n, label, CORE, e))
        .ok()
}

fn xiong_params<const N: usize>() -> XiongParams<N> {
    let mut elements = [XiongElement::default(); N];
    for (i, e) in elements.iter_mut().enumerate() {
        let (k, lambda, sigma) = element(i, N);
        *e = XiongElement { k, sigma, lambda };
    }
    XiongParams {
        curve: NOMINAL.curve,
        tau: 0.01,
        sigma2: NOMINAL.sigma2,
        elements,
    }
}

fn xiong<const N: usize>() -> Xiong<f32, N> {
    xiong_params::<N>()
        .build()
        .unwrap_or_else(|_| fail("Xiong parameters"))
}

/// The fixed-step Xiong in scalar `S`, built for `H` (see [`gms_at`]).
fn xiong_at<S: Scalar, const N: usize>(label: &str) -> Option<XiongFixedStep<S, N>> {
    built(
        xiong_params::<N>().build_fixed_step(f64::from(H)),
        "xiong",
        N,
        label,
    )
}

/// The servo tick's input: positions 1 mrad around a sine whose differences
/// sweep the velocity through zero, reference 10 µrad off.
fn servo_sweep(k: usize) -> (f32, Setpoint<f32>) {
    let x = 1e-3 * libm::sinf((k % 64) as f32 * 0.1963);
    let r = Setpoint {
        x: x + 1e-5,
        v: sweep_velocity(k) as f32,
        a: 0.0,
    };
    (x, r)
}

/// A servo tick's input in Q16.16.
fn q16(input: (f32, Setpoint<f32>)) -> (Fixed32, Setpoint<Fixed32>) {
    let q = |x: f32| Fixed32::from_f64(f64::from(x));
    let (x, r) = input;
    (
        q(x),
        Setpoint {
            x: q(r.x),
            v: q(r.v),
            a: q(r.a),
        },
    )
}

/// The servo tick's stress: position errors and reference velocities from
/// the stress magnitudes (mrad, rad/s), saturating the command.
fn servo_stress(k: usize) -> (f32, Setpoint<f32>) {
    let v = stress_velocity(k) as f32;
    let r = Setpoint { x: 0.0, v, a: 0.0 };
    (1e-3 * v, r)
}

step_fn!(step_commissioning_f32, Commissioning<f32>, CommissioningState<f32>, f32 => CommissioningTick<f32>,
    |m, s, x| m.tick(s, x));
step_fn!(step_commissioning_q16, Commissioning<Fixed32>, CommissioningState<Fixed32>, Fixed32 => CommissioningTick<Fixed32>,
    |m, s, x| m.tick(s, x));

/// Replays of each commissioning tick: 16, not [`REPS`], since every tick
/// of a 25 s run is replayed with a copy of a state of over a kilobyte
/// (the copy is measured and subtracted, as for every row).
const COMMISSIONING_REPS: u32 = 16;

/// SysTick wraps (2^24 ticks each) while [`long_count`] measures.
static WRAPS: AtomicU32 = AtomicU32::new(0);

#[exception]
fn SysTick() {
    // single core, the only writer: a load and a store (ARMv6-M has no
    // atomic read-modify-write)
    WRAPS.store(WRAPS.load(Ordering::Relaxed) + 1, Ordering::Relaxed);
}

/// Instructions spent by `f`, once, for calls longer than SysTick's 24
/// bits (671 M instructions): the wraps are counted by the SysTick
/// exception, enabled only here.
fn long_count<O>(per_tick: f32, syst: &mut SYST, f: impl FnOnce() -> O) -> (O, f64) {
    WRAPS.store(0, Ordering::Relaxed);
    syst.clear_current();
    syst.enable_interrupt();
    let start = SYST::get_current();
    let out = black_box(f());
    let end = SYST::get_current();
    syst.disable_interrupt();
    let wraps = WRAPS.load(Ordering::Relaxed);
    let ticks = f64::from(wraps) * f64::from(1u32 << 24) + f64::from(start) - f64::from(end);
    (out, ticks * f64::from(per_tick))
}

/// The commissioning tick's rows: the routine of the example (`setup.rs`)
/// run from rest to its end against the example's plant (inertia and
/// LuGre friction in f32 at 10 kHz, the 20-bit encoder, the drive's
/// torque limit), every tick replayed from its own starting state and
/// counted alone, by the phase the tick starts in, and for the whole run.
/// Returns the routine and its finished state (for the fit's row), or
/// `None` with a `cost-skip` line where the scalar cannot carry the
/// settings.
fn commissioning_rows<S: Scalar>(
    per_tick: f32,
    settings: CommissioningParams,
    scalar: &str,
    function: &str,
    step: fn(&Commissioning<S>, &mut CommissioningState<S>, S) -> CommissioningTick<S>,
) -> Option<(Commissioning<S>, CommissioningState<S>)> {
    const SUBSTEPS: u32 = 10;
    let routine = match settings.build::<S>() {
        Ok(r) => r,
        Err(e) => {
            hprintln!("cost-skip commissioning {} {} {}", scalar, CORE, e);
            return None;
        }
    };
    let plant = ACTUAL
        .build::<f32>()
        .unwrap_or_else(|_| fail("plant parameters"));
    let counts_per_rad = (ENCODER_COUNTS / core::f64::consts::TAU) as f32;
    let (mut z, mut x, mut v) = (LuGreState::default(), 0.0f32, 0.0f32);
    let mut state = CommissioningState::<S>::default();
    // per phase (break-away, presliding, plateaus) and for the whole run:
    // sum, ticks, worst and the tick it was at
    let mut sums = [(0.0f64, 0u32, f32::MIN, 0u32); 4];
    let most = libm::ceil(settings.duration / settings.servo.h) as u32 + 2;
    let hs = H / SUBSTEPS as f32;
    let mut finished = false;
    for k in 0..most {
        let measured = libm::floorf(x * counts_per_rad) / counts_per_rad;
        let input = S::from_f64(f64::from(measured));
        let phase = match state.phase() {
            CommissioningPhase::Breakaway => 0,
            CommissioningPhase::Presliding => 1,
            CommissioningPhase::Plateaus => 2,
            CommissioningPhase::Done | CommissioningPhase::Aborted => {
                finished = true;
                break;
            }
        };
        let t = ticks(COMMISSIONING_REPS, || {
            let mut s = black_box(state);
            black_box(step(black_box(&routine), &mut s, black_box(input)));
            black_box(&s);
        });
        let base = ticks(COMMISSIONING_REPS, || {
            let mut s = black_box(state);
            black_box(step_none(black_box(&routine), &mut s, black_box(input)));
            black_box(&s);
        });
        let c = (t as f32 - base as f32) * per_tick / COMMISSIONING_REPS as f32;
        for i in [phase, 3] {
            if let Some(e) = sums.get_mut(i) {
                e.0 += f64::from(c);
                e.1 += 1;
                if c > e.2 {
                    (e.2, e.3) = (c, k);
                }
            }
        }
        let tick = step(&routine, &mut state, input);
        let torque = tick.command.to_f64() as f32;
        let torque = torque.clamp(-TORQUE_MAX, TORQUE_MAX);
        for _ in 0..SUBSTEPS {
            let f = plant.step(&mut z, v, hs);
            v += hs * (torque - f) / INERTIA;
            x += hs * v;
        }
    }
    if !(finished && state.phase() == CommissioningPhase::Done) {
        hprintln!("cost: commissioning in {}: {:?}", scalar, state.abort());
        fail("the commissioning run of the cost rows did not finish");
    }
    let names = [
        "commissioning-breakaway",
        "commissioning-presliding",
        "commissioning-plateaus",
        "commissioning",
    ];
    for (name, (sum, n, worst, at)) in names.into_iter().zip(sums) {
        if n == 0 {
            fail("a commissioning phase without ticks");
        }
        let avg = (sum / f64::from(n)) as f32;
        hprintln!("cost {} {} {} {}", name, scalar, CORE, round(avg));
        hprintln!("cost-worst {} {} {} {}", name, scalar, CORE, round(worst));
        hprintln!(
            "cost-detail {} {} {} fixed avg={} worst={} ratio={} worst-at=tick:{} straight-avg={} model-bytes={} state-bytes={} stack-bytes=- fn={}",
            name,
            scalar,
            CORE,
            tenths(avg),
            tenths(worst),
            hundredths(worst / avg),
            at,
            tenths(avg),
            core::mem::size_of::<Commissioning<S>>(),
            core::mem::size_of::<CommissioningState<S>>(),
            function
        );
    }
    Some((routine, state))
}

/// The final fit's row: `Commissioning::result` once on the finished run
/// (f64, in software on both cores), its instructions in the avg and
/// worst columns; fails if the fit refuses the run.
fn fit_row<S: Scalar>(
    per_tick: f32,
    syst: &mut SYST,
    scalar: &str,
    routine: &Commissioning<S>,
    state: &CommissioningState<S>,
) {
    let (result, n) = long_count(per_tick, syst, || routine.result(black_box(state)));
    if result.is_err() {
        fail("the commissioning fit refused the cost rows' run");
    }
    // beyond i32's tenths: whole instructions
    let n = n as u64;
    hprintln!("cost commissioning-fit {} {} {}", scalar, CORE, n);
    hprintln!("cost-worst commissioning-fit {} {} {}", scalar, CORE, n);
    hprintln!(
        "cost-detail commissioning-fit {} {} fixed avg={}.0 worst={}.0 ratio=1.00 worst-at=run:0 straight-avg={}.0 model-bytes={} state-bytes={} stack-bytes=- fn=result",
        scalar,
        CORE,
        n,
        n,
        n,
        core::mem::size_of::<Commissioning<S>>(),
        core::mem::size_of::<CommissioningState<S>>()
    );
}

fn fail(what: &str) -> ! {
    hprintln!("cost: failed: {}", what);
    debug::exit(EXIT_FAILURE);
    loop {
        cortex_m::asm::nop();
    }
}

/// `a / b` in Q16.16 as `Fixed32`'s division defines it (round half up,
/// saturate, `x / 0` the largest value of its sign) from a 64-bit integer
/// division, a call of several hundred instructions here.
fn reference_quotient(a: i32, b: i32) -> i32 {
    if b == 0 {
        return match a.signum() {
            1 => i32::MAX,
            -1 => i32::MIN,
            _ => 0,
        };
    }
    let q = (u64::from(a.unsigned_abs()) << 17) / u64::from(b.unsigned_abs());
    let q = ((q >> 1) + (q & 1)) as i64;
    let q = if (a < 0) != (b < 0) { -q } else { q };
    q.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32
}

/// The Q16.16 quotient on this core (on ARMv6-M, `Fixed32`'s own division,
/// not the host's) against [`reference_quotient`] over pseudo-random pairs of
/// every magnitude.
fn check_division(pairs: u32) {
    let mut x = 0x2545_f491u32;
    let mut next = || {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        x
    };
    for _ in 0..pairs {
        let (a, b, shift) = (next() as i32, next() as i32, next());
        let (a, b) = (a >> (shift & 31), b >> ((shift >> 5) & 31));
        let got = (Fixed32::from_bits(a) / Fixed32::from_bits(b)).to_bits();
        if got != reference_quotient(a, b) {
            hprintln!(
                "cost: {} / {}: {} against {}",
                a,
                b,
                got,
                reference_quotient(a, b)
            );
            fail("Q16.16 division");
        }
    }
    hprintln!("cost-check q16-div {} pairs match a 64-bit division", pairs);
}

#[entry]
fn main() -> ! {
    let Some(mut cp) = cortex_m::Peripherals::take() else {
        fail("peripherals")
    };
    cp.SYST.set_clock_source(SystClkSource::Core);
    cp.SYST.set_reload(0x00FF_FFFF);
    cp.SYST.clear_current();
    cp.SYST.enable_counter();
    let Some(pt) = calibrate() else {
        fail("SysTick does not advance with instructions (run QEMU with -icount shift=0)")
    };
    hprintln!(
        "cost-calibration {} instructions per SysTick tick",
        tenths(pt)
    );
    check_division(20_000);

    let curve = NOMINAL.curve;
    let coulomb = CoulombViscousParams {
        fc: curve.fc,
        sigma2: NOMINAL.sigma2,
    }
    .build::<f32>()
    .unwrap_or_else(|_| fail("Coulomb parameters"));
    let stribeck = StribeckMapParams {
        curve,
        sigma2: NOMINAL.sigma2,
    }
    .build::<f32>()
    .unwrap_or_else(|_| fail("Stribeck parameters"));
    let lugre = NOMINAL
        .build::<f32>()
        .unwrap_or_else(|_| fail("LuGre parameters"));
    let observer = Observer::new(lugre, OBSERVER_GAIN).unwrap_or_else(|_| fail("observer gain"));
    let dahl = DahlParams {
        sigma: NOMINAL.sigma0,
        fc: curve.fc,
        delta: 1.0,
        sigma2: NOMINAL.sigma2,
    }
    .build::<f32>()
    .unwrap_or_else(|_| fail("Dahl parameters"));
    let elasto_plastic = ElastoPlasticParams {
        lugre: NOMINAL,
        z_ba: 0.5 * curve.fc / NOMINAL.sigma0,
    }
    .build::<f32>()
    .unwrap_or_else(|_| fail("elasto-plastic parameters"));
    // the narrowest transition zone of the former worst case (z_ba = 0.99
    // Fc/sigma0): same step, the parameter set at the edge of its range
    let elasto_plastic_z99 = ElastoPlasticParams {
        lugre: NOMINAL,
        z_ba: 0.99 * curve.fc / NOMINAL.sigma0,
    }
    .build::<f32>()
    .unwrap_or_else(|_| fail("elasto-plastic parameters"));
    let reset = ResetIntegratorParams {
        sigma0: NOMINAL.sigma0,
        sigma1: NOMINAL.sigma1,
        z0: curve.fc / NOMINAL.sigma0,
        stiction: 0.2,
        curve: None,
    }
    .build::<f32>()
    .unwrap_or_else(|_| fail("reset integrator parameters"));
    let bristle = BristleParams {
        sigma0: NOMINAL.sigma0 / 8.0,
        delta_s: 3.0 * curve.fc / NOMINAL.sigma0,
        seed: 1,
    }
    .build::<f32, 8>()
    .unwrap_or_else(|_| fail("bristle parameters"));
    // the firmware servo's PD + acceleration feed-forward
    let controller = controller();
    let servo = controller
        .build::<f32, _>(observer)
        .unwrap_or_else(|_| fail("servo gains"));

    // One line per row: a new row is one `step_fn!` and one `row!`. A model
    // with a fixed-step form names its variable-step rows `<model>-var`.
    let v = Form::Variable;
    row!(pt, "coulomb", "f32", v, &coulomb, step_coulomb_f32, f32);
    row!(pt, "stribeck", "f32", v, &stribeck, step_stribeck_f32, f32);
    row!(pt, "lugre-var", "f32", v, &lugre, step_lugre_f32, f32);
    row!(
        pt,
        "lugre-observer-var",
        "f32",
        v,
        &observer,
        step_lugre_observer_f32,
        f32
    );
    row!(pt, "dahl-var", "f32", v, &dahl, step_dahl_f32, f32);
    row!(
        pt,
        "elasto-plastic-var",
        "f32",
        v,
        &elasto_plastic,
        step_elasto_plastic_f32,
        f32
    );
    row!(
        pt,
        "elasto-plastic-z99-var",
        "f32",
        v,
        &elasto_plastic_z99,
        step_elasto_plastic_f32,
        f32
    );
    row!(
        pt,
        "reset-integrator",
        "f32",
        v,
        &reset,
        step_reset_integrator_f32,
        f32
    );
    row!(pt, "bristle8", "f32", v, &bristle, step_bristle8_f32, f32);
    // Leuven (variable step only), memory of 8 reversal points, n = 2 and
    // the virgin curve's xs = Fs / sigma0, as in the firmware's servo
    let leuven = leuven_nominal()
        .build::<f32, 8>()
        .unwrap_or_else(|_| fail("Leuven parameters"));
    row!(pt, "leuven8", "f32", v, &leuven, step_leuven8_f32, f32);
    row!(pt, "gms1-var", "f32", v, &gms::<1>(), step_gms1_f32, f32);
    row!(pt, "gms4-var", "f32", v, &gms::<4>(), step_gms4_f32, f32);
    row!(pt, "gms16-var", "f32", v, &gms::<16>(), step_gms16_f32, f32);
    row!(
        pt,
        "xiong1-var",
        "f32",
        v,
        &xiong::<1>(),
        step_xiong1_f32,
        f32
    );
    row!(
        pt,
        "xiong4-var",
        "f32",
        v,
        &xiong::<4>(),
        step_xiong4_f32,
        f32
    );
    row!(
        pt,
        "xiong16-var",
        "f32",
        v,
        &xiong::<16>(),
        step_xiong16_f32,
        f32
    );
    let tick = row(
        pt,
        "servo-lugre-var",
        "step_servo_lugre_f32",
        "f32",
        v,
        &servo,
        step_servo_lugre_f32,
        servo_sweep,
        servo_stress,
        STRESS_LEN,
    );
    if !(tick.avg > 0.0 && tick.worst >= tick.avg) {
        fail("implausible servo tick count");
    }
    // the fixed-step forms, f32 and Q16.16 fixed point, and the servo tick on
    // the fixed-step observer (what the firmware's servo runs)
    fixed_step_rows!(
        pt,
        f32,
        "f32",
        step_lugre_at_f32,
        step_lugre_at_observer_f32,
        step_dahl_at_f32,
        step_elasto_plastic_at_f32,
        step_gms1_at_f32,
        step_gms4_at_f32,
        step_gms16_at_f32,
        step_xiong1_at_f32,
        step_xiong4_at_f32,
        step_xiong16_at_f32
    );
    fixed_step_rows!(
        pt,
        Fixed32,
        "fixed",
        step_lugre_at_q16,
        step_lugre_at_observer_q16,
        step_dahl_at_q16,
        step_elasto_plastic_at_q16,
        step_gms1_at_q16,
        step_gms4_at_q16,
        step_gms16_at_q16,
        step_xiong1_at_q16,
        step_xiong4_at_q16,
        step_xiong16_at_q16
    );
    let lugre_at = NOMINAL
        .build_fixed_step::<f32>(f64::from(H))
        .unwrap_or_else(|_| fail("fixed-step LuGre parameters"));
    let servo_at = controller
        .build(FixedPeriod(
            Observer::new(lugre_at, OBSERVER_GAIN).unwrap_or_else(|_| fail("observer gain")),
        ))
        .unwrap_or_else(|_| fail("servo gains"));
    let tick_at = row(
        pt,
        "servo-lugre",
        "step_servo_lugre_at_f32",
        "f32",
        Form::Fixed,
        &servo_at,
        step_servo_lugre_at_f32,
        servo_sweep,
        servo_stress,
        STRESS_LEN,
    );
    if !(tick_at.avg > 0.0 && tick_at.worst >= tick_at.avg) {
        fail("implausible fixed-step servo tick count");
    }
    let adaptive_observer =
        Observer::new(lugre_at, OBSERVER_GAIN).unwrap_or_else(|_| fail("observer gain"));
    let servo_adaptive = controller
        .build(FixedPeriod(
            adaptation()
                .build(adaptive_observer, f64::from(H))
                .unwrap_or_else(|_| fail("adaptation parameters")),
        ))
        .unwrap_or_else(|_| fail("servo gains"));
    let tick_adaptive = row(
        pt,
        "servo-adaptive",
        "step_servo_adaptive_at_f32",
        "f32",
        Form::Fixed,
        &servo_adaptive,
        step_servo_adaptive_at_f32,
        servo_sweep,
        servo_stress,
        STRESS_LEN,
    );
    if !(tick_adaptive.avg > 0.0 && tick_adaptive.worst >= tick_adaptive.avg) {
        fail("implausible adaptive servo tick count");
    }
    let tick_parameter = row(
        pt,
        "servo-parameter-adaptive",
        "step_servo_parameter_adaptive_f32",
        "f32",
        Form::Fixed,
        &parameter_servo::<f32>("per-parameter servo"),
        step_servo_parameter_adaptive_f32,
        servo_sweep,
        servo_stress,
        STRESS_LEN,
    );
    if !(tick_parameter.avg > 0.0 && tick_parameter.worst >= tick_parameter.avg) {
        fail("implausible per-parameter servo tick count");
    }
    row(
        pt,
        "servo-parameter-exact",
        "step_servo_parameter_exact_f32",
        "f32",
        Form::Fixed,
        &parameter_servo_exact::<f32>("per-parameter servo, exact step"),
        step_servo_parameter_exact_f32,
        servo_sweep,
        servo_stress,
        STRESS_LEN,
    );
    row(
        pt,
        "servo-parameter-bare",
        "step_servo_parameter_bare_f32",
        "f32",
        Form::Fixed,
        &parameter_servo_bare::<f32>("per-parameter servo"),
        step_servo_parameter_bare_f32,
        servo_sweep,
        servo_stress,
        STRESS_LEN,
    );
    // the same ticks in Q16.16
    let lugre_q16 = NOMINAL
        .build_fixed_step::<Fixed32>(f64::from(H))
        .unwrap_or_else(|_| fail("fixed-step LuGre parameters in Q16.16"));
    let observer_q16 =
        Observer::new(lugre_q16, OBSERVER_GAIN).unwrap_or_else(|_| fail("observer gain"));
    let servo_q16 = controller
        .build(FixedPeriod(observer_q16))
        .unwrap_or_else(|_| fail("servo gains in Q16.16"));
    row(
        pt,
        "servo-lugre",
        "step_servo_lugre_at_q16",
        "fixed",
        Form::Fixed,
        &servo_q16,
        step_servo_lugre_at_q16,
        |k| q16(servo_sweep(k)),
        |k| q16(servo_stress(k)),
        STRESS_LEN,
    );
    let servo_adaptive_q16 = controller
        .build(FixedPeriod(
            adaptation()
                .build(observer_q16, f64::from(H))
                .unwrap_or_else(|_| fail("adaptation parameters in Q16.16")),
        ))
        .unwrap_or_else(|_| fail("servo gains in Q16.16"));
    row(
        pt,
        "servo-adaptive",
        "step_servo_adaptive_at_q16",
        "fixed",
        Form::Fixed,
        &servo_adaptive_q16,
        step_servo_adaptive_at_q16,
        |k| q16(servo_sweep(k)),
        |k| q16(servo_stress(k)),
        STRESS_LEN,
    );
    row(
        pt,
        "servo-parameter-adaptive",
        "step_servo_parameter_adaptive_q16",
        "fixed",
        Form::Fixed,
        &parameter_servo::<Fixed32>("per-parameter servo in Q16.16"),
        step_servo_parameter_adaptive_q16,
        |k| q16(servo_sweep(k)),
        |k| q16(servo_stress(k)),
        STRESS_LEN,
    );
    row(
        pt,
        "servo-parameter-exact",
        "step_servo_parameter_exact_q16",
        "fixed",
        Form::Fixed,
        &parameter_servo_exact::<Fixed32>("per-parameter servo in Q16.16, exact step"),
        step_servo_parameter_exact_q16,
        |k| q16(servo_sweep(k)),
        |k| q16(servo_stress(k)),
        STRESS_LEN,
    );
    row(
        pt,
        "servo-parameter-bare",
        "step_servo_parameter_bare_q16",
        "fixed",
        Form::Fixed,
        &parameter_servo_bare::<Fixed32>("per-parameter servo in Q16.16"),
        step_servo_parameter_bare_q16,
        |k| q16(servo_sweep(k)),
        |k| q16(servo_stress(k)),
        STRESS_LEN,
    );
    // the parts: e^(-(v/vs)^2) of the Stribeck curve and e^(-a h) - 1 of the
    // relaxation (a h = sigma0 |v| h / g, about 0.01 on the sweep)
    let stribeck_arg = |v: f64| -(v / curve.vs) * (v / curve.vs);
    let relax_arg = |v: f64| -(NOMINAL.sigma0 * libm::fabs(v) * H as f64 / curve.fc).min(1.0);
    row(
        pt,
        "libm-expf",
        "step_libm_expf_f32",
        "f32",
        v,
        &(),
        step_libm_expf_f32,
        |k| stribeck_arg(sweep_velocity(k)) as f32,
        |k| stribeck_arg(stress_velocity(k)) as f32,
        STRESS_LEN,
    );
    row(
        pt,
        "libm-expm1f",
        "step_libm_expm1f_f32",
        "f32",
        v,
        &(),
        step_libm_expm1f_f32,
        |k| relax_arg(sweep_velocity(k)) as f32,
        |k| relax_arg(stress_velocity(k)) as f32,
        STRESS_LEN,
    );
    // the parts of Q16.16: a product, a quotient (a force over forces of
    // 230 to 330, as LuGre's 1/g; beyond 1 on the stress sequence) and
    // e^-x over [0, 3]
    let two = Fixed32::from_f64(2.0);
    let force = |k: usize| Fixed32::from_f64(280.0 + 50.0 * libm::sin(k as f64));
    let ramp = |k: usize| Fixed32::from_f64(0.3 + k as f64);
    row(
        pt,
        "q16-mul",
        "step_q16_mul",
        "fixed",
        Form::Fixed,
        &two,
        step_q16_mul,
        force,
        ramp,
        STRESS_LEN,
    );
    row(
        pt,
        "q16-div",
        "step_q16_div",
        "fixed",
        Form::Fixed,
        &two,
        step_q16_div,
        force,
        ramp,
        STRESS_LEN,
    );
    row(
        pt,
        "q16-exp",
        "step_q16_exp",
        "fixed",
        Form::Fixed,
        &(),
        step_q16_exp,
        |k| Fixed32::from_f64(3.0 * libm::fabs(libm::sin(k as f64))),
        |k| Fixed32::from_f64(0.01 * k as f64),
        STRESS_LEN,
    );
    // the commissioning tick by phase, and the fit (f64 in software): f32
    // on both cores, Q16.16 as the M0's scalar
    let Some((routine, state)) = commissioning_rows::<f32>(
        pt,
        commissioning(),
        "f32",
        "step_commissioning_f32",
        step_commissioning_f32,
    ) else {
        fail("the example's commissioning settings in f32")
    };
    fit_row(pt, &mut cp.SYST, "f32", &routine, &state);
    if CORE == "cortex-m0" {
        // Q16.16 holds a plateau's 1 / (8 v h) only up to 32,768 (the
        // example's slowest plateau, 3 mrad/s, gives 41,667) and each
        // setting within 0.1 % of its value: the slowest plateau at 10
        // mrad/s, the ramp a whole number of Q16.16 steps a tick. The fit
        // is the f32 row's f64 code, not repeated.
        let settings = CommissioningParams {
            min_speed: 0.01,
            ramp_rate: 33.0 / 65_536.0 / f64::from(H),
            ..commissioning()
        };
        commissioning_rows::<Fixed32>(
            pt,
            settings,
            "fixed",
            "step_commissioning_q16",
            step_commissioning_q16,
        );
    }
    hprintln!("cost-done");
    debug::exit(EXIT_SUCCESS);
    loop {
        cortex_m::asm::nop();
    }
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    fail("panic")
}
