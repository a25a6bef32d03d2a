//! Run configurations (`experiments/reproduce.json`, `experiments/ci.json`): which formulations,
//! which conditions file, which split, derivative and SINDy configuration, which LeARN
//! configuration (with overrides) and which seeds. Checked once.

use std::path::{Path, PathBuf};

use crate::sindy_column::SindyConfig;
use data::{ExperimentConditions, SplitSpec, file_sha256};
use learn::{CheckedConfig, Formulation, LearnConfig};
use serde::{Deserialize, Serialize};
use sindy::Derivative;

use crate::error::{EvaluationError, Result};
use crate::flights::Protocol;
use crate::segment::Segmentation;

/// The LeARN part of a run.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LearnRun {
    /// The LeARN hyper-parameter file (e.g. `experiments/learn.json`).
    pub config: PathBuf,
    /// A JSON merge patch (RFC 7396) applied to that file before it is checked, e.g.
    /// `{"meta_training": {"iterations": 40}}` for a smaller budget with the same protocol.
    #[serde(default, skip_serializing_if = "serde_json::Value::is_null")]
    pub overrides: serde_json::Value,
    /// `auto` (the paper's protocol when its training flights are present, else
    /// `leave-condition-out`), `paper` or `leave-condition-out`.
    #[serde(default = "auto")]
    pub protocol: String,
    /// Seeds of the reported LeARN run: each cell is the mean over them; figures use the first.
    pub seeds: Vec<u64>,
}

fn auto() -> String {
    "auto".to_string()
}

/// One run configuration file. Relative paths are relative to the project root.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunConfig {
    /// A short name recorded in every output, e.g. `reproduce` or `ci`.
    pub name: String,
    pub description: String,
    /// The tables to produce, in order.
    pub formulations: Vec<Formulation>,
    /// The wind conditions (`experiments/conditions.json`): one table row per evaluation condition.
    pub conditions: PathBuf,
    /// The paper's numbers (`paper/published.json`).
    pub published: PathBuf,
    /// Support / query split of every flight, evaluation and meta-training (the paper: halves).
    pub split: SplitSpec,
    /// Target derivative estimate on each segment (the paper: forward differences).
    pub derivative: Derivative,
    pub sindy: SindyConfig,
    pub learn: LearnRun,
    /// A variants file (`experiments/variants.json`) whose `reproduce` variants are added to every
    /// row as extra columns (cheap ones only; the paper's columns are unchanged).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub variants: Option<PathBuf>,
}

/// A run configuration whose values and files were checked, with everything it names loaded.
#[derive(Clone, Debug)]
pub struct CheckedRunConfig {
    pub raw: RunConfig,
    /// The file it was read from and its SHA-256.
    pub path: PathBuf,
    pub sha256: String,
    /// Paths as resolved against the project root.
    pub conditions_path: PathBuf,
    pub published_path: PathBuf,
    pub learn_config_path: PathBuf,
    /// The variants file whose `reproduce` variants are added, if any.
    pub variants_path: Option<PathBuf>,
    pub conditions: ExperimentConditions,
    /// The LeARN configuration after the overrides, checked.
    pub learn: CheckedConfig,
    /// `None`: decided from the data present.
    pub protocol: Option<Protocol>,
}

impl CheckedRunConfig {
    /// How the run cuts every flight: its `split` and `derivative`.
    pub fn segmentation(&self) -> Segmentation {
        Segmentation {
            split: self.raw.split,
            derivative: self.raw.derivative,
        }
    }

    /// Every file the run reads besides the flights, each with what names it (the option or the
    /// field of this file): outputs must be none of them.
    pub fn input_files(&self, option: &str) -> Vec<(String, PathBuf)> {
        let field = |name: &str| format!("{name} of {}", self.path.display());
        let mut inputs = vec![
            (option.to_string(), self.path.clone()),
            (field("conditions"), self.conditions_path.clone()),
            (field("published"), self.published_path.clone()),
            (field("learn.config"), self.learn_config_path.clone()),
        ];
        if let Some(variants) = &self.variants_path {
            inputs.push((field("variants"), variants.clone()));
        }
        inputs
    }
}

/// `error`, met reading the file that `field` of the configuration at `path` names, with that
/// field named unless the message names the configuration already.
pub(crate) fn named_in(path: &Path, field: &str, error: EvaluationError) -> EvaluationError {
    let message = error.to_string();
    if message.contains(&path.display().to_string()) {
        return error;
    }
    EvaluationError::Config {
        path: path.to_path_buf(),
        field: field.to_string(),
        message,
    }
}

impl RunConfig {
    /// Reads and checks a run configuration; relative paths are taken from `root`.
    pub fn load(path: &Path, root: &Path) -> Result<CheckedRunConfig> {
        let text = read(path)?;
        let raw: RunConfig = bounded_read::json::from_str(&text)
            .map_err(|error| EvaluationError::json(path, error))?;
        raw.check(path, root)
    }

    fn check(self, path: &Path, root: &Path) -> Result<CheckedRunConfig> {
        let error = |field: &str, message: String| EvaluationError::Config {
            path: path.to_path_buf(),
            field: field.to_string(),
            message,
        };
        if self.formulations.is_empty() {
            return Err(error("formulations", "name at least one".to_string()));
        }
        for (index, formulation) in self.formulations.iter().enumerate() {
            if self.formulations[..index].contains(formulation) {
                return Err(error(
                    "formulations",
                    format!("'{}' is listed twice", formulation.name()),
                ));
            }
        }
        // Any split and derivative the cutting of a segment accepts: the experiment's cells, the
        // meta-training tasks and every method are cut with them (rows are checked per flight).
        if let Err(e) = self.split.validate() {
            let message = match e {
                data::DataError::Invalid { message, .. } => message,
                other => other.to_string(),
            };
            return Err(error("split", message));
        }
        if let Err(e) = self.derivative.validate() {
            return Err(error("derivative", e.to_string()));
        }
        check_seeds(&self.learn.seeds).map_err(|message| error("learn.seeds", message))?;
        // Checked now, not after the flights are loaded and LeARN is meta-trained: the library's
        // size on each formulation's inputs too (in closed form, nothing is enumerated).
        let library = sindy::FeatureLibrary::from_spec(&self.sindy.library)
            .map_err(|e| error("sindy.library", e.to_string()))?;
        for formulation in &self.formulations {
            library
                .checked_feature_count(formulation.input_names().len())
                .map_err(|e| {
                    error(
                        "sindy.library",
                        format!("on the {} formulation: {e}", formulation.name()),
                    )
                })?;
        }
        if let Some(derivative) = self.sindy.fit_derivative {
            derivative
                .validate()
                .map_err(|e| error("sindy.fit_derivative", e.to_string()))?;
        }
        self.sindy
            .optimizer
            .checked()
            .map_err(|e| error("sindy.optimizer", e.to_string()))?;
        let protocol = Protocol::parse(&self.learn.protocol)?;
        // An empty path would resolve to the root directory: named by its field instead.
        let paths = [
            ("conditions", Some(&self.conditions)),
            ("published", Some(&self.published)),
            ("learn.config", Some(&self.learn.config)),
            ("variants", self.variants.as_ref()),
        ];
        for (field, value) in paths {
            if value.is_some_and(|p| p.as_os_str().is_empty()) {
                return Err(error(field, "an empty path (name a file)".to_string()));
            }
        }
        let resolve = |p: &Path| {
            if p.is_absolute() {
                p.to_path_buf()
            } else {
                root.join(p)
            }
        };
        let conditions_path = resolve(&self.conditions);
        let published_path = resolve(&self.published);
        let learn_config_path = resolve(&self.learn.config);
        // A file a field names that cannot be read is named with that field.
        let within = |field: &str, error: EvaluationError| named_in(path, field, error);
        let conditions = ExperimentConditions::load(&conditions_path)
            .map_err(|e| within("conditions", e.into()))?;
        if conditions.evaluation().next().is_none() {
            return Err(error(
                "conditions",
                format!("{} has no evaluation condition", conditions_path.display()),
            ));
        }
        let learn = load_learn_config(&learn_config_path, &self.learn.overrides, path)
            .map_err(|e| within("learn.config", e))?;
        report::PublishedTables::load(&published_path)
            .map_err(|e| within("published", e.into()))?;
        let variants_path = self.variants.as_deref().map(resolve);
        if let Some(variants) = &variants_path {
            crate::variants::VariantsConfig::read(variants).map_err(|e| within("variants", e))?;
        }
        Ok(CheckedRunConfig {
            sha256: file_sha256(path)?,
            path: path.to_path_buf(),
            conditions_path,
            published_path,
            learn_config_path,
            variants_path,
            conditions,
            learn,
            protocol,
            raw: self,
        })
    }
}

/// The most seeds a run (`learn.seeds`) or a variants file (`seeds`) may list: every seed is a
/// full meta-training per cell (the committed configurations use up to 5).
pub const MAX_SEEDS: usize = 100;

/// At least one seed, at most [`MAX_SEEDS`], none twice; the message otherwise.
pub(crate) fn check_seeds(seeds: &[u64]) -> std::result::Result<(), String> {
    if seeds.is_empty() {
        return Err("name at least one seed".to_string());
    }
    if seeds.len() > MAX_SEEDS {
        return Err(format!(
            "{} seeds, more than the limit of {MAX_SEEDS} (evaluation::MAX_SEEDS)",
            seeds.len()
        ));
    }
    for (index, seed) in seeds.iter().enumerate() {
        if seeds[..index].contains(seed) {
            return Err(format!("seed {seed} is listed twice"));
        }
    }
    Ok(())
}

fn read(path: &Path) -> Result<String> {
    bounded_read::read_json_text(path).map_err(|source| EvaluationError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// Reads a LeARN configuration, applies the run's overrides and checks the result.
fn load_learn_config(
    path: &Path,
    overrides: &serde_json::Value,
    run_config: &Path,
) -> Result<CheckedConfig> {
    if !(overrides.is_null() || overrides.is_object()) {
        return Err(EvaluationError::Config {
            path: run_config.to_path_buf(),
            field: "learn.overrides".to_string(),
            message: "must be a JSON object (a merge patch)".to_string(),
        });
    }
    let text = read(path)?;
    let mut value: serde_json::Value =
        bounded_read::json::from_str(&text).map_err(|error| EvaluationError::json(path, error))?;
    merge_patch(&mut value, overrides);
    // With overrides, a bad value may be the override's: the error names both files.
    let with_overrides = |message: String| EvaluationError::Config {
        path: run_config.to_path_buf(),
        field: "learn.overrides".to_string(),
        message: format!("{} with these overrides: {message}", path.display()),
    };
    // Without overrides a fault is the file's own: named with its line and column.
    let config: LearnConfig = if overrides.is_null() {
        bounded_read::json::from_str(&text).map_err(|error| EvaluationError::json(path, error))?
    } else {
        bounded_read::json::from_value(value).map_err(|error| with_overrides(error.to_string()))?
    };
    match config.check(path) {
        Ok(checked) => Ok(checked),
        Err(error) if overrides.is_null() => Err(error.into()),
        Err(learn::LearnError::Config { field, message, .. }) => {
            Err(with_overrides(format!("field '{field}': {message}")))
        }
        Err(error) => Err(with_overrides(error.to_string())),
    }
}

/// RFC 7396: objects merge key by key, `null` removes a key, anything else replaces.
pub fn merge_patch(target: &mut serde_json::Value, patch: &serde_json::Value) {
    let Some(patch_object) = patch.as_object() else {
        if !patch.is_null() {
            *target = patch.clone();
        }
        return;
    };
    if !target.is_object() {
        *target = serde_json::Value::Object(Default::default());
    }
    let object = target.as_object_mut().expect("made an object above");
    for (key, value) in patch_object {
        if value.is_null() {
            object.remove(key);
        } else {
            merge_patch(
                object.entry(key.clone()).or_insert(serde_json::Value::Null),
                value,
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn merge_patch_follows_rfc_7396() {
        let mut target = json!({"a": {"b": 1, "c": 2}, "d": [1, 2], "e": 5});
        merge_patch(
            &mut target,
            &json!({"a": {"b": 10, "c": null}, "d": [3], "f": true}),
        );
        assert_eq!(target, json!({"a": {"b": 10}, "d": [3], "e": 5, "f": true}));
        let mut unchanged = json!({"a": 1});
        merge_patch(&mut unchanged, &serde_json::Value::Null);
        assert_eq!(unchanged, json!({"a": 1}));
    }
}
