//! Shared support for the `learn` command's behaviour tests: run the built binary, check that a
//! failure is the one-line error the README promises, and make scratch directories.

#![allow(dead_code)]

pub mod sweep;

use std::path::{Path, PathBuf};
use std::process::Command;

/// The workspace root.
pub fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// What one run of `learn` gave.
pub struct Run {
    pub code: Option<i32>,
    pub stdout: String,
    pub stderr: String,
}

/// Runs `learn` with `args` in `dir` (quiet, no backtraces, no data directory from the environment).
pub fn learn_in(dir: &Path, args: &[&str]) -> Run {
    let output = Command::new(env!("CARGO_BIN_EXE_learn"))
        .args(args)
        .current_dir(dir)
        .env_remove("NEURAL_FLY_DIR")
        .env("RUST_BACKTRACE", "0")
        .output()
        .expect("the learn binary runs");
    Run {
        code: output.status.code(),
        stdout: String::from_utf8_lossy(&output.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&output.stderr).into_owned(),
    }
}

impl Run {
    /// Asserts a failure with exit code 1 and a one-line `error: …` message containing every one
    /// of `needles` (a file, row or field name), and no panic; returns the message.
    pub fn one_line_error(&self, needles: &[&str]) -> &str {
        self.one_line_failure(1, needles)
    }

    /// As [`Run::one_line_error`], for arguments refused while parsing (exit code 2).
    pub fn one_line_usage_error(&self, needles: &[&str]) -> &str {
        self.one_line_failure(2, needles)
    }

    fn one_line_failure(&self, code: i32, needles: &[&str]) -> &str {
        assert_eq!(self.code, Some(code), "exit code; stderr: {}", self.stderr);
        let message = self.stderr.trim_end();
        assert!(!message.contains("panicked"), "panic: {message}");
        assert_eq!(message.lines().count(), 1, "not one line: {message}");
        assert!(message.starts_with("error: "), "{message}");
        for needle in needles {
            assert!(
                message.contains(needle),
                "{needle:?} missing from {message}"
            );
        }
        message
    }

    /// Asserts success and returns standard output.
    pub fn success(&self) -> &str {
        assert_eq!(self.code, Some(0), "stderr: {}", self.stderr);
        &self.stdout
    }
}

/// A fresh, empty scratch directory for one test (named after it), removed with everything in it
/// when dropped: keep it alive for as long as the test uses the path.
pub fn scratch(test: &str) -> Scratch {
    Scratch(
        tempfile::Builder::new()
            .prefix(&format!("learn-cli-{test}-"))
            .tempdir()
            .expect("scratch directory"),
    )
}

/// A temporary directory, used as its path.
pub struct Scratch(tempfile::TempDir);

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        self.0.path()
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        self.0.path()
    }
}

/// `t,x,y,u` for t = 0, 0.01, ...: a damped rotation driven by u.
pub fn signal(rows: usize) -> String {
    let mut text = String::from("t,x,y,u\n");
    for k in 0..rows {
        let t = k as f64 * 0.01;
        let decay = (-0.1 * t).exp();
        text.push_str(&format!(
            "{t:.2},{},{},{}\n",
            decay * t.cos(),
            -decay * t.sin(),
            (0.5 * t).sin()
        ));
    }
    text
}
