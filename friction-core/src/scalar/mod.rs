//! The number trait the models are generic over: see [`Scalar`].

use crate::fixed_step::signed;
use core::fmt::Debug;
use core::ops::{Add, Div, Mul, Neg, Sub};
#[cfg(doc)]
use sealed::Kernels;

/// Why [`Scalar::try_from_f64`] refused a value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ScalarConversion {
    /// Too large in magnitude for the type (or not finite).
    Overflow,
    /// Non-zero, but below the smallest positive value the type carries
    /// at full precision.
    Underflow,
    /// Representable, but more than 0.1 % away from the design value.
    Rounding,
}

/// A real number as the models compute with it: the number trait the
/// models are generic over.
///
/// It is the project's own and deliberately small: arithmetic and
/// comparison, the constants, conversion from and to `f64`, and the few
/// functions the models' equations are written with (`abs`, `exp`,
/// `exp_m1`, `ln_1p`, `powf`, the bounded-range `exp_neg`, `sign`, `min`,
/// `max`, `sat`), so that a fixed-point type (from the `fixed` crate) can
/// implement it with table or polynomial approximations where `f32`/`f64`
/// call [`libm`]. `num_traits::Float` cannot be implemented for fixed point.
///
/// Implemented for `f32` and `f64` through `libm`, and (feature `fixed`) for
/// the Q16.16 `Fixed32`. Parameters are designed
/// in `f64` and converted once, when a model is built, with [`Scalar::from_f64`].
///
/// The trait is sealed: it cannot be implemented outside this crate. The
/// numeric kernels and tuning flags the fixed-step forms are tuned with
/// (force scaling, bounded and fraction products, the Stribeck and
/// elasto-plastic curves) sit in a crate-private supertrait, so that they
/// can change without a breaking release.
pub trait Scalar:
    sealed::Kernels
    + Copy
    + PartialOrd
    + Debug
    + Default
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// 0.
    const ZERO: Self;
    /// 1.
    const ONE: Self;
    /// The smallest positive normal value: a non-zero parameter smaller in
    /// magnitude is rejected when a model is built.
    const MIN_POSITIVE: Self;
    /// Velocity magnitude (m/s or rad/s) above which model inputs are
    /// clamped; `build()` checks that every force term stays within range up
    /// to it. [`crate::VELOCITY_LIMIT`] (1e6) for `f32` and `f64`.
    const VELOCITY_LIMIT: Self;

    /// Converts a design-time `f64`, rounding to the nearest representable
    /// value (saturating where the type cannot overflow to infinity).
    fn from_f64(x: f64) -> Self;

    /// Converts a design-time `f64`, checked: [`ScalarConversion::Overflow`] if it
    /// does not fit (or is not finite), [`ScalarConversion::Underflow`] if a
    /// non-zero value lands below [`Scalar::MIN_POSITIVE`] (zero, or a
    /// subnormal float), [`ScalarConversion::Rounding`] if it loses more than
    /// 0.1 % to rounding. Every `build()` converts its parameters with it.
    fn try_from_f64(x: f64) -> Result<Self, ScalarConversion> {
        if !x.is_finite() {
            return Err(ScalarConversion::Overflow);
        }
        let s = Self::from_f64(x);
        if !s.is_finite() {
            Err(ScalarConversion::Overflow)
        } else if x != 0.0 && s.abs() < Self::MIN_POSITIVE {
            Err(ScalarConversion::Underflow)
        } else if (s.to_f64() - x).abs() > 1e-3 * x.abs() {
            Err(ScalarConversion::Rounding)
        } else {
            Ok(s)
        }
    }
    /// Converts back to `f64` (for logs and host-side comparisons).
    fn to_f64(self) -> f64;
    /// `|x|`.
    fn abs(self) -> Self;
    /// `e^x`.
    fn exp(self) -> Self;
    /// `e^x - 1`, accurate for small `x`.
    fn exp_m1(self) -> Self;
    /// `ln(1 + x)`, accurate for small `x`.
    fn ln_1p(self) -> Self;
    /// `x^y` for `x >= 0`.
    fn powf(self, y: Self) -> Self;
    /// `true` unless the value is NaN or infinite.
    fn is_finite(self) -> bool;

    /// `e^-x` for `x >= 0` (a negative `x` counts as 0; NaN stays NaN): the
    /// bounded-range exponential of the fixed-step forms. `f32` uses a
    /// range-reduced polynomial in `f32` alone (libm's `expf` works partly in
    /// `f64`, which an M4F's FPU lacks), within 3 units in the last place;
    /// `f64` a table of `2^-(j/64)` and a polynomial, within 1 unit in the
    /// last place of `libm::exp` (0 beyond 746, where it rounds to 0).
    fn exp_neg(self) -> Self;

    /// `sign(x)`: -1, 0 or 1 (0 at zero, unlike `f64::signum`).
    #[inline]
    fn sign(self) -> Self {
        if self > Self::ZERO {
            Self::ONE
        } else if self < Self::ZERO {
            -Self::ONE
        } else {
            Self::ZERO
        }
    }

    /// The smaller of two values.
    #[inline]
    fn min(self, other: Self) -> Self {
        if other < self {
            other
        } else {
            self
        }
    }

    /// The larger of two values.
    #[inline]
    fn max(self, other: Self) -> Self {
        if other > self {
            other
        } else {
            self
        }
    }

    /// `sat(a, x) = max(-a, min(a, x))` for `a >= 0`.
    #[inline]
    fn sat(self, a: Self) -> Self {
        self.min(a).max(-a)
    }
}

/// The crate-private half of [`Scalar`] (the sealed-trait pattern): `pub`
/// so that it can be a supertrait of the public [`Scalar`], in a module
/// that is not exported, so that code outside the crate can neither name
/// nor implement it (nor, therefore, [`Scalar`]). Generic code outside the
/// crate still reaches its items through an `S: Scalar` bound (the pattern
/// cannot hide a supertrait's methods from a bound), but they are not
/// documented there and not part of the API.
pub(crate) mod sealed {
    use super::Scalar;

    /// The numeric kernels and tuning flags of the fixed-step forms, which
    /// a scalar may specialise: force scaling ([`Kernels::force_scale`] and
    /// the rescaling products), the products a model has bounded
    /// ([`Kernels::mul_bounded`], [`Kernels::mul_fraction`]), the
    /// exponentials of the Stribeck curve ([`Kernels::exp2_neg`],
    /// [`Kernels::exp_neg_square`]), the elasto-plastic zone's
    /// [`Kernels::zone_curve`], and the flags the models read. Every
    /// `S: Scalar` bound in the crate reaches them; the defaults are the
    /// floating-point forms, written with [`Scalar`]'s items.
    pub trait Kernels {
        /// `(m + 0.5) / 2^24` for a 24-bit `m`, rounded once to the type: a
        /// random unit in `(0, 1)` ([`crate::random::CounterRng::unit`]). The
        /// floats form it in their own precision (`m` is exact, the sum is
        /// rounded once, the power of two is exact: the same value as through
        /// `f64`, without soft-float `f64` arithmetic on an FPU-less or f32-only core).
        fn from_unit24(m: u32) -> Self
        where
            Self: Scalar,
        {
            Self::from_f64((f64::from(m) + 0.5) * (1.0 / 16_777_216.0))
        }

        /// The power of two by which a fixed-step form scales the forces it
        /// carries inside, given the largest force term it must hold
        /// (`max_force`, from the parameters at the velocity limit). `1` for
        /// floats, where scaling by a power of two changes nothing; for fixed
        /// point, the largest power of two that keeps `4 max_force scale` in
        /// range, so that small forces and small per-step increments keep their
        /// precision.
        fn force_scale(max_force: f64) -> f64 {
            let _ = max_force;
            1.0
        }

        /// Whether [`Kernels::force_scale`] can differ from 1 (fixed point).
        const SCALES_FORCES: bool = false;

        /// Whether every value is finite (fixed point: no NaN or infinity), so
        /// that an input check is a clamp alone.
        const ALWAYS_FINITE: bool = false;

        /// Whether a quotient is one instruction (floating point on a core with
        /// a floating-point unit), so that a step forms one it may not need
        /// rather than test whether it needs it; not in fixed point (a long
        /// division) or soft float (a library call).
        const CHEAP_DIVISION: bool = false;

        /// `self * factor` for a factor derived from [`Kernels::force_scale`]:
        /// skipped where forces are never scaled (floats), so that the
        /// fixed-step forms pay nothing for scaling in floating point.
        #[inline]
        fn rescale(self, factor: Self) -> Self
        where
            Self: Scalar,
        {
            if Self::SCALES_FORCES {
                self * factor
            } else {
                self
            }
        }

        /// `self / 2`, as `self * 0.5`: fixed point overrides it with a
        /// shift that rounds as its product does (half up), the same bits
        /// for a fraction of a product's cost on a core without a 64-bit
        /// multiply.
        #[inline]
        fn half(self) -> Self
        where
            Self: Scalar,
        {
            self * Self::from_f64(0.5)
        }

        /// `self 2^exp` for a power of two derived from
        /// [`Kernels::force_scale`] (`exp` in -31..=31), skipped like
        /// [`Kernels::rescale`] where forces are never scaled. Fixed point
        /// overrides it with a shift (rounding to nearest, saturating), which
        /// costs a core without a 64-bit multiply far less than a product.
        #[inline]
        fn rescale_pow2(self, exp: i8) -> Self
        where
            Self: Scalar,
        {
            if Self::SCALES_FORCES {
                self * Self::from_f64(libm::exp2(f64::from(exp)))
            } else {
                self
            }
        }

        /// `self * b` where the caller has shown the product within the scalar's
        /// range, with a margin, for every input a model accepts (by the checks
        /// of its `build_fixed_step` and the clamp of its velocity): fixed point then skips
        /// its overflow test (on ARMv6-M three 32-bit products without the test
        /// of the operands' high halves). The product whenever it is within the
        /// range; beyond it, fixed point wraps instead of saturating (never a
        /// panic). This crate's own tests assert the bound at every call.
        #[inline]
        fn mul_bounded(self, b: Self) -> Self
        where
            Self: Scalar,
        {
            self * b
        }

        /// `1 / (self 2^exp)` for `self > 0` and an `exp` derived from
        /// [`Kernels::force_scale`] (`-14..=14`; 0 in floating point): the
        /// unscaled reciprocal of a scaled force, such as LuGre's `k / g`, formed
        /// without rounding `self 2^exp` first. The same value as the quotient
        /// `2^-exp / self` ([`Kernels::rescale_pow2`] of 1) for any `self`; fixed
        /// point overrides it with a reciprocal in digits of a 16-bit estimate,
        /// which has no whole part to divide first (cheaper than the quotient on
        /// a Cortex-M0, which has no divide instruction; see the cost guide).
        #[inline]
        fn reciprocal_rescaled(self, exp: i8) -> Self
        where
            Self: Scalar,
        {
            Self::ONE.rescale_pow2(exp.saturating_neg()) / self
        }

        /// `self * f` where the caller knows the factor is a fraction,
        /// `0 <= f < 1` (such as `e^-x`, `1 - e^-x`, a ratio below its bound):
        /// the same value as the product for any `f`. Fixed point on ARMv6-M
        /// overrides it with two 16 by 16-bit partial products instead of four
        /// and no saturation, which cannot occur (a Cortex-M0 has only a 32-bit
        /// multiply, so each partial product saved counts); any other `f` takes
        /// the full product.
        #[inline]
        fn mul_fraction(self, f: Self) -> Self
        where
            Self: Scalar,
        {
            self * f
        }

        /// `2^-x` for `x >= 0` (a negative `x` counts as 0; NaN stays NaN), for
        /// a caller that folded `log2 e` into a constant built in `f64`
        /// (`e^-y = 2^-(y log2 e)`; the Stribeck curve of the fixed-step forms):
        /// the integer part of `x` is a power of two, only the fraction needs a
        /// polynomial, so the range reduction is one subtraction. Default:
        /// [`Scalar::exp_neg`] of `x ln 2`.
        #[inline]
        fn exp2_neg(self) -> Self
        where
            Self: Scalar,
        {
            (self * Self::from_f64(core::f64::consts::LN_2)).exp_neg()
        }

        /// `e^-(x^2)`: the Stribeck curve of the fixed-step forms with
        /// `delta = 2` in a scalar without [`Kernels::EXP2_FOLDS`]. Default:
        /// [`Scalar::exp_neg`] of `x x`; fixed point evaluates a table of cubic
        /// segments instead (no product, no range reduction).
        #[inline]
        fn exp_neg_square(self) -> Self
        where
            Self: Scalar,
        {
            (self * self).exp_neg()
        }

        /// `(pi/2)^2 (sin(phi) / phi)^2` for `phi = pi u / 2` and `u = self` in
        /// `[0, 1]`: the elasto-plastic transition zone's rate factor, from 2.47
        /// at 0 to 1 at 1. Default: the series of `sin(phi) / phi` in
        /// `(phi/2)^2`, squared; fixed point evaluates a table of cubic segments
        /// built at compile time instead (one segment's cubic in place of the
        /// series and its square, cheaper on a Cortex-M0; see the cost guide).
        #[inline]
        fn zone_curve(self) -> Self
        where
            Self: Scalar,
        {
            crate::models::elasto_plastic::zone_curve_series(self)
        }

        /// Whether [`Kernels::exp2_neg`] is the cheaper exponential (the floats):
        /// then the fixed-step Stribeck curve folds `log2 e` into `1/vs` when it
        /// is built. Fixed point keeps [`Scalar::exp_neg`] and `1/vs` as given
        /// (a folded `1/vs` would overflow Q16.16 sooner).
        const EXP2_FOLDS: bool = false;

        /// `-self` when `v < 0`, else `self`: the fixed steps' `sign(v) x` where
        /// the value at `v = 0` is never used. Off ARM the floats flip the sign
        /// bit by `v`'s, bit operations instead of a comparison and a select (a
        /// `v` of `-0.0` then flips it too).
        #[inline]
        fn negated_if_negative(self, v: Self) -> Self
        where
            Self: Scalar,
        {
            if v < Self::ZERO {
                -self
            } else {
                self
            }
        }
    }
}

macro_rules! impl_float_scalar {
    ($t:ty, $cheap_division:expr, $abs:path, $exp:path, $exp_neg:path, $exp2_neg:path, $expm1:path, $log1p:path, $pow:path) => {
        impl sealed::Kernels for $t {
            const EXP2_FOLDS: bool = true;
            const CHEAP_DIVISION: bool = $cheap_division;
            #[inline]
            fn from_unit24(m: u32) -> Self {
                ((m & 0xFF_FFFF) as $t + 0.5) * (1.0 / 16_777_216.0)
            }
            #[cfg(not(target_arch = "arm"))]
            #[inline]
            fn negated_if_negative(self, v: Self) -> Self {
                let sign = (-0.0 as $t).to_bits();
                <$t>::from_bits(self.to_bits() ^ (v.to_bits() & sign))
            }
            #[inline]
            fn exp2_neg(self) -> Self {
                $exp2_neg(self)
            }
        }

        impl Scalar for $t {
            const ZERO: Self = 0.0;
            const ONE: Self = 1.0;
            const MIN_POSITIVE: Self = <$t>::MIN_POSITIVE;
            const VELOCITY_LIMIT: Self = crate::model::VELOCITY_LIMIT as $t;
            #[inline]
            fn from_f64(x: f64) -> Self {
                x as $t
            }
            #[inline]
            fn to_f64(self) -> f64 {
                self as f64
            }
            #[inline]
            fn abs(self) -> Self {
                $abs(self)
            }
            #[inline]
            fn exp(self) -> Self {
                $exp(self)
            }
            #[inline]
            fn exp_m1(self) -> Self {
                $expm1(self)
            }
            #[inline]
            fn ln_1p(self) -> Self {
                $log1p(self)
            }
            #[inline]
            fn powf(self, y: Self) -> Self {
                $pow(self, y)
            }
            #[inline]
            fn is_finite(self) -> bool {
                <$t>::is_finite(self)
            }
            #[inline]
            fn exp_neg(self) -> Self {
                $exp_neg(self)
            }
            /// On ARM (no floating-point min or max before ARMv8)
            /// `sat_by_magnitude`: the default's value, with one
            /// comparison of `|x|` for a value within the bound.
            #[inline]
            fn sat(self, a: Self) -> Self {
                if cfg!(target_arch = "arm") {
                    sat_by_magnitude(self, a)
                } else {
                    // the trait's min and max (a NaN stays NaN), not the
                    // inherent IEEE ones
                    Scalar::max(Scalar::min(self, a), -a)
                }
            }
        }
    };
}

impl_float_scalar!(
    f32,
    FLOAT_UNIT,
    libm::fabsf,
    libm::expf,
    exp_neg_f32,
    exp2_neg_f32,
    libm::expm1f,
    libm::log1pf,
    libm::powf
);
// an ARM core's floating-point unit, where it has one, is taken to be
// single precision (Cortex-M4F, M33): f64 is a library call there
impl_float_scalar!(
    f64,
    FLOAT_UNIT && !cfg!(target_arch = "arm"),
    libm::fabs,
    libm::exp,
    exp_neg_f64,
    exp2_neg_f64,
    libm::expm1,
    libm::log1p,
    libm::pow
);

/// `log2(1 / k)` for a force scale `k` ([`Kernels::force_scale`], a power
/// of two within `2^-14 ..= 2^14`, 1 in floating point): the exponent that
/// [`Kernels::rescale_pow2`] divides by `k` with.
pub(crate) fn inverse_scale_exp(k: f64) -> i8 {
    // a whole number within -14 ..= 14
    -(libm::round(libm::log2(k)).clamp(-14.0, 14.0) as i8)
}

/// Whether floating-point arithmetic runs on a floating-point unit: not on
/// an ARM target with the soft-float ABI (Cortex-M0, or M3), where each
/// operation is a library call.
const FLOAT_UNIT: bool = !cfg!(all(target_arch = "arm", not(target_abi = "eabihf")));

/// Whether every value is finite. With a floating-point unit `x - x` is 0
/// for a finite `x` and NaN for an infinite or NaN one, so one comparison of
/// the sum tests them all (in place of a test of each value's exponent
/// bits, a move out of the FPU and an integer test per value);
/// soft float tests the bits; fixed point is always finite.
#[inline]
#[allow(clippy::eq_op)] // `x - x` is the test
pub(crate) fn all_finite<S: Scalar, const N: usize>(xs: [S; N]) -> bool {
    if S::SCALES_FORCES || !FLOAT_UNIT {
        xs.iter().all(|x| x.is_finite())
    } else {
        // no `0 +` to start from: the compiler cannot drop it (-0 + 0 = +0)
        xs.iter()
            .map(|&x| x - x)
            .reduce(|sum, d| sum + d)
            .is_none_or(|sum| sum == S::ZERO)
    }
}

/// `sat(x, a)` for `a >= 0` as the ARM targets form it: `x` unless
/// `|x| > a`, then `a` with the sign of `x` (`x` is then neither 0 nor
/// NaN). The same value as `x.min(a).max(-a)`, NaN and `-0` included
/// (`|x| > a` is false for a NaN `x` or `a`, which leaves `x`); on the
/// Cortex-M4F (FPv4 has no min or max) a value within the bound costs one
/// comparison instead of two compare-and-moves, and one beyond it about as
/// much as the two.
#[inline]
fn sat_by_magnitude<S: Scalar>(x: S, a: S) -> S {
    if x.abs() > a {
        signed(x, a)
    } else {
        x
    }
}

/// The bits of `2^-(j/64)` for `j` in `0..64`, correctly rounded (computed
/// to 60 digits with Python's `decimal`; a test checks each against
/// `libm::exp2`). A table built here in `f64` carried up to 3 units in the
/// last place.
const EXP2_NEG_SIXTY_FOURTHS: [u64; 64] = [
    0x3ff0_0000_0000_0000,
    0x3fef_a7c1_819e_90d8,
    0x3fef_5076_5b6e_4540,
    0x3fee_fa1b_ee61_5a27,
    0x3fee_a4af_a2a4_90da,
    0x3fee_502e_e78b_3ff6,
    0x3fed_fc97_337b_9b5f,
    0x3fed_a9e6_03db_3285,
    0x3fed_5818_dcfb_a487,
    0x3fed_072d_4a07_897c,
    0x3fec_b720_dcef_9069,
    0x3fec_67f1_2e57_d14b,
    0x3fec_199b_dd85_529c,
    0x3feb_cc1e_904b_c1d2,
    0x3feb_7f76_f2fb_5e47,
    0x3feb_33a2_b84f_15fb,
    0x3fea_e89f_995a_d3ad,
    0x3fea_9e6b_5579_fdbf,
    0x3fea_5503_b23e_255d,
    0x3fea_0c66_7b5d_e565,
    0x3fe9_c491_82a3_f090,
    0x3fe9_7d82_9fde_4e50,
    0x3fe9_3737_b0cd_c5e5,
    0x3fe8_f1ae_9915_7736,
    0x3fe8_ace5_422a_a0db,
    0x3fe8_68d9_9b44_92ed,
    0x3fe8_2589_994c_ce13,
    0x3fe7_e2f3_36cf_4e62,
    0x3fe7_a114_73eb_0187,
    0x3fe7_5feb_5642_67c9,
    0x3fe7_1f75_e8ec_5f74,
    0x3fe6_dfb2_3c65_1a2f,
    0x3fe6_a09e_667f_3bcd,
    0x3fe6_6238_8255_2225,
    0x3fe6_247e_b03a_5585,
    0x3fe5_e76f_15ad_2148,
    0x3fe5_ab07_dd48_5429,
    0x3fe5_6f47_36b5_27da,
    0x3fe5_342b_569d_4f82,
    0x3fe4_f9b2_769d_2ca7,
    0x3fe4_bfda_d536_2a27,
    0x3fe4_86a2_b5c1_3cd0,
    0x3fe4_4e08_6061_892d,
    0x3fe4_160a_21f7_2e2a,
    0x3fe3_dea6_4c12_3422,
    0x3fe3_a7db_34e5_9ff7,
    0x3fe3_71a7_373a_a9cb,
    0x3fe3_3c08_b264_16ff,
    0x3fe3_06fe_0a31_b715,
    0x3fe2_d285_a6e4_030b,
    0x3fe2_9e9d_f51f_dee1,
    0x3fe2_6b45_65e2_7cdd,
    0x3fe2_387a_6e75_6238,
    0x3fe2_063b_8862_8cd6,
    0x3fe1_d487_3168_b9aa,
    0x3fe1_a35b_eb6f_cb75,
    0x3fe1_72b8_3c7d_517b,
    0x3fe1_429a_aea9_2de0,
    0x3fe1_1301_d012_5b51,
    0x3fe0_e3ec_32d3_d1a2,
    0x3fe0_b558_6cf9_890f,
    0x3fe0_8745_1875_9bc8,
    0x3fe0_59b0_d315_8574,
    0x3fe0_2c9a_3e77_8061,
];

/// The integer nearest to `0 <= y < 2^31` (ties to even), as `u32` and
/// `f64`: `y + 2^52` rounds `y` to an integer in its low bits, and taking
/// `2^52` off again is exact (no conversion instruction and, unlike an
/// `as` cast, no clamp to the `u32` range).
#[inline]
fn nearest_integer(y: f64) -> (u32, f64) {
    const SHIFT: f64 = 4_503_599_627_370_496.0; // 2^52
    let shifted = y + SHIFT;
    (shifted.to_bits() as u32, shifted - SHIFT)
}

/// [`EXP2_NEG_SIXTY_FOURTHS`] times `2^256` (its exponent fields raised by
/// 256, exact), for [`times_table`].
// evaluated at compile time: an index out of range fails the build
#[allow(clippy::indexing_slicing)]
const EXP2_NEG_SIXTY_FOURTHS_RAISED: [u64; 64] = {
    let mut table = EXP2_NEG_SIXTY_FOURTHS;
    let mut j = 0;
    while j < 64 {
        table[j] += 256 << 52;
        j += 1;
    }
    table
};

/// `2^-(n/64) (1 + p)` for a small `p` and `n < 64 1077`: `n = 64 q + j`,
/// `t = 2^(256 - j/64 - q)` from the raised table by taking `q` off its
/// exponent field (which stays within 202 ..= 1279, a normal number), and
/// `(t + t p) 2^-256`: exact scaling for a normal result, one rounding for
/// a subnormal one (where the unraised `t p` would itself have rounded).
#[inline]
fn times_table(n: u32, p: f64) -> f64 {
    const TWO_TO_MINUS_256: f64 = 8.636_168_555_094_445e-78;
    let bits = EXP2_NEG_SIXTY_FOURTHS_RAISED
        .get((n & 63) as usize)
        .copied()
        .unwrap_or(0); // the index is below 64
    let t = f64::from_bits(bits.wrapping_sub(u64::from(n >> 6) << 52));
    (t + t * p) * TWO_TO_MINUS_256
}

/// `e^t - 1` for `|t| <= ln2 / 128` by its degree-5 Taylor polynomial
/// (truncation under `0.0055^6 / 6! < 4e-17`): the reduced argument's part
/// of [`exp_neg_f64`] and [`exp2_neg_f64`].
#[inline]
fn exp_m1_small(t: f64) -> f64 {
    t * (1.0 + t * (1.0 / 2.0 + t * (1.0 / 6.0 + t * (1.0 / 24.0 + t * (1.0 / 120.0)))))
}

/// `e^-x` in `f64`: `x = n ln2 / 64 + r` with `|r| <= ln2 / 128` (Cody-Waite:
/// `ln2 / 64` split in a part whose product with `n < 2^17` is exact and a
/// correction), `e^-r - 1` by [`exp_m1_small`], `2^-(n/64)` from a table of 64 and the
/// exponent bits ([`times_table`]): within 1 unit in the last place of
/// `libm::exp` over its whole range, subnormal results included (tested),
/// and cheaper; 0 beyond 746, where `e^-x` rounds to 0.
#[inline]
fn exp_neg_f64(x: f64) -> f64 {
    const SIXTY_FOUR_LOG2E: f64 = 64.0 * core::f64::consts::LOG2_E;
    // ln2 / 64 = STEP_HI + STEP_LO: STEP_HI with 36 significant bits
    // (0x1.62e42fefap-7; n < 2^17), STEP_LO the rest of ln2 / 64 to 50
    // digits, rounded (`LN_2 / 64.0 - STEP_HI` would carry LN_2's rounding,
    // 3.6e-19)
    const STEP_HI: f64 = 0.010_830_424_696_223_417;
    const STEP_LO: f64 = 2.572_804_622_327_669e-14;
    // one comparison of the bits admits exactly 0 <= x <= 746 (not -0.0:
    // the sign bit, not NaN or infinity: the largest exponent); e^-0 comes
    // out as 1 exactly
    const TOP: u64 = 0x4087_5000_0000_0000; // 746.0
    if x.to_bits() > TOP {
        return beyond_range_f64(x);
    }
    let (n, nf) = nearest_integer(x * SIXTY_FOUR_LOG2E);
    let s = nf * STEP_HI - x + nf * STEP_LO; // -r, within ±ln2 / 128
    times_table(n, exp_m1_small(s))
}

/// [`exp_neg_f64`] and [`exp2_neg_f64`] outside their polynomial's range:
/// NaN stays NaN, `x <= 0` gives 1, a large `x` gives 0.
#[inline]
fn beyond_range_f64(x: f64) -> f64 {
    if x.is_nan() {
        x
    } else if x <= 0.0 {
        1.0
    } else {
        0.0
    }
}

/// `e^-x` in `f32` arithmetic only: `x = k ln2 + r` with `|r| <= ln2 / 2`
/// (Cody-Waite: `ln2` split in a part whose product with `k <= 126` is exact
/// and a correction), `e^-r` by a degree-5 polynomial (Remez, relative
/// error 7.5e-8; 3.0 units in the last place at worst over every `f32` in
/// `(0, 87.3]`, measured), and `2^-k` written into the exponent bits. Returns 0 beyond
/// `x = 87.3`, where the result leaves the normal range (`e^-87.3 = 1.2e-38`).
#[inline]
fn exp_neg_f32(x: f32) -> f32 {
    const LOG2E: f32 = core::f32::consts::LOG2_E;
    const LN2_HI: f32 = 0.693_145_75; // 0x3f31_7200: 15 significant bits
    const LN2_LO: f32 = 1.428_606_8e-6; // ln 2 - LN2_HI

    // one unsigned comparison of the bits admits exactly 0 < x <= 87.3
    // (negatives have the sign bit set, NaN and infinity the largest exponents)
    const TOP: u32 = 0x42ae_999a; // 87.3

    // e^s on |s| <= ln2 / 2: the degree-5 polynomial of least relative
    // error (Remez; 7.5e-8, half a unit in the last place), one term fewer
    // than the Taylor polynomial of the same accuracy
    const C0: f32 = 1.000_000_1;
    const C1: f32 = 0.999_999_8;
    const C2: f32 = 0.499_988_94;
    const C3: f32 = 0.166_675_75;
    const C4: f32 = 0.041_915_383;
    const C5: f32 = 0.008_297_656;
    if x.to_bits().wrapping_sub(1) >= TOP {
        return beyond_range(x);
    }
    // 0 <= k <= 126: the cast cannot saturate
    let k = (x * LOG2E + 0.5) as i32;
    let kf = k as f32;
    let s = kf * LN2_HI - x + kf * LN2_LO; // -r, within ±ln2/2
    let p = C0 + s * (C1 + s * (C2 + s * (C3 + s * (C4 + s * C5))));
    times_pow2_neg(p, k)
}

/// [`exp_neg_f32`] and [`exp2_neg_f32`] outside their polynomial's range:
/// NaN stays NaN, `x <= 0` gives 1, a large `x` gives 0.
#[inline]
fn beyond_range(x: f32) -> f32 {
    if x.is_nan() {
        x
    } else if x <= 0.0 {
        1.0
    } else {
        0.0
    }
}

/// `p 2^-k` for `0 <= k <= 126`, with `2^-k` written into the exponent
/// bits (`127 - k` is in 1..=127: a normal power of two).
#[inline]
fn times_pow2_neg(p: f32, k: i32) -> f32 {
    p * f32::from_bits(((127 - k) as u32) << 23)
}

/// `2^-x` in `f64`: `x = (n - s) / 64` with `n` the nearest integer to
/// `64 x` and `|s| <= 1/2` (`s = n - 64 x` is exact), `2^(s/64) - 1` by
/// [`exp_m1_small`] of `s ln2 / 64` and `2^-(n/64)` as in [`exp_neg_f64`]: within
/// 1 unit in the last place of `libm::exp2` over its whole range (tested);
/// 0 beyond 1075, where `2^-x` rounds to 0.
#[inline]
fn exp2_neg_f64(x: f64) -> f64 {
    const STEP: f64 = core::f64::consts::LN_2 / 64.0;
    // one comparison of the bits admits exactly 0 <= x <= 1075, as in
    // exp_neg_f64; 2^-0 comes out as 1 exactly
    const TOP: u64 = 0x4090_cc00_0000_0000; // 1075.0
    if x.to_bits() > TOP {
        return beyond_range_f64(x);
    }
    let y = 64.0 * x; // exact
    let (n, nf) = nearest_integer(y);
    let t = (nf - y) * STEP; // s ln2 / 64, within ±ln2 / 128
    times_table(n, exp_m1_small(t))
}

/// `2^-x` in `f32` arithmetic only: `x = k - s` with `k` the nearest
/// integer and `|s| <= 1/2` (`s = k - x` is exact), `2^s` by
/// [`exp_neg_f32`]'s polynomial with its coefficients times `ln2^i` (the
/// same relative error; 3.0 units in the last place at worst over every
/// `f32` in `(0, 126]`, measured), and `2^-k` written into the exponent
/// bits. Returns 0 beyond `x = 126`, where the result leaves the normal range.
#[inline]
fn exp2_neg_f32(x: f32) -> f32 {
    // one unsigned comparison of the bits admits exactly 0 < x <= 126
    // (0x42fc_0000 is 126.0)
    const TOP: u32 = 0x42fc_0000;

    // 2^s = e^(s ln 2) on |s| <= 1/2: exp_neg_f32's C_i times ln2^i
    const D0: f32 = 1.000_000_1;
    const D1: f32 = 0.693_147_04;
    const D2: f32 = 0.240_221_19;
    const D3: f32 = 0.055_507_134;
    const D4: f32 = 0.009_675_542;
    const D5: f32 = 0.001_327_647_4;
    if x.to_bits().wrapping_sub(1) >= TOP {
        return beyond_range(x);
    }
    // 0 <= k <= 126: the cast cannot saturate
    let k = (x + 0.5) as i32;
    // exact (Sterbenz), within ±1/2; for x = 1/2 - 2^-25, where x + 1/2
    // rounds up to 1, s = 1/2 is off by 2^-25 (within the error bound)
    let s = k as f32 - x;
    let p = D0 + s * (D1 + s * (D2 + s * (D3 + s * (D4 + s * D5))));
    times_pow2_neg(p, k)
}

#[cfg(test)]
mod tests;
