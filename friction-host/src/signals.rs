//! Velocity signals with their exact displacement, for driving models.

use std::f64::consts::PI;

/// A velocity signal `v(t)` and its integral `x(t)` (with `x(0) = 0`).
pub struct Signal {
    /// Short name (report rows, file names).
    pub name: String,
    /// What it exercises.
    pub description: String,
    /// Duration (s).
    pub duration: f64,
    v: Box<dyn Fn(f64) -> f64>,
    x: Box<dyn Fn(f64) -> f64>,
}

impl Signal {
    /// `v(t)`.
    pub fn v(&self, t: f64) -> f64 {
        (self.v)(t)
    }
    /// `x(t)`.
    pub fn x(&self, t: f64) -> f64 {
        (self.x)(t)
    }

    /// `v = amplitude sin(2 pi f t)`: crosses zero velocity twice a period.
    pub fn sine(amplitude: f64, frequency: f64, periods: f64) -> Self {
        let w = 2.0 * PI * frequency;
        Self {
            name: format!("sine {amplitude} m/s {frequency} Hz"),
            description: "crosses zero velocity: pre-sliding and reversals".into(),
            duration: periods / frequency,
            v: Box::new(move |t| amplitude * (w * t).sin()),
            x: Box::new(move |t| amplitude * (1.0 - (w * t).cos()) / w),
        }
    }

    /// `v = v0 (cos(w t) + 1.5)` (the frictional-lag signal of Canudas de Wit et al. 1995).
    pub fn lag(v0: f64, w: f64, periods: f64) -> Self {
        Self {
            name: format!("lag v0 {v0} m/s w {w} rad/s"),
            description: "unidirectional, varying speed: frictional lag".into(),
            duration: periods * 2.0 * PI / w,
            v: Box::new(move |t| v0 * ((w * t).cos() + 1.5)),
            x: Box::new(move |t| v0 * ((w * t).sin() / w + 1.5 * t)),
        }
    }

    /// `v = a1 sin(2 pi f1 t) + a2 sin(2 pi f2 t)`: fast reversals of varying
    /// depth, some at high speed, some barely crossing zero.
    pub fn two_tone(a1: f64, f1: f64, a2: f64, f2: f64, duration: f64) -> Self {
        let (w1, w2) = (2.0 * PI * f1, 2.0 * PI * f2);
        Self {
            name: format!("two-tone {a1}@{f1} + {a2}@{f2} Hz"),
            description: "fast reversals of varying depth".into(),
            duration,
            v: Box::new(move |t| a1 * (w1 * t).sin() + a2 * (w2 * t).sin()),
            x: Box::new(move |t| {
                a1 * (1.0 - (w1 * t).cos()) / w1 + a2 * (1.0 - (w2 * t).cos()) / w2
            }),
        }
    }

    /// Sample times `0, h, 2h, ...` up to the duration.
    pub fn times(&self, h: f64) -> Vec<f64> {
        let n = (self.duration / h).round() as usize;
        (0..=n).map(|k| k as f64 * h).collect()
    }

    /// The velocities a controller measures over each sample period: the mean
    /// velocity `(x(t_k) - x(t_{k-1})) / h` (an encoder difference); row 0 is `v(0)`.
    pub fn mean_velocities(&self, t: &[f64]) -> Vec<f64> {
        let mut out = Vec::with_capacity(t.len());
        for (k, &tk) in t.iter().enumerate() {
            if k == 0 {
                out.push(self.v(tk));
            } else {
                let h = tk - t[k - 1];
                out.push((self.x(tk) - self.x(t[k - 1])) / h);
            }
        }
        out
    }
}

/// The validation signals: zero crossings slow and fast, frictional lag slow and fast.
pub fn validation_signals() -> Vec<Signal> {
    vec![
        Signal::sine(5e-3, 0.5, 2.0),
        Signal::sine(2e-2, 5.0, 5.0),
        Signal::lag(1e-3, 1.0, 2.0),
        Signal::lag(1e-3, 25.0, 5.0),
    ]
}

/// Signals crossing zero velocity, slow and fast: the two validation sines
/// and a two-tone signal reaching 0.07 m/s (0.05 m/s at 2 Hz + 0.02 m/s at
/// 13 Hz, 1 s), where a model's transition from sticking to sliding is passed
/// in a fraction of a 1 kHz sample.
pub fn reversal_signals() -> Vec<Signal> {
    vec![
        Signal::sine(5e-3, 0.5, 2.0),
        Signal::sine(2e-2, 5.0, 5.0),
        Signal::two_tone(5e-2, 2.0, 2e-2, 13.0, 1.0),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn displacement_is_the_integral() {
        for s in validation_signals().into_iter().chain(reversal_signals()) {
            let t = s.times(1e-4);
            let mut x = 0.0;
            for k in 1..t.len() {
                let tm = 0.5 * (t[k] + t[k - 1]);
                x += s.v(tm) * 1e-4; // midpoint rule
            }
            assert!((x - s.x(*t.last().unwrap())).abs() < 1e-8, "{}", s.name);
        }
    }
}
