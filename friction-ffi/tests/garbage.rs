//! Garbage objects, as a drive's C code that forgot a constructor hands
//! them over: every object type filled with every byte value, with 100,000
//! random byte patterns, and with 10,000 random patterns carrying the type's
//! own tag with a kind no constructor writes (the first 4 bytes, where a
//! constructor writes the tag plus its kind), through every call of
//! the ABI that reads an object. A call on garbage must return a status
//! that is not `FRICTION_OK`, and must not crash, abort or hang.
//!
//! Each call's sweep runs in a child process (this test binary run again
//! with `FRICTION_GARBAGE` set), so that a crash is counted rather than
//! taking the test runner down; after a crash the parent runs the rest of
//! the sweep again, from the pattern after the one that crashed.
//! Under Miri (which cannot spawn processes) a smaller sweep runs in
//! process: there undefined behaviour is an error, not a crash.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)]

use friction_ffi::*;
use friction_status::*;
use std::io::Write;

/// Patterns per call: the 256 fills, then `RANDOM` random patterns, then
/// `TAGGED` random patterns with the object's tag.
const FILLS: u64 = 256;
const RANDOM: u64 = 100_000;
const TAGGED: u64 = 10_000;

/// A call that reads an object: its name, the object's size and tag, and
/// the call with the object built from the given bytes.
struct Call {
    name: &'static str,
    bytes: usize,
    tag: u32,
    run: fn(&[u8]) -> friction_status,
    /// A constructor writing into the garbage: it never reads its `out`,
    /// so `FRICTION_OK` is what it must return (the promise that any
    /// caller-allocated memory can be initialised); every other call must
    /// refuse the garbage.
    writes_only: bool,
}

/// The object's words from `bytes` (native byte order, as C's memory holds them).
fn words<const N: usize>(bytes: &[u8]) -> [u64; N] {
    std::array::from_fn(|i| u64::from_ne_bytes(bytes[8 * i..8 * i + 8].try_into().unwrap()))
}

fn lugre() -> friction_lugre_params {
    friction_lugre_params {
        curve: friction_stribeck {
            fc: 1.0,
            fs: 1.5,
            vs: 1e-3,
            exponent: 2.0,
        },
        sigma0: 1e5,
        sigma1: 316.0,
        sigma2: 0.4,
        vd: 0.0,
    }
}

fn servo_params() -> friction_servo_params {
    friction_servo_params {
        h: 1e-3,
        kp: 9.08,
        ki: 0.0,
        kd: 0.289,
        inertia: 0.0023,
        torque_constant: 1.0,
        limit: 5.0,
    }
}

const ADAPTIVE: friction_adaptive_params = friction_adaptive_params {
    gamma: 50.0,
    gamma_derivative: 0.0,
    leakage: 0.0,
    theta0: 1.0,
    theta_min: 0.5,
    theta_max: 2.0,
};

/// The per-parameter adaptive observer around [`lugre`], its supervisor
/// and fallback: what the per-parameter servo constructor takes.
fn parameter_adaptive() -> friction_parameter_adaptive_params {
    let mut p = friction_parameter_adaptive_params {
        model: lugre(),
        observer_gain: 0.0,
        rate: 0.0,
        derivative_weight: 0.0,
        leakage: 0.0,
        box_factor: 0.0,
        dead_zone: 0.0,
        min_speed: 0.0,
        speed: 0.0,
        load: 0.0,
        load_max: 0.0,
        exact_step: 0,
    };
    assert_eq!(
        friction_parameter_adaptive_defaults(Some(&lugre()), 20.0, Some(&mut p)),
        FRICTION_OK
    );
    p
}

fn supervisor() -> friction_supervisor_params {
    let mut p = friction_supervisor_params {
        window: 0.0,
        memory: 0.0,
        ratio: 0.0,
        warm_up: 0.0,
        retry: 0.0,
        tolerance: 0.0,
    };
    assert_eq!(friction_supervisor_defaults(Some(&mut p)), FRICTION_OK);
    p
}

const FALLBACK: friction_coulomb_viscous_params = friction_coulomb_viscous_params {
    fc: 1.0,
    sigma2: 0.4,
};

/// A valid model in `$m`, built in place: an initialised object holds the
/// value's padding, which is not data, so it is never moved as a value
/// (Miri: a copy of a `u64` with an uninitialised byte is undefined behaviour).
macro_rules! valid_model {
    ($m:ident, $ty:ident, $words:expr, $init:ident) => {
        let mut $m = $ty {
            opaque: [0; $words],
        };
        assert_eq!(
            $init(Some(&mut $m), Some(&lugre()), 1e-3, None),
            FRICTION_OK
        );
    };
}

macro_rules! model_calls {
    ($ty:ident, $words:expr, $tag:expr, $scalar:ty, $step:ident, $reset:ident,
     $obs:ident, $obs_words:expr, $servo:ident, $servo_words:expr, $servo_init:ident,
     $observer_init:ident, $init:ident) => {
        [
            Call {
                name: concat!(stringify!($step)),
                bytes: 8 * $words,
                tag: $tag,
                run: |b| {
                    let mut m = $ty { opaque: words(b) };
                    let mut f: $scalar = 0.0;
                    $step(Some(&mut m), 1e-3, 1e-3, Some(&mut f))
                },
                writes_only: false,
            },
            Call {
                name: stringify!($reset),
                bytes: 8 * $words,
                tag: $tag,
                run: |b| $reset(Some(&mut $ty { opaque: words(b) })),
                writes_only: false,
            },
            Call {
                name: concat!(stringify!($observer_init), " (model)"),
                bytes: 8 * $words,
                tag: $tag,
                run: |b| {
                    let mut o = $obs {
                        opaque: [0; $obs_words],
                    };
                    $observer_init(
                        Some(&mut o),
                        Some(&$ty { opaque: words(b) }),
                        100.0,
                        true,
                        None,
                    )
                },
                writes_only: false,
            },
            Call {
                name: concat!(stringify!($servo_init), " (model)"),
                bytes: 8 * $words,
                tag: $tag,
                run: |b| {
                    let mut s = $servo {
                        opaque: [0; $servo_words],
                    };
                    let m = $ty { opaque: words(b) };
                    $servo_init(
                        Some(&mut s),
                        Some(&servo_params()),
                        Some(&m),
                        200.0,
                        None,
                        None,
                    )
                },
                writes_only: false,
            },
            Call {
                name: concat!(stringify!($servo_init), " (model, adaptive)"),
                bytes: 8 * $words,
                tag: $tag,
                run: |b| {
                    let mut s = $servo {
                        opaque: [0; $servo_words],
                    };
                    let m = $ty { opaque: words(b) };
                    $servo_init(
                        Some(&mut s),
                        Some(&servo_params()),
                        Some(&m),
                        200.0,
                        Some(&ADAPTIVE),
                        None,
                    )
                },
                writes_only: false,
            },
            Call {
                name: concat!(stringify!($init), " (out)"),
                bytes: 8 * $words,
                tag: $tag,
                run: |b| {
                    let mut m = $ty { opaque: words(b) };
                    let status = $init(Some(&mut m), Some(&lugre()), 1e-3, None);
                    let mut f: $scalar = 0.0;
                    // the object is now a model: it steps
                    match $step(Some(&mut m), 1e-3, 1e-3, Some(&mut f)) {
                        FRICTION_OK => status,
                        other => other,
                    }
                },
                writes_only: true,
            },
            Call {
                name: concat!(stringify!($observer_init), " (out)"),
                bytes: 8 * $obs_words,
                tag: $tag + 0x0202_0202,
                run: |b| {
                    let mut o = $obs { opaque: words(b) };
                    valid_model!(m, $ty, $words, $init);
                    $observer_init(Some(&mut o), Some(&m), 100.0, true, None)
                },
                writes_only: true,
            },
            Call {
                name: concat!(stringify!($servo_init), " (out)"),
                bytes: 8 * $servo_words,
                tag: $tag + 0x0404_0404,
                run: |b| {
                    let mut s = $servo { opaque: words(b) };
                    valid_model!(m, $ty, $words, $init);
                    $servo_init(
                        Some(&mut s),
                        Some(&servo_params()),
                        Some(&m),
                        200.0,
                        None,
                        None,
                    )
                },
                writes_only: true,
            },
        ]
    };
}

macro_rules! observer_calls {
    ($ty:ident, $words:expr, $tag:expr, $scalar:ty, $step:ident, $reset:ident) => {
        [
            Call {
                name: stringify!($step),
                bytes: 8 * $words,
                tag: $tag,
                run: |b| {
                    let mut o = $ty { opaque: words(b) };
                    let mut f: $scalar = 0.0;
                    $step(Some(&mut o), 1e-3, 1e-6, 1e-3, Some(&mut f))
                },
                writes_only: false,
            },
            Call {
                name: stringify!($reset),
                bytes: 8 * $words,
                tag: $tag,
                run: |b| $reset(Some(&mut $ty { opaque: words(b) })),
                writes_only: false,
            },
        ]
    };
}

macro_rules! servo_calls {
    ($ty:ident, $words:expr, $tag:expr, $scalar:ty, $tick:ident, $setpoint:ident,
     $out:ident, $reset:ident, $theta:ident, $estimates:ident, $estimates_ty:ident,
     $supervisor:ident, $parameter_init:ident, $retune:ident, $parameter_retune:ident,
     $external:ident, $velocity_observer:ident) => {
        [
            Call {
                name: stringify!($velocity_observer),
                bytes: 8 * $words,
                tag: $tag,
                run: |b| $velocity_observer(Some(&mut $ty { opaque: words(b) }), 50.0, None),
                writes_only: false,
            },
            Call {
                name: stringify!($external),
                bytes: 8 * $words,
                tag: $tag,
                run: |b| $external(Some(&mut $ty { opaque: words(b) }), 1.5),
                writes_only: false,
            },
            Call {
                name: stringify!($retune),
                bytes: 8 * $words,
                tag: $tag,
                run: |b| $retune(Some(&mut $ty { opaque: words(b) }), None, 200.0, None, None),
                writes_only: false,
            },
            Call {
                name: stringify!($parameter_retune),
                bytes: 8 * $words,
                tag: $tag,
                run: |b| {
                    $parameter_retune(
                        Some(&mut $ty { opaque: words(b) }),
                        Some(&parameter_adaptive()),
                        Some(&supervisor()),
                        Some(&FALLBACK),
                        None,
                    )
                },
                writes_only: false,
            },
            Call {
                name: stringify!($estimates),
                bytes: 8 * $words,
                tag: $tag,
                run: |b| {
                    let mut e = $estimates_ty {
                        fc_pos: 0.0,
                        fc_neg: 0.0,
                        stribeck: 0.0,
                        sigma2: 0.0,
                        load: 0.0,
                    };
                    $estimates(Some(&mut $ty { opaque: words(b) }), Some(&mut e))
                },
                writes_only: false,
            },
            Call {
                name: stringify!($supervisor),
                bytes: 8 * $words,
                tag: $tag,
                run: |b| {
                    let mut st = friction_supervisor_status {
                        mode: friction_mode::FRICTION_MODE_OFF,
                        switches: 0,
                        windows: 0,
                        since_switch: 0,
                    };
                    $supervisor(Some(&mut $ty { opaque: words(b) }), Some(&mut st))
                },
                writes_only: false,
            },
            Call {
                name: concat!(stringify!($parameter_init), " (out)"),
                bytes: 8 * $words,
                tag: $tag,
                run: |b| {
                    let mut s = $ty { opaque: words(b) };
                    $parameter_init(
                        Some(&mut s),
                        Some(&servo_params()),
                        Some(&parameter_adaptive()),
                        Some(&supervisor()),
                        Some(&FALLBACK),
                        None,
                    )
                },
                writes_only: true,
            },
            Call {
                name: stringify!($tick),
                bytes: 8 * $words,
                tag: $tag,
                run: |b| {
                    let mut s = $ty { opaque: words(b) };
                    let r = $setpoint {
                        x: 1e-3,
                        v: 0.0,
                        a: 0.0,
                    };
                    let mut t = $out {
                        command: 0.0,
                        friction: 0.0,
                    };
                    $tick(Some(&mut s), 0.0, r, Some(&mut t))
                },
                writes_only: false,
            },
            Call {
                name: stringify!($reset),
                bytes: 8 * $words,
                tag: $tag,
                run: |b| $reset(Some(&mut $ty { opaque: words(b) })),
                writes_only: false,
            },
            Call {
                name: stringify!($theta),
                bytes: 8 * $words,
                tag: $tag,
                run: |b| {
                    let mut theta: $scalar = 0.0;
                    $theta(Some(&mut $ty { opaque: words(b) }), Some(&mut theta))
                },
                writes_only: false,
            },
        ]
    };
}

fn commissioning_params() -> friction_commissioning_params {
    let mut p = friction_commissioning_params {
        servo: servo_params(),
        travel: 0.0,
        duration: 0.0,
        min_speed: 0.0,
        max_speed: 0.0,
        speeds: 0,
        plateau: 0.0,
        settle: 0.0,
        acceleration: 0.0,
        ramp_rate: 0.0,
        breakaway_travel: 0.0,
        resolution: 0.0,
    };
    assert_eq!(
        friction_commissioning_defaults(Some(&servo_params()), 1.0, 2.0, Some(&mut p)),
        FRICTION_OK
    );
    p
}

fn commissioned() -> friction_commissioned {
    let zero = friction_stribeck {
        fc: 0.0,
        fs: 0.0,
        vs: 0.0,
        exponent: 0.0,
    };
    friction_commissioned {
        model: friction_lugre_params {
            curve: zero,
            sigma0: 0.0,
            sigma1: 0.0,
            sigma2: 0.0,
            vd: 0.0,
        },
        fc: [0.0; 2],
        fs: [0.0; 2],
        sigma2: [0.0; 2],
        breakaway: [0.0; 2],
        identified_coulomb: 0,
        identified_stribeck: 0,
        identified_viscous: 0,
        identified_stiffness: 0,
        identified_damping: 0,
        plateaus: 0,
        residual: 0.0,
        speed_range: [0.0; 2],
        load: -1.0,
        load_torque: -1.0,
        identified_load: 0,
    }
}

macro_rules! commissioning_calls {
    ($ty:ident, $words:expr, $tag:expr, $init:ident, $tick:ident, $out:ident, $phase:ident,
     $abort:ident, $reset:ident, $result:ident) => {
        [
            Call {
                name: stringify!($tick),
                bytes: 8 * $words,
                tag: $tag,
                run: |b| {
                    let mut t = $out {
                        command: 0.0,
                        phase: 0,
                        plateaus: 0,
                    };
                    $tick(Some(&mut $ty { opaque: words(b) }), 0.0, Some(&mut t))
                },
                writes_only: false,
            },
            Call {
                name: stringify!($phase),
                bytes: 8 * $words,
                tag: $tag,
                run: |b| $phase(Some(&mut $ty { opaque: words(b) }), Some(&mut 0)),
                writes_only: false,
            },
            Call {
                name: stringify!($abort),
                bytes: 8 * $words,
                tag: $tag,
                run: |b| $abort(Some(&mut $ty { opaque: words(b) }), Some(&mut 0)),
                writes_only: false,
            },
            Call {
                name: stringify!($reset),
                bytes: 8 * $words,
                tag: $tag,
                run: |b| $reset(Some(&mut $ty { opaque: words(b) })),
                writes_only: false,
            },
            Call {
                name: stringify!($result),
                bytes: 8 * $words,
                tag: $tag,
                run: |b| {
                    let mut r = commissioned();
                    $result(Some(&mut $ty { opaque: words(b) }), Some(&mut r), None)
                },
                writes_only: false,
            },
            Call {
                name: concat!(stringify!($init), " (out)"),
                bytes: 8 * $words,
                tag: $tag,
                run: |b| {
                    let mut c = $ty { opaque: words(b) };
                    let status = $init(Some(&mut c), Some(&commissioning_params()), None);
                    let mut t = $out {
                        command: 0.0,
                        phase: 0,
                        plateaus: 0,
                    };
                    // the object is now a routine: it ticks
                    match $tick(Some(&mut c), 0.0, Some(&mut t)) {
                        FRICTION_OK => status,
                        other => other,
                    }
                },
                writes_only: true,
            },
        ]
    };
}

/// Every call of the ABI that reads or writes a caller's object.
fn calls() -> Vec<Call> {
    let mut all = Vec::new();
    all.extend(model_calls!(
        friction_model_f32,
        FRICTION_MODEL_F32_WORDS,
        0xB1B1_B1B1,
        f32,
        friction_model_step_f32,
        friction_model_reset_f32,
        friction_observer_f32,
        FRICTION_OBSERVER_F32_WORDS,
        friction_servo_f32,
        FRICTION_SERVO_F32_WORDS,
        friction_servo_init_f32,
        friction_observer_init_f32,
        friction_lugre_init_f32
    ));
    all.extend(model_calls!(
        friction_model_f64,
        FRICTION_MODEL_F64_WORDS,
        0xB2B2_B2B2,
        f64,
        friction_model_step_f64,
        friction_model_reset_f64,
        friction_observer_f64,
        FRICTION_OBSERVER_F64_WORDS,
        friction_servo_f64,
        FRICTION_SERVO_F64_WORDS,
        friction_servo_init_f64,
        friction_observer_init_f64,
        friction_lugre_init_f64
    ));
    all.extend(observer_calls!(
        friction_observer_f32,
        FRICTION_OBSERVER_F32_WORDS,
        0xB3B3_B3B3,
        f32,
        friction_observer_step_f32,
        friction_observer_reset_f32
    ));
    all.extend(observer_calls!(
        friction_observer_f64,
        FRICTION_OBSERVER_F64_WORDS,
        0xB4B4_B4B4,
        f64,
        friction_observer_step_f64,
        friction_observer_reset_f64
    ));
    all.extend(servo_calls!(
        friction_servo_f32,
        FRICTION_SERVO_F32_WORDS,
        0xB5B5_B5B5,
        f32,
        friction_servo_tick_f32,
        friction_setpoint_f32,
        friction_tick_f32,
        friction_servo_reset_f32,
        friction_servo_theta_f32,
        friction_servo_estimates_f32,
        friction_estimates_f32,
        friction_servo_supervisor_f32,
        friction_servo_parameter_adaptive_init_f32,
        friction_servo_retune_f32,
        friction_servo_parameter_adaptive_retune_f32,
        friction_servo_set_external_torque_f32,
        friction_servo_velocity_observer_f32
    ));
    all.extend(servo_calls!(
        friction_servo_f64,
        FRICTION_SERVO_F64_WORDS,
        0xB6B6_B6B6,
        f64,
        friction_servo_tick_f64,
        friction_setpoint_f64,
        friction_tick_f64,
        friction_servo_reset_f64,
        friction_servo_theta_f64,
        friction_servo_estimates_f64,
        friction_estimates_f64,
        friction_servo_supervisor_f64,
        friction_servo_parameter_adaptive_init_f64,
        friction_servo_retune_f64,
        friction_servo_parameter_adaptive_retune_f64,
        friction_servo_set_external_torque_f64,
        friction_servo_velocity_observer_f64
    ));
    all.extend(commissioning_calls!(
        friction_commissioning_f32,
        FRICTION_COMMISSIONING_F32_WORDS,
        0xB7B7_B7B7,
        friction_commissioning_init_f32,
        friction_commissioning_tick_f32,
        friction_commissioning_command_f32,
        friction_commissioning_phase_f32,
        friction_commissioning_abort_f32,
        friction_commissioning_reset_f32,
        friction_commissioning_result_f32
    ));
    all.extend(commissioning_calls!(
        friction_commissioning_f64,
        FRICTION_COMMISSIONING_F64_WORDS,
        0xB8B8_B8B8,
        friction_commissioning_init_f64,
        friction_commissioning_tick_f64,
        friction_commissioning_command_f64,
        friction_commissioning_phase_f64,
        friction_commissioning_abort_f64,
        friction_commissioning_reset_f64,
        friction_commissioning_result_f64
    ));
    all
}

/// SplitMix64: the pattern generator (fixed seeds: every run sends the
/// same patterns, and a child restarted after a crash regenerates them).
fn splitmix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Pattern `i` of a call's sweep into `bytes`: a fill of byte `i` for
/// `i < 256`, then random bytes, then random bytes behind `tag`.
fn pattern(i: u64, tag: u32, bytes: &mut [u8]) {
    if i < FILLS {
        bytes.fill(i as u8);
        return;
    }
    let mut state = splitmix(i);
    for chunk in bytes.chunks_mut(8) {
        state = splitmix(state);
        chunk.copy_from_slice(&state.to_ne_bytes()[..chunk.len()]);
    }
    if i >= FILLS + RANDOM {
        // the tag word (friction-ffi's slot.rs: the first 32 bits, the tag
        // plus the kind of value, from 1): the bare tag (kind 0) or a kind
        // past every type's (9 or more: the servo's go to 8)
        let kind = if i % 2 == 0 {
            0
        } else {
            9 + (state >> 32) as u32 % 1000
        };
        bytes[..4].copy_from_slice(&tag.wrapping_add(kind).to_ne_bytes());
    }
}

/// Whether `status` is what the call must return on garbage.
fn refused(call: &Call, status: friction_status) -> bool {
    (status == FRICTION_OK) == call.writes_only
}

/// The child: runs patterns `start..end` of call `index`, printing `bad I
/// STATUS` for each wrong status, `at I` before each pattern when
/// `trace` (so that the parent learns which pattern crashed), and `done`.
fn child(index: usize, start: u64, end: u64, trace: bool) {
    let calls = calls();
    let call = &calls[index];
    let mut bytes = vec![0u8; call.bytes];
    let mut out = std::io::stdout().lock();
    for i in start..end {
        if trace {
            writeln!(out, "at {i}").unwrap();
            out.flush().unwrap();
        }
        pattern(i, call.tag, &mut bytes);
        let status = (call.run)(&bytes);
        if !refused(call, status) {
            writeln!(out, "bad {i} {status:?}").unwrap();
        }
    }
    writeln!(out, "done").unwrap();
}

/// What the sweep of one call found.
#[derive(Default, Debug)]
struct Found {
    crashes: Vec<u64>,
    hangs: Vec<u64>,
    bad: Vec<u64>,
    /// Patterns whose first call returned `FRICTION_OK` (the interior
    /// sweep: the garbage got past the kind checks into the core's values).
    reached: u64,
}

/// The count of tagged patterns (`FRICTION_GARBAGE_TAGGED` overrides it:
/// a build that crashes on most of them needs a process per pattern).
fn tagged() -> u64 {
    std::env::var("FRICTION_GARBAGE_TAGGED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(TAGGED)
}

/// Runs `start..end` of call `index` in a child; `None` when it finished,
/// else the pattern it crashed or hung on (traced: the parent reruns).
fn run_child(
    sweep: &Sweep,
    index: usize,
    start: u64,
    end: u64,
    trace: bool,
    found: &mut Found,
) -> Option<u64> {
    let mut child = std::process::Command::new(std::env::current_exe().unwrap())
        .args(["--exact", sweep.test, "--nocapture"])
        .env(sweep.env, format!("{index}:{start}:{end}:{trace}"))
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let mut stdout = child.stdout.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        std::io::Read::read_to_string(&mut stdout, &mut s).unwrap();
        s
    });
    let deadline = std::time::Instant::now() + sweep.limit;
    let mut hung = false;
    let exit = loop {
        if let Some(exit) = child.try_wait().unwrap() {
            break exit;
        }
        if std::time::Instant::now() > deadline {
            child.kill().unwrap();
            hung = true;
            break child.wait().unwrap();
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    };
    let output = reader.join().unwrap();
    let mut last = None;
    let mut done = false;
    for line in output.lines() {
        let mut words = line.split(' ');
        match (words.next(), words.next().and_then(|i| i.parse().ok())) {
            (Some("at"), Some(i)) => last = Some(i),
            (Some("bad"), Some(i)) => found.bad.push(i),
            (Some("done"), _) => done = true,
            (Some("reached"), Some(n)) => found.reached += n,
            _ => {}
        }
    }
    if done && exit.success() {
        return None;
    }
    // untraced: report the batch's start; the parent reruns it traced
    let at = last.unwrap_or(start);
    if trace {
        if hung {
            found.hangs.push(at);
        } else {
            found.crashes.push(at);
        }
    }
    Some(at)
}

/// A sweep run in children: the test that runs it (and, with `env` set,
/// is the child) and each child's time limit.
struct Sweep {
    test: &'static str,
    env: &'static str,
    /// A hang is a failure too: a child past this is killed and counted.
    limit: std::time::Duration,
    /// Crashes and hangs after which a job's sweep stops (reported, not
    /// waited for).
    failures: usize,
}

/// The sweep of every call over the garbage patterns: 120 s a child is
/// 20x what a whole sweep takes here.
const GARBAGE: Sweep = Sweep {
    test: "garbage_objects_get_a_status_never_a_crash",
    env: "FRICTION_GARBAGE",
    limit: std::time::Duration::from_secs(120),
    failures: 1000,
};

/// The child's job from `sweep.env`: `(index, start, end, trace)`.
fn job(sweep: &Sweep) -> Option<(usize, u64, u64, bool)> {
    let job = std::env::var(sweep.env).ok()?;
    let mut parts = job.split(':');
    let mut next = || parts.next().unwrap().to_owned();
    let (index, start, end, trace) = (next(), next(), next(), next());
    Some((
        index.parse().unwrap(),
        start.parse().unwrap(),
        end.parse().unwrap(),
        trace == "true",
    ))
}

/// One call's sweep: in one child; after a crash, traced from the
/// pattern after it.
fn sweep(index: usize) -> Found {
    sweep_in_children(&GARBAGE, index, FILLS + RANDOM + tagged())
}

/// Patterns `0..end` of job `index` of `sweep`: in one child; after a
/// crash or hang, traced from the pattern after it.
fn sweep_in_children(sweep: &Sweep, index: usize, end: u64) -> Found {
    let mut found = Found::default();
    let mut start = 0;
    let mut trace = false;
    // bounded: a build that crashes on every pattern is reported, not waited for
    while start < end && found.crashes.len() + found.hangs.len() < sweep.failures {
        match run_child(sweep, index, start, end, trace, &mut found) {
            None => break,
            Some(at) if trace => start = at + 1,
            Some(_) => {
                // rerun traced from the same start: the first run's `bad`
                // lines come again
                found.bad.clear();
                trace = true;
            }
        }
    }
    found
}

#[test]
#[cfg_attr(miri, ignore = "spawns processes; see garbage_in_process")]
fn garbage_objects_get_a_status_never_a_crash() {
    if let Some((index, start, end, trace)) = job(&GARBAGE) {
        child(index, start, end, trace);
        return;
    }
    let calls = calls();
    let patterns = FILLS + RANDOM + tagged();
    let (mut crashes, mut hangs, mut bad) = (0, 0, 0);
    for (index, call) in calls.iter().enumerate() {
        let found = sweep(index);
        println!(
            "{:45} {patterns} patterns: {} crashes, {} hangs, {} wrong statuses{}",
            call.name,
            found.crashes.len(),
            found.hangs.len(),
            found.bad.len(),
            if found.crashes.is_empty() && found.bad.is_empty() {
                String::new()
            } else {
                format!(
                    " (first crash at {:?}, first wrong at {:?})",
                    found.crashes.first(),
                    found.bad.first()
                )
            }
        );
        crashes += found.crashes.len();
        hangs += found.hangs.len();
        bad += found.bad.len();
    }
    println!(
        "total over {} calls x {patterns} patterns: {crashes} crashes, {hangs} hangs, {bad} wrong statuses",
        calls.len()
    );
    assert_eq!((crashes, hangs, bad), (0, 0, 0));
}

/// Under Miri: the fills that matter (zero, all ones, each tag's byte) and
/// four random and four tagged patterns of every call, in process (Miri
/// reports undefined behaviour as an error, which a crash-only sweep can
/// miss when the bad read happens not to crash; all 256 fills took Miri
/// over 5 minutes).
#[test]
#[cfg_attr(
    not(miri),
    ignore = "in process: for Miri; the child-process sweep covers normal runs"
)]
fn garbage_in_process() {
    for call in calls() {
        let mut bytes = vec![0u8; call.bytes];
        let some = [0x00, 0xB1, 0xB2, 0xB3, 0xB4, 0xB5, 0xB6, 0xB7, 0xB8, 0xFF]
            .into_iter()
            .chain(FILLS..FILLS + 4)
            .chain(FILLS + RANDOM..FILLS + RANDOM + 4);
        for i in some {
            pattern(i, call.tag, &mut bytes);
            let status = (call.run)(&bytes);
            assert!(
                refused(&call, status),
                "{} pattern {i}: {status:?}",
                call.name
            );
        }
    }
}

// ---------------------------------------------------------------------------
// Tag-correct objects with garbage inside: a valid object of every type and
// kind (every model, as a model, inside an observer and inside each servo
// compensation), its tag word kept and its other bytes overwritten with
// random ones, through every call that reads it. The core stores its values
// in forms every bit pattern is a value of (friction-core `src/bits.rs`), so
// that such an object gives garbage numbers and a documented status, never
// undefined behaviour, a panic (an abort across the C ABI) or a long loop.

/// Patterns over all subjects (each subject gets its share).
const INTERIOR: u64 = 100_000;

/// The sweep of the tag-correct objects: a child is one subject (about 900
/// patterns, well under a second here in the debug profile), so 10 s is a
/// hang; a subject's sweep stops at its third failure (a hang costs the
/// whole limit).
const INTERIOR_SWEEP: Sweep = Sweep {
    test: "tag_correct_objects_with_garbage_inside_never_crash",
    env: "FRICTION_INTERIOR",
    limit: std::time::Duration::from_secs(10),
    failures: 3,
};

const CURVE: friction_stribeck = friction_stribeck {
    fc: 1.0,
    fs: 1.5,
    vs: 1e-3,
    exponent: 2.0,
};

const LUGRE: friction_lugre_params = friction_lugre_params {
    curve: CURVE,
    sigma0: 1e5,
    sigma1: 316.0,
    sigma2: 0.4,
    vd: 0.0,
};

const GMS: friction_gms_params = friction_gms_params {
    curve: CURVE,
    sigma2: 0.4,
    c: 20.0,
    elements: [
        friction_gms_element {
            k: 2.5e4,
            alpha: 0.4,
            sigma1: 2.5,
        },
        friction_gms_element {
            k: 5e4,
            alpha: 0.3,
            sigma1: 5.0,
        },
        friction_gms_element {
            k: 1e5,
            alpha: 0.2,
            sigma1: 10.0,
        },
        friction_gms_element {
            k: 2e5,
            alpha: 0.1,
            sigma1: 20.0,
        },
    ],
};

const XIONG: friction_xiong_params = friction_xiong_params {
    curve: CURVE,
    tau: 0.01,
    sigma2: 0.4,
    elements: [
        friction_xiong_element {
            k: 2.5e4,
            sigma: 2.5,
            lambda: 0.4,
        },
        friction_xiong_element {
            k: 5e4,
            sigma: 5.0,
            lambda: 0.3,
        },
        friction_xiong_element {
            k: 1e5,
            sigma: 10.0,
            lambda: 0.2,
        },
        friction_xiong_element {
            k: 2e5,
            sigma: 20.0,
            lambda: 0.1,
        },
    ],
};

/// Every status a call may return, as its documentation lists them (a
/// garbage object with a right tag may pass for a built one, so `OK` is
/// among them; the constructors reading a garbage model may refuse its
/// period or what the parameters give, with the parameter statuses).
mod allowed {
    use super::friction_status::{self, *};

    pub const STEP: &[friction_status] = &[
        FRICTION_OK,
        FRICTION_NOT_INITIALISED,
        FRICTION_INPUT_REJECTED,
        FRICTION_PERIOD_MISMATCH,
    ];
    pub const RESET: &[friction_status] = &[FRICTION_OK, FRICTION_NOT_INITIALISED];
    pub const INIT: &[friction_status] = &[
        FRICTION_OK,
        FRICTION_NOT_INITIALISED,
        FRICTION_NOT_SUPPORTED,
        FRICTION_PERIOD_MISMATCH,
        FRICTION_NOT_FINITE,
        FRICTION_NOT_POSITIVE,
        FRICTION_NEGATIVE,
        FRICTION_NOT_REPRESENTABLE,
        FRICTION_UNDERFLOW,
        FRICTION_FORCE_OVERFLOW,
        FRICTION_OUT_OF_RANGE,
        FRICTION_NOT_BELOW,
    ];
    pub const TICK: &[friction_status] = &[
        FRICTION_OK,
        FRICTION_NOT_INITIALISED,
        FRICTION_INPUT_REJECTED,
    ];
    pub const THETA: &[friction_status] = &[
        FRICTION_OK,
        FRICTION_NOT_INITIALISED,
        FRICTION_NOT_SUPPORTED,
    ];
    pub const READ: &[friction_status] = &[FRICTION_OK, FRICTION_NOT_INITIALISED];
    /// A commissioning result: the fit's refusals, or a parameter status
    /// for a fitted model that does not build.
    pub const RESULT: &[friction_status] = &[
        FRICTION_OK,
        FRICTION_NOT_INITIALISED,
        FRICTION_NOT_FINISHED,
        FRICTION_ABORTED,
        FRICTION_TOO_FEW_PLATEAUS,
        FRICTION_POOR_FIT,
        FRICTION_NO_FRICTION,
        FRICTION_NOT_FINITE,
        FRICTION_NOT_POSITIVE,
        FRICTION_NEGATIVE,
        FRICTION_STATIC_BELOW_COULOMB,
        FRICTION_NOT_REPRESENTABLE,
        FRICTION_UNDERFLOW,
        FRICTION_FORCE_OVERFLOW,
        FRICTION_OUT_OF_RANGE,
        FRICTION_BELOW_ONE,
        FRICTION_NOT_BELOW,
    ];
}

/// A call on an object of type `T`: its name, the call, and the statuses
/// it may return.
type CallOf<T> = (
    &'static str,
    fn(&mut T) -> friction_status,
    &'static [friction_status],
);

/// A C object type: zeroed storage, and every call that reads one, with
/// the statuses it may return.
trait Object: Sized {
    fn zeroed() -> Self;
    fn calls() -> Vec<CallOf<Self>>;
}

macro_rules! object_types {
    ($scalar:ty, $model:ident, $observer:ident, $servo:ident, $model_step:ident,
     $model_reset:ident, $observer_init:ident, $servo_init:ident, $observer_step:ident,
     $observer_reset:ident, $tick:ident, $setpoint:ident, $out:ident, $servo_reset:ident,
     $theta:ident, $retune:ident, $lugre_init:ident) => {
        impl Object for $model {
            fn zeroed() -> Self {
                Self {
                    opaque: [0; core::mem::size_of::<$model>() / 8],
                }
            }
            fn calls() -> Vec<CallOf<Self>> {
                vec![
                    (
                        stringify!($model_step),
                        |m| {
                            let mut f: $scalar = 0.0;
                            $model_step(Some(m), 1e-3, 1e-3, Some(&mut f))
                        },
                        allowed::STEP,
                    ),
                    (
                        concat!(stringify!($model_step), " (fast)"),
                        |m| {
                            let mut f: $scalar = 0.0;
                            $model_step(Some(m), -2.0, 1e-3, Some(&mut f))
                        },
                        allowed::STEP,
                    ),
                    (
                        stringify!($model_reset),
                        |m| $model_reset(Some(m)),
                        allowed::RESET,
                    ),
                    (
                        stringify!($observer_init),
                        |m| {
                            let mut o = $observer::zeroed();
                            $observer_init(Some(&mut o), Some(&*m), 100.0, true, None)
                        },
                        allowed::INIT,
                    ),
                    (
                        stringify!($servo_init),
                        |m| {
                            let mut s = $servo::zeroed();
                            $servo_init(
                                Some(&mut s),
                                Some(&servo_params()),
                                Some(&*m),
                                200.0,
                                None,
                                None,
                            )
                        },
                        allowed::INIT,
                    ),
                    (
                        concat!(stringify!($servo_init), " (adaptive)"),
                        |m| {
                            let mut s = $servo::zeroed();
                            $servo_init(
                                Some(&mut s),
                                Some(&servo_params()),
                                Some(&*m),
                                200.0,
                                Some(&ADAPTIVE),
                                None,
                            )
                        },
                        allowed::INIT,
                    ),
                ]
            }
        }

        impl Object for $observer {
            fn zeroed() -> Self {
                Self {
                    opaque: [0; core::mem::size_of::<$observer>() / 8],
                }
            }
            fn calls() -> Vec<CallOf<Self>> {
                vec![
                    (
                        stringify!($observer_step),
                        |o| {
                            let mut f: $scalar = 0.0;
                            $observer_step(Some(o), 1e-3, 1e-6, 1e-3, Some(&mut f))
                        },
                        allowed::STEP,
                    ),
                    (
                        concat!(stringify!($observer_step), " (fast)"),
                        |o| {
                            let mut f: $scalar = 0.0;
                            $observer_step(Some(o), -2.0, -1e-3, 1e-3, Some(&mut f))
                        },
                        allowed::STEP,
                    ),
                    (
                        stringify!($observer_reset),
                        |o| $observer_reset(Some(o)),
                        allowed::RESET,
                    ),
                ]
            }
        }

        impl Object for $servo {
            fn zeroed() -> Self {
                Self {
                    opaque: [0; core::mem::size_of::<$servo>() / 8],
                }
            }
            fn calls() -> Vec<CallOf<Self>> {
                vec![
                    (
                        stringify!($tick),
                        |s| {
                            let r = $setpoint {
                                x: 1e-3,
                                v: 0.0,
                                a: 0.0,
                            };
                            let mut t = $out {
                                command: 0.0,
                                friction: 0.0,
                            };
                            $tick(Some(s), 0.0, r, Some(&mut t))
                        },
                        allowed::TICK,
                    ),
                    (
                        concat!(stringify!($tick), " (twice)"),
                        |s| {
                            let r = $setpoint {
                                x: 1e-3,
                                v: 0.5,
                                a: 1.0,
                            };
                            let mut t = $out {
                                command: 0.0,
                                friction: 0.0,
                            };
                            let first = $tick(Some(s), 0.0, r, Some(&mut t));
                            match $tick(Some(s), -2e-3, r, Some(&mut t)) {
                                FRICTION_OK => first,
                                other => other,
                            }
                        },
                        allowed::TICK,
                    ),
                    (
                        stringify!($theta),
                        |s| {
                            let mut theta: $scalar = 0.0;
                            $theta(Some(s), Some(&mut theta))
                        },
                        allowed::THETA,
                    ),
                    (
                        stringify!($servo_reset),
                        |s| $servo_reset(Some(s)),
                        allowed::RESET,
                    ),
                    (
                        concat!(stringify!($retune), " (no model)"),
                        |s| $retune(Some(s), None, 200.0, None, None),
                        allowed::INIT,
                    ),
                    (
                        concat!(stringify!($retune), " (fixed-step, variable-step LuGre)"),
                        |s| {
                            let (mut fixed, mut variable) = ($model::zeroed(), $model::zeroed());
                            assert_eq!(
                                $lugre_init(Some(&mut fixed), Some(&lugre()), 1e-3, None),
                                FRICTION_OK
                            );
                            assert_eq!(
                                $lugre_init(Some(&mut variable), Some(&lugre()), 0.0, None),
                                FRICTION_OK
                            );
                            let first = $retune(Some(&mut *s), Some(&fixed), 200.0, None, None);
                            match $retune(Some(s), Some(&variable), 200.0, Some(&ADAPTIVE), None) {
                                FRICTION_OK => first,
                                other => other,
                            }
                        },
                        allowed::INIT,
                    ),
                ]
            }
        }
    };
}

object_types!(
    f32,
    friction_model_f32,
    friction_observer_f32,
    friction_servo_f32,
    friction_model_step_f32,
    friction_model_reset_f32,
    friction_observer_init_f32,
    friction_servo_init_f32,
    friction_observer_step_f32,
    friction_observer_reset_f32,
    friction_servo_tick_f32,
    friction_setpoint_f32,
    friction_tick_f32,
    friction_servo_reset_f32,
    friction_servo_theta_f32,
    friction_servo_retune_f32,
    friction_lugre_init_f32
);
object_types!(
    f64,
    friction_model_f64,
    friction_observer_f64,
    friction_servo_f64,
    friction_model_step_f64,
    friction_model_reset_f64,
    friction_observer_init_f64,
    friction_servo_init_f64,
    friction_observer_step_f64,
    friction_observer_reset_f64,
    friction_servo_tick_f64,
    friction_setpoint_f64,
    friction_tick_f64,
    friction_servo_reset_f64,
    friction_servo_theta_f64,
    friction_servo_retune_f64,
    friction_lugre_init_f64
);

macro_rules! commissioning_object {
    ($ty:ident, $tick:ident, $out:ident, $phase:ident, $abort:ident, $reset:ident,
     $result:ident) => {
        impl Object for $ty {
            fn zeroed() -> Self {
                Self {
                    opaque: [0; core::mem::size_of::<$ty>() / 8],
                }
            }
            fn calls() -> Vec<CallOf<Self>> {
                vec![
                    (
                        stringify!($tick),
                        |c| {
                            let mut t = $out {
                                command: 0.0,
                                phase: 0,
                                plateaus: 0,
                            };
                            let first = $tick(Some(&mut *c), 0.0, Some(&mut t));
                            match $tick(Some(c), 1e-3, Some(&mut t)) {
                                FRICTION_OK => first,
                                other => other,
                            }
                        },
                        allowed::TICK,
                    ),
                    (
                        stringify!($phase),
                        |c| $phase(Some(c), Some(&mut 0)),
                        allowed::READ,
                    ),
                    (
                        stringify!($abort),
                        |c| $abort(Some(c), Some(&mut 0)),
                        allowed::READ,
                    ),
                    (
                        stringify!($result),
                        |c| $result(Some(c), Some(&mut commissioned()), None),
                        allowed::RESULT,
                    ),
                    (stringify!($reset), |c| $reset(Some(c)), allowed::RESET),
                ]
            }
        }
    };
}

commissioning_object!(
    friction_commissioning_f32,
    friction_commissioning_tick_f32,
    friction_commissioning_command_f32,
    friction_commissioning_phase_f32,
    friction_commissioning_abort_f32,
    friction_commissioning_reset_f32,
    friction_commissioning_result_f32
);
commissioning_object!(
    friction_commissioning_f64,
    friction_commissioning_tick_f64,
    friction_commissioning_command_f64,
    friction_commissioning_phase_f64,
    friction_commissioning_abort_f64,
    friction_commissioning_reset_f64,
    friction_commissioning_result_f64
);

/// Overwrites `object` but its first 32 bits (the tag word) with pattern
/// `seed`'s bytes, 32 bits at a time, without reading it (a built object's
/// padding is not data): by `seed % 3` every word (random behind the tag),
/// each word with probability 1/2, or 1/8 (a few words of a valid object
/// overwritten, so that the model kinds inside often survive and the
/// core's own fields get the garbage).
fn corrupt<T>(object: &mut T, seed: u64) {
    let words = core::mem::size_of::<T>() / 4;
    let base = (object as *mut T).cast::<u32>();
    let mut state = splitmix(seed ^ 0x1A7E_5105_u64);
    for k in 1..words {
        state = splitmix(state);
        let keep = match seed % 3 {
            0 => false,
            1 => state >> 63 == 0,
            _ => (state >> 61) != 0,
        };
        if !keep {
            // SAFETY: word `k` is inside the object (objects are arrays of
            // `u64`, so 32-bit aligned), written, never read.
            unsafe { base.add(k).write(state as u32) };
        }
    }
}

/// A call's name, its status and whether that status is allowed.
type Outcome = (&'static str, friction_status, bool);

/// One valid object of one type and kind, built in place by `build`.
struct Subject {
    name: String,
    /// Runs every call on its own copy of the subject with pattern `seed`
    /// (rebuilt and corrupted for each call): `(call, status, allowed)`.
    run: Box<dyn Fn(u64) -> Vec<Outcome>>,
}

fn subject<T: Object + 'static>(
    name: String,
    build: impl Fn(&mut T) -> friction_status + 'static,
) -> Subject {
    Subject {
        name,
        run: Box::new(move |seed| {
            T::calls()
                .into_iter()
                .map(|(call, f, allowed)| {
                    let mut object = T::zeroed();
                    assert_eq!(build(&mut object), FRICTION_OK, "{call}: building");
                    corrupt(&mut object, seed);
                    let status = f(&mut object);
                    (call, status, allowed.contains(&status))
                })
                .collect()
        }),
    }
}

/// Every subject: each model kind as a model, each state model inside an
/// observer, and each compensation of the servo (none, feed-forward of the
/// static maps, observer and adaptive observer of every state model in
/// its variable- and fixed-step form), in `float` and in `double`.
macro_rules! subjects_of {
    ($all:ident, $scalar:literal, $model:ident, $observer:ident, $servo:ident,
     $observer_init:ident, $servo_init:ident, $coulomb_viscous:ident, $stribeck_map:ident,
     $asymmetric_coulomb_viscous:ident,
     $bristle:ident, $reset_integrator:ident, $dahl:ident, $lugre:ident,
     $elasto_plastic:ident, $leuven:ident, $gms:ident, $xiong:ident) => {{
        type Build = std::rc::Rc<dyn Fn(&mut $model) -> friction_status>;
        let statics: Vec<(&str, Build)> = vec![
            (
                "coulomb-viscous",
                std::rc::Rc::new(|m: &mut $model| {
                    $coulomb_viscous(
                        Some(m),
                        Some(&friction_coulomb_viscous_params {
                            fc: 1.0,
                            sigma2: 0.4,
                        }),
                        None,
                    )
                }),
            ),
            (
                "stribeck-map",
                std::rc::Rc::new(|m: &mut $model| {
                    $stribeck_map(
                        Some(m),
                        Some(&friction_stribeck_map_params {
                            curve: CURVE,
                            sigma2: 0.4,
                        }),
                        None,
                    )
                }),
            ),
            (
                "asymmetric-coulomb-viscous",
                std::rc::Rc::new(|m: &mut $model| {
                    $asymmetric_coulomb_viscous(
                        Some(m),
                        Some(&friction_asymmetric_coulomb_viscous_params {
                            fc_pos: 1.2,
                            sigma2_pos: 0.5,
                            fc_neg: 0.9,
                            sigma2_neg: 0.35,
                        }),
                        None,
                    )
                }),
            ),
        ];
        // state models at the servo's period 1e-3 (0: the variable-step form)
        let states: Vec<(&str, Build)> = vec![
            (
                "bristle",
                std::rc::Rc::new(|m: &mut $model| {
                    $bristle(
                        Some(m),
                        Some(&friction_bristle_params {
                            sigma0: 12_000.0,
                            delta_s: 1e-5,
                            seed: 1,
                        }),
                        None,
                    )
                }),
            ),
            (
                "reset-integrator",
                std::rc::Rc::new(|m: &mut $model| {
                    let p = friction_reset_integrator_params {
                        sigma0: 1e5,
                        sigma1: 316.0,
                        z0: 1e-5,
                        stiction: 0.5,
                        has_curve: 1,
                        curve: CURVE,
                    };
                    $reset_integrator(Some(m), Some(&p), None)
                }),
            ),
            (
                "leuven",
                std::rc::Rc::new(|m: &mut $model| {
                    let p = friction_leuven_params {
                        curve: CURVE,
                        sigma1: 15.0,
                        sigma2: 0.4,
                        n: 1.5,
                        xs: 1e-5,
                    };
                    $leuven(Some(m), Some(&p), None)
                }),
            ),
            (
                "dahl",
                std::rc::Rc::new(|m: &mut $model| {
                    let p = friction_dahl_params {
                        sigma: 1e5,
                        fc: 1.0,
                        delta: 1.0,
                        sigma2: 0.4,
                    };
                    $dahl(Some(m), Some(&p), 0.0, None)
                }),
            ),
            (
                "dahl at 1e-3",
                std::rc::Rc::new(|m: &mut $model| {
                    let p = friction_dahl_params {
                        sigma: 1e5,
                        fc: 1.0,
                        delta: 1.0,
                        sigma2: 0.4,
                    };
                    $dahl(Some(m), Some(&p), 1e-3, None)
                }),
            ),
            (
                "lugre",
                std::rc::Rc::new(|m: &mut $model| $lugre(Some(m), Some(&LUGRE), 0.0, None)),
            ),
            (
                "lugre at 1e-3",
                std::rc::Rc::new(|m: &mut $model| $lugre(Some(m), Some(&LUGRE), 1e-3, None)),
            ),
            (
                "elasto-plastic",
                std::rc::Rc::new(|m: &mut $model| {
                    $elasto_plastic(
                        Some(m),
                        Some(&friction_elasto_plastic_params {
                            lugre: LUGRE,
                            z_ba: 5e-6,
                        }),
                        0.0,
                        None,
                    )
                }),
            ),
            (
                "elasto-plastic at 1e-3",
                std::rc::Rc::new(|m: &mut $model| {
                    $elasto_plastic(
                        Some(m),
                        Some(&friction_elasto_plastic_params {
                            lugre: LUGRE,
                            z_ba: 5e-6,
                        }),
                        1e-3,
                        None,
                    )
                }),
            ),
            (
                "gms",
                std::rc::Rc::new(|m: &mut $model| $gms(Some(m), Some(&GMS), 0.0, None)),
            ),
            (
                "gms at 1e-3",
                std::rc::Rc::new(|m: &mut $model| $gms(Some(m), Some(&GMS), 1e-3, None)),
            ),
            (
                "xiong",
                std::rc::Rc::new(|m: &mut $model| $xiong(Some(m), Some(&XIONG), 0.0, None)),
            ),
            (
                "xiong at 1e-3",
                std::rc::Rc::new(|m: &mut $model| $xiong(Some(m), Some(&XIONG), 1e-3, None)),
            ),
        ];
        for (name, build) in statics.iter().chain(&states) {
            let b = build.clone();
            $all.push(subject::<$model>(
                format!("{} model {name}", $scalar),
                move |m| b(m),
            ));
        }
        for (name, build) in &states {
            let b = build.clone();
            $all.push(subject::<$observer>(
                format!("{} observer {name}", $scalar),
                move |o| {
                    let mut m = <$model>::zeroed();
                    assert_eq!(b(&mut m), FRICTION_OK);
                    $observer_init(Some(o), Some(&m), 100.0, true, None)
                },
            ));
        }
        $all.push(subject::<$servo>(format!("{} servo none", $scalar), |s| {
            $servo_init(Some(s), Some(&servo_params()), None, 0.0, None, None)
        }));
        for (name, build) in &statics {
            let b = build.clone();
            $all.push(subject::<$servo>(
                format!("{} servo feed-forward {name}", $scalar),
                move |s| {
                    let mut m = <$model>::zeroed();
                    assert_eq!(b(&mut m), FRICTION_OK);
                    $servo_init(Some(s), Some(&servo_params()), Some(&m), 0.0, None, None)
                },
            ));
        }
        for adaptive in [None, Some(ADAPTIVE)] {
            for (name, build) in &states {
                let b = build.clone();
                let label = if adaptive.is_some() {
                    "adaptive"
                } else {
                    "observer"
                };
                $all.push(subject::<$servo>(
                    format!("{} servo {label} {name}", $scalar),
                    move |s| {
                        let mut m = <$model>::zeroed();
                        assert_eq!(b(&mut m), FRICTION_OK);
                        $servo_init(
                            Some(s),
                            Some(&servo_params()),
                            Some(&m),
                            200.0,
                            adaptive.as_ref(),
                            None,
                        )
                    },
                ));
            }
        }
    }};
}

fn subjects() -> Vec<Subject> {
    let mut all = Vec::new();
    subjects_of!(
        all,
        "f32",
        friction_model_f32,
        friction_observer_f32,
        friction_servo_f32,
        friction_observer_init_f32,
        friction_servo_init_f32,
        friction_coulomb_viscous_init_f32,
        friction_stribeck_map_init_f32,
        friction_asymmetric_coulomb_viscous_init_f32,
        friction_bristle_init_f32,
        friction_reset_integrator_init_f32,
        friction_dahl_init_f32,
        friction_lugre_init_f32,
        friction_elasto_plastic_init_f32,
        friction_leuven_init_f32,
        friction_gms_init_f32,
        friction_xiong_init_f32
    );
    subjects_of!(
        all,
        "f64",
        friction_model_f64,
        friction_observer_f64,
        friction_servo_f64,
        friction_observer_init_f64,
        friction_servo_init_f64,
        friction_coulomb_viscous_init_f64,
        friction_stribeck_map_init_f64,
        friction_asymmetric_coulomb_viscous_init_f64,
        friction_bristle_init_f64,
        friction_reset_integrator_init_f64,
        friction_dahl_init_f64,
        friction_lugre_init_f64,
        friction_elasto_plastic_init_f64,
        friction_leuven_init_f64,
        friction_gms_init_f64,
        friction_xiong_init_f64
    );
    // the commissioning routine, fresh (the garbage reaches its state,
    // its loop and its settings, which the fit reads)
    all.push(subject::<friction_commissioning_f32>(
        "f32 commissioning".into(),
        |c| friction_commissioning_init_f32(Some(c), Some(&commissioning_params()), None),
    ));
    all.push(subject::<friction_commissioning_f64>(
        "f64 commissioning".into(),
        |c| friction_commissioning_init_f64(Some(c), Some(&commissioning_params()), None),
    ));
    all
}

/// Patterns per subject: `INTERIOR` shared out (rounded up).
fn per_subject(subjects: usize) -> u64 {
    INTERIOR.div_ceil(subjects as u64)
}

/// The seed of subject `index`'s pattern `i`: distinct over all subjects.
fn interior_seed(index: usize, i: u64) -> u64 {
    (index as u64) << 32 | i
}

/// The child of the interior sweep: patterns `start..end` of subject
/// `index`, as [`child`] (`bad I` for a status the call may not return).
fn interior_child(index: usize, start: u64, end: u64, trace: bool) {
    let subjects = subjects();
    let subject = &subjects[index];
    let mut out = std::io::stdout().lock();
    let mut reached = 0;
    for i in start..end {
        if trace {
            writeln!(out, "at {i}").unwrap();
            out.flush().unwrap();
        }
        let outcomes = (subject.run)(interior_seed(index, i));
        reached += u64::from(outcomes[0].1 == FRICTION_OK);
        for (call, status, ok) in outcomes {
            if !ok {
                writeln!(out, "bad {i} {call} {status:?}").unwrap();
            }
        }
    }
    writeln!(out, "reached {reached}").unwrap();
    writeln!(out, "done").unwrap();
}

#[test]
#[cfg_attr(miri, ignore = "spawns processes; see interiors_in_process")]
fn tag_correct_objects_with_garbage_inside_never_crash() {
    if let Some((index, start, end, trace)) = job(&INTERIOR_SWEEP) {
        interior_child(index, start, end, trace);
        return;
    }
    let subjects = subjects();
    let per = per_subject(subjects.len());
    let (mut crashes, mut hangs, mut bad) = (0, 0, 0);
    let mut least = (u64::MAX, "");
    for (index, subject) in subjects.iter().enumerate() {
        let found = sweep_in_children(&INTERIOR_SWEEP, index, per);
        if found.reached < least.0 {
            least = (found.reached, &subject.name);
        }
        if !(found.crashes.is_empty() && found.hangs.is_empty() && found.bad.is_empty()) {
            println!(
                "{:40} {per} patterns: crashes at {:?}, hangs at {:?}, wrong statuses at {:?}",
                subject.name, found.crashes, found.hangs, found.bad
            );
        }
        crashes += found.crashes.len();
        hangs += found.hangs.len();
        bad += found.bad.len();
    }
    println!(
        "total over {} subjects x {per} patterns: {crashes} crashes, {hangs} hangs, {bad} wrong statuses; \
         fewest patterns stepped with FRICTION_OK: {} ({})",
        subjects.len(),
        least.0,
        least.1
    );
    assert_eq!((crashes, hangs, bad), (0, 0, 0));
    // the garbage reached the core's values (the kinds inside survived)
    // for every subject, not only the kind checks
    assert!(least.0 >= per / 10, "{least:?} of {per}");
}

/// Under Miri: three patterns of every subject (one of each kind of
/// corruption), in process: Miri reports reading a byte that is not a
/// `bool` as one, or a discriminant no variant has, as undefined behaviour
/// (which a crash-only sweep misses when the read happens not to crash).
#[test]
#[cfg_attr(
    not(miri),
    ignore = "in process: for Miri; the child-process sweep covers normal runs"
)]
fn interiors_in_process() {
    for (index, subject) in subjects().iter().enumerate() {
        for i in 0..3 {
            for (call, status, ok) in (subject.run)(interior_seed(index, i)) {
                assert!(ok, "{} pattern {i}, {call}: {status:?}", subject.name);
            }
        }
    }
}
