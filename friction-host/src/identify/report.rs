//! What `identify` writes: `params.toml`, `report.md`, `fit.csv` and plots.

use super::fit::{Fit, Friction};
use super::{Options, Signals};
use crate::plot::{line_plot, Axis, Series};
use anyhow::{anyhow, Result};
use plotters::prelude::*;
use std::fmt::Write as _;
use std::path::Path;

/// Prediction error on one data set.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorStats {
    /// Samples compared.
    pub samples: usize,
    /// Root-mean-square of measured minus predicted force.
    pub rms: f64,
    /// `|y - y_pred| / |y|` in percent (the relative error of the IDIM-LS literature).
    pub relative: f64,
    /// Largest `|y - y_pred|`.
    pub max: f64,
}

impl ErrorStats {
    /// Whether the RMS and relative errors are finite numbers.
    pub fn is_finite(&self) -> bool {
        self.rms.is_finite() && self.relative.is_finite()
    }

    /// Compares measured `y` and predicted `p`.
    pub fn new(y: &[f64], p: &[f64]) -> Self {
        let (mut e2, mut y2, mut max) = (0.0, 0.0, 0.0f64);
        for (a, b) in y.iter().zip(p) {
            e2 += (a - b) * (a - b);
            y2 += a * a;
            max = max.max((a - b).abs());
        }
        let n = y.len().min(p.len());
        Self {
            samples: n,
            rms: (e2 / n.max(1) as f64).sqrt(),
            relative: 100.0 * (e2 / y2.max(f64::MIN_POSITIVE)).sqrt(),
            max,
        }
    }
}

/// `{:?}` of an f64 is valid TOML for finite values (`1e-5`, `95.1`, `1e16`).
fn toml_number(x: f64) -> String {
    format!("{x:?}")
}

/// The parameter file: the model's keys as `friction simulate` reads them,
/// plus `[plant]` with `mass`, `offset` (when estimated) and
/// `per_normal_force` (when the fit used a normal force).
pub fn params_toml(fit: &Fit, o: &Options) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# Identified by `friction identify --model {}` from {}",
        o.model,
        o.input.display()
    );
    if let Some(n) = &o.columns.normal_force {
        let _ = writeln!(
            s,
            "# Friction coefficients: the friction force is the normal force (column `{n}`) times this model."
        );
    }
    let _ = writeln!(s, "model = \"{}\"", fit.friction.name());
    let mut kv = |k: &str, v: f64| {
        let _ = writeln!(s, "{k} = {}", toml_number(v));
    };
    match fit.friction {
        Friction::Coulomb { fc } => kv("fc", fc),
        Friction::CoulombViscous { fc, sigma2 } => {
            kv("fc", fc);
            kv("sigma2", sigma2);
        }
        Friction::Stribeck { curve, sigma2 } => {
            kv("fc", curve.fc);
            kv("fs", curve.fs);
            kv("vs", curve.vs);
            kv("stribeck_exponent", curve.exponent);
            kv("sigma2", sigma2);
        }
        Friction::LuGre(p) => {
            kv("fc", p.curve.fc);
            kv("fs", p.curve.fs);
            kv("vs", p.curve.vs);
            kv("stribeck_exponent", p.curve.exponent);
            kv("sigma0", p.sigma0);
            kv("sigma1", p.sigma1);
            kv("sigma2", p.sigma2);
        }
    }
    if fit.mass.is_some() || fit.offset.is_some() || o.columns.normal_force.is_some() {
        let _ = writeln!(s, "\n[plant]");
        if let Some(m) = fit.mass {
            let _ = writeln!(s, "mass = {}", toml_number(m));
        }
        if let Some(c) = fit.offset {
            let _ = writeln!(s, "offset = {}", toml_number(c));
        }
        if o.columns.normal_force.is_some() {
            let _ = writeln!(s, "per_normal_force = true");
        }
    }
    s
}

/// At most `max` evenly spread points.
fn thin(points: Vec<(f64, f64)>, max: usize) -> Vec<(f64, f64)> {
    let step = points.len().div_ceil(max.max(1)).max(1);
    points.into_iter().step_by(step).collect()
}

/// Measured against predicted force over time.
pub fn force_plot(path: &Path, title: &str, s: &Signals, pred: &[f64]) -> Result<()> {
    let zip = |y: &[f64]| thin(s.t.iter().copied().zip(y.iter().copied()).collect(), 6000);
    line_plot(
        path,
        title,
        ("t (s)", Axis::Linear),
        "force",
        &[
            Series {
                label: "measured",
                points: zip(&s.f),
            },
            Series {
                label: "predicted",
                points: zip(pred),
            },
            Series {
                label: "error",
                points: zip(&s.f.iter().zip(pred).map(|(a, b)| a - b).collect::<Vec<_>>()),
            },
        ],
    )
}

/// The friction the data show, `(force - mass a - offset) / N`, at each
/// sample's velocity.
pub fn measured_friction(fit: &Fit, s: &Signals) -> Vec<f64> {
    (0..s.len())
        .map(|k| (s.f[k] - fit.mass.unwrap_or(0.0) * s.a[k] - fit.offset.unwrap_or(0.0)) / s.n(k))
        .collect()
}

/// Friction against velocity: the samples (dots) and the fitted
/// steady-state curve (line).
pub fn friction_plot(path: &Path, title: &str, fit: &Fit, s: &Signals) -> Result<()> {
    let measured = measured_friction(fit, s);
    let pts = thin(
        s.v.iter().copied().zip(measured.iter().copied()).collect(),
        2500,
    );
    let (vlo, vhi) =
        s.v.iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(*v), b.max(*v))
            });
    let curve: Vec<(f64, f64)> = (0..=800)
        .map(|i| {
            let v = vlo + (vhi - vlo) * i as f64 / 800.0;
            (v, fit.friction.steady(v))
        })
        .collect();
    // padded, finite and wide enough to place ticks for any data (plotters
    // loops forever on an infinite or vanishing axis)
    let x_range = crate::plot::range([vlo, vhi].into_iter(), crate::plot::Axis::Linear);
    let y_range = crate::plot::range(
        pts.iter().chain(&curve).map(|&(_, y)| y),
        crate::plot::Axis::Linear,
    );
    // drawn within the axes (plotters' pixel arithmetic overflows far
    // outside its range); NaN points left out
    let inside = |pts: Vec<(f64, f64)>| {
        let finite_or_inf = pts.into_iter().filter(|(x, y)| !(x.is_nan() || y.is_nan()));
        crate::plot::within(finite_or_inf.collect(), x_range, y_range)
    };
    let (pts, curve) = (inside(pts), inside(curve));
    let err = |e: &dyn std::fmt::Display| anyhow!("plot {}: {e}", path.display());
    let mut svg = String::new();
    let root = SVGBackend::with_string(&mut svg, (900, 560)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(80)
        .build_cartesian_2d(x_range.0..x_range.1, y_range.0..y_range.1)
        .map_err(|e| err(&e))?;
    let ylabel = if fit.offset.is_some() {
        "friction: force - mass a - offset"
    } else {
        "friction"
    };
    chart
        .configure_mesh()
        .x_desc("velocity")
        .y_desc(ylabel)
        .draw()
        .map_err(|e| err(&e))?;
    let blue = RGBColor(31, 119, 180);
    let red = RGBColor(214, 39, 40);
    chart
        .draw_series(
            pts.iter()
                .map(|&p| Circle::new(p, 1, blue.mix(0.4).filled())),
        )
        .map_err(|e| err(&e))?
        .label("measured")
        .legend(move |(x, y)| Circle::new((x + 10, y), 3, blue.filled()));
    chart
        .draw_series(LineSeries::new(curve, red.stroke_width(2)))
        .map_err(|e| err(&e))?
        .label(format!("fitted {} (steady state)", fit.friction.name()))
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], red.stroke_width(2)));
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperLeft)
        .draw()
        .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))?;
    drop(chart);
    drop(root);
    crate::io::write_bytes(path, svg.as_bytes())
}

/// Everything the report shows.
pub struct Report<'a> {
    /// The options.
    pub options: &'a Options,
    /// Estimation signals.
    pub signals: &'a Signals,
    /// The fit, if any.
    pub fit: Option<&'a Fit>,
    /// Why the fit is rejected, if it is.
    pub rejected: Option<&'a str>,
    /// Error on the estimation data.
    pub estimation: Option<ErrorStats>,
    /// Error on the validation data.
    pub validation: Option<ErrorStats>,
    /// Plot file names (relative to the report), with captions.
    pub plots: Vec<(String, String)>,
}

fn sci(x: f64) -> String {
    let a = x.abs();
    if a != 0.0 && !(1e-3..1e5).contains(&a) {
        format!("{x:.6e}")
    } else {
        format!("{x:.6}")
    }
}

/// `report.md`.
pub fn markdown(r: &Report) -> String {
    let o = r.options;
    let s = r.signals;
    let mut m = String::new();
    let _ = writeln!(
        m,
        "# Identification: `{}` from `{}`\n",
        o.model,
        o.input.display()
    );
    if let Some(why) = r.rejected {
        let _ = writeln!(m, "**Rejected:** {why}\n");
    }
    let _ = writeln!(m, "## Data\n");
    let c = &o.columns;
    let _ = writeln!(
        m,
        "- {} samples at {:.4} Hz; time `{}`, {}, force `{}` times {}{}",
        s.raw_samples,
        s.fs,
        c.time,
        match &c.velocity {
            Some(v) => format!("measured velocity `{v}`"),
            None => format!("position `{}`", c.position),
        },
        c.force,
        c.force_gain,
        match &c.normal_force {
            Some(n) => format!(", normal force `{n}` (the friction parameters are coefficients)"),
            None => String::new(),
        }
    );
    if let Some((lo, hi)) = s.resampled {
        let _ = writeln!(
            m,
            "- the time steps vary from {lo:.4e} s to {hi:.4e} s: every column was linearly interpolated onto the median step"
        );
    }
    let _ = writeln!(
        m,
        "- model: `force = {}{}{}`",
        if o.inertia { "mass * a + " } else { "" },
        if c.normal_force.is_some() {
            "N * friction(v)"
        } else {
            "friction(v)"
        },
        if o.inertia { " + offset" } else { "" }
    );
    let _ = writeln!(
        m,
        "- conditioning: order-{} Butterworth low-pass at {:.4} Hz applied forward and backward (zero phase) to the {} and to the force{}; {}; decimation by {} to {} samples (period {:.4e} s)",
        o.conditioning.order,
        s.cutoff,
        if c.velocity.is_some() { "velocity" } else { "position" },
        if c.normal_force.is_some() { " and normal force" } else { "" },
        if c.velocity.is_some() {
            "acceleration by central differences of the velocity"
        } else {
            "velocity and acceleration by central differences"
        },
        s.decimate,
        s.len(),
        s.h
    );
    let _ = writeln!(
        m,
        "- parallel filtering: every regressor and every prediction is computed at the raw rate from the conditioned velocity and acceleration and passes through the same zero-phase filter and decimation as the force before the comparison"
    );
    if let Some(fit) = r.fit {
        let _ = writeln!(m, "\n## Estimates\n");
        for st in &fit.stages {
            let _ = writeln!(m, "- {st}");
        }
        let _ = writeln!(
            m,
            "\n| parameter | estimate | standard deviation | relative (%) |\n|---|---:|---:|---:|"
        );
        for p in &fit.params {
            let _ = writeln!(
                m,
                "| `{}` | {} | {} | {:.3} |",
                p.name,
                sci(p.value),
                sci(p.std),
                p.relative_std()
            );
        }
    }
    let _ = writeln!(m, "\n## Error\n");
    let _ = writeln!(
        m,
        "Relative error `|f - f_pred| / |f|` (the IDIM-LS literature's measure) and RMS of the force error.\n"
    );
    let _ = writeln!(
        m,
        "| data | samples | RMS error | largest error | relative error (%) |\n|---|---:|---:|---:|---:|"
    );
    for (role, name, e) in [
        ("estimation", o.input.display().to_string(), r.estimation),
        (
            "cross-validation",
            o.validate
                .as_ref()
                .map(|p| p.display().to_string())
                .unwrap_or_default(),
            r.validation,
        ),
    ] {
        if let Some(e) = e {
            let _ = writeln!(
                m,
                "| {role}: `{name}` | {} | {} | {} | {:.3} |",
                e.samples,
                sci(e.rms),
                sci(e.max),
                e.relative
            );
        }
    }
    if !r.plots.is_empty() {
        let _ = writeln!(m, "\n## Plots\n");
        for (file, caption) in &r.plots {
            let _ = writeln!(m, "{caption}\n\n![{caption}]({file})\n");
        }
    }
    m
}
