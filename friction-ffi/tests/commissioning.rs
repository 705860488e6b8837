//! The commissioning routine through the C ABI, as C firmware runs it: a
//! simulated LuGre plant commissioned through `friction_commissioning_*`
//! and through the core side by side (the same commands and the same
//! result, bit for bit: the ABI adds no arithmetic), the result handed to
//! a running servo axis by `friction_servo_retune_*`; refusals, NULLs,
//! never-initialised objects and hostile positions.

#![allow(clippy::unwrap_used, clippy::indexing_slicing)]

use friction_core::{
    Commissioned, CommissioningParams, CommissioningPhase, CommissioningState, CompensatorParams,
    FrictionModel, LuGreParams, LuGreState, Scalar,
};
use friction_ffi::*;
use friction_status::*;

/// The loop of the core's commissioning tests (a 1 kHz drive with the
/// inertia and torque constant of Olsson et al. 1998's servo).
const SERVO: friction_servo_params = friction_servo_params {
    h: 1e-3,
    kp: 60.0,
    ki: 200.0,
    kd: 1.2,
    inertia: 0.0023,
    torque_constant: 1.02,
    limit: 10.0,
};

fn params() -> friction_commissioning_params {
    let mut p = friction_commissioning_params {
        servo: SERVO,
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
        friction_commissioning_defaults(Some(&SERVO), 1.0, 2.0, Some(&mut p)),
        FRICTION_OK
    );
    p
}

fn error() -> friction_error {
    friction_error {
        status: -1,
        parameter: [0xFF; FRICTION_NAME_LEN],
    }
}

fn name(e: &friction_error) -> &str {
    let end = e.parameter.iter().position(|&b| b == 0).unwrap();
    std::str::from_utf8(&e.parameter[..end]).unwrap()
}

fn commissioned() -> friction_commissioned {
    let lugre = friction_lugre_params {
        curve: friction_stribeck {
            fc: 0.0,
            fs: 0.0,
            vs: 0.0,
            exponent: 0.0,
        },
        sigma0: 0.0,
        sigma1: 0.0,
        sigma2: 0.0,
        vd: 0.0,
    };
    friction_commissioned {
        model: lugre,
        fc: [0.0; 2],
        fs: [0.0; 2],
        sigma2: [0.0; 2],
        breakaway: [0.0; 2],
        identified_coulomb: -1,
        identified_stribeck: -1,
        identified_viscous: -1,
        identified_stiffness: -1,
        identified_damping: -1,
        plateaus: 0,
        residual: -1.0,
        speed_range: [0.0; 2],
        load: -1.0,
        load_torque: -1.0,
        identified_load: -1,
    }
}

/// The plant: a LuGre mass with the loop's inertia and torque constant,
/// 100 integration steps a tick.
struct Plant {
    model: friction_core::LuGre<f64>,
    z: LuGreState<f64>,
    x: f64,
    v: f64,
}

impl Plant {
    fn new(p: &LuGreParams) -> Self {
        Self {
            model: p.build().unwrap(),
            z: LuGreState::default(),
            x: 0.0,
            v: 0.0,
        }
    }

    fn step(&mut self, command: f64) {
        let hp = SERVO.h / 100.0;
        for _ in 0..100 {
            let f = self.model.step(&mut self.z, self.v, hp);
            self.v += hp * (SERVO.torque_constant * command - f) / SERVO.inertia;
            self.x += hp * self.v;
        }
    }
}

/// The C result of a core result, field by field as the ABI writes it.
fn same_result(c: &friction_commissioned, r: &Commissioned) {
    let bits = |a: f64, b: f64, what: &str| assert_eq!(a.to_bits(), b.to_bits(), "{what}");
    bits(c.model.curve.fc, r.model.curve.fc, "fc");
    bits(c.model.curve.fs, r.model.curve.fs, "fs");
    bits(c.model.curve.vs, r.model.curve.vs, "vs");
    bits(c.model.curve.exponent, r.model.curve.exponent, "exponent");
    bits(c.model.sigma0, r.model.sigma0, "sigma0");
    bits(c.model.sigma1, r.model.sigma1, "sigma1");
    bits(c.model.sigma2, r.model.sigma2, "sigma2");
    assert_eq!(c.model.vd, 0.0);
    assert_eq!(r.model.vd, None);
    for k in 0..2 {
        bits(c.fc[k], r.fc[k], "fc per direction");
        bits(c.fs[k], r.fs[k], "fs per direction");
        bits(c.sigma2[k], r.sigma2[k], "sigma2 per direction");
        bits(c.breakaway[k], r.breakaway[k], "breakaway");
        bits(c.speed_range[k], r.speed_range[k], "speed_range");
    }
    bits(c.residual, r.residual, "residual");
    bits(c.load, r.load, "load");
    bits(c.load_torque, r.load_torque, "load_torque");
    let i = r.identified;
    assert_eq!(
        [
            c.identified_coulomb,
            c.identified_stribeck,
            c.identified_viscous,
            c.identified_stiffness,
            c.identified_damping,
            c.identified_load
        ],
        [
            i.coulomb,
            i.stribeck,
            i.viscous,
            i.stiffness,
            i.damping,
            i.load
        ]
        .map(i32::from)
    );
    assert_eq!(c.plateaus, u32::from(r.plateaus));
}

/// Commissions Olsson et al. 1998's LuGre plant through the ABI object and
/// through the core, each on its own plant: the same command every tick,
/// the same phase, the same result, bit for bit. Returns the result.
macro_rules! commission_both {
    ($scalar:ty, $object:ident, $words:expr, $init:ident, $tick:ident, $command_ty:ident,
     $phase:ident, $abort:ident, $result:ident) => {{
        let p = params();
        let mut c = $object {
            opaque: [0; $words],
        };
        let mut e = error();
        assert_eq!($init(Some(&mut c), Some(&p), Some(&mut e)), FRICTION_OK);
        assert_eq!((e.status, name(&e)), (0, ""));
        let core = CommissioningParams::from(&p);
        assert_eq!(
            core,
            CommissioningParams::new(CompensatorParams::from(&SERVO), 1.0, 2.0)
        );
        let routine = core.build::<$scalar>().unwrap();
        let mut state = CommissioningState::<$scalar>::default();
        let plant = LuGreParams::OLSSON_1998;
        let (mut a, mut b) = (Plant::new(&plant), Plant::new(&plant));
        let mut t = $command_ty {
            command: 0.0,
            phase: -1,
            plateaus: 0,
        };
        let mut ticks = 0u32;
        loop {
            assert_eq!(
                $tick(Some(&mut c), <$scalar>::from_f64(a.x), Some(&mut t)),
                FRICTION_OK
            );
            let r = routine.tick(&mut state, <$scalar>::from_f64(b.x));
            assert_eq!(t.command.to_bits(), r.command.to_bits(), "tick {ticks}");
            assert_eq!(t.plateaus, u32::from(r.plateaus));
            assert_eq!(t.phase, r.phase as i32, "tick {ticks}");
            ticks += 1;
            if matches!(
                r.phase,
                CommissioningPhase::Done | CommissioningPhase::Aborted
            ) {
                break;
            }
            a.step(f64::from(t.command));
            b.step(f64::from(r.command));
            assert!(ticks < 40_000, "the routine ends within its duration");
        }
        assert_eq!(t.phase, friction_phase::FRICTION_PHASE_DONE as i32);
        let mut phase = -1;
        assert_eq!($phase(Some(&mut c), Some(&mut phase)), FRICTION_OK);
        assert_eq!(phase, FRICTION_PHASE_DONE as i32);
        let mut abort = -1;
        assert_eq!($abort(Some(&mut c), Some(&mut abort)), FRICTION_OK);
        assert_eq!(abort, friction_abort::FRICTION_ABORT_NONE as i32);
        // after the end, the command is the safe zero
        assert_eq!(
            $tick(Some(&mut c), <$scalar>::from_f64(a.x), Some(&mut t)),
            FRICTION_OK
        );
        assert_eq!(t.command, 0.0);
        let mut out = commissioned();
        let mut e = error();
        assert_eq!(
            $result(Some(&mut c), Some(&mut out), Some(&mut e)),
            FRICTION_OK
        );
        assert_eq!((e.status, name(&e)), (0, ""));
        let r = routine.result(&state).unwrap();
        same_result(&out, &r);
        // the bounds on the exact plant
        let truth = plant;
        let rel = |a: f64, b: f64| ((a - b) / b).abs();
        assert!(rel(out.model.curve.fc, truth.curve.fc) <= 0.05, "{out:?}");
        assert!(rel(out.model.sigma2, truth.sigma2) <= 0.05, "{out:?}");
        out
    }};
}

/// The ABI's phases are the core's, in the core's order.
#[test]
fn phase_values_are_the_cores() {
    for (phase, value) in [
        (CommissioningPhase::Breakaway, FRICTION_PHASE_BREAKAWAY),
        (CommissioningPhase::Presliding, FRICTION_PHASE_PRESLIDING),
        (CommissioningPhase::Plateaus, FRICTION_PHASE_PLATEAUS),
        (CommissioningPhase::Done, FRICTION_PHASE_DONE),
        (CommissioningPhase::Aborted, FRICTION_PHASE_ABORTED),
    ] {
        assert_eq!(phase as i32, value as i32);
    }
}

use friction_phase::*;

#[test]
fn commissions_a_lugre_plant_as_the_core_does_then_retunes_a_servo_f32() {
    let out = commission_both!(
        f32,
        friction_commissioning_f32,
        FRICTION_COMMISSIONING_F32_WORDS,
        friction_commissioning_init_f32,
        friction_commissioning_tick_f32,
        friction_commissioning_command_f32,
        friction_commissioning_phase_f32,
        friction_commissioning_abort_f32,
        friction_commissioning_result_f32
    );
    // the result becomes a fixed-step model and is swapped into a running
    // observer servo between two ticks
    let nominal = friction_lugre_params {
        curve: friction_stribeck {
            fc: 1.0,
            fs: 1.5,
            vs: 0.01,
            exponent: 2.0,
        },
        sigma0: 1e5,
        sigma1: 300.0,
        sigma2: 0.4,
        vd: 0.0,
    };
    let mut old = friction_model_f32 {
        opaque: [0; FRICTION_MODEL_F32_WORDS],
    };
    assert_eq!(
        friction_lugre_init_f32(Some(&mut old), Some(&nominal), SERVO.h, None),
        FRICTION_OK
    );
    let mut servo = friction_servo_f32 {
        opaque: [0; FRICTION_SERVO_F32_WORDS],
    };
    assert_eq!(
        friction_servo_init_f32(
            Some(&mut servo),
            Some(&SERVO),
            Some(&old),
            200.0,
            None,
            None
        ),
        FRICTION_OK
    );
    let r = friction_setpoint_f32 {
        x: 1e-3,
        v: 0.0,
        a: 0.0,
    };
    let mut t = friction_tick_f32 {
        command: 0.0,
        friction: 0.0,
    };
    for _ in 0..10 {
        assert_eq!(
            friction_servo_tick_f32(Some(&mut servo), 0.0, r, Some(&mut t)),
            FRICTION_OK
        );
    }
    let mut m = friction_model_f32 {
        opaque: [0; FRICTION_MODEL_F32_WORDS],
    };
    let mut e = error();
    assert_eq!(
        friction_lugre_init_f32(Some(&mut m), Some(&out.model), SERVO.h, Some(&mut e)),
        FRICTION_OK,
        "{}",
        name(&e)
    );
    assert_eq!(
        friction_servo_retune_f32(Some(&mut servo), Some(&m), 200.0, None, Some(&mut e)),
        FRICTION_OK,
        "{}",
        name(&e)
    );
    assert_eq!(
        friction_servo_tick_f32(Some(&mut servo), 0.0, r, Some(&mut t)),
        FRICTION_OK
    );
    assert!(t.command.is_finite() && t.command.abs() <= SERVO.limit as f32);
}

#[test]
fn commissions_a_lugre_plant_as_the_core_does_then_retunes_a_servo_f64() {
    let out = commission_both!(
        f64,
        friction_commissioning_f64,
        FRICTION_COMMISSIONING_F64_WORDS,
        friction_commissioning_init_f64,
        friction_commissioning_tick_f64,
        friction_commissioning_command_f64,
        friction_commissioning_phase_f64,
        friction_commissioning_abort_f64,
        friction_commissioning_result_f64
    );
    // a servo with no model yet cannot take one by a re-tune (another
    // kind): it is built with the result instead; a variable-step observer
    // servo re-tunes to it
    let mut m = friction_model_f64 {
        opaque: [0; FRICTION_MODEL_F64_WORDS],
    };
    assert_eq!(
        friction_lugre_init_f64(Some(&mut m), Some(&out.model), 0.0, None),
        FRICTION_OK
    );
    let mut none = friction_servo_f64 {
        opaque: [0; FRICTION_SERVO_F64_WORDS],
    };
    assert_eq!(
        friction_servo_init_f64(Some(&mut none), Some(&SERVO), None, 0.0, None, None),
        FRICTION_OK
    );
    let mut e = error();
    assert_eq!(
        friction_servo_retune_f64(Some(&mut none), Some(&m), 200.0, None, Some(&mut e)),
        FRICTION_NOT_SUPPORTED
    );
    assert_eq!(name(&e), "model");
    let mut servo = friction_servo_f64 {
        opaque: [0; FRICTION_SERVO_F64_WORDS],
    };
    assert_eq!(
        friction_servo_init_f64(Some(&mut servo), Some(&SERVO), Some(&m), 200.0, None, None),
        FRICTION_OK
    );
    let mut again = friction_model_f64 {
        opaque: [0; FRICTION_MODEL_F64_WORDS],
    };
    let doubled = friction_lugre_params {
        sigma2: 2.0 * out.model.sigma2,
        ..out.model
    };
    assert_eq!(
        friction_lugre_init_f64(Some(&mut again), Some(&doubled), 0.0, None),
        FRICTION_OK
    );
    assert_eq!(
        friction_servo_retune_f64(Some(&mut servo), Some(&again), 200.0, None, None),
        FRICTION_OK
    );
}

#[test]
fn refusals_name_the_parameter_and_leave_the_object() {
    let mut c = friction_commissioning_f64 {
        opaque: [7; FRICTION_COMMISSIONING_F64_WORDS],
    };
    for (p, status, parameter) in [
        (
            friction_commissioning_params {
                speeds: 17,
                ..params()
            },
            FRICTION_OUT_OF_RANGE,
            "speeds",
        ),
        (
            friction_commissioning_params {
                speeds: 258,
                ..params()
            },
            FRICTION_OUT_OF_RANGE,
            "speeds",
        ),
        (
            friction_commissioning_params {
                travel: f64::NAN,
                ..params()
            },
            FRICTION_NOT_FINITE,
            "travel",
        ),
        (
            friction_commissioning_params {
                plateau: 5.0,
                ..params()
            },
            FRICTION_NOT_BELOW,
            "plateau",
        ),
        (
            friction_commissioning_params {
                servo: friction_servo_params { kd: -1.0, ..SERVO },
                ..params()
            },
            FRICTION_NEGATIVE,
            "kd",
        ),
    ] {
        let mut e = error();
        assert_eq!(
            friction_commissioning_init_f64(Some(&mut c), Some(&p), Some(&mut e)),
            status
        );
        assert_eq!((e.status, name(&e)), (status as i32, parameter));
        assert!(c.opaque.iter().all(|&w| w == 7), "{parameter}: untouched");
    }
    let mut e = error();
    assert_eq!(
        friction_commissioning_init_f64(None, Some(&params()), Some(&mut e)),
        FRICTION_NULL_POINTER
    );
    assert_eq!(name(&e), "out");
    assert_eq!(
        friction_commissioning_init_f64(Some(&mut c), None, Some(&mut e)),
        FRICTION_NULL_POINTER
    );
    assert_eq!(name(&e), "params");
    assert_eq!(
        friction_commissioning_defaults(None, 1.0, 2.0, None),
        FRICTION_NULL_POINTER
    );
}

#[test]
fn null_and_never_initialised_objects_are_refused() {
    let mut c = friction_commissioning_f32 {
        opaque: [0; FRICTION_COMMISSIONING_F32_WORDS],
    };
    let mut t = friction_commissioning_command_f32 {
        command: 1.0,
        phase: -1,
        plateaus: 9,
    };
    let mut i = 0;
    let mut out = commissioned();
    assert_eq!(
        friction_commissioning_tick_f32(Some(&mut c), 0.0, Some(&mut t)),
        FRICTION_NOT_INITIALISED
    );
    assert_eq!((t.command, t.phase, t.plateaus), (1.0, -1, 9));
    assert_eq!(
        friction_commissioning_tick_f32(None, 0.0, Some(&mut t)),
        FRICTION_NULL_POINTER
    );
    assert_eq!(
        friction_commissioning_tick_f32(Some(&mut c), 0.0, None),
        FRICTION_NULL_POINTER
    );
    assert_eq!(
        friction_commissioning_phase_f32(Some(&mut c), Some(&mut i)),
        FRICTION_NOT_INITIALISED
    );
    assert_eq!(
        friction_commissioning_abort_f32(Some(&mut c), None),
        FRICTION_NULL_POINTER
    );
    assert_eq!(
        friction_commissioning_reset_f32(Some(&mut c)),
        FRICTION_NOT_INITIALISED
    );
    let mut e = error();
    assert_eq!(
        friction_commissioning_result_f32(Some(&mut c), Some(&mut out), Some(&mut e)),
        FRICTION_NOT_INITIALISED
    );
    assert_eq!(name(&e), "commissioning");
    assert_eq!(out.residual, -1.0, "untouched");
    // a double object is not a float one: its own tag
    let mut d = friction_commissioning_f64 {
        opaque: [0; FRICTION_COMMISSIONING_F64_WORDS],
    };
    assert_eq!(
        friction_commissioning_init_f64(Some(&mut d), Some(&params()), None),
        FRICTION_OK
    );
    let mut f = friction_commissioning_f32 {
        opaque: [0; FRICTION_COMMISSIONING_F32_WORDS],
    };
    f.opaque
        .copy_from_slice(&d.opaque[..FRICTION_COMMISSIONING_F32_WORDS]);
    assert_eq!(
        friction_commissioning_tick_f32(Some(&mut f), 0.0, Some(&mut t)),
        FRICTION_NOT_INITIALISED
    );
}

/// A stuck axis: the ramp reaches the limit and the run aborts with a zero
/// command; the result is refused naming the limit; a NaN position is
/// refused with the state unchanged; a reset runs it again.
#[test]
fn an_axis_that_never_moves_aborts_and_nan_is_refused() {
    let mut c = friction_commissioning_f32 {
        opaque: [0; FRICTION_COMMISSIONING_F32_WORDS],
    };
    assert_eq!(
        friction_commissioning_init_f32(Some(&mut c), Some(&params()), None),
        FRICTION_OK
    );
    let mut t = friction_commissioning_command_f32 {
        command: 0.0,
        phase: -1,
        plateaus: 0,
    };
    let mut out = commissioned();
    let mut e = error();
    assert_eq!(
        friction_commissioning_result_f32(Some(&mut c), Some(&mut out), Some(&mut e)),
        FRICTION_NOT_FINISHED
    );
    assert_eq!(e.status, FRICTION_NOT_FINISHED as i32);
    assert_eq!(
        friction_commissioning_tick_f32(Some(&mut c), 0.0, Some(&mut t)),
        FRICTION_OK
    );
    let before = t.command;
    assert!(before > 0.0);
    for x in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        assert_eq!(
            friction_commissioning_tick_f32(Some(&mut c), x, Some(&mut t)),
            FRICTION_INPUT_REJECTED
        );
        assert_eq!((t.command, t.phase), (0.0, FRICTION_PHASE_BREAKAWAY as i32));
    }
    // the ramp goes on from where it was: the NaNs did not count
    assert_eq!(
        friction_commissioning_tick_f32(Some(&mut c), 0.0, Some(&mut t)),
        FRICTION_OK
    );
    assert_eq!(t.command, 2.0 * before);
    let mut ticks = 0;
    while t.phase == FRICTION_PHASE_BREAKAWAY as i32 {
        assert!(t.command.abs() <= SERVO.limit as f32);
        friction_commissioning_tick_f32(Some(&mut c), 0.0, Some(&mut t));
        ticks += 1;
        assert!(ticks < 20_000, "the ramp reaches the limit in 10 s");
    }
    assert_eq!((t.phase, t.command), (FRICTION_PHASE_ABORTED as i32, 0.0));
    let mut abort = -1;
    friction_commissioning_abort_f32(Some(&mut c), Some(&mut abort));
    assert_eq!(abort, friction_abort::FRICTION_ABORT_NO_BREAKAWAY as i32);
    assert_eq!(
        friction_commissioning_result_f32(Some(&mut c), Some(&mut out), Some(&mut e)),
        FRICTION_ABORTED
    );
    assert_eq!(name(&e), "ramp_rate");
    assert_eq!(out.residual, -1.0, "untouched");
    assert_eq!(friction_commissioning_reset_f32(Some(&mut c)), FRICTION_OK);
    let mut phase = -1;
    friction_commissioning_phase_f32(Some(&mut c), Some(&mut phase));
    assert_eq!(phase, FRICTION_PHASE_BREAKAWAY as i32);
    friction_commissioning_abort_f32(Some(&mut c), Some(&mut abort));
    assert_eq!(abort, friction_abort::FRICTION_ABORT_NONE as i32);
}
