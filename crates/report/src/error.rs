//! The report crate's one error type.

use std::path::PathBuf;

/// Everything that can go wrong while reading, rendering or comparing results.
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// A file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// A JSON file does not have the expected shape.
    #[error("{}: {field}: {message}", path.display())]
    Json {
        path: PathBuf,
        field: String,
        message: String,
    },
    /// Input that is well-formed but inconsistent.
    #[error("{what}: {message}")]
    Invalid { what: String, message: String },
    /// Drawing a figure failed.
    #[error("{}: cannot draw the figure: {message}", path.display())]
    Plot { path: PathBuf, message: String },
}

/// The crate's result type.
pub type Result<T> = std::result::Result<T, ReportError>;

/// Reads a JSON file into `T`, naming the file and the failing field (with its line and column)
/// on error.
pub(crate) fn read_json<T: serde::de::DeserializeOwned + serde::Serialize>(
    path: &std::path::Path,
) -> Result<T> {
    let text = bounded_read::read_json_text(path).map_err(|source| ReportError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    bounded_read::json::from_str(&text).map_err(|error| ReportError::Json {
        path: path.to_path_buf(),
        field: error.field,
        message: error.message,
    })
}

/// Writes `text` to `path`, creating the parent folders (never a staging folder an interrupt
/// removed: [`output_set::create_parent_folders`]).
pub(crate) fn write_text(path: &std::path::Path, text: &str) -> Result<()> {
    output_set::create_parent_folders(path).map_err(|source| ReportError::Io {
        path: path.parent().unwrap_or(path).to_path_buf(),
        source,
    })?;
    std::fs::write(path, text).map_err(|source| ReportError::Io {
        path: path.to_path_buf(),
        source,
    })
}

#[cfg(test)]
mod tests {
    /// A report written into a staging folder that an interrupt removed fails instead of making
    /// the folder again (made again, it outlived the process: a flaky interrupt test showed it).
    #[test]
    fn a_report_does_not_bring_back_a_removed_staging_folder() {
        let dir = tempfile::tempdir().unwrap();
        let staging = dir.path().join(".learn-staging-1-x");
        assert!(super::write_text(&staging.join("tables/t.md"), "x").is_err());
        assert!(!staging.exists());
        super::write_text(&dir.path().join("tables/t.md"), "x").unwrap();
    }
}
