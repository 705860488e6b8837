//! The bristle model: [`Bristle`] and [`BristleState`].

use super::{snap_budget, BRISTLE_MAX_SNAPS};
use crate::model::{checked_inputs, FrictionModel};
use crate::observer::Observable;
use crate::random::CounterRng;
use crate::Scalar;

/// The built bristle model with `N` bristles.
///
/// The bristle model (Haessig & Friedland 1991) with `N` bristles.
///
/// ```text
/// F = sum_i sigma0 (x - b_i)
/// ```
///
/// Bristle `i` is bonded at `b_i`; its strain `s_i = x - b_i` follows the
/// displacement. When `|s_i|` reaches the snapping deflection `delta_s` the
/// bond breaks and re-bonds at a random place: the new strain is uniform in
/// `(-delta_s, delta_s)`, drawn from a seeded [`CounterRng`] (stream `i`,
/// index = the bristle's re-bond count), so runs repeat exactly.
///
/// What the randomness does: from rest all bristles load together, so the
/// first break-away peak is `N sigma0 delta_s`; after that the snaps are
/// spread out and the force fluctuates around its sliding mean
/// `N sigma0 delta_s / 3` (a re-bonded strain is uniform, then grows to
/// `delta_s`: its mean over a cycle is `delta_s / 3`). The relative
/// fluctuation falls like `1/sqrt(N)` (measured by `friction validate`).
/// No damping: a sticking mass oscillates on the bristles (the model's known
/// drawback), and the force jumps at every snap.
///
/// Discretisation: with `v` held the step moves every strain by `v h` and
/// handles each snap inside the step, in order along the displacement:
/// exact for held `v` while the step needs at most `2 N` snaps in all (the
/// default budget; [`Bristle::with_snap_budget`] sets another). The
/// work per step is bounded there (a real-time step is sized by
/// its worst case): once the budget is drawn, a bristle whose travel
/// would snap it again ends the step held at its snapping deflection
/// `±delta_s` and snaps with the next step's travel (a reversal unloads it
/// from there: that snap is lost). Bristles are served in index order. A
/// re-bonded strain is uniform, so a bristle travels `delta_s` between snaps
/// on average: the bound bites when `|v| h` approaches `2 delta_s` (for
/// haessig1991-bristle, 20 mm/s at 1 kHz, 0.2 m/s at 10 kHz), where held
/// bristles raise the force towards `N sigma0 delta_s`. A draw is a 32-bit
/// counter-based hash (`crate::random`), cheap beside the step on a
/// Cortex-M.
///
/// `N` must be at least 1:
///
/// ```compile_fail
/// use friction_core::BristleParams;
/// let p = BristleParams { sigma0: 1e3, delta_s: 1e-5, seed: 1 };
/// let m = p.build::<f32, 0>(); // error: N = 0 bristles
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Bristle<S, const N: usize> {
    pub(super) sigma0: S,
    pub(super) delta_s: S,
    pub(super) rng: CounterRng,
    /// Re-bonds a step may draw, in all ([`Bristle::with_snap_budget`]).
    pub(super) budget: u32,
}

/// The bristle state: each bristle's strain and re-bond count.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BristleState<S, const N: usize> {
    /// Strains `s_i = x - b_i`, within `±delta_s`.
    pub strain: [S; N],
    /// How many times each bristle has re-bonded (its generator index).
    pub bonds: [u32; N],
}

impl<S: Scalar, const N: usize> Default for BristleState<S, N> {
    fn default() -> Self {
        Self {
            strain: [S::ZERO; N],
            bonds: [0; N],
        }
    }
}

impl<S: Scalar, const N: usize> Bristle<S, N> {
    /// The same model with a budget of `per_bristle N` re-bonds per step
    /// (`per_bristle` from 1 to [`BRISTLE_MAX_SNAPS`];
    /// [`BRISTLE_DEFAULT_SNAPS`](super::BRISTLE_DEFAULT_SNAPS) = 2 when built): the
    /// worst-case step draws that many, and a step that needs more holds
    /// the bristles it cannot re-bond at `±delta_s` (see [`Bristle`]).
    /// A desk simulation that wants the exact event sequence at any speed
    /// raises it (the host uses 64).
    ///
    /// ```
    /// use friction_core::{BristleParams, BristleState, FrictionModel};
    /// let p = BristleParams { sigma0: 1e3, delta_s: 1e-5, seed: 7 };
    /// let firmware = p.build::<f32, 8>()?; // at most 16 draws a step
    /// let desk = p.build::<f32, 8>()?.with_snap_budget(64);
    /// let (mut a, mut b) = (BristleState::default(), BristleState::default());
    /// firmware.step(&mut a, 1.0, 1e-3); // 1 mm: 100 snapping lengths
    /// desk.step(&mut b, 1.0, 1e-3);
    /// assert_eq!(a.bonds.iter().sum::<u32>(), 16);
    /// assert!(b.bonds.iter().sum::<u32>() > 16);
    /// # Ok::<(), friction_core::ParamError>(())
    /// ```
    #[must_use]
    pub fn with_snap_budget(mut self, per_bristle: u32) -> Self {
        self.budget = snap_budget(N, per_bristle);
        self
    }

    /// A fresh strain for bristle `i`'s `k`-th re-bond, uniform in `(-delta_s, delta_s)`.
    #[inline]
    fn rebond(&self, i: usize, k: u32) -> S {
        let u: S = self.rng.unit(i as u32, k);
        self.delta_s * (u + u - S::ONE)
    }

    /// Moves one bristle by `d`, snapping as often as the travel demands
    /// while `budget` (re-bonds left in this step) lasts; past it the
    /// bristle stops at its snapping deflection.
    fn move_bristle(&self, i: usize, strain: &mut S, bonds: &mut u32, d: S, budget: &mut u32) {
        let dir = d.sign();
        let mut left = d.abs();
        let mut s = *strain;
        loop {
            let room = self.delta_s - dir * s;
            if left < room {
                *strain = s + dir * left;
                return;
            }
            if *budget == 0 {
                *strain = dir * self.delta_s;
                return;
            }
            *budget -= 1;
            left = left - room.max(S::ZERO);
            *bonds = bonds.wrapping_add(1);
            s = self.rebond(i, *bonds);
        }
    }

    /// `sigma0 sum s_i`.
    fn force(&self, state: &BristleState<S, N>) -> S {
        let mut sum = S::ZERO;
        for &s in &state.strain {
            sum = sum + s;
        }
        self.sigma0 * sum
    }

    /// The sliding mean force `N sigma0 delta_s / 3`.
    pub fn sliding_mean(&self) -> S {
        S::from_f64(N as f64 / 3.0) * self.sigma0 * self.delta_s
    }
}

impl<S: Scalar, const N: usize> FrictionModel<S> for Bristle<S, N> {
    type State = BristleState<S, N>;

    fn step(&self, state: &mut BristleState<S, N>, v: S, h: S) -> S {
        match checked_inputs(v, h) {
            Some(v) => self.advance(state, v * h),
            None => self.hold_force(state),
        }
    }

    /// `sigma0 sum s_i` (the force is a function of the strains alone).
    fn hold_force(&self, state: &BristleState<S, N>) -> S {
        self.force(state)
    }
}

/// Observer form: every strain moves with `v - c`. No damping term.
impl<S: Scalar, const N: usize> Observable<S> for Bristle<S, N> {
    fn step_corrected(
        &self,
        state: &mut BristleState<S, N>,
        v: S,
        correction: S,
        h: S,
        _damping: bool,
    ) -> S {
        self.advance(state, (v - correction) * h)
    }

    /// `N sigma0 delta_s`: every bristle at its snapping deflection.
    fn force_bound(&self, _v: S) -> S {
        S::from_f64(N as f64) * self.sigma0 * self.delta_s
    }
}

impl<S: Scalar, const N: usize> Bristle<S, N> {
    /// Moves every strain by the displacement `d` (a zero `d` leaves the
    /// state untouched) and returns the force.
    fn advance(&self, state: &mut BristleState<S, N>, d: S) -> S {
        if d != S::ZERO {
            // a valid model's budget is at most this: the bound holds for
            // any stored bytes
            let mut budget = self.budget.min(snap_budget(N, BRISTLE_MAX_SNAPS));
            for (i, (s, b)) in state
                .strain
                .iter_mut()
                .zip(state.bonds.iter_mut())
                .enumerate()
            {
                self.move_bristle(i, s, b, d, &mut budget);
            }
        }
        self.force(state)
    }
}
