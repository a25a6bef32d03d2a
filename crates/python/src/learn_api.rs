//! LeARN on tasks in memory: meta-training, online adaptation on a support segment, prediction,
//! explanation, and the JSON checkpoint `learn meta-train --tasks` writes.

use std::ops::Range;
use std::path::{Path, PathBuf};

use evaluation::own_data;
use learn::{
    ColumnSpec, EquationRule, MetaTrainedModel, Recording, TaskConfig, TaskSet, TaskSource,
};
use numpy::{PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::arrays::{matrix, row_major_to_numpy};
use crate::errors::{Progress, raise};
use crate::sindy_api::derivative_from;

pub fn register(module: &Bound<'_, PyModule>) -> PyResult<()> {
    module.add_class::<NativeLearnModel>()?;
    module.add_function(wrap_pyfunction!(meta_train_arrays, module)?)?;
    module.add_function(wrap_pyfunction!(meta_train_files, module)?)?;
    Ok(())
}

/// Where in-memory tasks came from, as the checkpoint records it.
const IN_MEMORY: &str = "arrays given to learn_sysid.LeARN.meta_train";

/// A recording's columns (one per state, then per control) from an array with one row per sample.
fn columns_of(array: &PyReadonlyArray2<'_, f64>) -> Vec<Vec<f64>> {
    let values = matrix(array);
    (0..values.ncols())
        .map(|j| (0..values.nrows()).map(|i| values[(i, j)]).collect())
        .collect()
}

fn check_width(what: &str, columns: &[Vec<f64>], spec: &ColumnSpec) -> PyResult<()> {
    let expected = spec.state.len() + spec.control.len();
    if columns.len() == expected {
        return Ok(());
    }
    Err(raise(format!(
        "{what}: {} columns, expected {expected} (the states {}, then the controls {})",
        columns.len(),
        spec.state.join(", "),
        spec.control.join(", ")
    )))
}

/// The columns a model of tasks learns from, checked: ẋ of the states by `derivative`.
fn column_spec(
    time: String,
    state: Vec<String>,
    control: Vec<String>,
    derivative: &str,
) -> PyResult<ColumnSpec> {
    let spec = ColumnSpec {
        time,
        state,
        control,
        derivative: derivative_from(derivative)?,
    };
    spec.check()
        .map_err(|message| raise(format!("state/control: {message}")))?;
    Ok(spec)
}

/// Meta-trains with `settings` (a `config` file's, the paper's without one; its seed replaced by
/// `seed` when given) on the task set `train` makes, the interpreter released, `progress` told
/// of each meta-iteration.
fn meta_train_released(
    py: Python<'_>,
    config: Option<PathBuf>,
    seed: Option<u64>,
    progress: Option<Py<PyAny>>,
    train: impl FnOnce(&TaskConfig, &dyn Fn(usize)) -> PyResult<MetaTrainedModel> + Send,
) -> PyResult<NativeLearnModel> {
    let mut settings = TaskConfig::load(config.as_deref()).map_err(raise)?;
    if let Some(seed) = seed {
        settings = settings.with_seed(seed);
    }
    let iterations = settings.get().meta_training.iterations;
    let progress = Progress::new(progress);
    let model = py.detach(|| train(&settings, &|done| progress.report((done, iterations))));
    let model = progress.finish(model)?;
    Ok(NativeLearnModel { model })
}

/// Meta-trains a LeARN model on `tasks` (each rows × (states + controls), sampled every
/// `interval` seconds), with the settings of `config` (a file with any subset of
/// `experiments/learn.json`'s fields; the paper's defaults without one), its seed replaced by
/// `seed` when given.
#[pyfunction]
#[pyo3(signature = (tasks, names, state, control, interval, derivative, config=None, seed=None, progress=None))]
#[allow(clippy::too_many_arguments)]
fn meta_train_arrays(
    py: Python<'_>,
    tasks: Vec<PyReadonlyArray2<'_, f64>>,
    names: Vec<String>,
    state: Vec<String>,
    control: Vec<String>,
    interval: f64,
    derivative: &str,
    config: Option<PathBuf>,
    seed: Option<u64>,
    progress: Option<Py<PyAny>>,
) -> PyResult<NativeLearnModel> {
    let spec = column_spec("t".to_string(), state, control, derivative)?;
    let columns: Vec<Vec<Vec<f64>>> = tasks.iter().map(columns_of).collect();
    for (name, task) in names.iter().zip(&columns) {
        check_width(&format!("task '{name}'"), task, &spec)?;
    }
    let path = Path::new(IN_MEMORY);
    let source = TaskSource::Files {
        pattern: IN_MEMORY.to_string(),
    };
    meta_train_released(py, config, seed, progress, |settings, report| {
        let recordings: Vec<Recording> = names
            .iter()
            .zip(&columns)
            .map(|(name, columns)| Recording {
                name,
                path,
                columns,
                interval,
            })
            .collect();
        let set = TaskSet {
            source: &source,
            spec: &spec,
            tasks: &recordings,
            files: Vec::new(),
        };
        learn::meta_train_tasks(set, settings, report).map_err(raise)
    })
}

/// Meta-trains on CSV (or Parquet) task files as `learn meta-train --tasks` does: every file
/// `pattern` matches is a task, or, with `task_column`, each run of one value of that column of
/// the file `pattern`; the model records the files and their SHA-256.
#[pyfunction]
#[pyo3(signature = (pattern, time, state, control, derivative, config=None, seed=None, task_column=None, progress=None))]
#[allow(clippy::too_many_arguments)]
fn meta_train_files(
    py: Python<'_>,
    pattern: String,
    time: String,
    state: Vec<String>,
    control: Vec<String>,
    derivative: &str,
    config: Option<PathBuf>,
    seed: Option<u64>,
    task_column: Option<String>,
    progress: Option<Py<PyAny>>,
) -> PyResult<NativeLearnModel> {
    let spec = column_spec(time, state, control, derivative)?;
    let source = match task_column {
        Some(column) => TaskSource::Column {
            file: PathBuf::from(pattern),
            column,
        },
        None => TaskSource::Files { pattern },
    };
    meta_train_released(py, config, seed, progress, |settings, report| {
        let tasks = own_data::read_tasks(&source, &spec).map_err(raise)?;
        let files = own_data::data_files(&tasks).map_err(raise)?;
        let recordings: Vec<Recording> = tasks.iter().map(own_data::recording).collect();
        let set = TaskSet {
            source: &source,
            spec: &spec,
            tasks: &recordings,
            files,
        };
        learn::meta_train_tasks(set, settings, report).map_err(raise)
    })
}

fn rows(range: (usize, usize)) -> Range<usize> {
    range.0..range.1
}

/// A meta-trained LeARN model of named columns (a checkpoint of CSV tasks).
#[pyclass(module = "learn_sysid._native")]
pub struct NativeLearnModel {
    model: MetaTrainedModel,
}

impl NativeLearnModel {
    fn recording<'a>(&self, columns: &'a [Vec<f64>], path: &'a Path) -> PyResult<Recording<'a>> {
        let training = learn::column_training(&self.model, "a recording").map_err(raise)?;
        check_width("the recording", columns, &training.spec())?;
        Ok(Recording {
            name: "recording",
            path,
            columns,
            interval: training.sampling_interval,
        })
    }
}

#[pymethods]
impl NativeLearnModel {
    /// A checkpoint written by `learn meta-train --tasks` or `save`.
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Self> {
        Ok(Self {
            model: MetaTrainedModel::load(&path).map_err(raise)?,
        })
    }

    /// Writes the checkpoint (JSON).
    fn save(&self, path: PathBuf) -> PyResult<()> {
        self.model.save(&path).map_err(raise)
    }

    fn input_names(&self) -> Vec<String> {
        self.model.input_names()
    }

    fn output_names(&self) -> Vec<String> {
        self.model.output_names()
    }

    fn seed(&self) -> u64 {
        self.model.seed
    }

    fn interval(&self) -> PyResult<f64> {
        Ok(learn::column_training(&self.model, "the interval")
            .map_err(raise)?
            .sampling_interval)
    }

    fn meta_loss_history(&self) -> Vec<f64> {
        self.model.meta_loss_history.clone()
    }

    /// ẋ predicted for inputs [x, u] (one row per sample) with the meta-trained parameters or
    /// with `parameters` (adapted ones).
    #[pyo3(signature = (inputs, parameters=None))]
    fn predict<'py>(
        &self,
        py: Python<'py>,
        inputs: PyReadonlyArray2<'py, f64>,
        parameters: Option<Vec<f64>>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let inputs = matrix(&inputs);
        let width = self.model.input_names().len();
        if inputs.ncols() != width {
            return Err(raise(format!(
                "inputs have {} columns, the model {width} ({})",
                inputs.ncols(),
                self.model.input_names().join(", ")
            )));
        }
        let parameters = parameters.unwrap_or_else(|| self.model.parameters.clone());
        if parameters.len() != self.model.parameters.len() {
            return Err(raise(format!(
                "{} parameters, the model has {}",
                parameters.len(),
                self.model.parameters.len()
            )));
        }
        let raw: Vec<f64> = (0..inputs.nrows())
            .flat_map(|i| (0..width).map(move |j| inputs[(i, j)]))
            .collect();
        let predicted = py.detach(|| self.model.predict_with(&parameters, &raw));
        Ok(row_major_to_numpy(
            py,
            predicted,
            self.model.output_names().len(),
        ))
    }

    /// Adapts online on the `support` rows of `recording` (states then controls, at the model's
    /// interval) and scores the adapted model there and, frozen, on the `query` rows: the
    /// adaptation and generalisation MSE, the same before adaptation, and the adapted θ.
    fn evaluate(
        &self,
        py: Python<'_>,
        recording: PyReadonlyArray2<'_, f64>,
        support: (usize, usize),
        query: (usize, usize),
    ) -> PyResult<(f64, f64, f64, f64, Vec<f64>)> {
        let columns = columns_of(&recording);
        let path = Path::new("the recording array");
        let recording = self.recording(&columns, path)?;
        let evaluation = py
            .detach(|| {
                learn::evaluate_recording(&self.model, recording, rows(support), rows(query))
            })
            .map_err(raise)?;
        Ok((
            evaluation.adaptation,
            evaluation.generalisation,
            evaluation.unadapted_adaptation,
            evaluation.unadapted_generalisation,
            evaluation.adapted_parameters,
        ))
    }

    /// The explanation through ℰ over every row of `recording` (adapted first on `support` rows
    /// when given), as JSON: per output, each input's mean feature-selection coefficient and the
    /// equation's leading terms.
    #[pyo3(signature = (recording, support=None, max_terms=3, relative_threshold=0.2))]
    fn explain(
        &self,
        py: Python<'_>,
        recording: PyReadonlyArray2<'_, f64>,
        support: Option<(usize, usize)>,
        max_terms: usize,
        relative_threshold: f64,
    ) -> PyResult<String> {
        let columns = columns_of(&recording);
        let path = Path::new("the recording array");
        let recording = self.recording(&columns, path)?;
        let rule = EquationRule {
            max_terms,
            relative_threshold,
        };
        let explanation = py
            .detach(|| learn::explain_recording(&self.model, recording, support.map(rows), rule))
            .map_err(raise)?;
        serde_json::to_string(&explanation).map_err(raise)
    }
}
