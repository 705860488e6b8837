//! `friction validate`: every implemented model against the reference
//! solver, f32 against f64, and every phenomenon experiment judged, into a
//! printed table and a Markdown report with plots.
//!
//! Three stages: `plan.rs` says what runs, from the model list and each
//! model's host module (its sets, variants, bounds and plots); `run.rs`
//! measures it in parallel (`measure.rs`) and times each section;
//! `report.rs` renders the console lines and `report.md`, its bounds read
//! from the models.

mod measure;
mod plan;
mod report;
mod run;

use crate::io::pct;
pub use measure::{accuracy, accuracy_on, bristle_convergence, BristleConvergence};
pub use plan::elasto_plastic_with_z_ba;
pub use report::accuracy_plot_name;
pub use run::{run, run_with};

use crate::models::ModelSpec;

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

/// The two sample periods every model is measured at: 1 and 10 kHz.
pub const PERIODS: [f64; 2] = [1e-3, 1e-4];

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
                let file = crate::params::param_set(set).unwrap();
                assert_eq!(file.model.name(), *name, "params/{set}.toml");
            }
        }
        let measured = super::plan::accuracy_models().unwrap();
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
                spec.host().validate().unwrap();
            }
        }
    }
}
