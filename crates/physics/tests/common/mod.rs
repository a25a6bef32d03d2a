//! Helpers shared by the behaviour tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

/// The workspace root.
pub fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The real data directory, if present: `$NEURAL_FLY_DIR` or `data/neural-fly` of the workspace.
/// Under CI (`CI=true`) a missing directory fails the test instead of skipping it.
pub fn real_data_dir() -> Option<PathBuf> {
    let candidate = std::env::var_os("NEURAL_FLY_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| workspace().join("data/neural-fly"));
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

/// A fresh temporary directory for one test.
pub fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("physics-tests-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}
