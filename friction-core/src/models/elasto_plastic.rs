//! The elasto-plastic model (Dupont, Hayward, Armstrong, Altpeter 2002).
//!
//! LuGre with a purely elastic pre-sliding regime, which removes drift:
//!
//! ```text
//! dz/dt = v - alpha(z, v) sigma0 |v| z / g(v)
//! F     = sigma0 z + sigma1 dz/dt + sigma2 v
//! z_max(v) = g(v) / sigma0,   0 < z_ba < Fc / sigma0 <= z_max(v)
//! alpha = 0                                                       |z| <= z_ba
//!       = 1/2 + 1/2 sin(pi (|z| - (z_max + z_ba)/2) / (z_max - z_ba))   z_ba < |z| < z_max
//!       = 1                                                       |z| >= z_max
//! (each when sign z = sign v; alpha = 0 when they differ)
//! ```
//!
//! Discretisation: with `v` held, write `w = z sign(v)` (deflection in the
//! direction of motion) and `xi = |v| h` (distance slid); then
//! `dw/dxi = 1 - alpha(w) w / z_max`. Below `z_ba` that is `w + xi`, exact.
//! Above `z_max`, and just below it where `alpha = 1` to 2.5e-4, it is an
//! exact exponential relaxation onto `z_max`. In the transition zone the
//! step is implicit Euler in up to 16 sub-steps, each solved by safeguarded
//! Newton from the explicit Euler guess. Stable at any `h`, `|z| <= Fs/sigma0`
//! kept, and no drift below `sigma0 z_ba`: there `z` follows the
//! displacement exactly.

use crate::model::{checked_inputs, convert, positive, FrictionModel, ParamError};
use crate::models::lugre::{LuGre, LuGreParams, LuGreState};
use crate::observer::Observable;
use crate::Scalar;

/// Elasto-plastic parameters (`model = "elasto-plastic"`): LuGre's and `z_ba`.
///
/// ```
/// use friction_core::{ElastoPlasticParams, FrictionModel, LuGreParams, LuGreState};
/// let p = ElastoPlasticParams { lugre: LuGreParams::CANUDAS_1995, z_ba: 5e-6 };
/// let model = p.build::<f64>()?;
/// let mut state = LuGreState::default();
/// // 2 µm of displacement below z_ba: purely elastic, F = sigma0 x
/// let f = model.step(&mut state, 2e-6, 1.0);
/// assert!((state.z - 2e-6).abs() < 1e-18);
/// // F = sigma0 z + (sigma1 + sigma2) v, as dz/dt = v in the elastic regime
/// let (sigma1, sigma2) = (p.lugre.sigma1, p.lugre.sigma2);
/// assert!((f - (0.2 + (sigma1 + sigma2) * 2e-6)).abs() < 1e-9);
/// # Ok::<(), friction_core::ParamError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ElastoPlasticParams {
    /// The LuGre parameters (curve, `sigma0`, `sigma1`, `sigma2`, optional `vd`).
    pub lugre: LuGreParams,
    /// Break-away deflection `0 < z_ba < Fc / sigma0` (m).
    pub z_ba: f64,
}

impl ElastoPlasticParams {
    /// Checks every parameter; the error names the first offending one.
    pub fn validate(&self) -> Result<(), ParamError> {
        self.lugre.validate()?;
        positive("z_ba", self.z_ba)?;
        if self.z_ba >= self.lugre.curve.fc / self.lugre.sigma0 {
            return Err(ParamError::NotBelow {
                name: "z_ba",
                limit: "fc / sigma0",
            });
        }
        Ok(())
    }

    /// Validates and builds the run-time model.
    pub fn build<S: Scalar>(&self) -> Result<ElastoPlastic<S>, ParamError> {
        self.validate()?;
        Ok(ElastoPlastic {
            lugre: self.lugre.build()?,
            z_ba: convert("z_ba", self.z_ba)?,
        })
    }
}

/// The built elasto-plastic model. Its state is a [`LuGreState`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ElastoPlastic<S> {
    lugre: LuGre<S>,
    z_ba: S,
}

impl<S: Scalar> ElastoPlastic<S> {
    /// The break-away deflection `z_ba`.
    pub fn z_ba(&self) -> S {
        self.z_ba
    }

    /// `alpha(w) w / z_max`, the plastic part of `dw/dxi`, for `w` the
    /// deflection along the motion, and its derivative in `w`.
    #[inline]
    fn plastic(&self, w: S, z_max: S) -> (S, S) {
        if w <= self.z_ba {
            (S::ZERO, S::ZERO)
        } else if w >= z_max {
            (w / z_max, S::ONE / z_max)
        } else {
            let width = z_max - self.z_ba;
            let k = S::from_f64(core::f64::consts::PI) / width;
            let phase = k * (w - (z_max + self.z_ba) * S::from_f64(0.5));
            // |phase| <= pi/2 here, so cos = sqrt(1 - sin^2) >= 0: one trig call
            let sin = phase.sin().sat(S::ONE);
            let cos = (S::ONE - sin * sin).sqrt();
            let alpha = S::from_f64(0.5) * (S::ONE + sin);
            let d_alpha = S::from_f64(0.5) * cos * k;
            (alpha * w / z_max, (d_alpha * w + alpha) / z_max)
        }
    }

    /// One step of the deflection along the motion, `w`, over distance `xi`.
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
        let width = z_max - self.z_ba;
        // Above z_max, dw/dxi = 1 - w / z_max: exact relaxation onto z_max.
        // Just below it alpha = 1 - (pi d / width)^2 / 4 (d = z_max - w), so
        // the same relaxation is exact to 2.5e-4 of dw/dxi while
        // d <= 1e-4 width^2 / z_max: steady sliding, whose z_max(v) moves with
        // v, stays on this cheap path.
        if z_max - w <= S::from_f64(1e-4) * width * width / z_max {
            return z_max + (w - z_max) * (-(xi / z_max)).exp();
        }
        // transition: implicit Euler in up to 16 sub-steps of at most an
        // eighth of the zone's width
        let eighth = width * S::from_f64(0.125);
        let mut n = 1u32;
        while n < 16 && xi > eighth * S::from_f64(f64::from(n)) {
            n += 1;
        }
        let sub = xi / S::from_f64(f64::from(n));
        for _ in 0..n {
            w = self.implicit_euler(w, sub, z_max);
        }
        w
    }

    /// Solves `x = w + xi (1 - p(x))` in the transition zone. `G(x) = x - w -
    /// xi (1 - p(x))` is increasing with `G(w) <= 0 <= G(z_max)`, so the root
    /// is bracketed in `[w, z_max]`: safeguarded Newton from the explicit
    /// Euler guess, at most 12 iterations, stopping at 1e-7 of `z_max`.
    fn implicit_euler(&self, w: S, xi: S, z_max: S) -> S {
        let (mut lo, mut hi) = (w, z_max);
        let (p0, _) = self.plastic(w, z_max);
        let mut x = (w + xi * (S::ONE - p0)).min(z_max);
        let tol = z_max * S::from_f64(1e-7);
        for _ in 0..12 {
            let (p, dp) = self.plastic(x, z_max);
            let g = x - w - xi * (S::ONE - p);
            if g > S::ZERO {
                hi = x;
            } else {
                lo = x;
            }
            let dg = S::ONE + xi * dp;
            let mut next = x - g / dg;
            if !(next >= lo && next <= hi) {
                next = (lo + hi) * S::from_f64(0.5);
            }
            let done = (next - x).abs() <= tol;
            x = next;
            if done {
                break;
            }
        }
        x
    }

    /// One step: the model's motion along `v`, then the observer's
    /// correction `z <- z - c h` (first-order splitting; `c = 0` for the
    /// model), clamped to `±Fs/sigma0`. `h = 0` leaves the state untouched.
    fn advance(&self, state: &mut LuGreState<S>, v: S, correction: S, h: S, damping: bool) -> S {
        let s = v.sign();
        let z_max = self.lugre.curve().eval(v) / self.lugre.sigma0();
        let mut z = state.z;
        if h > S::ZERO {
            if s != S::ZERO {
                z = s * self.advance_w(s * z, v.abs() * h, z_max);
            }
            z = (z - correction * h).sat(self.lugre.z_max());
            state.z = z;
        }
        let mut f = self.lugre.sigma0() * z + self.lugre.sigma2() * v;
        if damping {
            let (p, _) = self.plastic(s * z, z_max);
            // dz/dt at the end of the step, zero while held at the bound
            let mut dz = v * (S::ONE - p) - correction;
            if z.abs() >= self.lugre.z_max() && dz * z > S::ZERO {
                dz = S::ZERO;
            }
            f = f + self.lugre.damping(v) * dz;
        }
        f
    }
}

impl<S: Scalar> FrictionModel<S> for ElastoPlastic<S> {
    type State = LuGreState<S>;

    fn step(&self, state: &mut LuGreState<S>, v: S, h: S) -> S {
        match checked_inputs(v, h) {
            Some(v) => self.advance(state, v, S::ZERO, h, true),
            None => self.hold_force(state),
        }
    }

    /// `sigma0 z`.
    fn hold_force(&self, state: &LuGreState<S>) -> S {
        self.lugre.sigma0() * state.z
    }
}

/// Observer form: the correction `k e` is applied after the model's step
/// (first-order splitting), `z^ <- z^ - h k e`, then clamped to `±Fs/sigma0`.
impl<S: Scalar> Observable<S> for ElastoPlastic<S> {
    fn step_corrected(
        &self,
        state: &mut LuGreState<S>,
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Observer;
    use proptest::prelude::*;
    use std::vec::Vec;

    const P: ElastoPlasticParams = ElastoPlasticParams {
        lugre: LuGreParams::CANUDAS_1995,
        z_ba: 5e-6,
    };

    #[test]
    fn z_ba_must_be_below_the_coulomb_deflection() {
        let bad = ElastoPlasticParams { z_ba: 1e-5, ..P }; // Fc/sigma0 = 1e-5
        assert_eq!(
            bad.validate(),
            Err(ParamError::NotBelow {
                name: "z_ba",
                limit: "fc / sigma0"
            })
        );
        assert_eq!(
            ElastoPlasticParams { z_ba: 0.0, ..P }.validate(),
            Err(ParamError::NotPositive("z_ba"))
        );
    }

    #[test]
    fn alpha_uses_the_magnitude_of_z() {
        // negative deflection moving in the negative direction relaxes just like the positive one
        let m = P.build::<f64>().unwrap();
        let (mut a, mut b) = (LuGreState { z: 8e-6 }, LuGreState { z: -8e-6 });
        let fa = m.step(&mut a, 1e-3, 1e-3);
        let fb = m.step(&mut b, -1e-3, 1e-3);
        assert!((a.z + b.z).abs() < 1e-18, "{} {}", a.z, b.z);
        assert!((fa + fb).abs() < 1e-12);
    }

    #[test]
    fn steady_state_is_the_stribeck_map() {
        let m = P.build::<f64>().unwrap();
        let lugre = LuGreParams::CANUDAS_1995.build::<f64>().unwrap();
        for v in [-0.3, -1e-3, 1e-4, 2e-2] {
            let mut s = LuGreState::default();
            let mut f = 0.0;
            for _ in 0..20_000 {
                f = m.step(&mut s, v, 1e-3);
            }
            assert!((f - lugre.steady_state(v)).abs() < 1e-9, "v {v}: {f}");
        }
    }

    #[test]
    fn transition_matches_fine_steps() {
        // implicit Euler in the transition zone converges to the fine solution
        let m = P.build::<f64>().unwrap();
        let (mut a, mut b) = (LuGreState { z: 5e-6 }, LuGreState { z: 5e-6 });
        m.step(&mut a, 1e-3, 5e-3); // xi = 5 µm in one step
        for _ in 0..5000 {
            m.step(&mut b, 1e-3, 1e-6);
        }
        assert!((a.z - b.z).abs() < 0.05 * b.z, "{} {}", a.z, b.z);
    }

    #[test]
    fn observer_corrects() {
        let m = P.build::<f64>().unwrap();
        let o = Observer::new(m, 1000.0).unwrap();
        let mut z = LuGreState::default();
        let f = o.step(&mut z, 0.0, 1e-6, 1e-3);
        assert!(z.z < 0.0 && f < 0.0);
    }

    proptest! {
        #[test]
        fn bounded_and_finite(inputs in proptest::collection::vec((-1.0f64..1.0, 0.0f64..1e-1), 1..80)) {
            let m = P.build::<f32>().unwrap();
            let mut s = LuGreState::default();
            for (v, h) in inputs {
                let f = m.step(&mut s, v as f32, h as f32);
                prop_assert!(f.is_finite());
                prop_assert!(s.z.abs() <= 1.5e-5 * (1.0 + 1e-6));
            }
        }

        #[test]
        fn no_drift_below_z_ba(amplitudes in proptest::collection::vec(0.0f64..4.9e-6, 1..20)) {
            // displacement cycles 0 -> a -> 0 whose deflection stays below z_ba:
            // z returns exactly to 0, so a force cycle leaves no displacement behind
            let m = P.build::<f64>().unwrap();
            let mut s = LuGreState::default();
            let mut x = 0.0;
            let h = 1e-3;
            for a in amplitudes {
                let n = 50;
                let v = a / (n as f64 * h);
                let path: Vec<f64> = core::iter::repeat_n(v, n).chain(core::iter::repeat_n(-v, n)).collect();
                for v in path {
                    m.step(&mut s, v, h);
                    x += v * h;
                }
                prop_assert!((s.z - x).abs() < 1e-15);
                prop_assert!(s.z.abs() < 1e-15);
            }
        }
    }
}
