//! The robustness map's render half: the CSV, the heat map and the
//! Markdown of [`RobustnessMap`], and the validation report's section; the
//! map itself is run in [`robustness`](super::robustness).

use super::robustness::{map, Grid, RobustnessMap, OUTPUTS, UNSTABLE};
use crate::io::write_cells;
use anyhow::{anyhow, Context, Result};
use plotters::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

impl RobustnessMap {
    /// Writes `robustness.csv` (RMS over the last half in mrad) and the
    /// heat map `robustness.svg` into `dir`; returns the files written.
    pub fn write(&self, dir: &Path) -> Result<Vec<PathBuf>> {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        let mut headers = vec!["force_scale".to_string(), "stiffness_scale".to_string()];
        let names = self.names();
        headers.extend(names.iter().map(|c| format!("rms_mrad_{c}")));
        let headers: Vec<&str> = headers.iter().map(String::as_str).collect();
        let mut columns: Vec<Vec<f64>> = vec![
            self.cells.iter().map(|c| c.force).collect(),
            self.cells.iter().map(|c| c.stiffness).collect(),
        ];
        for k in 0..names.len() {
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
                    .caption(self.names()[column], ("sans-serif", 18))
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
        let names = self.names();
        for (k, name) in names.iter().enumerate() {
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
        for (k, name) in [(3usize, names[3]), (2, names[2])] {
            let _ = writeln!(
                md,
                "\n`{name}` / `none` (rows: friction level scale; columns: stiffness scale):\n"
            );
            md.push_str("| level \\ stiffness |");
            for s in &self.grid.stiffness {
                let _ = write!(md, " {} |", two_decimals(*s));
            }
            md.push_str("\n|---|");
            md.push_str(&"---:|".repeat(self.grid.stiffness.len()));
            md.push('\n');
            for (i, f) in self.grid.force.iter().enumerate() {
                let _ = write!(md, "| {} |", two_decimals(*f));
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
fn two_decimals(x: f64) -> String {
    let s = format!("{x:.2}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// The axis label at the centre of cell `i` (`x = i + 0.5`), none elsewhere.
fn label(values: &[f64], x: f64) -> String {
    let i = x - 0.5;
    if (i - i.round()).abs() < 1e-6 && i >= 0.0 {
        values
            .get(i.round() as usize)
            .map_or(String::new(), |v| two_decimals(*v))
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
