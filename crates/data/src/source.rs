//! Where flight data comes from, and fingerprints of the files used.

use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

use crate::error::{DataError, Result};

/// The environment variable naming the data directory.
pub const DATA_DIR_VARIABLE: &str = "NEURAL_FLY_DIR";

/// The default data directory, relative to the project root (filled by `make data`).
pub const DEFAULT_DATA_DIR: &str = "data/neural-fly";

/// Finds the data directory: `flag` if given, else `$NEURAL_FLY_DIR`, else `data/neural-fly` in the
/// current directory or the nearest ancestor that has one. A given flag or variable that does not
/// name a directory is an error naming it (it is never silently skipped); finding none is an error.
pub fn resolve_data_dir(flag: Option<&Path>) -> Result<PathBuf> {
    if let Some(dir) = find_data_dir(flag)? {
        return Ok(dir);
    }
    let cwd = current_dir()?;
    Err(DataError::NoDataDir {
        tried: format!(
            "${DATA_DIR_VARIABLE} (unset), {DEFAULT_DATA_DIR} in {} and its parents",
            cwd.display()
        ),
    })
}

/// As [`resolve_data_dir`], for commands that can do without flight data: `None` when no
/// directory was given (no `flag`, `$NEURAL_FLY_DIR` unset) and the default one is absent. A
/// given flag or variable that does not name a directory is still an error naming it.
pub fn find_data_dir(flag: Option<&Path>) -> Result<Option<PathBuf>> {
    if let Some(dir) = flag {
        return existing_dir(dir, "--data").map(Some);
    }
    if let Some(dir) = std::env::var_os(DATA_DIR_VARIABLE).filter(|v| !v.is_empty()) {
        return existing_dir(Path::new(&dir), DATA_DIR_VARIABLE).map(Some);
    }
    Ok(current_dir()?
        .ancestors()
        .map(|ancestor| ancestor.join(DEFAULT_DATA_DIR))
        .find(|candidate| candidate.is_dir()))
}

fn current_dir() -> Result<PathBuf> {
    std::env::current_dir().map_err(|source| DataError::Io {
        path: PathBuf::from("."),
        source,
    })
}

fn existing_dir(dir: &Path, origin: &str) -> Result<PathBuf> {
    if dir.is_dir() {
        return Ok(dir.to_path_buf());
    }
    let problem = if dir.exists() {
        "is not a directory"
    } else {
        "no such directory"
    };
    Err(DataError::NotADataDir {
        path: dir.to_path_buf(),
        origin: origin.to_string(),
        problem,
    })
}

/// For tests of this workspace's crates: the real flight data, if present (`$NEURAL_FLY_DIR`, else
/// `data/neural-fly` under `workspace_root`), or `None` with a "skipping" message. Under CI
/// (`CI=true`) missing data is an error, so a test that needs the real flights cannot silently skip.
///
/// # Panics
/// When `CI=true` and no data directory with an `experiment/` folder is found.
pub fn real_data_dir_for_tests(workspace_root: &Path) -> Option<PathBuf> {
    let candidate = std::env::var_os(DATA_DIR_VARIABLE)
        .map(PathBuf::from)
        .unwrap_or_else(|| workspace_root.join(DEFAULT_DATA_DIR));
    if candidate.join("experiment").is_dir() {
        return Some(candidate);
    }
    if std::env::var("CI").is_ok_and(|v| v == "true") {
        panic!(
            "CI=true but no flight data at {} (run `make data`)",
            candidate.display()
        );
    }
    eprintln!(
        "skipping: no flight data at {} (run `make data`)",
        candidate.display()
    );
    None
}

/// The public ULog `file` of `data/ulog` under `workspace_root` (a link `make data` makes), for
/// tests: [`shared_file_for_tests`] of folder `ulog`.
///
/// # Panics
/// When `CI=true` and the file is absent.
pub fn ulog_file_for_tests(workspace_root: &Path, file: &str) -> Option<PathBuf> {
    shared_file_for_tests(workspace_root, "ulog", file)
}

/// A public recording `file` of `data/FOLDER` under `workspace_root` (a link to
/// `../shared/data/FOLDER` that `make data` makes), for tests, as [`real_data_dir_for_tests`] finds
/// the flights: `None` with a note where it is absent, except under CI (`CI=true`), where a test
/// that needs it cannot silently skip.
///
/// # Panics
/// When `CI=true` and the file is absent.
pub fn shared_file_for_tests(workspace_root: &Path, folder: &str, file: &str) -> Option<PathBuf> {
    let path = workspace_root.join("data").join(folder).join(file);
    if path.is_file() {
        return Some(path);
    }
    if std::env::var("CI").is_ok_and(|v| v == "true") {
        panic!(
            "CI=true but no recording at {} (run `make data`)",
            path.display()
        );
    }
    eprintln!(
        "skipping: no recording at {} (run `make data`)",
        path.display()
    );
    None
}

/// SHA-256 of a file, hex encoded.
pub fn file_sha256(path: &Path) -> Result<String> {
    let bytes = std::fs::read(path).map_err(|source| DataError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(bytes_sha256(&bytes))
}

/// SHA-256 of `bytes`, hex encoded (as [`file_sha256`] gives it for a file's bytes).
pub fn bytes_sha256(bytes: &[u8]) -> String {
    let digest = Sha256::digest(bytes);
    digest.iter().map(|b| format!("{b:02x}")).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flag_that_is_not_a_directory_is_an_error() {
        let message = resolve_data_dir(Some(Path::new("/no/such/dir")))
            .unwrap_err()
            .to_string();
        assert_eq!(
            message,
            "/no/such/dir: no such directory (the data directory given by --data)"
        );
    }

    #[test]
    fn a_flag_naming_a_file_is_an_error_naming_it() {
        let file = tempfile::Builder::new()
            .prefix("not-a-data-dir-")
            .tempfile()
            .unwrap();
        let path = file.path();
        std::fs::write(path, b"x").unwrap();
        for result in [
            resolve_data_dir(Some(path)).map(Some),
            find_data_dir(Some(path)),
        ] {
            let message = result.unwrap_err().to_string();
            assert_eq!(
                message,
                format!(
                    "{}: is not a directory (the data directory given by --data)",
                    path.display()
                )
            );
        }
    }

    #[test]
    fn hashes_are_sha256() {
        let file = tempfile::Builder::new().prefix("hash-").tempfile().unwrap();
        std::fs::write(file.path(), b"abc").unwrap();
        assert_eq!(
            file_sha256(file.path()).unwrap(),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
    }
}
