//! The controller of each row ([`build_controller`]) and the compensations
//! it is built from: the static feed-forward, the observer's nominal
//! model, the adaptive laws, the supervisor and the least squares.

use super::rows::{Law, Row};
use crate::control::{controller, controller_reading, Controller, Fallback, Loop, ObserverRequest};
use crate::models::ModelSpec;
use crate::params::servo::ServoConfig;
use anyhow::Result;
use friction_core::{
    AdaptiveParams, CoulombViscousParams, FeedForward, LuGreParams, NoCompensation, ParamError,
    ParameterAdaptiveParams, ParameterAdaptiveState, RlsParams, StribeckParams, SupervisorParams,
};

/// The adaptation of the θ-adaptive rows: `gamma = a kc kp / Fs^2` from
/// `adaptation_rate` and the static force `Fs` of the compensator's own
/// (possibly mis-scaled) model, and `gamma_derivative = w gamma kd / kp`
/// (`w`: `adaptation_derivative`, default 1), so
/// that θ^ follows the composite error `s = de/dt + (kp / kd) e` of the
/// loop's PD part; with the file's leakage and bounds.
pub fn adaptation(cfg: &ServoConfig, static_force: f64) -> AdaptiveParams {
    let gamma = AdaptiveParams::gain_for_rate(
        cfg.adaptation_rate,
        cfg.kp,
        cfg.torque_constant,
        static_force,
    );
    AdaptiveParams {
        gamma,
        // the composite error s = de/dt + (kp / kd) e of the loop's PD part
        gamma_derivative: if cfg.kp > 0.0 {
            cfg.adaptation_derivative * gamma * cfg.kd / cfg.kp
        } else {
            0.0
        },
        leakage: cfg.adaptation_leakage,
        theta0: 1.0,
        theta_min: cfg.theta_min,
        theta_max: cfg.theta_max,
    }
}

/// The static feed-forward of a row at `scale`: `scale Fc sign(v) + sigma2 v`
/// (also the Python package's supervisor fallback).
pub fn static_map(spec: &ModelSpec, scale: f64) -> CoulombViscousParams {
    CoulombViscousParams {
        fc: scale * spec.host().coulomb_level(),
        sigma2: spec.host().sigma2(),
    }
}

/// The supervisor of the adaptive rows, falling back to the static map at
/// the row's scale; `None` when the file turns it off.
fn fallback(cfg: &ServoConfig, spec: &ModelSpec, scale: f64) -> Option<Fallback> {
    cfg.supervisor.then(|| Fallback {
        params: SupervisorParams {
            window: cfg.supervisor_window,
            tolerance: supervisor_tolerance(cfg, spec),
            ..SupervisorParams::DEFAULT
        },
        map: static_map(spec, scale),
    })
}

/// The prediction error the supervisor cannot tell from zero: 1 % of the
/// nominal Coulomb level, or the encoder's rounding as a window's mean
/// friction, `2 J q / (h window)` (one count `q` at each end of the window),
/// whichever is larger.
fn supervisor_tolerance(cfg: &ServoConfig, spec: &ModelSpec) -> f64 {
    let count = if cfg.encoder_counts > 0.0 {
        2.0 * std::f64::consts::PI / cfg.encoder_counts
    } else {
        0.0
    };
    let rounding = 2.0 * cfg.inertia * count * cfg.rate / cfg.supervisor_window;
    (0.01 * spec.host().coulomb_level()).max(rounding)
}

/// The LuGre model the per-parameter law starts from: the model's own
/// levels times `scale` (its Coulomb level, static force, Stribeck
/// velocity and exponent), its rest stiffness times `stiffness` as
/// `sigma0`, its rest damping less `sigma2` as `sigma1`. For LuGre this is
/// the model itself; for the others the LuGre model with the same static
/// curve and the same contact at rest.
pub fn lugre_nominal(spec: &ModelSpec, scale: f64, stiffness: f64) -> LuGreParams {
    let host = spec.host();
    let fc = scale * host.coulomb_level();
    let fs = (scale * spec.host().max_static_force()).max(fc);
    let sigma2 = spec.host().sigma2();
    let rest = spec.host().rest_stiffness();
    LuGreParams {
        curve: StribeckParams {
            fc,
            fs,
            vs: spec.host().stribeck_velocity().unwrap_or(1.0),
            exponent: host.stribeck_exponent().unwrap_or(2.0),
        },
        // a model without a finite stiffness at rest (none here) deflects
        // by a thousandth of a unit before it slides
        sigma0: stiffness
            * if rest.is_finite() && rest > 0.0 {
                rest
            } else {
                fs / 1e-3
            },
        sigma1: (spec.host().rest_damping() - sigma2).max(0.0),
        sigma2,
        vd: None,
    }
}

/// The per-parameter adaptation of the `adaptive` rows around `model`,
/// from the file's settings: its rate, the θ law's derivative weight and
/// leakage, the box factor, the dead zone (default one encoder count), the
/// nominal load coefficient and its bound; LuGre's exact step (the
/// implicit one rings at a stiff bristle's break-away: `docs/guide/servo.md`).
pub fn parameter_adaptation(cfg: &ServoConfig, model: LuGreParams) -> ParameterAdaptiveParams {
    ParameterAdaptiveParams {
        exact_step: true,
        rate: cfg.parameter_rate,
        stiffness_rate: cfg.stiffness_rate,
        derivative_weight: cfg.adaptation_derivative,
        leakage: cfg.adaptation_leakage,
        box_factor: cfg.adaptation_box,
        dead_zone: cfg.dead_zone,
        speed: cfg.peak_speed(),
        load: cfg.adaptation_load,
        load_max: cfg.load_max,
        ..ParameterAdaptiveParams::new(model, cfg.observer_gain)
    }
}

/// The names of the per-parameter rows' adapted quantities: the
/// estimates, the stiffness factor, then `mode` (last: Python reads the
/// unsupervised law's as the rest).
pub const PARAMETER_NAMES: [&str; 7] = [
    "fc_pos",
    "fc_neg",
    "stribeck",
    "sigma2",
    "load",
    "stiffness",
    "mode",
];

/// The least-squares feed-forward of the `rls` row.
pub fn least_squares(cfg: &ServoConfig) -> RlsParams {
    RlsParams {
        forgetting: cfg.rls_forgetting,
        min_speed: cfg.rls_min_speed,
        offset: cfg.rls_offset,
        ..RlsParams::new(cfg.peak_speed(), cfg.torque_constant * cfg.limit)
    }
}

/// The controller of `row`, or `None` where the model has no observer form.
pub fn build_controller(
    cfg: &ServoConfig,
    spec: &ModelSpec,
    row: Row,
) -> Option<Result<Box<dyn Controller>>> {
    let setup = Loop {
        params: cfg.controller(),
        velocity_filter: (cfg.velocity_filter > 0.0).then_some(cfg.velocity_filter),
        velocity_observer: (cfg.velocity_observer > 0.0).then_some(cfg.velocity_observer),
    };
    let built = match row {
        Row::NoFriction | Row::None => controller(&setup, NoCompensation),
        Row::Static { scale } => match static_map(spec, scale).build::<f64>() {
            Ok(map) => controller(&setup, FeedForward(map)),
            Err(e) => Err(e),
        },
        Row::Observer {
            scale,
            stiffness,
            damping,
        } => {
            let request = ObserverRequest {
                scale,
                stiffness,
                gain: cfg.observer_gain,
                damping,
                adaptive: None,
                supervisor: None,
            };
            spec.host().observer_controller(&setup, &request)?
        }
        Row::Adaptive {
            scale,
            stiffness,
            law: Law::Theta,
        } => {
            let request = ObserverRequest {
                scale,
                stiffness,
                gain: cfg.observer_gain,
                damping: true,
                adaptive: Some(adaptation(cfg, scale * spec.host().max_static_force())),
                supervisor: fallback(cfg, spec, scale),
            };
            spec.host().observer_controller(&setup, &request)?
        }
        Row::Adaptive {
            scale,
            stiffness,
            law: Law::Parameters,
        } => {
            if !spec.host().has_state() {
                return None;
            }
            parameter_controller(cfg, spec, &setup, scale, stiffness)
        }
        Row::Rls => match least_squares(cfg).build::<f64>() {
            Ok(rls) => controller_reading(&setup, rls, &["fc", "sigma2"], |c, s| {
                let (fc, sigma2) = c.coefficients(s);
                vec![fc, sigma2]
            }),
            Err(e) => Err(e),
        },
    };
    Some(built.map_err(anyhow::Error::from))
}

/// The per-parameter adaptive row's controller, supervised unless the file
/// turns the supervisor off.
fn parameter_controller(
    cfg: &ServoConfig,
    spec: &ModelSpec,
    setup: &Loop,
    scale: f64,
    stiffness: f64,
) -> Result<Box<dyn Controller>, ParamError> {
    let adaptive = parameter_adaptation(cfg, lugre_nominal(spec, scale, stiffness))
        .build::<f64>(&setup.params)?;
    match fallback(cfg, spec, scale) {
        None => controller_reading(setup, adaptive, &PARAMETER_NAMES, |_, s| with_mode(s, 0.0)),
        Some(f) => controller_reading(
            setup,
            f.params
                .build(adaptive, f.map.build::<f64>()?, &setup.params)?,
            &PARAMETER_NAMES,
            |c, s| with_mode(&s.primary, f64::from(c.status(s).mode.code())),
        ),
    }
}

/// The estimates of a per-parameter state and the supervisor's mode.
fn with_mode(s: &ParameterAdaptiveState<f64>, mode: f64) -> Vec<f64> {
    let mut v = s.estimates().to_vec();
    v.push(s.stiffness());
    v.push(mode);
    v
}

/// The Coulomb level of the static feed-forward: the model's sliding
/// friction at high speed less its viscous part ([`crate::models::HostModel::coulomb_level`]).
pub fn coulomb_level(spec: &ModelSpec) -> f64 {
    spec.host().coulomb_level()
}
