//! Frictional lag: F-v loops under an oscillating velocity.

use super::*;

/// `v = v0 (cos(w t) + 1.5)` with `w = 1, 10, 25 rad/s`: the F-v loop widens with `w`.
pub(super) fn frictional_lag(file: &ParamFile, opts: Options, dir: &Path) -> Result<Outcome> {
    let h = opts.dt.unwrap_or(1e-4);
    // three periods at w = 1, 10 and 25 rad/s
    check_samples("frictional-lag", 6.0 * std::f64::consts::PI * 1.14, h)?;
    let mut series = Vec::new();
    let mut areas = Vec::new();
    let (mut cw, mut ct, mut cv, mut cf, mut cr) = (vec![], vec![], vec![], vec![], vec![]);
    let mut worst = 0.0f64;
    for w in [1.0, 10.0, 25.0] {
        let s = Signal::lag(1e-3, w, 3.0);
        let t = s.times(h);
        let v: Vec<f64> = t.iter().map(|&ti| s.v(ti)).collect();
        let f = drive_core(core(&file.model)?.as_mut(), &t, &v);
        let fr = drive_reference(&file.model, &s, &t)?.force;
        worst = worst.max(rms_diff(&f, &fr) / file.model.max_static_force());
        // loop area over the last period: closed integral of F dv
        let start = t.len() * 2 / 3;
        let area: f64 = (start + 1..t.len())
            .map(|k| 0.5 * (f[k] + f[k - 1]) * (v[k] - v[k - 1]))
            .sum();
        areas.push(area.abs());
        series.push(zip(&v[start..], &f[start..]));
        cw.extend(std::iter::repeat_n(w, t.len()));
        ct.extend(&t);
        cv.extend(&v);
        cf.extend(&f);
        cr.extend(&fr);
    }
    write_columns(
        &dir.join("trace.csv"),
        &["w", "t", "v", "f", "f_ref"],
        &[&cw, &ct, &cv, &cf, &cr],
    )?;
    let labels = ["w = 1 rad/s", "w = 10 rad/s", "w = 25 rad/s"];
    let plot = dir.join("frictional-lag.svg");
    line_plot(
        &plot,
        "Frictional lag: friction versus velocity, v = 1e-3 (cos wt + 1.5)",
        ("v (m/s)", Axis::Linear),
        "F (N)",
        &series
            .into_iter()
            .zip(labels)
            .map(|(p, label)| Series { label, points: p })
            .collect::<Vec<_>>(),
    )?;
    // widens: the area grows with w, and the widest loop is visible (more
    // than 0.1 % of its bounding box, the static force x the velocity range 2 v0)
    let box_area = file.model.max_static_force() * 2e-3;
    let widens = areas.windows(2).all(|a| a[1] > a[0]) && areas[2] > 1e-3 * box_area;
    Ok(Outcome {
        name: "frictional-lag",
        model: "",
        expected: None,
        phenomenon: "frictional lag",
        shown: widens,
        agrees: None,
        pass: None,
        figure: format!(
            "loop area |∮F dv| = {:.3e}, {:.3e}, {:.3e} N m/s for w = 1, 10, 25 (lag shows when it grows and exceeds 0.1 % of the static force x 2 v0)",
            areas[0], areas[1], areas[2]
        ),
        summary: vec![format!("worst rms force error against the reference: {:.4} % of the static force", 100.0 * worst)],
        plot,
    })
}
