//! Per-parameter adaptive friction compensation: a LuGre observer whose
//! friction levels are estimated one by one, each in its own box (after
//! Canudas de Wit & Lischinsky 1997, Int. J. Adapt. Control Signal Process.
//! 11(1); Panteley, Ortega & Gäfvert 1998, Syst. Control Lett. 33(5);
//! robust modifications from Ioannou & Sun 1996, Robust Adaptive Control,
//! Ch. 8: projection, dead zone, leakage).
//!
//! The θ-adaptive observer ([`crate::AdaptiveObserver`]) scales the whole
//! model: a model whose Coulomb level alone is off is no scaled copy of the
//! plant, and the error in the Stribeck shape stays. Here the observer is
//! LuGre's, with the levels of its curve estimated: the steady friction is
//! linear in them, with the normalized bristle `ζ = sigma0 z / g(v)`
//! (`|ζ| <= 1`, `ζ = sign v` in steady sliding) as their regressor:
//!
//! ```text
//! g^(v)   = Fc±^ + Ds^ s(v) + mu^ |τ|,  s(v) = exp(-|v / vs|^delta),  Fc+^ for z >= 0, Fc-^ below
//! dz/dt   = v - k e - sigma0 |v| z / g^(v)                     LuGre observer (gain k)
//! ζ       = sigma0 z / g^(v), within [-1, 1]                    the normalized bristle
//! F^      = sigma0 z + sigma1 dz/dt + sigma2^ v
//! φ       = [max(ζ, 0), min(ζ, 0), s(v) ζ, v, |τ| ζ]            regressors of
//! θ^      = [Fc+^, Fc-^, Ds^, sigma2^, mu^]                     the estimates
//! dθ^/dt  = -Γ φ (γ e + γd de/dt) - rho (θ^ - θ0)              per estimate, then
//! θ^      = clamp(θ^, box)                                      projection
//! ```
//!
//! In steady sliding `sigma0 z = g^(v) ζ` with `ζ = sign v`, so `φ` is the
//! sensitivity of the steady friction to each estimate; the elastic force
//! follows a change of the estimates within the bristle's lag
//! `g / (sigma0 |v|)`.
//!
//! `τ` is the torque the transmission carries: the compensator's own last
//! command times `kc`, less an external torque the user may set
//! ([`ParameterAdaptive::set_external_torque`]). The adaptation signal is the
//! θ law's (`γ = a kc kp`, `γd = w γ kd / kp`, the composite error of the
//! loop's PD part), scaled per estimate by its regressor's size: 1 for the
//! levels, the reference speed for `sigma2`, the reference torque for `mu`.
//!
//! A second law, off by default, learns from the friction the compensator
//! measures instead of the tracking error ([`ParameterAdaptive::learn`]):
//! the estimates' prediction `φᵀ θ^` of each measured sample against the
//! sample (a gradient on the prediction error, as in composite adaptation,
//! Slotine & Li 1989). It is the one that learns where this compensation
//! is not in the loop: beside another controller, or on a logged run
//! replayed through [`Compensator::listen`](crate::Compensator::listen).
//!
//! Robust modifications, all optional:
//! - **dead zone**: no adaptation while `|e|` is within `dead_zone` (one or
//!   two encoder counts: a quantized error that small carries no
//!   information about the friction);
//! - **leakage** `rho` toward the nominal values;
//! - **excitation**: no adaptation while `|v|` is below `min_speed`;
//! - **projection** onto each estimate's box (`[θ0 / box, θ0 box]` for the
//!   Coulomb levels, `[0, box max(Ds0, Fc0)]` for the Stribeck excess, `[0,
//!   max(box sigma2_0, Fs0 / speed)]` for the viscous coefficient,
//!   `[0, load_max]` for the load coefficient).
//!
//! Bounds, for any finite inputs: every estimate stays in its box, `|ζ| <= 1`,
//! and the output is finite and within the largest friction the boxes allow
//! at that speed (see [`ParameterAdaptive::bound`]). A NaN or infinite input
//! leaves the state untouched.
//!
//! The fixed-step form for every scalar, Q16.16 included, is [`at`]
//! ([`ParameterAdaptiveParams::build_at`]).

use crate::bits::Flag;
use crate::compensator::{Compensation, CompensatorParams, FrictionSample};
use crate::fixed_step::carried;
use crate::model::{convert, non_negative, positive, ParamError};
use crate::models::lugre::LuGreParams;
use crate::Scalar;

pub mod at;
pub use at::{ParameterAdaptiveAt, ParameterAdaptiveAtState};

/// The number of estimates: `Fc+`, `Fc-`, `Ds`, `sigma2`, `mu`.
pub const ESTIMATES: usize = 5;

/// Design-time parameters of the per-parameter adaptation, in `f64`.
///
/// ```
/// use friction_core::{CompensatorParams, LuGreParams, ParameterAdaptiveParams};
/// let servo = CompensatorParams { h: 1e-3, kp: 60.0, ki: 200.0, kd: 1.2,
///     inertia: 0.0023, torque_constant: 1.02, limit: 10.0 };
/// let p = ParameterAdaptiveParams::new(LuGreParams::OLSSON_1998, 20.0);
/// let adaptive = p.build::<f32>(&servo)?;
/// # let _ = adaptive;
/// # Ok::<(), friction_core::ParamError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ParameterAdaptiveParams {
    /// The nominal model: its `fc` (both directions), `fs - fc` and `sigma2`
    /// start the estimates and are the leakage targets; `vs`, the exponent,
    /// `sigma0` and `sigma1` are used as they are. `vd` is ignored.
    pub model: LuGreParams,
    /// Observer gain `k >= 0` (1/s).
    pub observer_gain: f64,
    /// Adaptation rate `a >= 0` (1/s): `γ = a kc kp`.
    pub rate: f64,
    /// Weight `w >= 0` of the error's rate: `γd = w γ kd / kp`.
    pub derivative_weight: f64,
    /// Leakage `rho >= 0` (1/s) toward the nominal values.
    pub leakage: f64,
    /// Box factor `>= 1` of the projection (see the [module docs](self)).
    pub box_factor: f64,
    /// Dead zone `>= 0` on `|e|` (position units).
    pub dead_zone: f64,
    /// Adaptation only while `|v| >= min_speed >= 0`.
    pub min_speed: f64,
    /// Reference speed `> 0` of the viscous estimate (e.g. the peak speed).
    pub speed: f64,
    /// Nominal load coefficient `mu0 >= 0` (friction per unit of
    /// transmitted torque).
    pub load: f64,
    /// Upper bound `load_max >= mu0` of the load coefficient (0: no load term).
    pub load_max: f64,
    /// Rate `>= 0` (1/s) of the prediction-error law (0: off), which
    /// learns from the friction the compensator measures (see the
    /// [module docs](self)); `prediction_rate h <= 1`.
    pub prediction_rate: f64,
}

impl ParameterAdaptiveParams {
    /// Defaults around `model` with observer gain `k`: rate 4 1/s, `w = 1`,
    /// no leakage, box factor 5, no dead zone, no speed threshold,
    /// reference speed 1, no load term, no prediction-error law.
    pub const fn new(model: LuGreParams, observer_gain: f64) -> Self {
        Self {
            model,
            observer_gain,
            rate: 4.0,
            derivative_weight: 1.0,
            leakage: 0.0,
            box_factor: 5.0,
            dead_zone: 0.0,
            min_speed: 0.0,
            speed: 1.0,
            load: 0.0,
            load_max: 0.0,
            prediction_rate: 0.0,
        }
    }

    /// Checks the model and every setting; the error names the parameter.
    pub fn validate(&self) -> Result<(), ParamError> {
        self.model.validate()?;
        non_negative("observer_gain", self.observer_gain)?;
        non_negative("rate", self.rate)?;
        non_negative("derivative_weight", self.derivative_weight)?;
        non_negative("leakage", self.leakage)?;
        positive("box_factor", self.box_factor)?;
        if self.box_factor < 1.0 {
            return Err(ParamError::BelowOne("box_factor"));
        }
        non_negative("dead_zone", self.dead_zone)?;
        non_negative("min_speed", self.min_speed)?;
        positive("speed", self.speed)?;
        non_negative("load", self.load)?;
        non_negative("load_max", self.load_max)?;
        non_negative("prediction_rate", self.prediction_rate)?;
        if self.load > self.load_max {
            return Err(ParamError::NotBelow {
                name: "load",
                limit: "load_max",
            });
        }
        Ok(())
    }

    /// The nominal estimates `[Fc, Fc, Fs - Fc, sigma2, mu0]`.
    pub fn nominal(&self) -> [f64; ESTIMATES] {
        let c = &self.model.curve;
        [c.fc, c.fc, c.fs - c.fc, self.model.sigma2, self.load]
    }

    /// The projection boxes `(low, high)` of the estimates.
    pub fn boxes(&self) -> [(f64, f64); ESTIMATES] {
        let b = self.box_factor;
        let c = &self.model.curve;
        let excess = c.fs - c.fc;
        [
            (c.fc / b, c.fc * b),
            (c.fc / b, c.fc * b),
            (0.0, b * excess.max(c.fc)),
            (0.0, (b * self.model.sigma2).max(c.fs / self.speed)),
            (0.0, self.load_max),
        ]
    }

    /// Validates and builds the compensation for a compensator with
    /// `servo`'s period, gains and torque constant.
    pub fn build<S: Scalar>(
        &self,
        servo: &CompensatorParams,
    ) -> Result<ParameterAdaptive<S>, ParamError> {
        self.validate()?;
        servo.validate()?;
        let h = servo.h;
        let gamma = self.rate * servo.torque_constant * servo.kp;
        let gamma_d = if servo.kp > 0.0 {
            self.derivative_weight * gamma * servo.kd / servo.kp
        } else {
            0.0
        };
        // the regressor sizes: 1 for the levels, the speed for sigma2, a
        // quarter of the largest command torque for mu; sigma2 at a tenth of
        // the rate: on a smooth reference its regressor v is nearly
        // collinear with the Coulomb levels' sign(v), and at equal rates the
        // two shared a level error and parted only slowly
        let torque = 0.25 * servo.torque_constant * servo.limit;
        let size = [1.0, 1.0, 1.0, self.speed * VISCOUS_SLOWDOWN, torque];
        let nominal = self.nominal();
        let boxes = self.boxes();
        if self.prediction_rate * h > 1.0 {
            return Err(ParamError::NotBelow {
                name: "prediction_rate",
                limit: "1 / h",
            });
        }
        let zero = Estimate {
            gamma_h: S::ZERO,
            gamma_p: S::ZERO,
            gamma_d: S::ZERO,
            nominal: S::ZERO,
            low: S::ZERO,
            high: S::ZERO,
        };
        let mut per = [zero; ESTIMATES];
        // the prediction law's sizes: without the slowdown, which helps the
        // tracking law only (its levels and viscous term share one error)
        let predicted_size = [1.0, 1.0, 1.0, self.speed, torque];
        for ((((slot, size), predicted_size), nominal), (low, high)) in per
            .iter_mut()
            .zip(size)
            .zip(predicted_size)
            .zip(nominal)
            .zip(boxes)
        {
            let scale = 1.0 / (size * size);
            *slot = Estimate {
                gamma_h: convert_or_zero("rate", gamma * h * scale)?,
                gamma_d: convert_or_zero("derivative_weight", gamma_d * scale)?,
                gamma_p: convert_or_zero(
                    "prediction_rate",
                    self.prediction_rate * h / (predicted_size * predicted_size),
                )?,
                nominal: convert_or_zero("fc", nominal)?,
                low: convert_or_zero("box_factor", low)?,
                high: convert_or_zero("box_factor", high)?,
            };
        }
        Ok(ParameterAdaptive {
            per,
            leakage_h: convert_or_zero("leakage", (self.leakage * h).min(1.0))?,
            sigma0_h: convert("sigma0", self.model.sigma0 * h)?,
            sigma0: convert("sigma0", self.model.sigma0)?,
            h: convert("h", h)?,
            inv_h: convert("h", 1.0 / h)?,
            sigma1: convert_or_zero("sigma1", self.model.sigma1)?,
            observer_gain: convert_or_zero("observer_gain", self.observer_gain)?,
            inv_vs: convert("vs", 1.0 / self.model.curve.vs)?,
            exponent: convert("stribeck_exponent", self.model.curve.exponent)?,
            square: Flag::new(self.model.curve.exponent == 2.0),
            dead_zone: convert_or_zero("dead_zone", self.dead_zone)?,
            min_speed: convert_or_zero("min_speed", self.min_speed)?,
            torque_constant: convert("torque_constant", servo.torque_constant)?,
            torque_limit: convert("limit", 4.0 * servo.torque_constant * servo.limit)?,
            signal_limit: S::from_f64(SIGNAL_LIMIT),
            centre: convert("speed", 0.5 * self.speed)?,
            params: *self,
            period: h,
        })
    }
}

/// `x` in the scalar, where 0 is allowed.
fn convert_or_zero<S: Scalar>(name: &'static str, x: f64) -> Result<S, ParamError> {
    if x == 0.0 {
        Ok(S::ZERO)
    } else {
        convert(name, x)
    }
}

/// `sqrt(10)`: the viscous estimate's gain is a tenth of the levels'
/// (relative to its regressor's size).
const VISCOUS_SLOWDOWN: f64 = 3.162_277_660_168_379_5;

/// The bound on the scaled adaptation signal, so that its product with a
/// regressor stays finite.
const SIGNAL_LIMIT: f64 = 1e6;

/// The state: the bristle, the estimates, the last error, the transmitted
/// torque. The compensator's state starts from `Default` (estimates 0, not
/// yet `started`): the first step sets the estimates to their nominal
/// values, as [`ParameterAdaptive::initial`] does.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ParameterAdaptiveState<S> {
    /// The bristle deflection `z`, within `g^(v) / sigma0`.
    pub z: S,
    /// The estimates `[Fc+, Fc-, Ds, sigma2, mu]`.
    estimates: [S; ESTIMATES],
    last_error: S,
    /// The transmitted torque `kc u - τ_ext`.
    torque: S,
    /// The external torque the user set.
    external: S,
    started: Flag,
    primed: Flag,
}

impl<S: Scalar> ParameterAdaptiveState<S> {
    /// The estimates `[Fc+, Fc-, Fs - Fc, sigma2, mu]`: 0 in a `Default`
    /// state until its first step sets them to the nominal values
    /// ([`ParameterAdaptive::initial`] starts there).
    pub fn estimates(&self) -> [S; ESTIMATES] {
        self.estimates
    }
}

/// One estimate's gains (per tick), nominal value and box.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Estimate<S> {
    gamma_h: S,
    gamma_d: S,
    /// The prediction-error law's gain per tick (0: off).
    gamma_p: S,
    nominal: S,
    low: S,
    high: S,
}

/// The built per-parameter adaptive observer: immutable, shared by any
/// number of [`ParameterAdaptiveState`]s; a [`Compensation`] for the
/// [`Compensator`](crate::Compensator) at the period it was built for.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ParameterAdaptive<S> {
    per: [Estimate<S>; ESTIMATES],
    leakage_h: S,
    sigma0_h: S,
    sigma0: S,
    h: S,
    inv_h: S,
    sigma1: S,
    observer_gain: S,
    inv_vs: S,
    exponent: S,
    square: Flag,
    dead_zone: S,
    min_speed: S,
    torque_constant: S,
    torque_limit: S,
    signal_limit: S,
    /// Half the reference speed: the prediction law's centre.
    centre: S,
    params: ParameterAdaptiveParams,
    period: f64,
}

impl<S: Scalar> ParameterAdaptive<S> {
    /// The parameters it was built from.
    pub fn params(&self) -> &ParameterAdaptiveParams {
        &self.params
    }

    /// A state at rest with the nominal estimates.
    pub fn initial(&self) -> ParameterAdaptiveState<S> {
        ParameterAdaptiveState {
            estimates: self.per.map(|k| k.nominal),
            started: Flag::new(true),
            ..Default::default()
        }
    }

    /// Sets a `Default` state's estimates to their nominal values (once),
    /// keeping the rest of it (an external torque already set).
    #[inline]
    fn start(&self, state: &mut ParameterAdaptiveState<S>) {
        if !state.started.get() {
            state.estimates = self.per.map(|k| k.nominal);
            state.started = Flag::new(true);
        }
    }

    /// Sets the estimates of `state` (e.g. restored after a power cycle),
    /// each projected onto its box; a non-finite value leaves that estimate
    /// as it is.
    pub fn set_estimates(&self, state: &mut ParameterAdaptiveState<S>, values: [f64; ESTIMATES]) {
        self.start(state);
        for ((x, v), k) in state.estimates.iter_mut().zip(values).zip(&self.per) {
            if v.is_finite() {
                *x = S::from_f64(v).max(k.low).min(k.high);
            }
        }
    }

    /// Sets the external torque `τ_ext` (gravity, a load) the transmission
    /// carries besides the motor's; a non-finite value is ignored.
    pub fn set_external_torque(&self, state: &mut ParameterAdaptiveState<S>, torque: S) {
        if torque.is_finite() {
            state.external = torque.sat(self.torque_limit);
        }
    }

    /// `s(v) = exp(-|v / vs|^delta)`, in `[0, 1]`.
    #[inline]
    fn shape(&self, v: S) -> S {
        let r = (v * self.inv_vs).abs();
        let p = if self.square.get() {
            r * r
        } else {
            r.powf(self.exponent)
        };
        (-p).exp().min(S::ONE).max(S::ZERO)
    }

    /// The largest `|F^|` at speed `v` the boxes allow: the elastic force
    /// within `g^ <= Fc_max + Ds_max + mu_max |τ|_max`, the damping term
    /// clamped to `Fc_max + Ds_max`, and `sigma2_max |v|`.
    pub fn bound(&self, v: S) -> S {
        let level = self.per[0].high.max(self.per[1].high) + self.per[2].high;
        level + level + self.per[4].high * self.torque_limit + self.per[3].high * v.abs()
    }

    /// One step with measured velocity `v` and position error `e` (see the
    /// [module documentation](self)); returns `F^`.
    #[inline]
    pub fn step(&self, state: &mut ParameterAdaptiveState<S>, v: S, e: S) -> S {
        self.start(state);
        if !(v.is_finite() && e.is_finite()) {
            return self.force(state, S::ZERO, S::ZERO);
        }
        let v = v.sat(S::VELOCITY_LIMIT);
        let e = e.sat(S::VELOCITY_LIMIT);
        let s = self.shape(v);
        let g = self.level(state, s);
        // LuGre's observer, implicit Euler: z' = (z + h (v - k e)) / (1 + sigma0 h |v| / g)
        let drive = (v - (self.observer_gain * e).sat(S::VELOCITY_LIMIT)).sat(S::VELOCITY_LIMIT);
        let z = (state.z + self.h * drive) / (S::ONE + self.sigma0_h * v.abs() / g);
        let zeta = (self.sigma0 * z / g).min(S::ONE).max(-S::ONE);
        // the damping term carries the correction -k e, as Canudas de Wit's
        // observer does: without it the loops with a stiff sigma1 lost the
        // damping sigma1 k e gives and did up to 9x worse than none
        let z_dot = (z - state.z) * self.inv_h;
        state.z = zeta * g / self.sigma0;
        // adaptation
        let de = if state.primed.get() {
            (e - state.last_error).sat(self.signal_limit)
        } else {
            S::ZERO
        };
        state.last_error = e;
        state.primed = Flag::new(true);
        let adapting = e.abs() > self.dead_zone && v.abs() >= self.min_speed;
        let phi = Self::regressors(state, zeta, s, v);
        for ((x, p), k) in state.estimates.iter_mut().zip(phi).zip(&self.per) {
            let mut next = *x;
            if adapting {
                let signal = (k.gamma_h * e).sat(self.signal_limit)
                    + (k.gamma_d * de).sat(self.signal_limit);
                next = next - (signal.sat(self.signal_limit) * p).sat(self.signal_limit);
            }
            if self.leakage_h != S::ZERO {
                next = next - self.leakage_h * (next - k.nominal);
            }
            *x = next.max(k.low).min(k.high);
        }
        self.force(state, v, z_dot)
    }

    /// `g^(v)` at the bristle's side (`Fc+^` for `z >= 0`), with the
    /// Stribeck shape `s = s(v)`; at least the smallest Coulomb level of
    /// the boxes.
    #[inline]
    fn level(&self, state: &ParameterAdaptiveState<S>, s: S) -> S {
        let th = &state.estimates;
        let coulomb = if state.z >= S::ZERO { th[0] } else { th[1] };
        (coulomb + th[2] * s + th[4] * state.torque.abs()).max(self.per[0].low.min(self.per[1].low))
    }

    /// The regressors `φ` at normalized bristle `ζ`, shape `s` and speed `v`.
    #[inline]
    fn regressors(state: &ParameterAdaptiveState<S>, zeta: S, s: S, v: S) -> [S; ESTIMATES] {
        [
            zeta.max(S::ZERO),
            zeta.min(S::ZERO),
            s * zeta,
            v,
            state.torque.abs() * zeta,
        ]
    }

    /// The prediction-error law: the steady friction `φᵀ θ^` the estimates
    /// predict for a measured sample (`φ` at the sample's mean velocity
    /// with `ζ = sign v`) against the measured force,
    ///
    /// ```text
    /// ε       = force - φᵀ θ^
    /// Δsigma2 = γp3 (v - c sign v) ε                the viscous term centred at c
    /// ΔFc±    = γp φ± ε - c |φ±| Δsigma2             each level as the friction at c
    /// ΔDs, Δmu = γp φ ε,  then projection onto the boxes
    /// ```
    ///
    /// with `γp` the prediction rate times `h` over each regressor's size
    /// squared (1 for the levels, the reference speed for `sigma2`, a
    /// quarter of the largest command torque for `mu`) and `c` half the
    /// reference speed: in one direction `sign v` and `v` are nearly
    /// collinear, and a plain gradient on them crawls along their shared
    /// direction. A no-op when the rate is 0, for a sample slower
    /// than `min_speed` (at rest the measured force is whatever holds the
    /// load, not the curve: set `min_speed` above the speeds of reversals)
    /// or a non-finite one. The [`Compensator`](crate::Compensator)
    /// calls it through [`Compensation::learn`], in a tick or while it
    /// listens ([`Compensator::listen`](crate::Compensator::listen)), where
    /// the tracking error is another controller's and only this law can learn.
    pub fn learn(&self, state: &mut ParameterAdaptiveState<S>, sample: FrictionSample<S>) {
        if self.per.iter().all(|k| k.gamma_p == S::ZERO)
            || !(sample.force.is_finite() && sample.v.is_finite())
        {
            return;
        }
        self.start(state);
        let v = sample.v.sat(S::VELOCITY_LIMIT);
        if v.abs() < self.min_speed {
            return;
        }
        // the steady curve's regressors: above min_speed the sample is
        // sliding friction, and the bristle's lag behind a changing speed
        // (its ζ a little short of ±1) would bias the levels
        let sign = if v > S::ZERO {
            S::ONE
        } else if v < S::ZERO {
            -S::ONE
        } else {
            S::ZERO
        };
        let phi = Self::regressors(state, sign, self.shape(v), v);
        let mut predicted = S::ZERO;
        for (x, p) in state.estimates.iter().zip(phi) {
            predicted = predicted + (*x * p).sat(self.signal_limit);
        }
        let error = (sample.force.sat(self.signal_limit) - predicted).sat(self.signal_limit);
        let lim = self.signal_limit;
        // centred at c (see above): the viscous step first, then each
        // level's, less what the viscous step moved the friction at c
        let viscous = ((self.per[3].gamma_p * error).sat(lim) * (v - self.centre * sign)).sat(lim);
        let mut step = [S::ZERO; ESTIMATES];
        for ((d, p), k) in step.iter_mut().zip(phi).zip(&self.per) {
            *d = ((k.gamma_p * error).sat(lim) * p).sat(lim);
        }
        step[3] = viscous;
        let shift = (self.centre * viscous).sat(lim);
        step[0] = step[0] - phi[0] * shift;
        step[1] = step[1] + phi[1] * shift;
        for ((x, d), k) in state.estimates.iter_mut().zip(step).zip(&self.per) {
            *x = (*x + d).max(k.low).min(k.high);
        }
    }

    /// `F^ = sigma0 z + mu^ |τ| ζ + sigma1 dz/dt + sigma2^ v` from the
    /// state and the step's `dz/dt` (0 when holding).
    #[inline]
    fn force(&self, state: &ParameterAdaptiveState<S>, v: S, z_dot: S) -> S {
        let cap = self.per[0].high.max(self.per[1].high) + self.per[2].high;
        let damping = (self.sigma1 * z_dot).sat(cap);
        self.sigma0 * state.z + damping + state.estimates[3] * v
    }
}

impl<S: Scalar> Compensation<S> for ParameterAdaptive<S> {
    type State = ParameterAdaptiveState<S>;
    const USES_H: bool = false;
    const LEARNS: bool = true;
    #[inline]
    fn learn(&self, state: &mut Self::State, sample: FrictionSample<S>) {
        ParameterAdaptive::learn(self, state, sample);
    }
    #[inline]
    fn estimate(&self, state: &mut Self::State, v: S, e: S, _h: S) -> S {
        self.step(state, v, e)
    }
    fn period(&self) -> Option<f64> {
        Some(self.period)
    }
    #[inline]
    fn commanded(&self, state: &mut Self::State, command: S) {
        state.torque = (self.torque_constant * command - state.external).sat(self.torque_limit);
    }

    /// The estimates restart at this law's nominal values (the new model is
    /// the new nominal); the elastic force `sigma0 z` is kept (`z = z_old
    /// sigma0_old / sigma0`) within the nominal `max(Fc+, Fc-) + Ds + mu
    /// |τ|`; the last error and the torques are kept (within this law's
    /// torque limit).
    fn carry_over(&self, old: &Self, state: &mut Self::State) {
        let torque = state.torque.sat(self.torque_limit);
        let fresh = self.initial();
        let [fc_pos, fc_neg, excess, _, load] = fresh.estimates;
        let level = fc_pos.max(fc_neg) + excess + load * torque.abs();
        let ratio = old.sigma0.to_f64() / self.sigma0.to_f64();
        *state = ParameterAdaptiveState {
            z: carried(state.z, ratio, level / self.sigma0),
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
    use crate::{CompensatorState, Setpoint};

    use crate::test_servo::olsson_servo as servo;

    #[test]
    fn a_default_state_starts_nominal_and_keeps_its_external_torque() {
        let p = ParameterAdaptiveParams {
            load_max: 0.2,
            ..ParameterAdaptiveParams::new(LuGreParams::OLSSON_1998, 20.0)
        };
        let a = p.build::<f64>(&servo()).unwrap();
        let mut s = ParameterAdaptiveState::default();
        a.set_external_torque(&mut s, 2.0);
        a.step(&mut s, 0.0, 0.0);
        assert_eq!(s.estimates(), a.initial().estimates());
        // the transmitted torque is the command's less the external one
        a.commanded(&mut s, 1.0);
        assert!((s.torque - (1.02 - 2.0)).abs() < 1e-12);
        let mut t = ParameterAdaptiveState::default();
        a.set_estimates(&mut t, [0.3, f64::NAN, 0.0, 1e9, 0.1]);
        let nominal = a.initial().estimates();
        assert_eq!(t.estimates()[0], 0.3);
        assert_eq!(t.estimates()[1], nominal[1]); // NaN: left as it is
        assert_eq!(t.estimates()[3], p.boxes()[3].1); // projected
    }

    #[test]
    fn invalid_settings_are_named() {
        let p = ParameterAdaptiveParams::new(LuGreParams::OLSSON_1998, 20.0);
        let bad = |q: ParameterAdaptiveParams, e: ParamError| {
            assert_eq!(q.build::<f64>(&servo()).err(), Some(e));
        };
        bad(
            ParameterAdaptiveParams { rate: -1.0, ..p },
            ParamError::Negative("rate"),
        );
        bad(
            ParameterAdaptiveParams {
                box_factor: 0.5,
                ..p
            },
            ParamError::BelowOne("box_factor"),
        );
        bad(
            ParameterAdaptiveParams {
                speed: f64::NAN,
                ..p
            },
            ParamError::NotFinite("speed"),
        );
        bad(
            ParameterAdaptiveParams { load: 1.0, ..p },
            ParamError::NotBelow {
                name: "load",
                limit: "load_max",
            },
        );
    }

    /// Simulates the Olsson plant (LuGre, exact parameters, 10 substeps of
    /// explicit Euler at 10 kHz would be stiff: the plant is the core's own
    /// LuGre at 100 kHz) under the compensator with a wrong nominal model;
    /// returns the final estimates.
    fn adapt_on_olsson(nominal: LuGreParams, plant: LuGreParams, seconds: f64) -> [f64; ESTIMATES] {
        use crate::{FrictionModel, LuGreState};
        let p = ParameterAdaptiveParams {
            speed: 0.63,
            rate: 16.0,
            ..ParameterAdaptiveParams::new(nominal, 20.0)
        };
        let c = servo().build(p.build::<f64>(&servo()).unwrap()).unwrap();
        let plant_model = plant.build::<f64>().unwrap();
        let mut ps = LuGreState::default();
        let mut s = CompensatorState::default();
        let (mut x, mut v) = (0.0f64, 0.0f64);
        let hp = 1e-5;
        let w = 2.0 * core::f64::consts::PI * 0.2;
        for k in 0..(seconds * 1e3) as usize {
            let t = k as f64 * 1e-3;
            let r = Setpoint {
                x: 0.5 * libm::sin(w * t),
                v: 0.5 * w * libm::cos(w * t),
                a: -0.5 * w * w * libm::sin(w * t),
            };
            let u = c.tick(&mut s, x, r).command;
            for _ in 0..100 {
                let f = plant_model.step(&mut ps, v, hp);
                v += hp * (1.02 * u - f) / 0.0023;
                x += hp * v;
            }
        }
        s.friction().estimates().map(|x| x.to_f64())
    }

    /// The Coulomb levels converge from 1.5x and 0.5x to the plant's
    /// within 5 % on Olsson's reference. The Stribeck excess and the
    /// viscous coefficient are not identified by it (the excess is seen only
    /// below about 0.02 rad/s, the viscous term is nearly collinear with the
    /// levels): they are only held in their boxes.
    #[test]
    fn coulomb_levels_converge_to_the_plant_levels() {
        let plant = LuGreParams::OLSSON_1998;
        for factor in [1.5, 0.5] {
            let mut nominal = plant;
            nominal.curve.fc *= factor;
            nominal.curve.fs *= factor;
            let th = adapt_on_olsson(nominal, plant, 60.0);
            let fc = plant.curve.fc;
            assert!((th[0] - fc).abs() < 0.05 * fc, "{factor}: {th:?}");
            assert!((th[1] - fc).abs() < 0.05 * fc, "{factor}: {th:?}");
            // and they moved: the test can fail
            assert!((th[0] - factor * fc).abs() > 0.3 * fc, "{factor}: {th:?}");
        }
    }

    /// The prediction-error law alone, listening beside another
    /// controller (a PD loop that knows nothing of friction) on a plant
    /// whose Coulomb level differs by direction: from 1.5x and 0.5x nominal
    /// values, the levels per direction and the viscous coefficient end
    /// within 5 % of the plant's after two minutes (the viscous term, nearly
    /// collinear with the levels in each direction, is the slow one).
    #[test]
    fn the_prediction_law_learns_by_listening_to_another_loop() {
        let (fc_pos, fc_neg, sigma2) = (0.33, 0.25, 0.018);
        let j = 0.0023;
        for factor in [1.5, 0.5] {
            let mut nominal = LuGreParams::OLSSON_1998;
            nominal.curve.fc = 0.29 * factor;
            nominal.curve.fs = 0.29 * factor;
            nominal.sigma2 = sigma2 * factor;
            let p = ParameterAdaptiveParams {
                rate: 0.0,
                prediction_rate: 20.0,
                speed: 1.5,
                // at rest the measured friction is whatever holds the load
                min_speed: 0.03,
                ..ParameterAdaptiveParams::new(nominal, 0.0)
            };
            let listener = servo().build(p.build::<f64>(&servo()).unwrap()).unwrap();
            let mut s = CompensatorState::default();
            let (mut x, mut v) = (0.0f64, 0.0f64);
            let hp = 1e-5;
            let (w1, w2) = (
                2.0 * core::f64::consts::PI * 0.2,
                2.0 * core::f64::consts::PI * 0.7,
            );
            for k in 0..120_000 {
                let t = k as f64 * 1e-3;
                let r = 0.5 * libm::sin(w1 * t) + 0.1 * libm::sin(w2 * t);
                let rv = 0.5 * w1 * libm::cos(w1 * t) + 0.1 * w2 * libm::cos(w2 * t);
                // the other controller: PD, no friction compensation
                let u = (8.0 * (r - x) + 0.4 * (rv - v)).clamp(-10.0, 10.0);
                listener.listen(&mut s, x, Setpoint::default(), u);
                for _ in 0..100 {
                    let level = if v >= 0.0 { fc_pos } else { fc_neg };
                    let f = level * libm::tanh(v / 1e-3) + sigma2 * v;
                    v += hp * (1.02 * u - f) / j;
                    x += hp * v;
                }
            }
            let th = s.friction().estimates();
            for (i, want) in [(0, fc_pos), (1, fc_neg), (3, sigma2)] {
                assert!((th[i] - want).abs() < 0.05 * want, "{factor}: {i} {th:?}");
            }
        }
    }

    #[test]
    fn hostile_samples_keep_every_estimate_in_its_box() {
        let p = ParameterAdaptiveParams {
            load_max: 0.3,
            prediction_rate: 100.0,
            ..ParameterAdaptiveParams::new(LuGreParams::OLSSON_1998, 20.0)
        };
        let boxes = p.boxes();
        let a = p.build::<f32>(&servo()).unwrap();
        let mut s = a.initial();
        let mut rng = crate::test_rng::xorshift64(11);
        let mut pick = || -> f32 {
            let r = rng();
            let unit = (r >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0;
            match r % 4 {
                0 => f32::MAX,
                1 => -f32::MAX,
                2 => unit as f32 * 1e-3,
                _ => unit as f32 * 1e3,
            }
        };
        for _ in 0..200_000 {
            a.commanded(&mut s, pick());
            a.learn(
                &mut s,
                FrictionSample {
                    force: pick(),
                    v: pick(),
                },
            );
            let v = pick();
            let f = a.step(&mut s, v, pick());
            assert!(f.is_finite() && f.abs() <= a.bound(v) * 1.0001, "{f} {v}");
            for (x, (lo, hi)) in s.estimates().iter().zip(boxes) {
                assert!(*x >= lo as f32 * 0.9999 && *x <= hi as f32 * 1.0001, "{x}");
            }
        }
        let before = s;
        for (force, v) in [(f32::NAN, 1.0), (1.0, f32::INFINITY)] {
            a.learn(&mut s, FrictionSample { force, v });
            assert_eq!(s, before);
        }
    }

    #[test]
    fn hostile_finite_inputs_keep_every_estimate_in_its_box() {
        let p = ParameterAdaptiveParams {
            load_max: 0.3,
            leakage: 0.1,
            ..ParameterAdaptiveParams::new(LuGreParams::OLSSON_1998, 20.0)
        };
        let boxes = p.boxes();
        let a = p.build::<f32>(&servo()).unwrap();
        let mut s = a.initial();
        let mut rng = crate::test_rng::xorshift64(7);
        let mut pick = || -> f32 {
            let r = rng();
            let unit = (r >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0;
            match r % 5 {
                0 => f32::MAX,
                1 => -f32::MAX,
                2 => 0.0,
                3 => unit as f32 * 1e-3,
                _ => unit as f32 * 1e3,
            }
        };
        for _ in 0..1_000_000 {
            let (v, e, u) = (pick(), pick(), pick());
            a.commanded(&mut s, u);
            let f = a.step(&mut s, v, e);
            assert!(
                f.is_finite() && f.abs() <= a.bound(v) * 1.0001,
                "{f} {v} {e}"
            );
            assert!(s.z.is_finite());
            for (x, (lo, hi)) in s.estimates().iter().zip(boxes) {
                assert!(*x >= lo as f32 * 0.9999 && *x <= hi as f32 * 1.0001, "{x}");
            }
        }
        // NaN and infinite inputs leave the state untouched
        let before = s;
        for (v, e) in [
            (f32::NAN, 0.0),
            (0.0, f32::INFINITY),
            (f32::NEG_INFINITY, 1.0),
        ] {
            let f = a.step(&mut s, v, e);
            assert!(f.is_finite());
            assert_eq!(s, before);
        }
    }
}
