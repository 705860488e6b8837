//! Parameter files (TOML): `model = "..."`, the model's keys, and an
//! optional `[rig]` table for the experiments, a `[servo]` table for
//! `friction servo` and a `[plant]` table written by `friction identify`.
//! Unknown keys are errors that
//! name the key, with line and column.

pub mod rows;
pub mod servo;

use crate::models::PARAM_SETS;
use anyhow::{bail, Context, Result};
use serde::Deserialize;
use servo::ServoTable;
use std::path::Path;

use crate::models::{ModelSpec, MODEL_NAMES};

/// The `[rig]` table: the mechanical set-up of the experiments. Every key is
/// optional; each experiment documents its defaults.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Rig {
    /// Moving mass `m` (kg), or inertia for rotary set-ups.
    pub mass: Option<f64>,
    /// Spring stiffness `k` (N/m) of the stick-slip rig.
    pub stiffness: Option<f64>,
    /// Velocity at which the spring's end is pulled (m/s).
    pub pull_velocity: Option<f64>,
    /// Peak applied force of the drift experiment (N).
    pub force: Option<f64>,
    /// Frequency of the drift experiment's force (Hz).
    pub frequency: Option<f64>,
    /// Number of force cycles of the drift experiment.
    pub cycles: Option<u32>,
    /// Force rate of the pre-sliding ramps (N/s).
    pub force_rate: Option<f64>,
}

/// The most force cycles a drift rig may ask for.
pub const MAX_CYCLES: u32 = 10_000;

impl Rig {
    /// Checks every key that is given: masses, stiffnesses, rates and
    /// frequencies finite and positive, `cycles` in `1..=MAX_CYCLES`. The
    /// error names the key.
    pub fn validate(&self) -> Result<()> {
        for (key, value) in [
            ("mass", self.mass),
            ("stiffness", self.stiffness),
            ("pull_velocity", self.pull_velocity),
            ("force", self.force),
            ("frequency", self.frequency),
            ("force_rate", self.force_rate),
        ] {
            if let Some(x) = value {
                if !(x.is_finite() && x > 0.0) {
                    bail!("[rig] `{key}` = {x} must be a finite number > 0");
                }
            }
        }
        if let Some(c) = self.cycles {
            if !(1..=MAX_CYCLES).contains(&c) {
                bail!("[rig] `cycles` = {c} must be between 1 and {MAX_CYCLES}");
            }
        }
        Ok(())
    }
}

/// The `[plant]` table that `friction identify` writes: the driven axis
/// the friction was identified on. Every key is optional.
#[derive(Clone, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Plant {
    /// Moving mass (kg), or inertia for rotary axes.
    pub mass: Option<f64>,
    /// Constant force offset of the drive (N).
    pub offset: Option<f64>,
    /// Whether the model's force parameters are friction coefficients:
    /// the friction is the normal force times the model's output.
    #[serde(default)]
    pub per_normal_force: bool,
}

/// A parsed parameter file.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamFile {
    /// The model.
    pub model: ModelSpec,
    /// The rig, if the file has a `[rig]` table.
    pub rig: Rig,
    /// The identified plant, if the file has a `[plant]` table.
    pub plant: Plant,
    /// The `[servo]` table of `friction servo` (every key optional).
    pub servo: ServoTable,
    /// The `[commission]` table of `friction commission` (every key optional).
    pub commission: CommissionTable,
}

/// The `[commission]` table: the window and speeds of `friction commission`;
/// every key optional (defaults in the command's docs), checked when the
/// routine is built.
#[derive(Clone, Copy, Debug, Default, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct CommissionTable {
    /// Largest excursion from the start (rad).
    pub travel: Option<f64>,
    /// Fastest plateau (rad/s).
    pub max_speed: Option<f64>,
    /// Slowest plateau (rad/s).
    pub min_speed: Option<f64>,
    /// Number of plateau speeds.
    pub speeds: Option<u8>,
    /// Longest run (s).
    pub duration: Option<f64>,
}

#[derive(Deserialize)]
struct Probe {
    model: Option<String>,
    #[serde(default)]
    rig: Rig,
    #[serde(default)]
    plant: Plant,
    #[serde(default)]
    servo: ServoTable,
    #[serde(default)]
    commission: CommissionTable,
}

impl ParamFile {
    /// Parses TOML text; `origin` names the source in messages.
    pub fn parse(text: &str, origin: &str) -> Result<Self> {
        let probe: Probe =
            toml::from_str(text).with_context(|| format!("{origin}: invalid parameter file"))?;
        let Some(name) = probe.model else {
            bail!(
                "{origin}: missing key `model` (one of {})",
                MODEL_NAMES.join(", ")
            );
        };
        let file = ParamFile {
            model: ModelSpec::parse(&name, text, origin)?,
            rig: probe.rig,
            plant: probe.plant,
            servo: probe.servo,
            commission: probe.commission,
        };
        file.model
            .host()
            .validate()
            .map_err(|e| anyhow::anyhow!("{origin}: {e}"))?;
        file.rig
            .validate()
            .map_err(|e| anyhow::anyhow!("{origin}: {e}"))?;
        Ok(file)
    }

    /// Reads and parses a file.
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read {}", path.display()))?;
        Self::parse(&text, &path.display().to_string())
    }
}

/// A shipped parameter set by name.
pub fn param_set(name: &str) -> Result<ParamFile> {
    let (_, text) = PARAM_SETS
        .iter()
        .find(|(n, _)| *n == name)
        .ok_or_else(|| anyhow::anyhow!("no parameter set `{name}`"))?;
    ParamFile::parse(text, &format!("params/{name}.toml"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use friction_core::CoulombParams;

    const LUGRE: &str = r#"
model = "lugre"
fc = 1.0
fs = 1.5
vs = 1e-3
sigma0 = 1e5
sigma1 = 316.2
sigma2 = 0.4

[rig]
mass = 1.0
stiffness = 2.0
pull_velocity = 0.1
"#;

    #[test]
    fn parses_lugre_with_rig() {
        let f = ParamFile::parse(LUGRE, "t").unwrap();
        let ModelSpec::LuGre(p) = f.model else {
            panic!()
        };
        assert_eq!(p.curve.exponent, 2.0);
        assert_eq!(p.sigma0, 1e5);
        assert_eq!(f.rig.stiffness, Some(2.0));
    }

    #[test]
    fn plant_table_is_read() {
        let f = ParamFile::parse(
            "model = \"coulomb-viscous\"\nfc = 20.4\nsigma2 = 203.5\n[plant]\nmass = 95.1\noffset = -3.16\n",
            "t",
        )
        .unwrap();
        assert_eq!(f.plant.mass, Some(95.1));
        assert_eq!(f.plant.offset, Some(-3.16));
        assert!(!f.plant.per_normal_force);
        let e = format!(
            "{:#}",
            ParamFile::parse(&format!("{LUGRE}\n[plant]\nmas = 1\n"), "t").unwrap_err()
        );
        assert!(e.contains("mas"), "{e}");
    }

    #[test]
    fn unknown_key_is_named_with_position() {
        let text = LUGRE.replace("sigma2 = 0.4", "sigma3 = 0.4");
        let e = format!("{:#}", ParamFile::parse(&text, "p.toml").unwrap_err());
        assert!(e.contains("sigma3"), "{e}");
        assert!(e.contains("line 8"), "{e}");
        let text = LUGRE.replace("mass = 1.0", "masss = 1.0");
        let e = format!("{:#}", ParamFile::parse(&text, "p.toml").unwrap_err());
        assert!(e.contains("masss"), "{e}");
    }

    #[test]
    fn invalid_values_are_named() {
        let text = LUGRE.replace("fs = 1.5", "fs = 0.5");
        let e = format!("{:#}", ParamFile::parse(&text, "p.toml").unwrap_err());
        assert!(e.contains("`fs`"), "{e}");
        let text = LUGRE.replace("sigma0 = 1e5", "sigma0 = -3");
        let e = format!("{:#}", ParamFile::parse(&text, "p.toml").unwrap_err());
        assert!(e.contains("sigma0"), "{e}");
        let e = format!(
            "{:#}",
            ParamFile::parse("model = \"nope\"", "p.toml").unwrap_err()
        );
        assert!(e.contains("unknown model `nope`"), "{e}");
        let e = format!("{:#}", ParamFile::parse("fc = 1", "p.toml").unwrap_err());
        assert!(e.contains("missing key `model`"), "{e}");
    }

    #[test]
    fn rig_keys_are_checked_by_name() {
        for (key, bad) in [
            ("mass = 1.0", "mass = -1"),
            ("mass = 1.0", "mass = 0"),
            ("stiffness = 2.0", "stiffness = nan"),
            ("pull_velocity = 0.1", "pull_velocity = 0"),
        ] {
            let text = LUGRE.replace(key, bad);
            let e = format!("{:#}", ParamFile::parse(&text, "p.toml").unwrap_err());
            let name = bad.split(' ').next().unwrap();
            assert!(
                e.contains(&format!("`{name}`")) && e.starts_with("p.toml"),
                "{e}"
            );
        }
        for extra in [
            "cycles = 4294967295",
            "cycles = 0",
            "frequency = 0",
            "force_rate = 0",
        ] {
            let text = format!("{LUGRE}{extra}\n");
            let e = format!("{:#}", ParamFile::parse(&text, "p.toml").unwrap_err());
            let name = extra.split(' ').next().unwrap();
            assert!(e.contains(&format!("`{name}`")), "{e}");
        }
    }

    #[test]
    fn static_maps_parse() {
        let f = ParamFile::parse("model = \"coulomb\"\nfc = 0.3", "t").unwrap();
        assert_eq!(f.model, ModelSpec::Coulomb(CoulombParams { fc: 0.3 }));
        let f = ParamFile::parse(
            "model = \"stribeck\"\nfc = 1\nfs = 2\nvs = 0.1\nstribeck_exponent = 1",
            "t",
        )
        .unwrap();
        assert_eq!(f.model.name(), "stribeck");
        let f = ParamFile::parse("model = \"dahl\"\nsigma = 1e5\nfc = 1\ndelta = 2", "t").unwrap();
        assert_eq!(f.model.name(), "dahl");
        let e = format!(
            "{:#}",
            ParamFile::parse("model = \"dahl\"\nsigma = 1e5\nfc = 1\ndelta = 0.5", "t")
                .unwrap_err()
        );
        assert!(e.contains("`delta` must be >= 1"), "{e}");
        let ep = LUGRE.replace(
            "model = \"lugre\"",
            "model = \"elasto-plastic\"\nz_ba = 2e-5",
        );
        let e = format!("{:#}", ParamFile::parse(&ep, "t").unwrap_err());
        assert!(e.contains("`z_ba` must be below `fc / sigma0`"), "{e}");
        let e = format!(
            "{:#}",
            ParamFile::parse(
                &LUGRE.replace("sigma2 = 0.4", "sigma2 = 0.4\nz_ba = 1e-6"),
                "t"
            )
            .unwrap_err()
        );
        assert!(e.contains("belongs to `elasto-plastic`"), "{e}");
        let e = format!(
            "{:#}",
            ParamFile::parse(
                &LUGRE.replace("model = \"lugre\"", "model = \"elasto-plastic\""),
                "t"
            )
            .unwrap_err()
        );
        assert!(e.contains("needs `z_ba`"), "{e}");
        let ri = "model = \"reset-integrator\"\nsigma0 = 1e5\nz0 = 1e-5\nstiction = 0.5\nfc = 1";
        let e = format!("{:#}", ParamFile::parse(ri, "t").unwrap_err());
        assert!(e.contains("needs all of"), "{e}");
        for n in [0, 65] {
            let b = format!("model = \"bristle\"\nsigma0 = 1e3\ndelta_s = 1e-5\nbristles = {n}");
            let e = format!("{:#}", ParamFile::parse(&b, "t").unwrap_err());
            assert!(e.contains("out of range") && e.contains("1 to 64"), "{e}");
        }
        let b = "model = \"bristle\"\nsigma0 = 1e3\ndelta_s = 1e-5\nbristles = 64\nseed = 3";
        assert_eq!(
            ParamFile::parse(b, "t")
                .unwrap()
                .model
                .host()
                .max_static_force(),
            64.0 * 1e3 * 1e-5
        );
    }
}
