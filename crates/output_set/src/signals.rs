//! Interrupts: on SIGINT, SIGTERM or SIGHUP the staging files and folders of the process are
//! removed and it exits (128 + the signal), so an interrupted run leaves the old outputs as they
//! were and nothing that looks like a result. A commit in progress is finished first: it holds the
//! same lock as the handler.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, MutexGuard, Once};

/// Staging paths of this process that an interrupt removes.
static STAGING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());
static INSTALL: Once = Once::new();
/// Set by the signal thread when an interrupt arrives, before it removes the staging.
static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Whether an interrupt arrived: the signal thread is removing the staging and then ends the
/// process with 128 + the signal.
pub fn interrupted() -> bool {
    INTERRUPTED.load(Ordering::SeqCst)
}

/// After an interrupt, waits for the signal thread to end the process (so never returns then):
/// an error that the removal of the staging caused (a writer finding its folder gone) must not
/// end the process first, with its own message and exit code, cutting the removal short.
pub fn wait_if_interrupted() {
    while interrupted() {
        std::thread::park();
    }
}

/// The staging registry, held for the length of a commit (the handler waits for it).
pub(crate) fn hold() -> MutexGuard<'static, Vec<PathBuf>> {
    STAGING
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// The registry, held, with the handler installed: an interrupt waits until it is released.
pub(crate) fn hold_installed() -> MutexGuard<'static, Vec<PathBuf>> {
    install();
    hold()
}

/// The registry unless this thread holds it already (a drop inside a commit).
pub(crate) fn try_hold() -> Result<MutexGuard<'static, Vec<PathBuf>>, ()> {
    match STAGING.try_lock() {
        Ok(guard) => Ok(guard),
        Err(std::sync::TryLockError::Poisoned(poisoned)) => Ok(poisoned.into_inner()),
        Err(std::sync::TryLockError::WouldBlock) => Err(()),
    }
}

/// Creates a staging file or folder with `create` and records its path (`path_of`), the handler
/// installed first and the registry held throughout: an interrupt at any moment either comes
/// before it exists (the default action is no longer in force) or removes it, never leaves it.
pub(crate) fn create_registered<T, E>(
    create: impl FnOnce() -> Result<T, E>,
    path_of: impl FnOnce(&T) -> PathBuf,
) -> Result<T, E> {
    install();
    let mut registry = hold();
    let created = create()?;
    registry.push(path_of(&created));
    Ok(created)
}

/// Forgets a staging path (committed or removed by its owner).
pub(crate) fn unregister(staging: &mut Vec<PathBuf>, path: &std::path::Path) {
    staging.retain(|p| p != path);
}

/// Starts the thread that waits for the signals. Without it (the handler cannot be installed)
/// the signals keep their default action; SIGKILL always does, and then the staging names stay
/// until the next run into the folder removes them.
fn install() {
    INSTALL.call_once(|| {
        use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
        let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP]) else {
            return;
        };
        let _ = std::thread::Builder::new()
            .name("learn-signals".to_string())
            .spawn(move || {
                if let Some(signal) = signals.forever().next() {
                    INTERRUPTED.store(true, Ordering::SeqCst);
                    let staging = hold();
                    remove_until_gone(&staging);
                    std::process::exit(128 + signal);
                }
            });
    });
}

/// Removes every path, and again while a thread still at work (a writer making its file's folder)
/// brings one back, until none has come back over [`QUIET_CHECKS`] checks 2 ms apart (at most
/// about 200 ms). A writer descheduled past the last check can still bring one back before the
/// process ends (a busy machine showed it with one quiet check); the next run into the folder
/// removes it, as it removes what SIGKILL leaves.
fn remove_until_gone(paths: &[PathBuf]) {
    let mut quiet = 0;
    for _ in 0..100 {
        if quiet == 0 {
            for path in paths {
                remove(path);
            }
        }
        std::thread::sleep(std::time::Duration::from_millis(2));
        if paths.iter().all(|path| !path.exists()) {
            quiet += 1;
            if quiet == QUIET_CHECKS {
                return;
            }
        } else {
            quiet = 0;
        }
    }
}

/// How many checks in a row must find every staging path gone before the process ends.
const QUIET_CHECKS: usize = 5;

/// Removes a staging file or folder, whichever it is; errors are ignored (nothing more can be
/// done on the way out).
pub(crate) fn remove(path: &std::path::Path) {
    if path.is_dir() {
        let _ = std::fs::remove_dir_all(path);
    } else {
        let _ = std::fs::remove_file(path);
    }
}
