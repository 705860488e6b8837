//! One module per state model.

pub(crate) mod bristle;
pub(crate) mod dahl;
pub(crate) mod elasto_plastic;
pub(crate) mod gms;
pub(crate) mod leuven;
mod list;
pub(crate) mod lugre;
pub(crate) mod reset_integrator;
pub(crate) mod static_maps;
pub(crate) mod xiong;
