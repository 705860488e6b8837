//! The fuzz harness of the C ABI's object decoding, shared by the fuzz
//! target (`fuzz_targets/objects.rs`) and the stable replay of its corpus
//! (`friction-ffi/tests/fuzz_corpus.rs`).
//!
//! The first byte picks the object type (model, observer or servo, in
//! `float` or `double`, by its value modulo 6; a commissioning routine for
//! `0x20..=0x27`, `float` when even, values the committed corpus never
//! starts with, so that its inputs keep their types); the rest are the object's bytes (cut, or padded
//! with zeros, to its size), sent through every call that reads that type.
//! Besides "no crash, no hang", it asserts that an object whose tag word
//! (its first 4 bytes) is not one its type's constructors write gets no
//! `FRICTION_OK` from any call.

use friction_ffi::friction_status::FRICTION_OK;
use friction_ffi::*;

/// The object's words from `bytes`, zero-padded (native byte order, as C's
/// memory holds them).
fn words<const N: usize>(bytes: &[u8]) -> [u64; N] {
    std::array::from_fn(|i| {
        let mut word = [0u8; 8];
        for (k, b) in word.iter_mut().enumerate() {
            *b = bytes.get(8 * i + k).copied().unwrap_or(0);
        }
        u64::from_ne_bytes(word)
    })
}

const SERVO: friction_servo_params = friction_servo_params {
    h: 1e-3,
    kp: 9.08,
    ki: 0.0,
    kd: 0.289,
    inertia: 0.0023,
    torque_constant: 1.0,
    limit: 5.0,
};

const ADAPTIVE: friction_adaptive_params = friction_adaptive_params {
    gamma: 50.0,
    gamma_derivative: 0.0,
    leakage: 0.0,
    theta0: 1.0,
    theta_min: 0.5,
    theta_max: 2.0,
};

/// Every call that reads a model, each on its own copy of `words`.
macro_rules! models {
    ($bytes:expr, $ty:ident, $scalar:ty, $step:ident, $reset:ident, $obs:ident,
     $obs_init:ident, $servo:ident, $servo_init:ident) => {{
        let object = $ty {
            opaque: words($bytes),
        };
        let mut f: $scalar = 0.0;
        let mut o = $obs {
            opaque: [0; core::mem::size_of::<$obs>() / 8],
        };
        let mut s = $servo {
            opaque: [0; core::mem::size_of::<$servo>() / 8],
        };
        let mut m = $ty {
            opaque: object.opaque,
        };
        let mut statuses = vec![
            $step(Some(&mut m), 1e-3, 1e-3, Some(&mut f)),
            $step(Some(&mut m), -2e-3, 1e-3, Some(&mut f)),
            $reset(Some(&mut m)),
        ];
        statuses.push($obs_init(Some(&mut o), Some(&object), 100.0, true, None));
        statuses.push($servo_init(
            Some(&mut s),
            Some(&SERVO),
            Some(&object),
            200.0,
            None,
            None,
        ));
        statuses.push($servo_init(
            Some(&mut s),
            Some(&SERVO),
            Some(&object),
            200.0,
            Some(&ADAPTIVE),
            None,
        ));
        statuses
    }};
}

macro_rules! observers {
    ($bytes:expr, $ty:ident, $scalar:ty, $step:ident, $reset:ident) => {{
        let mut o = $ty {
            opaque: words($bytes),
        };
        let mut f: $scalar = 0.0;
        vec![
            $step(Some(&mut o), 1e-3, 1e-6, 1e-3, Some(&mut f)),
            $step(Some(&mut o), -2e-3, 0.0, 1e-3, Some(&mut f)),
            $reset(Some(&mut o)),
        ]
    }};
}

macro_rules! servos {
    ($bytes:expr, $ty:ident, $scalar:ty, $tick:ident, $setpoint:ident, $out:ident,
     $reset:ident, $theta:ident, $retune:ident) => {{
        let mut s = $ty {
            opaque: words($bytes),
        };
        let r = $setpoint {
            x: 1e-3,
            v: 0.0,
            a: 0.0,
        };
        let mut t = $out {
            command: 0.0,
            friction: 0.0,
        };
        let mut theta: $scalar = 0.0;
        vec![
            $tick(Some(&mut s), 0.0, r, Some(&mut t)),
            $tick(Some(&mut s), 1e-4, r, Some(&mut t)),
            $theta(Some(&mut s), Some(&mut theta)),
            $retune(Some(&mut s), None, 200.0, None, None),
            $reset(Some(&mut s)),
        ]
    }};
}

/// Every call that reads a commissioning routine, on `words`.
macro_rules! routines {
    ($bytes:expr, $ty:ident, $scalar:ty, $tick:ident, $out:ident, $phase:ident, $abort:ident,
     $reset:ident, $result:ident) => {{
        let mut c = $ty {
            opaque: words($bytes),
        };
        let mut t = $out {
            command: 0.0,
            phase: 0,
            plateaus: 0,
        };
        let zero = friction_stribeck {
            fc: 0.0,
            fs: 0.0,
            vs: 0.0,
            exponent: 0.0,
        };
        let mut r = friction_commissioned {
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
            load: 0.0,
            load_torque: 0.0,
            identified_load: 0,
        };
        let (mut phase, mut abort) = (0, 0);
        vec![
            $tick(Some(&mut c), 0.0, Some(&mut t)),
            $tick(Some(&mut c), 1e-3, Some(&mut t)),
            $tick(Some(&mut c), <$scalar>::NAN, Some(&mut t)),
            $phase(Some(&mut c), Some(&mut phase)),
            $abort(Some(&mut c), Some(&mut abort)),
            $result(Some(&mut c), Some(&mut r), None),
            $reset(Some(&mut c)),
        ]
    }};
}

/// Sends `data` through the ABI (see the module's doc).
pub fn run(data: &[u8]) {
    let Some((&which, bytes)) = data.split_first() else {
        return;
    };
    // the object type: 0 to 5 as ever, 6 and 7 the commissioning routines
    let kind = match which {
        0x20..=0x27 => 6 + which % 2,
        _ => which % 6,
    };
    // the tag a constructor of that type writes (see friction-ffi's slot.rs)
    let (tag, statuses) = match kind {
        0 => (
            0xB1B1_B1B1u32,
            models!(
                bytes,
                friction_model_f32,
                f32,
                friction_model_step_f32,
                friction_model_reset_f32,
                friction_observer_f32,
                friction_observer_init_f32,
                friction_servo_f32,
                friction_servo_init_f32
            ),
        ),
        1 => (
            0xB2B2_B2B2,
            models!(
                bytes,
                friction_model_f64,
                f64,
                friction_model_step_f64,
                friction_model_reset_f64,
                friction_observer_f64,
                friction_observer_init_f64,
                friction_servo_f64,
                friction_servo_init_f64
            ),
        ),
        2 => (
            0xB3B3_B3B3,
            observers!(
                bytes,
                friction_observer_f32,
                f32,
                friction_observer_step_f32,
                friction_observer_reset_f32
            ),
        ),
        3 => (
            0xB4B4_B4B4,
            observers!(
                bytes,
                friction_observer_f64,
                f64,
                friction_observer_step_f64,
                friction_observer_reset_f64
            ),
        ),
        4 => (
            0xB5B5_B5B5,
            servos!(
                bytes,
                friction_servo_f32,
                f32,
                friction_servo_tick_f32,
                friction_setpoint_f32,
                friction_tick_f32,
                friction_servo_reset_f32,
                friction_servo_theta_f32,
                friction_servo_retune_f32
            ),
        ),
        5 => (
            0xB6B6_B6B6,
            servos!(
                bytes,
                friction_servo_f64,
                f64,
                friction_servo_tick_f64,
                friction_setpoint_f64,
                friction_tick_f64,
                friction_servo_reset_f64,
                friction_servo_theta_f64,
                friction_servo_retune_f64
            ),
        ),
        6 => (
            0xB7B7_B7B7,
            routines!(
                bytes,
                friction_commissioning_f32,
                f32,
                friction_commissioning_tick_f32,
                friction_commissioning_command_f32,
                friction_commissioning_phase_f32,
                friction_commissioning_abort_f32,
                friction_commissioning_reset_f32,
                friction_commissioning_result_f32
            ),
        ),
        _ => (
            0xB8B8_B8B8,
            routines!(
                bytes,
                friction_commissioning_f64,
                f64,
                friction_commissioning_tick_f64,
                friction_commissioning_command_f64,
                friction_commissioning_phase_f64,
                friction_commissioning_abort_f64,
                friction_commissioning_reset_f64,
                friction_commissioning_result_f64
            ),
        ),
    };
    // the tag word: the first 32 bits (friction-ffi's slot.rs)
    let head: [u8; 4] = std::array::from_fn(|k| bytes.get(k).copied().unwrap_or(0));
    let head = u32::from_ne_bytes(head);
    // a constructor writes the tag plus a kind (1 to 3 for a model, 1 or 2
    // for an observer, 1 to 7 for a servo, 1 for a routine)
    let kinds = match kind {
        0 | 1 => 3,
        2 | 3 => 2,
        4 | 5 => 7,
        _ => 1,
    };
    if !(1..=kinds).contains(&head.wrapping_sub(tag)) {
        assert!(
            statuses.iter().all(|&s| s != FRICTION_OK),
            "an object without its tag got FRICTION_OK: {statuses:?}"
        );
    }
}
