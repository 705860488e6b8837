//! Friction observer with a correction gain (Canudas de Wit et al. 1995;
//! Olsson et al. 1998).
//!
//! The friction state is not measured. The observer runs the model on the
//! measured velocity with a correction from the position error
//! `e = x - x_ref` (measured minus desired):
//!
//! ```text
//! dz^/dt = v - sigma0 |v| z^ / g(v) - k e
//! F^     = sigma0 z^ + sigma1 dz^/dt + sigma2 v
//! ```
//!
//! and a controller adds `F^` to its output. With the opposite sign of `e`
//! the correction destabilises the loop. The estimate `z^` is clamped to the
//! model's bound `±Fs/sigma0`, an anti-windup the continuous-time observer
//! does not have. In a sampled loop the velocity is a sample late and noisy,
//! so the `sigma1 dz^/dt` feed-forward can cost more than it gains: it is a
//! switch ([`Observer::with_damping`]).

use crate::model::{checked_inputs, non_negative, FrictionModel, ParamError};
use crate::Scalar;

/// A state model whose state equation accepts an observer's correction term.
pub trait Observable<S: Scalar>: FrictionModel<S> {
    /// Advances the state like [`FrictionModel::step`] with `correction`
    /// subtracted from `dz/dt`; inputs are already checked and clamped.
    /// Returns the force, with the `sigma1 dz/dt` term only if `damping`.
    fn step_corrected(
        &self,
        state: &mut Self::State,
        v: S,
        correction: S,
        h: S,
        damping: bool,
    ) -> S;
}

/// An observer built around a model `M`.
///
/// ```
/// use friction_core::{LuGreParams, LuGreState, Observer};
/// let model = LuGreParams::CANUDAS_1995.build::<f32>()?;
/// let observer = Observer::new(model, 100.0)?;
/// let mut z_hat = LuGreState::default();
/// // measured velocity 1 mm/s, position 1 µm ahead of the reference
/// let f_hat = observer.step(&mut z_hat, 1e-3, 1e-6, 1e-3);
/// assert!(f_hat > 0.0 && f_hat.is_finite());
/// # Ok::<(), friction_core::ParamError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Observer<M, S> {
    model: M,
    gain: S,
    damping: bool,
}

impl<S: Scalar, M: Observable<S>> Observer<M, S> {
    /// Wraps `model` with correction gain `k >= 0` (1/s; parameter `gain`).
    /// The `sigma1 dz^/dt` term is included by default.
    pub fn new(model: M, gain: f64) -> Result<Self, ParamError> {
        non_negative("gain", gain)?;
        let gain = S::from_f64(gain);
        if !gain.is_finite() {
            return Err(ParamError::NotRepresentable("gain"));
        }
        Ok(Self {
            model,
            gain,
            damping: true,
        })
    }

    /// Includes (`true`) or drops the `sigma1 dz^/dt` term from the estimate.
    pub fn with_damping(self, damping: bool) -> Self {
        Self { damping, ..self }
    }

    /// The wrapped model.
    pub fn model(&self) -> &M {
        &self.model
    }

    /// Advances the estimate by `h` with measured velocity `v` and position
    /// error `e = x - x_ref`, and returns the friction estimate `F^`.
    /// A non-finite `v`, `e` or `h` (or `h < 0`) leaves the estimate untouched
    /// and returns the model's hold force (`sigma0 z^`).
    #[inline]
    pub fn step(&self, state: &mut M::State, v: S, e: S, h: S) -> S {
        match checked_inputs(v, h) {
            Some(v) if e.is_finite() => {
                self.model
                    .step_corrected(state, v, self.gain * e, h, self.damping)
            }
            _ => self.model.hold_force(state),
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
            Observer::new(m, -1.0).err(),
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
