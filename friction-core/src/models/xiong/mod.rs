//! The multistate friction model of Xiong, Kikuuwe and Yamamoto (~2013), with
//! `N` elements: see [`Xiong`].

mod fixed_step;
#[cfg(test)]
mod tests;
mod variable_step;

use crate::fixed_step::period;
use crate::model::{
    check_force, convert, convert_derived, magnitude, magnitude_or_zero, ParamError,
};
use crate::models::gms::WEIGHT_TOLERANCE;
use crate::stribeck::StribeckParams;
use crate::Scalar;
use fixed_step::ElementFixedStep;
pub use fixed_step::{XiongFixedStep, XiongFixedStepState};
use variable_step::Element;
pub use variable_step::{Xiong, XiongState};

/// One element of the Xiong model, in `f64`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct XiongElement {
    /// Stiffness `K_i > 0` (N/m).
    pub k: f64,
    /// Viscosity `sigma_i > 0` (N s/m).
    pub sigma: f64,
    /// Weight `lambda_i > 0` (the weights sum to 1).
    pub lambda: f64,
}

/// Xiong parameters (`model = "xiong"`) with `N` elements, in `f64`.
///
/// ```
/// use friction_core::{FrictionModel, StribeckParams, XiongElement, XiongParams, XiongState};
/// let curve = StribeckParams { fc: 1.0, fs: 1.5, vs: 1e-3, exponent: 2.0 };
/// let e = |k: f64, lambda| XiongElement { k, sigma: k * 1e-4, lambda };
/// let p = XiongParams { curve, tau: 1e-2, sigma2: 0.4, elements: [e(1e5, 0.5), e(2e4, 0.5)] };
/// let model = p.build::<f32>()?;
/// let mut state = XiongState::default();
/// let mut f = 0.0;
/// for _ in 0..1000 {
///     f = model.step(&mut state, 0.1, 1e-3); // 0.1 m/s for 1 s at 1 kHz
/// }
/// assert!((f - (1.0 + 0.4 * 0.1)).abs() < 1e-4); // steady state: Fc + sigma2 v
/// # Ok::<(), friction_core::ParamError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct XiongParams<const N: usize> {
    /// The Stribeck curve `g(v)` (`fc`, `fs`, `vs`, `stribeck_exponent`).
    pub curve: StribeckParams,
    /// Lag time `tau > 0` (s) of the frictional-lag level `gamma`.
    pub tau: f64,
    /// Viscous friction `sigma2 >= 0` (N s/m).
    pub sigma2: f64,
    /// The elements.
    pub elements: [XiongElement; N],
}

impl<const N: usize> XiongParams<N> {
    /// Checks every parameter; the error names the first offending one.
    pub fn validate(&self) -> Result<(), ParamError> {
        self.curve.validate()?;
        magnitude("tau", self.tau)?;
        magnitude_or_zero("sigma2", self.sigma2)?;
        let mut sum = 0.0;
        for e in &self.elements {
            magnitude("k", e.k)?;
            magnitude("sigma", e.sigma)?;
            magnitude("lambda", e.lambda)?;
            sum += e.lambda;
        }
        if (sum - 1.0).abs() > WEIGHT_TOLERANCE {
            return Err(ParamError::WeightsNotOne("lambda"));
        }
        Ok(())
    }

    /// Validates and builds the run-time model (`N >= 1`, checked at compile
    /// time). Besides [`Self::validate`], rejects what the scalar type cannot
    /// carry: a parameter, `lambda_i Fc`, `lambda_i Fc / K_i` or `K_i /
    /// sigma_i` that underflows or overflows, and `sigma2 v` overflowing at
    /// the velocity limit.
    pub fn build<S: Scalar>(&self) -> Result<Xiong<S, N>, ParamError> {
        const { assert!(N > 0, "the Xiong model needs at least one element") };
        self.validate()?;
        let curve = self.curve.build()?;
        let fc = self.curve.fc;
        let sum: f64 = self.elements.iter().map(|e| e.lambda).sum();
        check_force::<S>("sigma2", self.sigma2 * S::VELOCITY_LIMIT.to_f64())?;
        let mut elements = [Element::<S>::default(); N];
        for (out, e) in elements.iter_mut().zip(&self.elements) {
            let lambda = e.lambda / sum;
            convert::<S>("lambda", lambda * fc)?;
            convert_derived::<S>("k", lambda * fc / e.k)?;
            *out = Element {
                k: convert("k", e.k)?,
                inv_k: convert_derived("k", 1.0 / e.k)?,
                sigma: convert("sigma", e.sigma)?,
                k_over_sigma: convert_derived("sigma", e.k / e.sigma)?,
                lambda: convert("lambda", lambda)?,
            };
        }
        Ok(Xiong {
            curve,
            inv_tau: convert_derived("tau", 1.0 / self.tau)?,
            sigma2: convert("sigma2", self.sigma2)?,
            fs_minus_fc: convert("fs", self.curve.fs - self.curve.fc)?,
            elements,
        })
    }

    /// Validates and builds the fixed-step form for sample period `h` (s):
    /// see [`XiongFixedStep`] (`N >= 1`, checked at compile time). Besides
    /// [`Self::build`]'s checks, rejects a bad `h` and an element whose
    /// trial force `(sigma_i + h K_i) (v - c)` overflows the scalar at twice
    /// the velocity limit ([`ParamError::ForceOverflow`] naming `k`).
    ///
    /// ```
    /// use friction_core::{FixedStepModel, StribeckParams, XiongFixedStepState, XiongElement, XiongParams};
    /// let curve = StribeckParams { fc: 1.0, fs: 1.5, vs: 1e-3, exponent: 2.0 };
    /// let e = |k: f64, lambda| XiongElement { k, sigma: k * 1e-4, lambda };
    /// let p = XiongParams { curve, tau: 1e-2, sigma2: 0.4, elements: [e(1e5, 0.5), e(2e4, 0.5)] };
    /// let model = p.build_fixed_step::<f32>(1e-3)?;
    /// let mut state = XiongFixedStepState::default();
    /// let mut f = 0.0;
    /// for _ in 0..1000 {
    ///     f = model.step(&mut state, 0.1); // 0.1 m/s for 1 s at 1 kHz
    /// }
    /// assert!((f - (1.0 + 0.4 * 0.1)).abs() < 1e-4);
    /// # Ok::<(), friction_core::ParamError>(())
    /// ```
    pub fn build_fixed_step<S: Scalar>(&self, h: f64) -> Result<XiongFixedStep<S, N>, ParamError> {
        const { assert!(N > 0, "the Xiong model needs at least one element") };
        self.validate()?;
        let h = period(h)?;
        let (fc, fs) = (self.curve.fc, self.curve.fs);
        let v_max = S::VELOCITY_LIMIT.to_f64();
        let sum: f64 = self.elements.iter().map(|e| e.lambda).sum();
        // forces carried times k (as LuGreFixedStep): the largest is Fs, sigma2 v
        // or an element's (sigma_i + h K_i) (v - c) at the limit
        let elastic_max = self
            .elements
            .iter()
            .map(|e| (e.sigma + h * e.k) * 2.0 * v_max)
            .fold(0.0, f64::max);
        let viscous_max = self.sigma2 * v_max;
        let k = S::force_scale(fs.max(elastic_max).max(viscous_max));
        check_force::<S>("sigma2", k * viscous_max)?;
        let curve = StribeckParams {
            fc: k * fc,
            fs: k * fs,
            ..self.curve
        }
        .build()?;
        let mut elements = [ElementFixedStep::<S>::default(); N];
        for (out, e) in elements.iter_mut().zip(&self.elements) {
            let lambda = e.lambda / sum;
            convert::<S>("lambda", k * lambda * fc)?;
            let scale = e.sigma + h * e.k;
            check_force::<S>("k", k * scale * 2.0 * v_max)?;
            // 1 - r_i = (h K_i / sigma_i) / (1 + h K_i / sigma_i)
            let x = h * (e.k / e.sigma);
            *out = ElementFixedStep {
                scale: convert("k", k * scale)?,
                one_minus_r: convert_derived("sigma", x / (1.0 + x))?,
                lambda: convert("lambda", lambda)?,
            };
        }
        Ok(XiongFixedStep {
            curve,
            decay: S::from_f64(libm::exp(-h / self.tau)),
            sigma2: convert("sigma2", k * self.sigma2)?,
            fs: convert("fs", k * fs)?,
            fs_minus_fc: convert("fs", k * (fs - fc))?,
            inv_scale: convert_derived("fs", 1.0 / k)?,
            elements,
            h,
        })
    }
}
