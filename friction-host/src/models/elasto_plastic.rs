//! Elasto-plastic (Dupont et al. 2002) on the host: LuGre's keys and
//! `z_ba`, the continuous equations with `alpha(z, v)` (`|z|` in the sine).

use super::lugre::{lugre_force, parse_keys, z_state};
use super::scaled_curve;
use super::HostParams;
use super::{
    boxed, boxed_fixed, curve_g, in_scalar, sign, Continuous, Expectations, HostModel, ScalarKind,
    Stepper, N, Y,
};
use crate::control::{observer_controller, Controller, Loop, ObserverRequest};
use anyhow::{bail, Result};
use friction_core::LuGreParams;
use friction_core::{ElastoPlasticParams, Fixed32, LuGreFixedStepState, ParamError, Scalar};

impl HostParams for ElastoPlasticParams {
    type Spec = ElastoPlasticParams;
    fn parse(text: &str, origin: &str, name: &'static str) -> Result<ElastoPlasticParams> {
        let (lugre, z_ba) = parse_keys(text, origin, name, true)?;
        let Some(z_ba) = z_ba else {
            bail!("{origin}: `elasto-plastic` needs `z_ba` (the break-away deflection)");
        };
        Ok(ElastoPlasticParams { lugre, z_ba })
    }
}

/// `dz/dt = v - alpha(z, v) sigma0 |v| z / g(v)`.
struct ElastoPlasticOde(ElastoPlasticParams);

impl ElastoPlasticOde {
    fn g(&self, v: f64) -> f64 {
        curve_g(&self.0.lugre.curve, v)
    }
    fn alpha(&self, z: f64, v: f64) -> f64 {
        if sign(z) != sign(v) {
            return 0.0;
        }
        let z_max = self.g(v) / self.0.lugre.sigma0;
        let z_ba = self.0.z_ba;
        let a = z.abs();
        if a <= z_ba {
            0.0
        } else if a >= z_max {
            1.0
        } else {
            0.5 + 0.5 * (std::f64::consts::PI * (a - 0.5 * (z_max + z_ba)) / (z_max - z_ba)).sin()
        }
    }
}

impl Continuous for ElastoPlasticOde {
    fn n(&self) -> usize {
        1
    }
    fn rhs(&self, z: &[f64], v: f64, dz: &mut [f64]) {
        let p = &self.0.lugre;
        dz[0] = v - self.alpha(z[0], v) * p.sigma0 * v.abs() * z[0] / self.g(v);
    }
    fn force(&self, z: &[f64], v: f64) -> f64 {
        let mut dz = [0.0];
        self.rhs(z, v, &mut dz);
        lugre_force(&self.0.lugre, z[0], dz[0], v)
    }
    fn atol(&self) -> Vec<f64> {
        vec![1e-6 * self.0.lugre.curve.fs / self.0.lugre.sigma0]
    }
    fn steady_force(&self, v: f64) -> f64 {
        self.g(v) * sign(v) + self.0.lugre.sigma2 * v
    }
}

fn build<S: Scalar + 'static>(p: &ElastoPlasticParams) -> Result<Box<dyn Stepper>, ParamError> {
    Ok(boxed::<_, S>(p.build::<S>()?, &["z"], z_state::<S>))
}

impl HostModel for ElastoPlasticParams {
    /// `fc`, `fs` scaled; `sigma0` by the stiffness factor, `z_ba` by both
    /// (`z_ba sigma0 / fc` kept).
    fn observer_controller(
        &self,
        setup: &Loop,
        request: &ObserverRequest,
    ) -> Option<Result<Box<dyn Controller>, ParamError>> {
        Some(observer_controller(setup, request, |s, k| {
            ElastoPlasticParams {
                lugre: LuGreParams {
                    curve: scaled_curve(&self.lugre.curve, s),
                    sigma0: self.lugre.sigma0 * k,
                    ..self.lugre
                },
                z_ba: self.z_ba * s / k,
            }
            .build()
        }))
    }
    fn validate(&self) -> Result<(), ParamError> {
        ElastoPlasticParams::validate(self)
    }
    fn stepper(&self, scalar: ScalarKind) -> Result<Box<dyn Stepper>, ParamError> {
        in_scalar!(scalar, build(self))
    }
    /// `ElastoPlasticFixedStep` in Q16.16 (the state `w = sigma0 z` times its force scale).
    fn fixed_stepper(&self, h: f64) -> Option<Result<Box<dyn Stepper>, ParamError>> {
        Some(self.build_fixed_step::<Fixed32>(h).map(|m| {
            boxed_fixed(m, &["w"], |s: &LuGreFixedStepState<Fixed32>| {
                vec![s.w.to_f64()]
            })
        }))
    }
    fn max_static_force(&self) -> f64 {
        self.lugre.curve.fs
    }
    fn presliding_scale(&self) -> f64 {
        self.lugre.curve.fs / self.lugre.sigma0
    }
    fn stribeck_velocity(&self) -> Option<f64> {
        Some(self.lugre.curve.vs)
    }
    fn sigma2(&self) -> f64 {
        self.lugre.sigma2
    }
    fn rest_damping(&self) -> f64 {
        self.lugre.sigma1 + self.lugre.sigma2
    }
    fn continuous(&self) -> Option<Box<dyn Continuous>> {
        Some(Box::new(ElastoPlasticOde(*self)))
    }
    /// As LuGre, but no drift below `sigma0 z_ba`.
    fn expectations(&self) -> Expectations {
        Expectations {
            stribeck: Y,
            presliding: Y,
            frictional_lag: Y,
            breakaway: Y,
            stick_slip: Y,
            drift: N,
            rate_independence: N,
            nonlocal_memory: N,
        }
    }
    /// Plotted against the reference.
    fn validation_plots(&self) -> bool {
        true
    }
    /// 3 % at 1 kHz, 1 % at 10 kHz.
    fn accuracy_bound(&self, h: f64) -> Option<f64> {
        Some(if h >= 1e-3 { 0.03 } else { 0.01 })
    }
    /// 90 % of the elastic limit `sigma0 z_ba`, below which it must not drift.
    fn drift_force(&self) -> f64 {
        0.9 * self.lugre.sigma0 * self.z_ba
    }
}
