//! Tests of the Xiong model, both forms.

use super::variable_step::*;
use super::*;
use crate::model::{FrictionModel, ParamError};
use crate::stribeck::StribeckParams;
use crate::Scalar;
use proptest::prelude::*;
use std::vec::Vec;

const CURVE: StribeckParams = StribeckParams {
    fc: 1.0,
    fs: 1.5,
    vs: 1e-3,
    exponent: 2.0,
};

const fn el(k: f64, lambda: f64) -> XiongElement {
    XiongElement {
        k,
        sigma: k * 1e-4,
        lambda,
    }
}

const P: XiongParams<4> = XiongParams {
    curve: CURVE,
    tau: 1e-2,
    sigma2: 0.4,
    elements: [el(2.5e4, 0.4), el(5e4, 0.3), el(1e5, 0.2), el(2e5, 0.1)],
};

#[test]
fn invalid_parameters_are_named() {
    let mut p = P;
    p.elements[1].sigma = 0.0;
    assert_eq!(p.build::<f64>(), Err(ParamError::NotPositive("sigma")));
    let mut p = P;
    p.elements[0].lambda = 0.5;
    assert_eq!(p.validate(), Err(ParamError::WeightsNotOne("lambda")));
    assert_eq!(
        XiongParams { tau: f64::NAN, ..P }.validate(),
        Err(ParamError::NotFinite("tau"))
    );
    let mut p = P;
    p.elements[3].k = -1.0;
    assert_eq!(p.validate(), Err(ParamError::NotPositive("k")));
}

#[test]
fn at_rest_gamma_is_the_static_level() {
    let m = P.build::<f64>().unwrap();
    let s = XiongState::default();
    assert_eq!(m.gamma(&s), 1.5);
}

#[test]
fn gamma_follows_the_curve_with_lag_tau() {
    let m = P.build::<f64>().unwrap();
    let mut s = XiongState::default();
    let v = 0.1;
    m.step(&mut s, v, 1e-2); // one tau
    let g = m.curve().eval(v);
    let expect = g + (1.5 - g) * (-1.0f64).exp();
    assert!((m.gamma(&s) - expect).abs() < 1e-12);
}

#[test]
fn presliding_is_a_spring_with_viscosity() {
    let m = P.build::<f64>().unwrap();
    let mut s = XiongState::default();
    let (v, h) = (1e-5, 1e-4);
    let mut f = 0.0;
    for _ in 0..10 {
        f = m.step(&mut s, v, h);
    }
    // x = 1e-8 m: every element sticks, z_i = x, F = sum (K x + sigma v) + sigma2 v
    let ks: f64 = P.elements.iter().map(|e| e.k).sum();
    let sig: f64 = P.elements.iter().map(|e| e.sigma).sum();
    for z in s.z {
        assert!((z - 1e-8).abs() < 1e-20, "{z}");
    }
    assert!((f - (ks * 1e-8 + (sig + 0.4) * v)).abs() < 1e-12, "{f}");
}

#[test]
fn zero_step_keeps_the_state() {
    let m = P.build::<f64>().unwrap();
    let mut s = XiongState::default();
    for k in 0..200 {
        m.step(&mut s, 1e-3 * (k as f64 * 0.1).cos(), 1e-3);
    }
    let before = s;
    let f = m.step(&mut s, 2e-3, 0.0);
    assert_eq!(s, before);
    assert!(f.is_finite());
    assert_eq!(m.step(&mut s, 0.0, 0.0), m.hold_force(&s));
}

#[test]
fn the_correction_strains_the_elements() {
    use crate::Observer;
    let m = P.build::<f64>().unwrap();
    let o = Observer::new(m, 1e3).unwrap().with_damping(false);
    let mut s = XiongState::default();
    let mut f = 0.0;
    for _ in 0..100 {
        f = o.step(&mut s, 0.0, 1.0, 1e-3);
    }
    // every element saturated at -lambda_i Fs: the estimate is -Fs
    assert!((f + 1.5).abs() < 1e-9, "{f}");
    for (z, (k, l)) in s.z.iter().zip(m.elements()) {
        assert!((k * z + l * 1.5).abs() < 1e-9);
    }
}

fn arb_params() -> impl Strategy<Value = XiongParams<3>> {
    (
        0.1f64..10.0,
        1.0f64..3.0,
        1e-4f64..1e-1,
        0.5f64..3.0,
        proptest::array::uniform3((1e2f64..1e7, 1e-6f64..1e-1, 0.05f64..1.0)),
        1e-4f64..1.0,
        0.0f64..10.0,
    )
        .prop_map(|(fc, ratio, vs, exponent, els, tau, sigma2)| {
            let sum: f64 = els.iter().map(|e| e.2).sum();
            XiongParams {
                curve: StribeckParams {
                    fc,
                    fs: fc * ratio,
                    vs,
                    exponent,
                },
                tau,
                sigma2,
                elements: els.map(|(k, ratio, l)| XiongElement {
                    k,
                    sigma: k * ratio,
                    lambda: l / sum,
                }),
            }
        })
}

fn arb_inputs() -> impl Strategy<Value = Vec<(f64, f64)>> {
    proptest::collection::vec(
        (
            prop_oneof![-1e3f64..1e3, -1e-3f64..1e-3, Just(0.0)],
            prop_oneof![0.0f64..1e-2, Just(0.0), 0.0f64..10.0],
        ),
        1..60,
    )
}

/// `|K_i z_i| <= lambda_i gamma` within rounding.
fn bounded<S: Scalar, const N: usize>(m: &Xiong<S, N>, s: &XiongState<S, N>) -> bool {
    let gamma = m.gamma(s);
    let eps = S::from_f64(1e-6);
    s.z.iter()
        .zip(m.elements())
        .all(|(&z, (k, l))| (k * z).abs() <= l * gamma * (S::ONE + eps))
        && s.lag >= S::ZERO
        && gamma >= m.curve().fc() * (S::ONE - eps)
}

proptest! {
    #[test]
    fn states_stay_bounded_and_force_finite(p in arb_params(), inputs in arb_inputs()) {
        let m = p.build::<f64>().unwrap();
        let m32 = p.build::<f32>().unwrap();
        let (mut s, mut s32) = (XiongState::default(), XiongState::default());
        for (v, h) in inputs {
            let f = m.step(&mut s, v, h);
            let f32_ = m32.step(&mut s32, v as f32, h as f32);
            prop_assert!(f.is_finite() && f32_.is_finite());
            prop_assert!(bounded(&m, &s), "{:?}", s);
            prop_assert!(bounded(&m32, &s32), "{:?}", s32);
        }
    }

    #[test]
    fn steady_state_is_the_stribeck_map(p in arb_params(), v in prop_oneof![-1.0f64..-1e-6, 1e-6f64..1.0]) {
        let m = p.build::<f64>().unwrap();
        let mut s = XiongState::default();
        // lands on gamma = g and every element saturated
        let k_min = p.elements.iter().map(|e| e.k).fold(f64::INFINITY, f64::min);
        let h = 1e3 * (p.tau + p.curve.fs / (k_min * v.abs()));
        m.step(&mut s, v, h);
        let f = m.step(&mut s, v, h);
        let expected = m.steady_state(v);
        prop_assert!((f - expected).abs() <= 1e-9 * expected.abs(), "{} vs {}", f, expected);
    }

    #[test]
    fn extreme_finite_inputs_stay_finite(v in proptest::num::f64::NORMAL, h in proptest::num::f64::POSITIVE) {
        let m = P.build::<f32>().unwrap();
        let mut s = XiongState::default();
        for _ in 0..3 {
            let f = m.step(&mut s, v as f32, h as f32);
            prop_assert!(f.is_finite());
        }
        prop_assert!(bounded(&m, &s));
    }
}
