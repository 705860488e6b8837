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
//! cores (rayon), with a progress bar on a terminal.

use super::{simulate, Row};
use crate::io::write_cells;
use crate::params::ParamFile;
use anyhow::{anyhow, bail, Context, Result};
use plotters::prelude::*;
use rayon::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The compensations of the map, in column order.
pub const COMPENSATIONS: [&str; 5] = ["none", "static", "observer", "adaptive", "rls"];

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
    /// RMS error per compensation, in the order of [`COMPENSATIONS`].
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
}

/// One simulation of the map.
#[derive(Clone, Copy)]
struct Job {
    column: usize,
    force: f64,
    stiffness: f64,
}

impl Job {
    /// The benchmark's row of this column's name, scaled to the cell
    /// (every name of [`COMPENSATIONS`] is one of [`super::ROWS`]: tested).
    fn row(&self) -> Row {
        COMPENSATIONS
            .get(self.column)
            .and_then(|name| Row::named(name))
            .map_or(Row::None, |row| row.scaled(self.force, self.stiffness))
    }
}

/// Runs the map for `file` (`origin` names it), calling `progress` with
/// (runs done, runs in all) after each run.
pub fn map(
    file: &ParamFile,
    origin: &str,
    grid: &Grid,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<RobustnessMap> {
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
            let name = COMPENSATIONS[job.column];
            let run = simulate(name, &cfg, spec, job.row()).transpose();
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

    /// The summary of `compensation` (a name of [`COMPENSATIONS`]).
    pub fn summary(&self, compensation: &str) -> Option<Summary> {
        let column = COMPENSATIONS.iter().position(|c| *c == compensation)?;
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

    /// Writes `robustness.csv` (RMS over the last half in mrad) and the
    /// heat map `robustness.svg` into `dir`; returns the files written.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>> {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        let mut headers = vec!["force_scale".to_string(), "stiffness_scale".to_string()];
        headers.extend(COMPENSATIONS.iter().map(|c| format!("rms_mrad_{c}")));
        let headers: Vec<&str> = headers.iter().map(String::as_str).collect();
        let mut columns: Vec<Vec<f64>> = vec![
            self.cells.iter().map(|c| c.force).collect(),
            self.cells.iter().map(|c| c.stiffness).collect(),
        ];
        for k in 0..COMPENSATIONS.len() {
            columns.push(self.cells.iter().map(|c| 1e3 * c.rms[k]).collect());
        }
        let columns: Vec<&[f64]> = columns.iter().map(Vec::as_slice).collect();
        let csv = dir.join(OUTPUTS[0]);
        // an unstable cell says so; a form the model lacks is empty
        write_cells(&csv, &headers, &columns, |x| {
            if x.is_finite() {
                format!("{x:.12e}")
            } else if x.is_nan() {
                String::new()
            } else {
                UNSTABLE.to_string()
            }
        })?;
        let svg = dir.join(OUTPUTS[1]);
        self.heat_map(&svg)?;
        Ok(vec![csv, svg])
    }

    /// One panel per model-based compensation (static, observer, adaptive,
    /// rls): each cell coloured by its RMS over that of `none`, on a log
    /// scale from 0.001 (dark) to 1 and above (red), with the ratio written
    /// in the cell.
    pub fn heat_map(&self, path: &Path) -> Result<()> {
        let (nf, ns) = (self.grid.force.len(), self.grid.stiffness.len());
        let none = self.cells.first().map_or(f64::NAN, |c| c.rms[0]);
        let panels = [1usize, 2, 3, 4];
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, (1200, 1000)).into_drawing_area();
            let err = |e: &dyn std::fmt::Display| anyhow!("plot {}: {e}", path.display());
            root.fill(&WHITE).map_err(|e| err(&e))?;
            let root = root
                .titled(
                    &format!(
                        "RMS tracking error / none ({:.3} mrad), last half: {}",
                        1e3 * none,
                        self.origin
                    ),
                    ("sans-serif", 20),
                )
                .map_err(|e| err(&e))?;
            for (area, &column) in root.split_evenly((2, 2)).iter().zip(&panels) {
                let mut chart = ChartBuilder::on(area)
                    .caption(COMPENSATIONS[column], ("sans-serif", 18))
                    .margin(10)
                    .x_label_area_size(40)
                    .y_label_area_size(55)
                    .build_cartesian_2d(0.0..ns as f64, 0.0..nf as f64)
                    .map_err(|e| err(&e))?;
                let stiffness = self.grid.stiffness.clone();
                let force = self.grid.force.clone();
                chart
                    .configure_mesh()
                    .disable_mesh()
                    .x_labels(ns + 1)
                    .y_labels(nf + 1)
                    .x_label_formatter(&|x| label(&stiffness, *x))
                    .y_label_formatter(&|y| label(&force, *y))
                    .x_desc("stiffness scale")
                    .y_desc("friction level scale (fc, fs)")
                    .draw()
                    .map_err(|e| err(&e))?;
                for (i, cell) in self.cells.iter().enumerate() {
                    let (fi, si) = ((i / ns) as f64, (i % ns) as f64);
                    let ratio = cell.rms[column] / none;
                    chart
                        .draw_series(std::iter::once(Rectangle::new(
                            [(si, fi), (si + 1.0, fi + 1.0)],
                            colour(ratio).filled(),
                        )))
                        .map_err(|e| err(&e))?;
                    let text = if ratio.is_nan() {
                        "-".to_string()
                    } else if ratio.is_infinite() {
                        "unst.".to_string()
                    } else if ratio < 0.01 {
                        format!("{ratio:.3}")
                    } else {
                        format!("{ratio:.2}")
                    };
                    chart
                        .draw_series(std::iter::once(Text::new(
                            text,
                            (si + 0.22, fi + 0.6),
                            ("sans-serif", 13).into_font().color(&BLACK),
                        )))
                        .map_err(|e| err(&e))?;
                }
            }
            root.present().map_err(|e| err(&e))?;
        }
        crate::io::write_bytes(path, svg.as_bytes())
    }

    /// The Markdown of the report section: a summary per compensation and
    /// the adaptive and observer grids as ratios to `none`.
    pub fn markdown(&self) -> String {
        let mut md = String::new();
        let none = self.cells.first().map_or(f64::NAN, |c| c.rms[0]);
        let _ = writeln!(
            md,
            "RMS tracking error over the last half, compensators built with the friction level \
             (`fc`, `fs`) and the stiffness of the model scaled; the plant is the nominal one. \
             {} x {} cells; `none`: {:.4} mrad.\n",
            self.grid.force.len(),
            self.grid.stiffness.len(),
            1e3 * none
        );
        md.push_str("| compensation | nominal [mrad] | median [mrad] | worst [mrad] | beats static | unstable |\n");
        md.push_str("|---|---:|---:|---:|---:|---:|\n");
        let nominal = self.nominal();
        for (k, name) in COMPENSATIONS.iter().enumerate() {
            if let Some(s) = self.summary(name) {
                let at = nominal.map_or(f64::NAN, |c| c.rms[k]);
                let _ = writeln!(
                    md,
                    "| {name} | {} | {} | {} | {:.0} % | {:.0} % |",
                    mrad(at),
                    mrad(s.median),
                    mrad(s.worst),
                    100.0 * s.beats_static,
                    100.0 * s.unstable
                );
            }
        }
        for (k, name) in [(3usize, "adaptive"), (2, "observer")] {
            let _ = writeln!(
                md,
                "\n`{name}` / `none` (rows: friction level scale; columns: stiffness scale):\n"
            );
            md.push_str("| level \\ stiffness |");
            for s in &self.grid.stiffness {
                let _ = write!(md, " {} |", short(*s));
            }
            md.push_str("\n|---|");
            md.push_str(&"---:|".repeat(self.grid.stiffness.len()));
            md.push('\n');
            for (i, f) in self.grid.force.iter().enumerate() {
                let _ = write!(md, "| {} |", short(*f));
                for j in 0..self.grid.stiffness.len() {
                    let r = self
                        .cells
                        .get(i * self.grid.stiffness.len() + j)
                        .map_or(f64::NAN, |c| c.rms[k] / none);
                    let _ = write!(md, " {} |", ratio_text(r));
                }
                md.push('\n');
            }
        }
        md
    }
}

fn mrad(rms: f64) -> String {
    if rms.is_infinite() {
        "unstable".into()
    } else if rms.is_nan() {
        "-".into()
    } else {
        format!("{:.4}", 1e3 * rms)
    }
}

fn ratio_text(r: f64) -> String {
    if r.is_infinite() {
        "unstable".into()
    } else if r.is_nan() {
        "-".into()
    } else {
        format!("{r:.3}")
    }
}

/// A scale as a short label (`0.25`, `1`, `10`).
fn short(x: f64) -> String {
    let s = format!("{x:.2}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// The axis label at the centre of cell `i` (`x = i + 0.5`), none elsewhere.
fn label(values: &[f64], x: f64) -> String {
    let i = x - 0.5;
    if (i - i.round()).abs() < 1e-6 && i >= 0.0 {
        values
            .get(i.round() as usize)
            .map_or(String::new(), |v| short(*v))
    } else {
        String::new()
    }
}

/// The colour of a ratio to `none`: green (1e-3 and below) through yellow
/// to red (1 and above), grey for unstable or missing.
fn colour(ratio: f64) -> RGBColor {
    if !ratio.is_finite() {
        return RGBColor(190, 190, 190);
    }
    // 0 at 1e-3, 1 at 1
    let f = ((ratio.max(1e-12).log10() + 3.0) / 3.0).clamp(0.0, 1.0);
    let (r, g) = if f < 0.5 {
        (2.0 * f, 1.0)
    } else {
        (1.0, 2.0 * (1.0 - f))
    };
    RGBColor(
        (60.0 + 195.0 * r) as u8,
        (60.0 + 160.0 * g) as u8,
        (80.0 - 40.0 * f) as u8,
    )
}

/// `friction robustness`: runs the map for the file (or the built-in
/// `olsson1998-servo` set), prints the summary and writes the CSV and the
/// heat map.
pub fn run(params: Option<&Path>, output: &Path, points: usize) -> Result<bool> {
    let grid = Grid::new(points)?;
    let (file, origin) = super::load(params, output, &OUTPUTS)?;
    let bar = progress_bar();
    let result = map(&file, &origin, &grid, &|done, total| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    });
    bar.finish_and_clear();
    let m = result?;
    crate::out!("{}", m.markdown());
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

/// The robustness section of the validation report: a 3 x 3 map (the corners and the centre of the CLI's 7 x 7 grid, to keep `validate` fast) on the
/// built-in `olsson1998-servo` set, with the heat map written into `dir`.
pub fn report_section(dir: &Path) -> Result<String> {
    let file = crate::params::param_set("olsson1998-servo")?;
    let grid = Grid::new(3)?;
    let m = map(&file, "params/olsson1998-servo.toml", &grid, &|_, _| {})?;
    m.heat_map(&dir.join(OUTPUTS[1]))?;
    Ok(format!(
        "\n## Robustness map (`friction robustness`)\n\n{}\n![robustness]({})\n",
        m.markdown(),
        OUTPUTS[1]
    ))
}

#[cfg(test)]
mod tests {
    use super::super::NAMES;
    use super::*;

    #[test]
    fn the_map_uses_benchmark_rows() {
        for name in COMPENSATIONS {
            assert!(NAMES.contains(&name), "{name}");
        }
        let cell = |column| {
            Job {
                column,
                force: 0.5,
                stiffness: 3.0,
            }
            .row()
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
            law: super::super::Law::Parameters,
        };
        assert_eq!((cell(0), cell(3), cell(4)), (Row::None, adaptive, Row::Rls));
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
