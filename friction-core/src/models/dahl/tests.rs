//! Tests of the Dahl model, both forms.

use super::variable_step::*;
use super::*;
use crate::model::{FrictionModel, ParamError};
use proptest::prelude::*;
use std::vec::Vec;

const P: DahlParams = DahlParams {
    sigma: 1e5,
    fc: 1.0,
    delta: 1.0,
    sigma2: 0.0,
};

#[test]
fn invalid_parameters_are_named() {
    assert_eq!(
        DahlParams { delta: 0.5, ..P }.validate(),
        Err(ParamError::BelowOne("delta"))
    );
    assert_eq!(
        DahlParams { sigma: 0.0, ..P }.validate(),
        Err(ParamError::NotPositive("sigma"))
    );
    assert_eq!(
        DahlParams {
            sigma2: f64::NAN,
            ..P
        }
        .validate(),
        Err(ParamError::NotFinite("sigma2"))
    );
}

#[test]
fn delta_one_matches_the_linear_form() {
    // z form: z+ = z_eq + (z - z_eq) e^(-sigma |dx| / Fc), F = sigma z
    let m = P.build::<f64>().unwrap();
    let mut s = DahlState::default();
    let f = m.step(&mut s, 2e-3, 1e-2); // dx = 2e-5
    let expect = 1.0 - (-1e5 * 2e-5f64).exp();
    assert!((f - expect).abs() < 1e-14);
}

#[test]
fn general_exponent_is_exact_in_displacement() {
    // one step over dx equals many small steps over the same dx
    let m = DahlParams { delta: 2.5, ..P }.build::<f64>().unwrap();
    let (mut a, mut b) = (DahlState::default(), DahlState::default());
    m.step(&mut a, 1e-3, 2e-2);
    for _ in 0..1000 {
        m.step(&mut b, 1e-3, 2e-5);
    }
    assert!((a.f - b.f).abs() < 1e-12, "{} {}", a.f, b.f);
    // and close to the limit delta -> 1
    let m1 = DahlParams {
        delta: 1.0 + 1e-9,
        ..P
    }
    .build::<f64>()
    .unwrap();
    let m0 = P.build::<f64>().unwrap();
    let (mut c, mut d) = (DahlState::default(), DahlState::default());
    m1.step(&mut c, 1e-3, 1e-2);
    m0.step(&mut d, 1e-3, 1e-2);
    assert!((c.f - d.f).abs() < 1e-6);
}

#[test]
fn rate_independent() {
    // the same displacement path at two speeds gives the same F(x)
    let m = DahlParams { delta: 2.0, ..P }.build::<f64>().unwrap();
    let path = |speed: f64| {
        let mut s = DahlState::default();
        let mut out = Vec::new();
        for k in 0..400 {
            let v = if (k / 100) % 2 == 0 { speed } else { -speed };
            m.step(&mut s, v, 1e-5 / speed);
            out.push(s.f);
        }
        out
    };
    let (slow, fast) = (path(1e-4), path(1.0));
    for (a, b) in slow.iter().zip(&fast) {
        assert!((a - b).abs() < 1e-12);
    }
}

proptest! {
    #[test]
    fn force_bounded_and_finite(
        delta in 1.0f64..4.0,
        inputs in proptest::collection::vec((-10.0f64..10.0, 0.0f64..1.0), 1..50),
    ) {
        let m = DahlParams { delta, sigma2: 0.3, ..P }.build::<f32>().unwrap();
        let mut s = DahlState::default();
        for (v, h) in inputs {
            let f = m.step(&mut s, v as f32, h as f32);
            prop_assert!(f.is_finite());
            prop_assert!(s.f.abs() <= 1.0);
        }
    }
}
