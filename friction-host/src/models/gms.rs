//! The generalized Maxwell-slip model, GMS (Lampaert, Al-Bender, Swevers
//! 2003; Al-Bender et al. 2005), on the host: file keys, its own reference,
//! expectations and bounds.
//!
//! Its elements switch between sticking and slipping, with memory, so its
//! reference is not a smooth ODE for the BDF solver: [`gms_reference`]
//! integrates the equations of the model sheet along the continuous signal
//! with a fine fixed sub-step, and locates every switching instant inside
//! its sub-step (written here from the sheet, sharing no code with the
//! core's step).

use super::HostParams;
use super::ReferenceRun;
use super::{
    boxed, boxed_fixed, curve_g, default_exponent, from_toml, in_scalar, model_file, Expectations,
    HostModel, ScalarKind, Stepper, N, Y,
};
use crate::control::{observer_controller, Controller, Loop, ObserverRequest};
use crate::signals::Signal;
use anyhow::{bail, Result};
use friction_core::{
    Fixed32, Gms, GmsElement, GmsParams, GmsState, ParamError, Scalar, StribeckParams,
};

/// The largest element count the host dispatches onto the core's const
/// generic `N` (every count from 1 to this; the core takes any `N >= 1`).
pub const MAX_ELEMENTS: usize = 16;

/// The reference's default sub-step (s).
pub const GMS_REFERENCE_STEP: f64 = 1e-5;

/// GMS parameters with any number of elements (1 to [`MAX_ELEMENTS`] on the host).
#[derive(Clone, Debug, PartialEq)]
pub struct GmsSpec {
    /// The Stribeck curve.
    pub curve: StribeckParams,
    /// Viscous friction `sigma2`.
    pub sigma2: f64,
    /// Attraction rate `C` (N/s).
    pub c: f64,
    /// The elements.
    pub elements: Vec<GmsElement>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct ElementFile {
    k: f64,
    alpha: f64,
    #[serde(default)]
    sigma1: f64,
}

model_file!(GmsFile {
    fc: f64,
    fs: f64,
    vs: f64,
    #[serde(default = "default_exponent")]
    stribeck_exponent: f64,
    #[serde(default)]
    sigma2: f64,
    c: f64,
    elements: Vec<ElementFile>,
});

impl<const N: usize> HostParams for GmsParams<N> {
    type Spec = GmsSpec;
    fn parse(text: &str, origin: &str, name: &'static str) -> Result<GmsSpec> {
        let f: GmsFile = from_toml(text, origin, name)?;
        if !(1..=MAX_ELEMENTS).contains(&f.elements.len()) {
            bail!(
            "{origin}: {} `[[elements]]` tables: the host runs GMS with 1 to {MAX_ELEMENTS} elements",
            f.elements.len()
        );
        }
        Ok(GmsSpec {
            curve: StribeckParams {
                fc: f.fc,
                fs: f.fs,
                vs: f.vs,
                exponent: f.stribeck_exponent,
            },
            sigma2: f.sigma2,
            c: f.c,
            elements: f
                .elements
                .iter()
                .map(|e| GmsElement {
                    k: e.k,
                    alpha: e.alpha,
                    sigma1: e.sigma1,
                })
                .collect(),
        })
    }
}

impl GmsSpec {
    /// The core's parameters with `K` elements (`None` if the count differs).
    pub fn params<const K: usize>(&self) -> Option<GmsParams<K>> {
        Some(GmsParams {
            curve: self.curve,
            sigma2: self.sigma2,
            c: self.c,
            elements: self.elements.as_slice().try_into().ok()?,
        })
    }
}

/// Element forces, then modes (0 stick, 1 forward, -1 backward).
fn states<S: Scalar, const K: usize>(s: &GmsState<S, K>) -> Vec<f64> {
    let mut out: Vec<f64> = s.force.iter().map(|x| x.to_f64()).collect();
    out.extend(s.mode.iter().map(|m| match m {
        friction_core::GmsSlipMode::Stick => 0.0,
        friction_core::GmsSlipMode::Forward => 1.0,
        friction_core::GmsSlipMode::Backward => -1.0,
    }));
    out
}

fn build_n<S: Scalar + 'static, const K: usize>(
    spec: &GmsSpec,
) -> Result<Box<dyn Stepper>, ParamError> {
    let p = spec.params::<K>().ok_or(ParamError::NotBelow {
        name: "elements",
        limit: "17",
    })?;
    let mut names: Vec<String> = (0..K).map(|i| format!("F{i}")).collect();
    names.extend((0..K).map(|i| format!("mode{i}")));
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    Ok(boxed::<Gms<S, K>, S>(
        p.build::<S>()?,
        &names,
        states::<S, K>,
    ))
}

/// Calls `$f::<[S,] K>($spec[, args])` with the spec's element count `K` (1 to 16).
macro_rules! with_count {
    ($spec:expr, $f:ident $(, $s:ty)? $(; $($arg:expr),+)?) => {
        match $spec.elements.len() {
            1 => $f::<$($s,)? 1>($spec $($(, $arg)+)?),
            2 => $f::<$($s,)? 2>($spec $($(, $arg)+)?),
            3 => $f::<$($s,)? 3>($spec $($(, $arg)+)?),
            4 => $f::<$($s,)? 4>($spec $($(, $arg)+)?),
            5 => $f::<$($s,)? 5>($spec $($(, $arg)+)?),
            6 => $f::<$($s,)? 6>($spec $($(, $arg)+)?),
            7 => $f::<$($s,)? 7>($spec $($(, $arg)+)?),
            8 => $f::<$($s,)? 8>($spec $($(, $arg)+)?),
            9 => $f::<$($s,)? 9>($spec $($(, $arg)+)?),
            10 => $f::<$($s,)? 10>($spec $($(, $arg)+)?),
            11 => $f::<$($s,)? 11>($spec $($(, $arg)+)?),
            12 => $f::<$($s,)? 12>($spec $($(, $arg)+)?),
            13 => $f::<$($s,)? 13>($spec $($(, $arg)+)?),
            14 => $f::<$($s,)? 14>($spec $($(, $arg)+)?),
            15 => $f::<$($s,)? 15>($spec $($(, $arg)+)?),
            16 => $f::<$($s,)? 16>($spec $($(, $arg)+)?),
            _ => Err(ParamError::NotBelow {
                name: "elements",
                limit: "17",
            }),
        }
    };
}
pub(super) use with_count;

fn build<S: Scalar + 'static>(spec: &GmsSpec) -> Result<Box<dyn Stepper>, ParamError> {
    with_count!(spec, build_n, S)
}

fn build_fixed_n<const K: usize>(spec: &GmsSpec, h: f64) -> Result<Box<dyn Stepper>, ParamError> {
    let p = spec.params::<K>().ok_or(ParamError::NotBelow {
        name: "elements",
        limit: "17",
    })?;
    let mut names: Vec<String> = (0..K).map(|i| format!("F{i}")).collect();
    names.extend((0..K).map(|i| format!("mode{i}")));
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    Ok(boxed_fixed(
        p.build_fixed_step::<Fixed32>(h)?,
        &names,
        states::<Fixed32, K>,
    ))
}

/// The observer controller with `K` elements (`fc`, `fs` scaled, the element
/// stiffnesses by the stiffness factor).
fn observer_n<const K: usize>(
    spec: &GmsSpec,
    setup: &Loop,
    request: &ObserverRequest,
) -> Result<Box<dyn Controller>, ParamError> {
    let p = spec.params::<K>().ok_or(ParamError::NotBelow {
        name: "elements",
        limit: "17",
    })?;
    observer_controller(setup, request, |s, k| {
        let mut q = GmsParams {
            curve: super::scaled_curve(&p.curve, s),
            ..p
        };
        for e in &mut q.elements {
            e.k *= k;
        }
        q.build::<f64>()
    })
}

fn validate_n<const K: usize>(spec: &GmsSpec) -> Result<(), ParamError> {
    spec.params::<K>()
        .ok_or(ParamError::NotBelow {
            name: "elements",
            limit: "17",
        })?
        .validate()
}

impl HostModel for GmsSpec {
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
    /// `GmsFixedStep` in Q16.16 (element forces in the state times its force scale).
    fn fixed_stepper(&self, h: f64) -> Option<Result<Box<dyn Stepper>, ParamError>> {
        Some(with_count!(self, build_fixed_n; h))
    }
    fn max_static_force(&self) -> f64 {
        self.curve.fs
    }
    /// The largest element deflection before it slips, `max_i alpha_i Fs / k_i`.
    fn presliding_scale(&self) -> f64 {
        self.elements
            .iter()
            .map(|e| e.alpha * self.curve.fs / e.k)
            .fold(0.0, f64::max)
    }
    fn stribeck_velocity(&self) -> Option<f64> {
        Some(self.curve.vs)
    }
    /// The sum of the element stiffnesses (all stick at rest).
    fn rest_stiffness(&self) -> f64 {
        self.elements.iter().map(|e| e.k).sum()
    }
    /// The slowest slipping element's `alpha_i g(v) / C`.
    fn lag_time(&self, v: f64) -> f64 {
        let alpha = self.elements.iter().map(|e| e.alpha).fold(0.0, f64::max);
        alpha * curve_g(&self.curve, v) / self.c
    }
    fn sigma2(&self) -> f64 {
        self.sigma2
    }
    fn rest_damping(&self) -> f64 {
        self.elements.iter().map(|e| e.sigma1).sum::<f64>() + self.sigma2
    }
    fn continuous(&self) -> Option<Box<dyn super::Continuous>> {
        None
    }
    fn own_reference(&self, signal: &Signal, t: &[f64]) -> Option<ReferenceRun> {
        Some(gms_reference(self, signal, t, GMS_REFERENCE_STEP))
    }
    fn steady_force(&self, v: f64) -> f64 {
        curve_g(&self.curve, v) * super::sign(v) + self.sigma2 * v
    }
    /// stribeck, presliding, lag, break-away, stick-slip: yes; drift: no
    /// (Maxwell-slip elements close their loops: measured by the drift
    /// experiment); rate independence: no (the slip law and the curve
    /// depend on time and velocity).
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
    /// Unstable where some stage of `GmsSpec::creep_growth` grows by more
    /// than round-off needs to reach the creep itself (`e^36`).
    fn unstable_creep(&self, mass: f64, rate: f64) -> Option<String> {
        let growth = self.creep_growth(mass, rate);
        let (stage, worst) = growth
            .iter()
            .enumerate()
            .filter(|(_, g)| !g.is_nan())
            .max_by(|a, b| a.1.total_cmp(b.1))?;
        (*worst > ROUND_OFF_EFOLDS).then(|| {
            format!(
                "once {} of the {} elements slip, the creep grows by e^{worst:.0} before the next one slips (round-off reaches the creep itself after e^36): the slipping elements' falling Stribeck curve acts as a negative damping larger than the sticking elements' sigma1 + sigma2",
                stage + 1,
                self.elements.len()
            )
        })
    }
}

/// One element of the reference: force and the direction it slips in
/// (0 while sticking).
#[derive(Clone, Copy, Debug, Default)]
struct RefElement {
    f: f64,
    slip: f64,
}

/// The GMS equations integrated along the continuous signal with sub-step
/// `dt`: a sticking element follows the exact displacement
/// (`F_i += k_i (x(b) - x(a))`); a slipping one is integrated by RK4 on
/// `dF_i/dt = C (sign(v) - F_i / (alpha_i g(v)))`. Each sub-step checks the
/// switching conditions at its end and, when one is met, locates the
/// instant inside the sub-step by bisection (60 halvings) and finishes
/// the sub-step in the new mode: a sticking element starts slipping when
/// `sign(v) F_i` reaches `alpha_i g(v)`, a slipping one sticks when `v`
/// changes sign. The force at each sample time is
/// `sum_i (F_i + sigma1_i dz_i/dt) + sigma2 v`.
pub fn gms_reference(spec: &GmsSpec, signal: &Signal, t: &[f64], dt: f64) -> ReferenceRun {
    let g = |v: f64| curve_g(&spec.curve, v);
    let sgn = super::sign;
    let mut el = vec![RefElement::default(); spec.elements.len()];
    let force = |el: &[RefElement], v: f64| -> f64 {
        let gv = g(v);
        let mut total = spec.sigma2 * v;
        for (s, p) in el.iter().zip(&spec.elements) {
            let dz = if s.slip != 0.0 {
                spec.c * (sgn(v) - s.f / (p.alpha * gv)) / p.k
            } else {
                v
            };
            total += s.f + p.sigma1 * dz;
        }
        total
    };
    let slip_rate = |f: f64, alpha: f64, v: f64| spec.c * (sgn(v) - f / (alpha * g(v)));
    // RK4 of the slip law over [a, b]
    let rk4 = |f: f64, alpha: f64, a: f64, b: f64| {
        let hh = b - a;
        let (va, vm, vb) = (signal.v(a), signal.v(0.5 * (a + b)), signal.v(b));
        let k1 = slip_rate(f, alpha, va);
        let k2 = slip_rate(f + 0.5 * hh * k1, alpha, vm);
        let k3 = slip_rate(f + 0.5 * hh * k2, alpha, vm);
        let k4 = slip_rate(f + hh * k3, alpha, vb);
        f + hh / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    };
    let bisect = |mut lo: f64, mut hi: f64, crossed: &dyn Fn(f64) -> bool| {
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if crossed(mid) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        hi
    };
    let mut run = ReferenceRun {
        force: vec![force(&el, signal.v(t[0]))],
        switching: vec![false],
    };
    for k in 1..t.len() {
        let n = ((t[k] - t[k - 1]) / dt).round().max(1.0) as usize;
        let hs = (t[k] - t[k - 1]) / n as f64;
        let mut switched = false;
        for j in 0..n {
            let a = t[k - 1] + j as f64 * hs;
            let b = if j + 1 == n { t[k] } else { a + hs };
            let (xa, vb) = (signal.x(a), signal.v(b));
            for (s, p) in el.iter_mut().zip(&spec.elements) {
                if s.slip == 0.0 {
                    let f0 = s.f;
                    let stick = |tt: f64| f0 + p.k * (signal.x(tt) - xa);
                    let reached = |tt: f64| {
                        let v = signal.v(tt);
                        v != 0.0 && sgn(v) * stick(tt) >= p.alpha * g(v)
                    };
                    if reached(b) {
                        let tc = if reached(a) {
                            a
                        } else {
                            bisect(a, b, &reached)
                        };
                        let vc = signal.v(tc);
                        let bound = p.alpha * g(vc);
                        s.slip = sgn(vc);
                        s.f = rk4(stick(tc).clamp(-bound, bound), p.alpha, tc, b);
                        switched = true;
                    } else {
                        s.f = stick(b);
                    }
                } else if sgn(vb) != s.slip {
                    // the velocity changes sign (or stops) inside the sub-step
                    let dir = s.slip;
                    let tc = bisect(a, b, &|tt: f64| sgn(signal.v(tt)) != dir);
                    let fc = rk4(s.f, p.alpha, a, tc);
                    s.f = fc + p.k * (signal.x(b) - signal.x(tc));
                    s.slip = 0.0;
                    switched = true;
                } else {
                    s.f = rk4(s.f, p.alpha, a, b);
                }
            }
        }
        run.force.push(force(&el, signal.v(t[k])));
        run.switching.push(switched);
    }
    run
}

/// How many e-folds of growth take round-off (`f64::EPSILON` relative) to
/// the size of the quantity itself: `ln(1 / EPSILON)`, about 36.
const ROUND_OFF_EFOLDS: f64 = 36.04;

impl GmsSpec {
    /// How the creep of a mass `mass` on this contact, loaded by a force
    /// ramp at `rate` from rest, grows between one element slipping and the
    /// next: for each stage `j` (the first `j` elements to break away
    /// slipping, the rest sticking, `j = 1 .. N - 1`), the largest real
    /// part of the creep's linearization times the stage's duration, in
    /// e-folds.
    ///
    /// At stage `j` the mass creeps at `v = rate / K` (`K` the sticking
    /// stiffness) against `m x'' = u - sum_stick (k_i x + sigma1_i x') -
    /// sum_slip F_i - sigma2 x'`. Each slipping element's force follows the
    /// sheet's slip law `dF_i/dt = C (1 - F_i / (alpha_i g(v)))`, linearized:
    /// it lags `alpha_i g(v)` with the time constant `alpha_i g(v) / C`, so
    /// where the curve falls (`g'(v) < 0`) it is a lagged negative damping.
    /// The stage lasts while the mass moves from one element's break-away
    /// deflection `alpha_i g(v) / k_i` to the next one's. A stage whose
    /// linearization cannot be evaluated (an entry overflows, or the
    /// eigenvalues do not converge) is NaN: no verdict, and
    /// [`HostModel::unstable_creep`] refuses nothing on it.
    pub(crate) fn creep_growth(&self, mass: f64, rate: f64) -> Vec<f64> {
        let g = |v: f64| curve_g(&self.curve, v);
        let mut order: Vec<&GmsElement> = self.elements.iter().collect();
        order.sort_by(|a, b| (a.alpha / a.k).total_cmp(&(b.alpha / b.k)));
        (1..order.len())
            .map(|j| {
                let (slipping, sticking) = order.split_at(j);
                let stiffness: f64 = sticking.iter().map(|e| e.k).sum();
                let damping = sticking.iter().map(|e| e.sigma1).sum::<f64>() + self.sigma2;
                let v = rate / stiffness;
                // g'(v) by a central difference (one-sided at v = 0)
                let (lo, hi) = (
                    (v - 1e-6 * self.curve.vs).max(0.0),
                    v + 1e-6 * self.curve.vs,
                );
                let slope = (g(hi) - g(lo)) / (hi - lo);
                // states: x, x', and the slipping elements' forces
                let n = 2 + slipping.len();
                let mut a = nalgebra::DMatrix::<f64>::zeros(n, n);
                a[(0, 1)] = 1.0;
                a[(1, 0)] = -stiffness / mass;
                a[(1, 1)] = -damping / mass;
                for (i, e) in slipping.iter().enumerate() {
                    let tau = e.alpha * g(v) / self.c;
                    a[(1, 2 + i)] = -1.0 / mass;
                    a[(2 + i, 2 + i)] = -1.0 / tau;
                    a[(2 + i, 1)] = e.alpha * slope / tau;
                }
                // NaN (no verdict) where an entry overflows or the QR
                // iteration does not converge
                let growth = if a.iter().all(|x| x.is_finite()) {
                    nalgebra::Schur::try_new(a, f64::EPSILON, 10_000).map_or(f64::NAN, |s| {
                        s.complex_eigenvalues()
                            .iter()
                            .map(|z| z.re)
                            .fold(f64::NEG_INFINITY, f64::max)
                    })
                } else {
                    f64::NAN
                };
                let (last, next) = (slipping[j - 1], sticking[0]);
                let duration = (next.alpha / next.k - last.alpha / last.k) * g(v) / v;
                growth * duration
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The module's parser, as the registry calls it.
    fn parse(text: &str, origin: &str) -> Result<GmsSpec> {
        <GmsParams<1> as HostParams>::parse(text, origin, "gms")
    }

    /// A shipped set's GMS parameters (its text parsed here: the layer
    /// test keeps `models` from importing `params`).
    fn shipped(text: &str) -> GmsSpec {
        parse(text, "shipped").unwrap()
    }

    const SERVO: &str = include_str!("../../../params/gms-servo.toml");
    const TYPICAL: &str = include_str!("../../../params/gms-typical.toml");

    /// With an attraction rate so fast that the slipping element's force is
    /// `alpha g(v)` at once, stage 1 is `m x'' + (sigma1 + alpha g'(v)) x' +
    /// k x = 0`, whose growth is known in closed form.
    #[test]
    fn creep_growth_matches_the_closed_form_of_an_instant_slip() {
        let text = "model = \"gms\"\nfc = 0.28\nfs = 0.33\nvs = 0.01\nc = 1e7\n\
                    [[elements]]\nk = 1000\nalpha = 0.5\n\
                    [[elements]]\nk = 10\nalpha = 0.5\nsigma1 = 0.01\n";
        let spec = parse(text, "t").unwrap();
        let (m, k, v) = (0.01, 10.0, 0.01 / 2f64.sqrt());
        // g'(v) = -2 v (fs - fc) / vs^2 exp(-(v / vs)^2)
        let slope = -2.0 * v * 0.05 / 1e-4 * (-0.5f64).exp();
        let c = 0.01 + 0.5 * slope;
        let rate = (-c + (c * c - 4.0 * m * k).sqrt()) / (2.0 * m);
        let g = 0.28 + 0.05 * (-0.5f64).exp();
        let duration = (0.5 / 10.0 - 0.5 / 1000.0) * g / v;
        let growth = spec.creep_growth(m, k * v);
        assert_eq!(growth.len(), 1);
        let want = rate * duration;
        assert!(
            (growth[0] / want - 1.0).abs() < 1e-3,
            "{growth:?} vs {want}"
        );
    }

    /// A flat curve has no negative damping: every stage is stable, and one
    /// element has no stages at all.
    #[test]
    fn creep_is_stable_without_a_falling_curve() {
        let mut flat = shipped(SERVO);
        flat.curve.fs = flat.curve.fc;
        for rate in [1e-3, 0.026, 1.3, 100.0] {
            let growth = flat.creep_growth(0.0023, rate);
            assert_eq!(growth.len(), 3);
            assert!(growth.iter().all(|g| *g < 0.0), "{rate}: {growth:?}");
            assert!(flat.unstable_creep(0.0023, rate).is_none());
        }
        let mut one = flat.clone();
        one.elements.truncate(1);
        assert!(one.creep_growth(0.0023, 0.026).is_empty());
        assert!(one.unstable_creep(0.0023, 0.026).is_none());
    }

    /// Extreme but finite sets, masses and rates give an answer (no panic,
    /// no endless QR iteration).
    #[test]
    fn creep_growth_answers_extreme_inputs() {
        let base = shipped(SERVO);
        for scale in [1e-300, 1e-30, 1.0, 1e30, 1e300] {
            for (mass, rate) in [(1e-300, 1e300), (1e300, 1e-300), (1.0, 0.0), (1.0, 1.0)] {
                let mut s = base.clone();
                s.curve.vs *= scale;
                s.c *= scale;
                for e in &mut s.elements {
                    e.k *= scale;
                    e.sigma1 /= scale;
                }
                let growth = s.creep_growth(mass, rate);
                assert_eq!(growth.len(), 3);
                let _ = s.unstable_creep(mass, rate);
            }
        }
    }

    /// gms-servo's creep is unstable at the break-away experiment's slowest
    /// rate (0.026 N m/s), far past round-off (e^36), and stops being so
    /// on a rig 100 times heavier; gms-typical's grows by less than e^36
    /// at each of its rates (0.975 to 48.7 N/s).
    #[test]
    fn the_shipped_sets_creep_as_measured() {
        let servo = shipped(SERVO);
        let growth = servo.creep_growth(0.0023, 0.026);
        assert!(growth[2] > 100.0, "{growth:?}");
        let why = servo.unstable_creep(0.0023, 0.026).unwrap();
        assert!(why.contains("3 of the 4 elements slip"), "{why}");
        assert!(servo.unstable_creep(0.23, 0.026).is_none());
        let typical = shipped(TYPICAL);
        for rate in [0.975, 1.95, 4.87, 9.75, 19.5, 48.7] {
            let growth = typical.creep_growth(1.0, rate);
            assert!(
                growth.iter().all(|g| *g < ROUND_OFF_EFOLDS),
                "{rate}: {growth:?}"
            );
        }
    }

    #[test]
    fn rejects_unknown_keys_and_counts() {
        let ok = "model = \"gms\"\nfc = 1\nfs = 1.5\nvs = 1e-3\nc = 100\n[[elements]]\nk = 1e5\nalpha = 1\n";
        assert!(parse(ok, "t").is_ok());
        let bad = format!("{ok}beta = 2\n");
        let e = format!("{:#}", parse(&bad, "t").unwrap_err());
        assert!(e.contains("beta"), "{e}");
        let none = "model = \"gms\"\nfc = 1\nfs = 1.5\nvs = 1e-3\nc = 100\nelements = []\n";
        let e = format!("{:#}", parse(none, "t").unwrap_err());
        assert!(e.contains("1 to 16"), "{e}");
        let many = format!(
            "model = \"gms\"\nfc = 1\nfs = 1.5\nvs = 1e-3\nc = 100\n{}",
            "[[elements]]\nk = 1e5\nalpha = 0.0588\n".repeat(17)
        );
        let e = format!("{:#}", parse(&many, "t").unwrap_err());
        assert!(e.contains("17") && e.contains("1 to 16"), "{e}");
    }
}
