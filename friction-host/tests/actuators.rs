//! The per-parameter law on a loaded actuator with the `[servo]` defaults:
//! BAM's MX-106 (Duclusaud, Passault et al. 2024, m4: friction that grows
//! with the transmitted torque) on a pendulum, 12-bit encoder. On an axis
//! with `gravity` the load coefficient is learnt by default
//! (`LOADED_AXIS_LOAD_MAX`); without it the wrong-Stribeck row `adaptive-50`
//! missed issue 32's actuator target (0.56x).

use friction_host::params::servo::LOADED_AXIS_LOAD_MAX;
use friction_host::params::ParamFile;
use friction_host::servo::{simulate, Row, ServoRun};
use rayon::prelude::*;
use std::path::Path;

/// The rms over the last half of each row, its loop required stable.
fn rms_half(path: &Path, extra: &str, rows: &[&'static str]) -> Vec<f64> {
    let text = std::fs::read_to_string(path).unwrap();
    // BAM's file is named relative to the parameter file
    let text = text.replace(
        "\"bam/",
        &format!("\"{}/bam/", path.parent().unwrap().display()),
    );
    let text = text.replace("[servo]\n", &format!("[servo]\n{extra}"));
    let file = ParamFile::parse(&text, &path.display().to_string()).unwrap();
    let cfg = file.servo.resolve(&path.display().to_string()).unwrap();
    rows.par_iter()
        .map(|&row| {
            let r: ServoRun = simulate(row, &cfg, &file.model, Row::named(row).unwrap())
                .unwrap()
                .unwrap();
            assert!(r.stable, "{row}");
            r.rms_half
        })
        .collect()
}

#[test]
fn the_load_coefficient_is_learnt_by_default_on_a_loaded_actuator() {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../params/actuators/mx106-pendulum.toml");
    let file = ParamFile::load(&path).unwrap();
    let cfg = file.servo.resolve(&path.display().to_string()).unwrap();
    assert_eq!(cfg.load_max, LOADED_AXIS_LOAD_MAX);

    let rows = ["static", "observer", "adaptive+50", "adaptive-50", "rls"];
    let rms = rms_half(&path, "", &rows);
    let better = rms[0].min(rms[1]);
    for (row, value) in rows[2..4].iter().zip(&rms[2..4]) {
        assert!(
            *value <= 0.3 * better,
            "{row}: {:.3}x the better of static and observer",
            value / better
        );
    }
    assert!(rms[4] < rms[0], "rls {} against static {}", rms[4], rms[0]);

    // the same rows without the load term: the load coefficient is what
    // brings adaptive-50 under the target
    let unloaded = rms_half(&path, "load_max = 0\n", &rows[2..4]);
    assert!(
        unloaded[1] > 2.0 * rms[3],
        "adaptive-50 without the load term {} against {}",
        unloaded[1],
        rms[3]
    );
}
