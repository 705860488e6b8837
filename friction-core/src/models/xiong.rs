//! The multistate friction model of Xiong, Kikuuwe and Yamamoto (~2013),
//! with `N` elements.
//!
//! ```text
//! dgamma/dt = (g(v) - gamma) / tau
//! dz_i/dt   = (sat(lambda_i gamma, K_i z_i + sigma_i v) - K_i z_i) / sigma_i
//! F         = sum_i sat(lambda_i gamma, K_i z_i + sigma_i v) + sigma2 v
//! ```
//!
//! `gamma` is the frictional-lag level: it follows the Stribeck curve with
//! lag time `tau`. No switching logic: the `sat` makes the equations a
//! continuous ODE.
//!
//! Initial state: at rest the full static level is available, `gamma = Fs`
//! (a contact that has dwelt at rest has `g(0) = Fs`, the lag equation's
//! equilibrium at `v = 0`). So that [`Default`] can be that rest state
//! without knowing the parameters, the state carries `lag = Fs - gamma`
//! (0 at rest, within `[0, Fs - Fc]`); [`Xiong::gamma`] gives `gamma`.
//!
//! Discretisation, in closed form with no iteration: `gamma` is solved
//! exactly for held `v` (`gamma+ = g + (gamma - g) e^(-h/tau)`), then each
//! element by implicit Euler:
//!
//! ```text
//! f_i  = sat(lambda_i gamma+, K_i z_i + (sigma_i + h K_i) v)
//! z_i+ = (sigma_i z_i + h f_i) / (sigma_i + h K_i)
//! F    = sum_i f_i + sigma2 v
//! ```
//!
//! computed as `z_i+ = r z_i + (1 - r) f_i / K_i` with `r = 1 / (1 + h
//! K_i/sigma_i)`, so that no `h K_i` overflow can produce a NaN. The step is
//! unconditionally stable, `|f_i| <= lambda_i gamma+`, and `K_i z_i+` is a
//! weighted mean of `K_i z_i` and `f_i`. When `gamma` falls faster than an
//! element relaxes (`sigma_i / K_i` against `tau`) the ODE lets `|K_i z_i|`
//! exceed `lambda_i gamma` for a while; the step clamps `|K_i z_i|` to
//! `lambda_i gamma` instead, so the bound holds at every step (the
//! difference is of order `lambda_i |dgamma/dt| sigma_i / K_i`). The
//! steady state is `g(v) sign(v) + sigma2 v` (the weights are normalised by
//! their sum when the model is built).
//!
//! `N` must be at least 1:
//!
//! ```compile_fail
//! use friction_core::{StribeckParams, XiongParams};
//! let curve = StribeckParams { fc: 1.0, fs: 1.5, vs: 1e-3, exponent: 2.0 };
//! let p = XiongParams::<0> { curve, tau: 1e-2, sigma2: 0.0, elements: [] };
//! let m = p.build::<f32>(); // error: N = 0 elements
//! ```

use crate::fixed_step::{checked_velocity, period, FixedStepModel, FixedStepObservable};
use crate::model::{
    check_force, checked_inputs, convert, convert_derived, magnitude, magnitude_or_zero,
    FrictionModel, ParamError,
};
use crate::models::gms::WEIGHT_TOLERANCE;
use crate::observer::Observable;
use crate::stribeck::{StribeckCurve, StribeckParams};
use crate::Scalar;

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
    /// see [`XiongAt`] (`N >= 1`, checked at compile time). Besides
    /// [`Self::build`]'s checks, rejects a bad `h` and an element whose
    /// trial force `(sigma_i + h K_i) (v - c)` overflows the scalar at twice
    /// the velocity limit ([`ParamError::ForceOverflow`] naming `k`).
    ///
    /// ```
    /// use friction_core::{FixedStepModel, StribeckParams, XiongAtState, XiongElement, XiongParams};
    /// let curve = StribeckParams { fc: 1.0, fs: 1.5, vs: 1e-3, exponent: 2.0 };
    /// let e = |k: f64, lambda| XiongElement { k, sigma: k * 1e-4, lambda };
    /// let p = XiongParams { curve, tau: 1e-2, sigma2: 0.4, elements: [e(1e5, 0.5), e(2e4, 0.5)] };
    /// let model = p.build_at::<f32>(1e-3)?;
    /// let mut state = XiongAtState::default();
    /// let mut f = 0.0;
    /// for _ in 0..1000 {
    ///     f = model.step(&mut state, 0.1); // 0.1 m/s for 1 s at 1 kHz
    /// }
    /// assert!((f - (1.0 + 0.4 * 0.1)).abs() < 1e-4);
    /// # Ok::<(), friction_core::ParamError>(())
    /// ```
    pub fn build_at<S: Scalar>(&self, h: f64) -> Result<XiongAt<S, N>, ParamError> {
        const { assert!(N > 0, "the Xiong model needs at least one element") };
        self.validate()?;
        let h = period(h)?;
        let (fc, fs) = (self.curve.fc, self.curve.fs);
        let v_max = S::VELOCITY_LIMIT.to_f64();
        let sum: f64 = self.elements.iter().map(|e| e.lambda).sum();
        // forces carried times k (as LuGreAt): the largest is Fs, sigma2 v
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
        let mut elements = [ElementAt::<S>::default(); N];
        for (out, e) in elements.iter_mut().zip(&self.elements) {
            let lambda = e.lambda / sum;
            convert::<S>("lambda", k * lambda * fc)?;
            let scale = e.sigma + h * e.k;
            check_force::<S>("k", k * scale * 2.0 * v_max)?;
            // 1 - r_i = (h K_i / sigma_i) / (1 + h K_i / sigma_i)
            let x = h * (e.k / e.sigma);
            *out = ElementAt {
                scale: convert("k", k * scale)?,
                one_minus_r: convert_derived("sigma", x / (1.0 + x))?,
                lambda: convert("lambda", lambda)?,
            };
        }
        Ok(XiongAt {
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

#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Element<S> {
    k: S,
    inv_k: S,
    sigma: S,
    k_over_sigma: S,
    /// Normalised weight.
    lambda: S,
}

/// The built Xiong model: immutable, shared by any number of [`XiongState`]s.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Xiong<S, const N: usize> {
    curve: StribeckCurve<S>,
    inv_tau: S,
    sigma2: S,
    fs_minus_fc: S,
    elements: [Element<S>; N],
}

/// The Xiong state: the frictional-lag level (as `lag = Fs - gamma`) and
/// each element's deflection.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct XiongState<S, const N: usize> {
    /// `Fs - gamma` (N), within `[0, Fs - Fc]`: 0 at rest, where the full
    /// static level is available.
    pub lag: S,
    /// Element deflections `z_i` (m), `|K_i z_i| <= lambda_i gamma`.
    pub z: [S; N],
}

impl<S: Scalar, const N: usize> Default for XiongState<S, N> {
    /// At rest: `gamma = Fs`, every `z_i = 0`.
    fn default() -> Self {
        Self {
            lag: S::ZERO,
            z: [S::ZERO; N],
        }
    }
}

impl<S: Scalar, const N: usize> Xiong<S, N> {
    /// The Stribeck curve `g`.
    pub fn curve(&self) -> &StribeckCurve<S> {
        &self.curve
    }

    /// The frictional-lag level `gamma = Fs - lag` of a state.
    pub fn gamma(&self, state: &XiongState<S, N>) -> S {
        self.curve.fs() - state.lag
    }

    /// Element stiffnesses `K_i` and normalised weights `lambda_i`.
    pub fn elements(&self) -> [(S, S); N] {
        let mut out = [(S::ZERO, S::ZERO); N];
        for (o, e) in out.iter_mut().zip(&self.elements) {
            *o = (e.k, e.lambda);
        }
        out
    }

    /// Steady-state friction `g(v) sign(v) + sigma2 v`.
    pub fn steady_state(&self, v: S) -> S {
        self.curve.eval(v) * v.sign() + self.sigma2 * v
    }

    /// The closed-form implicit step with `u = v - c` inside the saturation
    /// (`c` an observer's correction, 0 for the model); `h = 0` leaves the
    /// state untouched. Returns the force (without the element viscosity
    /// unless `damping`).
    fn advance(&self, state: &mut XiongState<S, N>, v: S, c: S, h: S, damping: bool) -> S {
        let u = v - c;
        let lag = if h > S::ZERO {
            // lag+ = (Fs - g) + (lag - (Fs - g)) e^(-h/tau), exact for held v
            let lag_eq = self.curve.fs() - self.curve.eval(v);
            let decay = (-(h * self.inv_tau)).exp();
            let lag = (lag_eq + (state.lag - lag_eq) * decay).sat(self.fs_minus_fc);
            lag.max(S::ZERO)
        } else {
            state.lag
        };
        let gamma = self.curve.fs() - lag;
        let mut total = self.sigma2 * v;
        for (e, z) in self.elements.iter().zip(state.z.iter_mut()) {
            let cap = e.lambda * gamma;
            let kz = e.k * *z;
            // h K_i may overflow to +inf; never multiply it by a zero u
            let scale = e.sigma + h * e.k;
            let trial = if u == S::ZERO { kz } else { kz + scale * u };
            // min/max rather than `sat`: these bounds hold while the element
            // slips (often), where `sat`'s in-range test is one more
            let f = trial.min(cap).max(-cap);
            if h > S::ZERO {
                let r = S::ONE / (S::ONE + h * e.k_over_sigma);
                let kz_next = (r * kz + (S::ONE - r) * f).min(cap).max(-cap);
                *z = kz_next * e.inv_k;
                total = total + if damping { f } else { kz_next };
            } else {
                total = total + if damping { f } else { kz };
            }
        }
        if h > S::ZERO {
            state.lag = lag;
        }
        total
    }
}

impl<S: Scalar, const N: usize> FrictionModel<S> for Xiong<S, N> {
    type State = XiongState<S, N>;

    #[inline]
    fn step(&self, state: &mut XiongState<S, N>, v: S, h: S) -> S {
        match checked_inputs(v, h) {
            Some(v) => self.advance(state, v, S::ZERO, h, true),
            None => self.hold_force(state),
        }
    }

    /// `sum_i K_i z_i` (each within `lambda_i gamma`), within `±Fs` (also
    /// after rounding).
    fn hold_force(&self, state: &XiongState<S, N>) -> S {
        let mut sum = S::ZERO;
        for (e, &z) in self.elements.iter().zip(&state.z) {
            sum = sum + e.k * z;
        }
        sum.sat(self.curve.fs())
    }
}

/// Observer form: `v - c` replaces `v` inside the saturation; the lag level
/// follows the measured `v`. Without damping the estimate is the elastic
/// part `sum_i K_i z_i+ + sigma2 v` (since `f_i = K_i z_i+ + sigma_i
/// dz_i/dt` for the implicit step).
impl<S: Scalar, const N: usize> Observable<S> for Xiong<S, N> {
    fn step_corrected(
        &self,
        state: &mut XiongState<S, N>,
        v: S,
        correction: S,
        h: S,
        damping: bool,
    ) -> S {
        self.advance(state, v, correction, h, damping)
    }

    /// `Fs + sigma2 |v|`: every `|f_i| <= lambda_i gamma <= lambda_i Fs`.
    fn force_bound(&self, v: S) -> S {
        self.curve.fs() + self.sigma2 * v.abs()
    }
}

/// One element of [`XiongAt`]: everything its step needs, formed at build.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct ElementAt<S> {
    /// `sigma_i + h K_i`, times the force scale.
    scale: S,
    /// `1 - r_i`, `r_i = 1 / (1 + h K_i / sigma_i)`.
    one_minus_r: S,
    /// Normalised weight.
    lambda: S,
}

/// Xiong built for one sample period `h` ([`XiongParams::build_at`]), with
/// the element forces `w_i = K_i z_i` as its state ([`XiongAtState`]):
///
/// ```text
/// lag+ = (Fs - g(v)) + (lag - (Fs - g(v))) e^(-h/tau),   gamma+ = Fs - lag+
/// f_i  = sat(lambda_i gamma+, w_i + (sigma_i + h K_i) (v - c))
/// w_i+ = sat(lambda_i gamma+, r_i w_i + (1 - r_i) f_i),  r_i = 1 / (1 + h K_i / sigma_i)
/// F    = sum_i f_i + sigma2 v
/// ```
///
/// the variable-step form's step (exact lag level, implicit Euler for the
/// elements of Xiong, Kikuuwe and Yamamoto's model; see [`Xiong`]) with
/// `e^(-h/tau)`, `sigma_i + h K_i`, `r_i` and `1 - r_i` formed in `f64` at
/// build time: no division, no exponential in the step. `c` is an
/// observer's correction, 0 for the model. Forces (the state included) are
/// carried times a power of two `k` ([`Scalar::force_scale`]: 1 in floating
/// point), as in [`LuGreAt`](crate::LuGreAt), and the force is returned in
/// newtons; `w_i+` is formed as the increment `w_i + (1 - r_i)(f_i - w_i)`.
///
/// `N` must be at least 1:
///
/// ```compile_fail
/// use friction_core::{XiongParams, StribeckParams};
/// let curve = StribeckParams { fc: 1.0, fs: 1.5, vs: 1e-3, exponent: 2.0 };
/// let p = XiongParams::<0> { curve, tau: 1e-2, sigma2: 0.0, elements: [] };
/// let m = p.build_at::<f32>(1e-3); // error: N = 0 elements
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct XiongAt<S, const N: usize> {
    curve: StribeckCurve<S>,
    /// `e^(-h/tau)`.
    decay: S,
    sigma2: S,
    fs: S,
    fs_minus_fc: S,
    /// `1 / k`, the force scale's inverse (a power of two).
    inv_scale: S,
    elements: [ElementAt<S>; N],
    h: f64,
}

/// The state of [`XiongAt`]: the lag level and each element's force.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct XiongAtState<S, const N: usize> {
    /// `Fs - gamma` (N) times the force scale (1 in floating point), within
    /// `[0, Fs - Fc]` times it: 0 at rest.
    pub lag: S,
    /// Element forces `w_i = K_i z_i` (N) times the force scale, `|w_i| <= lambda_i gamma`.
    pub w: [S; N],
}

impl<S: Scalar, const N: usize> Default for XiongAtState<S, N> {
    /// At rest: `gamma = Fs`, every `w_i = 0`.
    fn default() -> Self {
        Self {
            lag: S::ZERO,
            w: [S::ZERO; N],
        }
    }
}

impl<S: Scalar, const N: usize> XiongAt<S, N> {
    /// The Stribeck curve `g`.
    pub fn curve(&self) -> &StribeckCurve<S> {
        &self.curve
    }

    /// The frictional-lag level `gamma = Fs - lag` of a state, times the
    /// force scale (the units of the state).
    pub fn gamma(&self, state: &XiongAtState<S, N>) -> S {
        self.fs - state.lag
    }

    #[inline]
    fn advance(&self, state: &mut XiongAtState<S, N>, v: S, c: S, damping: bool) -> S {
        let u = v - c;
        let lag_eq = self.fs - self.curve.eval_fast(v);
        let lag = (lag_eq + (state.lag - lag_eq) * self.decay)
            .sat(self.fs_minus_fc)
            .max(S::ZERO);
        state.lag = lag;
        let gamma = self.fs - lag;
        let mut total = self.sigma2 * v;
        for (e, w) in self.elements.iter().zip(state.w.iter_mut()) {
            let cap = e.lambda * gamma;
            // min/max rather than `sat`: these bounds hold while the element
            // slips (often), where `sat`'s in-range test is one more
            let f = (*w + e.scale * u).min(cap).max(-cap);
            // r w + (1 - r) f as an increment: no rounding of a large w by r
            let next = (*w + (f - *w).mul_fraction(e.one_minus_r))
                .min(cap)
                .max(-cap);
            *w = next;
            total = total + if damping { f } else { next };
        }
        total
    }
}

impl<S: Scalar, const N: usize> FixedStepModel<S> for XiongAt<S, N> {
    type State = XiongAtState<S, N>;

    fn period(&self) -> f64 {
        self.h
    }

    #[inline]
    fn step(&self, state: &mut XiongAtState<S, N>, v: S) -> S {
        match checked_velocity(v) {
            Some(v) => self
                .advance(state, v, S::ZERO, true)
                .rescale(self.inv_scale),
            None => self.hold_force(state),
        }
    }

    /// `sum_i w_i`, within `±Fs` (also after rounding).
    fn hold_force(&self, state: &XiongAtState<S, N>) -> S {
        let mut sum = S::ZERO;
        for &w in &state.w {
            sum = sum + w;
        }
        sum.sat(self.fs).rescale(self.inv_scale)
    }
}

/// As [`Xiong`]'s observer form: `v - c` inside the saturation, the lag
/// level follows the measured `v`; without damping the estimate is the
/// elastic part `sum_i w_i+ + sigma2 v`.
impl<S: Scalar, const N: usize> FixedStepObservable<S> for XiongAt<S, N> {
    fn step_corrected(
        &self,
        state: &mut XiongAtState<S, N>,
        v: S,
        correction: S,
        damping: bool,
    ) -> S {
        self.advance(state, v, correction, damping)
            .rescale(self.inv_scale)
    }

    /// `Fs + sigma2 |v|`.
    fn force_bound(&self, v: S) -> S {
        (self.fs + self.sigma2 * v.abs()).rescale(self.inv_scale)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::vec::Vec;

    const CURVE: StribeckParams = StribeckParams {
        fc: 1.0,
        fs: 1.5,
        vs: 1e-3,
        exponent: 2.0,
    };

    const fn el(k: f64, lambda: f64) -> XiongElement {
        XiongElement {
            k,
            sigma: k * 1e-4,
            lambda,
        }
    }

    const P: XiongParams<4> = XiongParams {
        curve: CURVE,
        tau: 1e-2,
        sigma2: 0.4,
        elements: [el(2.5e4, 0.4), el(5e4, 0.3), el(1e5, 0.2), el(2e5, 0.1)],
    };

    #[test]
    fn invalid_parameters_are_named() {
        let mut p = P;
        p.elements[1].sigma = 0.0;
        assert_eq!(p.build::<f64>(), Err(ParamError::NotPositive("sigma")));
        let mut p = P;
        p.elements[0].lambda = 0.5;
        assert_eq!(p.validate(), Err(ParamError::WeightsNotOne("lambda")));
        assert_eq!(
            XiongParams { tau: f64::NAN, ..P }.validate(),
            Err(ParamError::NotFinite("tau"))
        );
        let mut p = P;
        p.elements[3].k = -1.0;
        assert_eq!(p.validate(), Err(ParamError::NotPositive("k")));
    }

    #[test]
    fn at_rest_gamma_is_the_static_level() {
        let m = P.build::<f64>().unwrap();
        let s = XiongState::default();
        assert_eq!(m.gamma(&s), 1.5);
    }

    #[test]
    fn gamma_follows_the_curve_with_lag_tau() {
        let m = P.build::<f64>().unwrap();
        let mut s = XiongState::default();
        let v = 0.1;
        m.step(&mut s, v, 1e-2); // one tau
        let g = m.curve().eval(v);
        let expect = g + (1.5 - g) * (-1.0f64).exp();
        assert!((m.gamma(&s) - expect).abs() < 1e-12);
    }

    #[test]
    fn presliding_is_a_spring_with_viscosity() {
        let m = P.build::<f64>().unwrap();
        let mut s = XiongState::default();
        let (v, h) = (1e-5, 1e-4);
        let mut f = 0.0;
        for _ in 0..10 {
            f = m.step(&mut s, v, h);
        }
        // x = 1e-8 m: every element sticks, z_i = x, F = sum (K x + sigma v) + sigma2 v
        let ks: f64 = P.elements.iter().map(|e| e.k).sum();
        let sig: f64 = P.elements.iter().map(|e| e.sigma).sum();
        for z in s.z {
            assert!((z - 1e-8).abs() < 1e-20, "{z}");
        }
        assert!((f - (ks * 1e-8 + (sig + 0.4) * v)).abs() < 1e-12, "{f}");
    }

    #[test]
    fn zero_step_keeps_the_state() {
        let m = P.build::<f64>().unwrap();
        let mut s = XiongState::default();
        for k in 0..200 {
            m.step(&mut s, 1e-3 * (k as f64 * 0.1).cos(), 1e-3);
        }
        let before = s;
        let f = m.step(&mut s, 2e-3, 0.0);
        assert_eq!(s, before);
        assert!(f.is_finite());
        assert_eq!(m.step(&mut s, 0.0, 0.0), m.hold_force(&s));
    }

    #[test]
    fn the_correction_strains_the_elements() {
        use crate::Observer;
        let m = P.build::<f64>().unwrap();
        let o = Observer::new(m, 1e3).unwrap().with_damping(false);
        let mut s = XiongState::default();
        let mut f = 0.0;
        for _ in 0..100 {
            f = o.step(&mut s, 0.0, 1.0, 1e-3);
        }
        // every element saturated at -lambda_i Fs: the estimate is -Fs
        assert!((f + 1.5).abs() < 1e-9, "{f}");
        for (z, (k, l)) in s.z.iter().zip(m.elements()) {
            assert!((k * z + l * 1.5).abs() < 1e-9);
        }
    }

    fn arb_params() -> impl Strategy<Value = XiongParams<3>> {
        (
            0.1f64..10.0,
            1.0f64..3.0,
            1e-4f64..1e-1,
            0.5f64..3.0,
            proptest::array::uniform3((1e2f64..1e7, 1e-6f64..1e-1, 0.05f64..1.0)),
            1e-4f64..1.0,
            0.0f64..10.0,
        )
            .prop_map(|(fc, ratio, vs, exponent, els, tau, sigma2)| {
                let sum: f64 = els.iter().map(|e| e.2).sum();
                XiongParams {
                    curve: StribeckParams {
                        fc,
                        fs: fc * ratio,
                        vs,
                        exponent,
                    },
                    tau,
                    sigma2,
                    elements: els.map(|(k, ratio, l)| XiongElement {
                        k,
                        sigma: k * ratio,
                        lambda: l / sum,
                    }),
                }
            })
    }

    fn arb_inputs() -> impl Strategy<Value = Vec<(f64, f64)>> {
        proptest::collection::vec(
            (
                prop_oneof![-1e3f64..1e3, -1e-3f64..1e-3, Just(0.0)],
                prop_oneof![0.0f64..1e-2, Just(0.0), 0.0f64..10.0],
            ),
            1..60,
        )
    }

    /// `|K_i z_i| <= lambda_i gamma` within rounding.
    fn bounded<S: Scalar, const N: usize>(m: &Xiong<S, N>, s: &XiongState<S, N>) -> bool {
        let gamma = m.gamma(s);
        let eps = S::from_f64(1e-6);
        s.z.iter()
            .zip(m.elements())
            .all(|(&z, (k, l))| (k * z).abs() <= l * gamma * (S::ONE + eps))
            && s.lag >= S::ZERO
            && gamma >= m.curve().fc() * (S::ONE - eps)
    }

    proptest! {
        #[test]
        fn states_stay_bounded_and_force_finite(p in arb_params(), inputs in arb_inputs()) {
            let m = p.build::<f64>().unwrap();
            let m32 = p.build::<f32>().unwrap();
            let (mut s, mut s32) = (XiongState::default(), XiongState::default());
            for (v, h) in inputs {
                let f = m.step(&mut s, v, h);
                let f32_ = m32.step(&mut s32, v as f32, h as f32);
                prop_assert!(f.is_finite() && f32_.is_finite());
                prop_assert!(bounded(&m, &s), "{:?}", s);
                prop_assert!(bounded(&m32, &s32), "{:?}", s32);
            }
        }

        #[test]
        fn steady_state_is_the_stribeck_map(p in arb_params(), v in prop_oneof![-1.0f64..-1e-6, 1e-6f64..1.0]) {
            let m = p.build::<f64>().unwrap();
            let mut s = XiongState::default();
            // lands on gamma = g and every element saturated
            let k_min = p.elements.iter().map(|e| e.k).fold(f64::INFINITY, f64::min);
            let h = 1e3 * (p.tau + p.curve.fs / (k_min * v.abs()));
            m.step(&mut s, v, h);
            let f = m.step(&mut s, v, h);
            let expected = m.steady_state(v);
            prop_assert!((f - expected).abs() <= 1e-9 * expected.abs(), "{} vs {}", f, expected);
        }

        #[test]
        fn extreme_finite_inputs_stay_finite(v in proptest::num::f64::NORMAL, h in proptest::num::f64::POSITIVE) {
            let m = P.build::<f32>().unwrap();
            let mut s = XiongState::default();
            for _ in 0..3 {
                let f = m.step(&mut s, v as f32, h as f32);
                prop_assert!(f.is_finite());
            }
            prop_assert!(bounded(&m, &s));
        }
    }
}
