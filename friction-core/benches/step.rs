//! Cost of one `step` of each model, f32 and f64. The velocity sweeps a
//! sine through zero so that every branch of the step is taken.
#![allow(missing_docs, clippy::unwrap_used, clippy::indexing_slicing)]

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use friction_core::{
    BristleParams, DahlParams, ElastoPlasticParams, FrictionModel, LuGreParams, LuGreState,
    Observer, ResetIntegratorParams, Scalar, StribeckMapParams,
};

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
    group.finish();
}

fn benches(c: &mut Criterion) {
    bench_scalar::<f32>(c, "f32");
    bench_scalar::<f64>(c, "f64");
}

criterion_group!(step, benches);
criterion_main!(step);
