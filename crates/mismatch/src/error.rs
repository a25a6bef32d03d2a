//! The one error type of the mismatch crate.

use std::path::PathBuf;

/// Everything that can go wrong while analysing a recording; each renders as one line.
#[derive(Debug, thiserror::Error)]
pub enum MismatchError {
    #[error(transparent)]
    Data(#[from] data::DataError),
    #[error(transparent)]
    Physics(#[from] physics::PhysicsError),
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: {message}", path.display())]
    Recording { path: PathBuf, message: String },
    /// More rows than one analysis accepts ([`crate::recording::degenerate::MAX_ANALYSED_ROWS`]).
    #[error(
        "{}: {rows} rows, more than the {} one analysis accepts ({}); analyse it in parts (mismatch::analyze_in_parts, as learn mismatch --recording does)",
        path.display(),
        crate::recording::degenerate::MAX_ANALYSED_ROWS,
        crate::recording::degenerate::COST_MEASURED
    )]
    TooLong { path: PathBuf, rows: usize },
    /// A recording that cannot be compared with a model ([`crate::recording::degenerate`]).
    #[error("{}: {degeneracy}", path.display())]
    Degenerate {
        path: PathBuf,
        degeneracy: crate::recording::degenerate::Degeneracy,
    },
    #[error(
        "{}: the analysis of this recording gives a non-finite {what}: its values are outside the range the analysis can handle",
        path.display()
    )]
    NonFinite { path: PathBuf, what: String },
    #[error("{}: cannot draw the figure: {message}", path.display())]
    Plot { path: PathBuf, message: String },
    #[error(
        "{}: none of the {count} flights listed in {} is there{}: is it the Neural-Fly data directory?",
        data_dir.display(),
        conditions.display(),
        example.as_ref().map(|p| format!(" (e.g. {})", p.display())).unwrap_or_default()
    )]
    NoFlights {
        data_dir: PathBuf,
        conditions: PathBuf,
        count: usize,
        example: Option<PathBuf>,
    },
    #[error(
        "{}: the {controller} flight of condition '{condition}' is missing: {} ({missing} of the {declared} flights it declares are missing; a condition that lists \"files\" declares only those)",
        conditions.display(),
        path.display()
    )]
    MissingFlight {
        conditions: PathBuf,
        condition: String,
        controller: String,
        path: PathBuf,
        missing: usize,
        declared: usize,
    },
    #[error("{}: field '{field}': {message}", path.display())]
    Config {
        path: PathBuf,
        field: String,
        message: String,
    },
    /// A setting of the analyses out of its range ([`crate::Settings::checked`]).
    #[error("setting '{setting}': {message}")]
    Setting {
        setting: &'static str,
        message: String,
    },
    /// A Levenberg–Marquardt setting out of its range ([`crate::model::least_squares`]).
    #[error("Levenberg–Marquardt setting '{setting}': {message}")]
    SolverSetting {
        setting: &'static str,
        message: String,
    },
    /// An output the `report` crate could not render (a figure that cannot be drawn is [`Plot`]).
    ///
    /// [`Plot`]: MismatchError::Plot
    #[error(transparent)]
    Report(report::ReportError),
}

impl From<report::ReportError> for MismatchError {
    fn from(error: report::ReportError) -> Self {
        match error {
            report::ReportError::Plot { path, message } => Self::Plot { path, message },
            other => Self::Report(other),
        }
    }
}

/// Shorthand for results of this crate.
pub type Result<T, E = MismatchError> = std::result::Result<T, E>;

pub(crate) fn io_error(
    path: &std::path::Path,
) -> impl FnOnce(std::io::Error) -> MismatchError + '_ {
    move |source| MismatchError::Io {
        path: path.to_path_buf(),
        source,
    }
}
