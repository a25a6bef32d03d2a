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
    /// A fault of the CSV layout (a comment line, a blank line, an unpaired quote, a row of the
    /// wrong width...) on line `row`.
    #[error("{}:{row}: {fault}", path.display())]
    Layout {
        path: PathBuf,
        row: usize,
        fault: crate::records::LayoutFault,
    },
    #[error("{}: missing column '{column}' (columns present: {present})", path.display())]
    MissingColumn {
        path: PathBuf,
        column: String,
        present: String,
    },
    #[error("{}:{row}:{column}: cannot parse {value}: {reason}", path.display())]
    BadCell {
        path: PathBuf,
        row: usize,
        column: String,
        /// The cell as a message shows it: quoted, at most [`bounded_read::EXCERPT_CHARACTERS`]
        /// characters ([`bounded_read::Excerpt`]).
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
    #[error(
        "{}:{row}:{column}: time is not strictly increasing ({} then {})",
        path.display(), Compact(*previous), Compact(*current)
    )]
    TimeNotIncreasing {
        path: PathBuf,
        row: usize,
        /// The name of the time column.
        column: String,
        previous: f64,
        current: f64,
    },
    #[error(
        "{}:{row}:{column}: sample interval is not uniform: worst gap {} s against a median of {} s",
        path.display(), Compact(*gap), Compact(*median)
    )]
    NonUniformSampling {
        path: PathBuf,
        row: usize,
        /// The name of the time column.
        column: String,
        gap: f64,
        median: f64,
    },
    #[error(
        "{}:{row}:{column}: sample interval {} s is outside the plausible range [{}, {}] s of a flight log (is the time in seconds?)",
        path.display(), Compact(*interval), Compact(*min), Compact(*max)
    )]
    ImplausibleInterval {
        path: PathBuf,
        row: usize,
        column: String,
        interval: f64,
        min: f64,
        max: f64,
    },
    #[error(
        "{}:{row}:{column}: {} is outside the plausible range [{}, {}]{unit} of {quantity}",
        path.display(), Compact(*value), Compact(*min), Compact(*max)
    )]
    Implausible {
        path: PathBuf,
        row: usize,
        column: String,
        value: f64,
        min: f64,
        max: f64,
        /// Empty, or the unit with a leading space.
        unit: &'static str,
        quantity: &'static str,
    },
    #[error("{}: {rows} data rows, at least {needed} are needed", path.display())]
    TooShort {
        path: PathBuf,
        rows: usize,
        needed: usize,
    },
    #[error("{}: rows {}:{} reach past its {count} data rows", path.display(), rows.start, rows.end)]
    RowsPastEnd {
        path: PathBuf,
        rows: std::ops::Range<usize>,
        count: usize,
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
    /// A data directory given by `--data` or `$NEURAL_FLY_DIR` (`origin`) that is not one.
    #[error("{}: {problem} (the data directory given by {origin})", path.display())]
    NotADataDir {
        path: PathBuf,
        origin: String,
        problem: &'static str,
    },
    #[error("{what}: {message}")]
    Invalid { what: String, message: String },
    /// A task that does not fit with the others (e.g. sampled at another interval), named by
    /// its file.
    #[error("{}: {message}", path.display())]
    Task { path: PathBuf, message: String },
}

/// A number as it reads best in a one-line message: plainly for ordinary magnitudes (so `0.02`
/// stays `0.02`), in scientific notation for tiny or huge ones (`1e-302`, not 300 zeros).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Compact(pub f64);

impl std::fmt::Display for Compact {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let magnitude = self.0.abs();
        if self.0 == 0.0 || !self.0.is_finite() || (1e-4..1e15).contains(&magnitude) {
            write!(f, "{}", self.0)
        } else {
            write!(f, "{:e}", self.0)
        }
    }
}

/// Shorthand for results of this crate.
pub type Result<T, E = DataError> = std::result::Result<T, E>;
