//! The compensated servo tick: the core's `Compensator` (PID, acceleration
//! feed-forward, command limit) with no compensation, a static
//! feed-forward, an observer, the theta-adaptive observer, or the
//! per-parameter adaptive observer under its supervisor.

use crate::any::{Fixed, FixedState, StaticMap, Variable, VariableState};
use crate::model::{friction_model_f32, friction_model_f64, Model};
use crate::params::{
    friction_adaptive_params, friction_coulomb_viscous_params, friction_parameter_adaptive_params,
    friction_servo_params, friction_supervisor_params,
};
use crate::slot::{self, opaque, Built};
use crate::status::{friction_error, friction_status, report, Refusal};
use friction_core::{
    AdaptiveObserver, AdaptiveParams, AdaptiveState, Compensation, Compensator, CompensatorParams,
    CompensatorState, CoulombViscous, CoulombViscousParams, FeedForward, FixedPeriod, LuGreParams,
    NoCompensation, Observer, ParameterAdaptiveFixedStep, ParameterAdaptiveParams, Scalar,
    Setpoint, Supervised, SupervisorMode, SupervisorParams,
};

/// Words (8 bytes each) of a `float` servo object, room for the largest
/// value it holds (a compile-time check keeps it so).
pub const FRICTION_SERVO_F32_WORDS: usize = 92;
/// Words (8 bytes each) of a `double` servo object.
pub const FRICTION_SERVO_F64_WORDS: usize = 165;

/// A compensated servo axis in `float` (caller-allocated; see [`friction_servo_init_f32`]).
#[repr(C)]
pub struct friction_servo_f32 {
    /// Private: written by the constructor, read by the other calls.
    pub opaque: [u64; FRICTION_SERVO_F32_WORDS],
}

/// A compensated servo axis in `double` (caller-allocated; see [`friction_servo_init_f64`]).
#[repr(C)]
pub struct friction_servo_f64 {
    /// Private: written by the constructor, read by the other calls.
    pub opaque: [u64; FRICTION_SERVO_F64_WORDS],
}

opaque!(friction_servo_f32, Stored<f32>, 0xB5B5_B5B5);
opaque!(friction_servo_f64, Stored<f64>, 0xB6B6_B6B6);

/// The desired motion at a tick, in `float`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_setpoint_f32 {
    /// Position `x_ref`.
    pub x: f32,
    /// Velocity `v_ref`.
    pub v: f32,
    /// Acceleration `a_ref` (feed-forward `J a_ref / kc`).
    pub a: f32,
}

/// The desired motion at a tick, in `double`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_setpoint_f64 {
    /// Position `x_ref`.
    pub x: f64,
    /// Velocity `v_ref`.
    pub v: f64,
    /// Acceleration `a_ref`.
    pub a: f64,
}

/// What a tick produced, in `float`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_tick_f32 {
    /// The command, finite and within `±limit`.
    pub command: f32,
    /// The friction estimate or feed-forward (force units).
    pub friction: f32,
}

/// What a tick produced, in `double`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_tick_f64 {
    /// The command, finite and within `±limit`.
    pub command: f64,
    /// The friction estimate or feed-forward (force units).
    pub friction: f64,
}

type AdaptiveFixedStep<S> = FixedPeriod<AdaptiveObserver<Fixed<S>, S>>;

/// The per-parameter adaptive observer (fixed-step form) under its
/// supervisor, with a Coulomb + viscous fallback.
type ParameterLaw<S> = Supervised<ParameterAdaptiveFixedStep<S>, CoulombViscous<S>, S>;

/// [`ParameterLaw`] with the exact step (`exact_step` set): a type of its
/// own in the core, so a kind of its own here.
type ParameterLawExact<S> = Supervised<ParameterAdaptiveFixedStep<S, true>, CoulombViscous<S>, S>;

/// A compensator with its state, one variant per kind of compensation, as
/// `build` makes it; stored as a kind and a union ([`Stored`]).
#[derive(Clone, Copy, Debug)]
pub(crate) enum Servo<S: Scalar> {
    None(Compensator<S, NoCompensation>, CompensatorState<S, ()>),
    FeedForward(
        Compensator<S, FeedForward<StaticMap<S>>>,
        CompensatorState<S, ()>,
    ),
    Observer(
        Compensator<S, Observer<Variable<S>, S>>,
        CompensatorState<S, VariableState<S>>,
    ),
    ObserverFixedStep(
        Compensator<S, FixedPeriod<Observer<Fixed<S>, S>>>,
        CompensatorState<S, FixedState<S>>,
    ),
    Adaptive(
        Compensator<S, AdaptiveObserver<Variable<S>, S>>,
        CompensatorState<S, AdaptiveState<VariableState<S>, S>>,
    ),
    AdaptiveFixedStep(
        Compensator<S, AdaptiveFixedStep<S>>,
        CompensatorState<S, AdaptiveState<FixedState<S>, S>>,
    ),
    ParameterAdaptive(
        Compensator<S, ParameterLaw<S>>,
        CompensatorState<S, <ParameterLaw<S> as Compensation<S>>::State>,
    ),
    ParameterAdaptiveExact(
        Compensator<S, ParameterLawExact<S>>,
        CompensatorState<S, <ParameterLawExact<S> as Compensation<S>>::State>,
    ),
}

/// The kinds of compensation, added to the object's tag (`slot::put_kind`):
/// from 1, so that an object holding its type's bare tag (a `memset` with
/// the tag's byte) has kind 0, which no constructor writes.
mod kind {
    pub(super) const NONE: u32 = 1;
    pub(super) const FEED_FORWARD: u32 = 2;
    pub(super) const OBSERVER: u32 = 3;
    pub(super) const OBSERVER_AT: u32 = 4;
    pub(super) const ADAPTIVE: u32 = 5;
    pub(super) const ADAPTIVE_AT: u32 = 6;
    pub(super) const PARAMETER_ADAPTIVE: u32 = 7;
    pub(super) const PARAMETER_ADAPTIVE_EXACT: u32 = 8;
}

/// A servo as an object stores it: the union field its kind names. The
/// kind is in the object's tag word, so that one load and one compare
/// check the tag and pick the field (a tick through the C ABI is budgeted
/// at 1.10x the Rust tick on the Cortex-M4F; a tag and an enum's
/// discriminant checked apart cost it three instructions more).
#[derive(Clone, Copy)]
#[repr(C)]
pub(crate) union Stored<S: Scalar> {
    none: Axis<S, NoCompensation>,
    feed_forward: Axis<S, FeedForward<StaticMap<S>>>,
    observer: Axis<S, Observer<Variable<S>, S>>,
    observer_fixed: Axis<S, FixedPeriod<Observer<Fixed<S>, S>>>,
    adaptive: Axis<S, AdaptiveObserver<Variable<S>, S>>,
    adaptive_at: Axis<S, AdaptiveFixedStep<S>>,
    parameter_adaptive: Axis<S, ParameterLaw<S>>,
    parameter_exact: Axis<S, ParameterLawExact<S>>,
}

/// A compensator and its state.
type Axis<S, C> = (
    Compensator<S, C>,
    CompensatorState<S, <C as Compensation<S>>::State>,
);

// SAFETY: a union of `Copy` types: every bit pattern is a value of it (its
// fields are read only for the kind that names them, `each_servo`).
unsafe impl<S: Scalar> slot::Union for Stored<S> {}

impl<S: Scalar> slot::Built for Servo<S> {
    type Stored = Stored<S>;

    fn stored(self) -> (u32, Stored<S>) {
        match self {
            Self::None(c, s) => (kind::NONE, Stored { none: (c, s) }),
            Self::FeedForward(c, s) => (
                kind::FEED_FORWARD,
                Stored {
                    feed_forward: (c, s),
                },
            ),
            Self::Observer(c, s) => (kind::OBSERVER, Stored { observer: (c, s) }),
            Self::ObserverFixedStep(c, s) => (
                kind::OBSERVER_AT,
                Stored {
                    observer_fixed: (c, s),
                },
            ),
            Self::Adaptive(c, s) => (kind::ADAPTIVE, Stored { adaptive: (c, s) }),
            Self::AdaptiveFixedStep(c, s) => (
                kind::ADAPTIVE_AT,
                Stored {
                    adaptive_at: (c, s),
                },
            ),
            Self::ParameterAdaptive(c, s) => (
                kind::PARAMETER_ADAPTIVE,
                Stored {
                    parameter_adaptive: (c, s),
                },
            ),
            Self::ParameterAdaptiveExact(c, s) => (
                kind::PARAMETER_ADAPTIVE_EXACT,
                Stored {
                    parameter_exact: (c, s),
                },
            ),
        }
    }
}

/// `$body` with `$c` and `$s` bound to the compensator and state of the
/// union field `$kind` names; `$other` for a kind no constructor writes
/// (garbage, never a field read).
macro_rules! each_servo {
    ($kind:expr, $servo:expr, |$c:ident, $s:ident| $body:expr, $other:expr) => {
        each_servo!($kind, $servo, |$c, $s| $body, $other, exact: |$c, $s| $body)
    };
    // `$exact` for the exact-step kind (the tick: out of line)
    ($kind:expr, $servo:expr, |$c:ident, $s:ident| $body:expr, $other:expr,
     exact: |$ce:ident, $se:ident| $exact:expr) => {{
        let servo: &mut Stored<S> = $servo;
        // SAFETY (each arm): a kind is only written with the field it names
        // (`slot::put_kind` from `Servo::stored`; C may copy both), and C's
        // bytes in that field are read as it (any bytes are a value of
        // the core's stored forms: see slot.rs).
        match $kind {
            kind::NONE => {
                let ($c, $s) = unsafe { &mut servo.none };
                $body
            }
            kind::FEED_FORWARD => {
                let ($c, $s) = unsafe { &mut servo.feed_forward };
                $body
            }
            kind::OBSERVER => {
                let ($c, $s) = unsafe { &mut servo.observer };
                $body
            }
            kind::OBSERVER_AT => {
                let ($c, $s) = unsafe { &mut servo.observer_fixed };
                $body
            }
            kind::ADAPTIVE => {
                let ($c, $s) = unsafe { &mut servo.adaptive };
                $body
            }
            kind::ADAPTIVE_AT => {
                let ($c, $s) = unsafe { &mut servo.adaptive_at };
                $body
            }
            kind::PARAMETER_ADAPTIVE => {
                let ($c, $s) = unsafe { &mut servo.parameter_adaptive };
                $body
            }
            kind::PARAMETER_ADAPTIVE_EXACT => {
                let ($ce, $se) = unsafe { &mut servo.parameter_exact };
                $exact
            }
            _ => $other,
        }
    }};
}

fn build<S: Scalar>(
    p: &CompensatorParams,
    model: Option<&Model<S>>,
    gain: f64,
    adaptive: Option<&AdaptiveParams>,
) -> Result<Servo<S>, friction_core::ParamError> {
    let state = CompensatorState::default();
    Ok(match (model, adaptive) {
        (None, _) => Servo::None(p.build(NoCompensation)?, state),
        (Some(Model::Static(m)), _) => Servo::FeedForward(p.build(FeedForward(*m))?, state),
        (Some(Model::Variable(m, _)), None) => {
            Servo::Observer(p.build(Observer::new(*m, gain)?)?, Default::default())
        }
        (Some(Model::Fixed(m, _)), None) => Servo::ObserverFixedStep(
            p.build(FixedPeriod(Observer::new(*m, gain)?))?,
            Default::default(),
        ),
        (Some(Model::Variable(m, _)), Some(a)) => Servo::Adaptive(
            p.build(a.build(Observer::new(*m, gain)?, p.h)?)?,
            Default::default(),
        ),
        (Some(Model::Fixed(m, _)), Some(a)) => Servo::AdaptiveFixedStep(
            p.build(FixedPeriod(a.build(Observer::new(*m, gain)?, p.h)?))?,
            Default::default(),
        ),
    })
}

fn new<O, M, S>(
    out: Option<&mut O>,
    params: Option<&friction_servo_params>,
    model: Option<&M>,
    gain: f64,
    adaptive: Option<&friction_adaptive_params>,
    error: Option<&mut friction_error>,
) -> friction_status
where
    O: slot::Opaque<Value = Stored<S>>,
    M: slot::Opaque<Value = crate::model::Stored<S>>,
    S: Scalar,
{
    let (Some(out), Some(params)) = (out, params) else {
        let which = if params.is_none() { "params" } else { "out" };
        return report(
            error,
            Refusal::new(friction_status::FRICTION_NULL_POINTER, which),
        );
    };
    let model = match model.map(|m| {
        let (kind, stored) = slot::get_kind_ref(m);
        Model::load(kind, stored)
    }) {
        None => None,
        Some(Some(m)) => Some(m),
        Some(None) => {
            return report(
                error,
                Refusal::new(friction_status::FRICTION_NOT_INITIALISED, "model"),
            )
        }
    };
    if matches!(model, Some(Model::Static(_))) && adaptive.is_some() {
        return report(
            error,
            Refusal::new(friction_status::FRICTION_NOT_SUPPORTED, "adaptive"),
        );
    }
    let adaptive = adaptive.map(AdaptiveParams::from);
    match build(&params.into(), model.as_ref(), gain, adaptive.as_ref()) {
        Ok(servo) => {
            let (kind, stored) = servo.stored();
            slot::put_kind(out, kind, stored);
            report(error, Refusal::OK)
        }
        Err(e) => report(error, Refusal::param(e)),
    }
}

fn tick<O, S>(
    servo: Option<&mut O>,
    x: S,
    r: Setpoint<S>,
) -> Result<friction_core::CompensatorTick<S>, friction_status>
where
    O: slot::Opaque<Value = Stored<S>>,
    S: Scalar,
{
    let servo = servo.ok_or(friction_status::FRICTION_NULL_POINTER)?;
    let (kind, servo) = slot::get_kind(servo);
    each_servo!(
        kind,
        servo,
        |c, s| Ok(c.tick(s, x, r)),
        Err(friction_status::FRICTION_NOT_INITIALISED),
        exact: |c, s| Ok(exact_tick(c, s, x, r))
    )
}

/// The exact-step kind's tick, out of line: inlined beside the other
/// kinds', it made every kind's tick through the C ABI dearer on a
/// Cortex-M4F, past its budget (registers saved on entry; see the cost
/// guide).
#[inline(never)]
fn exact_tick<S: Scalar>(
    c: &Compensator<S, ParameterLawExact<S>>,
    s: &mut CompensatorState<S, <ParameterLawExact<S> as Compensation<S>>::State>,
    x: S,
    r: Setpoint<S>,
) -> friction_core::CompensatorTick<S> {
    c.tick(s, x, r)
}

fn reset<O, S>(servo: Option<&mut O>) -> friction_status
where
    O: slot::Opaque<Value = Stored<S>>,
    S: Scalar,
{
    let Some(servo) = servo else {
        return friction_status::FRICTION_NULL_POINTER;
    };
    let (kind, servo) = slot::get_kind(servo);
    each_servo!(
        kind,
        servo,
        |_c, s| {
            *s = CompensatorState::default();
            friction_status::FRICTION_OK
        },
        friction_status::FRICTION_NOT_INITIALISED
    )
}

fn velocity_observer<O, S>(
    servo: Option<&mut O>,
    bandwidth_hz: f64,
    error: Option<&mut friction_error>,
) -> friction_status
where
    O: slot::Opaque<Value = Stored<S>>,
    S: Scalar,
{
    let Some(servo) = servo else {
        return report(
            error,
            Refusal::new(friction_status::FRICTION_NULL_POINTER, "servo"),
        );
    };
    let (kind, servo) = slot::get_kind(servo);
    let refusal = each_servo!(
        kind,
        servo,
        |c, s| match c.with_velocity_observer(bandwidth_hz) {
            Ok(next) => {
                *c = next;
                *s = CompensatorState::default();
                Refusal::OK
            }
            Err(e) => Refusal::param(e),
        },
        Refusal::new(friction_status::FRICTION_NOT_INITIALISED, "servo")
    );
    report(error, refusal)
}

fn read_theta<O, S>(servo: Option<&mut O>, out: Option<&mut S>) -> friction_status
where
    O: slot::Opaque<Value = Stored<S>>,
    S: Scalar,
{
    let (Some(servo), Some(out)) = (servo, out) else {
        return friction_status::FRICTION_NULL_POINTER;
    };
    let (kind, servo) = slot::get_kind(servo);
    // SAFETY: as in `each_servo`.
    let theta = match kind {
        kind::ADAPTIVE => {
            let (c, s) = unsafe { &servo.adaptive };
            c.compensation().theta(s.friction())
        }
        kind::ADAPTIVE_AT => {
            let (c, s) = unsafe { &servo.adaptive_at };
            c.compensation().0.theta(s.friction())
        }
        kind::NONE
        | kind::FEED_FORWARD
        | kind::OBSERVER
        | kind::OBSERVER_AT
        | kind::PARAMETER_ADAPTIVE
        | kind::PARAMETER_ADAPTIVE_EXACT => return friction_status::FRICTION_NOT_SUPPORTED,
        _ => return friction_status::FRICTION_NOT_INITIALISED,
    };
    *out = theta;
    friction_status::FRICTION_OK
}

/// A compensation taken out of a freshly built [`Servo`] of its own kind
/// (`None` for another kind): what a re-tune swaps in.
trait Take<S: Scalar>: Sized {
    fn take(servo: Servo<S>) -> Option<Self>;
}

macro_rules! take {
    ($($variant:ident: $ty:ty),* $(,)?) => {
        $(
            impl<S: Scalar> Take<S> for $ty {
                fn take(servo: Servo<S>) -> Option<Self> {
                    match servo {
                        Servo::$variant(c, _) => Some(*c.compensation()),
                        _ => None,
                    }
                }
            }
        )*
    };
}

take!(
    None: NoCompensation,
    FeedForward: FeedForward<StaticMap<S>>,
    Observer: Observer<Variable<S>, S>,
    ObserverFixedStep: FixedPeriod<Observer<Fixed<S>, S>>,
    Adaptive: AdaptiveObserver<Variable<S>, S>,
    AdaptiveFixedStep: AdaptiveFixedStep<S>,
    ParameterAdaptive: ParameterLaw<S>,
    ParameterAdaptiveExact: ParameterLawExact<S>,
);

/// Swaps `next` (built with the servo's own loop parameters) into the axis
/// `c`, `s`: refused, touching nothing, when it is of another kind or
/// another period.
fn swap<S: Scalar, C: Compensation<S> + Take<S>>(
    c: &mut Compensator<S, C>,
    s: &mut CompensatorState<S, C::State>,
    next: Result<Servo<S>, friction_core::ParamError>,
    other_kind: &'static str,
) -> Refusal {
    match next.map(C::take) {
        Ok(Some(next)) => match c.retune(s, next) {
            Ok(()) => Refusal::OK,
            Err(e) => Refusal::param(e),
        },
        Ok(None) => Refusal::new(friction_status::FRICTION_NOT_SUPPORTED, other_kind),
        Err(e) => Refusal::param(e),
    }
}

fn retune<O, M, S>(
    servo: Option<&mut O>,
    model: Option<&M>,
    gain: f64,
    adaptive: Option<&friction_adaptive_params>,
    error: Option<&mut friction_error>,
) -> friction_status
where
    O: slot::Opaque<Value = Stored<S>>,
    M: slot::Opaque<Value = crate::model::Stored<S>>,
    S: Scalar,
{
    let Some(servo) = servo else {
        return report(
            error,
            Refusal::new(friction_status::FRICTION_NULL_POINTER, "servo"),
        );
    };
    let model = match model.map(|m| {
        let (kind, stored) = slot::get_kind_ref(m);
        Model::load(kind, stored)
    }) {
        None => None,
        Some(Some(m)) => Some(m),
        Some(None) => {
            return report(
                error,
                Refusal::new(friction_status::FRICTION_NOT_INITIALISED, "model"),
            )
        }
    };
    let adaptive = adaptive.map(AdaptiveParams::from);
    let (kind, servo) = slot::get_kind(servo);
    // the servo's kind wants an adaptive law exactly when it is adaptive
    let other_kind = if matches!(kind, kind::ADAPTIVE | kind::ADAPTIVE_AT) != adaptive.is_some() {
        "adaptive"
    } else {
        "model"
    };
    let refusal = each_servo!(
        kind,
        servo,
        |c, s| {
            let next = build(c.params(), model.as_ref(), gain, adaptive.as_ref());
            swap(c, s, next, other_kind)
        },
        Refusal::new(friction_status::FRICTION_NOT_INITIALISED, "servo")
    );
    report(error, refusal)
}

/// The status of a tick, writing the tick into `out`.
fn finish<S: Copy, T>(
    result: Result<friction_core::CompensatorTick<S>, friction_status>,
    out: &mut T,
    convert: impl FnOnce(friction_core::CompensatorTick<S>) -> T,
) -> friction_status {
    match result {
        Ok(t) => {
            let accepted = t.accepted;
            *out = convert(t);
            if accepted {
                friction_status::FRICTION_OK
            } else {
                friction_status::FRICTION_INPUT_REJECTED
            }
        }
        Err(status) => status,
    }
}

/// A servo axis in `float`: the loop `params` around a compensation chosen
/// by `model`: NULL for none, a static map for its feed-forward, a state
/// model for its observer with correction gain `gain` (1/s), or, with
/// `adaptive` not NULL, the theta-adaptive observer (state models only).
/// A fixed-step model must be built for `params->h`.
#[no_mangle]
pub extern "C" fn friction_servo_init_f32(
    out: Option<&mut friction_servo_f32>,
    params: Option<&friction_servo_params>,
    model: Option<&friction_model_f32>,
    gain: f64,
    adaptive: Option<&friction_adaptive_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    new(out, params, model, gain, adaptive, error)
}

/// [`friction_servo_init_f32`] in `double`.
#[no_mangle]
pub extern "C" fn friction_servo_init_f64(
    out: Option<&mut friction_servo_f64>,
    params: Option<&friction_servo_params>,
    model: Option<&friction_model_f64>,
    gain: f64,
    adaptive: Option<&friction_adaptive_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    new(out, params, model, gain, adaptive, error)
}

/// One servo tick: measured position `x`, setpoint `r`; writes the command
/// and the friction term. A NaN or infinite input: `FRICTION_INPUT_REJECTED`
/// and the safe output (all zero), state unchanged.
#[no_mangle]
pub extern "C" fn friction_servo_tick_f32(
    servo: Option<&mut friction_servo_f32>,
    x: f32,
    r: friction_setpoint_f32,
    out: Option<&mut friction_tick_f32>,
) -> friction_status {
    let Some(out) = out else {
        return friction_status::FRICTION_NULL_POINTER;
    };
    let r = Setpoint {
        x: r.x,
        v: r.v,
        a: r.a,
    };
    finish(tick(servo, x, r), out, |t| friction_tick_f32 {
        command: t.command,
        friction: t.friction,
    })
}

/// [`friction_servo_tick_f32`] in `double`.
#[no_mangle]
pub extern "C" fn friction_servo_tick_f64(
    servo: Option<&mut friction_servo_f64>,
    x: f64,
    r: friction_setpoint_f64,
    out: Option<&mut friction_tick_f64>,
) -> friction_status {
    let Some(out) = out else {
        return friction_status::FRICTION_NULL_POINTER;
    };
    let r = Setpoint {
        x: r.x,
        v: r.v,
        a: r.a,
    };
    finish(tick(servo, x, r), out, |t| friction_tick_f64 {
        command: t.command,
        friction: t.friction,
    })
}

/// Puts the servo axis back before its first tick (integral, memory and
/// compensation state cleared), keeping its parameters.
#[no_mangle]
pub extern "C" fn friction_servo_reset_f32(
    servo: Option<&mut friction_servo_f32>,
) -> friction_status {
    reset(servo)
}

/// [`friction_servo_reset_f32`] in `double`.
#[no_mangle]
pub extern "C" fn friction_servo_reset_f64(
    servo: Option<&mut friction_servo_f64>,
) -> friction_status {
    reset(servo)
}

/// Estimates the axis's velocity with an observer of bandwidth
/// `bandwidth_hz` (Hz, above 0 and below half the sample rate; the loop's
/// inertia above 0) instead of the backward difference: an alpha-beta-gamma
/// tracker driven by the command and the friction estimate, for an encoder
/// that moves less than one count per period at the axis's speed, where
/// the backward difference reads 0 or a whole count on every tick
/// (`friction_core::Compensator::with_velocity_observer`). Every kind of
/// compensation; the axis's state restarts as [`friction_servo_reset_f32`]
/// puts it, its parameters kept (an external torque must be set again). A
/// refusal (`FRICTION_NOT_POSITIVE`, `FRICTION_NOT_FINITE`,
/// `FRICTION_NOT_BELOW` or `FRICTION_UNDERFLOW`, the error naming
/// `velocity_observer` or `inertia`) leaves the axis as it was.
#[no_mangle]
pub extern "C" fn friction_servo_velocity_observer_f32(
    servo: Option<&mut friction_servo_f32>,
    bandwidth_hz: f64,
    error: Option<&mut friction_error>,
) -> friction_status {
    velocity_observer(servo, bandwidth_hz, error)
}

/// [`friction_servo_velocity_observer_f32`] in `double`.
#[no_mangle]
pub extern "C" fn friction_servo_velocity_observer_f64(
    servo: Option<&mut friction_servo_f64>,
    bandwidth_hz: f64,
    error: Option<&mut friction_error>,
) -> friction_status {
    velocity_observer(servo, bandwidth_hz, error)
}

/// The adaptive servo's current `theta` (the learnt scale of the model's
/// friction); `FRICTION_NOT_SUPPORTED` for other compensations.
#[no_mangle]
pub extern "C" fn friction_servo_theta_f32(
    servo: Option<&mut friction_servo_f32>,
    theta: Option<&mut f32>,
) -> friction_status {
    read_theta(servo, theta)
}

/// Re-tunes a running servo axis between two ticks: the compensation
/// becomes the one `model`, `gain` and `adaptive` give (as
/// [`friction_servo_init_f32`] builds it, with the axis's own loop
/// parameters), of the same kind as the axis's (no model, a static map, a
/// variable-step or a fixed-step state model, with or without `adaptive`;
/// `FRICTION_NOT_SUPPORTED` naming `model` or `adaptive` otherwise, and for
/// the per-parameter kind: [`friction_servo_parameter_adaptive_retune_f32`]).
/// The integral, the last position and the velocity estimate are kept, the
/// observer's state carried over (LuGre and Dahl keep their force; a model
/// of another kind starts at rest), `theta` restarts at `theta0`; so the
/// next command differs from the old compensation's by at most the change
/// of the friction estimate over `kc`. A refusal (a fixed-step model built
/// for another period: `FRICTION_PERIOD_MISMATCH`) leaves the axis as it was.
#[no_mangle]
pub extern "C" fn friction_servo_retune_f32(
    servo: Option<&mut friction_servo_f32>,
    model: Option<&friction_model_f32>,
    gain: f64,
    adaptive: Option<&friction_adaptive_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    retune(servo, model, gain, adaptive, error)
}

/// [`friction_servo_retune_f32`] in `double`.
#[no_mangle]
pub extern "C" fn friction_servo_retune_f64(
    servo: Option<&mut friction_servo_f64>,
    model: Option<&friction_model_f64>,
    gain: f64,
    adaptive: Option<&friction_adaptive_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    retune(servo, model, gain, adaptive, error)
}

/// [`friction_servo_theta_f32`] in `double`.
#[no_mangle]
pub extern "C" fn friction_servo_theta_f64(
    servo: Option<&mut friction_servo_f64>,
    theta: Option<&mut f64>,
) -> friction_status {
    read_theta(servo, theta)
}

/// The estimates of the per-parameter adaptive observer, in `float`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_estimates_f32 {
    /// Coulomb level while the bristle leans forward (N).
    pub fc_pos: f32,
    /// Coulomb level while it leans backward (N, positive).
    pub fc_neg: f32,
    /// Stribeck excess `fs - fc` (N).
    pub stribeck: f32,
    /// Viscous coefficient `sigma2`.
    pub sigma2: f32,
    /// Load coefficient (friction per unit of transmitted torque).
    pub load: f32,
}

/// [`friction_estimates_f32`] in `double`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_estimates_f64 {
    /// Coulomb level while the bristle leans forward (N).
    pub fc_pos: f64,
    /// Coulomb level while it leans backward (N, positive).
    pub fc_neg: f64,
    /// Stribeck excess `fs - fc` (N).
    pub stribeck: f64,
    /// Viscous coefficient `sigma2`.
    pub sigma2: f64,
    /// Load coefficient (friction per unit of transmitted torque).
    pub load: f64,
}

/// Which compensation the supervisor applies.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum friction_mode {
    /// The adaptive observer.
    FRICTION_MODE_PRIMARY = 0,
    /// The static fallback (Coulomb + viscous feed-forward).
    FRICTION_MODE_FALLBACK = 1,
    /// No compensation.
    FRICTION_MODE_OFF = 2,
}

/// The supervisor's state: the applied mode and how it got there.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_supervisor_status {
    /// The applied compensation.
    pub mode: friction_mode,
    /// Switches so far.
    pub switches: u32,
    /// Completed evidence windows (each counted when its evidence has
    /// chosen the mode, six ticks after it closed).
    pub windows: u32,
    /// Windows since the last switch (counted as `windows`).
    pub since_switch: u32,
}

/// A per-parameter axis: the law with the implicit or the exact step.
enum ParameterAxis<'a, S: Scalar> {
    Implicit(&'a mut Axis<S, ParameterLaw<S>>),
    Exact(&'a mut Axis<S, ParameterLawExact<S>>),
}

/// `$body` with `$c` and `$s` bound to either per-parameter axis.
macro_rules! each_parameter_axis {
    ($axis:expr, |$c:ident, $s:ident| $body:expr) => {
        match $axis {
            ParameterAxis::Implicit(($c, $s)) => $body,
            ParameterAxis::Exact(($c, $s)) => $body,
        }
    };
}

/// The per-parameter kinds' compensator and state, or the status for an
/// object of another kind (`FRICTION_NOT_SUPPORTED`) or none
/// (`FRICTION_NOT_INITIALISED`).
fn parameter_axis<O, S>(servo: &mut O) -> Result<ParameterAxis<'_, S>, friction_status>
where
    O: slot::Opaque<Value = Stored<S>>,
    S: Scalar,
{
    let (kind, servo) = slot::get_kind(servo);
    match kind {
        // SAFETY: as in `each_servo`.
        kind::PARAMETER_ADAPTIVE => Ok(ParameterAxis::Implicit(unsafe {
            &mut servo.parameter_adaptive
        })),
        // SAFETY: as in `each_servo`.
        kind::PARAMETER_ADAPTIVE_EXACT => {
            Ok(ParameterAxis::Exact(unsafe { &mut servo.parameter_exact }))
        }
        kind::NONE
        | kind::FEED_FORWARD
        | kind::OBSERVER
        | kind::OBSERVER_AT
        | kind::ADAPTIVE
        | kind::ADAPTIVE_AT => Err(friction_status::FRICTION_NOT_SUPPORTED),
        _ => Err(friction_status::FRICTION_NOT_INITIALISED),
    }
}

/// The supervised per-parameter law of `adaptive` (its step as
/// `exact_step` says), `supervisor` and `fallback` for the loop `p`.
fn parameter_law<S: Scalar>(
    p: &CompensatorParams,
    adaptive: &friction_parameter_adaptive_params,
    supervisor: &friction_supervisor_params,
    fallback: &friction_coulomb_viscous_params,
) -> Result<Servo<S>, friction_core::ParamError> {
    let law = ParameterAdaptiveParams::from(adaptive);
    let map = CoulombViscousParams::from(fallback).build::<S>()?;
    let supervisor = SupervisorParams::from(supervisor);
    let state = CompensatorState::default();
    Ok(if law.exact_step {
        let law = law.build_fixed_step_exact::<S>(p)?;
        Servo::ParameterAdaptiveExact(p.build(supervisor.build(law, map, p)?)?, state)
    } else {
        let law = law.build_fixed_step::<S>(p)?;
        Servo::ParameterAdaptive(p.build(supervisor.build(law, map, p)?)?, state)
    })
}

fn new_parameter_adaptive<O, S>(
    out: Option<&mut O>,
    params: Option<&friction_servo_params>,
    adaptive: Option<&friction_parameter_adaptive_params>,
    supervisor: Option<&friction_supervisor_params>,
    fallback: Option<&friction_coulomb_viscous_params>,
    error: Option<&mut friction_error>,
) -> friction_status
where
    O: slot::Opaque<Value = Stored<S>>,
    S: Scalar,
{
    let (Some(out), Some(params), Some(adaptive), Some(supervisor), Some(fallback)) =
        (out, params, adaptive, supervisor, fallback)
    else {
        let which = match (params, adaptive, supervisor, fallback) {
            (None, ..) => "params",
            (_, None, ..) => "adaptive",
            (_, _, None, _) => "supervisor",
            (.., None) => "fallback",
            _ => "out",
        };
        return report(
            error,
            Refusal::new(friction_status::FRICTION_NULL_POINTER, which),
        );
    };
    let p = CompensatorParams::from(params);
    match parameter_law::<S>(&p, adaptive, supervisor, fallback) {
        Ok(servo) => {
            let (kind, stored) = servo.stored();
            slot::put_kind(out, kind, stored);
            report(error, Refusal::OK)
        }
        Err(e) => report(error, Refusal::param(e)),
    }
}

/// A servo axis in `float` with the per-parameter adaptive observer under
/// its supervisor: the loop `params`, the observer `adaptive` (its
/// fixed-step form, built for `params->h`), the supervisor `supervisor`
/// and its static fallback `fallback` (Coulomb + viscous feed-forward on
/// the measured velocity). The supervisor applies whichever of the
/// observer, the fallback and no compensation predicts the measured
/// friction best (`friction_servo_supervisor_f32`); the estimates are read
/// with `friction_servo_estimates_f32`.
#[no_mangle]
pub extern "C" fn friction_servo_parameter_adaptive_init_f32(
    out: Option<&mut friction_servo_f32>,
    params: Option<&friction_servo_params>,
    adaptive: Option<&friction_parameter_adaptive_params>,
    supervisor: Option<&friction_supervisor_params>,
    fallback: Option<&friction_coulomb_viscous_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    new_parameter_adaptive(out, params, adaptive, supervisor, fallback, error)
}

/// [`friction_servo_parameter_adaptive_init_f32`] in `double`.
#[no_mangle]
pub extern "C" fn friction_servo_parameter_adaptive_init_f64(
    out: Option<&mut friction_servo_f64>,
    params: Option<&friction_servo_params>,
    adaptive: Option<&friction_parameter_adaptive_params>,
    supervisor: Option<&friction_supervisor_params>,
    fallback: Option<&friction_coulomb_viscous_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    new_parameter_adaptive(out, params, adaptive, supervisor, fallback, error)
}

fn retune_parameter_adaptive<O, S>(
    servo: Option<&mut O>,
    adaptive: Option<&friction_parameter_adaptive_params>,
    supervisor: Option<&friction_supervisor_params>,
    fallback: Option<&friction_coulomb_viscous_params>,
    error: Option<&mut friction_error>,
) -> friction_status
where
    O: slot::Opaque<Value = Stored<S>>,
    S: Scalar,
{
    let (Some(servo), Some(adaptive), Some(supervisor), Some(fallback)) =
        (servo, adaptive, supervisor, fallback)
    else {
        let which = match (adaptive, supervisor, fallback) {
            (None, ..) => "adaptive",
            (_, None, _) => "supervisor",
            (.., None) => "fallback",
            _ => "servo",
        };
        return report(
            error,
            Refusal::new(friction_status::FRICTION_NULL_POINTER, which),
        );
    };
    let axis = match parameter_axis(servo) {
        Ok(axis) => axis,
        Err(status) => return report(error, Refusal::new(status, "servo")),
    };
    // the step is the axis's kind: the other one is refused, naming it
    let refusal = each_parameter_axis!(axis, |c, s| {
        let p = *c.params();
        swap(
            c,
            s,
            parameter_law::<S>(&p, adaptive, supervisor, fallback),
            "exact_step",
        )
    });
    report(error, refusal)
}

/// Re-tunes a running per-parameter adaptive servo axis between two ticks
/// (see [`friction_servo_retune_f32`]): the observer, the supervisor and
/// the fallback become those `adaptive`, `supervisor` and `fallback` give,
/// built for the axis's own loop parameters. The estimates restart at the
/// new model's values, the elastic force is carried over, the supervisor
/// keeps the mode it applies and restarts its evidence (warm-up again). A
/// refusal leaves the axis as it was; `FRICTION_NOT_SUPPORTED` for an axis
/// of another kind.
#[no_mangle]
pub extern "C" fn friction_servo_parameter_adaptive_retune_f32(
    servo: Option<&mut friction_servo_f32>,
    adaptive: Option<&friction_parameter_adaptive_params>,
    supervisor: Option<&friction_supervisor_params>,
    fallback: Option<&friction_coulomb_viscous_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    retune_parameter_adaptive(servo, adaptive, supervisor, fallback, error)
}

/// [`friction_servo_parameter_adaptive_retune_f32`] in `double`.
#[no_mangle]
pub extern "C" fn friction_servo_parameter_adaptive_retune_f64(
    servo: Option<&mut friction_servo_f64>,
    adaptive: Option<&friction_parameter_adaptive_params>,
    supervisor: Option<&friction_supervisor_params>,
    fallback: Option<&friction_coulomb_viscous_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    retune_parameter_adaptive(servo, adaptive, supervisor, fallback, error)
}

/// The defaults of the per-parameter adaptive observer around the nominal
/// `model` with observer gain `gain` (1/s): rate 4 1/s, derivative weight
/// 1, no leakage, box factor 5, no dead zone, no speed threshold,
/// reference speed 1, no load term, the implicit step. Nothing is checked until a
/// constructor uses them.
#[no_mangle]
pub extern "C" fn friction_parameter_adaptive_defaults(
    model: Option<&crate::params::friction_lugre_params>,
    gain: f64,
    out: Option<&mut friction_parameter_adaptive_params>,
) -> friction_status {
    let (Some(model), Some(out)) = (model, out) else {
        return friction_status::FRICTION_NULL_POINTER;
    };
    let d = ParameterAdaptiveParams::new(LuGreParams::from(model), gain);
    *out = friction_parameter_adaptive_params {
        model: *model,
        observer_gain: d.observer_gain,
        rate: d.rate,
        derivative_weight: d.derivative_weight,
        leakage: d.leakage,
        box_factor: d.box_factor,
        dead_zone: d.dead_zone,
        min_speed: d.min_speed,
        speed: d.speed,
        load: d.load,
        load_max: d.load_max,
        exact_step: u8::from(d.exact_step),
    };
    friction_status::FRICTION_OK
}

/// The supervisor's defaults: windows of 0.1 s, a memory of 10 windows,
/// ratio 0.7, warm-up 10 windows, a retry after 100 windows, no tolerance
/// (set one: a few per cent of the Coulomb level).
#[no_mangle]
pub extern "C" fn friction_supervisor_defaults(
    out: Option<&mut friction_supervisor_params>,
) -> friction_status {
    let Some(out) = out else {
        return friction_status::FRICTION_NULL_POINTER;
    };
    *out = SupervisorParams::DEFAULT.into();
    friction_status::FRICTION_OK
}

fn read_estimates<O, S, T>(
    servo: Option<&mut O>,
    out: Option<&mut T>,
    convert: impl FnOnce([S; friction_core::PARAMETER_ADAPTIVE_ESTIMATES]) -> T,
) -> friction_status
where
    O: slot::Opaque<Value = Stored<S>>,
    S: Scalar,
{
    let (Some(servo), Some(out)) = (servo, out) else {
        return friction_status::FRICTION_NULL_POINTER;
    };
    match parameter_axis(servo) {
        Ok(axis) => {
            *out = convert(each_parameter_axis!(axis, |c, s| {
                let law = c.compensation().primary();
                // a state before its first tick reads the nominal values
                let state = s.friction().primary;
                let state = if state == Default::default() {
                    law.initial()
                } else {
                    state
                };
                law.estimates(&state)
            }));
            friction_status::FRICTION_OK
        }
        Err(status) => status,
    }
}

fn read_status<O, S>(
    servo: Option<&mut O>,
    out: Option<&mut friction_supervisor_status>,
) -> friction_status
where
    O: slot::Opaque<Value = Stored<S>>,
    S: Scalar,
{
    let (Some(servo), Some(out)) = (servo, out) else {
        return friction_status::FRICTION_NULL_POINTER;
    };
    match parameter_axis(servo) {
        Ok(axis) => {
            let st = each_parameter_axis!(axis, |c, s| c.compensation().status(s.friction()));
            *out = friction_supervisor_status {
                mode: match st.mode {
                    SupervisorMode::Primary => friction_mode::FRICTION_MODE_PRIMARY,
                    SupervisorMode::Fallback => friction_mode::FRICTION_MODE_FALLBACK,
                    SupervisorMode::Off => friction_mode::FRICTION_MODE_OFF,
                },
                switches: st.switches,
                windows: st.windows,
                since_switch: st.since_switch,
            };
            friction_status::FRICTION_OK
        }
        Err(status) => status,
    }
}

/// The per-parameter adaptive servo's estimates (the nominal values before
/// its first tick); `FRICTION_NOT_SUPPORTED` for other compensations.
#[no_mangle]
pub extern "C" fn friction_servo_estimates_f32(
    servo: Option<&mut friction_servo_f32>,
    out: Option<&mut friction_estimates_f32>,
) -> friction_status {
    read_estimates(
        servo,
        out,
        |[fc_pos, fc_neg, stribeck, sigma2, load]: [f32; 5]| friction_estimates_f32 {
            fc_pos,
            fc_neg,
            stribeck,
            sigma2,
            load,
        },
    )
}

/// [`friction_servo_estimates_f32`] in `double`.
#[no_mangle]
pub extern "C" fn friction_servo_estimates_f64(
    servo: Option<&mut friction_servo_f64>,
    out: Option<&mut friction_estimates_f64>,
) -> friction_status {
    read_estimates(
        servo,
        out,
        |[fc_pos, fc_neg, stribeck, sigma2, load]: [f64; 5]| friction_estimates_f64 {
            fc_pos,
            fc_neg,
            stribeck,
            sigma2,
            load,
        },
    )
}

fn set_external<O, S>(servo: Option<&mut O>, torque: S) -> friction_status
where
    O: slot::Opaque<Value = Stored<S>>,
    S: Scalar,
{
    let Some(servo) = servo else {
        return friction_status::FRICTION_NULL_POINTER;
    };
    match parameter_axis(servo) {
        Ok(_) if !torque.is_finite() => friction_status::FRICTION_INPUT_REJECTED,
        Ok(axis) => {
            each_parameter_axis!(axis, |c, s| c.set_external_torque(s, torque));
            friction_status::FRICTION_OK
        }
        Err(status) => status,
    }
}

/// Sets the external torque `tau_ext` on a per-parameter adaptive servo
/// axis (force units), which its load input reads as `kc u - tau_ext` from
/// the next tick on (BAM's transmitted torque `tau_m - tau_e`): the load's
/// torque on the axis (a pendulum's `-T sin x`) less any torque the drive
/// adds beside this axis's command (a gravity feed-forward). It holds until
/// set again. NaN or infinite: `FRICTION_INPUT_REJECTED`, state unchanged;
/// `FRICTION_NOT_SUPPORTED` for other compensations.
#[no_mangle]
pub extern "C" fn friction_servo_set_external_torque_f32(
    servo: Option<&mut friction_servo_f32>,
    torque: f32,
) -> friction_status {
    set_external(servo, torque)
}

/// [`friction_servo_set_external_torque_f32`] in `double`.
#[no_mangle]
pub extern "C" fn friction_servo_set_external_torque_f64(
    servo: Option<&mut friction_servo_f64>,
    torque: f64,
) -> friction_status {
    set_external(servo, torque)
}

/// The per-parameter adaptive servo's supervisor: the applied mode, the
/// switches and windows so far; `FRICTION_NOT_SUPPORTED` for other
/// compensations.
#[no_mangle]
pub extern "C" fn friction_servo_supervisor_f32(
    servo: Option<&mut friction_servo_f32>,
    out: Option<&mut friction_supervisor_status>,
) -> friction_status {
    read_status(servo, out)
}

/// [`friction_servo_supervisor_f32`] in `double`.
#[no_mangle]
pub extern "C" fn friction_servo_supervisor_f64(
    servo: Option<&mut friction_servo_f64>,
    out: Option<&mut friction_supervisor_status>,
) -> friction_status {
    read_status(servo, out)
}
