//! What `friction validate` runs: the parameter sets of the accuracy
//! table, derived from the model list (`friction_core::model_list!`, read
//! by the host registry) and each model's host module, and the experiments.

use crate::experiments;
use crate::models::MODEL_SETS;
use crate::params::{param_set, ModelSpec};
use anyhow::Result;

/// One entry of the accuracy table: `(label, model, bounded, plots)`.
pub(crate) type Measured = (String, ModelSpec, bool, bool);

/// Everything one validation runs.
pub(super) struct Plan {
    /// The accuracy table's sets ([`accuracy_models`]).
    pub models: Vec<Measured>,
    /// The hard elasto-plastic case: z_ba near Fc/sigma0, on reversals up
    /// to 0.07 m/s, its bounds reported as targets.
    pub hard: (&'static str, ModelSpec),
    /// The experiments, each `(set, experiment)`, in report order.
    pub experiments: Vec<(&'static str, &'static str)>,
}

impl Plan {
    /// The validation's plan.
    pub fn new() -> Result<Self> {
        Ok(Self {
            models: accuracy_models()?,
            hard: (
                "canudas1995-ep z_ba=0.9Fc/sigma0",
                elasto_plastic_with_z_ba(0.9)?,
            ),
            experiments: EXPERIMENTS
                .iter()
                .flat_map(|(set, names)| names.iter().map(move |name| (*set, *name)))
                .collect(),
        })
    }

    /// The sections the progress line counts: every measured set, every
    /// experiment and the bristle convergence.
    pub fn sections(&self) -> usize {
        self.models.len() + self.experiments.len() + 1
    }
}

/// The experiments run on each set, in report order (each name one of
/// [`experiments::NAMES`], tested): LuGre's phenomena on
/// the sets made to show them (with the elasto-plastic drift beside
/// LuGre's), then every experiment on the other models' primary sets.
const EXPERIMENTS: &[(&str, &[&str])] = &[
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

/// The parameter sets the accuracy table measures, each `(label, model,
/// bounded, plots)`, all read from the model list and the models' host
/// modules: every listed model's primary set (the models with state and
/// a continuous force first, then the switching ones, then the static
/// maps, each group in list order), judged unless
/// the model switches ([`HostModel::switching`]), plotted where the model
/// asks ([`HostModel::validation_plots`]), followed by its variants
/// ([`HostModel::validation_variants`]) and the other sets it reports
/// ([`HostModel::reported_sets`], measured without a bound or plots).
///
/// [`HostModel::switching`]: crate::models::HostModel::switching
/// [`HostModel::validation_plots`]: crate::models::HostModel::validation_plots
/// [`HostModel::validation_variants`]: crate::models::HostModel::validation_variants
/// [`HostModel::reported_sets`]: crate::models::HostModel::reported_sets
pub(crate) fn accuracy_models() -> Result<Vec<Measured>> {
    let mut primaries = Vec::new();
    for (_, sets) in MODEL_SETS {
        if let Some(&set) = sets.first() {
            primaries.push((set, param_set(set)?.model));
        }
    }
    // the continuous models, then the switching ones, then the static
    // maps; stable: the list's order within each group
    primaries.sort_by_key(|(_, spec)| (!spec.host().has_state(), spec.host().switching()));
    let mut models = Vec::new();
    for (set, spec) in primaries {
        let host = spec.host();
        if host.validates_itself() {
            models.push((
                set.to_string(),
                spec.clone(),
                !host.switching(),
                host.validation_plots(),
            ));
        }
        for v in host.validation_variants() {
            models.push((format!("{set}{}", v.suffix), v.spec, v.bounded, v.plots));
        }
        for &other in host.reported_sets() {
            models.push((other.to_string(), param_set(other)?.model, false, false));
        }
    }
    Ok(models)
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

#[cfg(test)]
mod tests {
    /// Every experiment the plan names is one of [`experiments::LIST`].
    ///
    /// [`experiments::LIST`]: crate::experiments::LIST
    #[test]
    fn the_plan_names_experiments() {
        for (set, names) in super::EXPERIMENTS {
            for name in *names {
                assert!(
                    crate::experiments::find(name).is_some(),
                    "{set}: no experiment `{name}`"
                );
            }
        }
    }
}
