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
    #[error(
        "{}: the simulated flight is not a usable log ({cause}); nothing written to {}",
        scenario.display(),
        out.display()
    )]
    UnusableLog {
        scenario: PathBuf,
        out: PathBuf,
        cause: String,
    },
    /// A vehicle description built in code (not read from a file) that breaks a rule.
    #[error("vehicle description: {field}: {message}")]
    Description { field: String, message: String },
    /// A PX4 parameter that is missing or out of its range.
    #[error("PX4 parameter {name}: {message}")]
    Parameter { name: String, message: String },
    #[error("simulation: {0}")]
    Simulation(String),
    #[error(transparent)]
    Data(#[from] data::DataError),
}

/// Shorthand for results of this crate.
pub type Result<T, E = PhysicsError> = std::result::Result<T, E>;

/// A number as an error message shows it: plain when it reads well (`3600`, `0.25`), otherwise in
/// scientific notation (`1e308`, `1e-300`), never as hundreds of digits.
pub(crate) fn readable(value: f64) -> String {
    let magnitude = value.abs();
    if !value.is_finite() || value == 0.0 || (1e-4..1e9).contains(&magnitude) {
        format!("{value}")
    } else {
        format!("{value:e}")
    }
}

#[cfg(test)]
mod tests {
    use super::readable;

    #[test]
    fn large_and_tiny_numbers_read_in_scientific_notation() {
        assert_eq!(readable(1e308), "1e308");
        assert_eq!(readable(-1e300), "-1e300");
        assert_eq!(readable(1e-300), "1e-300");
        assert_eq!(readable(3600.0), "3600");
        assert_eq!(readable(0.25), "0.25");
        assert_eq!(readable(0.0), "0");
        assert_eq!(readable(f64::NAN), "NaN");
        assert_eq!(readable(f64::INFINITY), "inf");
    }
}
