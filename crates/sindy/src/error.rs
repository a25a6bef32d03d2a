//! The crate's one error type. Every message is one line naming what was wrong and where.

use std::path::PathBuf;

/// Errors of the sindy crate.
#[derive(Debug, thiserror::Error)]
pub enum SindyError {
    /// A parameter outside its valid range, e.g. a negative threshold.
    #[error("invalid {name}: {message}")]
    InvalidParameter { name: String, message: String },
    /// A field of a serialisable specification (a regression, a causal library) out of range:
    /// `field` is its path inside that specification, e.g. `penalty.lambdas` of a
    /// [`crate::RegressionSpec`] (empty: the specification as a whole), so that a configuration
    /// file can name it in full.
    #[error("invalid {}: {message}", if field.is_empty() { "specification" } else { field.as_str() })]
    Field { field: String, message: String },
    /// A library or optimizer specification that does not parse.
    #[error("cannot parse {kind} '{text}': {message}")]
    Parse {
        kind: &'static str,
        text: String,
        message: String,
    },
    /// Matrices or name lists whose sizes do not agree.
    #[error("{what}: {message}")]
    Shape { what: String, message: String },
    /// A NaN or infinite value in the data: `row` is the sample's index (from 0) in the matrix
    /// checked, `column` names the column (e.g. `feature 'x^2'`).
    #[error("{what}: {column} is not finite ({value}) at sample index {row}")]
    NonFinite {
        what: String,
        row: usize,
        column: String,
        value: f64,
    },
    /// Library features of sizes too far apart for a least-squares fit in double precision.
    #[error(
        "the library's features differ in size by more than 1e12 (feature '{large_feature}' \
         reaches {large:.2e}, feature '{small_feature}' only {small:.2e}): a fit in double precision \
         cannot resolve them; rescale the data (e.g. to units where values lie between 1e-3 and \
         1e3)"
    )]
    Scale {
        large_feature: String,
        large: f64,
        small_feature: String,
        small: f64,
    },
    /// A solver that did not reach a solution.
    #[error("{solver} failed on target '{target}': {message}")]
    Solver {
        solver: &'static str,
        target: String,
        message: String,
    },
    /// A model that cannot be written, e.g. one with custom (closure) features.
    #[error("cannot save the model: {0}")]
    NotSerialisable(String),
    /// A model file whose content is inconsistent.
    #[error("{path}: field '{field}': {message}")]
    ModelFile {
        path: PathBuf,
        field: String,
        message: String,
    },
    /// Reading or writing a file.
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// A derivative estimator misconfigured or given too few samples.
    #[error(transparent)]
    Differentiation(#[from] crate::differentiation::DifferentiationError),
    /// The caller's source of rows failed (e.g. a streamed file with a bad line), as it said.
    #[error(transparent)]
    Source(Box<dyn std::error::Error + Send + Sync>),
}

impl SindyError {
    /// This error as a [`SindyError::Field`] of a specification nested at `prefix`: a field error's
    /// path gets `prefix.` in front, any other error becomes an error of the field `prefix`.
    /// E.g. a regression's `penalty.lambdas` error is `regression.penalty.lambdas` in a variant.
    pub fn within(self, prefix: &str) -> Self {
        match self {
            Self::Field { field, message } => Self::Field {
                field: if field.is_empty() {
                    prefix.to_string()
                } else if prefix.is_empty() {
                    field
                } else {
                    format!("{prefix}.{field}")
                },
                message,
            },
            other => Self::Field {
                field: prefix.to_string(),
                message: other.to_string(),
            },
        }
    }
}

/// The crate's result type.
pub type Result<T> = std::result::Result<T, SindyError>;

pub(crate) fn invalid(name: &str, message: impl Into<String>) -> SindyError {
    SindyError::InvalidParameter {
        name: name.to_string(),
        message: message.into(),
    }
}

/// A [`SindyError::Field`]: the specification's field `field` (empty: the whole) is wrong.
pub fn field(field: &str, message: impl Into<String>) -> SindyError {
    SindyError::Field {
        field: field.to_string(),
        message: message.into(),
    }
}

/// A [`SindyError::Shape`]: the sizes of `what` do not agree.
pub fn shape(what: &str, message: impl Into<String>) -> SindyError {
    SindyError::Shape {
        what: what.to_string(),
        message: message.into(),
    }
}

impl SindyError {
    /// A non-finite value's row counted from `offset` rows earlier (a block's row in its fit).
    pub(crate) fn offset_row(self, offset: usize) -> Self {
        match self {
            Self::NonFinite {
                what,
                row,
                column,
                value,
            } => Self::NonFinite {
                what,
                row: offset + row,
                column,
                value,
            },
            other => other,
        }
    }
}
