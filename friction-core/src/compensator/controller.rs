//! The servo tick: PID plus the compensation, anti-windup and saturation:
//! [`Compensator`], its state, [`Setpoint`] and [`CompensatorTick`].

use super::{Compensation, CompensatorParams, FrictionSample};
use crate::bits::Flag;
use crate::gain::Gain;
use crate::model::{convert, positive, ParamError};
use crate::scalar::all_finite;
use crate::Scalar;
use core::fmt::Debug;

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
pub struct CompensatorTick<S> {
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
    pub(super) friction: T,
    /// The filtered velocity (with a velocity filter).
    pub(super) velocity: S,
    /// For compensations that learn: the position before `last_x`, the last
    /// two commands, and how many consecutive valid ticks preceded (at most 2).
    x_before: S,
    command: S,
    command_before: S,
    run: u8,
    /// The velocity observer's position estimate and the acceleration it
    /// predicts over the next period (with a velocity observer).
    pub(super) x_hat: S,
    accel: S,
    /// The velocity observer's estimate of the acceleration the command
    /// and the friction estimate do not explain.
    pub(super) disturbance: S,
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
/// A hardware-free position servo tick: PID with acceleration feed-forward
/// plus the friction compensation the user chooses.
///
/// Each tick takes the measured position `x` and the setpoint
/// `(x_ref, v_ref, a_ref)` and computes
///
/// ```text
/// e   = x - x_ref                                  measured minus desired
/// v   = (x - x_prev) / h                           backward difference; 0 on the first tick
/// F^  = compensation(v, e)                         0, a static map F(v), or an observer
/// I  += -ki h e                                    integral action, clamped to ±limit (anti-windup)
/// u   = (J a_ref + F^) / kc - kp e - kd (v - v_ref) + I
/// command = sat(limit, u)
/// ```
///
/// The PID gains and `limit` are in command units (amperes for a current
/// drive, N m for a torque command), the model terms `J a_ref` and `F^` in
/// force units, turned into command units by the torque constant `kc`
/// (force per command unit; 1 when the command is a torque).
///
/// The compensation is a type parameter implementing [`Compensation`]:
/// [`NoCompensation`](crate::NoCompensation), [`FeedForward`](crate::FeedForward) around any stateless model (e.g.
/// [`CoulombViscous`](crate::CoulombViscous) on the measured velocity), or an
/// [`Observer`](crate::Observer) around any [`Observable`](crate::Observable)
/// model, stepped with `v` and `e`.
///
/// Guarantees, for any inputs:
/// - the command is finite and within `±limit`; each term is clamped to
///   `±4 limit` before the sum, so no finite input can overflow it (a term
///   that would overflow counts as `±4 limit`); `|v|` and `|e|` are clamped
///   to [`VELOCITY_LIMIT`](crate::VELOCITY_LIMIT) before use;
/// - a NaN or infinite measured position or setpoint gives the **safe
///   output** `command = 0`, `friction = 0`, `accepted = false`, and leaves
///   the integral action, the friction state and the last valid position
///   untouched: only the count of ticks since that position advances, so the
///   next valid tick's velocity is the mean over the gap;
/// - **anti-windup**, both ways: the integral action is clamped to
///   `±limit`, and it is not integrated on a tick where integrating would
///   push an already saturated command further into saturation
///   (conditional integration);
/// - no panics, no allocation.
///
/// Immutable configuration ([`Compensator`]) is split from the mutable state
/// ([`CompensatorState`]): one compensator drives any number of axes.
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
    pub(super) compensation: C,
    pub(super) h: S,
    pub(super) inv_h: Gain<S>,
    pub(super) kp: Gain<S>,
    pub(super) ki_h: Gain<S>,
    pub(super) kd: Gain<S>,
    pub(super) feed_forward: Gain<S>,
    pub(super) inv_kc: Gain<S>,
    pub(super) limit: S,
    pub(super) term_limit: S,
    pub(super) signal_limit: S,
    /// `J / (kc h^2)` and `kc`, for the friction samples of compensations
    /// that learn (0 otherwise).
    pub(super) accel_ff: Gain<S>,
    pub(super) kc: Gain<S>,
    /// The velocity filter's `h / (tau + h)` (`1`: no filter).
    pub(super) velocity_blend: S,
    pub(super) filter_velocity: Flag,
    /// The velocity observer's position and velocity gains `alpha`,
    /// `beta / h` (`alpha = 0`: no observer), its period and `1 / J`.
    pub(super) observer_alpha: S,
    pub(super) observer_beta: Gain<S>,
    pub(super) observer_gamma: Gain<S>,
    pub(super) observer_h: Gain<S>,
    pub(super) inv_inertia: Gain<S>,
    pub(super) params: CompensatorParams,
}

/// `k x` clamped to `±b`; 0 when `k = 0` (so `0 * inf` cannot give NaN).
#[inline]
pub(super) fn term<S: Scalar>(k: Gain<S>, x: S, b: S) -> S {
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

    /// Sets the external torque `τ_ext` on the axis (force units) for a
    /// compensation whose friction grows with the torque the transmission
    /// carries, `kc u - τ_ext` (BAM's `τ_m - τ_e`, Duclusaud, Passault et
    /// al. 2024): the load's torque on the axis (a pendulum's `-T sin x`),
    /// less any torque the drive adds beside this compensator's command
    /// (a gravity feed-forward `kc u_g`: `τ_ext = τ_e - kc u_g`). It holds
    /// until set again; a non-finite value is ignored, and compensations
    /// without a load input ignore it.
    pub fn set_external_torque(&self, state: &mut CompensatorState<S, C::State>, torque: S) {
        if torque.is_finite() {
            self.compensation
                .set_external_torque(&mut state.friction, torque);
        }
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
    /// rate, and large enough that the gains do not round to 0 in `f64` or
    /// in the scalar (`Underflow`). Replaces a velocity filter.
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
        // a bandwidth so small that the gains round to 0 would leave the
        // backward difference in place (`observer_alpha` 0 means off)
        if gamma <= 0.0 {
            return Err(ParamError::Underflow("velocity_observer"));
        }
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

    /// One tick with measured position `x` towards the setpoint `r`; see
    /// [`Compensator`] for the control law and the guarantees.
    // Always inlined, with the helpers it calls: it is the interrupt's hot
    // path, and a second caller of the same instance (commissioning ticks the
    // uncompensated servo) must not move it out of line in the servo tick.
    #[inline(always)]
    pub fn tick(
        &self,
        state: &mut CompensatorState<S, C::State>,
        x: S,
        r: Setpoint<S>,
    ) -> CompensatorTick<S> {
        if !all_finite([x, r.x, r.v, r.a]) {
            self.skip(state);
            return CompensatorTick {
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
        CompensatorTick {
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
            self.skip(state);
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
    /// velocity, no friction sample spans it, and the compensation is told
    /// ([`Compensation::skipped`]).
    #[inline(always)]
    fn skip(&self, state: &mut CompensatorState<S, C::State>) {
        self.compensation.skipped(&mut state.friction);
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
        if C::LOADED {
            self.compensation
                .motor_torque(&mut state.friction, self.kc.times(command));
        }
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
