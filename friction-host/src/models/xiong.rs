//! The multistate model of Xiong, Kikuuwe and Yamamoto (~2013) on the host:
//! file keys, the continuous equations, expectations and bounds.

use super::gms::with_count;
use super::HostParams;
use super::{
    boxed, boxed_fixed, curve_g, default_exponent, from_toml, in_scalar, model_file, sign,
    Continuous, Expectations, HostModel, ScalarKind, Stepper, N, Y,
};
use crate::control::{observer_controller, Controller, Loop, ObserverRequest};
use anyhow::{bail, Result};
use friction_core::{
    Fixed32, ParamError, Scalar, StribeckParams, Xiong, XiongElement, XiongFixedStepState,
    XiongParams, XiongState,
};

/// Xiong parameters with any number of elements (1 to 16 on the host).
#[derive(Clone, Debug, PartialEq)]
pub struct XiongSpec {
    /// The Stribeck curve.
    pub curve: StribeckParams,
    /// Lag time `tau` (s).
    pub tau: f64,
    /// Viscous friction `sigma2`.
    pub sigma2: f64,
    /// The elements.
    pub elements: Vec<XiongElement>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct ElementFile {
    k: f64,
    sigma: f64,
    lambda: f64,
}

model_file!(XiongFile {
    fc: f64,
    fs: f64,
    vs: f64,
    #[serde(default = "default_exponent")]
    stribeck_exponent: f64,
    tau: f64,
    #[serde(default)]
    sigma2: f64,
    elements: Vec<ElementFile>,
});

impl<const N: usize> HostParams for XiongParams<N> {
    type Spec = XiongSpec;
    fn parse(text: &str, origin: &str, name: &'static str) -> Result<XiongSpec> {
        let f: XiongFile = from_toml(text, origin, name)?;
        if !(1..=super::gms::MAX_ELEMENTS).contains(&f.elements.len()) {
            bail!(
            "{origin}: {} `[[elements]]` tables: the host runs the Xiong model with 1 to {} elements",
            f.elements.len(),
            super::gms::MAX_ELEMENTS
        );
        }
        Ok(XiongSpec {
            curve: StribeckParams {
                fc: f.fc,
                fs: f.fs,
                vs: f.vs,
                exponent: f.stribeck_exponent,
            },
            tau: f.tau,
            sigma2: f.sigma2,
            elements: f
                .elements
                .iter()
                .map(|e| XiongElement {
                    k: e.k,
                    sigma: e.sigma,
                    lambda: e.lambda,
                })
                .collect(),
        })
    }
}

impl XiongSpec {
    /// The core's parameters with `K` elements (`None` if the count differs).
    pub fn params<const K: usize>(&self) -> Option<XiongParams<K>> {
        Some(XiongParams {
            curve: self.curve,
            tau: self.tau,
            sigma2: self.sigma2,
            elements: self.elements.as_slice().try_into().ok()?,
        })
    }
}

const TOO_MANY: ParamError = ParamError::NotBelow {
    name: "elements",
    limit: "17",
};

/// `gamma`, then the deflections `z_i`.
fn states<S: Scalar, const K: usize>(s: &XiongState<S, K>) -> Vec<f64> {
    // gamma is not in the state alone (lag = Fs - gamma): report lag
    let mut out = vec![s.lag.to_f64()];
    out.extend(s.z.iter().map(|x| x.to_f64()));
    out
}

fn build_n<S: Scalar + 'static, const K: usize>(
    spec: &XiongSpec,
) -> Result<Box<dyn Stepper>, ParamError> {
    let p = spec.params::<K>().ok_or(TOO_MANY)?;
    let mut names = vec!["lag".to_string()];
    names.extend((0..K).map(|i| format!("z{i}")));
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    Ok(boxed::<Xiong<S, K>, S>(
        p.build::<S>()?,
        &names,
        states::<S, K>,
    ))
}

fn build<S: Scalar + 'static>(spec: &XiongSpec) -> Result<Box<dyn Stepper>, ParamError> {
    with_count!(spec, build_n, S)
}

/// `lag`, then the element forces `w_i` (times the model's force scale).
fn fixed_states<const K: usize>(s: &XiongFixedStepState<Fixed32, K>) -> Vec<f64> {
    let mut out = vec![s.lag.to_f64()];
    out.extend(s.w.iter().map(|x| x.to_f64()));
    out
}

fn build_fixed_n<const K: usize>(spec: &XiongSpec, h: f64) -> Result<Box<dyn Stepper>, ParamError> {
    let p = spec.params::<K>().ok_or(TOO_MANY)?;
    let mut names = vec!["lag".to_string()];
    names.extend((0..K).map(|i| format!("w{i}")));
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    Ok(boxed_fixed(
        p.build_fixed_step::<Fixed32>(h)?,
        &names,
        fixed_states::<K>,
    ))
}

fn validate_n<const K: usize>(spec: &XiongSpec) -> Result<(), ParamError> {
    spec.params::<K>().ok_or(TOO_MANY)?.validate()
}

/// The Xiong ODE with states `(w, z_1..z_N)`, `w = Fs - gamma` (0 at rest,
/// where `gamma = Fs`, so that the solver's zero initial state is the rest
/// state): `dw/dt = (Fs - w - g(v)) / tau`,
/// `dz_i/dt = (sat(lambda_i gamma, K_i z_i + sigma_i v) - K_i z_i) / sigma_i`.
struct XiongOde(XiongSpec);

impl XiongOde {
    fn element_force(e: &XiongElement, gamma: f64, z: f64, v: f64) -> f64 {
        let cap = e.lambda * gamma;
        (e.k * z + e.sigma * v).clamp(-cap, cap)
    }
}

impl Continuous for XiongOde {
    fn n(&self) -> usize {
        1 + self.0.elements.len()
    }
    fn rhs(&self, z: &[f64], v: f64, dz: &mut [f64]) {
        let fs = self.0.curve.fs;
        let gamma = fs - z[0];
        dz[0] = (fs - z[0] - curve_g(&self.0.curve, v)) / self.0.tau;
        for (i, e) in self.0.elements.iter().enumerate() {
            let f = Self::element_force(e, gamma, z[i + 1], v);
            dz[i + 1] = (f - e.k * z[i + 1]) / e.sigma;
        }
    }
    fn force(&self, z: &[f64], v: f64) -> f64 {
        let gamma = self.0.curve.fs - z[0];
        let mut total = self.0.sigma2 * v;
        for (i, e) in self.0.elements.iter().enumerate() {
            total += Self::element_force(e, gamma, z[i + 1], v);
        }
        total
    }
    fn atol(&self) -> Vec<f64> {
        let fs = self.0.curve.fs;
        let mut out = vec![1e-9 * fs];
        out.extend(self.0.elements.iter().map(|e| 1e-6 * e.lambda * fs / e.k));
        out
    }
    fn steady_force(&self, v: f64) -> f64 {
        curve_g(&self.0.curve, v) * sign(v) + self.0.sigma2 * v
    }
}

/// The observer controller with `K` elements (`fc`, `fs` scaled, the element
/// stiffnesses by the stiffness factor).
fn observer_n<const K: usize>(
    spec: &XiongSpec,
    setup: &Loop,
    request: &ObserverRequest,
) -> Result<Box<dyn Controller>, ParamError> {
    let p = spec.params::<K>().ok_or(ParamError::NotBelow {
        name: "elements",
        limit: "17",
    })?;
    observer_controller(setup, request, |s, k| {
        let mut q = XiongParams {
            curve: super::scaled_curve(&p.curve, s),
            ..p
        };
        for e in &mut q.elements {
            e.k *= k;
        }
        q.build::<f64>()
    })
}

impl HostModel for XiongSpec {
    /// See `observer_n`.
    fn observer_controller(
        &self,
        setup: &Loop,
        request: &ObserverRequest,
    ) -> Option<Result<Box<dyn Controller>, ParamError>> {
        Some(with_count!(self, observer_n; setup, request))
    }
    fn validate(&self) -> Result<(), ParamError> {
        with_count!(self, validate_n)
    }
    fn stepper(&self, scalar: ScalarKind) -> Result<Box<dyn Stepper>, ParamError> {
        in_scalar!(scalar, build(self))
    }
    /// `XiongFixedStep` in Q16.16.
    fn fixed_stepper(&self, h: f64) -> Option<Result<Box<dyn Stepper>, ParamError>> {
        Some(with_count!(self, build_fixed_n; h))
    }
    fn max_static_force(&self) -> f64 {
        self.curve.fs
    }
    /// The largest element deflection before it saturates, `max_i lambda_i Fs / K_i`.
    fn presliding_scale(&self) -> f64 {
        self.elements
            .iter()
            .map(|e| e.lambda * self.curve.fs / e.k)
            .fold(0.0, f64::max)
    }
    fn stribeck_velocity(&self) -> Option<f64> {
        Some(self.curve.vs)
    }
    /// The sum of the element stiffnesses (all stick at rest).
    fn rest_stiffness(&self) -> f64 {
        self.elements.iter().map(|e| e.k).sum()
    }
    /// The lag state's `tau`.
    fn lag_time(&self, _v: f64) -> f64 {
        self.tau
    }
    fn sigma2(&self) -> f64 {
        self.sigma2
    }
    fn continuous(&self) -> Option<Box<dyn Continuous>> {
        Some(Box::new(XiongOde(self.clone())))
    }
    /// stribeck, presliding, lag, break-away, stick-slip: yes; drift: no
    /// (measured by the drift experiment); rate independence: no.
    fn expectations(&self) -> Expectations {
        Expectations {
            stribeck: Y,
            presliding: Y,
            frictional_lag: Y,
            breakaway: Y,
            stick_slip: Y,
            drift: N,
            rate_independence: N,
            nonlocal_memory: Y,
        }
    }
    /// Plotted against the reference.
    fn validation_plots(&self) -> bool {
        true
    }
    /// 3 % at 1 kHz, 1 % at 10 kHz.
    fn accuracy_bound(&self, h: f64) -> Option<f64> {
        Some(if h >= 1e-3 { 0.03 } else { 0.01 })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The module's parser, as the registry calls it.
    fn parse(text: &str, origin: &str) -> Result<XiongSpec> {
        <XiongParams<1> as HostParams>::parse(text, origin, "xiong")
    }

    #[test]
    fn rejects_unknown_keys_in_elements() {
        let ok = "model = \"xiong\"\nfc = 1\nfs = 1.5\nvs = 1e-3\ntau = 0.01\n[[elements]]\nk = 1e5\nsigma = 10\nlambda = 1\n";
        assert!(parse(ok, "t").is_ok());
        let bad = format!("{ok}alpha = 2\n");
        let e = format!("{:#}", parse(&bad, "t").unwrap_err());
        assert!(e.contains("alpha") && e.contains("line"), "{e}");
    }
}
