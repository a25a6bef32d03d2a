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

use crate::error::{Result, invalid};
use crate::linalg::{
    CholeskyQr, full_rank_triangular_rows, householder_least_squares, least_squares, product,
    ridge_from_gram, solve_upper,
};
use crate::reduced::ReducedProblem;

/// Work per target above which targets are fitted in parallel: features³ for the ridge steps on
/// the Gram matrix and the refit on R (p × p), samples × features² when the refit needs Θ itself
/// (no reduced problem). Below it, waking rayon's threads costs more than the work (measured: the
/// paper's 14-feature fits were ~2x slower in parallel).
const PARALLEL_WORK: usize = 100_000;

/// Checked STLSQ settings.
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
        let gram = product(theta.transpose(), theta);
        let moments = product(theta.transpose(), targets);
        let reduced = LibraryQr::new(theta, targets, gram.as_ref());
        let reference = match &reduced {
            Some(reduced) => reduced.solution.clone(),
            None => least_squares(theta, targets),
        };
        let fit_target = |i: usize| -> (Vec<f64>, usize) {
            let reference_pattern: Vec<bool> = (0..theta.ncols())
                .map(|j| reference[(j, i)] != 0.0)
                .collect();
            let support = self.select(gram.as_ref(), moments.col(i).as_mat(), reference_pattern);
            (
                refit(
                    theta,
                    targets.col(i).as_mat(),
                    reduced.as_ref(),
                    i,
                    &support.0,
                ),
                support.1,
            )
        };
        let features = theta.ncols();
        let work = match reduced {
            Some(_) => features * features * features,
            None => theta.nrows() * features * features,
        };
        let columns: Vec<(Vec<f64>, usize)> = if work >= PARALLEL_WORK && targets.ncols() > 1 {
            (0..targets.ncols())
                .into_par_iter()
                .map(fit_target)
                .collect()
        } else {
            (0..targets.ncols()).map(fit_target).collect()
        };
        let coefficients = Mat::from_fn(targets.ncols(), theta.ncols(), |i, j| columns[i].0[j]);
        StlsqFit {
            coefficients,
            iterations: columns.iter().map(|c| c.1).collect(),
        }
    }

    /// Fits every target of a problem reduced by rows ([`ReducedProblem`]): the same steps on
    /// RᵀR, RᵀZ and R instead of ΘᵀΘ, ΘᵀY and Θ.
    pub fn fit_reduced(&self, reduced: &ReducedProblem) -> StlsqFit {
        let r = reduced.triangular();
        let projected = reduced.projected();
        let (features, targets) = (r.ncols(), projected.ncols());
        let gram = reduced.gram();
        let moments = reduced.moments();
        let reference = match full_rank_triangular_rows(r, reduced.rows()) {
            true => solve_upper(r, projected),
            false => least_squares(r, projected),
        };
        let fit_target = |i: usize| -> (Vec<f64>, usize) {
            let reference_pattern: Vec<bool> =
                (0..features).map(|j| reference[(j, i)] != 0.0).collect();
            let (support, iterations) =
                self.select(gram.as_ref(), moments.col(i).as_mat(), reference_pattern);
            let mut unbiased = vec![0.0; features];
            if !support.is_empty() {
                let sub = Mat::from_fn(features, support.len(), |k, a| r[(k, support[a])]);
                let solution = least_squares(sub.as_ref(), projected.col(i).as_mat());
                for (a, &j) in support.iter().enumerate() {
                    unbiased[j] = solution[(a, 0)];
                }
            }
            (unbiased, iterations)
        };
        let columns: Vec<(Vec<f64>, usize)> =
            if features * features * features >= PARALLEL_WORK && targets > 1 {
                (0..targets).into_par_iter().map(fit_target).collect()
            } else {
                (0..targets).map(fit_target).collect()
            };
        StlsqFit {
            coefficients: Mat::from_fn(targets, features, |i, j| columns[i].0[j]),
            iterations: columns.iter().map(|c| c.1).collect(),
        }
    }

    /// The thresholding iterations of one target: the kept features (|ξ| > 1e-14) and the
    /// number of iterations run.
    fn select(
        &self,
        gram: MatRef<'_, f64>,
        moments: MatRef<'_, f64>,
        mut previous_pattern: Vec<bool>,
    ) -> (Vec<usize>, usize) {
        let features = gram.ncols();
        let mut active: Vec<usize> = (0..features).collect();
        let mut coefficients = vec![0.0; features];
        let mut iterations = 0;
        for k in 1..=self.max_iter {
            iterations = k;
            coefficients.iter_mut().for_each(|c| *c = 0.0);
            if !active.is_empty() {
                let sub_gram = Mat::from_fn(active.len(), active.len(), |a, b| {
                    gram[(active[a], active[b])]
                });
                let sub_moments = Mat::from_fn(active.len(), 1, |a, _| moments[(active[a], 0)]);
                let ridge = ridge_from_gram(sub_gram.as_ref(), sub_moments.as_ref(), self.alpha);
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

/// Θ = QR of the full library, with Qᵀy for every target: a least-squares problem on a subset S
/// of the columns, `min ‖Θ_S ξ − y‖`, equals `min ‖R_S ξ − Qᵀy‖` (p rows instead of n), solved
/// as stably as a QR of Θ_S. The QR comes from CholeskyQR2 on the Gram matrix already formed
/// for the ridge steps, or from Householder when Θ is too ill-conditioned for it. `None` when Θ
/// is wide or rank-deficient.
struct LibraryQr {
    triangular: Mat<f64>,
    projected: Mat<f64>,
    /// The least-squares solution on all features, one column per target.
    solution: Mat<f64>,
}

impl LibraryQr {
    fn new(
        theta: MatRef<'_, f64>,
        targets: MatRef<'_, f64>,
        gram: MatRef<'_, f64>,
    ) -> Option<Self> {
        if let Some(qr) = CholeskyQr::new(theta, gram) {
            let projected = qr.project(targets);
            let solution = solve_upper(qr.r(), projected.as_ref());
            return Some(Self {
                triangular: qr.r().to_owned(),
                projected,
                solution,
            });
        }
        let (triangular, solution) = householder_least_squares(theta, targets)?;
        // Qᵀy = R·ξ_ls.
        let projected = product(triangular.as_ref(), solution.as_ref());
        Some(Self {
            triangular,
            projected,
            solution,
        })
    }
}

/// The unregularised least-squares refit on `support` (PySINDy's `unbias` step).
fn refit(
    theta: MatRef<'_, f64>,
    target: MatRef<'_, f64>,
    reduced: Option<&LibraryQr>,
    index: usize,
    support: &[usize],
) -> Vec<f64> {
    let mut unbiased = vec![0.0; theta.ncols()];
    if support.is_empty() {
        return unbiased;
    }
    let solution = match reduced {
        Some(reduced) => {
            let r = &reduced.triangular;
            let sub = Mat::from_fn(r.nrows(), support.len(), |i, a| r[(i, support[a])]);
            least_squares(sub.as_ref(), reduced.projected.col(index).as_mat())
        }
        None => {
            let sub = Mat::from_fn(theta.nrows(), support.len(), |i, a| theta[(i, support[a])]);
            least_squares(sub.as_ref(), target)
        }
    };
    for (a, &j) in support.iter().enumerate() {
        unbiased[j] = solution[(a, 0)];
    }
    unbiased
}
