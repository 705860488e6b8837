//! Cost of one step of each fixed-step form (`build_fixed_step(h)`, h = 1 ms) in
//! f32, f64 and Q16.16 fixed point, next to the variable-step LuGre. The
//! velocity sweeps a sine through zero (as in `step.rs`). Run with
//! `cargo bench -p friction-core --features fixed --bench fixed_step`.
#![allow(missing_docs, clippy::unwrap_used, clippy::indexing_slicing)]

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use friction_core::{
    DahlParams, ElastoPlasticParams, Fixed32, FixedStepModel, FrictionModel, GmsElement, GmsParams,
    LuGreParams, Scalar, StribeckParams, XiongElement, XiongParams,
};

const H: f64 = 1e-3;

const CURVE: StribeckParams = StribeckParams {
    fc: 1.0,
    fs: 1.5,
    vs: 1e-3,
    exponent: 2.0,
};

/// Four elements as in gms-typical / xiong-typical.
const ELEMENTS: [(f64, f64); 4] = [(2.5e4, 0.4), (5e4, 0.3), (1e5, 0.2), (2e5, 0.1)];

fn velocities<S: Scalar>() -> Vec<S> {
    (0..1024)
        .map(|k| S::from_f64(0.01 * (k as f64 * 0.0123).sin()))
        .collect()
}

fn bench_at<S: Scalar + 'static, M: FixedStepModel<S>>(
    g: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    name: &str,
    model: Option<M>,
) {
    // a form the scalar cannot carry with these parameters is skipped
    let Some(model) = model else { return };
    let vs = velocities::<S>();
    g.bench_function(name, |b| {
        let mut s = M::State::default();
        let mut i = 0;
        b.iter(|| {
            i = (i + 1) & 1023;
            black_box(model.step(&mut s, black_box(vs[i])))
        })
    });
}

fn bench_scalar<S: Scalar + 'static>(c: &mut Criterion, name: &str) {
    let lugre = LuGreParams::CANUDAS_1995;
    let mut g = c.benchmark_group(format!("fixed-step/{name}"));
    bench_at(&mut g, "lugre", lugre.build_fixed_step::<S>(H).ok());
    let dahl = DahlParams {
        sigma: 1e5,
        fc: 1.0,
        delta: 1.0,
        sigma2: 0.4,
    };
    bench_at(&mut g, "dahl", dahl.build_fixed_step::<S>(H).ok());
    let ep = ElastoPlasticParams { lugre, z_ba: 5e-6 };
    bench_at(&mut g, "elasto-plastic", ep.build_fixed_step::<S>(H).ok());
    let gms = GmsParams {
        curve: CURVE,
        sigma2: 0.4,
        c: 100.0,
        elements: ELEMENTS.map(|(k, alpha)| GmsElement {
            k,
            alpha,
            sigma1: 1e-4 * k,
        }),
    };
    bench_at(&mut g, "gms-4", gms.build_fixed_step::<S>(H).ok());
    let xiong = XiongParams {
        curve: CURVE,
        tau: 1e-2,
        sigma2: 0.4,
        elements: ELEMENTS.map(|(k, lambda)| XiongElement {
            k,
            sigma: 1e-4 * k,
            lambda,
        }),
    };
    bench_at(&mut g, "xiong-4", xiong.build_fixed_step::<S>(H).ok());
    g.finish();
}

/// The variable-step LuGre in f32, the reference row for the ratios.
fn bench_variable(c: &mut Criterion) {
    let model = LuGreParams::CANUDAS_1995.build::<f32>().unwrap();
    let vs = velocities::<f32>();
    c.bench_function("fixed-step/variable-step-f32/lugre", |b| {
        let mut s = Default::default();
        let mut i = 0;
        b.iter(|| {
            i = (i + 1) & 1023;
            black_box(model.step(&mut s, black_box(vs[i]), black_box(1e-3)))
        })
    });
}

fn all(c: &mut Criterion) {
    bench_variable(c);
    bench_scalar::<f32>(c, "f32");
    bench_scalar::<f64>(c, "f64");
    bench_scalar::<Fixed32>(c, "fixed");
}

criterion_group!(benches, all);
criterion_main!(benches);
