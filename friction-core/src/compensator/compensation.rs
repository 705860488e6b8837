//! What the compensator adds for friction: the [`Compensation`] trait and
//! its forms (none, a static feed-forward map, an observer, an observer at
//! its period).

use crate::fixed_step::FixedStepObservable;
use crate::model::FrictionModel;
use crate::observer::{Observable, Observer};
use crate::Scalar;
use core::fmt::Debug;

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

    /// Whether the compensation is told the motor torque `kc u` of each
    /// command issued ([`Compensation::motor_torque`]): an observer on a
    /// model whose friction grows with the load
    /// ([`Observable::LOADED`]).
    const LOADED: bool = false;

    /// Told the motor torque `kc u` of the command an accepted tick issued,
    /// after [`Compensation::commanded`], when [`Self::LOADED`].
    fn motor_torque(&self, _state: &mut Self::State, _torque: S) {}

    /// Told the external torque `τ_ext` on the axis (force units, finite),
    /// between ticks ([`Compensator::set_external_torque`](super::Compensator::set_external_torque)):
    /// a compensation whose friction grows with the torque the
    /// transmission carries reads its load input as `kc u - τ_ext`. The
    /// default ignores it.
    #[inline]
    fn set_external_torque(&self, _state: &mut Self::State, _torque: S) {}

    /// Told that a tick was skipped (a non-finite input): the next
    /// [`Compensation::estimate`] comes after a gap. A compensation that
    /// sums evidence over consecutive ticks restarts it here.
    #[inline]
    fn skipped(&self, _state: &mut Self::State) {}

    /// Makes `state`, a state of the compensation `old`, a state of this one,
    /// between two ticks of a re-tuned drive
    /// ([`Compensator::retune`](super::Compensator::retune)). An observer keeps
    /// the force its state holds where this model's bounds allow
    /// ([`Observable::carry_over`]); an adaptive law restarts its estimates
    /// from this one's nominal values. The default keeps the state as it is
    /// (right for `()`, a static map's).
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
    const LOADED: bool = M::LOADED;
    #[inline]
    fn estimate(&self, state: &mut M::State, v: S, e: S, h: S) -> S {
        self.step(state, v, e, h)
    }
    fn carry_over(&self, old: &Self, state: &mut M::State) {
        self.model().carry_over(old.model(), state);
    }
    fn motor_torque(&self, state: &mut M::State, torque: S) {
        self.model().set_motor_torque(state, torque);
    }
    fn set_external_torque(&self, state: &mut M::State, torque: S) {
        self.model().set_external_torque(state, torque);
    }
}

/// An [`Observer`] on a fixed-step model ([`FixedStepModel`](crate::FixedStepModel)) as the
/// compensation: `FixedPeriod(Observer::new(model, k)?)`. The compensator's `h`
/// must be the model's period
/// ([`CompensatorParams::build`](super::CompensatorParams::build) checks it). A
/// wrapper, because one blanket `impl` for both observer kinds would overlap.
///
/// ```
/// use friction_core::{FixedPeriod, CompensatorParams, CompensatorState, LuGreParams, Observer, ParamError, Setpoint};
/// let model = LuGreParams::OLSSON_1998.build_fixed_step::<f32>(1e-3)?;
/// let mut params = CompensatorParams {
///     h: 1e-3, kp: 60.0, ki: 200.0, kd: 1.2,
///     inertia: 0.0023, torque_constant: 1.0, limit: 5.0,
/// };
/// let servo = params.build(FixedPeriod(Observer::new(model, 100.0)?))?;
/// let tick = servo.tick(&mut CompensatorState::default(), 0.0, Setpoint { x: 1e-3, v: 0.0, a: 0.0 });
/// assert!(tick.accepted && tick.command > 0.0);
/// params.h = 5e-4; // not the model's period
/// assert_eq!(params.build(FixedPeriod(Observer::new(model, 100.0)?)).err(), Some(ParamError::PeriodMismatch));
/// # Ok::<(), ParamError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FixedPeriod<O>(pub O);

impl<S: Scalar, M: FixedStepObservable<S>> Compensation<S> for FixedPeriod<Observer<M, S>> {
    type State = M::State;
    const LOADED: bool = M::LOADED;
    const USES_H: bool = false;
    #[inline]
    fn estimate(&self, state: &mut M::State, v: S, e: S, _h: S) -> S {
        self.0.step_fixed(state, v, e)
    }
    fn period(&self) -> Option<f64> {
        Some(self.0.model().period())
    }
    fn carry_over(&self, old: &Self, state: &mut M::State) {
        self.0.model().carry_over(old.0.model(), state);
    }
    fn motor_torque(&self, state: &mut M::State, torque: S) {
        self.0.model().set_motor_torque(state, torque);
    }
    fn set_external_torque(&self, state: &mut M::State, torque: S) {
        self.0.model().set_external_torque(state, torque);
    }
}
