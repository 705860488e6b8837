//! Every model's host side, one module each, behind one trait
//! ([`HostModel`]), and the one registry that lists them ([`ModelSpec`]).
//!
//! A model's module holds everything the host knows of it: its file keys
//! and their checks, the continuous-time equations for the reference solver
//! (written again from the model sheet, sharing no code with the core's
//! steps), what each experiment is expected to show, its accuracy bounds,
//! its state column names, and how to build its core stepper in each scalar.
//!
//! Adding a model: its core file, its host module here (implementing
//! [`HostParams`] and [`HostModel`]), and one entry in the core's model list
//! (`friction_core::model_list!`), which the `registry!` below reads; see
//! `docs/guide/adding-a-model.md`.

use crate::control::{Controller, Loop, ObserverRequest};
use crate::signals::Signal;
use anyhow::Result;
use friction_core::{Fixed32, FixedStepModel, FrictionModel, ParamError, Scalar};

/// The reference solution along a velocity signal, sampled.
#[derive(Clone, Debug, Default)]
pub struct ReferenceRun {
    /// Force at each sample time.
    pub force: Vec<f64>,
    /// `switching[k]`: the model switched (its force jumped) in `(t[k-1], t[k]]`.
    pub switching: Vec<bool>,
}

mod bristle;
mod dahl;
mod elasto_plastic;
mod gms;
pub(crate) mod leuven;
mod lugre;
mod reset_integrator;
mod static_maps;
mod xiong;

pub use bristle::{bristle_reference, BristleSpec, MAX_BRISTLES};
pub use gms::{gms_reference, GmsSpec, GMS_REFERENCE_STEP, MAX_ELEMENTS};
pub use leuven::{leuven_reference, LeuvenSpec, DEFAULT_MEMORY, LEUVEN_REFERENCE_STEP, MAX_MEMORY};
pub use lugre::lugre_force;
pub use xiong::XiongSpec;

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

/// Boxes a built core model at rest, with its state column names and reader.
pub(crate) fn boxed<M, S>(
    model: M,
    names: &[&str],
    read: fn(&M::State) -> Vec<f64>,
) -> Box<dyn Stepper>
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

/// A core model's fixed-step form in Q16.16 fixed point, stepped from `f64`
/// inputs. Every `h` is taken to be the period it was built for (the
/// caller checks that steps are uniform); `h = 0`, the first sample, and a
/// non-finite `v` return the held force without stepping.
struct FixedCore<M: FixedStepModel<Fixed32>> {
    model: M,
    state: M::State,
    names: Vec<String>,
    read: fn(&M::State) -> Vec<f64>,
}

impl<M: FixedStepModel<Fixed32>> Stepper for FixedCore<M> {
    fn step(&mut self, v: f64, h: f64) -> f64 {
        if h == 0.0 || !v.is_finite() {
            return self.model.hold_force(&self.state).to_f64();
        }
        self.model
            .step(&mut self.state, Fixed32::from_f64(v))
            .to_f64()
    }
    fn state_names(&self) -> Vec<String> {
        self.names.clone()
    }
    fn states(&self) -> Vec<f64> {
        (self.read)(&self.state)
    }
}

/// Boxes a built fixed-point fixed-step model at rest (see `FixedCore`).
pub(crate) fn boxed_fixed<M>(
    model: M,
    names: &[&str],
    read: fn(&M::State) -> Vec<f64>,
) -> Box<dyn Stepper>
where
    M: FixedStepModel<Fixed32> + 'static,
{
    Box::new(FixedCore {
        model,
        state: M::State::default(),
        names: names.iter().map(|n| n.to_string()).collect(),
        read,
    })
}

/// Builds a core stepper in the chosen scalar from a function generic over it.
macro_rules! in_scalar {
    ($scalar:expr, $build:ident ( $($arg:expr),* )) => {
        match $scalar {
            $crate::models::ScalarKind::F32 => $build::<f32>($($arg),*),
            $crate::models::ScalarKind::F64 => $build::<f64>($($arg),*),
        }
    };
}
pub(crate) use in_scalar;

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

/// An expectation: `Some(true)` the model shows the phenomenon, `Some(false)`
/// it does not, `None` not judged.
pub type Expect = Option<bool>;
/// Expected.
pub const Y: Expect = Some(true);
/// Not expected.
pub const N: Expect = Some(false);
/// Not judged (figures reported only).
pub const U: Expect = None;

/// What a model is known to show, one named field per experiment (each
/// experiment of `crate::experiments::LIST` reads its own).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Expectations {
    /// `stribeck`: the steady state is the model's map (for the bristle
    /// model: its sliding mean).
    pub stribeck: Expect,
    /// `presliding`: hysteresis before sliding.
    pub presliding: Expect,
    /// `frictional-lag`: the force lags a varying velocity.
    pub frictional_lag: Expect,
    /// `breakaway`: the break-away force varies with the force rate.
    pub breakaway: Expect,
    /// `stick-slip`: stick-slip on a spring.
    pub stick_slip: Expect,
    /// `drift`: creep under a force cycling below break-away.
    pub drift: Expect,
    /// `rate-independence`: the hysteresis loops do not depend on the rate.
    pub rate_independence: Expect,
    /// `nonlocal-memory`: the force depends on past turning points.
    pub nonlocal_memory: Expect,
}

impl Expectations {
    /// The steady curve expected, nothing else judged (the default).
    pub const STEADY_CURVE_ONLY: Self = Self {
        stribeck: Y,
        presliding: U,
        frictional_lag: U,
        breakaway: U,
        stick_slip: U,
        drift: U,
        rate_independence: U,
        nonlocal_memory: U,
    };
}

/// Everything the host knows of one model.
pub trait HostModel {
    /// Validates the parameters (the core's checks), naming the offending one.
    fn validate(&self) -> Result<(), ParamError>;
    /// The core's model in the given scalar, at rest.
    fn stepper(&self, scalar: ScalarKind) -> Result<Box<dyn Stepper>, ParamError>;
    /// The core's fixed-step form in Q16.16 fixed point for period `h`, at
    /// rest; `None` where the model has no fixed-point form.
    fn fixed_stepper(&self, _h: f64) -> Option<Result<Box<dyn Stepper>, ParamError>> {
        None
    }
    /// The static friction level: the largest force the model holds at rest.
    fn max_static_force(&self) -> f64;
    /// How far the contact deflects before it slides; 0 for static maps.
    fn presliding_scale(&self) -> f64 {
        0.0
    }
    /// The viscous coefficient `sigma2`.
    fn sigma2(&self) -> f64 {
        0.0
    }
    /// The damping of the contact at rest, `dF/dv` while it sticks:
    /// `sigma1 + sigma2` where the model has a bristle damping `sigma1` (the
    /// sum over the elements for GMS), `sigma2` by default.
    fn rest_damping(&self) -> f64 {
        self.sigma2()
    }
    /// The stiffness of the contact at rest, `dF/dx` for small
    /// displacements: `Fs / presliding_scale` by default (LuGre's `sigma0`),
    /// the sum of the element stiffnesses for the multi-element models.
    fn rest_stiffness(&self) -> f64 {
        self.max_static_force() / self.presliding_scale()
    }
    /// The Stribeck velocity `vs` of the model's curve; `None` where the
    /// model has no Stribeck curve (Dahl, the bristle model).
    fn stribeck_velocity(&self) -> Option<f64> {
        None
    }
    /// The exponent `delta` of the model's Stribeck curve, where it has one
    /// that the host can read (LuGre); `None` otherwise.
    fn stribeck_exponent(&self) -> Option<f64> {
        None
    }
    /// The time constant with which the friction force follows the curve
    /// while sliding at speed `v` (frictional lag). Default: the bristle
    /// relaxation of LuGre, `g(v) / (sigma0 |v|)`, taken as
    /// `presliding_scale / |v|`.
    fn lag_time(&self, v: f64) -> f64 {
        self.presliding_scale() / v.abs()
    }
    /// Whether the model has internal state.
    fn has_state(&self) -> bool {
        true
    }
    /// The continuous-time equations for the reference solver, if any.
    fn continuous(&self) -> Option<Box<dyn Continuous>>;
    /// A reference of its own along a velocity signal (event-driven models),
    /// used instead of integrating [`HostModel::continuous`].
    fn own_reference(&self, _signal: &Signal, _t: &[f64]) -> Option<ReferenceRun> {
        None
    }
    /// The steady-state force at constant `v` the core must reach.
    fn steady_force(&self, v: f64) -> f64 {
        self.continuous().map_or(f64::NAN, |c| c.steady_force(v))
    }
    /// Whether the steady state is the mean of a random force.
    fn stochastic(&self) -> bool {
        false
    }
    /// What the model is known to show in each experiment.
    fn expectations(&self) -> Expectations {
        Expectations::STEADY_CURVE_ONLY
    }
    /// RMS force error bound (fraction of the static force) against the
    /// reference at step `h` (1 or 10 kHz); `None`: reported, not judged.
    fn accuracy_bound(&self, _h: f64) -> Option<f64> {
        None
    }
    /// The sliding friction at high speed less its viscous part (`fc` for
    /// Stribeck-shaped models, `sigma0 z0 g/Fs` for the reset integrator,
    /// the sliding mean for the bristle model): the level of a Coulomb
    /// feed-forward built from the model.
    fn coulomb_level(&self) -> f64 {
        let v = friction_core::VELOCITY_LIMIT;
        self.steady_force(v) - self.sigma2() * v
    }
    /// The drift experiment's default peak force.
    fn drift_force(&self) -> f64 {
        0.5 * self.max_static_force()
    }
    /// Why a mass `mass` on this contact, loaded by a force ramp at `rate`
    /// from rest, does not creep quasi-statically until it breaks away (the
    /// premise of the break-away experiment), if it does not; `None` where
    /// it does or the model does not say.
    fn unstable_creep(&self, _mass: f64, _rate: f64) -> Option<String> {
        None
    }
    /// Parameter sets `friction validate` measures beside this one when it
    /// is the model's primary set (e.g. LuGre's static maps and its `vd`
    /// form, Dahl's quadratic form), each with its label suffix.
    fn validation_variants(&self) -> Vec<Variant> {
        Vec::new()
    }
    /// Whether `friction validate` measures the set itself, or only its
    /// [`validation_variants`](HostModel::validation_variants).
    fn validates_itself(&self) -> bool {
        true
    }
    /// Whether the force jumps (a bond breaking, a bristle snapping), so
    /// that an RMS over all samples is mostly a count of misplaced jumps:
    /// `friction validate` then reports the model's figures without
    /// judging them.
    fn switching(&self) -> bool {
        false
    }
    /// Whether `friction validate` plots the core against the reference at
    /// 1 kHz when this is the model's primary set (one model of each kind).
    fn validation_plots(&self) -> bool {
        false
    }
    /// The model's other shipped sets `friction validate` measures beside
    /// the primary one (reported, not judged), in order.
    fn reported_sets(&self) -> &'static [&'static str] {
        &[]
    }
    /// The core observer around this model (plain or θ-adaptive, as
    /// `request` says) with its friction level scaled by `request.scale`,
    /// in the loop `setup`; `None` where the model has no observer form.
    fn observer_controller(
        &self,
        _setup: &Loop,
        _request: &ObserverRequest,
    ) -> Option<Result<Box<dyn Controller>, ParamError>> {
        None
    }
}

/// A parameter set derived from a model's primary set for the validation.
#[derive(Clone, Debug)]
pub struct Variant {
    /// Appended to the set's label (`+vd`, ` delta=2`, ` N=8`; empty for
    /// another model on the same curve).
    pub suffix: String,
    /// The model.
    pub spec: ModelSpec,
    /// Judged against its accuracy bound (otherwise reported).
    pub bounded: bool,
    /// Core-against-reference plots at 1 kHz.
    pub plots: bool,
}

/// What the host adds to a core parameter type of the model list: the
/// type it keeps the model's parameters in (the core's own, or a spec that
/// picks the element count at run time) and the reader of its file keys.
/// Each model's host module implements it beside [`HostModel`].
pub trait HostParams {
    /// The parameters as the host keeps them ([`ModelSpec`]'s variant).
    type Spec: HostModel + Clone + std::fmt::Debug + PartialEq;
    /// Parses the model's keys from a parameter file's text; `name` is the
    /// list's `model = "..."` name, for the error messages (the list is the
    /// one place it is written).
    fn parse(text: &str, origin: &str, name: &'static str) -> Result<Self::Spec>;
}

/// The capacities the list's core types are named with; the host picks the
/// count at run time up to these (see [`HostParams::Spec`]).
#[allow(dead_code)] // the host reads the list's parameter types only
const BRISTLES: usize = MAX_BRISTLES;
#[allow(dead_code)]
const ELEMENTS: usize = MAX_ELEMENTS;
#[allow(dead_code)]
const MEMORY: usize = MAX_MEMORY;

/// `$name` (a helper of `registry!`: a repetition that `$form` drives
/// yields the name of each model that has the form).
macro_rules! named {
    ($name:literal, $($form:tt)*) => {
        $name
    };
}

/// The host's reading of the core's model list (`friction_core::model_list!`):
/// [`ModelSpec`], [`MODEL_NAMES`], [`FIXED_POINT_MODELS`], [`PARAM_SETS`],
/// [`MODEL_SETS`], the parser dispatch and the model names. A model's host
/// module implements [`HostParams`] and [`HostModel`] for it; nothing else
/// here names a model.
macro_rules! registry {
    ($(
        $(#[$doc:meta])* $variant:ident = $name:literal {
            params: $params:ty,
            field: $field:ident,
            $(map: $map:ty,)?
            $(variable: $variable:ty,)?
            $(fixed: $fixed:ty,)?
            sets: [$($set:literal),* $(,)?],
        }
    )*) => {
        /// A model of the library with its parameters.
        #[derive(Clone, Debug, PartialEq)]
        pub enum ModelSpec {
            $($(#[$doc])* $variant(<$params as HostParams>::Spec),)*
        }

        /// The model names a file may give.
        pub const MODEL_NAMES: &[&str] = &[$($name),*];

        /// The models with a fixed-point (fixed-step) form.
        pub const FIXED_POINT_MODELS: &[&str] = &[$($(named!($name, $fixed),)?)*];

        /// Each model's parameter sets shipped in `params/`, its primary set
        /// first (none for a static map validated on another model's curve).
        pub const MODEL_SETS: &[(&str, &[&str])] = &[$(($name, &[$($set),*]),)*];

        /// The parameter sets shipped with the project (`params/`), embedded
        /// so that `validate` needs no files.
        pub const PARAM_SETS: &[(&str, &str)] = &[$($(
            ($set, include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/../params/", $set, ".toml"))),
        )*)*];

        impl ModelSpec {
            /// The host side of the model.
            pub fn host(&self) -> &dyn HostModel {
                match self {
                    $(Self::$variant(p) => p,)*
                }
            }

            /// The `model = "..."` name.
            pub fn name(&self) -> &'static str {
                match self {
                    $(Self::$variant(_) => $name,)*
                }
            }

            /// Parses the model's keys from a parameter file's text.
            pub fn parse(name: &str, text: &str, origin: &str) -> Result<Self> {
                match name {
                    $($name => Ok(Self::$variant(<$params as HostParams>::parse(text, origin, $name)?)),)*
                    other => anyhow::bail!(
                        "{origin}: unknown model `{other}` (expected one of {})",
                        MODEL_NAMES.join(", ")
                    ),
                }
            }
        }
    };
}

friction_core::model_list!(registry);

impl ModelSpec {
    /// See [`HostModel::fixed_stepper`]; an error names the model when it
    /// has no fixed-point form.
    pub fn fixed_stepper(&self, h: f64) -> anyhow::Result<Box<dyn Stepper>> {
        match self.host().fixed_stepper(h) {
            Some(built) => Ok(built?),
            None => anyhow::bail!(
                "model `{}` has no fixed-point form (`--scalar fixed` runs {})",
                self.name(),
                FIXED_POINT_MODELS.join(", ")
            ),
        }
    }
}

/// `fc` and `fs` of a Stribeck curve times `scale`.
pub(crate) fn scaled_curve(
    c: &friction_core::StribeckParams,
    scale: f64,
) -> friction_core::StribeckParams {
    let mut c = *c;
    c.fc *= scale;
    c.fs *= scale;
    c
}

/// `g(v) = Fc + (Fs - Fc) exp(-|v/vs|^delta)`.
pub(crate) fn stribeck(fc: f64, fs: f64, vs: f64, delta: f64, v: f64) -> f64 {
    fc + (fs - fc) * (-(v / vs).abs().powf(delta)).exp()
}

/// `g(v)` of a core curve's parameters.
pub(crate) fn curve_g(c: &friction_core::StribeckParams, v: f64) -> f64 {
    stribeck(c.fc, c.fs, c.vs, c.exponent, v)
}

/// `sign(v)`: -1, 0 or 1 (0 at zero and for NaN): the core's
/// [`Scalar::sign`](friction_core::Scalar::sign), so that the host's
/// references and fits take the sign exactly as the core's models do.
#[inline]
pub(crate) fn sign(v: f64) -> f64 {
    friction_core::Scalar::sign(v)
}

/// Declares a model's file struct: its own keys, `deny_unknown_fields`, and
/// the tables every parameter file may carry (`[rig]`, `[servo]`,
/// `[plant]`, `[commission]`), which their own readers parse.
macro_rules! model_file {
    ($name:ident { $($(#[$fm:meta])* $field:ident : $ty:ty),* $(,)? }) => {
        #[derive(serde::Deserialize)]
        #[serde(deny_unknown_fields)]
        struct $name {
            $($(#[$fm])* $field: $ty,)*
            #[allow(dead_code)]
            model: String,
            #[serde(default)]
            #[allow(dead_code)]
            rig: Option<serde::de::IgnoredAny>,
            #[serde(default)]
            #[allow(dead_code)]
            servo: Option<serde::de::IgnoredAny>,
            #[serde(default)]
            #[allow(dead_code)]
            plant: Option<serde::de::IgnoredAny>,
            #[serde(default)]
            #[allow(dead_code)]
            commission: Option<serde::de::IgnoredAny>,
        }
    };
}
pub(crate) use model_file;

/// Deserializes a model file struct, the error naming the origin and model.
pub(crate) fn from_toml<T: serde::de::DeserializeOwned>(
    text: &str,
    origin: &str,
    model: &str,
) -> Result<T> {
    use anyhow::Context;
    toml::from_str(text).with_context(|| format!("{origin}: invalid `{model}` parameters"))
}

/// The default Stribeck exponent for file structs.
pub(crate) fn default_exponent() -> f64 {
    friction_core::StribeckParams::DEFAULT_EXPONENT
}
