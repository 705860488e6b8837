//! A compensated servo loop on a Cortex-M4F (QEMU mps2-an386).
//!
//! It first commissions its plant: the core's `Commissioning` routine
//! ticked in the control loop against the simulated axis, the fit, the
//! identified parameters against the plant's (issue 33's bounds, enforced
//! where the run says it identified them), then the LuGre observer on the
//! commissioned model tracks against the observer on the exact model and
//! must stay within 2x its RMS error.
//!
//! The core's compensator (here a PD position loop with acceleration
//! feed-forward) tracks one trajectory four times against a simulated plant
//! (inertia + LuGre friction whose parameters differ from the controller's
//! model): without compensation, with a static Coulomb + viscous
//! feed-forward on the measured velocity, and with the LuGre observer (the
//! fixed-step form built for the loop's 1 kHz) with and without its
//! `sigma1 dz^/dt` term; then the Leuven observer on the same plant, and a
//! Leuven plant without compensation and with the Leuven observer; then a
//! plant whose friction has drifted (fixed against θ-adaptive observer),
//! and a geared joint whose friction differs by direction and grows with
//! the torque it carries (no compensation, the fixed observer, and the
//! per-parameter adaptive observer under its supervisor, which must hold
//! the RMS error of the last 10 s within 0.5 mrad).
//! `servo.rs` is only the embedded-hal
//! glue around it. It logs the RMS tracking errors through defmt, counts
//! the instructions of the core's steps and of one full compensated servo
//! tick with SysTick (QEMU `-icount shift=0`), and exits non-zero if the
//! observer does not reduce the tracking error.

#![no_std]
#![no_main]

mod hw;
mod servo;
mod setup;
mod telemetry;

use core::cell::RefCell;
use core::hint::black_box;
use cortex_m::peripheral::{syst::SystClkSource, SYST};
use cortex_m_rt::entry;
use cortex_m_semihosting::debug::{self, EXIT_FAILURE, EXIT_SUCCESS};
use defmt_semihosting as _;
use embedded_hal::pwm::SetDutyCycle;
use friction_core::{
    BristleParams, Commissioned, CommissioningPhase, CommissioningState, Compensation, Compensator,
    CompensatorState, CoulombViscousParams, DahlParams, ElastoPlasticParams, FeedForward,
    FixedPeriod, FixedStepModel, FrictionModel, GmsElement, GmsParams, GmsSlipMode, GmsState,
    LeuvenParams, LeuvenState, LuGre, LuGreFixedStep, LuGreFixedStepState, LuGreParams, LuGreServo,
    LuGreState, NoCompensation, Observer, ParameterAdaptiveServo, ResetIntegratorParams, Setpoint,
    StribeckParams, XiongElement, XiongParams,
};
use heapless::spsc::Queue;
use hw::Encoder;
use hw::{Plant, SimDrive, SimEncoder};
use servo::Servo;
use setup::{
    adaptation, commissioning, controller, fallback, leuven_nominal, parameter_adaptation,
    supervisor, ACTUAL, ENCODER_COUNTS, H, INERTIA, NOMINAL, OBSERVER_GAIN, TORQUE_MAX,
};
use telemetry::{Sample, Sender, Stats};

const SUBSTEPS: u32 = 10; // plant simulated at 10 kHz
const TICKS: u32 = 4000; // 4 s: two periods of the trajectory
const COUNTS_PER_RAD: f32 = (ENCODER_COUNTS / core::f64::consts::TAU) as f32;
const AMPLITUDE: f32 = 0.2; // rad
const FREQUENCY: f32 = 0.5; // Hz

struct Errors {
    rms: f32,
    max: f32,
    /// Telemetry samples the full queue refused (0: the logging loop kept up).
    overflows: u32,
}

fn run<C: Compensation<f32>>(compensator: Compensator<f32, C>) -> Errors {
    let Ok(friction) = ACTUAL.build::<f32>() else {
        fail("plant parameters")
    };
    run_on(friction, compensator)
}

/// The tracking run against a plant whose friction is `friction`.
fn run_on<M: FrictionModel<f32>, C: Compensation<f32>>(
    friction: M,
    compensator: Compensator<f32, C>,
) -> Errors {
    run_actuator(friction, SYMMETRIC, compensator, TICKS)
}

/// A transmission's friction beyond its model's: the direction factor and
/// the load coefficient of [`Plant`].
#[derive(Clone, Copy)]
struct Transmission {
    asymmetry: f32,
    load: f32,
}

const SYMMETRIC: Transmission = Transmission {
    asymmetry: 0.0,
    load: 0.0,
};

/// A geared joint's: 20 % more friction forward than backward (as measured
/// offsets of +0.560 / -0.584 N m and wider), growing by 15 % per N m the
/// gearbox carries.
const GEARED: Transmission = Transmission {
    asymmetry: 0.2,
    load: 0.15,
};

/// The tracking run on the geared joint: 20 s, errors over the last 10 s.
fn geared_run<C: Compensation<f32>>(compensator: Compensator<f32, C>) -> Errors {
    let Ok(plant) = ACTUAL.build::<f32>() else {
        fail("plant parameters")
    };
    run_actuator(plant, GEARED, compensator, 20_000)
}

/// The tracking run, `ticks` long, against a plant whose friction is
/// `friction` through `transmission`; errors over the last half for runs
/// longer than [`TICKS`] (after the adaptation), else over the whole run.
fn run_actuator<M: FrictionModel<f32>, C: Compensation<f32>>(
    friction: M,
    transmission: Transmission,
    compensator: Compensator<f32, C>,
    ticks: u32,
) -> Errors {
    let plant = RefCell::new(Plant {
        inertia: INERTIA,
        friction,
        z: M::State::default(),
        x: 0.0,
        v: 0.0,
        torque: 0.0,
        asymmetry: transmission.asymmetry,
        load: transmission.load,
    });
    let drive = SimDrive {
        plant: &plant,
        max_duty: 20_000,
        torque_max: TORQUE_MAX,
    };
    let encoder = SimEncoder {
        plant: &plant,
        counts_per_rad: COUNTS_PER_RAD,
    };
    let mut servo = Servo::new(drive, encoder, COUNTS_PER_RAD, TORQUE_MAX, compensator);
    // the tick's samples reach the statistics through the telemetry queue
    // (capacity N - 1 in heapless 0.9)
    let mut queue: Queue<Sample, { telemetry::CAPACITY + 1 }> = Queue::new();
    let (producer, mut consumer) = queue.split();
    let mut sender = Sender::new(producer);
    let mut stats = Stats::default();
    let wt = 2.0 * core::f32::consts::PI * FREQUENCY;
    let settled = if ticks > TICKS { ticks / 2 } else { 0 };
    let mut skipped = 0;
    for k in 0..ticks {
        let t = k as f32 * H;
        let (s, c) = (libm::sinf(wt * t), libm::cosf(wt * t));
        let (x_ref, v_ref, a_ref) = (AMPLITUDE * s, AMPLITUDE * wt * c, -AMPLITUDE * wt * wt * s);
        let r = Setpoint {
            x: x_ref,
            v: v_ref,
            a: a_ref,
        };
        let x = match servo.tick(r) {
            Ok(x) => x,
            Err(e) => {
                defmt::error!("servo error: {}", e);
                fail("servo");
            }
        };
        // the control tick's side: enqueue, never wait
        if k >= settled {
            sender.send(Sample { error: x - x_ref });
        } else {
            skipped += 1;
        }
        plant.borrow_mut().advance(H, SUBSTEPS);
        // the logging loop's side, at its own pace
        if k % telemetry::DRAIN_EVERY == telemetry::DRAIN_EVERY - 1 {
            stats.drain(&mut consumer);
        }
    }
    stats.drain(&mut consumer);
    if stats.count + sender.overflows + skipped != ticks {
        fail("telemetry lost samples without counting them");
    }
    Errors {
        rms: stats.rms(),
        max: stats.max,
        overflows: sender.overflows,
    }
}

/// Commissions the plant: the core's routine ticked in the control loop
/// (encoder read -> `Commissioning::tick` -> `SetDutyCycle`) against the
/// same simulated axis the servo runs on, from rest, then the fit. Logs the
/// phases and plateaus as they pass; fails on an abort, a refused result,
/// or a run beyond its window or its duration.
fn commission() -> Commissioned {
    let settings = commissioning();
    let Ok(routine) = settings.build::<f32>() else {
        fail("commissioning settings")
    };
    let Ok(friction) = ACTUAL.build::<f32>() else {
        fail("plant parameters")
    };
    let plant = RefCell::new(Plant {
        inertia: INERTIA,
        friction,
        z: LuGreState::default(),
        x: 0.0,
        v: 0.0,
        torque: 0.0,
        asymmetry: 0.0,
        load: 0.0,
    });
    let mut drive = SimDrive {
        plant: &plant,
        max_duty: 20_000,
        torque_max: TORQUE_MAX,
    };
    let mut encoder = SimEncoder {
        plant: &plant,
        counts_per_rad: COUNTS_PER_RAD,
    };
    let max = drive.max_duty_cycle();
    let mut state = CommissioningState::default();
    // the routine stops itself at its duration: two more ticks are a bug
    let most = libm::ceil(settings.duration / settings.servo.h) as u32 + 2;
    let (mut widest, mut shown) = (0.0f32, (CommissioningPhase::Breakaway, 0u8));
    defmt::info!("commissioning: break-away ramps");
    for _ in 0..most {
        let Ok(counts) = encoder.read_counts();
        let x = counts as f32 / COUNTS_PER_RAD;
        widest = widest.max(libm::fabsf(x));
        let tick = routine.tick(&mut state, x);
        let Ok(()) = drive.set_duty_cycle(servo::duty(tick.command, TORQUE_MAX, max));
        if (tick.phase, tick.plateaus) != shown {
            shown = (tick.phase, tick.plateaus);
            defmt::info!(
                "commissioning: {} after {=f32} s, {=u8} plateaus",
                tick.phase,
                state.ticks() as f32 * H,
                tick.plateaus
            );
        }
        if matches!(
            tick.phase,
            CommissioningPhase::Done | CommissioningPhase::Aborted
        ) {
            break;
        }
        plant.borrow_mut().advance(H, SUBSTEPS);
    }
    let seconds = state.ticks() as f32 * H;
    defmt::info!(
        "commissioning: {=f32} s of plant time, widest excursion {=f32} rad (window {=f64})",
        seconds,
        widest,
        settings.travel
    );
    if f64::from(widest) > settings.travel || f64::from(seconds) > settings.duration {
        fail("commissioning left its window or ran over its duration");
    }
    for p in routine.plateau_points(&state).into_iter().flatten() {
        defmt::info!(
            "commissioning plateau: v {=f64} rad/s, F {=f64} N m, steady {=bool}",
            p.speed,
            p.force,
            p.steady
        );
    }
    match routine.result(&state) {
        Ok(r) => r,
        Err(e) => {
            defmt::error!("commissioning refused: {}", e);
            fail("commissioning")
        }
    }
}

/// Checks the commissioned parameters against the plant's (issue 33's
/// bounds: `fc` and `sigma2` within 5 %; `fs` within 5 % and `vs` within
/// 20 % where the run says it identified the Stribeck branch, `sigma0`
/// within 30 % where it says it identified the stiffness; `sigma1` and what
/// was not identified reported against the same bounds, not enforced).
/// True when the enforced bounds hold.
///
/// On this plant the PD loop cannot hold the Stribeck branch (its damping
/// is below the branch's falling slope), so `fs` is the routine's fallback,
/// the break-away level of its command ramp, which LuGre's creep under the
/// ramp keeps below `fs`: the guide's cost page gives the figure.
fn parameters_hold(r: &Commissioned) -> bool {
    let (m, t, id) = (r.model, ACTUAL, r.identified);
    let rows = [
        // (name, commissioned, plant, identified, bound): fc and
        // sigma2 are enforced whatever the run says, the plant has both
        ("fc", m.curve.fc, t.curve.fc, true, 0.05),
        ("fs", m.curve.fs, t.curve.fs, id.stribeck, 0.05),
        ("sigma2", m.sigma2, t.sigma2, true, 0.05),
        ("vs", m.curve.vs, t.curve.vs, id.stribeck, 0.2),
        (
            "exponent",
            m.curve.exponent,
            t.curve.exponent,
            id.stribeck,
            f64::INFINITY,
        ),
        ("sigma0", m.sigma0, t.sigma0, id.stiffness, 0.3),
        ("sigma1", m.sigma1, t.sigma1, id.damping, f64::INFINITY),
    ];
    let mut hold = true;
    for (name, got, truth, identified, bound) in rows {
        let error = (got - truth) / truth;
        let within = libm::fabs(error) <= bound;
        let enforced = identified && bound.is_finite();
        hold &= within || !enforced;
        let verdict = match (identified, enforced, within) {
            (_, true, true) => "ok",
            (_, true, false) => "MISSED",
            (true, false, _) => "identified, no bound in the issue (reported)",
            (false, _, true) => "not identified, within (reported)",
            (false, _, false) => "not identified, outside (reported, not enforced)",
        };
        defmt::info!(
            "commissioned {=str}: {=f64} (plant {=f64}, error {=f64} %), bound {=f64} %: {=str}",
            name,
            got,
            truth,
            100.0 * error,
            100.0 * bound,
            verdict
        );
    }
    defmt::info!(
        "commissioned: identified {}, fit residual {=f64} % of the friction, speeds {=f64} to {=f64} rad/s, {=u8} plateaus fitted, break-away {=f64} / {=f64} N m",
        id,
        100.0 * r.residual,
        r.speed_range[0],
        r.speed_range[1],
        r.plateaus,
        r.breakaway[0],
        r.breakaway[1]
    );
    hold
}

/// SysTick ticks spent by `f`, `n` times (counting down, 24 bits).
fn ticks(n: u32, mut f: impl FnMut()) -> u32 {
    let start = SYST::get_current();
    for _ in 0..n {
        f();
    }
    start.wrapping_sub(SYST::get_current()) & 0x00FF_FFFF
}

/// Instructions per call of each model's step, from SysTick under QEMU's
/// `-icount shift=0` (time advances with executed instructions). SysTick
/// ticks per instruction are calibrated with a loop of 16 NOPs against the
/// same empty loop. Velocities sweep a sine through zero, as in the host
/// benchmark.
fn count_instructions(
    model: &LuGre<f32>,
    observer: &Observer<LuGre<f32>, f32>,
    model_at: &LuGreFixedStep<f32>,
    observer_fixed: &Observer<LuGreFixedStep<f32>, f32>,
    servo: &LuGreServo<f32>,
) {
    const N: u32 = 1024;
    let with_loop = ticks(N, || {
        for _ in 0..16 {
            black_box(());
        }
    });
    let nops = ticks(N, || {
        for _ in 0..16 {
            cortex_m::asm::nop();
        }
    });
    let per_insn = (nops.saturating_sub(with_loop)) as f32 / (16 * N) as f32;
    if per_insn <= 0.0 {
        defmt::warn!("SysTick did not advance with instructions (run QEMU with -icount shift=0)");
        return;
    }
    let mut vs = [0.0f32; 64];
    for (k, v) in vs.iter_mut().enumerate() {
        *v = 0.01 * libm::sinf(k as f32 * 0.1963);
    }
    let mut i = 0usize;
    let empty = ticks(N, || {
        i = (i + 1) & 63;
        black_box(vs.get(i));
    });
    let per_call = |t: u32| t.saturating_sub(empty) as f32 / N as f32 / per_insn;
    fn measure<M: FrictionModel<f32>>(m: &M, vs: &[f32; 64]) -> u32 {
        let mut s = M::State::default();
        let mut i = 0usize;
        ticks(1024, || {
            i = (i + 1) & 63;
            black_box(m.step(&mut s, black_box(vs[i]), black_box(1e-3)));
        })
    }
    let mut z = LuGreState::default();
    let obs = ticks(N, || {
        i = (i + 1) & 63;
        black_box(observer.step(&mut z, black_box(vs[i]), black_box(1e-5), black_box(1e-3)));
    });
    let mut w = LuGreFixedStepState::default();
    let at = ticks(N, || {
        i = (i + 1) & 63;
        black_box(FixedStepModel::step(model_at, &mut w, black_box(vs[i])));
    });
    let mut w = LuGreFixedStepState::default();
    let obs_at = ticks(N, || {
        i = (i + 1) & 63;
        black_box(observer_fixed.step_fixed(&mut w, black_box(vs[i]), black_box(1e-5)));
    });
    // one full servo tick (observer + PID): positions 1 mrad around a sine
    // whose differences sweep the velocity through zero, reference 10 µrad off
    let mut xs = [0.0f32; 64];
    for (k, x) in xs.iter_mut().enumerate() {
        *x = 1e-3 * libm::sinf(k as f32 * 0.1963);
    }
    let mut st = CompensatorState::default();
    let tick = ticks(N, || {
        i = (i + 1) & 63;
        let x = xs[i];
        let r = Setpoint {
            x: x + 1e-5,
            v: vs[i],
            a: 0.0,
        };
        black_box(servo.tick(&mut st, black_box(x), black_box(r)));
    });
    let curve = NOMINAL.curve;
    let (Ok(dahl), Ok(ep), Ok(reset), Ok(bristle)) = (
        DahlParams {
            sigma: NOMINAL.sigma0,
            fc: curve.fc,
            delta: 1.0,
            sigma2: NOMINAL.sigma2,
        }
        .build::<f32>(),
        ElastoPlasticParams {
            lugre: NOMINAL,
            z_ba: 0.5 * curve.fc / NOMINAL.sigma0,
        }
        .build::<f32>(),
        ResetIntegratorParams {
            sigma0: NOMINAL.sigma0,
            sigma1: NOMINAL.sigma1,
            z0: curve.fc / NOMINAL.sigma0,
            stiction: 0.2,
            curve: None,
        }
        .build::<f32>(),
        BristleParams {
            sigma0: NOMINAL.sigma0 / 8.0,
            delta_s: 3.0 * curve.fc / NOMINAL.sigma0,
            seed: 1,
        }
        .build::<f32, 8>(),
    ) else {
        fail("model parameters")
    };
    // the elasto-plastic worst case: every step starts at z_ba (0.99 Fc/sigma0)
    // and slides 100 widths of its transition zone, so it runs every RK4
    // sub-step and the tail
    let z_ba = 0.99 * curve.fc / NOMINAL.sigma0;
    let Ok(narrow) = (ElastoPlasticParams {
        lugre: NOMINAL,
        z_ba,
    })
    .build::<f32>() else {
        fail("model parameters")
    };
    // GMS and Xiong with 4 elements on the nominal curve: stiffnesses 20 to
    // 130 N m/rad summing to sigma0 = 260, weights 0.4/0.3/0.2/0.1, damping
    // (Xiong: viscosity) sharing sigma1 = 0.6 in proportion to stiffness
    // (sigma1_i / k_i = 2.3 ms), GMS slip time constants alpha_i Fc / C of
    // 1.4 to 5.6 ms (C = 20 N m/s), Xiong lag tau = 10 ms
    let ks = [20.0, 40.0, 70.0, 130.0];
    let weights = [0.4, 0.3, 0.2, 0.1];
    let damping = |k: f64| NOMINAL.sigma1 * k / NOMINAL.sigma0;
    let mut gms_elements = [GmsElement::default(); 4];
    let mut xiong_elements = [XiongElement::default(); 4];
    for (((g, x), &k), &w) in gms_elements
        .iter_mut()
        .zip(xiong_elements.iter_mut())
        .zip(&ks)
        .zip(&weights)
    {
        *g = GmsElement {
            k,
            alpha: w,
            sigma1: damping(k),
        };
        *x = XiongElement {
            k,
            sigma: damping(k),
            lambda: w,
        };
    }
    let (Ok(gms), Ok(xiong)) = (
        GmsParams {
            curve,
            sigma2: NOMINAL.sigma2,
            c: 20.0,
            elements: gms_elements,
        }
        .build::<f32>(),
        XiongParams {
            curve,
            tau: 0.01,
            sigma2: NOMINAL.sigma2,
            elements: xiong_elements,
        }
        .build::<f32>(),
    ) else {
        fail("model parameters")
    };
    // the GMS worst case: v alternates between +-50 rad/s, so every element
    // reverses every step, sticks, reaches its bound inside the step (k |v| h
    // = 1 to 6.5 N m against at most 2 alpha_i Fs = 0.26 N m of room) and
    // slips for the rest of it (exact instant and exponential relaxation)
    let mut sg = GmsState::<f32, 4>::default();
    for k in 0..4 {
        let (v, mode) = if k % 2 == 0 {
            (50.0, GmsSlipMode::Forward)
        } else {
            (-50.0, GmsSlipMode::Backward)
        };
        gms.step(&mut sg, v, 1e-3);
        if sg.mode != [mode; 4] {
            fail("GMS worst case: not every element slips");
        }
    }
    let mut vw = 50.0f32;
    let gms_worst = ticks(N, || {
        i = (i + 1) & 63;
        black_box(vs.get(i));
        vw = -vw;
        black_box(gms.step(&mut sg, black_box(vw), black_box(1e-3)));
    });
    let mut zw = LuGreState::default();
    let ep_worst = ticks(N, || {
        i = (i + 1) & 63;
        black_box(vs.get(i));
        zw.z = black_box(z_ba as f32);
        black_box(narrow.step(&mut zw, black_box(1.0), black_box(1e-3)));
    });
    // Leuven with a memory of 8 on the nominal curve (initial stiffness
    // Fs/xs = sigma0); worst case: a full memory of nested reversals, and a
    // step that reverses (a push into the full memory: drop the oldest,
    // O(M) shift) and passes every remaining point (6 pops) before solving
    let Ok(leuven) = leuven_nominal().build::<f32, 8>() else {
        fail("Leuven parameters")
    };
    let xs = leuven_nominal().xs as f32;
    let mut nested = LeuvenState::<f32, 8>::default();
    let mut amp = 0.8 * xs;
    leuven.step(&mut nested, 1.0, amp);
    for _ in 0..8 {
        amp *= 0.8;
        leuven.step(&mut nested, -1.0, amp);
        amp *= 0.8;
        leuven.step(&mut nested, 1.0, amp);
    }
    let mut check = nested;
    leuven.step(&mut check, -xs / 1e-3, 1e-3);
    if nested.memory().len() != 8 || check.memory().len() > 1 {
        fail("Leuven worst case: memory not full, or not wiped in one step");
    }
    let mut sl = nested;
    let leuven_worst = ticks(N, || {
        i = (i + 1) & 63;
        black_box(vs.get(i));
        sl = black_box(nested);
        black_box(leuven.step(&mut sl, black_box(-xs / 1e-3), black_box(1e-3)));
    });
    let copy_only = ticks(N, || {
        i = (i + 1) & 63;
        black_box(vs.get(i));
        sl = black_box(nested);
        black_box(&sl);
    });
    defmt::info!("SysTick ticks per instruction: {=f32}", per_insn);
    for (name, t) in [
        ("LuGre", measure(model, &vs)),
        ("LuGre observer", obs),
        ("LuGre fixed-step", at),
        ("LuGre fixed-step observer", obs_at),
        ("servo tick (fixed-step observer + PID)", tick),
        ("Dahl", measure(&dahl, &vs)),
        ("elasto-plastic", measure(&ep, &vs)),
        ("elasto-plastic worst case", ep_worst),
        ("reset integrator", measure(&reset, &vs)),
        ("bristle N=8", measure(&bristle, &vs)),
        ("GMS N=4", measure(&gms, &vs)),
        ("GMS N=4 worst case", gms_worst),
        ("Xiong N=4", measure(&xiong, &vs)),
        ("Leuven M=8", measure(&leuven, &vs)),
        (
            "Leuven M=8 worst case (state copy excluded)",
            leuven_worst.saturating_sub(copy_only.saturating_sub(empty)),
        ),
    ] {
        defmt::info!(
            "instructions per step (f32, QEMU icount): {=str} {=f32}",
            name,
            per_call(t)
        );
    }
}

fn fail(what: &str) -> ! {
    defmt::error!("failed: {=str}", what);
    debug::exit(EXIT_FAILURE);
    loop {
        cortex_m::asm::nop();
    }
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

    if !telemetry::self_check() {
        fail("telemetry queue self-check");
    }

    // commissioning first: the routine identifies the plant, then the
    // servo compensates with the result
    let commissioned = commission();
    let parameters_ok = parameters_hold(&commissioned);

    // the loop runs at one rate: the fixed-step form, built for H
    let (Ok(model), Ok(model_at), Ok(coulomb)) = (
        NOMINAL.build::<f32>(),
        NOMINAL.build_fixed_step::<f32>(H as f64),
        CoulombViscousParams {
            fc: NOMINAL.curve.fc,
            sigma2: NOMINAL.sigma2,
        }
        .build::<f32>(),
    ) else {
        fail("controller parameters")
    };
    let (Ok(observer), Ok(observer_fixed)) = (
        Observer::new(model, OBSERVER_GAIN),
        Observer::new(model_at, OBSERVER_GAIN),
    ) else {
        fail("observer gain")
    };
    let p = controller();
    let (Ok(c_none), Ok(c_coul), Ok(c_obs), Ok(c_plain)) = (
        p.build::<f32, _>(NoCompensation),
        p.build(FeedForward(coulomb)),
        p.build(FixedPeriod(observer_fixed)),
        p.build(FixedPeriod(observer_fixed.with_damping(false))),
    ) else {
        fail("controller gains")
    };

    count_instructions(&model, &observer, &model_at, &observer_fixed, &c_obs);

    let Ok(leuven) = leuven_nominal().build::<f32, 8>() else {
        fail("Leuven parameters")
    };
    let Ok(leuven_observer) = Observer::new(leuven, OBSERVER_GAIN) else {
        fail("observer gain")
    };
    let Ok(c_leuven) = p.build(leuven_observer) else {
        fail("controller gains")
    };

    let none = run(c_none);
    // the commissioned model's observer against the same observer on the
    // plant's exact model (issue 33: within 2x its error)
    let (Ok(exact_at), Ok(commissioned_at)) = (
        ACTUAL.build_fixed_step::<f32>(H as f64),
        commissioned.model.build_fixed_step::<f32>(H as f64),
    ) else {
        fail("exact or commissioned model")
    };
    let (Ok(exact_observer), Ok(commissioned_observer)) = (
        Observer::new(exact_at, OBSERVER_GAIN),
        Observer::new(commissioned_at, OBSERVER_GAIN),
    ) else {
        fail("observer gain")
    };
    let (Ok(c_exact), Ok(c_commissioned)) = (
        p.build(FixedPeriod(exact_observer)),
        p.build(FixedPeriod(commissioned_observer)),
    ) else {
        fail("controller gains")
    };
    let exact = run(c_exact);
    let with_commissioned = run(c_commissioned);
    let coul = run(c_coul);
    let obs_damped = run(c_obs);
    let obs_plain = run(c_plain);
    let obs_leuven = run(c_leuven);
    // a Leuven plant (M = 8) on the plant's LuGre curve, xs = Fs / sigma0,
    // against no compensation and the nominal Leuven observer
    let Ok(leuven_plant) = LeuvenParams {
        curve: ACTUAL.curve,
        sigma1: ACTUAL.sigma1,
        sigma2: ACTUAL.sigma2,
        n: 2.0,
        xs: ACTUAL.curve.fs / ACTUAL.sigma0,
    }
    .build::<f32, 8>() else {
        fail("Leuven plant parameters")
    };
    let (Ok(c_none2), Ok(c_leuven2)) =
        (p.build::<f32, _>(NoCompensation), p.build(leuven_observer))
    else {
        fail("controller gains")
    };
    let leuven_none = run_on(leuven_plant, c_none2);
    let leuven_obs = run_on(leuven_plant, c_leuven2);
    // a plant whose friction has drifted to 1.5x (warm-up, load, wear: the
    // actual set with every force term scaled) against the fixed observer
    // and the θ-adaptive one, both from the nominal model
    let drifted = LuGreParams {
        curve: StribeckParams {
            fc: 1.5 * ACTUAL.curve.fc,
            fs: 1.5 * ACTUAL.curve.fs,
            ..ACTUAL.curve
        },
        sigma0: 1.5 * ACTUAL.sigma0,
        sigma1: 1.5 * ACTUAL.sigma1,
        sigma2: 1.5 * ACTUAL.sigma2,
        ..ACTUAL
    };
    let (Ok(drifted_plant), Ok(adaptive)) = (
        drifted.build::<f32>(),
        adaptation().build(observer_fixed, H as f64),
    ) else {
        fail("drifted plant or adaptation parameters")
    };
    let (Ok(c_obs2), Ok(c_adaptive)) = (
        p.build(FixedPeriod(observer_fixed)),
        p.build(FixedPeriod(adaptive)),
    ) else {
        fail("controller gains")
    };
    let drift_obs = run_on(drifted_plant, c_obs2);
    let drift_adaptive = run_on(drifted_plant, c_adaptive);
    // a geared joint (friction 1.2x forward, 0.8x backward, growing with the
    // torque carried) for 20 s, errors over the last 10 s: no compensation,
    // the fixed observer, and the per-parameter adaptive observer under its
    // supervisor (ParameterAdaptiveServo), all from the nominal model
    let (Ok(law), Ok(map)) = (
        parameter_adaptation().build_fixed_step::<f32>(&p),
        fallback().build::<f32>(),
    ) else {
        fail("per-parameter adaptation or fallback parameters")
    };
    let Ok(supervised) = supervisor().build(law, map, &p) else {
        fail("supervisor parameters")
    };
    let (Ok(c_none3), Ok(c_obs3), Ok(c_param)) = (
        p.build::<f32, _>(NoCompensation),
        p.build(FixedPeriod(observer_fixed)),
        p.build(supervised),
    ) else {
        fail("controller gains")
    };
    let c_param: ParameterAdaptiveServo<f32> = c_param;
    let geared_none = geared_run(c_none3);
    let geared_obs = geared_run(c_obs3);
    let geared_param = geared_run(c_param);
    for (name, e) in [
        ("no compensation", &none),
        ("Coulomb + viscous feed-forward (measured v)", &coul),
        ("LuGre observer", &obs_damped),
        ("LuGre observer without sigma1 dz/dt", &obs_plain),
        ("LuGre observer, the plant's exact model", &exact),
        ("LuGre observer, the commissioned model", &with_commissioned),
        ("Leuven observer (M = 8) on the LuGre plant", &obs_leuven),
        ("Leuven plant: no compensation", &leuven_none),
        ("Leuven plant: Leuven observer (M = 8)", &leuven_obs),
        ("friction drifted to 1.5x: LuGre observer", &drift_obs),
        (
            "friction drifted to 1.5x: adaptive LuGre observer",
            &drift_adaptive,
        ),
        ("geared joint: no compensation", &geared_none),
        ("geared joint: LuGre observer", &geared_obs),
        (
            "geared joint: per-parameter adaptive observer, supervised",
            &geared_param,
        ),
    ] {
        defmt::info!(
            "{=str}: rms error {=f32} mrad, max {=f32} mrad",
            name,
            1e3 * e.rms,
            1e3 * e.max
        );
        if e.overflows > 0 {
            defmt::error!(
                "{=str}: {=u32} telemetry samples lost to a full queue",
                name,
                e.overflows
            );
            debug::exit(EXIT_FAILURE);
        }
    }
    defmt::info!(
        "telemetry: every tick's sample through a heapless spsc queue of {=usize}, drained every {=u32} ticks, none lost",
        telemetry::CAPACITY,
        telemetry::DRAIN_EVERY
    );
    let best = obs_damped.rms.min(obs_plain.rms);
    defmt::info!(
        "observer / uncompensated rms ratio: {=f32}",
        best / none.rms
    );
    defmt::info!(
        "commissioned / exact observer rms ratio: {=f32} (bound 2)",
        with_commissioned.rms / exact.rms
    );
    if !parameters_ok {
        defmt::error!("the commissioned parameters missed their bounds");
        debug::exit(EXIT_FAILURE);
    }
    // a NaN error fails too
    let tracks = with_commissioned.rms <= 2.0 * exact.rms;
    if !tracks {
        defmt::error!(
            "the commissioned observer missed its bound (2x the exact model's rms error)"
        );
        debug::exit(EXIT_FAILURE);
    }
    if obs_leuven.rms >= none.rms || leuven_obs.rms >= leuven_none.rms {
        defmt::error!("the Leuven observer did not reduce the tracking error");
        debug::exit(EXIT_FAILURE);
    }
    // the geared joint's bound: the fixed observer, with a model that knows
    // neither the direction nor the load, is left at several mrad; the
    // per-parameter law must learn both (0.5 mrad RMS, a tenth of the
    // fixed observer's)
    if !(geared_param.rms <= 0.5e-3 && geared_param.rms <= 0.1 * geared_obs.rms) {
        defmt::error!(
            "the per-parameter adaptive observer missed its bound on the geared joint (0.5 mrad, 0.1x the fixed observer)"
        );
        debug::exit(EXIT_FAILURE);
    }
    if drift_adaptive.rms >= drift_obs.rms {
        defmt::error!("the adaptive observer did not beat the fixed one on the drifted plant");
        debug::exit(EXIT_FAILURE);
    }
    if best < none.rms {
        debug::exit(EXIT_SUCCESS);
    } else {
        defmt::error!("compensation did not reduce the tracking error");
        debug::exit(EXIT_FAILURE);
    }
    loop {
        cortex_m::asm::nop();
    }
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    fail("panic")
}
