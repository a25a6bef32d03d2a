//! Sparse regression of the targets on the library: STLSQ (PySINDy's default) and LASSO.

mod lasso;
mod stlsq;

use faer::{Mat, MatRef};
use serde::{Deserialize, Serialize};

use crate::error::Result;

pub use lasso::{Lasso, kkt_violation};
pub use stlsq::{Stlsq, StlsqFit};

/// PySINDy's default ridge strength of STLSQ.
pub const DEFAULT_ALPHA: f64 = 0.05;
/// PySINDy's default iteration limit of STLSQ.
pub const DEFAULT_MAX_ITER: usize = 20;

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

    /// Validates the parameters once.
    pub fn checked(&self) -> Result<Optimizer> {
        Ok(match *self {
            Self::Stlsq {
                threshold,
                alpha,
                max_iter,
            } => Optimizer::Stlsq(Stlsq::new(threshold, alpha, max_iter)?),
            Self::Lasso { lambda } => Optimizer::Lasso(Lasso::new(lambda)?),
        })
    }
}

/// A validated optimizer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Optimizer {
    Stlsq(Stlsq),
    Lasso(Lasso),
}

impl Optimizer {
    /// ξ (one row per target column, one column per feature) fitted on `theta` (n × features) and
    /// `targets` (n × targets). `target_names` only label errors.
    pub fn fit(
        &self,
        theta: MatRef<'_, f64>,
        targets: MatRef<'_, f64>,
        target_names: &[String],
    ) -> Result<Mat<f64>> {
        match self {
            Self::Stlsq(stlsq) => Ok(stlsq.fit(theta, targets).coefficients),
            Self::Lasso(lasso) => lasso.fit(theta, targets, target_names),
        }
    }

    /// [`Self::fit`] on a problem reduced by rows: the same coefficients up to rounding, without
    /// the library's rows.
    pub fn fit_reduced(
        &self,
        reduced: &crate::ReducedProblem,
        target_names: &[String],
    ) -> Result<Mat<f64>> {
        match self {
            Self::Stlsq(stlsq) => Ok(stlsq.fit_reduced(reduced).coefficients),
            Self::Lasso(lasso) => lasso.fit_gram(
                reduced.gram().as_ref(),
                reduced.moments().as_ref(),
                target_names,
            ),
        }
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
