//! Rate independence: the same displacement loop at three frequencies.

use super::*;

/// A periodic displacement of amplitude `2 d` (`d` the pre-sliding scale) at
/// 0.1, 1 and 10 Hz, 2000 samples a period: is the loop `F - sigma2 v`
/// versus `x` the same at every frequency?
pub(super) fn rate_independence(file: &ParamFile, _opts: Options, dir: &Path) -> Result<Outcome> {
    let d = file.model.host().presliding_scale();
    let fs = file.model.host().max_static_force();
    let sigma2 = file.model.host().sigma2();
    let mut loops: Vec<(Vec<f64>, Vec<f64>)> = Vec::new();
    let (mut cf, mut ct, mut cx, mut cv, mut cff) = (vec![], vec![], vec![], vec![], vec![]);
    for freq in [0.1, 1.0, 10.0] {
        let w = 2.0 * std::f64::consts::PI * freq;
        // x(t) = 2 d (1 - cos w t) / 2 ... from the velocity 2 d w / 2 sin(w t)
        let s = Signal::sine(d * w, freq, 2.0);
        let t = s.times(1.0 / (2000.0 * freq));
        let v = s.mean_velocities(&t);
        let f = drive_core(core(&file.model)?.as_mut(), &t, &v);
        let x: Vec<f64> = t.iter().map(|&ti| s.x(ti)).collect();
        let fh: Vec<f64> = f.iter().zip(&v).map(|(f, v)| f - sigma2 * v).collect();
        cf.extend(std::iter::repeat_n(freq, t.len()));
        ct.extend(&t);
        cx.extend(&x);
        cv.extend(&v);
        cff.extend(&f);
        let half = t.len() / 2;
        loops.push((x[half..].to_vec(), fh[half..].to_vec()));
    }
    write_columns(
        &dir.join("trace.csv"),
        &["frequency", "t", "x", "v", "f"],
        &[&cf, &ct, &cx, &cv, &cff],
    )?;
    // the samples sit at the same phases, so the loops compare point by point
    let diff = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .map(|(p, q)| (p - q).abs())
            .fold(0.0, f64::max)
    };
    let spread = diff(&loops[0].1, &loops[1].1).max(diff(&loops[0].1, &loops[2].1)) / fs;
    let plot = dir.join("rate-independence.svg");
    let labels = ["0.1 Hz", "1 Hz", "10 Hz"];
    line_plot(
        &plot,
        "Force-displacement loop at three frequencies (F - sigma2 v)",
        ("x (m)", Axis::Linear),
        "F - sigma2 v (N)",
        &loops
            .iter()
            .zip(labels)
            .map(|((x, f), label)| Series {
                label,
                points: zip(x, f),
            })
            .collect::<Vec<_>>(),
    )?;
    Ok(Outcome {
        name: "rate-independence",
        model: "",
        expected: None,
        phenomenon: "rate-independent hysteresis",
        shown: spread < 0.01,
        agrees: None,
        pass: None,
        figure: format!(
            "largest difference between the loops at 0.1, 1 and 10 Hz: {spread:.2e} of the static force (rate independent below 1 %)"
        ),
        summary: Vec::new(),
        plot,
    })
}
