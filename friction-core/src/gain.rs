//! A constant gain that fixed point can carry at full precision.
//!
//! Q16.16 holds `k` to within 0.1 % only from about 0.015 to 32767: a loop
//! at 1 kHz has `h = 1e-3` (65.5 units of the last place, 0.7 % off), a
//! servo motor's `J / kc` is 1e-3 or less, and at 40 kHz `1 / h = 40000`
//! does not fit at all. [`Gain`] carries `k = m 2^-p` with a mantissa `m`
//! the scalar holds precisely and applies it as `k x = (m x) 2^-p`, the
//! power of two chosen when built. For floating point `m = k`, `p = 0`, and
//! applying it is one multiplication.
//!
//! For a small gain the mantissa is below 1, so `m x` cannot saturate for
//! any representable `x`; for a large one (`k >= 32768`, mantissa at most
//! 16384) `m x` and its scaling saturate towards the sign of `k x`, which
//! every caller clamps anyway.

use crate::model::{convert, ParamError};
use crate::Scalar;

/// `k = m 2^-p`, applied as `(m x) 2^-p` (see the [module documentation](self)).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(crate) struct Gain<S> {
    mantissa: S,
    /// `-p`, applied only where the scalar scales (fixed point), as a shift.
    exp: i8,
}

impl<S: Scalar> Gain<S> {
    /// `k` as a gain of scalar `S`; `name` is the parameter reported when
    /// `k` cannot be carried within the scalar's precision even scaled
    /// (below about `2.3e-7` or above `2.7e8` in Q16.16).
    pub(crate) fn new(name: &'static str, k: f64) -> Result<Self, ParamError> {
        let exact = Self {
            mantissa: S::ZERO,
            exp: 0,
        };
        if k == 0.0 {
            return Ok(exact);
        }
        if !S::SCALES_FORCES {
            return Ok(Self {
                mantissa: convert(name, k)?,
                ..exact
            });
        }
        if let Ok(mantissa) = convert::<S>(name, k) {
            return Ok(Self { mantissa, ..exact });
        }
        // the power of two that brings |k| into [0.5, 1) for a small gain,
        // or below 16384 for a large one; 2^-16 and 2^14 are both exact
        let exponent = libm::ceil(libm::log2(k.abs()));
        let p = if exponent <= 0.0 {
            (-exponent).min(16.0)
        } else {
            -(exponent - 14.0).clamp(0.0, 14.0)
        };
        Ok(Self {
            mantissa: convert(name, k * libm::exp2(p))?,
            // p is a whole number in -14..=16
            exp: -(p as i8),
        })
    }

    /// `k x`.
    #[inline]
    pub(crate) fn times(self, x: S) -> S {
        let p = self.mantissa * x;
        // most gains need no scaling: skip the shift
        if S::SCALES_FORCES && self.exp != 0 {
            p.rescale_pow2(self.exp)
        } else {
            p
        }
    }

    /// Whether `k = 0`.
    #[inline]
    pub(crate) fn is_zero(self) -> bool {
        self.mantissa == S::ZERO
    }

    /// `k` (rounded to `f64`, for reporting).
    #[cfg(all(test, feature = "fixed"))]
    pub(crate) fn to_f64(self) -> f64 {
        self.mantissa.to_f64() * libm::exp2(f64::from(self.exp))
    }
}

#[cfg(all(test, feature = "fixed"))]
mod tests {
    use super::*;
    use crate::Fixed32;

    #[test]
    fn fixed_point_carries_gains_that_do_not_fit_plainly() {
        for k in [
            1e-3,
            2.5e-5,
            0.0023 / 1.02,
            2.3e-6,
            1.0,
            0.3,
            1000.0,
            40000.0,
            3.6e6,
            2.0e8,
        ] {
            let g = Gain::<Fixed32>::new("k", k).unwrap();
            let rel = (g.to_f64() - k).abs() / k;
            assert!(rel < 1e-3, "{k}: {} ({rel:e})", g.to_f64());
            // and applied to a representable input
            let x = 0.01;
            let want = k * x;
            let got = g.times(Fixed32::from_f64(x)).to_f64();
            if want.abs() < 30000.0 {
                assert!(
                    (got - want).abs() <= 1e-3 * want.abs() + 2.0 / 65536.0,
                    "{k} x {x}: {got} vs {want}"
                );
            } else {
                assert_eq!(got, Fixed32::MAX.to_f64(), "{k} x {x} saturates");
            }
        }
        // negative inputs keep their sign when the product saturates
        let g = Gain::<Fixed32>::new("k", 40000.0).unwrap();
        assert!(g.times(Fixed32::from_f64(-2.0)).to_f64() < -32000.0);
        assert_eq!(
            Gain::<Fixed32>::new("k", 1e-9).err(),
            Some(ParamError::Underflow("k"))
        );
        assert_eq!(
            Gain::<Fixed32>::new("k", 1e12).err(),
            Some(ParamError::NotRepresentable("k"))
        );
    }

    #[test]
    fn floats_carry_the_gain_as_it_is() {
        let g = Gain::<f32>::new("k", 2.5e-5).unwrap();
        assert_eq!(g.times(2.0), 2.5e-5f32 * 2.0);
        assert!(Gain::<f64>::new("k", 0.0).unwrap().is_zero());
    }
}
