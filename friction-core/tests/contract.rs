//! The step contract and the observer's bounds, for every state model, at the
//! edges: random states, hostile but finite inputs, parameters across their
//! whole range.
#![allow(clippy::unwrap_used, clippy::indexing_slicing, clippy::panic)]

use friction_core::*;
use proptest::prelude::*;
use std::format;

/// Bitwise comparison of states (`-0.0` differs from `0.0`) through `Debug`.
fn bits<T: core::fmt::Debug>(state: &T) -> String {
    format!("{state:?}")
}

/// Signed zero and ordinary values, as a fraction of a bound.
fn fraction() -> impl Strategy<Value = f64> {
    prop_oneof![Just(0.0), Just(-0.0), Just(1.0), Just(-1.0), -1.0f64..1.0]
}

fn velocity() -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(0.0),
        Just(-0.0),
        -1e-2f64..1e-2,
        -10.0f64..10.0,
        -1e9f64..1e9,
        proptest::num::f64::NORMAL,
    ]
}

fn lugre_params() -> LuGreParams {
    LuGreParams::CANUDAS_1995
}

fn ep_params(zba_fraction: f64) -> ElastoPlasticParams {
    let lugre = lugre_params();
    ElastoPlasticParams {
        lugre,
        z_ba: zba_fraction * lugre.curve.fc / lugre.sigma0,
    }
}

fn dahl_params(delta: f64) -> DahlParams {
    DahlParams {
        sigma: 1e5,
        fc: 1.0,
        delta,
        sigma2: 0.4,
    }
}

fn reset_params() -> ResetIntegratorParams {
    ResetIntegratorParams {
        sigma0: 1e5,
        sigma1: 300.0,
        z0: 1e-5,
        stiction: 0.5,
        curve: Some(lugre_params().curve),
    }
}

const BRISTLE: BristleParams = BristleParams {
    sigma0: 1e3,
    delta_s: 1e-5,
    seed: 5,
};

fn gms_params() -> GmsParams<4> {
    let e = |k: f64, alpha| GmsElement {
        k,
        alpha,
        sigma1: k * 1e-4,
    };
    GmsParams {
        curve: lugre_params().curve,
        sigma2: 0.4,
        c: 100.0,
        elements: [e(2.5e4, 0.4), e(5e4, 0.3), e(1e5, 0.2), e(2e5, 0.1)],
    }
}

fn xiong_params() -> XiongParams<4> {
    let e = |k: f64, lambda| XiongElement {
        k,
        sigma: k * 1e-4,
        lambda,
    };
    XiongParams {
        curve: lugre_params().curve,
        tau: 1e-2,
        sigma2: 0.4,
        elements: [e(2.5e4, 0.4), e(5e4, 0.3), e(1e5, 0.2), e(2e5, 0.1)],
    }
}

fn leuven_params() -> LeuvenParams {
    LeuvenParams {
        curve: lugre_params().curve,
        sigma1: 10.0,
        sigma2: 0.4,
        n: 2.0,
        xs: 1e-5,
    }
}

/// A Leuven state with a memory of up to 4 points: reversals of the given
/// depths (fractions of `xs`), alternating, each followed by a rest.
fn leuven_state<S: Scalar>(fractions: &[f64; 8]) -> LeuvenState<S, 4> {
    let m = leuven_params().build::<S, 4>().unwrap();
    let mut s = LeuvenState::default();
    for (i, x) in fractions.iter().enumerate() {
        let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
        m.step(
            &mut s,
            S::from_f64(sign * x.abs() * 1e-2),
            S::from_f64(1e-3),
        );
        m.step(&mut s, S::ZERO, S::from_f64(1e-3));
    }
    s
}

/// A GMS state from fractions of each element's bound and mode choices.
fn gms_state<S: Scalar>(fractions: &[f64; 8], modes: [u32; 8]) -> GmsState<S, 4> {
    let p = gms_params();
    let mut s = GmsState::<S, 4>::default();
    for i in 0..4 {
        s.force[i] = S::from_f64(fractions[i] * p.elements[i].alpha * p.curve.fs);
        s.mode[i] = match modes[i] % 3 {
            0 => GmsSlipMode::Stick,
            1 => GmsSlipMode::Forward,
            _ => GmsSlipMode::Backward,
        };
    }
    s
}

/// A Xiong state from fractions of each element's bound and of the lag range.
fn xiong_state<S: Scalar>(fractions: &[f64; 8]) -> XiongState<S, 4> {
    let p = xiong_params();
    let lag = fractions[7].abs() * (p.curve.fs - p.curve.fc);
    let gamma = p.curve.fs - lag;
    let mut s = XiongState::<S, 4> {
        lag: S::from_f64(lag),
        ..Default::default()
    };
    for ((z, e), x) in s.z.iter_mut().zip(&p.elements).zip(fractions) {
        *z = S::from_f64(x * e.lambda * gamma / e.k);
    }
    s
}

/// `h = 0` leaves the state bitwise unchanged, for the model and its observer.
fn zero_step_keeps<S: Scalar, M: Observable<S> + Copy>(model: &M, state: M::State, v: f64, e: f64) {
    let mut s = state;
    let f = model.step(&mut s, S::from_f64(v), S::ZERO);
    assert_eq!(bits(&s), bits(&state), "model, v {v}");
    assert!(f.is_finite());
    let observer = Observer::new(*model, 300.0).unwrap();
    let f = observer.step(&mut s, S::from_f64(v), S::from_f64(e), S::ZERO);
    assert_eq!(bits(&s), bits(&state), "observer, v {v}, e {e}");
    assert!(f.is_finite());
}

fn zero_step_all<S: Scalar>(z: f64, v: f64, e: f64, strains: &[f64; 8], bonds: [u32; 8]) {
    let lugre = lugre_params().build::<S>().unwrap();
    let z_max = lugre_params().curve.fs / lugre_params().sigma0;
    zero_step_keeps(
        &lugre,
        LuGreState {
            z: S::from_f64(z * z_max),
        },
        v,
        e,
    );
    let ep = ep_params(0.5).build::<S>().unwrap();
    zero_step_keeps(
        &ep,
        LuGreState {
            z: S::from_f64(z * z_max),
        },
        v,
        e,
    );
    // fs > 2 fc: the steady deflection at speed is below z (a case that moved z before)
    let mut wide = ep_params(0.5);
    wide.lugre.curve.fs = 3.0;
    let wide = wide.build::<S>().unwrap();
    zero_step_keeps(
        &wide,
        LuGreState {
            z: S::from_f64(z * 3e-5),
        },
        v,
        e,
    );
    for delta in [1.0, 1.000001, 2.5] {
        let dahl = dahl_params(delta).build::<S>().unwrap();
        zero_step_keeps(&dahl, DahlState { f: S::from_f64(z) }, v, e);
    }
    let reset = reset_params().build::<S>().unwrap();
    zero_step_keeps(
        &reset,
        ResetIntegratorState {
            z: S::from_f64(z * 1e-5),
        },
        v,
        e,
    );
    let bristle = BRISTLE.build::<S, 8>().unwrap();
    let mut state = BristleState::<S, 8>::default();
    for (s, &x) in state.strain.iter_mut().zip(strains) {
        *s = S::from_f64(x * 1e-5);
    }
    state.bonds = bonds;
    zero_step_keeps(&bristle, state, v, e);
    let gms = gms_params().build::<S>().unwrap();
    zero_step_keeps(&gms, gms_state::<S>(strains, bonds), v, e);
    let xiong = xiong_params().build::<S>().unwrap();
    zero_step_keeps(&xiong, xiong_state::<S>(strains), v, e);
    let leuven = leuven_params().build::<S, 4>().unwrap();
    zero_step_keeps(&leuven, leuven_state::<S>(strains), v, e);
}

#[test]
fn zero_step_examples_from_the_issue() {
    // Dahl f64, delta 1: F = -0.9187152753212887 at v = 121.93... used to move by one ulp
    let dahl = dahl_params(1.0).build::<f64>().unwrap();
    let mut s = DahlState {
        f: -0.918_715_275_321_288_7,
    };
    dahl.step(&mut s, 121.933_357_067_618_18, 0.0);
    assert_eq!(s.f.to_bits(), (-0.918_715_275_321_288_7f64).to_bits());
    // f32, F = 1e-9, v = -1 used to become -0.0
    let dahl = dahl_params(1.0).build::<f32>().unwrap();
    let mut s = DahlState { f: 1e-9f32 };
    dahl.step(&mut s, -1.0, 0.0);
    assert_eq!(s.f.to_bits(), 1e-9f32.to_bits());
    // elasto-plastic, fs = 3 fc, z beyond the steady deflection at speed
    let mut p = ep_params(0.5);
    p.lugre.curve.fs = 3.0;
    let ep = p.build::<f64>().unwrap();
    let z = -2.999_980_669_237_314_4e-5;
    let mut s = LuGreState { z };
    ep.step(&mut s, -2_840_317.69, 0.0);
    assert_eq!(s.z.to_bits(), z.to_bits());
}

proptest! {
    #[test]
    fn zero_step_leaves_every_state_bitwise_unchanged(
        z in fraction(),
        v in velocity(),
        e in prop_oneof![Just(0.0), -1e-3f64..1e-3, -1e300f64..1e300],
        strains in proptest::array::uniform8(fraction()),
        bonds in proptest::array::uniform8(any::<u32>()),
    ) {
        zero_step_all::<f64>(z, v, e, &strains, bonds);
        zero_step_all::<f32>(z, v, e, &strains, bonds);
    }
}

/// Drives an observer with hostile inputs: the estimate is finite and
/// within `force_bound(v)`, or the hold force where the step cannot be
/// taken (a non-finite input, `h < 0`); the state finite, within `state_ok`.
fn observer_stays_bounded<S: Scalar, M: Observable<S> + Copy>(
    model: M,
    k: f64,
    inputs: &[(f64, f64, f64)],
    state_ok: impl Fn(&M::State) -> bool,
) {
    for damping in [true, false] {
        let observer = Observer::new(model, k).unwrap().with_damping(damping);
        let mut state = M::State::default();
        for &(v, e, h) in inputs {
            let (v, e, h) = (S::from_f64(v), S::from_f64(e), S::from_f64(h));
            let f = observer.step(&mut state, v, e, h);
            assert!(f.is_finite(), "estimate {f:?} for v {v:?} e {e:?} h {h:?}");
            let v_used = if v.is_finite() {
                v.sat(S::from_f64(VELOCITY_LIMIT))
            } else {
                S::ZERO
            };
            if v.is_finite() && e.is_finite() && h.is_finite() && h >= S::ZERO {
                let bound = model.force_bound(v_used);
                assert!(f.abs() <= bound, "|{f:?}| > {bound:?} at v {v:?}");
            } else {
                // a step it cannot take (h beyond the scalar's range in f32,
                // a NaN): the hold force, as documented, which is the force
                // at rest and may exceed force_bound(v) (the reset
                // integrator's Stribeck-shaped stiffness is largest at rest)
                assert_eq!(f, model.hold_force(&state), "at v {v:?} e {e:?} h {h:?}");
            }
            assert!(state_ok(&state), "state {state:?}");
        }
    }
}

fn hostile_inputs() -> impl Strategy<Value = Vec<(f64, f64, f64)>> {
    proptest::collection::vec(
        (
            velocity(),
            prop_oneof![Just(0.0), -1e-2f64..1e-2, -1e300f64..1e300],
            prop_oneof![
                Just(0.0),
                0.0f64..1e-2,
                0.0f64..1e3,
                0.0f64..1e38,
                0.0f64..1e300
            ],
        ),
        1..40,
    )
}

fn gain() -> impl Strategy<Value = f64> {
    prop_oneof![Just(0.0), 0.0f64..1e3, 0.0f64..1e9, Just(1e9)]
}

fn all_observers<S: Scalar>(k: f64, inputs: &[(f64, f64, f64)]) {
    let lugre = lugre_params();
    let z_max = S::from_f64(lugre.curve.fs / lugre.sigma0);
    let lugre_ok = |s: &LuGreState<S>| s.z.is_finite() && s.z.abs() <= z_max;
    observer_stays_bounded(lugre.build::<S>().unwrap(), k, inputs, lugre_ok);
    for zba in [0.1, 0.9] {
        observer_stays_bounded(ep_params(zba).build::<S>().unwrap(), k, inputs, lugre_ok);
    }
    for delta in [1.0, 2.0] {
        observer_stays_bounded(dahl_params(delta).build::<S>().unwrap(), k, inputs, |s| {
            s.f.is_finite() && s.f.abs() <= S::ONE
        });
    }
    let z0 = S::from_f64(1e-5);
    observer_stays_bounded(reset_params().build::<S>().unwrap(), k, inputs, |s| {
        s.z.is_finite() && s.z.abs() <= z0
    });
    let ds = S::from_f64(BRISTLE.delta_s);
    observer_stays_bounded(
        BRISTLE.build::<S, 8>().unwrap(),
        k,
        inputs,
        |s: &BristleState<S, 8>| s.strain.iter().all(|x| x.is_finite() && x.abs() <= ds),
    );
    let gms = gms_params().build::<S>().unwrap();
    let bounds = gms.force_bounds();
    observer_stays_bounded(gms, k, inputs, |s: &GmsState<S, 4>| {
        s.force
            .iter()
            .zip(&bounds)
            .all(|(f, b)| f.is_finite() && f.abs() <= *b)
    });
    let leuven = leuven_params().build::<S, 4>().unwrap();
    let fs = S::from_f64(lugre.curve.fs);
    observer_stays_bounded(leuven, k, inputs, |s: &LeuvenState<S, 4>| {
        s.z().is_finite() && s.hysteresis_force().abs() <= fs && s.memory().len() <= 4
    });
    let xiong = xiong_params().build::<S>().unwrap();
    let fc = S::from_f64(lugre.curve.fc);
    let eps = S::from_f64(1e-6);
    observer_stays_bounded(xiong, k, inputs, |s: &XiongState<S, 4>| {
        let gamma = xiong.gamma(s);
        gamma >= fc * (S::ONE - eps)
            && s.z
                .iter()
                .zip(xiong.elements())
                .all(|(z, (k, l))| z.is_finite() && (k * *z).abs() <= l * gamma * (S::ONE + eps))
    });
}

proptest! {
    #[test]
    fn every_observer_stays_finite_and_bounded(k in gain(), inputs in hostile_inputs()) {
        all_observers::<f64>(k, &inputs);
        all_observers::<f32>(k, &inputs);
    }

    #[test]
    fn at_rest_the_pinned_estimate_never_exceeds_fs(
        k in gain(),
        e in prop_oneof![-1e300f64..1e300, -1.0f64..1.0],
        h in prop_oneof![Just(0.0), 1e-6f64..1e-2, 0.0f64..1e300],
        side in prop_oneof![Just(1.0), Just(-1.0)],
        damping in any::<bool>(),
    ) {
        let p = lugre_params();
        let model = p.build::<f64>().unwrap();
        let observer = Observer::new(model, k).unwrap().with_damping(damping);
        let mut z = LuGreState { z: side * model.z_max() };
        let f = observer.step(&mut z, 0.0, e, h);
        prop_assert!(f.abs() <= p.curve.fs, "{}", f);
        let model = ep_params(0.9).build::<f32>().unwrap();
        let observer = Observer::new(model, k).unwrap().with_damping(damping);
        let mut z = LuGreState { z: (side * p.curve.fs / p.sigma0) as f32 };
        let f = observer.step(&mut z, 0.0, e as f32, h as f32);
        prop_assert!(f.abs() <= p.curve.fs as f32, "{}", f);
    }
}

#[test]
fn observer_examples_from_the_issue() {
    // canudas1995, k = 200, v = 0, z^ at -Fs/sigma0, e = 0.01, h = 1e-3: was -634 N
    let model = lugre_params().build::<f64>().unwrap();
    let observer = Observer::new(model, 200.0).unwrap();
    let mut z = LuGreState { z: -model.z_max() };
    let f = observer.step(&mut z, 0.0, 0.01, 1e-3);
    assert!(f.abs() <= 1.5, "{f}");
    assert_eq!(z.z, -model.z_max());
    // k = 1e9, e = 1e300 (f64) or 1e30 (f32), h = 0: NaN used to enter z^; h > 0 gave -inf
    for h in [0.0, 1e-3] {
        let mut z = LuGreState::default();
        let f = Observer::new(model, 1e9)
            .unwrap()
            .step(&mut z, 0.0, 1e300, h);
        assert!(
            f.is_finite() && z.z.is_finite() && f.abs() <= 1.5,
            "{f} {z:?}"
        );
        let m32 = lugre_params().build::<f32>().unwrap();
        let mut z = LuGreState::default();
        let f = Observer::new(m32, 1e9)
            .unwrap()
            .step(&mut z, 0.0, 1e30, h as f32);
        assert!(
            f.is_finite() && z.z.is_finite() && f.abs() <= 1.5,
            "{f} {z:?}"
        );
    }
}

#[test]
fn observer_without_error_is_the_model() {
    // e = 0: the observer reproduces the model's force exactly, for every model
    fn same<M: Observable<f64> + Copy>(model: M) {
        let observer = Observer::new(model, 500.0).unwrap();
        let (mut a, mut b) = (M::State::default(), M::State::default());
        for k in 0..2000 {
            let v = 2e-2 * (k as f64 * 0.013).sin();
            let fm = model.step(&mut a, v, 1e-3);
            let fo = observer.step(&mut b, v, 0.0, 1e-3);
            assert_eq!(fm, fo, "step {k}");
        }
    }
    same(lugre_params().build::<f64>().unwrap());
    same(ep_params(0.9).build::<f64>().unwrap());
    same(dahl_params(1.7).build::<f64>().unwrap());
    same(reset_params().build::<f64>().unwrap());
    same(BRISTLE.build::<f64, 8>().unwrap());
    same(gms_params().build::<f64>().unwrap());
    same(xiong_params().build::<f64>().unwrap());
    same(leuven_params().build::<f64, 4>().unwrap());
}

#[test]
fn correction_acts_on_every_model() {
    // at rest with the measured position ahead of the reference, every
    // observer's estimate is pulled negative
    fn pulls<M: Observable<f64> + Copy>(model: M) {
        let observer = Observer::new(model, 1000.0).unwrap().with_damping(false);
        let mut s = M::State::default();
        let mut f = 0.0;
        for _ in 0..3 {
            f = observer.step(&mut s, 0.0, 1e-6, 1e-3);
        }
        assert!(f < 0.0, "{f}");
    }
    pulls(lugre_params().build::<f64>().unwrap());
    pulls(ep_params(0.5).build::<f64>().unwrap());
    pulls(dahl_params(1.0).build::<f64>().unwrap());
    pulls(reset_params().build::<f64>().unwrap());
    pulls(BRISTLE.build::<f64, 8>().unwrap());
    pulls(gms_params().build::<f64>().unwrap());
    pulls(xiong_params().build::<f64>().unwrap());
    pulls(leuven_params().build::<f64, 4>().unwrap());
}

#[test]
fn builds_reject_what_the_scalar_cannot_carry() {
    // beyond PARAM_RANGE, in any scalar, naming the parameter
    let mut p = lugre_params();
    p.curve.fc = 1e-50;
    p.curve.fs = 1e-50;
    assert_eq!(p.build::<f64>(), Err(ParamError::OutOfRange("fc")));
    let mut p = lugre_params();
    p.sigma1 = 1e303;
    assert_eq!(p.build::<f64>(), Err(ParamError::OutOfRange("sigma1")));
    let mut d = dahl_params(1.0);
    d.fc = 1e-45;
    assert_eq!(d.build::<f32>(), Err(ParamError::OutOfRange("fc")));
    let e = ParamError::OutOfRange("fc");
    assert!(format!("{e}").contains("`fc`") && format!("{e}").contains("1e-20"));
    // within it, what f32 cannot carry: Fc / sigma0 = 1e-40 underflows
    let mut p = lugre_params();
    p.curve.fc = 1e-20;
    p.curve.fs = 1e-20;
    p.sigma0 = 1e20;
    assert_eq!(p.build::<f32>(), Err(ParamError::Underflow("sigma0")));
    assert!(p.build::<f64>().is_ok());
    // sigma1 |v| (2 + Fs/Fc) = 1e41 at the velocity limit
    let mut p = lugre_params();
    p.curve.fc = 1e-15;
    p.sigma1 = 1e20;
    assert_eq!(p.build::<f32>(), Err(ParamError::ForceOverflow("sigma1")));
    assert!(p.build::<f64>().is_ok());
    let mut r = reset_params();
    r.sigma0 = 1e20;
    r.z0 = 1e20;
    r.curve = None;
    assert_eq!(r.build::<f32>(), Err(ParamError::ForceOverflow("sigma0")));
    let b = BristleParams {
        sigma0: 1e20,
        delta_s: 1e20,
        seed: 1,
    };
    assert_eq!(
        b.build::<f32, 8>(),
        Err(ParamError::ForceOverflow("sigma0"))
    );
    let mut l = leuven_params();
    l.xs = 1e-40;
    assert_eq!(l.build::<f32, 2>(), Err(ParamError::OutOfRange("xs")));
}

#[test]
fn stiff_lugre_lands_on_the_steady_state() {
    // sigma0 = 1e20 (the top of PARAM_RANGE), v = 1e4: z used to collapse
    // to 0 for a stiff sigma0
    let mut p = lugre_params();
    p.sigma0 = 1e20;
    p.sigma1 = 0.0;
    let m = p.build::<f64>().unwrap();
    let mut s = LuGreState::default();
    let f = m.step(&mut s, 1e4, 1e-3);
    let expect = m.steady_state(1e4);
    assert!((f - expect).abs() <= 1e-9 * expect, "{f} vs {expect}");
    // f32 at v = 1e6
    let mut p = lugre_params();
    p.sigma0 = 1e20;
    let m = p.build::<f32>().unwrap();
    let mut s = LuGreState::default();
    let f = m.step(&mut s, 1e6, 1e-3);
    let expect = m.steady_state(1e6);
    assert!((f - expect).abs() <= 1e-6 * expect, "{f} vs {expect}");
}

#[test]
fn dahl_close_to_one_keeps_its_state_in_f32() {
    // delta = 1.000001: 1000 steps of 1e-8 m used to stay at F = 0 in f32
    let p = dahl_params(1.000_001);
    let (m32, m64) = (p.build::<f32>().unwrap(), p.build::<f64>().unwrap());
    let (mut a, mut b) = (DahlState::default(), DahlState::default());
    for _ in 0..1000 {
        m32.step(&mut a, 1e-5, 1e-3);
        m64.step(&mut b, 1e-5, 1e-3);
    }
    assert!((b.f - 0.632).abs() < 1e-3, "{}", b.f);
    assert!((f64::from(a.f) - b.f).abs() < 1e-5 * b.f, "{} {}", a.f, b.f);
}

/// Log-uniform magnitude from 1e-60 to 1e60 (beyond f32's range both ways).
fn wide() -> impl Strategy<Value = f64> {
    (-60.0f64..60.0).prop_map(|e| 10f64.powf(e))
}

proptest! {
    /// Any parameter set that builds in f32 gives finite forces for any
    /// finite input, with the model and with its observer.
    #[test]
    fn every_f32_set_that_builds_stays_finite(
        fc in wide(), ratio in 1.0f64..10.0, vs in wide(), sigma0 in wide(),
        sigma1 in wide(), sigma2 in wide(), zba in 0.01f64..0.99, delta in 1.0f64..3.0,
        inputs in hostile_inputs(),
    ) {
        let lugre = LuGreParams {
            curve: StribeckParams { fc, fs: fc * ratio, vs, exponent: 2.0 },
            sigma0, sigma1, sigma2, vd: None,
        };
        fn run<M: Observable<f32> + Copy + core::fmt::Debug>(m: Result<M, ParamError>, inputs: &[(f64, f64, f64)]) {
            let Ok(m) = m else { return };
            let o = Observer::new(m, 50.0).unwrap();
            let (mut a, mut b) = (M::State::default(), M::State::default());
            for &(v, e, h) in inputs {
                let f = m.step(&mut a, v as f32, h as f32);
                assert!(f.is_finite(), "{m:?} v {v} h {h}");
                let f = o.step(&mut b, v as f32, e as f32, h as f32);
                assert!(f.is_finite(), "{m:?} v {v} e {e} h {h}");
            }
        }
        run(lugre.build::<f32>(), &inputs);
        run(ElastoPlasticParams { lugre, z_ba: zba * fc / sigma0 }.build::<f32>(), &inputs);
        run(DahlParams { sigma: sigma0, fc, delta, sigma2 }.build::<f32>(), &inputs);
        run(ResetIntegratorParams { sigma0, sigma1, z0: fc / sigma0, stiction: ratio - 1.0, curve: None }.build::<f32>(), &inputs);
        run(BristleParams { sigma0, delta_s: fc / sigma0, seed: 2 }.build::<f32, 4>(), &inputs);
        let ge = |k: f64, alpha| GmsElement { k, alpha, sigma1 };
        run(GmsParams {
            curve: lugre.curve, sigma2, c: sigma0 * vs,
            elements: [ge(sigma0, 0.5), ge(sigma0 * ratio, 0.25), ge(sigma0 / ratio, 0.25)],
        }.build::<f32>(), &inputs);
        let xe = |k: f64, lambda| XiongElement { k, sigma: sigma1, lambda };
        run(XiongParams {
            curve: lugre.curve, tau: vs, sigma2,
            elements: [xe(sigma0, 0.5), xe(sigma0 * ratio, 0.25), xe(sigma0 / ratio, 0.25)],
        }.build::<f32>(), &inputs);
        run(LeuvenParams { curve: lugre.curve, sigma1, sigma2, n: delta, xs: fc / sigma0 }
            .build::<f32, 3>(), &inputs);
    }
}

/// The case proptest found (f32): a period beyond f32's range is no step,
/// and the reset integrator's hold force there, at its stiffness at rest,
/// is above its `force_bound(v)` at the Stribeck-shaped stiffness of `v`.
#[test]
fn a_period_beyond_the_scalar_returns_the_hold_force() {
    let inputs = [
        (0.0023156517135559905, 0.0, 0.004308081734145256),
        (0.0010507715345699968, 0.0, 1.8138507520876634e299),
    ];
    all_observers::<f32>(0.0, &inputs);
    all_observers::<f64>(0.0, &inputs);
}
