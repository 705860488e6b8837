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
    /// (see the module documentation).
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
