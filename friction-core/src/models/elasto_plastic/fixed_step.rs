//! The fixed-step elasto-plastic model, built for one sample period:
//! [`ElastoPlasticFixedStep`].

use super::corrected_shift;
use super::zone::{relaxed_fraction, zone_rate, zone_step_fixed, Slip, MAX_SUBSTEPS, XI_CAP};
use crate::fixed_step::{checked_velocity, signed, FixedStepModel, FixedStepObservable};
use crate::models::lugre::{LuGreFixedStep, LuGreFixedStepState};
use crate::Scalar;

/// The state of [`ElastoPlasticFixedStep`]: the fixed-step LuGre model's,
/// [`LuGreFixedStepState`] (the elastic force `w = sigma0 z`).
pub type ElastoPlasticFixedStepState<S> = LuGreFixedStepState<S>;

/// The elasto-plastic model built for one sample period `h`
/// ([`ElastoPlasticParams::build_fixed_step`](super::ElastoPlasticParams::build_fixed_step)),
/// with the elastic force `w = sigma0 z` as its state ([`ElastoPlasticFixedStepState`], `|w|
/// <= Fs`). In force units the model of Dupont, Hayward, Armstrong and Altpeter
/// (2002) reads, along the motion (`W = sign(v) w`, distance `X = sigma0 h
/// |v|`, `sigma0 h` formed at build time):
///
/// ```text
/// dW/dX = 1 - alpha(W) W / g(v),   W_ba = sigma0 z_ba <= W <= g(v) the transition zone
/// w+ = sat(w(X) - sigma0 h c, Fs)
/// F  = w+ + sigma1(v) dz/dt + sigma2 v,   dz/dt = v dW/dX - c
/// ```
///
/// with the variable-step form's discretisation ([`ElastoPlastic`](super::ElastoPlastic)): exact
/// below `W_ba` and above `g(v)`, in the zone the exact Riccati tail with
/// its rate frozen where the step starts (bounded in cost, the default) or
/// RK4 sub-steps then that tail ([`ElastoPlasticFixedStep::with_full_step`]: the
/// two forms then agree to rounding). `c` is an observer's
/// correction, 0 for the model. As in [`LuGreFixedStep`], forces (the state `w`
/// and `W_ba` included) are carried times its force scale (1 in floating
/// point), ratios of forces are formed from the unscaled `1/g` or as
/// quotients, and the force is returned in newtons.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ElastoPlasticFixedStep<S> {
    pub(super) lugre: LuGreFixedStep<S>,
    /// `sigma0 z_ba` (N), times the LuGre part's force scale.
    pub(super) w_ba: S,
    /// RK4 sub-steps of the transition zone a step may take
    /// ([`ElastoPlasticFixedStep::with_max_substeps`]).
    pub(super) max_substeps: u8,
}

impl<S: Scalar> ElastoPlasticFixedStep<S> {
    /// The same model with at most `k` RK4 sub-steps of the transition zone
    /// a step (0 to 24, clamped; 0 when built, the bounded step; 24, the
    /// full step of [`Self::with_full_step`], is enough for any distance):
    /// a real-time loop sized by its worst step trades accuracy for a
    /// bound. The distance left after `k` sub-steps goes to the closed-form
    /// tail with the rate's `b` frozen where the sub-steps stopped (with
    /// `k = 0`, where the step started). Only a step that crosses most of
    /// the zone at once is affected: measured against the full step over
    /// every distance and zone shape (`eps` 0.01 to 1), the state `w` is off
    /// by at most 14.5 % of the zone's width `g(v) - sigma0 z_ba` with
    /// `k = 0`, 8.7 % with 1 (5.0 % with 2, 2.8 % with 3, 1.5 % with 4,
    /// 0.4 % with 6, 7e-5 with 12). Each sub-step costs four evaluations of
    /// the zone polynomial and a division (dear on a Cortex-M0, which has no
    /// divide instruction); the entry, the tail's exponential and the
    /// damping term's zone rate stay. A real-time loop is sized by its worst
    /// step: with `k = 0` the worst step stays within 4x the average on both
    /// cores and scalars the cost guide measures, with `k = 1` on a
    /// Cortex-M4F in `f32`, while the full step's worst is an order of
    /// magnitude dearer than its average (the cost table's
    /// `elasto-plastic-k0`, `-k1`, `-k3` and `-full` rows give the figures).
    /// The damping term `sigma1 |v| dW/dX` carries the
    /// state's error into the force: from rest, at a speed that crosses
    /// the zone in one step, by up to 49 Fs with `k = 0` (35 Fs with 1, 12
    /// Fs with 3), one step's transient.
    ///
    /// ```
    /// use friction_core::{ElastoPlasticParams, LuGreParams};
    /// let p = ElastoPlasticParams { lugre: LuGreParams::CANUDAS_1995, z_ba: 0.5 / 1e5 };
    /// let real_time = p.build_fixed_step::<f32>(1e-3)?.with_max_substeps(3);
    /// # let _ = real_time;
    /// # Ok::<(), friction_core::ParamError>(())
    /// ```
    #[must_use]
    pub fn with_max_substeps(mut self, k: u8) -> Self {
        self.max_substeps = k.min(MAX_SUBSTEPS as u8);
        self
    }

    /// The same model with the full step: as many RK4 sub-steps of the
    /// transition zone as the distance needs (24 at most), the
    /// variable-step form's solution to rounding, at an unbounded cost
    /// (its worst step 20x its average on a Cortex-M4F): for the desk, or
    /// a loop with time to spare.
    ///
    /// ```
    /// use friction_core::{ElastoPlasticParams, LuGreParams};
    /// let p = ElastoPlasticParams { lugre: LuGreParams::CANUDAS_1995, z_ba: 0.5 / 1e5 };
    /// let exact = p.build_fixed_step::<f64>(1e-3)?.with_full_step();
    /// # let _ = exact;
    /// # Ok::<(), friction_core::ParamError>(())
    /// ```
    #[must_use]
    pub fn with_full_step(self) -> Self {
        self.with_max_substeps(MAX_SUBSTEPS as u8)
    }

    /// The break-away force `sigma0 z_ba` (N).
    pub fn w_ba(&self) -> S {
        self.lugre.unscale(self.w_ba)
    }

    /// `a / w_max` for `0 <= a <= w_max` (scaled forces), from the unscaled
    /// `1 / g`: `(a / g) k <= k` fits, and no factor is a tiny number.
    #[inline]
    fn ratio(&self, a: S, inv_w_max: S) -> S {
        self.lugre.unscale(a * inv_w_max)
    }

    /// `dW/dX` at the force along the motion `w`, with `w_max = g(v)`
    /// (scaled) and `inv_w_max = 1/g` (unscaled), and in the transition
    /// zone its rate, which the damping term reuses ([`Slip`]).
    #[inline]
    pub(super) fn slip(&self, w: S, w_max: S, inv_w_max: S) -> Slip<S> {
        if w <= self.w_ba {
            Slip {
                slope: S::ONE,
                zone_rate: S::ZERO,
            }
        } else if w >= w_max {
            // 1 - w / w_max, with w - w_max <= Fs - Fc (scaled) in the product
            Slip {
                slope: -self.lugre.unscale((w - w_max) * inv_w_max),
                zone_rate: S::ZERO,
            }
        } else {
            let width = w_max - self.w_ba;
            let u = ((w_max - w) / width).min(S::ONE);
            let (rate, _) = zone_rate(u, self.ratio(width, inv_w_max));
            Slip {
                slope: u * rate,
                zone_rate: rate,
            }
        }
    }

    /// `alpha` at the force along the motion `w` (scaled), as
    /// [`ElastoPlastic`](super::ElastoPlastic)'s.
    #[inline]
    fn alpha(&self, w: S, w_max: S) -> S {
        if w <= self.w_ba {
            S::ZERO
        } else if w >= w_max {
            S::ONE
        } else {
            relaxed_fraction(((w_max - w) / (w_max - self.w_ba)).min(S::ONE))
        }
    }

    /// `dv dW/dX` (`dv = sigma1 v`, scaled) given `slip` at `w` (from
    /// [`Self::slip`]): where `dW/dX = (w_max - w) r / width` (`r = 1/w_max`
    /// above `w_max`, the zone rate in it) as `(dv / width) (w_max - w) r`,
    /// the small difference of two scaled forces times a quotient; `dv
    /// dW/dX` if the quotient could saturate.
    #[inline]
    fn damped_slip(&self, dv: S, w: S, w_max: S, slip: Slip<S>) -> S {
        if w <= self.w_ba {
            return dv;
        }
        let (width, r) = if w >= w_max {
            (w_max, S::ONE)
        } else {
            (w_max - self.w_ba, slip.zone_rate)
        };
        // |dv| < 8192 width, without a product that would saturate
        if dv.abs().mul_fraction(S::from_f64(1.0 / 8192.0)) < width {
            (dv / width) * (w_max - w) * r
        } else {
            dv * slip.slope
        }
    }

    /// The force along the motion `w` over the distance `xi` (in force
    /// units, `sigma0 |v| h`), as [`ElastoPlastic`](super::ElastoPlastic)'s `advance_w`.
    #[inline]
    fn advance_w(&self, mut w: S, mut xi: S, w_max: S, inv_w_max: S) -> S {
        if w < self.w_ba {
            let reach = self.w_ba - w;
            if xi <= reach {
                return w + xi;
            }
            w = self.w_ba;
            xi = xi - reach;
        }
        // xi <= XI_CAP w_max, without a product that would saturate
        if xi.mul_fraction(S::from_f64(1.0 / XI_CAP)) > w_max {
            xi = S::from_f64(XI_CAP) * w_max;
        }
        if w >= w_max {
            // xi / w_max as a quotient of two scaled forces: any product
            // form would saturate (k xi / g) or use a tiny 1/(k g)
            return w_max + (w - w_max) * (xi / w_max).exp_neg();
        }
        let width = w_max - self.w_ba;
        let eps = self.ratio(width, inv_w_max);
        // quotients of scaled forces: 1/width in scaled units is tiny in fixed point
        let u = ((w_max - w) / width).min(S::ONE);
        // at most MAX_SUBSTEPS whatever the stored byte (C may have
        // overwritten it): the same count for a built model
        let substeps = usize::from(self.max_substeps).min(MAX_SUBSTEPS);
        (w + zone_step_fixed(u, xi, width, eps, w_max - w, substeps)).min(w_max)
    }

    // CORRECTED: the observer's step, with its correction `c`; the model's
    // (c = 0) forms none of its terms (as `LuGreFixedStep`'s)
    #[inline]
    fn advance<const CORRECTED: bool>(
        &self,
        state: &mut ElastoPlasticFixedStepState<S>,
        v: S,
        c: S,
        damping: bool,
    ) -> S {
        let lugre = &self.lugre;
        // scaled
        let w_max = lugre.curve().eval_fast(v);
        // 1/g unscaled, g >= Fc > 0, by the quotient: LuGre's reciprocal
        // (`inverse_unscaled`, the same bits) makes the Q16.16 average on a
        // Cortex-M0 cheaper than it makes the `k = 0` worst step, which then
        // sits closer to the enforced 4x than a compiler's layout can be
        // trusted to stay (figures in the cost guide)
        let inv_w_max = lugre.scale_s() / w_max;
        let mut w = state.w;
        let xi = lugre.sigma0_h() * v.abs();
        if v != S::ZERO {
            let along = self.advance_w(signed(v, w), xi, w_max, inv_w_max);
            w = signed(v, along);
        }
        // the model's own end state (its rate enters the damping term)
        let w_model = w;
        // the fraction of the correction's rate left at the end of the step
        let mut kept = S::ONE;
        if CORRECTED && c != S::ZERO {
            // as ElastoPlastic's `advance`, in scaled forces
            let shift = lugre.sigma0_h() * c;
            let relax = |a: S| self.alpha(a, w_max) * a;
            let along = signed(v, shift).sat(lugre.fs() + lugre.fs());
            let (phi, left) = corrected_shift(signed(v, w), along, xi / w_max, relax);
            w = w - shift.mul_fraction(phi);
            kept = left;
        }
        let w = w.sat(lugre.fs());
        state.w = w;
        let mut f = w + lugre.sigma2() * v;
        if damping {
            // at v = 0 the slip is multiplied by 0: its argument's sign is moot
            // the model's rate on its own path plus the correction's share
            let slip = self.slip(signed(v, w_model), w_max, inv_w_max);
            let dz = if CORRECTED {
                v * slip.slope - c * kept
            } else {
                v * slip.slope
            };
            if !(w.abs() >= lugre.fs() && dz * w > S::ZERO) {
                // sigma1 dz/dt = (sigma1 v) dW/dX - sigma1 c kept, with the
                // product formed so that no rounding of a ratio (1.5e-5 in
                // fixed point) is multiplied by sigma1 v
                let d = lugre.damping(v);
                f = f + self.damped_slip(d * v, signed(v, w_model), w_max, slip);
                if CORRECTED {
                    f = f - (d * c).mul_fraction(kept);
                }
            }
        }
        f
    }
}

impl<S: Scalar> FixedStepModel<S> for ElastoPlasticFixedStep<S> {
    type State = ElastoPlasticFixedStepState<S>;

    fn period(&self) -> f64 {
        self.lugre.period()
    }

    #[inline]
    fn step(&self, state: &mut ElastoPlasticFixedStepState<S>, v: S) -> S {
        match checked_velocity(v) {
            Some(v) => self
                .lugre
                .unscale(self.advance::<false>(state, v, S::ZERO, true)),
            None => self.hold_force(state),
        }
    }

    /// `w = sigma0 z`.
    fn hold_force(&self, state: &ElastoPlasticFixedStepState<S>) -> S {
        self.lugre.unscale(state.w)
    }
}

/// As [`ElastoPlastic`](super::ElastoPlastic)'s observer form: the correction moves the state
/// after the model's step against its relaxation, `w <- w - sigma0 h c
/// phi(lambda h)` (see `corrected_shift`), then `|w| <= Fs`.
impl<S: Scalar> FixedStepObservable<S> for ElastoPlasticFixedStep<S> {
    fn step_corrected(
        &self,
        state: &mut ElastoPlasticFixedStepState<S>,
        v: S,
        correction: S,
        damping: bool,
    ) -> S {
        self.lugre
            .unscale(self.advance::<true>(state, v, correction, damping))
    }

    /// As LuGre's.
    fn force_bound(&self, v: S) -> S {
        self.lugre.force_bound(v)
    }
}
