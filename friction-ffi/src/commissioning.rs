//! Commissioning: the core's `Commissioning` routine, ticked in the
//! control interrupt until it is done, then fitted into LuGre parameters
//! that `friction_lugre_init_*` and `friction_servo_retune_*` take.
//!
//! One object holds the built routine and its run-time state (one kind,
//! so one tag word per scalar type). The fit (`friction_commissioning_result_*`)
//! runs in `double` whatever the object's scalar, outside the interrupt.

use crate::model::init;
use crate::params::{friction_lugre_params, friction_servo_params, friction_stribeck};
use crate::slot::{self, opaque, Built};
use crate::status::{friction_error, friction_status, report, Refusal};
use friction_core::{
    CommissionError, Commissioning, CommissioningAbort, CommissioningParams, CommissioningPhase,
    CommissioningState, CompensatorParams, Scalar,
};

/// Words (8 bytes each) of a `float` commissioning object, room for the
/// routine and its state (a compile-time check keeps it so).
pub const FRICTION_COMMISSIONING_F32_WORDS: usize = 400;
/// Words (8 bytes each) of a `double` commissioning object.
pub const FRICTION_COMMISSIONING_F64_WORDS: usize = 640;

/// A commissioning routine with its state, in `float` (caller-allocated;
/// see [`friction_commissioning_init_f32`]).
#[repr(C)]
pub struct friction_commissioning_f32 {
    /// Private: written by the constructor, read by the other calls.
    pub opaque: [u64; FRICTION_COMMISSIONING_F32_WORDS],
}

/// A commissioning routine with its state, in `double` (caller-allocated;
/// see [`friction_commissioning_init_f64`]).
#[repr(C)]
pub struct friction_commissioning_f64 {
    /// Private: written by the constructor, read by the other calls.
    pub opaque: [u64; FRICTION_COMMISSIONING_F64_WORDS],
}

opaque!(friction_commissioning_f32, Stored<f32>, 0xB7B7_B7B7);
opaque!(friction_commissioning_f64, Stored<f64>, 0xB8B8_B8B8);

/// The commissioning programme's settings
/// (`friction_core::CommissioningParams`);
/// [`friction_commissioning_defaults`] fills them from a loop, a travel
/// window and a top speed.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_commissioning_params {
    /// The position loop that drives the plateaus: its `limit` is the
    /// command limit of the whole routine, its `inertia` the one `sigma1`
    /// is damped against.
    pub servo: friction_servo_params,
    /// Largest excursion `> 0` from the starting position.
    pub travel: f64,
    /// Longest run `> 0` (s).
    pub duration: f64,
    /// Slowest plateau speed `> 0`.
    pub min_speed: f64,
    /// Fastest plateau speed `>= min_speed`.
    pub max_speed: f64,
    /// Number of plateau speeds, 2 to 16 (each run in both directions).
    pub speeds: u32,
    /// Measuring time `> 0` of a plateau (s).
    pub plateau: f64,
    /// Time `>= 0` (s) a plateau cruises before it is measured.
    pub settle: f64,
    /// Acceleration `> 0` of the plateau moves.
    pub acceleration: f64,
    /// Rate `> 0` of the break-away and presliding command ramps (command
    /// units per second).
    pub ramp_rate: f64,
    /// Displacement `> 0` (below `travel`) that counts as breaking away.
    pub breakaway_travel: f64,
    /// The encoder's count `>= 0` (position units; 0: exact).
    pub resolution: f64,
}

impl From<&friction_commissioning_params> for CommissioningParams {
    fn from(p: &friction_commissioning_params) -> Self {
        Self {
            servo: CompensatorParams::from(&p.servo),
            travel: p.travel,
            duration: p.duration,
            min_speed: p.min_speed,
            max_speed: p.max_speed,
            // a count beyond a byte is out of range as 255 is
            speeds: u8::try_from(p.speeds).unwrap_or(u8::MAX),
            plateau: p.plateau,
            settle: p.settle,
            acceleration: p.acceleration,
            ramp_rate: p.ramp_rate,
            breakaway_travel: p.breakaway_travel,
            resolution: p.resolution,
        }
    }
}

/// Where a routine is (the values of [`friction_commissioning_command_f32`]'s
/// `phase` and of [`friction_commissioning_phase_f32`]).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum friction_phase {
    /// The break-away ramps, forward then backward.
    FRICTION_PHASE_BREAKAWAY = 0,
    /// The presliding reversal.
    FRICTION_PHASE_PRESLIDING = 1,
    /// The velocity plateaus.
    FRICTION_PHASE_PLATEAUS = 2,
    /// Finished: `friction_commissioning_result_*` fits the parameters.
    FRICTION_PHASE_DONE = 3,
    /// Stopped by a limit or a fault; the command is 0 from now on.
    FRICTION_PHASE_ABORTED = 4,
}

/// Why a routine stopped early (the values of
/// [`friction_commissioning_abort_f32`]).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum friction_abort {
    /// Not aborted.
    FRICTION_ABORT_NONE = 0,
    /// The axis left the travel window.
    FRICTION_ABORT_TRAVEL = 1,
    /// The programme ran longer than `duration`.
    FRICTION_ABORT_TIMEOUT = 2,
    /// The position loop held its command at the limit for 50 ms.
    FRICTION_ABORT_STALL = 3,
    /// A break-away ramp reached the command limit without moving the axis.
    FRICTION_ABORT_NO_BREAKAWAY = 4,
    /// The axis moved against the command (motor or encoder sign reversed).
    FRICTION_ABORT_REVERSED_SIGN = 5,
    /// A measured position was NaN or infinite (the core's routine; the
    /// ABI refuses such a position before the routine sees it).
    FRICTION_ABORT_NON_FINITE = 6,
}

fn phase_code(phase: CommissioningPhase) -> i32 {
    (match phase {
        CommissioningPhase::Breakaway => friction_phase::FRICTION_PHASE_BREAKAWAY,
        CommissioningPhase::Presliding => friction_phase::FRICTION_PHASE_PRESLIDING,
        CommissioningPhase::Plateaus => friction_phase::FRICTION_PHASE_PLATEAUS,
        CommissioningPhase::Done => friction_phase::FRICTION_PHASE_DONE,
        CommissioningPhase::Aborted => friction_phase::FRICTION_PHASE_ABORTED,
    }) as i32
}

fn abort_code(abort: Option<CommissioningAbort>) -> i32 {
    (match abort {
        None => friction_abort::FRICTION_ABORT_NONE,
        Some(CommissioningAbort::Travel) => friction_abort::FRICTION_ABORT_TRAVEL,
        Some(CommissioningAbort::Timeout) => friction_abort::FRICTION_ABORT_TIMEOUT,
        Some(CommissioningAbort::Stall) => friction_abort::FRICTION_ABORT_STALL,
        Some(CommissioningAbort::NoBreakaway) => friction_abort::FRICTION_ABORT_NO_BREAKAWAY,
        Some(CommissioningAbort::ReversedSign) => friction_abort::FRICTION_ABORT_REVERSED_SIGN,
        Some(CommissioningAbort::NonFiniteMeasurement) => friction_abort::FRICTION_ABORT_NON_FINITE,
    }) as i32
}

/// The abort reason as the parameter a refused result names (the limit
/// that stopped the routine, as `friction_commissioning_params` names it).
fn abort_name(abort: CommissioningAbort) -> &'static str {
    match abort {
        CommissioningAbort::Travel => "travel",
        CommissioningAbort::Timeout => "duration",
        CommissioningAbort::Stall => "limit",
        CommissioningAbort::NoBreakaway => "ramp_rate",
        CommissioningAbort::ReversedSign => "torque_constant",
        CommissioningAbort::NonFiniteMeasurement => "x",
    }
}

/// What a commissioning tick produced, in `float`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_commissioning_command_f32 {
    /// The command to apply: finite, within `±limit`, 0 once done or
    /// aborted.
    pub command: f32,
    /// Where the routine is after the tick (a [`friction_phase`] value; an
    /// `int32_t`).
    pub phase: i32,
    /// Plateaus measured so far (of `2 speeds`).
    pub plateaus: u32,
}

/// What a commissioning tick produced, in `double`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_commissioning_command_f64 {
    /// The command to apply: finite, within `±limit`, 0 once done or
    /// aborted.
    pub command: f64,
    /// Where the routine is after the tick (a [`friction_phase`] value).
    pub phase: i32,
    /// Plateaus measured so far (of `2 speeds`).
    pub plateaus: u32,
}

/// A commissioning run's result (`friction_core::Commissioned`), always in
/// `double`: the LuGre model for `friction_lugre_init_*` (its `vd` 0), the
/// levels per direction and the quality figures. The `identified` flags
/// are 1 where the run measured the parameter and 0 where it is the
/// documented fallback.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct friction_commissioned {
    /// The LuGre model (levels and viscous coefficient the means of the
    /// two directions).
    pub model: friction_lugre_params,
    /// Coulomb levels forward and backward (force units, both positive).
    pub fc: [f64; 2],
    /// Static levels forward and backward.
    pub fs: [f64; 2],
    /// Viscous coefficients forward and backward.
    pub sigma2: [f64; 2],
    /// Break-away levels of the ramps, forward and backward.
    pub breakaway: [f64; 2],
    /// 1: `fc` measured (per direction).
    pub identified_coulomb: i32,
    /// 1: `fs`, `vs` and the exponent measured.
    pub identified_stribeck: i32,
    /// 1: `sigma2` measured.
    pub identified_viscous: i32,
    /// 1: `sigma0` measured.
    pub identified_stiffness: i32,
    /// 1: `sigma1` measured.
    pub identified_damping: i32,
    /// Plateaus fitted.
    pub plateaus: u32,
    /// RMS of the curve fit over the plateaus, relative to the friction:
    /// the largest of the mean `fc`, a tenth of the static level and the
    /// curve's lowest at the plateaus' speeds (also written alone when the
    /// result is refused as `FRICTION_POOR_FIT`).
    pub residual: f64,
    /// Slowest and fastest fitted plateau speed.
    pub speed_range: [f64; 2],
    /// The load coefficient: friction per unit of the transmitted torque
    /// `|kc u|` (0 where not identified).
    pub load: f64,
    /// The mean transmitted torque over the plateaus: the levels are the
    /// curve at this load.
    pub load_torque: f64,
    /// 1: the load coefficient measured (a load that changes along the
    /// window, such as gravity).
    pub identified_load: i32,
}

/// The routine and its state, as an object stores them.
#[derive(Clone, Copy)]
#[repr(C)]
pub(crate) union Stored<S: Scalar> {
    routine: (Commissioning<S>, CommissioningState<S>),
}

// SAFETY: a union of `Copy` types: every bit pattern is a value of it (its
// field is read only for the kind that names it).
unsafe impl<S: Scalar> slot::Union for Stored<S> {}

/// The one kind, added to the object's tag: from 1, so that an object
/// holding its type's bare tag (kind 0) is refused.
const ROUTINE: u32 = 1;

/// A routine built by the constructor, before it is stored.
struct Routine<S: Scalar>(Commissioning<S>);

impl<S: Scalar> Built for Routine<S> {
    type Stored = Stored<S>;

    fn stored(self) -> (u32, Stored<S>) {
        (
            ROUTINE,
            Stored {
                routine: (self.0, CommissioningState::default()),
            },
        )
    }
}

/// The routine and state in `object`, or `FRICTION_NOT_INITIALISED` for a
/// kind no constructor writes.
fn routine<O, S>(
    object: &mut O,
) -> Result<&mut (Commissioning<S>, CommissioningState<S>), friction_status>
where
    O: slot::Opaque<Value = Stored<S>>,
    S: Scalar,
{
    let (kind, stored) = slot::get_kind(object);
    if kind == ROUTINE {
        // SAFETY: the kind is only written with this field (`put_kind` from
        // `Routine::stored`; C may copy both), and C's bytes in it are read
        // as the core's values, which any bytes are (see slot.rs: the
        // routine and its state hold floats, integers, `Flag`s and bytes
        // decoded totally).
        Ok(unsafe { &mut stored.routine })
    } else {
        Err(friction_status::FRICTION_NOT_INITIALISED)
    }
}

fn new<O, S>(
    out: Option<&mut O>,
    params: Option<&friction_commissioning_params>,
    error: Option<&mut friction_error>,
) -> friction_status
where
    O: slot::Opaque<Value = Stored<S>>,
    S: Scalar,
{
    init(out, params, "params", error, |p| {
        CommissioningParams::from(p)
            .build::<S>()
            .map(Routine)
            .map_err(Refusal::param)
    })
}

fn tick<O, S>(object: Option<&mut O>, x: S) -> Result<(S, i32, u32, bool), friction_status>
where
    O: slot::Opaque<Value = Stored<S>>,
    S: Scalar,
{
    let object = object.ok_or(friction_status::FRICTION_NULL_POINTER)?;
    let (c, s) = routine(object)?;
    if !x.is_finite() {
        // the ABI's rule: a refused input leaves the state as it was (the
        // core would end the routine); the command is the safe zero
        return Ok((S::ZERO, phase_code(s.phase()), 0, false));
    }
    let t = c.tick(s, x);
    Ok((t.command, phase_code(t.phase), u32::from(t.plateaus), true))
}

/// The status of a tick, writing it into `out` through `convert`.
fn finish<S, T>(
    result: Result<(S, i32, u32, bool), friction_status>,
    out: &mut T,
    convert: impl FnOnce(S, i32, u32) -> T,
) -> friction_status {
    match result {
        Ok((command, phase, plateaus, accepted)) => {
            *out = convert(command, phase, plateaus);
            if accepted {
                friction_status::FRICTION_OK
            } else {
                friction_status::FRICTION_INPUT_REJECTED
            }
        }
        Err(status) => status,
    }
}

fn reset<O, S>(object: Option<&mut O>) -> friction_status
where
    O: slot::Opaque<Value = Stored<S>>,
    S: Scalar,
{
    let Some(object) = object else {
        return friction_status::FRICTION_NULL_POINTER;
    };
    match routine(object) {
        Ok((_, s)) => {
            *s = CommissioningState::default();
            friction_status::FRICTION_OK
        }
        Err(status) => status,
    }
}

fn read<O, S>(
    object: Option<&mut O>,
    out: Option<&mut i32>,
    code: impl FnOnce(&CommissioningState<S>) -> i32,
) -> friction_status
where
    O: slot::Opaque<Value = Stored<S>>,
    S: Scalar,
{
    let (Some(object), Some(out)) = (object, out) else {
        return friction_status::FRICTION_NULL_POINTER;
    };
    match routine(object) {
        Ok((_, s)) => {
            *out = code(s);
            friction_status::FRICTION_OK
        }
        Err(status) => status,
    }
}

fn result<O, S>(
    object: Option<&mut O>,
    out: Option<&mut friction_commissioned>,
    error: Option<&mut friction_error>,
) -> friction_status
where
    O: slot::Opaque<Value = Stored<S>>,
    S: Scalar,
{
    let (Some(object), Some(out)) = (object, out) else {
        return report(
            error,
            Refusal::new(
                friction_status::FRICTION_NULL_POINTER,
                "commissioning or out",
            ),
        );
    };
    let (c, s) = match routine(object) {
        Ok(routine) => routine,
        Err(status) => return report(error, Refusal::new(status, "commissioning")),
    };
    let refusal = match c.result(s) {
        Ok(r) => {
            let m = r.model;
            let flag = i32::from;
            *out = friction_commissioned {
                model: friction_lugre_params {
                    curve: friction_stribeck {
                        fc: m.curve.fc,
                        fs: m.curve.fs,
                        vs: m.curve.vs,
                        exponent: m.curve.exponent,
                    },
                    sigma0: m.sigma0,
                    sigma1: m.sigma1,
                    sigma2: m.sigma2,
                    vd: m.vd.unwrap_or(0.0),
                },
                fc: r.fc,
                fs: r.fs,
                sigma2: r.sigma2,
                breakaway: r.breakaway,
                identified_coulomb: flag(r.identified.coulomb),
                identified_stribeck: flag(r.identified.stribeck),
                identified_viscous: flag(r.identified.viscous),
                identified_stiffness: flag(r.identified.stiffness),
                identified_damping: flag(r.identified.damping),
                plateaus: u32::from(r.plateaus),
                residual: r.residual,
                speed_range: r.speed_range,
                load: r.load,
                load_torque: r.load_torque,
                identified_load: flag(r.identified.load),
            };
            Refusal::OK
        }
        Err(CommissionError::NotFinished) => {
            Refusal::new(friction_status::FRICTION_NOT_FINISHED, "")
        }
        Err(CommissionError::Aborted(why)) => {
            Refusal::new(friction_status::FRICTION_ABORTED, abort_name(why))
        }
        Err(CommissionError::TooFewPlateaus) => {
            Refusal::new(friction_status::FRICTION_TOO_FEW_PLATEAUS, "speeds")
        }
        Err(CommissionError::PoorFit(residual)) => {
            out.residual = residual;
            Refusal::new(friction_status::FRICTION_POOR_FIT, "residual")
        }
        Err(CommissionError::NoFriction) => {
            Refusal::new(friction_status::FRICTION_NO_FRICTION, "fc")
        }
        Err(CommissionError::Invalid(e)) => Refusal::param(e),
    };
    report(error, refusal)
}

/// The defaults for the loop `servo`, a travel window `travel` and a top
/// speed `max_speed` (`friction_core::CommissioningParams::new`): 30 s at
/// most, 10 speeds down to `max_speed / 1000`, plateaus of 0.8 s after
/// 0.15 s of settling, the top speed reached in 0.1 s (or slower, so that
/// accelerating the inertia takes at most a quarter of the limit), command
/// ramps of a tenth of the limit per second, break-away at a hundredth of
/// the travel, an exact encoder (set `resolution` to the encoder's count).
/// Nothing is checked until a constructor uses them.
#[no_mangle]
pub extern "C" fn friction_commissioning_defaults(
    servo: Option<&friction_servo_params>,
    travel: f64,
    max_speed: f64,
    out: Option<&mut friction_commissioning_params>,
) -> friction_status {
    let (Some(servo), Some(out)) = (servo, out) else {
        return friction_status::FRICTION_NULL_POINTER;
    };
    let d = CommissioningParams::new(CompensatorParams::from(servo), travel, max_speed);
    *out = friction_commissioning_params {
        servo: *servo,
        travel: d.travel,
        duration: d.duration,
        min_speed: d.min_speed,
        max_speed: d.max_speed,
        speeds: u32::from(d.speeds),
        plateau: d.plateau,
        settle: d.settle,
        acceleration: d.acceleration,
        ramp_rate: d.ramp_rate,
        breakaway_travel: d.breakaway_travel,
        resolution: d.resolution,
    };
    friction_status::FRICTION_OK
}

/// A commissioning routine in `float` from `params`, ready for its first
/// tick (the position at that tick is the start of the travel window).
/// Checks every setting and that the programme fits the travel and the
/// duration (`FRICTION_NOT_BELOW` naming `max_speed` or `plateau`
/// otherwise).
#[no_mangle]
pub extern "C" fn friction_commissioning_init_f32(
    out: Option<&mut friction_commissioning_f32>,
    params: Option<&friction_commissioning_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    new(out, params, error)
}

/// [`friction_commissioning_init_f32`] in `double`.
#[no_mangle]
pub extern "C" fn friction_commissioning_init_f64(
    out: Option<&mut friction_commissioning_f64>,
    params: Option<&friction_commissioning_params>,
    error: Option<&mut friction_error>,
) -> friction_status {
    new(out, params, error)
}

/// One control period of the routine with measured position `x`: writes
/// the command to apply, the phase and the plateaus measured. Call it in
/// the control interrupt until the phase is `FRICTION_PHASE_DONE` (then
/// `friction_commissioning_result_f32`) or `FRICTION_PHASE_ABORTED` (the
/// command is 0 from then on). A NaN or infinite `x`:
/// `FRICTION_INPUT_REJECTED`, a zero command and the state unchanged (the
/// routine waits; it neither advances nor times out).
#[no_mangle]
pub extern "C" fn friction_commissioning_tick_f32(
    commissioning: Option<&mut friction_commissioning_f32>,
    x: f32,
    out: Option<&mut friction_commissioning_command_f32>,
) -> friction_status {
    let Some(out) = out else {
        return friction_status::FRICTION_NULL_POINTER;
    };
    finish(tick(commissioning, x), out, |command, phase, plateaus| {
        friction_commissioning_command_f32 {
            command,
            phase,
            plateaus,
        }
    })
}

/// [`friction_commissioning_tick_f32`] in `double`.
#[no_mangle]
pub extern "C" fn friction_commissioning_tick_f64(
    commissioning: Option<&mut friction_commissioning_f64>,
    x: f64,
    out: Option<&mut friction_commissioning_command_f64>,
) -> friction_status {
    let Some(out) = out else {
        return friction_status::FRICTION_NULL_POINTER;
    };
    finish(tick(commissioning, x), out, |command, phase, plateaus| {
        friction_commissioning_command_f64 {
            command,
            phase,
            plateaus,
        }
    })
}

/// Where the routine is (a [`friction_phase`] value).
#[no_mangle]
pub extern "C" fn friction_commissioning_phase_f32(
    commissioning: Option<&mut friction_commissioning_f32>,
    phase: Option<&mut i32>,
) -> friction_status {
    read(commissioning, phase, |s| phase_code(s.phase()))
}

/// [`friction_commissioning_phase_f32`] in `double`.
#[no_mangle]
pub extern "C" fn friction_commissioning_phase_f64(
    commissioning: Option<&mut friction_commissioning_f64>,
    phase: Option<&mut i32>,
) -> friction_status {
    read(commissioning, phase, |s| phase_code(s.phase()))
}

/// Why the routine stopped (a [`friction_abort`] value;
/// `FRICTION_ABORT_NONE` unless its phase is `FRICTION_PHASE_ABORTED`).
#[no_mangle]
pub extern "C" fn friction_commissioning_abort_f32(
    commissioning: Option<&mut friction_commissioning_f32>,
    abort: Option<&mut i32>,
) -> friction_status {
    read(commissioning, abort, |s| abort_code(s.abort()))
}

/// [`friction_commissioning_abort_f32`] in `double`.
#[no_mangle]
pub extern "C" fn friction_commissioning_abort_f64(
    commissioning: Option<&mut friction_commissioning_f64>,
    abort: Option<&mut i32>,
) -> friction_status {
    read(commissioning, abort, |s| abort_code(s.abort()))
}

/// Puts the routine back before its first tick (a new run from wherever
/// the axis is), keeping its settings.
#[no_mangle]
pub extern "C" fn friction_commissioning_reset_f32(
    commissioning: Option<&mut friction_commissioning_f32>,
) -> friction_status {
    reset(commissioning)
}

/// [`friction_commissioning_reset_f32`] in `double`.
#[no_mangle]
pub extern "C" fn friction_commissioning_reset_f64(
    commissioning: Option<&mut friction_commissioning_f64>,
) -> friction_status {
    reset(commissioning)
}

/// Fits the LuGre parameters to a finished routine, in `double` (bounded:
/// a few thousand least-squares solves and up to 71 simulations of the
/// presliding hold; run it outside the control interrupt). Refusals, the
/// error naming what to look at: `FRICTION_NOT_FINISHED` (still running),
/// `FRICTION_ABORTED` (naming the limit: `travel`, `duration`, `limit` for
/// a stall, `ramp_rate` for no break-away, `torque_constant` for a
/// reversed sign), `FRICTION_TOO_FEW_PLATEAUS` (fewer than 3 steady
/// plateaus in a direction), `FRICTION_POOR_FIT` (the relative RMS above
/// 10 %: written to `out->residual`, nothing else), `FRICTION_NO_FRICTION`,
/// or a parameter status for a model that does not build. `out` is
/// otherwise written only on `FRICTION_OK`.
#[no_mangle]
pub extern "C" fn friction_commissioning_result_f32(
    commissioning: Option<&mut friction_commissioning_f32>,
    out: Option<&mut friction_commissioned>,
    error: Option<&mut friction_error>,
) -> friction_status {
    result(commissioning, out, error)
}

/// [`friction_commissioning_result_f32`] for a `double` routine.
#[no_mangle]
pub extern "C" fn friction_commissioning_result_f64(
    commissioning: Option<&mut friction_commissioning_f64>,
    out: Option<&mut friction_commissioned>,
    error: Option<&mut friction_error>,
) -> friction_status {
    result(commissioning, out, error)
}
