//! The Q16.16 product kernels: `(a b + 2^15) >> 16` from the 64-bit
//! product, or on ARMv6-M (whose multiplier keeps only the low 32 bits)
//! from 16 by 16-bit partial products.

use super::ARMV6M;

/// `(a b + 2^15) >> 16` saturated to `i32`: from three 32-bit products on
/// ARMv6-M, from the 64-bit product elsewhere.
#[inline]
pub(super) fn saturated_product(a: i32, b: i32) -> i32 {
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
pub(super) fn split_saturated_product(a: i32, b: i32) -> i32 {
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

/// `(a b + 2^15) >> 16` modulo 2^32, for
/// [`Kernels::mul_bounded`](crate::scalar::sealed::Kernels::mul_bounded): the product when it is
/// within `i32`, which the caller has shown (and this crate's tests assert);
/// three 32-bit products on ARMv6-M, the 64-bit product truncated elsewhere
/// (the same bits).
#[inline]
pub(super) fn wrapping_product(a: i32, b: i32) -> i32 {
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
pub(super) fn fraction_product(a: i32, b: u32) -> i32 {
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
pub(super) fn split_product(a: i32, b: i32) -> i64 {
    let (ah, al) = (a >> 16, (a as u32) & 0xffff);
    let (bh, bl) = (b >> 16, (b as u32) & 0xffff);
    // |ah bh| <= 2^30; |ah bl|, |al bh| < 2^31; al bl + 2^15 < 2^32
    (i64::from(ah * bh) << 16)
        + i64::from(ah * bl as i32)
        + i64::from(al as i32 * bh)
        + i64::from((al * bl + 0x8000) >> 16)
}
