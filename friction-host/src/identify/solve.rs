//! The numerics: linear least squares (nalgebra's SVD) and nonlinear least
//! squares (the `levenberg-marquardt` crate, a port of MINPACK's `lmder`),
//! with the parameters' standard deviations from the Jacobian at the
//! optimum, `cov = s^2 (J^T J)^-1`, `s^2 = |r|^2 / (m - p)`.

use indicatif::ProgressBar;
use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt, TerminationReason};
use nalgebra::{storage::Owned, DMatrix, DVector, Dyn};

/// Why a fit is not trusted.
#[derive(Clone, Debug, PartialEq)]
pub enum FitFailure {
    /// The regressor has (numerically) dependent columns: the data do not
    /// tell this parameter apart from the others.
    NotIdentifiable {
        /// The parameter most involved in the dependency.
        parameter: String,
        /// Smallest over largest singular value of the scaled regressor.
        ratio: f64,
    },
    /// The iteration ran out of function evaluations.
    NotConverged {
        /// Residual evaluations spent.
        evaluations: usize,
        /// The cost `|r|^2 / 2` where it stopped.
        cost: f64,
    },
    /// The iteration stopped where the gradient of the cost vanishes
    /// without the cost settling (a plateau: some parameter has no effect).
    ZeroGradient {
        /// The largest cosine between the residual and a Jacobian column.
        cosine: f64,
        /// Residual evaluations spent.
        evaluations: usize,
    },
    /// The residuals became NaN or infinite.
    Numerical(String),
}

impl std::fmt::Display for FitFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::NotIdentifiable { parameter, ratio } => write!(
                f,
                "`{parameter}` is not identifiable from these data: the regressor is rank-deficient (smallest/largest singular value {ratio:.2e})"
            ),
            Self::NotConverged { evaluations, cost } => write!(
                f,
                "the fit did not converge: it stopped after {evaluations} evaluations with the cost |r|^2/2 = {cost:.6e} still changing"
            ),
            Self::ZeroGradient { cosine, evaluations } => write!(
                f,
                "the fit stopped at a zero gradient after {evaluations} evaluations (largest cosine between residual and Jacobian columns {cosine:.2e}): a parameter has no effect on the force there"
            ),
            Self::Numerical(what) => write!(f, "the fit failed numerically: {what}"),
        }
    }
}

/// A least-squares estimate.
#[derive(Clone, Debug)]
pub struct Estimate {
    /// The parameters.
    pub theta: Vec<f64>,
    /// Their standard deviations.
    pub std: Vec<f64>,
    /// Residuals `y - prediction`.
    pub residual: Vec<f64>,
    /// Residual evaluations (1 for a linear fit).
    pub evaluations: usize,
    /// Set when the Jacobian at the optimum is singular (the standard
    /// deviations are then infinite): which parameter has no effect.
    pub singular: Option<FitFailure>,
}

/// Columns scaled to unit norm, so the singular values measure dependency
/// rather than units.
fn scaled(columns: &DMatrix<f64>) -> (DMatrix<f64>, Vec<f64>) {
    let mut m = columns.clone();
    let mut norms = Vec::with_capacity(m.ncols());
    for mut c in m.column_iter_mut() {
        let n = c.norm();
        let n = if n > 0.0 { n } else { 1.0 };
        c /= n;
        norms.push(n);
    }
    (m, norms)
}

/// The covariance factor `(J^T J)^-1` of a Jacobian, or which parameter
/// makes it singular.
fn inverse_normal(j: &DMatrix<f64>, names: &[String]) -> Result<DMatrix<f64>, FitFailure> {
    let (js, norms) = scaled(j);
    let svd = js.svd(false, true);
    let s = &svd.singular_values;
    let (smax, smin) = (s.max(), s.min());
    let vt = svd.v_t.as_ref().expect("v_t computed");
    if smin.is_nan() || smin <= 1e-10 * smax {
        let k = s.imin();
        let p = (0..vt.ncols())
            .max_by(|&a, &b| vt[(k, a)].abs().total_cmp(&vt[(k, b)].abs()))
            .unwrap_or(0);
        return Err(FitFailure::NotIdentifiable {
            parameter: names[p].clone(),
            ratio: smin / smax,
        });
    }
    let p = j.ncols();
    let mut inv = DMatrix::zeros(p, p);
    for a in 0..p {
        for b in 0..p {
            let mut sum = 0.0;
            for k in 0..p {
                sum += vt[(k, a)] * vt[(k, b)] / (s[k] * s[k]);
            }
            inv[(a, b)] = sum / (norms[a] * norms[b]);
        }
    }
    Ok(inv)
}

fn std_from(inv: &DMatrix<f64>, residual: &[f64]) -> Vec<f64> {
    let (m, p) = (residual.len(), inv.ncols());
    let s2 = residual.iter().map(|r| r * r).sum::<f64>() / (m.saturating_sub(p).max(1)) as f64;
    (0..p).map(|i| (s2 * inv[(i, i)]).sqrt()).collect()
}

/// Ordinary least squares `y ~ X theta` for the columns of `X`.
pub fn linear(columns: &[Vec<f64>], y: &[f64], names: &[String]) -> Result<Estimate, FitFailure> {
    let m = y.len();
    let x = DMatrix::from_fn(m, columns.len(), |i, j| columns[j][i]);
    let inv = inverse_normal(&x, names)?;
    let theta = &inv * (x.transpose() * DVector::from_column_slice(y));
    let pred = &x * &theta;
    let residual: Vec<f64> = y.iter().zip(pred.iter()).map(|(a, b)| a - b).collect();
    Ok(Estimate {
        std: std_from(&inv, &residual),
        theta: theta.iter().copied().collect(),
        residual,
        evaluations: 1,
        singular: None,
    })
}

struct Problem<'a> {
    u: DVector<f64>,
    scale: Vec<f64>,
    residual: &'a dyn Fn(&[f64]) -> Option<Vec<f64>>,
    progress: &'a ProgressBar,
}

impl Problem<'_> {
    fn natural(&self, u: &DVector<f64>) -> Vec<f64> {
        u.iter().zip(&self.scale).map(|(a, s)| a * s).collect()
    }
    fn eval(&self, u: &DVector<f64>) -> Option<Vec<f64>> {
        self.progress.inc(1);
        (self.residual)(&self.natural(u))
    }
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, u: &DVector<f64>) {
        self.u.copy_from(u);
    }
    fn params(&self) -> DVector<f64> {
        self.u.clone()
    }
    fn residuals(&self) -> Option<DVector<f64>> {
        let r = self.eval(&self.u)?;
        r.iter()
            .all(|x| x.is_finite())
            .then(|| DVector::from_vec(r))
    }
    fn jacobian(&self) -> Option<DMatrix<f64>> {
        // central differences in the scaled parameters
        let p = self.u.len();
        let mut cols = Vec::with_capacity(p);
        for i in 0..p {
            let step = 1e-6 * self.u[i].abs().max(1e-3);
            let mut up = self.u.clone();
            up[i] += step;
            let mut dn = self.u.clone();
            dn[i] -= step;
            let (a, b) = (self.eval(&up)?, self.eval(&dn)?);
            cols.push(
                a.iter()
                    .zip(&b)
                    .map(|(x, y)| (x - y) / (2.0 * step))
                    .collect::<Vec<_>>(),
            );
        }
        let m = cols.first().map_or(0, Vec::len);
        let j = DMatrix::from_fn(m, p, |r, c| cols[c][r]);
        j.iter().all(|x| x.is_finite()).then_some(j)
    }
}

/// Nonlinear least squares: minimises `|residual(theta)|^2` from `theta0`,
/// iterating on `theta / scale`. `patience` bounds the iterations (MINPACK's
/// factor: evaluations `<= patience (p + 1)`). The progress bar ticks once per
/// residual evaluation.
pub fn nonlinear(
    residual: &dyn Fn(&[f64]) -> Option<Vec<f64>>,
    theta0: &[f64],
    scale: &[f64],
    names: &[String],
    patience: usize,
    progress: &ProgressBar,
) -> Result<Estimate, FitFailure> {
    let problem = Problem {
        u: DVector::from_iterator(theta0.len(), theta0.iter().zip(scale).map(|(t, s)| t / s)),
        scale: scale.to_vec(),
        residual,
        progress,
    };
    let (problem, report) = LevenbergMarquardt::new()
        .with_ftol(1e-10)
        .with_xtol(1e-10)
        .with_gtol(0.0)
        .with_patience(patience)
        .minimize(problem);
    let evaluations = report.number_of_evaluations;
    let theta = problem.natural(&problem.u);
    let r = (problem.residual)(&theta)
        .filter(|r| r.iter().all(|x| x.is_finite()))
        .ok_or_else(|| {
            FitFailure::Numerical("the residuals at the optimum are not finite".into())
        })?;
    let j = problem
        .jacobian()
        .ok_or_else(|| FitFailure::Numerical("the Jacobian at the optimum is not finite".into()))?;
    let cosine = || {
        let rn = r.iter().map(|x| x * x).sum::<f64>().sqrt();
        j.column_iter()
            .map(|c| {
                let dot: f64 = c.iter().zip(&r).map(|(a, b)| a * b).sum();
                (dot / (c.norm() * rn).max(f64::MIN_POSITIVE)).abs()
            })
            .fold(0.0, f64::max)
    };
    match report.termination {
        TerminationReason::Converged { .. }
        | TerminationReason::ResidualsZero
        | TerminationReason::NoImprovementPossible("ftol" | "xtol") => {}
        TerminationReason::Orthogonal | TerminationReason::NoImprovementPossible(_) => {
            return Err(FitFailure::ZeroGradient {
                cosine: cosine(),
                evaluations,
            })
        }
        TerminationReason::LostPatience => {
            return Err(FitFailure::NotConverged {
                evaluations,
                cost: report.objective_function,
            })
        }
        other => return Err(FitFailure::Numerical(format!("{other:?}"))),
    }
    // Jacobian in natural units
    let mut jn = j;
    for (mut c, s) in jn.column_iter_mut().zip(scale) {
        c /= *s;
    }
    let (std, singular) = match inverse_normal(&jn, names) {
        Ok(inv) => (std_from(&inv, &r), None),
        Err(e) => (vec![f64::INFINITY; theta.len()], Some(e)),
    };
    Ok(Estimate {
        std,
        theta,
        residual: r,
        evaluations,
        singular,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(n: &[&str]) -> Vec<String> {
        n.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn linear_fit_and_standard_deviations() {
        // y = 2 + 3 x with alternating +-0.1 noise
        let x: Vec<f64> = (0..100).map(|k| k as f64 / 10.0).collect();
        let y: Vec<f64> = x
            .iter()
            .enumerate()
            .map(|(k, x)| 2.0 + 3.0 * x + if k % 2 == 0 { 0.1 } else { -0.1 })
            .collect();
        let e = linear(&[vec![1.0; 100], x.clone()], &y, &names(&["a", "b"])).unwrap();
        assert!((e.theta[0] - 2.0).abs() < 0.05 && (e.theta[1] - 3.0).abs() < 0.01);
        // textbook: std(b) = s / sqrt(sum (x - mean)^2)
        let mean = x.iter().sum::<f64>() / 100.0;
        let sxx: f64 = x.iter().map(|v| (v - mean).powi(2)).sum();
        let s = (e.residual.iter().map(|r| r * r).sum::<f64>() / 98.0).sqrt();
        assert!((e.std[1] - s / sxx.sqrt()).abs() < 1e-12);
        let e = linear(
            &[x.clone(), x.iter().map(|v| 2.0 * v).collect()],
            &y,
            &names(&["a", "b"]),
        )
        .unwrap_err();
        assert!(matches!(e, FitFailure::NotIdentifiable { .. }), "{e}");
    }

    #[test]
    fn nonlinear_fit_recovers_an_exponential() {
        let t: Vec<f64> = (0..50).map(|k| k as f64 * 0.1).collect();
        let y: Vec<f64> = t.iter().map(|t| 3.0 * (-0.7 * t).exp()).collect();
        let res = |p: &[f64]| -> Option<Vec<f64>> {
            Some(
                t.iter()
                    .zip(&y)
                    .map(|(t, y)| y - p[0] * (-p[1] * t).exp())
                    .collect(),
            )
        };
        let bar = ProgressBar::hidden();
        let e = nonlinear(
            &res,
            &[1.0, 0.2],
            &[1.0, 1.0],
            &names(&["a", "k"]),
            100,
            &bar,
        )
        .unwrap();
        assert!(
            (e.theta[0] - 3.0).abs() < 1e-6 && (e.theta[1] - 0.7).abs() < 1e-6,
            "{:?}",
            e.theta
        );
        // a parameter with no effect: a plateau
        let flat = |p: &[f64]| -> Option<Vec<f64>> {
            Some(
                t.iter()
                    .zip(&y)
                    .map(|(t, y)| y - p[0] * (-0.7 * t).exp() - 0.0 * p[1])
                    .collect(),
            )
        };
        let e = nonlinear(
            &flat,
            &[1.0, 0.2],
            &[1.0, 1.0],
            &names(&["a", "k"]),
            100,
            &bar,
        )
        .unwrap()
        .singular
        .unwrap();
        assert!(
            matches!(e, FitFailure::NotIdentifiable { ref parameter, .. } if parameter == "k"),
            "{e}"
        );
        // no parameter has any effect: the gradient is zero from the start
        let none = |_: &[f64]| -> Option<Vec<f64>> { Some(vec![1.0, 2.0, 3.0]) };
        let e = nonlinear(&none, &[1.0], &[1.0], &names(&["a"]), 100, &bar).unwrap_err();
        assert!(matches!(e, FitFailure::ZeroGradient { .. }), "{e}");
        assert!(e.to_string().contains("zero gradient"), "{e}");
        // too few iterations
        let e =
            nonlinear(&res, &[1.0, 0.2], &[1.0, 1.0], &names(&["a", "k"]), 1, &bar).unwrap_err();
        assert!(matches!(e, FitFailure::NotConverged { .. }), "{e}");
    }
}
