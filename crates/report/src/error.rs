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

/// Writes `text` to `path`, creating the parent directory.
pub(crate) fn write_text(path: &std::path::Path, text: &str) -> Result<()> {
    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent).map_err(|source| ReportError::Io {
            path: parent.to_path_buf(),
            source,
        })?;
    }
    std::fs::write(path, text).map_err(|source| ReportError::Io {
        path: path.to_path_buf(),
        source,
    })
}
