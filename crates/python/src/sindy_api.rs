//! SINDy: fits on trajectories, the optimizers on a library matrix, derivatives, saved models.

use std::path::PathBuf;

use faer::MatRef;
use numpy::{PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use sindy::{
    Derivative, FeatureLibrary, Lasso, LibrarySpec, OptimizerSpec, SindyModel, SindyParams, Stlsq,
    Trajectory,
};

use crate::arrays::{matrix, owned, to_numpy, values};
use crate::errors::raise;

/// One trajectory as Python hands it over: time, states, controls, derivatives.
type TrajectoryArrays<'py> = (
    PyReadonlyArray1<'py, f64>,
    PyReadonlyArray2<'py, f64>,
    Option<PyReadonlyArray2<'py, f64>>,
    Option<PyReadonlyArray2<'py, f64>>,
);

pub fn register(module: &Bound<'_, PyModule>) -> PyResult<()> {
    module.add_class::<NativeModel>()?;
    module.add_function(wrap_pyfunction!(fit_sindy, module)?)?;
    module.add_function(wrap_pyfunction!(differentiate, module)?)?;
    module.add_function(wrap_pyfunction!(stlsq, module)?)?;
    module.add_function(wrap_pyfunction!(lasso, module)?)?;
    Ok(())
}

/// A differentiation method from its JSON (`{"kind": "central"}`, …).
pub fn derivative_from(json: &str) -> PyResult<Derivative> {
    serde_json::from_str(json).map_err(|e| raise(format!("differentiation method {json}: {e}")))
}

fn optimizer_from(json: &str) -> PyResult<OptimizerSpec> {
    serde_json::from_str(json).map_err(|e| raise(format!("optimizer {json}: {e}")))
}

fn library_from(spec: &str) -> PyResult<FeatureLibrary> {
    let spec = LibrarySpec::parse(spec).map_err(raise)?;
    FeatureLibrary::from_spec(&spec).map_err(raise)
}

fn trajectory(index: usize, arrays: &TrajectoryArrays<'_>) -> PyResult<Trajectory> {
    let (time, states, controls, derivatives) = arrays;
    let label = |e: sindy::SindyError| raise(format!("trajectory {index}: {e}"));
    let mut trajectory =
        Trajectory::new(values(time).into_owned(), owned(states)).map_err(label)?;
    if let Some(controls) = controls {
        trajectory = trajectory.with_controls(owned(controls)).map_err(label)?;
    }
    if let Some(derivatives) = derivatives {
        trajectory = trajectory
            .with_derivatives(owned(derivatives))
            .map_err(label)?;
    }
    Ok(trajectory)
}

/// Fits one model on every trajectory (their samples stacked), the interpreter released.
#[pyfunction]
fn fit_sindy(
    py: Python<'_>,
    trajectories: Vec<TrajectoryArrays<'_>>,
    state_names: Vec<String>,
    control_names: Vec<String>,
    library: &str,
    optimizer: &str,
    derivative: &str,
) -> PyResult<NativeModel> {
    let trajectories = trajectories
        .iter()
        .enumerate()
        .map(|(index, arrays)| trajectory(index, arrays))
        .collect::<PyResult<Vec<_>>>()?;
    let states: Vec<&str> = state_names.iter().map(String::as_str).collect();
    let controls: Vec<&str> = control_names.iter().map(String::as_str).collect();
    let params = SindyParams::new(&states, &controls)
        .library(library_from(library)?)
        .optimizer(optimizer_from(optimizer)?)
        .derivative(derivative_from(derivative)?);
    let model = py.detach(|| params.fit(&trajectories)).map_err(raise)?;
    Ok(NativeModel { model })
}

/// ẋ of each column of `states` at the time stamps `time`.
#[pyfunction]
fn differentiate<'py>(
    py: Python<'py>,
    states: PyReadonlyArray2<'py, f64>,
    time: PyReadonlyArray1<'py, f64>,
    derivative: &str,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let method = derivative_from(derivative)?;
    let time = values(&time);
    let states = matrix(&states);
    let result = py
        .detach(|| method.apply_columns_at_times(states, &time))
        .map_err(raise)?;
    Ok(to_numpy(py, result.as_ref()))
}

/// STLSQ on a library matrix: ξ (one row per target) and each target's iterations.
#[pyfunction]
fn stlsq<'py>(
    py: Python<'py>,
    theta: PyReadonlyArray2<'py, f64>,
    targets: PyReadonlyArray2<'py, f64>,
    threshold: f64,
    alpha: f64,
    max_iter: usize,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Vec<usize>)> {
    let optimizer = Stlsq::new(threshold, alpha, max_iter).map_err(raise)?;
    let (theta, targets) = library_and_targets(&theta, &targets)?;
    let fit = py.detach(|| optimizer.fit(theta, targets));
    Ok((to_numpy(py, fit.coefficients.as_ref()), fit.iterations))
}

/// LASSO `min ½‖Θξ − y‖² + λ‖ξ‖₁` on a library matrix: ξ, one row per target.
#[pyfunction]
fn lasso<'py>(
    py: Python<'py>,
    theta: PyReadonlyArray2<'py, f64>,
    targets: PyReadonlyArray2<'py, f64>,
    penalty: f64,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let optimizer = Lasso::new(penalty).map_err(raise)?;
    let (theta, targets) = library_and_targets(&theta, &targets)?;
    let names: Vec<String> = (0..targets.ncols()).map(|j| format!("x{j}")).collect();
    let coefficients = py
        .detach(|| optimizer.fit(theta, targets, &names))
        .map_err(raise)?;
    Ok(to_numpy(py, coefficients.as_ref()))
}

/// A library matrix and its targets, read in place; they must have the same rows.
fn library_and_targets<'a>(
    theta: &'a PyReadonlyArray2<'_, f64>,
    targets: &'a PyReadonlyArray2<'_, f64>,
) -> PyResult<(MatRef<'a, f64>, MatRef<'a, f64>)> {
    let (theta, targets) = (matrix(theta), matrix(targets));
    let (library_rows, target_rows) = (theta.nrows(), targets.nrows());
    if library_rows != target_rows {
        return Err(raise(format!(
            "the library matrix has {library_rows} rows and the targets {target_rows}"
        )));
    }
    Ok((theta, targets))
}

/// A fitted SINDy model (the `sindy` crate's), held for the Python `SINDy` class.
#[pyclass(module = "learn_sysid._native")]
pub struct NativeModel {
    model: SindyModel,
}

#[pymethods]
impl NativeModel {
    /// Predicted ẋ for states and controls (zero columns without control).
    fn predict<'py>(
        &self,
        py: Python<'py>,
        states: PyReadonlyArray2<'py, f64>,
        controls: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let (states, controls) = (matrix(&states), matrix(&controls));
        let predicted = py
            .detach(|| self.model.predict(states, controls))
            .map_err(raise)?;
        Ok(to_numpy(py, predicted.as_ref()))
    }

    /// ξ: one row per state, one column per feature.
    fn coefficients<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        to_numpy(py, self.model.coefficients())
    }

    fn feature_names(&self) -> Vec<String> {
        self.model.feature_names().to_vec()
    }

    fn state_names(&self) -> Vec<String> {
        self.model.state_names().to_vec()
    }

    fn control_names(&self) -> Vec<String> {
        self.model.control_names().to_vec()
    }

    /// The states from `x0` at every time of `time` (RK4, controls interpolated linearly).
    fn simulate<'py>(
        &self,
        py: Python<'py>,
        x0: PyReadonlyArray1<'py, f64>,
        time: PyReadonlyArray1<'py, f64>,
        controls: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let (x0, time, controls) = (values(&x0), values(&time), matrix(&controls));
        let states = py
            .detach(|| self.model.simulate(&x0, &time, controls))
            .map_err(raise)?;
        Ok(to_numpy(py, states.as_ref()))
    }

    /// The model file's text (`sindy-model/1`, as `learn sindy --out` writes it).
    fn to_json(&self) -> PyResult<String> {
        self.model.to_json().map_err(raise)
    }

    /// Writes the model file; an existing file is an error unless `overwrite`.
    fn save(&self, path: PathBuf, overwrite: bool) -> PyResult<()> {
        self.model.save(&path, overwrite).map_err(raise)
    }

    /// A model from a model file's text; `label` names it in errors.
    #[staticmethod]
    fn from_json(text: &str, label: PathBuf) -> PyResult<Self> {
        let model = SindyModel::from_json(text, &label).map_err(raise)?;
        Ok(Self { model })
    }

    /// A model file written by `learn sindy` or `save`.
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Self> {
        let model = SindyModel::load(&path).map_err(raise)?;
        Ok(Self { model })
    }
}
