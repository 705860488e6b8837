//! `friction identify`: friction parameters from a measured trajectory.
//!
//! The measured force of a driven axis is modelled by inverse dynamics,
//!
//! ```text
//! force = mass * a + N * friction(v) + offset
//! ```
//!
//! where `mass` and `offset` are estimated only with `--inertia` (otherwise
//! the force is the friction itself), and `N` is the normal force when
//! `--normal-force` names a column (the friction parameters are then
//! coefficients: friction per unit normal force) and 1 otherwise.
//!
//! Signal conditioning follows the inverse-dynamics identification
//! literature (IDIM-LS, Gautier and Janot): the position is low-pass
//! filtered forward and backward by a Butterworth filter (zero phase, see
//! [`filter`]), velocity and acceleration come from central differences of
//! the filtered position, the force (and normal force) go through the same
//! zero-phase filter, and every signal is then decimated.
//!
//! Models: `coulomb` and `coulomb-viscous` (linear least squares), `stribeck` (nonlinear
//! least squares from the best point of a grid over `vs`) and `lugre`
//! (the Stribeck part from the sliding samples, then `sigma0` and `sigma1`
//! by minimising the simulation error of the core's LuGre step).

pub mod data;
pub mod filter;
pub mod fit;
pub mod report;
pub mod solve;

use crate::checks::{self, args, ranges};
use anyhow::{bail, Result};
use filter::{central_differences, downsample, Butterworth};
use std::path::{Path, PathBuf};

/// The models `identify` fits.
pub const MODELS: &[&str] = &["coulomb", "coulomb-viscous", "stribeck", "lugre"];

/// Column names and scalings of a measured trajectory.
#[derive(Clone, Debug)]
pub struct Columns {
    /// Time (s).
    pub time: String,
    /// Position; ignored when `velocity` is given.
    pub position: String,
    /// Measured velocity, if any.
    pub velocity: Option<String>,
    /// Force (or the signal proportional to it, see `force_gain`).
    pub force: String,
    /// Factor from the force column to force (e.g. motor constant, -1 to flip the sign).
    pub force_gain: f64,
    /// Normal force, for friction proportional to the normal load.
    pub normal_force: Option<String>,
}

impl Default for Columns {
    fn default() -> Self {
        Self {
            time: "t".into(),
            position: "x".into(),
            velocity: None,
            force: "f".into(),
            force_gain: 1.0,
            normal_force: None,
        }
    }
}

/// Signal conditioning.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Conditioning {
    /// Cut-off of the zero-phase Butterworth low-pass (Hz); `None`: a tenth
    /// of the sample rate.
    pub cutoff: Option<f64>,
    /// Order of the Butterworth filter.
    pub order: usize,
    /// Keep every `decimate`-th sample; `None`: the largest factor that
    /// keeps the new Nyquist frequency at or above 2.5 times the cut-off.
    pub decimate: Option<usize>,
}

impl Default for Conditioning {
    fn default() -> Self {
        Self {
            cutoff: None,
            order: 4,
            decimate: None,
        }
    }
}

/// Everything `identify` needs.
#[derive(Clone, Debug)]
pub struct Options {
    /// The measured trajectory.
    pub input: PathBuf,
    /// One of [`MODELS`].
    pub model: String,
    /// Output folder.
    pub output: PathBuf,
    /// Columns.
    pub columns: Columns,
    /// Estimate `mass` and `offset` (a driven axis).
    pub inertia: bool,
    /// Signal conditioning.
    pub conditioning: Conditioning,
    /// Stribeck exponent `delta` (fixed, not fitted).
    pub stribeck_exponent: f64,
    /// The steady-state law of `lugre`'s first stage.
    pub lugre_static: fit::StaticPart,
    /// A second trajectory for cross-validation.
    pub validate: Option<PathBuf>,
    /// Show a progress bar for iterative fits.
    pub progress: bool,
}

/// Fewest raw samples accepted.
pub const MIN_SAMPLES: usize = 50;

/// The conditioned signals at the raw sample rate, before the second
/// filtering and decimation (the end samples dropped).
#[derive(Clone, Debug, Default)]
pub struct FullRate {
    /// Time (s).
    pub t: Vec<f64>,
    /// Velocity.
    pub v: Vec<f64>,
    /// Acceleration.
    pub a: Vec<f64>,
    /// Normal force (filtered), if used.
    pub normal: Option<Vec<f64>>,
}

impl FullRate {
    /// The normal force at sample `k` (1 without a normal-force column).
    pub fn n(&self, k: usize) -> f64 {
        self.normal.as_ref().map_or(1.0, |n| n[k])
    }
}

/// The conditioned signals the regression sees.
///
/// Parallel filtering: the measured force is low-pass filtered (zero phase)
/// and decimated; every regressor column and every model prediction, which
/// are computed at the raw rate from the conditioned velocity and
/// acceleration, go through the same filter and decimation
/// ([`Signals::observe`]) before they are compared with it. A model linear
/// in its parameters then fits the filtered data exactly as it fits the
/// raw data, while the Coulomb jump at each reversal (which the filter
/// smears) biases nothing.
#[derive(Clone, Debug, Default)]
pub struct Signals {
    /// The raw-rate signals.
    pub full: FullRate,
    /// The zero-phase filter.
    pub filter: Option<Butterworth>,
    /// Time (s).
    pub t: Vec<f64>,
    /// Velocity.
    pub v: Vec<f64>,
    /// Acceleration.
    pub a: Vec<f64>,
    /// Force (times the gain).
    pub f: Vec<f64>,
    /// Normal force, if used.
    pub normal: Option<Vec<f64>>,
    /// Sample period after decimation (s).
    pub h: f64,
    /// Raw sample rate (Hz).
    pub fs: f64,
    /// Cut-off used (Hz).
    pub cutoff: f64,
    /// Decimation factor used.
    pub decimate: usize,
    /// Raw samples (after resampling, if any).
    pub raw_samples: usize,
    /// The smallest and largest time step when the file was not evenly
    /// sampled and was resampled at its median step.
    pub resampled: Option<(f64, f64)>,
}

/// Linear interpolation of every column onto `t0 + k h`.
fn resample(data: &[Vec<f64>], h: f64) -> Vec<Vec<f64>> {
    let t = &data[0];
    let n = ((t[t.len() - 1] - t[0]) / h).floor() as usize + 1;
    let mut out = vec![Vec::with_capacity(n); data.len()];
    let mut j = 0;
    for k in 0..n {
        let tk = t[0] + k as f64 * h;
        while j + 2 < t.len() && t[j + 1] < tk {
            j += 1;
        }
        let w = ((tk - t[j]) / (t[j + 1] - t[j])).clamp(0.0, 1.0);
        out[0].push(tk);
        for (o, c) in out.iter_mut().zip(data).skip(1) {
            o.push(c[j] + w * (c[j + 1] - c[j]));
        }
    }
    out
}

impl Signals {
    /// The normal force at sample `k` (1 without a normal-force column).
    pub fn n(&self, k: usize) -> f64 {
        self.normal.as_ref().map_or(1.0, |n| n[k])
    }
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }
    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }
    /// A raw-rate signal as the regression sees the force: zero-phase
    /// filtered, then decimated.
    pub fn observe(&self, x: &[f64]) -> Vec<f64> {
        match &self.filter {
            Some(lp) => downsample(&lp.filtfilt(x), 0, self.decimate),
            None => downsample(x, 0, self.decimate),
        }
    }
}

/// Where a trajectory came from, to name a sample in a message: a file's
/// line and column, or an array's index (the Python package).
#[derive(Clone, Copy, Debug)]
pub enum Origin<'a> {
    /// A file (its path as shown); sample `k` is on line `k + 2`.
    File(&'a str),
    /// Arrays passed by a caller, named by the columns' names.
    Arrays,
}

impl Origin<'_> {
    /// The whole trajectory: `data.csv:` or `the arrays:`.
    fn whole(&self) -> String {
        match self {
            Origin::File(path) => path.to_string(),
            Origin::Arrays => "the arrays".into(),
        }
    }

    /// What to split at a gap: `file` or `arrays`.
    fn noun(&self) -> &'static str {
        match self {
            Origin::File(_) => "file",
            Origin::Arrays => "arrays",
        }
    }

    /// Sample `k` of column `name`.
    fn sample(&self, name: &str, k: usize) -> String {
        match self {
            Origin::File(path) => format!("{path}:{}: column `{name}`", k + 2),
            Origin::Arrays => format!("`{name}`[{k}]"),
        }
    }
}

/// Reads and conditions a trajectory. Errors are bad input (exit code 2).
pub fn prepare(path: &Path, cols: &Columns, cond: &Conditioning) -> Result<Signals> {
    let origin = path.display().to_string();
    let data = data::read_columns(path, &column_names(cols))?.data;
    data::check_time(&data[0], &origin, &cols.time)?;
    condition(data, Origin::File(&origin), cols, cond)
}

/// The columns a trajectory needs, in the order [`condition`] takes them:
/// time, force, position (or velocity), and the normal force if used.
pub fn column_names(cols: &Columns) -> Vec<&str> {
    let mut names: Vec<&str> = vec![&cols.time, &cols.force];
    names.push(cols.velocity.as_deref().unwrap_or(&cols.position));
    if let Some(n) = &cols.normal_force {
        names.push(n);
    }
    names
}

/// Conditions a trajectory whose columns are in the order of
/// [`column_names`], each finite, the time strictly increasing (checked
/// by the caller, which knows where each sample came from).
pub fn condition(
    data: Vec<Vec<f64>>,
    origin: Origin<'_>,
    cols: &Columns,
    cond: &Conditioning,
) -> Result<Signals> {
    let n = data[0].len();
    if n < MIN_SAMPLES {
        bail!(
            "{}: {n} samples; identification needs at least {MIN_SAMPLES}",
            origin.whole()
        );
    }
    // uneven sampling (gaps, a stretch at another rate): linear
    // interpolation onto the median period
    let mut steps: Vec<f64> = data[0].windows(2).map(|w| w[1] - w[0]).collect();
    steps.sort_by(f64::total_cmp);
    let median = steps[steps.len() / 2];
    let (dmin, dmax) = (steps[0], steps[steps.len() - 1]);
    let resampled = dmax > 1.5 * median || dmin < 0.5 * median;
    if resampled {
        // the resampled length must stay near the file's: a gap of many
        // median steps would be filled with interpolated data (and memory)
        let span = (data[0][n - 1] - data[0][0]) / median;
        if !(span.is_finite() && span <= 2.0 * n as f64) {
            let gap = data[0]
                .windows(2)
                .position(|w| w[1] - w[0] == dmax)
                .unwrap_or(0);
            bail!(
                "{}: a time step of {dmax:e} s ({:.0} median steps of {median:e} s); resampling onto the median step would take {span:.3e} samples for {n} rows: split the {} at the gap",
                origin.sample(&cols.time, gap + 1),
                dmax / median,
                origin.noun()
            );
        }
    }
    let data = if resampled {
        resample(&data, median)
    } else {
        data
    };
    let t = &data[0];
    let n = t.len();
    let h = (t[n - 1] - t[0]) / (n - 1) as f64;
    checks::magnitude_within(args::FORCE_GAIN, cols.force_gain, ranges::FORCE_GAIN)?;
    let order = checks::filter_order(i64::try_from(cond.order).unwrap_or(i64::MAX))?;
    let fs = 1.0 / h;
    let cutoff = match cond.cutoff {
        Some(c) => checks::cutoff(c, fs)?,
        None => 0.1 * fs,
    };
    // the checks above are the filter's own conditions: an error here is
    // the sample rate's (a time span that over- or underflows)
    let lp = Butterworth::lowpass(order, cutoff, fs).map_err(|e| {
        anyhow::anyhow!(
            "{}: the sample rate {fs:e} Hz admits no filter: {e}",
            origin.whole()
        )
    })?;
    let (v, a) = match cols.velocity {
        Some(_) => {
            let v = lp.filtfilt(&data[2]);
            let (a, _) = central_differences(&v, h);
            (v, a)
        }
        None => central_differences(&lp.filtfilt(&data[2]), h),
    };
    let normal = cols.normal_force.as_ref().map(|_| lp.filtfilt(&data[3]));
    let decimate = match cond.decimate {
        Some(d) => checks::decimate(i64::try_from(d).unwrap_or(i64::MAX))?,
        None => ((0.5 * fs / (2.5 * cutoff)).floor() as usize).max(1),
    };
    // drop the ends, where the filtered position depends on the padding
    // (three periods of the cut-off, and at least the one-sided differences)
    let edge = lp.settle().max(1);
    let needed = edge.saturating_mul(2).saturating_add(MIN_SAMPLES);
    if n <= needed {
        // named as the cut-off's fault, in each front end's spelling: a
        // higher one settles sooner (also when the default was used)
        let refusal = checks::Refusal {
            arg: args::CUTOFF,
            value: cutoff,
            rule: format!(
                "too low for {n} samples: the filter's settling time ({edge} samples at each end, dropped) leaves too few, identification needs at least {} at this cut-off; raise it",
                needed.saturating_add(1)
            ),
        };
        return Err(anyhow::Error::new(refusal).context(origin.whole()));
    }
    let inner = edge..n - edge;
    let full = FullRate {
        t: t[inner.clone()].to_vec(),
        v: v[inner.clone()].to_vec(),
        a: a[inner.clone()].to_vec(),
        normal: normal.as_ref().map(|x| x[inner.clone()].to_vec()),
    };
    let f: Vec<f64> = data[1][inner].iter().map(|x| x * cols.force_gain).collect();
    let inner = |x: &[f64]| downsample(x, 0, decimate);
    let f = downsample(&lp.filtfilt(&f), 0, decimate);
    let s = Signals {
        t: inner(&full.t),
        v: inner(&full.v),
        a: inner(&full.a),
        f,
        normal: full.normal.as_deref().map(inner),
        full,
        filter: Some(lp),
        h: h * decimate as f64,
        fs,
        cutoff,
        decimate,
        raw_samples: n,
        resampled: resampled.then_some((dmin, dmax)),
    };
    if s.len() < MIN_SAMPLES {
        bail!(
            "{}: {} samples after decimation by {decimate}; identification needs at least {MIN_SAMPLES}",
            origin.whole(),
            s.len()
        );
    }
    if s.v.iter().all(|v| v.abs() < f64::MIN_POSITIVE) {
        bail!(
            "{}: the axis never moves: friction cannot be identified",
            origin.whole()
        );
    }
    Ok(s)
}

/// The outcome of [`identify`].
#[derive(Debug)]
pub struct Outcome {
    /// The fit (also when rejected, if there is an estimate).
    pub fit: Option<fit::Fit>,
    /// Why the fit is rejected (a judged failure).
    pub rejected: Option<String>,
    /// Error on the estimation data.
    pub estimation: Option<report::ErrorStats>,
    /// Error on the validation data.
    pub validation: Option<report::ErrorStats>,
    /// The conditioned estimation signals.
    pub signals: Signals,
}

/// Checks the model name: the library's other models (the model list)
/// get their own message.
pub fn check_model(name: &str) -> Result<()> {
    if MODELS.contains(&name) {
        return Ok(());
    }
    let supported = MODELS.join(", ");
    if crate::models::MODEL_NAMES.contains(&name) {
        bail!(
            "model `{name}` exists in the library but `identify` cannot fit it yet; identify supports: {supported}"
        );
    }
    bail!("unknown model `{name}`; identify supports: {supported}")
}

fn progress_bar(show: bool, model: &str) -> indicatif::ProgressBar {
    use std::io::IsTerminal;
    if !show || !std::io::stderr().is_terminal() {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new_spinner();
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{spinner} {msg}: {pos} model evaluations [{elapsed}]",
        )
        .expect("valid template"),
    );
    bar.set_message(format!("fitting `{model}`"));
    bar.enable_steady_tick(std::time::Duration::from_millis(120));
    bar
}

/// What `identify` writes into its output folder.
const OUTPUTS: [&str; 6] = [
    "params.toml",
    "report.md",
    "fit.csv",
    "force.svg",
    "friction.svg",
    "validation.svg",
];

/// Where a rejected fit's report goes, inside the output folder.
pub const REJECTED: &str = "rejected";

/// A folder the run writes into first, removed when dropped (after an
/// error: earlier outputs stay as they were).
struct Staging(PathBuf);

impl Drop for Staging {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Fits the model and writes its outputs, all or nothing. An accepted fit:
/// `params.toml`, `report.md`, `fit.csv` and the plots replace the output
/// folder's earlier ones (an output this run does not produce, e.g.
/// `validation.svg` without `--validate`, is removed). A rejected fit
/// ([`Outcome::rejected`]) leaves them as they were and writes its report
/// and plots into `rejected/` inside the output folder. Bad input is an
/// error and writes nothing.
pub fn identify(o: &Options) -> Result<Outcome> {
    identify_from(o, None)
}

/// [`identify`] on a trajectory given as columns in the order of
/// [`column_names`] (the Python package's arrays, checked by the caller:
/// finite, time strictly increasing, equal lengths) instead of `o.input`,
/// which only names it in the report.
pub fn identify_data(o: &Options, data: Vec<Vec<f64>>) -> Result<Outcome> {
    identify_from(o, Some(data))
}

fn identify_from(o: &Options, data: Option<Vec<Vec<f64>>>) -> Result<Outcome> {
    check_model(&o.model)?;
    checks::within(
        args::STRIBECK_EXPONENT,
        o.stribeck_exponent,
        ranges::STRIBECK_EXPONENT,
    )?;
    // no output of this run may overwrite an input
    let mut inputs: Vec<&Path> = vec![&o.input];
    if let Some(v) = &o.validate {
        inputs.push(v);
    }
    for name in OUTPUTS {
        crate::io::refuse_overwrite("--output", &o.output.join(name), &inputs)?;
        crate::io::refuse_overwrite("--output", &o.output.join(REJECTED).join(name), &inputs)?;
    }
    let s = match data {
        Some(data) => condition(data, Origin::Arrays, &o.columns, &o.conditioning)?,
        None => prepare(&o.input, &o.columns, &o.conditioning)?,
    };
    let val = match &o.validate {
        Some(p) => {
            let cond = Conditioning {
                cutoff: Some(s.cutoff),
                decimate: Some(s.decimate),
                ..o.conditioning
            };
            let v = prepare(p, &o.columns, &cond)?;
            if (v.fs - s.fs).abs() > 1e-3 * s.fs {
                bail!(
                    "{}: sampled at {:.4} Hz, the estimation data at {:.4} Hz: resample one of them",
                    p.display(),
                    v.fs,
                    s.fs
                );
            }
            Some(v)
        }
        None => None,
    };
    std::fs::create_dir_all(&o.output)
        .map_err(|e| anyhow::anyhow!("cannot create {}: {e}", o.output.display()))?;
    let staging = Staging(o.output.join(format!(".identify-{}", std::process::id())));
    let _ = std::fs::remove_dir_all(&staging.0);
    std::fs::create_dir(&staging.0)
        .map_err(|e| anyhow::anyhow!("cannot create {}: {e}", staging.0.display()))?;
    let dir = staging.0.as_path();
    let fo = fit::FitOptions {
        inertia: o.inertia,
        stribeck_exponent: o.stribeck_exponent,
        lugre_static: o.lugre_static,
    };
    let bar = progress_bar(o.progress, &o.model);
    let result = match o.model.as_str() {
        "coulomb" => fit::coulomb(&s, &fo),
        "coulomb-viscous" => fit::coulomb_viscous(&s, &fo),
        "stribeck" => fit::stribeck(&s, &fo, &bar),
        _ => fit::lugre(&s, &fo, &bar),
    };
    bar.finish_and_clear();
    let (fit, rejected) = match result {
        Ok(f) => {
            let undetermined = f
                .params
                .iter()
                .find(|p| !(p.value.is_finite() && p.std.is_finite()));
            match undetermined {
                Some(p) => {
                    let why = format!(
                        "`{}` = {:e} with standard deviation {:e}: the data do not determine it",
                        p.name, p.value, p.std
                    );
                    (Some(f), Some(why))
                }
                None => (Some(f), None),
            }
        }
        Err(r) => (r.fit.map(|b| *b), Some(r.reason)),
    };
    let mut out = Outcome {
        fit,
        rejected,
        estimation: None,
        validation: None,
        signals: Signals::default(),
    };
    let mut plots = Vec::new();
    if let Some(fit) = &out.fit {
        if let Some(pred) = fit.predict(&s) {
            out.estimation = Some(report::ErrorStats::new(&s.f, &pred));
            report::force_plot(
                &dir.join("force.svg"),
                &format!("{}: measured and predicted force", o.model),
                &s,
                &pred,
            )?;
            plots.push((
                "force.svg".to_string(),
                "Measured against predicted force over time (estimation data)".to_string(),
            ));
            let fr = report::measured_friction(fit, &s);
            crate::io::write_columns(
                &dir.join("fit.csv"),
                &["t", "v", "a", "f", "f_pred", "friction"],
                &[&s.t, &s.v, &s.a, &s.f, &pred, &fr],
            )?;
        }
        report::friction_plot(
            &dir.join("friction.svg"),
            &format!("{}: friction against velocity", o.model),
            fit,
            &s,
        )?;
        plots.push((
            "friction.svg".to_string(),
            "Friction against velocity with the fitted curve".to_string(),
        ));
        if let Some(v) = &val {
            if let Some(pred) = fit.predict(v) {
                out.validation = Some(report::ErrorStats::new(&v.f, &pred));
                report::force_plot(
                    &dir.join("validation.svg"),
                    &format!("{}: cross-validation", o.model),
                    v,
                    &pred,
                )?;
                plots.push((
                    "validation.svg".to_string(),
                    "Measured against predicted force over time (validation data)".to_string(),
                ));
            }
        }
    }
    if out.rejected.is_none() {
        if let Some(e) = out.estimation.filter(|e| !e.is_finite()) {
            out.rejected = Some(format!(
                "the prediction error is not finite (RMS {:e}, relative {:e} %)",
                e.rms, e.relative
            ));
        }
    }
    if out.rejected.is_none() {
        if let Some(e) = out.validation.filter(|e| !e.is_finite()) {
            out.rejected = Some(format!(
                "the cross-validation error on {} is not finite (RMS {:e}, relative {:e} %): its forces overflow or vanish in double precision, or the fit predicts none there",
                o.validate.as_ref().map_or_else(String::new, |p| p.display().to_string()),
                e.rms,
                e.relative
            ));
        }
    }
    if out.rejected.is_none() {
        if let Some(fit) = &out.fit {
            let text = report::params_toml(fit, o);
            crate::params::ParamFile::parse(&text, "identified parameters")?;
            crate::io::write_bytes(&dir.join("params.toml"), text.as_bytes())?;
        }
    }
    let md = report::markdown(&report::Report {
        options: o,
        signals: &s,
        fit: out.fit.as_ref(),
        rejected: out.rejected.as_deref(),
        estimation: out.estimation,
        validation: out.validation,
        plots,
    });
    crate::io::write_bytes(&dir.join("report.md"), md.as_bytes())?;
    publish(dir, &o.output, out.rejected.is_some())?;
    out.signals = s;
    Ok(out)
}

/// Moves the staged outputs into `output`: for an accepted fit, each
/// replaces its earlier version and an earlier output this run did not
/// produce (and an earlier `rejected/`) is removed; for a rejected one, the
/// whole staging folder becomes `rejected/`, the accepted outputs untouched.
fn publish(staged: &Path, output: &Path, rejected: bool) -> Result<()> {
    let fail =
        |what: &Path, e: std::io::Error| anyhow::anyhow!("cannot write {}: {e}", what.display());
    let rejected_dir = output.join(REJECTED);
    if rejected_dir.exists() {
        std::fs::remove_dir_all(&rejected_dir).map_err(|e| fail(&rejected_dir, e))?;
    }
    if rejected {
        return std::fs::rename(staged, &rejected_dir).map_err(|e| fail(&rejected_dir, e));
    }
    for name in OUTPUTS {
        let (from, to) = (staged.join(name), output.join(name));
        if from.exists() {
            std::fs::rename(&from, &to).map_err(|e| fail(&to, e))?;
        } else if to.exists() {
            std::fs::remove_file(&to).map_err(|e| fail(&to, e))?;
        }
    }
    Ok(())
}

/// The command: runs [`identify`] and prints a summary. `Ok(false)` when the
/// fit is rejected (exit code 1).
pub fn run(o: &Options) -> Result<bool> {
    let out = identify(o)?;
    let s = &out.signals;
    crate::outln!(
        "{} from {}: {} samples (cut-off {:.4} Hz, decimation {})",
        o.model,
        o.input.display(),
        s.len(),
        s.cutoff,
        s.decimate
    );
    if let Some(fit) = &out.fit {
        for p in &fit.params {
            crate::outln!(
                "  {:<8} = {:>14.6e}  (std {:.3e}, {:.3} %)",
                p.name,
                p.value,
                p.std,
                p.relative_std()
            );
        }
    }
    if let Some(e) = out.estimation {
        crate::outln!(
            "  estimation: relative error {:.3} %, RMS {:.4e}",
            e.relative,
            e.rms
        );
    }
    if let Some(e) = out.validation {
        crate::outln!(
            "  validation: relative error {:.3} %, RMS {:.4e}",
            e.relative,
            e.rms
        );
    }
    let folder = if out.rejected.is_some() {
        o.output.join(REJECTED)
    } else {
        o.output.clone()
    };
    crate::outln!("  report: {}", folder.join("report.md").display());
    match out.rejected {
        Some(why) => {
            eprintln!("error: fit rejected: {why}");
            Ok(false)
        }
        None => {
            crate::outln!("  params: {}", o.output.join("params.toml").display());
            Ok(true)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_library_model_is_known_the_fitted_ones_accepted() {
        for name in crate::models::MODEL_NAMES {
            match check_model(name) {
                Ok(()) => assert!(MODELS.contains(name), "{name}"),
                Err(e) => {
                    let e = e.to_string();
                    assert!(e.contains("exists in the library"), "{name}: {e}");
                    assert!(e.contains(&MODELS.join(", ")), "{e}");
                }
            }
        }
        let e = check_model("asymmetric-coulomb-viscous")
            .unwrap_err()
            .to_string();
        assert!(e.contains("exists in the library"), "{e}");
        let e = check_model("nope").unwrap_err().to_string();
        assert!(
            e.starts_with("unknown model `nope`; identify supports: coulomb"),
            "{e}"
        );
    }
}
