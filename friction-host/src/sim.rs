//! Drivers: a model pushed by a velocity signal, or a mass on the contact
//! pushed by an applied force (the rig), each both ways: the core's
//! discrete step, and the reference solver on the continuous equations.

use crate::models::ModelSpec;
use crate::models::{Continuous, Stepper};
use crate::reference::{integrate, integrate_stopping, Tolerances};
use crate::signals::Signal;
use anyhow::Result;

/// The number type `friction simulate` runs the core in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum SimScalar {
    /// 32-bit float (variable-step form).
    F32,
    /// 64-bit float (variable-step form).
    F64,
    /// Q16.16 fixed point (fixed-step form).
    Fixed,
}

/// The fixed-step model refused its period, the time step of the input's
/// first two samples (not a parameter of the file).
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[error("the time step {} s from the previous sample cannot be the fixed-step model's period: {error}", crate::checks::num(*.h))]
pub struct PeriodRefused {
    /// The time step (s).
    pub h: f64,
    /// The core's error.
    pub error: friction_core::ParamError,
}

/// `friction simulate`'s stepping, row by row, for the command line (which
/// streams a CSV) and the Python package (which passes arrays): row `k`
/// steps the model from `t[k-1]` to `t[k]` with `v[k]` held (clamped to
/// the velocity limit); row 0 is the force at rest. In fixed point the
/// model is the fixed-step form built for `period`, which every step must
/// keep (to 1e-6).
pub struct Simulation {
    model: Box<dyn Stepper>,
    limit: f64,
    period: Option<f64>,
    prev_t: Option<f64>,
    /// Rows whose velocity was clamped to the limit.
    pub clamped: u64,
}

impl Simulation {
    /// The model of `spec` in `scalar`; fixed point needs `period` (the
    /// time step of the first two rows). Errors name the model.
    pub fn new(spec: &ModelSpec, scalar: SimScalar, period: Option<f64>) -> Result<Self> {
        let (model, limit, period) = match scalar {
            SimScalar::F32 | SimScalar::F64 => {
                let kind = if scalar == SimScalar::F32 {
                    crate::models::ScalarKind::F32
                } else {
                    crate::models::ScalarKind::F64
                };
                (
                    spec.host().stepper(kind)?,
                    friction_core::VELOCITY_LIMIT,
                    None,
                )
            }
            SimScalar::Fixed => {
                let h = match period {
                    Some(h) if h.is_finite() && h > 0.0 => h,
                    Some(h) => anyhow::bail!(
                        "the time step of the first two rows ({h:e} s) must be finite and > 0"
                    ),
                    None => {
                        anyhow::bail!("`--scalar fixed` needs at least two rows (the time step)")
                    }
                };
                // the period is the input's, not the parameter file's: a
                // period the core refuses is reported as the input's fault
                let stepper = spec.fixed_stepper(h).map_err(|e| match e
                    .downcast_ref::<friction_core::ParamError>()
                {
                    Some(&error) if crate::checks::param_name(&error) == "h" => {
                        anyhow::Error::new(PeriodRefused { h, error })
                    }
                    _ => e,
                })?;
                (
                    stepper,
                    friction_core::Scalar::to_f64(
                        <friction_core::Fixed32 as friction_core::Scalar>::VELOCITY_LIMIT,
                    ),
                    Some(h),
                )
            }
        };
        Ok(Self {
            model,
            limit,
            period,
            prev_t: None,
            clamped: 0,
        })
    }

    /// The velocity limit the model clamps to.
    pub fn limit(&self) -> f64 {
        self.limit
    }

    /// Steps to time `t` with velocity `v`; returns the velocity the model
    /// saw (clamped) and the force. Errors (a time step that overflows, or
    /// one off the fixed-step period) leave the model as it was.
    pub fn row(&mut self, t: f64, v: f64) -> Result<(f64, f64)> {
        let h: f64 = self.prev_t.map_or(0.0, |p| t - p);
        if !h.is_finite() {
            anyhow::bail!("the time step from the previous row overflows ({h:e})");
        }
        if let (Some(p), true) = (self.period, self.prev_t.is_some()) {
            if (h - p).abs() > 1e-6 * p {
                anyhow::bail!(
                    "the time step {h:e} s differs from {p:e} s, the period the fixed-step model was built for (`--scalar fixed` needs uniform steps)"
                );
            }
        }
        self.prev_t = Some(t);
        let v_used = v.clamp(-self.limit, self.limit);
        if v_used != v {
            self.clamped += 1;
        }
        Ok((v_used, self.model.step(v_used, h)))
    }

    /// Names of the model's internal states.
    pub fn state_names(&self) -> Vec<String> {
        self.model.state_names()
    }

    /// The model's internal states now.
    pub fn states(&self) -> Vec<f64> {
        self.model.states()
    }
}

/// Relative tolerance of every reference solve.
pub const REFERENCE_RTOL: f64 = 1e-9;

/// Steps the core model through the sampled velocities `v` at times `t`:
/// row 0 is the force at rest (`h = 0`), row `k` the force after stepping
/// from `t[k-1]` to `t[k]` with `v[k]` held.
pub fn drive_core(model: &mut dyn Stepper, t: &[f64], v: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(t.len());
    for k in 0..t.len() {
        let h = if k == 0 { 0.0 } else { t[k] - t[k - 1] };
        out.push(model.step(v[k], h));
    }
    out
}

use crate::models::ReferenceRun;

/// The reference force for the continuous velocity signal at times `t`:
/// the model's own reference where it has one (the bristle model's exact
/// event-driven solution), else diffsol on its continuous equations.
pub fn drive_reference(spec: &ModelSpec, signal: &Signal, t: &[f64]) -> Result<ReferenceRun> {
    if let Some(run) = spec.host().own_reference(signal, t) {
        return Ok(run);
    }
    let model = spec
        .host()
        .continuous()
        .ok_or_else(|| anyhow::anyhow!("no continuous form for `{}`", spec.name()))?;
    let n = model.n();
    let v: Vec<f64> = t.iter().map(|&ti| signal.v(ti)).collect();
    let z = if n == 0 {
        vec![Vec::new(); t.len()]
    } else {
        let tol = Tolerances {
            rtol: REFERENCE_RTOL,
            atol: model.atol(),
        };
        let rhs = |ti: f64, z: &[f64], dz: &mut [f64]| model.rhs(z, signal.v(ti), dz);
        if model.stop_at_samples() {
            integrate_stopping(&vec![0.0; n], t, &tol, rhs)?
        } else {
            integrate(&vec![0.0; n], t, &tol, rhs)?
        }
    };
    let force = z
        .iter()
        .zip(&v)
        .map(|(zi, &vi)| model.force(zi, vi))
        .collect();
    let mut switching = vec![false; t.len()];
    for k in 1..t.len() {
        switching[k] = model.switched(&z[k - 1], v[k - 1], &z[k], v[k]);
    }
    Ok(ReferenceRun { force, switching })
}

/// A mass `m` on the friction contact, driven by an applied force `u(t, x)`:
/// `m dv/dt = u - F`.
pub struct Rig<'a> {
    /// Mass (kg).
    pub mass: f64,
    /// Applied force as a function of time and position.
    pub force: &'a dyn Fn(f64, f64) -> f64,
}

/// Sampled rig trajectory.
#[derive(Clone, Debug, Default)]
pub struct Trace {
    /// Time (s).
    pub t: Vec<f64>,
    /// Position (m).
    pub x: Vec<f64>,
    /// Velocity (m/s).
    pub v: Vec<f64>,
    /// Friction force (N).
    pub f: Vec<f64>,
    /// Applied force (N).
    pub u: Vec<f64>,
}

/// The rig with the core's step at period `h`: semi-implicit Euler on the
/// mass (`v+ = v + h (u - F)/m`, `x+ = x + h v+`), the friction force from
/// the core model stepped over the same period with `v` held.
pub fn rig_core(model: &mut dyn Stepper, rig: &Rig, h: f64, duration: f64) -> Trace {
    let n = (duration / h).round() as usize;
    let mut tr = Trace::default();
    let (mut x, mut v) = (0.0, 0.0);
    let mut f = model.step(0.0, 0.0);
    for k in 0..=n {
        let t = k as f64 * h;
        let u = (rig.force)(t, x);
        tr.t.push(t);
        tr.x.push(x);
        tr.v.push(v);
        tr.f.push(f);
        tr.u.push(u);
        f = model.step(v, h);
        v += h * (u - f) / rig.mass;
        x += h * v;
    }
    tr
}

/// The rig by the reference solver, states `(x, v, z...)`, sampled at `t`.
pub fn rig_reference(model: &dyn Continuous, rig: &Rig, t: &[f64]) -> Result<Trace> {
    let n = model.n();
    let mut atol = vec![1e-12, 1e-10];
    atol.extend(model.atol());
    let tol = Tolerances {
        rtol: REFERENCE_RTOL,
        atol,
    };
    let y = integrate(&vec![0.0; n + 2], t, &tol, |ti, y, dy| {
        let (x, v, z) = (y[0], y[1], &y[2..]);
        dy[0] = v;
        dy[1] = ((rig.force)(ti, x) - model.force(z, v)) / rig.mass;
        model.rhs(z, v, &mut dy[2..]);
    })?;
    let mut tr = Trace::default();
    for (&ti, yi) in t.iter().zip(&y) {
        tr.t.push(ti);
        tr.x.push(yi[0]);
        tr.v.push(yi[1]);
        tr.f.push(model.force(&yi[2..], yi[1]));
        tr.u.push((rig.force)(ti, yi[0]));
    }
    Ok(tr)
}

/// Root-mean-square of `a - b`.
pub fn rms_diff(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len()).max(1);
    (a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>() / n as f64).sqrt()
}

/// Largest `|a - b|`.
pub fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}
