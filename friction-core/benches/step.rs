//! Cost of one `step` of each model, f32 and f64. The velocity sweeps a
//! sine through zero so that every branch of the step is taken.
#![allow(missing_docs, clippy::unwrap_used, clippy::indexing_slicing)]

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use friction_core::{FrictionModel, LuGreParams, LuGreState, Observer, Scalar, StribeckMapParams};

fn velocities<S: Scalar>() -> Vec<S> {
    (0..1024)
        .map(|k| S::from_f64(0.01 * (k as f64 * 0.0123).sin()))
        .collect()
}

fn bench_scalar<S: Scalar + 'static>(c: &mut Criterion, name: &str) {
    let p = LuGreParams::CANUDAS_1995;
    let lugre = p.build::<S>().unwrap();
    let vs = velocities::<S>();
    let h = S::from_f64(1e-3);
    let mut group = c.benchmark_group(format!("step/{name}"));
    group.bench_function("lugre", |b| {
        let mut s = LuGreState::default();
        let mut i = 0;
        b.iter(|| {
            i = (i + 1) & 1023;
            black_box(lugre.step(&mut s, black_box(vs[i]), h))
        })
    });
    let observer = Observer::new(lugre, 100.0).unwrap();
    group.bench_function("lugre-observer", |b| {
        let mut s = LuGreState::default();
        let mut i = 0;
        b.iter(|| {
            i = (i + 1) & 1023;
            black_box(observer.step(&mut s, black_box(vs[i]), black_box(S::from_f64(1e-6)), h))
        })
    });
    let map = StribeckMapParams {
        curve: p.curve,
        sigma2: p.sigma2,
    }
    .build::<S>()
    .unwrap();
    group.bench_function("stribeck-map", |b| {
        let mut i = 0;
        b.iter(|| {
            i = (i + 1) & 1023;
            black_box(map.step(&mut (), black_box(vs[i]), h))
        })
    });
    group.finish();
}

fn benches(c: &mut Criterion) {
    bench_scalar::<f32>(c, "f32");
    bench_scalar::<f64>(c, "f64");
}

criterion_group!(step, benches);
criterion_main!(step);
