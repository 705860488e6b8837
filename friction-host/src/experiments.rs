//! The classic friction experiments of the model sheet. Each writes
//! `trace.csv` and a plot into its folder and returns an [`Outcome`]: whether
//! the phenomenon showed, the figure that decided it, and where the model's
//! expected behaviour is known ([`expectation`]) a pass/fail judgement. Rig
//! experiments also run the reference solver and, for stick-slip, require
//! the core to agree with it.

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
    "rate-independence",
];

/// The most samples one experiment run may take (checked before anything
/// is allocated): 20 million, about 1 GB of trace columns.
pub const MAX_SAMPLES: f64 = 2e7;

/// Checks a run of `duration` seconds at period `h` against [`MAX_SAMPLES`].
fn check_samples(name: &str, duration: f64, h: f64) -> Result<()> {
    let n = duration / h;
    if !(n.is_finite() && n <= MAX_SAMPLES) {
        bail!(
            "experiment `{name}` would take {n:.3e} samples ({duration} s at --dt {h} s), more than the limit {MAX_SAMPLES:.0e}: shorten --duration (or the rig's `cycles`/`frequency`) or lengthen --dt"
        );
    }
    Ok(())
}

/// The experiments whose length is fixed by their definition (no `--duration`).
const FIXED_LENGTH: &[&str] = &[
    "stribeck",
    "frictional-lag",
    "breakaway",
    "rate-independence",
];

/// Notes on the `[rig]` keys an experiment uses that the file does not give.
fn rig_defaults(name: &str, file: &ParamFile) -> Vec<String> {
    let r = &file.rig;
    let keys: &[(&str, bool, &str)] = match name {
        "presliding" => &[
            ("mass", r.mass.is_none(), "1 kg"),
            ("force_rate", r.force_rate.is_none(), "0.095 Fs per second"),
        ],
        "breakaway" => &[("mass", r.mass.is_none(), "1 kg")],
        "stick-slip" => &[
            ("mass", r.mass.is_none(), "1 kg"),
            ("stiffness", r.stiffness.is_none(), "2 N/m"),
            ("pull_velocity", r.pull_velocity.is_none(), "0.1 m/s"),
        ],
        "drift" => &[
            ("mass", r.mass.is_none(), "1 kg"),
            (
                "force",
                r.force.is_none(),
                "Fs/2 (elasto-plastic: 0.9 sigma0 z_ba)",
            ),
            ("frequency", r.frequency.is_none(), "1 Hz"),
            ("cycles", r.cycles.is_none(), "10"),
        ],
        _ => &[],
    };
    keys.iter()
        .filter(|(_, missing, _)| *missing)
        .map(|(key, _, default)| format!("[rig] `{key}` not given: default {default}"))
        .collect()
}

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
    /// Whether the phenomenon showed.
    pub shown: bool,
    /// Whether the core agreed with the reference solver, where compared.
    pub agrees: Option<bool>,
    /// `Some(true)` when the model did what it is known to do (and agreed
    /// with the reference); `None` when not judged.
    pub pass: Option<bool>,
    /// The figure that decided `shown`, in words.
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
    if opts.duration.is_some() && FIXED_LENGTH.contains(&name) {
        bail!("--duration does not apply to experiment `{name}`: its length is fixed by its definition");
    }
    if opts.dt.is_some() && name == "rate-independence" {
        bail!("--dt does not apply to experiment `{name}`: it takes 2000 samples a period");
    }
    let defaults = rig_defaults(name, file);
    let mut out = match name {
        "stribeck" => stribeck(file, opts, dir),
        "presliding" => presliding(file, opts, dir),
        "frictional-lag" => frictional_lag(file, opts, dir),
        "breakaway" => breakaway(file, opts, dir),
        "stick-slip" => stick_slip(file, opts, dir),
        "drift" => drift(file, opts, dir),
        "rate-independence" => rate_independence(file, opts, dir),
        other => bail!(
            "unknown experiment `{other}` (expected one of {})",
            NAMES.join(", ")
        ),
    }?;
    for (i, note) in defaults.into_iter().enumerate() {
        out.summary.insert(i, note);
    }
    let expected = expectation(&file.model, name);
    if let Some(expected) = expected {
        out.summary.push(format!(
            "{} is {} for `{}`; here it {}",
            out.phenomenon,
            if expected { "expected" } else { "not expected" },
            file.model.name(),
            if out.shown { "shows" } else { "does not show" }
        ));
    }
    out.pass = match (expected, out.agrees) {
        (Some(e), agrees) => Some(e == out.shown && agrees != Some(false)),
        (None, agrees) => agrees,
    };
    Ok(out)
}

/// Whether `model` is known to show the phenomenon of `experiment`
/// (`None`: not judged, the figures are reported only). From the model
/// sheet and the models' papers:
///
/// | | stribeck | presliding | lag | breakaway | stick-slip | drift | rate-indep. |
/// |---|---|---|---|---|---|---|---|
/// | LuGre | yes | yes | yes | yes | yes | yes | no |
/// | elasto-plastic | yes | yes | yes | yes | yes | **no** (below `sigma0 z_ba`) | no |
/// | Dahl | yes | yes | no | no | no | yes | yes |
/// | reset integrator | yes | no | no | no | yes | no | - |
/// | bristle | yes | no | - | no | - | no | yes |
///
/// `stribeck` here means "the steady state is the model's map" (for the
/// bristle model: its sliding mean).
pub fn expectation(model: &ModelSpec, experiment: &str) -> Option<bool> {
    const Y: Option<bool> = Some(true);
    const N: Option<bool> = Some(false);
    const U: Option<bool> = None;
    #[rustfmt::skip]
    let row: [Option<bool>; 7] = match model {
        //                              stribeck pre  lag  break slip drift rate
        ModelSpec::LuGre(_)          => [Y,       Y,   Y,   Y,    Y,   Y,    N],
        ModelSpec::ElastoPlastic(_)  => [Y,       Y,   Y,   Y,    Y,   N,    N],
        ModelSpec::Dahl(_)           => [Y,       Y,   N,   N,    N,   Y,    Y],
        ModelSpec::ResetIntegrator(_)=> [Y,       N,   N,   N,    Y,   N,    U],
        // bristle: the force is random in x, so F-v loops enclose area
        // without any lag; rate-independence is the relevant check
        ModelSpec::Bristle { .. }    => [Y,       N,   U,   N,    U,   N,    Y],
        _                            => [Y,       U,   U,   U,    U,   U,    U],
    };
    NAMES
        .iter()
        .position(|n| *n == experiment)
        .and_then(|i| row[i])
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

/// Runs the rig with the core and, where the model has a continuous form,
/// with the reference solver on the same sample times; writes `trace.csv`.
fn rig_pair(
    file: &ParamFile,
    rig: &Rig,
    h: f64,
    duration: f64,
    dir: &Path,
) -> Result<(Trace, Option<Trace>)> {
    let tr = rig_core(core(&file.model)?.as_mut(), rig, h, duration);
    let rf = match file.model.continuous() {
        Some(c) => Some(rig_reference(c.as_ref(), rig, &tr.t)?),
        None => None,
    };
    trace_csv(dir, &tr, rf.as_ref())?;
    Ok((tr, rf))
}

/// Plots one quantity of the core's trajectory against the reference's.
fn plot_pair(
    path: &Path,
    title: &str,
    (x_label, y_label): (&str, &str),
    core: Vec<(f64, f64)>,
    reference: Option<Vec<(f64, f64)>>,
) -> Result<()> {
    let mut series = vec![Series {
        label: "core",
        points: core,
    }];
    if let Some(points) = reference {
        series.push(Series {
            label: "reference",
            points,
        });
    }
    line_plot(path, title, (x_label, Axis::Linear), y_label, &series)
}

/// The steady state the core must reach at constant `v`: the continuous
/// model's map, or the bristle model's sliding mean `N sigma0 delta_s / 3`.
fn steady_force(spec: &ModelSpec, v: f64) -> f64 {
    match (spec, spec.continuous()) {
        (_, Some(c)) => c.steady_force(v),
        (ModelSpec::Bristle { params, bristles }, None) => {
            *bristles as f64 * params.sigma0 * params.delta_s / 3.0 * v.signum()
        }
        _ => f64::NAN,
    }
}

/// Steady friction at constant velocities, log-spaced from 1e-6 to 1 m/s, both signs.
fn stribeck(file: &ParamFile, opts: Options, dir: &Path) -> Result<Outcome> {
    let h = opts.dt.unwrap_or(1e-3);
    let fs = file.model.max_static_force();
    let stochastic = matches!(file.model, ModelSpec::Bristle { .. });
    let speeds: Vec<f64> = (0..=60)
        .map(|i| 10f64.powf(-6.0 + i as f64 * 0.1))
        .collect();
    let (mut vs, mut fcore, mut fss) = (Vec::new(), Vec::new(), Vec::new());
    for sign in [1.0, -1.0] {
        for &s in &speeds {
            let v = sign * s;
            let mut m = core(&file.model)?;
            let f = if let ModelSpec::Bristle { params, .. } = &file.model {
                // rate independent and exact for held v: step by delta_s / 20,
                // average over 200 delta_s after 20 delta_s of running in
                let hb = params.delta_s / 20.0 / s;
                for _ in 0..400 {
                    m.step(v, hb);
                }
                (0..4000).map(|_| m.step(v, hb)).sum::<f64>() / 4000.0
            } else {
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
                f
            };
            vs.push(v);
            fcore.push(f);
            fss.push(steady_force(&file.model, v));
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
        &format!("Steady friction ({}) versus speed", file.model.name()),
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
    let bound = if stochastic { 0.05 } else { 1e-6 };
    let weakening = (fcore[0] - fcore[n - 1] + file.model.sigma2()) / fs;
    Ok(Outcome {
        name: "stribeck",
        phenomenon: "steady-state map",
        shown: worst <= bound,
        agrees: None,
        pass: None,
        figure: format!(
            "max |F - steady-state map| = {worst:.2e} of the static force over ±[1e-6, 1] m/s (bound {bound:.0e}{})",
            if stochastic { ", the mean of a random force" } else { "" }
        ),
        summary: vec![
            format!("F(1e-6) = {:.4} N, F(1e-3) = {:.4} N, F(1) = {:.4} N", fcore[0], fcore[30], fcore[n - 1]),
            format!(
                "Stribeck effect (velocity weakening, less sigma2 v): F(1e-6) - F(1) = {:.3} of the static force",
                weakening
            ),
        ],
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
    check_samples("presliding", duration, h)?;
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
    let d = file.model.presliding_scale();
    let plot = dir.join("presliding.svg");
    plot_pair(
        &plot,
        "Pre-sliding hysteresis: friction versus displacement",
        ("x (m)", "F (N)"),
        zip(&tr.x, &tr.f),
        rf.as_ref().map(|r| zip(&r.x, &r.f)),
    )?;
    let hysteretic = residual.abs() > 0.01 * d;
    let bounded = x_max < 10.0 * d;
    let mut summary = Vec::new();
    if let Some(r) = &rf {
        let err = rms_diff(&tr.x, &r.x);
        summary.push(format!(
            "rms |x_core - x_ref| = {:.3e} m ({:.3} % of max |x|)",
            err,
            100.0 * err / x_max
        ));
    }
    Ok(Outcome {
        name: "presliding",
        phenomenon: "pre-sliding hysteresis",
        shown: hysteretic && bounded,
        agrees: None,
        pass: None,
        figure: format!(
            "residual x at u = 0: {:.3e} m ({:.1} % of the pre-sliding scale d = {:.3e} m, hysteresis above 1 %); max |x| = {:.2} d (pre-sliding below 10 d)",
            residual,
            100.0 * residual.abs() / d,
            d,
            x_max / d
        ),
        summary,
        plot,
    })
}

/// `v = v0 (cos(w t) + 1.5)` with `w = 1, 10, 25 rad/s`: the F-v loop widens with `w`.
fn frictional_lag(file: &ParamFile, opts: Options, dir: &Path) -> Result<Outcome> {
    let h = opts.dt.unwrap_or(1e-4);
    // three periods at w = 1, 10 and 25 rad/s
    check_samples("frictional-lag", 6.0 * std::f64::consts::PI * 1.14, h)?;
    let mut series = Vec::new();
    let mut areas = Vec::new();
    let (mut cw, mut ct, mut cv, mut cf, mut cr) = (vec![], vec![], vec![], vec![], vec![]);
    let mut worst = 0.0f64;
    for w in [1.0, 10.0, 25.0] {
        let s = Signal::lag(1e-3, w, 3.0);
        let t = s.times(h);
        let v: Vec<f64> = t.iter().map(|&ti| s.v(ti)).collect();
        let f = drive_core(core(&file.model)?.as_mut(), &t, &v);
        let fr = drive_reference(&file.model, &s, &t)?.force;
        worst = worst.max(rms_diff(&f, &fr) / file.model.max_static_force());
        // loop area over the last period: closed integral of F dv
        let start = t.len() * 2 / 3;
        let area: f64 = (start + 1..t.len())
            .map(|k| 0.5 * (f[k] + f[k - 1]) * (v[k] - v[k - 1]))
            .sum();
        areas.push(area.abs());
        series.push(zip(&v[start..], &f[start..]));
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
            .map(|(p, label)| Series { label, points: p })
            .collect::<Vec<_>>(),
    )?;
    // widens: the area grows with w, and the widest loop is visible (more
    // than 0.1 % of its bounding box, the static force x the velocity range 2 v0)
    let box_area = file.model.max_static_force() * 2e-3;
    let widens = areas.windows(2).all(|a| a[1] > a[0]) && areas[2] > 1e-3 * box_area;
    Ok(Outcome {
        name: "frictional-lag",
        phenomenon: "frictional lag",
        shown: widens,
        agrees: None,
        pass: None,
        figure: format!(
            "loop area |∮F dv| = {:.3e}, {:.3e}, {:.3e} N m/s for w = 1, 10, 25 (lag shows when it grows and exceeds 0.1 % of the static force x 2 v0)",
            areas[0], areas[1], areas[2]
        ),
        summary: vec![format!("worst rms force error against the reference: {:.4} % of the static force", 100.0 * worst)],
        plot,
    })
}

/// Mass at rest, applied force ramping at 1 to 50 N/s: the friction peak
/// (break-away force) against the rate.
fn breakaway(file: &ParamFile, opts: Options, dir: &Path) -> Result<Outcome> {
    let h = opts.dt.unwrap_or(1e-4);
    let fs = file.model.max_static_force();
    let rates = [1.0, 2.0, 5.0, 10.0, 20.0, 50.0];
    check_samples("breakaway", rates.iter().map(|r| 2.0 * fs / r).sum(), h)?;
    let (mut peaks, mut peaks_ref) = (Vec::new(), Vec::new());
    let (mut cr, mut ct, mut cx, mut cv, mut cf, mut cu) =
        (vec![], vec![], vec![], vec![], vec![], vec![]);
    let continuous = file.model.continuous();
    // break-away: the peak of the friction force less its viscous part
    // (which only grows once the mass slides)
    let sigma2 = file.model.sigma2();
    let peak = |tr: &Trace| {
        tr.f.iter()
            .zip(&tr.v)
            .map(|(f, v)| f - sigma2 * v)
            .fold(f64::NEG_INFINITY, f64::max)
    };
    for &rate in &rates {
        let u = move |t: f64, _x: f64| rate * t;
        let rig = Rig {
            mass: mass(file),
            force: &u,
        };
        let duration = 2.0 * fs / rate;
        let tr = rig_core(core(&file.model)?.as_mut(), &rig, h, duration);
        peaks.push(peak(&tr));
        if let Some(c) = &continuous {
            peaks_ref.push(peak(&rig_reference(c.as_ref(), &rig, &tr.t)?));
        }
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
    let mut series = vec![Series {
        label: "core",
        points: zip(&rates, &peaks),
    }];
    if !peaks_ref.is_empty() {
        series.push(Series {
            label: "reference",
            points: zip(&rates, &peaks_ref),
        });
    }
    line_plot(
        &plot,
        "Varying break-away: friction peak versus force rate",
        ("force rate (N/s)", Axis::Log),
        "break-away force (N)",
        &series,
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
    let mut summary = Vec::new();
    if !peaks_ref.is_empty() {
        summary.push(format!("reference: {} N", list(&peaks_ref)));
    }
    Ok(Outcome {
        name: "breakaway",
        phenomenon: "varying break-away force",
        shown: falls,
        agrees: None,
        pass: None,
        figure: format!(
            "break-away force {} N at 1, 2, 5, 10, 20, 50 N/s (peak of F - sigma2 v; shows when it falls by > 1 % of the static force as the rate rises)",
            list(&peaks)
        ),
        summary,
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

/// Compares core and reference stick-slip: the same number of slips, onsets
/// within 1 % of the mean period, peak velocity within 2 %, final position
/// within 1 %.
pub fn compare_stick_slip(core: &StickSlipFigures, reference: &StickSlipFigures) -> (bool, String) {
    let same_count = core.onsets.len() == reference.onsets.len();
    let period = if reference.onsets.len() >= 2 {
        (reference.onsets[reference.onsets.len() - 1] - reference.onsets[0])
            / (reference.onsets.len() - 1) as f64
    } else {
        f64::INFINITY
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
    check_samples("stick-slip", duration, h)?;
    let k = file.rig.stiffness.unwrap_or(2.0);
    let pull = file.rig.pull_velocity.unwrap_or(0.1);
    let u = move |t: f64, x: f64| k * (pull * t - x);
    let rig = Rig {
        mass: mass(file),
        force: &u,
    };
    let (tr, rf) = rig_pair(file, &rig, h, duration, dir)?;
    let c = StickSlipFigures::of(&tr, pull);
    let comparison = rf
        .as_ref()
        .map(|r| compare_stick_slip(&c, &StickSlipFigures::of(r, pull)));
    let plot = dir.join("stick-slip.svg");
    plot_pair(
        &plot,
        &format!("Stick-slip: mass on a spring pulled at {pull} m/s (core at h = {h} s)"),
        ("t (s)", "v (m/s)"),
        zip(&tr.t, &tr.v),
        rf.as_ref().map(|r| zip(&r.t, &r.v)),
    )?;
    let onsets = c
        .onsets
        .iter()
        .map(|t| format!("{t:.3}"))
        .collect::<Vec<_>>()
        .join(", ");
    let mut summary = vec![format!("slip onsets (s): {onsets}")];
    if let Some((_, text)) = &comparison {
        summary.push(format!("against the reference: {text}"));
    }
    Ok(Outcome {
        name: "stick-slip",
        phenomenon: "stick-slip",
        shown: c.onsets.len() >= 2,
        agrees: comparison.as_ref().map(|(ok, _)| *ok),
        pass: None,
        figure: match &comparison {
            Some((_, text)) => text.clone(),
            None => format!(
                "{} slips, peak velocity {:.4} m/s (no reference for this model)",
                c.onsets.len(),
                c.peak_velocity
            ),
        },
        summary,
        plot,
    })
}

/// Mass at rest, `u = force (1 - cos 2 pi f t) / 2` for `cycles` cycles.
fn drift(file: &ParamFile, opts: Options, dir: &Path) -> Result<Outcome> {
    let h = opts.dt.unwrap_or(1e-3);
    // default: half the static force, or for elasto-plastic 90 % of the
    // elastic limit sigma0 z_ba, below which it must not drift
    let default_force = match &file.model {
        ModelSpec::ElastoPlastic(p) => 0.9 * p.lugre.sigma0 * p.z_ba,
        m => 0.5 * m.max_static_force(),
    };
    let force = file.rig.force.unwrap_or(default_force);
    let freq = file.rig.frequency.unwrap_or(1.0);
    let cycles = file.rig.cycles.unwrap_or(10).max(1);
    let duration = opts.duration.unwrap_or(cycles as f64 / freq);
    check_samples("drift", duration, h)?;
    let u =
        move |t: f64, _x: f64| force * (1.0 - (2.0 * std::f64::consts::PI * freq * t).cos()) / 2.0;
    let rig = Rig {
        mass: mass(file),
        force: &u,
    };
    let (tr, rf) = rig_pair(file, &rig, h, duration, dir)?;
    let at = |x: &[f64], cycle: f64| x[((cycle / freq / h).round() as usize).min(x.len() - 1)];
    let n = (duration * freq).floor().max(1.0);
    let (first, last) = (at(&tr.x, 1.0), at(&tr.x, n));
    let plot = dir.join("drift.svg");
    plot_pair(
        &plot,
        &format!("Drift under a force cycling between 0 and {force} N"),
        ("t (s)", "x (m)"),
        zip(&tr.t, &tr.x),
        rf.as_ref().map(|r| zip(&r.t, &r.x)),
    )?;
    // drift: the displacement keeps growing cycle after cycle, by more than
    // a thousandth of the pre-sliding scale
    let d = file.model.presliding_scale();
    let drifts = last > 1.5 * first && last - first > 1e-3 * d;
    let mut summary = vec![format!(
        "drift per cycle: {:.3e} m",
        (last - first) / (n - 1.0).max(1.0)
    )];
    if let Some(r) = &rf {
        summary.push(format!(
            "reference: x after cycle 1 = {:.4e} m, after cycle {} = {:.4e} m",
            at(&r.x, 1.0),
            n,
            at(&r.x, n)
        ));
    }
    Ok(Outcome {
        name: "drift",
        phenomenon: "zero-slip drift",
        shown: drifts,
        agrees: None,
        pass: None,
        figure: format!(
            "force peak {force:.4} N: x after cycle 1 = {first:.4e} m, after cycle {n} = {last:.4e} m (drift shows when it grows > 1.5x and by > 1e-3 d, d = {d:.2e} m)"
        ),
        summary,
        plot,
    })
}

/// A periodic displacement of amplitude `2 d` (`d` the pre-sliding scale) at
/// 0.1, 1 and 10 Hz, 2000 samples a period: is the loop `F - sigma2 v`
/// versus `x` the same at every frequency?
fn rate_independence(file: &ParamFile, _opts: Options, dir: &Path) -> Result<Outcome> {
    let d = file.model.presliding_scale();
    let fs = file.model.max_static_force();
    let sigma2 = file.model.sigma2();
    let mut loops: Vec<(Vec<f64>, Vec<f64>)> = Vec::new();
    let (mut cf, mut ct, mut cx, mut cv, mut cff) = (vec![], vec![], vec![], vec![], vec![]);
    for freq in [0.1, 1.0, 10.0] {
        let w = 2.0 * std::f64::consts::PI * freq;
        // x(t) = 2 d (1 - cos w t) / 2 ... from the velocity 2 d w / 2 sin(w t)
        let s = Signal::sine(d * w, freq, 2.0);
        let t = s.times(1.0 / (2000.0 * freq));
        let v = s.mean_velocities(&t);
        let f = drive_core(core(&file.model)?.as_mut(), &t, &v);
        let x: Vec<f64> = t.iter().map(|&ti| s.x(ti)).collect();
        let fh: Vec<f64> = f.iter().zip(&v).map(|(f, v)| f - sigma2 * v).collect();
        cf.extend(std::iter::repeat_n(freq, t.len()));
        ct.extend(&t);
        cx.extend(&x);
        cv.extend(&v);
        cff.extend(&f);
        let half = t.len() / 2;
        loops.push((x[half..].to_vec(), fh[half..].to_vec()));
    }
    write_columns(
        &dir.join("trace.csv"),
        &["frequency", "t", "x", "v", "f"],
        &[&cf, &ct, &cx, &cv, &cff],
    )?;
    // the samples sit at the same phases, so the loops compare point by point
    let diff = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .map(|(p, q)| (p - q).abs())
            .fold(0.0, f64::max)
    };
    let spread = diff(&loops[0].1, &loops[1].1).max(diff(&loops[0].1, &loops[2].1)) / fs;
    let plot = dir.join("rate-independence.svg");
    let labels = ["0.1 Hz", "1 Hz", "10 Hz"];
    line_plot(
        &plot,
        "Force-displacement loop at three frequencies (F - sigma2 v)",
        ("x (m)", Axis::Linear),
        "F - sigma2 v (N)",
        &loops
            .iter()
            .zip(labels)
            .map(|((x, f), label)| Series {
                label,
                points: zip(x, f),
            })
            .collect::<Vec<_>>(),
    )?;
    Ok(Outcome {
        name: "rate-independence",
        phenomenon: "rate-independent hysteresis",
        shown: spread < 0.01,
        agrees: None,
        pass: None,
        figure: format!(
            "largest difference between the loops at 0.1, 1 and 10 Hz: {spread:.2e} of the static force (rate independent below 1 %)"
        ),
        summary: Vec::new(),
        plot,
    })
}
