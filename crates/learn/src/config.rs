//! Hyper-parameters of LeARN, read from `experiments/learn.json` and checked once.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::formulation::Formulation;

use crate::error::{LearnError, Result};
use crate::maml::MetaOrder;

/// The outer (meta) optimiser.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Optimizer {
    /// θ ← θ − β·g, as in Algorithm 1 of the paper.
    Sgd,
    /// Adam with step β (moment decay 0.9 / 0.999, ε = 1e-8).
    Adam,
}

/// What one meta-training task is.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TaskGrouping {
    /// One task per meta-training flight: its support and query segments (the default).
    #[default]
    Flight,
    /// One task per wind condition, the paper's task ("a new task i.e. a new wind condition"): the
    /// support and query segments of all that condition's flights, pooled. Under the `paper`
    /// protocol, with one flight per condition, the two are the same.
    Condition,
}

/// Meta-training (Algorithm 1).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MetaTrainingConfig {
    /// α, the inner SGD step (on the mean squared error).
    pub inner_step: f64,
    /// n ≥ 1, the inner SGD rounds.
    pub inner_rounds: usize,
    /// β, the outer step.
    pub outer_step: f64,
    pub optimizer: Optimizer,
    /// μ of the meta-regulariser μ‖θ‖².
    pub meta_regularisation: f64,
    /// Exact second order, or first order.
    pub order: MetaOrder,
    /// What a task is: a flight (the default) or a wind condition.
    #[serde(default)]
    pub tasks: TaskGrouping,
    /// Tasks per meta-iteration, drawn without replacement: at most the number of meta-training
    /// tasks (flights, or conditions).
    pub task_batch: usize,
    /// Support points per task (drawn from the first half of the task's flights, with
    /// replacement): at most the samples of the shortest such segment.
    pub support_batch: usize,
    /// Query points per task (drawn from the second half of the task's flights, with
    /// replacement): at most the samples of the shortest such segment.
    pub query_batch: usize,
    /// Number of meta-iterations.
    pub iterations: usize,
    /// Iterate averaging (Polyak–Ruppert): the meta-trained parameters are the mean of the
    /// parameters after each of the last `average_last` updates, instead of the last one.
    /// 0 (the default, and the paper) keeps the final iterate.
    #[serde(default)]
    pub average_last: usize,
}

/// Online adaptation on the support segment (equation online_adapt of the paper).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AdaptationConfig {
    /// Gradient step of each online update.
    pub step: f64,
    /// Passes over the support segment, each in time order.
    pub passes: usize,
    /// Consecutive samples per online update (1 = the paper's one sample per step): at most the
    /// samples of the support segment.
    pub window: usize,
    /// λ of the Lipschitz regulariser λ·max(0, ‖f(X_t) − f(X_{t−1})‖₁ − L).
    pub lipschitz_weight: f64,
    /// L of the same regulariser.
    pub lipschitz_bound: f64,
    /// Averaged SGD: the adapted parameters are the mean of the parameters after each update of
    /// the last pass, instead of those after the last update. Off by default (the paper).
    #[serde(default)]
    pub average_last_pass: bool,
}

/// Everything in `experiments/learn.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LearnConfig {
    /// P, learned basis functions per input feature (the paper: 2, the analogue of sin and cos).
    pub basis_per_input: usize,
    /// Hidden widths of both networks (the paper: [12, 16, 24, 48]).
    pub hidden_layers: Vec<usize>,
    /// z-score the inputs with the meta-training statistics.
    pub standardise_inputs: bool,
    /// Clamp each raw input to the range it spans in the meta-training flights before the z-score,
    /// so that adaptation and prediction never evaluate the networks beyond the inputs they were
    /// meta-trained on (a GELU network extrapolates linearly, without bound). Off: the paper.
    #[serde(default)]
    pub clamp_inputs: bool,
    pub meta_training: MetaTrainingConfig,
    pub adaptation: AdaptationConfig,
    /// The seed of the reported run (initialisation and task sampling).
    pub seed: u64,
    /// The seeds of the seed-to-seed spread measurement: at least two, all different.
    pub spread_seeds: Vec<u64>,
}

/// Upper bounds of the sizes in `learn.json`, so that no setting can exhaust memory or run
/// without end. Each is far above the paper's values; the bounds that depend on the data (batches
/// no larger than what they are drawn from, an adaptation window no longer than the support
/// segment) are checked when the flights are known.
pub mod limits {
    /// `basis_per_input` (the paper: 2).
    pub const BASIS_PER_INPUT: usize = 16;
    /// Number of `hidden_layers` (the paper: 4).
    pub const HIDDEN_LAYERS: usize = 16;
    /// Width of each hidden layer (the paper: at most 48).
    pub const HIDDEN_WIDTH: usize = 1024;
    /// Parameters |θ| of the networks of any formulation (the paper: about 10 000).
    pub const PARAMETERS: usize = 1_000_000;
    /// `meta_training.inner_rounds` (the paper: 1).
    pub const INNER_ROUNDS: usize = 100;
    /// `meta_training.iterations` (the paper's budget here: 800).
    pub const ITERATIONS: usize = 1_000_000;
    /// `adaptation.passes` (here: 16).
    pub const PASSES: usize = 10_000;
}

/// A configuration that passed [`LearnConfig::check`], with the file it came from (named in the
/// errors of settings that can only be checked against the data).
#[derive(Clone, Debug)]
pub struct CheckedConfig {
    config: LearnConfig,
    origin: PathBuf,
}

/// Two checked configurations are equal when their values are, wherever they were read.
impl PartialEq for CheckedConfig {
    fn eq(&self, other: &Self) -> bool {
        self.config == other.config
    }
}

impl CheckedConfig {
    /// The checked values.
    pub fn get(&self) -> &LearnConfig {
        &self.config
    }

    /// The file the values were read from.
    pub fn origin(&self) -> &Path {
        &self.origin
    }

    /// A copy with another seed.
    pub fn with_seed(&self, seed: u64) -> Self {
        let mut config = self.config.clone();
        config.seed = seed;
        Self {
            config,
            origin: self.origin.clone(),
        }
    }
}

impl LearnConfig {
    /// Reads and checks a configuration file.
    pub fn load(path: &Path) -> Result<CheckedConfig> {
        let text = bounded_read::read_json_text(path).map_err(|cause| LearnError::Io {
            path: path.to_path_buf(),
            cause,
        })?;
        let config: Self =
            bounded_read::json::from_str(&text).map_err(|error| LearnError::Config {
                path: path.to_path_buf(),
                field: error.field,
                message: error.message,
            })?;
        config.check(path)
    }

    /// Checks every value once; `origin` names the file in error messages.
    pub fn check(self, origin: &Path) -> Result<CheckedConfig> {
        let error = |field: &str, message: &str| LearnError::Config {
            path: PathBuf::from(origin),
            field: field.to_string(),
            message: message.to_string(),
        };
        self.check_architecture(&error)?;
        self.check_training(&error)?;
        self.check_spread_seeds(&error)?;
        Ok(CheckedConfig {
            config: self,
            origin: origin.to_path_buf(),
        })
    }

    /// The networks' sizes and their parameter count.
    fn check_architecture(&self, error: &dyn Fn(&str, &str) -> LearnError) -> Result<()> {
        if !(1..=limits::BASIS_PER_INPUT).contains(&self.basis_per_input) {
            return Err(error(
                "basis_per_input",
                &format!("must be from 1 to {}", limits::BASIS_PER_INPUT),
            ));
        }
        if self.hidden_layers.len() > limits::HIDDEN_LAYERS {
            return Err(error(
                "hidden_layers",
                &format!("at most {} layers", limits::HIDDEN_LAYERS),
            ));
        }
        if self.hidden_layers.contains(&0) {
            return Err(error("hidden_layers", "every width must be at least 1"));
        }
        if self
            .hidden_layers
            .iter()
            .any(|&width| width > limits::HIDDEN_WIDTH)
        {
            return Err(error(
                "hidden_layers",
                &format!("every width must be at most {}", limits::HIDDEN_WIDTH),
            ));
        }
        // With the bounds above the count cannot overflow.
        let parameters = Formulation::ALL
            .iter()
            .map(|&formulation| {
                crate::formulation::architecture(formulation, self).parameter_count()
            })
            .max()
            .unwrap_or(0);
        if parameters > limits::PARAMETERS {
            return Err(error(
                "hidden_layers",
                &format!(
                    "the networks would have {parameters} parameters, more than {}",
                    limits::PARAMETERS
                ),
            ));
        }
        Ok(())
    }

    /// Meta-training's and adaptation's steps, rounds, batches and weights.
    fn check_training(&self, error: &dyn Fn(&str, &str) -> LearnError) -> Result<()> {
        let positive = |value: f64| value.is_finite() && value > 0.0;
        let meta = &self.meta_training;
        let adaptation = &self.adaptation;
        if !positive(meta.inner_step) {
            return Err(error(
                "meta_training.inner_step",
                "must be a positive number",
            ));
        }
        if !(1..=limits::INNER_ROUNDS).contains(&meta.inner_rounds) {
            return Err(error(
                "meta_training.inner_rounds",
                &format!(
                    "must be from 1 to {} (n ≥ 1 inner rounds: with none MAML has nothing to adapt)",
                    limits::INNER_ROUNDS
                ),
            ));
        }
        if !positive(meta.outer_step) {
            return Err(error(
                "meta_training.outer_step",
                "must be a positive number",
            ));
        }
        if !(meta.meta_regularisation.is_finite() && meta.meta_regularisation >= 0.0) {
            return Err(error("meta_training.meta_regularisation", "must be ≥ 0"));
        }
        // Their upper bounds depend on the flights: see `train::check_sampling`.
        for (field, value) in [
            ("meta_training.task_batch", meta.task_batch),
            ("meta_training.support_batch", meta.support_batch),
            ("meta_training.query_batch", meta.query_batch),
            ("adaptation.window", adaptation.window),
        ] {
            if value == 0 {
                return Err(error(field, "must be at least 1"));
            }
        }
        if !(1..=limits::ITERATIONS).contains(&meta.iterations) {
            return Err(error(
                "meta_training.iterations",
                &format!("must be from 1 to {}", limits::ITERATIONS),
            ));
        }
        if meta.average_last > meta.iterations {
            return Err(error(
                "meta_training.average_last",
                "must not exceed meta_training.iterations",
            ));
        }
        if !positive(adaptation.step) {
            return Err(error("adaptation.step", "must be a positive number"));
        }
        if !(1..=limits::PASSES).contains(&adaptation.passes) {
            return Err(error(
                "adaptation.passes",
                &format!("must be from 1 to {}", limits::PASSES),
            ));
        }
        if !(adaptation.lipschitz_weight.is_finite() && adaptation.lipschitz_weight >= 0.0) {
            return Err(error("adaptation.lipschitz_weight", "must be ≥ 0"));
        }
        if !(adaptation.lipschitz_bound.is_finite() && adaptation.lipschitz_bound >= 0.0) {
            return Err(error("adaptation.lipschitz_bound", "must be ≥ 0"));
        }
        Ok(())
    }

    /// At least two different seeds for the seed-to-seed spread.
    fn check_spread_seeds(&self, error: &dyn Fn(&str, &str) -> LearnError) -> Result<()> {
        // The spread is a sample standard deviation (n − 1): undefined over fewer than two seeds.
        if self.spread_seeds.len() < 2 {
            return Err(error(
                "spread_seeds",
                &format!(
                    "names {} seed(s); the seed-to-seed spread (a sample standard deviation) needs at least two different seeds",
                    self.spread_seeds.len()
                ),
            ));
        }
        let mut seeds = self.spread_seeds.clone();
        seeds.sort_unstable();
        if let Some(pair) = seeds.windows(2).find(|pair| pair[0] == pair[1]) {
            return Err(error(
                "spread_seeds",
                &format!("seed {} appears more than once", pair[0]),
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paper() -> LearnConfig {
        serde_json::from_str(include_str!("../../../experiments/learn.json")).unwrap()
    }

    #[test]
    fn every_field_is_bounded_and_the_error_names_it() {
        type Edit = fn(&mut LearnConfig);
        let cases: Vec<(&str, Edit)> = vec![
            ("basis_per_input", |c| c.basis_per_input = 0),
            ("basis_per_input", |c| {
                c.basis_per_input = limits::BASIS_PER_INPUT + 1
            }),
            ("hidden_layers", |c| c.hidden_layers = vec![0]),
            ("hidden_layers", |c| {
                c.hidden_layers = vec![limits::HIDDEN_WIDTH + 1]
            }),
            ("hidden_layers", |c| {
                c.hidden_layers = vec![4; limits::HIDDEN_LAYERS + 1]
            }),
            ("hidden_layers", |c| c.hidden_layers = vec![1024, 1024]),
            ("hidden_layers", |c| c.hidden_layers = vec![usize::MAX]),
            ("meta_training.inner_step", |c| {
                c.meta_training.inner_step = 0.0
            }),
            ("meta_training.inner_rounds", |c| {
                c.meta_training.inner_rounds = 0
            }),
            ("meta_training.inner_rounds", |c| {
                c.meta_training.inner_rounds = limits::INNER_ROUNDS + 1
            }),
            ("meta_training.outer_step", |c| {
                c.meta_training.outer_step = f64::INFINITY
            }),
            ("meta_training.meta_regularisation", |c| {
                c.meta_training.meta_regularisation = -1.0
            }),
            ("meta_training.task_batch", |c| {
                c.meta_training.task_batch = 0
            }),
            ("meta_training.support_batch", |c| {
                c.meta_training.support_batch = 0
            }),
            ("meta_training.query_batch", |c| {
                c.meta_training.query_batch = 0
            }),
            ("meta_training.iterations", |c| {
                c.meta_training.iterations = 0
            }),
            ("meta_training.iterations", |c| {
                c.meta_training.iterations = limits::ITERATIONS + 1
            }),
            ("meta_training.average_last", |c| {
                c.meta_training.average_last = c.meta_training.iterations + 1
            }),
            ("adaptation.step", |c| c.adaptation.step = 0.0),
            ("adaptation.step", |c| c.adaptation.step = f64::NAN),
            ("adaptation.passes", |c| c.adaptation.passes = 0),
            ("adaptation.passes", |c| {
                c.adaptation.passes = limits::PASSES + 1
            }),
            ("adaptation.window", |c| c.adaptation.window = 0),
            ("adaptation.lipschitz_weight", |c| {
                c.adaptation.lipschitz_weight = -0.1
            }),
            ("adaptation.lipschitz_bound", |c| {
                c.adaptation.lipschitz_bound = f64::NAN
            }),
            ("spread_seeds", |c| c.spread_seeds = vec![]),
            ("spread_seeds", |c| c.spread_seeds = vec![1]),
            ("spread_seeds", |c| c.spread_seeds = vec![4, 4]),
            ("spread_seeds", |c| c.spread_seeds = vec![3, 1, 3]),
        ];
        for (field, edit) in cases {
            let mut config = paper();
            edit(&mut config);
            let message = config
                .check(Path::new("learn.json"))
                .unwrap_err()
                .to_string();
            assert!(
                message.starts_with(&format!("learn.json: field '{field}'")),
                "{field}: {message}"
            );
        }
    }

    #[test]
    fn the_paper_settings_pass_and_keep_their_file() {
        let checked = paper().check(Path::new("experiments/learn.json")).unwrap();
        assert_eq!(checked.get(), &paper());
        let other = checked.with_seed(7);
        assert_eq!(other.origin(), Path::new("experiments/learn.json"));
        assert_eq!(other.get().seed, 7);
    }
}
