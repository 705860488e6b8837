//! A small deterministic, seedable pseudo-random generator: see
//! [`CounterRng`].

use crate::Scalar;

/// A seeded counter-based generator.
///
/// A small deterministic, seedable pseudo-random generator.
///
/// Counter-based: the number drawn for `(stream, index)` is a hash of the
/// seed and that pair, so a draw does not depend on the order in which
/// streams are consumed. The bristle model uses one stream per bristle and
/// one index per re-bond: runs repeat exactly, whatever the step size.
///
/// [`CounterRng::bits`] is SplitMix64's finaliser (Steele, Lea & Flood
/// 2014) of seed and pair. [`CounterRng::unit`], what the bristle model
/// draws, uses 32-bit arithmetic only (a Cortex-M has no 64-bit multiply):
/// a Weyl sequence per stream, offset by a key formed from the seed when
/// the generator is made, mixed by MurmurHash3's 32-bit finaliser
/// (Appleby): 32-bit products, where SplitMix64's 64-bit ones take several
/// each on a Cortex-M (and a library call on a Cortex-M0).
///
/// ```
/// use friction_core::CounterRng;
/// let rng = CounterRng::new(42);
/// let a: f64 = rng.unit(3, 7);
/// assert!(a > 0.0 && a < 1.0);
/// assert_eq!(a, CounterRng::new(42).unit::<f64>(3, 7)); // repeatable
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CounterRng {
    seed: u64,
    /// 32 bits of the seed's SplitMix64 hash, for [`CounterRng::bits32`].
    key: u32,
}

/// SplitMix64's finaliser (Steele, Lea & Flood 2014).
const fn splitmix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

impl CounterRng {
    /// A generator with the given seed.
    pub const fn new(seed: u64) -> Self {
        Self {
            seed,
            key: (splitmix64(seed) >> 32) as u32,
        }
    }

    /// 64 well-mixed bits for `(stream, index)`.
    pub fn bits(&self, stream: u32, index: u32) -> u64 {
        let key = (u64::from(stream) << 32) | u64::from(index);
        splitmix64(
            self.seed
                .wrapping_add(key.wrapping_add(1).wrapping_mul(0x9E37_79B9_7F4A_7C15)),
        )
    }

    /// 32 well-mixed bits for `(stream, index)`, in 32-bit arithmetic: the
    /// stream's Weyl sequence `key + C_s stream + C_i (index + 1)` through
    /// MurmurHash3's finaliser.
    #[inline]
    pub fn bits32(&self, stream: u32, index: u32) -> u32 {
        let mut z = self
            .key
            .wrapping_add(stream.wrapping_mul(0x85EB_CA77))
            .wrapping_add(index.wrapping_add(1).wrapping_mul(0x9E37_79B9));
        z = (z ^ (z >> 16)).wrapping_mul(0x85EB_CA6B);
        z = (z ^ (z >> 13)).wrapping_mul(0xC2B2_AE35);
        z ^ (z >> 16)
    }

    /// A number in the open interval `(0, 1)`, from the 24 high bits of
    /// [`CounterRng::bits32`] (exact in `f32`).
    #[inline]
    pub fn unit<S: Scalar>(&self, stream: u32, index: u32) -> S {
        S::from_unit24(self.bits32(stream, index) >> 8)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scalar::sealed::Kernels;

    /// `from_unit24` gives the value of the exact `f64` formula rounded
    /// once, in `f32` as in `f64`.
    #[test]
    fn unit_is_the_rounded_exact_value() {
        let rng = CounterRng::new(3);
        for i in 0..20_000u32 {
            let m = rng.bits32(i % 8, i) >> 8;
            let exact = (f64::from(m) + 0.5) / 16_777_216.0;
            assert_eq!(rng.unit::<f64>(i % 8, i), exact);
            assert_eq!(rng.unit::<f32>(i % 8, i), exact as f32);
        }
        for m in [0, 1, 0xFF_FFFE, 0xFF_FFFF] {
            let exact = (f64::from(m) + 0.5) / 16_777_216.0;
            assert_eq!(f32::from_unit24(m), exact as f32);
        }
    }

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
        assert_ne!(a.bits32(0, 0), b.bits32(0, 0));
        assert_ne!(a.bits32(0, 1), a.bits32(1, 0));
    }

    /// Successive draws of one stream, and the same draw of neighbouring
    /// streams and seeds, are uncorrelated (|r| < 0.01 over 1e5 pairs,
    /// whose standard error is 0.003).
    #[test]
    fn neighbours_are_uncorrelated() {
        let corr = |pairs: &mut dyn Iterator<Item = (f64, f64)>| {
            let (mut n, mut sx, mut sy, mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
            for (x, y) in pairs {
                n += 1.0;
                (sx, sy) = (sx + x, sy + y);
                (sxy, sxx, syy) = (sxy + x * y, sxx + x * x, syy + y * y);
            }
            (sxy / n - sx * sy / n / n)
                / ((sxx / n - (sx / n).powi(2)) * (syy / n - (sy / n).powi(2))).sqrt()
        };
        let (a, b) = (CounterRng::new(1), CounterRng::new(2));
        let u = |r: &CounterRng, s: u32, i: u32| r.unit::<f64>(s, i);
        let along = corr(&mut (0..100_000u32).map(|i| (u(&a, 3, i), u(&a, 3, i + 1))));
        let across =
            corr(&mut (0..100_000u32).map(|i| (u(&a, i % 64, i / 64), u(&a, i % 64 + 1, i / 64))));
        let seeds =
            corr(&mut (0..100_000u32).map(|i| (u(&a, i % 64, i / 64), u(&b, i % 64, i / 64))));
        for r in [along, across, seeds] {
            assert!(r.abs() < 0.01, "{along} {across} {seeds}");
        }
    }
}
