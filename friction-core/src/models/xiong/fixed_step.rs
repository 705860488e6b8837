//! The fixed-step Xiong model, built for one sample period: [`XiongFixedStep`]
//! and [`XiongFixedStepState`].

use crate::fixed_step::{checked_velocity, FixedStepModel, FixedStepObservable};
use crate::stribeck::StribeckCurve;
use crate::Scalar;

/// One element of [`XiongFixedStep`]: everything its step needs, formed at build.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(super) struct ElementFixedStep<S> {
    /// `sigma_i + h K_i`, times the force scale.
    pub(super) scale: S,
    /// `1 - r_i`, `r_i = 1 / (1 + h K_i / sigma_i)`.
    pub(super) one_minus_r: S,
    /// Normalised weight.
    pub(super) lambda: S,
}

/// Xiong built for one sample period `h`
/// ([`XiongParams::build_fixed_step`](super::XiongParams::build_fixed_step)), with the element
/// forces `w_i = K_i z_i` as its state ([`XiongFixedStepState`]):
///
/// ```text
/// lag+ = (Fs - g(v)) + (lag - (Fs - g(v))) e^(-h/tau),   gamma+ = Fs - lag+
/// f_i  = sat(lambda_i gamma+, w_i + (sigma_i + h K_i) (v - c))
/// w_i+ = sat(lambda_i gamma+, r_i w_i + (1 - r_i) f_i),  r_i = 1 / (1 + h K_i / sigma_i)
/// F    = sum_i f_i + sigma2 v
/// ```
///
/// the variable-step form's step (exact lag level, implicit Euler for the
/// elements of Xiong, Kikuuwe and Yamamoto's model; see [`Xiong`](super::Xiong)) with
/// `e^(-h/tau)`, `sigma_i + h K_i`, `r_i` and `1 - r_i` formed in `f64` at
/// build time: no division, no exponential in the step. `c` is an
/// observer's correction, 0 for the model. Forces (the state included) are
/// carried times a power of two `k` (the force scale: 1 in floating
/// point), as in [`LuGreFixedStep`](crate::LuGreFixedStep), and the force is returned in
/// newtons; `w_i+` is formed as the increment `w_i + (1 - r_i)(f_i - w_i)`.
///
/// `N` must be at least 1:
///
/// ```compile_fail
/// use friction_core::{XiongParams, StribeckParams};
/// let curve = StribeckParams { fc: 1.0, fs: 1.5, vs: 1e-3, exponent: 2.0 };
/// let p = XiongParams::<0> { curve, tau: 1e-2, sigma2: 0.0, elements: [] };
/// let m = p.build_fixed_step::<f32>(1e-3); // error: N = 0 elements
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct XiongFixedStep<S, const N: usize> {
    pub(super) curve: StribeckCurve<S>,
    /// `e^(-h/tau)`.
    pub(super) decay: S,
    pub(super) sigma2: S,
    pub(super) fs: S,
    pub(super) fs_minus_fc: S,
    /// `1 / k`, the force scale's inverse (a power of two).
    pub(super) inv_scale: S,
    pub(super) elements: [ElementFixedStep<S>; N],
    pub(super) h: f64,
}

/// The state of [`XiongFixedStep`]: the lag level and each element's force.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct XiongFixedStepState<S, const N: usize> {
    /// `Fs - gamma` (N) times the force scale (1 in floating point), within
    /// `[0, Fs - Fc]` times it: 0 at rest.
    pub lag: S,
    /// Element forces `w_i = K_i z_i` (N) times the force scale, `|w_i| <= lambda_i gamma`.
    pub w: [S; N],
}

impl<S: Scalar, const N: usize> Default for XiongFixedStepState<S, N> {
    /// At rest: `gamma = Fs`, every `w_i = 0`.
    fn default() -> Self {
        Self {
            lag: S::ZERO,
            w: [S::ZERO; N],
        }
    }
}

impl<S: Scalar, const N: usize> XiongFixedStep<S, N> {
    /// The Stribeck curve `g`.
    pub fn curve(&self) -> &StribeckCurve<S> {
        &self.curve
    }

    /// The frictional-lag level `gamma = Fs - lag` of a state, times the
    /// force scale (the units of the state).
    pub fn gamma(&self, state: &XiongFixedStepState<S, N>) -> S {
        self.fs - state.lag
    }

    #[inline]
    fn advance(&self, state: &mut XiongFixedStepState<S, N>, v: S, c: S, damping: bool) -> S {
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

impl<S: Scalar, const N: usize> FixedStepModel<S> for XiongFixedStep<S, N> {
    type State = XiongFixedStepState<S, N>;

    fn period(&self) -> f64 {
        self.h
    }

    #[inline]
    fn step(&self, state: &mut XiongFixedStepState<S, N>, v: S) -> S {
        match checked_velocity(v) {
            Some(v) => self
                .advance(state, v, S::ZERO, true)
                .rescale(self.inv_scale),
            None => self.hold_force(state),
        }
    }

    /// `sum_i w_i`, within `±Fs` (also after rounding).
    fn hold_force(&self, state: &XiongFixedStepState<S, N>) -> S {
        let mut sum = S::ZERO;
        for &w in &state.w {
            sum = sum + w;
        }
        sum.sat(self.fs).rescale(self.inv_scale)
    }
}

/// As [`Xiong`](super::Xiong)'s observer form: `v - c` inside the saturation, the lag
/// level follows the measured `v`; without damping the estimate is the
/// elastic part `sum_i w_i+ + sigma2 v`.
impl<S: Scalar, const N: usize> FixedStepObservable<S> for XiongFixedStep<S, N> {
    fn step_corrected(
        &self,
        state: &mut XiongFixedStepState<S, N>,
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
