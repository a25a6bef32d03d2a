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
use crate::linalg::{least_squares, ridge_from_gram};

/// Work (samples × features²) above which targets are fitted in parallel.
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
        let gram = theta.transpose() * theta;
        let moments = theta.transpose() * targets;
        let reference = least_squares(theta, targets);
        let fit_target = |i: usize| -> (Vec<f64>, usize) {
            let reference_pattern: Vec<bool> = (0..theta.ncols())
                .map(|j| reference[(j, i)] != 0.0)
                .collect();
            self.fit_one(
                theta,
                targets.col(i).as_mat(),
                gram.as_ref(),
                moments.col(i).as_mat(),
                reference_pattern,
            )
        };
        let work = theta.nrows() * theta.ncols() * theta.ncols();
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

    fn fit_one(
        &self,
        theta: MatRef<'_, f64>,
        target: MatRef<'_, f64>,
        gram: MatRef<'_, f64>,
        moments: MatRef<'_, f64>,
        mut previous_pattern: Vec<bool>,
    ) -> (Vec<f64>, usize) {
        let features = theta.ncols();
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
            for (j, c) in coefficients.iter_mut().enumerate() {
                if c.abs() < self.threshold {
                    *c = 0.0;
                }
                debug_assert!(*c == 0.0 || kept.contains(&j));
            }
            let pattern: Vec<bool> = coefficients.iter().map(|&c| c != 0.0).collect();
            let all_active = kept.len() == features;
            active = kept;
            if all_active || pattern == previous_pattern {
                break;
            }
            previous_pattern = pattern;
        }
        let support: Vec<usize> = (0..features)
            .filter(|&j| coefficients[j].abs() > 1e-14)
            .collect();
        let mut unbiased = vec![0.0; features];
        if !support.is_empty() {
            let sub_theta =
                Mat::from_fn(theta.nrows(), support.len(), |i, a| theta[(i, support[a])]);
            let refit = least_squares(sub_theta.as_ref(), target);
            for (a, &j) in support.iter().enumerate() {
                unbiased[j] = refit[(a, 0)];
            }
        }
        (unbiased, iterations)
    }
}
