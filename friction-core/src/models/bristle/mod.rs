//! The bristle model (Haessig & Friedland 1991) with `N` bristles: see
//! [`Bristle`].

#[cfg(test)]
mod tests;
mod variable_step;

use crate::model::{check_force, convert, magnitude, ParamError};
use crate::random::CounterRng;
use crate::Scalar;
pub use variable_step::{Bristle, BristleState};

/// Re-bonds drawn per bristle and step by default, on average over the
/// bristles: a step draws at most `2 N` (see [`Bristle`] and
/// [`Bristle::with_snap_budget`]).
pub const BRISTLE_DEFAULT_SNAPS: u32 = 2;

/// The most re-bonds per bristle and step a budget may allow
/// ([`Bristle::with_snap_budget`] clamps to it): a step's loop is bounded
/// by `BRISTLE_MAX_SNAPS N` draws even for a stored budget C has overwritten.
pub const BRISTLE_MAX_SNAPS: u32 = 1024;

/// `per_bristle N` (`per_bristle` within `1..=BRISTLE_MAX_SNAPS`), saturating.
fn snap_budget(n: usize, per_bristle: u32) -> u32 {
    u32::try_from(n)
        .unwrap_or(u32::MAX)
        .saturating_mul(per_bristle.clamp(1, BRISTLE_MAX_SNAPS))
}

/// Bristle-model parameters (`model = "bristle"`).
///
/// ```
/// use friction_core::{BristleParams, BristleState, FrictionModel};
/// let p = BristleParams { sigma0: 1e3, delta_s: 1e-5, seed: 7 };
/// let model = p.build::<f32, 8>()?;
/// let mut state = BristleState::default();
/// let f = model.step(&mut state, 1e-3, 5e-3); // 5 µm: every bristle strained by 5 µm
/// assert!((f - 8.0 * 1e3 * 5e-6).abs() < 1e-6);
/// # Ok::<(), friction_core::ParamError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BristleParams {
    /// Stiffness of one bristle `sigma0 > 0` (N/m).
    pub sigma0: f64,
    /// Snapping deflection `delta_s > 0` (m).
    pub delta_s: f64,
    /// Seed of the re-bonding generator.
    pub seed: u64,
}

impl BristleParams {
    /// Checks every parameter; the error names the first offending one.
    pub fn validate(&self) -> Result<(), ParamError> {
        magnitude("sigma0", self.sigma0)?;
        magnitude("delta_s", self.delta_s)?;
        Ok(())
    }

    /// Validates and builds the model with `N >= 1` bristles (checked at compile time).
    pub fn build<S: Scalar, const N: usize>(&self) -> Result<Bristle<S, N>, ParamError> {
        const { assert!(N > 0, "the bristle model needs at least one bristle") };
        self.validate()?;
        check_force::<S>("sigma0", N as f64 * self.sigma0 * self.delta_s)?;
        Ok(Bristle {
            sigma0: convert("sigma0", self.sigma0)?,
            delta_s: convert("delta_s", self.delta_s)?,
            rng: CounterRng::new(self.seed),
            budget: snap_budget(N, BRISTLE_DEFAULT_SNAPS),
        })
    }
}
