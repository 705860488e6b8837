//! What `friction validate` runs: the parameter sets of the accuracy
//! table, derived from the model list (`friction_core::model_list!`, read
//! by the host registry) and each model's host module, and the experiments.

use crate::experiments;
use crate::models::ModelSpec;
use crate::models::MODEL_SETS;
use crate::params::param_set;
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
            experiments: experiment_plan()?,
        })
    }

    /// The sections the progress line counts: every measured set, every
    /// experiment and the bristle convergence.
    pub fn sections(&self) -> usize {
        self.models.len() + self.experiments.len() + 1
    }
}

/// The experiments planned by hand, in report order (each name one of
/// [`experiments::NAMES`], tested): LuGre's phenomena on the sets made to
/// show them, with the elasto-plastic model beside LuGre (its drift on
/// LuGre's drift set, then every experiment on its primary set). Every
/// other model with state gets every experiment on its primary set,
/// from the model list ([`experiment_plan`]).
const BY_HAND: &[(&str, &[&str])] = &[
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
];

/// The experiments, each `(set, experiment)`, in report order: the rows
/// planned by hand ([`BY_HAND`]), then every experiment on the primary set
/// of each model with state ([`HostModel::has_state`]) in the model list's
/// order, except the models whose sets the hand rows already run.
///
/// [`HostModel::has_state`]: crate::models::HostModel::has_state
fn experiment_plan() -> Result<Vec<(&'static str, &'static str)>> {
    let mut rows: Vec<(&'static str, &'static str)> = BY_HAND
        .iter()
        .flat_map(|(set, names)| names.iter().map(move |name| (*set, *name)))
        .collect();
    for (_, sets) in MODEL_SETS {
        let Some(&primary) = sets.first() else {
            continue;
        };
        if BY_HAND.iter().any(|(set, _)| sets.contains(set)) {
            continue;
        }
        if param_set(primary)?.model.host().has_state() {
            rows.extend(experiments::NAMES.iter().map(|name| (primary, *name)));
        }
    }
    Ok(rows)
}

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
        for (set, name) in super::experiment_plan().unwrap() {
            assert!(
                crate::experiments::find(name).is_some(),
                "{set}: no experiment `{name}`"
            );
        }
    }

    /// Every model with state has every experiment run on one of its sets,
    /// the static maps none.
    #[test]
    fn every_model_with_state_is_run_on_its_sets() {
        let plan = super::experiment_plan().unwrap();
        for (model, sets) in crate::models::MODEL_SETS {
            let Some(&primary) = sets.first() else {
                continue;
            };
            let stateful = crate::params::param_set(primary)
                .unwrap()
                .model
                .host()
                .has_state();
            for name in crate::experiments::NAMES {
                let run = sets.iter().any(|set| plan.contains(&(*set, *name)));
                assert_eq!(run, stateful, "{model}: {primary} {name}");
            }
        }
    }
}
