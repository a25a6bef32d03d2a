//! What a model of CSV tasks reads and was meta-trained on ([`ColumnTraining`], the checkpoint's
//! `trained_on`, with where its tasks came from: [`TaskSource`]), and its settings: the paper's
//! values as defaults ([`LearnConfig::task_defaults`]), any of them overridden by a configuration
//! file that names only what it changes ([`TaskConfig::load`]).

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use serde_json::Value;
use sindy::Derivative;

use crate::config::{
    AdaptationConfig, CheckedConfig, LearnConfig, MetaTrainingConfig, Optimizer, TaskGrouping,
};
use crate::error::{LearnError, Result};
use crate::maml::MetaOrder;
use crate::network::{Architecture, PAPER_HIDDEN};

/// The columns a model of CSV tasks reads, and how its targets are estimated.
#[derive(Clone, Debug, PartialEq)]
pub struct ColumnSpec {
    /// The time column (strictly increasing, uniformly sampled).
    pub time: String,
    /// The state columns x; the model predicts ẋ for each.
    pub state: Vec<String>,
    /// The control columns u.
    pub control: Vec<String>,
    /// How ẋ is estimated from x, on each segment separately.
    pub derivative: Derivative,
}

impl ColumnSpec {
    /// The state then control columns: the model's inputs X, in order.
    pub fn input_names(&self) -> Vec<String> {
        self.state.iter().chain(&self.control).cloned().collect()
    }

    /// `x'` for each state column `x` (as `learn sindy` writes its equations).
    pub fn output_names(&self) -> Vec<String> {
        self.state.iter().map(|name| format!("{name}'")).collect()
    }

    /// The architecture of the paper's rule for these columns: I + U inputs, I outputs, the
    /// configuration's P and hidden widths.
    pub fn architecture(&self, config: &LearnConfig) -> Architecture {
        Architecture {
            input_dim: self.state.len() + self.control.len(),
            state_dim: self.state.len(),
            basis_per_input: config.basis_per_input,
            hidden: config.hidden_layers.clone(),
        }
    }

    /// At least one state, no empty or repeated name, the time column not among them.
    pub fn check(&self) -> std::result::Result<(), String> {
        if self.state.is_empty() {
            return Err("at least one state column is needed".to_string());
        }
        let names = self.input_names();
        for (i, name) in names.iter().enumerate() {
            if name.is_empty() {
                return Err("a column name is empty".to_string());
            }
            if names[..i].contains(name) {
                return Err(format!(
                    "column '{name}' is named twice among the states and controls"
                ));
            }
            if name == &self.time {
                return Err(format!("column '{name}' is the time column"));
            }
        }
        self.derivative
            .validate()
            .map_err(|error| error.to_string())
    }
}

/// Where the tasks of a model of CSV tasks come from, as its checkpoint records it (reading them
/// is the `evaluation` crate's). JSON: `{"kind": "files", "pattern": "tasks/*.csv"}` or
/// `{"kind": "column", "file": "all.csv", "column": "task"}`.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum TaskSource {
    /// Every regular file matched by a glob pattern (`*`, `?`, `[…]`, `**`), one task each, in
    /// sorted path order.
    Files { pattern: String },
    /// One CSV file, one task per run of consecutive rows with the same value of `column`.
    Column { file: PathBuf, column: String },
}

/// One meta-training task of a model: its name and number of rows.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TaskRows {
    pub name: String,
    pub rows: usize,
}

/// What a model of CSV tasks was meta-trained on: the checkpoint's `trained_on`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ColumnTraining {
    pub time: String,
    pub state: Vec<String>,
    pub control: Vec<String>,
    pub derivative: Derivative,
    /// The sampling interval all tasks share, seconds.
    pub sampling_interval: f64,
    /// Per output, the standard deviation of its targets over the meta-training tasks: the
    /// networks learn ẋ divided by it (so that the default steps suit any units), and their
    /// outputs are multiplied by it. The input statistics are the checkpoint's `standardiser`.
    pub target_scale: Vec<f64>,
    /// Where the tasks came from (`--tasks` or `--task-column`).
    pub source: TaskSource,
    /// The tasks, in meta-training order.
    pub tasks: Vec<TaskRows>,
}

impl ColumnTraining {
    /// The columns and derivative the model reads.
    pub fn spec(&self) -> ColumnSpec {
        ColumnSpec {
            time: self.time.clone(),
            state: self.state.clone(),
            control: self.control.clone(),
            derivative: self.derivative,
        }
    }

    /// The state then control columns.
    pub fn input_names(&self) -> Vec<String> {
        self.spec().input_names()
    }

    /// `x'` for each state column `x`.
    pub fn output_names(&self) -> Vec<String> {
        self.spec().output_names()
    }

    /// The record is consistent: valid columns, a positive interval, one positive scale per output.
    pub fn check(&self) -> std::result::Result<(), String> {
        self.spec().check()?;
        if !(self.sampling_interval.is_finite() && self.sampling_interval > 0.0) {
            return Err(format!(
                "sampling_interval {} must be a positive number",
                self.sampling_interval
            ));
        }
        if self.target_scale.len() != self.state.len() {
            return Err(format!(
                "{} target_scale values for {} state columns",
                self.target_scale.len(),
                self.state.len()
            ));
        }
        if let Some(bad) = self
            .target_scale
            .iter()
            .find(|s| !(s.is_finite() && **s > 0.0))
        {
            return Err(format!("target_scale {bad} must be a positive number"));
        }
        Ok(())
    }
}

impl LearnConfig {
    /// The settings of a model of CSV tasks when its configuration does not name them: the
    /// paper's (`experiments/learn.json`: P = 2, hidden widths [12, 16, 24, 48], exact second
    /// order, one inner step of 0.1, Adam at 0.004 for 800 iterations, 16 adaptation passes at
    /// 0.0005 with λ = 0.01, L = 1). The batch sizes are upper bounds there: each is lowered to
    /// what the tasks hold unless the configuration names it ([`TaskConfig`]).
    pub fn task_defaults() -> Self {
        Self {
            basis_per_input: 2,
            hidden_layers: PAPER_HIDDEN.to_vec(),
            standardise_inputs: true,
            clamp_inputs: false,
            meta_training: MetaTrainingConfig {
                inner_step: 0.1,
                inner_rounds: 1,
                outer_step: 0.004,
                optimizer: Optimizer::Adam,
                meta_regularisation: 1e-6,
                order: MetaOrder::Second,
                tasks: TaskGrouping::Flight,
                task_batch: 4,
                support_batch: 64,
                query_batch: 64,
                iterations: 800,
                average_last: 0,
            },
            adaptation: AdaptationConfig {
                step: 0.0005,
                passes: 16,
                window: 1,
                lipschitz_weight: 0.01,
                lipschitz_bound: 1.0,
                average_last_pass: false,
            },
            seed: 1,
            spread_seeds: vec![1, 2, 3, 4, 5],
        }
    }
}

/// The sizes that [`TaskConfig::fit_to`] lowers to the data unless the configuration names them.
const DATA_BOUNDED: [(&str, &str); 3] = [
    ("meta_training", "task_batch"),
    ("meta_training", "support_batch"),
    ("meta_training", "query_batch"),
];

/// The settings of meta-training on CSV tasks: [`LearnConfig::task_defaults`] with what a
/// configuration file names, checked.
#[derive(Clone, Debug)]
pub struct TaskConfig {
    checked: CheckedConfig,
    /// Which of [`DATA_BOUNDED`] the file named (those are never lowered: too large is an error).
    named: [bool; 3],
}

impl TaskConfig {
    /// The defaults, or a file (any subset of the fields of `experiments/learn.json`) over them.
    /// Errors name the file and the field.
    pub fn load(path: Option<&Path>) -> Result<Self> {
        let Some(path) = path else {
            return Ok(Self {
                checked: LearnConfig::task_defaults().check(Path::new("the default settings"))?,
                named: [false; 3],
            });
        };
        let config_error = |field: String, message: String| LearnError::Config {
            path: path.to_path_buf(),
            field,
            message,
        };
        let text = bounded_read::read_json_text(path).map_err(|cause| LearnError::Io {
            path: path.to_path_buf(),
            cause,
        })?;
        let text = bounded_read::json::checked_text(&text)
            .map_err(|error| config_error(error.field, error.message))?;
        let given: Value = serde_json::from_str(text)
            .map_err(|error| config_error("the document".to_string(), error.to_string()))?;
        if !given.is_object() {
            return Err(config_error(
                "the document".to_string(),
                "expected a JSON object of settings".to_string(),
            ));
        }
        let named = DATA_BOUNDED.map(|(section, field)| given[section].get(field).is_some());
        let mut merged = serde_json::to_value(LearnConfig::task_defaults())
            .expect("the default settings serialise");
        merge(&mut merged, given);
        let config: LearnConfig = bounded_read::json::from_value(merged)
            .map_err(|error| config_error(error.field, error.message))?;
        Ok(Self {
            checked: config.check(path)?,
            named,
        })
    }

    /// A copy with another seed.
    pub fn with_seed(&self, seed: u64) -> Self {
        Self {
            checked: self.checked.with_seed(seed),
            named: self.named,
        }
    }

    /// The settings (batch sizes before [`Self::fit_to`]).
    pub fn get(&self) -> &LearnConfig {
        self.checked.get()
    }

    /// The file the settings came from (or "the default settings").
    pub fn origin(&self) -> &Path {
        self.checked.origin()
    }

    /// The settings for `tasks` tasks whose shortest support and query segments have
    /// `support_rows` and `query_rows` samples: each batch size the file did not name is lowered
    /// to that bound; one it named and that exceeds it is left for the sampling check to refuse,
    /// naming the field.
    pub fn fit_to(&self, tasks: usize, support_rows: usize, query_rows: usize) -> LearnConfig {
        let mut config = self.get().clone();
        let meta = &mut config.meta_training;
        for (value, named, bound) in [
            (&mut meta.task_batch, self.named[0], tasks),
            (&mut meta.support_batch, self.named[1], support_rows),
            (&mut meta.query_batch, self.named[2], query_rows),
        ] {
            if !named {
                *value = (*value).min(bound).max(1);
            }
        }
        config
    }

    /// Where the settings came from, for the model and messages.
    pub fn origin_path(&self) -> PathBuf {
        self.origin().to_path_buf()
    }
}

/// `patch` merged into `base`: objects key by key (recursively), any other value replaces. A key
/// `base` lacks is kept, so that reading the result names it as an unknown field.
fn merge(base: &mut Value, patch: Value) {
    match (base, patch) {
        (Value::Object(base), Value::Object(patch)) => {
            for (key, value) in patch {
                match base.get_mut(&key) {
                    Some(slot) if slot.is_object() && value.is_object() => merge(slot, value),
                    _ => {
                        base.insert(key, value);
                    }
                }
            }
        }
        (base, patch) => *base = patch,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A temporary `.json` file holding `text`, removed when dropped.
    fn scratch(name: &str, text: &str) -> tempfile::TempPath {
        let mut file = tempfile::Builder::new()
            .prefix(&format!("learn-columns-{name}-"))
            .suffix(".json")
            .tempfile()
            .unwrap();
        std::io::Write::write_all(&mut file, text.as_bytes()).unwrap();
        file.into_temp_path()
    }

    #[test]
    fn the_defaults_are_the_paper_settings() {
        let paper: LearnConfig =
            serde_json::from_str(include_str!("../../../experiments/learn.json")).unwrap();
        assert_eq!(LearnConfig::task_defaults(), paper);
    }

    #[test]
    fn a_file_overrides_only_what_it_names_and_unnamed_batches_fit_the_data() {
        let path = scratch(
            "partial",
            r#"{"hidden_layers": [8, 8], "meta_training": {"iterations": 5, "query_batch": 50}}"#,
        );
        let config = TaskConfig::load(Some(&path)).unwrap();
        assert_eq!(config.get().hidden_layers, vec![8, 8]);
        assert_eq!(config.get().meta_training.iterations, 5);
        assert_eq!(config.get().meta_training.inner_step, 0.1);
        let fitted = config.fit_to(3, 20, 10);
        assert_eq!(fitted.meta_training.task_batch, 3);
        assert_eq!(fitted.meta_training.support_batch, 20);
        // Named: kept, for the sampling check to refuse by name.
        assert_eq!(fitted.meta_training.query_batch, 50);
    }

    #[test]
    fn an_unknown_or_bad_field_is_named() {
        let path = scratch("unknown", r#"{"meta_training": {"iteratons": 5}}"#);
        let message = TaskConfig::load(Some(&path)).unwrap_err().to_string();
        assert!(message.contains("meta_training.iteratons"), "{message}");
        let path = scratch("bad", r#"{"adaptation": {"step": -1}}"#);
        let message = TaskConfig::load(Some(&path)).unwrap_err().to_string();
        assert!(message.contains("adaptation.step"), "{message}");
    }
}
