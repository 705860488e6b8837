//! Tests of the bristle model.

use super::variable_step::*;
use super::*;
use crate::model::{FrictionModel, ParamError};
use proptest::prelude::*;

const P: BristleParams = BristleParams {
    sigma0: 1e3,
    delta_s: 1e-5,
    seed: 11,
};

#[test]
fn invalid_parameters_are_named() {
    assert_eq!(
        BristleParams { delta_s: 0.0, ..P }.validate(),
        Err(ParamError::NotPositive("delta_s"))
    );
    assert_eq!(
        BristleParams {
            sigma0: f64::NAN,
            ..P
        }
        .build::<f64, 4>()
        .err(),
        Some(ParamError::NotFinite("sigma0"))
    );
}

#[test]
fn runs_repeat_and_do_not_depend_on_step_size() {
    let m = P.build::<f64, 8>().unwrap();
    let (mut a, mut b) = (BristleState::default(), BristleState::default());
    for _ in 0..1000 {
        m.step(&mut a, 1e-3, 1e-3); // 1 µm a step
    }
    for _ in 0..100 {
        m.step(&mut b, 1e-3, 1e-2); // 10 µm a step (snaps inside the step)
    }
    assert_eq!(a.bonds, b.bonds);
    for (x, y) in a.strain.iter().zip(&b.strain) {
        assert!((x - y).abs() < 1e-15);
    }
}

#[test]
fn first_breakaway_peak_then_sliding_mean() {
    let m = P.build::<f64, 64>().unwrap();
    let mut s = BristleState::default();
    let mut peak = 0.0f64;
    let mut sum = 0.0;
    let n = 200_000;
    for k in 0..n {
        let f = m.step(&mut s, 1e-3, 1e-4); // 0.1 µm a step
        peak = peak.max(f);
        if k >= n / 2 {
            sum += f;
        }
    }
    assert!(peak > 0.99 * 64.0 * 1e3 * 1e-5); // all bristles loaded together
    let mean = sum / (n / 2) as f64;
    assert!(
        (mean / m.sliding_mean() - 1.0).abs() < 0.05,
        "mean {mean} vs {}",
        m.sliding_mean()
    );
}

#[test]
fn huge_steps_are_bounded() {
    let m = P.build::<f32, 64>().unwrap();
    let mut s = BristleState::default();
    let f = m.step(&mut s, 1e6, 1.0);
    assert!(f.is_finite() && f.abs() <= 64.0 * 1e3 * 1e-5 * (1.0 + 1e-6));
    // 2 N draws in all, then every bristle that would snap again is held
    // at its snapping deflection, and the next step's travel snaps it
    assert_eq!(s.bonds.iter().sum::<u32>(), BRISTLE_DEFAULT_SNAPS * 64);
    assert!(s.strain.iter().all(|&z| z == 1e-5));
    let before = s.bonds;
    m.step(&mut s, 1e-3, 1e-6);
    assert!(s.bonds.iter().zip(before).all(|(&b, a)| b == a + 1));
}

/// While a step needs at most `2 N` snaps, one long step is the same as
/// many short ones (the snaps happen in order, exactly).
#[test]
fn long_steps_within_the_budget_are_exact() {
    let m = P.build::<f64, 16>().unwrap();
    let (mut long, mut short) = (BristleState::default(), BristleState::default());
    for k in 0..400 {
        let v = if (k / 50) % 2 == 0 { 1e-3 } else { -7e-4 };
        let h = 1.3e-2; // 13 µm and 9.1 µm of travel: up to 1.3 delta_s
        m.step(&mut long, v, h);
        for _ in 0..100 {
            m.step(&mut short, v, h / 100.0);
        }
        assert_eq!(long.bonds, short.bonds, "step {k}");
        for (a, b) in long.strain.iter().zip(short.strain) {
            assert!((a - b).abs() < 1e-15, "step {k}: {a} vs {b}");
        }
    }
    assert!(long.bonds.iter().sum::<u32>() > 16 * 100);
}

proptest! {
    #[test]
    fn strains_stay_inside_the_snapping_band(inputs in proptest::collection::vec((-1.0f64..1.0, 0.0f64..1e-3), 1..60)) {
        let m = P.build::<f32, 8>().unwrap();
        let mut s = BristleState::default();
        for (v, h) in inputs {
            let f = m.step(&mut s, v as f32, h as f32);
            prop_assert!(f.is_finite());
            for &x in &s.strain {
                prop_assert!(x.abs() <= 1e-5);
            }
        }
    }
}
