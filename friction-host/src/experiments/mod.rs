//! The classic friction experiments of the model sheet. Each writes
//! `trace.csv` and a plot into its folder and returns an [`Outcome`]: whether
//! the phenomenon showed, the figure that decided it, and where the model's
//! expected behaviour is known ([`expectation`]) a pass/fail judgement. Rig
//! experiments also run the reference solver and, for stick-slip, require
//! the core to agree with it.

use crate::io::{short, write_columns};
use crate::models::{ScalarKind, Stepper};
use crate::params::{ModelSpec, ParamFile};
use crate::plot::{comparison_plot, line_plot, zip, Axis, Series};
use crate::signals::Signal;
use crate::sim::{drive_core, drive_reference, rig_core, rig_reference, rms_diff, Rig, Trace};
use anyhow::{bail, Result};
use std::path::{Path, PathBuf};

mod breakaway;
mod drift;
mod frictional_lag;
mod nonlocal_memory;
mod presliding;
mod rate_independence;
mod stick_slip;
mod stribeck;

pub(crate) use breakaway::breakaway_rates;
pub use stick_slip::{compare_stick_slip, slip_onsets, StickSlipFigures};

/// The experiment names, in the order `validate` runs them.
pub const NAMES: &[&str] = &[
    "stribeck",
    "presliding",
    "frictional-lag",
    "breakaway",
    "stick-slip",
    "drift",
    "rate-independence",
    "nonlocal-memory",
];

/// The most samples one experiment run may take (checked before anything
/// is allocated): 5 million, at most about 0.5 GB of trace columns in memory
/// (core and reference) and 1.5 GB of `trace.csv`.
pub const MAX_SAMPLES: f64 = 5e6;

/// The fewest samples a run needs to mean anything.
pub const MIN_SAMPLES: f64 = 100.0;

/// Checks a run of `duration` seconds at period `h` against [`MAX_SAMPLES`]
/// and [`MIN_SAMPLES`], with advice that experiment `name` can follow.
pub(crate) fn check_samples(name: &str, duration: f64, h: f64) -> Result<()> {
    let n = duration / h;
    let fixed = FIXED_LENGTH.contains(&name);
    if !(n.is_finite() && n <= MAX_SAMPLES) {
        let advice = match name {
            _ if fixed => "lengthen --dt (its length follows from the parameter set)",
            "drift" => "shorten --duration (or the rig's `cycles`/`frequency`) or lengthen --dt",
            _ => "shorten --duration or lengthen --dt",
        };
        bail!(
            "experiment `{name}` would take {n:.3e} samples ({duration:e} s at --dt {h:e} s), more than the limit {MAX_SAMPLES:.0e}: {advice}"
        );
    }
    if n < MIN_SAMPLES {
        let advice = if fixed {
            "shorten --dt (its length follows from the parameter set)"
        } else {
            "shorten --dt or lengthen --duration"
        };
        bail!(
            "experiment `{name}` would take only {n:.3e} samples ({duration:e} s at --dt {h:e} s), fewer than {MIN_SAMPLES}: {advice}"
        );
    }
    Ok(())
}

/// The default sample period of the rig experiments (s): a mass driven
/// through the model ([`rig_core`]).
pub(crate) const RIG_DT: f64 = 1e-3;
/// The break-away experiment's default sample period (s), finer: its
/// slowest ramps creep at a fraction of the Stribeck velocity.
pub(crate) const BREAKAWAY_DT: f64 = 1e-4;

/// The sample period experiment `name` runs its rig at, `None` for the
/// experiments without a rig (driven by a velocity signal).
fn rig_dt(name: &str, opts: Options) -> Option<f64> {
    match name {
        "breakaway" => Some(opts.dt.unwrap_or(BREAKAWAY_DT)),
        "presliding" | "stick-slip" | "drift" => Some(opts.dt.unwrap_or(RIG_DT)),
        _ => None,
    }
}

/// Largest `omega h` and `c h / m` of the rig's step, `omega = sqrt(k / m)`
/// the mass on the contact's stiffness at rest (and the stick-slip rig's
/// spring) and `c` the contact's damping at rest: the explicit step
/// ([`rig_core`]) is unstable beyond 2 on either, and at 1 samples the
/// oscillation about 6 times a period and the damping's decay in a step or
/// more (every shipped set is at 0.62 or less).
pub const MAX_RIG_OMEGA_H: f64 = 1.0;

/// Why the rig cannot resolve the mass on the contact at period `h`, if it
/// cannot ([`MAX_RIG_OMEGA_H`]).
fn unresolved_rig(name: &str, file: &ParamFile, h: f64) -> Option<Refusal> {
    let spring = if name == "stick-slip" {
        file.rig.stiffness.unwrap_or(0.0)
    } else {
        0.0
    };
    let (k, c, m) = (
        file.model.host().rest_stiffness() + spring,
        file.model.host().rest_damping(),
        mass(file),
    );
    let omega = (k / m).sqrt();
    let decay = c / m;
    // NaN (a zero mass and stiffness) is refused too
    let resolved = omega * h <= MAX_RIG_OMEGA_H && decay * h <= MAX_RIG_OMEGA_H;
    if resolved {
        return None;
    }
    // name the larger of the two
    let (what, rate) = if omega >= decay || omega.is_nan() {
        (
            format!(
                "on the {} stiffness {} oscillates at omega = sqrt(k / m) = {} rad/s",
                if spring > 0.0 {
                    "contact's and spring's"
                } else {
                    "contact's"
                },
                short(k),
                short(omega)
            ),
            omega,
        )
    } else {
        (
            format!(
                "on the contact's damping at rest {} decays at c / m = {} 1/s",
                short(c),
                short(decay)
            ),
            decay,
        )
    };
    Some(Refusal(format!(
        "experiment `{name}`: the rig's mass {} {what}, which its explicit step at --dt {} s does not resolve ({} h = {} > {MAX_RIG_OMEGA_H}; the step is unstable beyond 2): shorten --dt below {} s or raise [rig] `mass`",
        short(m),
        short(h),
        if rate == omega { "omega" } else { "c / m x" },
        if rate * h < 10.0 {
            format!("{:.3}", rate * h)
        } else {
            short(rate * h)
        },
        short(MAX_RIG_OMEGA_H / rate)
    )))
}

/// The experiments whose length is fixed by their definition (no `--duration`).
const FIXED_LENGTH: &[&str] = &[
    "nonlocal-memory",
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

/// An experiment that does not apply to a parameter file, refused before
/// anything runs, with the reason (the command line exits with 2).
#[derive(Clone, Debug)]
pub struct Refusal(pub String);

impl std::fmt::Display for Refusal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Refusal {}

/// Why experiment `name` does not apply to `file`, if it does not.
fn refusal(name: &str, file: &ParamFile) -> Option<Refusal> {
    let r = &file.rig;
    let drift_rig = r.force.is_some() || r.frequency.is_some() || r.cycles.is_some();
    let spring_rig = r.stiffness.is_some() || r.pull_velocity.is_some();
    if name == "stick-slip" && drift_rig && !spring_rig {
        return Some(Refusal(
            "experiment `stick-slip` needs a spring rig, and this file's [rig] is the drift rig (`force`, `frequency`, `cycles`, no spring): a mass driven by a force has nothing to slip against. Give [rig] `stiffness` and `pull_velocity`, or run `drift`".into(),
        ));
    }
    if name == "breakaway" {
        let m = mass(file);
        let unstable = breakaway_rates(file).iter().find_map(|&rate| {
            let why = file.model.host().unstable_creep(m, rate)?;
            Some(format!("at {} N/s, {why}", crate::io::short(rate)))
        });
        if let Some(why) = unstable {
            return Some(Refusal(format!(
                "experiment `breakaway` does not apply to this set on its rig (mass {}): it measures how the break-away force falls as a slow, steady creep speeds up with the force rate, and here the creep is unstable: {why}. The break-away force is then set by when the instability takes off, not by the curve (params/gms-typical.toml is a GMS set whose creep is stable)",
                crate::io::short(m)
            )));
        }
    }
    if name != "stribeck" && !file.model.host().has_state() {
        return Some(Refusal(format!(
            "experiment `{name}` does not apply to the static map `{}`: it needs a model with internal state",
            file.model.name()
        )));
    }
    None
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
    /// The model's `model = "..."` name.
    pub model: &'static str,
    /// What the model is known to do ([`expectation`]).
    pub expected: Option<bool>,
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
    use anyhow::Context;
    if let Some(refusal) = refusal(name, file) {
        return Err(refusal.into());
    }
    if opts.duration.is_some() && FIXED_LENGTH.contains(&name) {
        bail!("--duration does not apply to experiment `{name}`: its length is fixed by its definition");
    }
    if opts.dt.is_some() && (name == "rate-independence" || name == "nonlocal-memory") {
        bail!(
            "--dt does not apply to experiment `{name}`: its sampling is fixed by its definition"
        );
    }
    if let Some(refusal) = rig_dt(name, opts).and_then(|h| unresolved_rig(name, file, h)) {
        return Err(refusal.into());
    }
    // the folders this run creates, deepest first
    let created: Vec<PathBuf> = dir
        .ancestors()
        .take_while(|d| !d.as_os_str().is_empty() && !d.exists())
        .map(Path::to_path_buf)
        .collect();
    std::fs::create_dir_all(dir)
        .with_context(|| format!("--output {}: cannot create the folder", dir.display()))?;
    let out = run_in(name, file, opts, dir);
    if out.is_err() {
        // a run that failed leaves no folder it created (only empty ones)
        for d in &created {
            let _ = std::fs::remove_dir(d);
        }
    }
    out
}

/// [`run`] once its checks passed and `dir` exists.
fn run_in(name: &str, file: &ParamFile, opts: Options, dir: &Path) -> Result<Outcome> {
    let defaults = rig_defaults(name, file);
    let mut out = match name {
        "stribeck" => stribeck::stribeck(file, opts, dir),
        "presliding" => presliding::presliding(file, opts, dir),
        "frictional-lag" => frictional_lag::frictional_lag(file, opts, dir),
        "breakaway" => breakaway::breakaway(file, opts, dir),
        "stick-slip" => stick_slip::stick_slip(file, opts, dir),
        "drift" => drift::drift(file, opts, dir),
        "rate-independence" => rate_independence::rate_independence(file, opts, dir),
        "nonlocal-memory" => nonlocal_memory::nonlocal_memory(file, opts, dir),
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
    out.model = file.model.name();
    out.expected = expected;
    out.pass = match (expected, out.agrees) {
        (Some(e), agrees) => Some(e == out.shown && agrees != Some(false)),
        (None, agrees) => agrees,
    };
    Ok(out)
}

/// Whether `model` is known to show the phenomenon of `experiment`
/// (`None`: not judged, the figures are reported only), from each model's
/// host module ([`crate::models::HostModel::expectations`]). `stribeck`
/// means "the steady state is the model's map" (for the bristle model: its
/// sliding mean).
pub fn expectation(model: &ModelSpec, experiment: &str) -> Option<bool> {
    model.host().expectations().of(experiment).flatten()
}

pub(crate) fn core(spec: &ModelSpec) -> Result<Box<dyn Stepper>> {
    Ok(spec.host().stepper(ScalarKind::F64)?)
}

pub(crate) fn mass(file: &ParamFile) -> f64 {
    file.rig.mass.unwrap_or(1.0)
}

pub(crate) fn trace_csv(dir: &Path, tr: &Trace, reference: Option<&Trace>) -> Result<()> {
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
pub(crate) fn rig_pair(
    file: &ParamFile,
    rig: &Rig,
    h: f64,
    duration: f64,
    dir: &Path,
) -> Result<(Trace, Option<Trace>)> {
    let tr = rig_core(core(&file.model)?.as_mut(), rig, h, duration);
    let rf = match file.model.host().continuous() {
        Some(c) => Some(rig_reference(c.as_ref(), rig, &tr.t)?),
        None => None,
    };
    trace_csv(dir, &tr, rf.as_ref())?;
    Ok((tr, rf))
}

/// Plots one quantity of the core's trajectory, with the reference's and
/// their difference where there is a reference.
pub(crate) fn plot_pair(
    path: &Path,
    title: &str,
    (x_label, y_label): (&str, &str),
    core: Vec<(f64, f64)>,
    reference: Option<Vec<(f64, f64)>>,
) -> Result<()> {
    match reference {
        Some(reference) => comparison_plot(path, title, x_label, y_label, core, reference),
        None => line_plot(
            path,
            title,
            (x_label, Axis::Linear),
            y_label,
            &[Series {
                label: "core",
                points: core,
            }],
        ),
    }
}

#[cfg(test)]
mod tests {
    /// Every experiment has its named field in
    /// [`crate::models::Expectations`].
    #[test]
    fn every_experiment_has_an_expectation() {
        let row = crate::models::Expectations::STEADY_CURVE_ONLY;
        for name in super::NAMES {
            assert!(row.of(name).is_some(), "{name}");
        }
        assert_eq!(row.of("none"), None);
    }
}
