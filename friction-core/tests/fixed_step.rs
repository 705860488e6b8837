//! The fixed-step form against the variable-step form: the same solution
//! (forces agree to rounding), the same contract (hostile inputs, bounded
//! states and estimates), the same observer and compensator.
#![allow(clippy::unwrap_used, clippy::indexing_slicing, clippy::panic)]

use friction_core::*;
use proptest::prelude::*;

/// A velocity program crossing zero, slow and fast, with rests: a sine of
/// 5 mm/s at 1 Hz, then one of 20 mm/s at 5 Hz, then 0.1 m/s plateaus.
fn signal(k: usize, h: f64) -> f64 {
    let t = k as f64 * h;
    match (t / 1.0) as u32 {
        0 => 5e-3 * (2.0 * core::f64::consts::PI * t).sin(),
        1 => 2e-2 * (10.0 * core::f64::consts::PI * t).sin(),
        2 => 0.0,
        _ => 0.1 * (3.0 * t).sin().signum(),
    }
}

/// Max |F_at - F_var| / Fs over the program, model and observer (with a
/// position error that the observer's correction turns into a velocity offset).
fn max_gap<V, A>(var: V, at: A, h: f64, fs: f64, gain: f64) -> (f64, f64)
where
    V: Observable<f64> + Copy,
    A: FixedStepObservable<f64> + Copy,
{
    let (mut sv, mut sa) = (V::State::default(), A::State::default());
    let (mut ov, mut oa) = (V::State::default(), A::State::default());
    let obs_v = Observer::new(var, gain).unwrap();
    let obs_a = Observer::new(at, gain).unwrap();
    let (mut model_gap, mut observer_gap) = (0.0f64, 0.0f64);
    let n = (4.0 / h) as usize;
    for k in 0..n {
        let v = signal(k, h);
        let e = 1e-6 * (k as f64 * h * 7.0).cos();
        let fv = var.step(&mut sv, v, h);
        let fa = at.step(&mut sa, v);
        model_gap = model_gap.max((fv - fa).abs() / fs);
        let gv = obs_v.step(&mut ov, v, e, h);
        let ga = obs_a.step_at(&mut oa, v, e);
        observer_gap = observer_gap.max((gv - ga).abs() / fs);
    }
    (model_gap, observer_gap)
}

#[test]
fn lugre_at_is_the_variable_step_solution() {
    for p in [LuGreParams::CANUDAS_1995, LuGreParams::OLSSON_1998] {
        for h in [1e-3, 1e-4] {
            let var = p.build::<f64>().unwrap();
            let at = p.build_at::<f64>(h).unwrap();
            let (m, o) = max_gap(var, at, h, p.curve.fs, 100.0);
            assert!(m < 1e-9, "model gap {m} at h {h}");
            assert!(o < 1e-9, "observer gap {o} at h {h}");
            let dissipative = LuGreParams {
                vd: Some(1e-3),
                ..p
            };
            let (m, _) = max_gap(
                dissipative.build::<f64>().unwrap(),
                dissipative.build_at::<f64>(h).unwrap(),
                h,
                p.curve.fs,
                0.0,
            );
            assert!(m < 1e-9, "vd model gap {m}");
        }
    }
}

/// f32 fixed-step against f64 variable-step: the fast exponential costs
/// nothing visible.
#[test]
fn lugre_at_f32_tracks_f64() {
    let p = LuGreParams::CANUDAS_1995;
    let h = 1e-4;
    let var = p.build::<f64>().unwrap();
    let at = p.build_at::<f32>(h).unwrap();
    let (mut sv, mut sa) = (LuGreState::default(), LuGreAtState::default());
    let mut worst = 0.0f64;
    for k in 0..(4.0 / h) as usize {
        let v = signal(k, h);
        let fv = var.step(&mut sv, v, h);
        let fa = at.step(&mut sa, v as f32) as f64;
        worst = worst.max((fv - fa).abs() / p.curve.fs);
    }
    assert!(worst < 1e-5, "f32 fixed-step gap {worst} of Fs");
}

#[test]
fn build_at_rejects_bad_periods_and_overflow() {
    let p = LuGreParams::CANUDAS_1995;
    for h in [0.0, -1e-3, f64::NAN, f64::INFINITY] {
        assert!(p.build_at::<f32>(h).is_err(), "h {h}");
    }
    assert_eq!(
        p.build_at::<f32>(0.0).err(),
        Some(ParamError::NotPositive("h"))
    );
    // sigma0 h 1e6 overflows f32
    let stiff = LuGreParams { sigma0: 1e36, ..p };
    assert_eq!(
        stiff.build_at::<f32>(1e-3).err(),
        Some(ParamError::ForceOverflow("sigma0"))
    );
}

#[test]
fn compensator_checks_the_period() {
    let model = LuGreParams::OLSSON_1998.build_at::<f64>(1e-3).unwrap();
    let observer = AtPeriod(Observer::new(model, 100.0).unwrap());
    let mut params = CompensatorParams {
        h: 1e-3,
        kp: 60.0,
        ki: 200.0,
        kd: 1.2,
        inertia: 0.0023,
        torque_constant: 1.0,
        limit: 5.0,
    };
    assert!(params.build(observer).is_ok());
    params.h = 1.001e-3;
    assert_eq!(
        params.build(observer).err(),
        Some(ParamError::PeriodMismatch)
    );
}

/// The fixed-step compensator ticks like the variable-step one.
#[test]
fn compensator_at_period_matches_variable_step() {
    let p = LuGreParams::OLSSON_1998;
    let params = CompensatorParams {
        h: 1e-3,
        kp: 60.0,
        ki: 200.0,
        kd: 1.2,
        inertia: 0.0023,
        torque_constant: 1.0,
        limit: 5.0,
    };
    let var = params
        .build(Observer::new(p.build::<f64>().unwrap(), 100.0).unwrap())
        .unwrap();
    let at = params
        .build(AtPeriod(
            Observer::new(p.build_at::<f64>(1e-3).unwrap(), 100.0).unwrap(),
        ))
        .unwrap();
    let (mut sv, mut sa) = (CompensatorState::default(), CompensatorState::default());
    for k in 0..3000 {
        let t = k as f64 * 1e-3;
        let r = Setpoint {
            x: 0.1 * (2.0 * t).sin(),
            v: 0.2 * (2.0 * t).cos(),
            a: -0.4 * (2.0 * t).sin(),
        };
        let x = r.x + 1e-4 * (13.0 * t).sin();
        let a = var.tick(&mut sv, x, r);
        let b = at.tick(&mut sa, x, r);
        assert!((a.command - b.command).abs() < 1e-9, "tick {k}");
    }
}

proptest! {
    /// Any finite velocity sequence: |w| <= Fs, finite force; a non-finite
    /// input leaves the state untouched and returns the hold force.
    #[test]
    fn lugre_at_contract(
        vs in proptest::collection::vec(prop_oneof![
            -1e-2f64..1e-2, -10.0f64..10.0, proptest::num::f64::ANY], 1..200),
        h in prop_oneof![Just(1e-5), Just(1e-4), Just(1e-3), 1e-6f64..1e-1],
    ) {
        let p = LuGreParams::CANUDAS_1995;
        let m = p.build_at::<f32>(h).unwrap();
        let mut s = LuGreAtState::default();
        for v in vs {
            let before = s;
            let f = m.step(&mut s, v as f32);
            prop_assert!(f.is_finite());
            prop_assert!(s.w.abs() <= 1.5);
            if !(v as f32).is_finite() {
                prop_assert_eq!(s, before);
                prop_assert_eq!(f, m.hold_force(&s));
            }
        }
    }

    /// The observer on the fixed-step form: any gain, error and velocity give
    /// a finite estimate within the force bound and a bounded state.
    #[test]
    fn lugre_at_observer_is_bounded(
        inputs in proptest::collection::vec(
            (-1e9f64..1e9, prop_oneof![-1e300f64..1e300, -1e-3f64..1e-3]), 1..100),
        gain in prop_oneof![Just(0.0), 0.0f64..1e9],
    ) {
        let p = LuGreParams::CANUDAS_1995;
        let m = p.build_at::<f64>(1e-3).unwrap();
        let o = Observer::new(m, gain).unwrap();
        let mut s = LuGreAtState::default();
        for (v, e) in inputs {
            let f = o.step_at(&mut s, v, e);
            prop_assert!(f.is_finite());
            prop_assert!(f.abs() <= m.force_bound(v.clamp(-1e6, 1e6)));
            prop_assert!(s.w.abs() <= 1.5);
        }
    }
}

/// Fixed point (feature `fixed`): LuGreAt in Q16.16 against f64, and the
/// variable-step form refused with a typed error.
#[cfg(feature = "fixed")]
mod fixed_point {
    use super::*;

    fn rms_gap(p: LuGreParams, h: f64, scale: f64) -> f64 {
        let var = p.build::<f64>().unwrap();
        let at = p.build_at::<Fixed32>(h).unwrap();
        let (mut sv, mut sa) = (LuGreState::default(), LuGreAtState::default());
        let mut sum = 0.0;
        let n = (4.0 / h) as usize;
        for k in 0..n {
            let v = scale * signal(k, h);
            let fv = var.step(&mut sv, v, h);
            let fa = at.step(&mut sa, Fixed32::from_f64(v)).to_f64();
            sum += (fv - fa).powi(2);
        }
        (sum / n as f64).sqrt() / p.curve.fs
    }

    #[test]
    fn lugre_fixed_point_tracks_f64() {
        for (p, scale) in [
            (LuGreParams::CANUDAS_1995, 1.0),
            (LuGreParams::OLSSON_1998, 10.0),
        ] {
            // measured 4.8e-4 (canudas1995) and 2e-5 (olsson1998) of Fs
            for (h, bound) in [(1e-3, 2e-3), (1e-4, 2e-3)] {
                let gap = rms_gap(p, h, scale);
                std::println!("fixed LuGre rms gap {gap:.2e} of Fs at h {h}");
                assert!(gap < bound, "rms gap {gap} of Fs at h {h}");
            }
        }
    }

    #[test]
    fn variable_step_lugre_is_refused_in_fixed_point() {
        assert_eq!(
            LuGreParams::CANUDAS_1995.build::<Fixed32>().err(),
            Some(ParamError::Underflow("sigma0"))
        );
    }
}
