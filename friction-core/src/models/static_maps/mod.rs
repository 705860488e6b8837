//! The static friction maps (Coulomb, Coulomb-viscous, asymmetric
//! Coulomb-viscous, Stribeck, Karnopp): forces of the velocity alone.

#[cfg(test)]
mod tests;

use crate::model::{
    check_force, checked_inputs, convert, magnitude, magnitude_or_zero, FrictionModel, ParamError,
};
use crate::stribeck::{StribeckCurve, StribeckParams};
use crate::Scalar;

/// Coulomb friction `F = Fc sign(v)` (`model = "coulomb"`).
///
/// ```
/// use friction_core::{CoulombParams, FrictionModel};
/// let m = CoulombParams { fc: 0.3 }.build::<f32>()?;
/// assert_eq!(m.step(&mut (), -2.0, 1e-3), -0.3);
/// # Ok::<(), friction_core::ParamError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CoulombParams {
    /// Coulomb level `Fc > 0`.
    pub fc: f64,
}

impl CoulombParams {
    /// Validates and builds the map.
    pub fn build<S: Scalar>(&self) -> Result<CoulombViscous<S>, ParamError> {
        CoulombViscousParams {
            fc: self.fc,
            sigma2: 0.0,
        }
        .build()
    }
}

/// Coulomb plus viscous friction `F = Fc sign(v) + sigma2 v` (`model = "coulomb-viscous"`).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CoulombViscousParams {
    /// Coulomb level `Fc > 0`.
    pub fc: f64,
    /// Viscous coefficient `sigma2 >= 0`.
    pub sigma2: f64,
}

impl CoulombViscousParams {
    /// Validates and builds the map.
    pub fn build<S: Scalar>(&self) -> Result<CoulombViscous<S>, ParamError> {
        magnitude("fc", self.fc)?;
        magnitude_or_zero("sigma2", self.sigma2)?;
        check_force::<S>("sigma2", self.sigma2 * S::VELOCITY_LIMIT.to_f64())?;
        Ok(CoulombViscous {
            fc: convert("fc", self.fc)?,
            sigma2: convert("sigma2", self.sigma2)?,
        })
    }
}

/// The built Coulomb + viscous map.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CoulombViscous<S> {
    fc: S,
    sigma2: S,
}

impl<S: Scalar> CoulombViscous<S> {
    /// `Fc sign(v) + sigma2 v`.
    #[inline]
    pub fn force(&self, v: S) -> S {
        // the level chosen, not multiplied by the sign: a Q16.16 product is
        // several 32-bit ones on a Cortex-M0
        let coulomb = if v > S::ZERO {
            self.fc
        } else if v < S::ZERO {
            -self.fc
        } else {
            S::ZERO
        };
        coulomb + self.sigma2 * v
    }
}

impl<S: Scalar> FrictionModel<S> for CoulombViscous<S> {
    type State = ();
    /// Static: ignores `h`; invalid input returns 0.
    fn step(&self, _state: &mut (), v: S, h: S) -> S {
        checked_inputs(v, h).map_or(S::ZERO, |v| self.force(v))
    }
    fn hold_force(&self, _state: &()) -> S {
        S::ZERO
    }
}

/// Coulomb plus viscous friction with its own levels for each direction
/// (`model = "asymmetric-coulomb-viscous"`): `F = fc_pos + sigma2_pos v`
/// for `v > 0`, `F = -fc_neg + sigma2_neg v` for `v < 0`, 0 at rest. The
/// map robot joint stacks configure: a joint's gravity load and seals make
/// it rub harder one way than the other, which one `Fc` cannot fit.
///
/// ```
/// use friction_core::{AsymmetricCoulombViscousParams, FrictionModel};
/// let m = AsymmetricCoulombViscousParams {
///     fc_pos: 1.2, sigma2_pos: 0.5, fc_neg: 0.8, sigma2_neg: 0.25,
/// }
/// .build::<f64>()?;
/// assert_eq!(m.step(&mut (), 2.0, 1e-3), 1.2 + 0.5 * 2.0);
/// assert_eq!(m.step(&mut (), -2.0, 1e-3), -0.8 - 0.25 * 2.0);
/// # Ok::<(), friction_core::ParamError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AsymmetricCoulombViscousParams {
    /// Coulomb level for `v > 0`, `fc_pos > 0`.
    pub fc_pos: f64,
    /// Viscous coefficient for `v > 0`, `sigma2_pos >= 0`.
    pub sigma2_pos: f64,
    /// Coulomb level (a magnitude) for `v < 0`, `fc_neg > 0`.
    pub fc_neg: f64,
    /// Viscous coefficient for `v < 0`, `sigma2_neg >= 0`.
    pub sigma2_neg: f64,
}

impl AsymmetricCoulombViscousParams {
    /// Validates and builds the map: each side as [`CoulombViscousParams`]
    /// checks its one side, the errors naming the side's parameter.
    pub fn build<S: Scalar>(&self) -> Result<AsymmetricCoulombViscous<S>, ParamError> {
        magnitude("fc_pos", self.fc_pos)?;
        magnitude_or_zero("sigma2_pos", self.sigma2_pos)?;
        magnitude("fc_neg", self.fc_neg)?;
        magnitude_or_zero("sigma2_neg", self.sigma2_neg)?;
        let v_max = S::VELOCITY_LIMIT.to_f64();
        check_force::<S>("sigma2_pos", self.fc_pos + self.sigma2_pos * v_max)?;
        check_force::<S>("sigma2_neg", self.fc_neg + self.sigma2_neg * v_max)?;
        Ok(AsymmetricCoulombViscous {
            fc_pos: convert("fc_pos", self.fc_pos)?,
            sigma2_pos: convert("sigma2_pos", self.sigma2_pos)?,
            fc_neg: convert("fc_neg", self.fc_neg)?,
            sigma2_neg: convert("sigma2_neg", self.sigma2_neg)?,
        })
    }
}

/// The built asymmetric Coulomb + viscous map.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AsymmetricCoulombViscous<S> {
    fc_pos: S,
    sigma2_pos: S,
    fc_neg: S,
    sigma2_neg: S,
}

impl<S: Scalar> AsymmetricCoulombViscous<S> {
    /// `fc_pos + sigma2_pos v` for `v > 0`, `-fc_neg + sigma2_neg v` for
    /// `v < 0`, 0 at `v = 0` (as `sign(0) = 0` in [`CoulombViscous`]).
    #[inline]
    pub fn force(&self, v: S) -> S {
        if v > S::ZERO {
            self.fc_pos + self.sigma2_pos * v
        } else if v < S::ZERO {
            self.sigma2_neg * v - self.fc_neg
        } else {
            S::ZERO
        }
    }
}

impl<S: Scalar> FrictionModel<S> for AsymmetricCoulombViscous<S> {
    type State = ();
    /// Static: ignores `h`; invalid input returns 0.
    fn step(&self, _state: &mut (), v: S, h: S) -> S {
        checked_inputs(v, h).map_or(S::ZERO, |v| self.force(v))
    }
    fn hold_force(&self, _state: &()) -> S {
        S::ZERO
    }
}

/// The Stribeck map `F = g(v) sign(v) + sigma2 v` (`model = "stribeck"`), the
/// steady state of most dynamic models.
///
/// ```
/// use friction_core::{StribeckMapParams, StribeckParams, FrictionModel};
/// let curve = StribeckParams { fc: 1.0, fs: 1.5, vs: 1e-3, exponent: 2.0 };
/// let m = StribeckMapParams { curve, sigma2: 0.4 }.build::<f64>()?;
/// assert_eq!(m.step(&mut (), 0.0, 1e-3), 0.0);
/// assert!((m.force(1e-3) - (1.0 + 0.5 / 1f64.exp() + 0.4e-3)).abs() < 1e-12);
/// # Ok::<(), friction_core::ParamError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct StribeckMapParams {
    /// The Stribeck curve.
    pub curve: StribeckParams,
    /// Viscous coefficient `sigma2 >= 0`.
    pub sigma2: f64,
}

impl StribeckMapParams {
    /// Validates and builds the map.
    pub fn build<S: Scalar>(&self) -> Result<StribeckMap<S>, ParamError> {
        let curve = self.curve.build()?;
        magnitude_or_zero("sigma2", self.sigma2)?;
        check_force::<S>("sigma2", self.sigma2 * S::VELOCITY_LIMIT.to_f64())?;
        Ok(StribeckMap {
            curve,
            sigma2: convert("sigma2", self.sigma2)?,
        })
    }
}

/// The built Stribeck map.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct StribeckMap<S> {
    curve: StribeckCurve<S>,
    sigma2: S,
}

impl<S: Scalar> StribeckMap<S> {
    /// `g(v) sign(v) + sigma2 v`.
    #[inline]
    pub fn force(&self, v: S) -> S {
        self.curve.eval(v) * v.sign() + self.sigma2 * v
    }

    /// The curve `g`.
    pub fn curve(&self) -> &StribeckCurve<S> {
        &self.curve
    }
}

impl<S: Scalar> FrictionModel<S> for StribeckMap<S> {
    type State = ();
    /// Static: ignores `h`; invalid input returns 0.
    fn step(&self, _state: &mut (), v: S, h: S) -> S {
        checked_inputs(v, h).map_or(S::ZERO, |v| self.force(v))
    }
    fn hold_force(&self, _state: &()) -> S {
        S::ZERO
    }
}

/// Karnopp's model (Karnopp 1985): inside the band `|v| < dv` the contact
/// sticks and friction balances the applied force `u` up to `Fs`,
/// `F = sat(Fs, u)`; outside it is the Stribeck map. It needs the applied
/// force as a second input, so it is not a [`FrictionModel`].
///
/// ```
/// use friction_core::{Karnopp, StribeckMapParams, StribeckParams};
/// let curve = StribeckParams { fc: 1.0, fs: 1.5, vs: 1e-3, exponent: 2.0 };
/// let map = StribeckMapParams { curve, sigma2: 0.0 }.build::<f64>()?;
/// let k = Karnopp::new(map, 1e-4)?;
/// assert_eq!(k.force(0.0, 1.0), 1.0);   // sticking: balances u
/// assert_eq!(k.force(0.0, 9.0), 1.5);   // saturates at Fs
/// # Ok::<(), friction_core::ParamError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Karnopp<S> {
    map: StribeckMap<S>,
    dv: S,
}

impl<S: Scalar> Karnopp<S> {
    /// Builds the model from a Stribeck map and the stick band `dv > 0` (parameter `dv`).
    pub fn new(map: StribeckMap<S>, dv: f64) -> Result<Self, ParamError> {
        magnitude("dv", dv)?;
        Ok(Self {
            map,
            dv: convert("dv", dv)?,
        })
    }

    /// Friction for velocity `v` and applied force `u`; 0 when an input is not finite.
    #[inline]
    pub fn force(&self, v: S, u: S) -> S {
        if !(v.is_finite() && u.is_finite()) {
            return S::ZERO;
        }
        if v.abs() < self.dv {
            u.sat(self.map.curve.fs())
        } else {
            self.map.force(v)
        }
    }
}
