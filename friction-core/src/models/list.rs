//! The one list of the library's models, which every crate of the
//! workspace derives its model wiring from.
//!
//! Why a macro: the host's `ModelSpec` enum, its parser dispatch and name
//! list, and the C ABI's unions and dispatch `match`es each need every model
//! at once, as items and arms; a trait can describe one model but cannot
//! enumerate them. So the list is written once here, and each crate hands
//! [`model_list!`](crate::model_list) a macro of its own that turns the list into its wiring
//! (`friction-host/src/models/mod.rs`, `friction-ffi/src/any.rs`).
//!
//! Each entry, in the order the host lists models (`MODEL_NAMES`):
//!
//! - `Variant = "name"`: the host's `ModelSpec` variant and the
//!   `model = "..."` name of parameter files (the only place it is written);
//! - `params`: the core's parameter type (each listed once);
//! - `field`: the model's snake-case name, the C ABI's union field and
//!   the stem of its `friction_<field>_init_f32/_f64` constructors;
//! - the forms the C ABI builds, each with its core type: `map` (a static
//!   map, no state), `variable` (a variable-step state model), `fixed` (its
//!   fixed-step form, which the host also runs in Q16.16 fixed point). `S`
//!   is the scalar; `BRISTLES`, `ELEMENTS` and `MEMORY` are the capacities,
//!   which the crate using the list chooses (the C ABI's are fixed);
//! - `sets`: the parameter files shipped in `params/` for it (without
//!   `.toml`), its primary set first (the one `friction validate` bounds).
//!
//! A model without a form the C ABI builds lists none (`coulomb` is
//! `coulomb-viscous` with `sigma2 = 0` there); a static map without a set
//! of its own is validated as a variant of another model's set (LuGre's
//! static maps on its curve).

/// Calls `$callback! { ... }` with the list of models (see the module
/// docs for the entries' keys). For the workspace's crates: the shape of
/// the list may change in any release.
#[doc(hidden)]
#[macro_export]
macro_rules! model_list {
    ($callback:ident) => {
        $callback! {
            /// `coulomb`: `fc`.
            Coulomb = "coulomb" {
                params: $crate::CoulombParams,
                field: coulomb,
                sets: [],
            }
            /// `coulomb-viscous`: `fc`, `sigma2`.
            CoulombViscous = "coulomb-viscous" {
                params: $crate::CoulombViscousParams,
                field: coulomb_viscous,
                map: $crate::CoulombViscous<S>,
                sets: [],
            }
            /// `stribeck`: `fc`, `fs`, `vs`, `stribeck_exponent`, `sigma2`.
            Stribeck = "stribeck" {
                params: $crate::StribeckMapParams,
                field: stribeck_map,
                map: $crate::StribeckMap<S>,
                sets: [],
            }
            /// `lugre`: `fc`, `fs`, `vs`, `stribeck_exponent`, `sigma0`, `sigma1`, `sigma2`, `vd`.
            LuGre = "lugre" {
                params: $crate::LuGreParams,
                field: lugre,
                variable: $crate::LuGre<S>,
                fixed: $crate::LuGreFixedStep<S>,
                sets: ["canudas1995", "astrom2008-drift", "astrom2008-stickslip", "olsson1998-servo"],
            }
            /// `dahl`: `sigma`, `fc`, `delta`, `sigma2`.
            Dahl = "dahl" {
                params: $crate::DahlParams,
                field: dahl,
                variable: $crate::Dahl<S>,
                fixed: $crate::DahlFixedStep<S>,
                sets: ["dahl1968"],
            }
            /// `elasto-plastic`: the LuGre keys and `z_ba`.
            ElastoPlastic = "elasto-plastic" {
                params: $crate::ElastoPlasticParams,
                field: elasto_plastic,
                variable: $crate::ElastoPlastic<S>,
                fixed: $crate::ElastoPlasticFixedStep<S>,
                sets: ["canudas1995-ep", "astrom2008-drift-ep"],
            }
            /// `reset-integrator`: `sigma0`, `sigma1`, `z0`, `stiction`, optional Stribeck keys.
            ResetIntegrator = "reset-integrator" {
                params: $crate::ResetIntegratorParams,
                field: reset_integrator,
                variable: $crate::ResetIntegrator<S>,
                sets: ["haessig1991-reset"],
            }
            /// `bristle`: `sigma0`, `delta_s`, `bristles` (1 to 64), `seed`.
            Bristle = "bristle" {
                params: $crate::BristleParams,
                field: bristle,
                variable: $crate::Bristle<S, BRISTLES>,
                sets: ["haessig1991-bristle"],
            }
            /// `gms`: Stribeck keys, `sigma2`, `c`, `[[elements]]` with `k`, `alpha`, `sigma1` (1 to 16).
            Gms = "gms" {
                params: $crate::GmsParams<ELEMENTS>,
                field: gms,
                variable: $crate::Gms<S, ELEMENTS>,
                fixed: $crate::GmsFixedStep<S, ELEMENTS>,
                sets: ["gms-typical"],
            }
            /// `xiong`: Stribeck keys, `tau`, `sigma2`, `[[elements]]` with `k`, `sigma`, `lambda` (1 to 16).
            Xiong = "xiong" {
                params: $crate::XiongParams<ELEMENTS>,
                field: xiong,
                variable: $crate::Xiong<S, ELEMENTS>,
                fixed: $crate::XiongFixedStep<S, ELEMENTS>,
                sets: ["xiong-typical"],
            }
            /// `leuven`: Stribeck keys, `sigma1`, `sigma2`, `n`, `xs`, `memory` (1 to 32, default 16).
            Leuven = "leuven" {
                params: $crate::LeuvenParams,
                field: leuven,
                variable: $crate::Leuven<S, MEMORY>,
                sets: ["leuven-typical"],
            }
            /// `asymmetric-coulomb-viscous`: `fc_pos`, `sigma2_pos`, `fc_neg`, `sigma2_neg`.
            AsymmetricCoulombViscous = "asymmetric-coulomb-viscous" {
                params: $crate::AsymmetricCoulombViscousParams,
                field: asymmetric_coulomb_viscous,
                map: $crate::AsymmetricCoulombViscous<S>,
                sets: ["robot-joint-asymmetric"],
            }
        }
    };
}
