//! The fixed-step form of the per-parameter adaptation, for every scalar:
//! see [`ParameterAdaptiveFixedStep`], built by
//! [`ParameterAdaptiveParams::build_fixed_step`].

use super::{
    Estimate, ParameterAdaptive, ParameterAdaptiveParams, PARAMETER_ADAPTIVE_ESTIMATES,
    SIGNAL_LIMIT,
};
use crate::bits::Flag;
use crate::compensator::{Compensation, CompensatorParams};
use crate::fixed_step::{carried, scale_ratio};
use crate::gain::Gain;
use crate::model::{check_force, convert, ParamError};
use crate::models::lugre::phi_series_inlined;
use crate::scalar::inverse_scale_exp;
use crate::stribeck::{StribeckCurve, StribeckParams};
use crate::Scalar;

/// One estimate's weight (its gains relative to the Coulomb levels'),
/// nominal value and box (times the force scale).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct ScaledEstimate<S> {
    weight: Gain<S>,
    nominal: S,
    low: S,
    high: S,
}

/// The state of a [`ParameterAdaptiveFixedStep`]: the elastic force, the
/// estimates (both in force units times the force scale), the last error
/// and the transmitted torque. `Default` is at rest before the first step,
/// which sets the estimates to their nominal values (as
/// [`ParameterAdaptiveFixedStep::initial`] does).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ParameterAdaptiveFixedStepState<S> {
    /// `k sigma0 z`: the elastic force times the force scale.
    w: S,
    /// `k [Fc+, Fc-, Ds, sigma2, mu]`.
    estimates: [S; PARAMETER_ADAPTIVE_ESTIMATES],
    last_error: S,
    /// The transmitted torque `kc u - τ_ext` (torque units, not scaled).
    torque: S,
    external: S,
    started: Flag,
    primed: Flag,
}

/// The built fixed-step per-parameter adaptive observer: immutable, shared by any number of
/// [`ParameterAdaptiveFixedStepState`]s; a [`Compensation`] for a
/// [`Compensator`](crate::Compensator) at the period it was built for, in
/// `f32`, `f64` or `Fixed32` (feature `fixed`).
///
/// The fixed-step form of the per-parameter adaptation, for every scalar:
/// [`ParameterAdaptiveFixedStep`], built by [`ParameterAdaptiveParams::build_fixed_step`].
///
/// The law, the discretisation and the bounds are
/// [`ParameterAdaptive`]'s; what differs is what
/// the state carries. The variable form keeps the bristle `z` (rad) and
/// forms `sigma0 h`, `1/h` and `sigma1` at run time: in Q16.16 a bristle of
/// `Fc / sigma0` is a few units of the last place, `h = 1e-3` is not held
/// within 0.1 % (its build fails), and per-tick increments of an estimate
/// (`γ h e`, about 1e-5 N) round away. This form carries, as the fixed-step
/// models do ([`FixedStepModel`](crate::FixedStepModel)):
///
/// - the elastic force `w = sigma0 z` and the estimates in force units
///   times a power of two `k` (the force scale: 1 in floating
///   point; in Q16.16 the largest that keeps the largest force the boxes
///   allow within range, so an estimate's last place is about `1.5e-5 / k` N);
/// - every product with `h` formed once in `f64` when built: `k sigma0 h`,
///   `sigma1 / (sigma0 h)` (the damping term from the change of `w`), and
///   the levels' `k γ h`, `k γd` and each estimate's weight (its gains over
///   the levels'), each as a mantissa and a power of two so that gains far
///   from 1 keep their precision; the adaptation signal is formed once a
///   tick and scaled by each weight.
///
/// ```text
/// ζ' = (W + k sigma0 h (v - k_o e)) / (G + k sigma0 h |v|),   G = k g^(v)
///                      (= W' / G of the variable form's implicit Euler step)
/// ζ  = clamp(ζ', -1, 1),  W = ζ G
/// F^ = (W + sigma1 / (sigma0 h) (ζ' G - W_old) + k sigma2^ v) / k
/// ```
///
/// Built by [`ParameterAdaptiveParams::build_fixed_step_exact`]
/// (`EXACT = true`), the bristle takes LuGre's exact step instead, as the
/// variable form's does with [`ParameterAdaptiveParams::exact_step`]: with
/// `x = k sigma0 h |v| / G`, `P = k sigma0 h (v - k_o e)` and `G0 = k g^(0)`
/// (the level at rest),
///
/// ```text
/// W+ = W e^-x + W_eq (1 - e^-x),  W_eq = P / x, within ±2 G0 if x > 1
/// W  = clamp(W+, ±G0),  ζ = clamp(W / G, -1, 1)
/// (G0 of the side W starts on in the clamp of W_eq, of the side W+ ends on in W's)
/// F^ = (W + sigma1 / (sigma0 h) (P - x W) + k sigma2^ v) / k     (no damping held at ±G0)
/// ```
///
/// In `f64` it agrees with the variable form to rounding, either step; in `f32` and
/// Q16.16 the tests compare a servo run under the supervisor with `f64`.
///
/// ```
/// use friction_core::{CompensatorParams, CompensatorState, LuGreParams, ParameterAdaptiveParams, Setpoint};
/// let servo = CompensatorParams { h: 1e-3, kp: 60.0, ki: 200.0, kd: 1.2,
///     inertia: 0.0023, torque_constant: 1.02, limit: 10.0 };
/// let p = ParameterAdaptiveParams { speed: 0.63, ..ParameterAdaptiveParams::new(LuGreParams::OLSSON_1998, 20.0) };
/// let adaptive = p.build_fixed_step::<f32>(&servo)?;
/// let ctl = servo.build(adaptive)?;
/// let mut s = CompensatorState::default();
/// let tick = ctl.tick(&mut s, 0.0, Setpoint { x: 1e-3, v: 0.1, a: 0.0 });
/// assert!(tick.accepted && tick.command > 0.0);
/// // 1 mrad behind, pushed forward: more forward friction than modelled
/// let [fc_pos, fc_neg, ..] = adaptive.estimates(s.friction());
/// assert!(fc_pos > 0.28 && fc_neg == 0.28);
/// # Ok::<(), friction_core::ParamError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ParameterAdaptiveFixedStep<S, const EXACT: bool = false> {
    per: [ScaledEstimate<S>; PARAMETER_ADAPTIVE_ESTIMATES],
    /// The Coulomb levels' `k γ h` and `k γd`: every estimate's gains are
    /// these times its weight, so the signal is formed once a tick.
    gamma_h: Gain<S>,
    gamma_d: Gain<S>,
    /// `e^-|v/vs|^delta + 1`: the unit curve (`Fc = 1`, `Fs = 2`), for its
    /// fixed-step exponential.
    unit: StribeckCurve<S>,
    /// `rho h` (at most 1), a [`Gain`]: 0.1 1/s at 1 kHz is 6.5 units of
    /// Q16.16's last place.
    leakage_h: Gain<S>,
    /// `k sigma0 h`.
    sigma0_h: Gain<S>,
    /// `sigma1 / (sigma0 h)`.
    damping: Gain<S>,
    observer_gain: Gain<S>,
    dead_zone: S,
    min_speed: S,
    torque_constant: S,
    torque_limit: S,
    signal_limit: S,
    /// `k min(Fc+ low, Fc- low)`: the least `G`.
    level_floor: S,
    /// `k (max(Fc+ high, Fc- high) + Ds high)`: the damping term's clamp.
    cap: S,
    /// `log2(1 / k)`.
    inv_scale_exp: i8,
    scale: f64,
    // no copy of the f64 parameters (152 bytes): the state and gains are
    // what a firmware axis keeps in RAM
    period: f64,
}

impl ParameterAdaptiveParams {
    /// Validates and builds the fixed-step form ([`ParameterAdaptiveFixedStep`])
    /// for a compensator with `servo`'s period, gains and torque constant.
    /// Besides [`build`](Self::build)'s checks, rejects what the scalar
    /// cannot carry: the largest force the boxes allow at the velocity
    /// limit (times 4, for sums), each scaled gain and box; a
    /// `prediction_rate` or `stiffness_rate` other than 0 (the laws that
    /// learn from measured friction are the variable form's) and `exact_step` (the step is the type's: see
    /// [`build_fixed_step_exact`](Self::build_fixed_step_exact)).
    ///
    /// ```
    /// # #[cfg(feature = "fixed")] {
    /// use friction_core::{CompensatorParams, Fixed32, LuGreParams, ParameterAdaptiveParams};
    /// let servo = CompensatorParams { h: 1e-3, kp: 60.0, ki: 200.0, kd: 1.2,
    ///     inertia: 0.0023, torque_constant: 1.02, limit: 10.0 };
    /// let p = ParameterAdaptiveParams::new(LuGreParams::OLSSON_1998, 20.0);
    /// // the variable form needs h within 0.1 %: not in Q16.16 at 1 kHz
    /// assert!(p.build::<Fixed32>(&servo).is_err());
    /// assert!(p.build_fixed_step::<Fixed32>(&servo).is_ok());
    /// # }
    /// ```
    pub fn build_fixed_step<S: Scalar>(
        &self,
        servo: &CompensatorParams,
    ) -> Result<ParameterAdaptiveFixedStep<S>, ParamError> {
        if self.exact_step {
            return Err(ParamError::NotBelow {
                name: "exact_step",
                limit: "true in build_fixed_step (build_fixed_step_exact builds the exact step)",
            });
        }
        self.fixed_step_form(servo)
    }

    /// As [`build_fixed_step`](Self::build_fixed_step), with LuGre's exact
    /// step for the bristle ([`ParameterAdaptiveParams::exact_step`], the
    /// `adaptive` rows of `friction servo`), whatever `exact_step` says: the
    /// step is the type's, so that the implicit step's tick carries no
    /// test of it (a run-time choice made the implicit tick dearer on a
    /// Cortex-M4F, past its budget; both costs are in the cost guide).
    ///
    /// ```
    /// use friction_core::{CompensatorParams, LuGreParams, ParameterAdaptiveParams};
    /// let servo = CompensatorParams { h: 1e-3, kp: 60.0, ki: 200.0, kd: 1.2,
    ///     inertia: 0.0023, torque_constant: 1.02, limit: 10.0 };
    /// let p = ParameterAdaptiveParams { exact_step: true,
    ///     ..ParameterAdaptiveParams::new(LuGreParams::CANUDAS_1995, 20.0) };
    /// assert!(p.build_fixed_step::<f32>(&servo).is_err());
    /// let law = p.build_fixed_step_exact::<f32>(&servo)?;
    /// let mut s = law.initial();
    /// // sliding at a stiff bristle (sigma0 h |v| / g = 3): the elastic
    /// // force settles at -g(v) = -Fc
    /// for _ in 0..100 {
    ///     law.step(&mut s, -0.03, 0.0);
    /// }
    /// assert!((law.elastic_force(&s) + 1.0).abs() < 1e-3);
    /// # Ok::<(), friction_core::ParamError>(())
    /// ```
    pub fn build_fixed_step_exact<S: Scalar>(
        &self,
        servo: &CompensatorParams,
    ) -> Result<ParameterAdaptiveFixedStep<S, true>, ParamError> {
        self.fixed_step_form(servo)
    }

    fn fixed_step_form<S: Scalar, const EXACT: bool>(
        &self,
        servo: &CompensatorParams,
    ) -> Result<ParameterAdaptiveFixedStep<S, EXACT>, ParamError> {
        // the prediction-error law (for listening beside another
        // controller) is the variable form's only
        if self.prediction_rate != 0.0 {
            return Err(ParamError::NotBelow {
                name: "prediction_rate",
                limit: "0 in the fixed-step form",
            });
        }
        // so is the stiffness law, which learns from the same samples
        if self.stiffness_rate != 0.0 {
            return Err(ParamError::NotBelow {
                name: "stiffness_rate",
                limit: "0 in the fixed-step form",
            });
        }
        // the gains and boxes of the variable form, in f64 (which holds h)
        let reference: ParameterAdaptive<f64> = self.build(servo)?;
        let h = servo.h;
        let v_max = S::VELOCITY_LIMIT.to_f64();
        let boxes = self.boxes();
        let level_max = boxes[0].1.max(boxes[1].1) + boxes[2].1;
        let torque_limit = 4.0 * servo.torque_constant * servo.limit;
        let sigma0_h = self.model.sigma0 * h;
        // the bound of the output at the velocity limit, and the elastic
        // increment a full-scale drive makes in one tick
        let largest = (2.0 * level_max + boxes[4].1 * torque_limit + boxes[3].1 * v_max)
            .max(sigma0_h * v_max);
        let k = S::force_scale(largest);
        check_force::<S>("box_factor", k * largest)?;
        let mut per = [ScaledEstimate {
            weight: Gain::new("rate", 0.0)?,
            nominal: S::ZERO,
            low: S::ZERO,
            high: S::ZERO,
        }; PARAMETER_ADAPTIVE_ESTIMATES];
        let [levels, ..] = reference.per;
        for (slot, e) in per.iter_mut().zip(reference.per) {
            let Estimate {
                gamma_h,
                nominal,
                low,
                high,
                ..
            } = e;
            // every estimate's gains are the levels' times 1 / size^2
            let weight = if levels.gamma_h > 0.0 {
                gamma_h / levels.gamma_h
            } else {
                0.0
            };
            *slot = ScaledEstimate {
                weight: Gain::new("speed", weight)?,
                nominal: scaled("fc", k * nominal)?,
                low: scaled("box_factor", k * low)?,
                high: scaled("box_factor", k * high)?,
            };
        }
        let inv_scale_exp = inverse_scale_exp(k);
        Ok(ParameterAdaptiveFixedStep {
            per,
            gamma_h: Gain::new("rate", k * levels.gamma_h)?,
            gamma_d: Gain::new("derivative_weight", k * levels.gamma_d)?,
            unit: StribeckParams {
                fc: 1.0,
                fs: 2.0,
                ..self.model.curve
            }
            .build()?,
            leakage_h: Gain::new("leakage", reference.leakage_h)?,
            sigma0_h: Gain::new("sigma0", k * sigma0_h)?,
            damping: Gain::new("sigma1", self.model.sigma1 / sigma0_h)?,
            observer_gain: Gain::new("observer_gain", self.observer_gain)?,
            dead_zone: threshold("dead_zone", self.dead_zone)?,
            min_speed: threshold("min_speed", self.min_speed)?,
            torque_constant: convert("torque_constant", servo.torque_constant)?,
            torque_limit: convert("limit", torque_limit)?,
            signal_limit: S::from_f64(SIGNAL_LIMIT),
            level_floor: scaled("box_factor", k * boxes[0].0.min(boxes[1].0))?,
            cap: scaled("box_factor", k * level_max)?,
            inv_scale_exp,
            scale: k,
            period: h,
        })
    }
}

/// `x` in the scalar, checked, where 0 is allowed.
fn scaled<S: Scalar>(name: &'static str, x: f64) -> Result<S, ParamError> {
    if x == 0.0 {
        Ok(S::ZERO)
    } else {
        convert(name, x)
    }
}

/// A threshold in the scalar: rounded to the nearest value it holds (a
/// dead zone of one count of a 4096-count encoder, 1.53e-3 rad, is 0.5 %
/// off in Q16.16, where [`convert`] refuses more than 0.1 %; a threshold
/// half a unit of the last place off moves nothing the tests can see),
/// refused only when it overflows or a non-zero value rounds to 0.
fn threshold<S: Scalar>(name: &'static str, x: f64) -> Result<S, ParamError> {
    match S::try_from_f64(x) {
        Ok(s) => Ok(s),
        Err(crate::ScalarConversion::Rounding) => Ok(S::from_f64(x)),
        Err(crate::ScalarConversion::Overflow) => Err(ParamError::NotRepresentable(name)),
        Err(crate::ScalarConversion::Underflow) => Err(ParamError::Underflow(name)),
    }
}

impl<S: Scalar, const EXACT: bool> ParameterAdaptiveFixedStep<S, EXACT> {
    /// The period it was built for (s).
    pub fn period(&self) -> f64 {
        self.period
    }

    /// The power of two `k` the state's forces are carried in (1 in
    /// floating point).
    pub fn force_scale(&self) -> f64 {
        self.scale
    }

    /// `x / k`.
    #[inline]
    fn unscaled(&self, x: S) -> S {
        x.rescale_pow2(self.inv_scale_exp)
    }

    /// A state at rest with the nominal estimates.
    pub fn initial(&self) -> ParameterAdaptiveFixedStepState<S> {
        ParameterAdaptiveFixedStepState {
            estimates: self.per.map(|k| k.nominal),
            started: Flag::new(true),
            ..Default::default()
        }
    }

    #[inline]
    fn start(&self, state: &mut ParameterAdaptiveFixedStepState<S>) {
        if !state.started.get() {
            state.estimates = self.per.map(|k| k.nominal);
            state.started = Flag::new(true);
        }
    }

    /// The estimates `[Fc+, Fc-, Fs - Fc, sigma2, mu]` of `state` (a
    /// `Default` state reads 0 until its first step).
    pub fn estimates(
        &self,
        state: &ParameterAdaptiveFixedStepState<S>,
    ) -> [S; PARAMETER_ADAPTIVE_ESTIMATES] {
        state.estimates.map(|x| self.unscaled(x))
    }

    /// The elastic force `sigma0 z` of `state`.
    pub fn elastic_force(&self, state: &ParameterAdaptiveFixedStepState<S>) -> S {
        self.unscaled(state.w)
    }

    /// Sets the estimates of `state` (e.g. restored after a power cycle),
    /// each projected onto its box; a non-finite value leaves that estimate
    /// as it is.
    pub fn set_estimates(
        &self,
        state: &mut ParameterAdaptiveFixedStepState<S>,
        values: [f64; PARAMETER_ADAPTIVE_ESTIMATES],
    ) {
        self.start(state);
        for ((x, v), k) in state.estimates.iter_mut().zip(values).zip(&self.per) {
            if v.is_finite() {
                *x = S::from_f64(v * self.scale).max(k.low).min(k.high);
            }
        }
    }

    /// Sets the external torque `τ_ext` the transmission carries besides
    /// the motor's; a non-finite value is ignored.
    pub fn set_external_torque(&self, state: &mut ParameterAdaptiveFixedStepState<S>, torque: S) {
        if torque.is_finite() {
            state.external = torque.sat(self.torque_limit);
        }
    }

    /// The largest `|F^|` at speed `v` the boxes allow (as
    /// [`ParameterAdaptive::bound`]).
    pub fn bound(&self, v: S) -> S {
        let high = |i: usize| self.per.get(i).map_or(S::ZERO, |k| self.unscaled(k.high));
        let level = high(0).max(high(1)) + high(2);
        level + level + high(4) * self.torque_limit + high(3) * v.abs()
    }

    /// `s(v) = exp(-|v / vs|^delta)`, in `[0, 1]`: the unit curve (within
    /// `[1, 2]`) less 1.
    #[inline]
    fn shape(&self, v: S) -> S {
        self.unit.eval_fast(v) - S::ONE
    }

    /// One period with measured velocity `v` and position error `e`;
    /// returns `F^`. A non-finite input leaves the state untouched and
    /// returns the force the state holds.
    // always inlined on a hard-float ARM target: a call from the servo tick
    // saves and restores the FPU's callee-saved registers, which counts in
    // a budgeted tick; on a Cortex-M0 the inlined step spills registers
    // and costs more than the call (see the cost guide)
    #[cfg_attr(target_abi = "eabihf", inline(always))]
    #[cfg_attr(not(target_abi = "eabihf"), inline)]
    pub fn step(&self, state: &mut ParameterAdaptiveFixedStepState<S>, v: S, e: S) -> S {
        self.start(state);
        if !(v.is_finite() && e.is_finite()) {
            return self.force(state, S::ZERO, S::ZERO);
        }
        let v = v.sat(S::VELOCITY_LIMIT);
        let e = e.sat(S::VELOCITY_LIMIT);
        let [fc_pos, fc_neg, excess, _, load_coefficient] = state.estimates;
        let s = self.shape(v);
        let level = if state.w >= S::ZERO { fc_pos } else { fc_neg };
        let g = (level + excess * s + load_coefficient * state.torque.abs()).max(self.level_floor);
        let drive = (v - self.observer_gain.times(e).sat(S::VELOCITY_LIMIT)).sat(S::VELOCITY_LIMIT);
        let (dw, zeta) = if EXACT {
            self.exact(state, v, drive, g)
        } else {
            self.implicit(state, v, drive, g)
        };
        let de = if state.primed.get() {
            (e - state.last_error).sat(self.signal_limit)
        } else {
            S::ZERO
        };
        state.last_error = e;
        state.primed = Flag::new(true);
        let adapting = e.abs() > self.dead_zone && v.abs() >= self.min_speed;
        if adapting || !self.leakage_h.is_zero() {
            let limit = self.signal_limit;
            // the levels' signal; each estimate's is it times its weight
            let signal = if adapting {
                (self.gamma_h.times(e).sat(limit) + self.gamma_d.times(de).sat(limit)).sat(limit)
            } else {
                S::ZERO
            };
            // the unrolled update for the M0's worst tick; not on a
            // hard-float ARM target, where the tick is inlined into the C
            // ABI's dispatch and the unrolled form made every kind's tick
            // there dearer, past the ABI's budget (the cost guide)
            if !cfg!(target_abi = "eabihf") && self.leakage_h.is_zero() {
                self.adapt(state, signal, zeta, s, v);
                return self.force(state, v, dw);
            }
            let phi = [
                zeta.max(S::ZERO),
                zeta.min(S::ZERO),
                s * zeta,
                v,
                state.torque.abs() * zeta,
            ];
            for ((x, p), k) in state.estimates.iter_mut().zip(phi).zip(&self.per) {
                let mut next = *x - k.weight.times(signal) * p;
                if !self.leakage_h.is_zero() {
                    next = next - self.leakage_h.times(next - k.nominal);
                }
                *x = next.max(k.low).min(k.high);
            }
        }
        self.force(state, v, dw)
    }

    /// The adaptation without leakage, unrolled: `x_i -= w_i signal phi_i`
    /// with the levels' and the excess' weights 1 (their regressor size is
    /// 1, see `ParameterAdaptiveParams::build`), so only the viscous and load
    /// estimates multiply by theirs, and only the level on `ζ`'s side moves
    /// (the other's regressor is 0, and an estimate is always within its
    /// box). The levels and the viscous estimate get the same values as the
    /// general loop; the excess and load products are reassociated around
    /// `signal ζ` (`(σ ζ) s` for `σ (s ζ)`, `w (σ ζ |τ|)` for `(w σ)(|τ| ζ)`:
    /// the same in exact arithmetic, a rounding apart in each scalar, with the
    /// load's weight applied after, not before, a saturation). Six products
    /// fewer than the loop.
    #[inline(always)]
    fn adapt(
        &self,
        state: &mut ParameterAdaptiveFixedStepState<S>,
        signal: S,
        zeta: S,
        s: S,
        v: S,
    ) {
        let [k0, k1, k2, k3, k4] = &self.per;
        let level = signal * zeta;
        let load = k4.weight.times(level * state.torque.abs());
        let [x0, x1, x2, x3, x4] = &mut state.estimates;
        if zeta > S::ZERO {
            *x0 = (*x0 - level).max(k0.low).min(k0.high);
        } else if zeta < S::ZERO {
            *x1 = (*x1 - level).max(k1.low).min(k1.high);
        }
        *x2 = (*x2 - level * s).max(k2.low).min(k2.high);
        *x3 = (*x3 - k3.weight.times(signal) * v).max(k3.low).min(k3.high);
        *x4 = (*x4 - load).max(k4.low).min(k4.high);
    }

    /// The implicit step: `W` to `ζ G`, with `ζ = clamp(ζ', -1, 1)`;
    /// returns `W' - W` (the damping term's `sigma0 h dz/dt`) and `ζ`.
    #[inline(always)]
    fn implicit(
        &self,
        state: &mut ParameterAdaptiveFixedStepState<S>,
        v: S,
        drive: S,
        g: S,
    ) -> (S, S) {
        // W' = (W + k sigma0 h drive) / (1 + k sigma0 h |v| / G), and ζ = W' / G,
        // with one quotient: ζ' = (W + k sigma0 h drive) / (G + k sigma0 h |v|)
        // (a Q16.16 quotient is a long division on a Cortex-M0)
        let ratio = (state.w + self.sigma0_h.times(drive)) / (g + self.sigma0_h.times(v.abs()));
        let zeta = ratio.min(S::ONE).max(-S::ONE);
        let w = ratio * g;
        let dw = w - state.w;
        // ζ G: W' itself within the bristle's bound, else ±G (one product
        // fewer: a Q16.16 product is several 32-bit ones on a Cortex-M0)
        state.w = if ratio == zeta {
            w
        } else if ratio > S::ZERO {
            g
        } else {
            -g
        };
        (dw, zeta)
    }

    /// The exact step ([`ParameterAdaptiveParams::exact_step`]; the
    /// equations are the type's) with the level `g`; returns
    /// `k sigma0 h dz/dt` at the end of the step (0 while held at the
    /// bound) and `ζ`.
    #[inline(always)]
    fn exact(
        &self,
        state: &mut ParameterAdaptiveFixedStepState<S>,
        v: S,
        drive: S,
        g: S,
    ) -> (S, S) {
        // the levels at rest (s(0) = 1) of each side
        let [fc_pos, fc_neg, excess, _, load_coefficient] = state.estimates;
        let common = excess + load_coefficient * state.torque.abs();
        let rest_on =
            |forward: bool| (if forward { fc_pos } else { fc_neg } + common).max(self.level_floor);
        let rest = rest_on(state.w >= S::ZERO);
        let p = self.sigma0_h.times(v.abs());
        let push = self.sigma0_h.times(drive);
        // two quotients of scaled forces, not products with 1/g: in Q16.16
        // a product with an unscaled 1/g saturates at 32768 / k, which cut
        // a stiff bristle's x (and W / G) short
        let x = p / g;
        // 1 - e^-x and (1 - e^-x) / x (a series below x = 0.1)
        let (one_minus_e, phi) = if x < S::from_f64(0.1) {
            let phi = phi_series_inlined(x);
            (x * phi, phi)
        } else {
            let one_minus_e = S::ONE - x.exp_neg();
            (one_minus_e, one_minus_e / x)
        };
        let w0 = state.w;
        // W e^-x + W_eq (1 - e^-x), with W_eq (1 - e^-x) = P (1 - e^-x) / x
        // and the equilibrium within 2 G0 beyond x = 1
        let mut inflow = push.mul_fraction(phi);
        if x > S::ONE {
            inflow = inflow.sat((rest + rest).mul_fraction(one_minus_e));
        }
        let free = w0 - w0.mul_fraction(one_minus_e) + inflow;
        // within the level at rest of the side W ends on (where the levels
        // differ by direction, the side it started on would let it past its
        // own level by their difference for a step)
        let rest = rest_on(free >= S::ZERO);
        let w = free.sat(rest);
        state.w = w;
        // W / G = z / r, within the levels' ratio, which the boxes may make
        // large: bounded, as the variable form's
        let ratio = (w / g).sat(S::VELOCITY_LIMIT);
        let mut rate = push - p * ratio;
        let outward = (rate > S::ZERO && w > S::ZERO) || (rate < S::ZERO && w < S::ZERO);
        if w.abs() >= rest && outward {
            rate = S::ZERO;
        }
        (rate, ratio.min(S::ONE).max(-S::ONE))
    }

    /// `F^ = (W + sigma1 / (sigma0 h) dW + k sigma2^ v) / k`.
    #[inline]
    fn force(&self, state: &ParameterAdaptiveFixedStepState<S>, v: S, dw: S) -> S {
        let damping = self.damping.times(dw).sat(self.cap);
        let viscous = state.estimates[3] * v;
        self.unscaled(state.w + damping + viscous)
    }
}

impl<S: Scalar, const EXACT: bool> Compensation<S> for ParameterAdaptiveFixedStep<S, EXACT> {
    type State = ParameterAdaptiveFixedStepState<S>;
    const USES_H: bool = false;
    #[cfg_attr(target_abi = "eabihf", inline(always))]
    #[cfg_attr(not(target_abi = "eabihf"), inline)]
    fn estimate(&self, state: &mut Self::State, v: S, e: S, _h: S) -> S {
        self.step(state, v, e)
    }
    fn period(&self) -> Option<f64> {
        Some(self.period)
    }
    fn set_external_torque(&self, state: &mut Self::State, torque: S) {
        ParameterAdaptiveFixedStep::set_external_torque(self, state, torque);
    }
    #[inline]
    fn commanded(&self, state: &mut Self::State, command: S) {
        state.torque = (self.torque_constant * command - state.external).sat(self.torque_limit);
    }

    /// As [`crate::ParameterAdaptive`]'s: the estimates
    /// restart at this law's nominal values; the elastic force `w` is kept
    /// (rescaled to this law's force scale) within the nominal `max(Fc+,
    /// Fc-) + Ds + mu |τ|`; the last error and the torques are kept.
    fn carry_over(&self, old: &Self, state: &mut Self::State) {
        let torque = state.torque.sat(self.torque_limit);
        let fresh = self.initial();
        let [fc_pos, fc_neg, excess, _, load] = fresh.estimates;
        let level = fc_pos.max(fc_neg) + excess + load * torque.abs();
        let ratio = scale_ratio(old.inv_scale_exp, self.inv_scale_exp);
        *state = ParameterAdaptiveFixedStepState {
            w: carried(state.w, ratio, level),
            torque,
            external: state.external.sat(self.torque_limit),
            last_error: state.last_error,
            primed: state.primed,
            ..fresh
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_servo::olsson_servo as servo;
    use crate::{
        Compensator, CompensatorState, CoulombViscousParams, FrictionModel, LuGreParams,
        LuGreState, Setpoint, SupervisorMode, SupervisorParams,
    };
    use std::vec::Vec;

    /// The `adaptive+50` row's law: Olsson's model with its levels 1.5x
    /// the plant's, the host's defaults (rate 16 1/s, speed the reference's
    /// peak 0.63 rad/s), with the implicit or the exact step.
    fn law(factor: f64, exact_step: bool) -> ParameterAdaptiveParams {
        let mut nominal = LuGreParams::OLSSON_1998;
        nominal.curve.fc *= factor;
        nominal.curve.fs *= factor;
        ParameterAdaptiveParams {
            speed: 0.63,
            rate: 16.0,
            load_max: 0.05,
            exact_step,
            ..ParameterAdaptiveParams::new(nominal, 20.0)
        }
    }

    /// One run's trace: the true position each tick, the final estimates
    /// and the supervisor's mode each second.
    struct Trace {
        x: Vec<f64>,
        estimates: [f64; PARAMETER_ADAPTIVE_ESTIMATES],
        modes: Vec<SupervisorMode>,
    }

    type Supervised<S, const EXACT: bool> =
        crate::Supervised<ParameterAdaptiveFixedStep<S, EXACT>, crate::CoulombViscous<S>, S>;

    fn supervised<S: Scalar, const EXACT: bool>(
        factor: f64,
    ) -> Compensator<S, Supervised<S, EXACT>> {
        let fallback = CoulombViscousParams {
            fc: 0.28 * factor,
            sigma2: 0.0176,
        }
        .build::<S>()
        .unwrap();
        let p = SupervisorParams {
            tolerance: 0.01 * 0.28,
            ..SupervisorParams::DEFAULT
        };
        let adaptive = law(factor, EXACT)
            .fixed_step_form::<S, EXACT>(&servo())
            .unwrap();
        servo()
            .build(p.build(adaptive, fallback, &servo()).unwrap())
            .unwrap()
    }

    /// The Olsson plant (the core's LuGre in f64 at 100 kHz, Coulomb level
    /// `1 + asymmetry` times forward, `1 - asymmetry` backward) under
    /// `tick`, on `0.5 sin(2 pi 0.2 t)` rad; `tick` returns the command.
    fn olsson_run(
        seconds: usize,
        asymmetry: f64,
        mut tick: impl FnMut(f64, Setpoint<f64>) -> f64,
        mut each_second: impl FnMut(),
    ) -> Vec<f64> {
        let plant = LuGreParams::OLSSON_1998.build::<f64>().unwrap();
        let mut ps = LuGreState::default();
        let (mut x, mut v) = (0.0f64, 0.0f64);
        let w = 2.0 * core::f64::consts::PI * 0.2;
        let mut xs = Vec::with_capacity(seconds * 1000);
        for k in 0..seconds * 1000 {
            let t = k as f64 * 1e-3;
            let r = Setpoint {
                x: 0.5 * libm::sin(w * t),
                v: 0.5 * w * libm::cos(w * t),
                a: -0.5 * w * w * libm::sin(w * t),
            };
            let u = tick(x, r);
            for _ in 0..100 {
                let f = plant.step(&mut ps, v, 1e-5);
                let f = f * if v >= 0.0 {
                    1.0 + asymmetry
                } else {
                    1.0 - asymmetry
                };
                v += 1e-5 * (1.02 * u - f) / 0.0023;
                x += 1e-5 * v;
            }
            xs.push(x - r.x);
            if k % 1000 == 999 {
                each_second();
            }
        }
        xs
    }

    fn supervised_run<S: Scalar, const EXACT: bool>(factor: f64, seconds: usize) -> Trace {
        let ctl = supervised::<S, EXACT>(factor);
        let state = core::cell::RefCell::new(CompensatorState::default());
        let mut modes = Vec::new();
        let x = olsson_run(
            seconds,
            0.0,
            |x, r| {
                let r = Setpoint {
                    x: S::from_f64(r.x),
                    v: S::from_f64(r.v),
                    a: S::from_f64(r.a),
                };
                ctl.tick(&mut state.borrow_mut(), S::from_f64(x), r)
                    .command
                    .to_f64()
            },
            || modes.push(ctl.compensation().status(state.borrow().friction()).mode),
        );
        let s = state.borrow();
        let estimates = ctl
            .compensation()
            .primary()
            .estimates(&s.friction().primary)
            .map(|e| e.to_f64());
        Trace {
            x,
            estimates,
            modes,
        }
    }

    fn rms(x: &[f64]) -> f64 {
        libm::sqrt(x.iter().map(|e| e * e).sum::<f64>() / x.len() as f64)
    }

    /// Either step, on the Olsson servo (the exact step's series and
    /// exponential; its `x > 1`, which this servo's soft bristle does not
    /// reach, is compared at a stiff one in the module's tests).
    #[test]
    fn in_f64_the_fixed_step_form_is_the_variable_form() {
        for factor in [1.5, 0.5] {
            is_the_variable_form::<false>(factor);
            is_the_variable_form::<true>(factor);
        }
    }

    fn is_the_variable_form<const EXACT: bool>(factor: f64) {
        let exact = EXACT;
        {
            let p = law(factor, exact);
            let at = servo()
                .build(p.fixed_step_form::<f64, EXACT>(&servo()).unwrap())
                .unwrap();
            let var = servo().build(p.build::<f64>(&servo()).unwrap()).unwrap();
            let (mut sa, mut sv) = (CompensatorState::default(), CompensatorState::default());
            let mut worst = 0.0f64;
            let x = olsson_run(
                20,
                0.0,
                |x, r| {
                    // the same position into both: compare the commands
                    let c = var.tick(&mut sv, x, r).command;
                    worst = worst.max((c - at.tick(&mut sa, x, r).command).abs());
                    c
                },
                || {},
            );
            assert!(
                worst < 1e-9,
                "{factor} {exact}: commands differ by {worst:e}"
            );
            let (ea, ev) = (
                at.compensation().estimates(sa.friction()),
                sv.friction().estimates(),
            );
            for (a, v) in ea.iter().zip(ev) {
                assert!((a - v).abs() < 1e-9, "{ea:?} {ev:?}");
            }
            // the estimates moved (a run the comparison could fail)
            assert!((ea[0] - 0.28 * factor).abs() > 0.05, "{ea:?}");
            assert!(rms(&x) < 1e-3, "{}", rms(&x));
        }
    }

    /// f32 and Q16.16 against f64 on the supervised servo run from levels
    /// 1.5x and 0.5x the plant's: the RMS tracking error over the last half
    /// within 2 % of f64's (measured: f32 within 1e-6, Q16.16 within 0.2 %),
    /// the final Coulomb estimates within 2 % of the plant's level of f64's
    /// (measured: f32 2e-6, Q16.16 1.2 %) and the same mode every second;
    /// with either step (the figures are the implicit step's; the exact
    /// step's are as close: rms within 0.19 %, estimates within 0.8 %).
    #[test]
    fn f32_and_fixed_point_runs_agree_with_f64() {
        for factor in [1.5, 0.5] {
            agree_with_f64::<false>(factor);
            agree_with_f64::<true>(factor);
        }
    }

    fn agree_with_f64<const EXACT: bool>(factor: f64) {
        let exact = EXACT;
        {
            let reference = supervised_run::<f64, EXACT>(factor, 20);
            let half = reference.x.len() / 2;
            let want = rms(&reference.x[half..]);
            #[cfg_attr(not(feature = "fixed"), allow(unused_mut))]
            let mut runs = std::vec![("f32", supervised_run::<f32, EXACT>(factor, 20))];
            #[cfg(feature = "fixed")]
            runs.push((
                "Q16.16",
                supervised_run::<crate::Fixed32, EXACT>(factor, 20),
            ));
            for (name, run) in runs {
                let got = rms(&run.x[half..]);
                assert!(
                    (got - want).abs() <= 0.02 * want,
                    "{name} {factor} {exact}: {got:e} vs {want:e}"
                );
                for i in 0..2 {
                    let d = (run.estimates[i] - reference.estimates[i]).abs();
                    assert!(
                        d <= 0.02 * 0.28,
                        "{name} {factor} {exact}: {:?} vs {:?}",
                        run.estimates,
                        reference.estimates
                    );
                }
                assert_eq!(run.modes, reference.modes, "{name} {factor} {exact}");
            }
        }
    }

    /// 1e6 random ticks of finite inputs of every size (velocity, error,
    /// command, external torque): every estimate in its box, the output
    /// finite and within [`ParameterAdaptiveFixedStep::bound`]; NaN and infinite
    /// inputs (floats) leave the state untouched.
    fn bounds_hold<S: Scalar, const EXACT: bool>(max: f64, ticks: usize) {
        // with leakage the general update, without it the unrolled one
        for leakage in [0.1, 0.0] {
            bounds_hold_with::<S, EXACT>(max, ticks, leakage);
        }
    }

    fn bounds_hold_with<S: Scalar, const EXACT: bool>(max: f64, ticks: usize, leakage: f64) {
        let p = ParameterAdaptiveParams {
            leakage,
            dead_zone: 1e-3,
            ..law(1.5, EXACT)
        };
        let a = p.fixed_step_form::<S, EXACT>(&servo()).unwrap();
        // the last place of an unscaled estimate (0 in floating point)
        let ulp = if S::SCALES_FORCES { 2.0 / 65536.0 } else { 0.0 };
        let boxes = p.boxes();
        let mut s = ParameterAdaptiveFixedStepState::default();
        let mut pick = crate::test_rng::hostile(11, max);
        for k in 0..ticks {
            let (v, e, u) = (pick(), pick(), pick());
            if k % 97 == 0 {
                a.set_external_torque(&mut s, S::from_f64(pick()));
            }
            let v = S::from_f64(v);
            let f = a.step(&mut s, v, S::from_f64(e));
            a.commanded(&mut s, S::from_f64(u));
            let bound = a.bound(v).to_f64();
            assert!(
                f.is_finite() && f.to_f64().abs() <= bound * 1.0001 + ulp,
                "{k}: {f:?} {v:?} {e}"
            );
            assert!(a.elastic_force(&s).is_finite());
            for (x, (lo, hi)) in a.estimates(&s).iter().zip(boxes) {
                let x = x.to_f64();
                assert!(
                    x.is_finite() && x >= lo * 0.9999 - ulp && x <= hi * 1.0001 + ulp,
                    "{k}: {x} not in [{lo}, {hi}]"
                );
            }
        }
        if !S::ALWAYS_FINITE {
            let before = s;
            for (v, e) in [
                (f64::NAN, 0.0),
                (0.0, f64::INFINITY),
                (f64::NEG_INFINITY, 1.0),
            ] {
                let f = a.step(&mut s, S::from_f64(v), S::from_f64(e));
                assert!(f.is_finite());
                assert_eq!(s, before);
            }
        }
    }

    /// The supervised servo under hostile finite positions and setpoints:
    /// the command finite and within the limit, the estimates in their
    /// boxes, the mode one of the three.
    fn supervised_bounds_hold<S: Scalar, const EXACT: bool>(max: f64, ticks: usize) {
        let ctl = supervised::<S, EXACT>(1.5);
        let boxes = law(1.5, EXACT).boxes();
        let ulp = if S::SCALES_FORCES { 2.0 / 65536.0 } else { 0.0 };
        let limit = servo().limit;
        let mut s = CompensatorState::default();
        let mut pick = crate::test_rng::hostile(12, max);
        for k in 0..ticks {
            let r = Setpoint {
                x: S::from_f64(pick()),
                v: S::from_f64(pick()),
                a: S::from_f64(pick()),
            };
            let t = ctl.tick(&mut s, S::from_f64(pick()), r);
            assert!(
                t.command.is_finite() && t.command.to_f64().abs() <= limit,
                "{k}"
            );
            assert!(t.friction.is_finite(), "{k}");
            let status = ctl.compensation().status(s.friction());
            assert!(
                status.errors.iter().all(|e| e.is_finite()),
                "{k}: {status:?}"
            );
            let primary = ctl.compensation().primary();
            for (x, (lo, hi)) in primary.estimates(&s.friction().primary).iter().zip(boxes) {
                let x = x.to_f64();
                assert!(x >= lo * 0.9999 - ulp && x <= hi * 1.0001 + ulp, "{k}: {x}");
            }
        }
    }

    #[test]
    fn hostile_finite_inputs_keep_the_bounds_in_f32() {
        bounds_hold::<f32, false>(f64::from(f32::MAX), 1_000_000);
        bounds_hold::<f32, true>(f64::from(f32::MAX), 1_000_000);
        supervised_bounds_hold::<f32, false>(f64::from(f32::MAX), 200_000);
        supervised_bounds_hold::<f32, true>(f64::from(f32::MAX), 200_000);
    }

    #[test]
    fn hostile_finite_inputs_keep_the_bounds_in_f64() {
        bounds_hold::<f64, false>(f64::MAX, 1_000_000);
        bounds_hold::<f64, true>(f64::MAX, 1_000_000);
        supervised_bounds_hold::<f64, false>(f64::MAX, 200_000);
        supervised_bounds_hold::<f64, true>(f64::MAX, 200_000);
    }

    #[cfg(feature = "fixed")]
    #[test]
    fn hostile_finite_inputs_keep_the_bounds_in_fixed_point() {
        let max = crate::Fixed32::MAX.to_f64();
        bounds_hold::<crate::Fixed32, false>(max, 1_000_000);
        bounds_hold::<crate::Fixed32, true>(max, 1_000_000);
        supervised_bounds_hold::<crate::Fixed32, false>(max, 200_000);
        supervised_bounds_hold::<crate::Fixed32, true>(max, 200_000);
    }

    #[test]
    fn scaled_settings_that_do_not_fit_are_named() {
        // the prediction-error law is the variable form's only
        assert_eq!(
            ParameterAdaptiveParams {
                prediction_rate: 1.0,
                ..law(1.0, false)
            }
            .build_fixed_step::<f32>(&servo())
            .err(),
            Some(ParamError::NotBelow {
                name: "prediction_rate",
                limit: "0 in the fixed-step form",
            })
        );
        // the exact step has its own builder
        assert_eq!(
            ParameterAdaptiveParams {
                exact_step: true,
                ..law(1.0, false)
            }
            .build_fixed_step::<f32>(&servo())
            .err(),
            Some(ParamError::NotBelow {
                name: "exact_step",
                limit: "true in build_fixed_step (build_fixed_step_exact builds the exact step)",
            })
        );
        // the variable form's checks come before the scalar's
        assert_eq!(
            ParameterAdaptiveParams {
                rate: -1.0,
                ..law(1.0, false)
            }
            .build_fixed_step::<f32>(&servo())
            .err(),
            Some(ParamError::Negative("rate"))
        );
        #[cfg(feature = "fixed")]
        {
            // a stiffness whose one-tick elastic increment at the velocity
            // limit does not fit Q16.16
            let mut p = law(1.0, false);
            p.model.sigma0 = 1e8;
            assert!(p.build_fixed_step::<crate::Fixed32>(&servo()).is_err());
            assert!(p.build_fixed_step::<f32>(&servo()).is_ok());
        }
    }
}
