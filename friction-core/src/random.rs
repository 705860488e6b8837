//! A small deterministic, seedable pseudo-random generator.
//!
//! Counter-based: the number drawn for `(stream, index)` is a hash of the
//! seed and that pair (SplitMix64's finaliser, Steele, Lea & Flood 2014), so
//! a draw does not depend on the order in which streams are consumed. The
//! bristle model uses one stream per bristle and one index per re-bond:
//! runs repeat exactly, whatever the step size.

use crate::Scalar;

/// A seeded counter-based generator.
///
/// ```
/// use friction_core::random::CounterRng;
/// let rng = CounterRng::new(42);
/// let a: f64 = rng.unit(3, 7);
/// assert!(a > 0.0 && a < 1.0);
/// assert_eq!(a, CounterRng::new(42).unit::<f64>(3, 7)); // repeatable
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CounterRng {
    seed: u64,
}

impl CounterRng {
    /// A generator with the given seed.
    pub const fn new(seed: u64) -> Self {
        Self { seed }
    }

    /// 64 well-mixed bits for `(stream, index)`.
    pub fn bits(&self, stream: u32, index: u32) -> u64 {
        let key = (u64::from(stream) << 32) | u64::from(index);
        let mut z = self
            .seed
            .wrapping_add(key.wrapping_add(1).wrapping_mul(0x9E37_79B9_7F4A_7C15));
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// A number in the open interval `(0, 1)`, from 24 bits (exact in `f32`).
    pub fn unit<S: Scalar>(&self, stream: u32, index: u32) -> S {
        let m = (self.bits(stream, index) >> 40) as u32; // 24 bits
        S::from_f64((f64::from(m) + 0.5) / 16_777_216.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_enough() {
        let rng = CounterRng::new(1);
        let n = 100_000;
        let (mut sum, mut sum2) = (0.0, 0.0);
        let mut bins = [0u32; 10];
        for i in 0..n {
            let u: f64 = rng.unit(i % 64, i / 64);
            assert!(u > 0.0 && u < 1.0);
            sum += u;
            sum2 += u * u;
            bins[(u * 10.0) as usize] += 1;
        }
        let mean = sum / n as f64;
        let var = sum2 / n as f64 - mean * mean;
        assert!((mean - 0.5).abs() < 0.005, "{mean}");
        assert!((var - 1.0 / 12.0).abs() < 0.002, "{var}");
        for b in bins {
            assert!((b as f64 - 10_000.0).abs() < 500.0, "{bins:?}");
        }
    }

    #[test]
    fn streams_and_seeds_differ() {
        let (a, b) = (CounterRng::new(1), CounterRng::new(2));
        assert_ne!(a.bits(0, 0), b.bits(0, 0));
        assert_ne!(a.bits(0, 1), a.bits(1, 0));
    }
}
