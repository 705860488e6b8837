//! The Q16.16 quotient in 32-bit integer arithmetic: a whole part, then
//! fraction digits from a 16-bit reciprocal ([`Divisor`]), for cores
//! without a divide instruction.

use super::{Fixed32, ARMV6M};
use crate::scalar::sealed::Kernels;
use crate::Scalar;
use core::ops::Div;

/// `(n / d, n % d)`; on ARMv6-M, which has no divide instruction, a
/// quotient below 16 (common: `1/g` of a force in newtons) from
/// `small_quotient` instead of the `u32` division call.
#[inline]
fn integer_part(n: u32, d: u32) -> (u32, u32) {
    if ARMV6M && n >> 4 < d {
        return small_quotient(n, d);
    }
    (n / d, n % d)
}

/// `(n / d, n % d)` for `n < 16 d` in four shift-subtract steps (the test
/// `r >> s >= d` is `r >= d << s`, without its overflow): cheaper on a
/// Cortex-M0, which has no divide instruction, than a `u32` division call
/// and its set-up (tested on the host against the division).
#[inline]
pub(super) fn small_quotient(n: u32, d: u32) -> (u32, u32) {
    let (mut q, mut r) = (0, n);
    for s in (0..4).rev() {
        if r >> s >= d {
            r -= d << s;
            q |= 1 << s;
        }
    }
    (q, r)
}

/// `floor(2^31 / (2^15 + (i + 1) 2^9))` for `i` in `0..64`: from below,
/// within 2^-6, the reciprocal of a 16-bit divisor whose top six bits after
/// its leading one are `i` (for [`Divisor`]).
// evaluated at compile time: an index out of range fails the build
#[allow(clippy::indexing_slicing)]
const RECIPROCAL_SEED: [u16; 64] = {
    let mut table = [0u16; 64];
    let mut i = 0;
    while i < 64 {
        table[i] = ((1u32 << 31) / ((1 << 15) + (i as u32 + 1) * (1 << 9))) as u16;
        i += 1;
    }
    table
};

/// For a byte `t` in `1..256`, the left shift that brings its leading one
/// to bit 7 (0 for `t = 0`): with two conditional shifts before it, a
/// divisor's normalization on a Cortex-M0 (no count-leading-zeros
/// instruction) without five conditional shifts.
// evaluated at compile time: an index out of range fails the build
#[allow(clippy::indexing_slicing)]
const LEADING_SHIFT: [u8; 256] = {
    let mut table = [0u8; 256];
    let mut t = 1;
    while t < 256 {
        let mut k = 0;
        while (t << k) < 128 {
            k += 1;
        }
        table[t] = k as u8;
        t += 1;
    }
    table
};

/// A divisor `D` in `[2^30, 2^31)` and its 16-bit reciprocal `R <= 2^46 / D`
/// within 2^-11, from which quotients are formed digit by digit
/// ([`Divisor::digit`]) with 16 by 16-bit products and one correction each:
/// no divide instruction (a Cortex-M0 has none) and no 64-bit arithmetic.
struct Divisor {
    d: u32,
    reciprocal: u32,
}

impl Divisor {
    /// `D = d 2^s` in `[2^30, 2^31)` for `0 < d < 2^31`, and `s`.
    ///
    /// `R0 <= 2^31 / (Dh + 1)` within 2^-6 comes from [`RECIPROCAL_SEED`]
    /// (`Dh = D >> 15` in `[2^15, 2^16)`), then `R = R0 + R0 e / 2^31`,
    /// `e = 2^31 - (Dh + 1) R0` in `[0, 2^25]`: the Newton step from below
    /// stays below, within 2^-12 + 2^-15.
    #[inline(always)]
    fn normalized(d: u32) -> (Self, u32) {
        let (mut d, mut s) = (d, 0);
        for k in [16, 8] {
            if d < 1 << (31 - k) {
                d <<= k;
                s += k;
            }
        }
        // d in [2^23, 2^31) (or 0): the last 0 to 7 bits from its top byte
        let top = LEADING_SHIFT.get((d >> 23) as usize);
        let k = u32::from(top.copied().unwrap_or(0));
        d <<= k;
        s += k;
        let dh1 = (d >> 15) + 1;
        // the index is below 64: no fallback is ever taken
        let seed = RECIPROCAL_SEED.get(((d >> 24) & 63) as usize);
        let r0 = u32::from(seed.copied().unwrap_or(0));
        let e = (1u32 << 31) - dh1 * r0;
        let reciprocal = r0 + ((r0 * (e >> 10)) >> 21);
        (Self { d, reciprocal }, s)
    }

    /// `(floor(x 2^m / D), its remainder)` for `x < D` and `m <= 10`: the
    /// estimate `(x >> 15) R >> (31 - m)` is from below and at most 1 short
    /// (`2^m 2^-11 + 2^(m - 15) < 1`), so the remainder `x 2^m - q D` is in
    /// `[0, 2 D)`: it fits `u32`, its wrapping product and shift are exact,
    /// and one comparison corrects `q`.
    #[inline(always)]
    fn digit(&self, x: u32, m: u32) -> (u32, u32) {
        let q = ((x >> 15) * self.reciprocal) >> (31 - m);
        let rem = (x << m).wrapping_sub(q.wrapping_mul(self.d));
        if rem >= self.d {
            (q + 1, rem - self.d)
        } else {
            (q, rem)
        }
    }
}

/// `floor(r 2^17 / d)` for `r < d <= 2^31`, the fraction bits of a
/// quotient (and one rounding bit), on ARM: two digits instead of a
/// 17-step shift-subtract loop, several times cheaper on a Cortex-M0 (no
/// divide instruction) and cheaper on a Cortex-M4 too (the cost guide's
/// `q16-div` row). The same bits: tested on the host against
/// the loop, and on both cores by the cost benchmark against a 64-bit
/// division. `d` is shifted into [`Divisor`]'s range, `r` with it, and the
/// quotient formed in two digits of 9 and 8 bits.
#[cfg(any(test, target_arch = "arm"))]
#[inline]
pub(super) fn fraction_quotient(r: u32, d: u32) -> u32 {
    if d == 1 << 31 {
        return r >> 14;
    }
    // D = d 2^s in [2^30, 2^31), X = r 2^s < D
    let (divisor, s) = Divisor::normalized(d);
    let (high, x) = divisor.digit(r << s, 9);
    let (low, _) = divisor.digit(x, 8);
    (high << 8) | low
}

/// `floor(n 2^17 / d)` for `d <= n < 16 d` and `d < 2^27`, or `None` for a
/// larger `d`: with `D = d 2^s` (`s >= 4`), the whole part is the digit
/// `floor((n 2^(s - 4)) 2^4 / D)` (`n 2^(s - 4) < D`), whose remainder is
/// `r 2^s`, and the 17 fraction bits two more digits, as in
/// `fraction_quotient`. One digit in place of `small_quotient`'s four
/// steps, cheaper on a Cortex-M0; the same bits (tested on the host).
#[inline]
pub(super) fn small_quotient_digits(n: u32, d: u32) -> Option<u32> {
    if n >> 4 >= d || d >= 1 << 27 {
        return None;
    }
    // d < 2^27: s >= 4
    let (divisor, s) = Divisor::normalized(d);
    let (whole, x) = divisor.digit(n << s.saturating_sub(4), 4);
    let (high, x) = divisor.digit(x, 9);
    let (low, _) = divisor.digit(x, 8);
    Some((whole << 17) | (high << 8) | low)
}

/// `floor(2^(e + 17) / g)` (a Q16.16 quotient `2^(e - 16) / g` with one
/// rounding bit) for `0 < g < 2^31` and `e <= 30`, or `None` where it is
/// not below `2^31`, where `e + s < 14` (`g`'s shift `s` into [`Divisor`]'s
/// range: a quotient below 2) or where `D = 2^30`. With `D = g 2^s` and
/// `j = e + s - 14`, the quotient is
/// `floor(2^j 2^31 / D) = 2^j + floor(2^j (2^31 - D) / D)`, the second term
/// in straight-line digits of at most 10 bits: one for `j < 10`, two up to
/// `j = 20`, three beyond (the reciprocal `k / g` of a force `g` times its
/// scale `k` takes two for `g` in `(2^-4, 2^7]`, one above, three below). The same bits as the long division (tested on
/// the host), with no whole part to divide first.
#[inline]
pub(super) fn pow2_quotient(e: u32, g: u32) -> Option<u32> {
    let (divisor, s) = Divisor::normalized(g);
    let j = (e + s).checked_sub(14)?;
    let x = (1 << 31) - divisor.d;
    if j > 30 || x == divisor.d {
        // beyond 2^31, or D = 2^30 (the quotient is 2^(j + 1)): rare
        return None;
    }
    if j < 10 {
        // a force above 128 units: one digit
        return Some((1 << j) | divisor.digit(x, j).0);
    }
    let (mut q, mut x, mut m) = (1u32, x, j - 10);
    if m > 10 {
        // a force below 1/16 of a unit: a third digit
        let (top, rem) = divisor.digit(x, m - 10);
        (q, x, m) = ((q << (m - 10)) | top, rem, 10);
    }
    let (high, x) = divisor.digit(x, m);
    let (low, _) = divisor.digit(x, 10);
    Some((((q << m) | high) << 10) | low)
}

/// `2^-exp / x` by the quotient, out of line: the rare inputs of
/// [`Kernels::reciprocal_rescaled`].
#[cold]
#[inline(never)]
pub(super) fn pow2_over(exp: i8, x: Fixed32) -> Fixed32 {
    Fixed32::ONE.rescale_pow2(exp.saturating_neg()) / x
}

impl Div for Fixed32 {
    type Output = Self;
    /// Rounds to nearest and saturates; `x / 0` is the largest value of the
    /// sign of `x` (0 for 0). In 32-bit integer arithmetic only (the whole
    /// part by a `u32` division, none below 1 and on ARMv6-M none below 16;
    /// the fraction by a 17-step long division, on ARM by two digits from a
    /// 16-bit reciprocal): a Cortex-M0 has no divide instruction, and
    /// a 64-bit division is a long library call there.
    #[inline]
    fn div(self, rhs: Self) -> Self {
        let (a, b) = (self.to_bits(), rhs.to_bits());
        if b == 0 {
            return match a.signum() {
                1 => Self::MAX,
                -1 => Self::MIN,
                _ => Self::ZERO,
            };
        }
        let negative = (a < 0) != (b < 0);
        let (n, d) = (a.unsigned_abs(), b.unsigned_abs());
        // ARMv6-M: a quotient from 1 to 16 in three digits, its whole part
        // the first (one digit instead of `small_quotient`'s four steps)
        if ARMV6M && n >= d {
            if let Some(q) = small_quotient_digits(n, d) {
                return Self::from_bits(rounded_quotient(q, negative));
            }
        }
        // a quotient below 1 (common: forces over forces) needs no u32
        // division, a library call on a Cortex-M0
        let (whole, r) = if n < d { (0, n) } else { integer_part(n, d) };
        // |quotient| >= 2^15 saturates
        if whole >= 1 << 15 {
            return if negative { Self::MIN } else { Self::MAX };
        }
        // 16 fraction bits and one rounding bit: r < d <= 2^31, so 2 r fits
        #[cfg(target_arch = "arm")]
        let q = (whole << 17) | fraction_quotient(r, d);
        #[cfg(not(target_arch = "arm"))]
        let q = {
            let (mut q, mut r) = (whole, r);
            for _ in 0..17 {
                r <<= 1;
                q <<= 1;
                if r >= d {
                    r -= d;
                    q |= 1;
                }
            }
            q
        };
        Self::from_bits(rounded_quotient(q, negative))
    }
}

/// The quotient's bits from `q`, which has one bit more than the result:
/// rounded half up, to at most 2^31 (`q` may be 2^32 - 1, so not
/// `(q + 1) >> 1`), with its sign, saturated.
#[inline]
fn rounded_quotient(q: u32, negative: bool) -> i32 {
    let q = i64::from(q >> 1) + i64::from(q & 1);
    let q = if negative { -q } else { q };
    q.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32
}
