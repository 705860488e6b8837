//! The static maps: Coulomb, Coulomb + viscous (symmetric and asymmetric)
//! and the Stribeck map. No state: their reference is the map itself,
//! evaluated independently here, and only the steady-state experiment
//! applies.

use super::HostParams;
use super::{
    boxed, default_exponent, from_toml, in_scalar, model_file, sign, stribeck, Continuous,
    HostModel, ScalarKind, Stepper,
};
use anyhow::Result;
use friction_core::{
    AsymmetricCoulombViscousParams, CoulombParams, CoulombViscousParams, ParamError, Scalar,
    StribeckMapParams, StribeckParams,
};

model_file!(CoulombFile { fc: f64 });
model_file!(CoulombViscousFile {
    fc: f64,
    sigma2: f64,
});
model_file!(AsymmetricCoulombViscousFile {
    fc_pos: f64,
    sigma2_pos: f64,
    fc_neg: f64,
    sigma2_neg: f64,
});
model_file!(StribeckFile {
    fc: f64,
    fs: f64,
    vs: f64,
    #[serde(default = "default_exponent")]
    stribeck_exponent: f64,
    #[serde(default)]
    sigma2: f64,
});

impl HostParams for CoulombParams {
    type Spec = Self;
    fn parse(text: &str, origin: &str, name: &'static str) -> Result<Self> {
        let f: CoulombFile = from_toml(text, origin, name)?;
        Ok(CoulombParams { fc: f.fc })
    }
}

impl HostParams for CoulombViscousParams {
    type Spec = Self;
    fn parse(text: &str, origin: &str, name: &'static str) -> Result<Self> {
        let f: CoulombViscousFile = from_toml(text, origin, name)?;
        Ok(CoulombViscousParams {
            fc: f.fc,
            sigma2: f.sigma2,
        })
    }
}

impl HostParams for StribeckMapParams {
    type Spec = Self;
    fn parse(text: &str, origin: &str, name: &'static str) -> Result<Self> {
        let f: StribeckFile = from_toml(text, origin, name)?;
        Ok(StribeckMapParams {
            curve: StribeckParams {
                fc: f.fc,
                fs: f.fs,
                vs: f.vs,
                exponent: f.stribeck_exponent,
            },
            sigma2: f.sigma2,
        })
    }
}

/// `F = g(v) sign(v) + sigma2 v`, with `g = Fc` for the Coulomb maps.
struct StaticMap {
    fc: f64,
    fs: f64,
    vs: f64,
    delta: f64,
    sigma2: f64,
}

impl Continuous for StaticMap {
    fn n(&self) -> usize {
        0
    }
    fn rhs(&self, _: &[f64], _: f64, _: &mut [f64]) {}
    fn force(&self, _: &[f64], v: f64) -> f64 {
        self.steady_force(v)
    }
    fn atol(&self) -> Vec<f64> {
        Vec::new()
    }
    fn steady_force(&self, v: f64) -> f64 {
        stribeck(self.fc, self.fs, self.vs, self.delta, v) * sign(v) + self.sigma2 * v
    }
}

fn no_states(_: &()) -> Vec<f64> {
    Vec::new()
}

/// Static maps are evaluated exactly at the sample: only rounding is left.
const EXACT: f64 = 1e-9;

macro_rules! static_map {
    ($params:ty, $build:ident, $map:expr) => {
        impl HostModel for $params {
            fn validate(&self) -> Result<(), ParamError> {
                self.build::<f64>().map(|_| ())
            }
            fn stepper(&self, scalar: ScalarKind) -> Result<Box<dyn Stepper>, ParamError> {
                fn $build<S: Scalar + 'static>(
                    p: &$params,
                ) -> Result<Box<dyn Stepper>, ParamError> {
                    Ok(boxed::<_, S>(p.build::<S>()?, &[], no_states))
                }
                in_scalar!(scalar, $build(self))
            }
            fn max_static_force(&self) -> f64 {
                let m: StaticMap = $map(self);
                m.fs
            }
            fn sigma2(&self) -> f64 {
                let m: StaticMap = $map(self);
                m.sigma2
            }
            fn has_state(&self) -> bool {
                false
            }
            fn continuous(&self) -> Option<Box<dyn Continuous>> {
                Some(Box::new($map(self)))
            }
            fn accuracy_bound(&self, _h: f64) -> Option<f64> {
                Some(EXACT)
            }
        }
    };
}

static_map!(CoulombParams, build_coulomb, |p: &CoulombParams| {
    StaticMap {
        fc: p.fc,
        fs: p.fc,
        vs: 1.0,
        delta: 1.0,
        sigma2: 0.0,
    }
});
static_map!(
    CoulombViscousParams,
    build_coulomb_viscous,
    |p: &CoulombViscousParams| StaticMap {
        fc: p.fc,
        fs: p.fc,
        vs: 1.0,
        delta: 1.0,
        sigma2: p.sigma2,
    }
);
static_map!(
    StribeckMapParams,
    build_stribeck,
    |p: &StribeckMapParams| StaticMap {
        fc: p.curve.fc,
        fs: p.curve.fs,
        vs: p.curve.vs,
        delta: p.curve.exponent,
        sigma2: p.sigma2,
    }
);

impl HostParams for AsymmetricCoulombViscousParams {
    type Spec = Self;
    fn parse(text: &str, origin: &str, name: &'static str) -> Result<Self> {
        let f: AsymmetricCoulombViscousFile = from_toml(text, origin, name)?;
        Ok(AsymmetricCoulombViscousParams {
            fc_pos: f.fc_pos,
            sigma2_pos: f.sigma2_pos,
            fc_neg: f.fc_neg,
            sigma2_neg: f.sigma2_neg,
        })
    }
}

/// The asymmetric map, written again from its definition (each side's
/// Coulomb level and slope) for the reference.
struct AsymmetricMap(AsymmetricCoulombViscousParams);

impl Continuous for AsymmetricMap {
    fn n(&self) -> usize {
        0
    }
    fn rhs(&self, _: &[f64], _: f64, _: &mut [f64]) {}
    fn force(&self, _: &[f64], v: f64) -> f64 {
        self.steady_force(v)
    }
    fn atol(&self) -> Vec<f64> {
        Vec::new()
    }
    fn steady_force(&self, v: f64) -> f64 {
        let p = &self.0;
        if v > 0.0 {
            p.fc_pos + p.sigma2_pos * v
        } else if v < 0.0 {
            -p.fc_neg + p.sigma2_neg * v
        } else {
            0.0
        }
    }
}

fn build_asymmetric<S: Scalar + 'static>(
    p: &AsymmetricCoulombViscousParams,
) -> Result<Box<dyn Stepper>, ParamError> {
    Ok(boxed::<_, S>(p.build::<S>()?, &[], no_states))
}

impl HostModel for AsymmetricCoulombViscousParams {
    fn validate(&self) -> Result<(), ParamError> {
        self.build::<f64>().map(|_| ())
    }
    fn stepper(&self, scalar: ScalarKind) -> Result<Box<dyn Stepper>, ParamError> {
        in_scalar!(scalar, build_asymmetric(self))
    }
    /// The larger side's Coulomb level (the map holds no force at rest:
    /// this is the scale its errors are judged on).
    fn max_static_force(&self) -> f64 {
        self.fc_pos.max(self.fc_neg)
    }
    /// The mean of the sides' slopes: the one `sigma2` of a symmetric
    /// map fitted to both directions.
    fn sigma2(&self) -> f64 {
        0.5 * (self.sigma2_pos + self.sigma2_neg)
    }
    /// The mean of the sides' levels, as [`HostModel::sigma2`] (the default
    /// reads the `v > 0` side only).
    fn coulomb_level(&self) -> f64 {
        0.5 * (self.fc_pos + self.fc_neg)
    }
    fn has_state(&self) -> bool {
        false
    }
    fn continuous(&self) -> Option<Box<dyn Continuous>> {
        Some(Box::new(AsymmetricMap(*self)))
    }
    fn accuracy_bound(&self, _h: f64) -> Option<f64> {
        Some(EXACT)
    }
}
