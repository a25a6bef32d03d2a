//! The one error type of the learn crate.

use std::path::PathBuf;

/// Everything that can go wrong while configuring, training, adapting or explaining LeARN.
/// Each variant renders as one line naming the file, field or condition involved.
#[derive(Debug, thiserror::Error)]
pub enum LearnError {
    /// A derivative estimator misconfigured or given too few samples.
    #[error(transparent)]
    Differentiation(#[from] sindy::DifferentiationError),
    /// The I/O error is part of the message, not a separate cause, so it is printed once.
    #[error("{}: {cause}", path.display())]
    Io {
        path: PathBuf,
        cause: std::io::Error,
    },
    #[error("{}: field '{field}': {message}", path.display())]
    Config {
        path: PathBuf,
        field: String,
        message: String,
    },
    #[error("{}: not a LeARN checkpoint: {message}", path.display())]
    Checkpoint { path: PathBuf, message: String },
    #[error("unknown formulation '{name}' (known: translational, attitude, full)")]
    UnknownFormulation { name: String },
    #[error("{what}: {message}")]
    Mismatch { what: String, message: String },
    #[error(
        "meta-training diverged at iteration {iteration} (loss {loss}); lower the outer or inner step in the configuration"
    )]
    Diverged { iteration: usize, loss: f64 },
    /// Training or adaptation of one cell (formulation and condition, or model and flight) gave a
    /// non-finite number: reported instead of printing NaN.
    #[error("{cell}: {message}")]
    NotFinite { cell: String, message: String },
    /// A task or recording that cannot serve LeARN (e.g. too few rows), named by its file.
    #[error("{}: {message}", path.display())]
    Task { path: PathBuf, message: String },
}

/// Result with a [`LearnError`].
pub type Result<T> = std::result::Result<T, LearnError>;
