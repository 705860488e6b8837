//! LuGre's discrete step against the independent reference solver, with the
//! bounds of the foundation issue (canudas1995 parameters).

use friction_core::{FrictionModel, LuGreParams, LuGreState};
use friction_host::experiments::{self, Options};
use friction_host::models::ModelSpec;
use friction_host::params::param_set;
use friction_host::validate::{accuracy, F32_BOUND};

#[test]
fn rms_force_error_within_bounds_at_1_and_10_khz() {
    let spec = param_set("canudas1995").unwrap().model;
    let rows = accuracy("canudas1995", &spec, true, None).unwrap();
    assert_eq!(rows.len(), 8, "4 signals x 2 rates");
    for r in &rows {
        let bound = if r.h >= 1e-3 { 0.02 } else { 0.005 };
        assert!(
            r.rms <= bound,
            "{} at {} Hz: rms {:.4} % of Fs > {} %",
            r.signal,
            1.0 / r.h,
            100.0 * r.rms,
            100.0 * bound
        );
        assert!(
            r.f32_rms <= F32_BOUND,
            "{}: f32 differs from f64 by {:.2e} Fs",
            r.signal,
            r.f32_rms
        );
    }
    // 10x the rate gives ~10x less error: the step is first order in h
    for pair in rows.chunks(2) {
        let ratio = pair[0].rms / pair[1].rms;
        assert!(
            (5.0..20.0).contains(&ratio),
            "{}: 1 kHz / 10 kHz error ratio {ratio}",
            pair[0].signal
        );
    }
}

#[test]
fn stick_slip_at_1_ms_matches_the_reference() {
    for set in ["canudas1995", "astrom2008-stickslip"] {
        let file = param_set(set).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let out = experiments::run(
            "stick-slip",
            &file,
            Options {
                dt: Some(1e-3),
                duration: None,
            },
            dir.path(),
        )
        .unwrap();
        assert_eq!(out.pass, Some(true), "{set}: {}", out.figure);
    }
}

#[test]
fn steady_state_matches_the_reference_map_at_every_speed() {
    let spec = param_set("canudas1995").unwrap().model;
    let ModelSpec::LuGre(p) = spec else {
        panic!("not LuGre")
    };
    let reference = spec.host().continuous().unwrap();
    let model = LuGreParams { ..p }.build::<f64>().unwrap();
    for k in 0..=60 {
        let v = 10f64.powf(-6.0 + 0.1 * k as f64);
        for v in [v, -v] {
            let mut s = LuGreState::default();
            let tau = 1.5 / (1e5 * v.abs());
            let f = model.step(&mut s, v, 100.0 * tau);
            let expect = reference.steady_force(v);
            assert!(
                (f - expect).abs() <= 1e-9 * expect.abs(),
                "v {v}: {f} vs {expect}"
            );
        }
    }
}
