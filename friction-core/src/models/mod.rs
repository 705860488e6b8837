//! One module per state model.

pub mod dahl;
pub mod lugre;
