//! Every experiment on every shipped parameter file (issue 18, item 2): a
//! run either passes, reports a phenomenon the model is not expected to
//! show, or is one of the known shortfalls listed below with its reason;
//! none ends in an error, and no step cap stops a run before it settles.
#![allow(clippy::unwrap_used, clippy::panic, clippy::indexing_slicing)]

use friction_host::experiments::{self, Options, NAMES};
use friction_host::params::ParamFile;
use std::path::Path;

/// Runs that FAIL today, each for a reason of the rig set-up or the
/// parameter set, not of a step cap (the Stribeck experiment used to stop
/// at 2e6 steps of 1 ms before Olsson's set settled at 1e-6 m/s: it now
/// steps by a fraction of the pre-sliding scale and passes everywhere).
const KNOWN: &[(&str, &str, &str)] = &[
    // measured: loop areas 7.6e-5, 2.9e-4, 2.1e-4 N m/s against a 0.1 %
    // threshold; the core agrees with the reference (0.006 % of Fs)
    (
        "astrom2008-drift",
        "frictional-lag",
        "stiff set (sigma0 = 3.9e4): lag below the threshold at v0 = 1 mm/s",
    ),
    (
        "astrom2008-drift-ep",
        "frictional-lag",
        "as astrom2008-drift",
    ),
    (
        "astrom2008-stickslip",
        "frictional-lag",
        "lag below the threshold at v0 = 1 mm/s",
    ),
    (
        "gms-servo",
        "frictional-lag",
        "lag below the threshold at v0 = 1 mm/s",
    ),
    // measured: 0 slips, and 0 in the reference: the drift rig has no spring
    (
        "astrom2008-drift",
        "stick-slip",
        "its [rig] is the drift rig: no slip, as in the reference",
    ),
    ("astrom2008-drift-ep", "stick-slip", "as astrom2008-drift"),
    // measured: residual x 1.54 m at u = 0 (the default force ramp exceeds
    // this set's break-away force)
    (
        "gms-servo",
        "presliding",
        "the default force ramp leaves pre-sliding for this set",
    ),
    // measured: 0.2817 .. 0.2950 N rising with the rate; Olsson: 0.2800 ..
    // 0.2884 N (vs = 0.01 rad/s: the mass breaks away near Fc)
    (
        "gms-servo",
        "breakaway",
        "break-away force rises with the rate for this set",
    ),
    (
        "olsson1998-servo",
        "breakaway",
        "break-away force rises with the rate for this set",
    ),
    ("olsson1998-drive", "breakaway", "as olsson1998-servo"),
];

#[test]
fn every_experiment_on_every_shipped_file_passes_or_is_a_known_shortfall() {
    let params = Path::new(env!("CARGO_MANIFEST_DIR")).join("../params");
    let dir = tempfile::tempdir().unwrap();
    let mut files: Vec<_> = std::fs::read_dir(&params)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    assert!(files.len() >= 14, "{files:?}");
    let mut failures = Vec::new();
    let mut runs = 0;
    for path in &files {
        let set = path.file_stem().unwrap().to_str().unwrap().to_string();
        let file = ParamFile::load(path).unwrap();
        for name in NAMES {
            let out = experiments::run(
                name,
                &file,
                Options::default(),
                &dir.path().join(format!("{set}-{name}")),
            )
            .unwrap_or_else(|e| panic!("{set} {name}: {e:#}"));
            runs += 1;
            if out.pass == Some(false) {
                failures.push((set.clone(), name.to_string(), out.figure.clone()));
            }
        }
    }
    assert_eq!(runs, files.len() * NAMES.len());
    let unexpected: Vec<_> = failures
        .iter()
        .filter(|(set, name, _)| !KNOWN.iter().any(|(s, n, _)| s == set && n == name))
        .collect();
    assert!(unexpected.is_empty(), "new failures: {unexpected:#?}");
    let fixed: Vec<_> = KNOWN
        .iter()
        .filter(|(s, n, _)| !failures.iter().any(|(set, name, _)| set == s && name == n))
        .collect();
    assert!(
        fixed.is_empty(),
        "no longer failing, remove from KNOWN: {fixed:#?}"
    );
}
