//! The flights of the experiment: each flight log read and hashed once ([`Flight`]), the evaluation
//! flights in table order ([`read_evaluation_flights`]), the evaluation conditions that name a
//! cell ([`evaluation_condition_of`]) and the protocols that choose the meta-training flights
//! ([`Protocol`]).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use data::{Condition, ExperimentConditions, FlightLog, Role, file_sha256};
use learn::DataFile;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::{EvaluationError, Result};

/// A flight log with its file: the path relative to the data directory and the SHA-256, both
/// recorded in checkpoints and summaries. Read once, shared by every method that uses the flight.
#[derive(Clone, Debug)]
pub struct Flight {
    pub log: FlightLog,
    pub file: DataFile,
}

impl Flight {
    /// Reads and hashes the flight at `path` (under `data_dir`, which the recorded path is
    /// relative to when it lies below it).
    pub fn read(path: &Path, data_dir: &Path) -> Result<Self> {
        let log = FlightLog::read(path)?;
        let file = DataFile {
            path: path.strip_prefix(data_dir).unwrap_or(path).to_path_buf(),
            sha256: file_sha256(path)?,
        };
        Ok(Self { log, file })
    }
}

/// The evaluation flight of every evaluation condition of `conditions` (the evaluation
/// controller's), in table order, read in parallel.
pub fn read_evaluation_flights(
    conditions: &ExperimentConditions,
    data_dir: &Path,
) -> Result<Vec<Arc<Flight>>> {
    let paths: Vec<PathBuf> = conditions
        .evaluation()
        .map(|condition| evaluation_flight_path(conditions, data_dir, condition))
        .collect();
    paths
        .par_iter()
        .map(|path| Flight::read(path, data_dir).map(Arc::new))
        .collect()
}

/// The evaluation flight of `condition`: the evaluation controller's.
pub(crate) fn evaluation_flight_path(
    conditions: &ExperimentConditions,
    data_dir: &Path,
    condition: &Condition,
) -> PathBuf {
    conditions.flight_path(data_dir, condition, &conditions.evaluation_controller)
}

/// The evaluation condition `name` (name or label) of `conditions`. A condition that exists but is
/// only used to meta-train is refused, naming it and listing the evaluation conditions.
pub fn evaluation_condition_of<'a>(
    conditions: &'a ExperimentConditions,
    name: &str,
) -> Result<&'a Condition> {
    let condition = conditions.condition(name)?;
    if condition.role != Role::Evaluation {
        let evaluation: Vec<&str> = conditions.evaluation().map(|c| c.name.as_str()).collect();
        return Err(EvaluationError::NotEvaluationCondition {
            condition: name.to_string(),
            role: match condition.role {
                Role::MetaTraining => "meta-training",
                Role::Evaluation => "evaluation",
            }
            .to_string(),
            evaluation: evaluation.join(", "),
        });
    }
    Ok(condition)
}

/// Which flights meta-train the model for an evaluation condition.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Protocol {
    /// The paper's meta-training flights `training/custom_random3_baseline_*.csv` (all six).
    Paper,
    /// For evaluation condition c: every shared figure-8 flight whose condition is not c, all
    /// controllers. The evaluated flight and its wind speed are never seen during meta-training.
    LeaveConditionOut,
}

impl Protocol {
    /// The name used in files and on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Paper => "paper",
            Self::LeaveConditionOut => "leave-condition-out",
        }
    }

    /// Parses `paper`, `leave-condition-out` or `auto` (None: decide from the data present).
    pub fn parse(text: &str) -> Result<Option<Self>> {
        match text {
            "paper" => Ok(Some(Self::Paper)),
            "leave-condition-out" => Ok(Some(Self::LeaveConditionOut)),
            "auto" => Ok(None),
            other => Err(EvaluationError::UnknownProtocol {
                name: other.to_string(),
            }),
        }
    }

    /// The protocol a checkpoint records by name (`paper` or `leave-condition-out`).
    pub fn recorded(name: &str) -> Result<Self> {
        Self::parse(name)?.ok_or_else(|| EvaluationError::UnknownProtocol {
            name: name.to_string(),
        })
    }

    /// `requested`, or when None: `paper` if the paper's training flights are present, otherwise
    /// `leave-condition-out`.
    pub fn resolve(
        requested: Option<Self>,
        conditions: &ExperimentConditions,
        data_dir: &Path,
    ) -> Self {
        requested.unwrap_or(if conditions.paper_training_present(data_dir) {
            Self::Paper
        } else {
            Self::LeaveConditionOut
        })
    }

    /// The meta-training flight files for `evaluation_condition` (a name or label).
    pub fn training_files(
        &self,
        conditions: &ExperimentConditions,
        data_dir: &Path,
        evaluation_condition: &str,
    ) -> Result<Vec<PathBuf>> {
        let held_out = conditions.condition(evaluation_condition)?;
        let files = conditions.flight_files(data_dir);
        let chosen: Vec<PathBuf> = match self {
            Self::Paper => {
                let paper: Vec<_> = files
                    .iter()
                    .filter(|f| f.controller == "paper-training")
                    .collect();
                if let Some(missing) = paper.iter().find(|f| !f.present) {
                    return Err(EvaluationError::NoTrainingFlights {
                        protocol: self.name().to_string(),
                        condition: held_out.name.clone(),
                        detail: format!("{} is missing", missing.path.display()),
                    });
                }
                paper.iter().map(|f| f.path.clone()).collect()
            }
            Self::LeaveConditionOut => files
                .iter()
                .filter(|f| {
                    f.controller != "paper-training" && f.condition != held_out.name && f.present
                })
                .map(|f| f.path.clone())
                .collect(),
        };
        if chosen.is_empty() {
            return Err(EvaluationError::NoTrainingFlights {
                protocol: self.name().to_string(),
                condition: held_out.name.clone(),
                detail: format!("no flight file present under {}", data_dir.display()),
            });
        }
        Ok(chosen)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn conditions() -> ExperimentConditions {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../experiments/conditions.json");
        ExperimentConditions::load(&path).unwrap()
    }

    #[test]
    fn only_evaluation_conditions_name_a_cell() {
        let conditions = conditions();
        let cell = evaluation_condition_of(&conditions, "70psin20").unwrap();
        assert_eq!(cell.name, "70p20sint");
        let error = evaluation_condition_of(&conditions, "nowind").unwrap_err();
        assert!(
            matches!(error, EvaluationError::NotEvaluationCondition { .. }),
            "{error}"
        );
        assert_eq!(
            error.to_string(),
            "condition 'nowind' is not an evaluation condition (its role is meta-training); \
             the evaluation conditions are: 35wind, 70p20sint, 70wind, 100wind"
        );
        let message = evaluation_condition_of(&conditions, "nope")
            .unwrap_err()
            .to_string();
        assert!(message.contains("unknown condition 'nope'"), "{message}");
    }

    #[test]
    fn a_recorded_protocol_is_one_of_the_two_names() {
        assert_eq!(Protocol::recorded("paper").unwrap(), Protocol::Paper);
        let text = serde_json::to_string(&Protocol::LeaveConditionOut).unwrap();
        assert_eq!(text, format!("\"{}\"", Protocol::LeaveConditionOut.name()));
        for bad in ["auto", "papers"] {
            let message = Protocol::recorded(bad).unwrap_err().to_string();
            assert!(message.contains("unknown protocol"), "{message}");
        }
    }
}
