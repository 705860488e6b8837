//! Varying break-away force: force ramps at several rates.

use super::*;

/// Mass at rest, applied force ramping at 1 to 50 N/s: the friction peak
/// (break-away force) against the rate.
pub(super) fn breakaway(file: &ParamFile, opts: Options, dir: &Path) -> Result<Outcome> {
    let h = opts.dt.unwrap_or(1e-4);
    let fs = file.model.max_static_force();
    let rates = [1.0, 2.0, 5.0, 10.0, 20.0, 50.0];
    check_samples("breakaway", rates.iter().map(|r| 2.0 * fs / r).sum(), h)?;
    let (mut peaks, mut peaks_ref) = (Vec::new(), Vec::new());
    let (mut cr, mut ct, mut cx, mut cv, mut cf, mut cu) =
        (vec![], vec![], vec![], vec![], vec![], vec![]);
    let continuous = file.model.continuous();
    // break-away: the peak of the friction force less its viscous part
    // (which only grows once the mass slides)
    let sigma2 = file.model.sigma2();
    let peak = |tr: &Trace| {
        tr.f.iter()
            .zip(&tr.v)
            .map(|(f, v)| f - sigma2 * v)
            .fold(f64::NEG_INFINITY, f64::max)
    };
    for &rate in &rates {
        let u = move |t: f64, _x: f64| rate * t;
        let rig = Rig {
            mass: mass(file),
            force: &u,
        };
        let duration = 2.0 * fs / rate;
        let tr = rig_core(core(&file.model)?.as_mut(), &rig, h, duration);
        peaks.push(peak(&tr));
        if let Some(c) = &continuous {
            peaks_ref.push(peak(&rig_reference(c.as_ref(), &rig, &tr.t)?));
        }
        cr.extend(std::iter::repeat_n(rate, tr.t.len()));
        ct.extend(&tr.t);
        cx.extend(&tr.x);
        cv.extend(&tr.v);
        cf.extend(&tr.f);
        cu.extend(&tr.u);
    }
    write_columns(
        &dir.join("trace.csv"),
        &["rate", "t", "x", "v", "f", "u"],
        &[&cr, &ct, &cx, &cv, &cf, &cu],
    )?;
    let plot = dir.join("breakaway.svg");
    let mut series = vec![Series {
        label: "core",
        points: zip(&rates, &peaks),
    }];
    if !peaks_ref.is_empty() {
        series.push(Series {
            label: "reference",
            points: zip(&rates, &peaks_ref),
        });
    }
    line_plot(
        &plot,
        "Varying break-away: friction peak versus force rate",
        ("force rate (N/s)", Axis::Log),
        "break-away force (N)",
        &series,
    )?;
    // falls: never rises (beyond 0.1 % of Fs) and drops by more than 1 % of Fs overall
    let falls = peaks.windows(2).all(|p| p[1] <= p[0] + 1e-3 * fs)
        && peaks[peaks.len() - 1] < peaks[0] - 0.01 * fs;
    let list = |p: &[f64]| {
        p.iter()
            .map(|x| format!("{x:.4}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut summary = Vec::new();
    if !peaks_ref.is_empty() {
        summary.push(format!("reference: {} N", list(&peaks_ref)));
    }
    Ok(Outcome {
        name: "breakaway",
        model: "",
        expected: None,
        phenomenon: "varying break-away force",
        shown: falls,
        agrees: None,
        pass: None,
        figure: format!(
            "break-away force {} N at 1, 2, 5, 10, 20, 50 N/s (peak of F - sigma2 v; shows when it falls by > 1 % of the static force as the rate rises)",
            list(&peaks)
        ),
        summary,
        plot,
    })
}
