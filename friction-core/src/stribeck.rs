//! The Stribeck curve `g(v)` and the static friction maps: see
//! [`StribeckCurve`].

use crate::model::{
    check_force, checked_inputs, convert, convert_derived, magnitude, magnitude_or_zero,
    FrictionModel, ParamError,
};
use crate::Scalar;

/// Parameters of the Stribeck curve, in `f64`.
///
/// ```
/// use friction_core::StribeckParams;
/// let g = StribeckParams { fc: 1.0, fs: 1.5, vs: 1e-3, exponent: 2.0 }.build::<f32>()?;
/// assert_eq!(g.eval(0.0), 1.5);
/// assert!((g.eval(1.0) - 1.0).abs() < 1e-6);
/// # Ok::<(), friction_core::ParamError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct StribeckParams {
    /// Coulomb friction level `Fc > 0` (N).
    pub fc: f64,
    /// Static friction level `Fs >= Fc` (N).
    pub fs: f64,
    /// Stribeck velocity `vs > 0` (m/s).
    pub vs: f64,
    /// Shape exponent `delta > 0` (2 is usual, 1 in Åström & Canudas de Wit 2008).
    pub exponent: f64,
}

impl StribeckParams {
    /// The default exponent, `delta = 2`.
    pub const DEFAULT_EXPONENT: f64 = 2.0;

    /// Checks `Fc > 0`, `Fs >= Fc`, `vs > 0`, `delta > 0`, all finite.
    pub fn validate(&self) -> Result<(), ParamError> {
        magnitude("fc", self.fc)?;
        magnitude("fs", self.fs)?;
        magnitude("vs", self.vs)?;
        magnitude("stribeck_exponent", self.exponent)?;
        if self.fs < self.fc {
            return Err(ParamError::StaticBelowCoulomb);
        }
        Ok(())
    }

    /// Validates and builds the run-time curve.
    pub fn build<S: Scalar>(&self) -> Result<StribeckCurve<S>, ParamError> {
        self.validate()?;
        let shape = if self.exponent == 2.0 {
            Shape::Square
        } else if self.exponent == 1.0 {
            Shape::Linear
        } else {
            Shape::Power(convert("stribeck_exponent", self.exponent)?)
        };
        // eval_fast's 2^-p' with p' = p log2 e: log2 e folded into 1/vs
        // (squared by the Square shape), or applied after powf
        let fold = match shape {
            Shape::Square if S::EXP2_FOLDS => libm::sqrt(core::f64::consts::LOG2_E),
            Shape::Linear if S::EXP2_FOLDS => core::f64::consts::LOG2_E,
            _ => 1.0,
        };
        Ok(StribeckCurve {
            fc: convert("fc", self.fc)?,
            fs: convert("fs", self.fs)?,
            fs_minus_fc: convert("fs", self.fs - self.fc)?,
            inv_vs: convert_derived("vs", 1.0 / self.vs)?,
            inv_vs_fast: convert_derived("vs", fold / self.vs)?,
            shape: StoredShape::new(shape),
        })
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Shape<S> {
    Square,
    Linear,
    Power(S),
}

/// A [`Shape`] as a curve stores it: a tag byte and the exponent, so that
/// every bit pattern is a shape (see `crate::bits`): tag 0 the square, 1
/// the linear shape, any other byte the power `delta` (0 in the others,
/// so that equal shapes compare equal).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct StoredShape<S> {
    tag: u8,
    delta: S,
}

impl<S: Scalar> StoredShape<S> {
    fn new(shape: Shape<S>) -> Self {
        let (tag, delta) = match shape {
            Shape::Square => (0, S::ZERO),
            Shape::Linear => (1, S::ZERO),
            Shape::Power(delta) => (2, delta),
        };
        Self { tag, delta }
    }

    /// The shape: every tag byte is one.
    #[inline(always)]
    fn get(self) -> Shape<S> {
        match self.tag {
            0 => Shape::Square,
            1 => Shape::Linear,
            _ => Shape::Power(self.delta),
        }
    }
}

/// The built Stribeck curve `g(v)`: magnitude, even, between `Fc` and `Fs`.
///
/// The Stribeck curve `g(v)` and the static friction maps.
///
/// `g(v) = Fc + (Fs - Fc) exp(-|v / vs|^delta)` (Stribeck 1902; the form used
/// by Canudas de Wit et al. 1995 with `delta = 2`, and by Åström & Canudas de
/// Wit 2008 with `delta = 1`). Static maps have no state: they are the
/// baseline every dynamic model is compared with, and the feed-forward of
/// the simplest compensators.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct StribeckCurve<S> {
    fc: S,
    fs: S,
    fs_minus_fc: S,
    inv_vs: S,
    /// `1/vs` for [`Self::eval_fast`]: times `sqrt(log2 e)` (`delta = 2`) or
    /// `log2 e` (`delta = 1`) where the scalar's cheaper exponential is
    /// `2^-x` ([`Kernels::EXP2_FOLDS`](crate::scalar::sealed::Kernels::EXP2_FOLDS)).
    inv_vs_fast: S,
    shape: StoredShape<S>,
}

impl<S: Scalar> StribeckCurve<S> {
    /// `g(v) = Fc + (Fs - Fc) exp(-|v / vs|^delta)`, always in `[Fc, Fs]`.
    #[inline]
    pub fn eval(&self, v: S) -> S {
        let r = (v * self.inv_vs).abs();
        let p = match self.shape.get() {
            Shape::Square => r * r,
            Shape::Linear => r,
            Shape::Power(delta) => r.powf(delta),
        };
        self.fc + self.fs_minus_fc * (-p).exp()
    }

    /// `g(v)` as [`Self::eval`], with the exponential of the fixed-step forms
    /// (`2^-x` in floating point; in fixed point
    /// a table of `e^-(x^2)` for `delta = 2`, else [`Scalar::exp_neg`]).
    /// Always inlined: on the Cortex-M0 the call and its register saves
    /// cost more than the body saves by being shared.
    #[inline(always)]
    pub fn eval_fast(&self, v: S) -> S {
        let r = (v * self.inv_vs_fast).abs();
        let shape = self.shape.get();
        let e = match shape {
            // fixed point: a table of cubic segments in r (no product r r
            // and no e^-x with its range reduction: a fraction of their
            // cost on a Cortex-M0)
            Shape::Square if !S::EXP2_FOLDS => r.exp_neg_square(),
            _ => {
                let p = match shape {
                    Shape::Square => r * r,
                    Shape::Linear => r,
                    Shape::Power(delta) if S::EXP2_FOLDS => {
                        r.powf(delta) * S::from_f64(core::f64::consts::LOG2_E)
                    }
                    Shape::Power(delta) => r.powf(delta),
                };
                // e^-|v/vs|^delta, as 2^-(|v/vs|^delta log2 e) where that
                // is cheaper
                if S::EXP2_FOLDS {
                    p.exp2_neg()
                } else {
                    p.exp_neg()
                }
            }
        };
        self.fc + self.fs_minus_fc.mul_fraction(e)
    }

    /// The Coulomb level `Fc`.
    pub fn fc(&self) -> S {
        self.fc
    }

    /// The static level `Fs`, the maximum of `g`.
    pub fn fs(&self) -> S {
        self.fs
    }

    /// A curve of zeros, stored where a model has none (so that its stored
    /// form needs no `Option`, see `crate::bits`); never evaluated.
    pub(crate) fn none() -> Self {
        Self {
            fc: S::ZERO,
            fs: S::ZERO,
            fs_minus_fc: S::ZERO,
            inv_vs: S::ZERO,
            inv_vs_fast: S::ZERO,
            shape: StoredShape::new(Shape::Square),
        }
    }
}

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
        self.fc * v.sign() + self.sigma2 * v
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

#[cfg(test)]
mod tests {
    use super::*;

    fn canudas() -> StribeckParams {
        StribeckParams {
            fc: 1.0,
            fs: 1.5,
            vs: 1e-3,
            exponent: 2.0,
        }
    }

    #[test]
    fn curve_values() {
        let g = canudas().build::<f64>().unwrap();
        assert_eq!(g.eval(0.0), 1.5);
        assert!((g.eval(1e-3) - (1.0 + 0.5 * (-1.0f64).exp())).abs() < 1e-15);
        assert_eq!(g.eval(-1e-3), g.eval(1e-3));
        // general and special exponents agree
        let g1 = StribeckParams {
            exponent: 1.0,
            ..canudas()
        }
        .build::<f64>()
        .unwrap();
        let g1p = StribeckParams {
            exponent: 1.0 + 1e-15,
            ..canudas()
        }
        .build::<f64>()
        .unwrap();
        assert!((g1.eval(2e-3) - g1p.eval(2e-3)).abs() < 1e-12);
        let g3 = StribeckParams {
            exponent: 3.0,
            ..canudas()
        }
        .build::<f64>()
        .unwrap();
        assert!((g3.eval(2e-3) - (1.0 + 0.5 * (-8.0f64).exp())).abs() < 1e-14);
    }

    #[test]
    fn invalid_curves_are_rejected() {
        assert_eq!(
            StribeckParams {
                fs: 0.5,
                ..canudas()
            }
            .validate(),
            Err(ParamError::StaticBelowCoulomb)
        );
        assert_eq!(
            StribeckParams {
                vs: -1.0,
                ..canudas()
            }
            .validate(),
            Err(ParamError::NotPositive("vs"))
        );
        assert_eq!(
            StribeckParams {
                exponent: f64::INFINITY,
                ..canudas()
            }
            .validate(),
            Err(ParamError::NotFinite("stribeck_exponent"))
        );
        assert_eq!(
            CoulombParams { fc: 0.0 }.build::<f32>(),
            Err(ParamError::NotPositive("fc"))
        );
    }

    #[test]
    fn maps_oppose_motion() {
        let m = StribeckMapParams {
            curve: canudas(),
            sigma2: 0.4,
        }
        .build::<f32>()
        .unwrap();
        for v in [-1.0f32, -1e-4, 1e-6, 0.3] {
            assert_eq!(m.step(&mut (), v, 1e-3).sign(), v.sign());
        }
        assert_eq!(m.step(&mut (), f32::NAN, 1e-3), 0.0);
        let c = CoulombViscousParams {
            fc: 1.0,
            sigma2: 2.0,
        }
        .build::<f64>()
        .unwrap();
        assert_eq!(c.force(-0.5), -2.0);
    }

    #[test]
    fn asymmetric_map_takes_each_sides_levels() {
        let p = AsymmetricCoulombViscousParams {
            fc_pos: 1.2,
            sigma2_pos: 0.5,
            fc_neg: 0.8,
            sigma2_neg: 0.25,
        };
        let m = p.build::<f64>().unwrap();
        assert_eq!(m.force(2.0), 1.2 + 0.5 * 2.0);
        assert_eq!(m.force(-2.0), -0.8 - 0.25 * 2.0);
        assert_eq!(m.force(0.0), 0.0);
        // a vanishing velocity keeps its side's Coulomb level
        assert_eq!(m.force(1e-12), 1.2 + 0.5 * 1e-12);
        assert_eq!(m.force(-1e-12), -0.8 - 0.25 * 1e-12);
        assert_eq!(m.step(&mut (), f64::NAN, 1e-3), 0.0);
        assert_eq!(m.step(&mut (), 1.0, -1.0), 0.0);
        // equal sides are the symmetric map
        let sym = CoulombViscousParams {
            fc: 0.8,
            sigma2: 0.25,
        }
        .build::<f32>()
        .unwrap();
        let same = AsymmetricCoulombViscousParams {
            fc_pos: 0.8,
            sigma2_pos: 0.25,
            ..p
        }
        .build::<f32>()
        .unwrap();
        for v in [-3.0f32, -1e-3, 0.0, 1e-3, 3.0] {
            assert_eq!(same.force(v), sym.force(v), "v = {v}");
        }
    }

    #[test]
    fn asymmetric_map_names_the_invalid_side() {
        let p = AsymmetricCoulombViscousParams {
            fc_pos: 1.0,
            sigma2_pos: 0.1,
            fc_neg: 1.0,
            sigma2_neg: 0.1,
        };
        let err = |q: AsymmetricCoulombViscousParams| q.build::<f32>().unwrap_err();
        assert_eq!(
            err(AsymmetricCoulombViscousParams { fc_neg: 0.0, ..p }),
            ParamError::NotPositive("fc_neg")
        );
        assert_eq!(
            err(AsymmetricCoulombViscousParams {
                fc_pos: f64::NAN,
                ..p
            }),
            ParamError::NotFinite("fc_pos")
        );
        assert_eq!(
            err(AsymmetricCoulombViscousParams {
                sigma2_neg: -1.0,
                ..p
            }),
            ParamError::Negative("sigma2_neg")
        );
        assert_eq!(
            err(AsymmetricCoulombViscousParams {
                sigma2_pos: 1e40,
                ..p
            }),
            ParamError::OutOfRange("sigma2_pos")
        );
        assert!(p.build::<f32>().is_ok());
    }

    #[test]
    fn karnopp_switches_on_the_band() {
        let map = StribeckMapParams {
            curve: canudas(),
            sigma2: 0.0,
        }
        .build::<f64>()
        .unwrap();
        let k = Karnopp::new(map, 1e-4).unwrap();
        assert_eq!(k.force(5e-5, -0.7), -0.7);
        assert_eq!(k.force(2e-4, -0.7), map.force(2e-4));
        assert_eq!(k.force(f64::NAN, 1.0), 0.0);
        assert_eq!(Karnopp::new(map, 0.0), Err(ParamError::NotPositive("dv")));
    }
}
