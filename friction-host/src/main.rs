//! `friction`: simulate, run experiments and validate the friction models.

use anyhow::{Context, Result};
use clap::{Parser, Subcommand};
use friction_host::experiments::{self, Options};
use friction_host::io::{read_tv, write_columns};
use friction_host::models::ScalarKind;
use friction_host::params::ParamFile;
use std::path::PathBuf;
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
        /// Number type of the core model.
        #[arg(long, value_enum, default_value = "f64")]
        scalar: ScalarKind,
    },
    /// Run one of the classic friction experiments: writes DIR/trace.csv and a plot.
    Experiment {
        /// One of: stribeck, presliding, frictional-lag, breakaway, stick-slip, drift.
        #[arg(value_parser = clap::builder::PossibleValuesParser::new(experiments::NAMES))]
        name: String,
        /// Parameter file; rig experiments read its `[rig]` table.
        #[arg(long)]
        params: PathBuf,
        /// Sample period of the core's step (s); each experiment has a default.
        #[arg(long)]
        dt: Option<f64>,
        /// Duration (s) of time-based experiments.
        #[arg(long)]
        duration: Option<f64>,
        /// Output folder.
        #[arg(long)]
        output: PathBuf,
    },
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
    /// Validate every model against the reference solver and judge the experiments.
    Validate {
        /// Output folder of the report.
        #[arg(long, default_value = "validation")]
        output: PathBuf,
    },
}

fn positive(name: &str, x: Option<f64>) -> Result<()> {
    match x {
        Some(v) if !(v.is_finite() && v > 0.0) => {
            anyhow::bail!("--{name} must be a positive number, got {v}")
        }
        _ => Ok(()),
    }
}

fn run(cli: Cli) -> Result<bool> {
    match cli.command {
        Command::Simulate {
            params,
            input,
            output,
            scalar,
        } => {
            let file = ParamFile::load(&params)?;
            let (t, v) = read_tv(&input)?;
            let mut model = file.model.stepper(scalar)?;
            let names = model.state_names();
            let mut f = Vec::with_capacity(t.len());
            let mut states: Vec<Vec<f64>> = vec![Vec::with_capacity(t.len()); names.len()];
            for k in 0..t.len() {
                let h = if k == 0 { 0.0 } else { t[k] - t[k - 1] };
                f.push(model.step(v[k], h));
                for (col, s) in states.iter_mut().zip(model.states()) {
                    col.push(s);
                }
            }
            let mut headers = vec!["t", "v", "f"];
            headers.extend(names.iter().map(String::as_str));
            let mut cols: Vec<&[f64]> = vec![&t, &v, &f];
            cols.extend(states.iter().map(|c| &c[..]));
            write_columns(&output, &headers, &cols)?;
            eprintln!("{} rows -> {}", t.len(), output.display());
            Ok(true)
        }
        Command::Experiment {
            name,
            params,
            dt,
            duration,
            output,
        } => {
            positive("dt", dt)?;
            positive("duration", duration)?;
            let file = ParamFile::load(&params)?;
            let out = experiments::run(&name, &file, Options { dt, duration }, &output)
                .with_context(|| format!("experiment `{name}`"))?;
            println!(
                "{} ({}) for `{}`",
                out.name,
                out.phenomenon,
                file.model.name()
            );
            println!("  {}: {}", out.verdict(), out.figure);
            for line in &out.summary {
                println!("  {line}");
            }
            println!("  trace: {}", output.join("trace.csv").display());
            println!("  plot:  {}", out.plot.display());
            Ok(true)
        }
        Command::Servo { params, output } => friction_host::servo::run(params.as_deref(), &output),
        Command::Validate { output } => friction_host::validate::run(&output),
    }
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(true) => ExitCode::SUCCESS,
        Ok(false) => ExitCode::FAILURE,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}
