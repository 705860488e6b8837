//! The variable-step elasto-plastic model: [`ElastoPlastic`], on an
//! [`ElastoPlasticState`] (a [`LuGreState`]).

use super::corrected_shift;
use super::zone::{relaxed_fraction, zone_rate, zone_step, XI_CAP};
use crate::model::{checked_inputs, FrictionModel};
use crate::models::lugre::{LuGre, LuGreState};
use crate::observer::Observable;
use crate::Scalar;

/// The state of [`ElastoPlastic`]: LuGre's, [`LuGreState`] (the bristle
/// deflection `z`).
pub type ElastoPlasticState<S> = LuGreState<S>;

/// The built elasto-plastic model. Its state is an [`ElastoPlasticState`]
/// (a [`LuGreState`]).
///
/// The elasto-plastic model (Dupont, Hayward, Armstrong, Altpeter 2002).
///
/// LuGre with a purely elastic pre-sliding regime, which removes drift:
///
/// ```text
/// dz/dt = v - alpha(z, v) sigma0 |v| z / g(v)
/// F     = sigma0 z + sigma1 dz/dt + sigma2 v
/// z_max(v) = g(v) / sigma0,   0 < z_ba < Fc / sigma0 <= z_max(v)
/// alpha = 0                                                       |z| <= z_ba
///       = 1/2 + 1/2 sin(pi (|z| - (z_max + z_ba)/2) / (z_max - z_ba))   z_ba < |z| < z_max
///       = 1                                                       |z| >= z_max
/// (each when sign z = sign v; alpha = 0 when they differ)
/// ```
///
/// Discretisation: with `v` held over the step, write `w = z sign(v)` (the
/// deflection along the motion) and `xi = |v| h` (the distance slid); then
/// `dw/dxi = 1 - alpha(w) w / z_max`, a scalar autonomous equation:
///
/// - below `z_ba` it is `w + xi`, exact: no drift, `z` follows the displacement;
/// - above `z_max` (`alpha = 1`) it is linear, solved exactly:
///   `z_max + (w - z_max) e^(-xi / z_max)`;
/// - in the transition zone, with `u = (z_max - w) / (z_max - z_ba)` in `[0, 1]`
///   and `eps = (z_max - z_ba) / z_max`, `1 - alpha = sin^2(pi u / 2)` and
///   `du/dxi' = -u r(u)`, `r = eps + b(u) u`, `b = (pi/2)^2 (sin(phi)/phi)^2 (1 - eps u)`,
///   `phi = pi u / 2`, `xi' = xi / (z_max - z_ba)`. `sin(phi)/phi` is its Taylor
///   polynomial to `phi^12` (error below 4.3e-10 on the bounded phase), so no
///   `sin` is called. Classical RK4 sub-steps of length
///   `0.5 / (r + (pi/2)^2 u)` (so `h r <= 0.5`) run until the distance is used
///   or `u <= 0.01`, at most 24 of them (from `u = 1` 22 suffice for any
///   `eps`, which a test checks: where `alpha`'s sine dominates, each
///   sub-step shrinks `u` by about `1/1.25`). The rest is the tail, where
///   `r = eps + b u` with `b` frozen at its entry value is a Riccati equation
///   with the exact solution `u e^(-eps xi') / (1 + b u (1 - e^(-eps xi')) / eps)`;
///   `b` varies by less than `1e-4 + eps u` relative there.
///
/// One long step matches many tiny ones, and the sheet's equation with `sin`
/// integrated finely, to `3e-5 (z_max - z_ba)` in `w` for any distance; on
/// the validation signals the step is the exact solution for the held
/// velocity to `5e-6 Fs` RMS in force. The distance past `z_ba` is capped at `1024 z_max`
/// (beyond it `e^(-1024)` rounds to 0), so every step is finite for any
/// finite `v` and `h`, also in `f32`; `|z| <= Fs/sigma0` is kept by a final
/// clamp, and the steady state (`u = 0`, `w = z_max`) is exactly the Stribeck map.
///
/// Worst-case cost per step: 24 RK4 sub-steps of 4 evaluations of `r(u)` (a
/// degree-6 polynomial in `phi^2`, no `sin`) plus the first, 97 in all, one
/// more for the damping term, one division per sub-step, and one `exp` and
/// one `exp_m1` in the tail. The elastic part and the region above `z_max`
/// cost no evaluation; steady sliding (`u <= 0.01`) one, plus the tail.
/// The cost guide gives the measured worst case, and the former
/// implicit-Euler step's with `sinf`, which was dearer by an order of
/// magnitude.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ElastoPlastic<S> {
    pub(super) lugre: LuGre<S>,
    pub(super) z_ba: S,
}

impl<S: Scalar> ElastoPlastic<S> {
    /// The break-away deflection `z_ba`.
    pub fn z_ba(&self) -> S {
        self.z_ba
    }

    /// `dw/dxi = 1 - alpha(w) w / z_max` at `w`, the deflection along the
    /// motion: the fraction of the sliding that goes into the deflection.
    #[inline]
    pub(super) fn slip(&self, w: S, z_max: S) -> S {
        if w <= self.z_ba {
            S::ONE
        } else if w >= z_max {
            S::ONE - w / z_max
        } else {
            let width = z_max - self.z_ba;
            let u = ((z_max - w) / width).min(S::ONE);
            let (r, _) = zone_rate(u, width / z_max);
            u * r
        }
    }

    /// One step of the deflection along the motion, `w`, over distance `xi`
    /// (see [`ElastoPlastic`]).
    fn advance_w(&self, mut w: S, mut xi: S, z_max: S) -> S {
        // elastic: dw/dxi = 1 up to z_ba
        if w < self.z_ba {
            let reach = self.z_ba - w;
            if xi <= reach {
                return w + xi;
            }
            w = self.z_ba;
            xi = xi - reach;
        }
        // Past the elastic part every path relaxes onto z_max at least as
        // fast as e^(-xi / z_max): beyond 1024 z_max nothing is left to move
        // (e^-1024 is 0 in f32 and f64). The cap keeps xi finite (f32's
        // `v h` can overflow) and every product below free of inf * 0.
        xi = xi.min(S::from_f64(XI_CAP) * z_max);
        // above z_max alpha = 1: dw/dxi = 1 - w / z_max, exact relaxation
        if w >= z_max {
            return z_max + (w - z_max) * (-(xi / z_max)).exp();
        }
        // transition zone, z_ba <= w < z_max, so width > 0
        let width = z_max - self.z_ba;
        let eps = width / z_max;
        let u = ((z_max - w) / width).min(S::ONE);
        let (u, _) = zone_step(u, xi / width, eps);
        z_max - u * width
    }

    /// `alpha(w)` along the motion (`w = z sign v`): 0 up to `z_ba`, 1 from
    /// `z_max`, `1 - sin^2(pi u / 2)` in the zone.
    #[inline]
    fn alpha(&self, w: S, z_max: S) -> S {
        if w <= self.z_ba {
            S::ZERO
        } else if w >= z_max {
            S::ONE
        } else {
            let u = ((z_max - w) / (z_max - self.z_ba)).min(S::ONE);
            relaxed_fraction(u)
        }
    }

    /// One step: the model's motion along `v`, then the observer's
    /// correction (`c = 0` for the model; see [`corrected_shift`]), clamped
    /// to `±Fs/sigma0`. `h = 0` leaves the state untouched.
    fn advance(
        &self,
        state: &mut ElastoPlasticState<S>,
        v: S,
        correction: S,
        h: S,
        damping: bool,
    ) -> S {
        let s = v.sign();
        let z_max = self.lugre.curve().eval(v) / self.lugre.sigma0();
        let mut z = state.z;
        // the model's own end state, and the fraction of the correction's
        // rate left at the end of the step
        let mut z_model = z;
        let mut kept = S::ONE;
        if h > S::ZERO {
            if s != S::ZERO {
                z = s * self.advance_w(s * z, v.abs() * h, z_max);
            }
            z_model = z;
            if correction != S::ZERO {
                let xi = v.abs() * h / z_max;
                let relax = |w: S| self.alpha(w, z_max) * w;
                // no shift moves the state further than across its bound
                let shift = (s * correction * h).sat(S::from_f64(2.0) * self.lugre.z_max());
                let (phi, left) = corrected_shift(s * z, shift, xi, relax);
                z = z - correction * h * phi;
                kept = left;
            }
            z = z.sat(self.lugre.z_max());
            state.z = z;
        }
        let mut f = self.lugre.sigma0() * z + self.lugre.sigma2() * v;
        if damping {
            // dz/dt at the end of the step: the model's rate on its own path
            // plus the correction's share; zero while held at the bound
            let mut dz = v * self.slip(s * z_model, z_max) - correction * kept;
            if z.abs() >= self.lugre.z_max() && dz * z > S::ZERO {
                dz = S::ZERO;
            }
            f = f + self.lugre.damping(v) * dz;
        }
        f
    }
}

impl<S: Scalar> FrictionModel<S> for ElastoPlastic<S> {
    type State = ElastoPlasticState<S>;

    fn step(&self, state: &mut ElastoPlasticState<S>, v: S, h: S) -> S {
        match checked_inputs(v, h) {
            Some(v) => self.advance(state, v, S::ZERO, h, true),
            None => self.hold_force(state),
        }
    }

    /// `sigma0 z`.
    fn hold_force(&self, state: &ElastoPlasticState<S>) -> S {
        self.lugre.sigma0() * state.z
    }
}

/// Observer form: the correction `c = k e` is applied after the model's step
/// against the model's relaxation, `z^ <- z^ - c h phi(lambda h)`, and its
/// share of `dz^/dt` is `-c e^(-lambda h)` (see `corrected_shift`); then
/// `|z^| <= Fs/sigma0`.
impl<S: Scalar> Observable<S> for ElastoPlastic<S> {
    fn step_corrected(
        &self,
        state: &mut ElastoPlasticState<S>,
        v: S,
        correction: S,
        h: S,
        damping: bool,
    ) -> S {
        self.advance(state, v, correction, h, damping)
    }

    /// As LuGre's: `|dz/dt| <= |v| (1 + Fs/Fc)` within the bound.
    fn force_bound(&self, v: S) -> S {
        self.lugre.force_bound(v)
    }
}
