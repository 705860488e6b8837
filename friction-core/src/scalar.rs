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
    ($t:ty, $abs:path, $exp:path, $expm1:path, $pow:path, $sqrt:path, $sin:path, $cos:path) => {
        impl Scalar for $t {
            const ZERO: Self = 0.0;
            const ONE: Self = 1.0;
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
    libm::pow,
    libm::sqrt,
    libm::sin,
    libm::cos
);

/// Exact solution over a step `h` of the linear relaxation `dz/dt = u - a z`
/// with `u` and `a >= 0` held: `z(h) = u/a + (z - u/a) e^(-a h)`, written as
/// `z + (u - a z) (1 - e^(-a h)) / a` while `a h <= 1` so that it stays exact
/// as `a -> 0` (where it tends to `z + u h`). Unconditionally stable: the
/// result lies between `z` and the equilibrium `u/a`.
#[inline]
pub(crate) fn relax<S: Scalar>(z: S, u: S, a: S, h: S) -> S {
    let x = a * h;
    if x > S::ONE {
        let z_eq = u / a;
        z_eq + (z - z_eq) * (-x).exp()
    } else if x > S::ZERO {
        z + (u - a * z) * (-(-x).exp_m1() / a)
    } else {
        z + u * h
    }
}

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
    fn relax_matches_closed_form() {
        let exact = |z: f64, u: f64, a: f64, h: f64| u / a + (z - u / a) * (-a * h).exp();
        for &(z, u, a, h) in &[
            (1.0, 2.0, 3.0, 0.1),
            (-1e-5, 1e-3, 66.0, 1e-3),
            (0.5, -1.0, 1e4, 1e-3),
            (1e-5, 0.37, 3.7e4, 1e-4),
        ] {
            let r = relax(z, u, a, h);
            let e = exact(z, u, a, h);
            assert!((r - e).abs() <= 1e-12 * (e.abs() + z.abs()), "{r} vs {e}");
        }
        // a = 0: plain integration
        assert_eq!(relax(1.0f64, 2.0, 0.0, 0.5), 2.0);
        // a h tiny: no cancellation, tends to z + (u - a z) h
        let r = relax(0.0f64, 1.0, 1e-12, 1e-3);
        assert!((r - 1e-3).abs() < 1e-15);
        // a infinite: lands on the equilibrium u/a = 0
        assert_eq!(relax(1.0f64, 1.0, f64::INFINITY, 1e-3), 0.0);
        // f32 keeps the small-argument accuracy
        let r = relax(0.0f32, 1.0, 1e-3, 1e-4);
        assert!((r - 1e-4).abs() / 1e-4 < 1e-6);
    }

    #[test]
    fn sat_clamps_both_sides() {
        assert_eq!(5.0f64.sat(2.0), 2.0);
        assert_eq!((-5.0f64).sat(2.0), -2.0);
        assert_eq!(1.0f64.sat(2.0), 1.0);
    }
}
