//! `learn … | head`: when the reader of standard output goes away, the command ends quietly (as
//! Unix tools do, by SIGPIPE) instead of panicking on the failed write; when standard output
//! cannot be written at all, that is a one-line error.

#![cfg(unix)]

mod common;

use std::os::unix::process::ExitStatusExt;
use std::process::{Command, Stdio};

use common::scratch;

#[test]
fn a_closed_output_ends_the_command_without_a_panic() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    // An empty data directory: every flight is listed as missing.
    let data = scratch("closed-output");
    let mut child = Command::new(env!("CARGO_BIN_EXE_learn"))
        .args(["conditions", "--data", data.to_str().unwrap()])
        .current_dir(root)
        .env("RUST_BACKTRACE", "0")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the learn binary runs");
    // Close the read end before the command writes its first line.
    drop(child.stdout.take());
    let output = child.wait_with_output().expect("the command ends");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!stderr.contains("panicked"), "{stderr}");
    // Killed by SIGPIPE, or (if it wrote before the pipe closed) a normal success.
    assert!(
        output.status.signal() == Some(libc::SIGPIPE) || output.status.success(),
        "{:?}: {stderr}",
        output.status
    );
}

/// A full standard output changes nothing: what the command does (and its exit code) does not
/// depend on whether its words can be printed (issue 18).
#[test]
fn an_unwritable_standard_output_changes_nothing() {
    let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") else {
        return; // no /dev/full on this system
    };
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let data = scratch("unwritable-output");
    let output = Command::new(env!("CARGO_BIN_EXE_learn"))
        .args(["conditions", "--data", data.to_str().unwrap()])
        .current_dir(root)
        .env("RUST_BACKTRACE", "0")
        .stdout(full)
        .output()
        .expect("the learn binary runs");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(0), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}
