//! Frictional lag: F-v loops under an oscillating velocity.

use super::*;

/// The sheet's `w T = 0.01, 0.1, 0.25`: canudas1995's `w = 1, 10, 25 rad/s`
/// against its lag time `T = 0.01 s` at the mean speed.
const W_T: [f64; 3] = [0.01, 0.1, 0.25];

/// Periods of the velocity run at each frequency (the loop is the last).
const PERIODS: f64 = 2.0;

/// The speed `v0` and the frequencies `w` for the model: the sheet's
/// `v0 = 1e-3 m/s` and `w = 1, 10, 25 rad/s` are canudas1995's Stribeck
/// velocity and `W_T` over its lag time at the mean speed `1.5 v0`. Another
/// set keeps those ratios: `v0 = vs` (the loop needs the curve's slope) and
/// `w = W_T / T(1.5 vs)`, so the lag shows on its own time scale (on
/// astrom2008's stiff set the sheet's figures put `w T` past the peak of
/// the lag, where the loop narrows again). Models without a Stribeck curve
/// keep the sheet's figures.
pub(crate) fn lag_scales(model: &crate::models::ModelSpec) -> (f64, [f64; 3]) {
    match model.host().stribeck_velocity() {
        Some(vs) => {
            let t = model.host().lag_time(1.5 * vs);
            (vs, W_T.map(|wt| wt / t))
        }
        None => (1e-3, [1.0, 10.0, 25.0]),
    }
}

/// `v = v0 (cos(w t) + 1.5)` at three frequencies ([`lag_scales`]): the F-v
/// loop widens with `w`.
pub(super) fn frictional_lag(file: &ParamFile, opts: Options, dir: &Path) -> Result<Outcome> {
    let (v0, ws) = lag_scales(&file.model);
    // 0.01 of the lag time at w T = 1 (1e-4 s for canudas1995)
    let h = opts.dt.unwrap_or(0.01 / ws[0] * W_T[0]);
    // two periods at each w: the first settles the state (within a few lag
    // times, a small part of a period), the loop is read on the second
    let duration: f64 = ws
        .iter()
        .map(|w| PERIODS * 2.0 * std::f64::consts::PI / w)
        .sum();
    check_samples("frictional-lag", duration, h)?;
    let mut series = Vec::new();
    let mut areas = Vec::new();
    let (mut cw, mut ct, mut cv, mut cf, mut cr) = (vec![], vec![], vec![], vec![], vec![]);
    let mut worst = 0.0f64;
    for w in ws {
        let s = Signal::lag(v0, w, PERIODS);
        let t = s.times(h);
        let v: Vec<f64> = t.iter().map(|&ti| s.v(ti)).collect();
        let f = drive_core(core(&file.model)?.as_mut(), &t, &v);
        let fr = drive_reference(&file.model, &s, &t)?.force;
        worst = worst.max(rms_diff(&f, &fr) / file.model.host().max_static_force());
        // loop area over the last period: closed integral of F dv
        let start = t.len() / 2;
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
    let labels = ws.map(|w| format!("w = {} rad/s", crate::checks::short(w)));
    let plot = dir.join("frictional-lag.svg");
    line_plot(
        &plot,
        &format!(
            "Frictional lag: friction versus velocity, v = {} (cos wt + 1.5)",
            crate::checks::short(v0)
        ),
        ("v (m/s)", Axis::Linear),
        "F (N)",
        &series
            .into_iter()
            .zip(&labels)
            .map(|(p, label)| Series {
                label: label.as_str(),
                points: p,
            })
            .collect::<Vec<_>>(),
    )?;
    // widens: the area grows with w, and the widest loop is visible (more
    // than 0.1 % of its bounding box, the static force x the velocity range 2 v0)
    let box_area = file.model.host().max_static_force() * 2.0 * v0;
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
            "loop area |∮F dv| = {:.3e}, {:.3e}, {:.3e} N m/s for w = {}, {}, {} rad/s at v0 = {} (lag shows when it grows and exceeds 0.1 % of the static force x 2 v0)",
            areas[0],
            areas[1],
            areas[2],
            crate::checks::short(ws[0]),
            crate::checks::short(ws[1]),
            crate::checks::short(ws[2]),
            crate::checks::short(v0)
        ),
        summary: vec![format!("worst rms force error against the reference: {:.4} % of the static force", 100.0 * worst)],
        plot,
    })
}
