//! One module per state model.

pub mod dahl;
pub mod elasto_plastic;
pub mod lugre;
