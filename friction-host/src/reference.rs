//! The independent reference solver.
//!
//! Continuous-time right-hand sides written here from the model sheet (they
//! share no code with the core's discrete steps), integrated by `diffsol`'s
//! variable-order BDF method (stiff, adaptive, error-controlled; like
//! MATLAB's `ode15s`). Tight tolerances make its error negligible next to
//! the errors it is used to measure.

use anyhow::{anyhow, Result};
use diffsol::{NalgebraLU, NalgebraMat, OdeBuilder, OdeSolverMethod, OdeSolverStopReason, Vector};

/// Relative and absolute error tolerances, the latter per state.
#[derive(Clone, Debug)]
pub struct Tolerances {
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance for each state.
    pub atol: Vec<f64>,
}

/// Integrates `dy/dt = rhs(t, y)` from `y(t_eval[0]) = y0` and returns the
/// state at every time of `t_eval` (increasing). The Jacobian-vector
/// products the Newton iterations need are taken by directional finite
/// differences of `rhs`. The output is interpolated between the solver's
/// own steps, which may span several times of `t_eval`.
pub fn integrate<F>(y0: &[f64], t_eval: &[f64], tol: &Tolerances, rhs: F) -> Result<Vec<Vec<f64>>>
where
    F: Fn(f64, &[f64], &mut [f64]),
{
    solve(y0, t_eval, tol, rhs, false)
}

/// [`integrate`], but the solver stops at every time of `t_eval`, so no step
/// spans two of them: a forcing `v(t)` that the solver only sees at its own
/// steps cannot change sign and back unseen inside one long step (with
/// interpolated output, BDF once stepped over a 30 ms velocity lobe of a
/// two-tone signal while an elasto-plastic `z` sat at its steady value).
pub fn integrate_stopping<F>(
    y0: &[f64],
    t_eval: &[f64],
    tol: &Tolerances,
    rhs: F,
) -> Result<Vec<Vec<f64>>>
where
    F: Fn(f64, &[f64], &mut [f64]),
{
    solve(y0, t_eval, tol, rhs, true)
}

fn solve<F>(
    y0: &[f64],
    t_eval: &[f64],
    tol: &Tolerances,
    rhs: F,
    stop_at_each: bool,
) -> Result<Vec<Vec<f64>>>
where
    F: Fn(f64, &[f64], &mut [f64]),
{
    let n = y0.len();
    let (&t0, rest) = t_eval
        .split_first()
        .ok_or_else(|| anyhow!("no evaluation times"))?;
    let mut out = Vec::with_capacity(t_eval.len());
    out.push(y0.to_vec());
    if rest.is_empty() {
        return Ok(out);
    }
    let rhs = &rhs;
    let jac = move |x: &[f64], _p: &[f64], t: f64, v: &[f64], y: &mut [f64]| {
        let norm_v = v.iter().map(|a| a * a).sum::<f64>().sqrt();
        if norm_v == 0.0 {
            y.fill(0.0);
            return;
        }
        let norm_x = x.iter().map(|a| a * a).sum::<f64>().sqrt();
        let eps = f64::EPSILON.sqrt() * (1.0 + norm_x) / norm_v;
        let xp: Vec<f64> = x.iter().zip(v).map(|(a, b)| a + eps * b).collect();
        let mut f0 = vec![0.0; x.len()];
        rhs(t, x, &mut f0);
        rhs(t, &xp, y);
        for (yi, f) in y.iter_mut().zip(&f0) {
            *yi = (*yi - f) / eps;
        }
    };
    let y0v = y0.to_vec();
    let mut problem = OdeBuilder::<NalgebraMat<f64>>::new()
        .t0(t0)
        .rtol(tol.rtol)
        .atol(tol.atol.iter().copied())
        .rhs_implicit(
            move |x: &[f64], _p: &[f64], t: f64, y: &mut [f64]| rhs(t, x, y),
            jac,
        )
        .init(
            move |_p: &[f64], _t: f64, y: &mut [f64]| y.copy_from_slice(&y0v),
            n,
        )
        .build()
        .map_err(|e| anyhow!("reference solver set-up: {e}"))?;
    // Friction right-hand sides have kinks (|v|, sign v) that a sticking mass
    // crosses thousands of times: let Newton fail and the step shrink more
    // often than the smooth-problem defaults allow before giving up.
    problem.ode_options.max_nonlinear_solver_failures = 100_000;
    problem.ode_options.max_error_test_failures = 10_000;
    let mut solver = problem
        .bdf::<NalgebraLU<f64>>()
        .map_err(|e| anyhow!("reference solver: {e}"))?;
    let failed = |e| anyhow!("reference solver failed: {e}");
    if !stop_at_each {
        let (ys, _) = solver.solve_dense(rest).map_err(failed)?;
        for j in 0..rest.len() {
            out.push((0..n).map(|i| ys[(i, j)]).collect());
        }
        return Ok(out);
    }
    for &t in rest {
        if t > solver.state().t {
            solver.set_stop_time(t).map_err(failed)?;
            while !matches!(
                solver.step().map_err(failed)?,
                OdeSolverStopReason::TstopReached
            ) {}
        }
        out.push(solver.state().y.clone_as_vec());
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stiff_linear_decay_is_accurate() {
        // dy/dt = -1e4 (y - cos t): stiff, with a known smooth solution
        let t: Vec<f64> = (0..=100).map(|k| k as f64 * 0.01).collect();
        let tol = Tolerances {
            rtol: 1e-9,
            atol: vec![1e-12],
        };
        let ys = integrate(&[1.0], &t, &tol, |t, y, dy| dy[0] = -1e4 * (y[0] - t.cos())).unwrap();
        for (ti, y) in t.iter().zip(&ys).skip(1) {
            // slow manifold: y ~ cos t + sin t / 1e4
            let expect = ti.cos() + ti.sin() * 1e-4 - ti.cos() * 1e-8;
            assert!((y[0] - expect).abs() < 1e-8, "t {ti}: {} vs {expect}", y[0]);
        }
    }

    #[test]
    fn oscillator_keeps_phase() {
        let t: Vec<f64> = (0..=50).map(|k| k as f64 * 0.2).collect();
        let tol = Tolerances {
            rtol: 1e-10,
            atol: vec![1e-12, 1e-12],
        };
        let ys = integrate(&[1.0, 0.0], &t, &tol, |_, y, dy| {
            dy[0] = y[1];
            dy[1] = -y[0];
        })
        .unwrap();
        let last = ys.last().unwrap();
        assert!((last[0] - 10f64.cos()).abs() < 1e-6, "{}", last[0]);
    }
}
