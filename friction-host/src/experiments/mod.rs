//! The classic friction experiments of the model sheet. Each writes
//! `trace.csv` and a plot into its folder and returns an [`Outcome`]: whether
//! the phenomenon showed, the figure that decided it, and where the model's
//! expected behaviour is known ([`expectation`]) a pass/fail judgement. Rig
//! experiments also run the reference solver and, for stick-slip, require
//! the core to agree with it.

use crate::checks::short;
use crate::io::write_columns;
use crate::models::ModelSpec;
use crate::models::{Expect, Expectations, ScalarKind, Stepper};
use crate::params::ParamFile;
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

/// One experiment: its name, its column of the report's phenomenon matrix,
/// what it takes from the command line, what a model is expected to show
/// in it, and its runner. [`LIST`] holds every one.
#[derive(Clone, Copy)]
pub struct Experiment {
    /// Its name on the command line and in the report (`stick-slip`).
    pub name: &'static str,
    /// The title of its column in the report's phenomenon matrix.
    pub title: &'static str,
    /// Where that column stands (0 first): the matrix orders the phenomena
    /// its own way (non-local memory beside pre-sliding hysteresis), while
    /// `validate` runs the experiments in [`LIST`]'s order.
    pub column: usize,
    /// Whether its length is fixed by its definition (no `--duration`).
    pub fixed_length: bool,
    /// How it is sampled.
    pub sampling: Sampling,
    /// What a model is known to show in it (its field of [`Expectations`]).
    pub expected: fn(&Expectations) -> Expect,
    /// Runs it once its checks passed and its folder exists.
    run: fn(&ParamFile, Options, &Path) -> Result<Outcome>,
}

/// How an experiment is sampled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Sampling {
    /// A velocity signal drives the model, at `--dt` or the experiment's
    /// own default.
    Signal,
    /// A rig drives a mass through the model ([`rig_core`]), at `--dt` or
    /// this default period (s); the rig must resolve the mass on the contact
    /// ([`MAX_RIG_OMEGA_H`]).
    Rig(f64),
    /// Fixed by its definition (no `--dt`).
    Fixed,
}

/// Every experiment, in the order `validate` runs them.
pub const LIST: &[Experiment] = &[
    Experiment {
        name: "stribeck",
        title: "Stribeck curve",
        column: 0,
        fixed_length: true,
        sampling: Sampling::Signal,
        expected: |e| e.stribeck,
        run: stribeck::stribeck,
    },
    Experiment {
        name: "presliding",
        title: "pre-sliding hysteresis",
        column: 1,
        fixed_length: false,
        sampling: Sampling::Rig(RIG_DT),
        expected: |e| e.presliding,
        run: presliding::presliding,
    },
    Experiment {
        name: "frictional-lag",
        title: "frictional lag",
        column: 3,
        fixed_length: true,
        sampling: Sampling::Signal,
        expected: |e| e.frictional_lag,
        run: frictional_lag::frictional_lag,
    },
    Experiment {
        name: "breakaway",
        title: "varying break-away",
        column: 4,
        fixed_length: true,
        sampling: Sampling::Rig(BREAKAWAY_DT),
        expected: |e| e.breakaway,
        run: breakaway::breakaway,
    },
    Experiment {
        name: "stick-slip",
        title: "stick-slip",
        column: 5,
        fixed_length: false,
        sampling: Sampling::Rig(RIG_DT),
        expected: |e| e.stick_slip,
        run: stick_slip::stick_slip,
    },
    Experiment {
        name: "drift",
        title: "drift",
        column: 6,
        fixed_length: false,
        sampling: Sampling::Rig(RIG_DT),
        expected: |e| e.drift,
        run: drift::drift,
    },
    Experiment {
        name: "rate-independence",
        title: "rate independence",
        column: 7,
        fixed_length: true,
        sampling: Sampling::Fixed,
        expected: |e| e.rate_independence,
        run: rate_independence::rate_independence,
    },
    Experiment {
        name: "nonlocal-memory",
        title: "non-local memory",
        column: 2,
        fixed_length: true,
        sampling: Sampling::Fixed,
        expected: |e| e.nonlocal_memory,
        run: nonlocal_memory::nonlocal_memory,
    },
];

/// The experiment names, in the order `validate` runs them (the names of
/// [`LIST`]).
pub const NAMES: &[&str] = &{
    let mut names = [""; LIST.len()];
    let mut i = 0;
    while i < LIST.len() {
        names[i] = LIST[i].name;
        i += 1;
    }
    names
};

/// The experiment called `name`.
pub fn find(name: &str) -> Option<&'static Experiment> {
    LIST.iter().find(|e| e.name == name)
}

/// The experiments in the order of the report's columns ([`Experiment::column`]).
pub fn columns() -> Vec<&'static Experiment> {
    let mut columns: Vec<_> = LIST.iter().collect();
    columns.sort_by_key(|e| e.column);
    columns
}

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
    let experiment = find(name);
    debug_assert!(experiment.is_some(), "no experiment `{name}`");
    let fixed = experiment.is_some_and(|e| e.fixed_length);
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

/// The sample period `experiment` runs its rig at, `None` for the
/// experiments without a rig.
fn rig_dt(experiment: &Experiment, opts: Options) -> Option<f64> {
    match experiment.sampling {
        Sampling::Rig(dt) => Some(opts.dt.unwrap_or(dt)),
        Sampling::Signal | Sampling::Fixed => None,
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
            Some(format!("at {} N/s, {why}", crate::checks::short(rate)))
        });
        if let Some(why) = unstable {
            return Some(Refusal(format!(
                "experiment `breakaway` does not apply to this set on its rig (mass {}): it measures how the break-away force falls as a slow, steady creep speeds up with the force rate, and here the creep is unstable: {why}. The break-away force is then set by when the instability takes off, not by the curve (params/gms-typical.toml is a GMS set whose creep is stable)",
                crate::checks::short(m)
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
    let Some(experiment) = find(name) else {
        bail!(
            "unknown experiment `{name}` (expected one of {})",
            NAMES.join(", ")
        )
    };
    if opts.duration.is_some() && experiment.fixed_length {
        bail!("--duration does not apply to experiment `{name}`: its length is fixed by its definition");
    }
    if opts.dt.is_some() && experiment.sampling == Sampling::Fixed {
        bail!(
            "--dt does not apply to experiment `{name}`: its sampling is fixed by its definition"
        );
    }
    if let Some(refusal) = rig_dt(experiment, opts).and_then(|h| unresolved_rig(name, file, h)) {
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
    let out = run_in(experiment, file, opts, dir);
    if out.is_err() {
        // a run that failed leaves no folder it created (only empty ones)
        for d in &created {
            let _ = std::fs::remove_dir(d);
        }
    }
    out
}

/// [`run`] once its checks passed and `dir` exists.
fn run_in(experiment: &Experiment, file: &ParamFile, opts: Options, dir: &Path) -> Result<Outcome> {
    let defaults = rig_defaults(experiment.name, file);
    let mut out = (experiment.run)(file, opts, dir)?;
    for (i, note) in defaults.into_iter().enumerate() {
        out.summary.insert(i, note);
    }
    let expected = (experiment.expected)(&file.model.host().expectations());
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
    let expectations = model.host().expectations();
    find(experiment).and_then(|e| (e.expected)(&expectations))
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
    use super::{columns, rig_defaults, Sampling, LIST, NAMES};
    use crate::models::{Expectations, U, Y};

    /// Each experiment reads its own field of [`Expectations`].
    #[test]
    fn every_experiment_reads_its_own_expectation() {
        let none = Expectations {
            stribeck: U,
            ..Expectations::STEADY_CURVE_ONLY
        };
        let only = [
            (
                "stribeck",
                Expectations {
                    stribeck: Y,
                    ..none
                },
            ),
            (
                "presliding",
                Expectations {
                    presliding: Y,
                    ..none
                },
            ),
            (
                "frictional-lag",
                Expectations {
                    frictional_lag: Y,
                    ..none
                },
            ),
            (
                "breakaway",
                Expectations {
                    breakaway: Y,
                    ..none
                },
            ),
            (
                "stick-slip",
                Expectations {
                    stick_slip: Y,
                    ..none
                },
            ),
            ("drift", Expectations { drift: Y, ..none }),
            (
                "rate-independence",
                Expectations {
                    rate_independence: Y,
                    ..none
                },
            ),
            (
                "nonlocal-memory",
                Expectations {
                    nonlocal_memory: Y,
                    ..none
                },
            ),
        ];
        assert_eq!(only.len(), LIST.len());
        for (name, row) in only {
            for e in LIST {
                let want = if e.name == name { Y } else { U };
                assert_eq!((e.expected)(&row), want, "{name}: {}", e.name);
            }
        }
    }

    /// The names, and the report's column places and titles, are each
    /// given once.
    #[test]
    fn names_and_columns_are_distinct() {
        let places: Vec<usize> = columns().iter().map(|e| e.column).collect();
        assert_eq!(places, (0..LIST.len()).collect::<Vec<_>>());
        for (i, e) in LIST.iter().enumerate() {
            assert_eq!(NAMES[i], e.name);
            for other in &LIST[..i] {
                assert!(other.name != e.name && other.title != e.title, "{}", e.name);
            }
        }
    }

    /// The rig experiments note the `[rig]` keys a file leaves out; the
    /// others use no rig.
    #[test]
    fn rig_experiments_note_their_defaults() {
        let mut file = crate::params::param_set("canudas1995").unwrap();
        file.rig = Default::default();
        for e in LIST {
            let rig = matches!(e.sampling, Sampling::Rig(_));
            assert_eq!(!rig_defaults(e.name, &file).is_empty(), rig, "{}", e.name);
        }
    }
}
