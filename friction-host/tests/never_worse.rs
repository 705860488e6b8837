//! Issue 32's "never worse" targets, on every shipped parameter file with
//! the `[servo]` defaults (`docs/guide/servo.md`, the never-worse table):
//! the supervisor guards every adaptive law, so that no adaptive row is
//! worse than no compensation, and no row built with a wrong (±50 %)
//! friction level is worse than the static feed-forward a user with the
//! same wrong level would have.

use friction_host::params::ParamFile;
use friction_host::servo::{simulate, ROWS};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// The rows each file is judged on and against, from the benchmark's one
/// table: `none`, the static feed-forwards and every adaptive row.
fn judged_rows() -> Vec<(&'static str, friction_host::servo::Row)> {
    ROWS.iter()
        .copied()
        .filter(|(name, _)| {
            *name == "none" || name.starts_with("static") || name.starts_with("adaptive")
        })
        .collect()
}

/// Every shipped parameter file: `params/*.toml` and `params/actuators/*.toml`.
fn shipped_files() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../params");
    let mut files = Vec::new();
    for dir in [root.clone(), root.join("actuators")] {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "toml") {
                files.push(path);
            }
        }
    }
    files.sort();
    files
}

/// Each judged row's name and rms over the last half.
type Rows = Vec<(&'static str, Option<f64>)>;

/// The rms over the last half of each judged row on `path`, by name
/// (`None` for a row the file's model has no form of), each loop required
/// stable.
fn rows_of(path: &Path) -> Rows {
    let file = ParamFile::load(path).unwrap();
    let name = path.display().to_string();
    let cfg = file.servo.resolve(&name).unwrap();
    judged_rows()
        .par_iter()
        .map(|&(row, spec)| {
            let rms = simulate(row, &cfg, &file.model, spec).map(|run| {
                let run = run.unwrap_or_else(|e| panic!("{name} {row}: {e}"));
                assert!(run.stable, "{name} {row}: unstable");
                run.rms_half
            });
            (row, rms)
        })
        .collect()
}

#[test]
fn no_supervised_adaptive_row_is_worse_than_none_or_its_static_feed_forward() {
    let judged: Vec<&str> = judged_rows().iter().map(|(name, _)| *name).collect();
    for row in [
        "none",
        "static",
        "static+50",
        "static-50",
        "adaptive",
        "adaptive+50",
        "adaptive-50",
        "adaptive-theta",
        "adaptive-theta+50",
        "adaptive-theta-50",
    ] {
        assert!(judged.contains(&row), "{row} not in {judged:?}");
    }
    let files = shipped_files();
    assert!(files.len() >= 17, "{files:?}");
    let results: Vec<(String, Rows)> = files
        .par_iter()
        .map(|p| {
            let stem = p.file_stem().unwrap().to_string_lossy().into_owned();
            (stem, rows_of(p))
        })
        .collect();
    let mut judged = 0;
    for (file, rms) in &results {
        let get = |row: &str| rms.iter().find(|(r, _)| *r == row).and_then(|(_, v)| *v);
        let Some(none) = get("none") else {
            panic!("{file}: no `none` row")
        };
        let mut failures = Vec::new();
        for (row, value) in rms {
            if let Some(value) = value {
                if row.starts_with("adaptive") && *value > none {
                    failures.push(format!("{row} {value:.4e} > none {none:.4e}"));
                }
            }
        }
        for law in ["adaptive", "adaptive-theta"] {
            for scale in ["+50", "-50"] {
                let row = format!("{law}{scale}");
                let own = format!("static{scale}");
                if let (Some(value), Some(own_value)) = (get(&row), get(&own)) {
                    if value > own_value {
                        failures.push(format!("{row} {value:.4e} > {own} {own_value:.4e}"));
                    }
                }
            }
        }
        if let (Some(adaptive), Some(fixed)) = (get("adaptive"), get("static")) {
            judged += 1;
            if adaptive > 1.5 * fixed {
                failures.push(format!(
                    "adaptive {adaptive:.4e} > 1.5x static {fixed:.4e} ({:.2}x)",
                    adaptive / fixed
                ));
            }
        }
        assert!(failures.is_empty(), "{file}: {}", failures.join("; "));
    }
    // every file but the one without an observer form has adaptive rows
    assert!(judged >= 17, "only {judged} files have adaptive rows");
}
