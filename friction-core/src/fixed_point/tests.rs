//! Tests of the fixed-point kernels, quotients and functions.

use super::division::*;
use super::functions::*;
use super::kernels::*;
use super::*;

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
        assert_eq!(fraction_product(a, b), want, "{a} x {b}");
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
        assert_eq!(split_product(a, b), want, "{a} x {b}");
        let saturated = want.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32;
        assert_eq!(split_saturated_product(a, b), saturated, "{a} x {b}");
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
    assert_eq!(Fixed32::try_from_f64(1e5), Err(ScalarConversion::Overflow));
    assert_eq!(
        Fixed32::try_from_f64(f64::NAN),
        Err(ScalarConversion::Overflow)
    );
    assert_eq!(
        Fixed32::try_from_f64(1e-6),
        Err(ScalarConversion::Underflow)
    );
    // 1e-3 is 65.536 steps: 0.7 % rounding
    assert_eq!(Fixed32::try_from_f64(1e-3), Err(ScalarConversion::Rounding));
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

#[test]
fn half_is_the_product_with_one_half_bit_for_bit() {
    let half = Fixed32::from_f64(0.5);
    let mut next = crate::test_rng::xorshift64(0x9e37_79b9_7f4a_7c15);
    let edges = [
        i32::MIN,
        i32::MIN + 1,
        -3,
        -2,
        -1,
        0,
        1,
        2,
        3,
        i32::MAX - 1,
        i32::MAX,
    ];
    let random = (0..100_000).map(|_| next() as i32);
    for bits in edges.into_iter().chain(random) {
        let x = Fixed32::from_bits(bits);
        assert_eq!(x.half().to_bits(), (x * half).to_bits(), "{bits}");
    }
}
