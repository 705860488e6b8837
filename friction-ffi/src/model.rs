//! Models: one C object per scalar type (`friction_model_f32`,
//! `friction_model_f64`) holding any core model and its state.
//!
//! A constructor per model validates the parameters (the core's `build`
//! or, for `h > 0`, `build_fixed_step(h)`: the fixed-step form) and, only on
//! success, overwrites the object; on failure the object is left as it
//! was. `friction_model_step_*` advances the state by `h` with `v` held.

use crate::any::{Fixed, FixedState, StaticMap, Variable, VariableState};
use crate::params::*;
use crate::slot::{self, opaque};
use crate::status::{friction_error, friction_status, report, Refusal};
// the capacities the model list's core types are named with
#[allow(unused_imports)]
use crate::params::{
    FRICTION_BRISTLES as BRISTLES, FRICTION_ELEMENTS as ELEMENTS, FRICTION_LEUVEN_MEMORY as MEMORY,
};
use friction_core::{
    AsymmetricCoulombViscousParams, BristleParams, CoulombViscousParams, DahlParams,
    ElastoPlasticParams, FixedStepModel, FrictionModel, GmsParams, LeuvenParams, LuGreParams,
    ParamError, ResetIntegratorParams, Scalar, StribeckMapParams, XiongParams,
};

/// Words (8 bytes each) of a `float` model object, room for the largest
/// value it holds (a compile-time check keeps it so).
pub const FRICTION_MODEL_F32_WORDS: usize = 40;
/// Words (8 bytes each) of a `double` model object.
pub const FRICTION_MODEL_F64_WORDS: usize = 80;

/// A model in `float` (caller-allocated; initialise with a constructor
/// such as [`friction_lugre_init_f32`]).
#[repr(C)]
pub struct friction_model_f32 {
    /// Private: written by the constructor, read by the other calls.
    pub opaque: [u64; FRICTION_MODEL_F32_WORDS],
}

/// A model in `double` (caller-allocated; initialise with a constructor
/// such as [`friction_lugre_init_f64`]).
#[repr(C)]
pub struct friction_model_f64 {
    /// Private: written by the constructor, read by the other calls.
    pub opaque: [u64; FRICTION_MODEL_F64_WORDS],
}

opaque!(friction_model_f32, Stored<f32>, 0xB1B1_B1B1);
opaque!(friction_model_f64, Stored<f64>, 0xB2B2_B2B2);

/// Any core model with its state, as the constructors build it and the
/// observer and servo constructors read it; stored as a kind and a union
/// ([`Stored`]).
#[derive(Clone, Copy, Debug)]
pub(crate) enum Model<S: Scalar> {
    /// A static map (no state).
    Static(StaticMap<S>),
    /// A variable-step state model.
    Variable(Variable<S>, VariableState<S>),
    /// A fixed-step state model.
    Fixed(Fixed<S>, FixedState<S>),
}

/// The kinds of model, added to the object's tag (`slot::put_kind`); from 1,
/// so that an object holding its type's bare tag has kind 0, which no
/// constructor writes.
mod kind {
    pub(super) const STATIC: u32 = 1;
    pub(super) const VARIABLE: u32 = 2;
    pub(super) const FIXED: u32 = 3;
}

/// A model as an object stores it: the union field its kind names.
#[derive(Clone, Copy)]
#[repr(C)]
pub(crate) union Stored<S: Scalar> {
    static_map: StaticMap<S>,
    variable: (Variable<S>, VariableState<S>),
    fixed: (Fixed<S>, FixedState<S>),
}

// SAFETY: a union of `Copy` types: every bit pattern is a value of it (its
// fields are read only for the kind that names them).
unsafe impl<S: Scalar> slot::Union for Stored<S> {}

impl<S: Scalar> slot::Built for Model<S> {
    type Stored = Stored<S>;

    fn stored(self) -> (u32, Stored<S>) {
        match self {
            Self::Static(m) => (kind::STATIC, Stored { static_map: m }),
            Self::Variable(m, s) => (kind::VARIABLE, Stored { variable: (m, s) }),
            Self::Fixed(m, s) => (kind::FIXED, Stored { fixed: (m, s) }),
        }
    }
}

impl<S: Scalar> Model<S> {
    /// The model in an object of kind `kind` (a copy), if the kind and
    /// the model kind inside are ones a constructor writes.
    pub(crate) fn load(kind: u32, stored: &Stored<S>) -> Option<Self> {
        // SAFETY (each arm): a kind is only written with the field it names
        // (`slot::put_kind` from `stored`; C may copy both), and C's bytes
        // in that field are read as it (any bytes are a value of
        // the core's stored forms: see slot.rs).
        let (model, valid) = match kind {
            kind::STATIC => {
                let m = unsafe { stored.static_map };
                (Self::Static(m), m.is_valid())
            }
            kind::VARIABLE => {
                let (m, s) = unsafe { stored.variable };
                (Self::Variable(m, s), m.is_valid())
            }
            kind::FIXED => {
                let (m, s) = unsafe { stored.fixed };
                (Self::Fixed(m, s), m.is_valid())
            }
            _ => return None,
        };
        valid.then_some(model)
    }
}

/// Whether a step's period `h` is the fixed-step model's own (to 1e-6).
pub(crate) fn same_period(h: f64, period: f64) -> bool {
    (h - period).abs() <= 1e-6 * period
}

impl<S: Scalar> Model<S> {
    fn variable(model: Variable<S>) -> Self {
        Self::Variable(model, VariableState::default())
    }

    fn fixed(model: Fixed<S>) -> Self {
        Self::Fixed(model, FixedState::default())
    }
}

/// Steps the model of kind `kind` by `h` with `v` held: the force and the
/// status (the state as it was, and the force it holds, when refused);
/// `None` for a kind no constructor writes.
fn step_stored<S: Scalar>(
    kind: u32,
    model: &mut Stored<S>,
    v: S,
    h: S,
) -> Option<(S, friction_status)> {
    let accepted = v.is_finite() && h.is_finite() && h >= S::ZERO;
    let status = if accepted {
        friction_status::FRICTION_OK
    } else {
        friction_status::FRICTION_INPUT_REJECTED
    };
    // SAFETY (each arm): as in `Model::load`.
    Some(match kind {
        kind::STATIC => {
            let m = unsafe { &model.static_map };
            (m.step(&mut (), v, h), status)
        }
        kind::VARIABLE => {
            let (m, s) = unsafe { &mut model.variable };
            (m.step(s, v, h), status)
        }
        kind::FIXED => {
            let (m, s) = unsafe { &mut model.fixed };
            if accepted && !same_period(h.to_f64(), m.period()) {
                (m.hold_force(s), friction_status::FRICTION_PERIOD_MISMATCH)
            } else {
                (m.step(s, v), status)
            }
        }
        _ => return None,
    })
}

/// Puts the model of kind `kind` at rest; `false` for a kind no
/// constructor writes.
fn reset_stored<S: Scalar>(kind: u32, model: &mut Stored<S>) -> bool {
    // writing a union field's part reads nothing (safe code)
    match kind {
        kind::STATIC => {}
        kind::VARIABLE => model.variable.1 = VariableState::default(),
        kind::FIXED => model.fixed.1 = FixedState::default(),
        _ => return false,
    }
    true
}

/// Builds `O::Value` from `params` into `out`; writes nothing on failure.
/// A NULL `params` is named `params_name`.
pub(crate) fn init<O: slot::Opaque, P, B: slot::Built<Stored = O::Value>>(
    out: Option<&mut O>,
    params: Option<&P>,
    params_name: &'static str,
    error: Option<&mut friction_error>,
    build: impl FnOnce(&P) -> Result<B, Refusal>,
) -> friction_status {
    let (Some(out), Some(params)) = (out, params) else {
        let which = if params.is_none() { params_name } else { "out" };
        return report(
            error,
            Refusal::new(friction_status::FRICTION_NULL_POINTER, which),
        );
    };
    match build(params) {
        Ok(value) => {
            let (kind, stored) = value.stored();
            slot::put_kind(out, kind, stored);
            report(error, Refusal::OK)
        }
        Err(e) => report(error, e),
    }
}

fn param(e: ParamError) -> Refusal {
    Refusal::param(e)
}

/// The variable-step form for `h == 0`, else the fixed-step form for `h`.
fn at<S: Scalar>(
    h: f64,
    variable: impl FnOnce() -> Result<Variable<S>, ParamError>,
    fixed: impl FnOnce(f64) -> Result<Fixed<S>, ParamError>,
) -> Result<Model<S>, Refusal> {
    if h == 0.0 {
        variable().map(Model::variable).map_err(param)
    } else {
        fixed(h).map(Model::fixed).map_err(param)
    }
}

/// A core parameter type of the model list, built into the form the C ABI
/// stores (`builders!` implements it from the list).
trait Build {
    /// The model: a static map, or a state model's variable-step form for
    /// `h == 0` and its fixed-step form for period `h > 0` where it has one
    /// (the constructors of the others take no `h` and pass 0).
    fn model<S: Scalar>(&self, h: f64) -> Result<Model<S>, Refusal>;
}

/// The C ABI's builders from the core's model list
/// (`friction_core::model_list!`): `Build` for each model the ABI builds.
macro_rules! builders {
    ($(
        $(#[$doc:meta])* $variant:ident = $name:literal {
            params: $params:ty,
            field: $field:ident,
            $(map: $map:ty,)?
            $(variable: $variable:ty,)?
            $(fixed: $fixed:ty,)?
            sets: [$($set:literal),* $(,)?],
        }
    )*) => {
        $(build!($params, $field $(, map $map)? $(, variable $variable)? $(, fixed $fixed)?);)*
    };
}

/// `Build` for one model, by the forms it has.
macro_rules! build {
    // no form in the C ABI
    ($params:ty, $field:ident) => {};
    ($params:ty, $field:ident, map $map:ty) => {
        impl Build for $params {
            fn model<S: Scalar>(&self, _h: f64) -> Result<Model<S>, Refusal> {
                let model = self.build().map_err(param)?;
                Ok(Model::Static(StaticMap::$field(model)))
            }
        }
    };
    ($params:ty, $field:ident, variable $variable:ty) => {
        impl Build for $params {
            fn model<S: Scalar>(&self, _h: f64) -> Result<Model<S>, Refusal> {
                let model = self.build().map_err(param)?;
                Ok(Model::variable(Variable::$field(model)))
            }
        }
    };
    ($params:ty, $field:ident, variable $variable:ty, fixed $fixed:ty) => {
        impl Build for $params {
            fn model<S: Scalar>(&self, h: f64) -> Result<Model<S>, Refusal> {
                at(
                    h,
                    || self.build().map(Variable::$field),
                    |h| self.build_fixed_step(h).map(Fixed::$field),
                )
            }
        }
    };
}

friction_core::model_list!(builders);

fn step<O, S>(model: Option<&mut O>, v: S, h: S, force: Option<&mut S>) -> friction_status
where
    O: slot::Opaque<Value = Stored<S>>,
    S: Scalar,
{
    let (Some(model), Some(force)) = (model, force) else {
        return friction_status::FRICTION_NULL_POINTER;
    };
    let (kind, model) = slot::get_kind(model);
    let Some((f, status)) = step_stored(kind, model, v, h) else {
        return friction_status::FRICTION_NOT_INITIALISED;
    };
    *force = f;
    status
}

fn reset<O, S>(model: Option<&mut O>) -> friction_status
where
    O: slot::Opaque<Value = Stored<S>>,
    S: Scalar,
{
    let Some(model) = model else {
        return friction_status::FRICTION_NULL_POINTER;
    };
    let (kind, model) = slot::get_kind(model);
    if reset_stored(kind, model) {
        friction_status::FRICTION_OK
    } else {
        friction_status::FRICTION_NOT_INITIALISED
    }
}

// The C entry points: one per model and scalar type, each a line over the
// generic builders above (cbindgen reads them as written, so no macro).

/// Coulomb plus viscous friction in `float`.
#[no_mangle]
pub extern "C" fn friction_coulomb_viscous_init_f32(
    out: Option<&mut friction_model_f32>,
    params: Option<&friction_coulomb_viscous_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| {
        CoulombViscousParams::from(p).model(0.0)
    })
}

/// Coulomb plus viscous friction in `double`.
#[no_mangle]
pub extern "C" fn friction_coulomb_viscous_init_f64(
    out: Option<&mut friction_model_f64>,
    params: Option<&friction_coulomb_viscous_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| {
        CoulombViscousParams::from(p).model(0.0)
    })
}

/// Coulomb plus viscous friction with a level and slope for each
/// direction in `float`.
#[no_mangle]
pub extern "C" fn friction_asymmetric_coulomb_viscous_init_f32(
    out: Option<&mut friction_model_f32>,
    params: Option<&friction_asymmetric_coulomb_viscous_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| {
        AsymmetricCoulombViscousParams::from(p).model(0.0)
    })
}

/// Coulomb plus viscous friction with a level and slope for each
/// direction in `double`.
#[no_mangle]
pub extern "C" fn friction_asymmetric_coulomb_viscous_init_f64(
    out: Option<&mut friction_model_f64>,
    params: Option<&friction_asymmetric_coulomb_viscous_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| {
        AsymmetricCoulombViscousParams::from(p).model(0.0)
    })
}

/// The static Stribeck map in `float`.
#[no_mangle]
pub extern "C" fn friction_stribeck_map_init_f32(
    out: Option<&mut friction_model_f32>,
    params: Option<&friction_stribeck_map_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| {
        StribeckMapParams::from(p).model(0.0)
    })
}

/// The static Stribeck map in `double`.
#[no_mangle]
pub extern "C" fn friction_stribeck_map_init_f64(
    out: Option<&mut friction_model_f64>,
    params: Option<&friction_stribeck_map_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| {
        StribeckMapParams::from(p).model(0.0)
    })
}

/// The bristle model in `float` (re-bonds at most 2 per bristle a step,
/// the core's firmware default).
#[no_mangle]
pub extern "C" fn friction_bristle_init_f32(
    out: Option<&mut friction_model_f32>,
    params: Option<&friction_bristle_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| {
        BristleParams::from(p).model(0.0)
    })
}

/// The bristle model in `double` (re-bonds at most 2 per bristle a step).
#[no_mangle]
pub extern "C" fn friction_bristle_init_f64(
    out: Option<&mut friction_model_f64>,
    params: Option<&friction_bristle_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| {
        BristleParams::from(p).model(0.0)
    })
}

/// The reset integrator in `float`.
#[no_mangle]
pub extern "C" fn friction_reset_integrator_init_f32(
    out: Option<&mut friction_model_f32>,
    params: Option<&friction_reset_integrator_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| {
        ResetIntegratorParams::from(p).model(0.0)
    })
}

/// The reset integrator in `double`.
#[no_mangle]
pub extern "C" fn friction_reset_integrator_init_f64(
    out: Option<&mut friction_model_f64>,
    params: Option<&friction_reset_integrator_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| {
        ResetIntegratorParams::from(p).model(0.0)
    })
}

/// The Dahl model in `float`: `h == 0` the variable-step form, `h > 0` the
/// fixed-step form for period `h` (s).
#[no_mangle]
pub extern "C" fn friction_dahl_init_f32(
    out: Option<&mut friction_model_f32>,
    params: Option<&friction_dahl_params>,
    h: f64,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| {
        DahlParams::from(p).model(h)
    })
}

/// The Dahl model in `double` (`h` as in [`friction_dahl_init_f32`]).
#[no_mangle]
pub extern "C" fn friction_dahl_init_f64(
    out: Option<&mut friction_model_f64>,
    params: Option<&friction_dahl_params>,
    h: f64,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| {
        DahlParams::from(p).model(h)
    })
}

/// The LuGre model in `float`: `h == 0` the variable-step form, `h > 0` the
/// fixed-step form for period `h` (s), the firmware's choice.
#[no_mangle]
pub extern "C" fn friction_lugre_init_f32(
    out: Option<&mut friction_model_f32>,
    params: Option<&friction_lugre_params>,
    h: f64,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| {
        LuGreParams::from(p).model(h)
    })
}

/// The LuGre model in `double` (`h` as in [`friction_lugre_init_f32`]).
#[no_mangle]
pub extern "C" fn friction_lugre_init_f64(
    out: Option<&mut friction_model_f64>,
    params: Option<&friction_lugre_params>,
    h: f64,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| {
        LuGreParams::from(p).model(h)
    })
}

/// The elasto-plastic model in `float` (`h` as in [`friction_lugre_init_f32`]).
#[no_mangle]
pub extern "C" fn friction_elasto_plastic_init_f32(
    out: Option<&mut friction_model_f32>,
    params: Option<&friction_elasto_plastic_params>,
    h: f64,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| {
        ElastoPlasticParams::from(p).model(h)
    })
}

/// The elasto-plastic model in `double` (`h` as in [`friction_lugre_init_f32`]).
#[no_mangle]
pub extern "C" fn friction_elasto_plastic_init_f64(
    out: Option<&mut friction_model_f64>,
    params: Option<&friction_elasto_plastic_params>,
    h: f64,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| {
        ElastoPlasticParams::from(p).model(h)
    })
}

/// The Leuven model in `float`.
#[no_mangle]
pub extern "C" fn friction_leuven_init_f32(
    out: Option<&mut friction_model_f32>,
    params: Option<&friction_leuven_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| {
        LeuvenParams::from(p).model(0.0)
    })
}

/// The Leuven model in `double`.
#[no_mangle]
pub extern "C" fn friction_leuven_init_f64(
    out: Option<&mut friction_model_f64>,
    params: Option<&friction_leuven_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| {
        LeuvenParams::from(p).model(0.0)
    })
}

/// The GMS model in `float` (`h` as in [`friction_lugre_init_f32`]).
#[no_mangle]
pub extern "C" fn friction_gms_init_f32(
    out: Option<&mut friction_model_f32>,
    params: Option<&friction_gms_params>,
    h: f64,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| {
        GmsParams::from(p).model(h)
    })
}

/// The GMS model in `double` (`h` as in [`friction_lugre_init_f32`]).
#[no_mangle]
pub extern "C" fn friction_gms_init_f64(
    out: Option<&mut friction_model_f64>,
    params: Option<&friction_gms_params>,
    h: f64,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| {
        GmsParams::from(p).model(h)
    })
}

/// The Xiong model in `float` (`h` as in [`friction_lugre_init_f32`]).
#[no_mangle]
pub extern "C" fn friction_xiong_init_f32(
    out: Option<&mut friction_model_f32>,
    params: Option<&friction_xiong_params>,
    h: f64,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| {
        XiongParams::from(p).model(h)
    })
}

/// The Xiong model in `double` (`h` as in [`friction_lugre_init_f32`]).
#[no_mangle]
pub extern "C" fn friction_xiong_init_f64(
    out: Option<&mut friction_model_f64>,
    params: Option<&friction_xiong_params>,
    h: f64,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| {
        XiongParams::from(p).model(h)
    })
}

/// Advances `model` by `h` (s) with velocity `v` held and writes the force.
/// A fixed-step model needs `h` equal to its period (to 1e-6, else
/// `FRICTION_PERIOD_MISMATCH` and no step). A NaN or infinite `v` or `h`,
/// or `h < 0`: `FRICTION_INPUT_REJECTED`, state unchanged, the force the
/// state holds.
#[no_mangle]
pub extern "C" fn friction_model_step_f32(
    model: Option<&mut friction_model_f32>,
    v: f32,
    h: f32,
    force: Option<&mut f32>,
) -> friction_status {
    step(model, v, h, force)
}

/// [`friction_model_step_f32`] in `double`.
#[no_mangle]
pub extern "C" fn friction_model_step_f64(
    model: Option<&mut friction_model_f64>,
    v: f64,
    h: f64,
    force: Option<&mut f64>,
) -> friction_status {
    step(model, v, h, force)
}

/// Puts `model` back at rest (unstrained), keeping its parameters.
#[no_mangle]
pub extern "C" fn friction_model_reset_f32(
    model: Option<&mut friction_model_f32>,
) -> friction_status {
    reset(model)
}

/// [`friction_model_reset_f32`] in `double`.
#[no_mangle]
pub extern "C" fn friction_model_reset_f64(
    model: Option<&mut friction_model_f64>,
) -> friction_status {
    reset(model)
}
