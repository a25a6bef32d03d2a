//! The one error type of the physics crate.

use std::path::PathBuf;

/// Everything that can go wrong while reading a model or a scenario, or while simulating.
/// Each variant renders as one line naming the file and the field.
#[derive(Debug, thiserror::Error)]
pub enum PhysicsError {
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: not valid JSON: {message}", path.display())]
    Json { path: PathBuf, message: String },
    #[error("{}: field '{field}': {message}", path.display())]
    Field {
        path: PathBuf,
        field: String,
        message: String,
    },
    #[error("simulation: {0}")]
    Simulation(String),
    #[error(transparent)]
    Data(#[from] data::DataError),
}

/// Shorthand for results of this crate.
pub type Result<T, E = PhysicsError> = std::result::Result<T, E>;
