//! Dahl (1968, 1976) on the host, in its force form:
//! `dF/dt = sigma v sign(y) |y|^delta`, `y = 1 - F sign(v) / Fc`.

use super::HostParams;
use super::{
    boxed, boxed_fixed, from_toml, in_scalar, model_file, sign, Continuous, Expectations,
    HostModel, ScalarKind, Stepper, N, Y,
};
use crate::control::{observer_controller, Controller, Loop, ObserverRequest};
use anyhow::Result;
use friction_core::{DahlParams, DahlState, Fixed32, ParamError, Scalar};

fn one() -> f64 {
    1.0
}

model_file!(DahlFile {
    sigma: f64,
    fc: f64,
    #[serde(default = "one")]
    delta: f64,
    #[serde(default)]
    sigma2: f64,
});

impl HostParams for DahlParams {
    type Spec = Self;
    fn parse(text: &str, origin: &str, name: &'static str) -> Result<Self> {
        let f: DahlFile = from_toml(text, origin, name)?;
        Ok(DahlParams {
            sigma: f.sigma,
            fc: f.fc,
            delta: f.delta,
            sigma2: f.sigma2,
        })
    }
}

struct DahlOde(DahlParams);

impl Continuous for DahlOde {
    fn n(&self) -> usize {
        1
    }
    fn rhs(&self, z: &[f64], v: f64, dz: &mut [f64]) {
        let p = &self.0;
        let y = 1.0 - z[0] * sign(v) / p.fc;
        dz[0] = p.sigma * v * sign(y) * y.abs().powf(p.delta);
    }
    fn force(&self, z: &[f64], v: f64) -> f64 {
        z[0] + self.0.sigma2 * v
    }
    fn atol(&self) -> Vec<f64> {
        vec![1e-9 * self.0.fc]
    }
    fn steady_force(&self, v: f64) -> f64 {
        self.0.fc * sign(v) + self.0.sigma2 * v
    }
}

fn states<S: Scalar>(s: &DahlState<S>) -> Vec<f64> {
    vec![s.f.to_f64()]
}

fn build<S: Scalar + 'static>(p: &DahlParams) -> Result<Box<dyn Stepper>, ParamError> {
    Ok(boxed::<_, S>(p.build::<S>()?, &["fh"], states::<S>))
}

impl HostModel for DahlParams {
    /// `fc` scaled; `sigma` by the stiffness factor.
    fn observer_controller(
        &self,
        setup: &Loop,
        request: &ObserverRequest,
    ) -> Option<Result<Box<dyn Controller>, ParamError>> {
        Some(observer_controller(setup, request, |s, k| {
            DahlParams {
                fc: self.fc * s,
                sigma: self.sigma * k,
                ..*self
            }
            .build()
        }))
    }
    fn validate(&self) -> Result<(), ParamError> {
        DahlParams::validate(self)
    }
    fn stepper(&self, scalar: ScalarKind) -> Result<Box<dyn Stepper>, ParamError> {
        in_scalar!(scalar, build(self))
    }
    /// `DahlFixedStep` in Q16.16 (`delta > 1` evaluates `powf`, `ln_1p`, `exp_m1` in `f32`).
    fn fixed_stepper(&self, h: f64) -> Option<Result<Box<dyn Stepper>, ParamError>> {
        Some(
            self.build_fixed_step::<Fixed32>(h)
                .map(|m| boxed_fixed(m, &["fh"], states::<Fixed32>)),
        )
    }
    fn max_static_force(&self) -> f64 {
        self.fc
    }
    fn presliding_scale(&self) -> f64 {
        self.fc / self.sigma
    }
    fn sigma2(&self) -> f64 {
        self.sigma2
    }
    fn continuous(&self) -> Option<Box<dyn Continuous>> {
        Some(Box::new(DahlOde(*self)))
    }
    /// Hysteresis and rate independence; no stiction, lag, varying break-away or stick-slip; it drifts.
    fn expectations(&self) -> Expectations {
        Expectations {
            stribeck: Y,
            presliding: Y,
            frictional_lag: N,
            breakaway: N,
            stick_slip: N,
            drift: Y,
            rate_independence: Y,
            nonlocal_memory: N,
        }
    }
    /// 3 % of Fc at 1 kHz, 1 % at 10 kHz.
    fn accuracy_bound(&self, h: f64) -> Option<f64> {
        Some(if h >= 1e-3 { 0.03 } else { 0.01 })
    }
    /// The quadratic form `delta = 2` (bounded).
    fn validation_variants(&self) -> Vec<super::Variant> {
        vec![super::Variant {
            suffix: " delta=2".into(),
            spec: super::ModelSpec::Dahl(DahlParams {
                delta: 2.0,
                ..*self
            }),
            bounded: true,
            plots: false,
        }]
    }
}
