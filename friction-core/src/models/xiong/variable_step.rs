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
///
/// The multistate friction model of Xiong, Kikuuwe and Yamamoto (~2013),
/// with `N` elements.
///
/// ```text
/// dgamma/dt = (g(v) - gamma) / tau
/// dz_i/dt   = (sat(lambda_i gamma, K_i z_i + sigma_i v) - K_i z_i) / sigma_i
/// F         = sum_i sat(lambda_i gamma, K_i z_i + sigma_i v) + sigma2 v
/// ```
///
/// `gamma` is the frictional-lag level: it follows the Stribeck curve with
/// lag time `tau`. No switching logic: the `sat` makes the equations a
/// continuous ODE.
///
/// Initial state: at rest the full static level is available, `gamma = Fs`
/// (a contact that has dwelt at rest has `g(0) = Fs`, the lag equation's
/// equilibrium at `v = 0`). So that [`Default`] can be that rest state
/// without knowing the parameters, the state carries `lag = Fs - gamma`
/// (0 at rest, within `[0, Fs - Fc]`); [`Xiong::gamma`] gives `gamma`.
///
/// Discretisation, in closed form with no iteration: `gamma` is solved
/// exactly for held `v` (`gamma+ = g + (gamma - g) e^(-h/tau)`), then each
/// element by implicit Euler:
///
/// ```text
/// f_i  = sat(lambda_i gamma+, K_i z_i + (sigma_i + h K_i) v)
/// z_i+ = (sigma_i z_i + h f_i) / (sigma_i + h K_i)
/// F    = sum_i f_i + sigma2 v
/// ```
///
/// computed as `z_i+ = r z_i + (1 - r) f_i / K_i` with `r = 1 / (1 + h
/// K_i/sigma_i)`, so that no `h K_i` overflow can produce a NaN. The step is
/// unconditionally stable, `|f_i| <= lambda_i gamma+`, and `K_i z_i+` is a
/// weighted mean of `K_i z_i` and `f_i`. When `gamma` falls faster than an
/// element relaxes (`sigma_i / K_i` against `tau`) the ODE lets `|K_i z_i|`
/// exceed `lambda_i gamma` for a while; the step clamps `|K_i z_i|` to
/// `lambda_i gamma` instead, so the bound holds at every step (the
/// difference is of order `lambda_i |dgamma/dt| sigma_i / K_i`). The
/// steady state is `g(v) sign(v) + sigma2 v` (the weights are normalised by
/// their sum when the model is built).
///
/// `N` must be at least 1:
///
/// ```compile_fail
/// use friction_core::{StribeckParams, XiongParams};
/// let curve = StribeckParams { fc: 1.0, fs: 1.5, vs: 1e-3, exponent: 2.0 };
/// let p = XiongParams::<0> { curve, tau: 1e-2, sigma2: 0.0, elements: [] };
/// let m = p.build::<f32>(); // error: N = 0 elements
/// ```
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
