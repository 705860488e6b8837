//! The reset integrator (Haessig & Friedland 1991) on the host: a
//! discontinuous right-hand side for the reference solver.

use super::HostParams;
use super::{
    boxed, from_toml, in_scalar, model_file, sign, stribeck, Continuous, Expectations, HostModel,
    ScalarKind, Stepper, N, U, Y,
};
use crate::control::{observer_controller, Controller, Loop, ObserverRequest};
use anyhow::{bail, Result};
use friction_core::{
    ParamError, ResetIntegratorParams, ResetIntegratorState, Scalar, StribeckParams,
};

model_file!(ResetIntegratorFile {
    sigma0: f64,
    #[serde(default)]
    sigma1: f64,
    z0: f64,
    #[serde(default)]
    stiction: f64,
    fc: Option<f64>,
    fs: Option<f64>,
    vs: Option<f64>,
    stribeck_exponent: Option<f64>,
});

impl HostParams for ResetIntegratorParams {
    type Spec = Self;
    fn parse(text: &str, origin: &str, name: &'static str) -> Result<Self> {
        let f: ResetIntegratorFile = from_toml(text, origin, name)?;
        let curve = match (f.fc, f.fs, f.vs) {
        (Some(fc), Some(fs), Some(vs)) => Some(StribeckParams {
            fc,
            fs,
            vs,
            exponent: f
                .stribeck_exponent
                .unwrap_or(StribeckParams::DEFAULT_EXPONENT),
        }),
        (None, None, None) if f.stribeck_exponent.is_none() => None,
        _ => bail!(
            "{origin}: the Stribeck shape of `reset-integrator` needs all of `fc`, `fs`, `vs` (or none)"
        ),
    };
        Ok(ResetIntegratorParams {
            sigma0: f.sigma0,
            sigma1: f.sigma1,
            z0: f.z0,
            stiction: f.stiction,
            curve,
        })
    }
}

struct ResetIntegratorOde(ResetIntegratorParams);

impl ResetIntegratorOde {
    fn stiffness(&self, v: f64) -> f64 {
        match &self.0.curve {
            Some(c) => self.0.sigma0 * stribeck(c.fc, c.fs, c.vs, c.exponent, v) / c.fs,
            None => self.0.sigma0,
        }
    }
    fn at_limit(&self, z: f64, v: f64) -> bool {
        (v > 0.0 && z >= self.0.z0) || (v < 0.0 && z <= -self.0.z0)
    }
}

impl Continuous for ResetIntegratorOde {
    fn stop_at_samples(&self) -> bool {
        false
    }
    fn n(&self) -> usize {
        1
    }
    fn rhs(&self, z: &[f64], v: f64, dz: &mut [f64]) {
        dz[0] = if self.at_limit(z[0], v) { 0.0 } else { v };
    }
    fn force(&self, z: &[f64], v: f64) -> f64 {
        let p = &self.0;
        let a = if z[0].abs() < p.z0 { p.stiction } else { 0.0 };
        let dz = if self.at_limit(z[0], v) { 0.0 } else { v };
        (1.0 + a) * self.stiffness(v) * z[0] + p.sigma1 * dz
    }
    fn atol(&self) -> Vec<f64> {
        vec![1e-9 * self.0.z0]
    }
    fn steady_force(&self, v: f64) -> f64 {
        self.stiffness(v) * self.0.z0 * sign(v)
    }
    fn switched(&self, z0: &[f64], v0: f64, z1: &[f64], v1: f64) -> bool {
        // the bond breaks (|z| reaches z0) or the motion reverses (it re-bonds)
        let limit = self.0.z0 * (1.0 - 1e-6);
        (z0[0].abs() < limit && z1[0].abs() >= limit) || sign(v0) != sign(v1)
    }
}

fn states<S: Scalar>(s: &ResetIntegratorState<S>) -> Vec<f64> {
    vec![s.z.to_f64()]
}

fn build<S: Scalar + 'static>(p: &ResetIntegratorParams) -> Result<Box<dyn Stepper>, ParamError> {
    Ok(boxed::<_, S>(p.build::<S>()?, &["z"], states::<S>))
}

impl HostModel for ResetIntegratorParams {
    /// `sigma0` by the stiffness factor and `z0` by `scale / stiffness`, so
    /// the bond's force `sigma0 z0` scales by `scale` (a Stribeck curve only
    /// shapes `sigma0(v)` by `g(v) / Fs`).
    fn observer_controller(
        &self,
        setup: &Loop,
        request: &ObserverRequest,
    ) -> Option<Result<Box<dyn Controller>, ParamError>> {
        Some(observer_controller(setup, request, |s, k| {
            ResetIntegratorParams {
                sigma0: self.sigma0 * k,
                z0: self.z0 * s / k,
                ..*self
            }
            .build()
        }))
    }
    fn validate(&self) -> Result<(), ParamError> {
        ResetIntegratorParams::validate(self)
    }
    fn stepper(&self, scalar: ScalarKind) -> Result<Box<dyn Stepper>, ParamError> {
        in_scalar!(scalar, build(self))
    }
    fn max_static_force(&self) -> f64 {
        (1.0 + self.stiction) * self.sigma0 * self.z0
    }
    fn presliding_scale(&self) -> f64 {
        self.z0
    }
    fn rest_damping(&self) -> f64 {
        self.sigma1
    }
    fn continuous(&self) -> Option<Box<dyn Continuous>> {
        Some(Box::new(ResetIntegratorOde(*self)))
    }
    /// Stiction and stick-slip, no drift; its bond is elastic (no
    /// hysteresis), no lag, and the break-away peak rises with the rate.
    fn expectations(&self) -> Expectations {
        Expectations {
            stribeck: Y,
            presliding: N,
            frictional_lag: N,
            breakaway: N,
            stick_slip: Y,
            drift: N,
            rate_independence: U,
            nonlocal_memory: N,
        }
    }
    /// Its bond breaks and re-forms.
    fn switching(&self) -> bool {
        true
    }
    /// Plotted against the reference.
    fn validation_plots(&self) -> bool {
        true
    }
}
