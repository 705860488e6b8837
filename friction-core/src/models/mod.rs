//! One module per state model.

pub mod lugre;
