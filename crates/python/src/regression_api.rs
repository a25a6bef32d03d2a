//! The `sindy` crate's regularised regressions on a library matrix, their penalty chosen by
//! blocked cross-validation, with bagged members for coefficient intervals and a predictive band.

use numpy::{PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;
use sindy::{LinearFit, RegressionFit, RegressionSpec};

use crate::arrays::{matrix, to_numpy};
use crate::errors::raise;

pub fn register(module: &Bound<'_, PyModule>) -> PyResult<()> {
    module.add_class::<NativeRegression>()?;
    module.add_function(wrap_pyfunction!(fit_regression, module)?)?;
    Ok(())
}

/// Fits `spec` (the JSON of a [`RegressionSpec`]) on Θ and the targets, the bootstrap drawn from
/// `seed`.
#[pyfunction]
fn fit_regression(
    py: Python<'_>,
    theta: PyReadonlyArray2<'_, f64>,
    targets: PyReadonlyArray2<'_, f64>,
    spec: &str,
    seed: u64,
) -> PyResult<NativeRegression> {
    let spec: RegressionSpec =
        serde_json::from_str(spec).map_err(|e| raise(format!("regression {spec}: {e}")))?;
    let (theta, targets) = (matrix(&theta), matrix(&targets));
    let fit = py
        .detach(|| spec.fit(theta, targets, seed))
        .map_err(raise)?;
    Ok(NativeRegression { fit })
}

/// A fitted regression: the fit on all rows and the bagged members.
#[pyclass(module = "learn_sysid._native")]
pub struct NativeRegression {
    fit: RegressionFit,
}

/// ξ in the raw features' units (one row per target) and the intercepts.
fn raw<'py>(py: Python<'py>, fit: &LinearFit) -> (Bound<'py, PyArray2<f64>>, Vec<f64>) {
    let (coefficients, intercepts) = fit.raw_coefficients();
    (to_numpy(py, coefficients.transpose()), intercepts)
}

#[pymethods]
impl NativeRegression {
    /// The fit on all rows: ξ (targets × features) and the intercepts.
    fn full<'py>(&self, py: Python<'py>) -> (Bound<'py, PyArray2<f64>>, Vec<f64>) {
        raw(py, &self.fit.full)
    }

    /// Each bagged member's ξ and intercepts.
    fn members<'py>(&self, py: Python<'py>) -> Vec<(Bound<'py, PyArray2<f64>>, Vec<f64>)> {
        self.fit.members.iter().map(|m| raw(py, m)).collect()
    }

    /// Each target's chosen penalty value.
    fn chosen(&self) -> Vec<f64> {
        self.fit.selections.iter().map(|s| s.chosen).collect()
    }

    /// The members' mean and the predictive band (lower, upper) on Θ; `None` without bagging.
    #[allow(clippy::type_complexity)]
    fn ensemble<'py>(
        &self,
        py: Python<'py>,
        theta: PyReadonlyArray2<'py, f64>,
    ) -> Option<(
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray2<f64>>,
    )> {
        let theta = matrix(&theta);
        let ensemble = py.detach(|| self.fit.ensemble(theta))?;
        Some((
            to_numpy(py, ensemble.mean.as_ref()),
            to_numpy(py, ensemble.lower.as_ref()),
            to_numpy(py, ensemble.upper.as_ref()),
        ))
    }
}
