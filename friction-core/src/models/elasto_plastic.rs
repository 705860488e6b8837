//! The elasto-plastic model (Dupont, Hayward, Armstrong, Altpeter 2002).
//!
//! LuGre with a purely elastic pre-sliding regime, which removes drift:
//!
//! ```text
//! dz/dt = v - alpha(z, v) sigma0 |v| z / g(v)
//! F     = sigma0 z + sigma1 dz/dt + sigma2 v
//! z_max(v) = g(v) / sigma0,   0 < z_ba < Fc / sigma0 <= z_max(v)
//! alpha = 0                                                       |z| <= z_ba
//!       = 1/2 + 1/2 sin(pi (|z| - (z_max + z_ba)/2) / (z_max - z_ba))   z_ba < |z| < z_max
//!       = 1                                                       |z| >= z_max
//! (each when sign z = sign v; alpha = 0 when they differ)
//! ```
//!
//! Discretisation: with `v` held over the step, write `w = z sign(v)` (the
//! deflection along the motion) and `xi = |v| h` (the distance slid); then
//! `dw/dxi = 1 - alpha(w) w / z_max`, a scalar autonomous equation:
//!
//! - below `z_ba` it is `w + xi`, exact: no drift, `z` follows the displacement;
//! - above `z_max` (`alpha = 1`) it is linear, solved exactly:
//!   `z_max + (w - z_max) e^(-xi / z_max)`;
//! - in the transition zone, with `u = (z_max - w) / (z_max - z_ba)` in `[0, 1]`
//!   and `eps = (z_max - z_ba) / z_max`, `1 - alpha = sin^2(pi u / 2)` and
//!   `du/dxi' = -u r(u)`, `r = eps + b(u) u`, `b = (pi/2)^2 (sin(phi)/phi)^2 (1 - eps u)`,
//!   `phi = pi u / 2`, `xi' = xi / (z_max - z_ba)`. `sin(phi)/phi` is its Taylor
//!   polynomial to `phi^12` (error below 4.3e-10 on the bounded phase), so no
//!   `sin` is called. Classical RK4 sub-steps of length
//!   `0.5 / (r + (pi/2)^2 u)` (so `h r <= 0.5`) run until the distance is used
//!   or `u <= 0.01`, at most 24 of them (from `u = 1` 22 suffice for any
//!   `eps`, which a test checks: where `alpha`'s sine dominates, each
//!   sub-step shrinks `u` by about `1/1.25`). The rest is the tail, where
//!   `r = eps + b u` with `b` frozen at its entry value is a Riccati equation
//!   with the exact solution `u e^(-eps xi') / (1 + b u (1 - e^(-eps xi')) / eps)`;
//!   `b` varies by less than `1e-4 + eps u` relative there.
//!
//! One long step matches many tiny ones, and the sheet's equation with `sin`
//! integrated finely, to `3e-5 (z_max - z_ba)` in `w` for any distance; on
//! the validation signals the step is the exact solution for the held
//! velocity to `5e-6 Fs` RMS in force. The distance past `z_ba` is capped at `1024 z_max`
//! (beyond it `e^(-1024)` rounds to 0), so every step is finite for any
//! finite `v` and `h`, also in `f32`; `|z| <= Fs/sigma0` is kept by a final
//! clamp, and the steady state (`u = 0`, `w = z_max`) is exactly the Stribeck map.
//!
//! Worst-case cost per step: 24 RK4 sub-steps of 4 evaluations of `r(u)` (a
//! degree-6 polynomial in `phi^2`, no `sin`) plus the first, 97 in all, one
//! more for the damping term, one division per sub-step, and one `exp` and
//! one `exp_m1` in the tail. The elastic part and the region above `z_max`
//! cost no evaluation; steady sliding (`u <= 0.01`) one, plus the tail.
//! The cost guide gives the measured worst case, and the former
//! implicit-Euler step's with `sinf`, which was dearer by an order of
//! magnitude.

use crate::fixed_step::{checked_velocity, signed, FixedStepModel, FixedStepObservable};
use crate::model::{checked_inputs, convert, magnitude, FrictionModel, ParamError};
use crate::models::lugre::{phi_series, LuGre, LuGreAt, LuGreAtState, LuGreParams, LuGreState};
use crate::observer::Observable;
use crate::Scalar;

/// Elasto-plastic parameters (`model = "elasto-plastic"`): LuGre's and `z_ba`.
///
/// ```
/// use friction_core::{ElastoPlasticParams, FrictionModel, LuGreParams, LuGreState};
/// let p = ElastoPlasticParams { lugre: LuGreParams::CANUDAS_1995, z_ba: 5e-6 };
/// let model = p.build::<f64>()?;
/// let mut state = LuGreState::default();
/// // 2 µm of displacement below z_ba: purely elastic, F = sigma0 x
/// let f = model.step(&mut state, 2e-6, 1.0);
/// assert!((state.z - 2e-6).abs() < 1e-18);
/// // F = sigma0 z + (sigma1 + sigma2) v, as dz/dt = v in the elastic regime
/// let (sigma1, sigma2) = (p.lugre.sigma1, p.lugre.sigma2);
/// assert!((f - (0.2 + (sigma1 + sigma2) * 2e-6)).abs() < 1e-9);
/// # Ok::<(), friction_core::ParamError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ElastoPlasticParams {
    /// The LuGre parameters (curve, `sigma0`, `sigma1`, `sigma2`, optional `vd`).
    pub lugre: LuGreParams,
    /// Break-away deflection `0 < z_ba < Fc / sigma0` (m).
    pub z_ba: f64,
}

impl ElastoPlasticParams {
    /// Checks every parameter; the error names the first offending one.
    pub fn validate(&self) -> Result<(), ParamError> {
        self.lugre.validate()?;
        magnitude("z_ba", self.z_ba)?;
        if self.z_ba >= self.lugre.curve.fc / self.lugre.sigma0 {
            return Err(ParamError::NotBelow {
                name: "z_ba",
                limit: "fc / sigma0",
            });
        }
        Ok(())
    }

    /// Validates and builds the run-time model.
    pub fn build<S: Scalar>(&self) -> Result<ElastoPlastic<S>, ParamError> {
        self.validate()?;
        Ok(ElastoPlastic {
            lugre: self.lugre.build()?,
            z_ba: convert("z_ba", self.z_ba)?,
        })
    }

    /// Validates and builds the fixed-step form for sample period `h` (s):
    /// see [`ElastoPlasticAt`]. The checks are [`LuGreParams::build_at`]'s,
    /// and `sigma0 z_ba` must be representable.
    ///
    /// ```
    /// use friction_core::{ElastoPlasticParams, FixedStepModel, LuGreAtState, LuGreParams};
    /// let p = ElastoPlasticParams { lugre: LuGreParams::CANUDAS_1995, z_ba: 5e-6 };
    /// let model = p.build_at::<f64>(1e-3)?;
    /// let mut state = LuGreAtState::default();
    /// // 2 µm of displacement below z_ba: purely elastic, w = sigma0 x
    /// model.step(&mut state, 2e-3);
    /// assert!((state.w - 0.2).abs() < 1e-12);
    /// # Ok::<(), friction_core::ParamError>(())
    /// ```
    pub fn build_at<S: Scalar>(&self, h: f64) -> Result<ElastoPlasticAt<S>, ParamError> {
        self.validate()?;
        let lugre: LuGreAt<S> = self.lugre.build_at(h)?;
        Ok(ElastoPlasticAt {
            w_ba: convert("z_ba", lugre.force_scale() * self.lugre.sigma0 * self.z_ba)?,
            lugre,
            max_substeps: DEFAULT_SUBSTEPS,
        })
    }
}

/// The built elasto-plastic model. Its state is a [`LuGreState`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ElastoPlastic<S> {
    lugre: LuGre<S>,
    z_ba: S,
}

impl<S: Scalar> ElastoPlastic<S> {
    /// The break-away deflection `z_ba`.
    pub fn z_ba(&self) -> S {
        self.z_ba
    }

    /// `dw/dxi = 1 - alpha(w) w / z_max` at `w`, the deflection along the
    /// motion: the fraction of the sliding that goes into the deflection.
    #[inline]
    fn slip(&self, w: S, z_max: S) -> S {
        if w <= self.z_ba {
            S::ONE
        } else if w >= z_max {
            S::ONE - w / z_max
        } else {
            let width = z_max - self.z_ba;
            let u = ((z_max - w) / width).min(S::ONE);
            let (r, _) = zone_rate(u, width / z_max);
            u * r
        }
    }

    /// One step of the deflection along the motion, `w`, over distance `xi`
    /// (see the module documentation).
    fn advance_w(&self, mut w: S, mut xi: S, z_max: S) -> S {
        // elastic: dw/dxi = 1 up to z_ba
        if w < self.z_ba {
            let reach = self.z_ba - w;
            if xi <= reach {
                return w + xi;
            }
            w = self.z_ba;
            xi = xi - reach;
        }
        // Past the elastic part every path relaxes onto z_max at least as
        // fast as e^(-xi / z_max): beyond 1024 z_max nothing is left to move
        // (e^-1024 is 0 in f32 and f64). The cap keeps xi finite (f32's
        // `v h` can overflow) and every product below free of inf * 0.
        xi = xi.min(S::from_f64(XI_CAP) * z_max);
        // above z_max alpha = 1: dw/dxi = 1 - w / z_max, exact relaxation
        if w >= z_max {
            return z_max + (w - z_max) * (-(xi / z_max)).exp();
        }
        // transition zone, z_ba <= w < z_max, so width > 0
        let width = z_max - self.z_ba;
        let eps = width / z_max;
        let u = ((z_max - w) / width).min(S::ONE);
        let (u, _) = zone_step(u, xi / width, eps);
        z_max - u * width
    }

    /// `alpha(w)` along the motion (`w = z sign v`): 0 up to `z_ba`, 1 from
    /// `z_max`, `1 - sin^2(pi u / 2)` in the zone.
    #[inline]
    fn alpha(&self, w: S, z_max: S) -> S {
        if w <= self.z_ba {
            S::ZERO
        } else if w >= z_max {
            S::ONE
        } else {
            let u = ((z_max - w) / (z_max - self.z_ba)).min(S::ONE);
            relaxed_fraction(u)
        }
    }

    /// One step: the model's motion along `v`, then the observer's
    /// correction (`c = 0` for the model; see [`corrected_shift`]), clamped
    /// to `±Fs/sigma0`. `h = 0` leaves the state untouched.
    fn advance(&self, state: &mut LuGreState<S>, v: S, correction: S, h: S, damping: bool) -> S {
        let s = v.sign();
        let z_max = self.lugre.curve().eval(v) / self.lugre.sigma0();
        let mut z = state.z;
        // the model's own end state, and the fraction of the correction's
        // rate left at the end of the step
        let mut z_model = z;
        let mut kept = S::ONE;
        if h > S::ZERO {
            if s != S::ZERO {
                z = s * self.advance_w(s * z, v.abs() * h, z_max);
            }
            z_model = z;
            if correction != S::ZERO {
                let xi = v.abs() * h / z_max;
                let relax = |w: S| self.alpha(w, z_max) * w;
                // no shift moves the state further than across its bound
                let shift = (s * correction * h).sat(S::from_f64(2.0) * self.lugre.z_max());
                let (phi, left) = corrected_shift(s * z, shift, xi, relax);
                z = z - correction * h * phi;
                kept = left;
            }
            z = z.sat(self.lugre.z_max());
            state.z = z;
        }
        let mut f = self.lugre.sigma0() * z + self.lugre.sigma2() * v;
        if damping {
            // dz/dt at the end of the step: the model's rate on its own path
            // plus the correction's share; zero while held at the bound
            let mut dz = v * self.slip(s * z_model, z_max) - correction * kept;
            if z.abs() >= self.lugre.z_max() && dz * z > S::ZERO {
                dz = S::ZERO;
            }
            f = f + self.lugre.damping(v) * dz;
        }
        f
    }
}

/// `alpha = 1 - sin^2(pi u / 2) = 1 - (pi/2)^2 u^2 (sin(phi)/phi)^2` at the
/// normalised zone position `u` in `[0, 1]`.
#[inline]
fn relaxed_fraction<S: Scalar>(u: S) -> S {
    let x = S::from_f64(Q).mul_fraction(u).mul_fraction(u);
    let p = sin_over_phi(x.mul_fraction(S::from_f64(0.25)));
    (S::ONE - x.mul_fraction(p).mul_fraction(p)).max(S::ZERO)
}

/// The observer's correction over one step against the model's relaxation.
///
/// Along the motion (`w = z sign v`, distance slid `xi` in units of `z_max`)
/// the corrected state obeys `dw/dt = |v| (1 - R(w)) - c'`, with the
/// relaxation `R(w) = alpha(w) w / z_max` and `c' = c sign v`. The
/// difference `d = w - w_m` from the model's own path `w_m` then follows
/// `dd/dt = -c' - lambda d`, where `lambda / |v|` is the slope of `R`
/// between `w_m` and `w_m + d`: the secant over the shift that the slope
/// above `z_max` gives, refined twice over the shift each gives (exact below
/// `z_ba`, where `R = 0`, and above `z_max`, where `R` is linear; at the
/// corrected steady state of steady sliding, `R(w) = 1 - c'/|v|` exactly).
/// Over the step `d = -c' h phi(x)` with `x = lambda h`,
/// `phi(x) = (1 - e^-x) / x`, and the correction's share of `dw/dt` at the
/// end of the step is `-c' e^-x`.
///
/// Given `w_m`, `shift = c' h`, `xi = |v| h / z_max` and `alpha_w(w) =
/// alpha(w) w` (any consistent force or length unit), returns
/// `(phi, e^-x)`: the state moves by `-c h phi`, the damping term carries
/// `-sigma1 c e^-x`.
///
/// Why: applying `z <- z - c h` after the step and `-c` in the damping term
/// (first-order splitting) left the full `sigma1 c = sigma1 k e` in the
/// estimate while sliding, where the model relaxes it away within
/// microseconds. On canudas1995 (`sigma1 k = 6,300 N m/rad` against
/// `kp = 60`) that gain destabilised the sampled servo loop (observer
/// 172 mrad RMS against 8.1 mrad without compensation).
#[inline]
pub(crate) fn corrected_shift<S: Scalar>(
    w_m: S,
    shift: S,
    xi: S,
    alpha_w: impl Fn(S) -> S,
) -> (S, S) {
    let r_m = alpha_w(w_m);
    // secant slope of alpha w over a shift `d`, within [0, MAX_SLOPE]
    // (also for a NaN quotient of extreme inputs; 0 where d vanishes)
    let slope = |d: S| {
        let q = if d == S::ZERO {
            S::ZERO
        } else {
            (r_m - alpha_w(w_m - d)) / d
        };
        if q >= S::ZERO {
            q.min(S::from_f64(MAX_SLOPE))
        } else {
            S::ZERO
        }
    };
    // start from the slope above z_max (1), then refine twice
    let (mut phi, mut left) = shift_factors(xi);
    for _ in 0..2 {
        (phi, left) = shift_factors(slope(shift * phi) * xi);
    }
    (phi, left)
}

/// Largest secant slope of `alpha w` that [`corrected_shift`] uses: beyond
/// it `lambda h` is far past where `e^-x` vanishes for any distance slid
/// that moves the state.
const MAX_SLOPE: f64 = 1e4;
/// Largest `lambda h` [`shift_factors`] takes (`e^-1000` is 0 in f32 and f64).
const MAX_RELAXATION: f64 = 1000.0;

/// `(phi(x), e^-x)` with `phi(x) = (1 - e^-x) / x` for `x >= 0`; `x` is
/// capped at [`MAX_RELAXATION`] (also a NaN `x`, from an infinite distance
/// times a zero slope), so `phi >= 1e-3` and no product with it is `inf * 0`.
#[inline]
fn shift_factors<S: Scalar>(x: S) -> (S, S) {
    let cap = S::from_f64(MAX_RELAXATION);
    let x = if x <= cap { x } else { cap };
    let left = x.exp_neg();
    let phi = if x > S::from_f64(1e-3) {
        (S::ONE - left) / x
    } else {
        // 1 - x/2 + x^2/6: the series, within 5e-11 below 1e-3
        S::ONE - x * (S::from_f64(0.5) - x * S::from_f64(1.0 / 6.0))
    };
    (phi, left)
}

/// Largest distance slid past the elastic part that a step integrates, in
/// units of `z_max` (see `advance_w`).
const XI_CAP: f64 = 1024.0;
/// Sub-steps of the transition zone: each has `h r <= RK_REACH`.
const RK_REACH: f64 = 0.5;
/// Most sub-steps in one step; 22 suffice from `u = 1` down to `TAIL` (the
/// distance shrinks by at least `1 / (1 + RK_REACH / 2)` a sub-step).
const MAX_SUBSTEPS: usize = 24;
/// RK4 sub-steps of the zone the fixed-step form takes when built: none, so
/// that its worst step stays within the 4x its average a real-time loop is
/// sized by on every core and scalar (the full step's worst is 20x on a
/// Cortex-M4F; see [`ElastoPlasticAt::with_max_substeps`]).
const DEFAULT_SUBSTEPS: u8 = 0;
/// Below this normalised distance to `z_max` the closed-form tail takes over.
const TAIL: f64 = 0.01;
/// `(pi / 2)^2`.
const Q: f64 = core::f64::consts::PI * core::f64::consts::PI / 4.0;

/// Advances the normalised distance to `z_max`, `u` (see [`zone_rate`]), over
/// `left` zone widths of sliding: RK4 sub-steps down to `u <= TAIL`, then the
/// exact tail. Returns `u` and the number of sub-steps taken.
fn zone_step<S: Scalar>(mut u: S, mut left: S, eps: S) -> (S, usize) {
    let (mut r, mut b) = zone_rate(u, eps);
    let (c, tail) = (S::from_f64(RK_REACH), S::from_f64(TAIL));
    let half = S::from_f64(0.5);
    let sixth = S::from_f64(1.0 / 6.0);
    let mut taken = 0;
    while taken < MAX_SUBSTEPS && u > tail {
        // h r <= c keeps the sub-step within the local relaxation length, and
        // the Q u term shortens it where alpha's sine curves most
        let h = (c / (r + S::from_f64(Q) * u)).min(left);
        let k1 = r.mul_fraction(u);
        let u2 = u - half * h * k1;
        let k2 = zone_rate(u2, eps).0.mul_fraction(u2);
        let u3 = u - half * h * k2;
        let k3 = zone_rate(u3, eps).0.mul_fraction(u3);
        let u4 = u - h * k3;
        let k4 = zone_rate(u4, eps).0.mul_fraction(u4);
        u = (u - sixth * h * (k1 + S::from_f64(2.0) * (k2 + k3) + k4)).max(S::ZERO);
        left = left - h;
        taken += 1;
        if left <= S::ZERO {
            return (u, taken);
        }
        (r, b) = zone_rate(u, eps);
    }
    // tail: du/dxi' = -(eps + b u) u with b frozen at the tail's entry is a
    // Riccati equation, solved exactly:
    // u+ = u e^(-eps xi') / (1 + b u (1 - e^(-eps xi')) / eps)
    let decay = (-(eps * left)).exp();
    let grown = -(-(eps * left)).exp_m1() / eps;
    (u * decay / (S::ONE + b * u * grown), taken)
}

/// The transition zone in normalised form: `u = (z_max - w) / (z_max - z_ba)`
/// in `[0, 1]`, `eps = (z_max - z_ba) / z_max` in `(0, 1]`. There
/// `1 - alpha = sin^2(pi u / 2)` and `dw/dxi = u r(u)` with
/// `r = eps + b u`, `b = (pi/2)^2 P^2 (1 - eps u)` and
/// `P = sin(phi) / phi` (`phi = pi u / 2`) a polynomial: returns `(r, b)`.
#[inline]
fn zone_rate<S: Scalar>(u: S, eps: S) -> (S, S) {
    // u, eps and 1 - eps u are fractions; (pi/2)^2 P^2 from
    // `Scalar::zone_curve`
    let b = u.zone_curve().mul_fraction(S::ONE - eps.mul_fraction(u));
    (eps + b.mul_fraction(u), b)
}

/// `(pi/2)^2 P^2` (`P = sin(phi) / phi`, `phi = pi u / 2`) from the series
/// of `P` in the fraction `(phi/2)^2`: [`Scalar::zone_curve`]'s default.
#[inline]
pub(crate) fn zone_curve_series<S: Scalar>(u: S) -> S {
    // u, p = sin(phi)/phi and (phi/2)^2 are fractions
    let y = S::from_f64(Q / 4.0).mul_fraction(u).mul_fraction(u); // (phi/2)^2
    let p = sin_over_phi(y);
    S::from_f64(Q).mul_fraction(p).mul_fraction(p)
}

/// `sin(phi) / phi` from `y = (phi/2)^2 <= (pi/4)^2`: the Taylor series
/// `sum_n (-4y)^n / (2n + 1)!` with `4^n` folded into the coefficients, so
/// that in fixed point every product is with the fraction `y`
/// ([`Scalar::mul_fraction`], cheaper on a Cortex-M0). Its terms run to `phi^12`
/// in `f64` (error below `(pi/2)^14 / 15! = 4.3e-10`), to `phi^10` in a
/// scalar that cannot tell `1 + 1e-9` from 1 (`f32`: below `3.6e-8`, under
/// half its unit at 1) and to `phi^8` in one that cannot tell `1 + 4e-6`
/// from 1 (Q16.16: below `2.3e-6`, a third of its half step): tests the
/// compiler folds away.
#[inline]
fn sin_over_phi<S: Scalar>(y: S) -> S {
    // 4^n / (2n + 1)!
    let c = |four_n: f64, factorial: f64| S::from_f64(four_n / factorial);
    let y_times = |a: S| a.mul_fraction(y);
    let tail = if S::from_f64(1.0 + 4e-6) == S::ONE {
        c(256.0, 362_880.0)
    } else if S::from_f64(1.0 + 1e-9) == S::ONE {
        c(256.0, 362_880.0) - y_times(c(1024.0, 39_916_800.0))
    } else {
        c(256.0, 362_880.0) - y_times(c(1024.0, 39_916_800.0) - y_times(c(4096.0, 6_227_020_800.0)))
    };
    S::ONE
        - y_times(c(4.0, 6.0) - y_times(c(16.0, 120.0) - y_times(c(64.0, 5040.0) - y_times(tail))))
}

/// `dW/dX` of the fixed-step form at a force `w` along the motion, and in
/// the transition zone its rate `r` (`dW/dX = u r`), which the damping term
/// reuses instead of forming it again (0 outside the zone).
#[derive(Clone, Copy)]
struct Slip<S> {
    slope: S,
    zone_rate: S,
}

/// [`zone_step`] for the fixed-step form, over the distance `xi` (force
/// units, scaled) in a zone of width `width`: returns the rise of the force
/// `w` (scaled), `(u - u+) width`, accumulated in force units (each sub-step
/// as `h width (k1 + 2 k2 + 2 k3 + k4) / 6`, the small tail step as
/// `u xi (1 - e^-x) / x (eps + b u) / (1 + b u left (1 - e^-x) / x)` with
/// `x = eps left`), so that in fixed point a short step is not rounded away
/// in the normalised `u`. A long tail (`x >= 0.1`) shrinks the gap left to
/// `w_max` in force units (`gap` is `w_max - w` at entry), so that a fully
/// relaxed step ends on `w_max` exactly: a gap of one rounding step there is
/// multiplied by `sigma1 |v| / width` in the damping term (in Q16.16, 9 % of
/// Fs for `sigma1 = 95`, `Fs = 0.063` at 1 m/s). The caller clamps
/// `w + rise` to `w_max`. The tail's `phi` comes from its series below
/// `x = 0.1`, `e^-x` from [`Scalar::exp_neg`] above.
fn zone_step_at<S: Scalar>(
    mut u: S,
    mut xi: S,
    width: S,
    eps: S,
    gap: S,
    max_substeps: usize,
) -> S {
    // zone widths left (a quotient of scaled forces)
    let mut left = xi / width;
    let (mut r, mut b) = zone_rate(u, eps);
    let (c, tail) = (S::from_f64(RK_REACH), S::from_f64(TAIL));
    let half = S::from_f64(0.5);
    let sixth = S::from_f64(1.0 / 6.0);
    let mut rise = S::ZERO;
    let mut taken = 0;
    while taken < max_substeps && u > tail {
        let reach = c / (r + S::from_f64(Q) * u);
        // the sub-step in zone widths and in force units
        let (h, h_w) = if reach < left {
            (reach, reach * width)
        } else {
            (left, xi)
        };
        let k1 = r.mul_fraction(u);
        let u2 = u - h.mul_fraction(half) * k1;
        let k2 = zone_rate(u2, eps).0.mul_fraction(u2);
        let u3 = u - h.mul_fraction(half) * k2;
        let k3 = zone_rate(u3, eps).0.mul_fraction(u3);
        let u4 = u - h * k3;
        let k4 = zone_rate(u4, eps).0.mul_fraction(u4);
        let middle = k2 + k3;
        let slope = k1 + (middle + middle) + k4;
        u = (u - h.mul_fraction(sixth) * slope).max(S::ZERO);
        rise = rise + (h_w * slope).mul_fraction(sixth);
        left = left - h;
        xi = xi - h_w;
        taken += 1;
        if left <= S::ZERO {
            return rise;
        }
        (r, b) = zone_rate(u, eps);
    }
    // eps, u, phi, e^-x, 1 - e^-x, a half and a sixth are fractions
    let x = left.mul_fraction(eps);
    if x < S::from_f64(0.1) {
        // u - u+ = u left phi (eps + b u) / (1 + b u phi left), times width
        // (xi = left width): the force-unit distance first
        let phi = phi_series(x);
        let grown = b.mul_fraction(u) * left.mul_fraction(phi);
        rise + (xi * (eps + b.mul_fraction(u)))
            .mul_fraction(u)
            .mul_fraction(phi)
            / (S::ONE + grown)
    } else {
        // u+ / u = e^-x / (1 + b u (1 - e^-x) / eps), applied to the gap, as
        // one quotient in [0, 1]: e^-x eps / (eps + b u (1 - e^-x)), its two
        // small terms lifted by 2^8 (a shift in fixed point, whose rounding
        // of an unlifted eps e^-x would be large relative to it; nothing in
        // floating point)
        let e = x.exp_neg();
        let eps_lifted = eps.rescale_pow2(LIFT);
        let bu_lifted = b.mul_fraction(u).rescale_pow2(LIFT);
        let kept = eps_lifted.mul_fraction(e) / (eps_lifted + bu_lifted.mul_fraction(S::ONE - e));
        let left_gap = (gap - rise).max(S::ZERO);
        gap - left_gap.mul_fraction(kept)
    }
}

/// The power of two the tail's quotient lifts its small terms by.
const LIFT: i8 = 8;

/// The elasto-plastic model built for one sample period `h`
/// ([`ElastoPlasticParams::build_at`]), with the elastic force `w = sigma0 z`
/// as its state ([`LuGreAtState`], `|w| <= Fs`). In force units the
/// model of Dupont, Hayward, Armstrong and Altpeter (2002) reads, along the
/// motion (`W = sign(v) w`, distance `X = sigma0 h |v|`, `sigma0 h` formed
/// at build time):
///
/// ```text
/// dW/dX = 1 - alpha(W) W / g(v),   W_ba = sigma0 z_ba <= W <= g(v) the transition zone
/// w+ = sat(w(X) - sigma0 h c, Fs)
/// F  = w+ + sigma1(v) dz/dt + sigma2 v,   dz/dt = v dW/dX - c
/// ```
///
/// with the variable-step form's discretisation ([`ElastoPlastic`]): exact
/// below `W_ba` and above `g(v)`, in the zone the exact Riccati tail with
/// its rate frozen where the step starts (bounded in cost, the default) or
/// RK4 sub-steps then that tail ([`ElastoPlasticAt::with_full_step`]: the
/// two forms then agree to rounding). `c` is an observer's
/// correction, 0 for the model. As in [`LuGreAt`], forces (the state `w`
/// and `W_ba` included) are carried times its force scale (1 in floating
/// point), ratios of forces are formed from the unscaled `1/g` or as
/// quotients, and the force is returned in newtons.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ElastoPlasticAt<S> {
    lugre: LuGreAt<S>,
    /// `sigma0 z_ba` (N), times the LuGre part's force scale.
    w_ba: S,
    /// RK4 sub-steps of the transition zone a step may take
    /// ([`ElastoPlasticAt::with_max_substeps`]).
    max_substeps: u8,
}

impl<S: Scalar> ElastoPlasticAt<S> {
    /// The same model with at most `k` RK4 sub-steps of the transition zone
    /// a step (0 to 24, clamped; 0 when built, the bounded step; 24, the
    /// full step of [`Self::with_full_step`], is enough for any distance):
    /// a real-time loop sized by its worst step trades accuracy for a
    /// bound. The distance left after `k` sub-steps goes to the closed-form
    /// tail with the rate's `b` frozen where the sub-steps stopped (with
    /// `k = 0`, where the step started). Only a step that crosses most of
    /// the zone at once is affected: measured against the full step over
    /// every distance and zone shape (`eps` 0.01 to 1), the state `w` is off
    /// by at most 14.5 % of the zone's width `g(v) - sigma0 z_ba` with
    /// `k = 0`, 8.7 % with 1 (5.0 % with 2, 2.8 % with 3, 1.5 % with 4,
    /// 0.4 % with 6, 7e-5 with 12). Each sub-step costs four evaluations of
    /// the zone polynomial and a division (dear on a Cortex-M0, which has no
    /// divide instruction); the entry, the tail's exponential and the
    /// damping term's zone rate stay. A real-time loop is sized by its worst
    /// step: with `k = 0` the worst step stays within 4x the average on both
    /// cores and scalars the cost guide measures, with `k = 1` on a
    /// Cortex-M4F in `f32`, while the full step's worst is an order of
    /// magnitude dearer than its average (the cost table's
    /// `elasto-plastic-k0`, `-k1`, `-k3` and `-full` rows give the figures).
    /// The damping term `sigma1 |v| dW/dX` carries the
    /// state's error into the force: from rest, at a speed that crosses
    /// the zone in one step, by up to 49 Fs with `k = 0` (35 Fs with 1, 12
    /// Fs with 3), one step's transient.
    ///
    /// ```
    /// use friction_core::{ElastoPlasticParams, LuGreParams};
    /// let p = ElastoPlasticParams { lugre: LuGreParams::CANUDAS_1995, z_ba: 0.5 / 1e5 };
    /// let real_time = p.build_at::<f32>(1e-3)?.with_max_substeps(3);
    /// # let _ = real_time;
    /// # Ok::<(), friction_core::ParamError>(())
    /// ```
    #[must_use]
    pub fn with_max_substeps(mut self, k: u8) -> Self {
        self.max_substeps = k.min(MAX_SUBSTEPS as u8);
        self
    }

    /// The same model with the full step: as many RK4 sub-steps of the
    /// transition zone as the distance needs (24 at most), the
    /// variable-step form's solution to rounding, at an unbounded cost
    /// (its worst step 20x its average on a Cortex-M4F): for the desk, or
    /// a loop with time to spare.
    ///
    /// ```
    /// use friction_core::{ElastoPlasticParams, LuGreParams};
    /// let p = ElastoPlasticParams { lugre: LuGreParams::CANUDAS_1995, z_ba: 0.5 / 1e5 };
    /// let exact = p.build_at::<f64>(1e-3)?.with_full_step();
    /// # let _ = exact;
    /// # Ok::<(), friction_core::ParamError>(())
    /// ```
    #[must_use]
    pub fn with_full_step(self) -> Self {
        self.with_max_substeps(MAX_SUBSTEPS as u8)
    }

    /// The break-away force `sigma0 z_ba` (N).
    pub fn w_ba(&self) -> S {
        self.lugre.unscale(self.w_ba)
    }

    /// `a / w_max` for `0 <= a <= w_max` (scaled forces), from the unscaled
    /// `1 / g`: `(a / g) k <= k` fits, and no factor is a tiny number.
    #[inline]
    fn ratio(&self, a: S, inv_w_max: S) -> S {
        self.lugre.unscale(a * inv_w_max)
    }

    /// `dW/dX` at the force along the motion `w`, with `w_max = g(v)`
    /// (scaled) and `inv_w_max = 1/g` (unscaled), and in the transition
    /// zone its rate, which the damping term reuses ([`Slip`]).
    #[inline]
    fn slip(&self, w: S, w_max: S, inv_w_max: S) -> Slip<S> {
        if w <= self.w_ba {
            Slip {
                slope: S::ONE,
                zone_rate: S::ZERO,
            }
        } else if w >= w_max {
            // 1 - w / w_max, with w - w_max <= Fs - Fc (scaled) in the product
            Slip {
                slope: -self.lugre.unscale((w - w_max) * inv_w_max),
                zone_rate: S::ZERO,
            }
        } else {
            let width = w_max - self.w_ba;
            let u = ((w_max - w) / width).min(S::ONE);
            let (rate, _) = zone_rate(u, self.ratio(width, inv_w_max));
            Slip {
                slope: u * rate,
                zone_rate: rate,
            }
        }
    }

    /// `alpha` at the force along the motion `w` (scaled), as
    /// [`ElastoPlastic`]'s.
    #[inline]
    fn alpha(&self, w: S, w_max: S) -> S {
        if w <= self.w_ba {
            S::ZERO
        } else if w >= w_max {
            S::ONE
        } else {
            relaxed_fraction(((w_max - w) / (w_max - self.w_ba)).min(S::ONE))
        }
    }

    /// `dv dW/dX` (`dv = sigma1 v`, scaled) given `slip` at `w` (from
    /// [`Self::slip`]): where `dW/dX = (w_max - w) r / width` (`r = 1/w_max`
    /// above `w_max`, the zone rate in it) as `(dv / width) (w_max - w) r`,
    /// the small difference of two scaled forces times a quotient; `dv
    /// dW/dX` if the quotient could saturate.
    #[inline]
    fn damped_slip(&self, dv: S, w: S, w_max: S, slip: Slip<S>) -> S {
        if w <= self.w_ba {
            return dv;
        }
        let (width, r) = if w >= w_max {
            (w_max, S::ONE)
        } else {
            (w_max - self.w_ba, slip.zone_rate)
        };
        // |dv| < 8192 width, without a product that would saturate
        if dv.abs().mul_fraction(S::from_f64(1.0 / 8192.0)) < width {
            (dv / width) * (w_max - w) * r
        } else {
            dv * slip.slope
        }
    }

    /// The force along the motion `w` over the distance `xi` (in force
    /// units, `sigma0 |v| h`), as [`ElastoPlastic`]'s `advance_w`.
    #[inline]
    fn advance_w(&self, mut w: S, mut xi: S, w_max: S, inv_w_max: S) -> S {
        if w < self.w_ba {
            let reach = self.w_ba - w;
            if xi <= reach {
                return w + xi;
            }
            w = self.w_ba;
            xi = xi - reach;
        }
        // xi <= XI_CAP w_max, without a product that would saturate
        if xi.mul_fraction(S::from_f64(1.0 / XI_CAP)) > w_max {
            xi = S::from_f64(XI_CAP) * w_max;
        }
        if w >= w_max {
            // xi / w_max as a quotient of two scaled forces: any product
            // form would saturate (k xi / g) or use a tiny 1/(k g)
            return w_max + (w - w_max) * (xi / w_max).exp_neg();
        }
        let width = w_max - self.w_ba;
        let eps = self.ratio(width, inv_w_max);
        // quotients of scaled forces: 1/width in scaled units is tiny in fixed point
        let u = ((w_max - w) / width).min(S::ONE);
        // at most MAX_SUBSTEPS whatever the stored byte (C may have
        // overwritten it): the same count for a built model
        let substeps = usize::from(self.max_substeps).min(MAX_SUBSTEPS);
        (w + zone_step_at(u, xi, width, eps, w_max - w, substeps)).min(w_max)
    }

    // CORRECTED: the observer's step, with its correction `c`; the model's
    // (c = 0) forms none of its terms (as `LuGreAt`'s)
    #[inline]
    fn advance<const CORRECTED: bool>(
        &self,
        state: &mut LuGreAtState<S>,
        v: S,
        c: S,
        damping: bool,
    ) -> S {
        let lugre = &self.lugre;
        // scaled
        let w_max = lugre.curve().eval_fast(v);
        // 1/g unscaled, g >= Fc > 0, by the quotient: LuGre's reciprocal
        // (`inverse_unscaled`, the same bits) makes the Q16.16 average on a
        // Cortex-M0 cheaper than it makes the `k = 0` worst step, which then
        // sits closer to the enforced 4x than a compiler's layout can be
        // trusted to stay (figures in the cost guide)
        let inv_w_max = lugre.scale_s() / w_max;
        let mut w = state.w;
        let xi = lugre.sigma0_h() * v.abs();
        if v != S::ZERO {
            let along = self.advance_w(signed(v, w), xi, w_max, inv_w_max);
            w = signed(v, along);
        }
        // the model's own end state (its rate enters the damping term)
        let w_model = w;
        // the fraction of the correction's rate left at the end of the step
        let mut kept = S::ONE;
        if CORRECTED && c != S::ZERO {
            // as ElastoPlastic's `advance`, in scaled forces
            let shift = lugre.sigma0_h() * c;
            let relax = |a: S| self.alpha(a, w_max) * a;
            let along = signed(v, shift).sat(lugre.fs() + lugre.fs());
            let (phi, left) = corrected_shift(signed(v, w), along, xi / w_max, relax);
            w = w - shift.mul_fraction(phi);
            kept = left;
        }
        let w = w.sat(lugre.fs());
        state.w = w;
        let mut f = w + lugre.sigma2() * v;
        if damping {
            // at v = 0 the slip is multiplied by 0: its argument's sign is moot
            // the model's rate on its own path plus the correction's share
            let slip = self.slip(signed(v, w_model), w_max, inv_w_max);
            let dz = if CORRECTED {
                v * slip.slope - c * kept
            } else {
                v * slip.slope
            };
            if !(w.abs() >= lugre.fs() && dz * w > S::ZERO) {
                // sigma1 dz/dt = (sigma1 v) dW/dX - sigma1 c kept, with the
                // product formed so that no rounding of a ratio (1.5e-5 in
                // fixed point) is multiplied by sigma1 v
                let d = lugre.damping(v);
                f = f + self.damped_slip(d * v, signed(v, w_model), w_max, slip);
                if CORRECTED {
                    f = f - (d * c).mul_fraction(kept);
                }
            }
        }
        f
    }
}

impl<S: Scalar> FixedStepModel<S> for ElastoPlasticAt<S> {
    type State = LuGreAtState<S>;

    fn period(&self) -> f64 {
        self.lugre.period()
    }

    #[inline]
    fn step(&self, state: &mut LuGreAtState<S>, v: S) -> S {
        match checked_velocity(v) {
            Some(v) => self
                .lugre
                .unscale(self.advance::<false>(state, v, S::ZERO, true)),
            None => self.hold_force(state),
        }
    }

    /// `w = sigma0 z`.
    fn hold_force(&self, state: &LuGreAtState<S>) -> S {
        self.lugre.unscale(state.w)
    }
}

/// As [`ElastoPlastic`]'s observer form: the correction moves the state
/// after the model's step against its relaxation, `w <- w - sigma0 h c
/// phi(lambda h)` (see `corrected_shift`), then `|w| <= Fs`.
impl<S: Scalar> FixedStepObservable<S> for ElastoPlasticAt<S> {
    fn step_corrected(&self, state: &mut LuGreAtState<S>, v: S, correction: S, damping: bool) -> S {
        self.lugre
            .unscale(self.advance::<true>(state, v, correction, damping))
    }

    /// As LuGre's.
    fn force_bound(&self, v: S) -> S {
        self.lugre.force_bound(v)
    }
}

impl<S: Scalar> FrictionModel<S> for ElastoPlastic<S> {
    type State = LuGreState<S>;

    fn step(&self, state: &mut LuGreState<S>, v: S, h: S) -> S {
        match checked_inputs(v, h) {
            Some(v) => self.advance(state, v, S::ZERO, h, true),
            None => self.hold_force(state),
        }
    }

    /// `sigma0 z`.
    fn hold_force(&self, state: &LuGreState<S>) -> S {
        self.lugre.sigma0() * state.z
    }
}

/// Observer form: the correction `c = k e` is applied after the model's step
/// against the model's relaxation, `z^ <- z^ - c h phi(lambda h)`, and its
/// share of `dz^/dt` is `-c e^(-lambda h)` (see `corrected_shift`); then
/// `|z^| <= Fs/sigma0`.
impl<S: Scalar> Observable<S> for ElastoPlastic<S> {
    fn step_corrected(
        &self,
        state: &mut LuGreState<S>,
        v: S,
        correction: S,
        h: S,
        damping: bool,
    ) -> S {
        self.advance(state, v, correction, h, damping)
    }

    /// As LuGre's: `|dz/dt| <= |v| (1 + Fs/Fc)` within the bound.
    fn force_bound(&self, v: S) -> S {
        self.lugre.force_bound(v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Observer;
    use proptest::prelude::*;
    use std::vec::Vec;

    const P: ElastoPlasticParams = ElastoPlasticParams {
        lugre: LuGreParams::CANUDAS_1995,
        z_ba: 5e-6,
    };

    #[test]
    fn z_ba_must_be_below_the_coulomb_deflection() {
        let bad = ElastoPlasticParams { z_ba: 1e-5, ..P }; // Fc/sigma0 = 1e-5
        assert_eq!(
            bad.validate(),
            Err(ParamError::NotBelow {
                name: "z_ba",
                limit: "fc / sigma0"
            })
        );
        assert_eq!(
            ElastoPlasticParams { z_ba: 0.0, ..P }.validate(),
            Err(ParamError::NotPositive("z_ba"))
        );
    }

    #[test]
    fn alpha_uses_the_magnitude_of_z() {
        // negative deflection moving in the negative direction relaxes just like the positive one
        let m = P.build::<f64>().unwrap();
        let (mut a, mut b) = (LuGreState { z: 8e-6 }, LuGreState { z: -8e-6 });
        let fa = m.step(&mut a, 1e-3, 1e-3);
        let fb = m.step(&mut b, -1e-3, 1e-3);
        assert!((a.z + b.z).abs() < 1e-18, "{} {}", a.z, b.z);
        assert!((fa + fb).abs() < 1e-12);
    }

    #[test]
    fn steady_state_is_the_stribeck_map() {
        let m = P.build::<f64>().unwrap();
        let lugre = LuGreParams::CANUDAS_1995.build::<f64>().unwrap();
        for v in [-0.3, -1e-3, 1e-4, 2e-2] {
            let mut s = LuGreState::default();
            let mut f = 0.0;
            for _ in 0..20_000 {
                f = m.step(&mut s, v, 1e-3);
            }
            assert!((f - lugre.steady_state(v)).abs() < 1e-9, "v {v}: {f}");
        }
    }

    /// `dw/dxi` from the sheet's formula, with `libm`'s `sin`.
    fn sheet_slip(z_ba: f64, z_max: f64, w: f64) -> f64 {
        let alpha = if w <= z_ba {
            0.0
        } else if w >= z_max {
            1.0
        } else {
            let phase = core::f64::consts::PI * (w - 0.5 * (z_max + z_ba)) / (z_max - z_ba);
            0.5 + 0.5 * libm::sin(phase)
        };
        1.0 - alpha * w / z_max
    }

    #[test]
    fn slip_is_the_sheets_alpha() {
        let z_max = 1.5e-5;
        for frac in [0.1, 0.5, 0.9, 0.99] {
            let m = ElastoPlasticParams {
                z_ba: frac * 1e-5,
                ..P
            }
            .build::<f64>()
            .unwrap();
            for k in 0..=1000 {
                let w = -2e-5 + 4e-5 * f64::from(k) / 1000.0;
                let (ours, sheet) = (m.slip(w, z_max), sheet_slip(m.z_ba, z_max, w));
                assert!((ours - sheet).abs() < 1e-9, "w {w}: {ours} {sheet}");
            }
        }
    }

    /// Largest difference, over many starts in the transition zone and
    /// distances from 1e-3 to 100 zone widths, between one step and 20,000
    /// tiny ones, as a fraction of the zone's width `z_max - z_ba`.
    fn long_step_error(frac: f64) -> f64 {
        let m = ElastoPlasticParams {
            z_ba: frac * 1e-5,
            ..P
        }
        .build::<f64>()
        .unwrap();
        let v = 2e-2; // z_max = g(v) / sigma0 = Fc / sigma0 here, to 1e-170
        let z_max = m.lugre.curve().eval(v) / 1e5;
        let width = z_max - m.z_ba;
        let mut worst: f64 = 0.0;
        for start in [0.0, 0.3, 0.7, 0.95, 0.999] {
            for dist in [1e-3, 0.1, 0.5, 1.0, 2.0, 5.0, 20.0, 100.0] {
                let z0 = m.z_ba + start * width;
                let h = dist * width / v;
                let (mut a, mut b) = (LuGreState { z: z0 }, LuGreState { z: z0 });
                m.step(&mut a, v, h);
                let n = 20_000;
                for _ in 0..n {
                    m.step(&mut b, v, h / f64::from(n));
                }
                worst = worst.max((a.z - b.z).abs() / width);
            }
        }
        worst
    }

    #[test]
    fn transition_matches_fine_steps() {
        // one step across the zone against 20,000 tiny ones (each then a
        // single short RK4 sub-step, accurate to ~1e-12 of the width)
        for frac in [0.1, 0.5, 0.9, 0.99] {
            let err = long_step_error(frac);
            std::println!("z_ba = {frac} Fc/sigma0: {err:.2e} of the width");
            assert!(
                err < 4e-5,
                "z_ba = {frac} Fc/sigma0: {err:.2e} of the width"
            );
        }
    }

    #[test]
    fn transition_matches_the_sheets_equation() {
        // independent of the step: the sheet's dz/dt with libm sin, RK4 in
        // 1e5 tiny steps of the distance, against one model step
        for frac in [0.1, 0.5, 0.9, 0.99] {
            let m = ElastoPlasticParams {
                z_ba: frac * 1e-5,
                ..P
            }
            .build::<f64>()
            .unwrap();
            let v = 2e-2;
            let z_max = m.lugre.curve().eval(v) / 1e5;
            let width = z_max - m.z_ba;
            for dist in [0.3, 3.0] {
                let xi = dist * width;
                let mut s = LuGreState { z: m.z_ba };
                m.step(&mut s, v, xi / v);
                let (n, mut w) = (100_000, m.z_ba);
                let d = xi / f64::from(n);
                let f = |w: f64| sheet_slip(m.z_ba, z_max, w);
                for _ in 0..n {
                    let k1 = f(w);
                    let k2 = f(w + 0.5 * d * k1);
                    let k3 = f(w + 0.5 * d * k2);
                    let k4 = f(w + d * k3);
                    w += d / 6.0 * (k1 + 2.0 * (k2 + k3) + k4);
                }
                let err = (s.z - w).abs() / width;
                assert!(err < 3e-5, "z_ba {frac}, {dist} widths: {err:.2e}");
            }
        }
    }

    #[test]
    fn the_tail_is_reached_within_the_sub_step_budget() {
        // the worst start (u = 1, just past z_ba) and a distance long enough to
        // reach the tail, for zones from 1e-6 to all of z_max: 22 sub-steps at
        // most, so the cap of 24 is never what ends the loop
        let mut most = 0;
        for k in 0..=60 {
            let eps = 10f64.powf(-6.0 + 0.1 * f64::from(k));
            let (u, taken) = zone_step(1.0f64, 1e9, eps);
            let (u32_, taken32) = zone_step(1.0f32, 1e9, eps as f32);
            assert!(u == 0.0 && u32_ == 0.0, "eps {eps}: {u} {u32_}");
            most = most.max(taken).max(taken32);
        }
        std::println!("most sub-steps: {most}");
        assert!(most <= 22, "{most} sub-steps");
        // and a path that stops inside the zone leaves it no later
        for left in [1e-3, 0.3, 1.0, 3.0, 10.0, 30.0] {
            let (_, taken) = zone_step(1.0f64, left, 0.01);
            assert!(taken <= 22, "{left}: {taken}");
        }
    }

    #[test]
    fn huge_steps_stay_finite_in_f32() {
        // v h overflows f32: the distance is capped, not turned into NaN
        for frac in [0.1, 0.5, 0.9, 0.99] {
            let m = ElastoPlasticParams {
                z_ba: frac * 1e-5,
                ..P
            }
            .build::<f32>()
            .unwrap();
            for z in [-1.5e-5f32, 0.0, 0.99 * m.z_ba(), 1.2e-5, 1.5e-5] {
                for (v, h) in [
                    (1e6f32, 3.5e32f32),
                    (-1e6, 3.5e32),
                    (1e6, f32::MAX),
                    (1e-30, 1e30),
                ] {
                    let mut s = LuGreState { z };
                    let f = m.step(&mut s, v, h);
                    assert!(
                        f.is_finite() && s.z.is_finite(),
                        "z {z} v {v} h {h}: {f} {}",
                        s.z
                    );
                    assert!(s.z.abs() <= 1.5e-5 * (1.0 + 1e-6));
                }
            }
        }
    }

    #[test]
    fn observer_corrects() {
        let m = P.build::<f64>().unwrap();
        let o = Observer::new(m, 1000.0).unwrap();
        let mut z = LuGreState::default();
        let f = o.step(&mut z, 0.0, 1e-6, 1e-3);
        assert!(z.z < 0.0 && f < 0.0);
    }

    /// The corrected steady state of steady sliding at `v` with the
    /// correction `c`: `dz/dt = (v - c) - alpha |v| z / z_max = 0`, by
    /// bisection on the sheet's `alpha` (with `sin`). Returns `sigma0 z +
    /// sigma2 v`, the estimate there (`dz/dt = 0`).
    fn corrected_steady_force(p: &ElastoPlasticParams, v: f64, c: f64) -> f64 {
        let c0 = p.lugre.curve;
        let g = c0.fc + (c0.fs - c0.fc) * libm::exp(-libm::pow((v / c0.vs).abs(), c0.exponent));
        let z_max = g / p.lugre.sigma0;
        let target = 1.0 - c / v; // alpha(w) w / z_max along the motion
        let (mut lo, mut hi) = (p.z_ba, p.lugre.curve.fs / p.lugre.sigma0);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if 1.0 - sheet_slip(p.z_ba, z_max, mid) < target {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        p.lugre.sigma0 * 0.5 * (lo + hi) * v.signum() + p.lugre.sigma2 * v
    }

    /// In steady sliding the model relaxes within microseconds, so a
    /// constant correction `c = k e` settles where `dz/dt = 0`, with no
    /// `sigma1 c` left in the estimate. Before the correction was applied
    /// against the relaxation, the estimate carried `-sigma1 c` (here up to
    /// 9.5 N) for ever: a proportional gain `sigma1 k` on the position error
    /// that made the elasto-plastic observer 21x worse than no compensation
    /// in `friction servo` (canudas1995-ep).
    #[test]
    fn observer_correction_settles_at_the_corrected_steady_state() {
        for z_ba in [5e-6, 1e-6, 9e-6] {
            let p = ElastoPlasticParams { z_ba, ..P };
            let ep = Observer::new(p.build::<f64>().unwrap(), 1000.0).unwrap();
            let ep_at = Observer::new(p.build_at::<f64>(1e-3).unwrap(), 1000.0).unwrap();
            for (v, e) in [
                (0.05, 1e-5),
                (0.05, -1e-5),
                (-0.2, 3e-5),
                (0.02, 0.0),
                (0.1, 3e-5),
            ] {
                let (mut z, mut w) = (LuGreState::default(), LuGreAtState::default());
                let (mut f, mut f_at) = (0.0, 0.0);
                for _ in 0..200 {
                    f = ep.step(&mut z, v, e, 1e-3);
                    f_at = ep_at.step_at(&mut w, v, e);
                }
                let expected = corrected_steady_force(&p, v, 1000.0 * e);
                for (name, f) in [("ep", f), ("ep_at", f_at)] {
                    assert!(
                        (f - expected).abs() < 0.01,
                        "{name} z_ba {z_ba} v {v} e {e}: {f} vs {expected}"
                    );
                }
            }
        }
    }

    proptest! {
        #[test]
        fn bounded_and_finite(inputs in proptest::collection::vec((-1.0f64..1.0, 0.0f64..1e-1), 1..80)) {
            let m = P.build::<f32>().unwrap();
            let mut s = LuGreState::default();
            for (v, h) in inputs {
                let f = m.step(&mut s, v as f32, h as f32);
                prop_assert!(f.is_finite());
                prop_assert!(s.z.abs() <= 1.5e-5 * (1.0 + 1e-6));
            }
        }

        #[test]
        fn bounded_and_finite_for_any_z_ba(
            frac in 1e-6f64..0.999_999,
            z0 in -1.0f64..1.0,
            inputs in proptest::collection::vec((-1.0f64..1.0, -12.0f64..2.0), 1..60),
        ) {
            // z_ba anywhere in (0, Fc/sigma0), velocities up to 1 m/s and
            // steps from 1e-12 s to 100 s, in f32 and f64
            let p = ElastoPlasticParams { z_ba: frac * 1e-5, ..P };
            let (m32, m64) = (p.build::<f32>().unwrap(), p.build::<f64>().unwrap());
            let (mut s32, mut s64) = (LuGreState { z: (z0 * 1.5e-5) as f32 }, LuGreState { z: z0 * 1.5e-5 });
            for (v, e) in inputs {
                let h = 10f64.powf(e);
                let f32_ = m32.step(&mut s32, v as f32, h as f32);
                let f64_ = m64.step(&mut s64, v, h);
                prop_assert!(f32_.is_finite() && f64_.is_finite());
                prop_assert!(s32.z.abs() <= 1.5e-5 * (1.0 + 1e-6));
                prop_assert!(s64.z.abs() <= 1.5e-5 * (1.0 + 1e-12));
            }
        }

        #[test]
        fn extreme_finite_inputs_stay_finite(
            frac in 1e-6f64..0.999_999,
            z0 in -1.0f64..1.0,
            v in proptest::num::f64::NORMAL,
            h in proptest::num::f64::POSITIVE,
        ) {
            // any finite v (clamped to 1e6) and h, whose product overflows
            let p = ElastoPlasticParams { z_ba: frac * 1e-5, ..P };
            let (m32, m64) = (p.build::<f32>().unwrap(), p.build::<f64>().unwrap());
            let mut s64 = LuGreState { z: z0 * 1.5e-5 };
            let f64_ = m64.step(&mut s64, v, h);
            prop_assert!(f64_.is_finite() && s64.z.abs() <= 1.5e-5 * (1.0 + 1e-12));
            let mut s32 = LuGreState { z: (z0 * 1.5e-5) as f32 };
            let f32_ = m32.step(&mut s32, v as f32, (h as f32).min(f32::MAX));
            prop_assert!(f32_.is_finite() && s32.z.abs() <= 1.5e-5 * (1.0 + 1e-6));
        }

        #[test]
        fn no_drift_below_z_ba(amplitudes in proptest::collection::vec(0.0f64..4.9e-6, 1..20)) {
            // displacement cycles 0 -> a -> 0 whose deflection stays below z_ba:
            // z returns exactly to 0, so a force cycle leaves no displacement behind
            let m = P.build::<f64>().unwrap();
            let mut s = LuGreState::default();
            let mut x = 0.0;
            let h = 1e-3;
            for a in amplitudes {
                let n = 50;
                let v = a / (n as f64 * h);
                let path: Vec<f64> = core::iter::repeat_n(v, n).chain(core::iter::repeat_n(-v, n)).collect();
                for v in path {
                    m.step(&mut s, v, h);
                    x += v * h;
                }
                prop_assert!((s.z - x).abs() < 1e-15);
                prop_assert!(s.z.abs() < 1e-15);
            }
        }
    }
}
