//! Pre-sliding hysteresis: applied-force ramps below break-away.

use super::*;

/// Applied-force ramps below break-away: 0 -> P -> -P -> P with
/// `P = 0.95 min(Fs, Fb)`, where `Fb` is the break-away force the core shows
/// for a ramp at the same rate (the sheet's `0.95 Fs` where `Fb` reaches
/// `Fs`; below it on a set whose contact creeps or slips element by element
/// before `Fs`, such as gms-servo, which breaks away near 0.30 N m of its
/// 0.33).
pub(super) fn presliding(file: &ParamFile, opts: Options, dir: &Path) -> Result<Outcome> {
    let h = opts.dt.unwrap_or(RIG_DT);
    let fs = file.model.host().max_static_force();
    let rate = file.rig.force_rate.unwrap_or(0.095 * fs);
    let fb = super::breakaway::breakaway_force("presliding", file, rate, h)?;
    let peak = 0.95 * fs.min(fb);
    let leg = peak / rate;
    let duration = opts.duration.unwrap_or(5.0 * leg);
    check_samples("presliding", duration, h)?;
    let u = move |t: f64, _x: f64| {
        let s = t / leg; // in ramp lengths
        if s <= 1.0 {
            peak * s
        } else if s <= 3.0 {
            peak * (2.0 - s)
        } else {
            peak * (s - 4.0).min(1.0)
        }
    };
    let rig = Rig {
        mass: mass(file),
        force: &u,
    };
    let (tr, rf) = rig_pair(file, &rig, h, duration, dir)?;
    let x_max = tr.x.iter().fold(0.0f64, |a, &b| a.max(b.abs()));
    // residual displacement where u comes back to 0 on the way down (t = 2 leg)
    let k0 = ((2.0 * leg) / h).round() as usize;
    let residual = tr.x.get(k0).copied().unwrap_or(0.0);
    let d = file.model.host().presliding_scale();
    let plot = dir.join("presliding.svg");
    plot_pair(
        &plot,
        "Pre-sliding hysteresis: friction versus displacement",
        ("x (m)", "F (N)"),
        zip(&tr.x, &tr.f),
        rf.as_ref().map(|r| zip(&r.x, &r.f)),
    )?;
    let hysteretic = residual.abs() > 0.01 * d;
    let bounded = x_max < 10.0 * d;
    let mut summary = vec![format!(
        "ramp peak {} N: 0.95 x min(Fs = {}, break-away force at this rate {})",
        crate::checks::short(peak),
        crate::checks::short(fs),
        crate::checks::short(fb)
    )];
    if let Some(r) = &rf {
        let err = rms_diff(&tr.x, &r.x);
        summary.push(format!(
            "rms |x_core - x_ref| = {:.3e} m ({:.3} % of max |x|)",
            err,
            100.0 * err / x_max
        ));
    }
    Ok(Outcome {
        name: "presliding",
        model: "",
        expected: None,
        phenomenon: "pre-sliding hysteresis",
        shown: hysteretic && bounded,
        agrees: None,
        pass: None,
        figure: format!(
            "residual x at u = 0: {:.3e} m ({:.1} % of the pre-sliding scale d = {:.3e} m, hysteresis above 1 %); max |x| = {:.2} d (pre-sliding below 10 d)",
            residual,
            100.0 * residual.abs() / d,
            d,
            x_max / d
        ),
        summary,
        plot,
    })
}
