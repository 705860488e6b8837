//! `friction identify`: synthetic recovery for every model, the EMPS
//! benchmark's published IDIM-LS figures, the tribometer, and the errors.

use friction_core::{FrictionModel, LuGreParams, LuGreState, Scalar, StribeckParams};
use friction_host::identify::{self, Columns, Conditioning, Options};
use friction_host::models::ModelSpec;
use friction_host::params::ParamFile;
use std::path::{Path, PathBuf};
use std::process::Command;

fn data(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(rel)
}

fn friction(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_friction"))
        .args(args)
        .output()
        .unwrap()
}

/// Gaussian noise from a fixed-seed generator (SplitMix64 and Box-Muller).
struct Noise(u64);

impl Noise {
    fn unit(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        ((z >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    fn gauss(&mut self) -> f64 {
        let (a, b) = (self.unit(), self.unit());
        (-2.0 * a.ln()).sqrt() * (2.0 * std::f64::consts::PI * b).cos()
    }
}

/// The true motion: a sum of sines, `(x, v, a)` at time `t`.
fn motion(t: f64) -> (f64, f64, f64) {
    // (amplitude of velocity, frequency Hz)
    const PARTS: [(f64, f64); 3] = [(0.08, 0.31), (0.03, 1.13), (0.01, 2.7)];
    let (mut x, mut v, mut a) = (0.0, 0.0, 0.0);
    for (amp, f) in PARTS {
        let w = 2.0 * std::f64::consts::PI * f;
        x += -amp / w * (w * t).cos();
        v += amp * (w * t).sin();
        a += amp * w * (w * t).cos();
    }
    (x, v, a)
}

const MASS: f64 = 2.0;
const OFFSET: f64 = 0.3;
const NOISE: f64 = 0.02;
const FS: f64 = 1000.0;
const DURATION: f64 = 20.0;

/// Writes `t,x,v,f` of the motion with friction `friction(v, h)` (called at
/// 10 kHz sub-steps, velocity at each sub-step's end), sampled at 1 kHz,
/// with Gaussian force noise.
fn synthetic(dir: &Path, mut friction: impl FnMut(f64, f64) -> f64) -> PathBuf {
    let mut noise = Noise(7);
    let mut text = String::from("t,x,v,f\n");
    const SUB: usize = 10;
    let h = 1.0 / (FS * SUB as f64);
    let mut fr = friction(motion(0.0).1, 0.0);
    let n = (DURATION * FS) as usize;
    for k in 0..=n {
        let t = k as f64 / FS;
        if k > 0 {
            for j in 1..=SUB {
                fr = friction(motion(t - 1.0 / FS + j as f64 * h).1, h);
            }
        }
        let (x, v, a) = motion(t);
        let f = MASS * a + fr + OFFSET + NOISE * noise.gauss();
        text.push_str(&format!("{t},{x},{v},{f}\n"));
    }
    let path = dir.join("synthetic.csv");
    std::fs::write(&path, text).unwrap();
    path
}

fn options(input: &Path, model: &str, output: &Path) -> Options {
    Options {
        input: input.to_path_buf(),
        model: model.into(),
        output: output.to_path_buf(),
        columns: Columns::default(),
        inertia: true,
        conditioning: Conditioning::default(),
        stribeck_exponent: 2.0,
        lugre_static: Default::default(),
        validate: None,
        progress: false,
    }
}

fn close(name: &str, got: f64, want: f64, rel: f64) {
    let e = (got - want).abs() / want.abs();
    eprintln!(
        "{name}: {got:.6} against {want} ({:.3} %, tolerance {} %)",
        100.0 * e,
        100.0 * rel
    );
    assert!(
        e <= rel,
        "{name}: {got} against {want}: {:.3} % > {} %",
        100.0 * e,
        100.0 * rel
    );
}

/// The written file loads and runs through `friction simulate`.
fn loads_and_simulates(dir: &Path) -> ParamFile {
    let params = dir.join("params.toml");
    let file = ParamFile::load(&params).unwrap();
    let input = dir.join("v.csv");
    std::fs::write(&input, "t,v\n0,0\n0.001,0.01\n0.002,0.02\n0.003,-0.01\n").unwrap();
    let out = friction(&[
        "simulate",
        "--params",
        params.to_str().unwrap(),
        "--input",
        input.to_str().unwrap(),
        "--output",
        dir.join("sim.csv").to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    file
}

#[test]
fn synthetic_coulomb_viscous_is_recovered_within_1_percent() {
    let dir = tempfile::tempdir().unwrap();
    let (fc, sigma2) = (1.0, 5.0);
    let input = synthetic(dir.path(), |v, _| fc * Scalar::sign(v) + sigma2 * v);
    let out = identify::identify(&options(&input, "coulomb-viscous", dir.path())).unwrap();
    assert!(out.rejected.is_none(), "{:?}", out.rejected);
    let fit = out.fit.unwrap();
    close("fc", fit.get("fc").unwrap(), fc, 0.01);
    close("sigma2", fit.get("sigma2").unwrap(), sigma2, 0.01);
    close("mass", fit.get("mass").unwrap(), MASS, 0.01);
    close("offset", fit.get("offset").unwrap(), OFFSET, 0.01);
    let file = loads_and_simulates(dir.path());
    assert_eq!(file.model.name(), "coulomb-viscous");
    assert_eq!(file.plant.mass, fit.mass);
    assert_eq!(file.plant.offset, fit.offset);
    // the same from a measured velocity column
    let mut o = options(&input, "coulomb-viscous", dir.path());
    o.columns.velocity = Some("v".into());
    let fit = identify::identify(&o).unwrap().fit.unwrap();
    close("fc (velocity)", fit.get("fc").unwrap(), fc, 0.01);
    close(
        "sigma2 (velocity)",
        fit.get("sigma2").unwrap(),
        sigma2,
        0.01,
    );
    close("mass (velocity)", fit.get("mass").unwrap(), MASS, 0.01);
}

#[test]
fn synthetic_stribeck_is_recovered() {
    let dir = tempfile::tempdir().unwrap();
    let curve = StribeckParams {
        fc: 1.0,
        fs: 1.5,
        vs: 0.01,
        exponent: 2.0,
    };
    let sigma2 = 5.0;
    let g = |v: f64| curve.fc + (curve.fs - curve.fc) * (-(v / curve.vs).powi(2)).exp();
    let input = synthetic(dir.path(), |v, _| g(v) * Scalar::sign(v) + sigma2 * v);
    let out = identify::identify(&options(&input, "stribeck", dir.path())).unwrap();
    assert!(out.rejected.is_none(), "{:?}", out.rejected);
    let fit = out.fit.unwrap();
    close("fc", fit.get("fc").unwrap(), curve.fc, 0.01);
    close("fs", fit.get("fs").unwrap(), curve.fs, 0.01);
    close("vs", fit.get("vs").unwrap(), curve.vs, 0.01);
    close("sigma2", fit.get("sigma2").unwrap(), sigma2, 0.01);
    close("mass", fit.get("mass").unwrap(), MASS, 0.01);
    close("offset", fit.get("offset").unwrap(), OFFSET, 0.01);
    let file = loads_and_simulates(dir.path());
    assert_eq!(file.model.name(), "stribeck");
}

#[test]
fn synthetic_lugre_is_recovered() {
    let dir = tempfile::tempdir().unwrap();
    let p = LuGreParams {
        curve: StribeckParams {
            fc: 1.0,
            fs: 1.5,
            vs: 0.01,
            exponent: 2.0,
        },
        sigma0: 1e3,
        sigma1: 10.0,
        sigma2: 5.0,
        vd: None,
    };
    let m = p.build::<f64>().unwrap();
    let mut state = LuGreState::default();
    let input = synthetic(dir.path(), |v, h| m.step(&mut state, v, h));
    let out = identify::identify(&options(&input, "lugre", dir.path())).unwrap();
    assert!(out.rejected.is_none(), "{:?}", out.rejected);
    let fit = out.fit.unwrap();
    close("fc", fit.get("fc").unwrap(), p.curve.fc, 0.01);
    close("fs", fit.get("fs").unwrap(), p.curve.fs, 0.01);
    close("vs", fit.get("vs").unwrap(), p.curve.vs, 0.02);
    close("sigma2", fit.get("sigma2").unwrap(), p.sigma2, 0.01);
    close("mass", fit.get("mass").unwrap(), MASS, 0.01);
    close("offset", fit.get("offset").unwrap(), OFFSET, 0.02);
    close("sigma0", fit.get("sigma0").unwrap(), p.sigma0, 0.05);
    close("sigma1", fit.get("sigma1").unwrap(), p.sigma1, 0.1);
    let file = loads_and_simulates(dir.path());
    assert!(matches!(file.model, ModelSpec::LuGre(_)));
}

fn emps(model: &str, dir: &Path) -> Options {
    Options {
        input: data("emps/estimation.csv"),
        model: model.into(),
        output: dir.to_path_buf(),
        columns: Columns {
            position: "qm".into(),
            force: "vir".into(),
            force_gain: 35.15065188,
            ..Columns::default()
        },
        inertia: true,
        conditioning: Conditioning {
            cutoff: Some(100.0),
            ..Conditioning::default()
        },
        stribeck_exponent: 2.0,
        lugre_static: Default::default(),
        validate: Some(data("emps/validation.csv")),
        progress: false,
    }
}

/// The EMPS benchmark's IDIM-LS estimates (Janot, Gautier, Brunot 2019),
/// reproduced within 1 %; then the Stribeck map and LuGre, measured on the
/// validation run.
#[test]
fn emps_reproduces_the_published_idim_ls_estimates() {
    let dir = tempfile::tempdir().unwrap();
    let cv = identify::identify(&emps("coulomb-viscous", dir.path())).unwrap();
    assert!(cv.rejected.is_none(), "{:?}", cv.rejected);
    let fit = cv.fit.as_ref().unwrap();
    for (name, published) in [
        ("mass", 95.1089),
        ("sigma2", 203.5034),
        ("fc", 20.3935),
        ("offset", -3.1648),
    ] {
        let got = fit.get(name).unwrap();
        eprintln!(
            "EMPS {name}: {got:.4} (published {published}, {:+.3} %)",
            100.0 * (got - published) / published.abs()
        );
        close(name, got, published, 0.01);
    }
    let cv_val = cv.validation.unwrap();
    eprintln!(
        "EMPS coulomb-viscous: estimation {:.3} %, validation {:.3} % (RMS {:.3} N)",
        cv.estimation.unwrap().relative,
        cv_val.relative,
        cv_val.rms
    );
    assert!(cv_val.relative < 10.0, "{cv_val:?}");
    let file = loads_and_simulates(dir.path());
    assert_eq!(file.plant.mass, fit.mass);

    // the Stribeck map: the data want fs < fc (friction rises faster than
    // linearly at low speed), which the model cannot take: rejected at the bound
    let dir = tempfile::tempdir().unwrap();
    let st = identify::identify(&emps("stribeck", dir.path())).unwrap();
    let why = st.rejected.unwrap();
    assert!(why.contains("`fs` ends at its bound"), "{why}");
    assert!(!dir.path().join("params.toml").exists());
    eprintln!(
        "EMPS stribeck (rejected: {why}): estimation {:.3} %, validation {:.3} %",
        st.estimation.unwrap().relative,
        st.validation.unwrap().relative
    );

    // LuGre on the Coulomb-viscous steady state: pre-sliding dynamics
    let dir = tempfile::tempdir().unwrap();
    let mut o = emps("lugre", dir.path());
    o.lugre_static = identify::fit::StaticPart::CoulombViscous;
    let lu = identify::identify(&o).unwrap();
    assert!(lu.rejected.is_none(), "{:?}", lu.rejected);
    let lu_val = lu.validation.unwrap();
    let lf = lu.fit.as_ref().unwrap();
    eprintln!(
        "EMPS lugre: sigma0 {:.4e}, sigma1 {:.4e}; estimation {:.3} %, validation {:.3} % (RMS {:.3} N)",
        lf.get("sigma0").unwrap(),
        lf.get("sigma1").unwrap(),
        lu.estimation.unwrap().relative,
        lu_val.relative,
        lu_val.rms
    );
    assert!(lu_val.relative < cv_val.relative, "{lu_val:?} {cv_val:?}");
    loads_and_simulates(dir.path());
}

fn tribometer(model: &str, dir: &Path) -> Options {
    Options {
        input: data("tribometer/test_data_2.txt"),
        model: model.into(),
        output: dir.to_path_buf(),
        columns: Columns {
            time: "Time [s]".into(),
            position: "Position [mm]".into(),
            force: "Friction [uN]".into(),
            force_gain: -1.0,
            normal_force: Some("Normal [uN]".into()),
            velocity: None,
        },
        inertia: false,
        conditioning: Conditioning::default(),
        stribeck_exponent: 2.0,
        lugre_static: identify::fit::StaticPart::Coulomb,
        validate: None,
        progress: false,
    }
}

/// A friction coefficient from the tribometer run: the Coulomb map is
/// accepted but explains little (the run dwells at rest under load and
/// spends half of each stroke in pre-sliding); LuGre explains far more.
#[test]
fn tribometer_friction_coefficient() {
    let dir = tempfile::tempdir().unwrap();
    let c = identify::identify(&tribometer("coulomb", dir.path())).unwrap();
    assert!(c.rejected.is_none(), "{:?}", c.rejected);
    let mu = c.fit.as_ref().unwrap().get("fc").unwrap();
    assert!(mu > 0.0 && mu < 1.0, "{mu}");
    let file = loads_and_simulates(dir.path());
    assert!(file.plant.per_normal_force);
    assert!(c.signals.resampled.is_some());
    let dir = tempfile::tempdir().unwrap();
    let l = identify::identify(&tribometer("lugre", dir.path())).unwrap();
    let (ce, le) = (c.estimation.unwrap(), l.estimation.unwrap());
    let lf = l.fit.as_ref().unwrap();
    eprintln!(
        "tribometer: coulomb mu = {mu:.4}, relative error {:.2} %; lugre mu = {:.4}, sigma0 = {:.4} /mm, relative error {:.2} % ({:?})",
        ce.relative,
        lf.get("fc").unwrap(),
        lf.get("sigma0").unwrap(),
        le.relative,
        l.rejected
    );
    assert!(le.relative < 0.5 * ce.relative, "{le:?} {ce:?}");
}

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.to_str().unwrap().to_string()
}

fn identify_cli(input: &str, model: &str, out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "identify",
        "--input",
        input,
        "--model",
        model,
        "--output",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    friction(&args)
}

#[test]
fn bad_input_exits_2_with_a_clear_message() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let mut rows = String::from("t,x,f\n");
    for k in 0..400 {
        let t = k as f64 * 1e-3;
        rows.push_str(&format!("{t},{},{}\n", (t * 3.0).sin(), (t * 3.0).cos()));
    }
    let good = write(dir.path(), "good.csv", &rows);
    let cases: [(&str, String, &[&str], &str); 9] = [
        (
            "missing column",
            good.clone(),
            &["--force", "F"],
            "no column `F`",
        ),
        (
            "too few samples",
            write(dir.path(), "short.csv", "t,x,f\n0,0,0\n0.001,0,0\n"),
            &[],
            "2 samples; identification needs at least",
        ),
        (
            "time not increasing",
            write(
                dir.path(),
                "time.csv",
                &rows.replacen("0.002,", "0.0005,", 1),
            ),
            &[],
            "time.csv:4: column `t`",
        ),
        (
            "model not there",
            good.clone(),
            &[],
            "identify supports: coulomb,",
        ),
        (
            "cut-off above Nyquist",
            good.clone(),
            &["--cutoff", "600"],
            "Nyquist",
        ),
        // issue 18: an index wrapped and panicked
        (
            "cut-off far below the record's length",
            good.clone(),
            &["--cutoff", "1e-6"],
            "--cutoff 1e-6: too low for 400 samples",
        ),
        // issue 18: an unbounded order took tens of GB
        (
            "filter order beyond 16",
            good.clone(),
            &["--filter-order", "100000000"],
            "--filter-order",
        ),
        (
            "decimation 0",
            good.clone(),
            &["--decimate", "0"],
            "--decimate",
        ),
        // a negative gain with a negative exponent parses (it was taken
        // for an option), then meets its range
        (
            "force gain below its range",
            good.clone(),
            &["--force-gain", "-1e-13"],
            "--force-gain -1e-13: its magnitude must be within",
        ),
    ];
    for (what, input, extra, message) in cases {
        let model = if what == "model not there" {
            "gms"
        } else {
            "coulomb-viscous"
        };
        let o = identify_cli(&input, model, &out, extra);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{what}: {err}");
        assert!(err.contains(message), "{what}: {err}");
    }
}

#[test]
fn a_parameter_beyond_its_bound_exits_1() {
    // friction that helps the motion: fc < 0
    let dir = tempfile::tempdir().unwrap();
    let mut rows = String::from("t,x,f\n");
    for k in 0..4000 {
        let t = k as f64 * 1e-3;
        let (x, v, _) = motion(t);
        rows.push_str(&format!("{t},{x},{}\n", -0.5 * Scalar::sign(v) + 2.0 * v));
    }
    let input = write(dir.path(), "neg.csv", &rows);
    let out = dir.path().join("out");
    let o = identify_cli(&input, "coulomb-viscous", &out, &["--quiet"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("`fc` ends at its bound (fc > 0)"), "{err}");
    // a rejected fit's report goes to rejected/, nothing beside it
    let rejected = out.join("rejected");
    assert!(rejected.join("report.md").exists() && !out.join("params.toml").exists());
    assert!(!out.join("report.md").exists());
    let report = std::fs::read_to_string(rejected.join("report.md")).unwrap();
    assert!(report.contains("**Rejected:**"), "{report}");
    // a good file: exit 0, every output written
    let ok = identify_cli(&input, "coulomb", &out, &["--quiet", "--force-gain", "-1"]);
    assert_eq!(
        ok.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    for f in [
        "params.toml",
        "report.md",
        "fit.csv",
        "force.svg",
        "friction.svg",
    ] {
        assert!(out.join(f).exists(), "{f}");
    }
    assert!(
        !rejected.exists(),
        "an earlier rejection is stale beside an accepted fit"
    );
    // issue 18: a rejected run leaves the accepted outputs as they were
    let params = std::fs::read(out.join("params.toml")).unwrap();
    let report = std::fs::read(out.join("report.md")).unwrap();
    let again = identify_cli(&input, "coulomb-viscous", &out, &["--quiet"]);
    assert_eq!(again.status.code(), Some(1));
    assert_eq!(std::fs::read(out.join("params.toml")).unwrap(), params);
    assert_eq!(std::fs::read(out.join("report.md")).unwrap(), report);
    assert!(rejected.join("report.md").exists());
    // and input that fails outright writes nothing
    let bad = write(dir.path(), "bad.csv", "t,x,f\n0,0,0\n");
    let failed = identify_cli(&bad, "coulomb", &out, &["--quiet"]);
    assert_eq!(failed.status.code(), Some(2));
    assert_eq!(std::fs::read(out.join("params.toml")).unwrap(), params);
    assert!(rejected.join("report.md").exists());
    // a run with --validate, then one without: no stale validation.svg
    let with = identify_cli(
        &input,
        "coulomb",
        &out,
        &["--quiet", "--force-gain", "-1", "--validate", &input],
    );
    assert_eq!(
        with.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&with.stderr)
    );
    assert!(out.join("validation.svg").exists());
    let without = identify_cli(&input, "coulomb", &out, &["--quiet", "--force-gain", "-1"]);
    assert_eq!(without.status.code(), Some(0));
    assert!(!out.join("validation.svg").exists());
    assert!(!rejected.exists());
    // no staging folder left behind
    let left: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().starts_with('.'))
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

/// Forces near the top of `f64` (issue 18): the friction plot's axes are
/// guarded (it looped forever), the fit on them is rejected as not finite,
/// and a cross-validation on them is rejected rather than reported as NaN.
#[test]
fn overflowing_forces_are_rejected_not_hung() {
    let dir = tempfile::tempdir().unwrap();
    let (mut good, mut big) = (String::from("t,x,f\n"), String::from("t,x,f\n"));
    for k in 0..4000 {
        let t = k as f64 * 1e-3;
        let (x, v) = (0.01 * (3.0 * t).sin(), 0.03 * (3.0 * t).cos());
        let s = if v > 0.0 { 1.0 } else { -1.0 };
        good.push_str(&format!("{t},{x},{}\n", 2.0 * s + 0.5 * v));
        big.push_str(&format!("{t},{x},{}\n", 1e307 * s));
    }
    let good = write(dir.path(), "good.csv", &good);
    let big = write(dir.path(), "big.csv", &big);
    let out = dir.path().join("out");
    let o = identify_cli(&big, "coulomb", &out, &["--quiet"]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("has no finite estimate"), "{err}");
    let o = identify_cli(&good, "coulomb", &out, &["--quiet", "--validate", &big]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("cross-validation error"), "{err}");
    assert!(!out.join("params.toml").exists());
}
