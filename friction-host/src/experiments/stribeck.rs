//! The Stribeck curve: steady friction at constant velocities.

use super::*;

/// Steady friction at constant velocities, log-spaced from 1e-6 to 1 m/s, both signs.
pub(super) fn stribeck(file: &ParamFile, opts: Options, dir: &Path) -> Result<Outcome> {
    let h = opts.dt.unwrap_or(1e-3);
    let fs = file.model.host().max_static_force();
    let host = file.model.host();
    let stochastic = host.stochastic();
    let speeds: Vec<f64> = (0..=60)
        .map(|i| 10f64.powf(-6.0 + i as f64 * 0.1))
        .collect();
    let (mut vs, mut fcore, mut fss) = (Vec::new(), Vec::new(), Vec::new());
    for sign in [1.0, -1.0] {
        for &s in &speeds {
            let v = sign * s;
            let mut m = core(&file.model)?;
            let f = if stochastic {
                // a random force, rate independent and exact for held v: step
                // by d / 20 (d the pre-sliding scale), average over 200 d
                // after 20 d of running in
                let hb = host.presliding_scale() / 20.0 / s;
                for _ in 0..400 {
                    m.step(v, hb);
                }
                (0..4000).map(|_| m.step(v, hb)).sum::<f64>() / 4000.0
            } else {
                // step until the force settles (geometric convergence) or
                // 2e6 steps. The state settles over a displacement of a few
                // pre-sliding scales d, so below d / (20 h) the step grows
                // to d / (20 |v|) (the steps are exact for a held velocity):
                // at 1e-6 m/s and h = 1 ms, Olsson's set needs 1270 s of
                // sliding to travel d, and its time constant is as long.
                let d = host.presliding_scale();
                let hv = if d > 0.0 { h.max(d / (20.0 * s)) } else { h };
                let mut f = m.step(v, hv);
                for _ in 0..2_000_000 {
                    let next = m.step(v, hv);
                    let settled = (next - f).abs() <= 1e-14 * fs;
                    f = next;
                    if settled {
                        break;
                    }
                }
                f
            };
            vs.push(v);
            fcore.push(f);
            fss.push(host.steady_force(v));
        }
    }
    write_columns(
        &dir.join("trace.csv"),
        &["v", "f", "f_steady"],
        &[&vs, &fcore, &fss],
    )?;
    let worst = fcore
        .iter()
        .zip(&fss)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
        / fs;
    let n = speeds.len();
    let plot = dir.join("stribeck.svg");
    line_plot(
        &plot,
        &format!("Steady friction ({}) versus speed", file.model.name()),
        ("|v| (m/s)", Axis::Log),
        "|F| (N)",
        &[
            Series {
                label: "core, v > 0",
                points: zip(&speeds, &fcore[..n]),
            },
            Series {
                label: "core, v < 0",
                points: speeds
                    .iter()
                    .zip(&fcore[n..])
                    .map(|(&s, &f)| (s, -f))
                    .collect(),
            },
            Series {
                label: "steady-state map",
                points: zip(&speeds, &fss[..n]),
            },
        ],
    )?;
    let bound = if stochastic { 0.05 } else { 1e-6 };
    let weakening = (fcore[0] - fcore[n - 1] + file.model.host().sigma2()) / fs;
    Ok(Outcome {
        name: "stribeck",
        model: "",
        expected: None,
        phenomenon: "steady-state map",
        shown: worst <= bound,
        agrees: None,
        pass: None,
        figure: format!(
            "max |F - steady-state map| = {worst:.2e} of the static force over ±[1e-6, 1] m/s (bound {bound:.0e}{})",
            if stochastic { ", the mean of a random force" } else { "" }
        ),
        summary: vec![
            format!("F(1e-6) = {:.4} N, F(1e-3) = {:.4} N, F(1) = {:.4} N", fcore[0], fcore[30], fcore[n - 1]),
            format!(
                "Stribeck effect (velocity weakening, less sigma2 v): F(1e-6) - F(1) = {:.3} of the static force",
                weakening
            ),
        ],
        plot,
    })
}
