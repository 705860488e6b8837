//! The Leuven model (Swevers, Al-Bender, Ganseman, Prajogo 2000) with the
//! continuous state equation of Lampaert, Swevers, Al-Bender 2002, and a
//! reversal-point memory of fixed capacity `M`: see [`Leuven`].

#[cfg(test)]
mod tests;
mod variable_step;

use crate::model::{
    check_force, convert, convert_derived, magnitude, magnitude_or_zero, ParamError, VELOCITY_LIMIT,
};
use crate::stribeck::StribeckParams;
use crate::Scalar;
use variable_step::Power;
pub use variable_step::{Leuven, LeuvenReversal, LeuvenState};

/// The branch may approach its asymptote to within this fraction of `2 Fs`.
const CAP: f64 = 1e-6;
/// Sliding: `rho >= 1 - SLIDE_TOL` clears the memory below the top.
const SLIDE_TOL: f64 = 1e-4;

/// Leuven parameters (`model = "leuven"`), in `f64`.
///
/// ```
/// use friction_core::{FrictionModel, LeuvenParams, LeuvenState, StribeckParams};
/// let curve = StribeckParams { fc: 1.0, fs: 1.5, vs: 1e-3, exponent: 2.0 };
/// let p = LeuvenParams { curve, sigma1: 0.0, sigma2: 0.4, n: 2.0, xs: 1e-5 };
/// let model = p.build::<f32, 8>()?;
/// let mut state = LeuvenState::default();
/// let mut f = 0.0;
/// for _ in 0..1000 {
///     f = model.step(&mut state, 0.1, 1e-3); // 0.1 m/s for 1 s at 1 kHz
/// }
/// assert!((f - (1.0 + 0.4 * 0.1)).abs() < 1e-3); // steady state: Fc + sigma2 v
/// # Ok::<(), friction_core::ParamError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LeuvenParams {
    /// The Stribeck curve `s(v) = g(v)` (`fc`, `fs`, `vs`, `stribeck_exponent`).
    pub curve: StribeckParams,
    /// Micro-viscous damping `sigma1 >= 0` (N s/m) on `dz/dt`.
    pub sigma1: f64,
    /// Viscous friction `sigma2 >= 0` (N s/m).
    pub sigma2: f64,
    /// Shape exponent `n >= 1` of the transition to sliding.
    pub n: f64,
    /// Characteristic pre-sliding displacement `xs > 0` (m) of the virgin
    /// curve `Fv(x) = 2 Fs (1 - exp(-|x| / (2 xs))) sign(x)` (initial
    /// stiffness `Fs / xs`).
    pub xs: f64,
}

impl LeuvenParams {
    /// Checks every parameter; the error names the first offending one.
    pub fn validate(&self) -> Result<(), ParamError> {
        self.curve.validate()?;
        magnitude_or_zero("sigma1", self.sigma1)?;
        magnitude_or_zero("sigma2", self.sigma2)?;
        if !self.n.is_finite() {
            return Err(ParamError::NotFinite("n"));
        }
        if self.n < 1.0 {
            return Err(ParamError::BelowOne("n"));
        }
        magnitude("xs", self.xs)?;
        Ok(())
    }

    /// `(Fs / Fc)^n`: the largest `rho^n` (reached when the speed rises
    /// from rest to where `g = Fc`).
    fn ratio_pow(&self) -> f64 {
        (self.curve.fs / self.curve.fc).powf(self.n)
    }

    /// Validates and builds the run-time model with a memory of `M >= 1`
    /// reversal points (checked at compile time). Besides
    /// [`Self::validate`], rejects what the scalar type cannot carry: `xs`,
    /// `Fs / xs` or the solver tolerance that underflow or overflow, a
    /// `(Fs/Fc)^n |v|` or damping term that overflows at the velocity limit.
    pub fn build<S: Scalar, const M: usize>(&self) -> Result<Leuven<S, M>, ParamError> {
        const {
            assert!(
                M > 0,
                "the Leuven model needs a memory of at least one point"
            )
        };
        self.validate()?;
        let curve = self.curve.build()?;
        let (fs, xs) = (self.curve.fs, self.xs);
        let ratio = self.ratio_pow();
        check_force::<S>("n", ratio * VELOCITY_LIMIT)?;
        // |dz/dt| <= |v - c| + |v| rho^n <= VELOCITY_LIMIT (2 + (Fs/Fc)^n)
        check_force::<S>("sigma1", self.sigma1 * VELOCITY_LIMIT * (2.0 + ratio))?;
        check_force::<S>("sigma2", self.sigma2 * VELOCITY_LIMIT)?;
        let shape = if self.n == 1.0 {
            Power::One
        } else if self.n == 2.0 {
            Power::Two
        } else {
            Power::Real
        };
        // tolerance on z of the Newton iteration: a few ulps of xs
        let eps = if S::from_f64(1.0 + 1e-10).to_f64() == 1.0 {
            1e-6
        } else {
            1e-13
        };
        Ok(Leuven {
            curve,
            sigma1: convert("sigma1", self.sigma1)?,
            sigma2: convert("sigma2", self.sigma2)?,
            n: convert("n", self.n)?,
            shape: shape as u8,
            fs: convert("fs", fs)?,
            fm: convert("fs", 2.0 * fs)?,
            width: convert("xs", 2.0 * xs)?,
            inv_width: convert_derived("xs", 0.5 / xs)?,
            keep: convert("fs", 1.0 - CAP)?,
            stiffness: convert_derived("xs", fs / xs)?,
            tol: convert("xs", eps * xs)?,
            slide: S::from_f64(1.0 - SLIDE_TOL),
            rate_factor: convert("n", (ratio - 1.0).max(1.0))?,
        })
    }
}
