//! Helpers shared by the behaviour tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

/// The workspace root.
pub fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The real data directory (see `data::real_data_dir_for_tests`: skips locally, fails under CI).
pub fn real_data_dir() -> Option<PathBuf> {
    data::real_data_dir_for_tests(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../.."))
}

/// A fresh temporary directory for one test.
pub fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("physics-tests-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}
