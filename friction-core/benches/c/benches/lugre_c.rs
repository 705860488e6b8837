//! friction-core's f64 LuGre step against the hand-written C step, in one
//! criterion run: the same canudas1995 parameters and 10 mm/s sine sweep as
//! the core's `step` benchmark, all called out of line; `c-implicit-euler`
//! is the minimal implicit-Euler C step (one `exp`) issue 19 sizes the host
//! step against.
use criterion::{black_box, criterion_group, criterion_main, Criterion};
use friction_bench_c::{
    c_ie_step, c_step, rust_fixed_step, rust_step, velocities, CLuGre, H, PARAMS,
};
use friction_core::{LuGreFixedStepState, LuGreState};

fn compare(c: &mut Criterion) {
    let rust = PARAMS.build::<f64>().expect("canudas1995 builds");
    let cm = CLuGre::new(&PARAMS).expect("exponent 2");
    let vs = velocities();
    let mut group = c.benchmark_group("lugre-f64");
    group.bench_function("rust", |b| {
        let mut s = LuGreState::default();
        let mut i = 0;
        b.iter(|| {
            i = (i + 1) & 1023;
            black_box(rust_step(&rust, &mut s, black_box(vs[i]), black_box(H)))
        })
    });
    let fixed = PARAMS
        .build_fixed_step::<f64>(H)
        .expect("canudas1995 builds");
    group.bench_function("rust-fixed-step", |b| {
        let mut w = LuGreFixedStepState::default();
        let mut i = 0;
        b.iter(|| {
            i = (i + 1) & 1023;
            black_box(rust_fixed_step(&fixed, &mut w, black_box(vs[i])))
        })
    });
    group.bench_function("c", |b| {
        let mut z = 0.0;
        let mut i = 0;
        b.iter(|| {
            i = (i + 1) & 1023;
            black_box(c_step(&cm, &mut z, black_box(vs[i]), black_box(H)))
        })
    });
    group.bench_function("c-implicit-euler", |b| {
        let mut z = 0.0;
        let mut i = 0;
        b.iter(|| {
            i = (i + 1) & 1023;
            black_box(c_ie_step(&cm, &mut z, black_box(vs[i]), black_box(H)))
        })
    });
    group.finish();
}

criterion_group!(benches, compare);
criterion_main!(benches);
