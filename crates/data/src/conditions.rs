//! The experiment's wind conditions and flight files, declared in `experiments/conditions.json`.
//!
//! Adding a wind condition is a CSV in the data directory plus one entry in that file: every table,
//! figure and fold is driven by this list.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::{DataError, Result};

/// What a condition is used for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Role {
    /// Only ever used to meta-train.
    MetaTraining,
    /// A row of the tables: evaluated (and left out of meta-training in its own fold).
    Evaluation,
}

/// One wind condition.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Condition {
    /// The condition as it appears in file names, e.g. `70p20sint`.
    pub name: String,
    /// The name printed in tables, e.g. `70psin20` (the paper's spelling); defaults to `name`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub label: Option<String>,
    /// Wind speed as text, e.g. `8.5 + 2.4 sin(t) m/s`.
    pub wind_speed: String,
    pub role: Role,
    /// Explicit files per controller (paths relative to the data directory), overriding the pattern.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub files: BTreeMap<String, String>,
}

impl Condition {
    /// The name printed in tables.
    pub fn label(&self) -> &str {
        self.label.as_deref().unwrap_or(&self.name)
    }
}

/// The paper's meta-training flights, used by the `paper` protocol when present.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PaperTraining {
    /// File pattern relative to the data directory, with `{condition}`.
    pub file_pattern: String,
    pub conditions: Vec<Condition>,
}

/// The whole `conditions.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExperimentConditions {
    /// File pattern relative to the data directory, with `{controller}` and `{condition}`.
    pub file_pattern: String,
    /// Every controller whose flights exist for the conditions.
    pub controllers: Vec<String>,
    /// The controller whose flights are evaluated (the paper: `baseline`).
    pub evaluation_controller: String,
    pub conditions: Vec<Condition>,
    pub paper_training: PaperTraining,
}

/// One flight file a configuration refers to, and whether it is present.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FlightFile {
    pub condition: String,
    pub controller: String,
    pub path: PathBuf,
    pub present: bool,
}

impl ExperimentConditions {
    /// Reads and checks `conditions.json`.
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|source| DataError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let config: Self = serde_json::from_str(&text).map_err(|error| DataError::Config {
            path: path.to_path_buf(),
            field: format!("line {} column {}", error.line(), error.column()),
            message: error.to_string(),
        })?;
        config.validate(path)?;
        Ok(config)
    }

    fn validate(&self, path: &Path) -> Result<()> {
        let config_error = |field: &str, message: String| DataError::Config {
            path: path.to_path_buf(),
            field: field.to_string(),
            message,
        };
        if !self.controllers.contains(&self.evaluation_controller) {
            return Err(config_error(
                "evaluation_controller",
                format!("'{}' is not in controllers", self.evaluation_controller),
            ));
        }
        let mut seen = std::collections::BTreeSet::new();
        for condition in &self.conditions {
            if !seen.insert(&condition.name) {
                return Err(config_error(
                    "conditions",
                    format!("condition '{}' is declared twice", condition.name),
                ));
            }
            if let Some(controller) = condition
                .files
                .keys()
                .find(|c| !self.controllers.contains(c))
            {
                return Err(config_error(
                    &format!("conditions.{}.files", condition.name),
                    format!("unknown controller '{controller}'"),
                ));
            }
        }
        if !self.file_pattern.contains("{condition}") {
            return Err(config_error(
                "file_pattern",
                "must contain {condition}".to_string(),
            ));
        }
        Ok(())
    }

    /// The conditions evaluated in the tables, in declaration order.
    pub fn evaluation(&self) -> impl Iterator<Item = &Condition> {
        self.conditions
            .iter()
            .filter(|c| c.role == Role::Evaluation)
    }

    /// A condition by its name or label.
    pub fn condition(&self, name: &str) -> Result<&Condition> {
        self.conditions
            .iter()
            .find(|c| c.name == name || c.label() == name)
            .ok_or_else(|| DataError::UnknownName {
                kind: "condition",
                name: name.to_string(),
                known: self
                    .conditions
                    .iter()
                    .map(|c| c.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            })
    }

    /// Path of the flight of `controller` in `condition`, under `data_dir`.
    pub fn flight_path(&self, data_dir: &Path, condition: &Condition, controller: &str) -> PathBuf {
        let relative = condition.files.get(controller).cloned().unwrap_or_else(|| {
            self.file_pattern
                .replace("{controller}", controller)
                .replace("{condition}", &condition.name)
        });
        data_dir.join(relative)
    }

    /// Every flight the configuration names (each condition with each controller, then the paper's
    /// training flights), with whether the file is present under `data_dir`.
    pub fn flight_files(&self, data_dir: &Path) -> Vec<FlightFile> {
        let mut files = Vec::new();
        for condition in &self.conditions {
            for controller in &self.controllers {
                let path = self.flight_path(data_dir, condition, controller);
                let explicit = condition.files.contains_key(controller);
                // Conditions with explicit files list only those controllers.
                if !condition.files.is_empty() && !explicit {
                    continue;
                }
                files.push(FlightFile {
                    condition: condition.name.clone(),
                    controller: controller.clone(),
                    present: path.is_file(),
                    path,
                });
            }
        }
        for condition in &self.paper_training.conditions {
            let path = data_dir.join(
                self.paper_training
                    .file_pattern
                    .replace("{condition}", &condition.name),
            );
            files.push(FlightFile {
                condition: condition.name.clone(),
                controller: "paper-training".to_string(),
                present: path.is_file(),
                path,
            });
        }
        files
    }

    /// Whether every flight of the paper's meta-training set is present.
    pub fn paper_training_present(&self, data_dir: &Path) -> bool {
        self.flight_files(data_dir)
            .iter()
            .filter(|f| f.controller == "paper-training")
            .all(|f| f.present)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> &'static str {
        r#"{
          "file_pattern": "experiment/custom_figure8_{controller}_{condition}.csv",
          "controllers": ["baseline", "NF"],
          "evaluation_controller": "baseline",
          "conditions": [
            {"name": "nowind", "wind_speed": "0 m/s", "role": "meta-training"},
            {"name": "70p20sint", "label": "70psin20", "wind_speed": "8.5 + 2.4 sin(t) m/s", "role": "evaluation"},
            {"name": "extra", "wind_speed": "1 m/s", "role": "evaluation", "files": {"baseline": "mine/extra.csv"}}
          ],
          "paper_training": {"file_pattern": "training/custom_random3_baseline_{condition}.csv",
            "conditions": [{"name": "10wind", "wind_speed": "1.3 m/s", "role": "meta-training"}]}
        }"#
    }

    #[test]
    fn reads_patterns_labels_and_explicit_files() {
        let dir = std::env::temp_dir().join(format!("conditions-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("conditions.json");
        std::fs::write(&path, sample()).unwrap();
        let config = ExperimentConditions::load(&path).unwrap();
        let labels: Vec<&str> = config.evaluation().map(|c| c.label()).collect();
        assert_eq!(labels, vec!["70psin20", "extra"]);
        let files = config.flight_files(Path::new("/d"));
        assert_eq!(files.len(), 2 + 2 + 1 + 1);
        assert_eq!(files[4].path, Path::new("/d/mine/extra.csv"));
        assert_eq!(
            config.flight_path(Path::new("/d"), config.condition("70psin20").unwrap(), "NF"),
            Path::new("/d/experiment/custom_figure8_NF_70p20sint.csv")
        );
        assert!(config.condition("200wind").is_err());
    }

    #[test]
    fn bad_json_names_the_file_and_field() {
        let dir = std::env::temp_dir().join(format!("conditions-bad-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("conditions.json");
        std::fs::write(
            &path,
            sample().replace("\"role\": \"evaluation\"}", "\"rol\": 1}"),
        )
        .unwrap();
        let message = ExperimentConditions::load(&path).unwrap_err().to_string();
        assert!(
            message.contains("conditions.json") && message.contains("rol"),
            "{message}"
        );
        std::fs::write(
            &path,
            sample().replace(
                "\"evaluation_controller\": \"baseline\"",
                "\"evaluation_controller\": \"pid\"",
            ),
        )
        .unwrap();
        let message = ExperimentConditions::load(&path).unwrap_err().to_string();
        assert!(
            message.contains("evaluation_controller") && message.contains("pid"),
            "{message}"
        );
    }
}
