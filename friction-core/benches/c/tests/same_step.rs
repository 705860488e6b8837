//! The C step is the same algorithm: state and force agree with the core's
//! step to rounding over the benchmark sweep and over sliding, reversing and
//! stiff (a h > 1) steps.
use friction_bench_c::{c_ie_step, c_step, rust_step, velocities, CLuGre, H, PARAMS};
use friction_core::{LuGreParams, LuGreState};

fn agree(p: &LuGreParams, vs: &[f64], h: f64) {
    let rust = p.build::<f64>().expect("builds");
    let c = CLuGre::new(p).expect("exponent 2");
    let (mut s, mut z) = (LuGreState::default(), 0.0);
    let scale = p.curve.fs + p.sigma2 * 1.0;
    for (k, &v) in vs.iter().enumerate() {
        let fr = rust_step(&rust, &mut s, v, h);
        let fc = c_step(&c, &mut z, v, h);
        assert!(
            (s.z - z).abs() <= 1e-12 * rust.z_max(),
            "z at step {k}: {} vs {z}",
            s.z
        );
        assert!(
            (fr - fc).abs() <= 1e-9 * scale,
            "force at step {k}: {fr} vs {fc}"
        );
    }
}

#[test]
fn same_as_the_core_on_the_sweep() {
    agree(&PARAMS, &velocities(), H);
}

#[test]
fn same_as_the_core_sliding_and_reversing() {
    let vs: Vec<f64> = (0..400)
        .map(|k| {
            let m = [1e-6, 1e-4, 1e-3, 0.01, 0.1, 1.0][k / 4 % 6];
            if k % 2 == 0 {
                m
            } else {
                -m
            }
        })
        .collect();
    agree(&PARAMS, &vs, H);
    agree(&PARAMS, &vs, 1e-6);
    agree(&LuGreParams::OLSSON_1998, &vs, H);
    agree(
        &LuGreParams {
            vd: Some(1e-3),
            ..PARAMS
        },
        &vs,
        H,
    );
}

/// The implicit-Euler reference of the instruction count is a LuGre step:
/// held at a velocity it settles on the Stribeck map, `F = sign(v) g(v) +
/// sigma2 v` (its fixed point is exact, `z = v g / (sigma0 |v|)`).
#[test]
fn implicit_euler_reference_settles_on_the_stribeck_map() {
    let c = CLuGre::new(&PARAMS).expect("exponent 2");
    let p = PARAMS.curve;
    for v in [1e-3, 0.01, -0.05] {
        let (mut z, mut f) = (0.0, 0.0);
        for _ in 0..20_000 {
            f = c_ie_step(&c, &mut z, v, H);
        }
        let g = p.fc + (p.fs - p.fc) * (-(v / p.vs) * (v / p.vs)).exp();
        let want = g.copysign(v) + PARAMS.sigma2 * v;
        assert!((f - want).abs() <= 1e-9 * p.fs, "v = {v}: {f} vs {want}");
    }
}
