//! The generalized Maxwell-slip model, GMS (Lampaert, Al-Bender, Swevers 2003;
//! Al-Bender, Lampaert, Swevers 2005), with `N` elements: see [`Gms`].

mod fixed_step;
#[cfg(test)]
mod tests;
mod variable_step;

use crate::fixed_step::period;
use crate::model::{
    check_force, convert, convert_derived, magnitude, magnitude_or_zero, ParamError,
};
use crate::stribeck::StribeckParams;
use crate::Scalar;
use fixed_step::ElementFixedStep;
pub use fixed_step::{GmsFixedStep, GmsFixedStepState};
use variable_step::Element;
pub use variable_step::{Gms, GmsSlipMode, GmsState};

/// One elasto-slide element of the GMS model, in `f64`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GmsElement {
    /// Stiffness `k_i > 0` (N/m).
    pub k: f64,
    /// Weight `alpha_i > 0`: the element's share of the Stribeck curve
    /// (the weights sum to 1).
    pub alpha: f64,
    /// Damping `sigma1_i >= 0` (N s/m).
    pub sigma1: f64,
}

/// GMS parameters (`model = "gms"`) with `N` elements, in `f64`.
///
/// ```
/// use friction_core::{FrictionModel, GmsElement, GmsParams, GmsState, StribeckParams};
/// let curve = StribeckParams { fc: 1.0, fs: 1.5, vs: 1e-3, exponent: 2.0 };
/// let e = |k, alpha| GmsElement { k, alpha, sigma1: 0.0 };
/// let p = GmsParams { curve, sigma2: 0.4, c: 100.0, elements: [e(1e5, 0.5), e(2e4, 0.5)] };
/// let model = p.build::<f32>()?;
/// let mut state = GmsState::default();
/// let mut f = 0.0;
/// for _ in 0..1000 {
///     f = model.step(&mut state, 0.1, 1e-3); // 0.1 m/s for 1 s at 1 kHz
/// }
/// assert!((f - (1.0 + 0.4 * 0.1)).abs() < 1e-4); // steady state: Fc + sigma2 v
/// # Ok::<(), friction_core::ParamError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct GmsParams<const N: usize> {
    /// The Stribeck curve `g(v)` (`fc`, `fs`, `vs`, `stribeck_exponent`).
    pub curve: StribeckParams,
    /// Viscous friction `sigma2 >= 0` (N s/m).
    pub sigma2: f64,
    /// Attraction rate `C > 0` (N/s): a slipping element follows the curve
    /// with time constant `alpha_i g(v) / C` (frictional lag).
    pub c: f64,
    /// The elements.
    pub elements: [GmsElement; N],
}

/// Tolerance on the sum of the weights.
pub(crate) const WEIGHT_TOLERANCE: f64 = 1e-9;

impl<const N: usize> GmsParams<N> {
    /// Checks every parameter; the error names the first offending one.
    pub fn validate(&self) -> Result<(), ParamError> {
        self.curve.validate()?;
        magnitude_or_zero("sigma2", self.sigma2)?;
        magnitude("c", self.c)?;
        let mut sum = 0.0;
        for e in &self.elements {
            magnitude("k", e.k)?;
            magnitude("alpha", e.alpha)?;
            magnitude_or_zero("sigma1", e.sigma1)?;
            sum += e.alpha;
        }
        if (sum - 1.0).abs() > WEIGHT_TOLERANCE {
            return Err(ParamError::WeightsNotOne("alpha"));
        }
        Ok(())
    }

    /// Validates and builds the run-time model (`N >= 1`, checked at compile
    /// time). Besides [`Self::validate`], rejects what the scalar type cannot
    /// carry: a parameter, `alpha_i Fc` or `C / (alpha_i Fc)` that underflows
    /// or overflows, and damping terms that overflow at the velocity limit.
    pub fn build<S: Scalar>(&self) -> Result<Gms<S, N>, ParamError> {
        const { assert!(N > 0, "the GMS model needs at least one element") };
        self.validate()?;
        let curve = self.curve.build()?;
        let (fc, fs) = (self.curve.fc, self.curve.fs);
        let sum: f64 = self.elements.iter().map(|e| e.alpha).sum();
        // |dz_i/dt| while slipping: |dF_i/dt| / k_i <= C (1 + Fs/Fc) / k_i
        let slip_damping: f64 = self
            .elements
            .iter()
            .map(|e| e.sigma1 * self.c * (1.0 + fs / fc) / e.k)
            .sum();
        let sigma1_sum: f64 = self.elements.iter().map(|e| e.sigma1).sum();
        check_force::<S>("c", slip_damping)?;
        // sticking: |dz_i/dt| <= |v| + an observer's correction up to the limit
        check_force::<S>(
            "sigma1",
            sigma1_sum * S::VELOCITY_LIMIT.to_f64() * 2.0 + slip_damping,
        )?;
        check_force::<S>("sigma2", self.sigma2 * S::VELOCITY_LIMIT.to_f64())?;
        let mut elements = [Element::<S>::default(); N];
        for (out, e) in elements.iter_mut().zip(&self.elements) {
            let alpha = e.alpha / sum;
            convert::<S>("alpha", alpha * fc)?;
            convert_derived::<S>("c", self.c / (alpha * fc))?;
            *out = Element {
                k: convert("k", e.k)?,
                alpha: convert("alpha", alpha)?,
                f_max: convert("alpha", alpha * fs)?,
                c_over_alpha: convert_derived("c", self.c / alpha)?,
                sigma1: convert("sigma1", e.sigma1)?,
                // at most slip_damping (checked above); a tiny one is 0
                slip_sigma1: S::from_f64(e.sigma1 * self.c / alpha / e.k),
            };
        }
        Ok(Gms {
            curve,
            sigma2: convert("sigma2", self.sigma2)?,
            elements,
            sigma1_sum: convert("sigma1", sigma1_sum)?,
            slip_damping: convert("c", slip_damping)?,
        })
    }

    /// Validates and builds the fixed-step form for sample period `h` (s):
    /// see [`GmsFixedStep`] (`N >= 1`, checked at compile time). Besides
    /// [`Self::build`]'s checks, rejects a bad `h` and an element whose
    /// stick travel `k_i h (v - c)` overflows the scalar at twice the
    /// velocity limit ([`ParamError::ForceOverflow`] naming `k`).
    ///
    /// ```
    /// use friction_core::{FixedStepModel, GmsElement, GmsParams, GmsState, StribeckParams};
    /// let curve = StribeckParams { fc: 1.0, fs: 1.5, vs: 1e-3, exponent: 2.0 };
    /// let e = |k, alpha| GmsElement { k, alpha, sigma1: 0.0 };
    /// let p = GmsParams { curve, sigma2: 0.4, c: 100.0, elements: [e(1e5, 0.5), e(2e4, 0.5)] };
    /// let model = p.build_fixed_step::<f32>(1e-3)?;
    /// let mut state = GmsState::default();
    /// let mut f = 0.0;
    /// for _ in 0..1000 {
    ///     f = model.step(&mut state, 0.1); // 0.1 m/s for 1 s at 1 kHz
    /// }
    /// assert!((f - (1.0 + 0.4 * 0.1)).abs() < 1e-4);
    /// # Ok::<(), friction_core::ParamError>(())
    /// ```
    pub fn build_fixed_step<S: Scalar>(&self, h: f64) -> Result<GmsFixedStep<S, N>, ParamError> {
        const { assert!(N > 0, "the GMS model needs at least one element") };
        self.validate()?;
        let h = period(h)?;
        let (fc, fs) = (self.curve.fc, self.curve.fs);
        let v_max = S::VELOCITY_LIMIT.to_f64();
        let sum: f64 = self.elements.iter().map(|e| e.alpha).sum();
        // as `build`: |dz_i/dt| <= C (1 + Fs/Fc) / k_i slipping, |v| + |c| sticking
        let slip_damping: f64 = self
            .elements
            .iter()
            .map(|e| e.sigma1 * self.c * (1.0 + fs / fc) / e.k)
            .sum();
        let sigma1_sum: f64 = self.elements.iter().map(|e| e.sigma1).sum();
        let damping_max = sigma1_sum * v_max * 2.0 + slip_damping;
        let viscous_max = self.sigma2 * v_max;
        let travel_max = self
            .elements
            .iter()
            .map(|e| e.k * h * 2.0 * v_max)
            .fold(0.0, f64::max);
        // forces carried times k, as in LuGreFixedStep
        let k = S::force_scale(fs.max(damping_max).max(viscous_max).max(travel_max));
        check_force::<S>("c", k * slip_damping)?;
        check_force::<S>("sigma1", k * damping_max)?;
        check_force::<S>("sigma2", k * viscous_max)?;
        let curve = StribeckParams {
            fc: k * fc,
            fs: k * fs,
            ..self.curve
        }
        .build()?;
        let mut elements = [ElementFixedStep::<S>::default(); N];
        for (out, e) in elements.iter_mut().zip(&self.elements) {
            let alpha = e.alpha / sum;
            convert::<S>("alpha", k * alpha * fc)?;
            let k_h = e.k * h;
            check_force::<S>("k", k * k_h * 2.0 * v_max)?;
            let c_over_alpha = self.c / alpha;
            convert_derived::<S>("c", c_over_alpha * h / fc)?;
            // the slip damping factor sigma1_i C / (alpha_i k_i) / g, formed
            // before its small force difference
            check_force::<S>("c", e.sigma1 * c_over_alpha / e.k / fc)?;
            *out = ElementFixedStep {
                k_h: convert("k", k * k_h)?,
                alpha: convert("alpha", alpha)?,
                f_max: convert("alpha", k * alpha * fs)?,
                c_h_over_alpha: convert("c", c_over_alpha * h)?,
                slip_sigma1: S::from_f64(e.sigma1 * c_over_alpha / e.k),
                sigma1: convert("sigma1", k * e.sigma1)?,
            };
        }
        Ok(GmsFixedStep {
            curve,
            sigma2: convert("sigma2", k * self.sigma2)?,
            elements,
            sigma1_sum: convert("sigma1", k * sigma1_sum)?,
            slip_damping: convert("c", k * slip_damping)?,
            inv_scale: convert_derived("fs", 1.0 / k)?,
            scale_s: convert("fs", k)?,
            h,
        })
    }
}
