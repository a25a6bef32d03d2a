//! The regressions of the targets on the library, behind one trait ([`Optimizer`]) and on one
//! representation ([`Problem`]: ΘᵀΘ and ΘᵀY for the ridge and LASSO steps, the QR triangle for
//! the least-squares steps, made from Θ whole or reduced by blocks of rows):
//! - [`Stlsq`], sequentially thresholded least squares, PySINDy's default (`pysindy.STLSQ`);
//! - [`Lasso`], `min ½‖Θξ − y‖² + λ‖ξ‖₁` as a quadratic program solved by clarabel;
//! - [`Ridge`], `min ‖Θξ − y‖² + α‖ξ‖²`.
//!
//! [`OptimizerSpec`] is the serialisable choice a model records (STLSQ or LASSO); the
//! regularised regressions with cross-validated penalties ([`crate::RegressionSpec`]) use the same
//! optimizers. Every dense computation of an optimizer goes through [`Problem`]'s methods, and
//! from there through [`crate::linalg`], which owns the faer calls and the vector-state clearing
//! after them: an optimizer written against this trait cannot skip it.

mod gram;
mod lasso;
mod problem;
mod ridge;
pub(crate) mod row_blocks;
mod stlsq;

use faer::Mat;
use serde::{Deserialize, Serialize};

use crate::error::Result;

pub use gram::{GRAM_CONDITION_LIMIT, GRAM_RESIDUAL_SHARE};
pub use lasso::{Lasso, kkt_violation};
pub use problem::Problem;
pub use ridge::Ridge;
pub use row_blocks::{Reduction, RowReduction};
pub use stlsq::{Stlsq, StlsqFit};

/// PySINDy's default ridge strength of STLSQ.
pub const DEFAULT_ALPHA: f64 = 0.05;
/// PySINDy's default iteration limit of STLSQ.
pub const DEFAULT_MAX_ITER: usize = 20;

/// A regression of the targets on the library: ξ from a [`Problem`].
///
/// ```
/// use sindy::{Mat, Optimizer, OptimizerSpec, Problem};
/// let theta = Mat::from_fn(60, 3, |i, j| ((i * (j + 1)) as f64 * 0.3).sin());
/// let y = Mat::from_fn(60, 2, |i, j| theta[(i, j)] * (j as f64 + 1.0));
/// let optimizer = OptimizerSpec::stlsq(0.1).checked()?;
/// let xi = optimizer.solve(&Problem::new(theta.as_ref(), y.as_ref()))?;
/// assert_eq!(xi.shape(), (2, 3)); // one row per target
/// assert!((xi[(1, 1)] - 2.0).abs() < 1e-12 && xi[(1, 0)] == 0.0);
/// # Ok::<(), sindy::SindyError>(())
/// ```
pub trait Optimizer: std::fmt::Debug + Send + Sync {
    /// ξ: one row per target of `problem`, one column per feature.
    fn solve(&self, problem: &Problem<'_>) -> Result<Mat<f64>>;
}

fn default_alpha() -> f64 {
    DEFAULT_ALPHA
}

fn default_max_iter() -> usize {
    DEFAULT_MAX_ITER
}

/// A serialisable optimizer choice (unchecked; see [`OptimizerSpec::checked`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum OptimizerSpec {
    /// Sequentially thresholded ridge regression, PySINDy's semantics.
    Stlsq {
        threshold: f64,
        #[serde(default = "default_alpha")]
        alpha: f64,
        #[serde(default = "default_max_iter")]
        max_iter: usize,
    },
    /// `min ½‖Θξ − ẋ‖² + λ‖ξ‖₁`, solved by clarabel.
    Lasso { lambda: f64 },
}

impl OptimizerSpec {
    /// STLSQ with PySINDy's defaults for alpha (0.05) and max_iter (20).
    pub fn stlsq(threshold: f64) -> Self {
        Self::Stlsq {
            threshold,
            alpha: DEFAULT_ALPHA,
            max_iter: DEFAULT_MAX_ITER,
        }
    }

    /// The optimizer, its parameters validated.
    pub fn checked(&self) -> Result<Box<dyn Optimizer>> {
        Ok(match *self {
            Self::Stlsq {
                threshold,
                alpha,
                max_iter,
            } => Box::new(Stlsq::new(threshold, alpha, max_iter)?),
            Self::Lasso { lambda } => Box::new(Lasso::new(lambda)?),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn specifications_are_checked_and_defaulted() {
        let spec: OptimizerSpec =
            serde_json::from_str(r#"{"kind": "stlsq", "threshold": 0.2}"#).unwrap();
        assert_eq!(spec, OptimizerSpec::stlsq(0.2));
        assert!(OptimizerSpec::stlsq(-0.1).checked().is_err());
        assert!(
            OptimizerSpec::Stlsq {
                threshold: 0.1,
                alpha: 0.05,
                max_iter: 0
            }
            .checked()
            .is_err()
        );
        assert!(OptimizerSpec::Lasso { lambda: f64::NAN }.checked().is_err());
        let message = OptimizerSpec::Lasso { lambda: -1.0 }
            .checked()
            .unwrap_err()
            .to_string();
        assert!(
            message.contains("lambda") && message.contains("-1"),
            "{message}"
        );
    }
}
