//! The adaptive compensations against a simulated servo: the θ-adaptive
//! observer finds a known plant scale, the least-squares feed-forward finds
//! a known Coulomb + viscous plant; and their contracts under hostile
//! finite inputs, NaN and long standstills.
#![allow(clippy::unwrap_used, clippy::indexing_slicing, clippy::panic)]

use core::f64::consts::PI;
use friction_core::*;
use proptest::prelude::*;

/// The DC servo of Olsson et al. (1998): J, kc, and the loop of `friction servo`.
const J: f64 = 0.0023;
const KC: f64 = 1.02;

fn loop_params() -> CompensatorParams {
    CompensatorParams {
        h: 1e-3,
        kp: 60.0,
        ki: 200.0,
        kd: 1.2,
        inertia: J,
        torque_constant: KC,
        limit: 10.0,
    }
}

/// `x_ref = 0.5 sin(2 pi 0.2 t)` and its derivatives: a persistently
/// exciting motion that reverses every 2.5 s.
fn setpoint(t: f64) -> Setpoint<f64> {
    let w = 2.0 * PI * 0.2;
    Setpoint {
        x: 0.5 * (w * t).sin(),
        v: 0.5 * w * (w * t).cos(),
        a: -0.5 * w * w * (w * t).sin(),
    }
}

/// Runs `ctl` on the plant `J x'' = kc u - F(x')` for `seconds` (10 plant
/// substeps of semi-implicit Euler per tick), calling `watch` after each
/// tick with the time and the compensator's state; returns the RMS
/// tracking error over the last half.
fn run<S, C>(
    ctl: &Compensator<S, C>,
    mut plant: impl FnMut(f64, f64) -> f64,
    seconds: f64,
    mut watch: impl FnMut(f64, &CompensatorState<S, C::State>),
) -> f64
where
    S: Scalar,
    C: Compensation<S>,
    C::State: Default + Copy,
{
    let h = loop_params().h;
    let hs = h / 10.0;
    let mut state = CompensatorState::default();
    let (mut x, mut v) = (0.0f64, 0.0f64);
    let n = (seconds / h) as usize;
    let (mut sum, mut count) = (0.0, 0usize);
    for k in 0..n {
        let t = k as f64 * h;
        let r = setpoint(t);
        let rs = Setpoint {
            x: S::from_f64(r.x),
            v: S::from_f64(r.v),
            a: S::from_f64(r.a),
        };
        let u = ctl.tick(&mut state, S::from_f64(x), rs).command.to_f64();
        for _ in 0..10 {
            let f = plant(v, hs);
            v += hs * (KC * u - f) / J;
            x += hs * v;
        }
        watch(t, &state);
        if k >= n / 2 {
            sum += (x - setpoint(t + h).x).powi(2);
            count += 1;
        }
    }
    (sum / count as f64).sqrt()
}

/// A LuGre plant whose whole force is `theta` times Olsson's.
fn scaled_lugre(theta: f64) -> impl FnMut(f64, f64) -> f64 {
    let model = LuGreParams::OLSSON_1998.build::<f64>().unwrap();
    let mut state = LuGreState::default();
    move |v, h| theta * model.step(&mut state, v, h)
}

fn adaptive_params(rate: f64) -> AdaptiveParams {
    let fs = LuGreParams::OLSSON_1998.curve.fs;
    AdaptiveParams {
        gamma: AdaptiveParams::gain_for_rate(rate, 60.0, KC, fs),
        // the composite error de/dt + (kp / kd) e
        gamma_derivative: AdaptiveParams::gain_for_rate(rate, 60.0, KC, fs) * 1.2 / 60.0,
        ..AdaptiveParams::DEFAULT
    }
}

fn adaptive<S: Scalar>(rate: f64) -> Compensator<S, AdaptiveObserver<LuGre<S>, S>> {
    let model = LuGreParams::OLSSON_1998.build::<S>().unwrap();
    let observer = Observer::new(model, 20.0).unwrap();
    let a = adaptive_params(rate).build(observer, 1e-3).unwrap();
    loop_params().build(a).unwrap()
}

#[test]
fn theta_converges_to_the_plant_scale_within_five_percent() {
    for theta_star in [0.6, 1.5, 2.5] {
        let ctl = adaptive::<f64>(4.0);
        let mut theta = 1.0;
        let rms = run(&ctl, scaled_lugre(theta_star), 40.0, |_, s| {
            theta = ctl.compensation().theta(s.friction());
        });
        let gap = (theta - theta_star).abs() / theta_star;
        assert!(gap < 0.05, "theta* {theta_star}: theta^ {theta} ({gap:.3})");
        // and without adaptation the same plant tracks worse
        let fixed = adaptive::<f64>(0.0);
        let rms_fixed = run(&fixed, scaled_lugre(theta_star), 40.0, |_, _| {});
        assert!(
            rms < 0.5 * rms_fixed,
            "theta* {theta_star}: {rms} vs {rms_fixed}"
        );
    }
}

#[test]
fn theta_converges_in_f32_too() {
    let ctl = adaptive::<f32>(4.0);
    let mut theta = 1.0;
    run(&ctl, scaled_lugre(1.5), 40.0, |_, s| {
        theta = ctl.compensation().theta(s.friction()).to_f64();
    });
    assert!((theta - 1.5).abs() < 0.05 * 1.5, "{theta}");
}

#[cfg(feature = "fixed")]
#[test]
fn theta_adapts_in_fixed_point() {
    // Q16.16 with the loop of a real drive at 1 kHz: theta^ must move (its
    // offset is carried scaled, so per-tick increments do not round to 0)
    let model = LuGreParams::OLSSON_1998
        .build_fixed_step::<Fixed32>(1e-3)
        .unwrap();
    let a = adaptive_params(4.0)
        .build(Observer::new(model, 20.0).unwrap(), 1e-3)
        .unwrap();
    let ctl = loop_params().build(FixedPeriod(a)).unwrap();
    let mut theta = 1.0;
    run(&ctl, scaled_lugre(1.5), 40.0, |_, s| {
        theta = ctl.compensation().0.theta(s.friction()).to_f64();
    });
    // measured 1.4993
    assert!((theta - 1.5).abs() < 0.05 * 1.5, "{theta}");
}

#[test]
fn the_fixed_step_form_adapts_like_the_general_one() {
    let p = adaptive_params(4.0);
    let general = adaptive::<f64>(4.0);
    let at_model = LuGreParams::OLSSON_1998
        .build_fixed_step::<f64>(1e-3)
        .unwrap();
    let at = FixedPeriod(
        p.build(Observer::new(at_model, 20.0).unwrap(), 1e-3)
            .unwrap(),
    );
    let fixed_step = loop_params().build(at).unwrap();
    let mut thetas = Vec::new();
    run(&general, scaled_lugre(1.5), 20.0, |_, s| {
        thetas.push(general.compensation().theta(s.friction()));
    });
    let mut k = 0;
    let mut gap = 0.0f64;
    run(&fixed_step, scaled_lugre(1.5), 20.0, |_, s| {
        gap = gap.max((fixed_step.compensation().0.theta(s.friction()) - thetas[k]).abs());
        k += 1;
    });
    assert!(gap < 1e-6, "theta gap {gap}");
    // and a fixed-step adaptation built for another period is refused
    let other = FixedPeriod(
        p.build(Observer::new(at_model, 20.0).unwrap(), 2e-3)
            .unwrap(),
    );
    let refused = loop_params().build(other).err();
    assert_eq!(refused, Some(ParamError::PeriodMismatch));
}

#[test]
fn invalid_adaptation_parameters_are_named() {
    let ok = adaptive_params(4.0);
    let observer: Observer<LuGre<f32>, f32> =
        Observer::new(LuGreParams::OLSSON_1998.build::<f32>().unwrap(), 20.0).unwrap();
    for (bad, name) in [
        (AdaptiveParams { gamma: -1.0, ..ok }, "gamma"),
        (
            AdaptiveParams {
                gamma_derivative: -1.0,
                ..ok
            },
            "gamma_derivative",
        ),
        (
            AdaptiveParams {
                gamma: f64::NAN,
                ..ok
            },
            "gamma",
        ),
        (
            AdaptiveParams {
                leakage: f64::INFINITY,
                ..ok
            },
            "leakage",
        ),
        (
            AdaptiveParams {
                theta_min: 6.0,
                ..ok
            },
            "theta_min",
        ),
        (AdaptiveParams { theta0: 0.1, ..ok }, "theta0"),
        (
            AdaptiveParams {
                theta_max: 0.0,
                ..ok
            },
            "theta_max",
        ),
    ] {
        let e = bad.build(observer, 1e-3).unwrap_err();
        assert!(format!("{e:?}").contains(name), "{name}: {e:?}");
    }
    assert_eq!(
        ok.build(observer, 0.0).unwrap_err(),
        ParamError::NotPositive("h")
    );
}

fn hostile() -> impl Strategy<Value = f64> {
    prop_oneof![
        -1e3..1e3f64,
        -1.0..1.0f64,
        Just(0.0),
        Just(f64::MAX),
        Just(-f64::MAX),
        Just(f64::MIN_POSITIVE),
        Just(1e30),
        Just(-1e30),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Any finite input keeps θ^ in its set and the estimate finite and
    /// within θmax times the model's bound; any NaN or infinity leaves the
    /// state as it was.
    #[test]
    fn theta_and_estimate_stay_bounded(
        gamma in prop_oneof![Just(0.0), 1e-3..1e3f64, Just(1e12), Just(1e300)],
        gamma_derivative in prop_oneof![Just(0.0), 1e-3..1e3f64, Just(1e12)],
        leakage in prop_oneof![Just(0.0), 0.0..1e3f64, Just(1e300)],
        inputs in prop::collection::vec((hostile(), hostile(), prop_oneof![Just(1e-3), 1e-9..1.0f64, Just(1e300)]), 1..200),
    ) {
        let p = AdaptiveParams { gamma, gamma_derivative, leakage, theta0: 1.0, theta_min: 0.2, theta_max: 5.0 };
        let model = LuGreParams::OLSSON_1998.build::<f64>().unwrap();
        let m32 = LuGreParams::OLSSON_1998.build::<f32>().unwrap();
        // a gain the scalar cannot carry is a typed error at build time
        let (a, a32) = match (
            p.build(Observer::new(model, 20.0).unwrap(), 1e-3),
            p.build(Observer::new(m32, 20.0).unwrap(), 1e-3),
        ) {
            (Ok(a), Ok(a32)) => (a, a32),
            (a, a32) => {
                for e in [a.err(), a32.err()].into_iter().flatten() {
                    prop_assert!(matches!(e, ParamError::NotRepresentable(_)), "{e:?}");
                }
                prop_assert!(gamma > 1e30 || leakage > 1e30, "{gamma} {leakage}");
                return Ok(());
            }
        };
        let mut s = AdaptiveState::default();
        let mut s32 = AdaptiveState::default();
        for (v, e, h) in inputs {
            let f = a.step(&mut s, v, e, h);
            let theta = a.theta(&s);
            prop_assert!((0.2..=5.0).contains(&theta), "theta {theta}");
            let bound = 5.0 * model.force_bound(v.clamp(-VELOCITY_LIMIT, VELOCITY_LIMIT));
            prop_assert!(f.is_finite() && f.abs() <= bound * (1.0 + 1e-12), "{f} > {bound}");
            let f32_ = a32.step(&mut s32, v as f32, e as f32, h as f32);
            let t32 = a32.theta(&s32);
            prop_assert!(f32_.is_finite() && (0.2..=5.0).contains(&t32), "{f32_} {t32}");
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                let before = s;
                a.step(&mut s, bad, e, h);
                a.step(&mut s, v, bad, h);
                a.step(&mut s, v, e, bad);
                prop_assert_eq!(before, s);
            }
        }
    }

    /// The least-squares feed-forward keeps its weights, estimate and
    /// covariance bounded for any finite samples.
    #[test]
    fn rls_stays_bounded(
        forgetting in prop_oneof![Just(1.0), 0.5..1.0f64, Just(1e-9)],
        offset in any::<bool>(),
        samples in prop::collection::vec((hostile(), hostile()), 1..300),
    ) {
        let p = RlsParams { forgetting, offset, ..RlsParams::new(0.63, 10.0) };
        let rls = p.build::<f64>().unwrap();
        let rls32 = p.build::<f32>().unwrap();
        let mut s = RlsState::default();
        let mut s32 = RlsState::default();
        for (force, v) in samples {
            rls.update(&mut s, FrictionSample { force, v });
            rls32.update(&mut s32, FrictionSample { force: force as f32, v: v as f32 });
            let (fc, viscous) = rls.coefficients(&s);
            prop_assert!(fc.abs() <= 10.0 && (viscous * 0.63).abs() <= 10.0 * (1.0 + 1e-12));
            prop_assert!(rls.offset(&s).abs() <= 10.0 && (offset || rls.offset(&s) == 0.0));
            let trace = rls.covariance_trace(&s);
            prop_assert!(trace.is_finite() && (0.0..=100.0 * (1.0 + 1e-12)).contains(&trace), "{trace}");
            prop_assert!(rls.force(&s, v).abs() <= 10.0);
            let t32 = rls32.covariance_trace(&s32);
            prop_assert!(t32.is_finite() && t32 <= 100.0 * (1.0 + 1e-6), "{t32}");
            let before = s;
            rls.update(&mut s, FrictionSample { force: f64::NAN, v });
            rls.update(&mut s, FrictionSample { force, v: f64::INFINITY });
            prop_assert_eq!(before, s);
        }
    }
}

#[test]
fn rls_covariance_stays_bounded_over_a_million_standstill_ticks() {
    let p = RlsParams::new(0.63, 10.0);
    let ctl = loop_params().build(p.build::<f64>().unwrap()).unwrap();
    let mut state = CompensatorState::default();
    // learn something first: a ramp in both directions
    let mut x = 0.0;
    for k in 0..4000 {
        x += if k < 2000 { 1e-4 } else { -1e-4 };
        ctl.tick(&mut state, x, Setpoint::default());
    }
    // the first standstill tick still learns from the last move
    for _ in 0..2 {
        ctl.tick(&mut state, x, Setpoint::default());
    }
    let rls = ctl.compensation();
    let learnt = state.friction().updates();
    assert!(learnt > 3000, "{learnt}");
    let trace = rls.covariance_trace(state.friction());
    // then stand still, with encoder chatter below the minimum speed
    for k in 0..1_000_000u32 {
        let chatter = if k % 2 == 0 { 0.0 } else { 1e-6 };
        ctl.tick(&mut state, x + chatter, Setpoint::default());
    }
    let after = rls.covariance_trace(state.friction());
    assert_eq!(state.friction().updates(), learnt);
    assert_eq!(after, trace);
    assert!(after <= p.max_covariance);
}

/// The least squares (with or without the offset) fed `samples` samples of
/// `plant(v)` at two speeds per direction (the offset's fit needs three
/// regressors).
fn rls_fit_at_four_speeds<S: Scalar>(
    offset: bool,
    samples: usize,
    plant: impl Fn(f64) -> f64,
) -> (RlsFeedForward<S>, RlsState<S>) {
    let rls = RlsParams {
        offset,
        ..RlsParams::new(0.63, 10.0)
    }
    .build::<S>()
    .unwrap();
    let mut s = RlsState::default();
    for k in 0..samples {
        let v = [0.5, -0.3, 0.2, -0.6][k % 4];
        rls.update(
            &mut s,
            FrictionSample {
                force: S::from_f64(plant(v)),
                v: S::from_f64(v),
            },
        );
    }
    (rls, s)
}

/// Samples of a "friction" that pushes along the motion (a load that
/// changes sign with the direction, as gravity does on a swinging joint)
/// fit a negative Coulomb weight, which the fit keeps and the feed-forward
/// drops: it never pushes along the motion with a Coulomb level.
#[test]
fn rls_feeds_forward_no_negative_coulomb_level() {
    fn check<S: Scalar>(offset: bool) {
        let (rls, s) =
            rls_fit_at_four_speeds::<S>(offset, 400, |v| -0.4 * f64::signum(v) + 0.1 * v);
        assert!(rls.offset(&s).abs() < 0.01, "{}", rls.offset(&s));
        let (fc, viscous) = rls.coefficients(&s);
        assert!(
            (fc.to_f64() + 0.4).abs() < 0.01,
            "the fit keeps w0: {}",
            fc.to_f64()
        );
        assert!(
            (viscous.to_f64() - 0.1).abs() < 0.01,
            "{}",
            viscous.to_f64()
        );
        for v in [0.5, -0.3, 1e-3] {
            let f = rls.force(&s, S::from_f64(v)).to_f64();
            assert!(
                (f - 0.1 * v).abs() < 0.01,
                "v {v}: {f} is the viscous term alone"
            );
        }
    }
    for offset in [false, true] {
        check::<f64>(offset);
        check::<f32>(offset);
        #[cfg(feature = "fixed")]
        check::<friction_core::Fixed32>(offset);
    }
}

/// With the offset the fit finds a Coulomb level per direction (a friction
/// with a constant load on it) and feeds each forward in its direction;
/// without it the offset stays exactly 0.
#[test]
fn rls_with_an_offset_fits_a_level_per_direction() {
    fn check<S: Scalar>() {
        let fit = |offset: bool| {
            rls_fit_at_four_speeds::<S>(offset, 800, |v| 0.3 * f64::signum(v) + 0.1 * v - 0.05)
        };
        let (rls, s) = fit(true);
        let (fc, viscous) = rls.coefficients(&s);
        let offset = rls.offset(&s);
        assert!((fc - 0.3).abs() < 0.01, "{fc}");
        assert!((viscous - 0.1).abs() < 0.01, "{viscous}");
        assert!((offset + 0.05).abs() < 0.01, "{offset}");
        for v in [0.5, -0.3, 0.1, -0.05] {
            let f = rls.force(&s, S::from_f64(v)).to_f64();
            let expected = 0.3 * f64::signum(v) + 0.1 * v - 0.05;
            assert!((f - expected).abs() < 0.01, "v {v}: {f} against {expected}");
        }
        assert_eq!(rls.force(&s, S::ZERO).to_f64(), 0.0);
        let (rls, s) = fit(false);
        assert_eq!(rls.offset(&s), 0.0);
    }
    check::<f64>();
    check::<f32>();
    #[cfg(feature = "fixed")]
    check::<friction_core::Fixed32>();
}

#[test]
fn rls_finds_a_coulomb_viscous_plant() {
    // plant F = 0.3 sign v + 0.05 v (a static map: the regressors fit exactly)
    let ctl = loop_params()
        .build(RlsParams::new(0.63, 10.0).build::<f64>().unwrap())
        .unwrap();
    let plant = |v: f64, _h: f64| 0.3 * v.signum() + 0.05 * v;
    let mut fitted = (0.0, 0.0);
    let rms = run(&ctl, plant, 20.0, |_, s| {
        fitted = ctl.compensation().coefficients(s.friction());
    });
    assert!((fitted.0 - 0.3).abs() < 0.03, "Coulomb {fitted:?}");
    assert!((fitted.1 - 0.05).abs() < 0.02, "viscous {fitted:?}");
    let none = loop_params().build::<f64, _>(NoCompensation).unwrap();
    let rms_none = run(&none, plant, 20.0, |_, _| {});
    assert!(rms < 0.5 * rms_none, "{rms} vs {rms_none}");
}

/// The Q16.16 servo builds for 1 kHz to 40 kHz loops and inertias from
/// 1e-6 to 1 (issue 18: it failed with `Underflow("h")` at 1 kHz and with
/// `J / kc = 0.0023`), and its gains act within 0.1 % of the f64 servo's.
#[cfg(feature = "fixed")]
#[test]
fn the_fixed_point_servo_builds_from_1_to_40_khz() {
    for hz in [1e3, 2e3, 5e3, 1e4, 2e4, 4e4] {
        for inertia in [1e-6, 1e-5, 1e-4, 0.0023, 0.05, 1.0] {
            let p = CompensatorParams {
                h: 1.0 / hz,
                inertia,
                ..loop_params()
            };
            let fixed = p.build::<Fixed32, _>(NoCompensation).unwrap();
            let float = p.build::<f64, _>(NoCompensation).unwrap();
            // a tick whose terms each stay within the limit: the commands agree
            // to the gains' 0.1 % plus a few units of the last place per term
            let (x0, x1) = (0.0, 1e-4 / hz);
            let r = Setpoint {
                x: 2e-3,
                v: 0.1,
                a: 1.0,
            };
            let mut sf = CompensatorState::default();
            let mut sd = CompensatorState::default();
            fixed.tick(
                &mut sf,
                Fixed32::from_f64(x0),
                Setpoint {
                    x: Fixed32::from_f64(r.x),
                    v: Fixed32::from_f64(r.v),
                    a: Fixed32::from_f64(r.a),
                },
            );
            float.tick(&mut sd, x0, r);
            let cf = fixed
                .tick(
                    &mut sf,
                    Fixed32::from_f64(x1),
                    Setpoint {
                        x: Fixed32::from_f64(r.x),
                        v: Fixed32::from_f64(r.v),
                        a: Fixed32::from_f64(r.a),
                    },
                )
                .command
                .to_f64();
            let cd = float.tick(&mut sd, x1, r).command;
            assert!(
                (cf - cd).abs() < 1e-3 * cd.abs() + 1e-3,
                "{hz} Hz, J {inertia}: {cf} vs {cd}"
            );
        }
    }
    // with the fixed-step LuGre observer at the drive's 1 kHz and 10 kHz
    for hz in [1e3, 1e4] {
        let model = LuGreParams::OLSSON_1998
            .build_fixed_step::<Fixed32>(1.0 / hz)
            .unwrap();
        let p = CompensatorParams {
            h: 1.0 / hz,
            ..loop_params()
        };
        assert!(p
            .build(FixedPeriod(Observer::new(model, 20.0).unwrap()))
            .is_ok());
    }
}

/// The Q16.16 servo with the fixed-step observer tracks like the f32 one at
/// 1 kHz: the position's resolution (1.5e-5 rad) is the limit.
#[cfg(feature = "fixed")]
#[test]
fn the_fixed_point_servo_tracks_like_f32() {
    fn observer_servo<S: Scalar>() -> Compensator<S, FixedPeriod<Observer<LuGreFixedStep<S>, S>>> {
        let model = LuGreParams::OLSSON_1998
            .build_fixed_step::<S>(1e-3)
            .unwrap();
        loop_params()
            .build(FixedPeriod(Observer::new(model, 20.0).unwrap()))
            .unwrap()
    }
    let fixed = run(
        &observer_servo::<Fixed32>(),
        scaled_lugre(1.0),
        20.0,
        |_, _| {},
    );
    let float = run(&observer_servo::<f32>(), scaled_lugre(1.0), 20.0, |_, _| {});
    let none = run(
        &loop_params().build::<Fixed32, _>(NoCompensation).unwrap(),
        scaled_lugre(1.0),
        20.0,
        |_, _| {},
    );
    eprintln!("rms: fixed {fixed:e}, f32 {float:e}, none {none:e}");
    assert!(fixed < 0.1 * none, "fixed {fixed} vs none {none}");
    assert!(fixed < float + 5e-5, "fixed {fixed} vs f32 {float}");
}

/// With the offset, long stretches of motion in one direction make `sign v`
/// and `1` the same regressor, and the covariance grows along their
/// difference up to the trace bound. On noisy data of a fixed plant the
/// feed-forward stays near it, in every scalar, with slow and fast
/// forgetting.
#[test]
fn rls_with_an_offset_survives_one_direction_stretches() {
    fn check<S: Scalar>(forgetting: f64, max_covariance: f64) {
        let rls = RlsParams {
            forgetting,
            max_covariance,
            offset: true,
            ..RlsParams::new(0.63, 10.0)
        }
        .build::<S>()
        .unwrap();
        let mut s = RlsState::default();
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut uniform = || {
            seed = seed
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut worst = 0.0f64;
        for k in 0..100_000 {
            let direction = if (k / 3000) % 2 == 0 { 1.0 } else { -1.0 };
            let v = direction * (0.02 + uniform());
            let truth = 0.3 * direction + 0.1 * v + 0.05;
            let force = truth + 0.1 * (uniform() - 0.5);
            rls.update(
                &mut s,
                FrictionSample {
                    force: S::from_f64(force),
                    v: S::from_f64(v),
                },
            );
            if k > 1000 {
                let error = rls.force(&s, S::from_f64(v)).to_f64() - truth;
                worst = worst.max(error.abs());
            }
        }
        assert!(worst < 0.5, "{forgetting} {max_covariance}: {worst}");
    }
    for (forgetting, max_covariance) in [(0.999, 100.0), (0.7, 1000.0), (0.5, 5000.0)] {
        check::<f64>(forgetting, max_covariance);
        check::<f32>(forgetting, max_covariance);
        #[cfg(feature = "fixed")]
        check::<friction_core::Fixed32>(forgetting, max_covariance);
    }
}

/// A covariance bound whose trace (two diagonal entries, three with the
/// offset) Q16.16 cannot hold is refused when built, naming it; the
/// floating-point forms take it.
#[cfg(feature = "fixed")]
#[test]
fn rls_refuses_a_covariance_bound_its_scalar_cannot_sum() {
    let p = |max_covariance: f64, offset: bool| RlsParams {
        max_covariance,
        offset,
        ..RlsParams::new(0.63, 10.0)
    };
    let refused = Some(ParamError::NotRepresentable("max_covariance"));
    assert_eq!(p(12_000.0, true).build::<Fixed32>().err(), refused);
    assert!(p(12_000.0, false).build::<Fixed32>().is_ok());
    assert_eq!(p(20_000.0, false).build::<Fixed32>().err(), refused);
    assert!(p(10_000.0, true).build::<Fixed32>().is_ok());
    assert!(p(1e6, true).build::<f32>().is_ok());
}
