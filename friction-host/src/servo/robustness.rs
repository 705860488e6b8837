//! The robustness map (`friction robustness`): the servo benchmark's
//! tracking error for each compensation over a grid of parameter errors.
//!
//! Each cell builds the compensations from the file's model with its
//! friction level (`fc`, `fs`) times a force scale and its stiffness (the
//! model's own, e.g. `sigma0`) times a stiffness scale, and runs them against
//! the unchanged plant of the file's `[servo]` scenario. The grid is
//! geometric: force scales 0.25 to 2, stiffness scales 0.1 to 10
//! ([`Grid::new`]). `none` and `rls` do not use the model and `static` uses
//! only its friction level: they run once (per force scale) and fill every
//! cell. The figure is the RMS error over the last half of the run (after
//! adaptation), `inf` when the loop diverged. Runs go in parallel on all
//! cores (rayon), with a progress bar on a terminal. The CSV, the heat
//! map and the Markdown are rendered in `robustness_render`.

use super::{simulate, Law, Row};
use crate::params::ParamFile;
use anyhow::{bail, Result};
use rayon::prelude::*;
use std::path::Path;

pub use super::robustness_render::report_section;

/// The compensations of the map, in column order (with `--law theta` the
/// fourth is `adaptive-theta`: [`RobustnessMap::names`]).
pub const COMPENSATIONS: [&str; 5] = ["none", "static", "observer", "adaptive", "rls"];

/// The map's compensations with the adaptive column running `law`.
pub fn compensations(law: Law) -> [&'static str; 5] {
    let mut names = COMPENSATIONS;
    if law == Law::Theta {
        names[3] = "adaptive-theta";
    }
    names
}

/// Allowed grid points per axis of `--points`.
pub const POINTS: std::ops::RangeInclusive<usize> = 2..=25;

/// The files `friction robustness` writes into its output folder.
pub const OUTPUTS: [&str; 2] = ["robustness.csv", "robustness.svg"];

/// The cell `robustness.csv` writes for a loop that diverged (an empty cell
/// is a compensation the model has no form of).
pub const UNSTABLE: &str = "unstable";

/// The grid of parameter errors.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    /// Factors on the compensator's friction level (`fc`, `fs`).
    pub force: Vec<f64>,
    /// Factors on the compensator's stiffness.
    pub stiffness: Vec<f64>,
}

impl Grid {
    /// `points` geometric steps per axis: force scale 0.25 to 2, stiffness
    /// scale 0.1 to 10 (1 is on both axes for an odd count of stiffness
    /// points). `points` must be within [`POINTS`].
    pub fn new(points: usize) -> Result<Grid> {
        if !POINTS.contains(&points) {
            bail!(
                "--points {points}: must be within {}..={}",
                POINTS.start(),
                POINTS.end()
            );
        }
        let geometric = |lo: f64, hi: f64| -> Vec<f64> {
            (0..points)
                .map(|i| {
                    let f = i as f64 / (points - 1) as f64;
                    lo * (hi / lo).powf(f)
                })
                .collect()
        };
        Ok(Grid {
            force: geometric(0.25, 2.0),
            stiffness: geometric(0.1, 10.0),
        })
    }
}

/// One cell: the scales and each compensation's RMS error over the last
/// half (rad; `inf`: unstable; `NaN`: the model has no such form).
#[derive(Clone, Debug, PartialEq)]
pub struct Cell {
    /// Factor on the friction level.
    pub force: f64,
    /// Factor on the stiffness.
    pub stiffness: f64,
    /// RMS error per compensation, in the order of [`RobustnessMap::names`].
    pub rms: [f64; 5],
}

/// The whole map.
#[derive(Clone, Debug)]
pub struct RobustnessMap {
    /// The grid it was run on.
    pub grid: Grid,
    /// Cells, force scale outer, stiffness scale inner.
    pub cells: Vec<Cell>,
    /// The parameter file it was run from (for titles).
    pub origin: String,
    /// The law of the adaptive column.
    pub law: Law,
}

/// One simulation of the map.
#[derive(Clone, Copy)]
struct Job {
    column: usize,
    force: f64,
    stiffness: f64,
}

impl Job {
    /// The benchmark's row of this column's name among `names`, scaled to
    /// the cell (every name of [`compensations`] is one of
    /// [`super::ROWS`]: tested).
    fn row(&self, names: &[&str; 5]) -> Row {
        names
            .get(self.column)
            .and_then(|name| Row::named(name))
            .map_or(Row::None, |row| row.scaled(self.force, self.stiffness))
    }
}

/// Runs the map for `file` (`origin` names it) with the per-parameter law
/// in the adaptive column, calling `progress` with (runs done, runs in
/// all) after each run.
pub fn map(
    file: &ParamFile,
    origin: &str,
    grid: &Grid,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<RobustnessMap> {
    map_with_law(file, origin, grid, Law::Parameters, progress)
}

/// [`map`] with `law` in the adaptive column.
pub fn map_with_law(
    file: &ParamFile,
    origin: &str,
    grid: &Grid,
    law: Law,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<RobustnessMap> {
    let names = compensations(law);
    let cfg = file.servo.resolve(origin)?;
    let spec = &file.model;
    // the distinct runs: none and rls once, static per force scale,
    // observer and adaptive per cell
    let mut jobs = vec![
        Job {
            column: 0,
            force: 1.0,
            stiffness: 1.0,
        },
        Job {
            column: 4,
            force: 1.0,
            stiffness: 1.0,
        },
    ];
    for &force in &grid.force {
        jobs.push(Job {
            column: 1,
            force,
            stiffness: 1.0,
        });
        for &stiffness in &grid.stiffness {
            for column in [2, 3] {
                jobs.push(Job {
                    column,
                    force,
                    stiffness,
                });
            }
        }
    }
    let total = jobs.len();
    let done = std::sync::atomic::AtomicUsize::new(0);
    let results: Vec<Result<Option<f64>>> = jobs
        .par_iter()
        .map(|job| {
            let name = names[job.column];
            let run = simulate(name, &cfg, spec, job.row(&names)).transpose();
            let n = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            progress(n, total);
            Ok(run?.map(|r| r.rms_half))
        })
        .collect();
    let mut found = Vec::with_capacity(total);
    for (job, r) in jobs.iter().zip(results) {
        found.push((*job, r?.unwrap_or(f64::NAN)));
    }
    let lookup = |column: usize, force: f64, stiffness: f64| -> f64 {
        found
            .iter()
            .find(|(j, _)| {
                j.column == column
                    && (column == 0 || column == 4 || j.force == force)
                    && (!(2..=3).contains(&column) || j.stiffness == stiffness)
            })
            .map_or(f64::NAN, |(_, rms)| *rms)
    };
    let mut cells = Vec::new();
    for &force in &grid.force {
        for &stiffness in &grid.stiffness {
            let mut rms = [f64::NAN; 5];
            for (column, value) in rms.iter_mut().enumerate() {
                *value = lookup(column, force, stiffness);
            }
            cells.push(Cell {
                force,
                stiffness,
                rms,
            });
        }
    }
    Ok(RobustnessMap {
        grid: grid.clone(),
        cells,
        origin: origin.to_string(),
        law,
    })
}

/// The fraction of cells and the figures of a compensation across the map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Summary {
    /// Median RMS over the cells (rad).
    pub median: f64,
    /// Largest RMS over the cells (rad; `inf` if a cell is unstable).
    pub worst: f64,
    /// Fraction of cells where it beats `static` of the same cell.
    pub beats_static: f64,
    /// Fraction of cells where the loop diverged.
    pub unstable: f64,
}

impl RobustnessMap {
    /// The cell nearest the nominal model (both scales 1, or the closest).
    pub fn nominal(&self) -> Option<&Cell> {
        self.cells.iter().min_by(|a, b| {
            let d = |c: &Cell| c.force.ln().abs() + c.stiffness.ln().abs();
            d(a).total_cmp(&d(b))
        })
    }

    /// The names of its columns ([`compensations`] of its law).
    pub fn names(&self) -> [&'static str; 5] {
        compensations(self.law)
    }

    /// The summary of `compensation` (a name of [`Self::names`]).
    pub fn summary(&self, compensation: &str) -> Option<Summary> {
        let column = self.names().iter().position(|c| *c == compensation)?;
        let values: Vec<f64> = self
            .cells
            .iter()
            .map(|c| c.rms[column])
            .filter(|v| !v.is_nan())
            .collect();
        if values.is_empty() {
            return None;
        }
        let mut sorted = values.clone();
        sorted.sort_by(f64::total_cmp);
        let median = sorted[sorted.len() / 2];
        let worst = sorted[sorted.len() - 1];
        let n = self.cells.len() as f64;
        let beats = self
            .cells
            .iter()
            .filter(|c| c.rms[column] < c.rms[1])
            .count() as f64;
        let unstable = values.iter().filter(|v| v.is_infinite()).count() as f64;
        Some(Summary {
            median,
            worst,
            beats_static: beats / n,
            unstable: unstable / n,
        })
    }
}

/// `friction robustness`: runs the map for the file (or the built-in
/// `olsson1998-servo` set) with `law` in the adaptive column, prints the
/// summary and writes the CSV and the heat map.
pub fn run(params: Option<&Path>, output: &Path, points: usize, law: Law) -> Result<bool> {
    let grid = Grid::new(points)?;
    let (file, origin) = super::load(params, output, &OUTPUTS)?;
    let bar = progress_bar();
    let result = map_with_law(&file, &origin, &grid, law, &|done, total| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    });
    bar.finish_and_clear();
    let m = result?;
    crate::out!("{}", m.markdown());
    if let Some(note) = file.servo.resolve(&origin)?.coarse_encoder_note() {
        crate::outln!("\nNote: {note}.");
    }
    for path in m.write(output)? {
        crate::outln!("wrote: {}", path.display());
    }
    Ok(true)
}

fn progress_bar() -> indicatif::ProgressBar {
    use std::io::IsTerminal;
    if !std::io::stderr().is_terminal() {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(0);
    if let Ok(style) = indicatif::ProgressStyle::with_template(
        "robustness map {bar:40} {pos}/{len} runs [{elapsed} / about {duration}]",
    ) {
        bar.set_style(style);
    }
    bar
}

#[cfg(test)]
mod tests {
    use super::super::NAMES;
    use super::*;

    /// Every column is a benchmark row; `--law theta` puts the θ law in
    /// the adaptive column, named `adaptive-theta`.
    #[test]
    fn the_map_uses_benchmark_rows() {
        for law in [Law::Parameters, Law::Theta] {
            let names = compensations(law);
            for name in names {
                assert!(NAMES.contains(&name), "{name}");
            }
            let cell = |column| {
                Job {
                    column,
                    force: 0.5,
                    stiffness: 3.0,
                }
                .row(&names)
            };
            assert_eq!(cell(1), Row::Static { scale: 0.5 });
            let observer = Row::Observer {
                scale: 0.5,
                stiffness: 3.0,
                damping: true,
            };
            assert_eq!(cell(2), observer);
            let adaptive = Row::Adaptive {
                scale: 0.5,
                stiffness: 3.0,
                law,
            };
            assert_eq!((cell(0), cell(3), cell(4)), (Row::None, adaptive, Row::Rls));
        }
        assert_eq!(compensations(Law::Parameters), COMPENSATIONS);
        assert_eq!(compensations(Law::Theta)[3], "adaptive-theta");
    }

    #[test]
    fn grid_spans_the_issue_ranges_and_rejects_bad_counts() {
        let g = Grid::new(7).unwrap();
        assert!((g.force[0] - 0.25).abs() < 1e-12 && (g.force[6] - 2.0).abs() < 1e-12);
        assert!((g.stiffness[0] - 0.1).abs() < 1e-12 && (g.stiffness[6] - 10.0).abs() < 1e-12);
        assert!((g.stiffness[3] - 1.0).abs() < 1e-12);
        assert!(Grid::new(1).is_err() && Grid::new(26).is_err());
    }

    #[test]
    fn a_small_map_finds_the_adaptive_observer_robust() {
        let text = include_str!("../../../params/olsson1998-servo.toml");
        let file = ParamFile::parse(
            &format!("{text}\n[servo]\nduration = 10\nplant_rate = 10000\n"),
            "p.toml",
        )
        .unwrap();
        let grid = Grid {
            force: vec![0.5, 2.0],
            stiffness: vec![1.0],
        };
        let calls = std::sync::atomic::AtomicUsize::new(0);
        let m = map(&file, "p.toml", &grid, &|_, _| {
            calls.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        })
        .unwrap();
        // none, rls, static x 2, (observer, adaptive) x 2
        assert_eq!(calls.into_inner(), 8);
        assert_eq!(m.cells.len(), 2);
        for c in &m.cells {
            let [none, stat, observer, adaptive, rls] = c.rms;
            assert!(none > 0.0 && rls > 0.0 && stat > 0.0, "{c:?}");
            // a wrong friction level: adaptation beats the fixed observer
            assert!(adaptive < 0.5 * observer, "{c:?}");
            assert!(adaptive < none, "{c:?}");
        }
        let md = m.markdown();
        assert!(
            md.contains("| adaptive |") && md.contains("unstable"),
            "{md}"
        );
    }
}
