//! Q16.16 fixed point for cores without an FPU (feature `fixed`).
//!
//! [`Fixed32`] wraps the `fixed` crate's `I16F16`: 16 integer and 16
//! fraction bits, so values from -32768 to 32767.99998 in steps of
//! `2^-16 = 1.53e-5`. Every operation saturates: no overflow panic in a
//! debug build, no wrap-around in release, and a division by zero gives the
//! largest value of the dividend's sign (0 / 0 gives 0).
//!
//! # What runs on it, and where it is valid
//!
//! The fixed-step forms ([`crate::fixed_step`]) are written for it: their
//! states are forces, and `h` enters only through products such as
//! `sigma0 h` formed in `f64` at build time. A deflection of micrometres or
//! a stiffness of 1e5 N/m does not fit, so the variable-step forms (state in
//! metres) are refused at `build()` with a typed error for any realistic
//! parameter set.
//!
//! A configuration is valid, and checked at `build_at()`, for:
//! - velocities `|v| <= 4` (m/s or rad/s; larger inputs are clamped to 4),
//!   resolved to 1.5e-5;
//! - force terms up to a quarter of the range (8192) at that velocity
//!   ([`ParamError::ForceOverflow`](crate::ParamError::ForceOverflow)
//!   otherwise), each parameter and product formed at build time within the
//!   range and 0.1 % of its design value
//!   ([`ParamError::Underflow`](crate::ParamError::Underflow) otherwise);
//! - any `h` for which those products fit.
//!
//! Inside, a fixed-step form carries its forces multiplied by a power of
//! two ([`Scalar::force_scale`]) chosen at build time to use the range: a
//! servo's 0.3 N m friction is carried as about 300 with 1.5e-5 steps, so
//! that the small per-step increments of a 10 kHz loop are not rounded
//! away (unscaled, they stall a slow relaxation short of its equilibrium by
//! up to 20 % of `Fs`).
//!
//! Accuracy against the `f64` reference is measured by `friction validate`
//! (`--scalar fixed` rows) and stated in the README.
//!
//! # Functions
//!
//! [`Scalar::exp_neg`], the only transcendental function of the fixed-step
//! forms, is computed in integer arithmetic (range reduction by `ln 2` and a
//! degree-6 polynomial, no floating point). `exp`, `exp_m1`, `ln_1p` and
//! `powf`, which only the variable-step forms and a Stribeck exponent other
//! than 1 or 2 use, go through `f32` (software floating point on an M0).

use crate::scalar::Conversion;
use crate::Scalar;
use core::ops::{Add, Div, Mul, Neg, Sub};
use fixed::types::I16F16;

/// A Q16.16 number with saturating arithmetic; see the [module
/// documentation](self).
///
/// ```
/// use friction_core::{Fixed32, Scalar};
/// let a = Fixed32::from_f64(30000.0);
/// assert_eq!((a + a).to_f64(), Fixed32::MAX.to_f64()); // saturates
/// assert_eq!((a / Fixed32::ZERO), Fixed32::MAX);
/// assert!((Fixed32::from_f64(1.0).exp_neg().to_f64() - (-1f64).exp()).abs() < 1e-4);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord)]
pub struct Fixed32(I16F16);

impl Fixed32 {
    /// The largest value, 32767.99998.
    pub const MAX: Self = Self(I16F16::MAX);
    /// The smallest value, -32768.
    pub const MIN: Self = Self(I16F16::MIN);

    /// The value with these raw bits (`value = bits / 65536`).
    pub const fn from_bits(bits: i32) -> Self {
        Self(I16F16::from_bits(bits))
    }

    /// The raw bits (`value * 65536`).
    pub const fn to_bits(self) -> i32 {
        self.0.to_bits()
    }
}

#[cfg(feature = "defmt")]
impl defmt::Format for Fixed32 {
    fn format(&self, f: defmt::Formatter) {
        defmt::write!(f, "{=i32}/65536", self.to_bits())
    }
}

impl Add for Fixed32 {
    type Output = Self;
    #[inline]
    fn add(self, rhs: Self) -> Self {
        Self(self.0.saturating_add(rhs.0))
    }
}

impl Sub for Fixed32 {
    type Output = Self;
    #[inline]
    fn sub(self, rhs: Self) -> Self {
        Self(self.0.saturating_sub(rhs.0))
    }
}

impl Mul for Fixed32 {
    type Output = Self;
    /// Rounds to nearest (ties up) and saturates: truncation would bias an
    /// accumulated state by half a step per operation.
    #[inline]
    fn mul(self, rhs: Self) -> Self {
        Self::from_bits(saturated_product(self.to_bits(), rhs.to_bits()))
    }
}

/// Whether the target is ARMv6-M (Cortex-M0, M0+; told apart from ARMv7-M
/// by its missing 32-bit atomics): no divide instruction, no count of
/// leading zeros, and a multiplier that keeps only the low 32 bits of a
/// product, so the kernels below take their ARMv6-M forms there. One
/// constant instead of a `cfg` at every use: both forms compile on every
/// target (the ARMv6-M kernels are tested on the host), and the compiler
/// drops the branch not taken.
const ARMV6M: bool = cfg!(all(target_arch = "arm", not(target_has_atomic = "32")));

/// `(a b + 2^15) >> 16` saturated to `i32`: from three 32-bit products on
/// ARMv6-M, from the 64-bit product elsewhere.
#[inline]
fn saturated_product(a: i32, b: i32) -> i32 {
    if ARMV6M {
        split_saturated_product(a, b)
    } else {
        clamp_i32(rounded_product(a, b))
    }
}

/// `(a b + 2^15) >> 16` saturated, from three 32-bit products where the
/// operands' high halves show that it cannot overflow, and otherwise from
/// [`split_product`] out of line (the same value as the 64-bit product,
/// saturated: tested on the host).
///
/// With `a = ah 2^16 + al` (`ah` signed, `al` in `0..2^16`),
/// `|a| <= (A + 1) 2^16` for `A = ah` (`a >= 0`) or `!ah = -ah - 1`
/// (`a < 0`), and `b` alike; `(A + 1)(B + 1) < 2^15` then bounds
/// `|a b| <= 2^47 - 2^32`, so the result is within `i32` and the sum
/// `a bh + ah bl + (al bl + 2^15) >> 16`, equal to it modulo 2^32
/// (`a bh = ah bh 2^16 + al bh`), is exact in wrapping arithmetic. ARMv6-M
/// has only a 32-bit multiply: three products and one test of the high
/// halves replace four partial products summed with an overflow test each.
#[inline]
fn split_saturated_product(a: i32, b: i32) -> i32 {
    let magnitude_a = ((a >> 16) ^ (a >> 31)) as u32 + 1;
    let magnitude_b = ((b >> 16) ^ (b >> 31)) as u32 + 1;
    // each at most 2^15: the product fits u32
    if magnitude_a * magnitude_b < 1 << 15 {
        wrapping_split_product(a, b)
    } else {
        saturated_split_product(a, b)
    }
}

/// `(a b + 2^15) >> 16` modulo 2^32 from three 32-bit products:
/// `a bh + ah bl + (al bl + 2^15) >> 16` (`a bh = ah bh 2^16 + al bh`).
#[inline]
fn wrapping_split_product(a: i32, b: i32) -> i32 {
    let (ah, al) = (a >> 16, (a as u32) & 0xffff);
    let (bh, bl) = (b >> 16, (b as u32) & 0xffff);
    a.wrapping_mul(bh)
        .wrapping_add(ah.wrapping_mul(bl as i32))
        .wrapping_add(((al * bl + 0x8000) >> 16) as i32)
}

/// `(a b + 2^15) >> 16` modulo 2^32, for [`Scalar::mul_bounded`]: the
/// product when it is within `i32`, which the caller has shown (and this
/// crate's tests assert); three 32-bit products on ARMv6-M, the 64-bit
/// product truncated elsewhere (the same bits).
#[inline]
fn wrapping_product(a: i32, b: i32) -> i32 {
    #[cfg(test)]
    assert!(
        i32::try_from(split_product(a, b)).is_ok(),
        "mul_bounded out of range: {a} x {b} (bits)"
    );
    if ARMV6M {
        wrapping_split_product(a, b)
    } else {
        rounded_product(a, b) as i32
    }
}

/// `(a b + 2^15) >> 16` for a fraction `0 <= b < 2^16` (below 1 in Q16.16)
/// from two 16 by 16-bit products: `b`'s high half is 0, the low 16 bits
/// of `ah b 2^16` are whole, so only `al b` is rounded, exactly as in
/// [`split_product`]. `|ah b| < 2^31`, `al b + 2^15 < 2^32`, and the result's
/// magnitude is at most `|a|`: no sum overflows (tested on the host).
#[inline]
fn fraction_product(a: i32, b: u32) -> i32 {
    let (ah, al) = (a >> 16, (a as u32) & 0xffff);
    ah * b as i32 + ((al * b + 0x8000) >> 16) as i32
}

/// The rare case of [`split_saturated_product`], out of line: the common
/// case then keeps its values in registers.
#[cold]
#[inline(never)]
fn saturated_split_product(a: i32, b: i32) -> i32 {
    clamp_i32(split_product(a, b))
}

/// `x` saturated to `i32`.
#[inline]
fn clamp_i32(x: i64) -> i32 {
    x.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32
}

/// `(a b + 2^15) >> 16` exactly, where the core multiplies 32 by 32 bits
/// into 64.
#[inline]
fn rounded_product(a: i32, b: i32) -> i64 {
    (i64::from(a) * i64::from(b) + 0x8000) >> 16
}

/// `(a b + 2^15) >> 16` exactly from four 16 by 16-bit products, for
/// ARMv6-M, whose multiplier keeps only the low 32 bits of a product: this
/// avoids a call to the 64 by 64-bit `__aeabi_lmul`. With `a = ah 2^16 + al`
/// (`ah` signed, `al` in `0..2^16`) and `b` alike, the low 16 bits of the
/// high and middle products are whole, so only `al bl` is rounded, and one
/// 64-bit shift remains (tested on the host against the 64-bit product).
#[inline]
fn split_product(a: i32, b: i32) -> i64 {
    let (ah, al) = (a >> 16, (a as u32) & 0xffff);
    let (bh, bl) = (b >> 16, (b as u32) & 0xffff);
    // |ah bh| <= 2^30; |ah bl|, |al bh| < 2^31; al bl + 2^15 < 2^32
    (i64::from(ah * bh) << 16)
        + i64::from(ah * bl as i32)
        + i64::from(al as i32 * bh)
        + i64::from((al * bl + 0x8000) >> 16)
}

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
fn small_quotient(n: u32, d: u32) -> (u32, u32) {
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
fn fraction_quotient(r: u32, d: u32) -> u32 {
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
fn small_quotient_digits(n: u32, d: u32) -> Option<u32> {
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
fn pow2_quotient(e: u32, g: u32) -> Option<u32> {
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
/// [`Scalar::reciprocal_rescaled`].
#[cold]
#[inline(never)]
fn pow2_over(exp: i8, x: Fixed32) -> Fixed32 {
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

impl Neg for Fixed32 {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        Self(self.0.saturating_neg())
    }
}

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

/// [`Scalar::zone_curve`] in Q16.16 for `u` in Q16.16: the segment of `u`
/// (bits 12 and up) by Horner in its 12-bit fraction `t`, all in `i32` (the
/// partial sums before `a` are within 2^19 in Q0.20, so `sum t < 2^31`);
/// `u <= 0` is the value at 0, `u >= 1` the value at 1, which is 1. Within
/// 0.7 Q16.16 steps of the exact value (0.68, tested for every `u`).
#[inline]
fn zone_curve_bits(u: i32) -> i32 {
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
fn exp_neg_square_bits(r: i32) -> i32 {
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
fn exp_neg_bits(x: i32) -> i32 {
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

impl Scalar for Fixed32 {
    const ZERO: Self = Self(I16F16::ZERO);
    const ONE: Self = Self(I16F16::ONE);
    const MIN_POSITIVE: Self = Self(I16F16::DELTA);
    const VELOCITY_LIMIT: Self = Self::from_bits(4 << 16);
    const SCALES_FORCES: bool = true;
    const ALWAYS_FINITE: bool = true;

    /// A shift in 32-bit arithmetic (a 64-bit shift is a library call on
    /// ARMv6-M): right rounds to nearest (ties up), left saturates.
    #[inline]
    fn rescale_pow2(self, exp: i8) -> Self {
        let bits = self.to_bits();
        if exp >= 0 {
            let k = u32::from(exp.unsigned_abs()).min(31);
            let limit = i32::MAX >> k;
            if bits > limit {
                Self::MAX
            } else if bits < -limit {
                Self::MIN
            } else {
                Self::from_bits(bits << k)
            }
        } else {
            let k = u32::from(exp.unsigned_abs()).min(31);
            Self::from_bits(bits.saturating_add(1 << (k - 1)) >> k)
        }
    }

    #[inline]
    fn mul_bounded(self, b: Self) -> Self {
        Self::from_bits(wrapping_product(self.to_bits(), b.to_bits()))
    }

    /// Rounds to nearest and saturates as the quotient does, with the same
    /// bits (tested on the host); a force scale's exponent and a positive
    /// `self` take `pow2_quotient`.
    #[inline]
    fn reciprocal_rescaled(self, exp: i8) -> Self {
        let (g, e) = (self.to_bits(), 16 - i32::from(exp));
        if g > 0 && (0..=30).contains(&e) {
            if let Some(q) = pow2_quotient(e as u32, g as u32) {
                // q has one bit more than the result: round half up
                return Self::from_bits(((q >> 1) + (q & 1)) as i32);
            }
        }
        pow2_over(exp, self)
    }

    #[inline]
    fn zone_curve(self) -> Self {
        Self::from_bits(zone_curve_bits(self.to_bits()))
    }

    #[inline]
    fn exp_neg_square(self) -> Self {
        Self::from_bits(exp_neg_square_bits(self.to_bits()))
    }

    /// On ARMv6-M a factor in `0..1` takes `fraction_product` (two
    /// partial products, no saturation), any other the full product: the
    /// same value either way.
    #[inline]
    fn mul_fraction(self, f: Self) -> Self {
        if ARMV6M {
            let b = f.to_bits() as u32;
            if b < 1 << 16 {
                return Self::from_bits(fraction_product(self.to_bits(), b));
            }
        }
        self * f
    }

    /// Rounds to nearest, saturating; NaN gives 0.
    fn from_f64(x: f64) -> Self {
        if x.is_nan() {
            Self::ZERO
        } else {
            Self(I16F16::saturating_from_num(x))
        }
    }

    /// Overflow beyond the range, underflow to 0, or rounding beyond 0.1 %.
    fn try_from_f64(x: f64) -> Result<Self, Conversion> {
        if !(-32768.0..32768.0).contains(&x) {
            return Err(Conversion::Overflow);
        }
        let s = Self::from_f64(x);
        if x != 0.0 && s == Self::ZERO {
            Err(Conversion::Underflow)
        } else if (s.to_f64() - x).abs() > 1e-3 * x.abs() {
            Err(Conversion::Rounding)
        } else {
            Ok(s)
        }
    }

    fn to_f64(self) -> f64 {
        self.0.to_num::<f64>()
    }

    /// `2^s` with `4 max_force 2^s <= 32768`, `s` in -14..=14.
    fn force_scale(max_force: f64) -> f64 {
        if !(max_force.is_finite() && max_force > 0.0) {
            return 1.0;
        }
        libm::exp2(libm::floor(libm::log2(8192.0 / max_force)).clamp(-14.0, 14.0))
    }

    #[inline]
    fn abs(self) -> Self {
        Self(self.0.saturating_abs())
    }

    fn exp(self) -> Self {
        Self::from_f64(f64::from(libm::expf(self.0.to_num::<f32>())))
    }

    fn exp_m1(self) -> Self {
        Self::from_f64(f64::from(libm::expm1f(self.0.to_num::<f32>())))
    }

    fn ln_1p(self) -> Self {
        Self::from_f64(f64::from(libm::log1pf(self.0.to_num::<f32>())))
    }

    fn powf(self, y: Self) -> Self {
        Self::from_f64(f64::from(libm::powf(
            self.0.to_num::<f32>(),
            y.0.to_num::<f32>(),
        )))
    }

    #[inline]
    fn is_finite(self) -> bool {
        true
    }

    #[inline]
    fn exp_neg(self) -> Self {
        Self::from_bits(exp_neg_bits(self.to_bits()))
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_armv6m_fraction_product_is_exact() {
        let mut next = crate::test_rng::xorshift64(0x2545_f491_4f6c_dd1d);
        let edges_a = [
            i32::MIN,
            i32::MIN + 1,
            -65537,
            -65536,
            -32768,
            -1,
            0,
            1,
            32767,
            65535,
            65536,
            i32::MAX,
        ];
        let edges_b = [0u32, 1, 32767, 32768, 65534, 65535];
        let check = |a: i32, b: u32| {
            let want = ((i64::from(a) * i64::from(b) + 0x8000) >> 16) as i32;
            assert_eq!(super::fraction_product(a, b), want, "{a} x {b}");
        };
        for &a in &edges_a {
            for &b in &edges_b {
                check(a, b);
            }
        }
        for _ in 0..1_000_000 {
            let r = next();
            check((r >> 32) as i32 >> (r % 31), (r as u32) & 0xffff);
        }
    }

    #[test]
    fn the_armv6m_product_is_exact() {
        let edges = [
            i32::MIN,
            i32::MIN + 1,
            -65537,
            -65536,
            -65535,
            -32769,
            -32768,
            -1,
            0,
            1,
            32767,
            32768,
            65535,
            65536,
            65537,
            i32::MAX - 1,
            i32::MAX,
        ];
        let mut rng = crate::test_rng::xorshift64(0x9e37_79b9_7f4a_7c15);
        let mut next = || {
            let r = rng();
            (r >> 32) as i32 >> (r % 31)
        };
        let check = |a: i32, b: i32| {
            let want = (i64::from(a) * i64::from(b) + 0x8000) >> 16;
            assert_eq!(super::split_product(a, b), want, "{a} x {b}");
            let saturated = want.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32;
            assert_eq!(super::split_saturated_product(a, b), saturated, "{a} x {b}");
        };
        for &a in &edges {
            for &b in &edges {
                check(a, b);
            }
        }
        for _ in 0..200_000 {
            check(next(), next());
        }
        // either side of the fast path's bound (A + 1)(B + 1) < 2^15, every
        // sign and low half at its edges
        for m in 1..=(1i64 << 15) {
            for n in [
                (1i64 << 15) / m,
                (1i64 << 15) / m + 1,
                ((1i64 << 15) - 1) / m,
            ] {
                for (sa, sb) in [(1, 1), (1, -1), (-1, 1), (-1, -1)] {
                    for (la, lb) in [(0, 0), (0xffff, 0xffff), (1, 0xffff), (0x8000, 0x8000)] {
                        // A + 1 = m: ah = m - 1 (a >= 0) or -m (a < 0)
                        let high = |k: i64, sign: i64| if sign > 0 { k - 1 } else { -k };
                        let a = (high(m, sa) << 16) + la;
                        let b = (high(n, sb) << 16) + lb;
                        if let (Ok(a), Ok(b)) = (i32::try_from(a), i32::try_from(b)) {
                            check(a, b);
                        }
                    }
                }
            }
        }
    }

    use super::*;

    #[test]
    fn arithmetic_saturates_and_never_panics() {
        let big = Fixed32::from_f64(20000.0);
        assert_eq!(big + big, Fixed32::MAX);
        assert_eq!(-big - big, Fixed32::MIN);
        assert_eq!(big * big, Fixed32::MAX);
        assert_eq!(big * -big, Fixed32::MIN);
        assert_eq!(-Fixed32::MIN, Fixed32::MAX);
        assert_eq!(Fixed32::MIN.abs(), Fixed32::MAX);
        assert_eq!(big / Fixed32::ZERO, Fixed32::MAX);
        assert_eq!(-big / Fixed32::ZERO, Fixed32::MIN);
        assert_eq!(Fixed32::ZERO / Fixed32::ZERO, Fixed32::ZERO);
        assert_eq!(Fixed32::MIN / -Fixed32::ONE, Fixed32::MAX);
        assert_eq!(big / Fixed32::MIN_POSITIVE, Fixed32::MAX);
        assert_eq!(Fixed32::from_f64(f64::NAN), Fixed32::ZERO);
        assert_eq!(Fixed32::from_f64(1e300), Fixed32::MAX);
    }

    #[test]
    fn split_product_is_exact() {
        // the ARMv6-M form, checked on the host against i64
        fn split(a: i32, b: i32) -> i64 {
            let (ah, al) = (a >> 16, (a as u32) & 0xffff);
            let (bh, bl) = (b >> 16, (b as u32) & 0xffff);
            (i64::from(ah * bh) << 32)
                + ((i64::from(ah * bl as i32) + i64::from(al as i32 * bh)) << 16)
                + i64::from(al * bl)
        }
        // the largest quotient that fits, with every fraction bit set
        assert_eq!(
            (Fixed32::from_bits(i32::MAX) / Fixed32::from_bits(65_537)).to_bits(),
            (f64::from(i32::MAX) / 65_537.0 * 65_536.0).round() as i32
        );
        assert_eq!(
            (Fixed32::from_bits(i32::MAX) / Fixed32::from_bits(65_536)),
            Fixed32::from_bits(i32::MAX)
        );
        let edges = [
            i32::MIN,
            i32::MIN + 1,
            -65_536,
            -65_535,
            -1,
            0,
            1,
            65_535,
            65_536,
            i32::MAX,
        ];
        for &a in &edges {
            for &b in &edges {
                assert_eq!(split(a, b), i64::from(a) * i64::from(b), "{a} * {b}");
            }
        }
        let mut x = 0x9e37_79b9u32;
        for _ in 0..100_000 {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            let (a, b) = (x as i32, x.rotate_left(11) as i32);
            assert_eq!(split(a, b), i64::from(a) * i64::from(b), "{a} * {b}");
        }
    }

    #[test]
    fn division_rounds_to_nearest_everywhere() {
        let mut rng = crate::test_rng::xorshift64(0x2545_f491_4f6c_dd1d);
        let mut next = || {
            let r = rng();
            r as u32 as i32 >> (r >> 59) as u32 // magnitudes of every size
        };
        for _ in 0..200_000 {
            let (a, b) = (next(), next());
            if b == 0 {
                continue;
            }
            let exact = f64::from(a) / f64::from(b) * 65_536.0;
            let got = (Fixed32::from_bits(a) / Fixed32::from_bits(b)).to_bits();
            if exact >= f64::from(i32::MAX) {
                assert_eq!(got, i32::MAX, "{a} / {b}");
            } else if exact <= f64::from(i32::MIN) {
                assert_eq!(got, i32::MIN, "{a} / {b}");
            } else {
                assert!(
                    (f64::from(got) - exact).abs() <= 0.5,
                    "{a} / {b}: {got} vs {exact}"
                );
            }
        }
    }

    /// The integer part of a quotient below 16 by shift-subtract steps: the
    /// same quotient and remainder as the `u32` division, over random pairs
    /// and every quotient's edges.
    #[test]
    fn small_quotients_match_the_u32_division() {
        let mut next = crate::test_rng::xorshift64(0x9e37_79b9_7f4a_7c15);
        let mut pairs = std::vec::Vec::new();
        for _ in 0..1_000_000 {
            let x = next();
            let d = ((x as u32) >> (x >> 59) as u32).max(1);
            let n = u64::from(d) * ((x >> 40) % 16) + (x >> 20) % u64::from(d);
            pairs.push((n.min(u64::from(u32::MAX)) as u32, d));
        }
        for d in [
            1u32,
            2,
            3,
            7,
            65_535,
            65_536,
            1 << 27,
            (1 << 27) + 1,
            1 << 31,
            u32::MAX / 16,
        ] {
            for k in 0..16u64 {
                for e in [0u64, 1] {
                    let n = (u64::from(d) * k + e * u64::from(d - 1)).min(u64::from(u32::MAX));
                    pairs.push((n as u32, d));
                }
            }
        }
        for (n, d) in pairs {
            if n >> 4 < d {
                assert_eq!(small_quotient(n, d), (n / d, n % d), "{n} / {d}");
            }
        }
    }

    /// `e^-r^2` from the cubic segments against `f64`, for every Q16.16
    /// `r` up to where it rounds to 0 (and beyond): within 1.1 steps (the
    /// product `r r` and `exp_neg` it replaces: 2.1), exact at 0, even.
    #[test]
    fn gaussian_segments_track_the_exponential() {
        let (mut worst, mut worst_old) = (0.0f64, 0.0f64);
        for bits in 0..=(4 << 16) {
            let r = f64::from(bits) / 65_536.0;
            let exact = libm::exp(-r * r) * 65_536.0;
            let got = exp_neg_square_bits(bits);
            assert!((0..=65_536).contains(&got), "e^-r^2 {got} at {bits}");
            assert_eq!(got, exp_neg_square_bits(-bits));
            worst = worst.max((f64::from(got) - exact).abs());
            let old = (Fixed32::from_bits(bits) * Fixed32::from_bits(bits)).exp_neg();
            worst_old = worst_old.max((f64::from(old.to_bits()) - exact).abs());
        }
        std::println!("e^-r^2: segments within {worst:.3} steps, exp_neg(r r) {worst_old:.3}");
        assert!(worst <= 1.1 && worst < worst_old, "{worst} {worst_old}");
        assert_eq!(exp_neg_square_bits(0), 65_536);
        assert_eq!(exp_neg_square_bits(i32::MAX), 0);
        assert_eq!(exp_neg_square_bits(i32::MIN), 0);
        assert_eq!(exp_neg_square_bits(3 << 16), 8); // e^-9 2^16 = 8.1
    }

    /// The fraction quotient of ARM targets: the same bits as the 17-step
    /// shift-subtract loop, over random pairs of every magnitude and the
    /// edges of every power of two and of its seed table's bins.
    #[test]
    fn fraction_quotients_match_the_long_division() {
        fn long_division(mut r: u32, d: u32) -> u32 {
            let mut q = 0;
            for _ in 0..17 {
                r <<= 1;
                q <<= 1;
                if r >= d {
                    r -= d;
                    q |= 1;
                }
            }
            q
        }
        let check = |r: u32, d: u32| {
            let want = long_division(r, d);
            assert_eq!(want, ((u64::from(r) << 17) / u64::from(d)) as u32);
            assert_eq!(fraction_quotient(r, d), want, "{r} / {d}");
        };
        let mut next = crate::test_rng::xorshift64(0x2545_f491_4f6c_dd1d);
        let mut divisors = std::vec![1u32, 2, 3, (1 << 31) - 1, 1 << 31];
        for k in 0..32 {
            divisors.extend([(1u32 << k) - 1, 1 << k, (1u32 << k).wrapping_add(1)]);
        }
        // the seed table's bin edges, at every shift
        for i in 0..=64u32 {
            for k in 0..31 {
                let edge = ((1u32 << 15) + i * (1 << 9)) << 15 >> k;
                divisors.extend([edge.max(1), edge + 1, edge.saturating_sub(1).max(1)]);
            }
        }
        divisors.retain(|&d| (1..=1 << 31).contains(&d));
        for &d in &divisors {
            for r in [0, 1, d / 2, d / 3, d - 1, d.saturating_sub(2)] {
                if r < d {
                    check(r, d);
                }
            }
        }
        for _ in 0..3_000_000 {
            let x = next();
            let d = (((x as u32) >> (x >> 59) as u32) & u32::MAX >> 1).max(1);
            let d = if x & (1 << 40) != 0 {
                d
            } else {
                d | 1 << 31 >> ((x >> 41) & 31)
            };
            let d = d.min(1 << 31);
            check(((x >> 20) % u64::from(d)) as u32, d);
        }
    }

    /// The zone curve's segments against `f64`, for every Q16.16 `u` in
    /// `[0, 1]` and beyond it: within 0.7 steps (closer than the series it
    /// replaces), the ends exact.
    #[test]
    fn zone_segments_track_the_curve() {
        let exact = |u: f64| {
            if u == 0.0 {
                return core::f64::consts::PI * core::f64::consts::PI / 4.0;
            }
            let phi = core::f64::consts::FRAC_PI_2 * u;
            let p = libm::sin(phi) / phi;
            core::f64::consts::FRAC_PI_2 * core::f64::consts::FRAC_PI_2 * p * p
        };
        let (mut worst, mut worst_series) = (0.0f64, 0.0f64);
        for bits in 0..=65_536 {
            let got = zone_curve_bits(bits);
            let want = exact(f64::from(bits) / 65_536.0) * 65_536.0;
            worst = worst.max((f64::from(got) - want).abs());
            let series = crate::models::elasto_plastic::zone_curve_series(Fixed32::from_bits(bits));
            worst_series = worst_series.max((f64::from(series.to_bits()) - want).abs());
        }
        std::println!("zone curve: segments within {worst:.3} steps, the series {worst_series:.3}");
        assert!(
            worst <= 0.7 && worst < worst_series,
            "{worst} {worst_series}"
        );
        assert_eq!(zone_curve_bits(65_536), 65_536);
        assert_eq!(zone_curve_bits(i32::MAX), 65_536);
        assert_eq!(zone_curve_bits(-5), zone_curve_bits(0));
        assert_eq!(zone_curve_bits(0), 161_704); // (pi/2)^2 2^16 = 161,703.6
    }

    /// The whole part as a digit (ARMv6-M): the same bits as the 64-bit
    /// quotient for every `n` from `d` to `16 d` at the edges, and random
    /// pairs of every magnitude.
    #[test]
    fn small_quotients_in_digits_match_the_division() {
        let check = |n: u32, d: u32| {
            let want = ((u64::from(n) << 17) / u64::from(d)) as u32;
            match small_quotient_digits(n, d) {
                Some(q) => assert_eq!(q, want, "{n} / {d}"),
                None => assert!(n >> 4 >= d || d >= 1 << 27, "{n} / {d} refused"),
            }
        };
        let mut next = crate::test_rng::xorshift64(0x5851_f42d_4c95_7f2d);
        let mut divisors = std::vec![1u32, 2, 3, (1 << 27) - 1, 1 << 27];
        for k in 0..28 {
            divisors.extend([(1u32 << k).saturating_sub(1).max(1), 1 << k, (1 << k) + 1]);
        }
        for _ in 0..2_000 {
            let x = next();
            divisors.push(((x as u32) >> (x >> 59)).max(1));
        }
        for &d in &divisors {
            let top = (16 * u64::from(d) - 1).min(u64::from(u32::MAX)) as u32;
            for n in [
                d,
                d.saturating_add(1),
                d.saturating_mul(2) - 1,
                d.saturating_mul(2),
            ] {
                check(n, d);
            }
            for n in [top / 2, top - 1, top] {
                if n >= d {
                    check(n, d);
                }
            }
        }
        for _ in 0..3_000_000 {
            let x = next();
            let d = (((x >> 32) as u32) >> ((x >> 27) & 31)).max(1);
            let n = d.saturating_add(((x as u32) & 0x7fff_ffff) % d.saturating_mul(15).max(1));
            check(n, d);
        }
    }

    /// `reciprocal_rescaled`: the same bits as the quotient `2^-exp / g` it
    /// replaces, for every exponent (the force scales' and beyond), every
    /// `g` near a power of two or a seed bin's edge, and random `g` of
    /// every magnitude, negative and zero included.
    #[test]
    fn rescaled_reciprocals_match_the_quotient() {
        let mut gs = std::vec![i32::MIN, -65_536, -1, 0, 1, 2, 3, i32::MAX - 1, i32::MAX];
        for k in 0..31 {
            gs.extend([(1i32 << k) - 1, 1 << k, (1 << k) + 1]);
        }
        for i in 0..=64i64 {
            for k in 0..31 {
                let edge = (((1i64 << 15) + i * (1 << 9)) << 15 >> k) as i32;
                gs.extend([edge, edge.wrapping_add(1), edge.wrapping_sub(1)]);
            }
        }
        let mut next = crate::test_rng::xorshift64(0x9e37_79b9_7f4a_7c15);
        for _ in 0..200_000 {
            let x = next();
            gs.push((x >> 32) as i32 >> (x & 31) as u32);
        }
        for exp in -20i8..=20 {
            let scale = Fixed32::ONE.rescale_pow2(-exp);
            for &g in &gs {
                let g = Fixed32::from_bits(g);
                assert_eq!(g.reciprocal_rescaled(exp), scale / g, "2^{} / {g:?}", -exp);
            }
        }
        // the extremes of the exponent go through the quotient
        for exp in [i8::MIN, -31, 31, i8::MAX] {
            let g = Fixed32::from_f64(0.3);
            assert_eq!(
                g.reciprocal_rescaled(exp),
                Fixed32::ONE.rescale_pow2(exp.saturating_neg()) / g
            );
        }
    }

    /// Every operation on any pair of bit patterns (and the edges): no
    /// panic, with the overflow checks of a debug build on.
    #[test]
    fn no_operation_panics_on_any_bits() {
        let mut next = crate::test_rng::xorshift64(0x1234_5678_9abc_def1);
        let mut values = std::vec![i32::MIN, i32::MIN + 1, -1, 0, 1, i32::MAX - 1, i32::MAX];
        for _ in 0..2000 {
            let x = next();
            values.push((x >> 32) as i32 >> (x & 31) as u32);
        }
        for &a in &values {
            for &b in values.iter().step_by(7) {
                let (p, q) = (Fixed32::from_bits(a), Fixed32::from_bits(b));
                let _ = (
                    p + q,
                    p - q,
                    p * q,
                    p / q,
                    -p,
                    p.abs(),
                    p.exp_neg(),
                    p.sat(q.abs()),
                );
            }
        }
    }

    #[test]
    fn checked_conversion_names_the_failure() {
        assert_eq!(Fixed32::try_from_f64(1e5), Err(Conversion::Overflow));
        assert_eq!(Fixed32::try_from_f64(f64::NAN), Err(Conversion::Overflow));
        assert_eq!(Fixed32::try_from_f64(1e-6), Err(Conversion::Underflow));
        // 1e-3 is 65.536 steps: 0.7 % rounding
        assert_eq!(Fixed32::try_from_f64(1e-3), Err(Conversion::Rounding));
        assert_eq!(Fixed32::try_from_f64(0.28).map(|x| x.to_bits()), Ok(18_350));
        assert_eq!(Fixed32::try_from_f64(0.0), Ok(Fixed32::ZERO));
    }

    #[test]
    fn exp_neg_is_within_3e5_absolute_everywhere() {
        let mut worst = 0.0f64;
        for bits in (0..(13 << 16)).step_by(7) {
            let x = Fixed32::from_bits(bits);
            let got = x.exp_neg().to_f64();
            let exact = (-x.to_f64()).exp();
            worst = worst.max((got - exact).abs());
        }
        assert!(worst < 3e-5, "worst {worst}");
        assert_eq!(Fixed32::from_bits(-5).exp_neg(), Fixed32::ONE);
        assert_eq!(Fixed32::MAX.exp_neg(), Fixed32::ZERO);
    }
}
