//! The desk side of `friction-core`: reference solver, experiments,
//! validation report and the `friction` command-line tool.

pub mod checks;
pub mod commission;
pub mod control;
pub mod experiments;
pub mod fuzzing;
pub mod identify;
pub mod io;
pub mod models;
pub mod online;
pub mod params;
pub mod plot;
pub mod reference;
pub mod servo;
pub mod signals;
pub mod sim;
pub mod validate;
