//! The C ABI called as C would call it: every constructor with valid and
//! invalid parameters, NULL and never-initialised objects, hostile step
//! inputs, and agreement with the core called directly (bit for bit: the
//! ABI adds no arithmetic).

#![allow(clippy::unwrap_used, clippy::indexing_slicing)]

use friction_core::{
    AdaptiveParams, AsymmetricCoulombViscousParams, CompensatorParams, CoulombViscousParams,
    FixedPeriod, FixedStepModel, FrictionModel, LuGreFixedStepState, LuGreParams, LuGreServo,
    LuGreState, Observer, ParameterAdaptiveParams, ParameterAdaptiveServo, Scalar, Setpoint,
    SupervisorMode, SupervisorParams,
};
use friction_ffi::*;
use friction_status::*;

const CURVE: friction_stribeck = friction_stribeck {
    fc: 1.0,
    fs: 1.5,
    vs: 1e-3,
    exponent: 2.0,
};

const LUGRE: friction_lugre_params = friction_lugre_params {
    curve: CURVE,
    sigma0: 1e5,
    sigma1: 316.227_766_016_837_94,
    sigma2: 0.4,
    vd: 0.0,
};

fn model_f64() -> friction_model_f64 {
    friction_model_f64 {
        opaque: [0; FRICTION_MODEL_F64_WORDS],
    }
}

fn model_f32() -> friction_model_f32 {
    friction_model_f32 {
        opaque: [0; FRICTION_MODEL_F32_WORDS],
    }
}

/// Steps `a` and `b` alike over the sweep and asserts equal forces, bit
/// for bit (the objects' words are not compared: their padding is not data).
fn same_run_f64(a: &mut friction_model_f64, b: &mut friction_model_f64, steps: usize) {
    for k in 0..steps {
        let (v, h) = signal(k);
        let (mut fa, mut fb) = (0.0, 0.0);
        assert_eq!(
            friction_model_step_f64(Some(&mut *a), v, h, Some(&mut fa)),
            FRICTION_OK
        );
        assert_eq!(
            friction_model_step_f64(Some(&mut *b), v, h, Some(&mut fb)),
            FRICTION_OK
        );
        assert_eq!(fa.to_bits(), fb.to_bits(), "step {k}");
    }
}

/// `n` runs of a loop, or 10 under Miri: there each step is checked for
/// undefined behaviour about a thousand times slower, and the paths, not
/// the statistics, are what it checks.
fn runs(n: usize) -> usize {
    if cfg!(miri) {
        n.min(10)
    } else {
        n
    }
}

fn no_error() -> friction_error {
    friction_error {
        status: -1,
        parameter: [0; FRICTION_NAME_LEN],
    }
}

fn name(e: &friction_error) -> &str {
    let end = e.parameter.iter().position(|&b| b == 0).unwrap_or(0);
    std::str::from_utf8(&e.parameter[..end]).unwrap()
}

/// A velocity sweep through zero with reversals, and its sample periods.
fn signal(k: usize) -> (f64, f64) {
    let t = k as f64 * 1e-4;
    (2e-3 * (2.0 * std::f64::consts::PI * 5.0 * t).sin(), 1e-4)
}

/// The `model = "..."` name of each model of the core's list that the C ABI
/// builds, and whether it has a fixed-step form.
fn c_models() -> Vec<(&'static str, bool)> {
    // `true` where the repetition that holds it is present
    macro_rules! has {
        ($($form:tt)*) => {
            true
        };
    }
    macro_rules! forms {
        ($(
            $(#[$doc:meta])* $variant:ident = $name:literal {
                params: $params:ty,
                field: $field:ident,
                $(map: $map:ty,)?
                $(variable: $variable:ty,)?
                $(fixed: $fixed:ty,)?
                sets: [$($set:literal),* $(,)?],
            }
        )*) => {{
            let mut models = Vec::new();
            $(
                let fixed = false $(|| has!($fixed))?;
                let c = false $(|| has!($map))? $(|| has!($variable))?;
                if c {
                    models.push(($name, fixed));
                }
            )*
            models
        }};
    }
    friction_core::model_list!(forms)
}

/// Every constructor, f32 and f64, on a valid set (the shipped parameter
/// files' values, GMS and Xiong with 4 elements): OK, and a finite force
/// over 2,000 steps of the sweep.
#[test]
fn every_model_builds_and_steps_finite() {
    let gms = friction_gms_params {
        curve: CURVE,
        sigma2: 0.4,
        c: 20.0,
        elements: [
            (2.5e4, 0.4, 2.5),
            (5e4, 0.3, 5.0),
            (1e5, 0.2, 10.0),
            (2e5, 0.1, 20.0),
        ]
        .map(|(k, alpha, sigma1)| friction_gms_element { k, alpha, sigma1 }),
    };
    let xiong = friction_xiong_params {
        curve: CURVE,
        tau: 0.01,
        sigma2: 0.4,
        elements: [
            (2.5e4, 2.5, 0.4),
            (5e4, 5.0, 0.3),
            (1e5, 10.0, 0.2),
            (2e5, 20.0, 0.1),
        ]
        .map(|(k, sigma, lambda)| friction_xiong_element { k, sigma, lambda }),
    };
    let ep = friction_elasto_plastic_params {
        lugre: LUGRE,
        z_ba: 5e-6,
    };
    let dahl = friction_dahl_params {
        sigma: 1e5,
        fc: 1.0,
        delta: 1.0,
        sigma2: 0.4,
    };
    let bristle = friction_bristle_params {
        sigma0: 12_000.0,
        delta_s: 1e-5,
        seed: 1,
    };
    let reset = friction_reset_integrator_params {
        sigma0: 1e5,
        sigma1: 316.0,
        z0: 1e-5,
        stiction: 0.5,
        has_curve: 0,
        curve: CURVE,
    };
    let leuven = friction_leuven_params {
        curve: CURVE,
        sigma1: 15.0,
        sigma2: 0.4,
        n: 2.0,
        xs: 1e-5,
    };
    let cv = friction_coulomb_viscous_params {
        fc: 1.0,
        sigma2: 0.4,
    };
    let map = friction_stribeck_map_params {
        curve: CURVE,
        sigma2: 0.4,
    };
    let asym = friction_asymmetric_coulomb_viscous_params {
        fc_pos: 1.2,
        sigma2_pos: 0.5,
        fc_neg: 0.9,
        sigma2_neg: 0.35,
    };
    type Build64 = Box<dyn Fn(&mut friction_model_f64, f64) -> friction_status>;
    type Build32 = Box<dyn Fn(&mut friction_model_f32, f64) -> friction_status>;
    let e = || None;
    let cases: Vec<(&str, bool, Build64, Build32)> = vec![
        (
            "coulomb-viscous",
            false,
            Box::new(move |m, _| friction_coulomb_viscous_init_f64(Some(m), Some(&cv), e())),
            Box::new(move |m, _| friction_coulomb_viscous_init_f32(Some(m), Some(&cv), e())),
        ),
        (
            "stribeck",
            false,
            Box::new(move |m, _| friction_stribeck_map_init_f64(Some(m), Some(&map), e())),
            Box::new(move |m, _| friction_stribeck_map_init_f32(Some(m), Some(&map), e())),
        ),
        (
            "asymmetric-coulomb-viscous",
            false,
            Box::new(move |m, _| {
                friction_asymmetric_coulomb_viscous_init_f64(Some(m), Some(&asym), e())
            }),
            Box::new(move |m, _| {
                friction_asymmetric_coulomb_viscous_init_f32(Some(m), Some(&asym), e())
            }),
        ),
        (
            "bristle",
            false,
            Box::new(move |m, _| friction_bristle_init_f64(Some(m), Some(&bristle), e())),
            Box::new(move |m, _| friction_bristle_init_f32(Some(m), Some(&bristle), e())),
        ),
        (
            "reset-integrator",
            false,
            Box::new(move |m, _| friction_reset_integrator_init_f64(Some(m), Some(&reset), e())),
            Box::new(move |m, _| friction_reset_integrator_init_f32(Some(m), Some(&reset), e())),
        ),
        (
            "leuven",
            false,
            Box::new(move |m, _| friction_leuven_init_f64(Some(m), Some(&leuven), e())),
            Box::new(move |m, _| friction_leuven_init_f32(Some(m), Some(&leuven), e())),
        ),
        (
            "dahl",
            true,
            Box::new(move |m, h| friction_dahl_init_f64(Some(m), Some(&dahl), h, e())),
            Box::new(move |m, h| friction_dahl_init_f32(Some(m), Some(&dahl), h, e())),
        ),
        (
            "lugre",
            true,
            Box::new(move |m, h| friction_lugre_init_f64(Some(m), Some(&LUGRE), h, e())),
            Box::new(move |m, h| friction_lugre_init_f32(Some(m), Some(&LUGRE), h, e())),
        ),
        (
            "elasto-plastic",
            true,
            Box::new(move |m, h| friction_elasto_plastic_init_f64(Some(m), Some(&ep), h, e())),
            Box::new(move |m, h| friction_elasto_plastic_init_f32(Some(m), Some(&ep), h, e())),
        ),
        (
            "gms",
            true,
            Box::new(move |m, h| friction_gms_init_f64(Some(m), Some(&gms), h, e())),
            Box::new(move |m, h| friction_gms_init_f32(Some(m), Some(&gms), h, e())),
        ),
        (
            "xiong",
            true,
            Box::new(move |m, h| friction_xiong_init_f64(Some(m), Some(&xiong), h, e())),
            Box::new(move |m, h| friction_xiong_init_f32(Some(m), Some(&xiong), h, e())),
        ),
    ];
    // the cases are the core's list: each model with a form in the C ABI,
    // the fixed-step form where the list gives one
    let mut tested: Vec<(&str, bool)> = cases.iter().map(|(l, f, ..)| (*l, *f)).collect();
    let mut listed = c_models();
    tested.sort();
    listed.sort();
    assert_eq!(
        tested, listed,
        "a model of the list without its C constructors"
    );
    for (label, has_fixed, build64, build32) in &cases {
        let periods: &[f64] = if *has_fixed { &[0.0, 1e-4] } else { &[0.0] };
        for &period in periods {
            let mut m64 = model_f64();
            let mut m32 = model_f32();
            assert_eq!(
                build64(&mut m64, period),
                FRICTION_OK,
                "{label} f64 h {period}"
            );
            assert_eq!(
                build32(&mut m32, period),
                FRICTION_OK,
                "{label} f32 h {period}"
            );
            let mut peak = 0.0f64;
            for k in 0..runs(2000) {
                let (v, h) = signal(k);
                let (mut f64_, mut f32_) = (f64::NAN, f32::NAN);
                assert_eq!(
                    friction_model_step_f64(Some(&mut m64), v, h, Some(&mut f64_)),
                    FRICTION_OK
                );
                assert_eq!(
                    friction_model_step_f32(Some(&mut m32), v as f32, h as f32, Some(&mut f32_)),
                    FRICTION_OK
                );
                assert!(f64_.is_finite() && f32_.is_finite(), "{label} step {k}");
                peak = peak.max(f64_.abs());
            }
            // every model reaches its sliding force on this sweep (2 mm/s;
            // Miri's 10 steps stop before it)
            assert!(
                cfg!(miri) || (peak > 0.5 && peak < 10.0),
                "{label} h {period}: peak {peak}"
            );
        }
    }
    // a model with a fixed-step form refuses h < 0, naming h
    let mut m = model_f64();
    let mut err = no_error();
    assert_eq!(
        friction_lugre_init_f64(Some(&mut m), Some(&LUGRE), -1e-3, Some(&mut err)),
        FRICTION_NOT_POSITIVE
    );
    assert_eq!(name(&err), "h");
}

#[test]
fn asymmetric_map_through_the_abi_is_the_core() {
    let p = friction_asymmetric_coulomb_viscous_params {
        fc_pos: 1.2,
        sigma2_pos: 0.5,
        fc_neg: 0.9,
        sigma2_neg: 0.35,
    };
    let core = AsymmetricCoulombViscousParams::from(&p)
        .build::<f64>()
        .unwrap();
    let mut m = model_f64();
    assert_eq!(
        friction_asymmetric_coulomb_viscous_init_f64(Some(&mut m), Some(&p), None),
        FRICTION_OK
    );
    for v in [-2.0, -1e-3, 0.0, 1e-3, 2.0] {
        let mut f = f64::NAN;
        friction_model_step_f64(Some(&mut m), v, 1e-3, Some(&mut f));
        assert_eq!(f.to_bits(), core.force(v).to_bits(), "v = {v}");
    }
    // each side names its own parameter
    let mut err = no_error();
    let bad = friction_asymmetric_coulomb_viscous_params { fc_neg: -1.0, ..p };
    assert_eq!(
        friction_asymmetric_coulomb_viscous_init_f32(
            Some(&mut model_f32()),
            Some(&bad),
            Some(&mut err)
        ),
        FRICTION_NOT_POSITIVE
    );
    assert_eq!(name(&err), "fc_neg");
}

#[test]
fn lugre_through_the_abi_is_the_core_bit_for_bit() {
    let core = LuGreParams::CANUDAS_1995.build::<f64>().unwrap();
    let mut z = LuGreState::default();
    let mut m = model_f64();
    assert_eq!(
        friction_lugre_init_f64(Some(&mut m), Some(&LUGRE), 0.0, None),
        FRICTION_OK
    );
    for k in 0..runs(5000) {
        let (v, h) = signal(k);
        let mut f = 0.0;
        friction_model_step_f64(Some(&mut m), v, h, Some(&mut f));
        assert_eq!(f.to_bits(), core.step(&mut z, v, h).to_bits(), "step {k}");
    }
    // the fixed-step form in f32, the firmware's
    let core = LuGreParams::CANUDAS_1995
        .build_fixed_step::<f32>(1e-4)
        .unwrap();
    let mut z = LuGreFixedStepState::default();
    let mut m = model_f32();
    assert_eq!(
        friction_lugre_init_f32(Some(&mut m), Some(&LUGRE), 1e-4, None),
        FRICTION_OK
    );
    for k in 0..runs(5000) {
        let (v, _) = signal(k);
        let mut f = 0.0;
        assert_eq!(
            friction_model_step_f32(Some(&mut m), v as f32, 1e-4, Some(&mut f)),
            FRICTION_OK
        );
        assert_eq!(
            f.to_bits(),
            core.step(&mut z, v as f32).to_bits(),
            "step {k}"
        );
    }
}

#[test]
fn invalid_parameters_are_named_and_leave_the_object_as_it_was() {
    let mut m = model_f64();
    assert_eq!(
        friction_lugre_init_f64(Some(&mut m), Some(&LUGRE), 0.0, None),
        FRICTION_OK
    );
    let cases = [
        (
            friction_lugre_params {
                sigma0: -1.0,
                ..LUGRE
            },
            FRICTION_NOT_POSITIVE,
            "sigma0",
        ),
        (
            friction_lugre_params {
                sigma1: f64::NAN,
                ..LUGRE
            },
            FRICTION_NOT_FINITE,
            "sigma1",
        ),
        (
            friction_lugre_params {
                curve: friction_stribeck { fs: 0.5, ..CURVE },
                ..LUGRE
            },
            FRICTION_STATIC_BELOW_COULOMB,
            "fs",
        ),
        (
            friction_lugre_params {
                sigma0: 1e30,
                ..LUGRE
            },
            FRICTION_OUT_OF_RANGE,
            "sigma0",
        ),
        (
            friction_lugre_params { vd: -1.0, ..LUGRE },
            FRICTION_NOT_POSITIVE,
            "vd",
        ),
    ];
    for (p, status, param) in cases {
        let mut err = no_error();
        assert_eq!(
            friction_lugre_init_f64(Some(&mut m), Some(&p), 0.0, Some(&mut err)),
            status,
            "{param}"
        );
        assert_eq!(err.status, status as i32);
        assert_eq!(name(&err), param);
    }
    // the refused constructors left the model as it was: it steps as a fresh one
    let mut fresh = model_f64();
    friction_lugre_init_f64(Some(&mut fresh), Some(&LUGRE), 0.0, None);
    same_run_f64(&mut m, &mut fresh, 300);
    // f32 cannot hold it
    let mut m32 = model_f32();
    let mut err = no_error();
    let huge = friction_lugre_params {
        sigma2: 1e39,
        ..LUGRE
    };
    let status = friction_lugre_init_f32(Some(&mut m32), Some(&huge), 0.0, Some(&mut err));
    assert!(
        matches!(status, FRICTION_OUT_OF_RANGE | FRICTION_NOT_REPRESENTABLE),
        "{status:?}"
    );
    assert_eq!(name(&err), "sigma2");
    // GMS weights that do not sum to 1
    let mut gms = friction_gms_params {
        curve: CURVE,
        sigma2: 0.0,
        c: 20.0,
        elements: [friction_gms_element {
            k: 1e5,
            alpha: 0.25,
            sigma1: 0.0,
        }; FRICTION_ELEMENTS],
    };
    assert_eq!(
        friction_gms_init_f64(Some(&mut m), Some(&gms), 0.0, None),
        FRICTION_OK
    );
    gms.elements[0].alpha = 0.5;
    let mut err = no_error();
    assert_eq!(
        friction_gms_init_f64(Some(&mut m), Some(&gms), 0.0, Some(&mut err)),
        FRICTION_WEIGHTS_NOT_ONE
    );
    assert_eq!(name(&err), "alpha");
}

#[test]
fn null_and_uninitialised_objects_get_a_status() {
    let mut err = no_error();
    assert_eq!(
        friction_lugre_init_f64(None, Some(&LUGRE), 0.0, Some(&mut err)),
        FRICTION_NULL_POINTER
    );
    assert_eq!(name(&err), "out");
    assert_eq!(
        friction_lugre_init_f64(Some(&mut model_f64()), None, 0.0, Some(&mut err)),
        FRICTION_NULL_POINTER
    );
    assert_eq!(name(&err), "params");
    let mut f = 0.0;
    assert_eq!(
        friction_model_step_f64(None, 0.0, 1e-3, Some(&mut f)),
        FRICTION_NULL_POINTER
    );
    assert_eq!(
        friction_model_step_f64(Some(&mut model_f64()), 0.0, 1e-3, None),
        FRICTION_NULL_POINTER
    );
    assert_eq!(
        friction_model_step_f64(Some(&mut model_f64()), 0.0, 1e-3, Some(&mut f)),
        FRICTION_NOT_INITIALISED
    );
    assert_eq!(
        friction_model_reset_f64(Some(&mut model_f64())),
        FRICTION_NOT_INITIALISED
    );
    assert_eq!(friction_model_reset_f32(None), FRICTION_NULL_POINTER);
    // garbage that is not a constructor's output
    let mut junk = friction_model_f64 {
        opaque: [0xDEAD_BEEF; FRICTION_MODEL_F64_WORDS],
    };
    assert_eq!(
        friction_model_step_f64(Some(&mut junk), 0.0, 1e-3, Some(&mut f)),
        FRICTION_NOT_INITIALISED
    );
    assert_eq!(
        friction_observer_init_f64(
            Some(&mut friction_observer_f64 {
                opaque: [0; FRICTION_OBSERVER_F64_WORDS]
            }),
            None,
            10.0,
            true,
            Some(&mut err)
        ),
        FRICTION_NULL_POINTER
    );
    assert_eq!(name(&err), "model");
    // an observer of an uninitialised model
    let mut o = friction_observer_f64 {
        opaque: [0; FRICTION_OBSERVER_F64_WORDS],
    };
    assert_eq!(
        friction_observer_init_f64(Some(&mut o), Some(&model_f64()), 10.0, true, Some(&mut err)),
        FRICTION_NOT_INITIALISED
    );
    assert_eq!(name(&err), "model");
    assert_eq!(
        friction_observer_step_f64(Some(&mut o), 0.0, 0.0, 1e-3, Some(&mut f)),
        FRICTION_NOT_INITIALISED
    );
    assert_eq!(friction_observer_reset_f64(None), FRICTION_NULL_POINTER);
    // servos
    let p = servo_params();
    let mut s = friction_servo_f32 {
        opaque: [0; FRICTION_SERVO_F32_WORDS],
    };
    let r = friction_setpoint_f32 {
        x: 0.0,
        v: 0.0,
        a: 0.0,
    };
    let mut t = friction_tick_f32 {
        command: 1.0,
        friction: 1.0,
    };
    assert_eq!(
        friction_servo_tick_f32(Some(&mut s), 0.0, r, Some(&mut t)),
        FRICTION_NOT_INITIALISED
    );
    assert_eq!(
        friction_servo_tick_f32(None, 0.0, r, Some(&mut t)),
        FRICTION_NULL_POINTER
    );
    assert_eq!(
        friction_servo_init_f32(Some(&mut s), None, None, 0.0, None, None),
        FRICTION_NULL_POINTER
    );
    assert_eq!(
        friction_servo_init_f32(Some(&mut s), Some(&p), Some(&model_f32()), 0.0, None, None),
        FRICTION_NOT_INITIALISED
    );
    assert_eq!(
        friction_servo_init_f32(Some(&mut s), Some(&p), None, 0.0, None, None),
        FRICTION_OK
    );
    assert_eq!(
        friction_servo_tick_f32(Some(&mut s), 0.0, r, None),
        FRICTION_NULL_POINTER
    );
    let mut theta = 0.0;
    assert_eq!(
        friction_servo_theta_f32(Some(&mut s), Some(&mut theta)),
        FRICTION_NOT_SUPPORTED
    );
    assert_eq!(friction_servo_reset_f64(None), FRICTION_NULL_POINTER);
}

#[test]
fn hostile_inputs_leave_the_state_unchanged() {
    let mut a = model_f64();
    assert_eq!(
        friction_lugre_init_f64(Some(&mut a), Some(&LUGRE), 0.0, None),
        FRICTION_OK
    );
    let mut b = model_f64();
    friction_lugre_init_f64(Some(&mut b), Some(&LUGRE), 0.0, None);
    let mut f = 0.0;
    for k in 0..runs(500) {
        let (v, h) = signal(k);
        friction_model_step_f64(Some(&mut a), v, h, Some(&mut f));
        friction_model_step_f64(Some(&mut b), v, h, Some(&mut f));
        if k % 7 == 0 {
            for (v, h) in [
                (f64::NAN, h),
                (f64::INFINITY, h),
                (v, f64::NAN),
                (v, -1.0),
                (v, f64::INFINITY),
            ] {
                assert_eq!(
                    friction_model_step_f64(Some(&mut b), v, h, Some(&mut f)),
                    FRICTION_INPUT_REJECTED
                );
                assert!(f.is_finite());
            }
        }
    }
    // the rejected inputs changed nothing: the two step alike from here
    same_run_f64(&mut a, &mut b, 300);
    // a fixed-step model refuses another period, state unchanged
    let mut m = model_f32();
    assert_eq!(
        friction_lugre_init_f32(Some(&mut m), Some(&LUGRE), 1e-3, None),
        FRICTION_OK
    );
    let mut twin = model_f32();
    friction_lugre_init_f32(Some(&mut twin), Some(&LUGRE), 1e-3, None);
    friction_model_step_f32(Some(&mut m), 1e-4, 1e-3, Some(&mut 0.0));
    friction_model_step_f32(Some(&mut twin), 1e-4, 1e-3, Some(&mut 0.0));
    assert_eq!(
        friction_model_step_f32(Some(&mut m), 1e-4, 2e-3, Some(&mut 0.0)),
        FRICTION_PERIOD_MISMATCH
    );
    for k in 0..runs(300) {
        let (v, _) = signal(k);
        let (mut f1, mut f2) = (0.0f32, 0.0f32);
        friction_model_step_f32(Some(&mut m), v as f32, 1e-3, Some(&mut f1));
        friction_model_step_f32(Some(&mut twin), v as f32, 1e-3, Some(&mut f2));
        assert_eq!(
            f1.to_bits(),
            f2.to_bits(),
            "step {k} after the refused period"
        );
    }
    // reset: back at rest, the same as a fresh model
    assert_eq!(friction_model_reset_f32(Some(&mut m)), FRICTION_OK);
    let mut fresh = model_f32();
    friction_lugre_init_f32(Some(&mut fresh), Some(&LUGRE), 1e-3, None);
    let (mut f1, mut f2) = (0.0, 0.0);
    friction_model_step_f32(Some(&mut m), 1e-4, 1e-3, Some(&mut f1));
    friction_model_step_f32(Some(&mut fresh), 1e-4, 1e-3, Some(&mut f2));
    assert_eq!(f1.to_bits(), f2.to_bits());
}

#[test]
fn observers_match_the_core_and_refuse_static_maps() {
    let mut m = model_f64();
    friction_lugre_init_f64(Some(&mut m), Some(&LUGRE), 0.0, None);
    let mut o = friction_observer_f64 {
        opaque: [0; FRICTION_OBSERVER_F64_WORDS],
    };
    assert_eq!(
        friction_observer_init_f64(Some(&mut o), Some(&m), 200.0, true, None),
        FRICTION_OK
    );
    let core = Observer::new(LuGreParams::CANUDAS_1995.build::<f64>().unwrap(), 200.0).unwrap();
    let mut z = LuGreState::default();
    for k in 0..runs(3000) {
        let (v, h) = signal(k);
        let e = 1e-6 * (k as f64 * 0.01).cos();
        let mut f = 0.0;
        assert_eq!(
            friction_observer_step_f64(Some(&mut o), v, e, h, Some(&mut f)),
            FRICTION_OK
        );
        assert_eq!(
            f.to_bits(),
            core.step(&mut z, v, e, h).to_bits(),
            "step {k}"
        );
    }
    // a negative gain is named
    let mut err = no_error();
    assert_eq!(
        friction_observer_init_f64(Some(&mut o), Some(&m), -1.0, true, Some(&mut err)),
        FRICTION_NEGATIVE
    );
    assert_eq!(name(&err), "gain");
    // a static map has no state to observe
    let mut cv = model_f64();
    friction_coulomb_viscous_init_f64(
        Some(&mut cv),
        Some(&friction_coulomb_viscous_params {
            fc: 1.0,
            sigma2: 0.0,
        }),
        None,
    );
    assert_eq!(
        friction_observer_init_f64(Some(&mut o), Some(&cv), 10.0, true, Some(&mut err)),
        FRICTION_NOT_SUPPORTED
    );
}

fn servo_params() -> friction_servo_params {
    let w = 2.0 * std::f64::consts::PI * 10.0;
    let j = 0.0023;
    friction_servo_params {
        h: 1e-3,
        kp: j * w * w,
        ki: 0.0,
        kd: 2.0 * j * w,
        inertia: j,
        torque_constant: 1.0,
        limit: 5.0,
    }
}

fn core_servo_params(p: &friction_servo_params) -> CompensatorParams {
    CompensatorParams {
        h: p.h,
        kp: p.kp,
        ki: p.ki,
        kd: p.kd,
        inertia: p.inertia,
        torque_constant: p.torque_constant,
        limit: p.limit,
    }
}

/// The firmware's tick (`LuGreServo<f32>`, Olsson's set at 1 kHz, gain
/// 200/s) through the ABI, bit for bit; then the adaptive tick's theta.
#[test]
fn servo_tick_matches_the_core() {
    let olsson = LuGreParams::OLSSON_1998;
    let c = olsson.curve;
    let p = friction_lugre_params {
        curve: friction_stribeck {
            fc: c.fc,
            fs: c.fs,
            vs: c.vs,
            exponent: c.exponent,
        },
        sigma0: olsson.sigma0,
        sigma1: olsson.sigma1,
        sigma2: olsson.sigma2,
        vd: olsson.vd.unwrap_or(0.0),
    };
    let sp = servo_params();
    let mut m = model_f32();
    assert_eq!(
        friction_lugre_init_f32(Some(&mut m), Some(&p), sp.h, None),
        FRICTION_OK
    );
    let mut s = friction_servo_f32 {
        opaque: [0; FRICTION_SERVO_F32_WORDS],
    };
    assert_eq!(
        friction_servo_init_f32(Some(&mut s), Some(&sp), Some(&m), 200.0, None, None),
        FRICTION_OK
    );
    let core: LuGreServo<f32> = core_servo_params(&sp)
        .build(FixedPeriod(
            Observer::new(olsson.build_fixed_step::<f32>(sp.h).unwrap(), 200.0).unwrap(),
        ))
        .unwrap();
    let mut state = Default::default();
    for k in 0..runs(4000) {
        let x = 1e-3 * (k as f32 * 0.02).sin();
        let r = Setpoint {
            x: x + 1e-5,
            v: 0.02 * (k as f32 * 0.02).cos(),
            a: 0.0,
        };
        let mut t = friction_tick_f32 {
            command: 0.0,
            friction: 0.0,
        };
        assert_eq!(
            friction_servo_tick_f32(
                Some(&mut s),
                x,
                friction_setpoint_f32 {
                    x: r.x,
                    v: r.v,
                    a: r.a
                },
                Some(&mut t)
            ),
            FRICTION_OK
        );
        let want = core.tick(&mut state, x, r);
        assert_eq!(
            (t.command.to_bits(), t.friction.to_bits()),
            (want.command.to_bits(), want.friction.to_bits()),
            "tick {k}"
        );
    }
    // NaN position: the safe output, then the same ticks as before
    let mut t = friction_tick_f32 {
        command: 1.0,
        friction: 1.0,
    };
    let r = friction_setpoint_f32 {
        x: 0.0,
        v: 0.0,
        a: 0.0,
    };
    assert_eq!(
        friction_servo_tick_f32(Some(&mut s), f32::NAN, r, Some(&mut t)),
        FRICTION_INPUT_REJECTED
    );
    assert_eq!((t.command, t.friction), (0.0, 0.0));
    // a fixed-step model built for another period is refused
    let mut err = no_error();
    let other = friction_servo_params { h: 5e-4, ..sp };
    assert_eq!(
        friction_servo_init_f32(
            Some(&mut s),
            Some(&other),
            Some(&m),
            200.0,
            None,
            Some(&mut err)
        ),
        FRICTION_PERIOD_MISMATCH
    );
    assert_eq!(name(&err), "h");
    // adaptive: theta starts at theta0 and moves when friction is twice the model's
    let a = AdaptiveParams::DEFAULT;
    let ap = friction_adaptive_params {
        gamma: 50.0,
        gamma_derivative: 0.0,
        leakage: a.leakage,
        theta0: a.theta0,
        theta_min: a.theta_min,
        theta_max: a.theta_max,
    };
    assert_eq!(
        friction_servo_init_f32(Some(&mut s), Some(&sp), Some(&m), 200.0, Some(&ap), None),
        FRICTION_OK
    );
    let mut theta = 0.0;
    assert_eq!(
        friction_servo_theta_f32(Some(&mut s), Some(&mut theta)),
        FRICTION_OK
    );
    assert_eq!(f64::from(theta), a.theta0);
    for k in 0..runs(2000) {
        // a position lagging the setpoint: positive error integrates theta
        let r = friction_setpoint_f32 {
            x: k as f32 * 1e-5,
            v: 1e-2,
            a: 0.0,
        };
        friction_servo_tick_f32(Some(&mut s), k as f32 * 1e-5 - 1e-4, r, Some(&mut t));
    }
    friction_servo_theta_f32(Some(&mut s), Some(&mut theta));
    assert!(f64::from(theta) != a.theta0, "theta did not adapt: {theta}");
    // feed-forward from a static map; adaptive on a static map is refused
    let mut cv = model_f32();
    friction_coulomb_viscous_init_f32(
        Some(&mut cv),
        Some(&friction_coulomb_viscous_params {
            fc: 0.28,
            sigma2: 0.0,
        }),
        None,
    );
    assert_eq!(
        friction_servo_init_f32(Some(&mut s), Some(&sp), Some(&cv), 0.0, None, None),
        FRICTION_OK
    );
    // moving forward at 0.1 rad/s: the feed-forward is +fc
    for k in 0..3 {
        let x = k as f32 * 1e-4;
        friction_servo_tick_f32(
            Some(&mut s),
            x,
            friction_setpoint_f32 { x, v: 0.1, a: 0.0 },
            Some(&mut t),
        );
    }
    assert!((t.friction - 0.28).abs() < 1e-6, "{}", t.friction);
    assert_eq!(
        friction_servo_init_f32(
            Some(&mut s),
            Some(&sp),
            Some(&cv),
            0.0,
            Some(&ap),
            Some(&mut err)
        ),
        FRICTION_NOT_SUPPORTED
    );
    assert_eq!(name(&err), "adaptive");
    // the period check of a fixed-step model's own steps still holds
    assert_eq!(
        friction_model_step_f32(Some(&mut m), 0.0, 1e-3, Some(&mut 0.0)),
        FRICTION_OK
    );
    let _ = FixedStepModel::period(&olsson.build_fixed_step::<f32>(1e-3).unwrap());
}

/// Olsson's model as the ABI takes it.
fn olsson_abi() -> friction_lugre_params {
    let o = LuGreParams::OLSSON_1998;
    friction_lugre_params {
        curve: friction_stribeck {
            fc: o.curve.fc,
            fs: o.curve.fs,
            vs: o.curve.vs,
            exponent: o.curve.exponent,
        },
        sigma0: o.sigma0,
        sigma1: o.sigma1,
        sigma2: o.sigma2,
        vd: 0.0,
    }
}

/// The per-parameter law of the ABI test: Olsson's model with its levels
/// 1.5x a plant's, a load term, the supervisor's defaults with a tolerance.
fn parameter_abi() -> (
    friction_parameter_adaptive_params,
    friction_supervisor_params,
    friction_coulomb_viscous_params,
) {
    let mut model = olsson_abi();
    model.curve.fc *= 1.5;
    model.curve.fs *= 1.5;
    let mut p = friction_parameter_adaptive_params {
        model,
        observer_gain: f64::NAN,
        rate: f64::NAN,
        derivative_weight: f64::NAN,
        leakage: f64::NAN,
        box_factor: f64::NAN,
        dead_zone: f64::NAN,
        min_speed: f64::NAN,
        speed: f64::NAN,
        load: f64::NAN,
        load_max: f64::NAN,
        exact_step: 0xA5,
    };
    assert_eq!(
        friction_parameter_adaptive_defaults(Some(&model), 20.0, Some(&mut p)),
        FRICTION_OK
    );
    // the defaults overwrite every field, the step's flag too
    assert_eq!(p.exact_step, 0);
    p.rate = 16.0;
    p.speed = 0.63;
    p.load_max = 0.05;
    let mut sup = friction_supervisor_params {
        window: 0.0,
        memory: 0.0,
        ratio: 0.0,
        warm_up: 0.0,
        retry: 0.0,
        tolerance: 0.0,
    };
    assert_eq!(friction_supervisor_defaults(Some(&mut sup)), FRICTION_OK);
    sup.tolerance = 0.0028;
    let fallback = friction_coulomb_viscous_params {
        fc: 0.42,
        sigma2: 0.0176,
    };
    (p, sup, fallback)
}

/// The core's supervised per-parameter servo with the same settings.
fn parameter_core<S: Scalar>(sp: &friction_servo_params) -> ParameterAdaptiveServo<S> {
    let (p, sup, fb) = parameter_abi();
    let servo = core_servo_params(sp);
    let law = ParameterAdaptiveParams::from(&p)
        .build_fixed_step::<S>(&servo)
        .unwrap();
    let map = CoulombViscousParams::from(&fb).build::<S>().unwrap();
    let supervised = SupervisorParams::from(&sup)
        .build(law, map, &servo)
        .unwrap();
    servo.build(supervised).unwrap()
}

/// A plant with Coulomb + viscous friction (the levels of the law's model
/// over 1.5, 1.2x forward, 0.8x backward) and the 1 kHz loop: `tick` gives
/// the command from the measured position and the setpoint.
fn asymmetric_plant(seconds: usize, mut tick: impl FnMut(usize, f64, Setpoint<f64>) -> f64) {
    let (mut x, mut v) = (0.0f64, 0.0f64);
    let w = 2.0 * std::f64::consts::PI * 0.2;
    for k in 0..seconds * 1000 {
        let t = k as f64 * 1e-3;
        let r = Setpoint {
            x: 0.5 * (w * t).sin(),
            v: 0.5 * w * (w * t).cos(),
            a: -0.5 * w * w * (w * t).sin(),
        };
        let u = tick(k, x, r);
        for _ in 0..100 {
            let side = if v >= 0.0 { 1.2 } else { 0.8 };
            let f = side * 0.28 * (v / 1e-3).tanh() + 0.0176 * v;
            v += 1e-5 * (1.02 * u - f) / 0.0023;
            x += 1e-5 * v;
        }
    }
}

/// With `exact_step` set the per-parameter servo is the core's exact-step
/// form (`build_fixed_step_exact`), bit for bit, with its estimates and
/// status readable; a re-tune keeps the step (the other one is refused,
/// naming `exact_step`, the axis untouched) and a re-tune with the same
/// step takes.
#[test]
fn the_exact_step_through_the_abi_is_the_cores() {
    let sp = friction_servo_params {
        torque_constant: 1.02,
        limit: 10.0,
        ki: 200.0,
        kp: 60.0,
        kd: 1.2,
        ..servo_params()
    };
    let (mut p, sup, fb) = parameter_abi();
    p.exact_step = 1;
    let mut s = friction_servo_f32 {
        opaque: [0; FRICTION_SERVO_F32_WORDS],
    };
    assert_eq!(
        friction_servo_parameter_adaptive_init_f32(
            Some(&mut s),
            Some(&sp),
            Some(&p),
            Some(&sup),
            Some(&fb),
            None
        ),
        FRICTION_OK
    );
    let servo = core_servo_params(&sp);
    let law = ParameterAdaptiveParams::from(&p)
        .build_fixed_step_exact::<f32>(&servo)
        .unwrap();
    let map = CoulombViscousParams::from(&fb).build::<f32>().unwrap();
    let core = servo
        .build(
            SupervisorParams::from(&sup)
                .build(law, map, &servo)
                .unwrap(),
        )
        .unwrap();
    // the implicit step's servo, to show the two differ on this run
    let implicit = parameter_core::<f32>(&sp);
    let (mut state, mut other) = (Default::default(), Default::default());
    let mut differ = 0;
    asymmetric_plant(runs(5), |k, x, r| {
        let mut t = friction_tick_f32 {
            command: 0.0,
            friction: 0.0,
        };
        let (xf, rf) = (
            x as f32,
            friction_setpoint_f32 {
                x: r.x as f32,
                v: r.v as f32,
                a: r.a as f32,
            },
        );
        assert_eq!(
            friction_servo_tick_f32(Some(&mut s), xf, rf, Some(&mut t)),
            FRICTION_OK
        );
        let set = Setpoint {
            x: rf.x,
            v: rf.v,
            a: rf.a,
        };
        let want = core.tick(&mut state, xf, set);
        assert_eq!(
            (t.command.to_bits(), t.friction.to_bits()),
            (want.command.to_bits(), want.friction.to_bits()),
            "tick {k}"
        );
        differ += usize::from(implicit.tick(&mut other, xf, set).friction != want.friction);
        f64::from(t.command)
    });
    assert!(differ > 0);
    let mut e = friction_estimates_f32 {
        fc_pos: 0.0,
        fc_neg: 0.0,
        stribeck: 0.0,
        sigma2: 0.0,
        load: 0.0,
    };
    assert_eq!(
        friction_servo_estimates_f32(Some(&mut s), Some(&mut e)),
        FRICTION_OK
    );
    assert_eq!(
        [e.fc_pos, e.fc_neg, e.stribeck, e.sigma2, e.load],
        core.compensation()
            .primary()
            .estimates(&state.friction().primary)
    );
    let mut st = friction_supervisor_status {
        mode: friction_mode::FRICTION_MODE_OFF,
        switches: 99,
        windows: 0,
        since_switch: 0,
    };
    assert_eq!(
        friction_servo_supervisor_f32(Some(&mut s), Some(&mut st)),
        FRICTION_OK
    );
    assert_eq!(
        st.windows,
        core.compensation().status(state.friction()).windows
    );
    // a re-tune to the implicit step: refused, naming the flag, untouched
    let before = s.opaque;
    let mut err = no_error();
    let implicit_params = friction_parameter_adaptive_params { exact_step: 0, ..p };
    assert_eq!(
        friction_servo_parameter_adaptive_retune_f32(
            Some(&mut s),
            Some(&implicit_params),
            Some(&sup),
            Some(&fb),
            Some(&mut err)
        ),
        FRICTION_NOT_SUPPORTED
    );
    assert_eq!(name(&err), "exact_step");
    assert_eq!(s.opaque, before);
    // the same step with another rate: taken
    let faster = friction_parameter_adaptive_params { rate: 32.0, ..p };
    assert_eq!(
        friction_servo_parameter_adaptive_retune_f32(
            Some(&mut s),
            Some(&faster),
            Some(&sup),
            Some(&fb),
            None
        ),
        FRICTION_OK
    );
    assert_ne!(s.opaque, before);
}

/// The per-parameter adaptive servo under its supervisor through the ABI,
/// in `float` and `double`: bit for bit the core's
/// `ParameterAdaptiveServo` on a closed-loop run against an asymmetric
/// plant; the estimates and the supervisor's status as the core reads
/// them; the forward and backward Coulomb levels learnt apart.
#[test]
fn parameter_adaptive_servo_matches_the_core() {
    let sp = friction_servo_params {
        torque_constant: 1.02,
        limit: 10.0,
        ki: 200.0,
        kp: 60.0,
        kd: 1.2,
        ..servo_params()
    };
    let (p, sup, fb) = parameter_abi();
    let mut err = no_error();
    // f32
    let mut s = friction_servo_f32 {
        opaque: [0; FRICTION_SERVO_F32_WORDS],
    };
    assert_eq!(
        friction_servo_parameter_adaptive_init_f32(
            Some(&mut s),
            Some(&sp),
            Some(&p),
            Some(&sup),
            Some(&fb),
            Some(&mut err)
        ),
        FRICTION_OK
    );
    let core = parameter_core::<f32>(&sp);
    let mut state = Default::default();
    let mut e = friction_estimates_f32 {
        fc_pos: 0.0,
        fc_neg: 0.0,
        stribeck: 0.0,
        sigma2: 0.0,
        load: 0.0,
    };
    // before the first tick: the nominal values
    assert_eq!(
        friction_servo_estimates_f32(Some(&mut s), Some(&mut e)),
        FRICTION_OK
    );
    assert_eq!((e.fc_pos, e.fc_neg), (0.42, 0.42));
    asymmetric_plant(runs(20), |k, x, r| {
        let mut t = friction_tick_f32 {
            command: 0.0,
            friction: 0.0,
        };
        let (xf, rf) = (
            x as f32,
            friction_setpoint_f32 {
                x: r.x as f32,
                v: r.v as f32,
                a: r.a as f32,
            },
        );
        assert_eq!(
            friction_servo_tick_f32(Some(&mut s), xf, rf, Some(&mut t)),
            FRICTION_OK
        );
        let want = core.tick(
            &mut state,
            xf,
            Setpoint {
                x: rf.x,
                v: rf.v,
                a: rf.a,
            },
        );
        assert_eq!(
            (t.command.to_bits(), t.friction.to_bits()),
            (want.command.to_bits(), want.friction.to_bits()),
            "tick {k}"
        );
        f64::from(t.command)
    });
    assert_eq!(
        friction_servo_estimates_f32(Some(&mut s), Some(&mut e)),
        FRICTION_OK
    );
    let want = core
        .compensation()
        .primary()
        .estimates(&state.friction().primary);
    assert_eq!(
        [e.fc_pos, e.fc_neg, e.stribeck, e.sigma2, e.load],
        want,
        "the ABI reads the core's estimates"
    );
    let mut st = friction_supervisor_status {
        mode: friction_mode::FRICTION_MODE_OFF,
        switches: 99,
        windows: 0,
        since_switch: 0,
    };
    assert_eq!(
        friction_servo_supervisor_f32(Some(&mut s), Some(&mut st)),
        FRICTION_OK
    );
    let status = core.compensation().status(state.friction());
    assert_eq!(
        (st.mode as u8, st.switches, st.windows, st.since_switch),
        (
            status.mode.code(),
            status.switches,
            status.windows,
            status.since_switch
        )
    );
    if runs(20) == 20 {
        // 20 s of 0.1 s windows, the first (after the start) not measured;
        // the law predicts best and stays applied
        assert_eq!(st.windows, 198);
        assert_eq!(status.mode, SupervisorMode::Primary);
        // the forward level learnt above the backward one (plant 0.336 and 0.224)
        assert!(
            e.fc_pos > e.fc_neg + 0.05 && e.fc_pos < 0.42 && e.fc_neg < 0.3,
            "{e:?}"
        );
    }
    // f64: the same run, bit for bit the core's
    let mut s = friction_servo_f64 {
        opaque: [0; FRICTION_SERVO_F64_WORDS],
    };
    assert_eq!(
        friction_servo_parameter_adaptive_init_f64(
            Some(&mut s),
            Some(&sp),
            Some(&p),
            Some(&sup),
            Some(&fb),
            None
        ),
        FRICTION_OK
    );
    let core = parameter_core::<f64>(&sp);
    let mut state = Default::default();
    asymmetric_plant(runs(20), |k, x, r| {
        let mut t = friction_tick_f64 {
            command: 0.0,
            friction: 0.0,
        };
        let rf = friction_setpoint_f64 {
            x: r.x,
            v: r.v,
            a: r.a,
        };
        assert_eq!(
            friction_servo_tick_f64(Some(&mut s), x, rf, Some(&mut t)),
            FRICTION_OK
        );
        let want = core.tick(&mut state, x, r);
        assert_eq!(
            (t.command.to_bits(), t.friction.to_bits()),
            (want.command.to_bits(), want.friction.to_bits()),
            "tick {k}"
        );
        t.command
    });
    let mut e = friction_estimates_f64 {
        fc_pos: 0.0,
        fc_neg: 0.0,
        stribeck: 0.0,
        sigma2: 0.0,
        load: 0.0,
    };
    assert_eq!(
        friction_servo_estimates_f64(Some(&mut s), Some(&mut e)),
        FRICTION_OK
    );
    assert_eq!(
        [e.fc_pos, e.fc_neg, e.stribeck, e.sigma2, e.load],
        core.compensation()
            .primary()
            .estimates(&state.friction().primary)
    );
    assert_eq!(
        friction_servo_supervisor_f64(Some(&mut s), Some(&mut st)),
        FRICTION_OK
    );
    assert_eq!(st.mode, friction_mode::FRICTION_MODE_PRIMARY);
    // reset: before the first tick again, the nominal estimates
    assert_eq!(friction_servo_reset_f64(Some(&mut s)), FRICTION_OK);
    friction_servo_estimates_f64(Some(&mut s), Some(&mut e));
    let fc = p.model.curve.fc;
    assert_eq!((e.fc_pos, e.fc_neg), (fc, fc));
    // the theta reader does not apply; the readers refuse other kinds
    let mut theta = 0.0;
    assert_eq!(
        friction_servo_theta_f64(Some(&mut s), Some(&mut theta)),
        FRICTION_NOT_SUPPORTED
    );
    let mut plain = friction_servo_f64 {
        opaque: [0; FRICTION_SERVO_F64_WORDS],
    };
    assert_eq!(
        friction_servo_estimates_f64(Some(&mut plain), Some(&mut e)),
        FRICTION_NOT_INITIALISED
    );
    assert_eq!(
        friction_servo_init_f64(Some(&mut plain), Some(&sp), None, 0.0, None, None),
        FRICTION_OK
    );
    assert_eq!(
        friction_servo_estimates_f64(Some(&mut plain), Some(&mut e)),
        FRICTION_NOT_SUPPORTED
    );
    assert_eq!(
        friction_servo_supervisor_f64(Some(&mut plain), Some(&mut st)),
        FRICTION_NOT_SUPPORTED
    );
    assert_eq!(
        friction_servo_supervisor_f64(Some(&mut plain), None),
        FRICTION_NULL_POINTER
    );
    assert_eq!(
        friction_servo_estimates_f64(None, Some(&mut e)),
        FRICTION_NULL_POINTER
    );
}

/// Invalid settings are named, NULLs are refused by name, and a refused
/// constructor leaves its object as it was.
#[test]
fn parameter_adaptive_servo_refuses_invalid_settings() {
    let sp = servo_params();
    let (p, sup, fb) = parameter_abi();
    let mut s = friction_servo_f32 {
        opaque: [0; FRICTION_SERVO_F32_WORDS],
    };
    assert_eq!(
        friction_servo_init_f32(Some(&mut s), Some(&sp), None, 0.0, None, None),
        FRICTION_OK
    );
    let before = s.opaque;
    let mut err = no_error();
    let mut refuse = |p: friction_parameter_adaptive_params,
                      sup: friction_supervisor_params,
                      fb: friction_coulomb_viscous_params,
                      status: friction_status,
                      parameter: &str| {
        assert_eq!(
            friction_servo_parameter_adaptive_init_f32(
                Some(&mut s),
                Some(&sp),
                Some(&p),
                Some(&sup),
                Some(&fb),
                Some(&mut err)
            ),
            status,
            "{parameter}"
        );
        assert_eq!(name(&err), parameter);
        assert_eq!(s.opaque, before);
    };
    refuse(
        friction_parameter_adaptive_params { rate: -1.0, ..p },
        sup,
        fb,
        FRICTION_NEGATIVE,
        "rate",
    );
    refuse(
        friction_parameter_adaptive_params {
            box_factor: 0.5,
            ..p
        },
        sup,
        fb,
        FRICTION_BELOW_ONE,
        "box_factor",
    );
    refuse(
        friction_parameter_adaptive_params {
            load: 1.0,
            load_max: 0.5,
            ..p
        },
        sup,
        fb,
        FRICTION_NOT_BELOW,
        "load",
    );
    refuse(
        p,
        friction_supervisor_params { ratio: 1.5, ..sup },
        fb,
        FRICTION_NOT_BELOW,
        "ratio",
    );
    refuse(
        p,
        friction_supervisor_params {
            window: f64::NAN,
            ..sup
        },
        fb,
        FRICTION_NOT_FINITE,
        "window",
    );
    refuse(
        p,
        sup,
        friction_coulomb_viscous_params { fc: -1.0, ..fb },
        FRICTION_NOT_POSITIVE,
        "fc",
    );
    for (which, status) in [
        ("params", FRICTION_NULL_POINTER),
        ("adaptive", FRICTION_NULL_POINTER),
        ("supervisor", FRICTION_NULL_POINTER),
        ("fallback", FRICTION_NULL_POINTER),
    ] {
        let got = friction_servo_parameter_adaptive_init_f64(
            Some(&mut friction_servo_f64 {
                opaque: [0; FRICTION_SERVO_F64_WORDS],
            }),
            (which != "params").then_some(&sp),
            (which != "adaptive").then_some(&p),
            (which != "supervisor").then_some(&sup),
            (which != "fallback").then_some(&fb),
            Some(&mut err),
        );
        assert_eq!(got, status);
        assert_eq!(name(&err), which);
    }
    assert_eq!(
        friction_servo_parameter_adaptive_init_f64(
            None,
            Some(&sp),
            Some(&p),
            Some(&sup),
            Some(&fb),
            Some(&mut err)
        ),
        FRICTION_NULL_POINTER
    );
    assert_eq!(name(&err), "out");
    assert_eq!(
        friction_parameter_adaptive_defaults(None, 1.0, None),
        FRICTION_NULL_POINTER
    );
    assert_eq!(friction_supervisor_defaults(None), FRICTION_NULL_POINTER);
}

#[test]
fn an_adaptive_bound_out_of_range_is_named() {
    let mut m = model_f64();
    assert_eq!(
        friction_lugre_init_f64(Some(&mut m), Some(&LUGRE), 1e-3, None),
        FRICTION_OK
    );
    let adaptive = friction_adaptive_params {
        gamma: 50.0,
        gamma_derivative: 0.0,
        leakage: 0.0,
        theta0: 1.0,
        theta_min: 0.2,
        theta_max: 1e-300,
    };
    let mut s = friction_servo_f64 {
        opaque: [0; FRICTION_SERVO_F64_WORDS],
    };
    let mut err = no_error();
    // theta_min (0.2) and theta0 (1) are right; theta_max is what is wrong
    assert_eq!(
        friction_servo_init_f64(
            Some(&mut s),
            Some(&servo_params()),
            Some(&m),
            200.0,
            Some(&adaptive),
            Some(&mut err)
        ),
        FRICTION_OUT_OF_RANGE
    );
    assert_eq!(name(&err), "theta_max");
}

#[test]
fn every_status_has_a_distinct_name() {
    let names: Vec<String> = (0..=21)
        .map(|s| {
            let p = friction_status_name(s);
            unsafe { std::ffi::CStr::from_ptr(p) }
                .to_str()
                .unwrap()
                .to_owned()
        })
        .collect();
    for (i, n) in names.iter().enumerate() {
        assert!(!n.is_empty() && n != "unknown status", "{i}");
        assert_eq!(names.iter().filter(|m| *m == n).count(), 1, "{n}");
    }
    let unknown = unsafe { std::ffi::CStr::from_ptr(friction_status_name(22)) };
    assert_eq!(unknown.to_str().unwrap(), "unknown status");
    assert_eq!(FRICTION_INPUT_REJECTED as i32, 16);
    assert_eq!(FRICTION_NO_FRICTION as i32, 21);
}

/// A small deterministic generator (SplitMix64) for the hostile-input sweep.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// `10^u` for u uniform in [lo, hi], with a random sign when `signed`.
    fn magnitude(&mut self, lo: f64, hi: f64, signed: bool) -> f64 {
        let u = (self.next() >> 11) as f64 / (1u64 << 53) as f64;
        let x = 10f64.powf(lo + (hi - lo) * u);
        if signed && self.next() & 1 == 1 {
            -x
        } else {
            x
        }
    }
}

/// Hostile but finite: LuGre, elasto-plastic, GMS and Xiong parameters
/// across 1e-25 to 1e25, both scalars and both forms, then steps with
/// velocities to 1e30 and periods to 1e3 s. Every constructor either
/// refuses with a named parameter or builds a model whose every force is
/// finite; the servo around it gives a command within its limit.
#[test]
fn hostile_finite_parameters_and_inputs_never_give_a_non_finite_force() {
    let mut rng = Rng(17);
    let (mut built, mut refused) = (0, 0);
    for case in 0..runs(3000) {
        let mut m = |lo, hi| rng.magnitude(lo, hi, false);
        let fc = m(-25.0, 25.0);
        let curve = friction_stribeck {
            fc,
            fs: fc * m(0.0, 3.0),
            vs: m(-25.0, 25.0),
            exponent: m(-1.0, 1.0),
        };
        let lugre = friction_lugre_params {
            curve,
            sigma0: m(-25.0, 25.0),
            sigma1: m(-25.0, 25.0),
            sigma2: m(-25.0, 25.0),
            vd: 0.0,
        };
        let ep = friction_elasto_plastic_params {
            lugre,
            z_ba: fc / lugre.sigma0 * m(-3.0, 0.0),
        };
        let gms = friction_gms_params {
            curve,
            sigma2: m(-25.0, 25.0),
            c: m(-25.0, 25.0),
            elements: [0.4, 0.3, 0.2, 0.1].map(|alpha| friction_gms_element {
                k: m(-25.0, 25.0),
                alpha,
                sigma1: m(-25.0, 25.0),
            }),
        };
        let xiong = friction_xiong_params {
            curve,
            tau: m(-25.0, 25.0),
            sigma2: m(-25.0, 25.0),
            elements: [0.4, 0.3, 0.2, 0.1].map(|lambda| friction_xiong_element {
                k: m(-25.0, 25.0),
                sigma: m(-25.0, 25.0),
                lambda,
            }),
        };
        let h = if case % 2 == 0 { 0.0 } else { m(-6.0, 0.0) };
        for kind in 0..4 {
            let mut m64 = model_f64();
            let mut m32 = model_f32();
            let mut err = no_error();
            let (s64, s32) = match kind {
                0 => (
                    friction_lugre_init_f64(Some(&mut m64), Some(&lugre), h, Some(&mut err)),
                    friction_lugre_init_f32(Some(&mut m32), Some(&lugre), h, None),
                ),
                1 => (
                    friction_elasto_plastic_init_f64(Some(&mut m64), Some(&ep), h, Some(&mut err)),
                    friction_elasto_plastic_init_f32(Some(&mut m32), Some(&ep), h, None),
                ),
                2 => (
                    friction_gms_init_f64(Some(&mut m64), Some(&gms), h, Some(&mut err)),
                    friction_gms_init_f32(Some(&mut m32), Some(&gms), h, None),
                ),
                _ => (
                    friction_xiong_init_f64(Some(&mut m64), Some(&xiong), h, Some(&mut err)),
                    friction_xiong_init_f32(Some(&mut m32), Some(&xiong), h, None),
                ),
            };
            if s64 != FRICTION_OK {
                assert!(
                    !name(&err).is_empty(),
                    "case {case} kind {kind}: {s64:?} names nothing"
                );
                refused += 1;
            } else {
                built += 1;
            }
            for _ in 0..20 {
                let v = rng.magnitude(-30.0, 30.0, true);
                let step = if h == 0.0 {
                    rng.magnitude(-9.0, 3.0, false)
                } else {
                    h
                };
                let (mut f64_, mut f32_) = (0.0f64, 0.0f32);
                if s64 == FRICTION_OK {
                    let s = friction_model_step_f64(Some(&mut m64), v, step, Some(&mut f64_));
                    assert_eq!(s, FRICTION_OK, "case {case} kind {kind}");
                    assert!(
                        f64_.is_finite(),
                        "case {case} kind {kind}: f64 force {f64_} at v {v:e}"
                    );
                }
                if s32 == FRICTION_OK {
                    let s = friction_model_step_f32(
                        Some(&mut m32),
                        v as f32,
                        step as f32,
                        Some(&mut f32_),
                    );
                    assert!(
                        matches!(
                            s,
                            FRICTION_OK | FRICTION_INPUT_REJECTED | FRICTION_PERIOD_MISMATCH
                        ),
                        "case {case}: {s:?}"
                    );
                    assert!(
                        f32_.is_finite(),
                        "case {case} kind {kind}: f32 force {f32_} at v {v:e}"
                    );
                }
            }
            if s32 == FRICTION_OK && h > 0.0 {
                let sp = friction_servo_params {
                    h,
                    ..servo_params()
                };
                let mut s = friction_servo_f32 {
                    opaque: [0; FRICTION_SERVO_F32_WORDS],
                };
                if friction_servo_init_f32(Some(&mut s), Some(&sp), Some(&m32), 200.0, None, None)
                    == FRICTION_OK
                {
                    for _ in 0..10 {
                        let x = rng.magnitude(-30.0, 30.0, true) as f32;
                        let r = friction_setpoint_f32 {
                            x: 0.0,
                            v: rng.magnitude(-30.0, 30.0, true) as f32,
                            a: 0.0,
                        };
                        let mut t = friction_tick_f32 {
                            command: 0.0,
                            friction: 0.0,
                        };
                        friction_servo_tick_f32(Some(&mut s), x, r, Some(&mut t));
                        assert!(
                            t.command.is_finite() && t.command.abs() <= 5.0,
                            "case {case}: command {}",
                            t.command
                        );
                    }
                }
            }
        }
    }
    // both branches were exercised (of Miri's 10 cases, some)
    let least = if cfg!(miri) { 0 } else { 1000 };
    assert!(
        built > least && refused > least,
        "built {built}, refused {refused}"
    );
}

/// The measured model a re-tune swaps in: stiffer bristles, higher levels,
/// more viscous friction than Olsson's.
fn measured_abi() -> friction_lugre_params {
    let mut p = olsson_abi();
    p.curve.fc = 0.36;
    p.curve.fs = 0.45;
    p.sigma0 = 650.0;
    p.sigma2 = 0.03;
    p
}

/// Re-tuning a running servo through the ABI: bit for bit the core's
/// `Compensator::retune` on the fixed-step LuGre servo in `float` and on
/// the per-parameter servo in `double` (estimates at the new values after
/// the swap); refusals (another period, another kind, NULL, an object
/// never built) leave the object's words as they were.
#[test]
fn retune_through_the_abi_is_the_core_bit_for_bit() {
    let sp = servo_params();
    let mut old = model_f32();
    let mut new = model_f32();
    let mut other_period = model_f32();
    let mut variable = model_f32();
    for (m, p, h) in [
        (&mut old, olsson_abi(), sp.h),
        (&mut new, measured_abi(), sp.h),
        (&mut other_period, measured_abi(), 5e-4),
        (&mut variable, measured_abi(), 0.0),
    ] {
        assert_eq!(
            friction_lugre_init_f32(Some(m), Some(&p), h, None),
            FRICTION_OK
        );
    }
    let mut s = friction_servo_f32 {
        opaque: [0; FRICTION_SERVO_F32_WORDS],
    };
    assert_eq!(
        friction_servo_init_f32(Some(&mut s), Some(&sp), Some(&old), 200.0, None, None),
        FRICTION_OK
    );
    let observer = |p: &friction_lugre_params| {
        FixedPeriod(
            Observer::new(
                LuGreParams::from(p).build_fixed_step::<f32>(sp.h).unwrap(),
                200.0,
            )
            .unwrap(),
        )
    };
    let mut core: LuGreServo<f32> = core_servo_params(&sp)
        .build(observer(&olsson_abi()))
        .unwrap();
    let mut state = Default::default();
    for k in 0..runs(2000) {
        if k == runs(2000) / 2 {
            let mut err = no_error();
            assert_eq!(
                friction_servo_retune_f32(Some(&mut s), Some(&new), 200.0, None, Some(&mut err)),
                FRICTION_OK
            );
            assert_eq!(err.status, 0);
            core.retune(&mut state, observer(&measured_abi())).unwrap();
            // refusals touch nothing
            let before = s.opaque;
            let refused = [
                (Some(&other_period), None, FRICTION_PERIOD_MISMATCH, "h"),
                (Some(&variable), None, FRICTION_NOT_SUPPORTED, "model"),
                (None, None, FRICTION_NOT_SUPPORTED, "model"),
                (
                    Some(&new),
                    Some(&friction_adaptive_params {
                        gamma: 50.0,
                        gamma_derivative: 0.0,
                        leakage: 0.0,
                        theta0: 1.0,
                        theta_min: 0.5,
                        theta_max: 2.0,
                    }),
                    FRICTION_NOT_SUPPORTED,
                    "adaptive",
                ),
            ];
            for (m, a, status, which) in refused {
                let mut err = no_error();
                assert_eq!(
                    friction_servo_retune_f32(Some(&mut s), m, 200.0, a, Some(&mut err)),
                    status
                );
                assert_eq!(name(&err), which);
                assert_eq!(s.opaque, before);
            }
        }
        let x = 1e-3 * (k as f32 * 0.02).sin();
        let r = Setpoint {
            x: x + 1e-5,
            v: 0.02 * (k as f32 * 0.02).cos(),
            a: 0.0,
        };
        let mut t = friction_tick_f32 {
            command: 0.0,
            friction: 0.0,
        };
        let rs = friction_setpoint_f32 {
            x: r.x,
            v: r.v,
            a: r.a,
        };
        assert_eq!(
            friction_servo_tick_f32(Some(&mut s), x, rs, Some(&mut t)),
            FRICTION_OK
        );
        let want = core.tick(&mut state, x, r);
        assert_eq!(
            (t.command.to_bits(), t.friction.to_bits()),
            (want.command.to_bits(), want.friction.to_bits()),
            "tick {k}"
        );
    }
    // NULL and never-built objects
    assert_eq!(
        friction_servo_retune_f32(None, Some(&new), 200.0, None, None),
        FRICTION_NULL_POINTER
    );
    let mut zero = friction_servo_f32 {
        opaque: [0; FRICTION_SERVO_F32_WORDS],
    };
    assert_eq!(
        friction_servo_retune_f32(Some(&mut zero), Some(&new), 200.0, None, None),
        FRICTION_NOT_INITIALISED
    );
    let (p, sup, fb) = parameter_abi();
    assert_eq!(
        friction_servo_parameter_adaptive_retune_f32(
            Some(&mut zero),
            Some(&p),
            Some(&sup),
            Some(&fb),
            None
        ),
        FRICTION_NOT_INITIALISED
    );
    // the LuGre servo is not of the per-parameter kind
    assert_eq!(
        friction_servo_parameter_adaptive_retune_f32(
            Some(&mut s),
            Some(&p),
            Some(&sup),
            Some(&fb),
            None
        ),
        FRICTION_NOT_SUPPORTED
    );

    // the per-parameter servo in double
    let mut s = friction_servo_f64 {
        opaque: [0; FRICTION_SERVO_F64_WORDS],
    };
    assert_eq!(
        friction_servo_parameter_adaptive_init_f64(
            Some(&mut s),
            Some(&sp),
            Some(&p),
            Some(&sup),
            Some(&fb),
            None
        ),
        FRICTION_OK
    );
    let mut core = parameter_core::<f64>(&sp);
    let mut state = Default::default();
    let mut p2 = p;
    p2.model = measured_abi();
    let fb2 = friction_coulomb_viscous_params {
        fc: 0.36,
        sigma2: 0.03,
    };
    let swap = runs(3000) / 2;
    asymmetric_plant(runs(3000) / 1000 + 1, |k, x, r| {
        if k == swap {
            assert_eq!(
                friction_servo_parameter_adaptive_retune_f64(
                    Some(&mut s),
                    Some(&p2),
                    Some(&sup),
                    Some(&fb2),
                    None
                ),
                FRICTION_OK
            );
            let law = ParameterAdaptiveParams::from(&p2)
                .build_fixed_step::<f64>(&core_servo_params(&sp))
                .unwrap();
            let map = CoulombViscousParams::from(&fb2).build::<f64>().unwrap();
            let next = SupervisorParams::from(&sup)
                .build(law, map, &core_servo_params(&sp))
                .unwrap();
            core.retune(&mut state, next).unwrap();
            let mut e = friction_estimates_f64 {
                fc_pos: 0.0,
                fc_neg: 0.0,
                stribeck: 0.0,
                sigma2: 0.0,
                load: 0.0,
            };
            assert_eq!(
                friction_servo_estimates_f64(Some(&mut s), Some(&mut e)),
                FRICTION_OK
            );
            assert_eq!(
                (e.fc_pos, e.fc_neg, e.sigma2),
                (0.36, 0.36, 0.03),
                "the estimates restart at the new model's"
            );
            assert!((e.stribeck - 0.09).abs() < 1e-15, "{e:?}");
            // a refused setting leaves the object as it was
            let before = s.opaque;
            let mut err = no_error();
            let mut bad = sup;
            bad.ratio = 2.0;
            assert_eq!(
                friction_servo_parameter_adaptive_retune_f64(
                    Some(&mut s),
                    Some(&p2),
                    Some(&bad),
                    Some(&fb2),
                    Some(&mut err)
                ),
                FRICTION_NOT_BELOW
            );
            assert_eq!(name(&err), "ratio");
            assert_eq!(s.opaque, before);
        }
        let mut t = friction_tick_f64 {
            command: 0.0,
            friction: 0.0,
        };
        let rs = friction_setpoint_f64 {
            x: r.x,
            v: r.v,
            a: r.a,
        };
        assert_eq!(
            friction_servo_tick_f64(Some(&mut s), x, rs, Some(&mut t)),
            FRICTION_OK
        );
        let want = core.tick(&mut state, x, r);
        assert_eq!(
            (t.command.to_bits(), t.friction.to_bits()),
            (want.command.to_bits(), want.friction.to_bits()),
            "tick {k}"
        );
        t.command
    });
}

/// An external torque set through the ABI reaches the per-parameter law's
/// load input as the core's does: with a load term (`load_max` 0.05), the
/// axis told 1.5 N m ticks bit for bit as the core told the same, and not
/// as an axis told nothing. A non-finite torque is refused, the axis
/// unchanged; other kinds are not supported.
#[test]
fn an_external_torque_reaches_the_load_input_as_the_cores() {
    let sp = friction_servo_params {
        torque_constant: 1.02,
        limit: 10.0,
        ki: 200.0,
        kp: 60.0,
        kd: 1.2,
        ..servo_params()
    };
    let (p, sup, fb) = parameter_abi();
    let init = |s: &mut friction_servo_f64| {
        assert_eq!(
            friction_servo_parameter_adaptive_init_f64(
                Some(s),
                Some(&sp),
                Some(&p),
                Some(&sup),
                Some(&fb),
                None
            ),
            FRICTION_OK
        );
    };
    let mut told = friction_servo_f64 {
        opaque: [0; FRICTION_SERVO_F64_WORDS],
    };
    let mut untold = friction_servo_f64 {
        opaque: [0; FRICTION_SERVO_F64_WORDS],
    };
    init(&mut told);
    init(&mut untold);
    assert_eq!(
        friction_servo_set_external_torque_f64(Some(&mut told), 1.5),
        FRICTION_OK
    );
    for bad in [f64::NAN, f64::INFINITY] {
        let before = told.opaque;
        assert_eq!(
            friction_servo_set_external_torque_f64(Some(&mut told), bad),
            FRICTION_INPUT_REJECTED
        );
        assert_eq!(told.opaque, before);
    }
    let core = parameter_core::<f64>(&sp);
    let mut state = Default::default();
    core.set_external_torque(&mut state, 1.5);
    let tick = |s: &mut friction_servo_f64, x: f64, r: Setpoint<f64>| tick_f64(s, x, r).command;
    let mut apart = 0;
    asymmetric_plant(2, |k, x, r| {
        let command = tick(&mut told, x, r);
        let want = core.tick(&mut state, x, r);
        assert_eq!(command.to_bits(), want.command.to_bits(), "tick {k}");
        if tick(&mut untold, x, r).to_bits() != command.to_bits() {
            apart += 1;
        }
        command
    });
    assert!(apart > 1000, "{apart} ticks apart");
    let mut plain = friction_servo_f64 {
        opaque: [0; FRICTION_SERVO_F64_WORDS],
    };
    assert_eq!(
        friction_servo_set_external_torque_f64(Some(&mut plain), 1.0),
        FRICTION_NOT_INITIALISED
    );
    assert_eq!(
        friction_servo_init_f64(Some(&mut plain), Some(&sp), None, 0.0, None, None),
        FRICTION_OK
    );
    assert_eq!(
        friction_servo_set_external_torque_f64(Some(&mut plain), 1.0),
        FRICTION_NOT_SUPPORTED
    );
    assert_eq!(
        friction_servo_set_external_torque_f32(None, 1.0),
        FRICTION_NULL_POINTER
    );
}

/// The velocity observer switched on through the ABI is the core's
/// `with_velocity_observer`, bit for bit, on a 12-bit encoder's positions;
/// refusals (a bandwidth at half the rate, NaN, a loop without inertia,
/// NULL, a never-initialised object) are named and leave the axis as it
/// was.
#[test]
fn the_velocity_observer_through_the_abi_is_the_cores() {
    let olsson = LuGreParams::OLSSON_1998;
    let sp = servo_params();
    let mut m = model_f64();
    assert_eq!(
        friction_lugre_init_f64(Some(&mut m), Some(&olsson_abi()), sp.h, None),
        FRICTION_OK
    );
    let mut s = friction_servo_f64 {
        opaque: [0; FRICTION_SERVO_F64_WORDS],
    };
    assert_eq!(
        friction_servo_init_f64(Some(&mut s), Some(&sp), Some(&m), 200.0, None, None),
        FRICTION_OK
    );
    // a running axis: the switch restarts its state
    for k in 0..300 {
        let r = Setpoint {
            x: 1e-3,
            ..Setpoint::default()
        };
        tick_f64(&mut s, 1e-5 * k as f64, r);
    }
    let mut err = no_error();
    assert_eq!(
        friction_servo_velocity_observer_f64(Some(&mut s), 50.0, Some(&mut err)),
        FRICTION_OK
    );
    let core = core_servo_params(&sp)
        .build(FixedPeriod(
            Observer::new(olsson.build_fixed_step::<f64>(sp.h).unwrap(), 200.0).unwrap(),
        ))
        .unwrap()
        .with_velocity_observer(50.0)
        .unwrap();
    let mut state = Default::default();
    let count = 2.0 * std::f64::consts::PI / 4096.0;
    // a 12-bit encoder's reading of a position that lags a sine
    let at = |k: usize| {
        let wt = 2.0 * std::f64::consts::PI * k as f64 * 1e-3;
        ((0.1 * wt.sin() - 2e-3 * wt.cos()) / count).round() * count
    };
    let mut changed = false;
    for k in 0..runs(2000) {
        let x = at(k);
        let r = Setpoint {
            x: 0.1 * (2.0 * std::f64::consts::PI * k as f64 * 1e-3).sin(),
            v: 0.0,
            a: 0.0,
        };
        let t = tick_f64(&mut s, x, r);
        let want = core.tick(&mut state, x, r);
        assert_eq!(
            (t.command.to_bits(), t.friction.to_bits()),
            (want.command.to_bits(), want.friction.to_bits()),
            "tick {k}"
        );
        changed |= t.command != 0.0;
    }
    assert!(changed);
    // refusals name the parameter and leave the axis as it was
    for (bandwidth, status, named) in [
        (500.0, FRICTION_NOT_BELOW, "velocity_observer"),
        (f64::NAN, FRICTION_NOT_FINITE, "velocity_observer"),
        (-1.0, FRICTION_NOT_POSITIVE, "velocity_observer"),
    ] {
        let mut copy = friction_servo_f64 { opaque: s.opaque };
        let mut err = no_error();
        assert_eq!(
            friction_servo_velocity_observer_f64(Some(&mut copy), bandwidth, Some(&mut err)),
            status
        );
        assert_eq!(name(&err), named);
        assert_eq!(copy.opaque, s.opaque, "{bandwidth}");
    }
    // a re-tune keeps the observer: the next ticks are still the core's
    let mut retuned = core;
    let mut m2 = model_f64();
    let faster = friction_lugre_params {
        sigma2: 0.02,
        ..olsson_abi()
    };
    assert_eq!(
        friction_lugre_init_f64(Some(&mut m2), Some(&faster), sp.h, None),
        FRICTION_OK
    );
    assert_eq!(
        friction_servo_retune_f64(Some(&mut s), Some(&m2), 200.0, None, None),
        FRICTION_OK
    );
    let mut plant = olsson;
    plant.sigma2 = 0.02;
    retuned
        .retune(
            &mut state,
            FixedPeriod(
                Observer::new(plant.build_fixed_step::<f64>(sp.h).unwrap(), 200.0).unwrap(),
            ),
        )
        .unwrap();
    for k in 2000..2200 {
        let (x, r) = (at(k), Setpoint::default());
        let (t, want) = (tick_f64(&mut s, x, r), retuned.tick(&mut state, x, r));
        assert_eq!(t.command.to_bits(), want.command.to_bits(), "tick {k}");
    }
    let mut still = friction_servo_f64 {
        opaque: [0; FRICTION_SERVO_F64_WORDS],
    };
    let massless = friction_servo_params { inertia: 0.0, ..sp };
    assert_eq!(
        friction_servo_init_f64(Some(&mut still), Some(&massless), None, 0.0, None, None),
        FRICTION_OK
    );
    let mut err = no_error();
    assert_eq!(
        friction_servo_velocity_observer_f64(Some(&mut still), 50.0, Some(&mut err)),
        FRICTION_NOT_POSITIVE
    );
    assert_eq!(name(&err), "inertia");
    assert_eq!(
        friction_servo_velocity_observer_f32(None, 50.0, Some(&mut err)),
        FRICTION_NULL_POINTER
    );
    let mut never = friction_servo_f32 {
        opaque: [0; FRICTION_SERVO_F32_WORDS],
    };
    assert_eq!(
        friction_servo_velocity_observer_f32(Some(&mut never), 50.0, None),
        FRICTION_NOT_INITIALISED
    );
}

/// One `double` servo tick through the ABI at measured position `x`
/// towards `r`, required to be accepted.
fn tick_f64(s: &mut friction_servo_f64, x: f64, r: Setpoint<f64>) -> friction_tick_f64 {
    let mut t = friction_tick_f64 {
        command: 0.0,
        friction: 0.0,
    };
    let r = friction_setpoint_f64 {
        x: r.x,
        v: r.v,
        a: r.a,
    };
    assert_eq!(
        friction_servo_tick_f64(Some(s), x, r, Some(&mut t)),
        FRICTION_OK
    );
    t
}
