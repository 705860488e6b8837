//! `friction online`: the compensator's estimators replayed causally on a
//! measured run, sample by sample, as a drive would run them.
//!
//! Each sample's position and applied command go through
//! [`friction_core::Compensator::listen`] (the drive's own controller made the command;
//! the estimators only listen): the friction the compensator measures
//! ([`friction_core::FrictionSample`]: the commands less the mass times the
//! second difference of the position) teaches
//!
//! - the per-parameter estimator ([`friction_core::ParameterAdaptive`]) by its
//!   prediction-error law: Coulomb level per direction (a force offset
//!   shows as a difference between them), Stribeck excess, viscous
//!   coefficient, each in its box around the starting guess;
//! - the least-squares feed-forward ([`friction_core::RlsFeedForward`]): Coulomb level and viscous
//!   coefficient, with forgetting.
//!
//! Nothing looks ahead: no zero-phase filter, no fit over the whole run.
//! The mass is the user's (a nameplate or a commissioning figure), as the
//! drive's loop has it. The offline inverse-model least-squares fit
//! (`identify`'s `coulomb-viscous` with `--inertia`, IDIM-LS) of the same
//! run is the yardstick: its figures, and the force each model predicts on
//! a second run (`--validate`), judged by the same measure as `identify`'s.

use crate::identify::{self, fit, report::ErrorStats, Conditioning};
use crate::io;
use crate::plot::{line_plot, Axis, Series};
use anyhow::{bail, Context, Result};
use friction_core::{
    CompensatorParams, CompensatorState, LuGreParams, ParameterAdaptiveParams, RlsParams, Setpoint,
    StribeckParams,
};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// What `friction online` reads and how it sets the estimators up.
#[derive(Clone, Debug)]
pub struct Options {
    /// The measured run.
    pub input: PathBuf,
    /// Output folder.
    pub output: PathBuf,
    /// Time, position and command columns; `force_gain` turns the command
    /// into force (a motor constant).
    pub columns: identify::Columns,
    /// The moving mass (or inertia) the drive's loop uses.
    pub mass: f64,
    /// Starting guess of the Coulomb level (both directions).
    pub coulomb: f64,
    /// Starting guess of the viscous coefficient.
    pub viscous: f64,
    /// Speed scale of the viscous regressors (the axis's rated speed);
    /// `None`: the run's peak speed.
    pub speed: Option<f64>,
    /// Slowest sample the estimators learn from; `None`: `speed / 50`.
    pub min_speed: Option<f64>,
    /// Rate (1/s) of the per-parameter estimator's prediction-error law.
    pub rate: f64,
    /// Forgetting factor of the least-squares feed-forward.
    pub forgetting: f64,
    /// Box factor of the per-parameter estimates around the guesses.
    pub box_factor: f64,
    /// A second run for the prediction comparison.
    pub validate: Option<PathBuf>,
}

/// Defaults of the options that have one.
pub mod defaults {
    /// `--rate` (1/s): a memory of about half a second for the levels.
    /// On the EMPS run, slower rates had not converged by its end (25 s)
    /// from guesses 2x off, faster ones followed the last seconds' motion
    /// (see the servo guide's online section).
    pub const RATE: f64 = 2.0;
    /// `--forgetting`: a memory of about 10 s at 1 kHz.
    pub const FORGETTING: f64 = 0.9999;
    /// `--box-factor`.
    pub const BOX_FACTOR: f64 = 5.0;
}

/// The run's samples as the drive saw them.
#[derive(Clone, Debug)]
pub struct Run {
    /// Time (s).
    pub t: Vec<f64>,
    /// Position.
    pub x: Vec<f64>,
    /// Command (the force column, before the gain).
    pub u: Vec<f64>,
}

/// The estimates over time, one row per sample.
#[derive(Clone, Debug, Default)]
pub struct Trace {
    /// Time (s).
    pub t: Vec<f64>,
    /// Per-parameter estimates `[Fc+, Fc-, Fs - Fc, sigma2, mu]`.
    pub adaptive: Vec<[f64; 5]>,
    /// Least-squares estimates `[Fc+, Fc-, sigma2]`.
    pub rls: Vec<[f64; 3]>,
}

/// The final figures of one estimator as a Coulomb-viscous law with an
/// offset.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Final {
    /// Coulomb level.
    pub coulomb: f64,
    /// Viscous coefficient.
    pub viscous: f64,
    /// Force offset (`(Fc+ - Fc-) / 2` for the per-direction levels).
    pub offset: f64,
}

/// The outcome of [`run`].
#[derive(Debug)]
pub struct Outcome {
    /// Estimates over time.
    pub trace: Trace,
    /// The per-parameter estimator's final figures.
    pub adaptive: Final,
    /// The least-squares feed-forward's final figures.
    pub rls: Final,
    /// The offline IDIM-LS fit's figures and its mass.
    pub offline: (Final, f64),
    /// Prediction errors on the validation run (offline, adaptive, rls).
    pub validation: Option<[ErrorStats; 3]>,
    /// The speed scale and minimum speed used.
    pub speeds: (f64, f64),
}

/// The speed scale: the peak of the backward-difference speed.
fn peak_speed(run: &Run) -> f64 {
    run.t
        .windows(2)
        .zip(run.x.windows(2))
        .map(|(t, x)| ((x[1] - x[0]) / (t[1] - t[0])).abs())
        .fold(0.0, f64::max)
}

/// The sample period the estimators are built for: the mean step.
fn period(run: &Run) -> f64 {
    let n = run.t.len();
    (run.t[n - 1] - run.t[0]) / (n - 1) as f64
}

/// The loop an estimator listens in: only the period, the mass and the
/// command's gain matter (no gains: the command is the drive's).
fn listening_loop(o: &Options, run: &Run) -> Result<CompensatorParams> {
    let limit = run.u.iter().fold(0.0, |m: f64, u| m.max(u.abs()));
    if limit == 0.0 {
        bail!("{}: the command is 0 throughout", o.input.display());
    }
    Ok(CompensatorParams {
        h: period(run),
        kp: 0.0,
        ki: 0.0,
        kd: 0.0,
        inertia: o.mass,
        torque_constant: o.columns.force_gain.abs(),
        // a clamp that never acts: the run's own largest command
        limit,
    })
}

/// Replays `run` through both estimators (the command's sign flipped when
/// the force gain is negative). Returns the trace and the speeds used.
pub fn replay(o: &Options, run: &Run) -> Result<(Trace, (f64, f64))> {
    let servo = listening_loop(o, run)?;
    let speed = o.speed.unwrap_or_else(|| peak_speed(run));
    if speed.is_nan() || speed <= 0.0 {
        bail!("{}: the axis never moves", o.input.display());
    }
    let min_speed = o.min_speed.unwrap_or(speed / 50.0);
    let model = LuGreParams {
        curve: StribeckParams {
            fc: o.coulomb,
            fs: o.coulomb,
            // the Stribeck excess spans the slowest speeds the law sees
            vs: min_speed,
            exponent: 2.0,
        },
        // a bristle that slides after a hundredth of the slowest learnt
        // sample's travel per period; the prediction law does not use it
        sigma0: o.coulomb / (0.01 * min_speed * servo.h),
        sigma1: 0.0,
        sigma2: o.viscous,
        vd: None,
    };
    let adaptive = ParameterAdaptiveParams {
        rate: 0.0,
        prediction_rate: o.rate,
        box_factor: o.box_factor,
        min_speed,
        speed,
        ..ParameterAdaptiveParams::new(model, 0.0)
    };
    let adaptive = servo
        .build(
            adaptive
                .build::<f64>(&servo)
                .context("the per-parameter estimator")?,
        )
        .context("the per-parameter estimator's loop")?;
    let rls_params = RlsParams {
        forgetting: o.forgetting,
        min_speed,
        initial_coulomb: o.coulomb,
        initial_viscous: o.viscous,
        // the offline fit's model: Coulomb, viscous and an offset
        offset: true,
        ..RlsParams::new(speed, 4.0 * o.columns.force_gain.abs() * servo.limit)
    };
    let rls = servo
        .build(
            rls_params
                .build::<f64>()
                .context("the least-squares feed-forward")?,
        )
        .context("the least-squares loop")?;
    let sign = o.columns.force_gain.signum();
    let mut sa = CompensatorState::default();
    let mut sr = CompensatorState::default();
    let mut trace = Trace::default();
    for ((&t, &x), &u) in run.t.iter().zip(&run.x).zip(&run.u) {
        adaptive.listen(&mut sa, x, Setpoint::default(), sign * u);
        rls.listen(&mut sr, x, Setpoint::default(), sign * u);
        trace.t.push(t);
        trace.adaptive.push(sa.friction().estimates());
        let (coulomb, viscous) = rls.compensation().coefficients(sr.friction());
        let offset = rls.compensation().offset(sr.friction());
        trace
            .rls
            .push([coulomb + offset, coulomb - offset, viscous]);
    }
    Ok((trace, (speed, min_speed)))
}

fn read_run(path: &Path, c: &identify::Columns) -> Result<Run> {
    let cols = identify::data::read_columns(path, &[&c.time, &c.position, &c.force])?;
    let mut data = cols.data.into_iter();
    let (t, x, u) = (
        data.next().unwrap_or_default(),
        data.next().unwrap_or_default(),
        data.next().unwrap_or_default(),
    );
    if t.len() < 3 {
        bail!(
            "{}: {} samples; online estimation needs at least 3",
            path.display(),
            t.len()
        );
    }
    identify::data::check_time(&t, &path.display().to_string(), &c.time)?;
    Ok(Run { t, x, u })
}

/// Checks the options a user sets, naming each by its command-line flag
/// (the shared validation layer, [`crate::checks`]).
pub fn check(o: &Options) -> Result<()> {
    use crate::checks::{args, ranges, within};
    within(args::MASS, o.mass, ranges::POSITIVE)?;
    within(args::COULOMB, o.coulomb, ranges::POSITIVE)?;
    within(args::VISCOUS, o.viscous, ranges::POSITIVE)?;
    if let Some(x) = o.speed {
        within(args::SPEED, x, ranges::POSITIVE)?;
    }
    if let Some(x) = o.min_speed {
        within(args::MIN_SPEED, x, ranges::POSITIVE)?;
    }
    within(args::RATE, o.rate, ranges::POSITIVE)?;
    within(args::FORGETTING, o.forgetting, ranges::FORGETTING)?;
    within(args::BOX_FACTOR, o.box_factor, ranges::BOX_FACTOR)?;
    Ok(())
}

/// [`run`], then the figures on stdout; `Ok(true)`: the run completed.
pub fn run_and_print(o: &Options) -> Result<bool> {
    let out = run(o)?;
    let (off, mass) = out.offline;
    crate::outln!(
        "online {}: {} samples; offline IDIM-LS Fc {:.4}, sigma2 {:.4}, offset {:.4}, mass {:.4}",
        o.input.display(),
        out.trace.t.len(),
        off.coulomb,
        off.viscous,
        off.offset,
        mass
    );
    for (name, f) in [("adaptive", out.adaptive), ("rls", out.rls)] {
        crate::outln!(
            "  {name:<8} Fc {:.4} ({:+.2} %), sigma2 {:.4} ({:+.2} %), offset {:.4}",
            f.coulomb,
            percent(f.coulomb, off.coulomb),
            f.viscous,
            percent(f.viscous, off.viscous),
            f.offset
        );
    }
    if let Some(v) = &out.validation {
        for (name, e) in ["offline", "adaptive", "rls"].iter().zip(v) {
            crate::outln!(
                "  validation {name:<8} RMS {:.4} ({:.3} %), {:.3}x offline",
                e.rms,
                e.relative,
                e.rms / v[0].rms
            );
        }
    }
    crate::outln!("wrote {}", o.output.display());
    Ok(true)
}

/// The outputs `run` writes.
const OUTPUTS: [&str; 3] = ["estimates.csv", "estimates.svg", "report.md"];

/// Replays the run, fits the offline yardstick, compares the predictions
/// on the validation run and writes `estimates.csv`, `estimates.svg` and
/// `report.md` into the output folder.
pub fn run(o: &Options) -> Result<Outcome> {
    check(o)?;
    let mut inputs: Vec<&Path> = vec![&o.input];
    if let Some(v) = &o.validate {
        inputs.push(v);
    }
    for name in OUTPUTS {
        io::refuse_overwrite("--output", &o.output.join(name), &inputs)?;
    }
    let data = read_run(&o.input, &o.columns)?;
    let (trace, speeds) = replay(o, &data)?;
    let last = |k: usize| trace.adaptive.last().map_or(0.0, |a| a[k]);
    let adaptive = Final {
        coulomb: 0.5 * (last(0) + last(1)),
        viscous: last(3),
        offset: 0.5 * (last(0) - last(1)),
    };
    let r = trace.rls.last().copied().unwrap_or_default();
    let rls = Final {
        coulomb: 0.5 * (r[0] + r[1]),
        viscous: r[2],
        offset: 0.5 * (r[0] - r[1]),
    };
    // the offline yardstick: IDIM-LS on the same run
    let conditioning = Conditioning::default();
    let s = identify::prepare(&o.input, &o.columns, &conditioning)?;
    let fo = fit::FitOptions {
        inertia: true,
        stribeck_exponent: 2.0,
        lugre_static: Default::default(),
    };
    let offline = fit::coulomb_viscous(&s, &fo)
        .map_err(|r| anyhow::anyhow!("the offline IDIM-LS fit failed: {}", r.reason))?;
    let offline_final = Final {
        coulomb: offline.get("fc").unwrap_or(f64::NAN),
        viscous: offline.get("sigma2").unwrap_or(f64::NAN),
        offset: offline.offset.unwrap_or(0.0),
    };
    let offline_mass = offline.mass.unwrap_or(f64::NAN);
    let as_fit = |f: Final| fit::Fit {
        friction: fit::Friction::CoulombViscous {
            fc: f.coulomb,
            sigma2: f.viscous,
        },
        mass: Some(o.mass),
        offset: Some(f.offset),
        params: Vec::new(),
        evaluations: 0,
        stages: Vec::new(),
    };
    let validation = match &o.validate {
        Some(path) => {
            let cond = Conditioning {
                cutoff: Some(s.cutoff),
                decimate: Some(s.decimate),
                ..conditioning
            };
            let v = identify::prepare(path, &o.columns, &cond)?;
            let stats = |f: &fit::Fit| -> Result<ErrorStats> {
                let p = f.predict(&v).context("prediction")?;
                Ok(ErrorStats::new(&v.f, &p))
            };
            Some([
                stats(&offline)?,
                stats(&as_fit(adaptive))?,
                stats(&as_fit(rls))?,
            ])
        }
        None => None,
    };
    let outcome = Outcome {
        trace,
        adaptive,
        rls,
        offline: (offline_final, offline_mass),
        validation,
        speeds,
    };
    write_outputs(o, &outcome)?;
    Ok(outcome)
}

fn write_outputs(o: &Options, out: &Outcome) -> Result<()> {
    std::fs::create_dir_all(&o.output)
        .with_context(|| format!("cannot create {}", o.output.display()))?;
    let tr = &out.trace;
    let col = |f: &dyn Fn(usize) -> f64| (0..tr.t.len()).map(f).collect::<Vec<f64>>();
    let columns = [
        tr.t.clone(),
        col(&|k| tr.adaptive[k][0]),
        col(&|k| tr.adaptive[k][1]),
        col(&|k| tr.adaptive[k][2]),
        col(&|k| tr.adaptive[k][3]),
        col(&|k| tr.rls[k][0]),
        col(&|k| tr.rls[k][1]),
        col(&|k| tr.rls[k][2]),
    ];
    let refs: Vec<&[f64]> = columns.iter().map(|c| c.as_slice()).collect();
    io::write_columns(
        &o.output.join("estimates.csv"),
        &[
            "t",
            "adaptive_fc_pos",
            "adaptive_fc_neg",
            "adaptive_stribeck",
            "adaptive_sigma2",
            "rls_fc_pos",
            "rls_fc_neg",
            "rls_sigma2",
        ],
        &refs,
    )?;
    estimates_plot(&o.output.join("estimates.svg"), out)?;
    io::write_bytes(&o.output.join("report.md"), report(o, out).as_bytes())
}

/// The Coulomb levels and the viscous coefficient (scaled into force at
/// the speed scale) over time, with the offline figures as flat lines.
fn estimates_plot(path: &Path, out: &Outcome) -> Result<()> {
    let tr = &out.trace;
    let step = (tr.t.len() / 4000).max(1);
    let speed = out.speeds.0;
    let pts = |f: &dyn Fn(usize) -> f64| -> Vec<(f64, f64)> {
        (0..tr.t.len())
            .step_by(step)
            .map(|k| (tr.t[k], f(k)))
            .collect()
    };
    let flat = |y: f64| vec![(tr.t[0], y), (tr.t[tr.t.len() - 1], y)];
    let (off, _) = out.offline;
    let series = [
        Series {
            label: "adaptive (Fc+ + Fc-)/2",
            points: pts(&|k| 0.5 * (tr.adaptive[k][0] + tr.adaptive[k][1])),
        },
        Series {
            label: "adaptive sigma2 x speed",
            points: pts(&|k| tr.adaptive[k][3] * speed),
        },
        Series {
            label: "rls (Fc+ + Fc-)/2",
            points: pts(&|k| 0.5 * (tr.rls[k][0] + tr.rls[k][1])),
        },
        Series {
            label: "rls sigma2 x speed",
            points: pts(&|k| tr.rls[k][2] * speed),
        },
        Series {
            label: "offline IDIM-LS Fc",
            points: flat(off.coulomb),
        },
        Series {
            label: "offline sigma2 x speed",
            points: flat(off.viscous * speed),
        },
    ];
    line_plot(
        path,
        "online estimates (causal) against the offline fit",
        ("t (s)", Axis::Linear),
        "force",
        &series,
    )
}

/// `100 (x - reference) / reference`.
pub fn percent(x: f64, reference: f64) -> f64 {
    100.0 * (x - reference) / reference
}

fn report(o: &Options, out: &Outcome) -> String {
    let (off, mass) = out.offline;
    let mut m = String::new();
    let _ = writeln!(
        m,
        "# Online estimation: `{}`\n\nReplayed causally at the run's sample rate \
         (`Compensator::listen`), mass {} (given), speed scale {:.4}, minimum speed {:.4}, \
         starting from Fc {} and sigma2 {}.\n",
        o.input.display(),
        o.mass,
        out.speeds.0,
        out.speeds.1,
        o.coulomb,
        o.viscous
    );
    let _ = writeln!(
        m,
        "| estimator | Fc | sigma2 | offset | Fc vs offline | sigma2 vs offline |"
    );
    let _ = writeln!(m, "|---|---|---|---|---|---|");
    let _ = writeln!(
        m,
        "| offline IDIM-LS (mass {mass:.4}) | {:.4} | {:.4} | {:.4} | | |",
        off.coulomb, off.viscous, off.offset
    );
    for (name, f) in [("adaptive (per parameter)", out.adaptive), ("rls", out.rls)] {
        let _ = writeln!(
            m,
            "| {name} | {:.4} | {:.4} | {:.4} | {:+.2} % | {:+.2} % |",
            f.coulomb,
            f.viscous,
            f.offset,
            percent(f.coulomb, off.coulomb),
            percent(f.viscous, off.viscous)
        );
    }
    if let (Some(v), Some(path)) = (&out.validation, &o.validate) {
        let _ = writeln!(
            m,
            "\nForce predicted on `{}` (zero-phase filtered and decimated as `identify` \
             compares; RMS of measured minus predicted):\n",
            path.display()
        );
        let _ = writeln!(m, "| model | RMS | relative | vs offline |");
        let _ = writeln!(m, "|---|---|---|---|");
        for (name, s) in ["offline IDIM-LS", "adaptive", "rls"].iter().zip(v) {
            let _ = writeln!(
                m,
                "| {name} | {:.4} | {:.3} % | {:.3}x |",
                s.rms,
                s.relative,
                s.rms / v[0].rms
            );
        }
    }
    m
}
