//! `friction validate`: every implemented model against the reference
//! solver, f32 against f64, and every phenomenon experiment judged, into a
//! printed table and a Markdown report with plots.

use crate::experiments::{self, Options, Outcome};
use crate::models::{BristleSpec, ScalarKind};
use crate::params::ModelSpec;
use crate::plot::{comparison_plot, line_plot, zip, Axis, Series};
use crate::signals::{reversal_signals, validation_signals, Signal};
use crate::sim::{drive_core, drive_reference, max_diff, rms_diff, ReferenceRun};
use anyhow::Result;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

pub use crate::io::pct;
pub use crate::params::{param_set, PARAM_SETS};

/// Accuracy bound (fraction of the model's static force) at step `h`, from
/// the model's host module; `None` where none is set.
pub fn accuracy_bound(spec: &ModelSpec, h: f64) -> Option<f64> {
    spec.host().accuracy_bound(h)
}

/// Bound on the f32 against f64 difference (fraction of the static force).
pub const F32_BOUND: f64 = 1e-3;

/// Bound on the RMS error of the Q16.16 fixed-step form against the
/// reference (fraction of the static force): 3 % at 1 kHz, 1.5 % at 10 kHz.
pub fn fixed_bound(h: f64) -> f64 {
    if h >= 1e-3 {
        0.03
    } else {
        0.015
    }
}

/// One row of the accuracy table.
#[derive(Clone, Debug)]
pub struct AccuracyRow {
    /// Parameter set and model.
    pub model: String,
    /// Signal name.
    pub signal: String,
    /// Sample period (s).
    pub h: f64,
    /// RMS force error, sampled velocity held, / Fs.
    pub rms: f64,
    /// Largest force error / Fs.
    pub max: f64,
    /// RMS force error with the mean velocity over the step, / Fs.
    pub rms_mean_v: f64,
    /// RMS force error away from switching instants (samples more than one
    /// sample from a discontinuity of the reference), / Fs.
    pub rms_smooth: f64,
    /// Fraction of the samples in `rms_smooth`.
    pub kept: f64,
    /// RMS difference f32 - f64 / Fs.
    pub f32_rms: f64,
    /// Bound on `rms`, where the project sets one for this parameter set.
    pub bound: Option<f64>,
    /// Bound on `f32_rms`, wherever an accuracy bound is set.
    pub f32_bound: Option<f64>,
    /// A target reported but not judged: a bound the project set and the
    /// model is known to miss (shown as `missed` or `met`).
    pub target: Option<f64>,
    /// RMS force error of the fixed-step form in Q16.16 fixed point against
    /// the reference, / Fs; `None` where the model has no fixed-point form.
    pub fixed_rms: Option<f64>,
    /// Bound on `fixed_rms` ([`fixed_bound`]), wherever an accuracy bound is set.
    pub fixed_bound: Option<f64>,
}

impl AccuracyRow {
    /// `pass`, `FAIL`, `missed`/`met` for a reported target, or `info` for
    /// a row without a bound.
    pub fn verdict(&self) -> &'static str {
        match (self.pass(), self.bound, self.target) {
            (false, _, _) => "FAIL",
            (true, Some(_), _) => "pass",
            (true, None, Some(t)) if self.rms > t => "missed",
            (true, None, Some(_)) => "met",
            (true, None, None) => "info",
        }
    }

    /// Whether the row meets its bounds.
    pub fn pass(&self) -> bool {
        self.bound.is_none_or(|b| self.rms <= b)
            && self.f32_bound.is_none_or(|b| self.f32_rms <= b)
            && match (self.fixed_rms, self.fixed_bound) {
                (Some(rms), Some(b)) => rms <= b,
                _ => true,
            }
    }
}

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
    let fs = spec.max_static_force();
    let mut rows = Vec::new();
    for (i, s) in signals.iter().enumerate() {
        // the reference once, on the 10 kHz grid; the 1 kHz grid is every
        // tenth sample of it (a switch anywhere in between marks the sample)
        let fine_t = s.times(1e-4);
        let fine = drive_reference(spec, s, &fine_t)?;
        for h in [1e-3, 1e-4] {
            let t = s.times(h);
            let v: Vec<f64> = t.iter().map(|&ti| s.v(ti)).collect();
            let reference = if h == 1e-4 {
                fine.clone()
            } else {
                subsample(&fine, &fine_t, &t, 10)
                    .map_or_else(|| drive_reference(spec, s, &t), Ok)?
            };
            let fr = &reference.force;
            let f64_ = drive_core(spec.stepper(ScalarKind::F64)?.as_mut(), &t, &v);
            let f32_ = drive_core(spec.stepper(ScalarKind::F32)?.as_mut(), &t, &v);
            // fixed point where the model has that form and the set builds in it
            let fixed_rms = spec
                .host()
                .fixed_stepper(h)
                .and_then(Result::ok)
                .map(|mut m| rms_diff(&drive_core(m.as_mut(), &t, &v), fr) / fs);
            let fm = drive_core(
                spec.stepper(ScalarKind::F64)?.as_mut(),
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
                    &dir.join(accuracy_plot_name(label, spec, i)),
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

/// canudas1995-ep with `z_ba = frac Fc / sigma0` (the shipped set has 0.5).
pub fn elasto_plastic_with_z_ba(frac: f64) -> Result<ModelSpec> {
    let ModelSpec::ElastoPlastic(p) = param_set("canudas1995-ep")?.model else {
        anyhow::bail!("canudas1995-ep is not an elasto-plastic set")
    };
    Ok(ModelSpec::ElastoPlastic(
        friction_core::ElastoPlasticParams {
            z_ba: frac * p.lugre.curve.fc / p.lugre.sigma0,
            ..p
        },
    ))
}

/// The full validation. Returns whether everything passed.
pub fn run(dir: &Path) -> Result<bool> {
    run_with(dir, false)
}

/// [`run`], printing each section's cost on stderr when `timings` is set
/// (`friction validate --timings`). Models and experiments run in
/// parallel on all cores; the console and the report keep their order.
pub fn run_with(dir: &Path, timings: bool) -> Result<bool> {
    use rayon::prelude::*;
    let started = std::time::Instant::now();
    let costs = std::sync::Mutex::new(Vec::<(String, f64)>::new());
    let timed = |what: String, since: std::time::Instant| {
        if let Ok(mut c) = costs.lock() {
            c.push((what, since.elapsed().as_secs_f64()));
        }
    };
    use anyhow::Context;
    std::fs::create_dir_all(dir)
        .with_context(|| format!("--output {}: cannot create the folder", dir.display()))?;
    crate::outln!(
        "Accuracy against the reference solver (diffsol BDF, rtol {:e})",
        crate::sim::REFERENCE_RTOL
    );
    crate::outln!(
        "{:<32} {:<28} {:>7} {:>10} {:>10} {:>12} {:>10} {:>9} {:>5}",
        "model",
        "signal",
        "rate",
        "rms/Fs",
        "max/Fs",
        "mean-v rms",
        "f32-f64",
        "fixed",
        "ok"
    );
    let mut rows = Vec::new();
    let models = accuracy_models()?;
    let plan: &[(&str, &[&str])] = &[
        (
            "canudas1995",
            &[
                "stribeck",
                "presliding",
                "frictional-lag",
                "breakaway",
                "stick-slip",
            ],
        ),
        ("astrom2008-stickslip", &["stick-slip"]),
        ("astrom2008-drift", &["drift"]),
        ("astrom2008-drift-ep", &["drift"]),
        ("canudas1995", &["rate-independence", "nonlocal-memory"]),
        ("canudas1995-ep", experiments::NAMES),
        ("dahl1968", experiments::NAMES),
        ("haessig1991-reset", experiments::NAMES),
        ("haessig1991-bristle", experiments::NAMES),
        ("gms-typical", experiments::NAMES),
        ("xiong-typical", experiments::NAMES),
        ("leuven-typical", experiments::NAMES),
    ];
    let experiments: usize = plan.iter().map(|(_, names)| names.len()).sum();
    let progress = std::sync::Mutex::new(Progress::new(models.len() + experiments + 1));
    let tick = |what: &str| {
        if let Ok(mut p) = progress.lock() {
            p.tick(what);
        }
    };
    // the hard elasto-plastic case: z_ba near Fc/sigma0, on reversals up to 0.07 m/s
    let hard = (
        "canudas1995-ep z_ba=0.9Fc/sigma0",
        elasto_plastic_with_z_ba(0.9)?,
    );
    let measured: Vec<Result<Vec<AccuracyRow>>> = models
        .par_iter()
        .map(|(label, spec, bounded, plots)| {
            let since = std::time::Instant::now();
            let rows = accuracy(label, spec, *bounded, plots.then_some(dir));
            let what = format!("accuracy {label} {}", spec.name());
            tick(&what);
            timed(what, since);
            rows
        })
        .collect();
    for model_rows in measured {
        for r in model_rows? {
            print_row(&r);
            rows.push(r);
        }
    }
    let since = std::time::Instant::now();
    // The 3 % / 1 % are reported as targets, not judged: with the
    // velocity held over each step the displacement runs h v / 2 ahead, more
    // than the 1 µm transition zone at this z_ba, while the step itself is
    // exact for the held velocity (see the README).
    for mut r in accuracy_on(&reversal_signals(), hard.0, &hard.1, false, Some(dir))? {
        r.f32_bound = Some(F32_BOUND);
        r.target = accuracy_bound(&hard.1, r.h);
        print_row(&r);
        rows.push(r);
    }
    timed(format!("accuracy {}", hard.0), since);

    crate::outln!("\nPhenomena");
    let mut outcomes: Vec<(String, Outcome)> = Vec::new();
    let jobs: Vec<(&str, &str)> = plan
        .iter()
        .flat_map(|(set, names)| names.iter().map(move |name| (*set, *name)))
        .collect();
    let judged: Vec<Result<Outcome>> = jobs
        .par_iter()
        .map(|&(set, name)| {
            let since = std::time::Instant::now();
            let file = param_set(set)?;
            let out = experiments::run(
                name,
                &file,
                Options::default(),
                &dir.join(format!("{set}-{name}")),
            );
            let what = format!("experiment {set} {name}");
            tick(&what);
            timed(what, since);
            out
        })
        .collect();
    for (&(set, _), out) in jobs.iter().zip(judged) {
        let out = out?;
        crate::outln!(
            "{:<22} {:<16} {:<5} {}",
            set,
            out.name,
            out.verdict(),
            out.figure
        );
        outcomes.push((set.to_string(), out));
    }
    crate::outln!(
        "\nBristle model: sliding force against N (mean / (N sigma0 delta_s / 3), relative spread)"
    );
    tick("bristle convergence");
    let since = std::time::Instant::now();
    let convergence = bristle_convergence()?;
    timed("bristle convergence".into(), since);
    for c in &convergence {
        crate::outln!(
            "N = {:>2}: mean {:.4}, std/mean {:.4}, std/mean x sqrt(N) {:.3}",
            c.n,
            c.mean,
            c.spread,
            c.spread * (c.n as f64).sqrt()
        );
    }
    let since = std::time::Instant::now();
    drift_comparison(dir)?;
    timed("drift comparison".into(), since);
    if let Ok(p) = progress.lock() {
        p.finish();
    }
    let all_pass =
        rows.iter().all(AccuracyRow::pass) && outcomes.iter().all(|(_, o)| o.pass != Some(false));
    let since = std::time::Instant::now();
    write_report(dir, &rows, &outcomes, &convergence, all_pass)?;
    timed(
        "report (servo benchmark, robustness map, plots)".into(),
        since,
    );
    if timings {
        let mut c = costs.into_inner().unwrap_or_default();
        c.sort_by(|a, b| b.1.total_cmp(&a.1));
        eprintln!("\nvalidate --timings: wall time {:.1} s on {} threads; cost of each section (s, in parallel):", started.elapsed().as_secs_f64(), rayon::current_num_threads());
        for (what, secs) in c {
            eprintln!("{secs:>8.2}  {what}");
        }
    }
    crate::outln!(
        "\n{} — report: {}",
        if all_pass {
            "all checks pass"
        } else {
            "SOME CHECKS FAIL"
        },
        dir.join("report.md").display()
    );
    Ok(all_pass)
}

/// Progress on stderr for a long run: silent for the first two seconds,
/// then one line per step (rewritten in place on a terminal).
struct Progress {
    start: std::time::Instant,
    total: usize,
    done: usize,
    tty: bool,
    shown: bool,
}

impl Progress {
    fn new(total: usize) -> Self {
        use std::io::IsTerminal;
        Self {
            start: std::time::Instant::now(),
            total,
            done: 0,
            tty: std::io::stderr().is_terminal(),
            shown: false,
        }
    }

    fn tick(&mut self, what: &str) {
        self.done += 1;
        let elapsed = self.start.elapsed().as_secs_f64();
        if elapsed < 2.0 {
            return;
        }
        self.shown = true;
        let line = format!(
            "validate [{}/{}] {elapsed:.0} s: {what}",
            self.done, self.total
        );
        if self.tty {
            eprint!("\r\x1b[K{line}");
        } else {
            eprintln!("{line}");
        }
    }

    fn finish(&self) {
        if self.shown && self.tty {
            eprintln!();
        }
    }
}

/// One accuracy row on the console.
fn print_row(r: &AccuracyRow) {
    crate::outln!(
        "{:<40} {:<28} {:>5.0}Hz {:>9.4}% {:>9.3}% {:>11.4}% {:>9.4}% ({:>3.0}%) {:>9.2e} {:>9} {:>5}",
        r.model,
        r.signal,
        1.0 / r.h,
        100.0 * r.rms,
        100.0 * r.max,
        100.0 * r.rms_mean_v,
        100.0 * r.rms_smooth,
        100.0 * r.kept,
        r.f32_rms,
        r.fixed_rms.map_or("-".to_string(), |x| format!("{:.3}%", 100.0 * x)),
        r.verdict()
    );
}

/// `accuracy-<label>-<model>-<signal>.svg`, with the label made file-name safe.
pub fn accuracy_plot_name(label: &str, spec: &ModelSpec, signal: usize) -> String {
    let slug: String = label
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
        .collect();
    format!("accuracy-{slug}-{}-{signal}.svg", spec.name())
}

/// The parameter sets the accuracy table measures, each `(label, model,
/// bounded, plots)`: the sets below with their variants, and the primary
/// set of every listed model the table does not name.
pub(crate) fn accuracy_models() -> Result<Vec<(String, ModelSpec, bool, bool)>> {
    // (set, bounded, plots, with its variants): the bounds are set for
    // each model's primary set; the other sets are measured and reported.
    // Each model's host module names its own variants
    // (`HostModel::validation_variants`).
    let sets: &[(&str, bool, bool, bool)] = &[
        ("canudas1995", true, true, true),
        ("astrom2008-drift", false, false, false),
        ("olsson1998-servo", false, false, false),
        ("dahl1968", true, false, true),
        ("canudas1995-ep", true, true, false),
        // the multistate family, N = 4, bounded like elasto-plastic (3 % / 1 %)
        ("gms-typical", true, true, false),
        ("xiong-typical", true, true, false),
        ("leuven-typical", true, true, false),
        // switching models: figures stated, no bound (see the report)
        ("haessig1991-reset", false, true, false),
        ("haessig1991-bristle", false, true, true),
    ];
    // a model whose primary set the table does not name (a model added to
    // the list since) is measured on it, bounded, with its variants
    let listed = crate::models::MODEL_SETS
        .iter()
        .filter_map(|(_, shipped)| shipped.first())
        .filter(|set| !sets.iter().any(|(named, ..)| named == *set))
        .map(|&set| (set, true, false, true));
    let sets: Vec<(&str, bool, bool, bool)> = sets.iter().copied().chain(listed).collect();
    let mut models = Vec::new();
    for &(set, bounded, plots, with_variants) in &sets {
        let spec = param_set(set)?.model;
        let host = spec.host();
        if host.validates_itself() {
            models.push((set.into(), spec.clone(), bounded, plots));
        }
        if with_variants {
            for v in host.validation_variants() {
                models.push((format!("{set}{}", v.suffix), v.spec, v.bounded, v.plots));
            }
        }
    }
    Ok(models)
}

/// Plots LuGre creeping and the elasto-plastic model not, under the same
/// cycling force (astrom2008 drift parameters), both with the core at 1 ms.
fn drift_comparison(dir: &Path) -> Result<PathBuf> {
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
            file.model.stepper(ScalarKind::F64)?.as_mut(),
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

/// Markdown emphasis for failures.
fn bold_fail(verdict: &str) -> &str {
    if verdict == "FAIL" {
        "**FAIL**"
    } else {
        verdict
    }
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

/// The phenomena of the matrix: (column title, experiment name).
const PHENOMENA: &[(&str, &str)] = &[
    ("Stribeck curve", "stribeck"),
    ("pre-sliding hysteresis", "presliding"),
    ("non-local memory", "nonlocal-memory"),
    ("frictional lag", "frictional-lag"),
    ("varying break-away", "breakaway"),
    ("stick-slip", "stick-slip"),
    ("drift", "drift"),
    ("rate independence", "rate-independence"),
];

/// One row per model, one column per phenomenon: what was measured against
/// what the model is expected to do.
fn write_matrix(md: &mut String, outcomes: &[(String, Outcome)]) -> Result<()> {
    writeln!(md, "## Phenomena: measured against expected\n")?;
    writeln!(
        md,
        "Each cell: whether the phenomenon showed (`yes`/`no`, one per parameter set run), then \
         what the model is known to do (`expected`, `not expected`, or `not judged`), and ✓ or \
         **✗**. Details, figures and plots are in the sections below.\n"
    )?;
    write!(md, "| model |")?;
    for (title, _) in PHENOMENA {
        write!(md, " {title} |")?;
    }
    writeln!(md)?;
    writeln!(md, "|---|{}", "---|".repeat(PHENOMENA.len()))?;
    let mut models: Vec<&str> = Vec::new();
    for (_, o) in outcomes {
        if !models.contains(&o.model) {
            models.push(o.model);
        }
    }
    for model in models {
        write!(md, "| {model} |")?;
        for (_, experiment) in PHENOMENA {
            let runs: Vec<&Outcome> = outcomes
                .iter()
                .map(|(_, o)| o)
                .filter(|o| o.model == model && o.name == *experiment)
                .collect();
            if runs.is_empty() {
                write!(md, " not run |")?;
                continue;
            }
            let shown: Vec<&str> = runs
                .iter()
                .map(|o| if o.shown { "yes" } else { "no" })
                .collect();
            let expected = match runs[0].expected {
                Some(true) => "expected",
                Some(false) => "not expected",
                None => "not judged",
            };
            let mark = if runs.iter().any(|o| o.pass == Some(false)) {
                " **✗**"
            } else if runs.iter().all(|o| o.pass.is_none()) {
                ""
            } else {
                " ✓"
            };
            write!(md, " {} ({expected}){mark} |", shown.join("/"))?;
        }
        writeln!(md)?;
    }
    writeln!(md)?;
    Ok(())
}

/// One accuracy line per model: the worst RMS at 1 and 10 kHz against its
/// bound, and the worst f32 against f64.
fn write_accuracy_summary(md: &mut String, rows: &[AccuracyRow]) -> Result<()> {
    writeln!(md, "## Accuracy at a glance\n")?;
    writeln!(
        md,
        "Worst RMS force error of the core against the reference over the validation signals, \
         as a fraction of the static force, for the parameter sets with a bound (the full table is below).\n"
    )?;
    writeln!(
        md,
        "| model | worst at 1 kHz (bound) | worst at 10 kHz (bound) | worst f32 - f64 | worst fixed point, 1 / 10 kHz | ok |"
    )?;
    writeln!(md, "|---|---|---|---|---|---|")?;
    let mut labels: Vec<&str> = Vec::new();
    for r in rows
        .iter()
        .filter(|r| r.bound.is_some() || r.target.is_some())
    {
        if !labels.contains(&r.model.as_str()) {
            labels.push(&r.model);
        }
    }
    for label in labels {
        let mine: Vec<&AccuracyRow> = rows.iter().filter(|r| r.model == label).collect();
        let worst = |slow: bool| {
            let sel = mine.iter().filter(|r| (r.h >= 1e-3) == slow);
            let rms = sel.clone().map(|r| r.rms).fold(0.0, f64::max);
            let bound = sel
                .filter_map(|r| r.bound.or(r.target))
                .fold(f64::INFINITY, f64::min);
            format!("{} ({})", pct(rms), pct(bound))
        };
        let f32_worst = mine.iter().map(|r| r.f32_rms).fold(0.0, f64::max);
        let fixed_worst = |slow: bool| {
            mine.iter()
                .filter(|r| (r.h >= 1e-3) == slow)
                .filter_map(|r| r.fixed_rms)
                .reduce(f64::max)
        };
        let fixed = match (fixed_worst(true), fixed_worst(false)) {
            (Some(a), Some(b)) => format!("{} / {}", pct(a), pct(b)),
            _ => "-".to_string(),
        };
        let ok = if !mine.iter().all(|r| r.pass()) {
            "**✗**"
        } else if mine.iter().any(|r| r.verdict() == "missed") {
            "target missed (reported, not judged)"
        } else {
            "✓"
        };
        writeln!(
            md,
            "| {label} | {} | {} | {} | {fixed} | {ok} |",
            worst(true),
            worst(false),
            pct(f32_worst)
        )?;
    }
    writeln!(md)?;
    Ok(())
}

fn write_report(
    dir: &Path,
    rows: &[AccuracyRow],
    outcomes: &[(String, Outcome)],
    convergence: &[BristleConvergence],
    all_pass: bool,
) -> Result<()> {
    let mut md = String::new();
    writeln!(md, "# friction validation report\n")?;
    let failed_rows = rows.iter().filter(|r| !r.pass()).count();
    let missed = rows.iter().filter(|r| r.verdict() == "missed").count();
    let failed_outcomes = outcomes
        .iter()
        .filter(|(_, o)| o.pass == Some(false))
        .count();
    writeln!(
        md,
        "**Verdict: {}** — {} accuracy rows ({} failing; {} miss a reported target, see \
         the elasto-plastic rows at z_ba = 0.9 Fc/sigma0), {} experiments ({} failing). \
         Generated by `friction validate` (friction-host {}).\n",
        if all_pass { "pass" } else { "FAIL" },
        rows.len(),
        failed_rows,
        missed,
        outcomes.len(),
        failed_outcomes,
        env!("CARGO_PKG_VERSION"),
    )?;
    write_matrix(&mut md, outcomes)?;
    write_accuracy_summary(&mut md, rows)?;
    writeln!(md, "## Accuracy of the core's discrete step\n")?;
    writeln!(
        md,
        "The core is stepped at 1 kHz and 10 kHz with the sampled velocity `v(t_k)` held over each step \
         (as in `friction simulate`); the reference is the continuous-time model integrated by diffsol's \
         BDF method (rtol {:e}), written independently in the host. Errors are RMS and maximum of the force \
         difference over the whole signal, as a fraction of the static force `Fs`. `mean-v` is the same RMS \
         when the core is fed the mean velocity over each step (an encoder difference) instead. `f32-f64` is \
         the RMS difference between the core in f32 and in f64, / Fs. `fixed` is the RMS error against the \
         reference of the fixed-step form (`build_at(h)`) in Q16.16 fixed point (`Fixed32`, feature `fixed`), \
         fed the same held velocities, for the models that have that form; bounded at 3 % (1 kHz) and 1.5 % \
         (10 kHz) wherever an accuracy bound is set. Bounds (canudas1995 parameters): LuGre \
         <= 2 % at 1 kHz, <= 0.5 % at 10 kHz; Dahl (dahl1968, delta 1 and 2) <= 3 % and <= 1 % of Fc; \
         elasto-plastic (canudas1995-ep, z_ba = 0.5 Fc/sigma0), GMS and Xiong (N = 4) <= 3 % and <= 1 % of Fs; \
         static maps exact to rounding; f32 within 0.1 % wherever an accuracy bound is set. \
         Elasto-plastic at z_ba = 0.9 Fc/sigma0 on reversals slow and fast (up to 0.07 m/s with the two-tone \
         signal) is measured against the same 3 % and 1 % as a *target*, reported (`met`/`missed`) but not \
         judged: its step is exact for the held velocity (to 5e-6 Fs), but holding the sampled velocity puts \
         the displacement about h v / 2 ahead, more than the 1 µm transition zone, so the force drop \
         `sigma1 v` across the zone lands in the wrong sample; the `mean-v` column (the exact displacement) \
         shows what an encoder difference gives. \
         Rows marked `info` are measured and reported without a bound: other LuGre parameter sets (`+vd` is the \
         velocity-dependent damping `sigma1(v)` with `vd = vs`), and the switching models (reset integrator, \
         bristle), whose force jumps make an RMS over all samples mostly a count of misplaced jumps. For them \
         `smooth` is the RMS over the samples more than one sample away from a switching instant of the \
         reference (a bond breaking or re-forming, a velocity reversal, a bristle snapping), with the share of \
         samples it keeps. The reset integrator's reference is diffsol on its discontinuous right-hand side; \
         the bristle model's is an exact event-driven solution on the signal's displacement, split at velocity \
         reversals, with the same seeded generator (the random numbers are part of the model).\n",
        crate::sim::REFERENCE_RTOL
    )?;
    writeln!(md, "| model | signal | rate | rms / Fs | max / Fs | mean-v rms / Fs | smooth rms / Fs (kept) | f32 - f64 | fixed rms / Fs | bound | ok |")?;
    writeln!(md, "|---|---|---|---|---|---|---|---|---|---|---|")?;
    for r in rows {
        writeln!(
            md,
            "| {} | {} | {:.0} Hz | {:.4} % | {:.3} % | {:.4} % | {:.4} % ({:.0} %) | {:.2e} | {} | {} | {} |",
            r.model,
            r.signal,
            1.0 / r.h,
            100.0 * r.rms,
            100.0 * r.max,
            100.0 * r.rms_mean_v,
            100.0 * r.rms_smooth,
            100.0 * r.kept,
            r.f32_rms,
            r.fixed_rms.map_or("-".to_string(), pct),
            match (r.bound, r.target) {
                (Some(b), _) => pct(b),
                (None, Some(t)) => format!("target {}", pct(t)),
                (None, None) => "-".to_string(),
            },
            bold_fail(r.verdict())
        )?;
    }
    writeln!(
        md,
        "\nCore against reference at 1 kHz, one model of each kind:\n"
    )?;
    let mut plots: Vec<String> = std::fs::read_dir(dir)?
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.starts_with("accuracy-") && n.ends_with(".svg"))
        .collect();
    plots.sort();
    for name in plots {
        writeln!(md, "![{name}]({name})")?;
    }
    writeln!(md, "\n## Drift: LuGre creeps, elasto-plastic does not\n")?;
    writeln!(
        md,
        "astrom2008 drift parameters, mass at rest, force `2.5 (1 - cos 2 pi t) / 2` N, below the \
         elasto-plastic elastic limit `sigma0 z_ba = 2.73 N`; the core at a 1 ms step.\n\n\
         ![drift](drift-lugre-vs-elasto-plastic.svg)"
    )?;
    writeln!(md, "\n## Bristle model: what the randomness does\n")?;
    writeln!(
        md,
        "Sliding at constant speed over 2000 snapping deflections; force mean against the theory \
         `N sigma0 delta_s / 3` and its relative spread. The spread falls like `1/sqrt(N)` (last column \
         roughly constant).\n"
    )?;
    writeln!(
        md,
        "| N | mean / (N sigma0 delta_s / 3) | std / mean | std / mean x sqrt(N) |"
    )?;
    writeln!(md, "|---|---|---|---|")?;
    for c in convergence {
        writeln!(
            md,
            "| {} | {:.4} | {:.4} | {:.3} |",
            c.n,
            c.mean,
            c.spread,
            c.spread * (c.n as f64).sqrt()
        )?;
    }
    writeln!(md, "\n## Phenomena\n")?;
    writeln!(
        md,
        "Each experiment reports whether its phenomenon showed; it passes when that is what the model \
         is known to do (see `experiments::expectation`), and, for stick-slip, when the core at a 1 ms step \
         agrees with the reference solver. `-`: not judged, figures reported.\n"
    )?;
    writeln!(
        md,
        "| parameters | experiment | phenomenon | result | figure |"
    )?;
    writeln!(md, "|---|---|---|---|---|")?;
    for (set, o) in outcomes {
        let res = bold_fail(o.verdict());
        writeln!(
            md,
            "| {set} | {} | {} | {res} | {} |",
            o.name, o.phenomenon, o.figure
        )?;
    }
    for (set, o) in outcomes {
        let rel = o.plot.strip_prefix(dir).unwrap_or(&o.plot);
        writeln!(md, "\n### {set}: {}\n\n{}\n", o.name, o.figure)?;
        for line in &o.summary {
            writeln!(md, "- {line}")?;
        }
        writeln!(md, "\n![{}]({})", o.name, rel.display())?;
    }
    md.push_str(&crate::servo::report_section()?);
    md.push_str(&crate::servo::robustness::report_section(dir)?);
    crate::io::write_bytes(&dir.join("report.md"), md.as_bytes())?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::pct;

    #[test]
    fn percentages_read_at_a_glance() {
        assert_eq!(pct(0.02), "2.00 %");
        assert_eq!(pct(0.005), "0.500 %");
        assert_eq!(pct(0.000_31), "0.0310 %");
        assert_eq!(pct(1e-9), "1.0e-7 %");
        assert_eq!(pct(0.25), "25.0 %");
        assert_eq!(pct(0.0), "0 %");
    }

    /// Every model of the core's list is wired in every part of the host
    /// it needs: its shipped sets exist and name it, `friction validate`
    /// measures it (on its own set or as another set's variant), and it
    /// runs in Q16.16 exactly when the list gives it a fixed-step form.
    #[test]
    fn every_listed_model_is_wired_in_the_host() {
        use crate::models::{FIXED_POINT_MODELS, MODEL_NAMES, MODEL_SETS};
        assert_eq!(
            MODEL_SETS.iter().map(|(name, _)| *name).collect::<Vec<_>>(),
            MODEL_NAMES
        );
        for (name, sets) in MODEL_SETS {
            for set in *sets {
                let file = super::param_set(set).unwrap();
                assert_eq!(file.model.name(), *name, "params/{set}.toml");
            }
        }
        let measured = super::accuracy_models().unwrap();
        for name in MODEL_NAMES {
            let specs: Vec<_> = measured
                .iter()
                .filter(|(_, spec, ..)| spec.name() == *name)
                .collect();
            assert!(
                !specs.is_empty(),
                "`friction validate` does not measure `{name}`"
            );
            let fixed = FIXED_POINT_MODELS.contains(name);
            for (label, spec, ..) in specs {
                assert_eq!(
                    spec.host().fixed_stepper(1e-3).is_some(),
                    fixed,
                    "{label}: the host's fixed-point form of `{name}` against the list"
                );
                spec.validate().unwrap();
            }
        }
    }
}
