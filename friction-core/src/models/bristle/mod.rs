//! The bristle model (Haessig & Friedland 1991) with `N` bristles.
//!
//! ```text
//! F = sum_i sigma0 (x - b_i)
//! ```
//!
//! Bristle `i` is bonded at `b_i`; its strain `s_i = x - b_i` follows the
//! displacement. When `|s_i|` reaches the snapping deflection `delta_s` the
//! bond breaks and re-bonds at a random place: the new strain is uniform in
//! `(-delta_s, delta_s)`, drawn from a seeded [`CounterRng`] (stream `i`,
//! index = the bristle's re-bond count), so runs repeat exactly.
//!
//! What the randomness does: from rest all bristles load together, so the
//! first break-away peak is `N sigma0 delta_s`; after that the snaps are
//! spread out and the force fluctuates around its sliding mean
//! `N sigma0 delta_s / 3` (a re-bonded strain is uniform, then grows to
//! `delta_s`: its mean over a cycle is `delta_s / 3`). The relative
//! fluctuation falls like `1/sqrt(N)` (measured by `friction validate`).
//! No damping: a sticking mass oscillates on the bristles (the model's known
//! drawback), and the force jumps at every snap.
//!
//! Discretisation: with `v` held the step moves every strain by `v h` and
//! handles each snap inside the step, in order along the displacement:
//! exact for held `v` while the step needs at most `2 N` snaps in all (the
//! default budget; [`Bristle::with_snap_budget`] sets another). The
//! work per step is bounded there (issue 19: a real-time step is sized by
//! its worst case): once the budget is drawn, a bristle whose travel
//! would snap it again ends the step held at its snapping deflection
//! `±delta_s` and snaps with the next step's travel (a reversal unloads it
//! from there: that snap is lost). Bristles are served in index order. A
//! re-bonded strain is uniform, so a bristle travels `delta_s` between snaps
//! on average: the bound bites when `|v| h` approaches `2 delta_s` (for
//! haessig1991-bristle, 20 mm/s at 1 kHz, 0.2 m/s at 10 kHz), where held
//! bristles raise the force towards `N sigma0 delta_s`. A draw is a 32-bit
//! counter-based hash (`crate::random`), cheap beside the step on a
//! Cortex-M.
//!
//! `N` must be at least 1:
//!
//! ```compile_fail
//! use friction_core::BristleParams;
//! let p = BristleParams { sigma0: 1e3, delta_s: 1e-5, seed: 1 };
//! let m = p.build::<f32, 0>(); // error: N = 0 bristles
//! ```

#[cfg(test)]
mod tests;
mod variable_step;

use crate::model::{check_force, convert, magnitude, ParamError};
use crate::random::CounterRng;
use crate::Scalar;
pub use variable_step::{Bristle, BristleState};

/// Re-bonds drawn per bristle and step by default, on average over the
/// bristles: a step draws at most `2 N` (see the module docs and
/// [`Bristle::with_snap_budget`]).
pub const DEFAULT_SNAPS: u32 = 2;

/// The most re-bonds per bristle and step a budget may allow
/// ([`Bristle::with_snap_budget`] clamps to it): a step's loop is bounded
/// by `MAX_SNAPS N` draws even for a stored budget C has overwritten.
pub const MAX_SNAPS: u32 = 1024;

/// `per_bristle N` (`per_bristle` within `1..=MAX_SNAPS`), saturating.
fn snap_budget(n: usize, per_bristle: u32) -> u32 {
    u32::try_from(n)
        .unwrap_or(u32::MAX)
        .saturating_mul(per_bristle.clamp(1, MAX_SNAPS))
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
            budget: snap_budget(N, DEFAULT_SNAPS),
        })
    }
}
