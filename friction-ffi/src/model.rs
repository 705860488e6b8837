//! Models: one C object per scalar type (`friction_model_f32`,
//! `friction_model_f64`) holding any core model and its state.
//!
//! A constructor per model validates the parameters (the core's `build`
//! or, for `h > 0`, `build_at(h)`: the fixed-step form) and, only on
//! success, overwrites the object; on failure the object is left as it
//! was. `friction_model_step_*` advances the state by `h` with `v` held.

use crate::any::{Fixed, FixedState, StaticMap, Variable, VariableState};
use crate::params::*;
use crate::slot::{self, opaque};
use crate::status::{friction_error, friction_status, report, Refusal};
use friction_core::{
    BristleParams, CoulombViscousParams, DahlParams, ElastoPlasticParams, FixedStepModel,
    FrictionModel, GmsParams, LeuvenParams, LuGreParams, ParamError, ResetIntegratorParams, Scalar,
    StribeckMapParams, XiongParams,
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

opaque!(friction_model_f32, Model<f32>, 0xB1B1_B1B1);
opaque!(friction_model_f64, Model<f64>, 0xB2B2_B2B2);

/// Any core model with its state. `repr(u32)`: C's bytes are checked
/// before they are viewed as one (`slot::Checked`).
#[derive(Clone, Copy, Debug)]
#[repr(u32)]
pub(crate) enum Model<S: Scalar> {
    /// A static map (no state).
    Static(StaticMap<S>),
    /// A variable-step state model.
    Variable(Variable<S>, VariableState<S>),
    /// A fixed-step state model.
    Fixed(Fixed<S>, FixedState<S>),
}

impl<S: Scalar> slot::Checked for Model<S> {
    const VARIANTS: u32 = 3;

    #[inline]
    fn is_valid(&self) -> bool {
        match self {
            Self::Static(m) => m.is_valid(),
            Self::Variable(m, _) => m.is_valid(),
            Self::Fixed(m, _) => m.is_valid(),
        }
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

    /// Steps by `h` with `v` held; `Err` leaves the state as it was and
    /// carries the force it holds.
    fn step(&mut self, v: S, h: S) -> (S, friction_status) {
        let accepted = v.is_finite() && h.is_finite() && h >= S::ZERO;
        let status = if accepted {
            friction_status::FRICTION_OK
        } else {
            friction_status::FRICTION_INPUT_REJECTED
        };
        match self {
            Self::Static(m) => (m.step(&mut (), v, h), status),
            Self::Variable(m, s) => (m.step(s, v, h), status),
            Self::Fixed(m, s) => {
                if accepted && !same_period(h.to_f64(), m.period()) {
                    (m.hold_force(s), friction_status::FRICTION_PERIOD_MISMATCH)
                } else {
                    (m.step(s, v), status)
                }
            }
        }
    }

    fn reset(&mut self) {
        match self {
            Self::Static(_) => {}
            Self::Variable(_, s) => *s = VariableState::default(),
            Self::Fixed(_, s) => *s = FixedState::default(),
        }
    }
}

/// Builds `O::Value` from `params` into `out`; writes nothing on failure.
/// A NULL `params` is named `params_name`.
pub(crate) fn init<O: slot::Opaque, P>(
    out: Option<&mut O>,
    params: Option<&P>,
    params_name: &'static str,
    error: Option<&mut friction_error>,
    build: impl FnOnce(&P) -> Result<O::Value, Refusal>,
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
            slot::put(out, value);
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

fn coulomb_viscous<S: Scalar>(p: &friction_coulomb_viscous_params) -> Result<Model<S>, Refusal> {
    let model = CoulombViscousParams::from(p).build().map_err(param)?;
    Ok(Model::Static(StaticMap::coulomb_viscous(model)))
}

fn stribeck_map<S: Scalar>(p: &friction_stribeck_map_params) -> Result<Model<S>, Refusal> {
    let model = StribeckMapParams::from(p).build().map_err(param)?;
    Ok(Model::Static(StaticMap::stribeck_map(model)))
}

fn bristle<S: Scalar>(p: &friction_bristle_params) -> Result<Model<S>, Refusal> {
    let model = BristleParams::from(p).build().map_err(param)?;
    Ok(Model::variable(Variable::bristle(model)))
}

fn reset_integrator<S: Scalar>(p: &friction_reset_integrator_params) -> Result<Model<S>, Refusal> {
    let model = ResetIntegratorParams::from(p).build().map_err(param)?;
    Ok(Model::variable(Variable::reset_integrator(model)))
}

fn dahl<S: Scalar>(p: &friction_dahl_params, h: f64) -> Result<Model<S>, Refusal> {
    let p = DahlParams::from(p);
    at(
        h,
        || p.build().map(Variable::dahl),
        |h| p.build_at(h).map(Fixed::dahl),
    )
}

fn lugre<S: Scalar>(p: &friction_lugre_params, h: f64) -> Result<Model<S>, Refusal> {
    let p = LuGreParams::from(p);
    at(
        h,
        || p.build().map(Variable::lugre),
        |h| p.build_at(h).map(Fixed::lugre),
    )
}

fn elasto_plastic<S: Scalar>(
    p: &friction_elasto_plastic_params,
    h: f64,
) -> Result<Model<S>, Refusal> {
    let p = ElastoPlasticParams::from(p);
    at(
        h,
        || p.build().map(Variable::elasto_plastic),
        |h| p.build_at(h).map(Fixed::elasto_plastic),
    )
}

fn leuven<S: Scalar>(p: &friction_leuven_params) -> Result<Model<S>, Refusal> {
    let model = LeuvenParams::from(p).build().map_err(param)?;
    Ok(Model::variable(Variable::leuven(model)))
}

fn gms<S: Scalar>(p: &friction_gms_params, h: f64) -> Result<Model<S>, Refusal> {
    let p = GmsParams::from(p);
    at(
        h,
        || p.build().map(Variable::gms),
        |h| p.build_at(h).map(Fixed::gms),
    )
}

fn xiong<S: Scalar>(p: &friction_xiong_params, h: f64) -> Result<Model<S>, Refusal> {
    let p = XiongParams::from(p);
    at(
        h,
        || p.build().map(Variable::xiong),
        |h| p.build_at(h).map(Fixed::xiong),
    )
}

fn step<O, S>(model: Option<&mut O>, v: S, h: S, force: Option<&mut S>) -> friction_status
where
    O: slot::Opaque<Value = Model<S>>,
    S: Scalar,
{
    let (Some(model), Some(force)) = (model, force) else {
        return friction_status::FRICTION_NULL_POINTER;
    };
    let Some(model) = slot::get(model) else {
        return friction_status::FRICTION_NOT_INITIALISED;
    };
    let (f, status) = model.step(v, h);
    *force = f;
    status
}

fn reset<O, S>(model: Option<&mut O>) -> friction_status
where
    O: slot::Opaque<Value = Model<S>>,
    S: Scalar,
{
    let Some(model) = model else {
        return friction_status::FRICTION_NULL_POINTER;
    };
    let Some(model) = slot::get(model) else {
        return friction_status::FRICTION_NOT_INITIALISED;
    };
    model.reset();
    friction_status::FRICTION_OK
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
    init(out, params, "params", error, coulomb_viscous)
}

/// Coulomb plus viscous friction in `double`.
#[no_mangle]
pub extern "C" fn friction_coulomb_viscous_init_f64(
    out: Option<&mut friction_model_f64>,
    params: Option<&friction_coulomb_viscous_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, coulomb_viscous)
}

/// The static Stribeck map in `float`.
#[no_mangle]
pub extern "C" fn friction_stribeck_map_init_f32(
    out: Option<&mut friction_model_f32>,
    params: Option<&friction_stribeck_map_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, stribeck_map)
}

/// The static Stribeck map in `double`.
#[no_mangle]
pub extern "C" fn friction_stribeck_map_init_f64(
    out: Option<&mut friction_model_f64>,
    params: Option<&friction_stribeck_map_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, stribeck_map)
}

/// The bristle model in `float` (re-bonds at most 2 per bristle a step,
/// the core's firmware default).
#[no_mangle]
pub extern "C" fn friction_bristle_init_f32(
    out: Option<&mut friction_model_f32>,
    params: Option<&friction_bristle_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, bristle)
}

/// The bristle model in `double` (re-bonds at most 2 per bristle a step).
#[no_mangle]
pub extern "C" fn friction_bristle_init_f64(
    out: Option<&mut friction_model_f64>,
    params: Option<&friction_bristle_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, bristle)
}

/// The reset integrator in `float`.
#[no_mangle]
pub extern "C" fn friction_reset_integrator_init_f32(
    out: Option<&mut friction_model_f32>,
    params: Option<&friction_reset_integrator_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, reset_integrator)
}

/// The reset integrator in `double`.
#[no_mangle]
pub extern "C" fn friction_reset_integrator_init_f64(
    out: Option<&mut friction_model_f64>,
    params: Option<&friction_reset_integrator_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, reset_integrator)
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
    init(out, params, "params", error, |p| dahl(p, h))
}

/// The Dahl model in `double` (`h` as in [`friction_dahl_init_f32`]).
#[no_mangle]
pub extern "C" fn friction_dahl_init_f64(
    out: Option<&mut friction_model_f64>,
    params: Option<&friction_dahl_params>,
    h: f64,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| dahl(p, h))
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
    init(out, params, "params", error, |p| lugre(p, h))
}

/// The LuGre model in `double` (`h` as in [`friction_lugre_init_f32`]).
#[no_mangle]
pub extern "C" fn friction_lugre_init_f64(
    out: Option<&mut friction_model_f64>,
    params: Option<&friction_lugre_params>,
    h: f64,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| lugre(p, h))
}

/// The elasto-plastic model in `float` (`h` as in [`friction_lugre_init_f32`]).
#[no_mangle]
pub extern "C" fn friction_elasto_plastic_init_f32(
    out: Option<&mut friction_model_f32>,
    params: Option<&friction_elasto_plastic_params>,
    h: f64,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| elasto_plastic(p, h))
}

/// The elasto-plastic model in `double` (`h` as in [`friction_lugre_init_f32`]).
#[no_mangle]
pub extern "C" fn friction_elasto_plastic_init_f64(
    out: Option<&mut friction_model_f64>,
    params: Option<&friction_elasto_plastic_params>,
    h: f64,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| elasto_plastic(p, h))
}

/// The Leuven model in `float`.
#[no_mangle]
pub extern "C" fn friction_leuven_init_f32(
    out: Option<&mut friction_model_f32>,
    params: Option<&friction_leuven_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, leuven)
}

/// The Leuven model in `double`.
#[no_mangle]
pub extern "C" fn friction_leuven_init_f64(
    out: Option<&mut friction_model_f64>,
    params: Option<&friction_leuven_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, leuven)
}

/// The GMS model in `float` (`h` as in [`friction_lugre_init_f32`]).
#[no_mangle]
pub extern "C" fn friction_gms_init_f32(
    out: Option<&mut friction_model_f32>,
    params: Option<&friction_gms_params>,
    h: f64,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| gms(p, h))
}

/// The GMS model in `double` (`h` as in [`friction_lugre_init_f32`]).
#[no_mangle]
pub extern "C" fn friction_gms_init_f64(
    out: Option<&mut friction_model_f64>,
    params: Option<&friction_gms_params>,
    h: f64,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| gms(p, h))
}

/// The Xiong model in `float` (`h` as in [`friction_lugre_init_f32`]).
#[no_mangle]
pub extern "C" fn friction_xiong_init_f32(
    out: Option<&mut friction_model_f32>,
    params: Option<&friction_xiong_params>,
    h: f64,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| xiong(p, h))
}

/// The Xiong model in `double` (`h` as in [`friction_lugre_init_f32`]).
#[no_mangle]
pub extern "C" fn friction_xiong_init_f64(
    out: Option<&mut friction_model_f64>,
    params: Option<&friction_xiong_params>,
    h: f64,
    error: Option<&mut friction_error>,
) -> friction_status {
    init(out, params, "params", error, |p| xiong(p, h))
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
