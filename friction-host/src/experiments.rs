//! The classic friction experiments of the model sheet. Each writes
//! `trace.csv` and a plot into its folder and returns an [`Outcome`] with a
//! short summary and, where the sheet states what the model must show, a
//! pass/fail judgement with the figure that decided it.

use crate::io::write_columns;
use crate::models::{ScalarKind, Stepper};
use crate::params::{ModelSpec, ParamFile};
use crate::plot::{line_plot, zip, Axis, Series};
use crate::signals::Signal;
use crate::sim::{drive_core, drive_reference, rig_core, rig_reference, rms_diff, Rig, Trace};
use anyhow::{bail, Result};
use std::path::{Path, PathBuf};

/// The experiment names, in the order `validate` runs them.
pub const NAMES: &[&str] = &[
    "stribeck",
    "presliding",
    "frictional-lag",
    "breakaway",
    "stick-slip",
    "drift",
];

/// Optional overrides of an experiment's sample period and duration.
#[derive(Clone, Copy, Debug, Default)]
pub struct Options {
    /// Sample period of the core's step (s).
    pub dt: Option<f64>,
    /// Duration (s), for the time-based experiments.
    pub duration: Option<f64>,
}

/// What an experiment found.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// Experiment name.
    pub name: &'static str,
    /// The phenomenon it shows.
    pub phenomenon: &'static str,
    /// `Some(true)` when the model shows what the sheet expects of it.
    pub pass: Option<bool>,
    /// The figure that decided `pass`, in words.
    pub figure: String,
    /// Further lines of summary.
    pub summary: Vec<String>,
    /// The plot file.
    pub plot: PathBuf,
}

impl Outcome {
    /// `pass`, `FAIL`, or `-` when not judged.
    pub fn verdict(&self) -> &'static str {
        match self.pass {
            Some(true) => "pass",
            Some(false) => "FAIL",
            None => "-",
        }
    }
}

/// Runs experiment `name` for the model of `file`, writing into `dir`.
pub fn run(name: &str, file: &ParamFile, opts: Options, dir: &Path) -> Result<Outcome> {
    std::fs::create_dir_all(dir)?;
    if name != "stribeck" && !file.model.has_state() {
        bail!(
            "experiment `{name}` does not apply to the static map `{}`: it needs a model with internal state",
            file.model.name()
        );
    }
    let mut out = match name {
        "stribeck" => stribeck(file, opts, dir),
        "presliding" => presliding(file, opts, dir),
        "frictional-lag" => frictional_lag(file, opts, dir),
        "breakaway" => breakaway(file, opts, dir),
        "stick-slip" => stick_slip(file, opts, dir),
        "drift" => drift(file, opts, dir),
        other => bail!(
            "unknown experiment `{other}` (expected one of {})",
            NAMES.join(", ")
        ),
    }?;
    // Each experiment reports whether the phenomenon showed; it passes when
    // that is what the model is known to do.
    let expected = expectation(&file.model, name);
    if let (Some(expected), Some(shown)) = (expected, out.pass) {
        out.summary.push(format!(
            "{} is {} for `{}`; here it {}",
            out.phenomenon,
            if expected { "expected" } else { "not expected" },
            file.model.name(),
            if shown { "shows" } else { "does not show" }
        ));
    }
    out.pass = expected.zip(out.pass).map(|(e, shown)| e == shown);
    Ok(out)
}

/// Whether `model` is known to show the phenomenon of `experiment`
/// (`None`: not judged yet).
pub fn expectation(model: &ModelSpec, experiment: &str) -> Option<bool> {
    match (model, experiment) {
        (ModelSpec::LuGre(_), _) => Some(true),
        // Dahl: hysteresis and a Coulomb steady state; rate independent, no stiction
        (ModelSpec::Dahl(_), "stribeck" | "presliding") => Some(true),
        (ModelSpec::Dahl(_), "frictional-lag" | "breakaway") => Some(false),
        (ModelSpec::Dahl(_), _) => None,
        (_, "stribeck") => Some(true),
        _ => None,
    }
}

fn core(spec: &ModelSpec) -> Result<Box<dyn Stepper>> {
    Ok(spec.stepper(ScalarKind::F64)?)
}

fn mass(file: &ParamFile) -> f64 {
    file.rig.mass.unwrap_or(1.0)
}

fn trace_csv(dir: &Path, tr: &Trace, reference: Option<&Trace>) -> Result<()> {
    let mut headers = vec!["t", "x", "v", "f", "u"];
    let mut cols: Vec<&[f64]> = vec![&tr.t, &tr.x, &tr.v, &tr.f, &tr.u];
    if let Some(r) = reference {
        headers.extend(["x_ref", "v_ref", "f_ref"]);
        cols.extend([&r.x[..], &r.v[..], &r.f[..]]);
    }
    write_columns(&dir.join("trace.csv"), &headers, &cols)
}

/// Runs the rig with the core and with the reference solver on the same
/// sample times and writes both into `trace.csv`.
fn rig_pair(
    file: &ParamFile,
    rig: &Rig,
    h: f64,
    duration: f64,
    dir: &Path,
) -> Result<(Trace, Trace)> {
    let tr = rig_core(core(&file.model)?.as_mut(), rig, h, duration);
    let rf = rig_reference(file.model.continuous().as_ref(), rig, &tr.t)?;
    trace_csv(dir, &tr, Some(&rf))?;
    Ok((tr, rf))
}

/// Plots one quantity of the core's trajectory against the reference's.
fn plot_pair(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    core: Vec<(f64, f64)>,
    reference: Vec<(f64, f64)>,
) -> Result<()> {
    let series = [
        Series {
            label: "core",
            points: core,
        },
        Series {
            label: "reference",
            points: reference,
        },
    ];
    line_plot(path, title, (x_label, Axis::Linear), y_label, &series)
}

/// Steady friction at constant velocities, log-spaced from 1e-6 to 1 m/s, both signs.
fn stribeck(file: &ParamFile, opts: Options, dir: &Path) -> Result<Outcome> {
    let h = opts.dt.unwrap_or(1e-3);
    let fs = file.model.max_static_force();
    let reference = file.model.continuous();
    let speeds: Vec<f64> = (0..=60)
        .map(|i| 10f64.powf(-6.0 + i as f64 * 0.1))
        .collect();
    let (mut vs, mut fcore, mut fss) = (Vec::new(), Vec::new(), Vec::new());
    for sign in [1.0, -1.0] {
        for &s in &speeds {
            let v = sign * s;
            let mut m = core(&file.model)?;
            // step until the force settles (geometric convergence) or 2e6 steps
            let mut f = m.step(v, h);
            for _ in 0..2_000_000 {
                let next = m.step(v, h);
                let settled = (next - f).abs() <= 1e-14 * fs;
                f = next;
                if settled {
                    break;
                }
            }
            vs.push(v);
            fcore.push(f);
            fss.push(reference.steady_force(v));
        }
    }
    write_columns(
        &dir.join("trace.csv"),
        &["v", "f", "f_steady"],
        &[&vs, &fcore, &fss],
    )?;
    let worst = fcore
        .iter()
        .zip(&fss)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
        / fs;
    let n = speeds.len();
    let plot = dir.join("stribeck.svg");
    line_plot(
        &plot,
        &format!("Stribeck curve ({}): steady friction", file.model.name()),
        ("|v| (m/s)", Axis::Log),
        "|F| (N)",
        &[
            Series {
                label: "core, v > 0",
                points: zip(&speeds, &fcore[..n]),
            },
            Series {
                label: "core, v < 0",
                points: speeds
                    .iter()
                    .zip(&fcore[n..])
                    .map(|(&s, &f)| (s, -f))
                    .collect(),
            },
            Series {
                label: "steady-state map",
                points: zip(&speeds, &fss[..n]),
            },
        ],
    )?;
    Ok(Outcome {
        name: "stribeck",
        phenomenon: "Stribeck curve",
        pass: Some(worst <= 1e-6),
        figure: format!(
            "max |F - steady-state map| = {:.2e} Fs over ±[1e-6, 1] m/s (bound 1e-6 Fs)",
            worst
        ),
        summary: vec![format!(
            "F(1e-6) = {:.4} N, F(1e-3) = {:.4} N, F(1) = {:.4} N",
            fcore[0],
            fcore[30],
            fcore[n - 1]
        )],
        plot,
    })
}

/// Applied-force ramps below break-away: 0 -> 0.95 Fs -> -0.95 Fs -> 0.95 Fs.
fn presliding(file: &ParamFile, opts: Options, dir: &Path) -> Result<Outcome> {
    let h = opts.dt.unwrap_or(1e-3);
    let fs = file.model.max_static_force();
    let peak = 0.95 * fs;
    let rate = file.rig.force_rate.unwrap_or(0.095 * fs);
    let leg = peak / rate;
    let duration = opts.duration.unwrap_or(5.0 * leg);
    let u = move |t: f64, _x: f64| {
        let s = t / leg; // in ramp lengths
        if s <= 1.0 {
            peak * s
        } else if s <= 3.0 {
            peak * (2.0 - s)
        } else {
            peak * (s - 4.0).min(1.0)
        }
    };
    let rig = Rig {
        mass: mass(file),
        force: &u,
    };
    let (tr, rf) = rig_pair(file, &rig, h, duration, dir)?;
    let x_max = tr.x.iter().fold(0.0f64, |a, &b| a.max(b.abs()));
    // residual displacement where u comes back to 0 on the way down (t = 2 leg)
    let k0 = ((2.0 * leg) / h).round() as usize;
    let residual = tr.x.get(k0).copied().unwrap_or(0.0);
    let z_scale = file.model.presliding_scale();
    let err = rms_diff(&tr.x, &rf.x);
    let plot = dir.join("presliding.svg");
    plot_pair(
        &plot,
        "Pre-sliding hysteresis: friction versus displacement",
        "x (m)",
        "F (N)",
        zip(&tr.x, &tr.f),
        zip(&rf.x, &rf.f),
    )?;
    let hysteretic = residual.abs() > 0.01 * z_scale;
    let bounded = x_max < 10.0 * z_scale;
    Ok(Outcome {
        name: "presliding",
        phenomenon: "pre-sliding hysteresis",
        pass: Some(hysteretic && bounded),
        figure: format!(
            "residual x at u = 0: {:.3e} m ({:.1} % of the pre-sliding scale d); max |x| = {:.3e} m ({:.2} d, bound 10 d); d = {:.3e} m",
            residual,
            100.0 * residual.abs() / z_scale,
            x_max,
            x_max / z_scale,
            z_scale
        ),
        summary: vec![format!("rms |x_core - x_ref| = {:.3e} m ({:.3} % of max |x|)", err, 100.0 * err / x_max)],
        plot,
    })
}

/// `v = v0 (cos(w t) + 1.5)` with `w = 1, 10, 25 rad/s`: the F-v loop widens with `w`.
fn frictional_lag(file: &ParamFile, opts: Options, dir: &Path) -> Result<Outcome> {
    let h = opts.dt.unwrap_or(1e-4);
    let reference = file.model.continuous();
    let mut series = Vec::new();
    let mut areas = Vec::new();
    let (mut cw, mut ct, mut cv, mut cf, mut cr) = (vec![], vec![], vec![], vec![], vec![]);
    let mut worst = 0.0f64;
    for w in [1.0, 10.0, 25.0] {
        let s = Signal::lag(1e-3, w, 3.0);
        let t = s.times(h);
        let v: Vec<f64> = t.iter().map(|&ti| s.v(ti)).collect();
        let f = drive_core(core(&file.model)?.as_mut(), &t, &v);
        let fr = drive_reference(reference.as_ref(), &s, &t)?;
        worst = worst.max(rms_diff(&f, &fr) / file.model.max_static_force());
        // loop area over the last period: closed integral of F dv
        let start = t.len() * 2 / 3;
        let area: f64 = (start + 1..t.len())
            .map(|k| 0.5 * (f[k] + f[k - 1]) * (v[k] - v[k - 1]))
            .sum();
        areas.push(area.abs());
        series.push((w, zip(&v[start..], &f[start..])));
        cw.extend(std::iter::repeat_n(w, t.len()));
        ct.extend(&t);
        cv.extend(&v);
        cf.extend(&f);
        cr.extend(&fr);
    }
    write_columns(
        &dir.join("trace.csv"),
        &["w", "t", "v", "f", "f_ref"],
        &[&cw, &ct, &cv, &cf, &cr],
    )?;
    let labels = ["w = 1 rad/s", "w = 10 rad/s", "w = 25 rad/s"];
    let plot = dir.join("frictional-lag.svg");
    line_plot(
        &plot,
        "Frictional lag: friction versus velocity, v = 1e-3 (cos wt + 1.5)",
        ("v (m/s)", Axis::Linear),
        "F (N)",
        &series
            .into_iter()
            .zip(labels)
            .map(|((_, p), label)| Series { label, points: p })
            .collect::<Vec<_>>(),
    )?;
    // widens: the area grows with w, and the widest loop is visible (more
    // than 0.1 % of its bounding box, Fs x the velocity range 2 v0)
    let box_area = file.model.max_static_force() * 2e-3;
    let widens = areas.windows(2).all(|a| a[1] > a[0]) && areas[2] > 1e-3 * box_area;
    Ok(Outcome {
        name: "frictional-lag",
        phenomenon: "frictional lag",
        pass: Some(widens),
        figure: format!(
            "loop area |∮F dv| = {:.3e}, {:.3e}, {:.3e} N m/s for w = 1, 10, 25 (lag shows when it grows and exceeds 0.1 % of Fs x 2 v0)",
            areas[0], areas[1], areas[2]
        ),
        summary: vec![format!(
            "worst rms force error against the reference: {:.4} % of Fs",
            100.0 * worst
        )],
        plot,
    })
}

/// Mass at rest, applied force ramping at 1 to 50 N/s: the friction peak
/// (break-away force) against the rate.
fn breakaway(file: &ParamFile, opts: Options, dir: &Path) -> Result<Outcome> {
    let h = opts.dt.unwrap_or(1e-4);
    let fs = file.model.max_static_force();
    let rates = [1.0, 2.0, 5.0, 10.0, 20.0, 50.0];
    let (mut peaks, mut peaks_ref) = (Vec::new(), Vec::new());
    let (mut cr, mut ct, mut cx, mut cv, mut cf, mut cu) =
        (vec![], vec![], vec![], vec![], vec![], vec![]);
    for &rate in &rates {
        let u = move |t: f64, _x: f64| rate * t;
        let rig = Rig {
            mass: mass(file),
            force: &u,
        };
        let duration = 2.0 * fs / rate;
        let tr = rig_core(core(&file.model)?.as_mut(), &rig, h, duration);
        let rf = rig_reference(file.model.continuous().as_ref(), &rig, &tr.t)?;
        // break-away: the peak of the friction force less its viscous part
        // (which only grows once the mass slides)
        let sigma2 = file.model.sigma2();
        let peak = |tr: &Trace| {
            tr.f.iter()
                .zip(&tr.v)
                .map(|(f, v)| f - sigma2 * v)
                .fold(f64::NEG_INFINITY, f64::max)
        };
        peaks.push(peak(&tr));
        peaks_ref.push(peak(&rf));
        cr.extend(std::iter::repeat_n(rate, tr.t.len()));
        ct.extend(&tr.t);
        cx.extend(&tr.x);
        cv.extend(&tr.v);
        cf.extend(&tr.f);
        cu.extend(&tr.u);
    }
    write_columns(
        &dir.join("trace.csv"),
        &["rate", "t", "x", "v", "f", "u"],
        &[&cr, &ct, &cx, &cv, &cf, &cu],
    )?;
    let plot = dir.join("breakaway.svg");
    line_plot(
        &plot,
        "Varying break-away: friction peak versus force rate",
        ("force rate (N/s)", Axis::Log),
        "break-away force (N)",
        &[
            Series {
                label: "core",
                points: zip(&rates, &peaks),
            },
            Series {
                label: "reference",
                points: zip(&rates, &peaks_ref),
            },
        ],
    )?;
    // falls: never rises (beyond 0.1 % of Fs) and drops by more than 1 % of Fs overall
    let falls = peaks.windows(2).all(|p| p[1] <= p[0] + 1e-3 * fs)
        && peaks[peaks.len() - 1] < peaks[0] - 0.01 * fs;
    let list = |p: &[f64]| {
        p.iter()
            .map(|x| format!("{x:.4}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    Ok(Outcome {
        name: "breakaway",
        phenomenon: "varying break-away force",
        pass: Some(falls),
        figure: format!(
            "break-away force {} N at 1, 2, 5, 10, 20, 50 N/s (peak of F - sigma2 v; shows when it falls by > 1 % of Fs as the rate rises)",
            list(&peaks)
        ),
        summary: vec![format!("reference: {} N", list(&peaks_ref))],
        plot,
    })
}

/// Times at which `v` crosses `threshold` upwards (slip onsets).
pub fn slip_onsets(t: &[f64], v: &[f64], threshold: f64) -> Vec<f64> {
    (1..v.len())
        .filter(|&k| v[k - 1] < threshold && v[k] >= threshold)
        .map(|k| t[k])
        .collect()
}

/// Stick-slip figures of one trajectory.
#[derive(Clone, Debug)]
pub struct StickSlipFigures {
    /// Slip onset times (s).
    pub onsets: Vec<f64>,
    /// Peak velocity (m/s).
    pub peak_velocity: f64,
    /// Final position (m).
    pub final_position: f64,
}

impl StickSlipFigures {
    fn of(tr: &Trace, pull: f64) -> Self {
        Self {
            onsets: slip_onsets(&tr.t, &tr.v, 0.5 * pull),
            peak_velocity: tr.v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            final_position: tr.x.last().copied().unwrap_or(0.0),
        }
    }
}

/// Compares core and reference stick-slip: onsets within 1 % of the mean
/// period, peak velocity within 2 %, final position within 1 %.
pub fn compare_stick_slip(core: &StickSlipFigures, reference: &StickSlipFigures) -> (bool, String) {
    let same_count = core.onsets.len() == reference.onsets.len() && core.onsets.len() >= 2;
    let period = if reference.onsets.len() >= 2 {
        (reference.onsets[reference.onsets.len() - 1] - reference.onsets[0])
            / (reference.onsets.len() - 1) as f64
    } else {
        f64::NAN
    };
    let onset_err = core
        .onsets
        .iter()
        .zip(&reference.onsets)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    let peak_err =
        (core.peak_velocity - reference.peak_velocity).abs() / reference.peak_velocity.abs();
    let pos_err =
        (core.final_position - reference.final_position).abs() / reference.final_position.abs();
    let pass = same_count && onset_err <= 0.01 * period && peak_err <= 0.02 && pos_err <= 0.01;
    let text = format!(
        "{} slips (reference {}), onsets within {:.2} ms ({:.2} % of the {:.3} s period, bound 1 %), peak velocity {:.4} vs {:.4} m/s ({:.2} %, bound 2 %), final position {:.5} vs {:.5} m ({:.3} %, bound 1 %)",
        core.onsets.len(),
        reference.onsets.len(),
        1e3 * onset_err,
        100.0 * onset_err / period,
        period,
        core.peak_velocity,
        reference.peak_velocity,
        100.0 * peak_err,
        core.final_position,
        reference.final_position,
        100.0 * pos_err
    );
    (pass, text)
}

/// Mass on a spring whose end is pulled at constant velocity.
fn stick_slip(file: &ParamFile, opts: Options, dir: &Path) -> Result<Outcome> {
    let h = opts.dt.unwrap_or(1e-3);
    let duration = opts.duration.unwrap_or(20.0);
    let k = file.rig.stiffness.unwrap_or(2.0);
    let pull = file.rig.pull_velocity.unwrap_or(0.1);
    let u = move |t: f64, x: f64| k * (pull * t - x);
    let rig = Rig {
        mass: mass(file),
        force: &u,
    };
    let (tr, rf) = rig_pair(file, &rig, h, duration, dir)?;
    let (c, r) = (
        StickSlipFigures::of(&tr, pull),
        StickSlipFigures::of(&rf, pull),
    );
    let (pass, figure) = compare_stick_slip(&c, &r);
    let plot = dir.join("stick-slip.svg");
    plot_pair(
        &plot,
        &format!("Stick-slip: mass on a spring pulled at {pull} m/s (core at h = {h} s)"),
        "t (s)",
        "v (m/s)",
        zip(&tr.t, &tr.v),
        zip(&rf.t, &rf.v),
    )?;
    Ok(Outcome {
        name: "stick-slip",
        phenomenon: "stick-slip",
        pass: Some(pass),
        figure,
        summary: vec![format!(
            "slip onsets (s): {}",
            c.onsets
                .iter()
                .map(|t| format!("{t:.3}"))
                .collect::<Vec<_>>()
                .join(", ")
        )],
        plot,
    })
}

/// Displacement at the end of the first and the last cycle of the drift experiment.
#[derive(Clone, Copy, Debug)]
pub struct DriftFigures {
    /// `x` after the first cycle (m).
    pub first: f64,
    /// `x` after the last cycle (m).
    pub last: f64,
}

/// Mass at rest, `u = force (1 - cos 2 pi f t) / 2` for `cycles` cycles.
fn drift(file: &ParamFile, opts: Options, dir: &Path) -> Result<Outcome> {
    let h = opts.dt.unwrap_or(1e-3);
    let force = file
        .rig
        .force
        .unwrap_or(0.5 * file.model.max_static_force());
    let freq = file.rig.frequency.unwrap_or(1.0);
    let cycles = file.rig.cycles.unwrap_or(10).max(1);
    let duration = opts.duration.unwrap_or(cycles as f64 / freq);
    let u =
        move |t: f64, _x: f64| force * (1.0 - (2.0 * std::f64::consts::PI * freq * t).cos()) / 2.0;
    let rig = Rig {
        mass: mass(file),
        force: &u,
    };
    let (tr, rf) = rig_pair(file, &rig, h, duration, dir)?;
    let at = |x: &[f64], cycle: f64| x[((cycle / freq / h).round() as usize).min(x.len() - 1)];
    let n = (duration * freq).floor().max(1.0);
    let d = DriftFigures {
        first: at(&tr.x, 1.0),
        last: at(&tr.x, n),
    };
    let dr = DriftFigures {
        first: at(&rf.x, 1.0),
        last: at(&rf.x, n),
    };
    let plot = dir.join("drift.svg");
    plot_pair(
        &plot,
        &format!("Drift under a force cycling between 0 and {force} N"),
        "t (s)",
        "x (m)",
        zip(&tr.t, &tr.x),
        zip(&rf.t, &rf.x),
    )?;
    // Drift: the displacement keeps growing cycle after cycle (LuGre creeps).
    let creeps = d.last > 1.5 * d.first && d.first > 0.0;
    Ok(Outcome {
        name: "drift",
        phenomenon: "zero-slip drift",
        pass: Some(creeps),
        figure: format!(
            "x after cycle 1 = {:.4e} m, after cycle {} = {:.4e} m (drift shows when it grows > 1.5x)",
            d.first, n, d.last
        ),
        summary: vec![format!("reference: x after cycle 1 = {:.4e} m, after cycle {} = {:.4e} m", dr.first, n, dr.last)],
        plot,
    })
}
