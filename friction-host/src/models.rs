//! The two faces of every model on the host:
//!
//! - [`Stepper`]: the core's discrete step (f32 or f64), type-erased so the
//!   CLI can drive any model from a parameter file;
//! - [`Continuous`]: the continuous-time equations, written here again from
//!   the model sheet for the reference solver. They share no code with the
//!   core's steps.

use crate::params::ModelSpec;
use friction_core::{DahlParams, DahlState, FrictionModel, LuGreParams, LuGreState, Scalar};

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
    fn state_names(&self) -> &'static [&'static str];
    /// Current internal states.
    fn states(&self) -> Vec<f64>;
}

struct Core<M: FrictionModel<S>, S: Scalar> {
    model: M,
    state: M::State,
    names: &'static [&'static str],
    read: fn(&M::State) -> Vec<f64>,
    _s: std::marker::PhantomData<S>,
}

impl<M: FrictionModel<S>, S: Scalar> Stepper for Core<M, S> {
    fn step(&mut self, v: f64, h: f64) -> f64 {
        self.model
            .step(&mut self.state, S::from_f64(v), S::from_f64(h))
            .to_f64()
    }
    fn state_names(&self) -> &'static [&'static str] {
        self.names
    }
    fn states(&self) -> Vec<f64> {
        (self.read)(&self.state)
    }
}

fn boxed<M, S>(
    model: M,
    names: &'static [&'static str],
    read: fn(&M::State) -> Vec<f64>,
) -> Box<dyn Stepper>
where
    M: FrictionModel<S> + 'static,
    S: Scalar + 'static,
{
    Box::new(Core {
        model,
        state: M::State::default(),
        names,
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
    Ok(match spec {
        ModelSpec::Coulomb(p) => boxed::<_, S>(p.build::<S>()?, &[], no_states),
        ModelSpec::CoulombViscous(p) => boxed::<_, S>(p.build::<S>()?, &[], no_states),
        ModelSpec::Stribeck(p) => boxed::<_, S>(p.build::<S>()?, &[], no_states),
        ModelSpec::LuGre(p) => boxed::<_, S>(p.build::<S>()?, &["z"], lugre_states::<S>),
        ModelSpec::Dahl(p) => boxed::<_, S>(p.build::<S>()?, &["fh"], dahl_states::<S>),
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

    /// The continuous-time equations for the reference solver.
    pub fn continuous(&self) -> Box<dyn Continuous> {
        match *self {
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
        }
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
        let p = &self.0;
        let mut dz = [0.0];
        self.rhs(z, v, &mut dz);
        let sigma1 = match p.vd {
            Some(vd) => p.sigma1 * (-(v / vd) * (v / vd)).exp(),
            None => p.sigma1,
        };
        p.sigma0 * z[0] + sigma1 * dz[0] + p.sigma2 * v
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
