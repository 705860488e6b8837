//! The transition zone, shared by both forms: the relaxed fraction, the
//! observer correction's shift, and the zone's sub-steps (RK4 and the
//! closed-form tail).

use crate::models::lugre::phi_series;
use crate::Scalar;

/// `alpha = 1 - sin^2(pi u / 2) = 1 - (pi/2)^2 u^2 (sin(phi)/phi)^2` at the
/// normalised zone position `u` in `[0, 1]`.
#[inline]
pub(super) fn relaxed_fraction<S: Scalar>(u: S) -> S {
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
pub(super) const XI_CAP: f64 = 1024.0;
/// Sub-steps of the transition zone: each has `h r <= RK_REACH`.
const RK_REACH: f64 = 0.5;
/// Most sub-steps in one step; 22 suffice from `u = 1` down to `TAIL` (the
/// distance shrinks by at least `1 / (1 + RK_REACH / 2)` a sub-step).
pub(super) const MAX_SUBSTEPS: usize = 24;
/// RK4 sub-steps of the zone the fixed-step form takes when built: none, so
/// that its worst step stays within the 4x its average a real-time loop is
/// sized by on every core and scalar (the full step's worst is 20x on a
/// Cortex-M4F; see
/// [`ElastoPlasticFixedStep::with_max_substeps`](super::ElastoPlasticFixedStep::with_max_substeps)).
pub(super) const DEFAULT_SUBSTEPS: u8 = 0;
/// Below this normalised distance to `z_max` the closed-form tail takes over.
const TAIL: f64 = 0.01;
/// `(pi / 2)^2`.
const Q: f64 = core::f64::consts::PI * core::f64::consts::PI / 4.0;

/// Advances the normalised distance to `z_max`, `u` (see [`zone_rate`]), over
/// `left` zone widths of sliding: RK4 sub-steps down to `u <= TAIL`, then the
/// exact tail. Returns `u` and the number of sub-steps taken.
pub(super) fn zone_step<S: Scalar>(mut u: S, mut left: S, eps: S) -> (S, usize) {
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
pub(super) fn zone_rate<S: Scalar>(u: S, eps: S) -> (S, S) {
    // u, eps and 1 - eps u are fractions; (pi/2)^2 P^2 from
    // `Kernels::zone_curve`
    let b = u.zone_curve().mul_fraction(S::ONE - eps.mul_fraction(u));
    (eps + b.mul_fraction(u), b)
}

/// `(pi/2)^2 P^2` (`P = sin(phi) / phi`, `phi = pi u / 2`) from the series
/// of `P` in the fraction `(phi/2)^2`:
/// [`Kernels::zone_curve`](crate::scalar::sealed::Kernels::zone_curve)'s
/// default.
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
/// ([`Kernels::mul_fraction`](crate::scalar::sealed::Kernels::mul_fraction),
/// cheaper on a Cortex-M0). Its terms run to `phi^12`
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
pub(super) struct Slip<S> {
    pub(super) slope: S,
    pub(super) zone_rate: S,
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
pub(super) fn zone_step_fixed<S: Scalar>(
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
