//! The one error type of the data crate.

use std::path::PathBuf;

/// Everything that can go wrong while finding, reading or validating data.
///
/// Each variant renders as a single line that names the file and, where it applies, the row (the
/// line number in the file, the header being line 1) and the column: `file:row:column: message`.
#[derive(Debug, thiserror::Error)]
pub enum DataError {
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: cannot parse as CSV: {message}", path.display())]
    Csv { path: PathBuf, message: String },
    #[error("{}: the file is empty (no data rows)", path.display())]
    Empty { path: PathBuf },
    #[error("{}: is a directory, not a CSV file", path.display())]
    IsDirectory { path: PathBuf },
    #[error("{}:{row}: not a CSV text file: {reason}", path.display())]
    NotText {
        path: PathBuf,
        row: usize,
        reason: String,
    },
    #[error(
        "{}:{row}:{column}: column '{column}' appears twice in the header (fields {first} and {second})",
        path.display()
    )]
    DuplicateColumn {
        path: PathBuf,
        row: usize,
        column: String,
        first: usize,
        second: usize,
    },
    #[error("{}:{row}: {message}", path.display())]
    BadRow {
        path: PathBuf,
        row: usize,
        message: String,
    },
    #[error("{}: missing column '{column}' (columns present: {present})", path.display())]
    MissingColumn {
        path: PathBuf,
        column: String,
        present: String,
    },
    #[error("{}:{row}:{column}: cannot parse {value:?}: {reason}", path.display())]
    BadCell {
        path: PathBuf,
        row: usize,
        column: String,
        value: String,
        reason: String,
    },
    #[error("{}:{row}:{column}: expected {expected} values, found {found}", path.display())]
    WrongLength {
        path: PathBuf,
        row: usize,
        column: String,
        expected: usize,
        found: usize,
    },
    #[error("{}:{row}:{column}: value is not finite ({value})", path.display())]
    NonFinite {
        path: PathBuf,
        row: usize,
        column: String,
        value: String,
    },
    #[error("{}:{row}:t: time is not strictly increasing ({previous} then {current})", path.display())]
    TimeNotIncreasing {
        path: PathBuf,
        row: usize,
        previous: f64,
        current: f64,
    },
    #[error(
        "{}:{row}:t: sample interval is not uniform: worst gap {gap} s against a median of {median} s",
        path.display()
    )]
    NonUniformSampling {
        path: PathBuf,
        row: usize,
        gap: f64,
        median: f64,
    },
    #[error("{}: {rows} data rows, at least {needed} are needed", path.display())]
    TooShort {
        path: PathBuf,
        rows: usize,
        needed: usize,
    },
    #[error("{}: {field}: {message}", path.display())]
    Config {
        path: PathBuf,
        field: String,
        message: String,
    },
    #[error("unknown {kind} '{name}' (known: {known})")]
    UnknownName {
        kind: &'static str,
        name: String,
        known: String,
    },
    #[error(
        "no flight data directory found (looked at: {tried}); run `make data`, pass --data DIR or set NEURAL_FLY_DIR"
    )]
    NoDataDir { tried: String },
    #[error("{what}: {message}")]
    Invalid { what: String, message: String },
}

/// Shorthand for results of this crate.
pub type Result<T, E = DataError> = std::result::Result<T, E>;
