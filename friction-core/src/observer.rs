//! Friction observer with a correction gain (Canudas de Wit et al. 1995;
//! Olsson et al. 1998), for every state model: see [`Observer`].

use crate::bits::Flag;
use crate::fixed_step::FixedStepObservable;
use crate::model::{checked_inputs, convert, non_negative, FrictionModel, ParamError};
use crate::scalar::all_finite;
use crate::Scalar;

/// A state model whose elastic input accepts an observer's velocity offset.
pub trait Observable<S: Scalar>: FrictionModel<S> {
    /// Advances the state like [`FrictionModel::step`], with `v - correction`
    /// straining the elastic part and `v` driving the sliding law. Inputs are
    /// already checked: `v` finite and clamped, `h` finite and `>= 0`,
    /// `|correction| <= VELOCITY_LIMIT`. `h = 0` leaves the state bitwise
    /// unchanged. Each state stays within its bound; the damping term (only
    /// if `damping`) uses the rate the state actually took. Returns the force.
    fn step_corrected(
        &self,
        state: &mut Self::State,
        v: S,
        correction: S,
        h: S,
        damping: bool,
    ) -> S;

    /// The largest `|F|` the model can produce at velocity `v`, from any
    /// state within its bounds (for LuGre `Fs + sigma1(v) |v| (1 + Fs/Fc) +
    /// sigma2 |v|`; `Fs` at rest).
    fn force_bound(&self, v: S) -> S;

    /// Makes `state`, an estimate of the model `old`, an estimate of this
    /// model (a re-tuned drive: [`Compensator::retune`](crate::Compensator::retune)).
    /// The default restarts it at rest (`Default`): always within this
    /// model's bounds, but the force the old state held is lost. A model
    /// whose state is a force, or maps to one, overrides it to keep that
    /// force where the new bounds allow (LuGre: `z = z_old sigma0_old /
    /// sigma0`, within `±Fs/sigma0`).
    fn carry_over(&self, old: &Self, state: &mut Self::State) {
        let _ = old;
        *state = Self::State::default();
    }

    /// Whether the model's friction grows with the torque its transmission
    /// carries ([`LuGreLoad`](crate::LuGreLoad)): a
    /// [`Compensator`](crate::Compensator) running an observer on it then
    /// tells it the motor torque `kc u` of each command issued
    /// ([`Self::set_motor_torque`]) and the external torque it is given
    /// ([`Compensator::set_external_torque`](crate::Compensator::set_external_torque)).
    const LOADED: bool = false;

    /// The motor torque for the next steps, for a model that is
    /// [`LOADED`](Self::LOADED); the default ignores it.
    fn set_motor_torque(&self, state: &mut Self::State, torque: S) {
        let _ = (state, torque);
    }

    /// As [`Self::set_motor_torque`], the external torque
    /// ([`Compensator::set_external_torque`](crate::Compensator::set_external_torque)).
    fn set_external_torque(&self, state: &mut Self::State, torque: S) {
        let _ = (state, torque);
    }
}

/// An observer built around a model `M`.
///
/// Friction observer with a correction gain (Canudas de Wit et al. 1995;
/// Olsson et al. 1998), for every state model.
///
/// The friction state is not measured. The observer runs the model on the
/// measured velocity `v` with a correction from the position error
/// `e = x - x_ref` (measured minus desired). The correction is a velocity
/// offset on the model's elastic input: `v - k e` is what strains the
/// bristles (elements, bond), while the sliding law and the Stribeck curve
/// still see the measured `v`. For LuGre:
///
/// ```text
/// dz^/dt = (v - k e) - sigma0 |v| z^ / g(v)
/// F^     = sigma0 z^ + sigma1 dz^/dt + sigma2 v
/// ```
///
/// and a controller adds `F^` to its output. With the opposite sign of `e`
/// the correction destabilises the loop.
///
/// The estimate is bounded by what the model can produce:
/// - `k e` saturates at [`VELOCITY_LIMIT`](crate::VELOCITY_LIMIT) instead of overflowing;
/// - each state is clamped to its bound (`|z^| <= Fs/sigma0` for LuGre), an
///   anti-windup the continuous-time observer does not have, and the
///   `sigma1 dz^/dt` term uses the rate the state actually took: zero while
///   the state is held at its bound;
/// - `F^` is clipped to [`Observable::force_bound`]`(v)`, the largest force
///   the model produces at that velocity from any state (`Fs` at `v = 0`).
///
/// So any finite `v`, `e`, `k` and `h` give a finite estimate and a finite
/// state. In a sampled loop the velocity is a sample late and noisy, so the
/// `sigma1 dz^/dt` feed-forward can cost more than it gains: it is a switch
/// ([`Observer::with_damping`]).
///
/// ```
/// use friction_core::{LuGreParams, LuGreState, Observer};
/// let model = LuGreParams::CANUDAS_1995.build::<f32>()?;
/// let observer = Observer::new(model, 100.0)?;
/// let mut z_hat = LuGreState::default();
/// // measured velocity 1 mm/s, position 1 µm ahead of the reference
/// let f_hat = observer.step(&mut z_hat, 1e-3, 1e-6, 1e-3);
/// assert!(f_hat > 0.0 && f_hat.is_finite());
/// // whatever the error, at rest the estimate stays within Fs = 1.5 N
/// let f_hat = observer.step(&mut z_hat, 0.0, 1e30, 1e-3);
/// assert!(f_hat.abs() <= 1.5);
/// # Ok::<(), friction_core::ParamError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Observer<M, S> {
    model: M,
    gain: S,
    /// Whether the `sigma1 dz^/dt` term is included (a byte: `crate::bits`).
    damping: Flag,
}

impl<S: Scalar, M> Observer<M, S> {
    /// Wraps `model` with correction gain `k >= 0` (1/s; parameter `gain`).
    /// The `sigma1 dz^/dt` term is included by default. A gain the scalar
    /// cannot hold within 0.1 % is refused, naming `gain`: too large
    /// (`NotRepresentable`, e.g. 1e9 in Q16.16) or too small (`Underflow`,
    /// e.g. 1e-6 in Q16.16), never saturated or zeroed.
    ///
    /// ```
    /// # #[cfg(feature = "fixed")] {
    /// use friction_core::{Fixed32, LuGreParams, Observer, ParamError};
    /// let model = LuGreParams::OLSSON_1998.build_fixed_step::<Fixed32>(1e-3)?;
    /// type Q = Observer<friction_core::LuGreFixedStep<Fixed32>, Fixed32>;
    /// assert!(Q::new(model, 200.0).is_ok());
    /// assert_eq!(Q::new(model, 1e9).err(), Some(ParamError::NotRepresentable("gain")));
    /// assert_eq!(Q::new(model, 1e-6).err(), Some(ParamError::Underflow("gain")));
    /// # }
    /// # Ok::<(), friction_core::ParamError>(())
    /// ```
    pub fn new(model: M, gain: f64) -> Result<Self, ParamError> {
        non_negative("gain", gain)?;
        let gain = if gain == 0.0 {
            S::ZERO
        } else {
            convert("gain", gain)?
        };
        Ok(Self {
            model,
            gain,
            damping: Flag::new(true),
        })
    }

    /// Includes (`true`) or drops the `sigma1 dz^/dt` term from the estimate.
    pub fn with_damping(self, damping: bool) -> Self {
        Self {
            damping: Flag::new(damping),
            ..self
        }
    }

    /// The wrapped model.
    pub fn model(&self) -> &M {
        &self.model
    }

    /// The correction gain `k` (1/s).
    pub fn gain(&self) -> S {
        self.gain
    }
}

impl<S: Scalar, M: Observable<S>> Observer<M, S> {
    /// Advances the estimate by `h` with measured velocity `v` and position
    /// error `e = x - x_ref`, and returns the friction estimate `F^`, within
    /// `±force_bound(v)`. A non-finite `v`, `e` or `h` (or `h < 0`) leaves the
    /// estimate untouched and returns the model's hold force; `h = 0` leaves
    /// it bitwise unchanged and returns the estimate at the current state.
    #[inline]
    pub fn step(&self, state: &mut M::State, v: S, e: S, h: S) -> S {
        match checked_inputs(v, h) {
            Some(v) if e.is_finite() => {
                // k and e are finite: k e is finite or infinite, never NaN
                let correction = (self.gain * e).sat(S::VELOCITY_LIMIT);
                let f = self
                    .model
                    .step_corrected(state, v, correction, h, self.damping.get());
                f.sat(self.model.force_bound(v))
            }
            _ => self.model.hold_force(state),
        }
    }
}

impl<S: Scalar, M: FixedStepObservable<S>> Observer<M, S> {
    /// [`Observer::step`] for a model built for one period
    /// ([`FixedStepModel`](crate::FixedStepModel)): advances the estimate by that period with
    /// measured velocity `v` and position error `e`; the same bounds and the
    /// same handling of non-finite inputs.
    ///
    /// ```
    /// use friction_core::{LuGreFixedStepState, LuGreParams, Observer};
    /// let model = LuGreParams::CANUDAS_1995.build_fixed_step::<f32>(1e-3)?;
    /// let observer = Observer::new(model, 100.0)?;
    /// let mut w_hat = LuGreFixedStepState::default();
    /// let f_hat = observer.step_fixed(&mut w_hat, 1e-3, 1e-6);
    /// assert!(f_hat > 0.0 && f_hat.is_finite());
    /// assert!(observer.step_fixed(&mut w_hat, 0.0, 1e30).abs() <= 1.5);
    /// # Ok::<(), friction_core::ParamError>(())
    /// ```
    #[inline]
    pub fn step_fixed(&self, state: &mut M::State, v: S, e: S) -> S {
        if all_finite([v, e]) {
            let limit = S::VELOCITY_LIMIT;
            let v = v.sat(limit);
            let correction = (self.gain * e).sat(limit);
            let f = self
                .model
                .step_corrected(state, v, correction, self.damping.get());
            f.sat(self.model.force_bound(v))
        } else {
            self.model.hold_force(state)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{LuGreParams, LuGreState};

    #[test]
    fn zero_gain_observer_is_the_model() {
        let m = LuGreParams::CANUDAS_1995.build::<f64>().unwrap();
        let o = Observer::new(m, 0.0).unwrap();
        let (mut a, mut b) = (LuGreState::default(), LuGreState::default());
        for k in 0..500 {
            let v = 1e-3 * libm::sin(k as f64 * 0.02);
            let fm = m.step(&mut a, v, 1e-3);
            let fo = o.step(&mut b, v, 123.0, 1e-3);
            assert_eq!(fm, fo);
        }
    }

    #[test]
    fn correction_pulls_the_estimate_against_the_error() {
        let m = LuGreParams::CANUDAS_1995.build::<f64>().unwrap();
        let o = Observer::new(m, 1000.0).unwrap().with_damping(false);
        let mut z = LuGreState::default();
        // at rest, measured position ahead of reference: estimate goes negative
        let f = o.step(&mut z, 0.0, 1e-6, 1e-3);
        assert!(z.z < 0.0 && f < 0.0);
        // and never leaves the bound
        for _ in 0..10_000 {
            o.step(&mut z, 0.0, 1.0, 1e-3);
        }
        assert_eq!(z.z, -m.z_max());
    }

    #[test]
    fn bad_gain_and_inputs() {
        let m = LuGreParams::CANUDAS_1995.build::<f32>().unwrap();
        assert_eq!(
            Observer::<_, f32>::new(m, -1.0).err(),
            Some(ParamError::Negative("gain"))
        );
        assert_eq!(
            Observer::<_, f32>::new(m, 1e300).err(),
            Some(ParamError::NotRepresentable("gain"))
        );
        let o = Observer::new(m, 10.0).unwrap();
        let mut z = LuGreState { z: 1e-6 };
        assert_eq!(o.step(&mut z, 0.0, f32::NAN, 1e-3), 1e5 * 1e-6);
        assert_eq!(z.z, 1e-6);
    }
}
