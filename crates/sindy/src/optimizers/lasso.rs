//! LASSO, `min ½‖Θξ − y‖² + λ‖ξ‖₁` for each target column, as a quadratic program solved by
//! clarabel, then polished on the found support.
//!
//! (scikit-learn's `Lasso(alpha)` minimises `1/(2n)‖Θξ − y‖² + alpha‖ξ‖₁`: the same problem with
//! `alpha = λ/n`.)
//!
//! QP in the Gram form (the library is tall, n ≫ p): variables `[ξ; t]` (2p),
//! `P = blockdiag(ΘᵀΘ, 0)`, `q = [−Θᵀy; λ·1]`, subject to `ξ − t ≤ 0` and `−ξ − t ≤ 0`
//! (a non-negative cone of dimension 2p); at the optimum `t = |ξ|`. The interior-point solution is
//! then polished by an active set started from its support S and signs s: the optimum solves
//! `Θ_SᵀΘ_S ξ_S = Θ_Sᵀy − λs`, coefficients whose sign flips leave S, violating zeros enter it; the
//! polished point is kept when it satisfies the KKT conditions at least as well.
//! [`kkt_violation`] measures how far any ξ is from optimal.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};
use faer::{Mat, MatRef};
use rayon::prelude::*;

use super::{Optimizer, Problem};
use crate::error::{Result, SindyError, invalid};

/// Checked LASSO settings.
///
/// ```
/// use sindy::{Lasso, Mat};
/// // y = θ₀ − 2·θ₁ exactly: a small λ keeps both terms and drops the third
/// let theta = Mat::from_fn(80, 3, |i, j| ((i * (j + 2)) as f64 * 0.21).sin());
/// let y = Mat::from_fn(80, 1, |i, _| theta[(i, 0)] - 2.0 * theta[(i, 1)]);
/// let xi = Lasso::new(1e-3)?.fit(theta.as_ref(), y.as_ref(), &["y".to_string()])?;
/// assert!((xi[(0, 0)] - 1.0).abs() < 1e-3 && (xi[(0, 1)] + 2.0).abs() < 1e-3);
/// assert_eq!(xi[(0, 2)], 0.0);
/// # Ok::<(), sindy::SindyError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lasso {
    lambda: f64,
}

impl Lasso {
    /// Checks `lambda ≥ 0` and finite.
    pub fn new(lambda: f64) -> Result<Self> {
        if !(lambda.is_finite() && lambda >= 0.0) {
            return Err(invalid("LASSO lambda", format!("{lambda} must be ≥ 0")));
        }
        Ok(Self { lambda })
    }

    /// Fits every column of `targets` on `theta`; ξ one row per target, one column per feature.
    /// `target_names` label errors.
    pub fn fit(
        &self,
        theta: MatRef<'_, f64>,
        targets: MatRef<'_, f64>,
        target_names: &[String],
    ) -> Result<Mat<f64>> {
        self.solve(&Problem::new(theta, targets).with_target_names(target_names))
    }

    /// One target: the QP on ΘᵀΘ and Θᵀy (the objective up to a constant), then the polish.
    fn fit_one(&self, problem: &Problem<'_>, target: usize) -> Result<Vec<f64>> {
        let (gram, moments) = (problem.gram(), problem.moments().col(target).as_mat());
        let name = problem.target_name(target);
        let p = gram.nrows();
        let solver_error = |message: String| SindyError::Solver {
            solver: "clarabel LASSO",
            target: name.clone(),
            message,
        };
        // P: upper triangle of ΘᵀΘ in the ξ block, column by column.
        let (mut rows, mut cols, mut values) = (Vec::new(), Vec::new(), Vec::new());
        for j in 0..p {
            for i in 0..=j {
                rows.push(i);
                cols.push(j);
                values.push(gram[(i, j)]);
            }
        }
        let quadratic = CscMatrix::new_from_triplets(2 * p, 2 * p, rows, cols, values);
        let mut linear: Vec<f64> = (0..p).map(|j| -moments[(j, 0)]).collect();
        linear.extend(std::iter::repeat_n(self.lambda, p));
        // Rows 0..p: ξ − t (+ s = 0); rows p..2p: −ξ − t.
        let (mut rows, mut cols, mut values) = (Vec::new(), Vec::new(), Vec::new());
        for j in 0..p {
            rows.extend([j, p + j, j, p + j]);
            cols.extend([j, j, p + j, p + j]);
            values.extend([1.0, -1.0, -1.0, -1.0]);
        }
        let constraints = CscMatrix::new_from_triplets(2 * p, 2 * p, rows, cols, values);
        let bounds = vec![0.0; 2 * p];
        let cones = [SupportedConeT::NonnegativeConeT(2 * p)];
        let settings = DefaultSettingsBuilder::default()
            .verbose(false)
            .tol_gap_abs(1e-11)
            .tol_gap_rel(1e-11)
            .tol_feas(1e-11)
            .build()
            .map_err(|e| solver_error(e.to_string()))?;
        let mut solver =
            DefaultSolver::new(&quadratic, &linear, &constraints, &bounds, &cones, settings)
                .map_err(|e| solver_error(e.to_string()))?;
        solver.solve();
        match solver.solution.status {
            SolverStatus::Solved | SolverStatus::AlmostSolved => {}
            status => return Err(solver_error(format!("status {status:?}"))),
        }
        let solution: Vec<f64> = solver.solution.x[..p].to_vec();
        Ok(self.polish(problem, target, solution))
    }

    /// The exact optimum by an active set started from the interior-point `solution`'s support and
    /// signs: coefficients whose sign flips on re-solving are dropped, the zero coefficient that
    /// violates its condition most enters with its gradient's sign. The best point seen (the
    /// interior-point one included) by the KKT conditions is returned.
    fn polish(&self, problem: &Problem<'_>, target: usize, solution: Vec<f64>) -> Vec<f64> {
        let (gram, moments) = (problem.gram(), problem.moments().col(target).as_mat());
        let p = solution.len();
        let scale = solution
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()))
            .max(1e-300);
        let mut signs: Vec<f64> = solution
            .iter()
            .map(|v| {
                if v.abs() > 1e-7 * scale {
                    v.signum()
                } else {
                    0.0
                }
            })
            .collect();
        let mut best_violation = gram_kkt_violation(gram, moments, &solution, self.lambda);
        let mut best = solution;
        for _ in 0..2 * p + 2 {
            let candidate = self.optimum_on_signs(problem, target, &signs);
            let flipped: Vec<usize> = (0..p)
                .filter(|&j| {
                    signs[j] != 0.0
                        && !(candidate[j].signum() == signs[j] && candidate[j].is_finite())
                })
                .collect();
            if !flipped.is_empty() {
                flipped.iter().for_each(|&j| signs[j] = 0.0);
                continue;
            }
            let violation = gram_kkt_violation(gram, moments, &candidate, self.lambda);
            if violation <= best_violation {
                (best, best_violation) = (candidate.clone(), violation);
            }
            match most_violating_zero(gram, moments, &candidate, self.lambda) {
                Some((j, gradient)) => signs[j] = gradient.signum(),
                None => break,
            }
        }
        best
    }

    /// The stationary point of the objective with the coefficients' signs fixed (zero where the
    /// sign is zero): `Θ_SᵀΘ_S ξ_S = Θ_Sᵀy − λs` on the support S.
    fn optimum_on_signs(&self, problem: &Problem<'_>, target: usize, signs: &[f64]) -> Vec<f64> {
        let moments = problem.moments().col(target).as_mat();
        let support: Vec<usize> = (0..signs.len()).filter(|&j| signs[j] != 0.0).collect();
        let mut optimum = vec![0.0; signs.len()];
        if !support.is_empty() {
            let rhs = Mat::from_fn(support.len(), 1, |a, _| {
                moments[(support[a], 0)] - self.lambda * signs[support[a]]
            });
            let exact = problem.ridge_on(&support, rhs.as_ref(), 0.0);
            for (a, &j) in support.iter().enumerate() {
                optimum[j] = exact[(a, 0)];
            }
        }
        optimum
    }
}

/// The zero coefficient whose gradient `g_j = (Θᵀ(y − Θξ))_j` exceeds λ the most, with `g_j`.
fn most_violating_zero(
    gram: MatRef<'_, f64>,
    moments: MatRef<'_, f64>,
    coefficients: &[f64],
    lambda: f64,
) -> Option<(usize, f64)> {
    let tolerance = 1e-12
        * (lambda + (0..coefficients.len()).fold(0.0f64, |m, j| m.max(moments[(j, 0)].abs())));
    (0..coefficients.len())
        .filter(|&j| coefficients[j] == 0.0)
        .map(|j| {
            let fitted: f64 = (0..coefficients.len())
                .map(|k| gram[(j, k)] * coefficients[k])
                .sum();
            (j, moments[(j, 0)] - fitted)
        })
        .filter(|&(_, gradient)| gradient.abs() - lambda > tolerance)
        .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()))
}

/// Largest violation of the LASSO optimality conditions by ξ for one target, with
/// g = Θᵀ(y − Θξ): `|g_j − λ·sign(ξ_j)|` where ξ_j ≠ 0, `max(|g_j| − λ, 0)` where ξ_j = 0.
/// Zero at the exact optimum.
pub fn kkt_violation(
    theta: MatRef<'_, f64>,
    target: &[f64],
    coefficients: &[f64],
    lambda: f64,
) -> f64 {
    let y = Mat::from_fn(target.len(), 1, |i, _| target[i]);
    let problem = Problem::new(theta, y.as_ref());
    gram_kkt_violation(problem.gram(), problem.moments(), coefficients, lambda)
}

fn gram_kkt_violation(
    gram: MatRef<'_, f64>,
    moments: MatRef<'_, f64>,
    coefficients: &[f64],
    lambda: f64,
) -> f64 {
    (0..coefficients.len())
        .map(|j| {
            let fitted: f64 = (0..coefficients.len())
                .map(|k| gram[(j, k)] * coefficients[k])
                .sum();
            let gradient = moments[(j, 0)] - fitted;
            if coefficients[j] != 0.0 {
                (gradient - lambda * coefficients[j].signum()).abs()
            } else {
                (gradient.abs() - lambda).max(0.0)
            }
        })
        .fold(0.0, f64::max)
}

impl Optimizer for Lasso {
    /// Every target in parallel (one QP each).
    fn solve(&self, problem: &Problem<'_>) -> Result<Mat<f64>> {
        let columns = (0..problem.targets())
            .into_par_iter()
            .map(|i| self.fit_one(problem, i))
            .collect::<Result<Vec<_>>>()?;
        Ok(Mat::from_fn(
            problem.targets(),
            problem.features(),
            |i, j| columns[i][j],
        ))
    }
}
