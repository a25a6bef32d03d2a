//! Ridge regression, `min ‖Θξ − y‖² + α‖ξ‖²` for each target column (scikit-learn's
//! `Ridge(alpha, fit_intercept=False)`, Cholesky solver; α = 0 is least squares on the normal
//! equations, the pseudo-inverse when they are singular). Dense: no feature is dropped.

use faer::Mat;

use super::{Optimizer, Problem};
use crate::error::{Result, invalid};

/// Checked ridge settings.
///
/// ```
/// use sindy::{Mat, Optimizer, Problem, Ridge};
/// let theta = Mat::from_fn(40, 2, |i, j| (i as f64 * 0.1).powi(j as i32));
/// let y = Mat::from_fn(40, 1, |i, _| 1.0 + 0.5 * i as f64 * 0.1);
/// let xi = Ridge::new(0.0)?.solve(&Problem::new(theta.as_ref(), y.as_ref()))?;
/// assert!((xi[(0, 0)] - 1.0).abs() < 1e-10 && (xi[(0, 1)] - 0.5).abs() < 1e-10);
/// # Ok::<(), sindy::SindyError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ridge {
    alpha: f64,
}

impl Ridge {
    /// Checks `alpha ≥ 0` and finite.
    pub fn new(alpha: f64) -> Result<Self> {
        if !(alpha.is_finite() && alpha >= 0.0) {
            return Err(invalid("ridge alpha", format!("{alpha} must be ≥ 0")));
        }
        Ok(Self { alpha })
    }
}

impl Optimizer for Ridge {
    /// Every target at once: `(ΘᵀΘ + α·I)·ξ = ΘᵀY`.
    fn solve(&self, problem: &Problem<'_>) -> Result<Mat<f64>> {
        let every: Vec<usize> = (0..problem.features()).collect();
        let solution = problem.ridge_on(&every, problem.moments(), self.alpha);
        Ok(solution.transpose().to_owned())
    }
}
