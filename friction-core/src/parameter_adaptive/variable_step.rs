//! The variable-step per-parameter adaptive observer: [`ParameterAdaptive`]
//! and its state.

use super::{ParameterAdaptiveParams, PARAMETER_ADAPTIVE_ESTIMATES};
use crate::bits::Flag;
use crate::compensator::{Compensation, FrictionSample};
use crate::fixed_step::carried;
use crate::models::lugre::relaxed;
use crate::Scalar;

/// The state: the bristle, the estimates, the last error, the transmitted
/// torque. The compensator's state starts from `Default` (estimates 0, not
/// yet `started`): the first step sets the estimates to their nominal
/// values, as [`ParameterAdaptive::initial`] does.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ParameterAdaptiveState<S> {
    /// The bristle deflection `z`: within `g^(v) / sigma0` (the implicit
    /// step) or `g^(0) / sigma0` (the exact step).
    pub z: S,
    /// The estimates `[Fc+, Fc-, Ds, sigma2, mu]`.
    estimates: [S; PARAMETER_ADAPTIVE_ESTIMATES],
    last_error: S,
    /// The transmitted torque `kc u - τ_ext`.
    pub(super) torque: S,
    /// The external torque the user set.
    external: S,
    started: Flag,
    primed: Flag,
    /// The prediction law's centre `c`: the mean speed of its samples.
    centre: S,
    /// The stiffness law's state.
    stiffness: StiffnessState<S>,
}

/// The stiffness law's state: the factor on `sigma0`, the last two
/// outputs (the friction the samples are compared with), the normalized
/// bristle, and the measured and predicted friction at the last reversal.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct StiffnessState<S> {
    factor: S,
    outputs: [S; 2],
    zeta: S,
    measured: S,
    predicted: S,
    /// The last sample's measured and predicted friction.
    last: [S; 2],
    direction: S,
    crossing: Flag,
    /// The sliding samples' mean distance from the steady curve, over
    /// `g` (each sample's at most 1; 1 until they show it, 0 in a
    /// `Default` state before its first step).
    mismatch: S,
}

impl<S: Scalar> ParameterAdaptiveState<S> {
    /// The estimates `[Fc+, Fc-, Fs - Fc, sigma2, mu]`: 0 in a `Default`
    /// state until its first step sets them to the nominal values
    /// ([`ParameterAdaptive::initial`] starts there).
    pub fn estimates(&self) -> [S; PARAMETER_ADAPTIVE_ESTIMATES] {
        self.estimates
    }

    /// The stiffness factor `κ^` on `sigma0` (1 until the stiffness law
    /// moves it; 0 in a `Default` state before its first step).
    pub fn stiffness(&self) -> S {
        self.stiffness.factor
    }
}

/// One estimate's gains (per tick), nominal value and box.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(super) struct Estimate<S> {
    pub(super) gamma_h: S,
    pub(super) gamma_d: S,
    /// The prediction-error law's gain per tick (0: off).
    pub(super) gamma_p: S,
    pub(super) nominal: S,
    pub(super) low: S,
    pub(super) high: S,
}

/// The built per-parameter adaptive observer: immutable, shared by any
/// number of [`ParameterAdaptiveState`]s; a [`Compensation`] for the
/// [`Compensator`](crate::Compensator) at the period it was built for.
///
/// Per-parameter adaptive friction compensation: a LuGre observer whose
/// friction levels are estimated one by one, each in its own box (after
/// Canudas de Wit & Lischinsky 1997, Int. J. Adapt. Control Signal Process.
/// 11(1); Panteley, Ortega & Gäfvert 1998, Syst. Control Lett. 33(5);
/// robust modifications from Ioannou & Sun 1996, Robust Adaptive Control,
/// Ch. 8: projection, dead zone, leakage).
///
/// The θ-adaptive observer ([`crate::AdaptiveObserver`]) scales the whole
/// model: a model whose Coulomb level alone is off is no scaled copy of the
/// plant, and the error in the Stribeck shape stays. Here the observer is
/// LuGre's, with the levels of its curve estimated: the steady friction is
/// linear in them, with the normalized bristle `ζ = sigma0 z / g(v)`
/// (`|ζ| <= 1`, `ζ = sign v` in steady sliding) as their regressor:
///
/// ```text
/// g^(v)   = Fc±^ + Ds^ s(v) + mu^ |τ|,  s(v) = exp(-|v / vs|^delta),  Fc+^ for z >= 0, Fc-^ below
/// dz/dt   = v - k e - sigma0 |v| z / g^(v)                     LuGre observer (gain k)
/// ζ       = sigma0 z / g^(v), within [-1, 1]                    the normalized bristle
/// F^      = sigma0 z + sigma1 dz/dt + sigma2^ v
/// φ       = [max(ζ, 0), min(ζ, 0), s(v) ζ, v, |τ| ζ]            regressors of
/// θ^      = [Fc+^, Fc-^, Ds^, sigma2^, mu^]                     the estimates
/// dθ^/dt  = -Γ φ (γ e + γd de/dt) - rho (θ^ - θ0)              per estimate, then
/// θ^      = clamp(θ^, box)                                      projection
/// ```
///
/// In steady sliding `sigma0 z = g^(v) ζ` with `ζ = sign v`, so `φ` is the
/// sensitivity of the steady friction to each estimate; the elastic force
/// follows a change of the estimates within the bristle's lag
/// `g / (sigma0 |v|)`.
///
/// The bristle's step over a tick: an implicit Euler step with `z` within
/// the sliding level `g^(v) / sigma0` and `dz/dt` its mean rate (the
/// default); or, with
/// [`ParameterAdaptiveParams::exact_step`](super::ParameterAdaptiveParams::exact_step),
/// LuGre's exact step for a held velocity, with `z` within the level at
/// rest `g^(0) / sigma0` of the side it ends on and `dz/dt` at the end of
/// the tick: with its
/// adaptation off it is then LuGre's observer ([`crate::Observer`]) on
/// the nominal model (without `vd` or a load term, below either's clip
/// of the output).
///
/// `τ` is the torque the transmission carries: the compensator's own last
/// command times `kc`, less an external torque the user may set
/// ([`ParameterAdaptive::set_external_torque`]). The adaptation signal is the
/// θ law's (`γ = a kc kp`, `γd = w γ kd / kp`, the composite error of the
/// loop's PD part), scaled per estimate by its regressor's size: 1 for the
/// levels, the reference speed for `sigma2`, the reference torque for `mu`.
///
/// A second law, off by default, learns from the friction the compensator
/// measures instead of the tracking error ([`ParameterAdaptive::learn`]):
/// the estimates' prediction `φᵀ θ^` of each measured sample against the
/// sample (a gradient on the prediction error, as in composite adaptation,
/// Slotine & Li 1989). It is the one that learns where this compensation
/// is not in the loop: beside another controller, or on a logged run
/// replayed through [`Compensator::listen`](crate::Compensator::listen).
///
/// A third law, off by default
/// ([`stiffness_rate`](super::ParameterAdaptiveParams::stiffness_rate);
/// `sigma0` above then reads `κ^ sigma0`, with `κ^` in its box),
/// learns a factor `κ^` on the bristle's stiffness `sigma0` from the same
/// samples: the rise of the measured friction after each reversal against
/// the rise of `F^`. The levels cannot stand in for a wrong stiffness, and
/// the tracking error cannot tell the two apart (an error left from the
/// sliding phase is still there at the next reversal); the measured
/// friction's rise over one crossing can. It is the variable form's only.
///
/// Robust modifications, all optional:
/// - **dead zone**: no adaptation while `|e|` is within `dead_zone` (one or
///   two encoder counts: a quantized error that small carries no
///   information about the friction);
/// - **leakage** `rho` toward the nominal values;
/// - **excitation**: no adaptation while `|v|` is below `min_speed`;
/// - **projection** onto each estimate's box (`[θ0 / box, θ0 box]` for the
///   Coulomb levels, `[0, box max(Ds0, Fc0)]` for the Stribeck excess, `[0,
///   max(box sigma2_0, Fs0 / speed)]` for the viscous coefficient,
///   `[0, load_max]` for the load coefficient).
///
/// Bounds, for any finite inputs: every estimate stays in its box, `|ζ| <= 1`,
/// and the output is finite and within the largest friction the boxes allow
/// at that speed (see [`ParameterAdaptive::bound`]). A NaN or infinite input
/// leaves the state untouched.
///
/// The fixed-step form for every scalar, Q16.16 included, is
/// [`ParameterAdaptiveFixedStep`](crate::ParameterAdaptiveFixedStep)
/// ([`ParameterAdaptiveParams::build_fixed_step`], or
/// [`ParameterAdaptiveParams::build_fixed_step_exact`] for the exact step).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ParameterAdaptive<S> {
    pub(super) per: [Estimate<S>; PARAMETER_ADAPTIVE_ESTIMATES],
    pub(super) leakage_h: S,
    pub(super) sigma0_h: S,
    pub(super) sigma0: S,
    pub(super) h: S,
    pub(super) inv_h: S,
    /// [`ParameterAdaptiveParams::exact_step`].
    pub(super) exact_step: Flag,
    pub(super) sigma1: S,
    pub(super) observer_gain: S,
    pub(super) inv_vs: S,
    pub(super) exponent: S,
    pub(super) square: Flag,
    pub(super) dead_zone: S,
    pub(super) min_speed: S,
    pub(super) torque_constant: S,
    pub(super) torque_limit: S,
    pub(super) signal_limit: S,
    /// Half the reference speed: the prediction law's first centre, and
    /// the stiffness law's sliding speed.
    pub(super) centre: S,
    /// `stiffness_rate h` (0: no stiffness law).
    pub(super) stiffness_gain: S,
    pub(super) stiffness_low: S,
    pub(super) stiffness_high: S,
    pub(super) params: ParameterAdaptiveParams,
    pub(super) period: f64,
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
            centre: self.centre,
            stiffness: StiffnessState {
                factor: S::ONE,
                mismatch: S::ONE,
                ..Default::default()
            },
            ..Default::default()
        }
    }

    /// Sets a `Default` state's estimates to their nominal values (once),
    /// keeping the rest of it (an external torque already set).
    #[inline]
    fn start(&self, state: &mut ParameterAdaptiveState<S>) {
        if !state.started.get() {
            state.estimates = self.per.map(|k| k.nominal);
            state.centre = self.centre;
            state.stiffness.factor = S::ONE;
            state.stiffness.mismatch = S::ONE;
            state.started = Flag::new(true);
        }
    }

    /// Sets the estimates of `state` (e.g. restored after a power cycle),
    /// each projected onto its box; a non-finite value leaves that estimate
    /// as it is. The stiffness law waits for the sliding samples to agree
    /// with the new levels.
    pub fn set_estimates(
        &self,
        state: &mut ParameterAdaptiveState<S>,
        values: [f64; PARAMETER_ADAPTIVE_ESTIMATES],
    ) {
        self.start(state);
        state.stiffness.mismatch = S::ONE;
        for ((x, v), k) in state.estimates.iter_mut().zip(values).zip(&self.per) {
            if v.is_finite() {
                *x = S::from_f64(v).max(k.low).min(k.high);
            }
        }
    }

    /// Sets the stiffness factor `κ^` of `state` (e.g. a learnt one
    /// restored after a power cycle), projected onto `[1 / stiffness_box,
    /// stiffness_box]` (1 with the stiffness law off); the bristle is
    /// rescaled so that the elastic force `κ^ sigma0 z` does not jump. A
    /// non-finite value is ignored.
    pub fn set_stiffness(&self, state: &mut ParameterAdaptiveState<S>, factor: f64) {
        self.start(state);
        if factor.is_finite() {
            self.move_stiffness(state, S::from_f64(factor));
        }
    }

    /// Sets the external torque `τ_ext` (gravity, a load) the transmission
    /// carries besides the motor's; a non-finite value is ignored.
    pub fn set_external_torque(&self, state: &mut ParameterAdaptiveState<S>, torque: S) {
        if torque.is_finite() {
            state.external = torque.sat(self.torque_limit);
        }
    }

    /// The bristle's stiffness `κ^ sigma0`.
    #[inline]
    fn sigma0_of(&self, state: &ParameterAdaptiveState<S>) -> S {
        self.sigma0 * state.stiffness.factor
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

    /// One step with measured velocity `v` and position error `e` (see
    /// [`ParameterAdaptive`]); returns `F^`.
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
        let drive = (v - (self.observer_gain * e).sat(S::VELOCITY_LIMIT)).sat(S::VELOCITY_LIMIT);
        let sigma0 = self.sigma0_of(state);
        let (z, z_dot, zeta) = if self.exact_step.get() {
            let (z, z_dot) = self.bristle(state, v, drive, g);
            (z, z_dot, (sigma0 * z / g).min(S::ONE).max(-S::ONE))
        } else {
            // implicit Euler: z' = (z + h (v - k e)) / (1 + sigma0 h |v| / g)
            let sigma0_h = self.sigma0_h * state.stiffness.factor;
            let z = (state.z + self.h * drive) / (S::ONE + sigma0_h * v.abs() / g);
            let zeta = (sigma0 * z / g).min(S::ONE).max(-S::ONE);
            // the damping term carries the correction -k e, as Canudas de
            // Wit's observer does: without it the loops with a stiff sigma1
            // lost the damping sigma1 k e gives and did up to 9x worse than none
            let z_dot = (z - state.z) * self.inv_h;
            (zeta * g / sigma0, z_dot, zeta)
        };
        state.z = z;
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
        let force = self.force(state, v, z_dot);
        let st = &mut state.stiffness;
        st.zeta = zeta;
        st.outputs = [force, st.outputs[0]];
        force
    }

    /// The exact step ([`ParameterAdaptiveParams::exact_step`]): LuGre's
    /// observer over the step, `dz/dt = u - a z` with `u = v - k e`
    /// (the `drive`) and `a = sigma0 |v| / g` held: the exact solution, as
    /// LuGre's own step ([`crate::LuGre`]), within `g^(0) / sigma0` (the
    /// level at rest, LuGre's bound) of the side `z` ends on; returns `z`
    /// and its rate at the end of the step, `u - a z` (0 while held at the
    /// bound).
    ///
    /// Why not the implicit step within `g^(v) / sigma0`: at a stiff
    /// `sigma0` the implicit step leaves a rate of about `(z - z_eq) / h`
    /// in the damping term, and the bound at `g^(v)` cuts the elastic force
    /// from the static level to the sliding one within a step as the speed
    /// rises. Both kick the loop at every break-away, which rang on stiff
    /// plants.
    #[inline]
    fn bristle(&self, state: &ParameterAdaptiveState<S>, v: S, drive: S, g: S) -> (S, S) {
        let sigma0 = self.sigma0_of(state);
        let r = g / sigma0; // > 0: g is at least the boxes' smallest level
        let speed = v.abs();
        // the equilibrium within twice the level at rest of the side the
        // bristle starts on (g, and so r, is that side's)
        let start = self.level(state, S::ONE) / sigma0;
        let free = relaxed(state.z, drive, speed, r, self.h, start + start);
        // within the level at rest of the side the bristle ends on (where
        // the levels differ by direction, the side it started on would let
        // it past its own level by their difference for a tick)
        let bound = self.level_on(state, free >= S::ZERO, S::ONE) / sigma0;
        let z = free.sat(bound);
        // z / r is within the levels' ratio, which the boxes may make
        // large: bounded, so that the product stays a number in f32
        let mut rate = drive - speed * (z / r).sat(S::VELOCITY_LIMIT);
        if z.abs() >= bound && rate * z > S::ZERO {
            rate = S::ZERO;
        }
        (z, rate)
    }

    /// `g^(v)` at the bristle's side (`Fc+^` for `z >= 0`), with the
    /// Stribeck shape `s = s(v)`; at least the smallest Coulomb level of
    /// the boxes.
    #[inline]
    fn level(&self, state: &ParameterAdaptiveState<S>, s: S) -> S {
        self.level_on(state, state.z >= S::ZERO, s)
    }

    /// [`level`](Self::level) on the forward side (`Fc+^`) or the backward one.
    #[inline]
    fn level_on(&self, state: &ParameterAdaptiveState<S>, forward: bool, s: S) -> S {
        self.level_of(&state.estimates, state.torque, forward, s)
    }

    /// The level `Fc± + (Fs - Fc) s + mu |τ|` of the estimates `th` on
    /// one side at transmitted torque `torque`, at least the smallest
    /// Coulomb level of the boxes.
    #[inline]
    fn level_of(
        &self,
        th: &[S; PARAMETER_ADAPTIVE_ESTIMATES],
        torque: S,
        forward: bool,
        s: S,
    ) -> S {
        let coulomb = if forward { th[0] } else { th[1] };
        (coulomb + th[2] * s + th[4] * torque.abs()).max(self.per[0].low.min(self.per[1].low))
    }

    /// How far a sliding sample's `force` at speed `v` (shape `s`) lies
    /// from the steady curve `g(v) sign v + sigma2 v` of the estimates
    /// `th`, over the level `g` (at most 1).
    #[inline]
    fn miss_from(
        &self,
        th: &[S; PARAMETER_ADAPTIVE_ESTIMATES],
        torque: S,
        (force, v, s): (S, S, S),
        g: S,
    ) -> S {
        let lim = self.signal_limit;
        let forward = v > S::ZERO;
        let level = self.level_of(th, torque, forward, s);
        let sliding = if forward { level } else { -level } + (th[3] * v).sat(lim);
        ((force - sliding).sat(lim).abs() / g).min(S::ONE)
    }

    /// The regressors `φ` at normalized bristle `ζ`, shape `s` and speed `v`.
    #[inline]
    fn regressors(
        state: &ParameterAdaptiveState<S>,
        zeta: S,
        s: S,
        v: S,
    ) -> [S; PARAMETER_ADAPTIVE_ESTIMATES] {
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
    /// c      <- c + γp0 (|v| - c)                    the samples' mean speed
    /// Δsigma2 = γp3 (v - c sign v) ε                the viscous term centred at c
    /// ΔFc±    = γp φ± ε - c |φ±| Δsigma2             each level as the friction at c
    /// ΔDs, Δmu = γp φ ε,  then projection onto the boxes
    /// ```
    ///
    /// with `γp` the prediction rate times `h` over each regressor's size
    /// squared (1 for the levels, the reference speed for `sigma2`, a
    /// quarter of the largest command torque for `mu`) and `c` the samples'
    /// mean speed over the levels' memory (from half the reference speed):
    /// in one direction `sign v` and `v` are nearly collinear, and a plain
    /// gradient on them crawls along their shared direction; centred at the
    /// samples' mean speed the two regressors are uncorrelated where both
    /// directions move at that mean speed. A no-op when the rate is 0, for
    /// a sample slower than `min_speed` (at rest the measured force is
    /// whatever holds the load, not the curve: set `min_speed` above the
    /// speeds of reversals) or a non-finite one. A finite sample also feeds the stiffness law
    /// (see [`ParameterAdaptive`]; a no-op at `stiffness_rate` 0). The
    /// [`Compensator`](crate::Compensator)
    /// calls it through [`Compensation::learn`], in a tick or while it
    /// listens ([`Compensator::listen`](crate::Compensator::listen)), where
    /// the tracking error is another controller's and only this law can learn.
    pub fn learn(&self, state: &mut ParameterAdaptiveState<S>, sample: FrictionSample<S>) {
        if !(sample.force.is_finite() && sample.v.is_finite()) {
            return;
        }
        self.start(state);
        self.learn_stiffness(state, sample);
        if self.per.iter().all(|k| k.gamma_p == S::ZERO) {
            return;
        }
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
        let centre = state.centre + self.per[0].gamma_p * (v.abs() - state.centre);
        state.centre = centre;
        let viscous = ((self.per[3].gamma_p * error).sat(lim) * (v - centre * sign)).sat(lim);
        let mut step = [S::ZERO; PARAMETER_ADAPTIVE_ESTIMATES];
        for ((d, p), k) in step.iter_mut().zip(phi).zip(&self.per) {
            *d = ((k.gamma_p * error).sat(lim) * p).sat(lim);
        }
        step[3] = viscous;
        let shift = (centre * viscous).sat(lim);
        step[0] = step[0] - phi[0] * shift;
        step[1] = step[1] + phi[1] * shift;
        for ((x, d), k) in state.estimates.iter_mut().zip(step).zip(&self.per) {
            *x = (*x + d).max(k.low).min(k.high);
        }
    }

    /// The stiffness law: the factor `κ^` on `sigma0` from the rise of the
    /// measured friction after a reversal against the rise of the estimate,
    ///
    /// ```text
    /// d    = sign v; at a change of d: F0, F0^ = the last sample's force and F^
    /// u    = ζ d, in [-1, 1]: about -1 at the reversal, 1 once the bristle slides
    /// ε    = (force - F0) - (F^ - F0^)             F^: the mean of the last two outputs
    /// ψ    = 0.74 (1 - u^2) (g - sigma1 |v|) / g    the rise's sensitivity to ln κ, over g
    /// κ^  <- clamp(κ^ (1 + clamp(γκ ε d ψ / g, ±0.1)), [1 / box, box]);  z <- z κ_old / κ^
    /// ```
    ///
    /// with `γκ` the stiffness rate times `h`. LuGre's elastic force after
    /// a reversal from `-g` rises as `g - 2 g exp(-κ sigma0 x / g)` over the
    /// travel `x`: its sensitivity to `ln κ` is `g (1 - u) ln(2 / (1 - u))`,
    /// 0 at both ends, whose peak `0.74 g (1 - u^2)` matches; the damping
    /// term `sigma1 dz/dt = sigma1 v (1 - u)` takes `sigma1 |v|` from it.
    ///
    /// The law runs once per reversal, from the reversal until the bristle
    /// slides (`u > 0.98`), and only from a bristle deflected the other way
    /// (`u < -0.5` at the reversal): a stick without a reversal, or a
    /// wobble within the presliding, starts none. Samples where the damping
    /// term outweighs the elastic one (`sigma1 |v| > g`: the sensitivity
    /// changes sign) do not move `κ^`. The references are the last sample
    /// before the reversal (a friction that flips at once has already
    /// risen in the first one after it). Differences from them cancel what
    /// the friction sample carries besides friction and holds over a
    /// crossing (gravity, an offset of the force). `z` is rescaled so that
    /// the elastic force does not jump. A no-op at rate 0.
    ///
    /// A level error also changes the rise (the plant's bristle saturates
    /// at its own level), so three gates keep it from being read as a
    /// stiffness error: the law learns only while the sliding samples
    /// (`|v|` above half the reference speed) agree with the steady curve,
    /// the mean of `min(|force - g^(v) d - sigma2^ v| / g, 1)` over about
    /// 16 of them at most 0.1 (`g` the level at rest), each sample's miss
    /// the smaller of that and five times its miss from the nominal curve
    /// (over the nominal level at rest): a nominal curve that the samples
    /// meet within 0.02 says the levels are right even where the tracking
    /// law's estimates have taken up a stiffness error (a nominal bristle
    /// too soft drags them off). The sliding samples of a half-period
    /// outnumber the mean's memory, so it speaks of the current direction;
    /// a crossing ends
    /// once the measured rise exceeds the estimate's whole swing
    /// `g - F0^ d`; and samples where the bristle moves more than a quarter
    /// of `g / (κ sigma0)` in a period, which the samples cannot resolve,
    /// are skipped. The first gate compares the sample itself, not a
    /// difference: a load the sample carries besides friction (gravity not
    /// given as the external torque) keeps it shut.
    fn learn_stiffness(&self, state: &mut ParameterAdaptiveState<S>, sample: FrictionSample<S>) {
        if self.stiffness_gain == S::ZERO {
            return;
        }
        let lim = self.signal_limit;
        let v = sample.v.sat(S::VELOCITY_LIMIT);
        let force = sample.force.sat(lim);
        let g = self.level(state, S::ONE);
        let damped = (g - (self.sigma1 * v.abs()).sat(lim)) / g;
        // at a sliding speed: the sample against the steady curve at v,
        // bristle aside, relative to the level: the estimates' curve, or
        // the nominal one held to a fifth of the threshold
        let miss = (v.abs() > self.centre).then(|| {
            let sample = (force, v, self.shape(v));
            let own = self.miss_from(&state.estimates, state.torque, sample, g);
            let nominal = self.per.map(|k| k.nominal);
            let at_rest = self.level_of(&nominal, state.torque, v > S::ZERO, S::ONE);
            let theirs = self.miss_from(&nominal, state.torque, sample, at_rest);
            own.min(theirs * S::from_f64(SETTLED / NOMINAL_SETTLED))
        });
        let st = &mut state.stiffness;
        let predicted = S::from_f64(0.5) * (st.outputs[0] + st.outputs[1]);
        let [last_force, last_predicted] = st.last;
        st.last = [force, predicted];
        let direction = if v > S::ZERO {
            S::ONE
        } else if v < S::ZERO {
            -S::ONE
        } else {
            return;
        };
        if direction != st.direction {
            // the references: the friction before the reversal (a plant
            // whose friction flips at once has already risen in the first
            // sample of the new direction)
            st.direction = direction;
            st.measured = last_force;
            st.predicted = last_predicted;
            // a crossing starts from a bristle deflected the other way (at
            // least half its sliding level: not a stick-slip wobble)
            st.crossing = Flag::new(st.zeta * direction < -S::from_f64(REVERSED));
            return;
        }
        let u = st.zeta * direction;
        // a measured rise beyond the estimate's whole swing (to its level
        // g) is the levels' error, which no stiffness explains
        let beyond = direction * (force - st.measured) > g - direction * st.predicted;
        if u > S::from_f64(CROSSED) || beyond {
            st.crossing = Flag::new(false);
        }
        if let Some(miss) = miss {
            st.mismatch = st.mismatch + S::from_f64(MISMATCH_BLEND) * (miss - st.mismatch);
        }
        // the rise tells the stiffness only where the levels are right:
        // with a level error, the plant's bristle saturates elsewhere
        if st.mismatch > S::from_f64(SETTLED) {
            return;
        }
        // a bristle that crosses a good part of its range in one period
        // rises between the samples, which cannot resolve it
        let stride = (self.sigma0_h * st.factor * v.abs()).sat(lim);
        if !st.crossing.get() || damped < S::ZERO || stride > S::from_f64(RESOLVED) * g {
            return;
        }
        let error = ((force - st.measured).sat(lim) - (predicted - st.predicted).sat(lim)).sat(lim);
        let psi = S::from_f64(SENSITIVITY_PEAK) * (S::ONE - u * u) * damped;
        let step = ((self.stiffness_gain * error).sat(lim) * direction * psi / g)
            .sat(S::from_f64(STIFFNESS_STEP));
        let factor = st.factor + st.factor * step;
        self.move_stiffness(state, factor);
    }

    /// The stiffness factor set to `factor` projected onto its box, the
    /// bristle rescaled (`z κ_old / κ^`) so that the elastic force does
    /// not jump.
    #[inline]
    fn move_stiffness(&self, state: &mut ParameterAdaptiveState<S>, factor: S) {
        let old = state.stiffness.factor;
        let new = factor.max(self.stiffness_low).min(self.stiffness_high);
        state.stiffness.factor = new;
        state.z = state.z * old / new;
    }

    /// `F^ = sigma0 z + mu^ |τ| ζ + sigma1 dz/dt + sigma2^ v` from the
    /// state and the step's `dz/dt` (0 when holding).
    #[inline]
    fn force(&self, state: &ParameterAdaptiveState<S>, v: S, z_dot: S) -> S {
        let cap = self.per[0].high.max(self.per[1].high) + self.per[2].high;
        let damping = (self.sigma1 * z_dot).sat(cap);
        self.sigma0_of(state) * state.z + damping + state.estimates[3] * v
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
    fn set_external_torque(&self, state: &mut Self::State, torque: S) {
        ParameterAdaptive::set_external_torque(self, state, torque);
    }
    #[inline]
    fn commanded(&self, state: &mut Self::State, command: S) {
        state.torque = (self.torque_constant * command - state.external).sat(self.torque_limit);
    }

    /// The estimates restart at this law's nominal values (the new model is
    /// the new nominal), the stiffness factor at 1; the elastic force
    /// `κ sigma0 z` is kept (`z = z_old κ_old sigma0_old / sigma0`) within
    /// the nominal `max(Fc+, Fc-) + Ds + mu |τ|`; the last error and the
    /// torques are kept (within this law's torque limit).
    fn carry_over(&self, old: &Self, state: &mut Self::State) {
        let torque = state.torque.sat(self.torque_limit);
        let fresh = self.initial();
        let [fc_pos, fc_neg, excess, _, load] = fresh.estimates;
        let level = fc_pos.max(fc_neg) + excess + load * torque.abs();
        // the old law's stiffness factor is part of its elastic force
        let factor = if state.started.get() {
            state.stiffness.factor.to_f64()
        } else {
            1.0
        };
        let ratio = old.sigma0.to_f64() * factor / self.sigma0.to_f64();
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

/// The stiffness law stops once `ζ sign v` passes it: the bristle slides.
const CROSSED: f64 = 0.98;

/// A crossing starts only where `ζ sign v` is below `-REVERSED` at the
/// reversal.
const REVERSED: f64 = 0.5;

/// The stiffness law learns only while the sliding samples' mean
/// mismatch is below this fraction of the level.
const SETTLED: f64 = 0.1;

/// The stricter bound on a sample's miss from the nominal curve: it counts
/// as `SETTLED / NOMINAL_SETTLED` times its miss where that is the smaller
/// (the levels are known right though the tracking law's estimates have
/// taken up a stiffness error).
const NOMINAL_SETTLED: f64 = 0.02;

/// The weight of each sliding sample in that mean.
const MISMATCH_BLEND: f64 = 1.0 / 16.0;

/// The stiffness law learns only where the bristle moves less than this
/// fraction of its deflection at the level at rest, `g / (κ sigma0)`, in
/// a period.
const RESOLVED: f64 = 0.25;

/// `0.74`: the peak of `(1 - u) ln(2 / (1 - u))` is `2 / e`, which
/// `0.74 (1 - u^2)` matches at its own peak.
const SENSITIVITY_PEAK: f64 = 0.74;

/// The largest relative change of the stiffness factor in one sample.
const STIFFNESS_STEP: f64 = 0.1;
