//! `friction servo`: a position servo against a simulated plant, with each
//! friction compensation of the core's [`Compensator`](friction_core::Compensator).
//!
//! The plant is an inertia `J` driven through a torque constant `kc`,
//! `J dv/dt = kc u - F`, with the friction `F` of the parameter file's model
//! stepped by the core (f64) at `plant_rate` (semi-implicit Euler, velocity
//! held over each step). The controller is the core's compensator at `rate`
//! (PID on `e = x - x_ref`, acceleration feed-forward, measured velocity the
//! backward difference of the sampled position, optionally low-passed), its
//! command held over the period.
//!
//! A drive scenario ([`servo`](crate::params::servo)) makes the plant realistic: the measured
//! position is rounded to encoder counts, the plant's whole friction force
//! is multiplied by a drift `s(t)` and by `1 + mu |kc u|` (load-dependent
//! friction), and the command reaches the plant `delay_ticks` late.
//! The plant is then `J dv/dt = kc u + tau_e - F`, with `tau_e` the gravity
//! torque where the file sets one. The
//! tracking error is the true one, `x - x_ref`.
//!
//! Compensations ([`NAMES`]): `nofriction` (the plant without friction: the
//! floor), `none`, `static` (Coulomb + viscous feed-forward from the nominal
//! parameters on the measured velocity), `static+50` / `static-50` (its
//! Coulomb level scaled by 1.5 and 0.5: what a user with the wrong
//! parameters would feed forward), `observer` (the nominal model),
//! `observer+50` / `observer-50` (the observer's friction level, `fc` and
//! `fs`, scaled by 1.5 and 0.5: the robustness check of Olsson et al.
//! 1998), `observer-nodamping` (without `sigma1 dz^/dt`), `adaptive`,
//! `adaptive+50`, `adaptive-50` (the per-parameter adaptive observer,
//! [`friction_core::ParameterAdaptive`], started from the nominal and the
//! scaled levels), `adaptive-theta`, `adaptive-theta+50`,
//! `adaptive-theta-50` (the θ-adaptive observer) and `rls` (the
//! least-squares Coulomb + viscous feed-forward, started from zero). Every
//! adaptive row is supervised ([`friction_core::Supervised`]) with the
//! static row of its scale as the fallback, unless `supervisor = false`.
//! The observer and adaptive rows need a model with an observer form; for
//! the static maps they are skipped with a note. Each model's host module
//! builds its own observer rows
//! ([`crate::models::HostModel::observer_controller`]); the per-parameter
//! law runs LuGre with the model's curve and rest stiffness
//! ([`lugre_nominal`]).
//!
//! The plant can also look like a real actuator: friction that differs by
//! direction (`asymmetry`), ripples with position (`ripple`), a gravity
//! torque (`gravity`), and a friction budget from a BAM identification
//! (`plant_bam`, [`BamPlant`]) that grows with the transmitted torque.
//!
//! Defaults reproduce Olsson et al. 1998 (Table 2 LuGre, `J = 0.0023`,
//! `kc = 1.02`, reference `0.5 sin(2 pi 0.2 t)` rad for 20 s, PID at 1 kHz
//! with `kp = 60`, `ki = 200`, `kd = 1.2`, observer gain 20 1/s, plant at
//! 100 kHz) on an ideal drive; each is a key of the file's `[servo]` table.
//! RMS and maximum tracking errors are taken over the last 90 % of the run,
//! and the RMS also over the last half (`rms_half`, after adaptation). A
//! loop that diverges is reported as `unstable`.
//!
//! Plan, run, render: the set-up is the file's `[servo]` table ([`params::servo`](crate::params::servo),
//! with the file format), the rows are listed once in `rows` ([`ROWS`]) and
//! built into controllers in `controllers`; `plant` simulates the drive,
//! `run` runs each row's loop and the benchmark, and `render` prints and
//! plots it ([`robustness`] maps it over parameter errors).

mod controllers;
mod plant;
mod render;
pub mod robustness;
mod robustness_render;
mod rows;
mod run;

pub use controllers::{
    adaptation, build_controller, coulomb_level, least_squares, lugre_nominal,
    parameter_adaptation, static_map, PARAMETER_NAMES,
};
pub use plant::BamPlant;
pub(crate) use plant::Drive;
pub use render::{report_section, OUTPUTS};
pub use rows::{Law, Row, NAMES, ROWS};
pub(crate) use run::run_loop;
pub use run::{benchmark, simulate, ServoBenchmark, ServoRun};

use crate::params::ParamFile;
use anyhow::Result;
use std::path::Path;

/// The parameter file of a servo command (or the built-in
/// `olsson1998-servo` set) and the name its messages use, after checking
/// that none of `outputs` in `output` is that file.
pub(crate) fn load(
    params: Option<&Path>,
    output: &Path,
    outputs: &[&str],
) -> Result<(ParamFile, String)> {
    match params {
        Some(p) => {
            for name in outputs {
                crate::io::refuse_overwrite("--output", &output.join(name), &[p])?;
            }
            Ok((ParamFile::load(p)?, p.display().to_string()))
        }
        None => Ok((
            crate::params::param_set("olsson1998-servo")?,
            "params/olsson1998-servo.toml".to_string(),
        )),
    }
}

/// `friction servo`: runs, prints the lines and the table, writes the trace
/// and plots. `params` = `None` uses the built-in `olsson1998-servo` set.
pub fn run(params: Option<&Path>, output: &Path) -> Result<bool> {
    let (file, origin) = load(params, output, &OUTPUTS)?;
    let bench = benchmark(&file, &origin)?;
    render::print(&bench, output)?;
    Ok(true)
}
