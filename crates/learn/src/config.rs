//! Hyper-parameters of LeARN, read from `experiments/learn.json` and checked once.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

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

/// Meta-training (Algorithm 1).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MetaTrainingConfig {
    /// α, the inner SGD step (on the mean squared error).
    pub inner_step: f64,
    /// n, the inner SGD rounds.
    pub inner_rounds: usize,
    /// β, the outer step.
    pub outer_step: f64,
    pub optimizer: Optimizer,
    /// μ of the meta-regulariser μ‖θ‖².
    pub meta_regularisation: f64,
    /// Exact second order, or first order.
    pub order: MetaOrder,
    /// Tasks (flights) per meta-iteration, drawn without replacement while possible.
    pub task_batch: usize,
    /// Support points per task (drawn from the first half of the flight).
    pub support_batch: usize,
    /// Query points per task (drawn from the second half of the flight).
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
    /// Consecutive samples per online update (1 = the paper's one sample per step).
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
    /// The seeds of the seed-to-seed spread measurement.
    pub spread_seeds: Vec<u64>,
}

/// A configuration that passed [`LearnConfig::check`].
#[derive(Clone, Debug, PartialEq)]
pub struct CheckedConfig(LearnConfig);

impl CheckedConfig {
    /// The checked values.
    pub fn get(&self) -> &LearnConfig {
        &self.0
    }

    /// A copy with another seed.
    pub fn with_seed(&self, seed: u64) -> Self {
        let mut config = self.0.clone();
        config.seed = seed;
        Self(config)
    }
}

impl LearnConfig {
    /// Reads and checks a configuration file.
    pub fn load(path: &Path) -> Result<CheckedConfig> {
        let text = std::fs::read_to_string(path).map_err(|cause| LearnError::Io {
            path: path.to_path_buf(),
            cause,
        })?;
        let config: Self = serde_json::from_str(&text).map_err(|error| LearnError::Config {
            path: path.to_path_buf(),
            field: format!("line {} column {}", error.line(), error.column()),
            message: error.to_string(),
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
        let positive = |value: f64| value.is_finite() && value > 0.0;
        let meta = &self.meta_training;
        let adaptation = &self.adaptation;
        if self.basis_per_input == 0 {
            return Err(error("basis_per_input", "must be at least 1"));
        }
        if self.hidden_layers.contains(&0) {
            return Err(error("hidden_layers", "every width must be at least 1"));
        }
        if !positive(meta.inner_step) {
            return Err(error(
                "meta_training.inner_step",
                "must be a positive number",
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
        if meta.average_last > meta.iterations {
            return Err(error(
                "meta_training.average_last",
                "must not exceed meta_training.iterations",
            ));
        }
        if !(adaptation.step.is_finite() && adaptation.step >= 0.0) {
            return Err(error("adaptation.step", "must be ≥ 0"));
        }
        if !(adaptation.lipschitz_weight.is_finite() && adaptation.lipschitz_weight >= 0.0) {
            return Err(error("adaptation.lipschitz_weight", "must be ≥ 0"));
        }
        if !(adaptation.lipschitz_bound.is_finite() && adaptation.lipschitz_bound >= 0.0) {
            return Err(error("adaptation.lipschitz_bound", "must be ≥ 0"));
        }
        if self.spread_seeds.is_empty() {
            return Err(error("spread_seeds", "must name at least one seed"));
        }
        Ok(CheckedConfig(self))
    }
}
