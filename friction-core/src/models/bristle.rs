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

use crate::model::{check_force, checked_inputs, convert, magnitude, FrictionModel, ParamError};
use crate::observer::Observable;
use crate::random::CounterRng;
use crate::Scalar;

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

/// The built bristle model with `N` bristles.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Bristle<S, const N: usize> {
    sigma0: S,
    delta_s: S,
    rng: CounterRng,
    /// Re-bonds a step may draw, in all ([`Bristle::with_snap_budget`]).
    budget: u32,
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
    /// (`per_bristle` from 1 to [`MAX_SNAPS`]; [`DEFAULT_SNAPS`] = 2 when
    /// built): the
    /// worst-case step draws that many, and a step that needs more holds
    /// the bristles it cannot re-bond at `±delta_s` (see the module docs).
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
            let mut budget = self.budget.min(snap_budget(N, MAX_SNAPS));
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

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const P: BristleParams = BristleParams {
        sigma0: 1e3,
        delta_s: 1e-5,
        seed: 11,
    };

    #[test]
    fn invalid_parameters_are_named() {
        assert_eq!(
            BristleParams { delta_s: 0.0, ..P }.validate(),
            Err(ParamError::NotPositive("delta_s"))
        );
        assert_eq!(
            BristleParams {
                sigma0: f64::NAN,
                ..P
            }
            .build::<f64, 4>()
            .err(),
            Some(ParamError::NotFinite("sigma0"))
        );
    }

    #[test]
    fn runs_repeat_and_do_not_depend_on_step_size() {
        let m = P.build::<f64, 8>().unwrap();
        let (mut a, mut b) = (BristleState::default(), BristleState::default());
        for _ in 0..1000 {
            m.step(&mut a, 1e-3, 1e-3); // 1 µm a step
        }
        for _ in 0..100 {
            m.step(&mut b, 1e-3, 1e-2); // 10 µm a step (snaps inside the step)
        }
        assert_eq!(a.bonds, b.bonds);
        for (x, y) in a.strain.iter().zip(&b.strain) {
            assert!((x - y).abs() < 1e-15);
        }
    }

    #[test]
    fn first_breakaway_peak_then_sliding_mean() {
        let m = P.build::<f64, 64>().unwrap();
        let mut s = BristleState::default();
        let mut peak = 0.0f64;
        let mut sum = 0.0;
        let n = 200_000;
        for k in 0..n {
            let f = m.step(&mut s, 1e-3, 1e-4); // 0.1 µm a step
            peak = peak.max(f);
            if k >= n / 2 {
                sum += f;
            }
        }
        assert!(peak > 0.99 * 64.0 * 1e3 * 1e-5); // all bristles loaded together
        let mean = sum / (n / 2) as f64;
        assert!(
            (mean / m.sliding_mean() - 1.0).abs() < 0.05,
            "mean {mean} vs {}",
            m.sliding_mean()
        );
    }

    #[test]
    fn huge_steps_are_bounded() {
        let m = P.build::<f32, 64>().unwrap();
        let mut s = BristleState::default();
        let f = m.step(&mut s, 1e6, 1.0);
        assert!(f.is_finite() && f.abs() <= 64.0 * 1e3 * 1e-5 * (1.0 + 1e-6));
        // 2 N draws in all, then every bristle that would snap again is held
        // at its snapping deflection, and the next step's travel snaps it
        assert_eq!(s.bonds.iter().sum::<u32>(), DEFAULT_SNAPS * 64);
        assert!(s.strain.iter().all(|&z| z == 1e-5));
        let before = s.bonds;
        m.step(&mut s, 1e-3, 1e-6);
        assert!(s.bonds.iter().zip(before).all(|(&b, a)| b == a + 1));
    }

    /// While a step needs at most `2 N` snaps, one long step is the same as
    /// many short ones (the snaps happen in order, exactly).
    #[test]
    fn long_steps_within_the_budget_are_exact() {
        let m = P.build::<f64, 16>().unwrap();
        let (mut long, mut short) = (BristleState::default(), BristleState::default());
        for k in 0..400 {
            let v = if (k / 50) % 2 == 0 { 1e-3 } else { -7e-4 };
            let h = 1.3e-2; // 13 µm and 9.1 µm of travel: up to 1.3 delta_s
            m.step(&mut long, v, h);
            for _ in 0..100 {
                m.step(&mut short, v, h / 100.0);
            }
            assert_eq!(long.bonds, short.bonds, "step {k}");
            for (a, b) in long.strain.iter().zip(short.strain) {
                assert!((a - b).abs() < 1e-15, "step {k}: {a} vs {b}");
            }
        }
        assert!(long.bonds.iter().sum::<u32>() > 16 * 100);
    }

    proptest! {
        #[test]
        fn strains_stay_inside_the_snapping_band(inputs in proptest::collection::vec((-1.0f64..1.0, 0.0f64..1e-3), 1..60)) {
            let m = P.build::<f32, 8>().unwrap();
            let mut s = BristleState::default();
            for (v, h) in inputs {
                let f = m.step(&mut s, v as f32, h as f32);
                prop_assert!(f.is_finite());
                for &x in &s.strain {
                    prop_assert!(x.abs() <= 1e-5);
                }
            }
        }
    }
}
