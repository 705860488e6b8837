//! The measurements: a model's core against the reference solver on the
//! validation signals, the bristle model's convergence with N, and the
//! drift of LuGre against the elasto-plastic model.

use super::{accuracy_bound, fixed_bound, AccuracyRow, F32_BOUND, PERIODS};
use crate::models::ModelSpec;
use crate::models::ReferenceRun;
use crate::models::{BristleSpec, ScalarKind};
use crate::params::param_set;
use crate::plot::{comparison_plot, line_plot, zip, Axis, Series};
use crate::signals::{validation_signals, Signal};
use crate::sim::{drive_core, drive_reference, max_diff, rms_diff};
use anyhow::Result;
use std::path::{Path, PathBuf};

/// Measures one model on every validation signal at 1 and 10 kHz; when
/// `plot_dir` is given, plots core against reference for each signal at 1 kHz.
/// `bounded`: judge the RMS error against [`accuracy_bound`] (otherwise the
/// figures are reported only).
pub fn accuracy(
    label: &str,
    spec: &ModelSpec,
    bounded: bool,
    plot_dir: Option<&Path>,
) -> Result<Vec<AccuracyRow>> {
    accuracy_on(&validation_signals(), label, spec, bounded, plot_dir)
}

/// [`accuracy`] on the given signals.
pub fn accuracy_on(
    signals: &[Signal],
    label: &str,
    spec: &ModelSpec,
    bounded: bool,
    plot_dir: Option<&Path>,
) -> Result<Vec<AccuracyRow>> {
    let fs = spec.host().max_static_force();
    let mut rows = Vec::new();
    for (i, s) in signals.iter().enumerate() {
        // the reference once, on the 10 kHz grid; the 1 kHz grid is every
        // tenth sample of it (a switch anywhere in between marks the sample)
        let fine_t = s.times(1e-4);
        let fine = drive_reference(spec, s, &fine_t)?;
        for h in PERIODS {
            let t = s.times(h);
            let v: Vec<f64> = t.iter().map(|&ti| s.v(ti)).collect();
            let reference = if h == 1e-4 {
                fine.clone()
            } else {
                subsample(&fine, &fine_t, &t, 10)
                    .map_or_else(|| drive_reference(spec, s, &t), Ok)?
            };
            let fr = &reference.force;
            let f64_ = drive_core(spec.host().stepper(ScalarKind::F64)?.as_mut(), &t, &v);
            let f32_ = drive_core(spec.host().stepper(ScalarKind::F32)?.as_mut(), &t, &v);
            // fixed point where the model has that form and the set builds in it
            let fixed_rms = spec
                .host()
                .fixed_stepper(h)
                .and_then(Result::ok)
                .map(|mut m| rms_diff(&drive_core(m.as_mut(), &t, &v), fr) / fs);
            let fm = drive_core(
                spec.host().stepper(ScalarKind::F64)?.as_mut(),
                &t,
                &s.mean_velocities(&t),
            );
            // away from switching: no discontinuity of the reference within one sample
            let sw = &reference.switching;
            let smooth: Vec<usize> = (0..t.len())
                .filter(|&k| {
                    !sw[k.saturating_sub(1)..(k + 2).min(t.len())]
                        .iter()
                        .any(|&b| b)
                })
                .collect();
            let pick = |f: &[f64]| smooth.iter().map(|&k| f[k]).collect::<Vec<_>>();
            let rms_smooth = if smooth.is_empty() {
                f64::NAN
            } else {
                rms_diff(&pick(&f64_), &pick(fr)) / fs
            };
            if let (Some(dir), true) = (plot_dir, h >= 1e-3) {
                comparison_plot(
                    &dir.join(super::accuracy_plot_name(label, spec, i)),
                    &format!("{label} {}: {} at 1 kHz (core in f64)", spec.name(), s.name),
                    "t (s)",
                    "F (N)",
                    zip(&t, &f64_),
                    zip(&t, fr),
                )?;
            }
            rows.push(AccuracyRow {
                model: format!("{label} {}", spec.name()),
                signal: s.name.clone(),
                h,
                rms: rms_diff(&f64_, fr) / fs,
                max: max_diff(&f64_, fr) / fs,
                rms_mean_v: rms_diff(&fm, fr) / fs,
                rms_smooth,
                kept: smooth.len() as f64 / t.len() as f64,
                f32_rms: rms_diff(&f32_, &f64_) / fs,
                bound: if bounded {
                    accuracy_bound(spec, h)
                } else {
                    None
                },
                f32_bound: bounded.then_some(F32_BOUND),
                target: None,
                fixed_bound: (bounded && fixed_rms.is_some()).then(|| fixed_bound(h)),
                fixed_rms,
            });
        }
    }
    Ok(rows)
}

/// Every `step`-th sample of a reference run on the grid `fine` (the
/// coarse grid `t`), a coarse sample marked as switching when any fine
/// interval inside it switched; `None` when the grids do not nest.
fn subsample(fine: &ReferenceRun, fine_t: &[f64], t: &[f64], step: usize) -> Option<ReferenceRun> {
    let nests = fine_t.len() == (t.len() - 1) * step + 1
        && t.iter()
            .enumerate()
            .all(|(k, &tk)| (fine_t[k * step] - tk).abs() <= 1e-9 * tk.abs().max(1.0));
    if !nests {
        return None;
    }
    let force = (0..t.len()).map(|k| fine.force[k * step]).collect();
    let switching = (0..t.len())
        .map(|k| {
            k > 0
                && fine.switching[(k - 1) * step + 1..=k * step]
                    .iter()
                    .any(|&b| b)
        })
        .collect();
    Some(ReferenceRun { force, switching })
}

/// Plots LuGre creeping and the elasto-plastic model not, under the same
/// cycling force (astrom2008 drift parameters), both with the core at 1 ms.
pub(super) fn drift_comparison(dir: &Path) -> Result<PathBuf> {
    let mut series = Vec::new();
    for (set, label) in [
        ("astrom2008-drift", "LuGre"),
        ("astrom2008-drift-ep", "elasto-plastic"),
    ] {
        let file = param_set(set)?;
        let (force, freq) = (
            file.rig.force.unwrap_or(2.5),
            file.rig.frequency.unwrap_or(1.0),
        );
        let u = move |t: f64, _x: f64| {
            force * (1.0 - (2.0 * std::f64::consts::PI * freq * t).cos()) / 2.0
        };
        let rig = crate::sim::Rig {
            mass: file.rig.mass.unwrap_or(1.0),
            force: &u,
        };
        let cycles = f64::from(file.rig.cycles.unwrap_or(10));
        let tr = crate::sim::rig_core(
            file.model.host().stepper(ScalarKind::F64)?.as_mut(),
            &rig,
            1e-3,
            cycles / freq,
        );
        series.push(Series {
            label,
            points: zip(&tr.t, &tr.x),
        });
    }
    let path = dir.join("drift-lugre-vs-elasto-plastic.svg");
    line_plot(
        &path,
        "Drift: the same cycling force below break-away",
        ("t (s)", Axis::Linear),
        "x (m)",
        &series,
    )?;
    Ok(path)
}

/// How the bristle model's sliding force converges with the number of bristles.
#[derive(Clone, Copy, Debug)]
pub struct BristleConvergence {
    /// Number of bristles.
    pub n: usize,
    /// Mean sliding force / (N sigma0 delta_s / 3).
    pub mean: f64,
    /// Standard deviation / mean.
    pub spread: f64,
}

/// Slides each offered bristle count at constant speed over 2000 `delta_s`
/// (after 50 of running in) and measures the mean and spread of the force.
pub fn bristle_convergence() -> Result<Vec<BristleConvergence>> {
    let mut out = Vec::new();
    for n in [1, 8, 25, 64] {
        let params = friction_core::BristleParams {
            sigma0: 1.0,
            delta_s: 1.0,
            seed: 1,
        };
        let mut m = ModelSpec::Bristle(BristleSpec {
            params,
            bristles: n,
        })
        .host()
        .stepper(ScalarKind::F64)?;
        let h = 0.05; // v = 1: 1/20 of delta_s a step
        for _ in 0..1000 {
            m.step(1.0, h);
        }
        let f: Vec<f64> = (0..40_000).map(|_| m.step(1.0, h)).collect();
        let mean = f.iter().sum::<f64>() / f.len() as f64;
        let var = f.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / f.len() as f64;
        out.push(BristleConvergence {
            n,
            mean: mean / (n as f64 / 3.0),
            spread: var.sqrt() / mean,
        });
    }
    Ok(out)
}
