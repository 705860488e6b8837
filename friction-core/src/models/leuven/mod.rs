//! The Leuven model (Swevers, Al-Bender, Ganseman, Prajogo 2000) with the
//! continuous state equation of Lampaert, Swevers, Al-Bender 2002, and a
//! reversal-point memory of fixed capacity `M`.
//!
//! ```text
//! dz/dt = v - v rho^n,        rho = max(0, sign(v) Fh(z) / s(v))        (Lampaert 2002)
//! F     = Fh(z) + sigma1 dz/dt + sigma2 v
//! Fh(z) = Fb + T(z - zb)                                  (zb, Fb): the last reversal point
//! T(u)  = 2 Fv(u / 2) = 4 Fs sign(u) (1 - exp(-|u| / (4 xs)))          (Masing's rule)
//! Fv(x) = 2 Fs sign(x) (1 - exp(-|x| / (2 xs)))           (virgin curve)
//! ```
//!
//! `s(v) = g(v)` is the unsigned Stribeck curve. The virgin curve is the
//! exponential one of Dahl's model with exponent 1 (`dF/dx = k0 (1 - F/Fm)`)
//! with initial stiffness `k0 = Fs / xs` and asymptote `Fm = 2 Fs`; its one
//! parameter is the characteristic pre-sliding displacement `xs` (`Fv`
//! reaches `Fs` at `2 ln 2 xs = 1.39 xs`). The asymptote lies above `Fs` so
//! that every branch reaches the sliding level `s(v) <= Fs` at a finite
//! displacement: with `Fm = Fs` the approach to the static level at creeping
//! speed is only algebraic (measured: still 0.25 % of `Fs` short after 200
//! `xs` at 1 µm/s). Transition curves follow Masing's rule: the branch from
//! a reversal point is the virgin curve scaled by 2.
//!
//! **Memory.** The reversal points form a stack. When the elastic input
//! `v` (an observer's `v - c`) reverses, the current point `(z, Fh)` is
//! pushed and a new branch starts from it. When `s(v)` falls below `|Fh|`
//! (speeding up through the Stribeck zone, `rho > 1`) `z` relaxes back
//! along the current branch: no reversal, no push. When
//! the branch reaches the point below the top (an inner loop closes; by
//! Masing's rule it arrives exactly at that point's `z` and `F`), both are
//! popped and the branch that led to that point continues through it
//! (wiping-out): the force is continuous. The rest state has an empty
//! memory on the virgin curve; below the first point pushed from it lies
//! the virgin curve, so that point's mirror `(-z1, -F1)` is where its
//! branch closes and the state returns to the virgin curve. Once the virgin
//! curve is forgotten (a slide or a full memory), the oldest point is never
//! popped: passing it pops only the top, and the branch from the oldest
//! point continues (its formula is odd about that point).
//!
//! **Sliding** clears the memory: when `z` moves with `v` and `rho`
//! reaches `1 - 1e-4` (the force within 0.01 % of `s(v)`: `rho = 1` is
//! only approached asymptotically), every point below the top is dropped;
//! the current branch is kept, so the force does not change.
//!
//! **Memory full.** The state must be `Copy + Default + Debug` (the
//! [`FrictionModel::State`](crate::FrictionModel::State) bound), so the
//! memory is a `Copy` array `[LeuvenReversal; M]` with a length (a `heapless::Vec` is not `Copy`). A push
//! into a full memory first drops the oldest point (the outermost loop is
//! forgotten). The current branch is untouched, so the force stays
//! continuous, and the cost is one `O(M)` shift. The loss of accuracy:
//! a branch that should close on the forgotten outer loop continues
//! instead on the mirror of the oldest remembered branch through the oldest
//! remembered point, and reaches sliding (or a later reversal) along it;
//! the force differs from the full-memory model's by at most the gap
//! between those two branches (below `2 Fs`, in practice far less), until
//! the next slide clears the memory. `M = 1` keeps only the current branch:
//! no non-local memory.
//!
//! **Continuity** (the point of Lampaert 2002). The original law
//! `dz/dt = v (1 - sign(Fd/(s(v) - Fb)) |Fd/(s(v) - Fb)|^n)` with `Fd = Fh - Fb`
//! divides by `s(v) - Fb`, which jumps when `Fb` changes on a pop, so
//! `sigma1 dz/dt` jumps. Here `rho` depends on `Fh` alone, which is
//! continuous through pushes, pops, drops and clearing, so `dz/dt` and `F`
//! are continuous functions of time for continuous `v`. `rho` is clipped
//! at 0 so that after a reversal `dz/dt = v` (pure pre-sliding hysteresis)
//! until the force changes sign; the clip is continuous.
//!
//! **Discrete step.** `v` is held over the step; `z` obeys an autonomous
//! scalar ODE whose right-hand side decreases along the motion, so one
//! implicit Euler step `z1 = z0 + h f(z1)` has a unique root, never
//! overshoots the equilibrium `Fh = sign(v) s(v)` and is stable at any
//! `h`. The root is found on the composite branch: each wiping-out point
//! ahead is tested first (cheap: `Fh` is known there), and passed points
//! are popped at their exact position (at most `M - 1` pops per step);
//! inside the last branch a safeguarded Newton iteration (at most 30
//! evaluations, bisection when Newton leaves the bracket) finds the root.
//! `|Fh|` never passes `Fs` (an observer's correction is held there), so
//! `z` stays within `4 ln 2 xs = 2.8 xs` beyond a reversal point on a
//! branch (`1.4 xs` on the virgin curve): the state is bounded.
//!
//! Pre-sliding with `rho = 0` (`z1 = z0 + h v`) and steady sliding are
//! exact; the transition to sliding is first order in `h`: measured 2.1 %
//! of `Fs` RMS at 1 kHz and 0.22 % at 10 kHz against an independent
//! reference on a 20 mm/s sine with `xs = 10 µm` (two `xs` a 1 kHz step).
//! Any `h` is stable.
//!
//! `M` must be at least 1:
//!
//! ```compile_fail
//! use friction_core::{LeuvenParams, StribeckParams};
//! let curve = StribeckParams { fc: 1.0, fs: 1.5, vs: 1e-3, exponent: 2.0 };
//! let p = LeuvenParams { curve, sigma1: 0.0, sigma2: 0.4, n: 2.0, xs: 1e-5 };
//! let m = p.build::<f32, 0>(); // error: a memory of capacity 0
//! ```

#[cfg(test)]
mod tests;
mod variable_step;

use crate::model::{
    check_force, convert, convert_derived, magnitude, magnitude_or_zero, ParamError, VELOCITY_LIMIT,
};
use crate::stribeck::StribeckParams;
use crate::Scalar;
use variable_step::Power;
pub use variable_step::{Leuven, LeuvenReversal, LeuvenState};

/// The branch may approach its asymptote to within this fraction of `2 Fs`.
const CAP: f64 = 1e-6;
/// Sliding: `rho >= 1 - SLIDE_TOL` clears the memory below the top.
const SLIDE_TOL: f64 = 1e-4;

/// Leuven parameters (`model = "leuven"`), in `f64`.
///
/// ```
/// use friction_core::{FrictionModel, LeuvenParams, LeuvenState, StribeckParams};
/// let curve = StribeckParams { fc: 1.0, fs: 1.5, vs: 1e-3, exponent: 2.0 };
/// let p = LeuvenParams { curve, sigma1: 0.0, sigma2: 0.4, n: 2.0, xs: 1e-5 };
/// let model = p.build::<f32, 8>()?;
/// let mut state = LeuvenState::default();
/// let mut f = 0.0;
/// for _ in 0..1000 {
///     f = model.step(&mut state, 0.1, 1e-3); // 0.1 m/s for 1 s at 1 kHz
/// }
/// assert!((f - (1.0 + 0.4 * 0.1)).abs() < 1e-3); // steady state: Fc + sigma2 v
/// # Ok::<(), friction_core::ParamError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LeuvenParams {
    /// The Stribeck curve `s(v) = g(v)` (`fc`, `fs`, `vs`, `stribeck_exponent`).
    pub curve: StribeckParams,
    /// Micro-viscous damping `sigma1 >= 0` (N s/m) on `dz/dt`.
    pub sigma1: f64,
    /// Viscous friction `sigma2 >= 0` (N s/m).
    pub sigma2: f64,
    /// Shape exponent `n >= 1` of the transition to sliding.
    pub n: f64,
    /// Characteristic pre-sliding displacement `xs > 0` (m) of the virgin
    /// curve `Fv(x) = 2 Fs (1 - exp(-|x| / (2 xs))) sign(x)` (initial
    /// stiffness `Fs / xs`).
    pub xs: f64,
}

impl LeuvenParams {
    /// Checks every parameter; the error names the first offending one.
    pub fn validate(&self) -> Result<(), ParamError> {
        self.curve.validate()?;
        magnitude_or_zero("sigma1", self.sigma1)?;
        magnitude_or_zero("sigma2", self.sigma2)?;
        if !self.n.is_finite() {
            return Err(ParamError::NotFinite("n"));
        }
        if self.n < 1.0 {
            return Err(ParamError::BelowOne("n"));
        }
        magnitude("xs", self.xs)?;
        Ok(())
    }

    /// `(Fs / Fc)^n`: the largest `rho^n` (reached when the speed rises
    /// from rest to where `g = Fc`).
    fn ratio_pow(&self) -> f64 {
        (self.curve.fs / self.curve.fc).powf(self.n)
    }

    /// Validates and builds the run-time model with a memory of `M >= 1`
    /// reversal points (checked at compile time). Besides
    /// [`Self::validate`], rejects what the scalar type cannot carry: `xs`,
    /// `Fs / xs` or the solver tolerance that underflow or overflow, a
    /// `(Fs/Fc)^n |v|` or damping term that overflows at the velocity limit.
    pub fn build<S: Scalar, const M: usize>(&self) -> Result<Leuven<S, M>, ParamError> {
        const {
            assert!(
                M > 0,
                "the Leuven model needs a memory of at least one point"
            )
        };
        self.validate()?;
        let curve = self.curve.build()?;
        let (fs, xs) = (self.curve.fs, self.xs);
        let ratio = self.ratio_pow();
        check_force::<S>("n", ratio * VELOCITY_LIMIT)?;
        // |dz/dt| <= |v - c| + |v| rho^n <= VELOCITY_LIMIT (2 + (Fs/Fc)^n)
        check_force::<S>("sigma1", self.sigma1 * VELOCITY_LIMIT * (2.0 + ratio))?;
        check_force::<S>("sigma2", self.sigma2 * VELOCITY_LIMIT)?;
        let shape = if self.n == 1.0 {
            Power::One
        } else if self.n == 2.0 {
            Power::Two
        } else {
            Power::Real
        };
        // tolerance on z of the Newton iteration: a few ulps of xs
        let eps = if S::from_f64(1.0 + 1e-10).to_f64() == 1.0 {
            1e-6
        } else {
            1e-13
        };
        Ok(Leuven {
            curve,
            sigma1: convert("sigma1", self.sigma1)?,
            sigma2: convert("sigma2", self.sigma2)?,
            n: convert("n", self.n)?,
            shape: shape as u8,
            fs: convert("fs", fs)?,
            fm: convert("fs", 2.0 * fs)?,
            width: convert("xs", 2.0 * xs)?,
            inv_width: convert_derived("xs", 0.5 / xs)?,
            keep: convert("fs", 1.0 - CAP)?,
            stiffness: convert_derived("xs", fs / xs)?,
            tol: convert("xs", eps * xs)?,
            slide: S::from_f64(1.0 - SLIDE_TOL),
            rate_factor: convert("n", (ratio - 1.0).max(1.0))?,
        })
    }
}
