//! The fixed-step forms' functions in integer arithmetic: `e^-x` by range
//! reduction and a polynomial, and `e^-r^2` and the zone curve by Hermite
//! cubics whose tables are built at compile time.

/// `ln 2` in Q16.16.
const LN2_BITS: i32 = 45_426;
/// `e^-x` rounds to 0 in Q16.16 beyond `x = 11.1` (`e^-11.1 < 2^-17`).
const EXP_NEG_ZERO_BITS: i32 = 11 * 65_536 + 6_554;
/// `1/n!` in Q16.16 for n = 0..=6 (rounded).
const INV_FACTORIAL: [u32; 7] = [65_536, 65_536, 32_768, 10_923, 2_731, 546, 91];

/// `e^-x` for `0 <= x <= 13` in `f64` at compile time (the cubic segments
/// of [`GAUSS_SEGMENTS`]): the Taylor series of `e^-(x/16)` to its 16th
/// power (truncation under `0.82^17 / 17! < 1e-16`), squared four times.
const fn exp_neg_const(x: f64) -> f64 {
    let y = x / 16.0;
    let (mut term, mut sum, mut n) = (1.0, 1.0, 1);
    while n <= 16 {
        term = -term * y / n as f64;
        sum += term;
        n += 1;
    }
    let mut k = 0;
    while k < 4 {
        sum *= sum;
        k += 1;
    }
    sum
}

/// Hermite's cubic `a + b t + c t^2 + d t^3` on `t` in `[0, 1]` through the
/// values `v0`, `v1` with the slopes (per unit of `t`) `s0`, `s1` at its
/// ends, its coefficients rounded to Q0.20 (for the tables built at compile
/// time).
const fn hermite_q20(v0: f64, s0: f64, v1: f64, s1: f64) -> [i32; 4] {
    const fn q20(x: f64) -> i32 {
        let scaled = x * (1 << 20) as f64;
        if scaled < 0.0 {
            -((-scaled + 0.5) as i32)
        } else {
            (scaled + 0.5) as i32
        }
    }
    [
        q20(v0),
        q20(s0),
        q20(3.0 * (v1 - v0) - 2.0 * s0 - s1),
        q20(2.0 * (v0 - v1) + s0 + s1),
    ]
}

/// A [`hermite_q20`] cubic at `t / 2^bits` by Horner in `i32`, in Q16.16
/// (rounded): the caller keeps `sum t` below 2^31.
#[inline]
fn hermite_bits([a, b, c, d]: [i32; 4], t: i32, bits: u32) -> i32 {
    let mut sum = d;
    for coefficient in [c, b, a] {
        sum = coefficient + ((sum * t) >> bits);
    }
    (sum + 8) >> 4
}

/// The segments of [`exp_neg_square_bits`]: `r` in `[0, 3.5)` in steps of
/// 1/8 (beyond, `e^-r^2 < 2^-17` rounds to 0).
const GAUSS_SEGMENT_COUNT: usize = 28;

/// `e^-r^2` on `[i/8, (i + 1)/8)` as the cubic `a + b t + c t^2 + d t^3` in
/// `t` in `[0, 1)`, Hermite's: the value and slope (`-2 r e^-r^2`) at both
/// ends. Interpolation error under `(1/8)^4 / 384` times the largest fourth
/// derivative (12, at 0): 7.6e-6, half a Q16.16 step. The coefficients in
/// Q0.20, built at compile time.
// evaluated at compile time: an index out of range fails the build
#[allow(clippy::indexing_slicing)]
const GAUSS_SEGMENTS: [[i32; 4]; GAUSS_SEGMENT_COUNT] = {
    let mut table = [[0; 4]; GAUSS_SEGMENT_COUNT];
    let mut i = 0;
    while i < GAUSS_SEGMENT_COUNT {
        let (r0, r1) = (i as f64 / 8.0, (i + 1) as f64 / 8.0);
        let (e0, e1) = (exp_neg_const(r0 * r0), exp_neg_const(r1 * r1));
        // slopes per segment: d/dt = (1/8) d/dr
        let (s0, s1) = (-2.0 * r0 * e0 / 8.0, -2.0 * r1 * e1 / 8.0);
        table[i] = hermite_q20(e0, s0, e1, s1);
        i += 1;
    }
    table
};

/// `sin(phi) / phi` and its derivative for `0 <= phi <= pi/2` in `f64` at
/// compile time (the segments of [`ZONE_SEGMENTS`]): their Taylor series to
/// `phi^24` (truncation under `(pi/2)^26 / 27! < 1e-20`).
const fn sin_over_phi_const(phi: f64) -> (f64, f64) {
    let (mut value, mut slope) = (0.0, 0.0);
    // term n: (-1)^n phi^(2n) / (2n + 1)!
    let mut term = 1.0;
    let mut n = 0;
    while n <= 12 {
        value += term;
        // d/dphi of term n is 2n term / phi (0 at phi = 0)
        if n > 0 && phi > 0.0 {
            slope += term * (2 * n) as f64 / phi;
        }
        term = -term * phi * phi / ((2 * n + 2) * (2 * n + 3)) as f64;
        n += 1;
    }
    (value, slope)
}

/// The segments of [`zone_curve_bits`]: `u` in `[0, 1)` in steps of 1/16.
const ZONE_SEGMENT_COUNT: usize = 16;

/// `T(u) = (pi/2)^2 (sin(phi) / phi)^2`, `phi = pi u / 2`, on
/// `[i/16, (i + 1)/16)` as Hermite's cubic `a + b t + c t^2 + d t^3` in `t`
/// in `[0, 1)` (the value and slope at both ends), the coefficients in
/// Q0.20, built at compile time. Interpolation error under
/// `(1/16)^4 / 384` times the largest fourth derivative of `T` (about 8):
/// 3e-7, a fiftieth of a Q16.16 step.
// evaluated at compile time: an index out of range fails the build
#[allow(clippy::indexing_slicing)]
const ZONE_SEGMENTS: [[i32; 4]; ZONE_SEGMENT_COUNT] = {
    const HALF_PI: f64 = core::f64::consts::FRAC_PI_2;
    // T and dT/du at u
    const fn curve(u: f64) -> (f64, f64) {
        let (p, dp) = sin_over_phi_const(HALF_PI * u);
        let q = HALF_PI * HALF_PI;
        (q * p * p, q * 2.0 * p * dp * HALF_PI)
    }
    let mut table = [[0; 4]; ZONE_SEGMENT_COUNT];
    let mut i = 0;
    while i < ZONE_SEGMENT_COUNT {
        let width = 1.0 / ZONE_SEGMENT_COUNT as f64;
        let (t0, d0) = curve(i as f64 * width);
        let (t1, d1) = curve((i + 1) as f64 * width);
        // slopes per segment: d/dt = width d/du
        let (s0, s1) = (d0 * width, d1 * width);
        table[i] = hermite_q20(t0, s0, t1, s1);
        i += 1;
    }
    table
};

/// [`Kernels::zone_curve`](crate::scalar::sealed::Kernels::zone_curve) in Q16.16 for `u` in
/// Q16.16: the segment of `u` (bits 12 and up) by Horner in its 12-bit
/// fraction `t`, all in `i32` (the partial sums before `a` are within 2^19
/// in Q0.20, so `sum t < 2^31`); `u <= 0` is the value at 0, `u >= 1` the
/// value at 1, which is 1. Within 0.7 Q16.16 steps of the exact value
/// (0.68, tested for every `u`).
#[inline]
pub(super) fn zone_curve_bits(u: i32) -> i32 {
    let u = u.max(0) as u32;
    let Some(&segment) = ZONE_SEGMENTS.get((u >> 12) as usize) else {
        return 1 << 16;
    };
    hermite_bits(segment, (u & 0xfff) as i32, 12)
}

/// `e^-r^2` in Q16.16 for `r` in Q16.16 (even): the segment of `|r|`
/// (bits 13 and up) by Horner in its 13-bit fraction `t`, all in `i32`
/// (every partial sum is within `2^18` in Q0.20, so `sum t < 2^31`), within
/// 1.1 Q16.16 steps of the exact value (1.02: tested for every `r` up to 4
/// on the host, and once over all 2^32 inputs; `exp_neg` of the product
/// `r r` is within 2.1).
#[inline]
pub(super) fn exp_neg_square_bits(r: i32) -> i32 {
    let r = r.unsigned_abs();
    let Some(&segment) = GAUSS_SEGMENTS.get((r >> 13) as usize) else {
        return 0;
    };
    // within [0, 2^16] for every input (tested): no clamp
    hermite_bits(segment, (r & 0x1fff) as i32, 13)
}

/// `e^-x` for `x >= 0` in integer arithmetic: `x = k ln2 + r` with
/// `0 <= r < ln2`, `e^-r` by Horner on the alternating degree-6 Taylor
/// polynomial (every partial sum stays in `[0, 1]`, so the products fit
/// in `u32`; truncation under `r^7 / 7! < 2e-5`), then a rounding shift by `k`.
#[inline]
pub(super) fn exp_neg_bits(x: i32) -> i32 {
    if x <= 0 {
        return 65_536;
    }
    if x >= EXP_NEG_ZERO_BITS {
        return 0;
    }
    // k = floor(x / ln2) <= 16, within 1: (x / 16) (2^28 / LN2_BITS) / 2^24,
    // a product below 2^29
    let mut k = ((x as u32 >> 4) * 5_909) >> 24;
    let mut r = x - (k as i32) * LN2_BITS;
    if r < 0 {
        k -= 1;
        r += LN2_BITS;
    } else if r >= LN2_BITS {
        k += 1;
        r -= LN2_BITS;
    }
    let r = r as u32; // 0 <= r < 45426
    let mut p = INV_FACTORIAL[6];
    for c in [
        INV_FACTORIAL[5],
        INV_FACTORIAL[4],
        INV_FACTORIAL[3],
        INV_FACTORIAL[2],
        INV_FACTORIAL[1],
        INV_FACTORIAL[0],
    ] {
        // p in [0, 65536], r < 2^16: r p < 2^32; c >= r p / 2^16 for this r
        p = c.saturating_sub((r * p + 32_768) >> 16);
    }
    if k == 0 {
        p as i32
    } else {
        ((p + (1 << (k - 1))) >> k) as i32
    }
}
