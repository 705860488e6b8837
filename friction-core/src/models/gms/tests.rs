//! Tests of the generalized Maxwell-slip model, both forms.

use super::variable_step::*;
use super::*;
use crate::model::{FrictionModel, ParamError};
use crate::observer::Observable;
use crate::stribeck::StribeckParams;
use proptest::prelude::*;
use std::vec::Vec;

const CURVE: StribeckParams = StribeckParams {
    fc: 1.0,
    fs: 1.5,
    vs: 1e-3,
    exponent: 2.0,
};

const fn el(k: f64, alpha: f64, sigma1: f64) -> GmsElement {
    GmsElement { k, alpha, sigma1 }
}

const P: GmsParams<4> = GmsParams {
    curve: CURVE,
    sigma2: 0.4,
    c: 100.0,
    elements: [
        el(2.5e4, 0.4, 2.5),
        el(5e4, 0.3, 5.0),
        el(1e5, 0.2, 10.0),
        el(2e5, 0.1, 20.0),
    ],
};

#[test]
fn invalid_parameters_are_named() {
    let mut p = P;
    p.elements[1].k = 0.0;
    assert_eq!(p.build::<f64>(), Err(ParamError::NotPositive("k")));
    let mut p = P;
    p.elements[2].alpha = -0.2;
    assert_eq!(p.validate(), Err(ParamError::NotPositive("alpha")));
    let mut p = P;
    p.elements[0].sigma1 = f64::NAN;
    assert_eq!(p.validate(), Err(ParamError::NotFinite("sigma1")));
    let mut p = P;
    p.elements[0].alpha = 0.41;
    assert_eq!(p.validate(), Err(ParamError::WeightsNotOne("alpha")));
    p.elements[0].alpha = 0.4 + 5e-10;
    assert!(p.validate().is_ok());
    assert_eq!(
        GmsParams { c: 0.0, ..P }.validate(),
        Err(ParamError::NotPositive("c"))
    );
    let mut p = P;
    p.curve.fs = 0.5;
    assert_eq!(p.validate(), Err(ParamError::StaticBelowCoulomb));
    let e = ParamError::WeightsNotOne("alpha");
    assert!(std::format!("{e}").contains("`alpha`"));
}

#[test]
fn elements_stick_then_slip_one_after_another() {
    // at 1 µm/s each element sticks until k_i x = alpha_i g(v)
    let m = P.build::<f64>().unwrap();
    let mut s = GmsState::default();
    let v = 1e-6;
    let g = m.curve().eval(v);
    // element 3 (k 2e5, alpha 0.1) breaks first: x = 0.1 g / 2e5
    let x3 = 0.1 * g / 2e5;
    let h = 0.5 * x3 / v;
    m.step(&mut s, v, h);
    assert_eq!(s.mode, [GmsSlipMode::Stick; 4]);
    assert!((s.force[3] - 2e5 * 0.5 * x3).abs() < 1e-12);
    m.step(&mut s, v, h * 1.2);
    assert_eq!(s.mode[3], GmsSlipMode::Forward);
    assert_eq!(s.mode[..3], [GmsSlipMode::Stick; 3]);
    assert!((s.force[3] - 0.1 * g).abs() < 1e-12);
    // a reversal sticks it again, unloading with its stiffness
    m.step(&mut s, -v, h);
    assert_eq!(s.mode[3], GmsSlipMode::Stick);
    assert!((s.force[3] - (0.1 * g - 2e5 * v * h)).abs() < 1e-12);
}

#[test]
fn a_slipping_element_remembers_it_slips() {
    // Slide at 10 mm/s (g ~ Fc), then slow to 0.2 mm/s: g rises, so every
    // |F_i| is below alpha_i g(v), yet the elements keep slipping and
    // follow the curve at the slip rate C / (alpha_i g). A rule
    // "sticks while |F_i| <= alpha_i g(v)" would load them at k_i v.
    let m = P.build::<f64>().unwrap();
    let mut s = GmsState::default();
    for _ in 0..1000 {
        m.step(&mut s, 1e-2, 1e-3);
    }
    assert_eq!(s.mode, [GmsSlipMode::Forward; 4]);
    let (v, h) = (2e-4, 1e-4);
    let g = m.curve().eval(v);
    let before = s;
    m.step(&mut s, v, h);
    for i in 0..4 {
        let alpha = P.elements[i].alpha;
        assert!(before.force[i] < alpha * g - 0.1 * alpha);
        assert_eq!(s.mode[i], GmsSlipMode::Forward, "element {i}");
        let target = alpha * g;
        let expect = target + (before.force[i] - target) * (-(P.c / (alpha * g)) * h).exp();
        assert!((s.force[i] - expect).abs() < 1e-12, "element {i}");
        // the stick rule would have added k_i v h (0.5 to 4 mN here; the
        // slip law adds about 3.2 mN to each)
        let kvh = P.elements[i].k * v * h;
        let stick = before.force[i] + kvh;
        assert!(
            (s.force[i] - stick).abs() > 0.1 * kvh + 2e-4,
            "element {i}: {} {} {stick} {kvh}",
            before.force[i],
            s.force[i]
        );
    }
}

#[test]
fn one_long_step_equals_many_short_ones() {
    let m = P.build::<f64>().unwrap();
    for (v, h) in [(1e-4, 1e-2), (-3e-3, 2e-3), (1e-6, 5e-1), (0.2, 1e-3)] {
        let mut a = GmsState::default();
        // a pre-loaded, partly slipping start
        for k in 0..300 {
            m.step(&mut a, 2e-4 * (k as f64 * 0.05).sin(), 1e-3);
        }
        let mut b = a;
        let fa = m.step(&mut a, v, h);
        let mut fb = 0.0;
        for _ in 0..1000 {
            fb = m.step(&mut b, v, h / 1000.0);
        }
        assert_eq!(a.mode, b.mode, "v {v}");
        for (x, y) in a.force.iter().zip(&b.force) {
            assert!((x - y).abs() < 1e-12, "v {v}: {x} {y}");
        }
        assert!((fa - fb).abs() < 1e-9, "v {v}: {fa} {fb}");
    }
}

#[test]
fn zero_step_keeps_the_state_and_gives_the_force() {
    let m = P.build::<f64>().unwrap();
    let mut s = GmsState::default();
    for k in 0..200 {
        m.step(&mut s, 1e-3 * (k as f64 * 0.1).cos(), 1e-3);
    }
    let before = s;
    let f = m.step(&mut s, -2e-3, 0.0);
    assert_eq!(s, before);
    // sticking elements contribute sigma1_i v
    let mut expect = 0.4 * -2e-3;
    for i in 0..4 {
        expect += s.force[i];
        if !s.mode[i].slips_with(-2e-3) {
            expect += P.elements[i].sigma1 * -2e-3;
        }
    }
    assert!((f - expect).abs() < 1e-12);
}

#[test]
fn a_correction_against_v_holds_an_element_at_its_bound() {
    use crate::Observer;
    let m = P.build::<f64>().unwrap();
    let o = Observer::new(m, 1e3).unwrap();
    let mut s = GmsState::default();
    // at rest, measured position far ahead: every element is driven to
    // -alpha_i Fs and held there, sticking; the estimate is -Fs
    let mut f = 0.0;
    for _ in 0..100 {
        f = o.step(&mut s, 0.0, 1.0, 1e-3);
    }
    assert_eq!(s.mode, [GmsSlipMode::Stick; 4]);
    for (x, b) in s.force.iter().zip(m.force_bounds()) {
        assert_eq!(*x, -b);
    }
    assert!((f + 1.5).abs() < 1e-12, "{f}");
    // moving forwards with the correction pushing back: held, no slip
    let f = o.step(&mut s, 1e-4, 1.0, 1e-3);
    assert_eq!(s.mode, [GmsSlipMode::Stick; 4]);
    assert!(f.abs() <= m.force_bound(1e-4));
}

fn arb_params() -> impl Strategy<Value = GmsParams<3>> {
    (
        0.1f64..10.0,
        1.0f64..3.0,
        1e-4f64..1e-1,
        0.5f64..3.0,
        proptest::array::uniform3((1e2f64..1e7, 0.05f64..1.0, 0.0f64..1e2)),
        0.0f64..10.0,
        1e-1f64..1e4,
    )
        .prop_map(|(fc, ratio, vs, exponent, els, sigma2, c)| {
            let sum: f64 = els.iter().map(|e| e.1).sum();
            GmsParams {
                curve: StribeckParams {
                    fc,
                    fs: fc * ratio,
                    vs,
                    exponent,
                },
                sigma2,
                c,
                elements: els.map(|(k, a, s1)| el(k, a / sum, s1)),
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

proptest! {
    #[test]
    fn forces_stay_bounded_and_finite(p in arb_params(), inputs in arb_inputs()) {
        let m = p.build::<f64>().unwrap();
        let m32 = p.build::<f32>().unwrap();
        let (mut s, mut s32) = (GmsState::default(), GmsState::default());
        for (v, h) in inputs {
            let f = m.step(&mut s, v, h);
            let f32_ = m32.step(&mut s32, v as f32, h as f32);
            prop_assert!(f.is_finite() && f32_.is_finite());
            for (x, b) in s.force.iter().zip(m.force_bounds()) {
                prop_assert!(x.abs() <= b);
            }
            for (x, b) in s32.force.iter().zip(m32.force_bounds()) {
                prop_assert!(x.abs() <= b);
            }
        }
    }

    #[test]
    fn steady_state_is_the_stribeck_map(p in arb_params(), v in prop_oneof![-1.0f64..-1e-6, 1e-6f64..1.0]) {
        let m = p.build::<f64>().unwrap();
        let mut s = GmsState::default();
        // long enough to break every element and relax 200 time constants
        let t_break = p.curve.fs / (p.elements.iter().map(|e| e.k).fold(f64::INFINITY, f64::min) * v.abs());
        let t_slip = p.curve.fs / p.c;
        let f = m.step(&mut s, v, t_break + 200.0 * t_slip);
        let expected = m.steady_state(v);
        prop_assert!((f - expected).abs() <= 1e-9 * expected.abs(), "{} vs {}", f, expected);
    }

    #[test]
    fn extreme_finite_inputs_stay_finite(v in proptest::num::f64::NORMAL, h in proptest::num::f64::POSITIVE) {
        let m = P.build::<f32>().unwrap();
        let mut s = GmsState::default();
        for _ in 0..3 {
            let f = m.step(&mut s, v as f32, h as f32);
            prop_assert!(f.is_finite());
        }
        for (x, b) in s.force.iter().zip(m.force_bounds()) {
            prop_assert!(x.is_finite() && x.abs() <= b);
        }
    }
}
