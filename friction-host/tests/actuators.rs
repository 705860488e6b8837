//! The per-parameter law on a loaded actuator with the `[servo]` defaults:
//! BAM's MX-106 (Duclusaud, Passault et al. 2024, m4: friction that grows
//! with the transmitted torque) on a pendulum, 12-bit encoder. On an axis
//! with `gravity` the load coefficient is learnt by default
//! (`LOADED_AXIS_LOAD_MAX`). Issue 32's actuator target (0.3x the better of
//! `static` and `observer`) lies below what the frictionless plant tracks
//! here (its gravity is not fed forward): it holds only with the backward
//! difference at the file's 4096 counts, whose count-by-count flips take up
//! gravity, not with the default velocity observer nor with a finer
//! encoder (docs/guide/servo.md, "Actuator plants").

use friction_host::params::servo::LOADED_AXIS_LOAD_MAX;
use friction_host::params::ParamFile;
use friction_host::servo::{simulate, Row, ServoRun};
use rayon::prelude::*;
use std::path::Path;

/// The rms over the last half of each row, its loop required stable.
fn rms_half(path: &Path, extra: &str, rows: &[&'static str]) -> Vec<f64> {
    rms_half_edited(path, extra, ("", ""), rows)
}

/// As [`rms_half`], with the file's text `edit.0` replaced by `edit.1`.
fn rms_half_edited(
    path: &Path,
    extra: &str,
    edit: (&str, &str),
    rows: &[&'static str],
) -> Vec<f64> {
    let mut text = std::fs::read_to_string(path).unwrap();
    if !edit.0.is_empty() {
        assert!(text.contains(edit.0), "{}", edit.0);
        text = text.replace(edit.0, edit.1);
    }
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

fn mx106() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../params/actuators/mx106-pendulum.toml")
}

/// With the defaults (the velocity observer at 50 Hz on this encoder) the
/// per-parameter rows beat both fixed compensations and `rls` beats
/// `static`; the 0.3x target is out of reach without a gravity model.
#[test]
fn the_per_parameter_rows_beat_fixed_compensation_on_a_loaded_12_bit_actuator() {
    let path = mx106();
    let file = ParamFile::load(&path).unwrap();
    let cfg = file.servo.resolve(&path.display().to_string()).unwrap();
    assert_eq!(cfg.velocity_observer, 50.0);
    let rows = [
        "nofriction",
        "static",
        "observer",
        "adaptive+50",
        "adaptive-50",
        "rls",
    ];
    let rms = rms_half(&path, "", &rows);
    let better = rms[1].min(rms[2]);
    for (row, value) in rows[3..5].iter().zip(&rms[3..5]) {
        assert!(
            *value < better,
            "{row}: {:.3}x the better of static and observer",
            value / better
        );
    }
    assert!(rms[5] < rms[1], "rls {} against static {}", rms[5], rms[1]);
    // the target asks for less than a frictionless plant's error
    assert!(0.3 * better < rms[0], "{better} against {}", rms[0]);
}

/// With the backward difference (`velocity_observer = 0`) the rows meet
/// issue 32's 0.3x, and the load coefficient is what brings `adaptive-50`
/// under it.
#[test]
fn the_load_coefficient_is_learnt_by_default_on_a_loaded_actuator() {
    let path = mx106();
    let file = ParamFile::load(&path).unwrap();
    let cfg = file.servo.resolve(&path.display().to_string()).unwrap();
    assert_eq!(cfg.load_max, LOADED_AXIS_LOAD_MAX);

    let backward = "velocity_observer = 0\n";
    let rows = ["static", "observer", "adaptive+50", "adaptive-50", "rls"];
    let rms = rms_half(&path, backward, &rows);
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
    let unloaded = rms_half(&path, &format!("{backward}load_max = 0\n"), &rows[2..4]);
    assert!(
        unloaded[1] > 2.0 * rms[3],
        "adaptive-50 without the load term {} against {}",
        unloaded[1],
        rms[3]
    );
}

#[test]
fn the_drive_feeds_the_pendulums_gravity_forward() {
    // BAM's eRob80 (m6) on a pendulum; its drive knows the pendulum
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../params/actuators/erob80-pendulum.toml");
    let rows = [
        "nofriction",
        "static",
        "observer",
        "adaptive+50",
        "adaptive-50",
    ];
    let fed = rms_half(&path, "", &rows);
    let bare = rms_half_edited(
        &path,
        "",
        (
            "gravity_feedforward = [6.62, 0]",
            "gravity_feedforward = [0, 0]",
        ),
        &rows,
    );
    // the exact feed-forward cancels the gravity: a frictionless plant
    // then tracks within a few percent of the error without it
    assert!(fed[0] < 0.05 * bare[0], "{} against {}", fed[0], bare[0]);
    // the per-parameter rows, which took up gravity in their levels
    // without it, track better with it, and stay well under the better
    // of static and observer (issue 32's 0.3x is missed: 0.38x, 0.34x)
    let better = fed[1].min(fed[2]);
    for k in 3..5 {
        assert!(
            fed[k] < bare[k],
            "{}: {} against {}",
            rows[k],
            fed[k],
            bare[k]
        );
        assert!(
            fed[k] <= 0.5 * better,
            "{}: {:.3}x the better of static and observer",
            rows[k],
            fed[k] / better
        );
    }
}
