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

/// Values beyond this magnitude are drawn at it: a span between two
/// finite values near `f64::MAX` would overflow to infinity, and plotters
/// loops forever on an infinite or vanishing axis.
const AXIS_LIMIT: f64 = 1e300;

/// The axis range of `values` (finite ones; positive ones for a log axis),
/// padded by 5 % of the span, at least 1e-9 of the largest magnitude and
/// 1e-100, so that the range is finite and wide enough to place ticks.
pub(crate) fn range(values: impl Iterator<Item = f64>, axis: Axis) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for v in values.filter(|v| v.is_finite() && (axis == Axis::Linear || *v > 0.0)) {
        let v = v.clamp(-AXIS_LIMIT, AXIS_LIMIT);
        lo = lo.min(v);
        hi = hi.max(v);
    }
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    if axis == Axis::Log {
        let lo = lo.max(1e-300);
        return (lo, if hi > 1.01 * lo { hi } else { lo * 10.0 });
    }
    let magnitude = lo.abs().max(hi.abs());
    let pad = if hi > lo {
        // 0.05 hi - 0.05 lo cannot overflow within the limit
        (0.05 * hi - 0.05 * lo).max(1e-9 * magnitude).max(1e-100)
    } else {
        (0.1 * magnitude).max(1e-12)
    };
    (lo - pad, hi + pad)
}

/// `points` clamped into the axis ranges `x` and `y`: plotters' pixel
/// arithmetic overflows far outside its range, so values beyond an axis
/// are drawn at its edge.
pub(crate) fn within(points: Vec<(f64, f64)>, x: (f64, f64), y: (f64, f64)) -> Vec<(f64, f64)> {
    points
        .into_iter()
        .map(|(a, b)| (a.clamp(x.0, x.1), b.clamp(y.0, y.1)))
        .collect()
}

/// Draws `series` into an SVG file at `path` (written atomically).
pub fn line_plot(
    path: &Path,
    title: &str,
    x: (&str, Axis),
    y_label: &str,
    series: &[Series],
) -> Result<()> {
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 560)).into_drawing_area();
        let err = |e: &dyn std::fmt::Display| anyhow!("plot {}: {e}", path.display());
        root.fill(&WHITE).map_err(|e| err(&e))?;
        draw_chart(&root, path, title, x, y_label, series)?;
        root.present().map_err(|e| err(&e))?;
    }
    crate::io::write_bytes(path, svg.as_bytes())
}

/// Core against reference with their difference below: the top panel shows
/// both curves (the reference drawn first, the core over it), the bottom
/// panel `core - reference`, so a reader sees where they differ even when
/// the curves cover each other.
pub fn comparison_plot(
    path: &Path,
    title: &str,
    x_label: &str,
    y_label: &str,
    core: Vec<(f64, f64)>,
    reference: Vec<(f64, f64)>,
) -> Result<()> {
    let error: Vec<(f64, f64)> = core
        .iter()
        .zip(&reference)
        .map(|(c, r)| (c.0, c.1 - r.1))
        .collect();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (900, 760)).into_drawing_area();
        let err = |e: &dyn std::fmt::Display| anyhow!("plot {}: {e}", path.display());
        root.fill(&WHITE).map_err(|e| err(&e))?;
        let (top, bottom) = root.split_vertically(470);
        draw_chart(
            &top,
            path,
            title,
            (x_label, Axis::Linear),
            y_label,
            &[
                Series {
                    label: "reference",
                    points: reference,
                },
                Series {
                    label: "core",
                    points: core,
                },
            ],
        )?;
        draw_chart(
            &bottom,
            path,
            "",
            (x_label, Axis::Linear),
            &format!("core - reference ({y_label})"),
            &[Series {
                label: "core - reference",
                points: error,
            }],
        )?;
        root.present().map_err(|e| err(&e))?;
    }
    crate::io::write_bytes(path, svg.as_bytes())
}

/// Draws one chart with its mesh, series and legend into `area`.
fn draw_chart<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    path: &Path,
    title: &str,
    (x_label, x_axis): (&str, Axis),
    y_label: &str,
    series: &[Series],
) -> Result<()> {
    let err = |e: &dyn std::fmt::Display| anyhow!("plot {}: {e}", path.display());
    let (x0, x1) = range(
        series.iter().flat_map(|s| s.points.iter().map(|p| p.0)),
        x_axis,
    );
    let (y0, y1) = range(
        series.iter().flat_map(|s| s.points.iter().map(|p| p.1)),
        Axis::Linear,
    );
    let mut builder = ChartBuilder::on(area);
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
                .x_label_formatter(&|v| tick_label(*v, x0.abs().max(x1.abs())))
                .y_label_formatter(&|v| tick_label(*v, y0.abs().max(y1.abs())))
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
                // beyond AXIS_LIMIT, drawn at the axis' edge (plotters'
                // pixel arithmetic overflows far outside its range)
                let pts = within(thin(pts), (x0, x1), (y0, y1));
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
    Ok(())
}

/// Axis numbers: plain between 0.01 and 10^4, scientific outside;
/// `scale` is the axis' largest magnitude: a tick within 1e-9 of it from
/// zero is zero (not `-2.2e-16`).
fn tick_label(v: f64, scale: f64) -> String {
    let a = v.abs();
    if a < 1e-300 || a < 1e-9 * scale {
        "0".into()
    } else if (1e-2..1e4).contains(&a) {
        let s = format!("{v:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.2e}")
    }
}

/// The most points a curve is drawn with: longer curves keep the first,
/// smallest and largest point of each bucket (the envelope a reader sees),
/// so a long run's plot stays small.
const MAX_POINTS: usize = 6000;

fn thin(points: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    if points.len() <= MAX_POINTS {
        return points;
    }
    let bucket = points.len().div_ceil(MAX_POINTS / 3);
    let mut out = Vec::with_capacity(MAX_POINTS + 3);
    for chunk in points.chunks(bucket) {
        let (mut lo, mut hi) = (0, 0);
        for (i, p) in chunk.iter().enumerate() {
            if p.1 < chunk[lo].1 {
                lo = i;
            }
            if p.1 > chunk[hi].1 {
                hi = i;
            }
        }
        let mut keep = [0, lo.min(hi), lo.max(hi)];
        keep.sort_unstable();
        let mut last = usize::MAX;
        for k in keep {
            if k != last {
                out.push(chunk[k]);
                last = k;
            }
        }
    }
    out
}

/// Pairs two columns into plot points.
pub fn zip(x: &[f64], y: &[f64]) -> Vec<(f64, f64)> {
    x.iter().copied().zip(y.iter().copied()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 18: plots looped forever when an axis range overflowed or
    /// vanished. Each case must finish (within a minute, on a thread).
    #[test]
    fn hostile_ranges_give_a_plot() {
        let cases: Vec<Vec<(f64, f64)>> = vec![
            vec![(0.0, -1.5e308), (1.0, 1.5e308)],
            vec![(-1.7e308, 0.0), (1.7e308, 1.0)],
            vec![(0.0, 1e-300), (1.0, 2e-300)],
            vec![(0.0, 1.0), (1.0, 1.0 + 1e-15)],
            vec![(0.0, 1e300), (1.0, 1e300)],
            vec![(0.0, f64::NAN), (1.0, f64::INFINITY)],
        ];
        let dir = tempfile::tempdir().unwrap();
        for (i, points) in cases.into_iter().enumerate() {
            for axis in [Axis::Linear, Axis::Log] {
                let path = dir.path().join(format!("{i}.svg"));
                let (tx, rx) = std::sync::mpsc::channel();
                let p = path.clone();
                let pts = points.clone();
                std::thread::spawn(move || {
                    let s = [Series {
                        label: "s",
                        points: pts,
                    }];
                    let _ = tx.send(line_plot(&p, "t", ("x", axis), "y", &s).is_ok());
                });
                let done = rx.recv_timeout(std::time::Duration::from_secs(60));
                assert_eq!(done, Ok(true), "case {i}: {points:?}");
                assert!(path.exists());
            }
        }
    }
}
