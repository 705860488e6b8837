//! The θ-adaptive observer: friction compensation that follows a plant whose
//! friction is a multiple of the model's (Canudas de Wit et al. 1995, IEEE TAC
//! 40(3), Section V; Olsson et al. 1998, Eur. J. Control 4(3); Canudas de Wit
//! & Lischinsky 1997, Int. J. Adapt. Control Signal Process. 11(1)): see
//! [`AdaptiveObserver`].

use crate::bits::Flag;
use crate::compensator::Compensation;
use crate::fixed_step::FixedStepObservable;
use crate::gain::Gain;
use crate::model::{convert, magnitude, magnitude_or_zero, non_negative, positive, ParamError};
use crate::observer::{Observable, Observer};
use crate::Scalar;

/// Design-time parameters of the adaptation, in `f64`.
///
/// ```
/// use friction_core::AdaptiveParams;
/// let p = AdaptiveParams { gamma: 600.0, ..AdaptiveParams::DEFAULT };
/// assert!(p.validate().is_ok());
/// let bad = AdaptiveParams { theta_min: 2.0, ..p }; // θ0 = 1 below θmin
/// assert!(bad.validate().is_err());
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AdaptiveParams {
    /// Adaptation gain `γ >= 0` on the position error (1/(position units x
    /// force units x s)).
    pub gamma: f64,
    /// Adaptation gain `γd >= 0` on the error's rate `de/dt` (1/(position
    /// units x force units)).
    pub gamma_derivative: f64,
    /// Leakage `ρ >= 0` (1/s): pulls `θ^` back to `θ0`.
    pub leakage: f64,
    /// Initial and leakage target `θ0`, within `[θmin, θmax]`.
    pub theta0: f64,
    /// Lower projection bound `θmin >= 0`.
    pub theta_min: f64,
    /// Upper projection bound `θmax > θmin`.
    pub theta_max: f64,
}

impl AdaptiveParams {
    /// No leakage, `θ0 = 1`, `θ ∈ [0.2, 5]`, and `γ = 0` (no adaptation:
    /// set `gamma`, e.g. with [`AdaptiveParams::gain_for_rate`]).
    pub const DEFAULT: Self = Self {
        gamma: 0.0,
        gamma_derivative: 0.0,
        leakage: 0.0,
        theta0: 1.0,
        theta_min: 0.2,
        theta_max: 5.0,
    };

    /// `γ = a kc kp / fs^2`: the gain that adapts at about `a` (1/s) in a
    /// loop with proportional gain `kp` and torque constant `kc` on friction
    /// of level `fs`; pair it with `gamma_derivative = γ kd / kp` (see
    /// [`AdaptiveObserver`]).
    pub fn gain_for_rate(rate: f64, kp: f64, torque_constant: f64, fs: f64) -> f64 {
        rate * torque_constant * kp / (fs * fs)
    }

    /// Checks `gamma`, `gamma_derivative`, `leakage` `>= 0`, `0 <= θmin <= θ0 <= θmax`,
    /// `θmin < θmax`, all finite, and each bound 0 (`θmin`, `θ0`) or within
    /// [`PARAM_RANGE`](crate::PARAM_RANGE); the error names the parameter
    /// (a `θmax` of `1e-300` is `θmax`'s error, not `θmin`'s).
    pub fn validate(&self) -> Result<(), ParamError> {
        non_negative("gamma", self.gamma)?;
        non_negative("gamma_derivative", self.gamma_derivative)?;
        non_negative("leakage", self.leakage)?;
        magnitude_or_zero("theta_min", self.theta_min)?;
        magnitude("theta_max", self.theta_max)?;
        magnitude_or_zero("theta0", self.theta0)?;
        if self.theta_min >= self.theta_max {
            return Err(ParamError::NotBelow {
                name: "theta_min",
                limit: "theta_max",
            });
        }
        if self.theta0 < self.theta_min || self.theta0 > self.theta_max {
            return Err(ParamError::NotBelow {
                name: "theta0",
                limit: "within [theta_min, theta_max]",
            });
        }
        Ok(())
    }

    /// Validates and builds the adaptive observer around `observer`, for a
    /// compensator running at period `h` (s). Besides
    /// [`validate`](Self::validate), rejects what the scalar cannot carry:
    /// `γ h` and `ρ h` (scaled), and the bounds.
    ///
    /// ```
    /// use friction_core::{AdaptiveParams, AdaptiveState, LuGreParams, Observer};
    /// let model = LuGreParams::OLSSON_1998.build::<f32>()?;
    /// let observer: Observer<_, f32> = Observer::new(model, 20.0)?;
    /// let gamma = AdaptiveParams::gain_for_rate(2.0, 60.0, 1.02, 0.33);
    /// let p = AdaptiveParams { gamma, gamma_derivative: gamma * 1.2 / 60.0, ..AdaptiveParams::DEFAULT };
    /// let adaptive = p.build(observer, 1e-3)?;
    /// let state: AdaptiveState<friction_core::LuGreState<f32>, f32> = AdaptiveState::default();
    /// assert_eq!(adaptive.theta(&state), 1.0);
    /// # Ok::<(), friction_core::ParamError>(())
    /// ```
    pub fn build<S: Scalar, M>(
        &self,
        observer: Observer<M, S>,
        h: f64,
    ) -> Result<AdaptiveObserver<M, S>, ParamError> {
        self.validate()?;
        positive("h", h)?;
        // θ^ - θ0 is carried times `scale`
        let range = self.theta_max.max(self.theta0 - self.theta_min);
        // 2^exp: 1 for floats; in fixed point the largest power that
        // holds the range, lowered while a gain would need scaling itself
        // (offset increments keep ample precision either way)
        let mut exp = libm::log2(S::force_scale(range)) as i8;
        let largest_gain = (self.gamma * h).max(self.gamma_derivative);
        while exp > 0 && largest_gain * libm::exp2(f64::from(exp)) >= 8192.0 {
            exp -= 1;
        }
        let scale = libm::exp2(f64::from(exp));
        let scaled = |name, x: f64| -> Result<S, ParamError> {
            if x == 0.0 {
                Ok(S::ZERO)
            } else {
                convert(name, x)
            }
        };
        Ok(AdaptiveObserver {
            observer,
            gamma_h: Gain::new("gamma", self.gamma * h * scale)?,
            gamma_d: Gain::new("gamma_derivative", self.gamma_derivative * scale)?,
            signal_limit: S::from_f64(SIGNAL_LIMIT),
            leakage_h: scaled("leakage", (self.leakage * h).min(1.0))?,
            theta0: convert("theta0", self.theta0)?,
            low: scaled("theta_min", (self.theta_min - self.theta0) * scale)?,
            high: scaled("theta_max", (self.theta_max - self.theta0) * scale)?,
            theta_min: convert("theta_min", self.theta_min)?,
            theta_max: convert("theta_max", self.theta_max)?,
            scale_exp: exp,
            period: h,
            params: *self,
        })
    }
}

impl Default for AdaptiveParams {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// The state of an [`AdaptiveObserver`]: the model's state and `θ^`.
/// `Default` is the model at rest with `θ^ = θ0`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AdaptiveState<T, S> {
    /// The observer's model state.
    pub model: T,
    /// `θ^ - θ0`, scaled (see [`AdaptiveObserver::theta`]).
    offset: S,
    /// The last position error, once `primed`.
    last_error: S,
    /// Whether `last_error` holds one (a byte: `crate::bits`).
    primed: Flag,
}

/// The built θ-adaptive observer: immutable, shared by any number of
/// [`AdaptiveState`]s. A [`Compensation`] for the
/// [`Compensator`](crate::Compensator) (wrap it in
/// [`FixedPeriod`](crate::FixedPeriod) for a fixed-step model).
///
/// The θ-adaptive observer: friction compensation that follows a plant
/// whose friction is a multiple of the model's (Canudas de Wit et al. 1995,
/// IEEE TAC 40(3), Section V; Olsson et al. 1998, Eur. J. Control 4(3);
/// Canudas de Wit & Lischinsky 1997, Int. J. Adapt. Control Signal Process.
/// 11(1)).
///
/// The plant's friction is taken to be `θ F(v, z)`, the model's friction
/// scaled by an unknown, slowly varying factor `θ` (normal force,
/// temperature, wear, or a model whose `Fc` and `Fs` are off by a common
/// factor). The [`Observer`] estimates the model's friction `F^` from the
/// measured velocity and the position error `e = x - x_ref`; the estimate
/// sent to the drive is `θ^ F^`, and `θ^` follows a gradient law with
/// leakage, projected onto `[θmin, θmax]`:
///
/// ```text
/// F^      = observer(v, e)                        the model's friction (as Observer)
/// dθ^/dt  = -(γ e + γd de/dt) F^ - ρ (θ^ - θ0)     gradient law, leakage ρ
/// θ^      = min(θmax, max(θmin, θ^))              projection
/// output  = θ^ F^                                 within θmax B(v), as |F^| <= B(v)
/// ```
///
/// Sign: a plant with more friction than the estimate lags its reference
/// (`e < 0` while `F^ > 0` in forward sliding), so `θ^` grows. With the
/// opposite sign of `e` the law diverges. Discretised with explicit Euler at
/// the compensator's period `h` (`de/dt h` is the change of `e` since the
/// last step), after the observer's step, and the output uses the updated
/// `θ^`.
///
/// Choosing the gains: in a PD(+I) loop with gains `kp`, `kd` and torque
/// constant `kc`, a friction error `δF` drives the composite error
/// `s = de/dt + (kp / kd) e` like `J ds/dt + kd s ≈ -δF / kc`, the error
/// model of Slotine and Li (1987) for which a gradient law on `s F^` is
/// stable; `γd = γ kd / kp` gives that law (`γ e + γd de/dt = γd s`). With
/// `γ = a kc kp / Fs^2` ([`AdaptiveParams::gain_for_rate`]) `θ^` converges
/// at a rate near `a` (1/s) while sliding at the friction level `Fs`; `a`
/// of 1 to 10 is a starting point. Without the `de/dt` term (`γd = 0`) the
/// law reads the error alone, which lags the friction error by the loop's
/// phase: on a loop that is slow against its friction (`friction servo` on
/// `params/astrom2008-drift.toml`) it drove `θ^` the wrong way, to `θmax`.
/// The integral action absorbs the steady error, so adaptation is driven
/// by the transients at reversals: a persistently reversing motion adapts,
/// a standstill does not (`s F^` is then small), and leakage `ρ` slowly
/// returns `θ^` to `θ0`.
///
/// Bounds, for any finite inputs: `θ^` stays in `[θmin, θmax]`, the output
/// is finite and within `θmax B(v)`, and the model's state stays within its
/// bounds (those of [`Observer`]). A NaN or infinite input leaves the state
/// untouched.
///
/// In fixed point `θ^` is carried scaled by a power of two
/// (the force scale of its range, chosen at build time): per-tick increments of `1e-6`
/// would otherwise round to 0 in Q16.16.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AdaptiveObserver<M, S> {
    observer: Observer<M, S>,
    gamma_h: Gain<S>,
    gamma_d: Gain<S>,
    signal_limit: S,
    leakage_h: S,
    theta0: S,
    low: S,
    high: S,
    theta_min: S,
    theta_max: S,
    /// The offset is carried times `2^scale_exp`.
    scale_exp: i8,
    period: f64,
    params: AdaptiveParams,
}

impl<M, S: Scalar> AdaptiveObserver<M, S> {
    /// The current `θ^` of `state`.
    #[inline]
    pub fn theta(&self, state: &AdaptiveState<impl Copy, S>) -> S {
        self.theta_of(state.offset)
    }

    /// `θ0 + offset / scale`, within `[θmin, θmax]` against rounding.
    #[inline]
    fn theta_of(&self, offset: S) -> S {
        // saturating: a stored exponent of -128 (C's garbage; a built one
        // is in 0..=31) would overflow the plain negation
        (self.theta0 + offset.rescale_pow2(self.scale_exp.saturating_neg()))
            .min(self.theta_max)
            .max(self.theta_min)
    }

    /// The wrapped observer.
    pub fn observer(&self) -> &Observer<M, S> {
        &self.observer
    }

    /// The parameters it was built from.
    pub fn params(&self) -> &AdaptiveParams {
        &self.params
    }

    /// The period it was built for (s).
    pub fn period(&self) -> f64 {
        self.period
    }

    /// Sets `θ^` of `state` (e.g. restored from non-volatile memory after a
    /// power cycle), projected onto `[θmin, θmax]`; a NaN leaves it as it is.
    pub fn set_theta(&self, state: &mut AdaptiveState<impl Copy, S>, theta: f64) {
        if !theta.is_nan() {
            let scale = libm::exp2(f64::from(self.scale_exp));
            let offset = S::from_f64((theta - self.theta0.to_f64()) * scale);
            state.offset = offset.min(self.high).max(self.low);
        }
    }

    /// Adapts `θ^` from the error `e` and the model's estimate `f`, then
    /// returns `θ^ f`.
    ///
    /// The observer clips `F^` to its force bound `B(v)` and `θ^ <= θmax`,
    /// so `|θ^ F^| <= θmax B(v)` (rounding is monotone) with no clamp here.
    #[inline]
    fn adapt<T>(&self, state: &mut AdaptiveState<T, S>, e: S, f: S) -> S {
        // each gain's product is clamped before it meets f, so no product
        // is inf * 0
        let limit = self.signal_limit;
        let de = if state.primed.get() {
            (e - state.last_error).sat(limit)
        } else {
            S::ZERO
        };
        let signal =
            (self.gamma_h.times(e).sat(limit) + self.gamma_d.times(de).sat(limit)).sat(limit);
        let step = if self.leakage_h == S::ZERO {
            signal * f
        } else {
            signal * f + self.leakage_h * state.offset
        };
        state.offset = (state.offset - step).min(self.high).max(self.low);
        state.last_error = e;
        state.primed = Flag::new(true);
        scaled(self.theta_of(state.offset), f)
    }
}

/// The bound on the scaled adaptation signal `γ h e + γd Δe` (and on
/// `Δe`), so that its product with a force stays finite in floating point;
/// fixed point saturates at its own limit (32768 in Q16.16).
const SIGNAL_LIMIT: f64 = 1e6;

/// `θ f`, or `f` where the product overflows a float (a `θmax` times a
/// force bound beyond the scalar's range): always finite for finite `f`.
#[inline]
fn scaled<S: Scalar>(theta: S, f: S) -> S {
    let out = theta * f;
    if out.is_finite() {
        out
    } else {
        f
    }
}

impl<S: Scalar, M: Observable<S>> AdaptiveObserver<M, S> {
    /// Advances the observer by `h` with measured velocity `v` and position
    /// error `e = x - x_ref`, adapts `θ^` (by the built period; `h` drives
    /// the model), and returns `θ^ F^`. A non-finite input, or `h <= 0`,
    /// leaves the state untouched and returns `θ^` times the model's hold
    /// force.
    ///
    /// ```
    /// use friction_core::{AdaptiveParams, AdaptiveState, LuGreParams, Observer};
    /// let observer = Observer::new(LuGreParams::OLSSON_1998.build::<f64>()?, 20.0)?;
    /// let p = AdaptiveParams { gamma: 1e4, ..AdaptiveParams::DEFAULT };
    /// let a = p.build(observer, 1e-3)?;
    /// let mut s = AdaptiveState::default();
    /// // sliding forward at 0.1 rad/s while lagging 1 mrad: more friction than modelled
    /// for _ in 0..100 {
    ///     a.step(&mut s, 0.1, -1e-3, 1e-3);
    /// }
    /// assert!(a.theta(&s) > 1.0 && a.theta(&s) <= 5.0);
    /// # Ok::<(), friction_core::ParamError>(())
    /// ```
    #[inline]
    pub fn step(&self, state: &mut AdaptiveState<M::State, S>, v: S, e: S, h: S) -> S {
        let theta = self.theta(state);
        if !(v.is_finite() && e.is_finite() && h.is_finite() && h > S::ZERO) {
            return scaled(theta, self.observer.model().hold_force(&state.model));
        }
        let v = v.sat(S::VELOCITY_LIMIT);
        let f = self.observer.step(&mut state.model, v, e, h);
        self.adapt(state, e.sat(S::VELOCITY_LIMIT), f)
    }
}

impl<S: Scalar, M: FixedStepObservable<S>> AdaptiveObserver<M, S> {
    /// [`AdaptiveObserver::step`] for a fixed-step model: one period (the
    /// model's, which the compensator checks against the built period).
    #[inline]
    pub fn step_fixed(&self, state: &mut AdaptiveState<M::State, S>, v: S, e: S) -> S {
        if !(v.is_finite() && e.is_finite()) {
            return scaled(
                self.theta(state),
                self.observer.model().hold_force(&state.model),
            );
        }
        let v = v.sat(S::VELOCITY_LIMIT);
        let f = self.observer.step_fixed(&mut state.model, v, e);
        self.adapt(state, e.sat(S::VELOCITY_LIMIT), f)
    }
}

/// The adaptive observer on a variable-step model as the compensation.
impl<S: Scalar, M: Observable<S>> Compensation<S> for AdaptiveObserver<M, S> {
    type State = AdaptiveState<M::State, S>;
    const LOADED: bool = M::LOADED;
    fn motor_torque(&self, state: &mut Self::State, torque: S) {
        self.observer
            .model()
            .set_motor_torque(&mut state.model, torque);
    }
    fn set_external_torque(&self, state: &mut Self::State, torque: S) {
        self.observer
            .model()
            .set_external_torque(&mut state.model, torque);
    }
    #[inline]
    fn estimate(&self, state: &mut Self::State, v: S, e: S, h: S) -> S {
        self.step(state, v, e, h)
    }
    fn period(&self) -> Option<f64> {
        Some(self.period)
    }
    /// The model's state carried over ([`Observable::carry_over`]), `θ^`
    /// restarted at this law's `θ0`: the new model is the new nominal.
    fn carry_over(&self, old: &Self, state: &mut Self::State) {
        self.observer
            .model()
            .carry_over(old.observer.model(), &mut state.model);
        state.offset = S::ZERO;
    }
}

/// The adaptive observer on a fixed-step model as the compensation. Its
/// period is the model's, which must be the one the adaptation was built
/// for (otherwise a negative period, which no compensator accepts:
/// [`ParamError::PeriodMismatch`]).
impl<S: Scalar, M: FixedStepObservable<S>> Compensation<S>
    for crate::FixedPeriod<AdaptiveObserver<M, S>>
{
    type State = AdaptiveState<M::State, S>;
    const USES_H: bool = false;
    const LOADED: bool = M::LOADED;
    fn motor_torque(&self, state: &mut Self::State, torque: S) {
        self.0
            .observer
            .model()
            .set_motor_torque(&mut state.model, torque);
    }
    fn set_external_torque(&self, state: &mut Self::State, torque: S) {
        self.0
            .observer
            .model()
            .set_external_torque(&mut state.model, torque);
    }
    #[inline]
    fn estimate(&self, state: &mut Self::State, v: S, e: S, _h: S) -> S {
        self.0.step_fixed(state, v, e)
    }
    fn period(&self) -> Option<f64> {
        let model = self.0.observer.model().period();
        if (model - self.0.period).abs() <= 1e-9 * model {
            Some(model)
        } else {
            Some(-1.0)
        }
    }
    /// As the variable-step form's: the model's state carried over, `θ^`
    /// restarted at `θ0`.
    fn carry_over(&self, old: &Self, state: &mut Self::State) {
        self.0
            .observer
            .model()
            .carry_over(old.0.observer.model(), &mut state.model);
        state.offset = S::ZERO;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bound_out_of_range_is_named() {
        let p = AdaptiveParams::DEFAULT;
        // θmax far below θmin: θmax is wrong (θmin and θ0 are the defaults)
        let tiny = AdaptiveParams {
            theta_max: 1e-300,
            ..p
        };
        assert_eq!(tiny.validate(), Err(ParamError::OutOfRange("theta_max")));
        let huge = AdaptiveParams {
            theta_max: 1e300,
            ..p
        };
        assert_eq!(huge.validate(), Err(ParamError::OutOfRange("theta_max")));
        let tiny_min = AdaptiveParams {
            theta_min: 1e-300,
            ..p
        };
        assert_eq!(
            tiny_min.validate(),
            Err(ParamError::OutOfRange("theta_min"))
        );
        // 0 stays a valid lower bound, and the defaults are valid
        assert_eq!(
            AdaptiveParams {
                theta_min: 0.0,
                ..p
            }
            .validate(),
            Ok(())
        );
        assert_eq!(p.validate(), Ok(()));
        assert_eq!(
            AdaptiveParams {
                theta_max: 0.0,
                ..p
            }
            .validate(),
            Err(ParamError::NotPositive("theta_max"))
        );
    }
}
