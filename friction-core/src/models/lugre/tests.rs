//! Tests of the LuGre model, both forms.

use super::fixed_step::*;
use super::variable_step::*;
use super::*;
use crate::fixed_step::FixedStepModel;
use crate::model::{FrictionModel, ParamError};
use crate::stribeck::StribeckParams;
#[cfg(feature = "fixed")]
use crate::Scalar;
use proptest::prelude::*;
use std::vec::Vec;

const P: LuGreParams = LuGreParams::CANUDAS_1995;

#[test]
fn invalid_parameters_are_named() {
    let bad = LuGreParams { sigma0: -1.0, ..P };
    assert_eq!(bad.build::<f64>(), Err(ParamError::NotPositive("sigma0")));
    let bad = LuGreParams {
        sigma1: f64::NAN,
        ..P
    };
    assert_eq!(bad.validate(), Err(ParamError::NotFinite("sigma1")));
    let bad = LuGreParams { vd: Some(0.0), ..P };
    assert_eq!(bad.validate(), Err(ParamError::NotPositive("vd")));
    let mut bad = P;
    bad.curve.fs = 0.9;
    assert_eq!(bad.validate(), Err(ParamError::StaticBelowCoulomb));
}

#[test]
fn passivity_query() {
    // 1995 set: sigma2 = 0.4 < 316 * 0.5 / 1 -> not passive.
    assert!(!P.is_passive());
    assert!(LuGreParams { sigma2: 200.0, ..P }.is_passive());
}

/// A parameter of -0 (let through as 0) is carried as +0: LuGre and
/// elasto-plastic models with `sigma1` = -0 and = +0 agree bit for bit,
/// the sign of a zero force included.
#[test]
fn negative_zero_parameters_are_zero() {
    let plus = LuGreParams {
        sigma1: 0.0,
        ..LuGreParams::CANUDAS_1995
    };
    let minus = LuGreParams {
        sigma1: -0.0,
        ..LuGreParams::CANUDAS_1995
    };
    let vs = [0.0f32, -0.0, 1e-30, -1e-30, 1e-3, -2e-3, -0.0, 0.0];
    let ep = |p: LuGreParams| {
        let z_ba = 0.5 * p.curve.fc / p.sigma0;
        crate::ElastoPlasticParams { lugre: p, z_ba }
            .build_fixed_step::<f32>(1e-3)
            .unwrap()
    };
    for start in [0.0f32, -0.0] {
        let (a, b) = (
            plus.build_fixed_step::<f32>(1e-3).unwrap(),
            minus.build_fixed_step::<f32>(1e-3).unwrap(),
        );
        let (c, d) = (ep(plus), ep(minus));
        let (mut sa, mut sb) = (
            LuGreFixedStepState { w: start },
            LuGreFixedStepState { w: start },
        );
        let (mut sc, mut sd) = (
            LuGreFixedStepState { w: start },
            LuGreFixedStepState { w: start },
        );
        for v in vs {
            let (fa, fb) = (a.step(&mut sa, v), b.step(&mut sb, v));
            assert_eq!(fa.to_bits(), fb.to_bits(), "LuGre, v = {v}");
            assert_eq!(sa.w.to_bits(), sb.w.to_bits());
            let (fc, fd) = (c.step(&mut sc, v), d.step(&mut sd, v));
            assert_eq!(
                fc.to_bits(),
                fd.to_bits(),
                "elasto-plastic, v = {v}, from {start}"
            );
            assert_eq!(sc.w.to_bits(), sd.w.to_bits());
        }
    }
}

#[test]
fn zero_step_returns_force_at_current_state() {
    let m = P.build::<f64>().unwrap();
    let mut s = LuGreState { z: 1e-5 };
    let f = m.step(&mut s, 0.0, 0.0);
    assert_eq!(s.z, 1e-5);
    assert_eq!(f, 1e5 * 1e-5);
    // with velocity: sigma1 dz/dt and sigma2 v appear, state still unchanged
    let f = m.step(&mut s, 1e-3, 0.0);
    assert_eq!(s.z, 1e-5);
    let g = m.curve().eval(1e-3);
    let dz = 1e-3 - 1e-3 * 1e5 * 1e-5 / g;
    assert!((f - (1.0 + P.sigma1 * dz + 0.4e-3)).abs() < 1e-12);
}

#[test]
fn invalid_inputs_leave_state_untouched() {
    let m = P.build::<f32>().unwrap();
    let mut s = LuGreState { z: 5e-6 };
    for (v, h) in [
        (f32::NAN, 1e-3),
        (f32::INFINITY, 1e-3),
        (0.1, f32::NAN),
        (0.1, -1e-3),
    ] {
        let f = m.step(&mut s, v, h);
        assert_eq!(s.z, 5e-6);
        assert_eq!(f, 1e5 * 5e-6);
    }
}

#[test]
fn presliding_is_a_spring() {
    // tiny displacement: F ~ sigma0 x (+ damping), linear spring with stiffness sigma0
    let m = P.build::<f64>().unwrap();
    let mut s = LuGreState::default();
    let h = 1e-4;
    for _ in 0..10 {
        m.step(&mut s, 1e-6, h);
    }
    // x = 1e-9 m; the relaxation is negligible at this deflection
    assert!((s.z - 1e-9).abs() < 1e-13);
}

#[test]
fn step_is_exact_for_held_velocity() {
    // one long step equals many short ones (the solution is exact for held v)
    let m = P.build::<f64>().unwrap();
    let (mut a, mut b) = (LuGreState::default(), LuGreState::default());
    let fa = m.step(&mut a, 2e-4, 1e-2);
    let mut fb = 0.0;
    for _ in 0..100 {
        fb = m.step(&mut b, 2e-4, 1e-4);
    }
    assert!((a.z - b.z).abs() < 1e-15, "{} {}", a.z, b.z);
    assert!((fa - fb).abs() < 1e-9);
}

#[test]
fn velocity_dependent_damping_fades() {
    let m = LuGreParams {
        vd: Some(1e-3),
        ..P
    }
    .build::<f64>()
    .unwrap();
    assert_eq!(m.damping(0.0), P.sigma1);
    assert!((m.damping(1e-3) - P.sigma1 / core::f64::consts::E).abs() < 1e-9);
}

/// The fixed-point step's bounded products
/// ([`Kernels::mul_bounded`](crate::scalar::sealed::Kernels::mul_bounded),
/// which asserts its bound in this crate's tests) over the parameter
/// sets `build_fixed_step` accepts among 20,000 drawn log-uniformly across and
/// beyond their ranges, and a review's worst cases, with hostile
/// inputs: velocities beyond the clamp, states at the ends of the range,
/// an observer's corrections at their limit and a velocity its caller
/// failed to clamp.
#[cfg(feature = "fixed")]
#[test]
fn fixed_point_bounded_products_stay_in_range() {
    use crate::{Fixed32, FixedStepModel, FixedStepObservable};
    let mut next = crate::test_rng::xorshift64(0x0bad_5eed_1234_5678);
    let mut uniform = move || (next() >> 11) as f64 / (1u64 << 53) as f64;
    let mut log_uniform = |lo: f64, hi: f64| lo * (hi / lo).powf(uniform());
    let velocities = [
        0.0, 1e-5, -1e-5, 1e-3, -0.02, 0.5, -3.9, 4.0, -4.0, 30.0, -1e6,
    ];
    let mut accepted = 0;
    for set in 0..20_000 {
        let fc = log_uniform(1e-4, 1e4);
        let p = LuGreParams {
            curve: StribeckParams {
                fc,
                fs: fc * log_uniform(1.0, 2000.0),
                vs: log_uniform(1e-5, 10.0),
                exponent: [2.0, 1.0, 0.7][set % 3],
            },
            sigma0: log_uniform(1.0, 1e9),
            sigma1: if set % 5 == 0 {
                0.0
            } else {
                log_uniform(1e-4, 1e6)
            },
            sigma2: if set % 4 == 0 {
                0.0
            } else {
                log_uniform(1e-4, 1e4)
            },
            vd: if set % 7 == 0 {
                Some(log_uniform(1e-4, 1.0))
            } else {
                None
            },
        };
        let h = log_uniform(1e-6, 1e-1);
        let Ok(m) = p.build_fixed_step::<Fixed32>(h) else {
            continue;
        };
        accepted += 1;
        for w in [Fixed32::MIN, Fixed32::MAX, Fixed32::ZERO, m.fs(), -m.fs()] {
            let mut s = LuGreFixedStepState { w };
            let mut o = LuGreFixedStepState { w };
            for (k, &v) in velocities.iter().enumerate() {
                let v = Fixed32::from_f64(v);
                m.step(&mut s, v);
                let c = Fixed32::from_f64([4.0, -4.0, 0.0][k % 3]);
                m.step_corrected(&mut o, v, c, k % 2 == 0);
            }
        }
    }
    // enough sets get through build_fixed_step for the test to mean something
    assert!(accepted > 2_000, "{accepted} sets accepted");
    // a review's worst cases: the damping force at half the range (a
    // 1/g of one step, twice the exact one, k = 2^-14, Fs/Fc = 1023, from
    // w at the bottom of the range) and the low-speed rate at an eighth
    // (a rounded x of 0 for a true x just under 0.125)
    let damping = LuGreParams {
        curve: StribeckParams {
            fc: 131_072.121_046_281_94,
            fs: 134_032_033.759_008_24,
            vs: 1e-3,
            exponent: 2.0,
        },
        sigma0: 1e7,
        sigma1: 32_749.375_873_960_103,
        sigma2: 0.0,
        vd: None,
    };
    let rate = LuGreParams {
        curve: StribeckParams {
            fc: 37.257,
            fs: 62_457.05,
            vs: 0.004_732,
            exponent: 0.7,
        },
        sigma0: 1.041e12,
        sigma1: 19_992.0,
        sigma2: 0.0,
        vd: Some(0.020_975),
    };
    for (p, h) in [(damping, 1e-3), (rate, 3.223e-5)] {
        let m = p.build_fixed_step::<Fixed32>(h).unwrap();
        for w in [Fixed32::MIN, Fixed32::MAX, Fixed32::ZERO, m.fs(), -m.fs()] {
            for bits in (-(4 << 16)..=(4 << 16)).step_by(977) {
                let mut s = LuGreFixedStepState { w };
                m.step(&mut s, Fixed32::from_bits(bits));
                m.step(&mut s, Fixed32::from_bits(bits));
            }
        }
    }
}

/// An unscaled `sigma1` beyond Q16.16 is refused where it would have
/// saturated the damping term (a review's case: 33.3 N for 1000 N).
#[cfg(feature = "fixed")]
#[test]
fn fixed_point_refuses_an_unrepresentable_sigma1() {
    let p = LuGreParams {
        curve: StribeckParams {
            fc: 1000.0,
            fs: 1000.0,
            vs: 1e-3,
            exponent: 2.0,
        },
        sigma0: 1e5,
        sigma1: 1e6,
        sigma2: 0.0,
        vd: None,
    };
    assert_eq!(
        p.build_fixed_step::<crate::Fixed32>(1e-3).err(),
        Some(ParamError::NotRepresentable("sigma1"))
    );
    assert!(p.build_fixed_step::<f32>(1e-3).is_ok());
}

fn arb_params() -> impl Strategy<Value = LuGreParams> {
    (
        0.1f64..10.0,
        1.0f64..3.0,
        1e-4f64..1e-1,
        0.5f64..3.0,
        1e2f64..1e7,
        0.0f64..1e3,
        0.0f64..10.0,
    )
        .prop_map(
            |(fc, ratio, vs, exponent, sigma0, sigma1, sigma2)| LuGreParams {
                curve: StribeckParams {
                    fc,
                    fs: fc * ratio,
                    vs,
                    exponent,
                },
                sigma0,
                sigma1,
                sigma2,
                vd: None,
            },
        )
}

fn arb_inputs() -> impl Strategy<Value = Vec<(f64, f64)>> {
    proptest::collection::vec(
        (
            -1e3f64..1e3,
            prop_oneof![0.0f64..1e-2, Just(0.0), 0.0f64..10.0],
        ),
        1..60,
    )
}

proptest! {
    #[test]
    fn z_stays_bounded_and_force_finite(p in arb_params(), inputs in arb_inputs(), z0 in -1.0f64..1.0) {
        let m = p.build::<f64>().unwrap();
        let m32 = p.build::<f32>().unwrap();
        let mut s = LuGreState { z: z0 * m.z_max() };
        let mut s32 = LuGreState { z: (z0 * m.z_max()) as f32 };
        for (v, h) in inputs {
            let f = m.step(&mut s, v, h);
            let f32_ = m32.step(&mut s32, v as f32, h as f32);
            prop_assert!(f.is_finite() && f32_.is_finite());
            prop_assert!(s.z.abs() <= m.z_max());
            prop_assert!(s32.z.abs() <= m32.z_max());
        }
    }

    #[test]
    fn steady_state_is_the_stribeck_map(p in arb_params(), v in prop_oneof![-1.0f64..-1e-6, 1e-6f64..1.0]) {
        let m = p.build::<f64>().unwrap();
        let mut s = LuGreState::default();
        // a step of many time constants lands on the equilibrium
        let tau = p.curve.fc / (p.sigma0 * v.abs());
        let f = m.step(&mut s, v, 200.0 * tau);
        let expected = m.steady_state(v);
        prop_assert!((f - expected).abs() <= 1e-9 * expected.abs(), "{} vs {}", f, expected);
    }

    #[test]
    fn extreme_finite_inputs_stay_finite(v in proptest::num::f64::NORMAL, h in proptest::num::f64::POSITIVE) {
        let m = P.build::<f32>().unwrap();
        let mut s = LuGreState::default();
        let f = m.step(&mut s, v as f32, h as f32);
        prop_assert!(f.is_finite());
        prop_assert!(s.z.is_finite() && s.z.abs() <= m.z_max());
    }

    #[test]
    fn dissipation_when_passive(p in arb_params(), vs in proptest::collection::vec(-1e-2f64..1e-2, 10..200)) {
        // Passivity of the friction map: the energy absorbed from z = 0,
        // sum of F v h, is never negative when the 2008 condition holds.
        let p = LuGreParams { sigma2: p.sigma1 * (p.curve.fs - p.curve.fc) / p.curve.fc * 1.01 + 1e-9, ..p };
        prop_assume!(p.is_passive());
        let m = p.build::<f64>().unwrap();
        let mut s = LuGreState::default();
        let h = 1e-4;
        let mut energy = 0.0;
        for v in vs {
            energy += m.step(&mut s, v, h) * v * h;
            prop_assert!(energy >= -1e-12, "energy {}", energy);
        }
    }
}
