//! The number trait the models are generic over.
//!
//! It is the project's own and deliberately small: it names only what the
//! models need, so that a fixed-point type (from the `fixed` crate) can
//! implement it with table or polynomial approximations where `f32`/`f64`
//! call [`libm`]. `num_traits::Float` cannot be implemented for fixed point.

use core::fmt::Debug;
use core::ops::{Add, Div, Mul, Neg, Sub};

/// A real number as the models compute with it.
///
/// Implemented for `f32` and `f64` through `libm`. Parameters are designed
/// in `f64` and converted once, when a model is built, with [`Scalar::from_f64`].
pub trait Scalar:
    Copy
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

    /// Converts a design-time `f64`, rounding to the nearest representable value.
    fn from_f64(x: f64) -> Self;
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
    /// `sqrt(x)` for `x >= 0`.
    fn sqrt(self) -> Self;
    /// `sin(x)` (radians).
    fn sin(self) -> Self;
    /// `cos(x)` (radians).
    fn cos(self) -> Self;
    /// `true` unless the value is NaN or infinite.
    fn is_finite(self) -> bool;

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

macro_rules! impl_float_scalar {
    ($t:ty, $abs:path, $exp:path, $expm1:path, $log1p:path, $pow:path, $sqrt:path, $sin:path, $cos:path) => {
        impl Scalar for $t {
            const ZERO: Self = 0.0;
            const ONE: Self = 1.0;
            const MIN_POSITIVE: Self = <$t>::MIN_POSITIVE;
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
            fn sqrt(self) -> Self {
                $sqrt(self)
            }
            #[inline]
            fn sin(self) -> Self {
                $sin(self)
            }
            #[inline]
            fn cos(self) -> Self {
                $cos(self)
            }
            #[inline]
            fn is_finite(self) -> bool {
                <$t>::is_finite(self)
            }
        }
    };
}

impl_float_scalar!(
    f32,
    libm::fabsf,
    libm::expf,
    libm::expm1f,
    libm::log1pf,
    libm::powf,
    libm::sqrtf,
    libm::sinf,
    libm::cosf
);
impl_float_scalar!(
    f64,
    libm::fabs,
    libm::exp,
    libm::expm1,
    libm::log1p,
    libm::pow,
    libm::sqrt,
    libm::sin,
    libm::cos
);

#[cfg(test)]
mod tests {
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

    #[test]
    fn sat_clamps_both_sides() {
        assert_eq!(5.0f64.sat(2.0), 2.0);
        assert_eq!((-5.0f64).sat(2.0), -2.0);
        assert_eq!(1.0f64.sat(2.0), 1.0);
    }
}
