//! LuGre (Canudas de Wit et al. 1995) on the host: file keys, the
//! continuous equations, expectations and bounds.

use super::scaled_curve;
use super::HostParams;
use super::{
    boxed, boxed_fixed, curve_g, default_exponent, from_toml, in_scalar, model_file, sign,
    Continuous, Expectations, HostModel, ScalarKind, Stepper, N, Y,
};
use crate::control::{observer_controller, Controller, Loop, ObserverRequest};
use anyhow::{bail, Result};
use friction_core::{
    Fixed32, LuGreFixedStepState, LuGreParams, LuGreState, ParamError, Scalar, StribeckParams,
};

model_file!(LuGreFile {
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
});

/// Reads the LuGre keys, and `z_ba` when `elasto_plastic`; `name` is the
/// model's, for the error messages.
pub(super) fn parse_keys(
    text: &str,
    origin: &str,
    name: &str,
    elasto_plastic: bool,
) -> Result<(LuGreParams, Option<f64>)> {
    let f: LuGreFile = from_toml(text, origin, name)?;
    if !elasto_plastic && f.z_ba.is_some() {
        bail!("{origin}: `z_ba` belongs to `elasto-plastic`, not `lugre`");
    }
    let p = LuGreParams {
        curve: StribeckParams {
            fc: f.fc,
            fs: f.fs,
            vs: f.vs,
            exponent: f.stribeck_exponent,
        },
        sigma0: f.sigma0,
        sigma1: f.sigma1,
        sigma2: f.sigma2,
        vd: f.vd,
    };
    Ok((p, f.z_ba))
}

impl HostParams for LuGreParams {
    type Spec = LuGreParams;
    fn parse(text: &str, origin: &str, name: &'static str) -> Result<LuGreParams> {
        Ok(parse_keys(text, origin, name, false)?.0)
    }
}

/// `F = sigma0 z + sigma1(v) dz/dt + sigma2 v`, shared by LuGre and elasto-plastic.
pub fn lugre_force(p: &LuGreParams, z: f64, dz: f64, v: f64) -> f64 {
    let sigma1 = match p.vd {
        Some(vd) => p.sigma1 * (-(v / vd) * (v / vd)).exp(),
        None => p.sigma1,
    };
    p.sigma0 * z + sigma1 * dz + p.sigma2 * v
}

/// `dz/dt = v - sigma0 |v| z / g(v)`.
struct LuGreOde(LuGreParams);

impl Continuous for LuGreOde {
    fn n(&self) -> usize {
        1
    }
    fn rhs(&self, z: &[f64], v: f64, dz: &mut [f64]) {
        dz[0] = v - self.0.sigma0 * v.abs() * z[0] / curve_g(&self.0.curve, v);
    }
    fn force(&self, z: &[f64], v: f64) -> f64 {
        let mut dz = [0.0];
        self.rhs(z, v, &mut dz);
        lugre_force(&self.0, z[0], dz[0], v)
    }
    fn atol(&self) -> Vec<f64> {
        vec![1e-6 * self.0.curve.fs / self.0.sigma0]
    }
    fn steady_force(&self, v: f64) -> f64 {
        curve_g(&self.0.curve, v) * sign(v) + self.0.sigma2 * v
    }
}

/// The deflection `z` as the state column.
pub(super) fn z_state<S: Scalar>(s: &LuGreState<S>) -> Vec<f64> {
    vec![s.z.to_f64()]
}

fn build<S: Scalar + 'static>(p: &LuGreParams) -> Result<Box<dyn Stepper>, ParamError> {
    Ok(boxed::<_, S>(p.build::<S>()?, &["z"], z_state::<S>))
}

impl HostModel for LuGreParams {
    /// `fc`, `fs` scaled; `sigma0` by the stiffness factor.
    fn observer_controller(
        &self,
        setup: &Loop,
        request: &ObserverRequest,
    ) -> Option<Result<Box<dyn Controller>, ParamError>> {
        Some(observer_controller(setup, request, |s, k| {
            LuGreParams {
                curve: scaled_curve(&self.curve, s),
                sigma0: self.sigma0 * k,
                ..*self
            }
            .build()
        }))
    }
    fn validate(&self) -> Result<(), ParamError> {
        LuGreParams::validate(self)
    }
    fn stepper(&self, scalar: ScalarKind) -> Result<Box<dyn Stepper>, ParamError> {
        in_scalar!(scalar, build(self))
    }
    fn fixed_stepper(&self, h: f64) -> Option<Result<Box<dyn Stepper>, ParamError>> {
        Some(self.build_fixed_step::<Fixed32>(h).map(|m| {
            boxed_fixed(m, &["w"], |s: &LuGreFixedStepState<Fixed32>| {
                vec![s.w.to_f64()]
            })
        }))
    }
    fn max_static_force(&self) -> f64 {
        self.curve.fs
    }
    fn presliding_scale(&self) -> f64 {
        self.curve.fs / self.sigma0
    }
    fn stribeck_velocity(&self) -> Option<f64> {
        Some(self.curve.vs)
    }
    fn stribeck_exponent(&self) -> Option<f64> {
        Some(self.curve.exponent)
    }
    fn sigma2(&self) -> f64 {
        self.sigma2
    }
    fn rest_damping(&self) -> f64 {
        self.sigma1 + self.sigma2
    }
    fn continuous(&self) -> Option<Box<dyn Continuous>> {
        Some(Box::new(LuGreOde(*self)))
    }
    /// stribeck, presliding, lag, break-away, stick-slip, drift: yes; rate independence: no.
    fn expectations(&self) -> Expectations {
        Expectations {
            stribeck: Y,
            presliding: Y,
            frictional_lag: Y,
            breakaway: Y,
            stick_slip: Y,
            drift: Y,
            rate_independence: N,
            nonlocal_memory: N,
        }
    }
    /// Plotted against the reference.
    fn validation_plots(&self) -> bool {
        true
    }
    /// The drift and servo sets, reported.
    fn reported_sets(&self) -> &'static [&'static str] {
        &["astrom2008-drift", "olsson1998-servo"]
    }
    /// The `sigma1(v)` form with `vd = vs` (reported), and the three static
    /// maps on the same curve (bounded).
    fn validation_variants(&self) -> Vec<super::Variant> {
        use friction_core::{CoulombParams, CoulombViscousParams, StribeckMapParams};
        let variant = |suffix: &str, spec, bounded| super::Variant {
            suffix: suffix.into(),
            spec,
            bounded,
            plots: false,
        };
        vec![
            variant(
                "+vd",
                super::ModelSpec::LuGre(LuGreParams {
                    vd: Some(self.curve.vs),
                    ..*self
                }),
                false,
            ),
            variant(
                "",
                super::ModelSpec::Coulomb(CoulombParams { fc: self.curve.fc }),
                true,
            ),
            variant(
                "",
                super::ModelSpec::CoulombViscous(CoulombViscousParams {
                    fc: self.curve.fc,
                    sigma2: self.sigma2,
                }),
                true,
            ),
            variant(
                "",
                super::ModelSpec::Stribeck(StribeckMapParams {
                    curve: self.curve,
                    sigma2: self.sigma2,
                }),
                true,
            ),
        ]
    }
    /// 2 % at 1 kHz, 0.5 % at 10 kHz (set for the canudas1995 parameters).
    fn accuracy_bound(&self, h: f64) -> Option<f64> {
        Some(if h >= 1e-3 { 0.02 } else { 0.005 })
    }
}
