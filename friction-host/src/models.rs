//! The two faces of every model on the host:
//!
//! - [`Stepper`]: the core's discrete step (f32 or f64), type-erased so the
//!   CLI can drive any model from a parameter file;
//! - [`Continuous`]: the continuous-time equations, written here again from
//!   the model sheet for the reference solver. They share no code with the
//!   core's steps. The bristle model has none: its state jumps at random
//!   snaps, and its reference is the event-driven `sim::bristle_reference`.

use crate::params::ModelSpec;
use friction_core::{
    Bristle, BristleParams, BristleState, DahlParams, DahlState, ElastoPlasticParams,
    FrictionModel, LuGreParams, LuGreState, ResetIntegratorParams, ResetIntegratorState, Scalar,
};

/// The number type a core model is built with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ScalarKind {
    /// 32-bit float, as on a Cortex-M4F.
    F32,
    /// 64-bit float.
    F64,
}

/// A core model with its state, stepped from `f64` inputs.
pub trait Stepper {
    /// Advances by `h` with velocity `v` held; returns the force.
    fn step(&mut self, v: f64, h: f64) -> f64;
    /// Names of the internal states (CSV columns).
    fn state_names(&self) -> Vec<String>;
    /// Current internal states.
    fn states(&self) -> Vec<f64>;
}

struct Core<M: FrictionModel<S>, S: Scalar> {
    model: M,
    state: M::State,
    names: Vec<String>,
    read: fn(&M::State) -> Vec<f64>,
    _s: std::marker::PhantomData<S>,
}

impl<M: FrictionModel<S>, S: Scalar> Stepper for Core<M, S> {
    fn step(&mut self, v: f64, h: f64) -> f64 {
        self.model
            .step(&mut self.state, S::from_f64(v), S::from_f64(h))
            .to_f64()
    }
    fn state_names(&self) -> Vec<String> {
        self.names.clone()
    }
    fn states(&self) -> Vec<f64> {
        (self.read)(&self.state)
    }
}

fn boxed<M, S>(model: M, names: &[&str], read: fn(&M::State) -> Vec<f64>) -> Box<dyn Stepper>
where
    M: FrictionModel<S> + 'static,
    S: Scalar + 'static,
{
    Box::new(Core {
        model,
        state: M::State::default(),
        names: names.iter().map(|n| n.to_string()).collect(),
        read,
        _s: std::marker::PhantomData,
    })
}

fn stepper_in<S: Scalar + 'static>(
    spec: &ModelSpec,
) -> Result<Box<dyn Stepper>, friction_core::ParamError> {
    fn no_states(_: &()) -> Vec<f64> {
        Vec::new()
    }
    fn lugre_states<S: Scalar>(s: &LuGreState<S>) -> Vec<f64> {
        vec![s.z.to_f64()]
    }
    fn dahl_states<S: Scalar>(s: &DahlState<S>) -> Vec<f64> {
        vec![s.f.to_f64()]
    }
    fn reset_states<S: Scalar>(s: &ResetIntegratorState<S>) -> Vec<f64> {
        vec![s.z.to_f64()]
    }
    fn bristle<S: Scalar + 'static, const N: usize>(
        p: &BristleParams,
    ) -> Result<Box<dyn Stepper>, friction_core::ParamError> {
        fn strains<S: Scalar, const N: usize>(s: &BristleState<S, N>) -> Vec<f64> {
            s.strain.iter().map(|x| x.to_f64()).collect()
        }
        let names: Vec<String> = (0..N).map(|i| format!("s{i}")).collect();
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        Ok(boxed::<Bristle<S, N>, S>(
            p.build::<S, N>()?,
            &names,
            strains::<S, N>,
        ))
    }
    Ok(match spec {
        ModelSpec::Coulomb(p) => boxed::<_, S>(p.build::<S>()?, &[], no_states),
        ModelSpec::CoulombViscous(p) => boxed::<_, S>(p.build::<S>()?, &[], no_states),
        ModelSpec::Stribeck(p) => boxed::<_, S>(p.build::<S>()?, &[], no_states),
        ModelSpec::LuGre(p) => boxed::<_, S>(p.build::<S>()?, &["z"], lugre_states::<S>),
        ModelSpec::Dahl(p) => boxed::<_, S>(p.build::<S>()?, &["fh"], dahl_states::<S>),
        ModelSpec::ElastoPlastic(p) => boxed::<_, S>(p.build::<S>()?, &["z"], lugre_states::<S>),
        ModelSpec::ResetIntegrator(p) => boxed::<_, S>(p.build::<S>()?, &["z"], reset_states::<S>),
        ModelSpec::Bristle { params, bristles } => match bristles {
            1 => bristle::<S, 1>(params)?,
            8 => bristle::<S, 8>(params)?,
            25 => bristle::<S, 25>(params)?,
            _ => bristle::<S, 64>(params)?,
        },
    })
}

impl ModelSpec {
    /// The core's model, built in the given scalar type, at rest.
    pub fn stepper(
        &self,
        scalar: ScalarKind,
    ) -> Result<Box<dyn Stepper>, friction_core::ParamError> {
        match scalar {
            ScalarKind::F32 => stepper_in::<f32>(self),
            ScalarKind::F64 => stepper_in::<f64>(self),
        }
    }

    /// The continuous-time equations for the reference solver; `None` for
    /// the bristle model, whose reference is event-driven (`sim::bristle_reference`).
    pub fn continuous(&self) -> Option<Box<dyn Continuous>> {
        Some(match *self {
            ModelSpec::Coulomb(p) => Box::new(StaticMap {
                fc: p.fc,
                fs: p.fc,
                vs: 1.0,
                delta: 1.0,
                sigma2: 0.0,
            }),
            ModelSpec::CoulombViscous(p) => Box::new(StaticMap {
                fc: p.fc,
                fs: p.fc,
                vs: 1.0,
                delta: 1.0,
                sigma2: p.sigma2,
            }),
            ModelSpec::Stribeck(p) => Box::new(StaticMap {
                fc: p.curve.fc,
                fs: p.curve.fs,
                vs: p.curve.vs,
                delta: p.curve.exponent,
                sigma2: p.sigma2,
            }),
            ModelSpec::LuGre(p) => Box::new(LuGreOde(p)),
            ModelSpec::Dahl(p) => Box::new(DahlOde(p)),
            ModelSpec::ElastoPlastic(p) => Box::new(ElastoPlasticOde(p)),
            ModelSpec::ResetIntegrator(p) => Box::new(ResetIntegratorOde(p)),
            ModelSpec::Bristle { .. } => return None,
        })
    }
}

/// Continuous-time friction: `dz/dt = rhs(z, v)`, `F = force(z, v)`.
pub trait Continuous {
    /// Number of internal states.
    fn n(&self) -> usize;
    /// `dz/dt`.
    fn rhs(&self, z: &[f64], v: f64, dz: &mut [f64]);
    /// The friction force.
    fn force(&self, z: &[f64], v: f64) -> f64;
    /// Absolute tolerance for each state (states are often micrometres).
    fn atol(&self) -> Vec<f64>;
    /// The steady-state force at constant velocity `v`.
    fn steady_force(&self, v: f64) -> f64;
    /// Whether the reference solver should stop at every sample time (see
    /// [`crate::reference::integrate_stopping`]); not for right-hand sides
    /// that switch at a limit, where forced stops make it fail.
    fn stop_at_samples(&self) -> bool {
        true
    }
    /// Whether the model switched (a discontinuity of its force) between two
    /// samples, given the states and velocities at both.
    fn switched(&self, _z0: &[f64], _v0: f64, _z1: &[f64], _v1: f64) -> bool {
        false
    }
}

/// `g(v) = Fc + (Fs - Fc) exp(-|v/vs|^delta)`.
fn stribeck(fc: f64, fs: f64, vs: f64, delta: f64, v: f64) -> f64 {
    fc + (fs - fc) * (-(v / vs).abs().powf(delta)).exp()
}

fn sign(v: f64) -> f64 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

struct StaticMap {
    fc: f64,
    fs: f64,
    vs: f64,
    delta: f64,
    sigma2: f64,
}

impl Continuous for StaticMap {
    fn n(&self) -> usize {
        0
    }
    fn rhs(&self, _: &[f64], _: f64, _: &mut [f64]) {}
    fn force(&self, _: &[f64], v: f64) -> f64 {
        self.steady_force(v)
    }
    fn atol(&self) -> Vec<f64> {
        Vec::new()
    }
    fn steady_force(&self, v: f64) -> f64 {
        stribeck(self.fc, self.fs, self.vs, self.delta, v) * sign(v) + self.sigma2 * v
    }
}

struct LuGreOde(LuGreParams);

/// `F = sigma0 z + sigma1(v) dz/dt + sigma2 v`, shared by LuGre and elasto-plastic.
fn lugre_force(p: &LuGreParams, z: f64, dz: f64, v: f64) -> f64 {
    let sigma1 = match p.vd {
        Some(vd) => p.sigma1 * (-(v / vd) * (v / vd)).exp(),
        None => p.sigma1,
    };
    p.sigma0 * z + sigma1 * dz + p.sigma2 * v
}

impl LuGreOde {
    fn g(&self, v: f64) -> f64 {
        let c = &self.0.curve;
        stribeck(c.fc, c.fs, c.vs, c.exponent, v)
    }
}

impl Continuous for LuGreOde {
    fn n(&self) -> usize {
        1
    }
    fn rhs(&self, z: &[f64], v: f64, dz: &mut [f64]) {
        dz[0] = v - self.0.sigma0 * v.abs() * z[0] / self.g(v);
    }
    fn force(&self, z: &[f64], v: f64) -> f64 {
        let mut dz = [0.0];
        self.rhs(z, v, &mut dz);
        lugre_force(&self.0, z[0], dz[0], v)
    }
    fn atol(&self) -> Vec<f64> {
        vec![1e-6 * self.0.curve.fs / self.0.sigma0]
    }
    fn steady_force(&self, v: f64) -> f64 {
        self.g(v) * sign(v) + self.0.sigma2 * v
    }
}

/// Dahl in its force form: `dF/dt = sigma v sign(y) |y|^delta`, `y = 1 - F sign(v) / Fc`.
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

/// Elasto-plastic: LuGre with `alpha(z, v)` (Dupont et al. 2002), `|z|` in the sine.
struct ElastoPlasticOde(ElastoPlasticParams);

impl ElastoPlasticOde {
    fn g(&self, v: f64) -> f64 {
        let c = &self.0.lugre.curve;
        stribeck(c.fc, c.fs, c.vs, c.exponent, v)
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

/// Reset integrator (Haessig & Friedland 1991): a discontinuous right-hand side.
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
