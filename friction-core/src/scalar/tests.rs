use super::*;

#[test]
fn sign_is_zero_at_zero() {
    assert_eq!(0.0f64.sign(), 0.0);
    assert_eq!((-2.0f32).sign(), -1.0);
    assert_eq!(3.0f64.sign(), 1.0);
}

#[test]
fn abs_clears_sign_bit() {
    assert_eq!((-2.5f32).abs(), 2.5);
    assert_eq!(Scalar::abs(-0.0f64).to_bits(), 0);
}

/// The worst error in units in the last place of `f` against the `f64`
/// `exact` over a sweep of `(0, end)`, dense near 0; beyond `top` (where
/// the result leaves the normal range) `f` must give (almost) 0.
fn worst_ulp(f: fn(f32) -> f32, exact: fn(f64) -> f64, top: f32, end: f32) -> f64 {
    let mut worst = 0.0f64;
    let mut x = 0.0f32;
    while x < end {
        let exact = exact(x as f64);
        let got = f(x) as f64;
        if x <= top {
            let ulp = (exact as f32).to_bits();
            let ulp = f32::from_bits(ulp + 1) as f64 - exact as f32 as f64;
            worst = worst.max((got - exact).abs() / ulp);
        } else {
            assert!(got < 2.0 * f32::MIN_POSITIVE as f64, "x {x}");
        }
        x = if x < 1e-3 {
            x + 1e-6
        } else {
            x * 1.000_37 + 1e-7
        };
    }
    worst
}

#[test]
fn exp_neg_f32_is_within_3_ulp_everywhere() {
    let worst = worst_ulp(exp_neg_f32, |x| libm::exp(-x), 87.3, 90.0);
    std::println!("exp_neg_f32: worst {worst} ulp");
    assert!(worst <= 3.0, "worst {worst} ulp");
    assert_eq!(exp_neg_f32(0.0), 1.0);
    assert_eq!(exp_neg_f32(-3.0), 1.0);
    assert!(exp_neg_f32(f32::NAN).is_nan());
    assert_eq!(exp_neg_f32(f32::INFINITY), 0.0);
    assert_eq!(exp_neg_f64(f64::INFINITY), 0.0);
    assert_eq!(exp_neg_f64(-1.0), 1.0);
}

#[test]
fn exp2_neg_f32_is_within_3_ulp_everywhere() {
    let worst = worst_ulp(exp2_neg_f32, |x| libm::exp2(-x), 126.0, 130.0);
    std::println!("exp2_neg_f32: worst {worst} ulp");
    assert!(worst <= 3.0, "worst {worst} ulp");
    assert_eq!(exp2_neg_f32(0.0), 1.0);
    assert_eq!(exp2_neg_f32(-3.0), 1.0);
    assert!((exp2_neg_f32(1.0) - 0.5).abs() <= 0.5 * f32::EPSILON);
    assert!(exp2_neg_f32(f32::NAN).is_nan());
    assert_eq!(exp2_neg_f32(f32::INFINITY), 0.0);
    assert_eq!(exp2_neg_f64(f64::INFINITY), 0.0);
    assert_eq!(exp2_neg_f64(-1.0), 1.0);
    assert_eq!(exp2_neg_f64(3.0), 0.125);
}

/// The worst error of `f` in units in the last place of `libm`'s
/// `reference` (itself within one of the exact value) over a sweep of
/// `(0, end)`, dense near 0 and over `band` (where the result nears the
/// subnormal range), pseudo-random points and every power of two.
fn worst_ulp_f64(f: fn(f64) -> f64, reference: fn(f64) -> f64, band: (f64, f64), end: f64) -> f64 {
    let mut worst = 0.0f64;
    let mut check = |x: f64| {
        let (want, got) = (reference(x), f(x));
        let ulp = f64::from_bits(want.to_bits() + 1) - want;
        worst = worst.max((got - want).abs() / ulp);
    };
    let mut x = 1e-300;
    while x < end {
        check(x);
        x = x * 1.000_03 + 1e-9;
    }
    let mut x = band.0;
    while x < band.1 {
        check(x);
        x += 1e-6;
    }
    let mut next = crate::test_rng::xorshift64(0x2545_f491_4f6c_dd1d);
    for _ in 0..1_000_000 {
        check((next() >> 11) as f64 / (1u64 << 53) as f64 * end);
    }
    for k in -60..10 {
        let p = 2.0f64.powi(k);
        for x in [p, p * (1.0 + f64::EPSILON), p * (1.0 - f64::EPSILON / 2.0)] {
            if x < end {
                check(x);
            }
        }
    }
    worst
}

#[test]
fn the_table_of_sixty_fourths_is_exp2() {
    for (j, &bits) in EXP2_NEG_SIXTY_FOURTHS.iter().enumerate() {
        let want = libm::exp2(-(j as f64) / 64.0);
        let ulp = f64::from_bits(want.to_bits() + 1) - want;
        assert!((f64::from_bits(bits) - want).abs() <= ulp, "2^-({j}/64)");
    }
}

#[test]
fn exp_neg_f64_is_within_1_ulp_of_libm() {
    let worst = worst_ulp_f64(exp_neg_f64, |x| libm::exp(-x), (700.0, 750.0), 760.0);
    std::println!("exp_neg_f64: worst {worst} ulp");
    assert!(worst <= 1.0, "worst {worst} ulp");
    assert_eq!(exp_neg_f64(0.0), 1.0);
    assert_eq!(exp_neg_f64(-0.0), 1.0);
    assert!(exp_neg_f64(f64::NAN).is_nan());
    assert_eq!(exp_neg_f64(f64::MIN_POSITIVE), 1.0);
}

#[test]
fn exp2_neg_f64_is_within_1_ulp_of_libm() {
    let worst = worst_ulp_f64(exp2_neg_f64, |x| libm::exp2(-x), (1005.0, 1080.0), 1100.0);
    std::println!("exp2_neg_f64: worst {worst} ulp");
    assert!(worst <= 1.0, "worst {worst} ulp");
    for k in 0..=1074 {
        assert_eq!(exp2_neg_f64(f64::from(k)), libm::ldexp(1.0, -k), "2^-{k}");
    }
    assert_eq!(exp2_neg_f64(f64::INFINITY), 0.0);
    assert!(exp2_neg_f64(f64::NAN).is_nan());
    assert_eq!(exp2_neg_f64(-0.0), 1.0);
}

#[test]
fn all_finite_finds_any_non_finite_value() {
    fn check<S: Scalar>(big: S, bad: &[S]) {
        let ok = [S::ONE, -big, big, S::ZERO];
        assert!(all_finite(ok));
        assert!(all_finite::<S, 0>([]));
        for &b in bad {
            for i in 0..4 {
                let mut xs = ok;
                xs[i] = b;
                assert!(!all_finite(xs), "{i}");
            }
        }
    }
    check(f32::MAX, &[f32::NAN, f32::INFINITY, f32::NEG_INFINITY]);
    check(f64::MAX, &[f64::NAN, f64::INFINITY, f64::NEG_INFINITY]);
}

#[test]
fn sat_by_magnitude_is_min_max() {
    fn check<S: Scalar + core::fmt::Debug>(values: &[S], bounds: &[S]) {
        for &a in bounds {
            for &x in values {
                let (want, got) = (x.min(a).max(-a).to_f64(), sat_by_magnitude(x, a).to_f64());
                // bit for bit (-0 stays -0), any NaN for a NaN
                let same = want.to_bits() == got.to_bits() || (want.is_nan() && got.is_nan());
                assert!(same, "sat({x:?}, {a:?}): {got:?}, want {want:?}");
            }
        }
    }
    let v32 = [
        0.0,
        -0.0,
        1e-45,
        -1e-45,
        0.5,
        -0.5,
        1.0,
        -1.0,
        2.0,
        -2.0,
        3e38,
        -3e38,
        f32::MAX,
        f32::MIN,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NAN,
    ];
    let a32 = [
        0.0,
        1e-45,
        1.0,
        1.5,
        3e38,
        f32::MAX,
        f32::INFINITY,
        f32::NAN,
    ];
    check::<f32>(&v32, &a32);
    let v64 = v32.map(f64::from);
    let a64 = a32.map(f64::from);
    check::<f64>(&v64, &a64);
}

#[test]
fn sat_clamps_both_sides() {
    assert_eq!(5.0f64.sat(2.0), 2.0);
    assert_eq!((-5.0f64).sat(2.0), -2.0);
    assert_eq!(1.0f64.sat(2.0), 1.0);
}
