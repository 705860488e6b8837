//! Observers: the core's `Observer` around a state model, stepped with the
//! measured velocity `v` and position error `e = x - x_ref`; the estimate
//! `F^` is what a compensator feeds forward.

use crate::any::{Fixed, FixedState, Variable, VariableState};
use crate::model::{friction_model_f32, friction_model_f64, init, same_period, Model};
use crate::slot::{self, opaque};
use crate::status::{friction_error, friction_status, Refusal};
use friction_core::{FixedStepModel, Observer, Scalar};

/// Words (8 bytes each) of a `float` observer object, room for the largest
/// value it holds (a compile-time check keeps it so).
pub const FRICTION_OBSERVER_F32_WORDS: usize = 40;
/// Words (8 bytes each) of a `double` observer object.
pub const FRICTION_OBSERVER_F64_WORDS: usize = 80;

/// An observer in `float` (caller-allocated; see [`friction_observer_init_f32`]).
#[repr(C)]
pub struct friction_observer_f32 {
    /// Private: written by the constructor, read by the other calls.
    pub opaque: [u64; FRICTION_OBSERVER_F32_WORDS],
}

/// An observer in `double` (caller-allocated; see [`friction_observer_init_f64`]).
#[repr(C)]
pub struct friction_observer_f64 {
    /// Private: written by the constructor, read by the other calls.
    pub opaque: [u64; FRICTION_OBSERVER_F64_WORDS],
}

opaque!(friction_observer_f32, Stored<f32>, 0xB3B3_B3B3);
opaque!(friction_observer_f64, Stored<f64>, 0xB4B4_B4B4);

/// An observer with the state of its model, as `build` makes it; stored
/// as a kind and a union ([`Stored`]).
#[derive(Clone, Copy, Debug)]
pub(crate) enum Estimator<S: Scalar> {
    Variable(Observer<Variable<S>, S>, VariableState<S>),
    Fixed(Observer<Fixed<S>, S>, FixedState<S>),
}

/// The kinds of observer, added to the object's tag (`slot::put_kind`);
/// from 1, so that an object holding its type's bare tag has kind 0.
mod kind {
    pub(super) const VARIABLE: u32 = 1;
    pub(super) const FIXED: u32 = 2;
}

/// An observer as an object stores it: the union field its kind names.
#[derive(Clone, Copy)]
#[repr(C)]
pub(crate) union Stored<S: Scalar> {
    variable: (Observer<Variable<S>, S>, VariableState<S>),
    fixed: (Observer<Fixed<S>, S>, FixedState<S>),
}

// SAFETY: a union of `Copy` types: every bit pattern is a value of it (its
// fields are read only for the kind that names them).
unsafe impl<S: Scalar> slot::Union for Stored<S> {}

impl<S: Scalar> slot::Built for Estimator<S> {
    type Stored = Stored<S>;

    fn stored(self) -> (u32, Stored<S>) {
        match self {
            Self::Variable(o, s) => (kind::VARIABLE, Stored { variable: (o, s) }),
            Self::Fixed(o, s) => (kind::FIXED, Stored { fixed: (o, s) }),
        }
    }
}

/// The observer of `model` (its parameters; the observer starts at rest).
fn build<S: Scalar>(model: &Model<S>, gain: f64, damping: bool) -> Result<Estimator<S>, Refusal> {
    let param = Refusal::param;
    match model {
        Model::Static(_) => Err(Refusal::new(
            friction_status::FRICTION_NOT_SUPPORTED,
            "model",
        )),
        Model::Variable(m, _) => Ok(Estimator::Variable(
            Observer::new(*m, gain)
                .map_err(param)?
                .with_damping(damping),
            VariableState::default(),
        )),
        Model::Fixed(m, _) => Ok(Estimator::Fixed(
            Observer::new(*m, gain)
                .map_err(param)?
                .with_damping(damping),
            FixedState::default(),
        )),
    }
}

/// Builds the observer of an initialised `model` into `out`.
fn new<O, M, S>(
    out: Option<&mut O>,
    model: Option<&M>,
    gain: f64,
    damping: bool,
    error: Option<&mut friction_error>,
) -> friction_status
where
    O: slot::Opaque<Value = Stored<S>>,
    M: slot::Opaque<Value = crate::model::Stored<S>>,
    S: Scalar,
{
    init(out, model, "model", error, |m| {
        let (kind, stored) = slot::get_kind_ref(m);
        match Model::load(kind, stored) {
            Some(m) => build(&m, gain, damping),
            None => Err(Refusal::new(
                friction_status::FRICTION_NOT_INITIALISED,
                "model",
            )),
        }
    })
}

fn step<O, S>(observer: Option<&mut O>, v: S, e: S, h: S, force: Option<&mut S>) -> friction_status
where
    O: slot::Opaque<Value = Stored<S>>,
    S: Scalar,
{
    let (Some(observer), Some(force)) = (observer, force) else {
        return friction_status::FRICTION_NULL_POINTER;
    };
    let (kind, observer) = slot::get_kind(observer);
    let accepted = v.is_finite() && e.is_finite() && h.is_finite() && h >= S::ZERO;
    let status = if accepted {
        friction_status::FRICTION_OK
    } else {
        friction_status::FRICTION_INPUT_REJECTED
    };
    // SAFETY (each arm): a kind is only written with the field it names
    // (`slot::put_kind` from `stored`; C may copy both), and C's bytes in
    // that field are read as it (any bytes are a value of
    // the core's stored forms: see slot.rs).
    match kind {
        kind::VARIABLE => {
            let (o, s) = unsafe { &mut observer.variable };
            *force = o.step(s, v, e, h);
        }
        kind::FIXED => {
            let (o, s) = unsafe { &mut observer.fixed };
            if accepted && !same_period(h.to_f64(), o.model().period()) {
                *force = o.model().hold_force(s);
                return friction_status::FRICTION_PERIOD_MISMATCH;
            }
            *force = o.step_fixed(s, v, e);
        }
        _ => return friction_status::FRICTION_NOT_INITIALISED,
    }
    status
}

fn reset<O, S>(observer: Option<&mut O>) -> friction_status
where
    O: slot::Opaque<Value = Stored<S>>,
    S: Scalar,
{
    let Some(observer) = observer else {
        return friction_status::FRICTION_NULL_POINTER;
    };
    let (kind, observer) = slot::get_kind(observer);
    // writing a union field's part reads nothing (safe code)
    match kind {
        kind::VARIABLE => observer.variable.1 = VariableState::default(),
        kind::FIXED => observer.fixed.1 = FixedState::default(),
        _ => return friction_status::FRICTION_NOT_INITIALISED,
    }
    friction_status::FRICTION_OK
}

/// The observer of `model`'s parameters in `float`, with correction gain
/// `gain >= 0` (1/s) and, if `damping`, the `sigma1 dz/dt` term in the
/// estimate. A static map has no state to observe: `FRICTION_NOT_SUPPORTED`.
/// The observer keeps its own copy of the model; it starts at rest.
#[no_mangle]
pub extern "C" fn friction_observer_init_f32(
    out: Option<&mut friction_observer_f32>,
    model: Option<&friction_model_f32>,
    gain: f64,
    damping: bool,
    error: Option<&mut friction_error>,
) -> friction_status {
    new(out, model, gain, damping, error)
}

/// [`friction_observer_init_f32`] in `double`.
#[no_mangle]
pub extern "C" fn friction_observer_init_f64(
    out: Option<&mut friction_observer_f64>,
    model: Option<&friction_model_f64>,
    gain: f64,
    damping: bool,
    error: Option<&mut friction_error>,
) -> friction_status {
    new(out, model, gain, damping, error)
}

/// Advances the observer by `h` (s) with measured velocity `v` and position
/// error `e = x - x_ref`; writes the friction estimate. Period and input
/// checks as in [`crate::model::friction_model_step_f32`].
#[no_mangle]
pub extern "C" fn friction_observer_step_f32(
    observer: Option<&mut friction_observer_f32>,
    v: f32,
    e: f32,
    h: f32,
    force: Option<&mut f32>,
) -> friction_status {
    step(observer, v, e, h, force)
}

/// [`friction_observer_step_f32`] in `double`.
#[no_mangle]
pub extern "C" fn friction_observer_step_f64(
    observer: Option<&mut friction_observer_f64>,
    v: f64,
    e: f64,
    h: f64,
    force: Option<&mut f64>,
) -> friction_status {
    step(observer, v, e, h, force)
}

/// Puts the observer's model state back at rest.
#[no_mangle]
pub extern "C" fn friction_observer_reset_f32(
    observer: Option<&mut friction_observer_f32>,
) -> friction_status {
    reset(observer)
}

/// [`friction_observer_reset_f32`] in `double`.
#[no_mangle]
pub extern "C" fn friction_observer_reset_f64(
    observer: Option<&mut friction_observer_f64>,
) -> friction_status {
    reset(observer)
}
