//! Q16.16 fixed point for cores without an FPU (feature `fixed`): see
//! [`Fixed32`].

mod division;
mod functions;
mod kernels;
#[cfg(test)]
mod tests;

use crate::scalar::sealed::Kernels;
use crate::scalar::ScalarConversion;
use crate::Scalar;
use core::ops::{Add, Mul, Neg, Sub};
use division::{pow2_over, pow2_quotient};
use fixed::types::I16F16;
use functions::{exp_neg_bits, exp_neg_square_bits, zone_curve_bits};
use kernels::{fraction_product, saturated_product, wrapping_product};

/// A Q16.16 number with saturating arithmetic.
///
/// Q16.16 fixed point for cores without an FPU (feature `fixed`).
///
/// [`Fixed32`] wraps the `fixed` crate's `I16F16`: 16 integer and 16
/// fraction bits, so values from -32768 to 32767.99998 in steps of
/// `2^-16 = 1.53e-5`. Every operation saturates: no overflow panic in a
/// debug build, no wrap-around in release, and a division by zero gives the
/// largest value of the dividend's sign (0 / 0 gives 0).
///
/// # What runs on it, and where it is valid
///
/// The fixed-step forms ([`FixedStepModel`](crate::FixedStepModel)) are written for it: their
/// states are forces, and `h` enters only through products such as
/// `sigma0 h` formed in `f64` at build time. A deflection of micrometres or
/// a stiffness of 1e5 N/m does not fit, so the variable-step forms (state in
/// metres) are refused at `build()` with a typed error for any realistic
/// parameter set.
///
/// A configuration is valid, and checked at `build_fixed_step()`, for:
/// - velocities `|v| <= 4` (m/s or rad/s; larger inputs are clamped to 4),
///   resolved to 1.5e-5;
/// - force terms up to a quarter of the range (8192) at that velocity
///   ([`ParamError::ForceOverflow`](crate::ParamError::ForceOverflow)
///   otherwise), each parameter and product formed at build time within the
///   range and 0.1 % of its design value
///   ([`ParamError::Underflow`](crate::ParamError::Underflow) otherwise);
/// - any `h` for which those products fit.
///
/// Inside, a fixed-step form carries its forces multiplied by a power of
/// two (the force scale) chosen at build time to use the range: a
/// servo's 0.3 N m friction is carried as about 300 with 1.5e-5 steps, so
/// that the small per-step increments of a 10 kHz loop are not rounded
/// away (unscaled, they stall a slow relaxation short of its equilibrium by
/// up to 20 % of `Fs`).
///
/// Accuracy against the `f64` reference is measured by `friction validate`
/// (`--scalar fixed` rows) and stated in the README.
///
/// # Functions
///
/// [`Scalar::exp_neg`], the only transcendental function of the fixed-step
/// forms, is computed in integer arithmetic (range reduction by `ln 2` and a
/// degree-6 polynomial, no floating point). `exp`, `exp_m1`, `ln_1p` and
/// `powf`, which only the variable-step forms and a Stribeck exponent other
/// than 1 or 2 use, go through `f32` (software floating point on an M0).
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
/// product, so the kernels ([`kernels`], [`division`]) take their ARMv6-M
/// forms there. One
/// constant instead of a `cfg` at every use: both forms compile on every
/// target (the ARMv6-M kernels are tested on the host), and the compiler
/// drops the branch not taken.
const ARMV6M: bool = cfg!(all(target_arch = "arm", not(target_has_atomic = "32")));

impl Neg for Fixed32 {
    type Output = Self;
    #[inline]
    fn neg(self) -> Self {
        Self(self.0.saturating_neg())
    }
}

impl Kernels for Fixed32 {
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
    fn half(self) -> Self {
        // (x 2^15 + 2^15) >> 16, the product with 0.5, without overflow
        let bits = self.to_bits();
        Self::from_bits((bits >> 1) + (bits & 1))
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

    /// `2^s` with `4 max_force 2^s <= 32768`, `s` in -14..=14.
    fn force_scale(max_force: f64) -> f64 {
        if !(max_force.is_finite() && max_force > 0.0) {
            return 1.0;
        }
        libm::exp2(libm::floor(libm::log2(8192.0 / max_force)).clamp(-14.0, 14.0))
    }
}

impl Scalar for Fixed32 {
    const ZERO: Self = Self(I16F16::ZERO);
    const ONE: Self = Self(I16F16::ONE);
    const MIN_POSITIVE: Self = Self(I16F16::DELTA);
    const VELOCITY_LIMIT: Self = Self::from_bits(4 << 16);

    /// Rounds to nearest, saturating; NaN gives 0.
    fn from_f64(x: f64) -> Self {
        if x.is_nan() {
            Self::ZERO
        } else {
            Self(I16F16::saturating_from_num(x))
        }
    }

    /// Overflow beyond the range, underflow to 0, or rounding beyond 0.1 %.
    fn try_from_f64(x: f64) -> Result<Self, ScalarConversion> {
        if !(-32768.0..32768.0).contains(&x) {
            return Err(ScalarConversion::Overflow);
        }
        let s = Self::from_f64(x);
        if x != 0.0 && s == Self::ZERO {
            Err(ScalarConversion::Underflow)
        } else if (s.to_f64() - x).abs() > 1e-3 * x.abs() {
            Err(ScalarConversion::Rounding)
        } else {
            Ok(s)
        }
    }

    fn to_f64(self) -> f64 {
        self.0.to_num::<f64>()
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
