//! `friction servo`: a position servo against a simulated plant, with each
//! friction compensation of the core's [`Compensator`].
//!
//! The plant is an inertia `J` driven through a torque constant `kc`,
//! `J dv/dt = kc u - F`, with the friction `F` of the parameter file's model
//! stepped by the core (f64) at `plant_rate` (semi-implicit Euler, velocity
//! held over each step). The controller is the core's compensator at `rate`
//! (PID on `e = x - x_ref`, acceleration feed-forward, measured velocity the
//! backward difference of the sampled position), its command held over the
//! period. Compensations: `nofriction` (the plant without friction: the
//! floor), `none`, `static` (Coulomb + viscous feed-forward from the nominal
//! parameters on the measured velocity), `observer` (the nominal model),
//! `observer+50` / `observer-50` (the observer's `fc` and `fs` scaled by 1.5
//! and 0.5, and `z_ba` with them for elasto-plastic: the robustness check of
//! Olsson et al. 1998) and `observer-nodamping` (without `sigma1 dz^/dt`).
//! The observer rows need an observable model (`lugre`, `elasto-plastic`,
//! `gms`, `xiong`, `leuven`); for the others they are skipped with a note.
//!
//! Defaults reproduce Olsson et al. 1998 (Table 2 LuGre, `J = 0.0023`,
//! `kc = 1.02`, reference `0.5 sin(2 pi 0.2 t)` rad for 20 s, PID at 1 kHz
//! with `kp = 60`, `ki = 200`, `kd = 1.2`, observer gain 20 1/s, plant at
//! 100 kHz); each is a key of the file's `[servo]` table. RMS and maximum
//! tracking errors are taken over the last 90 % of the run.

use crate::io::write_columns;
use crate::models::{GmsSpec, LeuvenSpec, XiongSpec};
use crate::params::{ModelSpec, ParamFile};
use crate::plot::{line_plot, Axis, Series};
use anyhow::{Context, Result};
use friction_core::{
    Compensation, CompensatorParams, CompensatorState, CoulombViscousParams, ElastoPlasticParams,
    FeedForward, GmsParams, LuGreParams, NoCompensation, Observable, Observer, ParamError,
    Setpoint, XiongParams,
};
use serde::Deserialize;
use std::fmt::Write as _;
use std::path::Path;

/// The `[servo]` table of a parameter file: every key optional, unknown
/// keys rejected by the loader.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ServoTable {
    /// Inertia `J` (kg m^2) of the plant and of the acceleration feed-forward.
    pub inertia: Option<f64>,
    /// Torque constant `kc` (N m per command unit).
    pub torque_constant: Option<f64>,
    /// Amplitude of the reference sine (rad).
    pub amplitude: Option<f64>,
    /// Frequency of the reference sine (Hz).
    pub frequency: Option<f64>,
    /// Length of the run (s).
    pub duration: Option<f64>,
    /// Controller rate (Hz).
    pub rate: Option<f64>,
    /// Plant integration rate (Hz), a whole multiple of `rate`.
    pub plant_rate: Option<f64>,
    /// Proportional gain.
    pub kp: Option<f64>,
    /// Integral gain.
    pub ki: Option<f64>,
    /// Derivative gain (on the error).
    pub kd: Option<f64>,
    /// Observer correction gain (1/s).
    pub observer_gain: Option<f64>,
    /// Command limit (command units).
    pub limit: Option<f64>,
}

/// The servo set-up with every default filled in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ServoConfig {
    /// `inertia` (kg m^2).
    pub inertia: f64,
    /// `torque_constant` (N m per command unit).
    pub torque_constant: f64,
    /// `amplitude` (rad).
    pub amplitude: f64,
    /// `frequency` (Hz).
    pub frequency: f64,
    /// `duration` (s).
    pub duration: f64,
    /// `rate` (Hz).
    pub rate: f64,
    /// `plant_rate` (Hz).
    pub plant_rate: f64,
    /// `kp`.
    pub kp: f64,
    /// `ki`.
    pub ki: f64,
    /// `kd`.
    pub kd: f64,
    /// `observer_gain` (1/s).
    pub observer_gain: f64,
    /// `limit`.
    pub limit: f64,
}

impl Default for ServoConfig {
    /// Olsson et al. 1998.
    fn default() -> Self {
        Self {
            inertia: 0.0023,
            torque_constant: 1.02,
            amplitude: 0.5,
            frequency: 0.2,
            duration: 20.0,
            rate: 1e3,
            plant_rate: 1e5,
            kp: 60.0,
            ki: 200.0,
            kd: 1.2,
            observer_gain: 20.0,
            limit: 10.0,
        }
    }
}

/// The most plant steps (`duration x plant_rate`) one run may take.
pub const MAX_PLANT_STEPS: f64 = 2e7;

/// The most controller ticks (`duration x rate`) one run may take: the
/// trace keeps two columns per compensation per tick.
pub const MAX_TICKS: f64 = 2e6;

/// Why a `[servo]` table was rejected: each variant names the file and the key.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ServoError {
    /// A key's value is out of its range.
    #[error("{file}: [servo] `{key}` must be {rule}, got {value}")]
    Invalid {
        /// The parameter file.
        file: String,
        /// The key.
        key: &'static str,
        /// What it must be.
        rule: &'static str,
        /// What it was.
        value: f64,
    },
    /// `plant_rate` is not a whole multiple of `rate`.
    #[error("{file}: [servo] `plant_rate` ({plant_rate} Hz) must be a whole multiple of `rate` ({rate} Hz)")]
    NotMultiple {
        /// The parameter file.
        file: String,
        /// `plant_rate`.
        plant_rate: f64,
        /// `rate`.
        rate: f64,
    },
    /// The run would take more plant steps than [`MAX_PLANT_STEPS`].
    #[error("{file}: [servo] `duration` x `plant_rate` = {steps:.3e} plant steps exceeds the cap of {cap:.0e}: shorten `duration` or lower `plant_rate`")]
    TooManySteps {
        /// The parameter file.
        file: String,
        /// `duration x plant_rate`.
        steps: f64,
        /// [`MAX_PLANT_STEPS`].
        cap: f64,
    },
    /// The run would take more controller ticks than [`MAX_TICKS`].
    #[error("{file}: [servo] `duration` x `rate` = {ticks:.3e} ticks exceeds the cap of {cap:.0e}: shorten `duration` or lower `rate`")]
    TooManyTicks {
        /// The parameter file.
        file: String,
        /// `duration x rate`.
        ticks: f64,
        /// [`MAX_TICKS`].
        cap: f64,
    },
    /// The closed loop diverged: a tracking error is not finite.
    #[error("{file}: the closed loop diverged with compensation `{name}` (tracking error not finite): check [servo] `inertia`, `amplitude` and the gains")]
    Diverged {
        /// The parameter file.
        file: String,
        /// The compensation.
        name: String,
    },
    /// The controller rejected its parameters (named by the core).
    #[error("{file}: [servo] controller: {error}")]
    Controller {
        /// The parameter file.
        file: String,
        /// The core's error.
        error: ParamError,
    },
}

impl ServoTable {
    /// Fills in the defaults and checks every key; `file` names the source.
    pub fn resolve(&self, file: &str) -> Result<ServoConfig, ServoError> {
        let d = ServoConfig::default();
        let c = ServoConfig {
            inertia: self.inertia.unwrap_or(d.inertia),
            torque_constant: self.torque_constant.unwrap_or(d.torque_constant),
            amplitude: self.amplitude.unwrap_or(d.amplitude),
            frequency: self.frequency.unwrap_or(d.frequency),
            duration: self.duration.unwrap_or(d.duration),
            rate: self.rate.unwrap_or(d.rate),
            plant_rate: self.plant_rate.unwrap_or(d.plant_rate),
            kp: self.kp.unwrap_or(d.kp),
            ki: self.ki.unwrap_or(d.ki),
            kd: self.kd.unwrap_or(d.kd),
            observer_gain: self.observer_gain.unwrap_or(d.observer_gain),
            limit: self.limit.unwrap_or(d.limit),
        };
        let invalid = |key, rule, value| ServoError::Invalid {
            file: file.to_string(),
            key,
            rule,
            value,
        };
        for (key, value, positive) in [
            ("inertia", c.inertia, true),
            ("torque_constant", c.torque_constant, true),
            ("amplitude", c.amplitude, false),
            ("frequency", c.frequency, false),
            ("duration", c.duration, true),
            ("rate", c.rate, true),
            ("plant_rate", c.plant_rate, true),
            ("kp", c.kp, false),
            ("ki", c.ki, false),
            ("kd", c.kd, false),
            ("observer_gain", c.observer_gain, false),
            ("limit", c.limit, true),
        ] {
            let (ok, rule) = if positive {
                (value > 0.0, "a finite number > 0")
            } else {
                (value >= 0.0, "a finite number >= 0")
            };
            if !(ok && value.is_finite()) {
                return Err(invalid(key, rule, value));
            }
        }
        if c.duration * c.rate < 10.0 {
            return Err(invalid(
                "duration",
                "at least 10 controller periods",
                c.duration,
            ));
        }
        let ratio = c.plant_rate / c.rate;
        if ratio < 1.0 || (ratio - ratio.round()).abs() > 1e-9 * ratio {
            return Err(ServoError::NotMultiple {
                file: file.to_string(),
                plant_rate: c.plant_rate,
                rate: c.rate,
            });
        }
        let steps = c.duration * c.plant_rate;
        if steps > MAX_PLANT_STEPS {
            return Err(ServoError::TooManySteps {
                file: file.to_string(),
                steps,
                cap: MAX_PLANT_STEPS,
            });
        }
        let ticks = c.duration * c.rate;
        if ticks > MAX_TICKS {
            return Err(ServoError::TooManyTicks {
                file: file.to_string(),
                ticks,
                cap: MAX_TICKS,
            });
        }
        c.controller()
            .validate()
            .map_err(|error| ServoError::Controller {
                file: file.to_string(),
                error,
            })?;
        Ok(c)
    }
}

impl ServoConfig {
    /// The core compensator's parameters.
    pub fn controller(&self) -> CompensatorParams {
        CompensatorParams {
            h: 1.0 / self.rate,
            kp: self.kp,
            ki: self.ki,
            kd: self.kd,
            inertia: self.inertia,
            torque_constant: self.torque_constant,
            limit: self.limit,
        }
    }
}

/// One compensation's run.
#[derive(Clone, Debug)]
pub struct ServoRun {
    /// Its name (`none`, `observer+50`, ...).
    pub name: &'static str,
    /// RMS tracking error over the last 90 % (rad).
    pub rms: f64,
    /// Largest tracking error over the last 90 % (rad).
    pub max: f64,
    /// Tracking error `x - x_ref` at each controller tick (rad).
    pub error: Vec<f64>,
    /// Friction estimate or feed-forward at each tick (N m).
    pub friction: Vec<f64>,
}

/// The whole benchmark.
#[derive(Clone, Debug)]
pub struct ServoBenchmark {
    /// The set-up.
    pub config: ServoConfig,
    /// Controller tick times (s).
    pub t: Vec<f64>,
    /// Reference position at each tick (rad).
    pub x_ref: Vec<f64>,
    /// The runs, in the order of [`NAMES`] (observer rows only for observable models).
    pub runs: Vec<ServoRun>,
    /// Why rows were skipped, if any.
    pub note: Option<String>,
}

/// Every compensation, in order.
pub const NAMES: [&str; 7] = [
    "nofriction",
    "none",
    "static",
    "observer",
    "observer+50",
    "observer-50",
    "observer-nodamping",
];

struct Plant {
    friction: Option<Box<dyn crate::models::Stepper>>,
    x: f64,
    v: f64,
}

fn simulate<C: Compensation<f64>>(
    name: &'static str,
    cfg: &ServoConfig,
    spec: Option<&ModelSpec>,
    compensation: C,
) -> Result<ServoRun> {
    let ctl = cfg
        .controller()
        .build::<f64, C>(compensation)
        .with_context(|| format!("controller of `{name}`"))?;
    let mut state = CompensatorState::default();
    let mut plant = Plant {
        friction: match spec {
            Some(s) => Some(s.stepper(crate::models::ScalarKind::F64)?),
            None => None,
        },
        x: 0.0,
        v: 0.0,
    };
    let n = ticks(cfg);
    let substeps = (cfg.plant_rate / cfg.rate).round() as usize;
    let hp = 1.0 / cfg.plant_rate;
    let (mut error, mut friction) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for k in 0..n {
        let r = setpoint(cfg, k as f64 / cfg.rate);
        let tick = ctl.tick(&mut state, plant.x, r);
        error.push(plant.x - r.x);
        friction.push(tick.friction);
        let torque = cfg.torque_constant * tick.command;
        for _ in 0..substeps {
            let f = plant.friction.as_mut().map_or(0.0, |m| m.step(plant.v, hp));
            plant.v += hp * (torque - f) / cfg.inertia;
            plant.x += hp * plant.v;
        }
    }
    let tail = &error[n / 10..];
    let rms = (tail.iter().map(|e| e * e).sum::<f64>() / tail.len().max(1) as f64).sqrt();
    let max = tail.iter().fold(0.0f64, |m, e| m.max(e.abs()));
    Ok(ServoRun {
        name,
        rms,
        max,
        error,
        friction,
    })
}

fn ticks(cfg: &ServoConfig) -> usize {
    (cfg.duration * cfg.rate).round() as usize
}

fn setpoint(cfg: &ServoConfig, t: f64) -> Setpoint<f64> {
    let w = 2.0 * std::f64::consts::PI * cfg.frequency;
    let (s, c) = (w * t).sin_cos();
    Setpoint {
        x: cfg.amplitude * s,
        v: cfg.amplitude * w * c,
        a: -cfg.amplitude * w * w * s,
    }
}

/// The Coulomb level of the static feed-forward: the model's sliding
/// friction at high speed less its viscous part ([`crate::models::HostModel::coulomb_level`]).
pub fn coulomb_level(spec: &ModelSpec) -> f64 {
    spec.host().coulomb_level()
}

fn scaled(p: &LuGreParams, s: f64) -> LuGreParams {
    let mut q = *p;
    q.curve.fc *= s;
    q.curve.fs *= s;
    q
}

/// The four observer rows around models built by `build(scale)`.
fn observer_runs<M: Observable<f64>>(
    cfg: &ServoConfig,
    spec: &ModelSpec,
    build: impl Fn(f64) -> Result<M, ParamError>,
) -> Result<Vec<ServoRun>> {
    let observer =
        |s: f64| -> Result<Observer<M, f64>> { Ok(Observer::new(build(s)?, cfg.observer_gain)?) };
    Ok(vec![
        simulate("observer", cfg, Some(spec), observer(1.0)?)?,
        simulate("observer+50", cfg, Some(spec), observer(1.5)?)?,
        simulate("observer-50", cfg, Some(spec), observer(0.5)?)?,
        simulate(
            "observer-nodamping",
            cfg,
            Some(spec),
            observer(1.0)?.with_damping(false),
        )?,
    ])
}

/// The four observer rows of a GMS model with `K` elements (`fc`, `fs` scaled).
fn gms_observer_runs<const K: usize>(
    cfg: &ServoConfig,
    spec: &ModelSpec,
    g: &GmsSpec,
) -> Result<Vec<ServoRun>> {
    let p: GmsParams<K> = g.params().context("GMS element count")?;
    observer_runs(cfg, spec, |s| {
        let mut q = p;
        q.curve.fc *= s;
        q.curve.fs *= s;
        q.build()
    })
}

/// The four observer rows of a Xiong model with `K` elements (`fc`, `fs` scaled).
fn xiong_observer_runs<const K: usize>(
    cfg: &ServoConfig,
    spec: &ModelSpec,
    x: &XiongSpec,
) -> Result<Vec<ServoRun>> {
    let p: XiongParams<K> = x.params().context("Xiong element count")?;
    observer_runs(cfg, spec, |s| {
        let mut q = p;
        q.curve.fc *= s;
        q.curve.fs *= s;
        q.build()
    })
}

/// The four observer rows of a Leuven model with memory `M` (`fc`, `fs` scaled).
fn leuven_observer_runs<const M: usize>(
    cfg: &ServoConfig,
    spec: &ModelSpec,
    l: &LeuvenSpec,
) -> Result<Vec<ServoRun>> {
    observer_runs(cfg, spec, |s| {
        let mut q = l.params;
        q.curve.fc *= s;
        q.curve.fs *= s;
        q.build::<f64, M>()
    })
}

/// Calls `$f::<K>(args)` with the element count `K` (1 to 16, as the host
/// dispatches GMS and Xiong).
macro_rules! with_elements {
    ($n:expr, $f:ident($($arg:expr),*)) => {
        match $n {
            1 => $f::<1>($($arg),*),
            2 => $f::<2>($($arg),*),
            3 => $f::<3>($($arg),*),
            4 => $f::<4>($($arg),*),
            5 => $f::<5>($($arg),*),
            6 => $f::<6>($($arg),*),
            7 => $f::<7>($($arg),*),
            8 => $f::<8>($($arg),*),
            9 => $f::<9>($($arg),*),
            10 => $f::<10>($($arg),*),
            11 => $f::<11>($($arg),*),
            12 => $f::<12>($($arg),*),
            13 => $f::<13>($($arg),*),
            14 => $f::<14>($($arg),*),
            15 => $f::<15>($($arg),*),
            16 => $f::<16>($($arg),*),
            n => anyhow::bail!("{n} elements: the host runs 1 to 16"),
        }
    };
}

/// Runs every compensation for the parameter file (`origin` names it in errors).
pub fn benchmark(file: &ParamFile, origin: &str) -> Result<ServoBenchmark> {
    let cfg = file.servo.resolve(origin)?;
    let spec = &file.model;
    let nominal = CoulombViscousParams {
        fc: coulomb_level(spec),
        sigma2: spec.sigma2(),
    }
    .build::<f64>()?;
    let mut runs = vec![
        simulate("nofriction", &cfg, None, NoCompensation)?,
        simulate("none", &cfg, Some(spec), NoCompensation)?,
        simulate("static", &cfg, Some(spec), FeedForward(nominal))?,
    ];
    let mut note = None;
    match spec {
        ModelSpec::LuGre(p) => runs.extend(observer_runs(&cfg, spec, |s| scaled(p, s).build())?),
        ModelSpec::ElastoPlastic(p) => runs.extend(observer_runs(&cfg, spec, |s| {
            ElastoPlasticParams {
                lugre: scaled(&p.lugre, s),
                z_ba: p.z_ba * s,
            }
            .build()
        })?),
        ModelSpec::Gms(g) => runs.extend(with_elements!(
            g.elements.len(),
            gms_observer_runs(&cfg, spec, g)
        )?),
        ModelSpec::Xiong(x) => runs.extend(with_elements!(
            x.elements.len(),
            xiong_observer_runs(&cfg, spec, x)
        )?),
        ModelSpec::Leuven(l) => runs.extend(crate::models::leuven::with_memory!(
            l.memory,
            leuven_observer_runs;
            &cfg,
            spec,
            l
        )?),
        other => {
            note = Some(format!(
                "observer rows skipped: `{}` has no observer form (observable models: lugre, elasto-plastic, gms, xiong, leuven)",
                other.name()
            ))
        }
    }
    if let Some(r) = runs
        .iter()
        .find(|r| !(r.rms.is_finite() && r.max.is_finite()))
    {
        return Err(ServoError::Diverged {
            file: origin.to_string(),
            name: r.name.to_string(),
        }
        .into());
    }
    let n = ticks(&cfg);
    let t: Vec<f64> = (0..n).map(|k| k as f64 / cfg.rate).collect();
    let x_ref = t.iter().map(|&ti| setpoint(&cfg, ti).x).collect();
    Ok(ServoBenchmark {
        config: cfg,
        t,
        x_ref,
        runs,
        note,
    })
}

impl ServoBenchmark {
    /// The run called `name`.
    pub fn run(&self, name: &str) -> Option<&ServoRun> {
        self.runs.iter().find(|r| r.name == name)
    }

    /// One line per compensation: `servo NAME RMS_MRAD MAX_MRAD`.
    pub fn lines(&self) -> Vec<String> {
        self.runs
            .iter()
            .map(|r| format!("servo {} {:.4} {:.4}", r.name, 1e3 * r.rms, 1e3 * r.max))
            .collect()
    }

    fn setup(&self) -> String {
        let c = &self.config;
        format!(
            "J = {} kg m^2, kc = {} N m/A, reference {} sin(2 pi {} t) rad for {} s; PID at {} Hz \
             (kp = {}, ki = {}, kd = {}, limit {} A), observer gain {} 1/s; plant at {} Hz; errors over the last 90 %",
            c.inertia,
            c.torque_constant,
            c.amplitude,
            c.frequency,
            c.duration,
            c.rate,
            c.kp,
            c.ki,
            c.kd,
            c.limit,
            c.observer_gain,
            c.plant_rate
        )
    }

    /// The results as a plain-text table.
    pub fn table(&self) -> String {
        let none = self.run("none").map_or(f64::NAN, |r| r.rms);
        let mut s = format!(
            "{:<20} {:>12} {:>12} {:>10}\n",
            "compensation", "rms [mrad]", "max [mrad]", "rms/none"
        );
        for r in &self.runs {
            let _ = writeln!(
                s,
                "{:<20} {:>12.4} {:>12.4} {:>10.3}",
                r.name,
                1e3 * r.rms,
                1e3 * r.max,
                r.rms / none
            );
        }
        s
    }

    /// The results as a Markdown section body (set-up, table, note).
    pub fn markdown(&self) -> String {
        let none = self.run("none").map_or(f64::NAN, |r| r.rms);
        let mut md = format!("{}.\n\n", self.setup());
        md.push_str("| compensation | rms (mrad) | max (mrad) | rms / none |\n|---|---|---|---|\n");
        for r in &self.runs {
            let _ = writeln!(
                md,
                "| {} | {:.4} | {:.4} | {:.3} |",
                r.name,
                1e3 * r.rms,
                1e3 * r.max,
                r.rms / none
            );
        }
        if let Some(note) = &self.note {
            let _ = writeln!(md, "\n{note}.");
        }
        md
    }

    /// Writes `dir/trace.csv` (t, x_ref, then `e_NAME` in rad and `fhat_NAME`
    /// in N m for each compensation) and two SVG plots of the tracking
    /// errors (`errors.svg`, `observer.svg`); returns the plot paths.
    pub fn write(&self, dir: &Path) -> Result<Vec<std::path::PathBuf>> {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        let mut headers = vec!["t".to_string(), "x_ref".to_string()];
        let mut cols: Vec<&[f64]> = vec![&self.t, &self.x_ref];
        for r in &self.runs {
            headers.push(format!("e_{}", r.name));
            cols.push(&r.error);
        }
        for r in &self.runs {
            headers.push(format!("fhat_{}", r.name));
            cols.push(&r.friction);
        }
        let headers: Vec<&str> = headers.iter().map(String::as_str).collect();
        write_columns(&dir.join("trace.csv"), &headers, &cols)?;
        let series = |names: &[&str]| -> Vec<(String, Vec<(f64, f64)>)> {
            names
                .iter()
                .filter_map(|n| self.run(n))
                .map(|r| {
                    (
                        r.name.to_string(),
                        self.t
                            .iter()
                            .zip(&r.error)
                            .map(|(&t, &e)| (t, 1e3 * e))
                            .collect(),
                    )
                })
                .collect()
        };
        let mut plots = Vec::new();
        for (file, title, names) in [
            (
                "errors.svg",
                "Tracking error by compensation",
                &["nofriction", "none", "static", "observer"][..],
            ),
            (
                "observer.svg",
                "Observer: nominal, Fc and Fs +/-50 %, without sigma1 dz/dt",
                &[
                    "nofriction",
                    "observer",
                    "observer+50",
                    "observer-50",
                    "observer-nodamping",
                ][..],
            ),
        ] {
            let data = series(names);
            if data.is_empty() {
                continue;
            }
            let s: Vec<Series> = data
                .iter()
                .map(|(label, points)| Series {
                    label,
                    points: points.clone(),
                })
                .collect();
            let path = dir.join(file);
            line_plot(
                &path,
                title,
                ("t [s]", Axis::Linear),
                "x - x_ref [mrad]",
                &s,
            )?;
            plots.push(path);
        }
        Ok(plots)
    }
}

/// `friction servo`: runs, prints the lines and the table, writes the trace
/// and plots. `params` = `None` uses the built-in `olsson1998-servo` set.
pub fn run(params: Option<&Path>, output: &Path) -> Result<bool> {
    if let Some(p) = params {
        for name in ["trace.csv", "errors.svg", "observer.svg"] {
            crate::io::refuse_overwrite("--output", &output.join(name), &[p])?;
        }
    }
    let (file, origin) = match params {
        Some(p) => (ParamFile::load(p)?, p.display().to_string()),
        None => (
            crate::validate::param_set("olsson1998-servo")?,
            "params/olsson1998-servo.toml".to_string(),
        ),
    };
    let bench = benchmark(&file, &origin)?;
    for line in bench.lines() {
        println!("{line}");
    }
    println!();
    print!("{}", bench.table());
    if let Some(note) = &bench.note {
        println!("note: {note}");
    }
    let plots = bench.write(output)?;
    println!("trace: {}", output.join("trace.csv").display());
    for p in plots {
        println!("plot:  {}", p.display());
    }
    Ok(true)
}

/// The servo section of the validation report: the default benchmark on the
/// built-in `olsson1998-servo` set, as Markdown (heading included).
pub fn report_section() -> Result<String> {
    let file = crate::validate::param_set("olsson1998-servo")?;
    let bench = benchmark(&file, "params/olsson1998-servo.toml")?;
    Ok(format!(
        "\n## Servo benchmark (`friction servo`)\n\n{}",
        bench.markdown()
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn servo_keys_are_checked_and_named() {
        let ok = ServoTable::default().resolve("p.toml").unwrap();
        assert_eq!(ok, ServoConfig::default());
        let e = ServoTable {
            kp: Some(-1.0),
            ..Default::default()
        }
        .resolve("p.toml")
        .unwrap_err();
        assert!(matches!(e, ServoError::Invalid { key: "kp", .. }), "{e:?}");
        assert!(e.to_string().starts_with("p.toml: [servo] `kp`"), "{e}");
        let e = ServoTable {
            inertia: Some(0.0),
            ..Default::default()
        }
        .resolve("p.toml")
        .unwrap_err();
        assert!(matches!(e, ServoError::Invalid { key: "inertia", .. }));
        let e = ServoTable {
            frequency: Some(f64::NAN),
            ..Default::default()
        }
        .resolve("p.toml")
        .unwrap_err();
        assert!(matches!(
            e,
            ServoError::Invalid {
                key: "frequency",
                ..
            }
        ));
        let e = ServoTable {
            plant_rate: Some(1500.0),
            ..Default::default()
        }
        .resolve("p.toml")
        .unwrap_err();
        assert!(matches!(e, ServoError::NotMultiple { .. }), "{e:?}");
        let e = ServoTable {
            duration: Some(1e4),
            ..Default::default()
        }
        .resolve("p.toml")
        .unwrap_err();
        assert!(matches!(e, ServoError::TooManySteps { .. }), "{e:?}");
        assert!(e.to_string().contains("`duration` x `plant_rate`"), "{e}");
    }

    #[test]
    fn servo_table_parses_and_rejects_unknown_keys() {
        let text = include_str!("../../params/olsson1998-servo.toml");
        let f = ParamFile::parse(
            &format!("{text}\n[servo]\nduration = 2\nkp = 50\n"),
            "p.toml",
        )
        .unwrap();
        assert_eq!(f.servo.duration, Some(2.0));
        assert_eq!(f.servo.kp, Some(50.0));
        let e = ParamFile::parse(&format!("{text}\n[servo]\nkpp = 50\n"), "p.toml").unwrap_err();
        let e = format!("{e:#}");
        assert!(e.contains("kpp") && e.contains("p.toml"), "{e}");
    }

    #[test]
    fn static_maps_get_three_rows_and_a_note() {
        let f = ParamFile::parse(
            "model = \"coulomb-viscous\"\nfc = 0.28\nsigma2 = 0.0176\n[servo]\nduration = 1\nplant_rate = 10000\n",
            "c.toml",
        )
        .unwrap();
        let b = benchmark(&f, "c.toml").unwrap();
        let names: Vec<_> = b.runs.iter().map(|r| r.name).collect();
        assert_eq!(names, ["nofriction", "none", "static"]);
        assert!(b.note.as_deref().unwrap().contains("coulomb-viscous"));
        // the exact static compensation of a static plant beats none
        assert!(b.run("static").unwrap().rms < b.run("none").unwrap().rms);
    }
}
