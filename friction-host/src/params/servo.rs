//! The `[servo]` table of a parameter file and the resolved set-up of
//! `friction servo`: the loop, the drive scenario (encoder, friction drift,
//! load-dependent friction, delay) and the adaptation settings, every key
//! with its default and its range checked up front.

use friction_core::{CompensatorParams, LoadForm, LoadFrictionParams, ParamError};
use serde::Deserialize;

/// The `[servo]` table of a parameter file: every key optional, unknown
/// keys rejected by the loader.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ServoTable {
    /// Inertia `J` (kg m^2) of the plant and of the acceleration feed-forward.
    pub inertia: Option<f64>,
    /// Torque constant `kc` (N m per command unit).
    pub torque_constant: Option<f64>,
    /// Amplitude of the reference sine (rad).
    pub amplitude: Option<f64>,
    /// Frequency of the reference sine (Hz).
    pub frequency: Option<f64>,
    /// Length of the run (s).
    pub duration: Option<f64>,
    /// Controller rate (Hz).
    pub rate: Option<f64>,
    /// Plant integration rate (Hz), a whole multiple of `rate`.
    pub plant_rate: Option<f64>,
    /// Proportional gain.
    pub kp: Option<f64>,
    /// Integral gain.
    pub ki: Option<f64>,
    /// Derivative gain (on the error).
    pub kd: Option<f64>,
    /// Observer correction gain (1/s).
    pub observer_gain: Option<f64>,
    /// Command limit (command units).
    pub limit: Option<f64>,
    /// Encoder resolution: the measured position is rounded to whole counts
    /// of `2 pi / encoder_counts` (0: ideal).
    pub encoder_counts: Option<f64>,
    /// The plant's friction scale over time, `[[t, scale], ...]`: piecewise
    /// linear in `t`, held before the first and after the last point.
    #[serde(default, deserialize_with = "super::rows::friction_drift")]
    pub friction_drift: Option<Vec<[f64; 2]>>,
    /// Load-dependent friction `mu` (1/(N m)): the plant's friction is
    /// multiplied by `1 + mu |kc u|`.
    pub load_friction: Option<f64>,
    /// The command reaches the plant this many controller ticks late.
    pub delay_ticks: Option<f64>,
    /// Cut-off (Hz) of the controller's velocity low-pass (0: none).
    pub velocity_filter: Option<f64>,
    /// Bandwidth (Hz) of the controller's velocity observer (0: none).
    pub velocity_observer: Option<f64>,
    /// Adaptation rate `a` (1/s) of the θ-adaptive observer:
    /// `gamma = a kc kp / Fs^2`.
    pub adaptation_rate: Option<f64>,
    /// Leakage `rho` (1/s) of the θ-adaptive observer.
    pub adaptation_leakage: Option<f64>,
    /// Weight of the error's rate in the adaptation: `gamma_derivative =
    /// w gamma kd / kp` (1: the composite error `de/dt + (kp/kd) e`; 0: the
    /// error alone, which copes better with a coarse encoder but can run
    /// away on a loop that is slow against its friction).
    pub adaptation_derivative: Option<f64>,
    /// Lower projection bound of `θ^`.
    pub theta_min: Option<f64>,
    /// Upper projection bound of `θ^`.
    pub theta_max: Option<f64>,
    /// Forgetting factor of the least-squares feed-forward.
    pub rls_forgetting: Option<f64>,
    /// Minimum speed (rad/s) of a least-squares update (default: the
    /// reference's peak speed / 50).
    pub rls_min_speed: Option<f64>,
    /// Whether the least-squares feed-forward also fits a constant force
    /// offset, a Coulomb level per direction (default false).
    pub rls_offset: Option<bool>,
    /// Whether the adaptive rows are supervised (default true).
    pub supervisor: Option<bool>,
    /// The supervisor's evidence window (s, at least four controller
    /// periods).
    pub supervisor_window: Option<f64>,
    /// Box factor of the per-parameter estimates.
    pub adaptation_box: Option<f64>,
    /// Adaptation rate `a` (1/s) of the per-parameter law.
    pub parameter_rate: Option<f64>,
    /// Rate (1/s) of the per-parameter law's stiffness estimate (0: off,
    /// the default; at most `rate`).
    pub stiffness_rate: Option<f64>,
    /// Dead zone (rad) of the per-parameter adaptation (default: one
    /// encoder count; 0 with an ideal encoder).
    pub dead_zone: Option<f64>,
    /// Upper bound of the per-parameter load coefficient (0: none; default
    /// [`LOADED_AXIS_LOAD_MAX`] on an axis with `gravity`, 0 otherwise).
    pub load_max: Option<f64>,
    /// Nominal per-parameter load coefficient (at most `load_max`).
    pub adaptation_load: Option<f64>,
    /// Direction asymmetry `a` (`|a| < 1`): the plant's friction times
    /// `1 + a` while moving forward, `1 - a` backward.
    pub asymmetry: Option<f64>,
    /// `[T, x0]`: an external torque `-T sin(x + x0)` on the plant (a
    /// pendulum, zero pointing down).
    #[serde(default, deserialize_with = "super::rows::gravity")]
    pub gravity: Option<[f64; 2]>,
    /// `[T, x0]`: the gravity the drive knows and feeds forward, a torque
    /// `T sin(x_ref + x0)` added to every row's command (the plant's
    /// `gravity` as the drive's model of it).
    #[serde(default, deserialize_with = "super::rows::gravity_feedforward")]
    pub gravity_feedforward: Option<[f64; 2]>,
    /// `[[amplitude, cycles_per_rad], ...]`: the plant's friction times
    /// `1 + sum a sin(n x)` (gear mesh).
    #[serde(default, deserialize_with = "super::rows::ripple")]
    pub ripple: Option<Vec<[f64; 2]>>,
    /// A BAM parameter file (JSON, m1 to m6) for the plant's friction,
    /// relative to the parameter file.
    pub plant_bam: Option<String>,
    /// Presliding deflection (rad) of the BAM plant at its break-away torque.
    pub presliding: Option<f64>,
}

/// The servo set-up with every default filled in.
#[derive(Clone, Debug, PartialEq)]
pub struct ServoConfig {
    /// `inertia` (kg m^2).
    pub inertia: f64,
    /// `torque_constant` (N m per command unit).
    pub torque_constant: f64,
    /// `amplitude` (rad).
    pub amplitude: f64,
    /// `frequency` (Hz).
    pub frequency: f64,
    /// `duration` (s).
    pub duration: f64,
    /// `rate` (Hz).
    pub rate: f64,
    /// `plant_rate` (Hz).
    pub plant_rate: f64,
    /// `kp`.
    pub kp: f64,
    /// `ki`.
    pub ki: f64,
    /// `kd`.
    pub kd: f64,
    /// `observer_gain` (1/s).
    pub observer_gain: f64,
    /// `limit`.
    pub limit: f64,
    /// `encoder_counts` (0: ideal).
    pub encoder_counts: f64,
    /// `friction_drift` (empty: scale 1).
    pub friction_drift: Vec<[f64; 2]>,
    /// `load_friction` (1/(N m)).
    pub load_friction: f64,
    /// `delay_ticks`.
    pub delay_ticks: usize,
    /// `velocity_filter` (Hz, 0: none).
    pub velocity_filter: f64,
    /// `velocity_observer` (Hz, 0: none).
    pub velocity_observer: f64,
    /// `adaptation_rate` (1/s).
    pub adaptation_rate: f64,
    /// `adaptation_leakage` (1/s).
    pub adaptation_leakage: f64,
    /// `adaptation_derivative` (weight of `de/dt`, default 1).
    pub adaptation_derivative: f64,
    /// `theta_min`.
    pub theta_min: f64,
    /// `theta_max`.
    pub theta_max: f64,
    /// `rls_forgetting`.
    pub rls_forgetting: f64,
    /// `rls_min_speed` (rad/s).
    pub rls_min_speed: f64,
    /// `rls_offset`.
    pub rls_offset: bool,
    /// `supervisor`.
    pub supervisor: bool,
    /// `supervisor_window` (s).
    pub supervisor_window: f64,
    /// `adaptation_box`.
    pub adaptation_box: f64,
    /// `parameter_rate` (1/s).
    pub parameter_rate: f64,
    /// `stiffness_rate` (1/s; default a tenth of `rate`).
    pub stiffness_rate: f64,
    /// `dead_zone` (rad).
    pub dead_zone: f64,
    /// `load_max`.
    pub load_max: f64,
    /// `adaptation_load`.
    pub adaptation_load: f64,
    /// `asymmetry`.
    pub asymmetry: f64,
    /// `gravity` `[T, x0]` (`T = 0`: none).
    pub gravity: [f64; 2],
    /// `gravity_feedforward` `[T, x0]` (`T = 0`: none).
    pub gravity_feedforward: [f64; 2],
    /// `ripple`.
    pub ripple: Vec<[f64; 2]>,
    /// The BAM plant's friction, if `plant_bam` is given.
    pub plant_bam: Option<LoadFrictionParams>,
    /// `presliding` (rad).
    pub presliding: f64,
}

impl Default for ServoConfig {
    /// Olsson et al. 1998, ideal drive (no quantization, drift, load or
    /// delay), and the adaptation defaults.
    fn default() -> Self {
        Self {
            inertia: 0.0023,
            torque_constant: 1.02,
            amplitude: 0.5,
            frequency: 0.2,
            duration: 20.0,
            rate: DEFAULT_RATE,
            plant_rate: 1e5,
            kp: 60.0,
            ki: 200.0,
            kd: 1.2,
            observer_gain: 20.0,
            limit: 10.0,
            encoder_counts: 0.0,
            friction_drift: Vec::new(),
            load_friction: 0.0,
            delay_ticks: 0,
            velocity_filter: 0.0,
            velocity_observer: 0.0,
            adaptation_rate: DEFAULT_ADAPTATION_RATE,
            adaptation_leakage: 0.0,
            adaptation_derivative: 1.0,
            theta_min: 0.2,
            theta_max: 5.0,
            rls_forgetting: DEFAULT_RLS_FORGETTING,
            rls_min_speed: 0.0,
            rls_offset: false,
            supervisor: true,
            supervisor_window: 0.1,
            adaptation_box: 5.0,
            parameter_rate: DEFAULT_PARAMETER_RATE,
            stiffness_rate: STIFFNESS_RATE_PER_HZ * DEFAULT_RATE,
            dead_zone: 0.0,
            load_max: 0.0,
            adaptation_load: 0.0,
            asymmetry: 0.0,
            gravity: [0.0, 0.0],
            gravity_feedforward: [0.0, 0.0],
            ripple: Vec::new(),
            plant_bam: None,
            presliding: DEFAULT_PRESLIDING,
        }
    }
}

/// The largest value a `[servo]` number may take: every figure stays
/// finite up to it (an `amplitude` of 1e300 made the RMS error infinite).
const MAX_VALUE: f64 = 1e12;

/// Default `adaptation_rate` (1/s).
pub const DEFAULT_ADAPTATION_RATE: f64 = 4.0;
/// Default `load_max` on an axis that carries a load (`gravity`): a gear
/// train of 70 % efficiency or better loses at most 0.3 of the torque it
/// transmits. On an unloaded axis the default is 0: the transmitted torque
/// is then the friction itself, a load coefficient is collinear with the
/// Coulomb levels, and learning it only lets the levels wander.
pub const LOADED_AXIS_LOAD_MAX: f64 = 0.3;
/// Default `parameter_rate` (1/s): the per-parameter law's estimates
/// each carry one level, so they take a faster rate than θ (whose product
/// with the whole model reaches every term at once).
pub const DEFAULT_PARAMETER_RATE: f64 = 16.0;
/// Default `rate` (Hz): Olsson et al.'s 1 kHz.
pub const DEFAULT_RATE: f64 = 1e3;
/// The default `stiffness_rate` per hertz of `rate`: the stiffness law
/// takes a tenth of each sample's error.
pub const STIFFNESS_RATE_PER_HZ: f64 = 0.1;
/// The default `velocity_observer` per hertz of `rate` on a coarse encoder
/// (one that moves less than one count per period at the reference's peak
/// speed, where the backward difference reads 0 or a whole count): a
/// twentieth of the rate. Elsewhere the default is 0, the backward
/// difference.
pub const COARSE_ENCODER_OBSERVER_PER_HZ: f64 = 0.05;
/// Default `presliding` (rad): the BAM plant's deflection at break-away.
pub const DEFAULT_PRESLIDING: f64 = 1e-4;
/// Default `rls_forgetting`.
pub const DEFAULT_RLS_FORGETTING: f64 = 0.9995;

/// The most plant steps (`duration x plant_rate`) one run may take.
pub const MAX_PLANT_STEPS: f64 = 2e7;

/// The most controller ticks (`duration x rate`) one run may take: the
/// trace keeps two columns per compensation per tick.
pub const MAX_TICKS: f64 = 2e6;

/// The most points of `friction_drift`.
pub const MAX_DRIFT_POINTS: usize = 10_000;

/// The largest `delay_ticks`.
pub const MAX_DELAY_TICKS: f64 = 1000.0;

/// Why a `[servo]` table was rejected: each variant names the file and the key.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ServoError {
    /// A key's value is out of its range.
    #[error("{file}: [servo] `{key}` must be {rule}, got {}", crate::checks::num(*.value))]
    Invalid {
        /// The parameter file.
        file: String,
        /// The key.
        key: &'static str,
        /// What it must be.
        rule: &'static str,
        /// What it was.
        value: f64,
    },
    /// `plant_rate` is not a whole multiple of `rate`.
    #[error("{file}: [servo] `plant_rate` ({} Hz) must be a whole multiple of `rate` ({} Hz)", crate::checks::num(*.plant_rate), crate::checks::num(*.rate))]
    NotMultiple {
        /// The parameter file.
        file: String,
        /// `plant_rate`.
        plant_rate: f64,
        /// `rate`.
        rate: f64,
    },
    /// The run would take more plant steps than [`MAX_PLANT_STEPS`].
    #[error("{file}: [servo] `duration` x `plant_rate` = {steps:.3e} plant steps exceeds the cap of {cap:.0e}: shorten `duration` or lower `plant_rate`")]
    TooManySteps {
        /// The parameter file.
        file: String,
        /// `duration x plant_rate`.
        steps: f64,
        /// [`MAX_PLANT_STEPS`].
        cap: f64,
    },
    /// The run would take more controller ticks than [`MAX_TICKS`].
    #[error("{file}: [servo] `duration` x `rate` = {ticks:.3e} ticks exceeds the cap of {cap:.0e}: shorten `duration` or lower `rate`")]
    TooManyTicks {
        /// The parameter file.
        file: String,
        /// `duration x rate`.
        ticks: f64,
        /// [`MAX_TICKS`].
        cap: f64,
    },
    /// `friction_drift` is malformed.
    #[error("{file}: [servo] `friction_drift` point {index}: {rule}")]
    Drift {
        /// The parameter file.
        file: String,
        /// The point (from 1).
        index: usize,
        /// What is wrong.
        rule: &'static str,
    },
    /// `plant_bam` names a file that cannot be read or is not a BAM
    /// parameter file.
    #[error("{file}: [servo] `plant_bam` = {path}: {message}")]
    PlantFile {
        /// The parameter file.
        file: String,
        /// The BAM file as written.
        path: String,
        /// What is wrong.
        message: String,
    },
    /// The controller rejected its parameters (named by the core).
    #[error("{file}: [servo] controller: {error}")]
    Controller {
        /// The parameter file.
        file: String,
        /// The core's error.
        error: ParamError,
    },
}

impl ServoTable {
    /// Fills in the defaults and checks every key; `file` names the source.
    pub fn resolve(&self, file: &str) -> Result<ServoConfig, ServoError> {
        let d = ServoConfig::default();
        let rate = self.rate.unwrap_or(d.rate);
        let mut c = ServoConfig {
            inertia: self.inertia.unwrap_or(d.inertia),
            torque_constant: self.torque_constant.unwrap_or(d.torque_constant),
            amplitude: self.amplitude.unwrap_or(d.amplitude),
            frequency: self.frequency.unwrap_or(d.frequency),
            duration: self.duration.unwrap_or(d.duration),
            rate,
            plant_rate: self.plant_rate.unwrap_or(d.plant_rate),
            kp: self.kp.unwrap_or(d.kp),
            ki: self.ki.unwrap_or(d.ki),
            kd: self.kd.unwrap_or(d.kd),
            observer_gain: self.observer_gain.unwrap_or(d.observer_gain),
            limit: self.limit.unwrap_or(d.limit),
            encoder_counts: self.encoder_counts.unwrap_or(d.encoder_counts),
            friction_drift: self.friction_drift.clone().unwrap_or_default(),
            load_friction: self.load_friction.unwrap_or(d.load_friction),
            delay_ticks: 0,
            velocity_filter: self.velocity_filter.unwrap_or(d.velocity_filter),
            velocity_observer: self.velocity_observer.unwrap_or(d.velocity_observer),
            adaptation_rate: self.adaptation_rate.unwrap_or(d.adaptation_rate),
            adaptation_leakage: self.adaptation_leakage.unwrap_or(d.adaptation_leakage),
            adaptation_derivative: self
                .adaptation_derivative
                .unwrap_or(d.adaptation_derivative),
            theta_min: self.theta_min.unwrap_or(d.theta_min),
            theta_max: self.theta_max.unwrap_or(d.theta_max),
            rls_forgetting: self.rls_forgetting.unwrap_or(d.rls_forgetting),
            rls_min_speed: 0.0,
            rls_offset: self.rls_offset.unwrap_or(d.rls_offset),
            supervisor: self.supervisor.unwrap_or(d.supervisor),
            supervisor_window: self.supervisor_window.unwrap_or(d.supervisor_window),
            adaptation_box: self.adaptation_box.unwrap_or(d.adaptation_box),
            parameter_rate: self.parameter_rate.unwrap_or(d.parameter_rate),
            // a tenth of the rate: a tenth of the error per sample
            stiffness_rate: self.stiffness_rate.unwrap_or(STIFFNESS_RATE_PER_HZ * rate),
            dead_zone: 0.0,
            load_max: self.load_max.unwrap_or(match self.gravity {
                Some([torque, _]) if torque != 0.0 => LOADED_AXIS_LOAD_MAX,
                _ => d.load_max,
            }),
            adaptation_load: self.adaptation_load.unwrap_or(d.adaptation_load),
            asymmetry: self.asymmetry.unwrap_or(d.asymmetry),
            gravity: self.gravity.unwrap_or(d.gravity),
            gravity_feedforward: self.gravity_feedforward.unwrap_or(d.gravity_feedforward),
            ripple: self.ripple.clone().unwrap_or_default(),
            plant_bam: None,
            presliding: self.presliding.unwrap_or(d.presliding),
        };
        // a coarse encoder's velocity from the observer unless a velocity
        // key says otherwise
        if self.velocity_observer.is_none() && self.velocity_filter.is_none() && c.coarse_encoder()
        {
            c.velocity_observer = COARSE_ENCODER_OBSERVER_PER_HZ * c.rate;
        }
        if let Some(name) = &self.plant_bam {
            let bam = read_bam(file, name)?;
            if self.torque_constant.is_none() {
                if let Some(kt) = bam.kt {
                    c.torque_constant = kt;
                }
            }
            if self.inertia.is_none() {
                if let Some(armature) = bam.armature {
                    c.inertia = armature;
                }
            }
            c.plant_bam = Some(bam.params);
        }
        let invalid = |key, rule, value| ServoError::Invalid {
            file: file.to_string(),
            key,
            rule,
            value,
        };
        for (key, value, positive) in [
            ("inertia", c.inertia, true),
            ("torque_constant", c.torque_constant, true),
            ("amplitude", c.amplitude, false),
            ("frequency", c.frequency, false),
            ("duration", c.duration, true),
            ("rate", c.rate, true),
            ("plant_rate", c.plant_rate, true),
            ("kp", c.kp, false),
            ("ki", c.ki, false),
            ("kd", c.kd, false),
            ("observer_gain", c.observer_gain, false),
            ("limit", c.limit, true),
            ("encoder_counts", c.encoder_counts, false),
            ("load_friction", c.load_friction, false),
            ("velocity_filter", c.velocity_filter, false),
            ("velocity_observer", c.velocity_observer, false),
            ("adaptation_rate", c.adaptation_rate, false),
            ("adaptation_leakage", c.adaptation_leakage, false),
            ("adaptation_derivative", c.adaptation_derivative, false),
            ("theta_min", c.theta_min, false),
            ("theta_max", c.theta_max, true),
            ("supervisor_window", c.supervisor_window, true),
            ("adaptation_box", c.adaptation_box, true),
            ("parameter_rate", c.parameter_rate, false),
            ("stiffness_rate", c.stiffness_rate, false),
            ("load_max", c.load_max, false),
            ("adaptation_load", c.adaptation_load, false),
            ("presliding", c.presliding, true),
        ] {
            let (ok, rule) = if positive {
                (value > 0.0, "a number > 0 and at most 1e12")
            } else {
                (value >= 0.0, "a number >= 0 and at most 1e12")
            };
            if !(ok && value <= MAX_VALUE) {
                return Err(invalid(key, rule, value));
            }
        }
        // a rate at which no allowed `duration` holds 10 periods is the
        // rate's fault, not the duration's (nor any key checked against
        // the period below)
        if c.rate * MAX_VALUE < 10.0 {
            return Err(invalid(
                "rate",
                "at least 1e-11 Hz (10 controller periods within the longest run, 1e12 s)",
                c.rate,
            ));
        }
        if c.encoder_counts != c.encoder_counts.round() || c.encoder_counts > 1e12 {
            return Err(invalid(
                "encoder_counts",
                "a whole number from 0 (ideal) to 1e12",
                c.encoder_counts,
            ));
        }
        if let Some(delay) = self.delay_ticks {
            if !((0.0..=MAX_DELAY_TICKS).contains(&delay) && delay == delay.round()) {
                return Err(invalid(
                    "delay_ticks",
                    "a whole number from 0 to 1000",
                    delay,
                ));
            }
            c.delay_ticks = delay as usize;
        }
        // 0 is "no filter" here; any other cut-off by the shared rule
        if c.velocity_filter != 0.0 {
            if let Some(rule) = crate::checks::velocity_filter_rule(c.velocity_filter, c.rate) {
                return Err(invalid("velocity_filter", rule, c.velocity_filter));
            }
        }
        if c.velocity_observer != 0.0 {
            if c.velocity_filter != 0.0 {
                return Err(invalid(
                    "velocity_observer",
                    "0 when `velocity_filter` is set (one velocity estimate)",
                    c.velocity_observer,
                ));
            }
            if c.velocity_observer >= 0.5 * c.rate {
                return Err(invalid(
                    "velocity_observer",
                    "below half the controller rate",
                    c.velocity_observer,
                ));
            }
        }
        if c.stiffness_rate > c.rate {
            return Err(invalid(
                "stiffness_rate",
                "at most the controller rate (a step of at most the whole error per sample)",
                c.stiffness_rate,
            ));
        }
        // θ starts at 1, the nominal model
        crate::checks::theta_bounds(c.theta_min, c.theta_max, 1.0, false)
            .map_err(|e| invalid(e.key, e.rule, e.value))?;
        if !(c.rls_forgetting > 0.0 && c.rls_forgetting <= 1.0) {
            return Err(invalid(
                "rls_forgetting",
                "a number in (0, 1]",
                c.rls_forgetting,
            ));
        }
        c.rls_min_speed = match self.rls_min_speed {
            Some(v) if v.is_finite() && v > 0.0 => v,
            Some(v) => return Err(invalid("rls_min_speed", "a finite number > 0", v)),
            None => c.peak_speed() / 50.0,
        };
        if c.asymmetry.is_nan() || c.asymmetry.abs() >= 1.0 {
            return Err(invalid(
                "asymmetry",
                "a number between -1 and 1 (exclusive)",
                c.asymmetry,
            ));
        }
        // the plant's pendulum and the drive's model of it, checked alike
        for (key, [torque, angle]) in [
            ("gravity", c.gravity),
            ("gravity_feedforward", c.gravity_feedforward),
        ] {
            if !(0.0..=MAX_VALUE).contains(&torque) {
                return Err(invalid(key, "[T, x0] with T >= 0 and at most 1e12", torque));
            }
            if !(angle.is_finite() && angle.abs() <= MAX_VALUE) {
                return Err(invalid(key, "[T, x0] with a finite x0", angle));
            }
        }
        if c.ripple.len() > MAX_DRIFT_POINTS {
            return Err(invalid(
                "ripple",
                "at most 10000 terms",
                c.ripple.len() as f64,
            ));
        }
        let mut depth = 0.0;
        for [a, n] in &c.ripple {
            if !(a.is_finite() && n.is_finite() && n.abs() <= MAX_VALUE) {
                return Err(invalid(
                    "ripple",
                    "[[amplitude, cycles_per_rad], ...] of finite numbers",
                    if a.is_finite() { *n } else { *a },
                ));
            }
            depth += a.abs();
        }
        if depth >= 1.0 {
            return Err(invalid(
                "ripple",
                "terms whose amplitudes sum below 1 (the friction stays positive)",
                depth,
            ));
        }
        if c.adaptation_load > c.load_max {
            return Err(invalid(
                "adaptation_load",
                "a number >= 0 and at most `load_max` (by default 0.3 on an axis with `gravity`, 0 otherwise)",
                c.adaptation_load,
            ));
        }
        if c.adaptation_box < 1.0 {
            return Err(invalid(
                "adaptation_box",
                "a number >= 1 and at most 1e12",
                c.adaptation_box,
            ));
        }
        // the supervisor's close is spread over the window's first ticks
        if (c.supervisor_window * c.rate).round() < f64::from(friction_core::MIN_WINDOW_TICKS) {
            return Err(invalid(
                "supervisor_window",
                "at least seven controller periods",
                c.supervisor_window,
            ));
        }
        c.dead_zone = match self.dead_zone {
            Some(d) if (0.0..=MAX_VALUE).contains(&d) => d,
            Some(d) => return Err(invalid("dead_zone", "a number >= 0 and at most 1e12", d)),
            None if c.encoder_counts > 0.0 => 2.0 * std::f64::consts::PI / c.encoder_counts,
            None => 0.0,
        };
        if c.friction_drift.len() > MAX_DRIFT_POINTS {
            return Err(ServoError::Drift {
                file: file.to_string(),
                index: MAX_DRIFT_POINTS + 1,
                rule: "at most 10000 points",
            });
        }
        let mut last_t = f64::NEG_INFINITY;
        for (i, [t, s]) in c.friction_drift.iter().enumerate() {
            let rule = if !(t.is_finite() && s.is_finite()) {
                Some("`t` and `scale` must be finite")
            } else if *s < 0.0 || *s > 1e3 {
                Some("`scale` must be between 0 and 1000")
            } else if *t <= last_t {
                Some("times must increase")
            } else {
                None
            };
            if let Some(rule) = rule {
                return Err(ServoError::Drift {
                    file: file.to_string(),
                    index: i + 1,
                    rule,
                });
            }
            last_t = *t;
        }
        if c.duration * c.rate < 10.0 {
            return Err(invalid(
                "duration",
                "at least 10 controller periods",
                c.duration,
            ));
        }
        let ratio = c.plant_rate / c.rate;
        if ratio < 1.0 || (ratio - ratio.round()).abs() > 1e-9 * ratio {
            return Err(ServoError::NotMultiple {
                file: file.to_string(),
                plant_rate: c.plant_rate,
                rate: c.rate,
            });
        }
        let steps = c.duration * c.plant_rate;
        if steps > MAX_PLANT_STEPS {
            return Err(ServoError::TooManySteps {
                file: file.to_string(),
                steps,
                cap: MAX_PLANT_STEPS,
            });
        }
        let ticks = c.duration * c.rate;
        if ticks > MAX_TICKS {
            return Err(ServoError::TooManyTicks {
                file: file.to_string(),
                ticks,
                cap: MAX_TICKS,
            });
        }
        c.controller()
            .validate()
            .map_err(|error| ServoError::Controller {
                file: file.to_string(),
                error,
            })?;
        Ok(c)
    }
}

/// A BAM parameter file: its friction budget, and its `kt` and `armature`
/// where it has them.
pub struct BamFile {
    /// The budget.
    pub params: LoadFrictionParams,
    /// `kt` (N m/A).
    pub kt: Option<f64>,
    /// `armature` (kg m^2).
    pub armature: Option<f64>,
}

/// Reads the BAM file `name`, relative to the parameter file `file`.
pub fn read_bam(file: &str, name: &str) -> Result<BamFile, ServoError> {
    let fail = |message: String| ServoError::PlantFile {
        file: file.to_string(),
        path: name.to_string(),
        message,
    };
    let dir = std::path::Path::new(file)
        .parent()
        .unwrap_or(std::path::Path::new("."));
    let path = dir.join(name);
    let text = std::fs::read_to_string(&path)
        .map_err(|e| fail(format!("cannot read {}: {e}", path.display())))?;
    let value: serde_json::Value = serde_json::from_str(&text).map_err(|e| {
        fail(format!(
            "not JSON at line {}, column {}: {e}",
            e.line(),
            e.column()
        ))
    })?;
    let object = value
        .as_object()
        .ok_or_else(|| fail("not a JSON object".into()))?;
    let form_name = object
        .get("model")
        .and_then(|m| m.as_str())
        .ok_or_else(|| fail("no `model` (m1 to m6)".into()))?;
    let form = LoadForm::named(form_name)
        .ok_or_else(|| fail(format!("`model` = {form_name:?} is not one of m1 to m6")))?;
    let number = |key: &str| -> Result<Option<f64>, ServoError> {
        match object.get(key) {
            None => Ok(None),
            Some(v) => v
                .as_f64()
                .map(Some)
                .ok_or_else(|| fail(format!("`{key}` is not a number"))),
        }
    };
    let mut p = LoadFrictionParams::zero(form);
    for (key, slot) in [
        ("friction_base", &mut p.friction_base),
        ("friction_stribeck", &mut p.friction_stribeck),
        ("friction_viscous", &mut p.friction_viscous),
        ("dtheta_stribeck", &mut p.dtheta_stribeck),
        ("alpha", &mut p.alpha),
        ("load_friction_base", &mut p.load_friction_base),
        ("load_friction_stribeck", &mut p.load_friction_stribeck),
        ("load_friction_motor", &mut p.load_friction_motor),
        ("load_friction_external", &mut p.load_friction_external),
        (
            "load_friction_motor_stribeck",
            &mut p.load_friction_motor_stribeck,
        ),
        (
            "load_friction_external_stribeck",
            &mut p.load_friction_external_stribeck,
        ),
        ("load_friction_motor_quad", &mut p.load_friction_motor_quad),
        (
            "load_friction_external_quad",
            &mut p.load_friction_external_quad,
        ),
    ] {
        if let Some(x) = number(key)? {
            *slot = x;
        }
    }
    p.validate().map_err(|e| fail(e.to_string()))?;
    let positive = |key: &str| -> Result<Option<f64>, ServoError> {
        match number(key)? {
            Some(x) if !(x > 0.0 && x <= MAX_VALUE) => {
                Err(fail(format!("`{key}` must be > 0 and at most 1e12")))
            }
            x => Ok(x),
        }
    };
    Ok(BamFile {
        params: p,
        kt: positive("kt")?,
        armature: positive("armature")?,
    })
}

impl ServoConfig {
    /// The core compensator's parameters.
    pub fn controller(&self) -> CompensatorParams {
        CompensatorParams {
            h: 1.0 / self.rate,
            kp: self.kp,
            ki: self.ki,
            kd: self.kd,
            inertia: self.inertia,
            torque_constant: self.torque_constant,
            limit: self.limit,
        }
    }

    /// The reference's peak speed `2 pi f A` (rad/s), or 1 for a still
    /// reference.
    pub fn peak_speed(&self) -> f64 {
        let v = 2.0 * std::f64::consts::PI * self.frequency * self.amplitude;
        if v > 0.0 {
            v
        } else {
            1.0
        }
    }

    /// Encoder counts the reference's peak speed crosses in one controller
    /// period, `encoder_counts A f / rate`; `None` with an ideal encoder.
    pub fn counts_per_period(&self) -> Option<f64> {
        (self.encoder_counts > 0.0)
            .then(|| self.encoder_counts * self.amplitude * self.frequency / self.rate)
    }

    /// Whether the encoder moves less than one count per period at the
    /// reference's peak speed (and the reference moves at all): the
    /// backward difference then reads 0 or a whole count on every tick, so
    /// a Stribeck curve and the adaptation see no speed in between.
    pub fn coarse_encoder(&self) -> bool {
        self.counts_per_period()
            .is_some_and(|counts| counts > 0.0 && counts < 1.0)
    }

    /// On a coarse encoder ([`coarse_encoder`](Self::coarse_encoder)): a
    /// note that says which velocity the controllers use, the observer by
    /// default or the backward difference when `velocity_observer = 0` was
    /// set, and what the other choice does.
    pub fn coarse_encoder_note(&self) -> Option<String> {
        if !self.coarse_encoder() || self.velocity_filter != 0.0 {
            return None;
        }
        let counts = crate::checks::short(self.counts_per_period()?);
        let guide = "docs/guide/servo.md, \"A 12-bit encoder\"";
        Some(if self.velocity_observer == 0.0 {
            format!(
                "the encoder moves {counts} counts per period at the peak speed, so the \
                 measured velocity is 0 or a whole count per period on every tick; \
                 `velocity_observer = {}` (a twentieth of the rate, the default on such \
                 an encoder) \
                 estimates the speed between counts ({guide})",
                self.rate * COARSE_ENCODER_OBSERVER_PER_HZ
            )
        } else {
            format!(
                "the encoder moves {counts} counts per period at the peak speed: the \
                 velocity comes from the velocity observer at {} Hz; `velocity_observer \
                 = 0` gives the backward difference, whose count-by-count flips can help \
                 a stick-slip-prone or gravity-loaded axis ({guide})",
                crate::checks::short(self.velocity_observer)
            )
        })
    }

    /// The plant's friction scale at time `t` (`friction_drift`).
    pub fn drift(&self, t: f64) -> f64 {
        let d = &self.friction_drift;
        match d.iter().position(|p| p[0] > t) {
            None => d.last().map_or(1.0, |p| p[1]),
            Some(0) => d[0][1],
            Some(i) => {
                let ([t0, s0], [t1, s1]) = (d[i - 1], d[i]);
                s0 + (s1 - s0) * (t - t0) / (t1 - t0)
            }
        }
    }

    /// Whether the set-up is the ideal drive (no quantization, drift, load
    /// or delay).
    pub fn is_ideal(&self) -> bool {
        self.encoder_counts == 0.0
            && self.friction_drift.is_empty()
            && self.load_friction == 0.0
            && self.delay_ticks == 0
            && self.asymmetry == 0.0
            && self.gravity[0] == 0.0
            && self.ripple.is_empty()
            && self.plant_bam.is_none()
    }

    /// The plant's friction factor at position `x` moving at `v`:
    /// direction asymmetry times ripple.
    pub fn friction_factor(&self, x: f64, v: f64) -> f64 {
        let direction = if v > 0.0 {
            1.0 + self.asymmetry
        } else if v < 0.0 {
            1.0 - self.asymmetry
        } else {
            1.0
        };
        let ripple: f64 = self.ripple.iter().map(|[a, n]| a * (n * x).sin()).sum();
        direction * (1.0 + ripple)
    }

    /// The external torque on the plant at position `x` (`gravity`).
    pub fn external_torque(&self, x: f64) -> f64 {
        pendulum(self.gravity, x)
    }

    /// The torque the drive feeds forward at the reference position
    /// `x_ref` (`gravity_feedforward`): its model of `gravity`, cancelled.
    pub fn gravity_feedforward(&self, x_ref: f64) -> f64 {
        -pendulum(self.gravity_feedforward, x_ref)
    }

    /// The external torque `τ_ext` the per-parameter compensator is told
    /// ([`friction_core::Compensator::set_external_torque`]): the drive's
    /// model of the gravity at the measured position `x`, less the torque
    /// fed forward beside the compensator's command.
    pub fn modelled_external_torque(&self, x: f64, x_ref: f64) -> f64 {
        pendulum(self.gravity_feedforward, x) - self.gravity_feedforward(x_ref)
    }
}

/// A pendulum's torque `-T sin(x + x0)` at `x` for `[T, x0]` (0 when `T = 0`).
fn pendulum([torque, angle]: [f64; 2], x: f64) -> f64 {
    if torque == 0.0 {
        0.0
    } else {
        -torque * (x + angle).sin()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::ParamFile;

    /// A coarse encoder (less than one count per period at the peak speed;
    /// amplitude 0.5, 0.2 Hz, 1 kHz: `counts x 1e-4` counts per period)
    /// gets the velocity observer at a twentieth of the rate by default and
    /// a note either way; a velocity key the file sets wins.
    #[test]
    fn a_coarse_encoder_gets_the_velocity_observer_and_a_note() {
        let at = |counts: f64| ServoTable {
            encoder_counts: Some(counts),
            ..ServoTable::default()
        };
        for (counts, coarse) in [
            (0.0, false),
            (4096.0, true),
            (9999.0, true),
            (10_000.0, false),
        ] {
            let c = at(counts).resolve("p.toml").unwrap();
            assert_eq!(c.coarse_encoder_note().is_some(), coarse, "{counts} counts");
            let observer = if coarse { 50.0 } else { 0.0 };
            assert_eq!(c.velocity_observer, observer, "{counts} counts");
        }
        let note = at(4096.0)
            .resolve("p.toml")
            .unwrap()
            .coarse_encoder_note()
            .unwrap();
        assert!(
            note.contains("0.4096 counts")
                && note.contains("observer at 50 Hz")
                && note.contains("`velocity_observer = 0`"),
            "{note}"
        );
        // the backward difference when the file asks for it, the note naming
        // the observer
        let set = |velocity_observer| ServoTable {
            velocity_observer: Some(velocity_observer),
            ..at(4096.0)
        };
        let c = set(0.0).resolve("p.toml").unwrap();
        assert_eq!(c.velocity_observer, 0.0);
        let note = c.coarse_encoder_note().unwrap();
        assert!(note.contains("velocity_observer = 50"), "{note}");
        let c = set(30.0).resolve("p.toml").unwrap();
        assert_eq!(c.velocity_observer, 30.0);
        assert!(c
            .coarse_encoder_note()
            .unwrap()
            .contains("observer at 30 Hz"));
        // the rule follows the rate
        let fast = ServoTable {
            rate: Some(2000.0),
            ..at(4096.0)
        };
        assert_eq!(fast.resolve("p.toml").unwrap().velocity_observer, 100.0);
        // a still reference moves no counts: the backward difference, no note
        let still = ServoTable {
            amplitude: Some(0.0),
            ..at(4096.0)
        };
        let c = still.resolve("p.toml").unwrap();
        assert_eq!((c.velocity_observer, c.coarse_encoder_note()), (0.0, None));
        let slow = ServoTable {
            amplitude: Some(1e-6),
            ..at(4096.0)
        };
        let note = slow
            .resolve("p.toml")
            .unwrap()
            .coarse_encoder_note()
            .unwrap();
        assert!(note.contains("8.192e-7 counts"), "{note}");
        // a velocity filter is a velocity choice of its own, and so is
        // `velocity_filter = 0` (the backward difference, with the note)
        let filtered = ServoTable {
            velocity_filter: Some(100.0),
            ..at(4096.0)
        };
        let c = filtered.resolve("p.toml").unwrap();
        assert_eq!((c.velocity_observer, c.coarse_encoder_note()), (0.0, None));
        let unfiltered = ServoTable {
            velocity_filter: Some(0.0),
            ..at(4096.0)
        };
        let c = unfiltered.resolve("p.toml").unwrap();
        assert_eq!(c.velocity_observer, 0.0);
        assert!(c
            .coarse_encoder_note()
            .unwrap()
            .contains("velocity_observer = 50"));
    }

    /// `load_max` defaults to `LOADED_AXIS_LOAD_MAX` on an axis with
    /// gravity and to 0 elsewhere; a set value wins, and a nominal above the
    /// default is refused with the default named.
    #[test]
    fn the_load_bound_defaults_by_whether_the_axis_is_loaded() {
        let loaded = ServoTable {
            gravity: Some([0.5, 0.0]),
            ..ServoTable::default()
        };
        assert_eq!(
            loaded.resolve("p.toml").unwrap().load_max,
            LOADED_AXIS_LOAD_MAX
        );
        let unloaded = ServoTable {
            gravity: Some([0.0, 0.0]),
            ..ServoTable::default()
        };
        assert_eq!(unloaded.resolve("p.toml").unwrap().load_max, 0.0);
        assert_eq!(
            ServoTable::default().resolve("p.toml").unwrap().load_max,
            0.0
        );
        let set = ServoTable {
            load_max: Some(0.1),
            ..loaded.clone()
        };
        assert_eq!(set.resolve("p.toml").unwrap().load_max, 0.1);
        let above = ServoTable {
            adaptation_load: Some(0.5),
            ..loaded
        };
        let e = above.resolve("p.toml").unwrap_err().to_string();
        assert!(e.contains("adaptation_load") && e.contains("0.3"), "{e}");
    }

    #[test]
    fn servo_keys_are_checked_and_named() {
        let ok = ServoTable::default().resolve("p.toml").unwrap();
        // the defaults, with the least-squares speed threshold at 1/50 of the peak speed
        let expected = ServoConfig {
            rls_min_speed: ServoConfig::default().peak_speed() / 50.0,
            ..ServoConfig::default()
        };
        assert_eq!(ok, expected);
        let e = ServoTable {
            kp: Some(-1.0),
            ..Default::default()
        }
        .resolve("p.toml")
        .unwrap_err();
        assert!(matches!(e, ServoError::Invalid { key: "kp", .. }), "{e:?}");
        assert!(e.to_string().starts_with("p.toml: [servo] `kp`"), "{e}");
        let e = ServoTable {
            inertia: Some(0.0),
            ..Default::default()
        }
        .resolve("p.toml")
        .unwrap_err();
        assert!(matches!(e, ServoError::Invalid { key: "inertia", .. }));
        let e = ServoTable {
            frequency: Some(f64::NAN),
            ..Default::default()
        }
        .resolve("p.toml")
        .unwrap_err();
        assert!(matches!(
            e,
            ServoError::Invalid {
                key: "frequency",
                ..
            }
        ));
        let e = ServoTable {
            plant_rate: Some(1500.0),
            ..Default::default()
        }
        .resolve("p.toml")
        .unwrap_err();
        assert!(matches!(e, ServoError::NotMultiple { .. }), "{e:?}");
        let e = ServoTable {
            duration: Some(1e4),
            ..Default::default()
        }
        .resolve("p.toml")
        .unwrap_err();
        assert!(matches!(e, ServoError::TooManySteps { .. }), "{e:?}");
        assert!(e.to_string().contains("`duration` x `plant_rate`"), "{e}");
    }

    #[test]
    fn servo_table_parses_and_rejects_unknown_keys() {
        let text = include_str!("../../../params/olsson1998-servo.toml");
        let f = ParamFile::parse(
            &format!("{text}\n[servo]\nduration = 2\nkp = 50\n"),
            "p.toml",
        )
        .unwrap();
        assert_eq!(f.servo.duration, Some(2.0));
        assert_eq!(f.servo.kp, Some(50.0));
        let e = ParamFile::parse(&format!("{text}\n[servo]\nkpp = 50\n"), "p.toml").unwrap_err();
        let e = format!("{e:#}");
        assert!(e.contains("kpp") && e.contains("p.toml"), "{e}");
    }

    #[test]
    fn bam_files_are_read_with_their_kt_and_armature_and_bad_ones_named() {
        let dir = std::env::temp_dir().join(format!("friction-bam-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("p.toml").display().to_string();
        let write = |name: &str, text: &str| std::fs::write(dir.join(name), text).unwrap();
        write(
            "m4.json",
            r#"{"kt": 2.2, "armature": 0.025, "friction_base": 0.01, "friction_stribeck": 0.1,
                "load_friction_base": 0.009, "load_friction_stribeck": 0.22,
                "dtheta_stribeck": 1.6, "alpha": 1.3, "friction_viscous": 0.05, "model": "m4"}"#,
        );
        let table = |name: &str| ServoTable {
            plant_bam: Some(name.into()),
            ..Default::default()
        };
        let c = table("m4.json").resolve(&file).unwrap();
        let p = c.plant_bam.unwrap();
        assert_eq!(p.form, LoadForm::M4);
        assert_eq!(p.load_friction_stribeck, 0.22);
        assert_eq!((c.torque_constant, c.inertia), (2.2, 0.025));
        assert!(!c.is_ideal());
        // the table's own values win
        let c = ServoTable {
            inertia: Some(0.5),
            ..table("m4.json")
        }
        .resolve(&file)
        .unwrap();
        assert_eq!((c.torque_constant, c.inertia), (2.2, 0.5));
        for (name, text, says) in [
            ("a.json", "{\"model\": \"m9\"}", "not one of m1 to m6"),
            ("b.json", "{\"model\": \"m2\",\n \"alpha\": -1}", "alpha"),
            (
                "c.json",
                "{\"model\": \"m2\", \"kt\": \"x\"}",
                "`kt` is not a number",
            ),
            ("d.json", "{\"model\": \"m2\",\n oops}", "line 2, column 2"),
            ("e.json", "[1, 2]", "not a JSON object"),
        ] {
            write(name, text);
            let e = table(name).resolve(&file).unwrap_err().to_string();
            assert!(
                e.contains(says) && e.contains("plant_bam") && e.contains(&file),
                "{e}"
            );
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn plant_factors_follow_direction_position_and_gravity() {
        let c = ServoConfig {
            asymmetry: 0.2,
            ripple: vec![[0.1, 4.0]],
            gravity: [3.0, 0.5],
            ..ServoConfig::default()
        };
        let ripple = 1.0 + 0.1 * (4.0f64 * 0.3).sin();
        assert!((c.friction_factor(0.3, 1.0) - 1.2 * ripple).abs() < 1e-15);
        assert!((c.friction_factor(0.3, -1.0) - 0.8 * ripple).abs() < 1e-15);
        assert!((c.external_torque(0.3) + 3.0 * 0.8f64.sin()).abs() < 1e-15);
        // the drive's model of it, fed forward at the reference: an exact
        // model cancels the plant's torque, and the compensator is told
        // the model at the measured position less the feed-forward
        let fed = ServoConfig {
            gravity_feedforward: [3.0, 0.5],
            ..c.clone()
        };
        assert_eq!(fed.gravity_feedforward(0.3), -c.external_torque(0.3));
        assert_eq!(
            fed.modelled_external_torque(0.3, 0.3),
            2.0 * c.external_torque(0.3)
        );
        assert_eq!(c.gravity_feedforward(0.3), 0.0);
        assert_eq!(ServoConfig::default().external_torque(1.0), 0.0);
        assert_eq!(ServoConfig::default().friction_factor(1.0, 1.0), 1.0);
    }

    #[test]
    fn drift_is_piecewise_linear_and_held() {
        let c = ServoConfig {
            friction_drift: vec![[1.0, 1.3], [11.0, 1.0], [12.0, 1.4]],
            ..ServoConfig::default()
        };
        assert_eq!(c.drift(0.0), 1.3);
        assert!((c.drift(6.0) - 1.15).abs() < 1e-12);
        assert!((c.drift(11.5) - 1.2).abs() < 1e-12);
        assert_eq!(c.drift(100.0), 1.4);
        assert_eq!(ServoConfig::default().drift(3.0), 1.0);
    }

    #[test]
    fn scenario_keys_are_checked_and_named() {
        let bad = |t: ServoTable, key: &str| {
            let e = t.resolve("p.toml").unwrap_err();
            assert!(e.to_string().contains(key), "{e}");
        };
        bad(
            ServoTable {
                encoder_counts: Some(1.5),
                ..Default::default()
            },
            "encoder_counts",
        );
        bad(
            ServoTable {
                delay_ticks: Some(-1.0),
                ..Default::default()
            },
            "delay_ticks",
        );
        bad(
            ServoTable {
                friction_drift: Some(vec![[1.0, 1.0], [0.5, 1.0]]),
                ..Default::default()
            },
            "point 2: times must increase",
        );
        bad(
            ServoTable {
                friction_drift: Some(vec![[1.0, f64::NAN]]),
                ..Default::default()
            },
            "point 1",
        );
        bad(
            ServoTable {
                theta_min: Some(2.0),
                ..Default::default()
            },
            "theta_min",
        );
        bad(
            ServoTable {
                velocity_filter: Some(600.0),
                ..Default::default()
            },
            "velocity_filter",
        );
        bad(
            ServoTable {
                velocity_observer: Some(500.0),
                ..Default::default()
            },
            "velocity_observer",
        );
        bad(
            ServoTable {
                velocity_observer: Some(50.0),
                velocity_filter: Some(100.0),
                ..Default::default()
            },
            "velocity_observer",
        );
        bad(
            ServoTable {
                velocity_observer: Some(-1.0),
                ..Default::default()
            },
            "velocity_observer",
        );
        bad(
            ServoTable {
                rls_forgetting: Some(0.0),
                ..Default::default()
            },
            "rls_forgetting",
        );
        bad(
            ServoTable {
                asymmetry: Some(1.0),
                ..Default::default()
            },
            "`asymmetry`",
        );
        bad(
            ServoTable {
                gravity: Some([-1.0, 0.0]),
                ..Default::default()
            },
            "`gravity`",
        );
        bad(
            ServoTable {
                gravity_feedforward: Some([-1.0, 0.0]),
                ..Default::default()
            },
            "`gravity_feedforward`",
        );
        bad(
            ServoTable {
                gravity_feedforward: Some([1.0, f64::INFINITY]),
                ..Default::default()
            },
            "`gravity_feedforward`",
        );
        bad(
            ServoTable {
                ripple: Some(vec![[0.6, 3.0], [-0.5, 7.0]]),
                ..Default::default()
            },
            "`ripple`",
        );
        bad(
            ServoTable {
                presliding: Some(0.0),
                ..Default::default()
            },
            "`presliding`",
        );
        bad(
            ServoTable {
                adaptation_box: Some(0.5),
                ..Default::default()
            },
            "`adaptation_box`",
        );
        bad(
            ServoTable {
                dead_zone: Some(-1.0),
                ..Default::default()
            },
            "`dead_zone`",
        );
        // six periods at the default 1 kHz: the supervisor needs seven
        bad(
            ServoTable {
                supervisor_window: Some(0.006),
                ..Default::default()
            },
            "at least seven controller periods",
        );
        bad(
            ServoTable {
                plant_bam: Some("no-such.json".into()),
                ..Default::default()
            },
            "`plant_bam` = no-such.json: cannot read",
        );
        let ok = ServoTable {
            encoder_counts: Some(262_144.0),
            delay_ticks: Some(1.0),
            ..Default::default()
        }
        .resolve("p.toml")
        .unwrap();
        assert_eq!((ok.encoder_counts, ok.delay_ticks), (262_144.0, 1));
        assert!(!ok.is_ideal() && ServoConfig::default().is_ideal());
    }
}
