//! Re-tuning a running drive: a new compensation (a model from
//! commissioning, a host, a user) swapped in between two ticks without a
//! bump.
//!
//! The swap touches only the compensation and its state: the integral
//! action, the last position, the velocity estimate (filter or observer)
//! and the gains are those of the running loop. The compensation's state
//! is carried over by [`Compensation::carry_over`]: an observer keeps the
//! force its state holds (LuGre's elastic force `sigma0 z`, within the new
//! `±Fs`), an adaptive law restarts its estimates from the new model's
//! nominal values, a least-squares fit restarts, a supervisor keeps its
//! applied mode and restarts its evidence. So at the first tick after the
//! swap, against the same tick without it,
//!
//! ```text
//! |u_swapped - u_kept| <= |F^_new - F^_old| / kc
//! ```
//!
//! where `F^_new` and `F^_old` are the two compensations' estimates at that
//! tick (each term is clamped and the command saturated, both of which can
//! only shrink a difference). One exception: on a tick where one of the two
//! commands saturates, the conditional integration may integrate in one
//! and not the other, adding at most `ki h |e|` (an integral step).
//!
//! How large `F^_new - F^_old` is depends on the models, not on the loop:
//! with force-continuous carry-over it is the change of the viscous and
//! damping terms and of the first step's relaxation toward the new curve;
//! a model without its own carry-over (only LuGre and Dahl have one among
//! the state models) restarts at rest and loses its elastic force.

use super::{runs_at, Compensation, Compensator, CompensatorState};
use crate::model::ParamError;
use crate::Scalar;

impl<S: Scalar, C: Compensation<S>> Compensator<S, C> {
    /// This compensator with `compensation` in place of its own: the same
    /// loop (gains, limit, velocity filter or observer). Refuses a
    /// compensation built for another period, as
    /// [`CompensatorParams::build`](crate::CompensatorParams::build) does
    /// ([`ParamError::PeriodMismatch`]). The states of the axes it is to
    /// drive must then be carried over ([`Compensator::carry_over`]); for
    /// one axis, [`Compensator::retune`] does both.
    pub fn retuned(&self, compensation: C) -> Result<Self, ParamError> {
        runs_at(&compensation, self.params.h)?;
        Ok(Self {
            compensation,
            ..*self
        })
    }

    /// Makes `state`, an axis driven by `old` until now, an axis of this
    /// compensator: the compensation's state is carried over
    /// ([`Compensation::carry_over`]), the rest of the axis (integral, last
    /// position, velocity estimate) is kept as it is.
    pub fn carry_over(&self, old: &Self, state: &mut CompensatorState<S, C::State>) {
        self.compensation
            .carry_over(&old.compensation, &mut state.friction);
    }

    /// Swaps in `compensation` between two ticks of the axis `state`: the
    /// command at the next tick differs from the one the old compensation
    /// would give by at most the change of the friction estimate over `kc`
    /// (see the [module documentation](self)). On an error (a compensation
    /// built for another period: [`ParamError::PeriodMismatch`]) neither the
    /// compensator nor the state is touched.
    ///
    /// A compensator shared by several axes is re-tuned with
    /// [`retuned`](Self::retuned) and [`carry_over`](Self::carry_over) on
    /// each axis, between the same two ticks:
    ///
    /// ```
    /// use friction_core::{AtPeriod, CompensatorParams, CompensatorState, LuGreParams, Observer, ParamError, Setpoint};
    /// let p = CompensatorParams { h: 1e-3, kp: 60.0, ki: 200.0, kd: 1.2,
    ///     inertia: 0.0023, torque_constant: 1.02, limit: 10.0 };
    /// let first = LuGreParams::OLSSON_1998.build_at::<f32>(1e-3)?;
    /// let mut servo = p.build(AtPeriod(Observer::new(first, 20.0)?))?;
    /// let mut axis = CompensatorState::default();
    /// let r = Setpoint { x: 0.0, v: 0.1, a: 0.0 };
    /// for k in 0..100 {
    ///     servo.tick(&mut axis, 1e-4 * k as f32, r);
    /// }
    /// // commissioning measured more friction: swap it in, one axis
    /// let measured = LuGreParams { sigma0: 400.0, sigma2: 0.03, ..LuGreParams::OLSSON_1998 };
    /// servo.retune(&mut axis, AtPeriod(Observer::new(measured.build_at(1e-3)?, 20.0)?))?;
    /// let tick = servo.tick(&mut axis, 1e-2, r);
    /// assert!(tick.accepted && tick.command.abs() <= 10.0);
    /// // a model for another period is refused, the axis untouched
    /// let before = axis;
    /// let other = AtPeriod(Observer::new(measured.build_at(5e-4)?, 20.0)?);
    /// assert_eq!(servo.retune(&mut axis, other).err(), Some(ParamError::PeriodMismatch));
    /// assert_eq!(axis, before);
    /// // several axes on one compensator: one new compensator, each axis carried over
    /// let (mut a, mut b) = (axis, axis);
    /// let next = servo.retuned(AtPeriod(Observer::new(first, 20.0)?))?;
    /// next.carry_over(&servo, &mut a);
    /// next.carry_over(&servo, &mut b);
    /// servo = next;
    /// # let _ = (servo, a, b);
    /// # Ok::<(), ParamError>(())
    /// ```
    pub fn retune(
        &mut self,
        state: &mut CompensatorState<S, C::State>,
        compensation: C,
    ) -> Result<(), ParamError> {
        let next = self.retuned(compensation)?;
        next.carry_over(self, state);
        *self = next;
        Ok(())
    }
}
