//! `friction commission` on the built-in Olsson servo: the routine's
//! parameters within the bounds and the commissioned rows against
//! the exact observer and the static feed-forward.

use friction_host::commission::commission;
use friction_host::params::{param_set, ParamFile};

#[test]
fn commissions_the_olsson_servo_and_compensates_with_the_result() {
    let file = param_set("olsson1998-servo").unwrap();
    let run = commission(&file, "params/olsson1998-servo.toml", false).unwrap();
    println!("{}", run.table());
    for (name, truth, value) in run.parameters() {
        let bound = match name {
            "fc" | "fs" | "sigma2" => 0.05,
            "sigma0" => 0.3,
            _ => continue,
        };
        let error = (value - truth) / truth;
        assert!(error.abs() <= bound, "{name}: {error:+.3}");
    }
    assert!(*run.t.last().unwrap() <= 30.0);
    let widest = run.position.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(widest <= run.settings.travel);
    let rms = |name: &str| run.run(name).unwrap().rms_half;
    // the target: the commissioned observer within 2x the exact one
    assert!(rms("commissioned") <= 2.0 * rms("observer"));
    assert!(rms("commissioned-adaptive") <= 0.3 * rms("static"));
}

/// Commissions a shipped actuator file; returns the run.
fn actuator(name: &str) -> friction_host::commission::CommissionRun {
    actuator_with(name, "")
}

/// Commissions a shipped actuator file with `extra` keys at the top of its
/// `[servo]` table; returns the run.
fn actuator_with(name: &str, extra: &str) -> friction_host::commission::CommissionRun {
    let path = format!(
        "{}/../params/actuators/{name}.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("[servo]\n"));
    let text = text.replace("[servo]\n", &format!("[servo]\n{extra}"));
    let file = ParamFile::parse(&text, &path).unwrap();
    let run = commission(&file, &path, false).unwrap();
    println!("{name}:\n{}", run.table());
    run
}

/// The actuator target, `commissioned-adaptive` at most 0.3x
/// `static`, on every actuator file: EMPS (with its measured direction
/// asymmetry), the eRob80 pendulum and the MX-106 pendulum (12-bit encoder,
/// gravity five times the friction: its load coefficient identified). On
/// the MX-106 it holds with the backward difference (`velocity_observer =
/// 0`), whose count-by-count flips take up gravity; with the default
/// velocity observer the target lies below the frictionless plant's error
/// (the next test).
#[test]
fn commissioned_adaptation_beats_static_on_the_actuator_files() {
    for name in ["emps", "erob80-pendulum", "mx106-pendulum"] {
        let extra = if name == "mx106-pendulum" {
            "velocity_observer = 0\n"
        } else {
            ""
        };
        let run = actuator_with(name, extra);
        let rms = |row: &str| run.run(row).unwrap().rms_half;
        assert!(
            rms("commissioned-adaptive") <= 0.3 * rms("static"),
            "{name}: {:.3}x static",
            rms("commissioned-adaptive") / rms("static")
        );
        if name == "mx106-pendulum" {
            assert!(run.result.identified.load, "{:?}", run.result);
            // commissioned.toml says so, and still reads as a LuGre file
            let text = run.toml(name);
            assert!(text.contains("# load coefficient"), "{text}");
            ParamFile::parse(&text, name).unwrap();
        }
    }
}

/// The MX-106 pendulum with the defaults (the velocity observer at 50 Hz
/// on its 4096 counts): the load coefficient identified, and the
/// commissioned rows beat `static` and the nominal observer, though not by
/// the 0.3x that would need a better error than the frictionless plant's
/// (`tests/actuators.rs`).
#[test]
fn commissions_the_mx106_pendulum_with_the_default_velocity_observer() {
    let run = actuator("mx106-pendulum");
    assert!(run.result.identified.load, "{:?}", run.result);
    // the run says which velocity it took
    let note = run.note.as_deref().unwrap();
    assert!(note.contains("observer at 50 Hz"), "{note}");
    let rms = |row: &str| run.run(row).unwrap().rms_half;
    let better = rms("static").min(rms("observer"));
    assert!(
        rms("commissioned") < better && rms("commissioned-adaptive") < rms("commissioned"),
        "{}",
        run.table()
    );
}

/// EMPS's Coulomb and viscous levels (the means of its two directions)
/// within 5 % of the file's published figures.
#[test]
fn commissions_the_emps_levels() {
    let run = actuator("emps");
    for (name, truth, value) in run.parameters() {
        if matches!(name, "fc" | "sigma2") {
            let error = (value - truth) / truth;
            assert!(error.abs() <= 0.05, "{name}: {error:+.3}");
        }
    }
}

/// A static map's file (no observer form): the benchmark runs without the
/// `observer` row, and the per-direction levels and slopes are the map's.
#[test]
fn commissions_a_static_map_without_an_observer_row() {
    let file = param_set("robot-joint-asymmetric").unwrap();
    let run = commission(&file, "params/robot-joint-asymmetric.toml", false).unwrap();
    println!("{}", run.table());
    assert!(run.run("observer").is_none() && run.table().contains("No `observer` row"));
    let r = &run.result;
    let within = |value: f64, truth: f64| ((value - truth) / truth).abs() <= 0.05;
    assert!(within(r.fc[0], 1.2) && within(r.fc[1], 0.9), "{:?}", r.fc);
    assert!(
        within(r.sigma2[0], 0.5) && within(r.sigma2[1], 0.35),
        "{:?}",
        r.sigma2
    );
    let rms = |name: &str| run.run(name).unwrap().rms_half;
    assert!(rms("commissioned") <= rms("static"));
}

/// The MX-106 pendulum with a 16-bit encoder: its symmetric curve fits the
/// plateaus' half-differences well, but its Coulomb level (an
/// extrapolation beyond the fastest plateau) came out small, and against
/// a tenth of `fs` the residual was just over the limit: the fit fell back
/// to the directions' own means, which carry the gravity, and failed
/// (`PoorFit`). The residual is now relative to the friction at the
/// plateaus too.
#[test]
fn commissions_the_mx106_pendulum_with_a_16_bit_encoder() {
    let path = format!(
        "{}/../params/actuators/mx106-pendulum.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("encoder_counts = 4096"));
    let text = text.replace("encoder_counts = 4096", "encoder_counts = 65536");
    let file = ParamFile::parse(&text, &path).unwrap();
    let run = commission(&file, &path, false).unwrap();
    println!("{}", run.table());
    let r = &run.result;
    assert!(r.identified.load && r.residual <= 0.02, "{r:?}");
    // the symmetric curve: the same levels both ways
    assert_eq!(r.fc[0], r.fc[1], "{r:?}");
    let rms = |row: &str| run.run(row).unwrap().rms_half;
    assert!(rms("commissioned-adaptive") <= 0.35 * rms("static"));
}
