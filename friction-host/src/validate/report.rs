//! The console lines and the Markdown report of `friction validate`; the
//! bounds it states are read from the models ([`accuracy_bound`]) and the
//! plan, not written here.

use super::plan::Plan;
use super::{
    accuracy_bound, fixed_bound, pct, AccuracyRow, BristleConvergence, F32_BOUND, PERIODS,
};
use crate::experiments::{self, Outcome};
use crate::models::ModelSpec;
use anyhow::Result;
use std::fmt::Write as _;
use std::path::Path;

/// The accuracy table's title and column heads on the console.
pub(super) fn print_accuracy_header() {
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
}

/// One accuracy row on the console.
pub(super) fn print_row(r: &AccuracyRow) {
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

/// The phenomena section's title on the console.
pub(super) fn print_phenomena_header() {
    crate::outln!("\nPhenomena");
}

/// One experiment's verdict on the console.
pub(super) fn print_outcome(set: &str, out: &Outcome) {
    crate::outln!(
        "{:<22} {:<16} {:<5} {}",
        set,
        out.name,
        out.verdict(),
        out.figure
    );
}

/// The bristle convergence's title on the console.
pub(super) fn print_convergence_header() {
    crate::outln!(
        "\nBristle model: sliding force against N (mean / (N sigma0 delta_s / 3), relative spread)"
    );
}

/// The bristle convergence on the console.
pub(super) fn print_convergence(convergence: &[BristleConvergence]) {
    for c in convergence {
        crate::outln!(
            "N = {:>2}: mean {:.4}, std/mean {:.4}, std/mean x sqrt(N) {:.3}",
            c.n,
            c.mean,
            c.spread,
            c.spread * (c.n as f64).sqrt()
        );
    }
}

/// The verdict line and where the report is.
pub(super) fn print_verdict(dir: &Path, all_pass: bool) {
    crate::outln!(
        "\n{} — report: {}",
        if all_pass {
            "all checks pass"
        } else {
            "SOME CHECKS FAIL"
        },
        dir.join("report.md").display()
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

/// Markdown emphasis for failures.
fn bold_fail(verdict: &str) -> &str {
    if verdict == "FAIL" {
        "**FAIL**"
    } else {
        verdict
    }
}

/// One row per model, one column per phenomenon (in the columns' order,
/// [`experiments::columns`]): what was measured against what the model is
/// expected to do.
fn write_matrix(md: &mut String, outcomes: &[(String, Outcome)]) -> Result<()> {
    writeln!(md, "## Phenomena: measured against expected\n")?;
    writeln!(
        md,
        "Each cell: whether the phenomenon showed (`yes`/`no`, one per parameter set run), then \
         what the model is known to do (`expected`, `not expected`, or `not judged`), and ✓ or \
         **✗**. Details, figures and plots are in the sections below.\n"
    )?;
    let columns = experiments::columns();
    write!(md, "| model |")?;
    for e in &columns {
        write!(md, " {} |", e.title)?;
    }
    writeln!(md)?;
    writeln!(md, "|---|{}", "---|".repeat(columns.len()))?;
    let mut models: Vec<&str> = Vec::new();
    for (_, o) in outcomes {
        if !models.contains(&o.model) {
            models.push(o.model);
        }
    }
    for model in models {
        write!(md, "| {model} |")?;
        for e in &columns {
            let runs: Vec<&Outcome> = outcomes
                .iter()
                .map(|(_, o)| o)
                .filter(|o| o.model == model && o.name == e.name)
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

/// Writes `dir/report.md`: the verdict, the phenomenon matrix, the
/// accuracy summary and table, the plots, the drift and bristle sections,
/// each experiment, and the servo and robustness sections.
pub(super) fn write_report(
    dir: &Path,
    plan: &Plan,
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
         reference of the fixed-step form (`build_fixed_step(h)`) in Q16.16 fixed point (`Fixed32`, feature `fixed`), \
         fed the same held velocities, for the models that have that form; bounded at {} (1 kHz) and {} \
         (10 kHz) wherever an accuracy bound is set. Bounds (each model's `HostModel::accuracy_bound`): {}; \
         f32 within {} wherever an accuracy bound is set. \
         Elasto-plastic at z_ba = 0.9 Fc/sigma0 on reversals slow and fast (up to 0.07 m/s with the two-tone \
         signal) is measured against {} as a *target*, reported (`met`/`missed`) but not \
         judged: its step is exact for the held velocity (to 5e-6 Fs), but holding the sampled velocity puts \
         the displacement about h v / 2 ahead, more than the 1 µm transition zone, so the force drop \
         `sigma1 v` across the zone lands in the wrong sample; the `mean-v` column (the exact displacement) \
         shows what an encoder difference gives. \
         Rows marked `info` are measured and reported without a bound: other LuGre parameter sets (`+vd` is the \
         velocity-dependent damping `sigma1(v)` with `vd = vs`), and the switching models ({}), whose force jumps make an RMS over all samples mostly a count of misplaced jumps. For them \
         `smooth` is the RMS over the samples more than one sample away from a switching instant of the \
         reference (a bond breaking or re-forming, a velocity reversal, a bristle snapping), with the share of \
         samples it keeps. The reset integrator's reference is diffsol on its discontinuous right-hand side; \
         the bristle model's is an exact event-driven solution on the signal's displacement, split at velocity \
         reversals, with the same seeded generator (the random numbers are part of the model).\n",
        crate::sim::REFERENCE_RTOL,
        pct(fixed_bound(PERIODS[0])),
        pct(fixed_bound(PERIODS[1])),
        bounds(plan).join("; "),
        pct(F32_BOUND),
        at_rates(&plan.hard.1).unwrap_or_else(|| "no bound".into()),
        switching_models(plan).join(", "),
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
    let (force, limit) = drift_force_and_elastic_limit()?;
    writeln!(
        md,
        "astrom2008 drift parameters, mass at rest, force `{force} (1 - cos 2 pi t) / 2` N, below the \
         elasto-plastic elastic limit `sigma0 z_ba = {limit:.2} N`; the core at a 1 ms step.\n\n\
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

/// `<= a at 1 kHz, <= b at 10 kHz` from the model's accuracy bounds at
/// [`PERIODS`]; `None` where it sets none.
fn at_rates(spec: &ModelSpec) -> Option<String> {
    let [a, b] = PERIODS.map(|h| accuracy_bound(spec, h));
    Some(format!("<= {} at 1 kHz, <= {} at 10 kHz", pct(a?), pct(b?)))
}

/// The judged sets' bounds, `label (model), ... <= a at 1 kHz, <= b at
/// 10 kHz`, the sets with the same bounds together, in the plan's order.
/// The switching models the accuracy table measures
/// ([`HostModel::switching`]), in its order, named as prose
/// (`reset integrator`).
///
/// [`HostModel::switching`]: crate::models::HostModel::switching
fn switching_models(plan: &Plan) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for (_, spec, _, _) in &plan.models {
        let name = spec.name().replace('-', " ");
        if spec.host().switching() && !names.contains(&name) {
            names.push(name);
        }
    }
    names
}

/// The drift comparison's peak force and the elasto-plastic elastic limit
/// `sigma0 z_ba`, read from the set the comparison runs
/// (`astrom2008-drift-ep`, see `measure::drift_comparison`).
fn drift_force_and_elastic_limit() -> Result<(f64, f64)> {
    let file = crate::params::param_set("astrom2008-drift-ep")?;
    let ModelSpec::ElastoPlastic(p) = file.model else {
        anyhow::bail!("astrom2008-drift-ep is not an elasto-plastic set")
    };
    Ok((file.rig.force.unwrap_or(2.5), p.lugre.sigma0 * p.z_ba))
}

fn bounds(plan: &Plan) -> Vec<String> {
    let mut groups: Vec<(String, Vec<String>)> = Vec::new();
    for (label, spec, ..) in plan.models.iter().filter(|(_, _, bounded, _)| *bounded) {
        let Some(rates) = at_rates(spec) else {
            continue;
        };
        let set = format!("{label} ({})", spec.name());
        match groups.iter_mut().find(|(r, _)| *r == rates) {
            Some((_, sets)) => sets.push(set),
            None => groups.push((rates, vec![set])),
        }
    }
    groups
        .into_iter()
        .map(|(rates, sets)| format!("{} {rates}", sets.join(", ")))
        .collect()
}
