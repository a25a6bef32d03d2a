//! The evaluation crate's one error type.

use std::path::PathBuf;

/// Everything that can stop a run.
#[derive(Debug, thiserror::Error)]
pub enum EvaluationError {
    #[error(transparent)]
    Data(#[from] data::DataError),
    #[error(transparent)]
    Sindy(#[from] sindy::SindyError),
    #[error(transparent)]
    Learn(#[from] learn::LearnError),
    #[error(transparent)]
    Report(#[from] report::ReportError),
    /// A file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// A run configuration field is missing or wrong.
    #[error("{}: {field}: {message}", path.display())]
    Config {
        path: PathBuf,
        field: String,
        message: String,
    },
    /// A flight that cannot be evaluated (e.g. too short to split), named by its file.
    #[error("{}: {message}", path.display())]
    Flight { path: PathBuf, message: String },
    /// Two parts of a run disagree (e.g. a model and the cell it is evaluated on).
    #[error("{what}: {message}")]
    Mismatch { what: String, message: String },
    /// A protocol that finds no meta-training flight for an evaluation condition.
    #[error(
        "protocol '{protocol}': no meta-training flight for evaluation condition '{condition}' ({detail})"
    )]
    NoTrainingFlights {
        protocol: String,
        condition: String,
        detail: String,
    },
    /// A condition asked for as a table row (evaluated, the held-out fold) that is only used to
    /// meta-train.
    #[error(
        "condition '{condition}' is not an evaluation condition (its role is {role}); the evaluation conditions are: {evaluation}"
    )]
    NotEvaluationCondition {
        condition: String,
        role: String,
        evaluation: String,
    },
    #[error("unknown protocol '{name}' (known: paper, leave-condition-out, auto)")]
    UnknownProtocol { name: String },
}

impl EvaluationError {
    /// A JSON document at `path` that did not deserialise, with the failing field.
    pub(crate) fn json(path: &std::path::Path, error: bounded_read::json::JsonError) -> Self {
        Self::Config {
            path: path.to_path_buf(),
            field: error.field,
            message: error.message,
        }
    }
}

/// `error` about the flight at `path`, naming the file unless the message already does.
pub(crate) fn in_flight(
    path: &std::path::Path,
    error: impl Into<EvaluationError>,
) -> EvaluationError {
    let error = error.into();
    let message = error.to_string();
    let shown = path.display().to_string();
    if shown.is_empty() || message.contains(&shown) {
        error
    } else {
        EvaluationError::Flight {
            path: path.to_path_buf(),
            message,
        }
    }
}

/// The crate's result type.
pub type Result<T> = std::result::Result<T, EvaluationError>;

/// Writes `text` to `path`, creating the parent folders (never a staging folder an interrupt
/// removed: [`output_set::create_parent_folders`]).
pub(crate) fn write_text(path: &std::path::Path, text: &str) -> Result<()> {
    output_set::create_parent_folders(path).map_err(|source| EvaluationError::Io {
        path: path.parent().unwrap_or(path).to_path_buf(),
        source,
    })?;
    std::fs::write(path, text).map_err(|source| EvaluationError::Io {
        path: path.to_path_buf(),
        source,
    })
}
