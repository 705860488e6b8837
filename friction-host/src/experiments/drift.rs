//! Zero-slip drift: a cycling force below break-away.

use super::*;

/// Mass at rest, `u = force (1 - cos 2 pi f t) / 2` for `cycles` cycles.
pub(super) fn drift(file: &ParamFile, opts: Options, dir: &Path) -> Result<Outcome> {
    let h = opts.dt.unwrap_or(RIG_DT);
    // default: half the static force, or for elasto-plastic 90 % of the
    // elastic limit sigma0 z_ba, below which it must not drift (HostModel::drift_force)
    let default_force = file.model.host().drift_force();
    let force = file.rig.force.unwrap_or(default_force);
    let freq = file.rig.frequency.unwrap_or(1.0);
    let cycles = file.rig.cycles.unwrap_or(10).max(1);
    let duration = opts.duration.unwrap_or(cycles as f64 / freq);
    check_samples("drift", duration, h)?;
    let u =
        move |t: f64, _x: f64| force * (1.0 - (2.0 * std::f64::consts::PI * freq * t).cos()) / 2.0;
    let rig = Rig {
        mass: mass(file),
        force: &u,
    };
    let (tr, rf) = rig_pair(file, &rig, h, duration, dir)?;
    let at = |x: &[f64], cycle: f64| x[((cycle / freq / h).round() as usize).min(x.len() - 1)];
    let n = (duration * freq).floor().max(1.0);
    let (first, last) = (at(&tr.x, 1.0), at(&tr.x, n));
    let plot = dir.join("drift.svg");
    plot_pair(
        &plot,
        &format!("Drift under a force cycling between 0 and {force} N"),
        ("t (s)", "x (m)"),
        zip(&tr.t, &tr.x),
        rf.as_ref().map(|r| zip(&r.t, &r.x)),
    )?;
    // drift: the displacement keeps growing cycle after cycle, by more than
    // a thousandth of the pre-sliding scale
    let d = file.model.host().presliding_scale();
    let drifts = last > 1.5 * first && last - first > 1e-3 * d;
    let mut summary = vec![format!(
        "drift per cycle: {:.3e} m",
        (last - first) / (n - 1.0).max(1.0)
    )];
    if let Some(r) = &rf {
        summary.push(format!(
            "reference: x after cycle 1 = {:.4e} m, after cycle {} = {:.4e} m",
            at(&r.x, 1.0),
            n,
            at(&r.x, n)
        ));
    }
    Ok(Outcome {
        name: "drift",
        model: "",
        expected: None,
        phenomenon: "zero-slip drift",
        shown: drifts,
        agrees: None,
        pass: None,
        figure: format!(
            "force peak {force:.4} N: x after cycle 1 = {first:.4e} m, after cycle {n} = {last:.4e} m (drift shows when it grows > 1.5x and by > 1e-3 d, d = {d:.2e} m)"
        ),
        summary,
        plot,
    })
}
