//! Sequentially thresholded least squares with PySINDy's semantics (`pysindy.STLSQ`, 2.1).
//!
//! For each target column y independently (PySINDy iterates all targets together, but a target
//! whose active set stops changing is at a fixed point, so the results are identical):
//! 1. the reference pattern is the non-zero pattern of the plain least-squares solution on all
//!    features (PySINDy's `history_[0]`), generically "all active";
//! 2. iteration k = 1..=max_iter: ridge regression `min ||Θ_S ξ − y||² + α||ξ||²` on the active
//!    set S (scikit-learn's Cholesky ridge, no column normalisation, no intercept); features with
//!    `|ξ_j| ≥ threshold` stay (an inactive feature counts as ξ_j = 0, so threshold 0 keeps all);
//!    stop when the non-zero pattern equals the previous one, or every feature is still active;
//! 3. the kept terms (|ξ| > 1e-14) are refitted by unregularised least squares (`unbias`).

use faer::{Mat, MatRef};
use rayon::prelude::*;

use super::{Optimizer, Problem};
use crate::error::{Result, invalid};

/// Work per target above which targets are fitted in parallel: features³ for the ridge steps on
/// the Gram matrix and the refit on R (p × p), samples × features² when the refit needs Θ itself
/// (see [`Problem::least_squares_on`]). Below it, waking rayon's threads costs more than the work
/// (measured: the paper's 14-feature fits were ~2x slower in parallel).
const PARALLEL_WORK: usize = 100_000;

/// Checked STLSQ settings (`pysindy.STLSQ(threshold, alpha, max_iter)`).
///
/// ```
/// use sindy::{Mat, Stlsq};
/// // y = 2·θ₁ exactly, three features
/// let theta = Mat::from_fn(50, 3, |i, j| ((i + 1) as f64 * (j + 1) as f64 * 0.1).cos());
/// let y = Mat::from_fn(50, 1, |i, _| 2.0 * theta[(i, 1)]);
/// let fit = Stlsq::new(0.1, 0.05, 20)?.fit(theta.as_ref(), y.as_ref());
/// assert_eq!(fit.coefficients[(0, 0)], 0.0);
/// assert!((fit.coefficients[(0, 1)] - 2.0).abs() < 1e-12);
/// # Ok::<(), sindy::SindyError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stlsq {
    threshold: f64,
    alpha: f64,
    max_iter: usize,
}

/// The result of one STLSQ fit.
#[derive(Clone, Debug)]
pub struct StlsqFit {
    /// ξ, one row per target, one column per feature (PySINDy's `coef_`).
    pub coefficients: Mat<f64>,
    /// Thresholding iterations each target ran before its active set stopped changing.
    pub iterations: Vec<usize>,
}

impl Stlsq {
    /// Checks `threshold ≥ 0`, `alpha ≥ 0` (both finite) and `max_iter ≥ 1`.
    pub fn new(threshold: f64, alpha: f64, max_iter: usize) -> Result<Self> {
        if !(threshold.is_finite() && threshold >= 0.0) {
            return Err(invalid(
                "STLSQ threshold",
                format!("{threshold} must be ≥ 0"),
            ));
        }
        if !(alpha.is_finite() && alpha >= 0.0) {
            return Err(invalid("STLSQ alpha", format!("{alpha} must be ≥ 0")));
        }
        if max_iter == 0 {
            return Err(invalid("STLSQ max_iter", "must be at least 1"));
        }
        Ok(Self {
            threshold,
            alpha,
            max_iter,
        })
    }

    /// Fits every column of `targets` (n × targets) on the library `theta` (n × features).
    pub fn fit(&self, theta: MatRef<'_, f64>, targets: MatRef<'_, f64>) -> StlsqFit {
        self.fit_problem(&Problem::new(theta, targets))
    }

    /// Fits every target of `problem`, with the iterations each ran ([`Optimizer::solve`] keeps
    /// the coefficients only).
    pub fn fit_problem(&self, problem: &Problem<'_>) -> StlsqFit {
        let (features, targets) = (problem.features(), problem.targets());
        let reference = problem.least_squares_solution();
        let fit_target = |i: usize| -> (Vec<f64>, usize) {
            let reference_pattern: Vec<bool> =
                (0..features).map(|j| reference[(j, i)] != 0.0).collect();
            let (support, iterations) = self.select(problem, i, reference_pattern);
            (problem.least_squares_on(i, &support), iterations)
        };
        let columns: Vec<(Vec<f64>, usize)> =
            if problem.least_squares_work() >= PARALLEL_WORK && targets > 1 {
                (0..targets).into_par_iter().map(fit_target).collect()
            } else {
                (0..targets).map(fit_target).collect()
            };
        StlsqFit {
            coefficients: Mat::from_fn(targets, features, |i, j| columns[i].0[j]),
            iterations: columns.iter().map(|c| c.1).collect(),
        }
    }

    /// The thresholding iterations of target `target`: the kept features (|ξ| > 1e-14) and the
    /// number of iterations run.
    fn select(
        &self,
        problem: &Problem<'_>,
        target: usize,
        mut previous_pattern: Vec<bool>,
    ) -> (Vec<usize>, usize) {
        let (features, moments) = (problem.features(), problem.moments());
        let mut active: Vec<usize> = (0..features).collect();
        let mut coefficients = vec![0.0; features];
        let mut iterations = 0;
        for k in 1..=self.max_iter {
            iterations = k;
            coefficients.iter_mut().for_each(|c| *c = 0.0);
            if !active.is_empty() {
                let rhs = Mat::from_fn(active.len(), 1, |a, _| moments[(active[a], target)]);
                let ridge = problem.ridge_on(&active, rhs.as_ref(), self.alpha);
                for (a, &j) in active.iter().enumerate() {
                    coefficients[j] = ridge[(a, 0)];
                }
            }
            // PySINDy thresholds every feature, inactive ones counting as zero.
            let kept: Vec<usize> = (0..features)
                .filter(|&j| coefficients[j].abs() >= self.threshold)
                .collect();
            // Zeroes exactly what `kept` leaves out (a NaN from a broken solve included).
            for c in coefficients.iter_mut() {
                if c.is_nan() || c.abs() < self.threshold {
                    *c = 0.0;
                }
            }
            let pattern: Vec<bool> = coefficients.iter().map(|&c| c != 0.0).collect();
            let all_active = kept.len() == features;
            active = kept;
            if all_active || pattern == previous_pattern {
                break;
            }
            previous_pattern = pattern;
        }
        let support = (0..features)
            .filter(|&j| coefficients[j].abs() > 1e-14)
            .collect();
        (support, iterations)
    }
}

impl Optimizer for Stlsq {
    fn solve(&self, problem: &Problem<'_>) -> Result<Mat<f64>> {
        Ok(self.fit_problem(problem).coefficients)
    }
}
