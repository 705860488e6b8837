//! SVG line plots (plotters).

use anyhow::{anyhow, Result};
use plotters::prelude::*;
use std::path::Path;

/// One named curve.
pub struct Series<'a> {
    /// Legend label.
    pub label: &'a str,
    /// Points `(x, y)`.
    pub points: Vec<(f64, f64)>,
}

/// Axis scaling.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    /// Linear.
    Linear,
    /// Base-10 logarithmic (positive values only).
    Log,
}

const COLORS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(23, 190, 207),
];

fn range(values: impl Iterator<Item = f64>, axis: Axis) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite() && (axis == Axis::Linear || *v > 0.0)) {
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    if axis == Axis::Log {
        return (lo, if hi > lo { hi } else { lo * 10.0 });
    }
    let pad = if hi > lo {
        0.05 * (hi - lo)
    } else {
        lo.abs().max(1e-12) * 0.1
    };
    (lo - pad, hi + pad)
}

/// Draws `series` into an SVG file at `path`.
pub fn line_plot(
    path: &Path,
    title: &str,
    (x_label, x_axis): (&str, Axis),
    y_label: &str,
    series: &[Series],
) -> Result<()> {
    let mut svg = String::new();
    draw_svg(&mut svg, path, title, (x_label, x_axis), y_label, series)?;
    crate::io::write_bytes(path, svg.as_bytes())
}

/// Renders the plot into `svg` (written to `path` atomically by [`line_plot`]).
fn draw_svg(
    svg: &mut String,
    path: &Path,
    title: &str,
    (x_label, x_axis): (&str, Axis),
    y_label: &str,
    series: &[Series],
) -> Result<()> {
    let root = SVGBackend::with_string(svg, (900, 560)).into_drawing_area();
    let err = |e: &dyn std::fmt::Display| anyhow!("plot {}: {e}", path.display());
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let (x0, x1) = range(
        series.iter().flat_map(|s| s.points.iter().map(|p| p.0)),
        x_axis,
    );
    let (y0, y1) = range(
        series.iter().flat_map(|s| s.points.iter().map(|p| p.1)),
        Axis::Linear,
    );
    let mut builder = ChartBuilder::on(&root);
    builder
        .caption(title, ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(80);
    macro_rules! draw {
        ($chart:expr) => {{
            let mut chart = $chart.map_err(|e| err(&e))?;
            chart
                .configure_mesh()
                .x_desc(x_label)
                .y_desc(y_label)
                .x_label_formatter(&|v| tick_label(*v))
                .y_label_formatter(&|v| tick_label(*v))
                .draw()
                .map_err(|e| err(&e))?;
            for (i, s) in series.iter().enumerate() {
                let color = COLORS[i % COLORS.len()];
                let pts = s
                    .points
                    .iter()
                    .copied()
                    .filter(|p| p.0.is_finite() && p.1.is_finite());
                let pts: Vec<(f64, f64)> = if x_axis == Axis::Log {
                    pts.filter(|p| p.0 > 0.0).collect()
                } else {
                    pts.collect()
                };
                chart
                    .draw_series(LineSeries::new(pts, color.stroke_width(2)))
                    .map_err(|e| err(&e))?
                    .label(s.label)
                    .legend(move |(x, y)| {
                        PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
                    });
            }
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .draw()
                .map_err(|e| err(&e))?;
        }};
    }
    match x_axis {
        Axis::Linear => draw!(builder.build_cartesian_2d(x0..x1, y0..y1)),
        Axis::Log => draw!(builder.build_cartesian_2d((x0..x1).log_scale(), y0..y1)),
    }
    root.present().map_err(|e| err(&e))?;
    drop(root);
    Ok(())
}

/// Axis numbers: plain between 0.01 and 10^4, scientific outside.
fn tick_label(v: f64) -> String {
    let a = v.abs();
    if a < 1e-300 {
        "0".into()
    } else if (1e-2..1e4).contains(&a) {
        let s = format!("{v:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.2e}")
    }
}

/// Pairs two columns into plot points.
pub fn zip(x: &[f64], y: &[f64]) -> Vec<(f64, f64)> {
    x.iter().copied().zip(y.iter().copied()).collect()
}
