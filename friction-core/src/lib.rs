#![doc = include_str!("../README.md")]
#![no_std]
#![cfg_attr(
    test,
    allow(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::indexing_slicing,
        clippy::panic
    )
)]

#[cfg(test)]
extern crate std;

mod adaptive;
mod bits;
mod commissioning;
mod compensator;
#[cfg(feature = "fixed")]
mod fixed_point;
mod fixed_step;
mod gain;
mod load_friction;
mod model;
mod models;
mod observer;
mod parameter_adaptive;
mod random;
mod rls;
mod scalar;
mod stribeck;
mod supervisor;
#[cfg(test)]
mod test_rng;
#[cfg(test)]
mod test_servo;

pub use adaptive::{AdaptiveObserver, AdaptiveParams, AdaptiveState};
pub use commissioning::{
    CommissionError, Commissioned, Commissioning, CommissioningAbort, CommissioningIdentified,
    CommissioningParams, CommissioningPhase, CommissioningState, CommissioningTick, PlateauPoint,
    COMMISSIONING_MAX_SPEEDS,
};
pub use compensator::{
    Compensation, Compensator, CompensatorParams, CompensatorState, CompensatorTick, FeedForward,
    FixedPeriod, FrictionSample, NoCompensation, Setpoint,
};
#[cfg(feature = "fixed")]
pub use fixed_point::Fixed32;
pub use fixed_step::{FixedStepModel, FixedStepObservable};
pub use load_friction::{LoadForm, LoadFriction, LoadFrictionParams};
pub use model::{FrictionModel, ParamError, PARAM_RANGE, VELOCITY_LIMIT};
pub use models::bristle::{
    Bristle, BristleParams, BristleState, BRISTLE_DEFAULT_SNAPS, BRISTLE_MAX_SNAPS,
};
pub use models::dahl::{Dahl, DahlFixedStep, DahlFixedStepState, DahlParams, DahlState};
pub use models::elasto_plastic::{
    ElastoPlastic, ElastoPlasticFixedStep, ElastoPlasticFixedStepState, ElastoPlasticParams,
    ElastoPlasticState,
};
pub use models::gms::{
    Gms, GmsElement, GmsFixedStep, GmsFixedStepState, GmsParams, GmsSlipMode, GmsState,
};
pub use models::leuven::{Leuven, LeuvenParams, LeuvenReversal, LeuvenState};
pub use models::lugre::{
    LuGre, LuGreFixedStep, LuGreFixedStepState, LuGreLoad, LuGreLoadFixedStep,
    LuGreLoadFixedStepState, LuGreLoadParams, LuGreLoadState, LuGreParams, LuGreState,
};
pub use models::reset_integrator::{ResetIntegrator, ResetIntegratorParams, ResetIntegratorState};
pub use models::static_maps::{
    AsymmetricCoulombViscous, AsymmetricCoulombViscousParams, CoulombParams, CoulombViscous,
    CoulombViscousParams, Karnopp, StribeckMap, StribeckMapParams,
};
pub use models::xiong::{
    Xiong, XiongElement, XiongFixedStep, XiongFixedStepState, XiongParams, XiongState,
};
pub use observer::{Observable, Observer};
pub use parameter_adaptive::{
    ParameterAdaptive, ParameterAdaptiveFixedStep, ParameterAdaptiveFixedStepState,
    ParameterAdaptiveParams, ParameterAdaptiveState, PARAMETER_ADAPTIVE_ESTIMATES,
};
pub use random::CounterRng;
pub use rls::{RlsFeedForward, RlsParams, RlsState};
pub use scalar::{Scalar, ScalarConversion};
pub use stribeck::{StribeckCurve, StribeckParams};
pub use supervisor::{
    Supervised, SupervisedState, SupervisorMode, SupervisorParams, SupervisorStatus,
    MIN_WINDOW_TICKS,
};

/// A compensated servo tick on a fixed-step model's observer, the firmware
/// case: `Compensator<S, FixedPeriod<Observer<M, S>>>` in one name.
///
/// ```
/// use friction_core::{CompensatorParams, LuGreFixedStep, LuGreParams, Observer, ObserverServo, FixedPeriod};
/// let model = LuGreParams::CANUDAS_1995.build_fixed_step::<f32>(1e-3)?;
/// let servo: ObserverServo<LuGreFixedStep<f32>, f32> = CompensatorParams {
///     h: 1e-3, kp: 400.0, ki: 0.0, kd: 40.0, inertia: 1.0, torque_constant: 1.0, limit: 20.0,
/// }
/// .build(FixedPeriod(Observer::new(model, 200.0)?))?;
/// # let _ = servo;
/// # Ok::<(), friction_core::ParamError>(())
/// ```
pub type ObserverServo<M, S> = Compensator<S, FixedPeriod<Observer<M, S>>>;

/// [`ObserverServo`] on the fixed-step LuGre model.
pub type LuGreServo<S> = ObserverServo<LuGreFixedStep<S>, S>;

/// A compensated servo tick on the θ-adaptive observer of a fixed-step
/// model: `Compensator<S, FixedPeriod<AdaptiveObserver<M, S>>>`.
pub type AdaptiveServo<M, S> = Compensator<S, FixedPeriod<AdaptiveObserver<M, S>>>;

/// [`AdaptiveServo`] on the fixed-step LuGre model.
pub type AdaptiveLuGreServo<S> = AdaptiveServo<LuGreFixedStep<S>, S>;

/// A compensated servo tick with a static feed-forward map `F`, e.g.
/// `FeedForwardServo<CoulombViscous<f32>, f32>`.
pub type FeedForwardServo<F, S> = Compensator<S, FeedForward<F>>;

/// The per-parameter adaptive observer's fixed-step form under its
/// supervisor, with a Coulomb + viscous map as the static fallback: the
/// compensation of `friction servo`'s `adaptive` rows, in any scalar.
///
/// ```
/// use friction_core::{CompensatorParams, CoulombViscousParams, LuGreParams,
///     ParameterAdaptiveParams, ParameterAdaptiveServo, SupervisorParams};
/// let servo = CompensatorParams { h: 1e-3, kp: 60.0, ki: 200.0, kd: 1.2,
///     inertia: 0.0023, torque_constant: 1.02, limit: 10.0 };
/// let adaptive = ParameterAdaptiveParams::new(LuGreParams::OLSSON_1998, 20.0).build_fixed_step::<f32>(&servo)?;
/// let fallback = CoulombViscousParams { fc: 0.28, sigma2: 0.0176 }.build::<f32>()?;
/// let supervised = SupervisorParams::DEFAULT.build(adaptive, fallback, &servo)?;
/// let ctl: ParameterAdaptiveServo<f32> = servo.build(supervised)?;
/// # let _ = ctl;
/// # Ok::<(), friction_core::ParamError>(())
/// ```
pub type ParameterAdaptiveServo<S> =
    Compensator<S, Supervised<ParameterAdaptiveFixedStep<S>, CoulombViscous<S>, S>>;
