//! Commissioning on the target: from a bare axis to LuGre parameters, ticked
//! in the control interrupt: see [`Commissioning`].

mod fit;

use crate::bits::Flag;
use crate::compensator::{Compensator, CompensatorParams, CompensatorState, NoCompensation};
use crate::gain::Gain;
use crate::model::{convert, magnitude, magnitude_or_zero, ParamError};
use crate::Scalar;

pub use fit::{CommissionError, Commissioned, CommissioningIdentified, PlateauPoint};

/// The most plateau speeds a routine can run (each in both directions).
pub const COMMISSIONING_MAX_SPEEDS: usize = 16;

/// The commissioning programme's settings (see [`Commissioning`]).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CommissioningParams {
    /// The position loop that drives the plateaus (its `limit` is the
    /// command limit of the whole routine, its `inertia` the one `sigma1`
    /// is damped against).
    pub servo: CompensatorParams,
    /// Largest excursion `> 0` from the starting position (position units).
    pub travel: f64,
    /// Longest run `> 0` (s).
    pub duration: f64,
    /// Slowest plateau speed `> 0`.
    pub min_speed: f64,
    /// Fastest plateau speed `>= min_speed`.
    pub max_speed: f64,
    /// Number of plateau speeds, 2 to [`COMMISSIONING_MAX_SPEEDS`].
    pub speeds: u8,
    /// Measuring time `> 0` of a plateau (s); shorter where the travel
    /// does not allow it.
    pub plateau: f64,
    /// Time `>= 0` (s) a plateau cruises before it is measured, and the
    /// pause after each move.
    pub settle: f64,
    /// Acceleration `> 0` of the plateau moves.
    pub acceleration: f64,
    /// Rate `> 0` of the break-away and presliding command ramps (command
    /// units per second).
    pub ramp_rate: f64,
    /// Displacement `> 0` that counts as breaking away; it must exceed the
    /// presliding displacement.
    pub breakaway_travel: f64,
    /// The encoder's count `>= 0` (position units; 0: exact): presliding
    /// shorter than 8 counts is reported as not identified.
    pub resolution: f64,
}

impl CommissioningParams {
    /// Defaults for a loop `servo`, a travel window and a top speed: 30 s
    /// at most, 10 speeds down to `max_speed / 1000`, plateaus of 0.8 s
    /// after 0.15 s of settling, the top speed reached in 0.1 s (or slower,
    /// so that accelerating the inertia takes at most a quarter of the
    /// limit), command ramps of a tenth of the limit per second, break-away
    /// at a hundredth of the travel, an exact encoder.
    pub fn new(servo: CompensatorParams, travel: f64, max_speed: f64) -> Self {
        let force = servo.torque_constant * servo.limit;
        let acceleration = if servo.inertia > 0.0 {
            (10.0 * max_speed).min(0.25 * force / servo.inertia)
        } else {
            10.0 * max_speed
        };
        Self {
            servo,
            travel,
            duration: 30.0,
            min_speed: max_speed / 1000.0,
            max_speed,
            speeds: 10,
            plateau: 0.8,
            settle: 0.15,
            acceleration,
            ramp_rate: servo.limit / 10.0,
            breakaway_travel: travel / 100.0,
            resolution: 0.0,
        }
    }

    /// Checks every setting (the error names it) and that the programme
    /// fits: the top speed gets a plateau of at least 20 periods within the
    /// travel, and the whole programme fits in `duration`.
    pub fn validate(&self) -> Result<(), ParamError> {
        self.servo.validate()?;
        for (name, value) in [
            ("travel", self.travel),
            ("duration", self.duration),
            ("min_speed", self.min_speed),
            ("max_speed", self.max_speed),
            ("plateau", self.plateau),
            ("acceleration", self.acceleration),
            ("ramp_rate", self.ramp_rate),
            ("breakaway_travel", self.breakaway_travel),
        ] {
            magnitude(name, value)?;
        }
        magnitude_or_zero("settle", self.settle)?;
        magnitude_or_zero("resolution", self.resolution)?;
        if self.max_speed < self.min_speed {
            return Err(ParamError::NotBelow {
                name: "min_speed",
                limit: "max_speed",
            });
        }
        if !(2..=COMMISSIONING_MAX_SPEEDS as u8).contains(&self.speeds) {
            return Err(ParamError::OutOfRange("speeds"));
        }
        if self.breakaway_travel >= self.travel {
            return Err(ParamError::NotBelow {
                name: "breakaway_travel",
                limit: "travel",
            });
        }
        if self.measuring_time(self.max_speed) < 20.0 * self.servo.h {
            return Err(ParamError::NotBelow {
                name: "max_speed",
                limit: "what the travel allows",
            });
        }
        if self.scheduled_time() > self.duration {
            return Err(ParamError::NotBelow {
                name: "plateau",
                limit: "what the duration allows",
            });
        }
        Ok(())
    }

    /// The `k`-th plateau speed, log-spaced from `min_speed` to `max_speed`.
    pub fn speed(&self, k: usize) -> f64 {
        let n = f64::from(self.speeds.max(2)) - 1.0;
        self.min_speed * libm::pow(self.max_speed / self.min_speed, k as f64 / n)
    }

    /// The measuring time at speed `v`: `plateau`, or less where the move
    /// (accelerating, settling, measuring, braking) would leave 90 % of the
    /// travel.
    pub fn measuring_time(&self, v: f64) -> f64 {
        let ramp = v / self.acceleration;
        self.plateau
            .min(WINDOW * self.travel / v - ramp - self.settle)
    }

    /// The programme's length in seconds without its break-away ramps
    /// (each lasts the break-away level over `ramp_rate`; the presliding
    /// ramps half as long together): the holds, presliding and plateaus.
    pub fn scheduled_time(&self) -> f64 {
        let ramps = 2.0 * HOLD;
        let presliding = 5.0 * PRESLIDING_HOLD + HOLD;
        let plateaus: f64 = (0..usize::from(self.speeds))
            .map(|k| {
                let v = self.speed(k);
                2.0 * (2.0 * v / self.acceleration + 2.0 * self.settle + self.measuring_time(v))
            })
            .sum();
        ramps + presliding + plateaus
    }

    /// Validates and builds the routine in the scalar `S`.
    ///
    /// ```
    /// use friction_core::{CommissioningParams, CompensatorParams};
    /// let servo = CompensatorParams { h: 1e-3, kp: 60.0, ki: 200.0, kd: 1.2,
    ///     inertia: 0.0023, torque_constant: 1.02, limit: 10.0 };
    /// let routine = CommissioningParams::new(servo, 1.0, 2.0).build::<f32>()?;
    /// # let _ = routine;
    /// # Ok::<(), friction_core::ParamError>(())
    /// ```
    pub fn build<S: Scalar>(&self) -> Result<Commissioning<S>, ParamError> {
        self.validate()?;
        let h = self.servo.h;
        let ticks = |seconds: f64| libm::ceil(seconds / h).min(f64::from(u32::MAX)) as u32;
        let zero = Gain::new("min_speed", 0.0)?;
        let mut speeds = [Speed {
            speed: S::ZERO,
            inv_step: zero,
            inv_ticks: zero,
            inv_blocks: zero,
            ticks: 0,
            pair_ticks: 0,
        }; COMMISSIONING_MAX_SPEEDS];
        for (k, slot) in speeds.iter_mut().enumerate() {
            if k < usize::from(self.speeds) {
                let v = self.speed(k);
                let count = ticks(self.measuring_time(v)).max(1);
                let blocks = (count / u32::from(BLOCK)).max(1);
                *slot = Speed {
                    speed: coarse("min_speed", v)?,
                    inv_step: Gain::new("min_speed", 1.0 / (f64::from(BLOCK) * v * h))?,
                    inv_ticks: Gain::new("plateau", 1.0 / f64::from(count))?,
                    inv_blocks: Gain::new("plateau", 1.0 / f64::from(blocks))?,
                    ticks: count,
                    pair_ticks: ticks(2.0 * (2.0 * v / self.acceleration + 2.0 * self.settle))
                        .saturating_add(count.saturating_mul(2)),
                };
            }
        }
        Ok(Commissioning {
            servo: self.servo.build(NoCompensation)?,
            travel: coarse("travel", self.travel)?,
            breakaway_travel: coarse("breakaway_travel", self.breakaway_travel)?,
            ramp_step: coarse("ramp_rate", self.ramp_rate * h)?,
            speed_step: coarse("acceleration", self.acceleration * h)?,
            acceleration: coarse("acceleration", self.acceleration)?,
            h: Gain::new("h", h)?,
            limit: convert("limit", self.servo.limit)?,
            ratio_cap: S::from_f64(RATIO_CAP),
            bin_edges: core::array::from_fn(|k| {
                S::from_f64(WINDOW * self.travel * (k + 1) as f64 / BINS as f64)
            }),
            speeds,
            settle_ticks: ticks(self.settle),
            hold_ticks: ticks(HOLD),
            presliding_ticks: ticks(PRESLIDING_HOLD),
            stall_ticks: ticks(STALL),
            max_ticks: ticks(self.duration),
            params: *self,
        })
    }
}

/// Ticks in a block of a plateau's sums (8 commands stay within the
/// `32 limit` every scalar of a compensator holds).
const BLOCK: u8 = 8;
/// A block's distance ratio beyond this is a jump, not sliding: it counts
/// as this (and its square stays within Q16.16).
const RATIO_CAP: f64 = 32.0;

/// `value` in `S`, rounded: for settings whose rounding only shifts the
/// programme (a ramp's or a reference's rate, a window), never a measured
/// figure; refused only where it overflows or rounds to 0.
fn coarse<S: Scalar>(name: &'static str, value: f64) -> Result<S, ParamError> {
    let s = S::from_f64(value);
    if !s.is_finite() || (s.to_f64() - value).abs() > 0.5 * value.abs() {
        return Err(ParamError::NotRepresentable(name));
    }
    if s == S::ZERO {
        return Err(ParamError::Underflow(name));
    }
    Ok(s)
}

/// A plateau speed and the gains of its measurement.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Speed<S> {
    speed: S,
    /// `1 / (8 v h)`: a block's distance as a ratio of the plateau's.
    inv_step: Gain<S>,
    /// `1 / ticks` and `1 / blocks` of the measurement: the sums are kept as
    /// means, so that no scalar overflows whatever the plateau's length.
    inv_ticks: Gain<S>,
    inv_blocks: Gain<S>,
    ticks: u32,
    /// The ticks of both plateaus at this speed, moves and pauses included.
    pair_ticks: u32,
}

/// The share of the travel a plateau's move may cover.
const WINDOW: f64 = 0.9;
/// The loop's hold after a break-away ramp (s).
const HOLD: f64 = 0.3;
/// Each hold of the presliding programme (s).
const PRESLIDING_HOLD: f64 = 0.2;
/// A command held at the limit this long is a stall (s).
const STALL: f64 = 0.05;

/// Where a routine is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum CommissioningPhase {
    /// The break-away ramps and the loop's return to the start.
    Breakaway,
    /// The presliding reversal.
    Presliding,
    /// The velocity plateaus.
    Plateaus,
    /// Finished: [`Commissioning::result`] fits the parameters.
    Done,
    /// Stopped by a limit or a fault; the command is 0 from now on.
    Aborted,
}

/// Why a routine stopped early.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum CommissioningAbort {
    /// A measured position was NaN or infinite.
    NonFiniteMeasurement,
    /// The axis left the travel window.
    Travel,
    /// The programme ran longer than `duration`.
    Timeout,
    /// The position loop held its command at the limit (a stall, a stuck
    /// encoder, a torque limit below the friction).
    Stall,
    /// A break-away ramp reached the command limit without moving the axis.
    NoBreakaway,
    /// The axis moved against the command: the motor's or the encoder's
    /// sign is reversed.
    ReversedSign,
}

/// What one tick returns.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CommissioningTick<S> {
    /// The command to apply (command units, within the limit; 0 once done
    /// or aborted).
    pub command: S,
    /// Where the routine is after this tick.
    pub phase: CommissioningPhase,
    /// Plateaus measured so far (of `2 speeds`).
    pub plateaus: u8,
}

/// The built routine: immutable, one per axis type.
///
/// Commissioning on the target: from a bare axis to LuGre parameters,
/// ticked in the control interrupt.
///
/// [`Commissioning::tick`] takes the measured position and returns the
/// command, one call per control period, through a fixed programme:
///
/// 1. **Break-away**, forward then backward: from rest, an open-loop command
///    ramp `u = ±ramp_rate t` until the axis has moved `breakaway_travel`;
///    the command reached is the break-away level. The loop then brings the
///    axis back to where it started.
/// 2. **Presliding**: an open-loop command of `+a`, held, a step down to
///    `a / 2`, held, then `-a`, held (`a` a quarter of the smaller
///    break-away level), the axis in stick throughout: the two rest
///    positions give the stiffness of a reversal, the step's overshoot the
///    damping.
/// 3. **Plateaus**: at `speeds` log-spaced speeds from `max_speed` down to
///    `min_speed`, a trapezoidal move forward then back through the
///    position loop (the [`Compensator`]'s PID without compensation, with
///    the gains of `servo`), the friction measured at the speed before fed
///    forward. Over each cruise, after `settle`, the mean command is the
///    friction at the mean speed: with the command held, the net force over
///    a stretch that starts and ends at the same speed is zero on average.
///    A plateau the loop could not hold (stick-slip, or lagging the
///    reference) is left out of the fit. A speed whose two plateaus would
///    not finish within `duration` is not started: the programme ends there
///    with the faster plateaus it has measured.
///
/// [`Commissioning::result`] then fits the steady curve (see [`Commissioned`]) and
/// returns the LuGre parameters with their quality figures.
///
/// Limits: the axis never leaves `±travel` around its first position, the
/// routine never runs longer than `duration`, and a command held at the
/// limit for 50 ms is a stall. Any limit reached, a non-finite position, a
/// ramp that reaches the limit without moving the axis, or an axis that
/// moves against the command ends the routine in
/// [`CommissioningPhase::Aborted`] with a [`CommissioningAbort`] reason, and every later command is 0.
///
/// Memory: a [`CommissioningState`] holds the loop's state and one record
/// per plateau (at most [`COMMISSIONING_MAX_SPEEDS`] speeds, two
/// directions), each with its commands over four stretches of the window
/// (for the load coefficient, see [`Commissioned`]); no allocation, no
/// panic.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Commissioning<S> {
    servo: Compensator<S, NoCompensation>,
    travel: S,
    breakaway_travel: S,
    ramp_step: S,
    speed_step: S,
    acceleration: S,
    h: Gain<S>,
    limit: S,
    ratio_cap: S,
    /// The edges of the position stretches, from the start.
    bin_edges: [S; BINS - 1],
    speeds: [Speed<S>; COMMISSIONING_MAX_SPEEDS],
    settle_ticks: u32,
    hold_ticks: u32,
    presliding_ticks: u32,
    stall_ticks: u32,
    max_ticks: u32,
    params: CommissioningParams,
}

/// One measured plateau: the distance, the ticks, and the mean command
/// over them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct Plateau<S> {
    pub(crate) distance: S,
    pub(crate) ticks: u32,
    pub(crate) command_mean: S,
    /// The means over the blocks of 8 ticks of each block's distance as a
    /// ratio `r` of the plateau's `8 v h`, and of `r^2`: their variance
    /// tells steady sliding from stick-slip.
    pub(crate) ratio_mean: S,
    pub(crate) square_mean: S,
    /// The commands by position: the block sums whose block ended in each
    /// of `BINS` equal stretches of the plateaus' window (`0.9 travel`
    /// ahead of the start), scaled as `command_mean`, and their ticks.
    pub(crate) bins: [S; BINS],
    pub(crate) bin_ticks: [u32; BINS],
}

/// Stretches of the plateaus' window whose commands are kept apart: both
/// directions at one speed pass the same stretch at the same load, so
/// the stretches with another load (gravity) give the load coefficient.
pub(crate) const BINS: usize = 4;

// The stored phase: a byte, decoded totally (every byte is some phase).
const BREAKAWAY: u8 = 0;
const PRESLIDING: u8 = 1;
const PLATEAUS: u8 = 2;
const DONE: u8 = 3;

/// A routine's run-time state (see [`Commissioning`] for its size).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CommissioningState<S> {
    servo: CompensatorState<S, ()>,
    phase: u8,
    /// The step within the phase (break-away: direction and hold;
    /// presliding: ramp or hold; plateaus: the plateau's index).
    step: u8,
    /// The stage within a plateau's move.
    stage: u8,
    abort: u8,
    started: Flag,
    ticks: u32,
    stage_ticks: u32,
    stalled: u32,
    x0: S,
    x_start: S,
    x_ref: S,
    v_ref: S,
    command: S,
    /// Commands summed in `S` over a block of up to [`BLOCK`] ticks before
    /// they join the plateau's `f64` sum.
    block: S,
    block_len: u8,
    /// The position at the start of the block.
    last_x: S,
    pub(crate) breakaway: [S; 2],
    /// Rest positions under `+a` and `-a`, and `a`.
    pub(crate) presliding: [S; 2],
    pub(crate) presliding_level: S,
    /// The step from `a` to `a / 2`: the position before it, the lowest
    /// after it, and the last.
    pub(crate) step_response: [S; 3],
    pub(crate) slipped: Flag,
    pub(crate) plateaus: [Plateau<S>; 2 * COMMISSIONING_MAX_SPEEDS],
    measured: u8,
}

impl<S: Scalar> Default for CommissioningState<S> {
    fn default() -> Self {
        Self {
            servo: CompensatorState::default(),
            phase: BREAKAWAY,
            step: 0,
            stage: 0,
            abort: 0,
            started: Flag::new(false),
            ticks: 0,
            stage_ticks: 0,
            stalled: 0,
            x0: S::ZERO,
            x_start: S::ZERO,
            x_ref: S::ZERO,
            v_ref: S::ZERO,
            command: S::ZERO,
            block: S::ZERO,
            block_len: 0,
            last_x: S::ZERO,
            breakaway: [S::ZERO; 2],
            presliding: [S::ZERO; 2],
            presliding_level: S::ZERO,
            step_response: [S::ZERO; 3],
            slipped: Flag::new(false),
            plateaus: [Plateau::default(); 2 * COMMISSIONING_MAX_SPEEDS],
            measured: 0,
        }
    }
}

impl<S: Scalar> CommissioningState<S> {
    /// Where the routine is.
    pub fn phase(&self) -> CommissioningPhase {
        match self.phase {
            BREAKAWAY => CommissioningPhase::Breakaway,
            PRESLIDING => CommissioningPhase::Presliding,
            PLATEAUS => CommissioningPhase::Plateaus,
            DONE => CommissioningPhase::Done,
            _ => CommissioningPhase::Aborted,
        }
    }

    /// Why it stopped, if it was aborted.
    pub fn abort(&self) -> Option<CommissioningAbort> {
        if self.phase() != CommissioningPhase::Aborted {
            return None;
        }
        Some(match self.abort {
            0 => CommissioningAbort::NonFiniteMeasurement,
            1 => CommissioningAbort::Travel,
            2 => CommissioningAbort::Timeout,
            3 => CommissioningAbort::Stall,
            4 => CommissioningAbort::NoBreakaway,
            _ => CommissioningAbort::ReversedSign,
        })
    }

    /// Seconds of the programme run so far, in ticks.
    pub fn ticks(&self) -> u32 {
        self.ticks
    }

    /// The friction level (command units) fed forward on plateau `index`:
    /// the mean command of the plateau two before (the next faster speed in
    /// the same direction), or the break-away level on the first two.
    fn level(&self, index: usize) -> S {
        let before = index.checked_sub(2).and_then(|i| self.plateaus.get(i));
        match before {
            Some(p) if p.ticks > 0 => p.command_mean.abs(),
            _ => self.breakaway.get(index % 2).copied().unwrap_or(S::ZERO),
        }
    }

    fn stop(&mut self, why: CommissioningAbort) {
        self.phase = u8::MAX;
        self.abort = why as u8;
        self.command = S::ZERO;
    }

    /// The next step of the phase, from its first tick.
    fn next_step(&mut self) {
        self.step = self.step.saturating_add(1);
        self.stage = 0;
        self.stage_ticks = 0;
    }

    /// The next phase, from its first step.
    fn next_phase(&mut self, phase: u8) {
        self.phase = phase;
        self.step = 0;
        self.stage = 0;
        self.stage_ticks = 0;
    }
}

impl<S: Scalar> Commissioning<S> {
    /// The settings it was built from.
    pub fn params(&self) -> &CommissioningParams {
        &self.params
    }

    /// One control period with measured position `x`: the command to apply
    /// (see [`Commissioning`] for the programme and its limits).
    ///
    /// ```
    /// use friction_core::{CommissioningParams, CommissioningState, CompensatorParams, CommissioningPhase};
    /// let servo = CompensatorParams { h: 1e-3, kp: 60.0, ki: 200.0, kd: 1.2,
    ///     inertia: 0.0023, torque_constant: 1.02, limit: 10.0 };
    /// let routine = CommissioningParams::new(servo, 1.0, 2.0).build::<f32>()?;
    /// let mut state = CommissioningState::default();
    /// // an axis that never moves: the break-away ramp reaches the limit
    /// let mut tick = routine.tick(&mut state, 0.0);
    /// while tick.phase == CommissioningPhase::Breakaway {
    ///     assert!(tick.command.abs() <= 10.0);
    ///     tick = routine.tick(&mut state, 0.0);
    /// }
    /// assert_eq!(tick.phase, CommissioningPhase::Aborted);
    /// assert_eq!(tick.command, 0.0);
    /// # Ok::<(), friction_core::ParamError>(())
    /// ```
    pub fn tick(&self, state: &mut CommissioningState<S>, x: S) -> CommissioningTick<S> {
        let command = self.command(state, x);
        let command = if command.is_finite() {
            command.sat(self.limit)
        } else {
            S::ZERO
        };
        CommissioningTick {
            command,
            phase: state.phase(),
            plateaus: state.measured,
        }
    }

    fn command(&self, state: &mut CommissioningState<S>, x: S) -> S {
        if matches!(
            state.phase(),
            CommissioningPhase::Done | CommissioningPhase::Aborted
        ) {
            return S::ZERO;
        }
        if !x.is_finite() {
            state.stop(CommissioningAbort::NonFiniteMeasurement);
            return S::ZERO;
        }
        if !state.started.get() {
            state.started = Flag::new(true);
            state.x0 = x;
            state.x_start = x;
        }
        state.ticks = state.ticks.saturating_add(1);
        state.stage_ticks = state.stage_ticks.saturating_add(1);
        if state.ticks > self.max_ticks {
            state.stop(CommissioningAbort::Timeout);
            return S::ZERO;
        }
        if (x - state.x0).abs() > self.travel {
            state.stop(CommissioningAbort::Travel);
            return S::ZERO;
        }
        let command = match state.phase {
            BREAKAWAY => self.breakaway(state, x),
            PRESLIDING => self.presliding(state, x),
            _ => self.plateaus(state, x),
        };
        if matches!(state.phase(), CommissioningPhase::Aborted) {
            return S::ZERO;
        }
        command
    }

    /// A tick of the position loop toward `(x_ref, v_ref, a)`, watching
    /// for a stall.
    fn track(&self, state: &mut CommissioningState<S>, x: S, a: S) -> S {
        let setpoint = crate::Setpoint {
            x: state.x_ref,
            v: state.v_ref,
            a,
        };
        let command = self.servo.tick(&mut state.servo, x, setpoint).command;
        if command.abs() >= self.limit {
            state.stalled = state.stalled.saturating_add(1);
            if state.stalled > self.stall_ticks {
                state.stop(CommissioningAbort::Stall);
            }
        } else {
            state.stalled = 0;
        }
        command
    }

    /// Holds the loop at `x_ref` for `ticks`; true when done.
    fn hold(&self, state: &mut CommissioningState<S>, x: S, ticks: u32) -> (S, bool) {
        state.v_ref = S::ZERO;
        (self.track(state, x, S::ZERO), state.stage_ticks >= ticks)
    }

    /// Steps 0 and 2: ramps forward, backward; 1 and 3: the loop brings
    /// the axis back to the start.
    fn breakaway(&self, state: &mut CommissioningState<S>, x: S) -> S {
        let forward = state.step < 2;
        if state.step % 2 == 1 {
            let (command, done) = self.hold(state, x, self.hold_ticks);
            if done {
                if state.step >= 3 {
                    self.start_presliding(state, x);
                } else {
                    state.next_step();
                    state.x_start = x;
                    state.command = S::ZERO;
                }
            }
            return command;
        }
        state.command = state.command + self.ramp_step;
        let moved = if forward {
            x - state.x_start
        } else {
            state.x_start - x
        };
        if moved > self.breakaway_travel {
            let level = state.command;
            if let Some(b) = state.breakaway.get_mut(usize::from(!forward)) {
                *b = level;
            }
            // the loop takes over from rest: a fresh state, back to the start
            state.servo = CompensatorState::default();
            state.x_ref = state.x0;
            state.next_step();
            return self.hold(state, x, self.hold_ticks).0;
        }
        if moved < -self.breakaway_travel {
            state.stop(CommissioningAbort::ReversedSign);
        } else if state.command > self.limit {
            state.stop(CommissioningAbort::NoBreakaway);
        }
        if forward {
            state.command
        } else {
            -state.command
        }
    }

    fn start_presliding(&self, state: &mut CommissioningState<S>, x: S) {
        let [forward, backward] = state.breakaway;
        let smaller = if forward < backward {
            forward
        } else {
            backward
        };
        state.presliding_level = smaller * S::from_f64(0.25);
        state.next_phase(PRESLIDING);
        state.x_start = x;
        state.command = S::ZERO;
    }

    /// Open loop: 0 ramps to `+a`, 1 holds (the rest position under `+a`),
    /// 2 steps down to `a / 2` and holds (the overshoot of the step), 3
    /// ramps to `-a`, 4 holds (the rest position under `-a`), 5 ramps to 0;
    /// then the loop takes over.
    fn presliding(&self, state: &mut CommissioningState<S>, x: S) -> S {
        let a = state.presliding_level;
        if (x - state.x_start).abs() > self.breakaway_travel {
            state.slipped = Flag::new(true);
        }
        let held = state.stage_ticks >= self.presliding_ticks;
        match state.step {
            0 => {
                state.command = (state.command + self.ramp_step).min(a);
                if state.command >= a {
                    state.next_step();
                }
            }
            1 => {
                if held {
                    state.presliding[0] = x;
                    state.step_response = [x, x, x];
                    state.command = a * S::from_f64(0.5);
                    state.next_step();
                }
            }
            2 => {
                let [before, lowest, _] = state.step_response;
                state.step_response = [before, lowest.min(x), x];
                if held {
                    state.next_step();
                }
            }
            3 => {
                state.command = (state.command - self.ramp_step).max(-a);
                if state.command <= -a {
                    state.next_step();
                }
            }
            4 => {
                if held {
                    state.presliding[1] = x;
                    state.next_step();
                }
            }
            _ => {
                state.command = (state.command + self.ramp_step).min(S::ZERO);
                if state.command >= S::ZERO {
                    state.servo = CompensatorState::default();
                    state.x_ref = state.x0;
                    state.v_ref = S::ZERO;
                    state.next_phase(PLATEAUS);
                }
            }
        }
        state.command
    }

    /// Plateau `step`: speed `speeds - 1 - step / 2` (fastest first),
    /// forward when `step` is even. Stage 0 accelerates, 1 settles, 2
    /// measures, 3 brakes, 4 pauses. While moving, the friction measured
    /// at the speed before (the break-away level at first) is fed forward
    /// in the direction of motion, so that the loop's PID only supplies the
    /// difference.
    fn plateaus(&self, state: &mut CommissioningState<S>, x: S) -> S {
        let index = usize::from(state.step);
        let count = usize::from(self.params.speeds).min(COMMISSIONING_MAX_SPEEDS);
        if index / 2 >= count {
            state.next_phase(DONE);
            return S::ZERO;
        }
        let forward = index % 2 == 0;
        let Some(speed) = self.speeds.get(count - 1 - index / 2) else {
            state.next_phase(DONE);
            return S::ZERO;
        };
        // a pair that cannot finish within the duration is not started: the
        // routine ends with the plateaus it has rather than abort on time
        let first_tick = forward && state.stage == 0 && state.stage_ticks <= 1;
        if first_tick && state.ticks.saturating_add(speed.pair_ticks) > self.max_ticks {
            state.next_phase(DONE);
            return S::ZERO;
        }
        let target = if forward { speed.speed } else { -speed.speed };
        let (a, next) = match state.stage {
            0 => self.accelerate(state, target),
            1 => (S::ZERO, state.stage_ticks >= self.settle_ticks),
            2 => (S::ZERO, state.stage_ticks >= speed.ticks),
            3 => self.accelerate(state, S::ZERO),
            _ => (S::ZERO, state.stage_ticks >= self.settle_ticks),
        };
        state.x_ref = state.x_ref + self.h.times(state.v_ref);
        let level = state.level(index);
        let feed = if state.v_ref > S::ZERO {
            level
        } else if state.v_ref < S::ZERO {
            -level
        } else {
            S::ZERO
        };
        let command = (self.track(state, x, a) + feed).sat(self.limit);
        if state.stage == 2 {
            self.measure(state, x, index, command, speed, next);
        }
        if next {
            if state.stage >= 4 {
                state.next_step();
            } else {
                state.stage += 1;
                state.stage_ticks = 0;
            }
        }
        command
    }

    /// One tick of plateau `index`'s measuring stage at `speed`.
    fn measure(
        &self,
        state: &mut CommissioningState<S>,
        x: S,
        index: usize,
        command: S,
        speed: &Speed<S>,
        last: bool,
    ) {
        if state.stage_ticks == 1 {
            state.x_start = x;
            state.last_x = x;
            state.block = S::ZERO;
            state.block_len = 0;
            if let Some(p) = state.plateaus.get_mut(index) {
                *p = Plateau::default();
            }
        }
        state.block = state.block + command;
        // saturating: a state C's memory holds may carry any count here
        state.block_len = state.block_len.saturating_add(1);
        if state.block_len >= BLOCK || last {
            let r = speed
                .inv_step
                .times(x - state.last_x)
                .abs()
                .min(self.ratio_cap);
            let full = state.block_len >= BLOCK;
            let offset = x - state.x0;
            let bin = self
                .bin_edges
                .iter()
                .filter(|edge| offset >= **edge)
                .count();
            if let Some(p) = state.plateaus.get_mut(index) {
                let share = speed.inv_ticks.times(state.block);
                p.command_mean = p.command_mean + share;
                if let (Some(sum), Some(ticks)) = (p.bins.get_mut(bin), p.bin_ticks.get_mut(bin)) {
                    *sum = *sum + share;
                    *ticks = ticks.saturating_add(u32::from(state.block_len));
                }
                if full {
                    p.ratio_mean = p.ratio_mean + speed.inv_blocks.times(r);
                    p.square_mean = p.square_mean + speed.inv_blocks.times(r * r);
                }
                p.ticks = state.stage_ticks;
                p.distance = x - state.x_start;
            }
            state.last_x = x;
            state.block = S::ZERO;
            state.block_len = 0;
        }
        if last {
            state.measured = state.measured.saturating_add(1);
        }
    }

    /// Moves the reference speed toward `target` by the acceleration;
    /// returns the reference acceleration and whether it arrived.
    fn accelerate(&self, state: &mut CommissioningState<S>, target: S) -> (S, bool) {
        let gap = target - state.v_ref;
        if gap.abs() <= self.speed_step {
            state.v_ref = target;
            (S::ZERO, true)
        } else if gap > S::ZERO {
            state.v_ref = state.v_ref + self.speed_step;
            (self.acceleration, false)
        } else {
            state.v_ref = state.v_ref - self.speed_step;
            (-self.acceleration, false)
        }
    }

    /// The plateaus measured so far (fastest first, forward first), for
    /// plots and logs.
    pub fn plateau_points(
        &self,
        state: &CommissioningState<S>,
    ) -> [Option<PlateauPoint>; 2 * COMMISSIONING_MAX_SPEEDS] {
        fit::measured(&self.params, state)
    }

    /// Fits the LuGre parameters to a finished routine (see [`Commissioned`]); runs
    /// in `f64`, outside the control interrupt.
    pub fn result(&self, state: &CommissioningState<S>) -> Result<Commissioned, CommissionError> {
        match state.phase() {
            CommissioningPhase::Done => fit::fit(&self.params, state),
            CommissioningPhase::Aborted => Err(CommissionError::Aborted(
                state
                    .abort()
                    .unwrap_or(CommissioningAbort::NonFiniteMeasurement),
            )),
            _ => Err(CommissionError::NotFinished),
        }
    }
}

#[cfg(test)]
mod tests;
