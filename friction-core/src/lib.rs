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
pub mod compensator;
#[cfg(feature = "fixed")]
pub mod fixed_point;
pub mod fixed_step;
mod gain;
pub mod model;
pub mod models;
pub mod observer;
pub mod random;
pub mod rls;
pub mod scalar;
pub mod stribeck;

pub use adaptive::{AdaptiveObserver, AdaptiveParams, AdaptiveState};
pub use compensator::{
    AtPeriod, Compensation, Compensator, CompensatorParams, CompensatorState, FeedForward,
    FrictionSample, NoCompensation, Setpoint, Tick,
};
#[cfg(feature = "fixed")]
pub use fixed_point::Fixed32;
pub use fixed_step::{FixedStepModel, FixedStepObservable};
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
pub use rls::{RlsFeedForward, RlsParams, RlsState};
pub use scalar::{Conversion, Scalar};
pub use stribeck::{
    CoulombParams, CoulombViscous, CoulombViscousParams, Karnopp, StribeckCurve, StribeckMap,
    StribeckMapParams, StribeckParams,
};
