//! The fixed-step form: a model built for one sample period `h`: see
//! [`FixedStepModel`].

use crate::Scalar;
use core::fmt::Debug;

/// A friction model built for one sample period.
///
/// The fixed-step form: a model built for one sample period `h`.
///
/// Most firmware runs a model at one rate. `XxxParams::build_fixed_step::<S>(h)`
/// returns a model whose `step(&self, state, v)` takes no `h`: everything
/// that depends on `h` (such as `sigma0 h`) is formed once, in `f64`, when it
/// is built, and `h` needs no run-time check. Its states carry forces rather
/// than deflections (`w = sigma0 z` in newtons instead of `z` in metres), so
/// that the same code runs on a fixed-point scalar, where micrometres do not
/// fit. The discretisation is the variable-step form's (the same exact
/// held-velocity solution), so the two agree to rounding.
///
/// The step contract is the variable-step one ([`FrictionModel`]) without
/// `h`: a non-finite `v` leaves the state untouched and returns
/// [`FixedStepModel::hold_force`]; `|v|` is clamped to [`VELOCITY_LIMIT`];
/// the force is always finite.
///
/// The [`Observer`](crate::Observer) runs on a fixed-step model with
/// [`Observer::step_fixed`](crate::Observer::step_fixed), and the
/// [`Compensator`](crate::Compensator) accepts such an observer when it is
/// built for the same period.
///
/// [`FrictionModel`]: crate::FrictionModel
/// [`VELOCITY_LIMIT`]: crate::VELOCITY_LIMIT
pub trait FixedStepModel<S: Scalar> {
    /// The internal state; `Default` is the contact at rest, unstrained.
    type State: Copy + Default + Debug;

    /// The sample period `h` (s) the model was built for.
    fn period(&self) -> f64;

    /// Advances `state` by one period with velocity `v` held; returns the force.
    fn step(&self, state: &mut Self::State, v: S) -> S;

    /// The force the state alone holds, returned when `v` is not finite.
    fn hold_force(&self, state: &Self::State) -> S;
}

/// A fixed-step model whose elastic input accepts an observer's velocity
/// offset: the fixed-step twin of [`Observable`](crate::Observable).
pub trait FixedStepObservable<S: Scalar>: FixedStepModel<S> {
    /// Advances the state by one period like [`FixedStepModel::step`], with
    /// `v - correction` straining the elastic part and `v` driving the
    /// sliding law. Inputs are checked by the caller: `v` finite and clamped,
    /// `|correction| <= VELOCITY_LIMIT`. Each state stays within its bound;
    /// the damping term (only if `damping`) uses the rate actually taken.
    fn step_corrected(&self, state: &mut Self::State, v: S, correction: S, damping: bool) -> S;

    /// The largest `|F|` the model can produce at velocity `v` from any state
    /// within its bounds.
    fn force_bound(&self, v: S) -> S;

    /// [`Observable::carry_over`](crate::Observable::carry_over) for the
    /// fixed-step form: makes `state`, an estimate of `old`, one of this
    /// model. The default restarts it at rest; LuGre and Dahl keep their
    /// force (rescaled to this model's force scale, within its bound).
    fn carry_over(&self, old: &Self, state: &mut Self::State) {
        let _ = old;
        *state = Self::State::default();
    }

    /// [`Observable::LOADED`](crate::Observable::LOADED) for the fixed-step
    /// form.
    const LOADED: bool = false;

    /// [`Observable::set_motor_torque`](crate::Observable::set_motor_torque)
    /// for the fixed-step form.
    fn set_motor_torque(&self, state: &mut Self::State, torque: S) {
        let _ = (state, torque);
    }

    /// [`Observable::set_external_torque`](crate::Observable::set_external_torque)
    /// for the fixed-step form.
    fn set_external_torque(&self, state: &mut Self::State, torque: S) {
        let _ = (state, torque);
    }
}

/// Checks a design-time sample period: finite and `> 0`.
pub(crate) fn period(h: f64) -> Result<f64, crate::ParamError> {
    crate::model::magnitude("h", h)
}

/// The fixed-step forms' input check: `Some(v)` clamped to
/// `±S::VELOCITY_LIMIT` when `v` is finite, `None` when it is not. Within the
/// limit (the common case) it costs one comparison: a NaN fails it, and
/// `is_finite` is asked only beyond the limit. Fixed point, always finite,
/// clamps (the same value, without a saturating `|v|` before the clamp,
/// which the Cortex-M0 would pay on every step).
#[inline]
pub(crate) fn checked_velocity<S: Scalar>(v: S) -> Option<S> {
    let limit = S::VELOCITY_LIMIT;
    if S::ALWAYS_FINITE {
        return Some(v.sat(limit));
    }
    if v.abs() <= limit {
        Some(v)
    } else if v.is_finite() {
        Some(v.sat(limit))
    } else {
        None
    }
}

/// `-x` when `v < 0`, else `x`: `sign(v) x` for `v != 0`, with one
/// comparison instead of `sign`'s two and a multiplication. Where it
/// replaces `sign(v) x` the value at `v = 0` is never used (the step moves
/// nothing there).
#[inline]
pub(crate) fn signed<S: Scalar>(v: S, x: S) -> S {
    // on ARM the comparison itself: through the trait method the compiler
    // inlines GMS's f32 step worse on a Cortex-M4F (see the cost guide)
    if cfg!(target_arch = "arm") {
        if v < S::ZERO {
            -x
        } else {
            x
        }
    } else {
        x.negated_if_negative(v)
    }
}

/// A force state carried from one model to another
/// ([`FixedStepObservable::carry_over`]): `x ratio` (the ratio of the two
/// force scales, or of two stiffnesses) within `±bound`, formed in `f64`
/// (not on the hot path); 0 for a non-finite result.
pub(crate) fn carried<S: Scalar>(x: S, ratio: f64, bound: S) -> S {
    let b = bound.to_f64();
    let y = x.to_f64() * ratio;
    if y.is_finite() {
        S::from_f64(y.max(-b).min(b)).sat(bound)
    } else {
        S::ZERO
    }
}

/// The ratio `k_new / k_old` of two force scales given as their
/// `log2(1 / k)`.
pub(crate) fn scale_ratio(old_inv_exp: i8, new_inv_exp: i8) -> f64 {
    libm::exp2(f64::from(old_inv_exp) - f64::from(new_inv_exp))
}
