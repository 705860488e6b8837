//! What the servo (`main.rs`) and the cost benchmark (`bin/cost.rs`) share:
//! the controller's friction model, its loop and its gains, so that the
//! cost table measures the servo the example runs.

use friction_core::{
    AdaptiveParams, CommissioningParams, CompensatorParams, CoulombViscousParams, LeuvenParams,
    LuGreParams, ParameterAdaptiveParams, StribeckParams, SupervisorParams,
};

/// Olsson et al. 1998, Table 2: the controller's model of the friction (N m, rad).
pub const NOMINAL: LuGreParams = LuGreParams::OLSSON_1998;

pub const INERTIA: f32 = 0.0023; // kg m^2
pub const H: f32 = 1e-3; // 1 kHz control loop
pub const OBSERVER_GAIN: f64 = 200.0; // 1/s
pub const TORQUE_MAX: f32 = 5.0; // N m, the drive's full scale and the command limit
pub const ENCODER_COUNTS: f64 = 1_048_576.0; // per revolution: a 20-bit encoder

/// The simulated plant's "real" friction: 10-20 % away from the nominal
/// model (the servo's plant, and the one the commissioning cost rows run on).
pub const ACTUAL: LuGreParams = LuGreParams {
    curve: StribeckParams {
        fc: 0.31,
        fs: 0.38,
        vs: 0.012,
        exponent: 2.0,
    },
    sigma0: 300.0,
    sigma1: 0.7,
    sigma2: 0.02,
    vd: None,
};

/// PD (bandwidth 2 pi 10 Hz, damping 1) with acceleration feed-forward, at
/// 1 kHz, commanding a torque.
pub fn controller() -> CompensatorParams {
    let w = 2.0 * core::f64::consts::PI * 10.0;
    let j = INERTIA as f64;
    CompensatorParams {
        h: H as f64,
        kp: j * w * w,
        ki: 0.0,
        kd: 2.0 * j * w,
        inertia: j,
        torque_constant: 1.0,
        limit: TORQUE_MAX as f64,
    }
}

/// The controller's Leuven model: the nominal curve and damping, `n = 2`,
/// the virgin curve's `xs = Fs / sigma0`.
pub fn leuven_nominal() -> LeuvenParams {
    LeuvenParams {
        curve: NOMINAL.curve,
        sigma1: NOMINAL.sigma1,
        sigma2: NOMINAL.sigma2,
        n: 2.0,
        xs: NOMINAL.curve.fs / NOMINAL.sigma0,
    }
}

/// The θ-adaptive observer's adaptation for [`controller`]: θ^ converges at
/// about `ADAPTATION_RATE` (1/s) on the composite error
/// `de/dt + (kp / kd) e` (see `friction_core::adaptive`).
pub fn adaptation() -> AdaptiveParams {
    const ADAPTATION_RATE: f64 = 8.0;
    let p = controller();
    let gamma =
        AdaptiveParams::gain_for_rate(ADAPTATION_RATE, p.kp, p.torque_constant, NOMINAL.curve.fs);
    AdaptiveParams {
        gamma,
        gamma_derivative: gamma * p.kd / p.kp,
        ..AdaptiveParams::DEFAULT
    }
}

/// The per-parameter adaptive observer for [`controller`] around the
/// nominal model: the command line's default rate (16 1/s), the
/// trajectory's peak speed (0.2 rad at 0.5 Hz) as the viscous estimate's
/// reference, a load coefficient of up to 0.2 N m per N m transmitted. No
/// dead zone: the 20-bit encoder's count is below Q16.16's last place.
pub fn parameter_adaptation() -> ParameterAdaptiveParams {
    ParameterAdaptiveParams {
        rate: 16.0,
        speed: 0.2 * 2.0 * core::f64::consts::PI * 0.5,
        load_max: 0.2,
        ..ParameterAdaptiveParams::new(NOMINAL, OBSERVER_GAIN)
    }
}

/// The supervisor of the per-parameter law: the defaults, prediction
/// errors below 1 % of the nominal Coulomb level counted as equal.
pub fn supervisor() -> SupervisorParams {
    SupervisorParams {
        tolerance: 0.01 * NOMINAL.curve.fc,
        ..SupervisorParams::DEFAULT
    }
}

/// The supervisor's static fallback: Coulomb + viscous feed-forward from
/// the nominal model.
pub fn fallback() -> CoulombViscousParams {
    CoulombViscousParams {
        fc: NOMINAL.curve.fc,
        sigma2: NOMINAL.sigma2,
    }
}

/// The commissioning routine for [`controller`]'s loop on the example's
/// axis: the core's defaults for a travel window of 1 rad and a top speed
/// of 2 rad/s (three times the trajectory's peak), the encoder's count, and
/// the slowest plateau where a block of 8 ticks spans 4 counts (slower
/// plateaus are too coarse for the steadiness test), as `friction
/// commission` chooses it.
pub fn commissioning() -> CommissioningParams {
    let count = core::f64::consts::TAU / ENCODER_COUNTS;
    let p = CommissioningParams::new(controller(), 1.0, 2.0);
    CommissioningParams {
        resolution: count,
        min_speed: (p.max_speed / 1000.0).max(count / (2.0 * p.servo.h)),
        ..p
    }
}
