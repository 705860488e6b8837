//! The renderers of a [`ServoBenchmark`]: the console lines and table,
//! the Markdown section, `trace.csv` and the SVG plots.

use super::{benchmark, ServoBenchmark, ServoRun};
use crate::io::write_columns;
use crate::plot::{line_plot, Axis, Series};
use anyhow::{Context, Result};
use std::fmt::Write as _;
use std::path::Path;

impl ServoBenchmark {
    /// One line per compensation: `servo NAME RMS_MRAD MAX_MRAD`, or
    /// `servo NAME unstable`.
    pub fn lines(&self) -> Vec<String> {
        self.runs
            .iter()
            .map(|r| {
                if r.stable {
                    format!("servo {} {:.4} {:.4}", r.name, 1e3 * r.rms, 1e3 * r.max)
                } else {
                    format!("servo {} unstable", r.name)
                }
            })
            .collect()
    }

    fn setup(&self) -> String {
        let c = &self.config;
        let mut s = format!(
            "J = {} kg m^2, kc = {} N m/A, reference {} sin(2 pi {} t) rad for {} s; PID at {} Hz \
             (kp = {}, ki = {}, kd = {}, limit {} A), observer gain {} 1/s; plant at {} Hz; \
             adaptation rate {} 1/s, theta in [{}, {}]; least squares forgetting {}; \
             errors over the last 90 % (rms, max) and the last half (rms half)",
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
            c.plant_rate,
            c.adaptation_rate,
            c.theta_min,
            c.theta_max,
            c.rls_forgetting,
        );
        if c.is_ideal() {
            s.push_str("; ideal drive");
        } else {
            let _ = write!(
                s,
                "; drive: encoder {} counts/rev, friction drift {:?}, load friction {} 1/(N m), \
                 delay {} ticks",
                c.encoder_counts, c.friction_drift, c.load_friction, c.delay_ticks
            );
        }
        if c.asymmetry != 0.0 || c.gravity[0] != 0.0 || !c.ripple.is_empty() {
            let _ = write!(
                s,
                "; plant: friction asymmetry {}, gravity {:?} (T, x0), ripple {:?}",
                c.asymmetry, c.gravity, c.ripple
            );
        }
        if let Some(p) = &c.plant_bam {
            let _ = write!(
                s,
                "; plant friction: BAM {:?} budget, presliding {} rad",
                p.form, c.presliding
            );
        }
        if c.velocity_filter > 0.0 {
            let _ = write!(s, ", velocity low-pass {} Hz", c.velocity_filter);
        }
        if c.velocity_observer > 0.0 {
            let _ = write!(s, ", velocity observer {} Hz", c.velocity_observer);
        }
        let _ = write!(
            s,
            "; adaptive rows: per-parameter law at {} 1/s (dead zone {} rad, stiffness law at {} 1/s), θ law rows `adaptive-theta`{}",
            c.parameter_rate,
            c.dead_zone,
            c.stiffness_rate,
            if c.supervisor {
                ", each supervised (fallback: the static row of its scale)"
            } else {
                ", unsupervised"
            }
        );
        s
    }

    fn figures(r: &ServoRun, none: f64) -> [String; 4] {
        if r.stable {
            [
                format!("{:.4}", 1e3 * r.rms),
                format!("{:.4}", 1e3 * r.max),
                format!("{:.4}", 1e3 * r.rms_half),
                format!("{:.3}", r.rms / none),
            ]
        } else {
            ["unstable".into(), "-".into(), "-".into(), "-".into()]
        }
    }

    fn none_rms(&self) -> f64 {
        self.run("none").map_or(f64::NAN, |r| r.rms)
    }

    /// The results as a plain-text table.
    pub fn table(&self) -> String {
        let none = self.none_rms();
        let mut s = format!(
            "{:<20} {:>12} {:>12} {:>14} {:>10}\n",
            "compensation", "rms [mrad]", "max [mrad]", "rms half", "rms/none"
        );
        for r in &self.runs {
            let [rms, max, half, ratio] = Self::figures(r, none);
            let _ = writeln!(
                s,
                "{:<20} {rms:>12} {max:>12} {half:>14} {ratio:>10}",
                r.name
            );
        }
        s
    }

    /// The results as a Markdown section body (set-up, table, note).
    pub fn markdown(&self) -> String {
        let none = self.none_rms();
        let mut md = format!("{}.\n\n", self.setup());
        md.push_str(
            "| compensation | rms (mrad) | max (mrad) | rms last half (mrad) | rms / none |\n|---|---|---|---|---|\n",
        );
        for r in &self.runs {
            let [rms, max, half, ratio] = Self::figures(r, none);
            let _ = writeln!(md, "| {} | {rms} | {max} | {half} | {ratio} |", r.name);
        }
        if let Some(note) = &self.note {
            let _ = writeln!(md, "\n{note}.");
        }
        md
    }

    /// The trace's columns: `t`, `x_ref`, `drift`, then `e_NAME` (rad) and
    /// `fhat_NAME` (N m) for each compensation, then the adapted quantities
    /// (`theta_NAME` for the adaptive rows, `fc_rls`, `sigma2_rls`).
    fn columns(&self) -> (Vec<String>, Vec<&[f64]>) {
        let mut headers = vec!["t".to_string(), "x_ref".to_string(), "drift".to_string()];
        let mut cols: Vec<&[f64]> = vec![&self.t, &self.x_ref, &self.drift];
        for r in &self.runs {
            headers.push(format!("e_{}", r.name));
            cols.push(&r.error);
        }
        for r in &self.runs {
            headers.push(format!("fhat_{}", r.name));
            cols.push(&r.friction);
        }
        for r in &self.runs {
            for (name, column) in r.adapted_names.iter().zip(&r.adapted) {
                headers.push(format!("{name}_{}", r.name));
                cols.push(column);
            }
        }
        (headers, cols)
    }

    /// The plots this benchmark draws: `(file, title, y label, series)`.
    fn plots(&self) -> Vec<(&'static str, &'static str, &'static str, Vec<Series<'_>>)> {
        let thin = |v: &[f64]| -> Vec<(f64, f64)> {
            let step = (v.len() / 4000).max(1);
            self.t
                .iter()
                .zip(v)
                .step_by(step)
                .filter(|(_, y)| y.is_finite())
                .map(|(&t, &y)| (t, y))
                .collect()
        };
        let errors = |names: &[&str]| -> Vec<Series<'_>> {
            names
                .iter()
                .filter_map(|n| self.run(n))
                .filter(|r| r.stable)
                .map(|r| Series {
                    label: r.name,
                    points: thin(&r.error.iter().map(|e| 1e3 * e).collect::<Vec<_>>()),
                })
                .collect()
        };
        let mut scales = vec![Series {
            label: "plant: friction drift",
            points: thin(&self.drift),
        }];
        if self.config.load_friction > 0.0 {
            if let Some(r) = self.run("adaptive") {
                scales.push(Series {
                    label: "plant: drift x load factor (1 s mean, adaptive run)",
                    points: thin(&moving_mean(&r.plant_scale, self.config.rate as usize)),
                });
            }
        }
        let coulomb = 1.0 / coulomb_level_of(self).max(f64::MIN_POSITIVE);
        for r in self.runs.iter().filter(|r| r.stable) {
            // (label, factor on the first adapted column)
            let (label, factor) = match r.name {
                "adaptive" => ("adaptive: Fc+^ / Fc", coulomb),
                "adaptive+50" => ("adaptive+50: Fc+^ / Fc", coulomb),
                "adaptive-50" => ("adaptive-50: Fc+^ / Fc", coulomb),
                "adaptive-theta" => ("adaptive-theta: theta", r.scale),
                "adaptive-theta+50" => ("adaptive-theta+50: 1.5 theta", r.scale),
                "adaptive-theta-50" => ("adaptive-theta-50: 0.5 theta", r.scale),
                "rls" => ("rls: Fc^ / Fc", coulomb),
                _ => continue,
            };
            let Some(first) = r.adapted.first() else {
                continue;
            };
            scales.push(Series {
                label,
                points: thin(&first.iter().map(|x| factor * x).collect::<Vec<_>>()),
            });
        }
        vec![
            (
                "errors.svg",
                "Tracking error by compensation",
                "x - x_ref [mrad]",
                errors(&["nofriction", "none", "static", "observer"]),
            ),
            (
                "observer.svg",
                "Observer: nominal, Fc and Fs +/-50 %, without sigma1 dz/dt",
                "x - x_ref [mrad]",
                errors(&[
                    "nofriction",
                    "observer",
                    "observer+50",
                    "observer-50",
                    "observer-nodamping",
                ]),
            ),
            (
                "adaptive.svg",
                "Adaptive compensation: per-parameter (nominal, +/-50 %), theta law (+/-50 %), least squares",
                "x - x_ref [mrad]",
                errors(&[
                    "static",
                    "adaptive",
                    "adaptive+50",
                    "adaptive-50",
                    "adaptive-theta+50",
                    "adaptive-theta-50",
                    "rls",
                ]),
            ),
            (
                "adaptation.svg",
                "Adapted friction scale against the plant's",
                "friction scale (1 = nominal model)",
                scales,
            ),
        ]
    }

    /// Writes `dir/trace.csv` (see `columns`) and the SVG plots
    /// (`errors.svg`, `observer.svg`, `adaptive.svg`, `adaptation.svg`, each
    /// where it has curves); returns the plot paths.
    pub fn write(&self, dir: &Path) -> Result<Vec<std::path::PathBuf>> {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        let (headers, cols) = self.columns();
        let headers: Vec<&str> = headers.iter().map(String::as_str).collect();
        write_columns(&dir.join("trace.csv"), &headers, &cols)?;
        let mut written = Vec::new();
        for (file, title, y, series) in self.plots() {
            let path = dir.join(file);
            if series.is_empty() || (file == "adaptation.svg" && series.len() < 2) {
                // no stale plot of an earlier run beside this one
                if path.exists() {
                    std::fs::remove_file(&path)
                        .with_context(|| format!("cannot remove {}", path.display()))?;
                }
                continue;
            }
            line_plot(&path, title, ("t [s]", Axis::Linear), y, &series)?;
            written.push(path);
        }
        Ok(written)
    }
}

/// The nominal Coulomb level of the benchmark's model (for the `rls` plot).
fn coulomb_level_of(b: &ServoBenchmark) -> f64 {
    b.coulomb_level
}

/// The mean of `v` over a trailing window of `w` samples.
fn moving_mean(v: &[f64], w: usize) -> Vec<f64> {
    let w = w.max(1);
    let mut sum = 0.0;
    let mut out = Vec::with_capacity(v.len());
    for (i, x) in v.iter().enumerate() {
        sum += x;
        if i >= w {
            sum -= v[i - w];
        }
        out.push(sum / (i + 1).min(w) as f64);
    }
    out
}

/// The plot and trace files `friction servo` writes into its output folder.
pub const OUTPUTS: [&str; 5] = [
    "trace.csv",
    "errors.svg",
    "observer.svg",
    "adaptive.svg",
    "adaptation.svg",
];

/// `friction servo`'s console: the lines, the table and the note, then
/// (after `write`) where the trace and the plots are.
pub(super) fn print(bench: &ServoBenchmark, output: &Path) -> Result<()> {
    for line in bench.lines() {
        crate::outln!("{line}");
    }
    crate::outln!();
    crate::out!("{}", bench.table());
    if let Some(note) = &bench.note {
        crate::outln!("note: {note}");
    }
    let plots = bench.write(output)?;
    crate::outln!("trace: {}", output.join("trace.csv").display());
    for p in plots {
        crate::outln!("plot:  {}", p.display());
    }
    Ok(())
}

/// The servo section of the validation report: the default benchmark on the
/// built-in `olsson1998-servo` set, as Markdown (heading included).
pub fn report_section() -> Result<String> {
    let file = crate::params::param_set("olsson1998-servo")?;
    let bench = benchmark(&file, "params/olsson1998-servo.toml")?;
    Ok(format!(
        "\n## Servo benchmark (`friction servo`)\n\n{}",
        bench.markdown()
    ))
}
