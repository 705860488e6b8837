//! Cost of one `step` of each model, f32 and f64. The velocity sweeps a
//! sine through zero so that every branch of the step is taken.
#![allow(missing_docs, clippy::unwrap_used, clippy::indexing_slicing)]

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use friction_core::{
    BristleParams, DahlParams, ElastoPlasticParams, FrictionModel, GmsElement, GmsParams,
    GmsSlipMode, GmsState, LeuvenParams, LeuvenState, LuGreParams, LuGreState, Observer,
    ResetIntegratorParams, Scalar, StribeckMapParams, StribeckParams, XiongElement, XiongParams,
};

/// The Stribeck curve of canudas1995 (and of gms-typical, xiong-typical).
const CURVE: StribeckParams = StribeckParams {
    fc: 1.0,
    fs: 1.5,
    vs: 1e-3,
    exponent: 2.0,
};

/// Element `i` of `n` as in gms-typical / xiong-typical: stiffnesses spread
/// geometrically from 2.5e4 to 2e5 N/m, weights falling linearly with
/// stiffness (normalised to sum 1), damping 1e-4 s x k.
fn element(i: usize, n: usize) -> (f64, f64) {
    let frac = if n > 1 {
        i as f64 / (n - 1) as f64
    } else {
        0.0
    };
    let k = 2.5e4 * 8f64.powf(frac);
    let total = (n * (n + 1) / 2) as f64;
    let weight = (n - i) as f64 / total;
    (k, weight)
}

fn gms_params<const N: usize>() -> GmsParams<N> {
    let mut elements = [GmsElement::default(); N];
    for (i, e) in elements.iter_mut().enumerate() {
        let (k, alpha) = element(i, N);
        *e = GmsElement {
            k,
            alpha,
            sigma1: 1e-4 * k,
        };
    }
    GmsParams {
        curve: CURVE,
        sigma2: 0.4,
        c: 100.0,
        elements,
    }
}

fn xiong_params<const N: usize>() -> XiongParams<N> {
    let mut elements = [XiongElement::default(); N];
    for (i, e) in elements.iter_mut().enumerate() {
        let (k, lambda) = element(i, N);
        *e = XiongElement {
            k,
            sigma: 1e-4 * k,
            lambda,
        };
    }
    XiongParams {
        curve: CURVE,
        tau: 1e-2,
        sigma2: 0.4,
        elements,
    }
}

fn velocities<S: Scalar>() -> Vec<S> {
    (0..1024)
        .map(|k| S::from_f64(0.01 * (k as f64 * 0.0123).sin()))
        .collect()
}

fn bench_model<S: Scalar + 'static, M: FrictionModel<S>>(
    c: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    name: &str,
    model: &M,
) {
    let vs = velocities::<S>();
    let h = S::from_f64(1e-3);
    c.bench_function(name, |b| {
        let mut s = M::State::default();
        let mut i = 0;
        b.iter(|| {
            i = (i + 1) & 1023;
            black_box(model.step(&mut s, black_box(vs[i]), h))
        })
    });
}

fn bench_scalar<S: Scalar + 'static>(c: &mut Criterion, name: &str) {
    let p = LuGreParams::CANUDAS_1995;
    let lugre = p.build::<S>().unwrap();
    let mut group = c.benchmark_group(format!("step/{name}"));
    bench_model(&mut group, "lugre", &lugre);
    let observer = Observer::new(lugre, 100.0).unwrap();
    let vs = velocities::<S>();
    let h = S::from_f64(1e-3);
    group.bench_function("lugre-observer", |b| {
        let mut s = Default::default();
        let mut i = 0;
        b.iter(|| {
            i = (i + 1) & 1023;
            black_box(observer.step(&mut s, black_box(vs[i]), black_box(S::from_f64(1e-6)), h))
        })
    });
    bench_model(
        &mut group,
        "stribeck-map",
        &StribeckMapParams {
            curve: p.curve,
            sigma2: p.sigma2,
        }
        .build::<S>()
        .unwrap(),
    );
    bench_model(
        &mut group,
        "dahl",
        &DahlParams {
            sigma: 1e5,
            fc: 1.0,
            delta: 1.0,
            sigma2: 0.4,
        }
        .build::<S>()
        .unwrap(),
    );
    bench_model(
        &mut group,
        "dahl-delta2",
        &DahlParams {
            sigma: 1e5,
            fc: 1.0,
            delta: 2.0,
            sigma2: 0.4,
        }
        .build::<S>()
        .unwrap(),
    );
    bench_model(
        &mut group,
        "elasto-plastic",
        &ElastoPlasticParams {
            lugre: p,
            z_ba: 5e-6,
        }
        .build::<S>()
        .unwrap(),
    );
    // worst case: every step starts at z_ba and slides far enough (20 µm, the
    // zone is 0.1 µm wide) to run all its RK4 sub-steps (22) and the tail
    let narrow = ElastoPlasticParams {
        lugre: p,
        z_ba: 0.99e-5,
    }
    .build::<S>()
    .unwrap();
    group.bench_function("elasto-plastic-worst", |b| {
        let mut s = LuGreState::default();
        let (z0, v) = (S::from_f64(0.99e-5), S::from_f64(0.02));
        b.iter(|| {
            s.z = black_box(z0);
            black_box(narrow.step(&mut s, black_box(v), h))
        })
    });
    let reset = ResetIntegratorParams {
        sigma0: 1e5,
        sigma1: 316.0,
        z0: 1e-5,
        stiction: 0.5,
        curve: None,
    };
    bench_model(&mut group, "reset-integrator", &reset.build::<S>().unwrap());
    let bristle = BristleParams {
        sigma0: 12_000.0,
        delta_s: 1e-5,
        seed: 1,
    };
    bench_model(&mut group, "bristle-8", &bristle.build::<S, 8>().unwrap());
    bench_model(&mut group, "bristle-64", &bristle.build::<S, 64>().unwrap());
    bench_model(
        &mut group,
        "gms-1",
        &gms_params::<1>().build::<S>().unwrap(),
    );
    let gms4 = gms_params::<4>().build::<S>().unwrap();
    bench_model(&mut group, "gms-4", &gms4);
    bench_model(
        &mut group,
        "gms-16",
        &gms_params::<16>().build::<S>().unwrap(),
    );
    // worst case: v alternates between +-0.1 m/s, so every element reverses
    // every step, sticks, reaches its bound inside the step (k |v| h = 25 to
    // 200 N against at most 2 alpha_i Fs = 1.2 N of room) and slips for the
    // rest of it (the exact instant and the exponential relaxation)
    let mut check = GmsState::default();
    for k in 0..4 {
        let v = if k % 2 == 0 { 0.1 } else { -0.1 };
        let before = check.force;
        gms4.step(&mut check, S::from_f64(v), h);
        let mode = if v > 0.0 {
            GmsSlipMode::Forward
        } else {
            GmsSlipMode::Backward
        };
        assert_eq!(check.mode, [mode; 4], "every element slips after step {k}");
        assert!(check.force.iter().zip(&before).all(|(a, b)| a != b));
    }
    group.bench_function("gms-4-worst", |b| {
        let mut s = GmsState::default();
        let mut v = S::from_f64(0.1);
        b.iter(|| {
            v = -v;
            black_box(gms4.step(&mut s, black_box(v), h))
        })
    });
    bench_model(
        &mut group,
        "xiong-1",
        &xiong_params::<1>().build::<S>().unwrap(),
    );
    bench_model(
        &mut group,
        "xiong-4",
        &xiong_params::<4>().build::<S>().unwrap(),
    );
    bench_model(
        &mut group,
        "xiong-16",
        &xiong_params::<16>().build::<S>().unwrap(),
    );
    // Leuven as params/leuven-typical.toml, memory of 8 points
    let leuven = LeuvenParams {
        curve: CURVE,
        sigma1: 10.0,
        sigma2: 0.4,
        n: 2.0,
        xs: 1e-5,
    }
    .build::<S, 8>()
    .unwrap();
    bench_model(&mut group, "leuven-8", &leuven);
    // worst case: a full memory of 8 nested reversal points; the step
    // reverses (a push into the full memory: drop the oldest, O(M) shift),
    // then passes every remaining point (6 pops) and solves in the last branch
    let nested = leuven_nested(&leuven);
    let mut check = nested;
    leuven.step(&mut check, S::from_f64(-1e-2), h);
    assert_eq!(nested.memory().len(), 8);
    assert!(check.memory().len() <= 1, "{:?}", check.memory());
    group.bench_function("leuven-8-worst", |b| {
        let mut s = nested;
        b.iter(|| {
            s = black_box(nested);
            black_box(leuven.step(&mut s, black_box(S::from_f64(-1e-2)), h))
        })
    });
    group.finish();
}

/// A Leuven state whose memory is full of nested reversals.
fn leuven_nested<S: Scalar, const M: usize>(m: &friction_core::Leuven<S, M>) -> LeuvenState<S, M> {
    let mut s = LeuvenState::default();
    let mut amp = 8e-6;
    m.step(&mut s, S::ONE, S::from_f64(amp));
    for _ in 0..M {
        amp *= 0.8;
        m.step(&mut s, -S::ONE, S::from_f64(amp));
        amp *= 0.8;
        m.step(&mut s, S::ONE, S::from_f64(amp));
    }
    s
}

fn benches(c: &mut Criterion) {
    bench_scalar::<f32>(c, "f32");
    bench_scalar::<f64>(c, "f64");
}

criterion_group!(step, benches);
criterion_main!(step);
