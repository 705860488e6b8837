//! Every experiment on every shipped parameter file (issue 18, item 2): a
//! run either passes, reports a phenomenon the model is not expected to
//! show, or is refused up front with its reason (listed below); none ends
//! in another error, and no step cap stops a run before it settles.
#![allow(clippy::unwrap_used, clippy::panic, clippy::indexing_slicing)]

use friction_host::experiments::{self, Options, Refusal, NAMES};
use friction_host::params::ParamFile;
use std::path::Path;

/// Runs refused up front (typed [`Refusal`]), with a word of the reason,
/// besides every experiment but `stribeck` on a static map ([`refusal`]).
const REFUSED: &[(&str, &str, &str)] = &[
    ("astrom2008-drift", "stick-slip", "needs a spring rig"),
    ("astrom2008-drift-ep", "stick-slip", "needs a spring rig"),
    // the creep before break-away is unstable (GmsSpec::creep_growth): the
    // elements slip one by one, and once 3 of the 4 slip their falling
    // Stribeck curve (slope up to 0.6 x 4.3 N m s/rad) outweighs the
    // damping of the one still sticking (0.05): measured peaks 0.3032,
    // 0.3027, 0.2975, 0.3112, 0.2835, 0.2828 N m at 0.026 to 1.3 N m/s, the
    // same at --dt 1e-5, and re-shaped sets pass or fail with +-5 % on one k
    ("gms-servo", "breakaway", "the creep is unstable"),
];

/// Why `name` is refused on `set` (`file`), if it is: a static map (no
/// internal state, read from the model itself) takes only the steady
/// curve; the other refusals are listed in [`REFUSED`].
fn refusal(set: &str, name: &str, file: &ParamFile) -> Option<&'static str> {
    if name != "stribeck" && !file.model.host().has_state() {
        return Some("needs a model with internal state");
    }
    REFUSED
        .iter()
        .find(|(s, n, _)| *s == set && *n == name)
        .map(|(_, _, reason)| *reason)
}

#[test]
fn every_experiment_on_every_shipped_file_passes_or_is_refused_up_front() {
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
            let out_dir = dir.path().join(format!("{set}-{name}"));
            let refused = refusal(&set, name, &file);
            let out = match (
                experiments::run(name, &file, Options::default(), &out_dir),
                refused,
            ) {
                (Err(e), Some(reason)) => {
                    let refusal = e.downcast_ref::<Refusal>();
                    assert!(
                        refusal.is_some_and(|r| r.0.contains(reason)),
                        "{set} {name}: {e:#}"
                    );
                    assert!(
                        !out_dir.exists(),
                        "{set} {name}: a refusal wrote {out_dir:?}"
                    );
                    runs += 1;
                    continue;
                }
                (Ok(_), Some(_)) => panic!("{set} {name}: runs, remove it from REFUSED"),
                (out, None) => out.unwrap_or_else(|e| panic!("{set} {name}: {e:#}")),
            };
            runs += 1;
            if out.pass == Some(false) {
                failures.push((set.clone(), name.to_string(), out.figure.clone()));
            }
        }
    }
    assert_eq!(runs, files.len() * NAMES.len());
    assert!(failures.is_empty(), "failures: {failures:#?}");
}

/// A rig whose explicit step cannot resolve the mass on the contact (a
/// mass of 1e-20 on gms-typical, stiffnesses of 1e15, canudas1995's
/// damping on a mass of 0.1, a stick-slip spring of 1e9) is refused up
/// front for every rig experiment, naming the step's limit, and leaves no
/// folder (nor the parents it made); so is an option the experiment does
/// not take.
#[test]
fn an_unresolved_rig_is_refused_and_leaves_no_folder() {
    let params = Path::new(env!("CARGO_MANIFEST_DIR")).join("../params");
    let text = std::fs::read_to_string(params.join("gms-typical.toml")).unwrap();
    let tiny = text.replace("mass = 1.0 ", "mass = 1e-20 ");
    assert_ne!(tiny, text);
    let stiff: String = text
        .lines()
        .map(|l| if l.starts_with("k = ") { "k = 1e15" } else { l })
        .collect::<Vec<_>>()
        .join("\n");
    let canudas_text = std::fs::read_to_string(params.join("canudas1995.toml")).unwrap();
    let damped = canudas_text.replace("mass = 1.0 ", "mass = 0.1 ");
    let spring = canudas_text.replace("stiffness = 2.0 ", "stiffness = 1e9 ");
    assert!(damped != canudas_text && spring != canudas_text);
    let dir = tempfile::tempdir().unwrap();
    let all: &[&str] = &["breakaway", "stick-slip", "drift", "presliding"];
    let cases = [
        ("tiny", tiny, all, "c / m x h"),
        ("stiff", stiff, all, "omega h"),
        ("damped", damped, &all[1..], "c / m x h = 3.166"),
        ("spring", spring, &all[1..2], "omega h = 31.62"),
    ];
    for (label, text, names, needle) in cases {
        let file = ParamFile::parse(&text, label).unwrap();
        for name in names {
            let out = dir.path().join(format!("{label}-{name}")).join("nested");
            let e = experiments::run(name, &file, Options::default(), &out).unwrap_err();
            let refusal = e
                .downcast_ref::<Refusal>()
                .unwrap_or_else(|| panic!("{e:#}"));
            assert!(refusal.0.contains(needle), "{label} {name}: {e:#}");
            assert!(!out.parent().unwrap().exists(), "{label} {name}");
        }
    }
    let canudas = ParamFile::load(&params.join("canudas1995.toml")).unwrap();
    let out = dir.path().join("duration");
    let opts = Options {
        duration: Some(5.0),
        ..Options::default()
    };
    let e = experiments::run("breakaway", &canudas, opts, &out).unwrap_err();
    assert!(
        format!("{e:#}").contains("--duration does not apply"),
        "{e:#}"
    );
    assert!(!out.exists());
    // a run that fails after its folder was made removes it again, with
    // the parents it made: 1e-9 s steps on a 100 s ramp
    let out = dir.path().join("samples").join("nested");
    let opts = Options {
        dt: Some(1e-9),
        ..Options::default()
    };
    let e = format!(
        "{:#}",
        experiments::run("breakaway", &canudas, opts, &out).unwrap_err()
    );
    assert!(
        e.contains("lengthen --dt") && !e.contains("--duration"),
        "{e}"
    );
    assert!(!out.parent().unwrap().exists());
}

/// Stick-slip over 2,000 s (314 cycles) on canudas1995 (issue 18): the
/// discrete step's period is about 1 ms longer than the reference's, so the
/// phase drifts by hundreds of ms; every cycle still agrees within 1 % of
/// the period, which is what is judged, and the drift is reported.
#[test]
fn a_long_stick_slip_run_agrees_cycle_by_cycle() {
    let params = Path::new(env!("CARGO_MANIFEST_DIR")).join("../params");
    let file = ParamFile::load(&params.join("canudas1995.toml")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let opts = Options {
        duration: Some(2000.0),
        ..Options::default()
    };
    let out = experiments::run("stick-slip", &file, opts, dir.path()).unwrap();
    assert_eq!(out.pass, Some(true), "{}", out.figure);
    assert!(out.figure.contains("phase drift"), "{}", out.figure);
    let onsets = out
        .summary
        .iter()
        .find(|l| l.starts_with("slip onsets"))
        .unwrap();
    assert!(
        onsets.contains("(314 in all)") && onsets.len() < 200,
        "{onsets}"
    );
    // astrom2008-stickslip over 2,000 s: the core's 424th slip would come
    // after the end (1.2 s of drift), one slip fewer is not a FAIL
    let file = ParamFile::load(&params.join("astrom2008-stickslip.toml")).unwrap();
    let out = experiments::run("stick-slip", &file, opts, &dir.path().join("a")).unwrap();
    assert_eq!(out.pass, Some(true), "{}", out.figure);
    assert!(
        out.figure
            .contains("423 slips (reference 424; the last slip"),
        "{}",
        out.figure
    );
}
