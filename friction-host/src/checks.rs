//! One validation layer for every front end: the `friction` command line
//! and the Python package call these checks, so an option's range, a
//! signal's rules (finite, time strictly increasing, equal lengths) and the
//! adaptation bounds are written once. The model and loop parameters are
//! the core's own typed checks ([`friction_core::ParamError`]), which both
//! front ends reach through the same builders.
//!
//! A check returns a typed refusal naming the argument; each front end
//! spells it its own way ([`Arg`]): `--filter-order 17` on the command
//! line, `order=17` in Python. A signal check returns what is wrong with a
//! sample ([`SampleError`]); the front end says where (a CSV file's line
//! and column, an array's index).

/// An argument as each front end spells it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Arg {
    /// On the command line: an option (`--filter-order`).
    pub cli: &'static str,
    /// The Python keyword argument (`order`).
    pub python: &'static str,
}

/// The arguments the front ends share, with their spellings.
pub mod args {
    use super::Arg;
    /// The identification filter's cut-off (Hz).
    pub const CUTOFF: Arg = Arg {
        cli: "--cutoff",
        python: "cutoff",
    };
    /// The identification filter's order.
    pub const FILTER_ORDER: Arg = Arg {
        cli: "--filter-order",
        python: "order",
    };
    /// The identification's decimation factor.
    pub const DECIMATE: Arg = Arg {
        cli: "--decimate",
        python: "decimate",
    };
    /// The Stribeck exponent held during a fit.
    pub const STRIBECK_EXPONENT: Arg = Arg {
        cli: "--stribeck-exponent",
        python: "stribeck_exponent",
    };
    /// The factor from the force column to force.
    pub const FORCE_GAIN: Arg = Arg {
        cli: "--force-gain",
        python: "force_gain",
    };
    /// An experiment's sample period (command line only).
    pub const DT: Arg = Arg {
        cli: "--dt",
        python: "dt",
    };
    /// An experiment's duration (command line only).
    pub const DURATION: Arg = Arg {
        cli: "--duration",
        python: "duration",
    };
    /// `online`: the mass of the drive's loop (command line only).
    pub const MASS: Arg = Arg {
        cli: "--mass",
        python: "mass",
    };
    /// `online`: the starting Coulomb level (command line only).
    pub const COULOMB: Arg = Arg {
        cli: "--coulomb",
        python: "coulomb",
    };
    /// `online`: the starting viscous coefficient (command line only).
    pub const VISCOUS: Arg = Arg {
        cli: "--viscous",
        python: "viscous",
    };
    /// `online`: the viscous regressors' speed scale (command line only).
    pub const SPEED: Arg = Arg {
        cli: "--speed",
        python: "speed",
    };
    /// `online`: the slowest sample learnt from (command line only).
    pub const MIN_SPEED: Arg = Arg {
        cli: "--min-speed",
        python: "min_speed",
    };
    /// `online`: the per-parameter estimator's rate (command line only).
    pub const RATE: Arg = Arg {
        cli: "--rate",
        python: "rate",
    };
    /// `online`: the least-squares forgetting factor (command line only).
    pub const FORGETTING: Arg = Arg {
        cli: "--forgetting",
        python: "forgetting",
    };
    /// `online`: the estimates' box factor (command line only).
    pub const BOX_FACTOR: Arg = Arg {
        cli: "--box-factor",
        python: "box_factor",
    };
}

/// The documented ranges of the numeric options (inclusive).
pub mod ranges {
    /// `experiment --dt` (s); the run must also take 100 to 5e6 samples.
    pub const DT: (f64, f64) = (1e-9, 10.0);
    /// `experiment --duration` (s).
    pub const DURATION: (f64, f64) = (1e-6, 1e7);
    /// The identification filter's cut-off (Hz); also below the Nyquist
    /// frequency.
    pub const CUTOFF: (f64, f64) = (1e-6, 1e9);
    /// The force gain, in magnitude (either sign).
    pub const FORCE_GAIN: (f64, f64) = (1e-12, 1e12);
    /// The Stribeck exponent of a fit.
    pub const STRIBECK_EXPONENT: (f64, f64) = (1.0, 100.0);
    /// The identification filter's order: beyond 16 the Butterworth
    /// sections' poles crowd the unit circle at low cut-offs.
    pub const FILTER_ORDER: (i64, i64) = (1, 16);
    /// A physical quantity that must be positive: a model parameter's range
    /// (`friction_core::PARAM_RANGE`).
    pub const POSITIVE: (f64, f64) = friction_core::PARAM_RANGE;
    /// A forgetting factor, `0 < f <= 1`.
    pub const FORGETTING: (f64, f64) = (f64::MIN_POSITIVE, 1.0);
    /// A box factor, at least 1.
    pub const BOX_FACTOR: (f64, f64) = (1.0, friction_core::PARAM_RANGE.1);
}

/// An argument refused: which, its value, and the rule it breaks (written
/// without any front end's spelling, so both can show it).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{} {}: {rule}", .arg.cli, num(*.value))]
pub struct Refusal {
    /// The argument.
    pub arg: Arg,
    /// Its value.
    pub value: f64,
    /// What it must be.
    pub rule: String,
}

impl Refusal {
    /// The message in Python's spelling: `order=17: must be ...`.
    pub fn python(&self) -> String {
        format!("{}={}: {}", self.arg.python, num(self.value), self.rule)
    }
}

/// `x` within `lo ..= hi`.
pub fn within(arg: Arg, x: f64, (lo, hi): (f64, f64)) -> Result<f64, Refusal> {
    if (lo..=hi).contains(&x) {
        Ok(x)
    } else {
        Err(Refusal {
            arg,
            value: x,
            rule: format!("must be within {} ..= {}", num(lo), num(hi)),
        })
    }
}

/// `|x|` within `lo ..= hi`, either sign.
pub fn magnitude_within(arg: Arg, x: f64, (lo, hi): (f64, f64)) -> Result<f64, Refusal> {
    if (lo..=hi).contains(&x.abs()) {
        Ok(x)
    } else {
        Err(Refusal {
            arg,
            value: x,
            rule: format!(
                "its magnitude must be within {} ..= {} (either sign)",
                num(lo),
                num(hi)
            ),
        })
    }
}

/// The identification filter's order, 1 to 16.
pub fn filter_order(order: i64) -> Result<usize, Refusal> {
    let (lo, hi) = ranges::FILTER_ORDER;
    if (lo..=hi).contains(&order) {
        Ok(order as usize)
    } else {
        Err(Refusal {
            arg: args::FILTER_ORDER,
            value: order as f64,
            rule: format!("must be a whole number from {lo} to {hi}"),
        })
    }
}

/// The decimation factor, at least 1.
pub fn decimate(d: i64) -> Result<usize, Refusal> {
    usize::try_from(d)
        .ok()
        .filter(|&d| d >= 1)
        .ok_or_else(|| Refusal {
            arg: args::DECIMATE,
            value: d as f64,
            rule: "must be a whole number, at least 1".into(),
        })
}

/// The identification filter's cut-off: within [`ranges::CUTOFF`] and
/// below the Nyquist frequency of the sample rate `fs` (Hz).
pub fn cutoff(c: f64, fs: f64) -> Result<f64, Refusal> {
    within(args::CUTOFF, c, ranges::CUTOFF)?;
    if c < 0.5 * fs {
        Ok(c)
    } else {
        Err(Refusal {
            arg: args::CUTOFF,
            value: c,
            rule: format!(
                "must be below the Nyquist frequency, {} Hz (half the sample rate)",
                short(0.5 * fs)
            ),
        })
    }
}

/// Why a controller's velocity low-pass cut-off (Hz) is refused at the
/// controller rate `rate` (Hz), if it is: `None` for a cut-off > 0 below
/// half the rate (the filter's discrete pole is meaningless beyond it).
/// A front end that reads 0 as "no filter" says so before calling this.
pub fn velocity_filter_rule(cutoff: f64, rate: f64) -> Option<&'static str> {
    if cutoff > 0.0 && cutoff < 0.5 * rate {
        None
    } else {
        Some("a cut-off (Hz) > 0 below half the controller rate")
    }
}

/// A bound of the θ-adaptive observer refused: the key (as in the `[servo]`
/// table and Python's `adaptive` dict), its value, the rule.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThetaRefusal {
    /// `theta0`, `theta_min` or `theta_max`.
    pub key: &'static str,
    /// Its value.
    pub value: f64,
    /// What it must be.
    pub rule: &'static str,
}

/// The adaptation's scale bounds: `theta_min <= theta0 <= theta_max` and
/// `theta_min < theta_max`, each finite (θ starts at `theta0`, 1 unless
/// given). The key blamed is the one that was given: `theta0` when
/// `theta0_given`, else the bound on the wrong side of it.
pub fn theta_bounds(
    theta_min: f64,
    theta_max: f64,
    theta0: f64,
    theta0_given: bool,
) -> Result<(), ThetaRefusal> {
    let refuse = |key, value, rule| Err(ThetaRefusal { key, value, rule });
    for (key, value) in [
        ("theta_min", theta_min),
        ("theta_max", theta_max),
        ("theta0", theta0),
    ] {
        if !(value.is_finite() && value >= 0.0) {
            return refuse(key, value, "a finite number >= 0");
        }
    }
    const WITHIN: &str = "within [`theta_min`, `theta_max`] (0.2 and 5 unless given)";
    if theta0 > theta_max {
        return if theta0_given {
            refuse("theta0", theta0, WITHIN)
        } else {
            refuse(
                "theta_max",
                theta_max,
                "at least 1 (the nominal model's scale, where θ starts)",
            )
        };
    }
    if theta0 < theta_min {
        return if theta0_given {
            refuse("theta0", theta0, WITHIN)
        } else {
            refuse(
                "theta_min",
                theta_min,
                "at most 1 (the nominal model's scale, where θ starts)",
            )
        };
    }
    if theta_min >= theta_max {
        return refuse("theta_min", theta_min, "below `theta_max`");
    }
    Ok(())
}

/// What is wrong with one sample of a signal; the front end says where.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SampleError {
    /// NaN or infinite.
    #[error("{} is not finite", num(*.0))]
    NotFinite(f64),
    /// A time at or before the previous one.
    #[error("time {} does not increase (previous {})", num(*.t), num(*.previous))]
    NotIncreasing {
        /// The time.
        t: f64,
        /// The previous time.
        previous: f64,
    },
}

/// A sample: finite.
pub fn finite(x: f64) -> Result<f64, SampleError> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(SampleError::NotFinite(x))
    }
}

/// A time after `previous` (if any): strictly increasing.
pub fn increasing(previous: Option<f64>, t: f64) -> Result<f64, SampleError> {
    match previous {
        Some(p) if t <= p => Err(SampleError::NotIncreasing { t, previous: p }),
        _ => Ok(t),
    }
}

/// A sampled signal refused: which (as the front end names it), the
/// sample's index and what is wrong.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SignalError {
    /// No samples.
    #[error("`{name}` is empty")]
    Empty {
        /// The signal.
        name: String,
    },
    /// Signals that must pair sample by sample differ in length.
    #[error("{} must have the same length (got {})", .names.join(", "), .lengths.iter().map(usize::to_string).collect::<Vec<_>>().join(", "))]
    Lengths {
        /// The signals.
        names: Vec<String>,
        /// Their lengths.
        lengths: Vec<usize>,
    },
    /// One sample.
    #[error("`{name}`[{index}]: {error}")]
    Sample {
        /// The signal.
        name: String,
        /// The sample (from 0).
        index: usize,
        /// What is wrong.
        error: SampleError,
    },
}

/// Equal, non-zero lengths of signals paired sample by sample.
pub fn same_length(signals: &[(&str, usize)]) -> Result<(), SignalError> {
    if let Some((name, _)) = signals.iter().find(|(_, n)| *n == 0) {
        return Err(SignalError::Empty {
            name: name.to_string(),
        });
    }
    if signals.windows(2).any(|w| w[0].1 != w[1].1) {
        return Err(SignalError::Lengths {
            names: signals.iter().map(|(n, _)| n.to_string()).collect(),
            lengths: signals.iter().map(|(_, l)| *l).collect(),
        });
    }
    Ok(())
}

/// Every sample of `x` finite; the error names the first one that is not.
pub fn finite_signal<'a>(
    name: &str,
    x: impl IntoIterator<Item = &'a f64>,
) -> Result<(), SignalError> {
    for (index, &xk) in x.into_iter().enumerate() {
        finite(xk).map_err(|error| SignalError::Sample {
            name: name.to_string(),
            index,
            error,
        })?;
    }
    Ok(())
}

/// A time signal: every sample finite and strictly increasing.
pub fn time_signal<'a>(
    name: &str,
    t: impl IntoIterator<Item = &'a f64>,
) -> Result<(), SignalError> {
    let mut previous = None;
    for (index, &tk) in t.into_iter().enumerate() {
        finite(tk)
            .and_then(|tk| increasing(previous, tk))
            .map_err(|error| SignalError::Sample {
                name: name.to_string(),
                index,
                error,
            })?;
        previous = Some(tk);
    }
    Ok(())
}

/// The parameter a core error names (`fs` for `fs < fc`, `h` for a period
/// mismatch).
pub fn param_name(e: &friction_core::ParamError) -> &'static str {
    use friction_core::ParamError as E;
    match *e {
        E::NotFinite(n)
        | E::NotPositive(n)
        | E::Negative(n)
        | E::NotRepresentable(n)
        | E::Underflow(n)
        | E::ForceOverflow(n)
        | E::OutOfRange(n)
        | E::BelowOne(n)
        | E::WeightsNotOne(n) => n,
        E::StaticBelowCoulomb => "fs",
        E::PeriodMismatch => "h",
        E::NotBelow { name, .. } => name,
    }
}

/// A number exactly as given (the shortest form that reads back to the same
/// value), in exponent form outside `1e-5 ..= 1e15` so that `1e300` is not
/// printed with 301 digits: for echoing a user's value in a message.
pub fn num(x: f64) -> String {
    let a = x.abs();
    if !x.is_finite() || x == 0.0 || (1e-5..=1e15).contains(&a) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// A computed figure to four significant digits, trailing zeros dropped,
/// in exponent form outside `1e-3 .. 1e5`: `0.7407`, `25`, `1.5e-7`.
pub fn short(x: f64) -> String {
    let a = x.abs();
    if !x.is_finite() || x == 0.0 {
        return format!("{x}");
    }
    let trim = |s: String| {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    };
    if (1e-3..1e5).contains(&a) {
        let digits = (3 - a.log10().floor() as i32).clamp(0, 6) as usize;
        trim(format!("{x:.digits$}"))
    } else {
        let s = format!("{x:.3e}");
        match s.split_once('e') {
            Some((m, e)) => format!("{}e{e}", trim(m.to_string())),
            None => s,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refusals_name_the_argument_in_each_spelling() {
        let e = filter_order(17).unwrap_err();
        assert_eq!(
            e.to_string(),
            "--filter-order 17: must be a whole number from 1 to 16"
        );
        assert_eq!(e.python(), "order=17: must be a whole number from 1 to 16");
        assert!(filter_order(0).is_err() && filter_order(16).is_ok());
        let e = within(args::STRIBECK_EXPONENT, 1e9, ranges::STRIBECK_EXPONENT).unwrap_err();
        assert!(
            e.python().starts_with("stribeck_exponent=1000000000: "),
            "{}",
            e.python()
        );
        assert!(within(args::STRIBECK_EXPONENT, f64::NAN, ranges::STRIBECK_EXPONENT).is_err());
        assert!(decimate(0).is_err() && decimate(-3).is_err() && decimate(1).is_ok());
        let e = cutoff(600.0, 1000.0).unwrap_err();
        assert!(e.rule.contains("500 Hz"), "{e}");
        assert!(cutoff(499.0, 1000.0).is_ok());
    }

    #[test]
    fn velocity_filter_below_half_the_rate() {
        assert!(velocity_filter_rule(1e9, 1e3).is_some());
        assert!(velocity_filter_rule(0.0, 1e3).is_some());
        assert!(velocity_filter_rule(f64::NAN, 1e3).is_some());
        assert!(velocity_filter_rule(499.0, 1e3).is_none());
    }

    #[test]
    fn theta_bounds_blame_the_key_given() {
        let e = theta_bounds(0.2, 5.0, 100.0, true).unwrap_err();
        assert_eq!((e.key, e.value), ("theta0", 100.0));
        let e = theta_bounds(0.2, 1e-300, 1.0, false).unwrap_err();
        assert_eq!((e.key, e.value), ("theta_max", 1e-300));
        let e = theta_bounds(2.0, 5.0, 1.0, false).unwrap_err();
        assert_eq!((e.key, e.value), ("theta_min", 2.0));
        let e = theta_bounds(1.0, 1.0, 1.0, false).unwrap_err();
        assert_eq!(e.key, "theta_min");
        assert!(theta_bounds(0.2, 5.0, 1.0, false).is_ok());
    }

    #[test]
    fn signals_name_the_index() {
        let e = time_signal("t", &[0.0, 1.0, 1.0]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "`t`[2]: time 1 does not increase (previous 1)"
        );
        let e = finite_signal("v", &[0.0, f64::NAN]).unwrap_err();
        assert_eq!(e.to_string(), "`v`[1]: NaN is not finite");
        let e = same_length(&[("t", 3), ("v", 2)]).unwrap_err();
        assert_eq!(e.to_string(), "t, v must have the same length (got 3, 2)");
        assert!(matches!(
            same_length(&[("t", 0), ("v", 0)]),
            Err(SignalError::Empty { .. })
        ));
    }
}
