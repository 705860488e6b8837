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
//! [`FrictionModel::State`] bound), so the memory is a `Copy` array
//! `[Reversal; M]` with a length (a `heapless::Vec` is not `Copy`). A push
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

use crate::bits::Flag;
use crate::model::{
    check_force, checked_inputs, convert, convert_derived, magnitude, magnitude_or_zero,
    FrictionModel, ParamError, VELOCITY_LIMIT,
};
use crate::observer::Observable;
use crate::stribeck::{StribeckCurve, StribeckParams};
use crate::Scalar;

/// The branch may approach its asymptote to within this fraction of `2 Fs`.
const CAP: f64 = 1e-6;
/// Sliding: `rho >= 1 - SLIDE_TOL` clears the memory below the top.
const SLIDE_TOL: f64 = 1e-4;
/// Evaluations of the Newton iteration inside the last branch.
const MAX_ITER: usize = 30;

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

/// `rho^n` for the common exponents without `powf`; stored as its `u8`
/// (see `crate::bits`) and read by [`Power::of`], for which any byte is
/// one.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Power {
    One = 0,
    Two = 1,
    /// `powf` with the model's `n`.
    Real = 2,
}

impl Power {
    /// The power a stored byte stands for: 0 and 1 the common ones, any
    /// other byte `powf`.
    #[inline]
    fn of(byte: u8) -> Self {
        match byte {
            0 => Self::One,
            1 => Self::Two,
            _ => Self::Real,
        }
    }
}

/// The built Leuven model with a memory of `M` reversal points: immutable,
/// shared by any number of [`LeuvenState`]s.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Leuven<S, const M: usize> {
    curve: StribeckCurve<S>,
    sigma1: S,
    sigma2: S,
    n: S,
    /// A [`Power`] as its byte.
    shape: u8,
    fs: S,
    /// `Fm = 2 Fs`: the asymptote of the virgin curve.
    fm: S,
    /// `2 xs`: the width of the virgin curve.
    width: S,
    inv_width: S,
    /// `1 - CAP`: a branch goes no farther than this fraction of its asymptote.
    keep: S,
    /// `Fs / xs`: the slope of every branch at its reversal point.
    stiffness: S,
    tol: S,
    slide: S,
    /// `max(1, (Fs/Fc)^n - 1)`: the largest `|dz/dt| / |v|` of the model.
    rate_factor: S,
}

/// A reversal point `(z, F)` of the hysteresis memory.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Reversal<S> {
    /// The state `z` at the reversal (m).
    pub z: S,
    /// The hysteresis force `Fh` at the reversal (N).
    pub f: S,
}

/// The Leuven state: `z`, the hysteresis force, the direction of the last
/// motion of `z`, and the memory of reversal points (the last one is the
/// origin of the current branch; none: the virgin curve).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LeuvenState<S, const M: usize> {
    z: S,
    fh: S,
    dir: S,
    len: usize,
    /// The virgin curve lies below the oldest point (no slide, no drop yet).
    virgin: Flag,
    points: [Reversal<S>; M],
}

impl<S: Scalar, const M: usize> Default for LeuvenState<S, M> {
    /// At rest, unstrained, on the virgin curve.
    fn default() -> Self {
        Self {
            z: S::ZERO,
            fh: S::ZERO,
            dir: S::ZERO,
            len: 0,
            virgin: Flag::new(true),
            points: [Reversal::default(); M],
        }
    }
}

/// The current branch: its origin, and whether it is the virgin curve.
#[derive(Clone, Copy, Debug)]
struct Branch<S> {
    origin: Reversal<S>,
    virgin: bool,
}

impl<S: Scalar, const M: usize> LeuvenState<S, M> {
    /// The state `z` (m), relative to the oldest remembered reversal point
    /// (to the origin while the virgin curve is remembered).
    pub fn z(&self) -> S {
        self.z
    }

    /// The hysteresis force `Fh(z)` (N), within `±Fs`.
    pub fn hysteresis_force(&self) -> S {
        self.fh
    }

    /// The remembered reversal points, oldest first (0 to `M` of them).
    pub fn memory(&self) -> &[Reversal<S>] {
        self.points.get(..self.len).unwrap_or(&[])
    }

    /// Whether the virgin curve is still remembered below the oldest point.
    pub fn on_virgin_curve(&self) -> bool {
        self.virgin.get()
    }

    /// The current branch.
    fn branch(&self) -> Branch<S> {
        match self.len.checked_sub(1).and_then(|i| self.points.get(i)) {
            Some(&origin) => Branch {
                origin,
                virgin: false,
            },
            None => Branch {
                origin: Reversal::default(),
                virgin: true,
            },
        }
    }

    /// The next wiping-out point ahead: the point below the top, or with
    /// one point above the virgin curve, that point's mirror on it.
    fn below(&self) -> Option<Reversal<S>> {
        match self.len {
            0 => None,
            1 if self.virgin.get() => self.points.first().map(|p| Reversal { z: -p.z, f: -p.f }),
            1 => None,
            n => self.points.get(n - 2).copied(),
        }
    }

    /// Pushes `(z, Fh)`, dropping the oldest point when the memory is full.
    fn push(&mut self) {
        if self.len >= M {
            self.points.rotate_left(1);
            self.len = M - 1;
            self.virgin = Flag::new(false);
            self.rebase();
        }
        if let Some(p) = self.points.get_mut(self.len) {
            *p = Reversal {
                z: self.z,
                f: self.fh,
            };
            self.len += 1;
        }
    }

    /// Wiping-out at the next point: pops it with the top (or, above the
    /// virgin curve, the last point, back onto the virgin curve); without
    /// the virgin curve the oldest point is never popped.
    fn pop(&mut self) {
        self.len = match (self.len, self.virgin.get()) {
            (0, _) => 0,
            (1, true) => 0,
            (1, false) => 1,
            (2, false) => 1,
            (n, _) => n - 2,
        };
    }

    /// Keeps only the current branch's origin (sliding).
    fn clear(&mut self) {
        if self.len == 0 {
            return; // sliding on the virgin curve: nothing to forget
        }
        let top = self.branch().origin;
        if let Some(p) = self.points.first_mut() {
            *p = top;
        }
        self.len = 1;
        self.virgin = Flag::new(false);
        self.rebase();
    }

    /// Shifts positions so that the oldest point sits at `z = 0` (keeps `z`
    /// small: pre-sliding needs its precision in `f32`). Not while the
    /// virgin curve, centred on `z = 0`, is remembered.
    fn rebase(&mut self) {
        if self.virgin.get() {
            return;
        }
        let base = self.points.first().map_or(S::ZERO, |p| p.z);
        if base != S::ZERO {
            self.z = self.z - base;
            for p in self.points.iter_mut().take(self.len) {
                p.z = p.z - base;
            }
        }
    }
}

impl<S: Scalar, const M: usize> Leuven<S, M> {
    /// The Stribeck curve `s(v) = g(v)`.
    pub fn curve(&self) -> &StribeckCurve<S> {
        &self.curve
    }

    /// The memory capacity `M`.
    pub const fn capacity(&self) -> usize {
        M
    }

    /// Steady-state friction `g(v) sign(v) + sigma2 v`.
    pub fn steady_state(&self, v: S) -> S {
        self.curve.eval(v) * v.sign() + self.sigma2 * v
    }

    /// `(k Fm, k 2 xs, 1 / (k 2 xs))` of a branch: `k = 1` for the virgin
    /// curve, 2 else.
    #[inline]
    fn scale(&self, b: Branch<S>) -> (S, S, S) {
        if b.virgin {
            (self.fm, self.width, self.inv_width)
        } else {
            (
                self.fm + self.fm,
                self.width + self.width,
                self.inv_width * S::from_f64(0.5),
            )
        }
    }

    /// `Fh` on branch `b` at `z`, `Fb + k Fm sign(u) (1 - exp(-|u| / (k 2 xs)))`
    /// with `u = z - zb`, and its slope `(Fs/xs) exp(-|u| / (k 2 xs))`.
    #[inline]
    fn curve_at(&self, b: Branch<S>, z: S) -> (S, S) {
        let (kf, _, inv_w) = self.scale(b);
        let u = z - b.origin.z;
        let em = (-(u.abs() * inv_w)).exp_m1(); // e^{-a} - 1, in (-1, 0]
        (
            b.origin.f - kf * u.sign() * em,
            self.stiffness * (em + S::ONE),
        )
    }

    /// `(rho^n, n rho^(n-1))` for `rho = max(0, sign(v) fh / g)`.
    #[inline]
    fn rho_pow(&self, fh: S, sv: S, inv_g: S) -> (S, S) {
        let r = sv * fh * inv_g;
        if r <= S::ZERO {
            return (S::ZERO, S::ZERO);
        }
        match Power::of(self.shape) {
            Power::One => (r, S::ONE),
            Power::Two => (r * r, (S::ONE + S::ONE) * r),
            Power::Real => {
                let n = self.n;
                let p = r.powf(n);
                (p, n * p / r)
            }
        }
    }

    /// `dz/dt = (v - c) - v rho^n`.
    #[inline]
    fn rate(&self, fh: S, v: S, elastic: S, inv_g: S) -> S {
        elastic - v * self.rho_pow(fh, v.sign(), inv_g).0
    }

    /// The point ahead on branch `b` (direction `d`) where `|Fh|` reaches
    /// `Fs`, or where the branch is within `CAP` of its asymptote if it
    /// never does: `(z, Fh)`.
    fn bound_point(&self, b: Branch<S>, d: S) -> (S, S) {
        let (kf, w, _) = self.scale(b);
        // the position of z relative to the origin counts for the virgin
        // curve (odd about it); a branch is used on its own side only
        let room = (self.fs - d * b.origin.f).max(S::ZERO).min(kf * self.keep);
        // inverse: |u| = -k xs ln(1 - room / (k Fs))
        let u = -w * (-(room / kf)).ln_1p();
        (b.origin.z + d * u, b.origin.f + d * room)
    }

    /// Advances the state over `h` (skipped at `h = 0`, which leaves the
    /// state bitwise unchanged) with `v - c` straining `z` and `v` driving
    /// the sliding law; returns the force at the end.
    fn advance(&self, state: &mut LeuvenState<S, M>, v: S, c: S, h: S, damping: bool) -> S {
        let g = self.curve.eval(v); // >= Fc > 0
        let inv_g = S::ONE / g;
        let elastic = v - c;
        let rate = if h > S::ZERO {
            self.integrate(state, v, elastic, inv_g, h)
        } else {
            let w = self.rate(state.fh, v, elastic, inv_g);
            if w.sign() * state.fh >= self.fs {
                S::ZERO // held at the bound
            } else {
                w
            }
        };
        let mut f = state.fh + self.sigma2 * v;
        if damping {
            f = f + self.sigma1 * rate;
        }
        f
    }

    /// One implicit Euler step `z1 = z0 + h f(z1)` on the composite branch;
    /// returns the rate actually taken.
    fn integrate(&self, state: &mut LeuvenState<S, M>, v: S, elastic: S, inv_g: S, h: S) -> S {
        let sv = v.sign();
        let w0 = self.rate(state.fh, v, elastic, inv_g);
        if w0 == S::ZERO {
            return S::ZERO;
        }
        let d = w0.sign();
        // a reversal of the elastic input v - c: push the point (or undo a
        // push not yet left). z may also move against v - c when s(v) falls
        // below |Fh| (rho > 1): it then relaxes back along the current
        // branch, which is no reversal (else every acceleration through the
        // Stribeck zone would start a stiff new branch at the sliding level,
        // a knife-edge decision that f32 and f64 take differently)
        let e = if elastic != S::ZERO {
            elastic.sign()
        } else {
            d
        };
        if state.dir != S::ZERO && e != state.dir {
            if state.len == 0 || state.z != state.branch().origin.z {
                state.push();
            } else if state.len >= 2 || state.virgin.get() {
                state.len -= 1; // back at the last point: undo its push
            }
        }
        state.dir = e;
        let z0 = state.z;
        // E(s) = s - h d f(z0 + d s), increasing in s; E(0) < 0
        let e_at = |s: S, fh: S| s - h * d * self.rate(fh, v, elastic, inv_g);
        // the root lies no farther than h |w0|
        let s_explicit = h * w0.abs();
        for _ in 0..M {
            let top = state.branch();
            let (zb, fb) = self.bound_point(top, d);
            let (z_lim, f_lim, wipe) = match state.below() {
                Some(p) if d == e && d * (p.z - zb) < S::ZERO => (p.z, p.f, true),
                _ => (zb, fb, false),
            };
            let s_now = d * (state.z - z0);
            let s_lim = d * (z_lim - z0);
            if s_lim <= s_now {
                // already there (rounding): wipe, or held at the bound
                if wipe {
                    state.z = z_lim;
                    state.fh = f_lim.sat(self.fs);
                    state.pop();
                    continue;
                }
                return self.taken(state, z0, d, v, elastic, inv_g, h);
            }
            if s_lim <= s_explicit && e_at(s_lim, f_lim) <= S::ZERO {
                // the root is at or beyond the limit
                state.z = z_lim;
                state.fh = f_lim.sat(self.fs);
                if wipe {
                    state.pop();
                    continue;
                }
                return self.taken(state, z0, d, v, elastic, inv_g, h);
            }
            // the root is inside this branch: safeguarded Newton
            let (mut lo, mut hi) = (s_now, s_lim.min(s_explicit));
            let mut s = lo;
            for _ in 0..MAX_ITER {
                let (fh, slope) = self.curve_at(top, z0 + d * s);
                let (p, dp) = self.rho_pow(fh, sv, inv_g);
                let e = s - h * d * (elastic - v * p);
                if e > S::ZERO {
                    hi = s;
                } else if e < S::ZERO {
                    lo = s;
                } else {
                    break;
                }
                let de = S::ONE + h * v.abs() * dp * slope * inv_g;
                let mut next = s - e / de;
                if !(next > lo && next < hi) {
                    next = (lo + hi) * S::from_f64(0.5);
                }
                let done = (next - s).abs() <= self.tol;
                s = next;
                if done {
                    break;
                }
            }
            state.z = z0 + d * s;
            state.fh = self.curve_at(top, state.z).0.sat(self.fs);
            break;
        }
        let rate = self.taken(state, z0, d, v, elastic, inv_g, h);
        // sliding clears the memory below the top
        if (state.len > 1 || state.virgin.get()) && d == sv && sv * state.fh * inv_g >= self.slide {
            state.clear();
        }
        rate
    }

    /// The rate actually taken over the step: `f(z1)`, no more than the
    /// increment over `h` (the state may be held at a limit).
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn taken(&self, state: &LeuvenState<S, M>, z0: S, d: S, v: S, elastic: S, inv_g: S, h: S) -> S {
        let end = (d * self.rate(state.fh, v, elastic, inv_g)).max(S::ZERO);
        let moved = (d * (state.z - z0)).max(S::ZERO) / h; // finite or +inf
        d * end.min(moved)
    }
}

impl<S: Scalar, const M: usize> FrictionModel<S> for Leuven<S, M> {
    type State = LeuvenState<S, M>;

    #[inline]
    fn step(&self, state: &mut LeuvenState<S, M>, v: S, h: S) -> S {
        match checked_inputs(v, h) {
            Some(v) => self.advance(state, v, S::ZERO, h, true),
            None => self.hold_force(state),
        }
    }

    /// The hysteresis force `Fh`, within `±Fs`.
    fn hold_force(&self, state: &LeuvenState<S, M>) -> S {
        state.fh.sat(self.fs)
    }
}

/// Observer form: `v - c` strains `z`, the sliding law sees `v`; `|Fh|`
/// is held at `Fs` when the correction drives it there, with `dz/dt = 0`.
impl<S: Scalar, const M: usize> Observable<S> for Leuven<S, M> {
    fn step_corrected(
        &self,
        state: &mut LeuvenState<S, M>,
        v: S,
        correction: S,
        h: S,
        damping: bool,
    ) -> S {
        self.advance(state, v, correction, h, damping)
    }

    /// `Fs + sigma1 |v| max(1, (Fs/Fc)^n - 1) + sigma2 |v|`: `|Fh| <= Fs`;
    /// `|dz/dt| <= |v|` moving into sliding, `|v| (rho^n - 1)` retreating
    /// when `s(v)` falls below `|Fh|`.
    fn force_bound(&self, v: S) -> S {
        let speed = v.abs();
        self.fs + (self.sigma1 * self.rate_factor + self.sigma2) * speed
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::vec::Vec;

    const CURVE: StribeckParams = StribeckParams {
        fc: 1.0,
        fs: 1.5,
        vs: 1e-3,
        exponent: 2.0,
    };

    const P: LeuvenParams = LeuvenParams {
        curve: CURVE,
        sigma1: 10.0,
        sigma2: 0.4,
        n: 2.0,
        xs: 1e-5,
    };

    /// The virgin curve `Fv(x)` written out (test oracle).
    fn fv(x: f64, p: &LeuvenParams) -> f64 {
        2.0 * p.curve.fs * x.signum() * (1.0 - (-x.abs() / (2.0 * p.xs)).exp())
    }

    /// Drives the model along displacement waypoints (the first is where it
    /// stands) at speed `v`, step `h`; returns (x, F) samples.
    fn drive<const M: usize>(
        m: &Leuven<f64, M>,
        s: &mut LeuvenState<f64, M>,
        waypoints: &[f64],
        v: f64,
        h: f64,
    ) -> Vec<(f64, f64)> {
        let mut x = waypoints[0];
        let mut out = Vec::new();
        for w in &waypoints[1..] {
            let dir = (w - x).signum();
            let n = ((w - x).abs() / (v * h)).round() as usize;
            for _ in 0..n {
                let f = m.step(s, dir * v, h);
                x += dir * v * h;
                out.push((x, f));
            }
        }
        out
    }

    #[test]
    fn invalid_parameters_are_named() {
        assert_eq!(
            LeuvenParams { n: 0.5, ..P }.validate(),
            Err(ParamError::BelowOne("n"))
        );
        assert_eq!(
            LeuvenParams { n: f64::NAN, ..P }.validate(),
            Err(ParamError::NotFinite("n"))
        );
        assert_eq!(
            LeuvenParams { xs: 0.0, ..P }.build::<f64, 4>(),
            Err(ParamError::NotPositive("xs"))
        );
        assert_eq!(
            LeuvenParams { sigma1: -1.0, ..P }.validate(),
            Err(ParamError::Negative("sigma1"))
        );
        assert_eq!(
            LeuvenParams { xs: 1e-50, ..P }.build::<f32, 4>(),
            Err(ParamError::OutOfRange("xs"))
        );
        assert_eq!(
            LeuvenParams { sigma1: 1e32, ..P }.build::<f32, 4>(),
            Err(ParamError::OutOfRange("sigma1"))
        );
        // (Fs/Fc)^n |v| overflows f32 at the velocity limit
        assert_eq!(
            LeuvenParams { n: 200.0, ..P }.build::<f32, 4>(),
            Err(ParamError::ForceOverflow("n"))
        );
        assert!(LeuvenParams { n: 200.0, ..P }.build::<f64, 4>().is_ok());
    }

    #[test]
    fn first_loading_follows_the_virgin_curve() {
        // far below sliding rho^n is small (0.37^20 ~ 2e-9): z follows x and Fh = Fv(x)
        let p = LeuvenParams { n: 20.0, ..P };
        let m = p.build::<f64, 4>().unwrap();
        let mut s = LeuvenState::default();
        let trace = drive(&m, &mut s, &[0.0, 0.5 * p.xs], 1e-6, 1e-4);
        let (x, _) = *trace.last().unwrap();
        let fh = s.hysteresis_force();
        assert!((fh - fv(x, &p)).abs() < 1e-8, "{fh} vs {}", fv(x, &p));
        assert!((s.z() - x).abs() < 1e-13);
        assert!(s.memory().is_empty() && s.on_virgin_curve());
    }

    #[test]
    fn inner_loops_are_wiped_out() {
        // n = 20: rho^n < 1e-4 below 0.63 Fs, so the hysteresis is that of z = x
        let p = LeuvenParams {
            n: 20.0,
            sigma1: 0.0,
            sigma2: 0.0,
            ..P
        };
        let m = p.build::<f64, 8>().unwrap();
        let a = p.xs;
        let (v, h) = (1e-6, 1e-4); // 1e-10 m a step
        let mut s = LeuvenState::default();
        // virgin 0 -> A, then down to -0.8 A: one point above the virgin curve
        drive(&m, &mut s, &[0.0, a, -0.8 * a], v, h);
        assert_eq!(s.memory().len(), 1);
        // Masing: the branch from A is the virgin curve scaled by 2
        let Reversal { z: za, f: fa } = s.memory()[0];
        assert!((fa - fv(za, &p)).abs() < 1e-12);
        let expect = fa - 2.0 * fv((za - s.z()) / 2.0, &p);
        assert!((s.hysteresis_force() - expect).abs() < 1e-12);
        // an inner loop: up to 0.6 A, down to -0.3 A, up to 0.2 A
        let mut with_loop = s;
        drive(
            &m,
            &mut with_loop,
            &[-0.8 * a, 0.6 * a, -0.3 * a, 0.2 * a],
            v,
            h,
        );
        assert_eq!(with_loop.memory().len(), 4);
        let f_inner = with_loop.memory()[2].f;
        // on up: the inner loop closes at 0.6 A, both its points are popped
        let tail = drive(&m, &mut with_loop, &[0.2 * a, 0.59 * a], v, h);
        assert_eq!(with_loop.memory().len(), 4);
        assert!(tail.iter().all(|&(_, f)| f < f_inner + 1e-12));
        drive(&m, &mut with_loop, &[0.59 * a, 0.61 * a], v, h);
        assert_eq!(with_loop.memory().len(), 2);
        // the force continues on the outer branch: as without the loop
        let mut plain = s;
        drive(&m, &mut plain, &[-0.8 * a, 0.61 * a], v, h);
        let (f1, f0) = (with_loop.hysteresis_force(), plain.hysteresis_force());
        assert!((f1 - f0).abs() < 1e-6, "{f1} vs {f0}");
        assert_eq!(plain.memory().len(), 2);
        // past A the outer loop closes too: back on the virgin curve
        drive(&m, &mut plain, &[0.61 * a, 1.05 * a], v, h);
        assert!(plain.memory().is_empty());
        let f = plain.hysteresis_force();
        assert!((f - fv(plain.z(), &p)).abs() < 1e-12, "{f}");
        assert!((plain.z() - 1.05 * a).abs() < 2e-2 * a);
    }

    #[test]
    fn sliding_clears_the_memory_and_reaches_the_curve() {
        let m = P.build::<f64, 8>().unwrap();
        let mut s = LeuvenState::default();
        drive(
            &m,
            &mut s,
            &[0.0, 1e-5, -0.5e-5, 0.5e-5, -0.2e-5],
            1e-6,
            1e-4,
        );
        assert_eq!(s.memory().len(), 3);
        let mut f = 0.0;
        for _ in 0..2000 {
            f = m.step(&mut s, 1e-2, 1e-4);
        }
        // the slide passed or cleared every point below the current branch
        // (the first, 1.18 N, lies above g = 1 N: it is cleared)
        assert_eq!(s.memory().len(), 1);
        assert!(!s.on_virgin_curve());
        let expect = m.steady_state(1e-2);
        assert!((f - expect).abs() < 1e-6 * expect, "{f} vs {expect}");
        // a point above the sliding level at speed is cleared by the slide:
        // creep to 1.45 N, back off, slide at 1 cm/s (g = 1 N)
        let mut s = LeuvenState::default();
        for _ in 0..100_000 {
            m.step(&mut s, 1e-6, 1e-3);
            if s.hysteresis_force() > 1.45 {
                break;
            }
        }
        drive(&m, &mut s, &[0.0, -2e-5], 1e-6, 1e-4);
        assert!(s.hysteresis_force() < 0.0);
        assert_eq!(s.memory().len(), 1);
        for _ in 0..2000 {
            f = m.step(&mut s, 1e-2, 1e-4);
        }
        assert_eq!(s.memory().len(), 1);
        assert!(!s.on_virgin_curve());
        let expect = m.steady_state(1e-2);
        assert!((f - expect).abs() < 1e-6 * expect, "{f} vs {expect}");
    }

    /// A generous Lipschitz-type constant of `F(t)` along a velocity signal
    /// with `|v| <= vmax`, `|dv/dt| <= amax`: `|dFh/dt| <= (Fs/xs) |dz/dt|`,
    /// `|dz/dt| <= |v| max(1, R - 1)`, and `d(dz/dt)/dt` from the law.
    fn lipschitz(p: &LeuvenParams, vmax: f64, amax: f64) -> f64 {
        let (fc, fs) = (p.curve.fc, p.curve.fs);
        let k = fs / p.xs;
        let r = (fs / fc).powf(p.n);
        let rate = vmax * (r - 1.0).max(1.0);
        // |dg/dv| <= (Fs - Fc) sqrt(2/e) / vs for the exponent-2 curve
        let dg = (fs - fc) * (2.0 / core::f64::consts::E).sqrt() / p.curve.vs;
        let drho = k * rate / fc + fs * dg * amax / (fc * fc);
        let dzdot = amax * (1.0 + r) + vmax * p.n * r * drho;
        k * rate + p.sigma1 * dzdot + p.sigma2 * amax
    }

    /// Steps `m` along `v(t)` with step `h`; checks `|F(t+h) - F(t)| <= 2 L h`
    /// and counts memory growth (pushes) and shrinkage (pops, clears).
    fn check_continuity<const M: usize>(
        p: &LeuvenParams,
        v: impl Fn(f64) -> f64,
        vmax: f64,
        amax: f64,
        h: f64,
        steps: usize,
    ) -> (usize, usize, usize) {
        let m = p.build::<f64, M>().unwrap();
        let l = lipschitz(p, vmax, amax);
        let mut s = LeuvenState::<f64, M>::default();
        let mut f_prev = m.step(&mut s, v(0.0), 0.0);
        let (mut grew, mut shrank, mut full) = (0, 0, 0);
        for k in 1..=steps {
            let len = s.memory().len();
            let f = m.step(&mut s, v(k as f64 * h), h);
            let jump = (f - f_prev).abs();
            assert!(
                jump <= 2.0 * l * h,
                "step {k}: |dF| {jump:.3e} > 2 L h = {:.3e} (memory {len} -> {})",
                2.0 * l * h,
                s.memory().len()
            );
            let now = s.memory().len();
            grew += usize::from(now > len);
            shrank += usize::from(now < len);
            full += usize::from(now == M && len == M && !s.on_virgin_curve());
            assert!(now <= M);
            f_prev = f;
        }
        (grew, shrank, full)
    }

    #[test]
    fn force_is_continuous_through_every_transition() {
        // two tones: reversals of varying depth, inner loops, slides both ways
        let w1 = 2.0 * core::f64::consts::PI * 5.0;
        let w2 = 2.0 * core::f64::consts::PI * 37.0;
        let a = 1e-3;
        let v = move |t: f64| a * ((w1 * t).sin() + 0.7 * (w2 * t).sin());
        let (vmax, amax) = (1.7 * a, a * (w1 + 0.7 * w2));
        let h = 5e-7;
        for n in [1.0, 2.0, 3.5] {
            let p = LeuvenParams { n, ..P };
            let (grew, shrank, _) = check_continuity::<16>(&p, v, vmax, amax, h, 2_000_000);
            assert!(
                grew > 20 && shrank > 10,
                "n {n}: {grew} pushes, {shrank} pops"
            );
            // a full memory of 2 drops points on most pushes: still continuous
            let (grew, _, full) = check_continuity::<2>(&p, v, vmax, amax, h, 2_000_000);
            assert!(grew > 10 && full > 0, "n {n}: {grew} pushes, {full} full");
        }
    }

    #[test]
    fn the_original_law_would_jump_at_a_pop() {
        // the test above can fail: with dz/dt = v (1 - (Fd / (s - Fb))^n) the
        // damping term jumps by sigma1 v times the change of the ratio when
        // Fb changes; here that jump against the bound 2 L h of that test
        let p = P;
        let (fb_inner, fb_outer, fh, g, v) = (0.2, -0.8, 0.5, 1.5, 1e-3);
        let ratio = |fb: f64| ((fh - fb) / (g - fb)).powf(p.n);
        let jump = p.sigma1 * v * (ratio(fb_inner) - ratio(fb_outer)).abs();
        let tau = 2.0 * core::f64::consts::PI;
        let bound = 2.0 * lipschitz(&p, 1.7e-3, 1e-3 * tau * (5.0 + 0.7 * 37.0)) * 5e-7;
        assert!(jump > 5.0 * bound, "{jump:.2e} vs {bound:.2e}");
    }

    #[test]
    fn a_full_memory_forgets_the_outer_loop_and_stays_continuous() {
        // nested loops three deep: M = 2 forgets the outermost, M = 8 does not
        let p = LeuvenParams {
            n: 20.0,
            sigma1: 0.0,
            sigma2: 0.0,
            ..P
        };
        let a = p.xs;
        let (v, h) = (1e-6, 1e-4);
        let path = [
            0.0,
            a,
            -0.9 * a,
            0.7 * a,
            -0.5 * a,
            0.3 * a,
            -0.1 * a,
            0.95 * a,
        ];
        let m8 = p.build::<f64, 8>().unwrap();
        let m2 = p.build::<f64, 2>().unwrap();
        let (mut s8, mut s2) = (LeuvenState::default(), LeuvenState::default());
        let t8 = drive(&m8, &mut s8, &path, v, h);
        let t2 = drive(&m2, &mut s2, &path, v, h);
        assert!(s2.memory().len() <= 2 && !s2.on_virgin_curve());
        // identical until the memory of 2 overflows, and never more than
        // 2 Fs apart; they differ once a forgotten loop should have closed
        let mut worst: f64 = 0.0;
        for ((x, f8), (_, f2)) in t8.iter().zip(&t2) {
            assert!(f2.is_finite() && f2.abs() <= p.curve.fs);
            worst = worst.max((f8 - f2).abs());
            let _ = x;
        }
        assert!(worst > 1e-3, "the loss of accuracy shows: {worst}");
        assert!(worst < 2.0 * p.curve.fs);
        // steps of M = 2 are continuous (|dF| <= Fs/xs |dx| with margin)
        for w in t2.windows(2) {
            assert!((w[1].1 - w[0].1).abs() <= 2.0 * 1.5 / a * v * h + 1e-12);
        }
        // after a slide both agree again: sliding clears both memories
        let (mut f8, mut f2) = (0.0, 0.0);
        for _ in 0..1000 {
            f8 = m8.step(&mut s8, -1e-2, 1e-4);
            f2 = m2.step(&mut s2, -1e-2, 1e-4);
        }
        assert!((f8 - f2).abs() < 1e-9, "{f8} {f2}");
    }

    #[test]
    fn thousands_of_tiny_reversals_keep_the_memory_bounded() {
        let m = P.build::<f32, 4>().unwrap();
        let m64 = P.build::<f64, 4>().unwrap();
        let (mut s, mut s64) = (LeuvenState::default(), LeuvenState::default());
        let rng = crate::random::CounterRng::new(7);
        for k in 0..20_000u32 {
            // alternating, shrinking then growing, with random depth
            let amp = 1e-3 * (1.0 + (k as f64 * 0.01).sin()) * rng.unit::<f64>(0, k);
            let v = if k % 2 == 0 { amp } else { -0.97 * amp };
            let f = m.step(&mut s, v as f32, 1e-4);
            let f64_ = m64.step(&mut s64, v, 1e-4);
            assert!(f.is_finite() && f64_.is_finite());
            assert!(s.memory().len() <= 4 && s64.memory().len() <= 4);
            assert!(s.hysteresis_force().abs() <= 1.5 && s64.hysteresis_force().abs() <= 1.5);
            assert!(s.z().is_finite() && s64.z().abs() < 1.0);
        }
        // a memory filled with nested loops is passed in one step: at most
        // M - 1 pops, back to a single point
        let mut s = LeuvenState::<f64, 8>::default();
        let m8 = P.build::<f64, 8>().unwrap();
        let mut amp = 8e-6;
        m8.step(&mut s, 1.0, amp);
        for _ in 0..8 {
            amp *= 0.8;
            m8.step(&mut s, -1.0, amp);
            amp *= 0.8;
            m8.step(&mut s, 1.0, amp);
        }
        assert_eq!(s.memory().len(), 8);
        m8.step(&mut s, -1e-3, 1e-2);
        assert!(s.memory().len() <= 1, "{:?}", s.memory());
    }

    #[test]
    fn a_correction_holds_the_estimate_at_fs() {
        use crate::Observer;
        let m = P.build::<f64, 4>().unwrap();
        let o = Observer::new(m, 1e3).unwrap();
        let mut s = LeuvenState::default();
        let mut f = 0.0;
        for _ in 0..200 {
            f = o.step(&mut s, 0.0, 1.0, 1e-3);
        }
        // held at -Fs
        let held = s;
        assert_eq!(s.hysteresis_force(), -1.5);
        assert!((f - s.hysteresis_force()).abs() < 1e-12, "{f}");
        o.step(&mut s, 0.0, 1.0, 1e-3);
        assert_eq!(s, held);
        // moving forwards with the correction pushing back: held, dz/dt = 0
        let f = o.step(&mut s, 1e-4, 1.0, 1e-3);
        assert!(f.abs() <= m.force_bound(1e-4));
        assert_eq!(s.hysteresis_force(), held.hysteresis_force());
        assert!(
            (f - (held.hysteresis_force() + 0.4 * 1e-4)).abs() < 1e-12,
            "{f}"
        );
    }

    fn arb_params() -> impl Strategy<Value = LeuvenParams> {
        (
            0.1f64..10.0,
            1.0f64..3.0,
            1e-4f64..1e-1,
            0.5f64..3.0,
            0.0f64..1e3,
            0.0f64..10.0,
            1.0f64..5.0,
            1e-7f64..1e-3,
        )
            .prop_map(
                |(fc, ratio, vs, exponent, sigma1, sigma2, n, xs)| LeuvenParams {
                    curve: StribeckParams {
                        fc,
                        fs: fc * ratio,
                        vs,
                        exponent,
                    },
                    sigma1,
                    sigma2,
                    n,
                    xs,
                },
            )
    }

    fn arb_inputs() -> impl Strategy<Value = Vec<(f64, f64)>> {
        proptest::collection::vec(
            (
                prop_oneof![-1e3f64..1e3, -1e-3f64..1e-3, -1e-6f64..1e-6, Just(0.0)],
                prop_oneof![0.0f64..1e-2, Just(0.0), 0.0f64..10.0, 0.0f64..1e-6],
            ),
            1..80,
        )
    }

    proptest! {
        #[test]
        fn states_stay_bounded_and_forces_finite(p in arb_params(), inputs in arb_inputs()) {
            let m = p.build::<f64, 3>().unwrap();
            let m32 = p.build::<f32, 3>().unwrap();
            let (mut s, mut s32) = (LeuvenState::default(), LeuvenState::default());
            let fs = p.curve.fs;
            for (v, h) in inputs {
                let f = m.step(&mut s, v, h);
                let f32_ = m32.step(&mut s32, v as f32, h as f32);
                prop_assert!(f.is_finite() && f32_.is_finite());
                prop_assert!(f.abs() <= m.force_bound(v) * (1.0 + 1e-12));
                prop_assert!(s.hysteresis_force().abs() <= fs);
                prop_assert!(s32.hysteresis_force().abs() <= fs as f32);
                prop_assert!(s.memory().len() <= 3 && s32.memory().len() <= 3);
                // z within the reach of every remembered branch: 3 x 2.8 xs
                prop_assert!(s.z().abs() <= 10.0 * p.xs, "{:?}", s);
                prop_assert!(s32.z().is_finite());
            }
        }

        #[test]
        fn steady_state_is_the_stribeck_map(p in arb_params(), v in prop_oneof![-1.0f64..-1e-6, 1e-6f64..1.0]) {
            let m = p.build::<f64, 4>().unwrap();
            let mut s = LeuvenState::default();
            let mut f = 0.0;
            // relaxation rate at least n |v| (Fm - Fs) / (2 xs g): five long
            // implicit steps
            let h = 1e4 * p.xs / v.abs();
            for _ in 0..5 {
                f = m.step(&mut s, v, h);
            }
            let expected = m.steady_state(v);
            let tol = 1e-9 * expected.abs();
            prop_assert!((f - expected).abs() <= tol, "{} vs {}", f, expected);
        }

        #[test]
        fn extreme_finite_inputs_stay_finite(v in proptest::num::f64::NORMAL, h in proptest::num::f64::POSITIVE) {
            let m = P.build::<f32, 2>().unwrap();
            let mut s = LeuvenState::default();
            for _ in 0..3 {
                let f = m.step(&mut s, v as f32, h as f32);
                prop_assert!(f.is_finite());
                let f = m.step(&mut s, -v as f32 * 0.5, h as f32);
                prop_assert!(f.is_finite());
            }
            prop_assert!(s.hysteresis_force().abs() <= 1.5 && s.z().is_finite());
        }
    }
}
