//! The variable-step Xiong model: [`Xiong`] and [`XiongState`].

use crate::model::{checked_inputs, FrictionModel};
use crate::observer::Observable;
use crate::stribeck::StribeckCurve;
use crate::Scalar;

#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(super) struct Element<S> {
    pub(super) k: S,
    pub(super) inv_k: S,
    pub(super) sigma: S,
    pub(super) k_over_sigma: S,
    /// Normalised weight.
    pub(super) lambda: S,
}

/// The built Xiong model: immutable, shared by any number of [`XiongState`]s.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Xiong<S, const N: usize> {
    pub(super) curve: StribeckCurve<S>,
    pub(super) inv_tau: S,
    pub(super) sigma2: S,
    pub(super) fs_minus_fc: S,
    pub(super) elements: [Element<S>; N],
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
