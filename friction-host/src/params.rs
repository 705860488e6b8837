//! Parameter files (TOML): `model = "..."`, the model's keys, and an
//! optional `[rig]` table for the experiments and `[servo]` table for
//! `friction servo`. Unknown keys are errors that
//! name the key, with line and column.

use crate::servo::ServoTable;
use anyhow::{bail, Context, Result};
use friction_core::{
    BristleParams, CoulombParams, CoulombViscousParams, DahlParams, ElastoPlasticParams,
    LuGreParams, ResetIntegratorParams, StribeckMapParams, StribeckParams,
};
use serde::Deserialize;
use std::path::Path;

/// A model of the library with its parameters.
#[derive(Clone, Debug, PartialEq)]
pub enum ModelSpec {
    /// `coulomb`: `fc`.
    Coulomb(CoulombParams),
    /// `coulomb-viscous`: `fc`, `sigma2`.
    CoulombViscous(CoulombViscousParams),
    /// `stribeck`: `fc`, `fs`, `vs`, `stribeck_exponent`, `sigma2`.
    Stribeck(StribeckMapParams),
    /// `lugre`: `fc`, `fs`, `vs`, `stribeck_exponent`, `sigma0`, `sigma1`, `sigma2`, `vd`.
    LuGre(LuGreParams),
    /// `dahl`: `sigma`, `fc`, `delta`, `sigma2`.
    Dahl(DahlParams),
    /// `elasto-plastic`: the LuGre keys and `z_ba`.
    ElastoPlastic(ElastoPlasticParams),
    /// `reset-integrator`: `sigma0`, `sigma1`, `z0`, `stiction`, optional Stribeck keys.
    ResetIntegrator(ResetIntegratorParams),
    /// `bristle`: `sigma0`, `delta_s`, `bristles` (one of [`BRISTLE_COUNTS`]), `seed`.
    Bristle {
        /// The parameters.
        params: BristleParams,
        /// Number of bristles `N`.
        bristles: usize,
    },
}

/// The bristle counts the host offers (the core takes any `N >= 1` as a const generic).
pub const BRISTLE_COUNTS: &[usize] = &[1, 8, 25, 64];

impl ModelSpec {
    /// The `model = "..."` name.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Coulomb(_) => "coulomb",
            Self::CoulombViscous(_) => "coulomb-viscous",
            Self::Stribeck(_) => "stribeck",
            Self::LuGre(_) => "lugre",
            Self::Dahl(_) => "dahl",
            Self::ElastoPlastic(_) => "elasto-plastic",
            Self::ResetIntegrator(_) => "reset-integrator",
            Self::Bristle { .. } => "bristle",
        }
    }

    /// The static friction level: the largest force the model holds at rest
    /// (`Fs` for Stribeck-shaped models, `Fc` for Coulomb).
    pub fn max_static_force(&self) -> f64 {
        match self {
            Self::Coulomb(p) => p.fc,
            Self::CoulombViscous(p) => p.fc,
            Self::Stribeck(p) => p.curve.fs,
            Self::LuGre(p) => p.curve.fs,
            Self::Dahl(p) => p.fc,
            Self::ElastoPlastic(p) => p.lugre.curve.fs,
            Self::ResetIntegrator(p) => (1.0 + p.stiction) * p.sigma0 * p.z0,
            Self::Bristle { params, bristles } => *bristles as f64 * params.sigma0 * params.delta_s,
        }
    }

    /// The pre-sliding displacement scale: how far the contact deflects
    /// before it slides (`Fs/sigma0` for LuGre, `Fc/sigma` for Dahl); 0 for
    /// static maps.
    pub fn presliding_scale(&self) -> f64 {
        match self {
            Self::LuGre(p) => p.curve.fs / p.sigma0,
            Self::Dahl(p) => p.fc / p.sigma,
            Self::ElastoPlastic(p) => p.lugre.curve.fs / p.lugre.sigma0,
            Self::ResetIntegrator(p) => p.z0,
            Self::Bristle { params, .. } => params.delta_s,
            _ => 0.0,
        }
    }

    /// The viscous coefficient `sigma2` (0 for `coulomb`).
    pub fn sigma2(&self) -> f64 {
        match self {
            Self::Coulomb(_) => 0.0,
            Self::CoulombViscous(p) => p.sigma2,
            Self::Stribeck(p) => p.sigma2,
            Self::LuGre(p) => p.sigma2,
            Self::Dahl(p) => p.sigma2,
            Self::ElastoPlastic(p) => p.lugre.sigma2,
            Self::ResetIntegrator(_) | Self::Bristle { .. } => 0.0,
        }
    }

    /// Whether the model has internal state (and so pre-sliding, rigs, ...).
    pub fn has_state(&self) -> bool {
        !matches!(
            self,
            Self::Coulomb(_) | Self::CoulombViscous(_) | Self::Stribeck(_)
        )
    }

    /// Validates the parameters (the core's checks), naming the offending one.
    pub fn validate(&self) -> Result<(), friction_core::ParamError> {
        match self {
            Self::Coulomb(p) => p.build::<f64>().map(|_| ()),
            Self::CoulombViscous(p) => p.build::<f64>().map(|_| ()),
            Self::Stribeck(p) => p.build::<f64>().map(|_| ()),
            Self::LuGre(p) => p.validate(),
            Self::Dahl(p) => p.validate(),
            Self::ElastoPlastic(p) => p.validate(),
            Self::ResetIntegrator(p) => p.validate(),
            Self::Bristle { params, .. } => params.validate(),
        }
    }
}

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

/// A parsed parameter file.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamFile {
    /// The model.
    pub model: ModelSpec,
    /// The rig, if the file has a `[rig]` table.
    pub rig: Rig,
    /// The `[servo]` table of `friction servo` (every key optional).
    pub servo: ServoTable,
}

#[derive(Deserialize)]
struct Probe {
    model: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CoulombFile {
    #[allow(dead_code)]
    model: String,
    fc: f64,
    #[serde(default)]
    rig: Rig,
    #[serde(default)]
    servo: ServoTable,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CoulombViscousFile {
    #[allow(dead_code)]
    model: String,
    fc: f64,
    sigma2: f64,
    #[serde(default)]
    rig: Rig,
    #[serde(default)]
    servo: ServoTable,
}

fn default_exponent() -> f64 {
    StribeckParams::DEFAULT_EXPONENT
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct StribeckFile {
    #[allow(dead_code)]
    model: String,
    fc: f64,
    fs: f64,
    vs: f64,
    #[serde(default = "default_exponent")]
    stribeck_exponent: f64,
    #[serde(default)]
    sigma2: f64,
    #[serde(default)]
    rig: Rig,
    #[serde(default)]
    servo: ServoTable,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LuGreFile {
    #[allow(dead_code)]
    model: String,
    fc: f64,
    fs: f64,
    vs: f64,
    #[serde(default = "default_exponent")]
    stribeck_exponent: f64,
    sigma0: f64,
    sigma1: f64,
    #[serde(default)]
    sigma2: f64,
    vd: Option<f64>,
    /// Only for `elasto-plastic`.
    z_ba: Option<f64>,
    #[serde(default)]
    rig: Rig,
    #[serde(default)]
    servo: ServoTable,
}

impl LuGreFile {
    fn params(&self) -> LuGreParams {
        LuGreParams {
            curve: StribeckParams {
                fc: self.fc,
                fs: self.fs,
                vs: self.vs,
                exponent: self.stribeck_exponent,
            },
            sigma0: self.sigma0,
            sigma1: self.sigma1,
            sigma2: self.sigma2,
            vd: self.vd,
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DahlFile {
    #[allow(dead_code)]
    model: String,
    sigma: f64,
    fc: f64,
    #[serde(default = "one")]
    delta: f64,
    #[serde(default)]
    sigma2: f64,
    #[serde(default)]
    rig: Rig,
    #[serde(default)]
    servo: ServoTable,
}

fn one() -> f64 {
    1.0
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ResetIntegratorFile {
    #[allow(dead_code)]
    model: String,
    sigma0: f64,
    #[serde(default)]
    sigma1: f64,
    z0: f64,
    #[serde(default)]
    stiction: f64,
    fc: Option<f64>,
    fs: Option<f64>,
    vs: Option<f64>,
    stribeck_exponent: Option<f64>,
    #[serde(default)]
    rig: Rig,
    #[serde(default)]
    servo: ServoTable,
}

fn default_bristles() -> usize {
    25
}

fn default_seed() -> u64 {
    1
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BristleFile {
    #[allow(dead_code)]
    model: String,
    sigma0: f64,
    delta_s: f64,
    #[serde(default = "default_bristles")]
    bristles: usize,
    #[serde(default = "default_seed")]
    seed: u64,
    #[serde(default)]
    rig: Rig,
    #[serde(default)]
    servo: ServoTable,
}

/// The model names a file may give.
pub const MODEL_NAMES: &[&str] = &[
    "coulomb",
    "coulomb-viscous",
    "stribeck",
    "lugre",
    "dahl",
    "elasto-plastic",
    "reset-integrator",
    "bristle",
];

impl ParamFile {
    /// Parses TOML text; `origin` names the source in messages.
    pub fn parse(text: &str, origin: &str) -> Result<Self> {
        let probe: Probe =
            toml::from_str(text).with_context(|| format!("{origin}: not valid TOML"))?;
        let Some(name) = probe.model else {
            bail!(
                "{origin}: missing key `model` (one of {})",
                MODEL_NAMES.join(", ")
            );
        };
        let ctx = || format!("{origin}: invalid `{name}` parameters");
        let file = match name.as_str() {
            "coulomb" => {
                let f: CoulombFile = toml::from_str(text).with_context(ctx)?;
                ParamFile {
                    model: ModelSpec::Coulomb(CoulombParams { fc: f.fc }),
                    rig: f.rig,
                    servo: f.servo,
                }
            }
            "coulomb-viscous" => {
                let f: CoulombViscousFile = toml::from_str(text).with_context(ctx)?;
                ParamFile {
                    model: ModelSpec::CoulombViscous(CoulombViscousParams {
                        fc: f.fc,
                        sigma2: f.sigma2,
                    }),
                    rig: f.rig,
                    servo: f.servo,
                }
            }
            "stribeck" => {
                let f: StribeckFile = toml::from_str(text).with_context(ctx)?;
                let curve = StribeckParams {
                    fc: f.fc,
                    fs: f.fs,
                    vs: f.vs,
                    exponent: f.stribeck_exponent,
                };
                ParamFile {
                    model: ModelSpec::Stribeck(StribeckMapParams {
                        curve,
                        sigma2: f.sigma2,
                    }),
                    rig: f.rig,
                    servo: f.servo,
                }
            }
            "lugre" => {
                let f: LuGreFile = toml::from_str(text).with_context(ctx)?;
                if f.z_ba.is_some() {
                    bail!("{origin}: `z_ba` belongs to `elasto-plastic`, not `lugre`");
                }
                ParamFile {
                    model: ModelSpec::LuGre(f.params()),
                    rig: f.rig,
                    servo: f.servo,
                }
            }
            "dahl" => {
                let f: DahlFile = toml::from_str(text).with_context(ctx)?;
                ParamFile {
                    model: ModelSpec::Dahl(DahlParams {
                        sigma: f.sigma,
                        fc: f.fc,
                        delta: f.delta,
                        sigma2: f.sigma2,
                    }),
                    rig: f.rig,
                    servo: f.servo,
                }
            }
            "elasto-plastic" => {
                let f: LuGreFile = toml::from_str(text).with_context(ctx)?;
                let Some(z_ba) = f.z_ba else {
                    bail!("{origin}: `elasto-plastic` needs `z_ba` (the break-away deflection)");
                };
                ParamFile {
                    model: ModelSpec::ElastoPlastic(ElastoPlasticParams {
                        lugre: f.params(),
                        z_ba,
                    }),
                    rig: f.rig,
                    servo: f.servo,
                }
            }
            "reset-integrator" => {
                let f: ResetIntegratorFile = toml::from_str(text).with_context(ctx)?;
                let curve = match (f.fc, f.fs, f.vs) {
                    (Some(fc), Some(fs), Some(vs)) => Some(StribeckParams {
                        fc,
                        fs,
                        vs,
                        exponent: f.stribeck_exponent.unwrap_or(StribeckParams::DEFAULT_EXPONENT),
                    }),
                    (None, None, None) if f.stribeck_exponent.is_none() => None,
                    _ => bail!("{origin}: the Stribeck shape of `reset-integrator` needs all of `fc`, `fs`, `vs` (or none)"),
                };
                ParamFile {
                    model: ModelSpec::ResetIntegrator(ResetIntegratorParams {
                        sigma0: f.sigma0,
                        sigma1: f.sigma1,
                        z0: f.z0,
                        stiction: f.stiction,
                        curve,
                    }),
                    rig: f.rig,
                    servo: f.servo,
                }
            }
            "bristle" => {
                let f: BristleFile = toml::from_str(text).with_context(ctx)?;
                if !BRISTLE_COUNTS.contains(&f.bristles) {
                    bail!(
                        "{origin}: `bristles` = {} is not offered; choose one of {:?}",
                        f.bristles,
                        BRISTLE_COUNTS
                    );
                }
                ParamFile {
                    model: ModelSpec::Bristle {
                        params: BristleParams {
                            sigma0: f.sigma0,
                            delta_s: f.delta_s,
                            seed: f.seed,
                        },
                        bristles: f.bristles,
                    },
                    rig: f.rig,
                    servo: f.servo,
                }
            }
            other => bail!(
                "{origin}: unknown model `{other}` (expected one of {})",
                MODEL_NAMES.join(", ")
            ),
        };
        file.model
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

#[cfg(test)]
mod tests {
    use super::*;

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
        let b = "model = \"bristle\"\nsigma0 = 1e3\ndelta_s = 1e-5\nbristles = 7";
        let e = format!("{:#}", ParamFile::parse(b, "t").unwrap_err());
        assert!(e.contains("not offered"), "{e}");
        let b = "model = \"bristle\"\nsigma0 = 1e3\ndelta_s = 1e-5\nbristles = 64\nseed = 3";
        assert_eq!(
            ParamFile::parse(b, "t").unwrap().model.max_static_force(),
            64.0 * 1e3 * 1e-5
        );
    }
}
