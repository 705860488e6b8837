//! The models' fits on conditioned signals, and their predictions.

use super::solve::{self, Estimate, FitFailure};
use super::{FullRate, Signals};
use crate::models::sign;
use friction_core::{FrictionModel, LuGreParams, LuGreState, StribeckParams};
use indicatif::ProgressBar;

/// A fitted friction law (parameters in force units, or coefficients when
/// the fit used a normal force).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Friction {
    /// `fc sign(v)`.
    Coulomb {
        /// Coulomb level.
        fc: f64,
    },
    /// `fc sign(v) + sigma2 v`.
    CoulombViscous {
        /// Coulomb level.
        fc: f64,
        /// Viscous coefficient.
        sigma2: f64,
    },
    /// `g(v) sign(v) + sigma2 v`.
    Stribeck {
        /// The curve.
        curve: StribeckParams,
        /// Viscous coefficient.
        sigma2: f64,
    },
    /// LuGre.
    LuGre(LuGreParams),
}

/// `exp(-|v/vs|^delta)`, the Stribeck shape.
fn shape(v: f64, vs: f64, delta: f64) -> f64 {
    (-(v / vs).abs().powf(delta)).exp()
}

impl Friction {
    /// The model name as parameter files spell it.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Coulomb { .. } => "coulomb",
            Self::CoulombViscous { .. } => "coulomb-viscous",
            Self::Stribeck { .. } => "stribeck",
            Self::LuGre(_) => "lugre",
        }
    }

    /// The steady-state friction at constant velocity `v`.
    pub fn steady(&self, v: f64) -> f64 {
        let stribeck = |c: &StribeckParams, s2: f64| {
            (c.fc + (c.fs - c.fc) * shape(v, c.vs, c.exponent)) * sign(v) + s2 * v
        };
        match self {
            Self::Coulomb { fc } => fc * sign(v),
            Self::CoulombViscous { fc, sigma2 } => fc * sign(v) + sigma2 * v,
            Self::Stribeck { curve, sigma2 } => stribeck(curve, *sigma2),
            Self::LuGre(p) => stribeck(&p.curve, p.sigma2),
        }
    }

    /// The friction force along the raw-rate signals (times the normal
    /// force): static maps sample by sample, LuGre by the core's step from
    /// rest, row 0 at `h = 0` and row `k` after a step of `t[k] - t[k-1]`
    /// with `v[k]` held (as `friction simulate` does). `None` if LuGre's
    /// parameters are invalid.
    pub fn force(&self, s: &FullRate) -> Option<Vec<f64>> {
        match self {
            Self::LuGre(p) => {
                let m = p.build::<f64>().ok()?;
                let mut state = LuGreState::default();
                Some(
                    (0..s.t.len())
                        .map(|k| {
                            let h = if k == 0 { 0.0 } else { s.t[k] - s.t[k - 1] };
                            s.n(k) * m.step(&mut state, s.v[k], h)
                        })
                        .collect(),
                )
            }
            _ => Some(
                (0..s.t.len())
                    .map(|k| s.n(k) * self.steady(s.v[k]))
                    .collect(),
            ),
        }
    }
}

/// One estimated parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct Param {
    /// Its key in the parameter file (`mass` and `offset` go to `[plant]`).
    pub name: &'static str,
    /// The estimate.
    pub value: f64,
    /// Its standard deviation.
    pub std: f64,
}

impl Param {
    /// The relative standard deviation in percent.
    pub fn relative_std(&self) -> f64 {
        100.0 * self.std / self.value.abs()
    }
}

/// A fit.
#[derive(Clone, Debug)]
pub struct Fit {
    /// The friction law.
    pub friction: Friction,
    /// The moving mass, if estimated.
    pub mass: Option<f64>,
    /// The force offset, if estimated.
    pub offset: Option<f64>,
    /// Every estimated parameter with its standard deviation.
    pub params: Vec<Param>,
    /// Residual evaluations of the iterative stages.
    pub evaluations: usize,
    /// What each stage did.
    pub stages: Vec<String>,
}

impl Fit {
    /// The predicted force `mass a + N friction(v) + offset`, computed at
    /// the raw rate and observed as the measured force is (filtered and
    /// decimated).
    pub fn predict(&self, s: &Signals) -> Option<Vec<f64>> {
        let f = self.friction.force(&s.full)?;
        let full: Vec<f64> = f
            .iter()
            .enumerate()
            .map(|(k, fk)| fk + self.mass.unwrap_or(0.0) * s.full.a[k] + self.offset.unwrap_or(0.0))
            .collect();
        Some(s.observe(&full))
    }

    /// The value of parameter `name`.
    pub fn get(&self, name: &str) -> Option<f64> {
        self.params.iter().find(|p| p.name == name).map(|p| p.value)
    }
}

/// Why a fit is rejected (a judged failure, exit code 1).
#[derive(Clone, Debug)]
pub struct Rejected {
    /// What went wrong, with the figure.
    pub reason: String,
    /// The estimate, when there is one.
    pub fit: Option<Box<Fit>>,
}

impl std::fmt::Display for Rejected {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.reason)
    }
}

fn failure(stage: &str, e: FitFailure) -> Rejected {
    Rejected {
        reason: format!("{stage}: {e}"),
        fit: None,
    }
}

/// Options of the fits.
#[derive(Clone, Copy, Debug)]
pub struct FitOptions {
    /// Estimate `mass` and `offset`.
    pub inertia: bool,
    /// The Stribeck exponent (fixed).
    pub stribeck_exponent: f64,
    /// The steady-state law of `lugre`'s first stage.
    pub lugre_static: StaticPart,
}

/// The steady-state law `lugre` fits first.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum StaticPart {
    /// The Stribeck curve: `fc`, `fs`, `vs` and `sigma2`.
    #[default]
    Stribeck,
    /// Coulomb and viscous only: `fs = fc` (then `vs` has no effect and is
    /// written as the largest measured speed).
    CoulombViscous,
    /// Coulomb only: `fs = fc`, `sigma2 = 0` (data at a single speed).
    Coulomb,
}

fn names(v: &[&str]) -> Vec<String> {
    v.iter().map(|s| s.to_string()).collect()
}

/// A regressor column: `g(k)` over the raw-rate samples, observed (filtered
/// and decimated) as the force is, at the samples `idx`.
fn observed(s: &Signals, idx: &[usize], g: impl Fn(usize) -> f64) -> Vec<f64> {
    let full: Vec<f64> = (0..s.full.t.len()).map(g).collect();
    let o = s.observe(&full);
    idx.iter().map(|&k| o[k]).collect()
}

/// Appends the inertia columns `a` and `1`.
fn inertia_columns(s: &Signals, idx: &[usize], cols: &mut Vec<Vec<f64>>, names: &mut Vec<String>) {
    cols.push(observed(s, idx, |k| s.full.a[k]));
    cols.push(vec![1.0; idx.len()]);
    names.extend(["mass".to_string(), "offset".to_string()]);
}

/// `coulomb-viscous` by linear least squares.
pub fn coulomb_viscous(s: &Signals, o: &FitOptions) -> Result<Fit, Rejected> {
    let idx: Vec<usize> = (0..s.len()).collect();
    check_bounds(coulomb_viscous_on(s, &idx, o)?, &[])
}

/// `coulomb` by linear least squares (`coulomb-viscous` with `sigma2 = 0`).
pub fn coulomb(s: &Signals, o: &FitOptions) -> Result<Fit, Rejected> {
    let idx: Vec<usize> = (0..s.len()).collect();
    check_bounds(linear_static(s, &idx, o, false)?, &[])
}

fn coulomb_viscous_on(s: &Signals, idx: &[usize], o: &FitOptions) -> Result<Fit, Rejected> {
    linear_static(s, idx, o, true)
}

fn linear_static(
    s: &Signals,
    idx: &[usize],
    o: &FitOptions,
    viscous: bool,
) -> Result<Fit, Rejected> {
    let fr = &s.full;
    let mut cols = vec![observed(s, idx, |k| fr.n(k) * sign(fr.v[k]))];
    let mut nm = names(&["fc"]);
    if viscous {
        cols.push(observed(s, idx, |k| fr.n(k) * fr.v[k]));
        nm.push("sigma2".into());
    }
    if o.inertia {
        inertia_columns(s, idx, &mut cols, &mut nm);
    }
    let y: Vec<f64> = idx.iter().map(|&k| s.f[k]).collect();
    let e = solve::linear(&cols, &y, &nm).map_err(|e| failure("linear least squares", e))?;
    let i = if viscous { 2 } else { 1 };
    let keys: &[&'static str] = if viscous {
        &["fc", "sigma2", "mass", "offset"]
    } else {
        &["fc", "mass", "offset"]
    };
    Ok(Fit {
        friction: if viscous {
            Friction::CoulombViscous {
                fc: e.theta[0],
                sigma2: e.theta[1],
            }
        } else {
            Friction::Coulomb { fc: e.theta[0] }
        },
        mass: o.inertia.then(|| e.theta[i]),
        offset: o.inertia.then(|| e.theta[i + 1]),
        params: params(keys, &e),
        evaluations: 1,
        stages: vec![format!(
            "linear least squares on {} samples, parameters {}",
            idx.len(),
            nm.join(", ")
        )],
    })
}

fn params(names: &[&'static str], e: &Estimate) -> Vec<Param> {
    e.theta
        .iter()
        .zip(&e.std)
        .zip(names)
        .map(|((&value, &std), &name)| Param { name, value, std })
        .collect()
}

/// A bound of a parameter, checked after a fit.
struct Bound {
    name: &'static str,
    lo: f64,
    hi: f64,
    what: String,
}

/// Rejects a fit whose parameter lies at or beyond a bound: the loader's
/// (`fc > 0`, `fs >= fc`, `sigma* >= 0`, `mass > 0`) and the extra ones given.
fn check_bounds(fit: Fit, extra: &[Bound]) -> Result<Fit, Rejected> {
    let get = |n: &str| fit.get(n);
    let mut bounds = vec![
        Bound {
            name: "fc",
            lo: 0.0,
            hi: f64::INFINITY,
            what: "fc > 0".into(),
        },
        Bound {
            name: "sigma2",
            lo: 0.0,
            hi: f64::INFINITY,
            what: "sigma2 >= 0".into(),
        },
        Bound {
            name: "mass",
            lo: 0.0,
            hi: f64::INFINITY,
            what: "mass > 0".into(),
        },
        Bound {
            name: "sigma1",
            lo: 0.0,
            hi: f64::INFINITY,
            what: "sigma1 >= 0".into(),
        },
    ];
    if let Some(fc) = get("fc") {
        bounds.push(Bound {
            name: "fs",
            lo: fc,
            hi: f64::INFINITY,
            what: format!("fs >= fc = {fc:.6e}"),
        });
    }
    for b in bounds.iter().chain(extra) {
        let Some(x) = get(b.name) else { continue };
        let strict = b.name == "fc" || b.name == "mass";
        let out = x < b.lo || x > b.hi || (strict && x <= b.lo);
        if out || !x.is_finite() {
            let std = fit
                .params
                .iter()
                .find(|p| p.name == b.name)
                .map_or(0.0, |p| p.std);
            let reason = if x.is_finite() {
                format!(
                    "parameter `{}` ends at its bound ({}): estimate {x:.6e} (standard deviation {std:.2e})",
                    b.name, b.what
                )
            } else {
                format!(
                    "parameter `{}` has no finite estimate ({x}): the data overflow or vanish in double precision on the way (forces or normal forces near 1e308 or 1e-300); scale the forces with --force-gain",
                    b.name
                )
            };
            return Err(Rejected {
                reason,
                fit: Some(Box::new(fit)),
            });
        }
    }
    Ok(fit)
}

/// The range of `|v|` over which `vs` can be identified: from the 2nd
/// percentile of the non-zero speeds to the largest.
fn speed_range(s: &Signals, idx: &[usize]) -> (f64, f64) {
    let mut speeds: Vec<f64> = idx
        .iter()
        .map(|&k| s.v[k].abs())
        .filter(|v| *v > 0.0)
        .collect();
    speeds.sort_by(f64::total_cmp);
    if speeds.is_empty() {
        return (1.0, 1.0);
    }
    (speeds[speeds.len() / 50], speeds[speeds.len() - 1])
}

/// The Stribeck map on the samples `idx`: a grid over `vs` (at each point
/// the other parameters enter linearly), then Levenberg-Marquardt on all of
/// them from the best grid point. Returns the fit and the `vs` range.
fn stribeck_on(
    s: &Signals,
    idx: &[usize],
    o: &FitOptions,
    progress: &ProgressBar,
) -> Result<(Fit, Bound, Option<FitFailure>), Rejected> {
    let delta = o.stribeck_exponent;
    let (vlo, vhi) = speed_range(s, idx);
    let y: Vec<f64> = idx.iter().map(|&k| s.f[k]).collect();
    let mut best: Option<(f64, f64, Estimate)> = None;
    const GRID: usize = 41;
    for i in 0..GRID {
        let vs = vlo * (vhi / vlo).powf(i as f64 / (GRID - 1) as f64);
        let fr = &s.full;
        let mut cols = vec![
            observed(s, idx, |k| fr.n(k) * sign(fr.v[k])),
            observed(s, idx, |k| {
                fr.n(k) * sign(fr.v[k]) * shape(fr.v[k], vs, delta)
            }),
            observed(s, idx, |k| fr.n(k) * fr.v[k]),
        ];
        let mut nm = names(&["fc", "fs - fc", "sigma2"]);
        if o.inertia {
            inertia_columns(s, idx, &mut cols, &mut nm);
        }
        if let Ok(e) = solve::linear(&cols, &y, &nm) {
            let ssr: f64 = e.residual.iter().map(|r| r * r).sum();
            if best.as_ref().is_none_or(|b| ssr < b.0) {
                best = Some((ssr, vs, e));
            }
        }
        progress.inc(1);
    }
    let Some((_, vs0, e0)) = best else {
        return Err(Rejected {
            reason: format!(
                "stribeck: no point of the grid over vs in [{vlo:.3e}, {vhi:.3e}] gives an identifiable linear problem"
            ),
            fit: None,
        });
    };
    // theta = [fc, fs, ln vs, sigma2, (mass, offset)]
    let mut theta0 = vec![
        e0.theta[0],
        e0.theta[0] + e0.theta[1],
        vs0.ln(),
        e0.theta[2],
    ];
    if o.inertia {
        theta0.extend([e0.theta[3], e0.theta[4]]);
    }
    let typical = y.iter().map(|f| f.abs()).fold(0.0, f64::max).max(1e-300);
    let scale: Vec<f64> = theta0
        .iter()
        .enumerate()
        .map(|(i, t)| {
            if i == 2 {
                1.0
            } else {
                t.abs().max(1e-6 * typical)
            }
        })
        .collect();
    let nm = names(&["fc", "fs", "vs", "sigma2", "mass", "offset"][..theta0.len()]);
    let residual = |p: &[f64]| -> Option<Vec<f64>> {
        let vs = p[2].exp();
        let fr = &s.full;
        let pred = observed(s, idx, |k| {
            let v = fr.v[k];
            let f = (p[0] + (p[1] - p[0]) * shape(v, vs, delta)) * sign(v) + p[3] * v;
            let mut pred = fr.n(k) * f;
            if o.inertia {
                pred += p[4] * fr.a[k] + p[5];
            }
            pred
        });
        Some(y.iter().zip(&pred).map(|(a, b)| a - b).collect())
    };
    let e = solve::nonlinear(&residual, &theta0, &scale, &nm, 200, progress)
        .map_err(|e| failure("stribeck (Levenberg-Marquardt)", e))?;
    let singular = e.singular.clone();
    let vs = e.theta[2].exp();
    let mut ps = params(&["fc", "fs", "vs", "sigma2", "mass", "offset"], &e);
    ps[2] = Param {
        name: "vs",
        value: vs,
        std: vs * e.std[2],
    };
    let fit = Fit {
        friction: Friction::Stribeck {
            curve: StribeckParams {
                fc: e.theta[0],
                fs: e.theta[1],
                vs,
                exponent: delta,
            },
            sigma2: e.theta[3],
        },
        mass: o.inertia.then(|| e.theta[4]),
        offset: o.inertia.then(|| e.theta[5]),
        params: ps,
        evaluations: e.evaluations + GRID,
        stages: vec![format!(
            "Stribeck map on {} samples: grid of {GRID} values of vs in [{vlo:.3e}, {vhi:.3e}] (linear least squares at each, best vs = {vs0:.4e}), then Levenberg-Marquardt on {} ({} evaluations); exponent fixed at {delta}",
            idx.len(),
            nm.join(", "),
            e.evaluations
        )],
    };
    let bound = Bound {
        name: "vs",
        lo: vlo,
        hi: vhi,
        what: format!("the measured speeds {vlo:.3e} <= vs <= {vhi:.3e}"),
    };
    Ok((fit, bound, singular))
}

/// `stribeck` on all samples.
pub fn stribeck(s: &Signals, o: &FitOptions, progress: &ProgressBar) -> Result<Fit, Rejected> {
    let idx: Vec<usize> = (0..s.len()).collect();
    let (fit, bound, singular) = stribeck_on(s, &idx, o, progress)?;
    let fit = check_bounds(fit, &[bound])?;
    match singular {
        Some(why) => Err(Rejected {
            reason: format!("stribeck: {why}"),
            fit: Some(Box::new(fit)),
        }),
        None => Ok(fit),
    }
}

/// Samples whose speed exceeds this fraction of the largest count as
/// sliding for the first stage of `lugre`.
pub const SLIDING_FRACTION: f64 = 0.01;

/// The samples of steady sliding: in a stretch of motion in one direction
/// (speed at least `vmin`), those past half of the stretch's travel, where
/// the contact has left its pre-sliding regime.
pub fn sliding_samples(s: &Signals, vmin: f64) -> Vec<usize> {
    let mut out = Vec::new();
    let mut k = 0;
    while k < s.len() {
        if s.v[k].abs() < vmin {
            k += 1;
            continue;
        }
        let dir = sign(s.v[k]);
        let start = k;
        let mut x = vec![0.0];
        while k + 1 < s.len() && sign(s.v[k + 1]) == dir && s.v[k + 1].abs() >= vmin {
            k += 1;
            let last = x[x.len() - 1];
            x.push(last + s.v[k].abs() * (s.t[k] - s.t[k - 1]));
        }
        let travel = x[x.len() - 1];
        out.extend(
            x.iter()
                .enumerate()
                .filter(|(_, xi)| **xi >= 0.5 * travel)
                .map(|(i, _)| start + i),
        );
        k += 1;
    }
    out
}

/// `lugre` in three stages. 1: the steady-state law (with `mass`,
/// `offset`) from the sliding samples ([`sliding_samples`] at
/// `SLIDING_FRACTION max |v|`),
/// clamped into the feasible set (a start, not a result). 2: `sigma0` from
/// a grid over the pre-sliding distance `fs / sigma0`, then
/// Levenberg-Marquardt on `ln sigma0` and `sigma1`, the rest held. 3:
/// Levenberg-Marquardt on every parameter together. Stages 2 and 3 minimise
/// the simulation error of the core's LuGre step over all samples.
pub fn lugre(s: &Signals, o: &FitOptions, progress: &ProgressBar) -> Result<Fit, Rejected> {
    let vmax = s.v.iter().map(|v| v.abs()).fold(0.0, f64::max);
    let idx = sliding_samples(s, SLIDING_FRACTION * vmax);
    let stribeck_static = o.lugre_static == StaticPart::Stribeck;
    let typical = s.f.iter().map(|f| f.abs()).fold(0.0, f64::max).max(1e-300);
    // stage 1
    let (stat, mut curve, mut sigma2) = if stribeck_static {
        let (stat, _, _) = stribeck_on(s, &idx, o, progress)?;
        let Friction::Stribeck { curve, sigma2 } = stat.friction else {
            unreachable!("stribeck_on fits a Stribeck map")
        };
        (stat, curve, sigma2)
    } else {
        let viscous = o.lugre_static == StaticPart::CoulombViscous;
        let stat = linear_static(s, &idx, o, viscous)?;
        let (fc, sigma2) = match stat.friction {
            Friction::CoulombViscous { fc, sigma2 } => (fc, sigma2),
            Friction::Coulomb { fc } => (fc, 0.0),
            _ => unreachable!("linear_static fits a Coulomb(-viscous) map"),
        };
        let curve = StribeckParams {
            fc,
            fs: fc,
            vs: vmax,
            exponent: o.stribeck_exponent,
        };
        (stat, curve, sigma2)
    };
    curve.fc = curve.fc.max(1e-6 * typical);
    curve.fs = curve.fs.max(curve.fc);
    sigma2 = sigma2.max(0.0);
    let (mass, offset) = (stat.mass.unwrap_or(0.0), stat.offset.unwrap_or(0.0));
    // theta = [fc, (fs, ln vs), sigma2, (mass, offset), ln sigma0, sigma1]
    let mut nm: Vec<&'static str> = vec!["fc"];
    let mut theta0 = vec![curve.fc];
    if stribeck_static {
        nm.extend(["fs", "vs"]);
        theta0.extend([curve.fs, curve.vs.ln()]);
    }
    if o.lugre_static != StaticPart::Coulomb {
        nm.push("sigma2");
        theta0.push(sigma2);
    }
    if o.inertia {
        nm.extend(["mass", "offset"]);
        theta0.extend([mass, offset]);
    }
    nm.extend(["sigma0", "sigma1"]);
    let at = |name: &str| nm.iter().position(|n| *n == name);
    // the model for a parameter vector, clamped into the feasible set (a
    // value beyond a bound has no further effect and is reported afterwards)
    let model = |p: &[f64]| -> Fit {
        let fc = p[0].max(1e-9 * typical);
        let (fs, vs) = match (at("fs"), at("vs")) {
            (Some(i), Some(j)) => (p[i].max(fc), p[j].exp()),
            _ => (fc, vmax),
        };
        let n = p.len();
        Fit {
            friction: Friction::LuGre(LuGreParams {
                curve: StribeckParams {
                    fc,
                    fs,
                    vs,
                    exponent: o.stribeck_exponent,
                },
                sigma0: p[n - 2].exp(),
                sigma1: p[n - 1].max(0.0),
                sigma2: at("sigma2").map_or(0.0, |i| p[i].max(0.0)),
                vd: None,
            }),
            mass: at("mass").map(|i| p[i]),
            offset: at("offset").map(|i| p[i]),
            params: Vec::new(),
            evaluations: 0,
            stages: Vec::new(),
        }
    };
    let sim_residual = |p: &[f64]| -> Option<Vec<f64>> {
        let pred = model(p).predict(s)?;
        Some(s.f.iter().zip(&pred).map(|(a, b)| a - b).collect())
    };
    // stage 2: grid over the pre-sliding distance, displacement range from the velocity
    let (mut x, mut xlo, mut xhi) = (0.0f64, 0.0f64, 0.0f64);
    for k in 1..s.len() {
        x += s.v[k] * (s.t[k] - s.t[k - 1]);
        xlo = xlo.min(x);
        xhi = xhi.max(x);
    }
    let range = (xhi - xlo).max(f64::MIN_POSITIVE);
    let (dlo, dhi) = (1e-7 * range, range);
    const GRID: usize = 25;
    let mut best = (f64::INFINITY, 0.0);
    let with_pre = |ln_sigma0: f64, sigma1: f64| {
        let mut p = theta0.clone();
        p.extend([ln_sigma0, sigma1]);
        p
    };
    for i in 0..GRID {
        let d = dlo * (dhi / dlo).powf(i as f64 / (GRID - 1) as f64);
        let sigma0 = curve.fs / d;
        if let Some(r) = sim_residual(&with_pre(sigma0.ln(), 0.0)) {
            let ssr: f64 = r.iter().map(|x| x * x).sum();
            if ssr < best.0 {
                best = (ssr, sigma0);
            }
        }
        progress.inc(1);
    }
    let sigma0_init = best.1;
    // sigma1 scale: a damping force of fs at the largest speed
    let s1scale = (curve.fs / vmax).max(sigma2);
    let pre = |p: &[f64]| sim_residual(&with_pre(p[0], p[1]));
    let e2 = solve::nonlinear(
        &pre,
        &[sigma0_init.ln(), 0.01 * s1scale],
        &[1.0, s1scale],
        &names(&["sigma0", "sigma1"]),
        100,
        progress,
    )
    .map_err(|e| failure("lugre, stage 2 (sigma0, sigma1)", e))?;
    // stage 3: everything together
    let start = with_pre(e2.theta[0], e2.theta[1]);
    let scale: Vec<f64> = start
        .iter()
        .zip(&nm)
        .map(|(t, n)| match *n {
            "vs" | "sigma0" => 1.0,
            "sigma1" => t.abs().max(s1scale * 1e-3),
            _ => t.abs().max(1e-6 * typical),
        })
        .collect();
    let e = solve::nonlinear(&sim_residual, &start, &scale, &names(&nm), 100, progress)
        .map_err(|e| failure("lugre, stage 3 (all parameters)", e))?;
    let mut ps = params(&nm, &e);
    for p in ps.iter_mut() {
        if p.name == "vs" || p.name == "sigma0" {
            p.value = p.value.exp();
            p.std *= p.value;
        }
    }
    let fitted = model(&e.theta);
    let Friction::LuGre(lp) = fitted.friction else {
        unreachable!()
    };
    let mut stages = stat.stages.clone();
    stages[0] = format!(
        "stage 1, a start for the steady-state law: {} on the sliding samples (the second half, by travel, of each stretch of motion in one direction at |v| >= {SLIDING_FRACTION} max |v| = {:.4e}){}",
        stages[0],
        SLIDING_FRACTION * vmax,
        match o.lugre_static {
            StaticPart::Stribeck => "",
            StaticPart::CoulombViscous => "; static part Coulomb-viscous: fs = fc, vs has no effect and is set to the largest speed",
            StaticPart::Coulomb => "; static part Coulomb: fs = fc, sigma2 = 0, vs has no effect and is set to the largest speed",
        }
    );
    stages.push(format!(
        "stage 2: sigma0 from a grid of {GRID} pre-sliding distances fs/sigma0 in [{dlo:.3e}, {dhi:.3e}] (best sigma0 = {sigma0_init:.4e}), then Levenberg-Marquardt on ln sigma0 and sigma1 ({} evaluations), the rest held",
        e2.evaluations
    ));
    stages.push(format!(
        "stage 3: Levenberg-Marquardt on {} together ({} evaluations); stages 2 and 3 minimise the simulation error of the core's LuGre step over all {} samples",
        nm.join(", "),
        e.evaluations,
        s.len()
    ));
    let fit = Fit {
        params: ps,
        evaluations: stat.evaluations + GRID + e2.evaluations + e.evaluations,
        stages,
        ..fitted
    };
    let mut bounds = vec![Bound {
        name: "sigma0",
        lo: lp.curve.fs / dhi,
        hi: lp.curve.fs / dlo,
        what: format!(
            "pre-sliding distance fs/sigma0 between {dlo:.3e} and {dhi:.3e}, 1e-7 to 1 times the travel"
        ),
    }];
    if stribeck_static {
        let (vlo, vhi) = speed_range(s, &(0..s.len()).collect::<Vec<_>>());
        bounds.push(Bound {
            name: "vs",
            lo: vlo,
            hi: vhi,
            what: format!("the measured speeds {vlo:.3e} <= vs <= {vhi:.3e}"),
        });
    }
    let fit = check_bounds(fit, &bounds)?;
    match e.singular {
        Some(why) => Err(Rejected {
            reason: format!("lugre, stage 3: {why}"),
            fit: Some(Box::new(fit)),
        }),
        None => Ok(fit),
    }
}
