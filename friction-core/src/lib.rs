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

pub mod adaptive;
mod bits;
pub mod commissioning;
pub mod compensator;
#[cfg(feature = "fixed")]
pub mod fixed_point;
pub mod fixed_step;
mod gain;
pub mod load_friction;
pub mod model;
pub mod models;
pub mod observer;
pub mod parameter_adaptive;
pub mod random;
pub mod rls;
pub mod scalar;
pub mod stribeck;
pub mod supervisor;
#[cfg(test)]
mod test_rng;
#[cfg(test)]
mod test_servo;

pub use adaptive::{AdaptiveObserver, AdaptiveParams, AdaptiveState};
pub use commissioning::{
    Abort, CommissionError, Commissioned, Commissioning, CommissioningParams, CommissioningState,
    CommissioningTick, Identified, Phase, PlateauPoint,
};
pub use compensator::{
    AtPeriod, Compensation, Compensator, CompensatorParams, CompensatorState, FeedForward,
    FrictionSample, NoCompensation, Setpoint, Tick,
};
#[cfg(feature = "fixed")]
pub use fixed_point::Fixed32;
pub use fixed_step::{FixedStepModel, FixedStepObservable};
pub use load_friction::{LoadForm, LoadFriction, LoadFrictionParams};
pub use model::{FrictionModel, ParamError, PARAM_RANGE, VELOCITY_LIMIT};
pub use models::bristle::{Bristle, BristleParams, BristleState};
pub use models::dahl::{Dahl, DahlAt, DahlParams, DahlState};
pub use models::elasto_plastic::{ElastoPlastic, ElastoPlasticAt, ElastoPlasticParams};
pub use models::gms::{Gms, GmsAt, GmsElement, GmsParams, GmsState, SlipMode};
pub use models::leuven::{Leuven, LeuvenParams, LeuvenState, Reversal};
pub use models::lugre::{LuGre, LuGreAt, LuGreAtState, LuGreParams, LuGreState};
pub use models::reset_integrator::{ResetIntegrator, ResetIntegratorParams, ResetIntegratorState};
pub use models::xiong::{Xiong, XiongAt, XiongAtState, XiongElement, XiongParams, XiongState};
pub use observer::{Observable, Observer};
pub use parameter_adaptive::{
    ParameterAdaptive, ParameterAdaptiveAt, ParameterAdaptiveAtState, ParameterAdaptiveParams,
    ParameterAdaptiveState,
};
pub use rls::{RlsFeedForward, RlsParams, RlsState};
pub use scalar::{Conversion, Scalar};
pub use stribeck::{
    AsymmetricCoulombViscous, AsymmetricCoulombViscousParams, CoulombParams, CoulombViscous,
    CoulombViscousParams, Karnopp, StribeckCurve, StribeckMap, StribeckMapParams, StribeckParams,
};
pub use supervisor::{Mode, Supervised, SupervisedState, SupervisorParams, SupervisorStatus};

/// A compensated servo tick on a fixed-step model's observer, the firmware
/// case: `Compensator<S, AtPeriod<Observer<M, S>>>` in one name.
///
/// ```
/// use friction_core::{CompensatorParams, LuGreAt, LuGreParams, Observer, ObserverServo, AtPeriod};
/// let model = LuGreParams::CANUDAS_1995.build_at::<f32>(1e-3)?;
/// let servo: ObserverServo<LuGreAt<f32>, f32> = CompensatorParams {
///     h: 1e-3, kp: 400.0, ki: 0.0, kd: 40.0, inertia: 1.0, torque_constant: 1.0, limit: 20.0,
/// }
/// .build(AtPeriod(Observer::new(model, 200.0)?))?;
/// # let _ = servo;
/// # Ok::<(), friction_core::ParamError>(())
/// ```
pub type ObserverServo<M, S> = Compensator<S, AtPeriod<Observer<M, S>>>;

/// [`ObserverServo`] on the fixed-step LuGre model.
pub type LuGreServo<S> = ObserverServo<LuGreAt<S>, S>;

/// A compensated servo tick on the θ-adaptive observer of a fixed-step
/// model: `Compensator<S, AtPeriod<AdaptiveObserver<M, S>>>`.
pub type AdaptiveServo<M, S> = Compensator<S, AtPeriod<AdaptiveObserver<M, S>>>;

/// [`AdaptiveServo`] on the fixed-step LuGre model.
pub type AdaptiveLuGreServo<S> = AdaptiveServo<LuGreAt<S>, S>;

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
/// let adaptive = ParameterAdaptiveParams::new(LuGreParams::OLSSON_1998, 20.0).build_at::<f32>(&servo)?;
/// let fallback = CoulombViscousParams { fc: 0.28, sigma2: 0.0176 }.build::<f32>()?;
/// let supervised = SupervisorParams::DEFAULT.build(adaptive, fallback, servo.h)?;
/// let ctl: ParameterAdaptiveServo<f32> = servo.build(supervised)?;
/// # let _ = ctl;
/// # Ok::<(), friction_core::ParamError>(())
/// ```
pub type ParameterAdaptiveServo<S> =
    Compensator<S, Supervised<ParameterAdaptiveAt<S>, CoulombViscous<S>, S>>;
