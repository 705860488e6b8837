//! Runs the [`Plan`]: models and experiments in parallel on all cores,
//! each section timed, progress on stderr; the console and the report
//! keep the plan's order.

use super::measure::{accuracy, accuracy_on, bristle_convergence, drift_comparison};
use super::plan::Plan;
use super::report::{self, print_row};
use super::{accuracy_bound, AccuracyRow, F32_BOUND};
use crate::experiments::{self, Options, Outcome};
use crate::params::param_set;
use crate::signals::reversal_signals;
use anyhow::{Context, Result};
use rayon::prelude::*;
use std::path::Path;
use std::sync::Mutex;
use std::time::Instant;

/// The full validation. Returns whether everything passed.
pub fn run(dir: &Path) -> Result<bool> {
    run_with(dir, false)
}

/// Each section's cost, gathered from the parallel runs.
struct Costs(Mutex<Vec<(String, f64)>>);

impl Costs {
    fn timed(&self, what: String, since: Instant) {
        if let Ok(mut c) = self.0.lock() {
            c.push((what, since.elapsed().as_secs_f64()));
        }
    }

    /// `validate --timings`: the wall time and each section's cost, on stderr.
    fn print(self, started: Instant) {
        let mut c = self.0.into_inner().unwrap_or_default();
        c.sort_by(|a, b| b.1.total_cmp(&a.1));
        eprintln!("\nvalidate --timings: wall time {:.1} s on {} threads; cost of each section (s, in parallel):", started.elapsed().as_secs_f64(), rayon::current_num_threads());
        for (what, secs) in c {
            eprintln!("{secs:>8.2}  {what}");
        }
    }
}

/// [`run`], printing each section's cost on stderr when `timings` is set
/// (`friction validate --timings`). Models and experiments run in
/// parallel on all cores; the console and the report keep their order.
pub fn run_with(dir: &Path, timings: bool) -> Result<bool> {
    let started = Instant::now();
    let costs = Costs(Mutex::new(Vec::new()));
    std::fs::create_dir_all(dir)
        .with_context(|| format!("--output {}: cannot create the folder", dir.display()))?;
    report::print_accuracy_header();
    let plan = Plan::new()?;
    let progress = Mutex::new(Progress::new(plan.sections()));
    let tick = |what: &str| {
        if let Ok(mut p) = progress.lock() {
            p.tick(what);
        }
    };
    let mut rows = Vec::new();
    let measured: Vec<Result<Vec<AccuracyRow>>> = plan
        .models
        .par_iter()
        .map(|(label, spec, bounded, plots)| {
            let since = Instant::now();
            let rows = accuracy(label, spec, *bounded, plots.then_some(dir));
            let what = format!("accuracy {label} {}", spec.name());
            tick(&what);
            costs.timed(what, since);
            rows
        })
        .collect();
    for model_rows in measured {
        for r in model_rows? {
            print_row(&r);
            rows.push(r);
        }
    }
    let since = Instant::now();
    // The 3 % / 1 % are reported as targets, not judged: with the
    // velocity held over each step the displacement runs h v / 2 ahead, more
    // than the 1 µm transition zone at this z_ba, while the step itself is
    // exact for the held velocity (see the README).
    let (hard_label, hard) = &plan.hard;
    for mut r in accuracy_on(&reversal_signals(), hard_label, hard, false, Some(dir))? {
        r.f32_bound = Some(F32_BOUND);
        r.target = accuracy_bound(hard, r.h);
        print_row(&r);
        rows.push(r);
    }
    costs.timed(format!("accuracy {hard_label}"), since);

    report::print_phenomena_header();
    let mut outcomes: Vec<(String, Outcome)> = Vec::new();
    let judged: Vec<Result<Outcome>> = plan
        .experiments
        .par_iter()
        .map(|&(set, name)| {
            let since = Instant::now();
            let file = param_set(set)?;
            let out = experiments::run(
                name,
                &file,
                Options::default(),
                &dir.join(format!("{set}-{name}")),
            );
            let what = format!("experiment {set} {name}");
            tick(&what);
            costs.timed(what, since);
            out
        })
        .collect();
    for (&(set, _), out) in plan.experiments.iter().zip(judged) {
        let out = out?;
        report::print_outcome(set, &out);
        outcomes.push((set.to_string(), out));
    }
    report::print_convergence_header();
    tick("bristle convergence");
    let since = Instant::now();
    let convergence = bristle_convergence()?;
    costs.timed("bristle convergence".into(), since);
    report::print_convergence(&convergence);
    let since = Instant::now();
    drift_comparison(dir)?;
    costs.timed("drift comparison".into(), since);
    if let Ok(p) = progress.lock() {
        p.finish();
    }
    let all_pass =
        rows.iter().all(AccuracyRow::pass) && outcomes.iter().all(|(_, o)| o.pass != Some(false));
    let since = Instant::now();
    report::write_report(dir, &plan, &rows, &outcomes, &convergence, all_pass)?;
    costs.timed(
        "report (servo benchmark, robustness map, plots)".into(),
        since,
    );
    if timings {
        costs.print(started);
    }
    report::print_verdict(dir, all_pass);
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
