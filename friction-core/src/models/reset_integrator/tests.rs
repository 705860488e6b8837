use super::*;
use crate::model::FrictionModel;
use proptest::prelude::*;

const P: ResetIntegratorParams = ResetIntegratorParams {
    sigma0: 1e5,
    sigma1: 300.0,
    z0: 1e-5,
    stiction: 0.5,
    curve: None,
};

#[test]
fn invalid_parameters_are_named() {
    assert_eq!(
        ResetIntegratorParams { z0: 0.0, ..P }.validate(),
        Err(ParamError::NotPositive("z0"))
    );
    assert_eq!(
        ResetIntegratorParams {
            stiction: -1.0,
            ..P
        }
        .validate(),
        Err(ParamError::Negative("stiction"))
    );
    let bad_curve = StribeckParams {
        fc: 2.0,
        fs: 1.0,
        vs: 1e-3,
        exponent: 2.0,
    };
    assert_eq!(
        ResetIntegratorParams {
            curve: Some(bad_curve),
            ..P
        }
        .validate(),
        Err(ParamError::StaticBelowCoulomb)
    );
}

#[test]
fn switching_inside_the_step_is_exact() {
    let m = P.build::<f64>().unwrap();
    let mut s = ResetIntegratorState { z: 9e-6 };
    // 2 µm of travel: 1 µm to z0, the rest slides
    let f = m.step(&mut s, 2e-3, 1e-3);
    assert_eq!(s.z, 1e-5);
    assert_eq!(f, 1e5 * 1e-5);
    // reversal: bonded again, stiction factor back, damping sigma1 v
    let f = m.step(&mut s, -1e-3, 1e-3);
    assert!((s.z - 9e-6).abs() < 1e-20);
    assert!((f - (1.5 * 1e5 * 9e-6 - 0.3)).abs() < 1e-9);
}

#[test]
fn stribeck_shaped_stiffness() {
    let curve = StribeckParams {
        fc: 1.0,
        fs: 1.5,
        vs: 1e-3,
        exponent: 2.0,
    };
    let m = ResetIntegratorParams {
        curve: Some(curve),
        ..P
    }
    .build::<f64>()
    .unwrap();
    let mut s = ResetIntegratorState::default();
    for _ in 0..100 {
        m.step(&mut s, 1.0, 1e-3);
    }
    // sliding fast: sigma0 (Fc / Fs) z0
    let f = m.step(&mut s, 1.0, 1e-3);
    assert!((f - 1e5 / 1.5 * 1e-5).abs() < 1e-9);
}

proptest! {
    #[test]
    fn bounded_and_finite(inputs in proptest::collection::vec((-1.0f64..1.0, 0.0f64..1e-2), 1..80)) {
        let m = P.build::<f32>().unwrap();
        let mut s = ResetIntegratorState::default();
        for (v, h) in inputs {
            let f = m.step(&mut s, v as f32, h as f32);
            prop_assert!(f.is_finite());
            prop_assert!(s.z.abs() <= 1e-5);
        }
    }
}
