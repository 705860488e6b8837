//! The Stribeck curve `g(v)`: see [`StribeckCurve`] (the static maps built
//! on it are in `models::static_maps`).

use crate::model::{convert, convert_derived, magnitude, ParamError};
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

#[cfg(test)]
pub(crate) mod tests;
