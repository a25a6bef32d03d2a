//! The experiment's wind conditions and flight files, declared in `experiments/conditions.json`.
//!
//! Adding a wind condition is a CSV in the data directory plus one entry in that file: every table,
//! figure and fold is driven by this list.

use std::collections::BTreeMap;
use std::path::{Component, Path, PathBuf};

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
    /// The mean wind speed where the vehicle flies, m/s, when it is known (e.g. a fan setting). Only
    /// ever compared with what the mismatch tool estimates, never an input to a fit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mean_wind_m_s: Option<f64>,
    /// Flown in still air: the mismatch tool's joint fit takes these flights' air velocity as zero
    /// and calibrates the vehicle on them (what still air cannot tell apart from a steady wind,
    /// such as a tilted thrust axis).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub calm: bool,
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
    /// The file this was read from (names it in errors of [`ExperimentConditions::condition`]).
    #[serde(skip)]
    source: Option<PathBuf>,
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
        let text = bounded_read::read_json_text(path).map_err(|source| DataError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let mut config: Self =
            bounded_read::json::from_str(&text).map_err(|error| DataError::Config {
                path: path.to_path_buf(),
                field: error.field,
                message: error.message,
            })?;
        config.validate(path)?;
        config.source = Some(path.to_path_buf());
        Ok(config)
    }

    fn validate(&self, path: &Path) -> Result<()> {
        let config_error = |field: &str, message: String| DataError::Config {
            path: path.to_path_buf(),
            field: field.to_string(),
            message,
        };
        self.validate_controllers(&config_error)?;
        self.validate_conditions(&config_error)?;
        self.validate_paper_training(&config_error)
    }

    /// Controller names: non-empty, one path component each, listed once.
    fn validate_controllers(&self, config_error: &dyn Fn(&str, String) -> DataError) -> Result<()> {
        for (index, controller) in self.controllers.iter().enumerate() {
            if controller.trim().is_empty() {
                return Err(config_error(
                    &format!("controllers[{index}]"),
                    "empty controller name".to_string(),
                ));
            }
            // The name becomes part of a path through {controller}: it must stay one component.
            if controller.contains(['/', '\\']) || matches!(controller.as_str(), "." | "..") {
                return Err(config_error(
                    &format!("controllers[{index}]"),
                    format!(
                        "'{controller}': a controller name is part of file names (no '/', '\\', \
                         '.' or '..')"
                    ),
                ));
            }
            if self.controllers[..index].contains(controller) {
                return Err(config_error(
                    "controllers",
                    format!("controller '{controller}' is listed twice"),
                ));
            }
        }
        Ok(())
    }

    /// The conditions: wind speeds, the evaluation controller, the file pattern, each
    /// condition's files, at least one evaluation condition.
    fn validate_conditions(&self, config_error: &dyn Fn(&str, String) -> DataError) -> Result<()> {
        for (index, condition) in self.conditions.iter().enumerate() {
            if let Some(speed) = condition.mean_wind_m_s
                && !(speed.is_finite() && (0.0..=1e3).contains(&speed))
            {
                return Err(config_error(
                    &format!("conditions[{index}].mean_wind_m_s"),
                    format!(
                        "a wind speed in m/s, between 0 and 1000, found {}",
                        crate::error::Compact(speed)
                    ),
                ));
            }
        }
        if !self.controllers.contains(&self.evaluation_controller) {
            return Err(config_error(
                "evaluation_controller",
                format!("'{}' is not in controllers", self.evaluation_controller),
            ));
        }
        // With several controllers, a pattern without {controller} names one file for all of them.
        let required: &[&str] = if self.controllers.len() > 1 {
            &["controller", "condition"]
        } else {
            &["condition"]
        };
        check_pattern(&self.file_pattern, &["controller", "condition"], required)
            .map_err(|message| config_error("file_pattern", message))?;
        if self.conditions.is_empty() {
            return Err(config_error(
                "conditions",
                "no condition is declared (at least one evaluation condition is needed)"
                    .to_string(),
            ));
        }
        check_conditions(&self.conditions, "conditions", config_error)?;
        for (index, condition) in self.conditions.iter().enumerate() {
            if let Some(controller) = condition
                .files
                .keys()
                .find(|c| !self.controllers.contains(c))
            {
                return Err(config_error(
                    &format!("conditions[{index}].files"),
                    format!(
                        "unknown controller '{controller}' (condition '{}')",
                        condition.name
                    ),
                ));
            }
            if let Some((controller, file)) = condition
                .files
                .iter()
                .find(|(_, file)| file.trim().is_empty() || !inside_data_dir(file))
            {
                return Err(config_error(
                    &format!("conditions[{index}].files.{controller}"),
                    format!(
                        "'{file}' must be a path relative to the data directory, inside it \
                         (no '..')"
                    ),
                ));
            }
        }
        if self.evaluation().next().is_none() {
            return Err(config_error(
                "conditions",
                "no condition has role \"evaluation\" (the tables would have no row)".to_string(),
            ));
        }
        Ok(())
    }

    /// The paper's meta-training flights: a pattern by condition, meta-training roles only.
    fn validate_paper_training(
        &self,
        config_error: &dyn Fn(&str, String) -> DataError,
    ) -> Result<()> {
        let paper = &self.paper_training;
        check_pattern(&paper.file_pattern, &["condition"], &["condition"])
            .map_err(|message| config_error("paper_training.file_pattern", message))?;
        if paper.conditions.is_empty() {
            return Err(config_error(
                "paper_training.conditions",
                "no condition is declared (the paper's protocol needs its training flights)"
                    .to_string(),
            ));
        }
        check_conditions(&paper.conditions, "paper_training.conditions", config_error)?;
        for (index, condition) in paper.conditions.iter().enumerate() {
            let field = format!("paper_training.conditions[{index}]");
            if condition.role != Role::MetaTraining {
                return Err(config_error(
                    &format!("{field}.role"),
                    format!(
                        "'{}': the paper's training flights are \"meta-training\"",
                        condition.name
                    ),
                ));
            }
            if !condition.files.is_empty() {
                return Err(config_error(
                    &format!("{field}.files"),
                    format!(
                        "'{}': paper_training flights follow paper_training.file_pattern",
                        condition.name
                    ),
                ));
            }
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
        if let Some(condition) = self
            .conditions
            .iter()
            .find(|c| c.name == name || c.label() == name)
        {
            return Ok(condition);
        }
        let known: Vec<&str> = self.conditions.iter().map(|c| c.name.as_str()).collect();
        let message = if known.is_empty() {
            format!("unknown condition '{name}': no conditions are declared")
        } else {
            format!("unknown condition '{name}' (known: {})", known.join(", "))
        };
        Err(match &self.source {
            Some(path) => DataError::Config {
                path: path.clone(),
                field: "conditions".to_string(),
                message,
            },
            None => DataError::Invalid {
                what: "conditions".to_string(),
                message,
            },
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
        let mut files = self.condition_flight_files(data_dir);
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

    /// The flights of the experiment's conditions: each condition with each controller (a
    /// condition that lists `files` declares only the controllers it lists), in the order of the
    /// conditions, with whether the file is present under `data_dir`.
    pub fn condition_flight_files(&self, data_dir: &Path) -> Vec<FlightFile> {
        let mut files = Vec::new();
        for condition in &self.conditions {
            for controller in &self.controllers {
                if !condition.files.is_empty() && !condition.files.contains_key(controller) {
                    continue;
                }
                let path = self.flight_path(data_dir, condition, controller);
                files.push(FlightFile {
                    condition: condition.name.clone(),
                    controller: controller.clone(),
                    present: path.is_file(),
                    path,
                });
            }
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

/// Whether `path` names a place inside the data directory: relative, and without a `..` component.
fn inside_data_dir(path: &str) -> bool {
    let path = Path::new(path);
    !path.has_root()
        && path
            .components()
            .all(|c| matches!(c, Component::Normal(_) | Component::CurDir))
}

/// Checks a file pattern: braces balanced, only the `allowed` placeholders, each of the
/// `required` ones present, a path inside the data directory (relative, no `..`).
fn check_pattern(
    pattern: &str,
    allowed: &[&str],
    required: &[&str],
) -> std::result::Result<(), String> {
    let known = allowed
        .iter()
        .map(|p| format!("{{{p}}}"))
        .collect::<Vec<_>>()
        .join(" and ");
    let mut rest = pattern;
    while let Some(open) = rest.find(['{', '}']) {
        if rest[open..].starts_with('}') {
            return Err(format!("'{pattern}' has a '}}' without its '{{'"));
        }
        let after = &rest[open + 1..];
        let close = after
            .find(['{', '}'])
            .filter(|&i| after[i..].starts_with('}'))
            .ok_or_else(|| format!("'{pattern}' has a '{{' that is not closed"))?;
        let placeholder = &after[..close];
        if !allowed.contains(&placeholder) {
            return Err(format!(
                "'{pattern}': unknown placeholder {{{placeholder}}} (known: {known})"
            ));
        }
        rest = &after[close + 1..];
    }
    if let Some(missing) = required
        .iter()
        .find(|p| !pattern.contains(&format!("{{{p}}}")))
    {
        return Err(if *missing == "controller" {
            format!(
                "'{pattern}' must contain {{controller}}: with several controllers, a pattern \
                 without it names the same file for all of them"
            )
        } else {
            format!("'{pattern}' must contain {{{missing}}}")
        });
    }
    if !inside_data_dir(pattern) {
        return Err(format!(
            "'{pattern}' must be a path relative to the data directory, inside it (no '..')"
        ));
    }
    Ok(())
}

/// Names present and unique, labels present and unique: a name or label designates one condition.
fn check_conditions(
    conditions: &[Condition],
    list: &str,
    config_error: &dyn Fn(&str, String) -> DataError,
) -> Result<()> {
    for (index, condition) in conditions.iter().enumerate() {
        let field = format!("{list}[{index}]");
        if condition.name.trim().is_empty() {
            return Err(config_error(
                &format!("{field}.name"),
                "empty condition name".to_string(),
            ));
        }
        // The name becomes part of file names (checkpoints, figures, file patterns).
        let plain = |c: char| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.' | '+');
        if !condition.name.chars().all(plain) || condition.name.starts_with('.') {
            return Err(config_error(
                &format!("{field}.name"),
                format!(
                    "'{}': use letters, digits, '-', '_', '+' and '.' (not first); the name is \
                     part of file names (a label may be any text)",
                    condition.name
                ),
            ));
        }
        if condition
            .label
            .as_deref()
            .is_some_and(|l| l.trim().is_empty())
        {
            return Err(config_error(
                &format!("{field}.label"),
                format!("empty label (condition '{}')", condition.name),
            ));
        }
        for (other_index, other) in conditions[..index].iter().enumerate() {
            if other.name == condition.name {
                return Err(config_error(
                    list,
                    format!("condition '{}' is declared twice", condition.name),
                ));
            }
            let ours = [condition.name.as_str(), condition.label()];
            let theirs = [other.name.as_str(), other.label()];
            if let Some(clash) = ours.iter().find(|n| theirs.contains(n)) {
                // The label that repeats a name or label: this condition's, or the other's.
                let culprit = if *clash == condition.name {
                    other_index
                } else {
                    index
                };
                return Err(config_error(
                    &format!("{list}[{culprit}].label"),
                    format!(
                        "'{clash}' names both '{}' ({list}[{other_index}]) and '{}'",
                        other.name, condition.name
                    ),
                ));
            }
        }
    }
    Ok(())
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
        let dir = tempfile::Builder::new()
            .prefix("conditions-")
            .tempdir()
            .unwrap();
        let path = dir.path().join("conditions.json");
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
        let dir = tempfile::Builder::new()
            .prefix("conditions-bad-")
            .tempdir()
            .unwrap();
        let path = dir.path().join("conditions.json");
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

    /// Loads `sample()` edited by `edit`, expecting an error that names the file and `needles`.
    fn rejected(name: &str, edit: impl Fn(&str) -> String, needles: &[&str]) {
        let dir = tempfile::Builder::new()
            .prefix(&format!("conditions-{name}-"))
            .tempdir()
            .unwrap();
        let path = dir.path().join("conditions.json");
        let text = edit(sample());
        assert_ne!(text, sample(), "{name}: the edit changed nothing");
        std::fs::write(&path, text).unwrap();
        let message = ExperimentConditions::load(&path).unwrap_err().to_string();
        assert!(!message.contains('\n'), "{message}");
        assert!(message.contains("conditions.json: "), "{message}");
        for needle in needles {
            assert!(
                message.contains(needle),
                "{name}: {needle:?} missing from {message}"
            );
        }
    }

    #[test]
    fn a_known_wind_speed_is_a_speed() {
        rejected(
            "negative-wind",
            |s| {
                s.replace(
                    "\"label\": \"70psin20\"",
                    "\"label\": \"70psin20\", \"mean_wind_m_s\": -8.5",
                )
            },
            &["conditions[1].mean_wind_m_s", "-8.5"],
        );
        rejected(
            "calm-text",
            |s| {
                s.replace(
                    "\"label\": \"70psin20\"",
                    "\"label\": \"70psin20\", \"calm\": \"no\"",
                )
            },
            &["calm"],
        );
    }

    #[test]
    fn names_and_labels_designate_one_condition_each() {
        rejected(
            "dup-label",
            |s| s.replace("\"label\": \"70psin20\"", "\"label\": \"extra\""),
            &["conditions[1].label", "'extra' names both"],
        );
        rejected(
            "label-is-another-name",
            |s| s.replace("\"label\": \"70psin20\"", "\"label\": \"nowind\""),
            &["conditions[1].label", "'nowind'"],
        );
        rejected(
            "empty-name",
            |s| s.replace("\"name\": \"extra\"", "\"name\": \" \""),
            &["conditions[2].name", "empty condition name"],
        );
        for (case, name) in [
            ("slash", "sub/../../escape"),
            ("dot", ".hidden"),
            ("space", "a b"),
        ] {
            rejected(
                case,
                |s| s.replace("\"name\": \"extra\"", &format!("\"name\": \"{name}\"")),
                &["conditions[2].name", "part of file names"],
            );
        }
        rejected(
            "empty-label",
            |s| s.replace("\"label\": \"70psin20\"", "\"label\": \"\""),
            &["conditions[1].label", "empty label"],
        );
        rejected(
            "dup-paper",
            |s| {
                s.replace(
                    "\"conditions\": [{\"name\": \"10wind\", \"wind_speed\": \"1.3 m/s\", \"role\": \"meta-training\"}]",
                    "\"conditions\": [{\"name\": \"10wind\", \"wind_speed\": \"1.3 m/s\", \"role\": \"meta-training\"}, {\"name\": \"10wind\", \"wind_speed\": \"1 m/s\", \"role\": \"meta-training\"}]",
                )
            },
            &["paper_training.conditions", "'10wind' is declared twice"],
        );
        rejected(
            "dup-controller",
            |s| s.replace("[\"baseline\", \"NF\"]", "[\"baseline\", \"NF\", \"NF\"]"),
            &["controllers", "'NF' is listed twice"],
        );
    }

    #[test]
    fn file_patterns_use_known_placeholders_only() {
        rejected(
            "unknown-placeholder",
            |s| s.replace("{controller}_{condition}", "{ctrl}_{condition}"),
            &["file_pattern", "unknown placeholder {ctrl}"],
        );
        rejected(
            "unclosed",
            |s| s.replace("{controller}_{condition}", "{controller_{condition}"),
            &["file_pattern", "not closed"],
        );
        rejected(
            "stray-brace",
            |s| s.replace("{controller}_{condition}", "controller}_{condition}"),
            &["file_pattern", "'}' without its '{'"],
        );
        rejected(
            "absolute",
            |s| s.replace("experiment/custom_figure8_", "/etc/"),
            &["file_pattern", "relative to the data directory"],
        );
        rejected(
            "paper-controller",
            |s| s.replace("custom_random3_baseline_", "custom_random3_{controller}_"),
            &[
                "paper_training.file_pattern",
                "unknown placeholder {controller}",
            ],
        );
        rejected(
            "absolute-file",
            |s| s.replace("mine/extra.csv", "/mine/extra.csv"),
            &["conditions[2].files.baseline", "relative"],
        );
    }

    #[test]
    fn file_patterns_name_one_file_per_flight_inside_the_data_directory() {
        // Without {controller}, the six controllers' flights of a condition would be one file.
        rejected(
            "no-controller",
            |s| s.replace("custom_figure8_{controller}_", "custom_figure8_baseline_"),
            &[
                "conditions.json: file_pattern: 'experiment/custom_figure8_baseline_{condition}.csv' \
                 must contain {controller}",
            ],
        );
        rejected(
            "no-condition",
            |s| s.replace("_{controller}_{condition}.csv", "_{controller}.csv"),
            &[
                "file_pattern: 'experiment/custom_figure8_{controller}.csv' must contain {condition}",
            ],
        );
        rejected(
            "paper-no-condition",
            |s| {
                s.replace(
                    "custom_random3_baseline_{condition}",
                    "custom_random3_baseline",
                )
            },
            &["paper_training.file_pattern", "must contain {condition}"],
        );
        rejected(
            "parent",
            |s| s.replace("experiment/custom_figure8_", "../"),
            &[
                "file_pattern: '../{controller}_{condition}.csv'",
                "inside it (no '..')",
            ],
        );
        rejected(
            "parent-inside",
            |s| s.replace("experiment/custom_figure8_", "experiment/../../"),
            &["file_pattern", "(no '..')"],
        );
        rejected(
            "paper-parent",
            |s| s.replace("training/custom_random3", "../training/custom_random3"),
            &["paper_training.file_pattern", "(no '..')"],
        );
        rejected(
            "parent-file",
            |s| s.replace("mine/extra.csv", "mine/../../extra.csv"),
            &["conditions[2].files.baseline", "(no '..')"],
        );
        rejected(
            "controller-path",
            |s| s.replace("[\"baseline\", \"NF\"]", "[\"baseline\", \"..\"]"),
            &["controllers[1]", "'..'"],
        );
        // One controller: its flights are the only ones, {controller} may be left out.
        let dir = tempfile::Builder::new()
            .prefix("conditions-one-")
            .tempdir()
            .unwrap();
        let path = dir.path().join("conditions.json");
        let one = sample()
            .replace("[\"baseline\", \"NF\"]", "[\"baseline\"]")
            .replace("custom_figure8_{controller}_", "custom_figure8_baseline_");
        std::fs::write(&path, one).unwrap();
        let config = ExperimentConditions::load(&path).unwrap();
        assert_eq!(
            config.flight_path(
                Path::new("/d"),
                config.condition("70psin20").unwrap(),
                "baseline"
            ),
            Path::new("/d/experiment/custom_figure8_baseline_70p20sint.csv")
        );
    }

    #[test]
    fn there_is_something_to_evaluate_and_to_train_on() {
        rejected(
            "no-conditions",
            |s| {
                let start = s.find("\"conditions\": [").unwrap();
                let end = s.find("],\n          \"paper_training\"").unwrap();
                format!("{}\"conditions\": [{}", &s[..start], &s[end..])
            },
            &["conditions: no condition is declared"],
        );
        rejected(
            "no-evaluation",
            |s| s.replace("\"role\": \"evaluation\"", "\"role\": \"meta-training\""),
            &["conditions: no condition has role \"evaluation\""],
        );
        rejected(
            "no-paper-conditions",
            |s| {
                let start = s.rfind("\"conditions\": [").unwrap();
                format!("{}\"conditions\": []}}\n}}", &s[..start])
            },
            &["paper_training.conditions", "no condition is declared"],
        );
        rejected(
            "paper-evaluation",
            |s| {
                s.replace(
                    "\"1.3 m/s\", \"role\": \"meta-training\"",
                    "\"1.3 m/s\", \"role\": \"evaluation\"",
                )
            },
            &["paper_training.conditions[0].role"],
        );
    }

    #[test]
    fn an_unknown_condition_names_the_file() {
        let dir = tempfile::Builder::new()
            .prefix("conditions-unknown-")
            .tempdir()
            .unwrap();
        let path = dir.path().join("conditions.json");
        std::fs::write(&path, sample()).unwrap();
        let mut config = ExperimentConditions::load(&path).unwrap();
        let message = config.condition("200wind").unwrap_err().to_string();
        assert!(
            message.contains("conditions.json: conditions: unknown condition '200wind' (known: nowind, 70p20sint, extra)"),
            "{message}"
        );
        // Only a configuration built in code can have none (load refuses it): say so.
        config.conditions.clear();
        let message = config.condition("35wind").unwrap_err().to_string();
        assert!(
            message.contains("conditions.json") && message.contains("no conditions are declared"),
            "{message}"
        );
        assert!(!message.contains("known: )"), "{message}");
    }
}
