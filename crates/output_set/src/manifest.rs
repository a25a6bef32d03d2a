//! The ownership record of an output folder (`.learn-outputs.json`): every file a `learn` command
//! wrote there, relative to the folder, with the producer that wrote it. Sorted, no time stamps:
//! a rerun writes it byte for byte the same (it is committed with `results/`).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::{OutputError, Result, io};

/// The manifest's file name in an output folder.
pub const MANIFEST: &str = ".learn-outputs.json";
/// The format tag of a manifest.
const FORMAT: &str = "learn-outputs/1";

/// Files of one folder written by `learn`: relative path (`/`-separated) → producer.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Manifest {
    format: String,
    pub files: BTreeMap<String, String>,
}

impl Manifest {
    /// The manifest of `dir`; empty when the folder has none.
    pub fn read(dir: &Path) -> Result<Self> {
        let path = dir.join(MANIFEST);
        let text = match std::fs::read_to_string(&path) {
            Ok(text) => text,
            Err(error) if error.kind() == std::io::ErrorKind::NotFound => {
                return Ok(Self::default());
            }
            Err(error) => return Err(io(&path)(error)),
        };
        let manifest: Self =
            serde_json::from_str(&text).map_err(|error| OutputError::Manifest {
                path: path.clone(),
                message: format!("not a learn output manifest ({error}); move it away"),
            })?;
        if manifest.format != FORMAT {
            return Err(OutputError::Manifest {
                path,
                message: format!("format {:?}, expected {FORMAT:?}", manifest.format),
            });
        }
        // Only plain relative names below the folder: a stale entry is removed, so `..` or an
        // absolute name would reach outside it.
        if let Some(bad) = manifest.files.keys().find(|key| !plain_key(key)) {
            return Err(OutputError::Manifest {
                path,
                message: format!("entry {bad:?} is not a plain relative path below the folder"),
            });
        }
        Ok(manifest)
    }

    /// The producer that wrote `relative`, if `learn` wrote it.
    pub fn producer(&self, relative: &str) -> Option<&str> {
        self.files.get(relative).map(String::as_str)
    }

    /// The files `producer` wrote that are not among `kept` (its earlier outputs it no longer
    /// writes: removed when its new set is committed).
    pub fn stale(&self, producer: &str, kept: &[String]) -> Vec<String> {
        self.files
            .iter()
            .filter(|(file, by)| by.as_str() == producer && !kept.contains(file))
            .map(|(file, _)| file.clone())
            .collect()
    }

    /// This manifest with `producer`'s entries replaced by `written` (`replace`), or with
    /// `written` added to them.
    pub fn updated(&self, producer: &str, written: &[String], replace: bool) -> Self {
        let mut files: BTreeMap<String, String> = self
            .files
            .iter()
            .filter(|(_, by)| !replace || by.as_str() != producer)
            .map(|(f, by)| (f.clone(), by.clone()))
            .collect();
        for file in written {
            files.insert(file.clone(), producer.to_string());
        }
        Self {
            format: FORMAT.to_string(),
            files,
        }
    }

    /// Writes the manifest into `dir` atomically (a temporary file renamed over it).
    pub fn write(&self, dir: &Path) -> Result<()> {
        let text = serde_json::to_string_pretty(self).map_err(|error| OutputError::Manifest {
            path: dir.join(MANIFEST),
            message: error.to_string(),
        })? + "\n";
        write_atomically(&dir.join(MANIFEST), &text)
    }
}

/// Writes `text` to `path` through a temporary file in the same directory renamed over it: a new
/// file follows the umask, a replaced one keeps its mode.
pub(crate) fn write_atomically(path: &Path, text: &str) -> Result<()> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut temp = tempfile::Builder::new()
        .prefix(&crate::stage::staging_prefix())
        .permissions(crate::stage::new_file_mode())
        .tempfile_in(dir)
        .map_err(io(path))?;
    std::io::Write::write_all(&mut temp, text.as_bytes()).map_err(io(path))?;
    temp.as_file().sync_all().map_err(io(path))?;
    if let Ok(existing) = std::fs::symlink_metadata(path)
        && existing.is_file()
    {
        crate::journal::keep_mode_and_owner(temp.path(), &existing)?;
    }
    temp.persist(path).map_err(|error| io(path)(error.error))?;
    Ok(())
}

/// `relative` as a manifest key: its components joined by `/`.
pub(crate) fn key(relative: &Path) -> String {
    relative
        .components()
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect::<Vec<_>>()
        .join("/")
}

/// Whether `key` is `a/b/c` with no empty, `.` or `..` part.
fn plain_key(key: &str) -> bool {
    !key.is_empty()
        && key
            .split('/')
            .all(|part| !part.is_empty() && part != "." && part != ".." && !part.contains('\\'))
}

/// The path of a manifest key below `dir`.
pub(crate) fn path_of(dir: &Path, key: &str) -> PathBuf {
    key.split('/')
        .fold(dir.to_path_buf(), |path, part| path.join(part))
}
