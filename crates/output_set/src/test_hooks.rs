//! Named points of the protocol at which a test build stops the process as a signal arriving
//! there would: `LEARN_TEST_SIGNAL_AT=KILL@<point>` (SIGKILL) or `INT@<point>` (SIGINT),
//! `LEARN_TEST_SIGNAL_AT=list` prints each point passed on standard error. Only with the cargo
//! feature `test-hooks` (enabled by the cli's tests); without it a point compiles to nothing.

use std::path::Path;

/// The environment variable read.
#[cfg(feature = "test-hooks")]
const VARIABLE: &str = "LEARN_TEST_SIGNAL_AT";

/// Stops the process at `point` when the environment asks for it. For an interrupt, the process
/// goes on once the signal thread has removed every path of `staging`, with a file left at each
/// (its writers then fail, as a writer racing the removal does).
#[cfg(feature = "test-hooks")]
pub(crate) fn point(point: std::fmt::Arguments, staging: &[&Path]) {
    let Ok(wanted) = std::env::var(VARIABLE) else {
        return;
    };
    let point = point.to_string();
    if wanted == "list" {
        eprintln!("signal point: {point}");
        return;
    }
    match wanted.split_once('@') {
        Some(("KILL", at)) if at == point => {
            // SAFETY: signals this process; SIGKILL ends it here.
            unsafe { libc::kill(libc::getpid(), libc::SIGKILL) };
            loop {
                std::thread::park();
            }
        }
        Some(("INT", at)) if at == point => {
            // SAFETY: signals this process; the signal thread handles SIGINT.
            unsafe { libc::kill(libc::getpid(), libc::SIGINT) };
            let deadline = std::time::Instant::now() + std::time::Duration::from_secs(5);
            while staging.iter().any(|path| path.exists()) && std::time::Instant::now() < deadline {
                std::thread::sleep(std::time::Duration::from_micros(100));
            }
            // As a writer racing the removal finds it: a file where its staging folder was.
            for path in staging {
                let _ = std::fs::write(path, "");
            }
        }
        _ => {}
    }
}

/// Without the `test-hooks` feature: nothing.
#[cfg(not(feature = "test-hooks"))]
#[inline(always)]
pub(crate) fn point(_point: std::fmt::Arguments, _staging: &[&Path]) {}
