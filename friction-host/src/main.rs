//! `friction`: simulate, run experiments and validate the friction models.

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use friction_host::checks::{self, args, ranges};
use friction_host::experiments::{self, Options};
use friction_host::identify;
use friction_host::io;
use friction_host::params::ParamFile;
use friction_host::sim::{PeriodRefused, SimScalar, Simulation};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "friction",
    version,
    about = "Dynamic friction models: simulate, experiment, servo, validate"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a model over a velocity signal read from CSV (columns `t`, `v`).
    ///
    /// Row k of the output is the force at t[k]: the model is stepped from
    /// t[k-1] to t[k] with the velocity held at v[k]; row 0 is the initial
    /// state (at rest). Output columns: t, v, f and the model's states.
    /// The input is streamed (constant memory), the output written to a
    /// temporary file and renamed into place when complete; it may not be
    /// an input. Velocities beyond ±1e6 are clamped, with a warning.
    Simulate {
        /// Parameter file (TOML with `model = "..."`).
        #[arg(long)]
        params: PathBuf,
        /// Input CSV with a header naming columns `t` (s) and `v`.
        #[arg(long)]
        input: PathBuf,
        /// Output CSV.
        #[arg(long)]
        output: PathBuf,
        /// Number type of the core model: `fixed` runs the fixed-step form
        /// in Q16.16 fixed point (LuGre, ...), built for the time step of
        /// the first two rows, which every row must keep (within 1e-6).
        #[arg(long, value_enum, default_value = "f64")]
        scalar: SimScalar,
    },
    /// Run one of the classic friction experiments: writes DIR/trace.csv and a plot.
    ///
    /// Exit code 0 when the verdict is pass or not judged, 1 on FAIL, 2 on bad input.
    Experiment {
        /// The experiment (its possible values are listed below); exit 2 with the reason when it does not apply to the file.
        #[arg(value_parser = clap::builder::PossibleValuesParser::new(experiments::NAMES))]
        name: String,
        /// Parameter file; rig experiments read its `[rig]` table.
        #[arg(long)]
        params: PathBuf,
        /// Sample period of the core's step (s), 1e-9 to 10; each experiment
        /// has a default, and a run takes 100 to 5e6 samples.
        #[arg(long)]
        dt: Option<f64>,
        /// Duration (s) of time-based experiments, 1e-6 to 1e7.
        #[arg(long)]
        duration: Option<f64>,
        /// Output folder.
        #[arg(long)]
        output: PathBuf,
    },
    /// Identify a model's parameters from a measured trajectory: writes
    /// DIR/params.toml, DIR/report.md, DIR/fit.csv and plots.
    ///
    /// The force is modelled as `mass * a + N * friction(v) + offset`
    /// (`mass`, `offset` with --inertia; `N` with --normal-force). Velocity and
    /// acceleration come from the position by a zero-phase Butterworth
    /// low-pass and central differences; every signal is then decimated.
    /// Exit codes: 0 accepted, 1 fit rejected (a bound, no convergence, a
    /// zero gradient), 2 bad input.
    Identify(IdentifyArgs),
    /// Online estimation: the compensator's estimators replayed causally on a measured run.
    ///
    /// Each sample's position and command go through the compensator as a
    /// drive would run it beside its own controller: the per-parameter
    /// estimator (prediction-error law) and the least-squares feed-forward
    /// (with a force offset) learn from the friction it measures. Writes DIR/estimates.csv (the
    /// estimates over time), DIR/estimates.svg and DIR/report.md, with the
    /// offline IDIM-LS fit of the same run and, with --validate, each model's
    /// force prediction error on a second run.
    Online(OnlineArgs),
    /// Position servo benchmark: each friction compensation against a simulated plant.
    ///
    /// Prints `servo NAME RMS_MRAD MAX_MRAD` per compensation and a table;
    /// writes DIR/trace.csv and SVG plots of the tracking errors. The set-up
    /// is read from the file's `[servo]` table (defaults: Olsson et al. 1998).
    Servo {
        /// Parameter file [default: the built-in params/olsson1998-servo.toml].
        #[arg(long)]
        params: Option<PathBuf>,
        /// Output folder.
        #[arg(long)]
        output: PathBuf,
    },
    /// Commissioning: from a bare axis to LuGre parameters, on the file's plant.
    ///
    /// Runs the core's commissioning routine (break-away ramps, a presliding
    /// reversal, velocity plateaus) against the simulated drive of the file's
    /// `[servo]` table, within its `[commission]` window; writes
    /// DIR/parameters.csv, DIR/commissioned.toml, the servo benchmark with the
    /// commissioned model (DIR/trace.csv) and plots.
    Commission {
        /// Parameter file [default: the built-in params/olsson1998-servo.toml].
        #[arg(long)]
        params: Option<PathBuf>,
        /// Output folder.
        #[arg(long)]
        output: PathBuf,
        /// No progress lines.
        #[arg(long)]
        quiet: bool,
    },
    /// Robustness map: the servo benchmark over a grid of parameter errors.
    ///
    /// Builds each compensation (none, static, observer, adaptive, rls) with
    /// the model's friction level (fc, fs) scaled 0.25 to 2 and its
    /// stiffness scaled 0.1 to 10, runs them in parallel against the file's
    /// plant and scenario, prints a summary and writes DIR/robustness.csv
    /// (RMS over the last half, mrad) and the heat map DIR/robustness.svg.
    Robustness {
        /// Parameter file [default: the built-in params/olsson1998-servo.toml].
        #[arg(long)]
        params: Option<PathBuf>,
        /// Output folder.
        #[arg(long)]
        output: PathBuf,
        /// Grid points per axis (2 to 25).
        #[arg(long, default_value_t = 7)]
        points: usize,
        /// The adaptive column's law: `parameters` (the per-parameter law,
        /// column `adaptive`) or `theta` (one factor on the whole model,
        /// column `adaptive-theta`).
        #[arg(long, default_value = "parameters", value_parser = ["parameters", "theta"])]
        law: String,
    },
    /// Validate every model against the reference solver and judge the experiments.
    ///
    /// Exit code 0 when every check passes, 1 when one fails, 2 on bad input.
    Validate {
        /// Output folder of the report.
        #[arg(long, default_value = "validation")]
        output: PathBuf,
        /// Print each section's cost (seconds) on stderr at the end.
        #[arg(long)]
        timings: bool,
    },
}

#[derive(clap::Args)]
struct IdentifyArgs {
    /// Measured trajectory (CSV; tab- or semicolon-separated text works too).
    #[arg(long)]
    input: PathBuf,
    /// One of: coulomb, coulomb-viscous, stribeck, lugre.
    #[arg(long)]
    model: String,
    /// Output folder.
    #[arg(long)]
    output: PathBuf,
    /// Time column (s).
    #[arg(long, default_value = "t")]
    time: String,
    /// Position column (ignored with --velocity).
    #[arg(long, default_value = "x")]
    position: String,
    /// Measured velocity column (instead of differentiating the position).
    #[arg(long)]
    velocity: Option<String>,
    /// Force column.
    #[arg(long, default_value = "f")]
    force: String,
    /// Factor from the force column to force (e.g. motor constant; negative
    /// flips the sign), magnitude 1e-12 to 1e12.
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true)]
    force_gain: f64,
    /// Normal-force column: the friction parameters become coefficients.
    #[arg(long)]
    normal_force: Option<String>,
    /// Also estimate the moving mass and a force offset (a driven axis).
    #[arg(long)]
    inertia: bool,
    /// Cut-off of the zero-phase Butterworth low-pass (Hz), 1e-6 to 1e9 and
    /// below the Nyquist frequency [default: sample rate / 10].
    #[arg(long)]
    cutoff: Option<f64>,
    /// Order of the Butterworth low-pass, 1 to 16.
    #[arg(long, default_value_t = 4, allow_hyphen_values = true)]
    filter_order: i64,
    /// Decimation factor, at least 1 [default: largest keeping Nyquist >= 2.5 cut-off].
    #[arg(long, allow_hyphen_values = true)]
    decimate: Option<i64>,
    /// Stribeck exponent (fixed during the fit), 1 to 100.
    #[arg(long, default_value_t = 2.0)]
    stribeck_exponent: f64,
    /// Steady-state law of the `lugre` fit's first stage.
    #[arg(long, value_enum, default_value = "stribeck")]
    lugre_static: identify::fit::StaticPart,
    /// Second trajectory (same columns) for cross-validation.
    #[arg(long)]
    validate: Option<PathBuf>,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
}

#[derive(clap::Args)]
struct OnlineArgs {
    /// Measured run (CSV; tab- or semicolon-separated text works too).
    #[arg(long)]
    input: PathBuf,
    /// Output folder.
    #[arg(long)]
    output: PathBuf,
    /// Time column (s).
    #[arg(long, default_value = "t")]
    time: String,
    /// Position column.
    #[arg(long, default_value = "x")]
    position: String,
    /// Command column (the force the drive applied, before --force-gain).
    #[arg(long, default_value = "f")]
    force: String,
    /// Factor from the command column to force (e.g. motor constant; negative
    /// flips the sign), magnitude 1e-12 to 1e12.
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true)]
    force_gain: f64,
    /// Moving mass (or inertia) of the drive's loop, > 0.
    #[arg(long)]
    mass: f64,
    /// Starting guess of the Coulomb level, > 0.
    #[arg(long)]
    coulomb: f64,
    /// Starting guess of the viscous coefficient, > 0.
    #[arg(long)]
    viscous: f64,
    /// Speed scale of the viscous regressors, > 0 [default: the run's peak speed].
    #[arg(long)]
    speed: Option<f64>,
    /// Slowest sample the estimators learn from, > 0 [default: speed / 50].
    #[arg(long)]
    min_speed: Option<f64>,
    /// Rate (1/s) of the per-parameter estimator, > 0, at most the sample rate.
    #[arg(long, default_value_t = friction_host::online::defaults::RATE)]
    rate: f64,
    /// Forgetting factor of the least-squares feed-forward, 0 < f <= 1.
    #[arg(long, default_value_t = friction_host::online::defaults::FORGETTING)]
    forgetting: f64,
    /// Box factor of the per-parameter estimates around the guesses, >= 1.
    #[arg(long, default_value_t = friction_host::online::defaults::BOX_FACTOR)]
    box_factor: f64,
    /// Second run (same columns) on which each model predicts the force.
    #[arg(long)]
    validate: Option<PathBuf>,
}

/// Checks numeric option `arg` against its range (see
/// [`friction_host::checks`], shared with the Python package).
fn within(arg: checks::Arg, x: Option<f64>, range: (f64, f64)) -> Result<()> {
    if let Some(x) = x {
        checks::within(arg, x, range)?;
    }
    Ok(())
}

/// `friction simulate`: streams the input row by row into the output, so
/// memory stays constant in the input's length.
fn simulate(params: &Path, input: &Path, output: &Path, scalar: SimScalar) -> Result<()> {
    io::refuse_overwrite("--output", output, &[params, input])?;
    let file = ParamFile::load(params)?;
    let context = || {
        format!(
            "{}: `{}` in {scalar:?}",
            params.display(),
            file.model.name()
        )
    };
    let mut rows = io::TvRows::open(input)?.peekable();
    let mut first_row = None;
    // fixed point: the period of the first two rows, which every row keeps
    let mut period = None;
    // the line of the second row, whose time step is the period
    let mut second_line = 0;
    if scalar == SimScalar::Fixed {
        let first = match rows.next() {
            Some(row) => row?,
            None => anyhow::bail!("{}: no data rows", input.display()),
        };
        // the second row's own error (e.g. a time that does not increase)
        if matches!(rows.peek(), Some(Err(_))) {
            if let Some(Err(e)) = rows.next() {
                return Err(e);
            }
        }
        let h = match rows.peek() {
            Some(Ok((line, t, _))) => {
                second_line = *line;
                t - first.1
            }
            _ => anyhow::bail!(
                "{}: `--scalar fixed` needs at least two rows (the time step)",
                input.display()
            ),
        };
        if !(h.is_finite() && h > 0.0) {
            anyhow::bail!(
                "{}: the time step of the first two rows ({h:e} s) must be finite and > 0",
                input.display()
            );
        }
        period = Some(h);
        first_row = Some(first);
    }
    let mut sim = Simulation::new(&file.model, scalar, period).map_err(|e| {
        if e.is::<PeriodRefused>() {
            anyhow::anyhow!("{}:{second_line}: {e}", input.display())
        } else {
            e.context(context())
        }
    })?;
    let limit = sim.limit();
    let names = sim.state_names();
    // the output's folder is made, as the other commands make theirs
    if let Some(dir) = output.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)
            .map_err(|e| anyhow::anyhow!("cannot create {}: {e}", dir.display()))?;
    }
    let count = io::write_atomic(output, |w| {
        let mut csv = csv::Writer::from_writer(w);
        let werr = |e: csv::Error| anyhow::anyhow!("cannot write {}: {e}", output.display());
        let mut header = vec!["t", "v", "f"];
        header.extend(names.iter().map(String::as_str));
        csv.write_record(&header).map_err(werr)?;
        let mut count = 0u64;
        for row in first_row.map(Ok).into_iter().chain(rows) {
            let (line, t, v) = row?;
            let (v_used, f) = sim
                .row(t, v)
                .map_err(|e| anyhow::anyhow!("{}:{line}: {e}", input.display()))?;
            if v_used != v && sim.clamped == 1 {
                eprintln!(
                    "warning: {}:{line}: |v| = {v:e} exceeds the velocity limit {limit:e}: clamped (the output's `v` column shows the velocity the model saw)",
                    input.display()
                );
            }
            let mut record = vec![
                format!("{t:.12e}"),
                format!("{v_used:.12e}"),
                format!("{f:.12e}"),
            ];
            record.extend(sim.states().iter().map(|s| format!("{s:.12e}")));
            csv.write_record(&record).map_err(werr)?;
            count += 1;
        }
        if count == 0 {
            anyhow::bail!("{}: no data rows", input.display());
        }
        if sim.clamped > 1 {
            eprintln!(
                "warning: {} rows of {} were clamped",
                sim.clamped,
                input.display()
            );
        }
        csv.flush()
            .with_context(|| format!("cannot write {}", output.display()))?;
        Ok(count)
    })?;
    eprintln!("{count} rows -> {}", output.display());
    Ok(())
}

fn run(cli: Cli) -> Result<bool> {
    match cli.command {
        Command::Simulate {
            params,
            input,
            output,
            scalar,
        } => {
            simulate(&params, &input, &output, scalar)?;
            Ok(true)
        }
        Command::Experiment {
            name,
            params,
            dt,
            duration,
            output,
        } => {
            within(args::DT, dt, ranges::DT)?;
            within(args::DURATION, duration, ranges::DURATION)?;
            let file = ParamFile::load(&params)?;
            for out in ["trace.csv".to_string(), format!("{name}.svg")] {
                io::refuse_overwrite("--output", &output.join(out), &[&params])?;
            }
            let out = experiments::run(&name, &file, Options { dt, duration }, &output)
                .with_context(|| params.display().to_string())?;
            friction_host::outln!(
                "{} ({}) for `{}`",
                out.name,
                out.phenomenon,
                file.model.name()
            );
            friction_host::outln!("  {}: {}", out.verdict(), out.figure);
            for line in &out.summary {
                friction_host::outln!("  {line}");
            }
            friction_host::outln!("  trace: {}", output.join("trace.csv").display());
            friction_host::outln!("  plot:  {}", out.plot.display());
            // exit code 1 when the verdict is FAIL, so scripts see it
            Ok(out.pass != Some(false))
        }
        Command::Identify(a) => {
            within(args::CUTOFF, a.cutoff, ranges::CUTOFF)?;
            checks::within(
                args::STRIBECK_EXPONENT,
                a.stribeck_exponent,
                ranges::STRIBECK_EXPONENT,
            )?;
            checks::magnitude_within(args::FORCE_GAIN, a.force_gain, ranges::FORCE_GAIN)?;
            let order = checks::filter_order(a.filter_order)?;
            let decimate = a.decimate.map(checks::decimate).transpose()?;
            let o = identify::Options {
                input: a.input,
                model: a.model,
                output: a.output,
                columns: identify::Columns {
                    time: a.time,
                    position: a.position,
                    velocity: a.velocity,
                    force: a.force,
                    force_gain: a.force_gain,
                    normal_force: a.normal_force,
                },
                inertia: a.inertia,
                conditioning: identify::Conditioning {
                    cutoff: a.cutoff,
                    order,
                    decimate,
                },
                stribeck_exponent: a.stribeck_exponent,
                lugre_static: a.lugre_static,
                validate: a.validate,
                progress: !a.quiet,
            };
            identify::run(&o)
        }
        Command::Online(a) => {
            checks::magnitude_within(args::FORCE_GAIN, a.force_gain, ranges::FORCE_GAIN)?;
            let o = friction_host::online::Options {
                input: a.input,
                output: a.output,
                columns: identify::Columns {
                    time: a.time,
                    position: a.position,
                    velocity: None,
                    force: a.force,
                    force_gain: a.force_gain,
                    normal_force: None,
                },
                mass: a.mass,
                coulomb: a.coulomb,
                viscous: a.viscous,
                speed: a.speed,
                min_speed: a.min_speed,
                rate: a.rate,
                forgetting: a.forgetting,
                box_factor: a.box_factor,
                validate: a.validate,
            };
            friction_host::online::run_and_print(&o)
        }
        Command::Servo { params, output } => friction_host::servo::run(params.as_deref(), &output),
        Command::Commission {
            params,
            output,
            quiet,
        } => friction_host::commission::run(params.as_deref(), &output, !quiet),
        Command::Robustness {
            params,
            output,
            points,
            law,
        } => friction_host::servo::robustness::run(
            params.as_deref(),
            &output,
            points,
            if law == "theta" {
                friction_host::servo::Law::Theta
            } else {
                friction_host::servo::Law::Parameters
            },
        ),
        Command::Validate { output, timings } => {
            friction_host::validate::run_with(&output, timings)
        }
    }
}

fn main() -> ExitCode {
    let result = run(Cli::parse());
    // a reader that closed standard output early (`| head`) is no error;
    // a failed write otherwise is (already reported on standard error)
    if io::stdout_failed() {
        if let Err(e) = &result {
            eprintln!("error: {e:#}");
        }
        return ExitCode::from(2);
    }
    match result {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::FAILURE,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}
