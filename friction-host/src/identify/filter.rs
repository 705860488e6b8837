//! Signal conditioning for inverse-dynamics identification: a Butterworth
//! low-pass filter applied forward and backward (zero phase), central
//! differences, and decimation.
//!
//! The filter is designed here by the bilinear transform with frequency
//! pre-warping, as a cascade of second-order sections (plus one first-order
//! section for odd orders). Each section `k` of the analog prototype is
//! `1 / (s^2 + b_k s + 1)` with `b_k = 2 sin((2k - 1) pi / (2n))`; with
//! `K = tan(pi fc / fs)` its digital form is
//!
//! ```text
//! H(z) = K^2 (1 + z^-1)^2 / ((1 + b K + K^2) + 2 (K^2 - 1) z^-1 + (1 - b K + K^2) z^-2)
//! ```
//!
//! This is the filter of `scipy.signal.butter(n, fc, fs=fs, output="sos")`
//! and of MATLAB's `butter`. [`Butterworth::filtfilt`] runs it forward, then
//! backward over the reversed output, so the phase cancels and the magnitude
//! response is squared (-6 dB at `fc`). The ends are padded by odd
//! reflection about the first and last samples, and each section starts in
//! the steady state of the first padded sample, so a signal that starts
//! with an offset (a position, for instance) shows no start-up transient.

/// One second-order section `(b0, b1, b2, a1, a2)` with `a0 = 1`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Section {
    b: [f64; 3],
    a: [f64; 2],
}

/// A Butterworth low-pass filter as second-order sections.
#[derive(Clone, Debug, PartialEq)]
pub struct Butterworth {
    sections: Vec<Section>,
    order: usize,
    settle: usize,
}

impl Butterworth {
    /// Designs an order-`order` low-pass with cut-off `fc` (Hz) at sample
    /// rate `fs` (Hz). Needs `0 < fc < fs / 2` and `order >= 1`.
    pub fn lowpass(order: usize, fc: f64, fs: f64) -> Result<Self, String> {
        if order == 0 {
            return Err("the filter order must be at least 1".into());
        }
        if !(fc > 0.0 && fc < 0.5 * fs && fc.is_finite() && fs.is_finite()) {
            return Err(format!(
                "the cut-off {fc} Hz must lie between 0 and the Nyquist frequency {} Hz",
                0.5 * fs
            ));
        }
        let k = (std::f64::consts::PI * fc / fs).tan();
        let k2 = k * k;
        let n = order as f64;
        let mut sections = Vec::new();
        for i in 1..=order / 2 {
            let b = 2.0 * ((2.0 * i as f64 - 1.0) * std::f64::consts::PI / (2.0 * n)).sin();
            let a0 = 1.0 + b * k + k2;
            sections.push(Section {
                b: [k2 / a0, 2.0 * k2 / a0, k2 / a0],
                a: [2.0 * (k2 - 1.0) / a0, (1.0 - b * k + k2) / a0],
            });
        }
        if order % 2 == 1 {
            // first order: K (1 + z^-1) / ((1 + K) + (K - 1) z^-1)
            let a0 = 1.0 + k;
            sections.push(Section {
                b: [k / a0, k / a0, 0.0],
                a: [(k - 1.0) / a0, 0.0],
            });
        }
        Ok(Self {
            sections,
            order,
            settle: (3.0 * fs / fc).ceil() as usize,
        })
    }

    /// The sections `(b0, b1, b2, a1, a2)`.
    pub fn sections(&self) -> Vec<[f64; 5]> {
        self.sections
            .iter()
            .map(|s| [s.b[0], s.b[1], s.b[2], s.a[0], s.a[1]])
            .collect()
    }

    /// The magnitude of the (one-pass) frequency response at `f` Hz for
    /// sample rate `fs`.
    pub fn gain(&self, f: f64, fs: f64) -> f64 {
        let w = 2.0 * std::f64::consts::PI * f / fs;
        let (c1, s1, c2, s2) = (w.cos(), -w.sin(), (2.0 * w).cos(), -(2.0 * w).sin());
        self.sections
            .iter()
            .map(|s| {
                let num = (
                    s.b[0] + s.b[1] * c1 + s.b[2] * c2,
                    s.b[1] * s1 + s.b[2] * s2,
                );
                let den = (1.0 + s.a[0] * c1 + s.a[1] * c2, s.a[0] * s1 + s.a[1] * s2);
                (num.0.hypot(num.1)) / (den.0.hypot(den.1))
            })
            .product()
    }

    /// Filters `x` once, forward, each section starting in the steady
    /// state of `x[0]` (the filter has unit gain at DC).
    pub fn filter(&self, x: &mut [f64]) {
        let Some(&x0) = x.first() else { return };
        let mut level = x0;
        for s in &self.sections {
            // transposed direct form II
            let mut z2 = (s.b[2] - s.a[1]) * level;
            let mut z1 = (s.b[1] - s.a[0]) * level + z2;
            for xi in x.iter_mut() {
                let u = *xi;
                let y = s.b[0] * u + z1;
                z1 = s.b[1] * u - s.a[0] * y + z2;
                z2 = s.b[2] * u - s.a[1] * y;
                *xi = y;
            }
            level = x0;
        }
    }

    /// Samples the impulse response needs to settle: three periods of
    /// the cut-off frequency.
    pub fn settle(&self) -> usize {
        self.settle
    }

    /// The number of samples of odd-reflection padding at each end:
    /// [`Butterworth::settle`], at most `n - 1`.
    pub fn pad_len(&self, n: usize) -> usize {
        self.settle.max(3 * self.order).min(n.saturating_sub(1))
    }

    /// Zero-phase filtering: forward, then backward (see the module notes).
    pub fn filtfilt(&self, x: &[f64]) -> Vec<f64> {
        let n = x.len();
        if n == 0 {
            return Vec::new();
        }
        let pad = self.pad_len(n);
        let mut y = Vec::with_capacity(n + 2 * pad);
        y.extend((1..=pad).rev().map(|i| 2.0 * x[0] - x[i]));
        y.extend_from_slice(x);
        y.extend((1..=pad).map(|i| 2.0 * x[n - 1] - x[n - 1 - i]));
        self.filter(&mut y);
        y.reverse();
        self.filter(&mut y);
        y.reverse();
        y[pad..pad + n].to_vec()
    }
}

/// Central differences: the first derivative `(x[k+1] - x[k-1]) / (2h)` and
/// the second `(x[k+1] - 2 x[k] + x[k-1]) / h^2`, for `k = 1 .. n-2`
/// (the end samples repeat their neighbour's value).
pub fn central_differences(x: &[f64], h: f64) -> (Vec<f64>, Vec<f64>) {
    let n = x.len();
    let mut d1 = vec![0.0; n];
    let mut d2 = vec![0.0; n];
    if n < 3 {
        return (d1, d2);
    }
    for k in 1..n - 1 {
        d1[k] = (x[k + 1] - x[k - 1]) / (2.0 * h);
        d2[k] = (x[k + 1] - 2.0 * x[k] + x[k - 1]) / (h * h);
    }
    d1[0] = d1[1];
    d2[0] = d2[1];
    d1[n - 1] = d1[n - 2];
    d2[n - 1] = d2[n - 2];
    (d1, d2)
}

/// Every `factor`-th sample starting at `start`.
pub fn downsample(x: &[f64], start: usize, factor: usize) -> Vec<f64> {
    x.iter()
        .skip(start)
        .step_by(factor.max(1))
        .copied()
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coefficients_match_the_textbook_design() {
        // scipy.signal.butter(2, 100, fs=1000) -> b = [0.0674553, 0.1349105, 0.0674553],
        // a = [1, -1.1429805, 0.4128016]
        let f = Butterworth::lowpass(2, 100.0, 1000.0).unwrap();
        let s = f.sections()[0];
        let want = [
            0.067_455_27,
            0.134_910_55,
            0.067_455_27,
            -1.142_980_5,
            0.412_801_6,
        ];
        for (a, b) in s.iter().zip(want) {
            assert!((a - b).abs() < 1e-7, "{s:?}");
        }
    }

    #[test]
    fn butterworth_response() {
        for order in 1..=5 {
            let f = Butterworth::lowpass(order, 100.0, 1000.0).unwrap();
            assert!((f.gain(0.0, 1000.0) - 1.0).abs() < 1e-12);
            // -3 dB at the cut-off, |H|^2 = 1 / (1 + (w/wc)^(2n)) in pre-warped frequency
            assert!(
                (f.gain(100.0, 1000.0) - 0.5f64.sqrt()).abs() < 1e-9,
                "{order}"
            );
            assert!(f.gain(400.0, 1000.0) < f.gain(200.0, 1000.0));
        }
        assert!(Butterworth::lowpass(4, 600.0, 1000.0).is_err());
        assert!(Butterworth::lowpass(0, 10.0, 1000.0).is_err());
    }

    #[test]
    fn filtfilt_has_zero_phase_and_keeps_offsets_and_ramps() {
        let fs = 1000.0;
        let f = Butterworth::lowpass(4, 100.0, fs).unwrap();
        let x: Vec<f64> = (0..2000)
            .map(|k| 3.0 + (2.0 * std::f64::consts::PI * 5.0 * k as f64 / fs).sin())
            .collect();
        let y = f.filtfilt(&x);
        // a 5 Hz sine passes with neither delay nor loss, ends included
        let err = x
            .iter()
            .zip(&y)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(err < 2e-3, "{err}");
        // a ramp passes unchanged (odd reflection at the ends)
        let r: Vec<f64> = (0..500).map(|k| 0.1 + 2e-3 * k as f64).collect();
        let y = f.filtfilt(&r);
        let err = r
            .iter()
            .zip(&y)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        // the sections start in the steady state of a constant, so a ramp
        // leaves a start-up transient that decays inside the padding: what
        // is left is about 1e-3 of one sample's step (2e-3)
        assert!(err < 1e-5, "{err}");
        // 300 Hz is removed
        let z: Vec<f64> = (0..2000)
            .map(|k| (2.0 * std::f64::consts::PI * 300.0 * k as f64 / fs).sin())
            .collect();
        let y = f.filtfilt(&z);
        let rms = (y[200..1800].iter().map(|v| v * v).sum::<f64>() / 1600.0).sqrt();
        assert!(rms < 1e-3, "{rms}");
    }

    #[test]
    fn differences_of_a_parabola_are_exact() {
        let h = 1e-3;
        let x: Vec<f64> = (0..10)
            .map(|k| 0.5 * 4.0 * (k as f64 * h).powi(2))
            .collect();
        let (v, a) = central_differences(&x, h);
        for k in 1..9 {
            assert!((v[k] - 4.0 * k as f64 * h).abs() < 1e-12);
            assert!((a[k] - 4.0).abs() < 1e-6);
        }
        assert_eq!(downsample(&[0.0, 1.0, 2.0, 3.0, 4.0], 1, 2), vec![1.0, 3.0]);
    }
}
