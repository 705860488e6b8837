//! The fuzz harness of the C ABI's object decoding, shared by the fuzz
//! target (`fuzz_targets/objects.rs`) and the stable replay of its corpus
//! (`friction-ffi/tests/fuzz_corpus.rs`).
//!
//! The first byte picks the object type (model, observer or servo, in
//! `float` or `double`); the rest are the object's bytes (cut, or padded
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

/// Sends `data` through the ABI (see the module's doc).
pub fn run(data: &[u8]) {
    let Some((&which, bytes)) = data.split_first() else {
        return;
    };
    // the tag a constructor of that type writes (see friction-ffi's slot.rs)
    let (tag, statuses) = match which % 6 {
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
        _ => (
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
    };
    // the tag word: the first 32 bits (friction-ffi's slot.rs)
    let head: [u8; 4] = std::array::from_fn(|k| bytes.get(k).copied().unwrap_or(0));
    let head = u32::from_ne_bytes(head);
    // a constructor writes the tag plus a kind (1 to 3 for a model, 1 or 2
    // for an observer, 1 to 6 for a servo)
    let kinds = match which % 6 {
        0 | 1 => 3,
        2 | 3 => 2,
        _ => 6,
    };
    if !(1..=kinds).contains(&head.wrapping_sub(tag)) {
        assert!(
            statuses.iter().all(|&s| s != FRICTION_OK),
            "an object without its tag got FRICTION_OK: {statuses:?}"
        );
    }
}
