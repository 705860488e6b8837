//! `friction commission`: the core's [`Commissioning`] routine run against a
//! parameter file's plant (the simulated drive of `friction servo`, every
//! `[servo]` key included), then the servo benchmark with the commissioned
//! model against that plant.
//!
//! The routine's window and speeds come from the file's `[commission]`
//! table; unset keys default to a travel of twice the servo's amplitude, a
//! top speed of three times its peak speed (slower where a plateau at it
//! would not fit the travel), the slowest plateau at a
//! thousandth of it or where a block of 8 ticks spans 4 encoder counts
//! (whichever is faster), 10 speeds and 30 s. The loop is the file's PID.
//!
//! Outputs: `parameters.csv` (`name,true,identified,relative_error`; the
//! true values are the file's model, which for a `plant_bam` file is the
//! zero-load curve a user would have), `commissioned.toml`, `run.csv` (the
//! routine's command and position), `trace.csv` (the benchmark's `e_NAME`
//! columns), `excitation.svg`, `curve.svg`, `errors.svg` and `report.md`.

use crate::io::write_columns;
use crate::models::ModelSpec;
use crate::params::servo::ServoConfig;
use crate::params::ParamFile;
use crate::plot::{line_plot, Axis, Series};
use crate::servo::{build_controller, run_loop, Drive, Law, Row, ServoRun};
use anyhow::{anyhow, bail, Context, Result};
use friction_core::{
    Commissioned, Commissioning, CommissioningParams, CommissioningPhase, CommissioningState,
    LuGreParams, ParamError, PlateauPoint, StribeckMapParams,
};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The rows of the benchmark, in order.
pub const ROWS: [&str; 5] = [
    "none",
    "static",
    "observer",
    "commissioned",
    "commissioned-adaptive",
];

/// The files `friction commission` writes into its output folder.
pub const OUTPUTS: [&str; 8] = [
    "parameters.csv",
    "commissioned.toml",
    "run.csv",
    "trace.csv",
    "excitation.svg",
    "curve.svg",
    "errors.svg",
    "report.md",
];

/// One commissioning run and its benchmark.
pub struct CommissionRun {
    /// The routine's settings.
    pub settings: CommissioningParams,
    /// Tick times (s), commands and true positions of the routine.
    pub t: Vec<f64>,
    /// The commands.
    pub command: Vec<f64>,
    /// The true positions.
    pub position: Vec<f64>,
    /// The fitted result.
    pub result: Commissioned,
    /// The plateaus measured (the fit used the steady ones).
    pub points: Vec<PlateauPoint>,
    /// The file's model as LuGre (the "true" column).
    pub reference: LuGreParams,
    /// The benchmark's rows, in the order of [`ROWS`] (no `observer` for a
    /// static map).
    pub runs: Vec<ServoRun>,
    /// The benchmark's tick times.
    pub trace_t: Vec<f64>,
    /// What the benchmark's set-up chose for the user (the coarse
    /// encoder's velocity), if anything.
    pub note: Option<String>,
}

/// The routine's settings for the file: the `[commission]` keys over the
/// defaults of the module docs.
pub fn settings(file: &ParamFile, cfg: &ServoConfig) -> CommissioningParams {
    let table = file.commission;
    let h = 1.0 / cfg.rate;
    let count = if cfg.encoder_counts > 0.0 {
        std::f64::consts::TAU / cfg.encoder_counts
    } else {
        0.0
    };
    let travel = table.travel.unwrap_or(2.0 * cfg.amplitude);
    let settings = |max_speed: f64| {
        let mut p = CommissioningParams::new(cfg.controller(), travel, max_speed);
        p.min_speed = table
            .min_speed
            .unwrap_or_else(|| (max_speed / 1000.0).max(count / (2.0 * h)).min(max_speed));
        p.speeds = table.speeds.unwrap_or(p.speeds);
        p.duration = table.duration.unwrap_or(p.duration);
        p.resolution = count;
        p.breakaway_travel = (travel / 100.0).max(8.0 * count).min(0.5 * travel);
        p
    };
    if let Some(max_speed) = table.max_speed {
        return settings(max_speed);
    }
    // three times the servo's peak speed, or slower until a plateau at the
    // top speed fits the travel
    let mut max_speed = 3.0 * cfg.peak_speed();
    for _ in 0..40 {
        let p = settings(max_speed);
        match p.validate() {
            Err(ParamError::NotBelow {
                name: "max_speed", ..
            }) => max_speed *= 0.8,
            _ => return p,
        }
    }
    settings(max_speed)
}

/// Runs the routine on the file's plant; `progress` prints each phase and
/// plateau to stderr.
pub fn commission(file: &ParamFile, origin: &str, progress: bool) -> Result<CommissionRun> {
    let cfg = file.servo.resolve(origin)?;
    let settings = settings(file, &cfg);
    let routine: Commissioning<f64> = settings
        .build()
        .map_err(|e| anyhow!("{origin}: [commission] {e}"))?;
    let mut drive = Drive::new(&cfg, &file.model, true)?;
    let mut state = CommissioningState::default();
    let (mut t, mut command, mut position) = (Vec::new(), Vec::new(), Vec::new());
    let mut shown = (CommissioningPhase::Breakaway, 0u8);
    if progress {
        eprintln!("commission: break-away ramps");
    }
    let most = (settings.duration * cfg.rate).ceil() as usize + 2;
    for k in 0..most {
        let now = k as f64 / cfg.rate;
        let tick = routine.tick(&mut state, drive.measured());
        t.push(now);
        command.push(tick.command);
        position.push(drive.position());
        if progress
            && (tick.phase, tick.plateaus) != shown
            && tick.phase != CommissioningPhase::Done
        {
            shown = (tick.phase, tick.plateaus);
            match tick.phase {
                CommissioningPhase::Presliding => eprintln!("commission: presliding reversal"),
                CommissioningPhase::Plateaus => {
                    let last = usize::from(tick.plateaus).checked_sub(1);
                    let point = last.and_then(|i| routine.plateau_points(&state).get(i).copied());
                    match point.flatten() {
                        Some(p) => eprintln!(
                            "commission: plateau {} of {}: v {:.5}, friction {:.5}{}",
                            tick.plateaus,
                            2 * settings.speeds,
                            p.speed,
                            p.force,
                            if p.steady {
                                ""
                            } else {
                                " (not steady: left out)"
                            }
                        ),
                        None => eprintln!("commission: plateaus"),
                    }
                }
                _ => {}
            }
        }
        if matches!(
            tick.phase,
            CommissioningPhase::Done | CommissioningPhase::Aborted
        ) {
            break;
        }
        // the drive's gravity feed-forward beside the routine (at the
        // measured position: the routine has no reference), within the limit
        let feedforward = cfg.gravity_feedforward(drive.measured()) / cfg.torque_constant;
        drive.apply(
            (tick.command + feedforward).clamp(-cfg.limit, cfg.limit),
            now,
        );
    }
    let points: Vec<PlateauPoint> = routine
        .plateau_points(&state)
        .into_iter()
        .flatten()
        .collect();
    let result = routine.result(&state).map_err(|e| {
        anyhow!(
            "{origin}: commissioning failed after {:.1} s: {e:?}",
            f64::from(state.ticks()) / cfg.rate
        )
    })?;
    if progress {
        eprintln!("commission: fitted; running the servo benchmark");
    }
    let reference = crate::servo::lugre_nominal(&file.model, 1.0, 1.0);
    let runs = compare(file, &cfg, &result)?;
    let n = runs.first().map_or(0, |r| r.error.len());
    Ok(CommissionRun {
        settings,
        t,
        command,
        position,
        result,
        points,
        reference,
        runs,
        trace_t: (0..n).map(|k| k as f64 / cfg.rate).collect(),
        note: cfg.coarse_encoder_note(),
    })
}

/// The benchmark rows of [`ROWS`] on the file's plant, the last two with
/// the commissioned model; without `observer` where the file's model has
/// no observer form (a static map). Where the run identified a load
/// coefficient, the adaptive row starts from it and from the levels at no
/// load (see [`adaptive_start`]).
pub fn compare(
    file: &ParamFile,
    cfg: &ServoConfig,
    commissioned: &Commissioned,
) -> Result<Vec<ServoRun>> {
    let (start, adaptive_cfg) = adaptive_start(cfg, commissioned);
    let (commissioned, start) = (
        ModelSpec::LuGre(commissioned.model),
        ModelSpec::LuGre(start),
    );
    let rows: [(&ModelSpec, &ServoConfig, Row); 5] = [
        (&file.model, cfg, Row::None),
        (&file.model, cfg, Row::Static { scale: 1.0 }),
        (&file.model, cfg, observer()),
        (&commissioned, cfg, observer()),
        (
            &start,
            &adaptive_cfg,
            Row::Adaptive {
                scale: 1.0,
                stiffness: 1.0,
                law: Law::Parameters,
            },
        ),
    ];
    std::thread::scope(|scope| {
        let handles: Vec<_> = ROWS
            .iter()
            .zip(rows)
            .map(|(&name, (spec, cfg, row))| {
                let plant = &file.model;
                scope.spawn(move || -> Result<Option<ServoRun>> {
                    let Some(ctl) = build_controller(cfg, spec, row) else {
                        // only the file's own model can be a static map
                        return Ok(None);
                    };
                    let ctl = ctl.with_context(|| format!("controller of `{name}`"))?;
                    run_loop(name, cfg, plant, row, ctl).map(Some)
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().map_err(|_| anyhow!("a benchmark row panicked"))?)
            .filter_map(Result::transpose)
            .collect::<Result<Vec<_>>>()
    })
}

/// The adaptive row's start: with a load coefficient `mu` identified, the
/// levels at no load (`fc` and `fs` less `mu` times the plateaus' mean
/// transmitted torque, at least a tenth of their value) and `mu` as the
/// nominal load coefficient, its bound at least `2 mu`; otherwise the
/// commissioned model and the file's settings. With a gravity feed-forward
/// the routine's commands carry no gravity, so a `mu` per unit of them is
/// not the one the law reads (its load input then includes the modelled
/// gravity): it is not carried over.
pub fn adaptive_start(cfg: &ServoConfig, c: &Commissioned) -> (LuGreParams, ServoConfig) {
    let mut settings = cfg.clone();
    if !c.identified.load || cfg.gravity_feedforward[0] != 0.0 {
        return (c.model, settings);
    }
    let shift = c.load * c.load_torque;
    let mut model = c.model;
    model.curve.fc = (model.curve.fc - shift).max(0.1 * model.curve.fc);
    model.curve.fs = (model.curve.fs - shift).max(model.curve.fc);
    settings.load_max = settings.load_max.max(2.0 * c.load);
    settings.adaptation_load = c.load;
    (model, settings)
}

fn observer() -> Row {
    Row::Observer {
        scale: 1.0,
        stiffness: 1.0,
        damping: true,
    }
}

impl CommissionRun {
    /// `(name, true, identified)` for every parameter.
    pub fn parameters(&self) -> Vec<(&'static str, f64, f64)> {
        let (r, m) = (&self.reference, &self.result.model);
        let nan = f64::NAN;
        vec![
            ("fc", r.curve.fc, m.curve.fc),
            ("fs", r.curve.fs, m.curve.fs),
            ("vs", r.curve.vs, m.curve.vs),
            ("stribeck_exponent", r.curve.exponent, m.curve.exponent),
            ("sigma0", r.sigma0, m.sigma0),
            ("sigma1", r.sigma1, m.sigma1),
            ("sigma2", r.sigma2, m.sigma2),
            ("fc_forward", nan, self.result.fc[0]),
            ("fc_backward", nan, self.result.fc[1]),
            ("fs_forward", nan, self.result.fs[0]),
            ("fs_backward", nan, self.result.fs[1]),
            ("sigma2_forward", nan, self.result.sigma2[0]),
            ("sigma2_backward", nan, self.result.sigma2[1]),
            ("breakaway_forward", nan, self.result.breakaway[0]),
            ("breakaway_backward", nan, self.result.breakaway[1]),
            ("load", nan, self.result.load),
            ("load_torque", nan, self.result.load_torque),
        ]
    }

    /// The run called `name`.
    pub fn run(&self, name: &str) -> Option<&ServoRun> {
        self.runs.iter().find(|r| r.name == name)
    }

    /// What the fit identified, as words.
    pub fn identified(&self) -> String {
        let i = self.result.identified;
        let mut parts = vec!["fc, sigma2 identified (per direction)"];
        let said = |on: bool, yes: &'static str, no: &'static str| if on { yes } else { no };
        parts.push(said(
            i.stribeck,
            "fs, vs, exponent identified",
            "vs not identified (an upper bound), fs from the break-away ramps",
        ));
        parts.push(said(
            i.stiffness,
            "sigma0 identified",
            "sigma0 not identified (the stiffness the loop cannot see)",
        ));
        parts.push(said(
            i.damping,
            "sigma1 identified",
            "sigma1 not identified (the critical-damping rule)",
        ));
        parts.push(said(
            i.load,
            "load coefficient identified",
            "load coefficient not identified (no load spread)",
        ));
        parts.join("; ")
    }

    /// The console and report table: parameters, then the benchmark.
    pub fn table(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "| parameter | true | identified | error |\n|---|---|---|---|"
        );
        for (name, truth, value) in self.parameters() {
            let error = (value - truth) / truth;
            let cell =
                |x: f64, f: &dyn Fn(f64) -> String| if x.is_finite() { f(x) } else { "-".into() };
            let _ = writeln!(
                s,
                "| {name} | {} | {} | {} |",
                cell(truth, &|x| format!("{x:.5}")),
                cell(value, &|x| format!("{x:.5}")),
                cell(error, &|x| format!("{:+.1} %", 100.0 * x)),
            );
        }
        let r = &self.result;
        let _ = writeln!(
            s,
            "\n{} plateaus from {:.4} to {:.4} rad/s, fit residual {:.2} % of the friction (the largest of fc, fs / 10 and the curve at the plateaus), {:.1} s; {}.\n",
            r.plateaus,
            r.speed_range[0],
            r.speed_range[1],
            100.0 * r.residual,
            self.t.last().copied().unwrap_or(0.0),
            self.identified()
        );
        let none = self.run("none").map_or(f64::NAN, |r| r.rms_half);
        let _ = writeln!(s, "| row | rms last half [mrad] | vs none |\n|---|---|---|");
        for run in &self.runs {
            let _ = writeln!(
                s,
                "| {} | {:.4} | {:.3}x |",
                run.name,
                1e3 * run.rms_half,
                run.rms_half / none
            );
        }
        if self.run("observer").is_none() {
            let _ = writeln!(
                s,
                "\nNo `observer` row: the file's model has no observer form (a static map)."
            );
        }
        if let Some(note) = &self.note {
            let _ = writeln!(s, "\nNote: {note}.");
        }
        s
    }

    /// `commissioned.toml`: the identified model as a parameter file, with
    /// the load coefficient (where identified) in a comment: a LuGre file
    /// has no key for it (`[servo] adaptation_load` takes it).
    pub fn toml(&self, origin: &str) -> String {
        let m = &self.result.model;
        let load = if self.result.identified.load {
            format!(
                "# load coefficient {} per unit of |kc u| (`[servo] adaptation_load`); \
                 the levels below are at the mean transmitted torque {}.\n",
                self.result.load, self.result.load_torque
            )
        } else {
            String::new()
        };
        format!(
            "# Commissioned by `friction commission` from {origin}\n\
             # ({}).\n{load}\
             model = \"lugre\"\nfc = {}\nfs = {}\nvs = {}\nstribeck_exponent = {}\n\
             sigma0 = {}\nsigma1 = {}\nsigma2 = {}\n",
            self.identified(),
            m.curve.fc,
            m.curve.fs,
            m.curve.vs,
            m.curve.exponent,
            m.sigma0,
            m.sigma1,
            m.sigma2
        )
    }

    /// Writes every file of [`OUTPUTS`] into `dir`.
    pub fn write(&self, dir: &Path, origin: &str) -> Result<Vec<PathBuf>> {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        let mut cells = String::from("name,true,identified,relative_error\n");
        for (name, truth, value) in self.parameters() {
            let f = |x: f64| {
                if x.is_finite() {
                    format!("{x:.9e}")
                } else {
                    String::new()
                }
            };
            let _ = writeln!(
                cells,
                "{name},{},{},{}",
                f(truth),
                f(value),
                f((value - truth) / truth)
            );
        }
        crate::io::write_bytes(&dir.join("parameters.csv"), cells.as_bytes())?;
        crate::io::write_bytes(&dir.join("commissioned.toml"), self.toml(origin).as_bytes())?;
        write_columns(
            &dir.join("run.csv"),
            &["t", "command", "position"],
            &[&self.t, &self.command, &self.position],
        )?;
        let names: Vec<String> = self.runs.iter().map(|r| format!("e_{}", r.name)).collect();
        let mut headers = vec!["t"];
        headers.extend(names.iter().map(String::as_str));
        let mut columns: Vec<&[f64]> = vec![&self.trace_t];
        columns.extend(self.runs.iter().map(|r| r.error.as_slice()));
        write_columns(&dir.join("trace.csv"), &headers, &columns)?;
        let mut written = Vec::new();
        let path = dir.join("excitation.svg");
        let series = [
            Series {
                label: "command",
                points: self
                    .t
                    .iter()
                    .copied()
                    .zip(self.command.iter().copied())
                    .collect(),
            },
            Series {
                label: "position [rad]",
                points: self
                    .t
                    .iter()
                    .copied()
                    .zip(self.position.iter().copied())
                    .collect(),
            },
        ];
        line_plot(
            &path,
            "commissioning excitation",
            ("t [s]", Axis::Linear),
            "command, position",
            &series,
        )?;
        written.push(path);
        let path = dir.join("curve.svg");
        line_plot(
            &path,
            "steady friction curve",
            ("v [rad/s]", Axis::Log),
            "friction",
            &self.curves()?,
        )?;
        written.push(path);
        let path = dir.join("errors.svg");
        let series: Vec<Series> = self
            .runs
            .iter()
            .map(|r| Series {
                label: r.name,
                points: self
                    .trace_t
                    .iter()
                    .copied()
                    .zip(r.error.iter().map(|e| 1e3 * e))
                    .collect(),
            })
            .collect();
        line_plot(
            &path,
            "tracking error",
            ("t [s]", Axis::Linear),
            "e [mrad]",
            &series,
        )?;
        written.push(path);
        let report = format!(
            "# Commissioning of {origin}\n\n{}\nPlots: `excitation.svg`, `curve.svg`, `errors.svg`.\n",
            self.table()
        );
        crate::io::write_bytes(&dir.join("report.md"), report.as_bytes())?;
        Ok(written)
    }

    /// The forward steady curves of the true and the commissioned model
    /// over the routine's speeds.
    fn curves(&self) -> Result<Vec<Series<'static>>> {
        let [lo, hi] = [self.settings.min_speed / 4.0, self.settings.max_speed * 2.0];
        let speeds: Vec<f64> = (0..200)
            .map(|k| lo * (hi / lo).powf(k as f64 / 199.0))
            .collect();
        // the models' steady state `g(v) sign(v) + sigma2 v`, the core's map
        let curve = |m: &LuGreParams, what: &str| {
            let map = StribeckMapParams {
                curve: m.curve,
                sigma2: m.sigma2,
            }
            .build::<f64>()
            .with_context(|| format!("the {what} model's steady curve"))?;
            Ok::<_, anyhow::Error>(speeds.iter().map(|&v| (v, map.force(v))).collect())
        };
        let forward = |steady: bool| -> Vec<(f64, f64)> {
            self.points
                .iter()
                .filter(|p| p.speed > 0.0 && p.steady == steady)
                .map(|p| (p.speed, p.force))
                .collect()
        };
        Ok(vec![
            Series {
                label: "plateaus (steady)",
                points: forward(true),
            },
            Series {
                label: "plateaus (left out)",
                points: forward(false),
            },
            Series {
                label: "file's model",
                points: curve(&self.reference, "file's")?,
            },
            Series {
                label: "commissioned",
                points: curve(&self.result.model, "commissioned")?,
            },
        ])
    }
}

/// `friction commission`: commissions, prints the table, writes the files.
pub fn run(params: Option<&Path>, output: &Path, progress: bool) -> Result<bool> {
    let (file, origin) = crate::servo::load(params, output, &OUTPUTS)?;
    if output.is_file() {
        bail!("--output {} is a file; give a folder", output.display());
    }
    let run = commission(&file, &origin, progress)?;
    crate::out!("{}", run.table());
    for p in run.write(output, &origin)? {
        crate::outln!("plot:  {}", p.display());
    }
    crate::outln!("parameters: {}", output.join("parameters.csv").display());
    crate::outln!("model: {}", output.join("commissioned.toml").display());
    Ok(true)
}
