//! A hardware-free position servo tick: PID with acceleration feed-forward
//! plus the friction compensation the user chooses.
//!
//! Each tick takes the measured position `x` and the setpoint
//! `(x_ref, v_ref, a_ref)` and computes
//!
//! ```text
//! e   = x - x_ref                                  measured minus desired
//! v   = (x - x_prev) / h                           backward difference; 0 on the first tick
//! F^  = compensation(v, e)                         0, a static map F(v), or an observer
//! I  += -ki h e                                    integral action, clamped to ±limit (anti-windup)
//! u   = (J a_ref + F^) / kc - kp e - kd (v - v_ref) + I
//! command = sat(limit, u)
//! ```
//!
//! The PID gains and `limit` are in command units (amperes for a current
//! drive, N m for a torque command), the model terms `J a_ref` and `F^` in
//! force units, turned into command units by the torque constant `kc`
//! (force per command unit; 1 when the command is a torque).
//!
//! The compensation is a type parameter implementing [`Compensation`]:
//! [`NoCompensation`], [`FeedForward`] around any stateless model (e.g.
//! [`CoulombViscous`](crate::CoulombViscous) on the measured velocity), or an
//! [`Observer`] around any [`Observable`] model, stepped with `v` and `e`.
//!
//! Guarantees, for any inputs:
//! - the command is finite and within `±limit`; each term is clamped to
//!   `±4 limit` before the sum, so no finite input can overflow it (a term
//!   that would overflow counts as `±4 limit`); `|v|` and `|e|` are clamped
//!   to [`VELOCITY_LIMIT`](crate::VELOCITY_LIMIT) before use;
//! - a NaN or infinite measured position or setpoint gives the **safe
//!   output** `command = 0`, `friction = 0`, `accepted = false`, and leaves
//!   the integral action, the friction state and the last valid position
//!   untouched: only the count of ticks since that position advances, so the
//!   next valid tick's velocity is the mean over the gap;
//! - **anti-windup**, both ways: the integral action is clamped to
//!   `±limit`, and it is not integrated on a tick where integrating would
//!   push an already saturated command further into saturation
//!   (conditional integration);
//! - no panics, no allocation.
//!
//! Immutable configuration ([`Compensator`]) is split from the mutable state
//! ([`CompensatorState`]): one compensator drives any number of axes.

use crate::bits::Flag;
use crate::fixed_step::FixedStepObservable;
use crate::gain::Gain;
use crate::model::{convert, magnitude, magnitude_or_zero, positive, FrictionModel, ParamError};
use crate::observer::{Observable, Observer};
use crate::scalar::all_finite;
use crate::Scalar;
use core::fmt::Debug;

mod retune;

/// What the compensator adds for friction: an estimate `F^` (force units)
/// from the measured velocity `v` and position error `e = x - x_ref`.
pub trait Compensation<S: Scalar> {
    /// The compensation's own state (`()` for static maps).
    type State: Copy + Default + Debug;

    /// Advances the state by `h` and returns the friction estimate. Inputs
    /// are finite, `|v|` and `|e|` at most [`VELOCITY_LIMIT`](crate::VELOCITY_LIMIT), `h > 0`. It
    /// should return a finite value (the compensator replaces a non-finite
    /// one by 0).
    fn estimate(&self, state: &mut Self::State, v: S, e: S, h: S) -> S;

    /// The sample period the compensation was built for, if it has one (a
    /// fixed-step model): the compensator must then run at that period.
    fn period(&self) -> Option<f64> {
        None
    }

    /// Whether the compensation learns from the friction the compensator
    /// measures ([`Compensation::learn`]); only then does the compensator
    /// keep the positions and commands that measurement needs.
    const LEARNS: bool = false;

    /// Whether [`Compensation::estimate`] uses its `h` argument (a
    /// variable-step model). When it does not (static maps, fixed-step
    /// models), the compensator passes `h` without requiring the scalar to
    /// hold it exactly: a Q16.16 loop at 1 kHz (`h` 0.7 % off) needs this.
    const USES_H: bool = true;

    /// Learns from one measured friction sample (called before
    /// [`Compensation::estimate`], on ticks where a sample exists). The
    /// sample is finite.
    fn learn(&self, _state: &mut Self::State, _sample: FrictionSample<S>) {}

    /// Told the command an accepted tick issued (command units, within the
    /// limit), after [`Compensation::estimate`]: a compensation whose
    /// friction grows with the torque the transmission carries reads its
    /// load input from it.
    #[inline]
    fn commanded(&self, _state: &mut Self::State, _command: S) {}

    /// Makes `state`, a state of the compensation `old`, a state of this one,
    /// between two ticks of a re-tuned drive ([`Compensator::retune`]). An
    /// observer keeps the force its state holds where this model's bounds
    /// allow ([`Observable::carry_over`]); an adaptive law restarts its
    /// estimates from this one's nominal values. The default keeps the state
    /// as it is (right for `()`, a static map's).
    fn carry_over(&self, old: &Self, state: &mut Self::State) {
        let _ = (old, state);
    }
}

/// The friction the compensator measured over the last two periods, for
/// compensations that learn ([`Compensation::LEARNS`]).
///
/// For an inertia `J` driven by `kc u - F` with the command held over each
/// period (zero-order hold), the second difference of three consecutive
/// positions is exactly `h^2 / J` times the mean net force over the two
/// periods, so
///
/// ```text
/// force = kc (u[k-1] + u[k-2]) / 2 - J (x[k] - 2 x[k-1] + x[k-2]) / h^2
/// v     = (x[k] - x[k-2]) / (2 h)
/// ```
///
/// is the mean friction over those periods and the mean velocity. It uses
/// the compensator's `inertia` and `torque_constant` (a wrong inertia
/// leaves an error proportional to the acceleration) and the commands it
/// issued (a drive that applies them late or limits them differently makes
/// the sample wrong by the difference).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FrictionSample<S> {
    /// Mean friction force over the two periods (force units).
    pub force: S,
    /// Mean velocity over the two periods.
    pub v: S,
}

/// No friction compensation: `F^ = 0`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct NoCompensation;

impl<S: Scalar> Compensation<S> for NoCompensation {
    type State = ();
    const USES_H: bool = false;
    #[inline]
    fn estimate(&self, _state: &mut (), _v: S, _e: S, _h: S) -> S {
        S::ZERO
    }
}

/// A stateless friction map as feed-forward on the measured velocity:
/// `F^ = F(v)`, e.g. `FeedForward(CoulombViscous)` for `Fc sign(v) + sigma2 v`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FeedForward<F>(pub F);

impl<S: Scalar, F: FrictionModel<S, State = ()>> Compensation<S> for FeedForward<F> {
    type State = ();
    // a stateless map's force does not depend on the step
    const USES_H: bool = false;
    #[inline]
    fn estimate(&self, state: &mut (), v: S, _e: S, h: S) -> S {
        self.0.step(state, v, h)
    }
}

/// The observer (Canudas de Wit et al. 1995) on the measured velocity and
/// the position error `e = x - x_ref`.
impl<S: Scalar, M: Observable<S>> Compensation<S> for Observer<M, S> {
    type State = M::State;
    #[inline]
    fn estimate(&self, state: &mut M::State, v: S, e: S, h: S) -> S {
        self.step(state, v, e, h)
    }
    fn carry_over(&self, old: &Self, state: &mut M::State) {
        self.model().carry_over(old.model(), state);
    }
}

/// An [`Observer`] on a fixed-step model ([`crate::fixed_step`]) as the
/// compensation: `AtPeriod(Observer::new(model, k)?)`. The compensator's `h`
/// must be the model's period ([`CompensatorParams::build`] checks it). A
/// wrapper, because one blanket `impl` for both observer kinds would overlap.
///
/// ```
/// use friction_core::{AtPeriod, CompensatorParams, CompensatorState, LuGreParams, Observer, ParamError, Setpoint};
/// let model = LuGreParams::OLSSON_1998.build_at::<f32>(1e-3)?;
/// let mut params = CompensatorParams {
///     h: 1e-3, kp: 60.0, ki: 200.0, kd: 1.2,
///     inertia: 0.0023, torque_constant: 1.0, limit: 5.0,
/// };
/// let servo = params.build(AtPeriod(Observer::new(model, 100.0)?))?;
/// let tick = servo.tick(&mut CompensatorState::default(), 0.0, Setpoint { x: 1e-3, v: 0.0, a: 0.0 });
/// assert!(tick.accepted && tick.command > 0.0);
/// params.h = 5e-4; // not the model's period
/// assert_eq!(params.build(AtPeriod(Observer::new(model, 100.0)?)).err(), Some(ParamError::PeriodMismatch));
/// # Ok::<(), ParamError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AtPeriod<O>(pub O);

impl<S: Scalar, M: FixedStepObservable<S>> Compensation<S> for AtPeriod<Observer<M, S>> {
    type State = M::State;
    const USES_H: bool = false;
    #[inline]
    fn estimate(&self, state: &mut M::State, v: S, e: S, _h: S) -> S {
        self.0.step_at(state, v, e)
    }
    fn period(&self) -> Option<f64> {
        Some(self.0.model().period())
    }
    fn carry_over(&self, old: &Self, state: &mut M::State) {
        self.0.model().carry_over(old.0.model(), state);
    }
}

/// Design-time parameters of the servo tick, in `f64`.
///
/// Checked by [`CompensatorParams::validate`]; each error names the
/// parameter.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CompensatorParams {
    /// Sample period `h > 0` (s).
    pub h: f64,
    /// Proportional gain `kp >= 0` (command units per unit of position).
    pub kp: f64,
    /// Integral gain `ki >= 0` (command units per unit of position and second).
    pub ki: f64,
    /// Derivative gain `kd >= 0` (command units per unit of velocity).
    pub kd: f64,
    /// Inertia (or mass) `J >= 0` of the acceleration feed-forward `J a_ref`.
    pub inertia: f64,
    /// Torque constant `kc > 0`: force per command unit (1 for a torque command).
    pub torque_constant: f64,
    /// Output limit `limit > 0` (command units): the command stays within `±limit`.
    pub limit: f64,
}

impl CompensatorParams {
    /// Checks `h > 0`, gains and `inertia` `>= 0`, `torque_constant > 0`,
    /// `limit > 0`, all finite and (where not 0) within
    /// [`PARAM_RANGE`](crate::PARAM_RANGE), so that the ratios the tick
    /// carries (`J/kc`, `ki h`, `1/h`) stay normal numbers.
    pub fn validate(&self) -> Result<(), ParamError> {
        magnitude("h", self.h)?;
        magnitude_or_zero("kp", self.kp)?;
        magnitude_or_zero("ki", self.ki)?;
        magnitude_or_zero("kd", self.kd)?;
        magnitude_or_zero("inertia", self.inertia)?;
        magnitude("torque_constant", self.torque_constant)?;
        magnitude("limit", self.limit)?;
        Ok(())
    }

    /// Validates and builds the run-time tick around `compensation`.
    /// Besides [`validate`](Self::validate), rejects values the scalar
    /// cannot hold: `h` (only for a compensation that steps by it,
    /// [`Compensation::USES_H`]), and `32 limit`, the headroom that keeps
    /// the sum of the clamped terms finite. The constant gains (`1/h`,
    /// `kp`, `ki h`, `kd`, `J/kc`, `1/kc`) are carried as a mantissa and a
    /// power of two, so that fixed point holds each within 0.1 % from about
    /// `2.3e-7` to `2.7e8` (Q16.16 alone: 0.015 to 32767): a Q16.16 servo
    /// builds for 1 kHz to 40 kHz loops and inertias down to `1e-6`.
    ///
    /// ```
    /// use friction_core::{CompensatorParams, NoCompensation, ParamError};
    /// let mut p = CompensatorParams {
    ///     h: 1e-3, kp: 60.0, ki: 200.0, kd: 1.2,
    ///     inertia: 0.0023, torque_constant: 1.0, limit: 5.0,
    /// };
    /// p.kd = -1.0;
    /// assert_eq!(p.build::<f32, _>(NoCompensation).err(), Some(ParamError::Negative("kd")));
    /// ```
    pub fn build<S: Scalar, C: Compensation<S>>(
        &self,
        compensation: C,
    ) -> Result<Compensator<S, C>, ParamError> {
        self.validate()?;
        runs_at(&compensation, self.h)?;
        let limit = convert("limit", self.limit)?;
        convert::<S>("limit", 32.0 * self.limit)?;
        let h = if C::USES_H {
            convert("h", self.h)?
        } else {
            S::from_f64(self.h)
        };
        let zero = Gain::new("inertia", 0.0)?;
        // 1/kc first: a torque constant beyond the gains' range is named as
        // such, not as the inertia of the ratio J/kc it also spoils
        let inv_kc = Gain::new("torque_constant", 1.0 / self.torque_constant)?;
        Ok(Compensator {
            compensation,
            h,
            inv_h: Gain::new("h", 1.0 / self.h)?,
            kp: Gain::new("kp", self.kp)?,
            ki_h: Gain::new("ki", self.ki * self.h)?,
            kd: Gain::new("kd", self.kd)?,
            feed_forward: Gain::new("inertia", self.inertia / self.torque_constant)?,
            inv_kc,
            limit,
            term_limit: convert("limit", 4.0 * self.limit)?,
            signal_limit: S::VELOCITY_LIMIT,
            accel_ff: if C::LEARNS {
                Gain::new(
                    "inertia",
                    self.inertia / (self.torque_constant * self.h * self.h),
                )?
            } else {
                zero
            },
            kc: if C::LEARNS {
                Gain::new("torque_constant", self.torque_constant)?
            } else {
                zero
            },
            velocity_blend: S::ONE,
            filter_velocity: Flag::new(false),
            observer_alpha: S::ZERO,
            observer_beta: zero,
            observer_gamma: zero,
            observer_h: zero,
            inv_inertia: zero,
            params: *self,
        })
    }
}

/// Checks that `compensation` runs at the period `h` (s), if it has one
/// ([`Compensation::period`]).
fn runs_at<S: Scalar, C: Compensation<S>>(compensation: &C, h: f64) -> Result<(), ParamError> {
    match compensation.period() {
        Some(period) if (period - h).abs() > 1e-9 * h => Err(ParamError::PeriodMismatch),
        _ => Ok(()),
    }
}

/// The desired motion at a tick.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Setpoint<S> {
    /// Position `x_ref`.
    pub x: S,
    /// Velocity `v_ref` (the derivative term acts on `v - v_ref`).
    pub v: S,
    /// Acceleration `a_ref` (feed-forward `J a_ref / kc`).
    pub a: S,
}

/// What one tick produced.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Tick<S> {
    /// The command, finite and within `±limit` (command units).
    pub command: S,
    /// The friction estimate or feed-forward `F^` (force units), included
    /// in the command as `F^ / kc` (before the limit).
    pub friction: S,
    /// `false` when an input was NaN or infinite: the safe output (all zero).
    pub accepted: bool,
}

/// The mutable state of one servo axis; `Default` is before the first tick.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CompensatorState<S, T> {
    integral: S,
    last_x: S,
    since_last: u32,
    friction: T,
    /// The filtered velocity (with a velocity filter).
    velocity: S,
    /// For compensations that learn: the position before `last_x`, the last
    /// two commands, and how many consecutive valid ticks preceded (at most 2).
    x_before: S,
    command: S,
    command_before: S,
    run: u8,
    /// The velocity observer's position estimate and the acceleration it
    /// predicts over the next period (with a velocity observer).
    x_hat: S,
    accel: S,
    /// The velocity observer's estimate of the acceleration the command
    /// and the friction estimate do not explain.
    disturbance: S,
}

impl<S: Scalar, T> CompensatorState<S, T> {
    /// The integral action `I` (command units), within `±limit`.
    pub fn integral(&self) -> S {
        self.integral
    }

    /// The last accepted measured position, if any.
    pub fn last_position(&self) -> Option<S> {
        (self.since_last > 0).then_some(self.last_x)
    }

    /// The compensation's state (e.g. the observer's `z^`).
    pub fn friction(&self) -> &T {
        &self.friction
    }
}

/// The built servo tick: immutable, shared by any number of
/// [`CompensatorState`]s.
///
/// ```
/// use friction_core::{
///     CompensatorParams, CompensatorState, LuGreParams, Observer, Setpoint,
/// };
/// let model = LuGreParams::CANUDAS_1995.build::<f32>()?;
/// let servo = CompensatorParams {
///     h: 1e-3, kp: 2e4, ki: 1e5, kd: 200.0,
///     inertia: 1.0, torque_constant: 1.0, limit: 20.0,
/// }
/// .build(Observer::new(model, 100.0)?)?;
/// let mut state = CompensatorState::default();
/// // measured 1 µm behind a reference moving at 1 mm/s
/// let r = Setpoint { x: 1e-6, v: 1e-3, a: 0.0 };
/// let tick = servo.tick(&mut state, 0.0, r);
/// assert!(tick.accepted && tick.command > 0.0 && tick.command <= 20.0);
/// // a NaN measurement: safe output, state untouched
/// let before = state;
/// let tick = servo.tick(&mut state, f32::NAN, r);
/// assert_eq!((tick.command, tick.accepted), (0.0, false));
/// assert_eq!(state.integral(), before.integral());
/// # Ok::<(), friction_core::ParamError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Compensator<S, C> {
    compensation: C,
    h: S,
    inv_h: Gain<S>,
    kp: Gain<S>,
    ki_h: Gain<S>,
    kd: Gain<S>,
    feed_forward: Gain<S>,
    inv_kc: Gain<S>,
    limit: S,
    term_limit: S,
    signal_limit: S,
    /// `J / (kc h^2)` and `kc`, for the friction samples of compensations
    /// that learn (0 otherwise).
    accel_ff: Gain<S>,
    kc: Gain<S>,
    /// The velocity filter's `h / (tau + h)` (`1`: no filter).
    velocity_blend: S,
    filter_velocity: Flag,
    /// The velocity observer's position and velocity gains `alpha`,
    /// `beta / h` (`alpha = 0`: no observer), its period and `1 / J`.
    observer_alpha: S,
    observer_beta: Gain<S>,
    observer_gamma: Gain<S>,
    observer_h: Gain<S>,
    inv_inertia: Gain<S>,
    params: CompensatorParams,
}

/// `k x` clamped to `±b`; 0 when `k = 0` (so `0 * inf` cannot give NaN).
#[inline]
fn term<S: Scalar>(k: Gain<S>, x: S, b: S) -> S {
    if k.is_zero() {
        S::ZERO
    } else {
        k.times(x).sat(b)
    }
}

/// [`term`] for a finite `x`, where `0 x = 0` needs no test: floating point
/// forms the product and the clamp alone (a test and a branch fewer a term
/// in the tick); fixed point still skips the product when `k = 0` (its
/// product is several 32-bit products on a core without a 64-bit multiply).
#[inline]
fn term_of_finite<S: Scalar>(k: Gain<S>, x: S, b: S) -> S {
    if S::SCALES_FORCES && k.is_zero() {
        S::ZERO
    } else {
        k.times(x).sat(b)
    }
}

impl<S: Scalar, C: Compensation<S>> Compensator<S, C> {
    /// The compensation.
    pub fn compensation(&self) -> &C {
        &self.compensation
    }

    /// The parameters it was built from.
    pub fn params(&self) -> &CompensatorParams {
        &self.params
    }

    /// The output limit.
    pub fn limit(&self) -> S {
        self.limit
    }

    /// Low-passes the measured velocity (the backward difference) with a
    /// first-order filter of cut-off `cutoff_hz` (Hz) before the
    /// compensation and the derivative term see it:
    /// `v_f += h / (tau + h) (v - v_f)`, `tau = 1 / (2 pi cutoff)`. With a
    /// quantized encoder the backward difference jumps by whole counts per
    /// period; the filter trades that noise for phase lag. `cutoff_hz`
    /// must be finite and `> 0`. Replaces a velocity observer.
    ///
    /// ```
    /// use friction_core::{CompensatorParams, NoCompensation, ParamError};
    /// let p = CompensatorParams { h: 1e-3, kp: 60.0, ki: 200.0, kd: 1.2,
    ///     inertia: 0.0023, torque_constant: 1.0, limit: 5.0 };
    /// let servo = p.build::<f32, _>(NoCompensation)?.with_velocity_filter(200.0)?;
    /// assert_eq!(p.build::<f32, _>(NoCompensation)?.with_velocity_filter(0.0).err(),
    ///     Some(ParamError::NotPositive("velocity_cutoff")));
    /// # let _ = servo;
    /// # Ok::<(), ParamError>(())
    /// ```
    pub fn with_velocity_filter(self, cutoff_hz: f64) -> Result<Self, ParamError> {
        positive("velocity_cutoff", cutoff_hz)?;
        let tau = 1.0 / (2.0 * core::f64::consts::PI * cutoff_hz);
        let h = self.params.h;
        Ok(Self {
            velocity_blend: convert("velocity_cutoff", h / (tau + h))?,
            filter_velocity: Flag::new(true),
            observer_alpha: S::ZERO,
            ..self
        })
    }

    /// Estimates the velocity with an observer driven by the command and
    /// corrected by the measured position, as drive firmware does on coarse
    /// encoders, instead of the backward difference (which jumps by whole
    /// counts per period). Between ticks the observer predicts the motion
    /// of the inertia `J` under the last command and friction estimate,
    /// `a = (kc u - F^) / J`, plus a disturbance `d^` it estimates (what the
    /// prediction misses: a friction error, a load, gravity); each tick it
    /// corrects by the innovation `x - x^` with the gains of a critically
    /// damped (fading-memory) alpha-beta-gamma tracker of bandwidth
    /// `bandwidth_hz` (Brookner 1998, Tracking and Kalman Filtering Made
    /// Easy, Ch. 1):
    ///
    /// ```text
    /// x^ <- x^ + h v^ + h^2 (a + d^) / 2,   v^ <- v^ + h (a + d^)      prediction
    /// x^ <- x^ + alpha i,  v^ <- v^ + beta / h i,  d^ <- d^ + 2 gamma / h^2 i,   i = x - x^
    /// theta = exp(-2 pi bandwidth h)
    /// alpha = 1 - theta^3, beta = 1.5 (1 - theta)^2 (1 + theta), gamma = 0.5 (1 - theta)^3
    /// ```
    ///
    /// Needs `J > 0`; `bandwidth_hz` finite, `> 0` and below half the sample
    /// rate. Replaces a velocity filter.
    ///
    /// ```
    /// use friction_core::{CompensatorParams, NoCompensation, ParamError};
    /// let p = CompensatorParams { h: 1e-3, kp: 60.0, ki: 200.0, kd: 1.2,
    ///     inertia: 0.0023, torque_constant: 1.0, limit: 5.0 };
    /// let servo = p.build::<f32, _>(NoCompensation)?.with_velocity_observer(50.0)?;
    /// assert_eq!(p.build::<f32, _>(NoCompensation)?.with_velocity_observer(600.0).err(),
    ///     Some(ParamError::NotBelow { name: "velocity_observer", limit: "half the sample rate" }));
    /// # let _ = servo;
    /// # Ok::<(), ParamError>(())
    /// ```
    pub fn with_velocity_observer(self, bandwidth_hz: f64) -> Result<Self, ParamError> {
        positive("velocity_observer", bandwidth_hz)?;
        let h = self.params.h;
        if bandwidth_hz * h >= 0.5 {
            return Err(ParamError::NotBelow {
                name: "velocity_observer",
                limit: "half the sample rate",
            });
        }
        positive("inertia", self.params.inertia)?;
        let theta = libm::exp(-2.0 * core::f64::consts::PI * bandwidth_hz * h);
        let alpha = 1.0 - theta * theta * theta;
        let beta = 1.5 * (1.0 - theta) * (1.0 - theta) * (1.0 + theta);
        let gamma = 0.5 * (1.0 - theta) * (1.0 - theta) * (1.0 - theta);
        Ok(Self {
            observer_alpha: convert("velocity_observer", alpha)?,
            observer_beta: Gain::new("velocity_observer", beta / h)?,
            observer_gamma: Gain::new("velocity_observer", 2.0 * gamma / (h * h))?,
            observer_h: Gain::new("h", h)?,
            inv_inertia: Gain::new("inertia", 1.0 / self.params.inertia)?,
            kc: Gain::new("torque_constant", self.params.torque_constant)?,
            velocity_blend: S::ONE,
            filter_velocity: Flag::new(false),
            ..self
        })
    }

    /// One tick with measured position `x` towards the setpoint `r`; see the
    /// [module documentation](self) for the control law and the guarantees.
    // Always inlined, with the helpers it calls: it is the interrupt's hot
    // path, and a second caller of the same instance (commissioning ticks the
    // uncompensated servo) must not move it out of line in the servo tick.
    #[inline(always)]
    pub fn tick(&self, state: &mut CompensatorState<S, C::State>, x: S, r: Setpoint<S>) -> Tick<S> {
        if !all_finite([x, r.x, r.v, r.a]) {
            Self::skip(state);
            return Tick {
                command: S::ZERO,
                friction: S::ZERO,
                accepted: false,
            };
        }
        let v = self.velocity(state, x);
        let e = (x - r.x).sat(self.signal_limit);
        if C::LEARNS {
            self.measure(state, x);
        }
        let f = self
            .compensation
            .estimate(&mut state.friction, v, e, self.h);
        let f = if f.is_finite() { f } else { S::ZERO };

        let b = self.term_limit;
        // r.a, f and e are finite here; v - r.v can overflow to infinity
        let base = term_of_finite(self.feed_forward, r.a, b) + term_of_finite(self.inv_kc, f, b)
            - term_of_finite(self.kp, e, b)
            - term(self.kd, v - r.v, b);
        let candidate = (state.integral - term_of_finite(self.ki_h, e, self.limit)).sat(self.limit);
        let trial = base + candidate;
        let winds_up = (trial > self.limit && candidate > state.integral)
            || (trial < -self.limit && candidate < state.integral);
        if !winds_up {
            state.integral = candidate;
        }
        state.last_x = x;
        state.since_last = 1;
        let command = (base + state.integral).sat(self.limit);
        self.issued(state, command, f);
        Tick {
            command,
            friction: f,
            accepted: true,
        }
    }

    /// One tick of listening: the drive applied `command` (command units),
    /// from its own controller or a recording, instead of a command of this
    /// compensator. The measured velocity, the friction sample and the
    /// compensation's step are those of [`tick`](Self::tick) with `e = x -
    /// r.x`; the compensation is told `command` (clamped to `±limit`) and
    /// learns from the samples it makes, but the integral is not touched.
    /// Returns the friction estimate `F^` (force units), 0 for a non-finite
    /// input, which leaves the state as `tick` leaves it.
    ///
    /// This runs an estimator beside a controller that is not this one (a
    /// drive's own loop, a commissioning routine) and replays logged runs
    /// as the drive saw them, sample by sample.
    ///
    /// ```
    /// use friction_core::{CompensatorParams, CompensatorState, RlsParams, Setpoint};
    /// let p = CompensatorParams { h: 1e-3, kp: 0.0, ki: 0.0, kd: 0.0,
    ///     inertia: 2.0, torque_constant: 1.0, limit: 100.0 };
    /// let servo = p.build::<f64, _>(RlsParams::new(0.1, 50.0).build::<f64>()?)?;
    /// let mut state = CompensatorState::default();
    /// // a mass of 2 sliding at 0.1 against 10 of friction, held by a 10 push
    /// for k in 0..3000 {
    ///     let x = 0.1 * f64::from(k) * 1e-3;
    ///     servo.listen(&mut state, x, Setpoint::default(), 10.0);
    /// }
    /// let estimate = servo.listen(&mut state, 0.3, Setpoint::default(), 10.0);
    /// assert!((estimate - 10.0).abs() < 0.1);
    /// # Ok::<(), friction_core::ParamError>(())
    /// ```
    pub fn listen(
        &self,
        state: &mut CompensatorState<S, C::State>,
        x: S,
        r: Setpoint<S>,
        command: S,
    ) -> S {
        if !all_finite([x, r.x, command]) {
            Self::skip(state);
            return S::ZERO;
        }
        let v = self.velocity(state, x);
        let e = (x - r.x).sat(self.signal_limit);
        if C::LEARNS {
            self.measure(state, x);
        }
        let f = self
            .compensation
            .estimate(&mut state.friction, v, e, self.h);
        let f = if f.is_finite() { f } else { S::ZERO };
        state.last_x = x;
        state.since_last = 1;
        self.issued(state, command.sat(self.limit), f);
        f
    }

    /// A tick with a non-finite input: the gap counts toward the next
    /// velocity, and no friction sample spans it.
    #[inline(always)]
    fn skip(state: &mut CompensatorState<S, C::State>) {
        if state.since_last > 0 {
            state.since_last = state.since_last.saturating_add(1);
        }
        if C::LEARNS {
            state.run = 0;
        }
    }

    /// After an accepted tick: the compensation told the `command` issued,
    /// the velocity observer's next acceleration from it and the friction
    /// estimate `f`, and the command kept for the next friction sample.
    #[inline(always)]
    fn issued(&self, state: &mut CompensatorState<S, C::State>, command: S, f: S) {
        self.compensation.commanded(&mut state.friction, command);
        self.predict_acceleration(state, command, f);
        if C::LEARNS {
            state.command_before = state.command;
            state.command = command;
        }
    }

    /// The measured velocity at position `x`: the backward difference over
    /// the ticks since the last accepted one (0 at the first), through the
    /// velocity filter if there is one.
    #[inline(always)]
    fn velocity(&self, state: &mut CompensatorState<S, C::State>, x: S) -> S {
        if self.observer_alpha != S::ZERO {
            return self.observe_velocity(state, x);
        }
        let mut v = match state.since_last {
            0 => S::ZERO,
            1 => self.inv_h.times(x - state.last_x),
            n => self.inv_h.times(x - state.last_x) / S::from_f64(f64::from(n)),
        }
        .sat(self.signal_limit);
        if self.filter_velocity.get() {
            v = if state.since_last == 0 {
                S::ZERO
            } else {
                state.velocity + self.velocity_blend * (v - state.velocity)
            };
            state.velocity = v;
        }
        v
    }

    /// The velocity observer's estimate at measured position `x` (see
    /// [`with_velocity_observer`](Self::with_velocity_observer)): the
    /// prediction over the ticks since the last accepted one, corrected by
    /// the innovation `x - x^`.
    fn observe_velocity(&self, state: &mut CompensatorState<S, C::State>, x: S) -> S {
        if state.since_last == 0 {
            state.x_hat = x;
            state.velocity = S::ZERO;
            return S::ZERO;
        }
        let half = S::from_f64(0.5);
        // a gap of n ticks is predicted as one step of n periods
        let n = S::from_f64(f64::from(state.since_last.min(1 << 20)));
        let dv = n * self.observer_h.times(state.accel + state.disturbance);
        let predicted_x = state.x_hat + n * self.observer_h.times(state.velocity + half * dv);
        let predicted_v = state.velocity + dv;
        let innovation = (x - predicted_x).sat(self.signal_limit);
        state.x_hat = predicted_x + self.observer_alpha * innovation;
        state.velocity =
            (predicted_v + self.observer_beta.times(innovation)).sat(self.signal_limit);
        state.disturbance =
            (state.disturbance + self.observer_gamma.times(innovation)).sat(self.signal_limit);
        state.velocity
    }

    /// With a velocity observer: the acceleration `(kc u - F^) / J` the
    /// command `u` and the friction estimate `f` give over the next period.
    #[inline(always)]
    fn predict_acceleration(&self, state: &mut CompensatorState<S, C::State>, command: S, f: S) {
        if self.observer_alpha != S::ZERO {
            let force = self.kc.times(command) - f;
            state.accel = self.inv_inertia.times(force).sat(self.signal_limit);
        }
    }

    /// For a compensation that learns: the friction sample ending at `x`
    /// (when the two ticks before were accepted in a row) passed to
    /// [`Compensation::learn`], and the positions kept for the next one.
    #[inline(always)]
    fn measure(&self, state: &mut CompensatorState<S, C::State>, x: S) {
        if state.run >= 2 {
            if let Some(sample) = self.sample(state, x) {
                self.compensation.learn(&mut state.friction, sample);
            }
        }
        state.run = if state.since_last == 1 {
            state.run.saturating_add(1).min(2)
        } else {
            1
        };
        state.x_before = state.last_x;
    }

    /// The friction sample over the last two periods (see
    /// [`FrictionSample`]), from the new position `x` and the state's last
    /// two positions and commands; `None` if it is not finite.
    #[inline(always)]
    fn sample(&self, state: &CompensatorState<S, C::State>, x: S) -> Option<FrictionSample<S>> {
        let second = x - state.last_x - (state.last_x - state.x_before);
        let half = S::from_f64(0.5);
        let command = half * (state.command + state.command_before);
        let force = self.kc.times(command - self.accel_ff.times(second));
        let v = self.inv_h.times(half * (x - state.x_before));
        (force.is_finite() && v.is_finite()).then_some(FrictionSample { force, v })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{CoulombViscous, CoulombViscousParams, LuGre, LuGreParams, LuGreState};
    use proptest::prelude::*;

    fn params() -> CompensatorParams {
        CompensatorParams {
            h: 1e-3,
            kp: 60.0,
            ki: 200.0,
            kd: 1.2,
            inertia: 0.0023,
            torque_constant: 1.02,
            limit: 5.0,
        }
    }

    fn olsson() -> LuGreParams {
        LuGreParams::OLSSON_1998
    }

    #[test]
    fn invalid_parameters_are_named() {
        let p = params();
        let check = |q: CompensatorParams, e: ParamError| {
            assert_eq!(q.build::<f64, _>(NoCompensation).err(), Some(e), "{q:?}");
        };
        check(
            CompensatorParams { h: 0.0, ..p },
            ParamError::NotPositive("h"),
        );
        check(
            CompensatorParams { h: f64::NAN, ..p },
            ParamError::NotFinite("h"),
        );
        check(
            CompensatorParams { kp: -1.0, ..p },
            ParamError::Negative("kp"),
        );
        check(
            CompensatorParams {
                ki: f64::INFINITY,
                ..p
            },
            ParamError::NotFinite("ki"),
        );
        check(
            CompensatorParams { kd: -0.1, ..p },
            ParamError::Negative("kd"),
        );
        check(
            CompensatorParams { inertia: -1.0, ..p },
            ParamError::Negative("inertia"),
        );
        check(
            CompensatorParams {
                torque_constant: 0.0,
                ..p
            },
            ParamError::NotPositive("torque_constant"),
        );
        check(
            CompensatorParams { limit: 0.0, ..p },
            ParamError::NotPositive("limit"),
        );
        check(
            CompensatorParams {
                limit: f64::INFINITY,
                ..p
            },
            ParamError::NotFinite("limit"),
        );
        assert_eq!(
            CompensatorParams { limit: 1e38, ..p }
                .build::<f32, _>(NoCompensation)
                .err(),
            Some(ParamError::OutOfRange("limit"))
        );
        // 1/h = 1e300: h is beyond PARAM_RANGE, whatever steps by it
        assert_eq!(
            CompensatorParams { h: 1e-300, ..p }
                .build::<f32, _>(NoCompensation)
                .err(),
            Some(ParamError::OutOfRange("h"))
        );
        let lugre = LuGreParams::OLSSON_1998.build::<f32>().unwrap();
        assert_eq!(
            CompensatorParams { h: 1e-300, ..p }
                .build::<f32, _>(crate::Observer::new(lugre, 20.0).unwrap())
                .err(),
            Some(ParamError::OutOfRange("h"))
        );
        // zero gains and inertia are valid
        let zero = CompensatorParams {
            kp: 0.0,
            ki: 0.0,
            kd: 0.0,
            inertia: 0.0,
            ..p
        };
        assert!(zero.build::<f32, _>(NoCompensation).is_ok());
    }

    #[test]
    fn control_law_terms() {
        let p = CompensatorParams {
            ki: 0.0,
            ..params()
        };
        let c = p.build::<f64, _>(NoCompensation).unwrap();
        let mut s = CompensatorState::default();
        // first tick: v = 0, so the derivative term is kd v_ref
        let r = Setpoint {
            x: 0.01,
            v: 0.1,
            a: 2.0,
        };
        let t = c.tick(&mut s, 0.0, r);
        let expected = 0.0023 * 2.0 / 1.02 + 60.0 * 0.01 + 1.2 * 0.1;
        assert!((t.command - expected).abs() < 1e-12, "{t:?}");
        assert_eq!(t.friction, 0.0);
        // second tick: backward difference
        let t = c.tick(
            &mut s,
            1e-4,
            Setpoint {
                x: 1e-4,
                v: 0.0,
                a: 0.0,
            },
        );
        assert!((t.command - (-1.2 * 0.1)).abs() < 1e-12, "{t:?}");
        assert_eq!(s.last_position(), Some(1e-4));
    }

    #[test]
    fn static_feed_forward_on_measured_velocity() {
        let map: CoulombViscous<f64> = CoulombViscousParams {
            fc: 0.28,
            sigma2: 0.0176,
        }
        .build()
        .unwrap();
        let p = CompensatorParams {
            kp: 0.0,
            ki: 0.0,
            kd: 0.0,
            inertia: 0.0,
            ..params()
        };
        let c = p.build(FeedForward(map)).unwrap();
        let mut s = CompensatorState::default();
        let r = Setpoint::default();
        assert_eq!(c.tick(&mut s, 0.0, r).friction, 0.0); // first tick: v = 0
        let t = c.tick(&mut s, -2e-3, r); // v = -2 rad/s
        assert!((t.friction - map.force(-2.0)).abs() < 1e-12);
        assert!((t.command - map.force(-2.0) / 1.02).abs() < 1e-12);
    }

    /// The velocity observer on a 12-bit encoder (4096 counts a turn): a
    /// PD loop on a sine, the plant the loop's inertia and torque constant
    /// with Coulomb friction the compensation does not know (the
    /// observer's disturbance state takes it up). Its velocity error is at
    /// most a fifth of the backward difference's in f64 and f32, and at most
    /// 0.4 of it in Q16.16.
    #[test]
    fn the_velocity_observer_beats_the_backward_difference_on_a_coarse_encoder() {
        fn run<S: Scalar>() -> (f64, f64) {
            let p = params();
            let c = p
                .build::<S, _>(NoCompensation)
                .unwrap()
                .with_velocity_observer(50.0)
                .unwrap();
            let q = 2.0 * core::f64::consts::PI / 4096.0;
            let mut s = CompensatorState::default();
            let (mut x, mut v, mut last) = (0.0f64, 0.0f64, 0.0f64);
            let (mut observed, mut differenced, mut n) = (0.0, 0.0, 0.0);
            let w = 2.0 * core::f64::consts::PI * 0.5;
            for k in 0..4000 {
                let t = k as f64 * 1e-3;
                let r = Setpoint {
                    x: S::from_f64(libm::sin(w * t)),
                    v: S::from_f64(w * libm::cos(w * t)),
                    a: S::from_f64(-w * w * libm::sin(w * t)),
                };
                let measured = libm::round(x / q) * q;
                let u = c.tick(&mut s, S::from_f64(measured), r).command.to_f64();
                if k > 1000 {
                    let difference = (measured - last) / 1e-3;
                    observed += (s.velocity.to_f64() - v) * (s.velocity.to_f64() - v);
                    differenced += (difference - v) * (difference - v);
                    n += 1.0;
                }
                last = measured;
                for _ in 0..10 {
                    let f = 0.1 * libm::tanh(v / 1e-3);
                    v += 1e-4 * (p.torque_constant * u - f) / p.inertia;
                    x += 1e-4 * v;
                }
            }
            (libm::sqrt(observed / n), libm::sqrt(differenced / n))
        }
        for (observed, differenced) in [run::<f64>(), run::<f32>()] {
            assert!(observed < 0.2 * differenced, "{observed} {differenced}");
        }
        #[cfg(feature = "fixed")]
        {
            // Q16.16 measured 0.36x (f64 and f32 0.17x): bounded at 0.4x
            let (observed, differenced) = run::<crate::Fixed32>();
            assert!(
                observed < 0.4 * differenced,
                "Q16.16: {observed} {differenced}"
            );
        }
    }

    /// The observer keeps its state through NaN and infinite positions and
    /// stays finite for hostile finite ones.
    #[test]
    fn the_velocity_observer_is_safe_for_hostile_inputs() {
        let c = params()
            .build::<f32, _>(NoCompensation)
            .unwrap()
            .with_velocity_observer(100.0)
            .unwrap();
        let mut s = CompensatorState::default();
        c.tick(&mut s, 0.0, Setpoint::default());
        c.tick(&mut s, 1e-3, Setpoint::default());
        let before = s;
        for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            c.tick(&mut s, bad, Setpoint::default());
        }
        assert_eq!(
            (s.x_hat, s.velocity, s.disturbance),
            (before.x_hat, before.velocity, before.disturbance)
        );
        let mut rng = crate::test_rng::xorshift64(5);
        for _ in 0..100_000 {
            let r = rng();
            let x = match r % 4 {
                0 => f32::MAX,
                1 => -f32::MAX,
                2 => 0.0,
                _ => ((r >> 11) as f64 / (1u64 << 53) as f64 * 2e3 - 1e3) as f32,
            };
            let tick = c.tick(&mut s, x, Setpoint::default());
            assert!(tick.command.is_finite() && tick.command.abs() <= 5.0);
            assert!(s.velocity.is_finite() && s.x_hat.is_finite() && s.disturbance.is_finite());
        }
        assert_eq!(
            params()
                .build::<f32, _>(NoCompensation)
                .unwrap()
                .with_velocity_observer(f64::NAN)
                .err(),
            Some(ParamError::NotFinite("velocity_observer"))
        );
    }

    #[test]
    fn non_finite_inputs_give_the_safe_output_and_keep_the_state() {
        let m = olsson().build::<f32>().unwrap();
        let c = params().build(Observer::new(m, 20.0).unwrap()).unwrap();
        let mut s = CompensatorState::default();
        for k in 0..200 {
            let x = 0.01 * (k as f32 * 0.05).sin();
            c.tick(
                &mut s,
                x,
                Setpoint {
                    x: 0.0,
                    v: 0.0,
                    a: 0.0,
                },
            );
        }
        let before = s;
        let good = Setpoint {
            x: 0.1,
            v: 0.2,
            a: 0.3,
        };
        for (x, r) in [
            (f32::NAN, good),
            (f32::INFINITY, good),
            (
                0.0,
                Setpoint {
                    x: f32::NAN,
                    ..good
                },
            ),
            (
                0.0,
                Setpoint {
                    x: f32::NEG_INFINITY,
                    ..good
                },
            ),
            (
                0.0,
                Setpoint {
                    v: f32::NAN,
                    ..good
                },
            ),
            (
                0.0,
                Setpoint {
                    a: f32::INFINITY,
                    ..good
                },
            ),
        ] {
            let t = c.tick(&mut s, x, r);
            assert_eq!(
                t,
                Tick {
                    command: 0.0,
                    friction: 0.0,
                    accepted: false
                }
            );
            assert_eq!(s.integral(), before.integral());
            assert_eq!(s.friction(), before.friction());
            assert_eq!(s.last_position(), before.last_position());
        }
        // the first valid tick after the gap differences over the whole gap
        let p = CompensatorParams {
            kp: 0.0,
            ki: 0.0,
            inertia: 0.0,
            ..params()
        };
        let c = p.build::<f64, _>(NoCompensation).unwrap();
        let mut s = CompensatorState::default();
        c.tick(&mut s, 0.0, Setpoint::default());
        c.tick(&mut s, f64::NAN, Setpoint::default());
        c.tick(&mut s, f64::NAN, Setpoint::default());
        let t = c.tick(&mut s, 3e-3, Setpoint::default()); // 3 periods: v = 1
        assert!((t.command + 1.2).abs() < 1e-12, "{t:?}");
        // before any valid position, invalid ticks keep the first-tick rule
        let mut s = CompensatorState::default();
        c.tick(&mut s, f64::NAN, Setpoint::default());
        assert_eq!(s.last_position(), None);
        assert_eq!(c.tick(&mut s, 5.0, Setpoint::default()).command, 0.0);
    }

    #[test]
    fn integral_is_clamped_and_does_not_wind_up() {
        // integral alone: grows to the limit and stops there
        let p = CompensatorParams {
            kp: 0.0,
            kd: 0.0,
            inertia: 0.0,
            ..params()
        };
        let c = p.build::<f64, _>(NoCompensation).unwrap();
        let mut s = CompensatorState::default();
        let behind = Setpoint {
            x: 1.0,
            v: 0.0,
            a: 0.0,
        };
        for _ in 0..100_000 {
            assert!(c.tick(&mut s, 0.0, behind).command <= 5.0);
        }
        assert_eq!(s.integral(), 5.0);
        // the error reverses: the command leaves saturation on the first tick
        let t = c.tick(
            &mut s,
            0.0,
            Setpoint {
                x: -1.0,
                v: 0.0,
                a: 0.0,
            },
        );
        assert!(t.command < 5.0, "{t:?}");

        // saturated by the proportional term: no integration at all
        let c = params().build::<f64, _>(NoCompensation).unwrap();
        let mut s = CompensatorState::default();
        for _ in 0..10_000 {
            assert_eq!(c.tick(&mut s, 0.0, behind).command, 5.0);
        }
        assert_eq!(s.integral(), 0.0);
        // small reversed error: the command follows at once (it would stay at
        // +5 for a long time had the integral wound up to 10 s x 200 x 1)
        let t = c.tick(
            &mut s,
            0.0,
            Setpoint {
                x: -0.01,
                v: 0.0,
                a: 0.0,
            },
        );
        assert!(t.command < 0.0, "{t:?}");
    }

    /// Simulates `J x'' = kc u - c x'` under the compensator from `x0 = 1`
    /// towards 0 (10 substeps per tick); returns `|x|` at the end.
    fn settle(p: CompensatorParams, damping: f64, seconds: f64) -> f64 {
        let ctl = p.build::<f64, _>(NoCompensation).unwrap();
        let mut s = CompensatorState::default();
        let (mut x, mut v) = (1.0f64, 0.0f64);
        let hs = p.h / 10.0;
        for _ in 0..(seconds / p.h) as usize {
            let u = ctl.tick(&mut s, x, Setpoint::default()).command;
            for _ in 0..10 {
                v += hs * (p.torque_constant * u - damping * v) / p.inertia;
                x += hs * v;
            }
        }
        x.abs() + v.abs()
    }

    #[test]
    fn a_pure_p_controller_converges_on_a_double_integrator() {
        // J = 1, kc = 1, kp = 4: without damping a P loop only oscillates
        // (poles at ±2j), so the plant has some (c = 1, damping ratio 1/4).
        let p = CompensatorParams {
            h: 1e-3,
            kp: 4.0,
            ki: 0.0,
            kd: 0.0,
            inertia: 1.0,
            torque_constant: 1.0,
            limit: 100.0,
        };
        assert!(settle(p, 1.0, 40.0) < 1e-6);
        // PD on the undamped double integrator, and PID with the limit active
        assert!(settle(CompensatorParams { kd: 2.0, ..p }, 0.0, 40.0) < 1e-6);
        let pid = CompensatorParams {
            kd: 3.0,
            ki: 1.0,
            limit: 1.0,
            ..p
        };
        assert!(settle(pid, 0.0, 60.0) < 1e-6);
        // and the undamped pure P loop does not settle: the test can fail
        assert!(settle(p, 0.0, 40.0) > 0.1);
    }

    fn observer_f32() -> Compensator<f32, Observer<LuGre<f32>, f32>> {
        let m = olsson().build::<f32>().unwrap();
        params().build(Observer::new(m, 20.0).unwrap()).unwrap()
    }

    fn finite_f32() -> impl Strategy<Value = f32> {
        prop_oneof![
            prop::num::f32::NORMAL,
            prop::num::f32::SUBNORMAL,
            prop::num::f32::ZERO,
            Just(f32::MAX),
            Just(f32::MIN),
            -1.0f32..1.0,
        ]
    }

    fn gain() -> impl Strategy<Value = f64> {
        prop_oneof![Just(0.0), 0.0..1e3, 1e3..1e20]
    }

    proptest! {
        #[test]
        fn output_is_finite_and_bounded_for_hostile_finite_inputs(
            inputs in prop::collection::vec(
                (finite_f32(), finite_f32(), finite_f32(), finite_f32()), 1..40),
            kp in gain(), ki in gain(), kd in gain(), inertia in gain(),
            limit in prop_oneof![1e-20f64..1.0, 1.0..1e20],
        ) {
            let p = CompensatorParams { kp, ki, kd, inertia, limit, ..params() };
            let model = olsson().build::<f32>().unwrap();
            let obs = p.build(Observer::new(model, 20.0).unwrap()).unwrap();
            let map = CoulombViscousParams { fc: 0.28, sigma2: 0.0176 }.build::<f32>().unwrap();
            let ff = p.build(FeedForward(map)).unwrap();
            let lim = limit as f32;
            let (mut so, mut sf) = (CompensatorState::default(), CompensatorState::default());
            for (x, rx, rv, ra) in inputs {
                let r = Setpoint { x: rx, v: rv, a: ra };
                for t in [obs.tick(&mut so, x, r), ff.tick(&mut sf, x, r)] {
                    prop_assert!(t.accepted);
                    prop_assert!(t.command.is_finite() && t.command.abs() <= lim, "{t:?}");
                    prop_assert!(t.friction.is_finite(), "{t:?}");
                }
                prop_assert!(so.integral().is_finite() && so.integral().abs() <= lim);
                prop_assert!(so.friction().z.is_finite());
            }
        }

        #[test]
        fn any_input_including_nan_never_poisons(
            inputs in prop::collection::vec(
                (any::<f32>(), any::<f32>(), any::<f32>(), any::<f32>()), 1..40),
        ) {
            let c = observer_f32();
            let mut s = CompensatorState::default();
            for (x, rx, rv, ra) in inputs {
                let before = s;
                let t = c.tick(&mut s, x, Setpoint { x: rx, v: rv, a: ra });
                prop_assert!(t.command.is_finite() && t.command.abs() <= 5.0);
                if !t.accepted {
                    prop_assert_eq!(t.command, 0.0);
                    prop_assert_eq!(s.integral(), before.integral());
                    prop_assert_eq!(s.friction(), before.friction());
                }
                prop_assert!(s.integral().is_finite());
                prop_assert!(s.friction().z.is_finite());
                prop_assert!(s.last_position().is_none_or(f32::is_finite));
            }
        }
    }

    #[test]
    fn observer_state_is_the_models() {
        let c = observer_f32();
        let mut s: CompensatorState<f32, LuGreState<f32>> = CompensatorState::default();
        c.tick(&mut s, 0.0, Setpoint::default());
        let t = c.tick(&mut s, 1e-4, Setpoint::default()); // moving at 0.1 rad/s
        assert!(t.friction > 0.0 && s.friction().z > 0.0);
    }
}
