//! One module per state model.

pub mod bristle;
pub mod dahl;
pub mod elasto_plastic;
pub mod gms;
pub mod leuven;
mod list;
pub mod lugre;
pub mod reset_integrator;
pub mod xiong;
