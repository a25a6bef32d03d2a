//! How much memory a command may still allocate, to refuse work whose estimated peak exceeds it
//! before the work starts (an allocation that fails inside faer aborts the process).
//!
//! The bound is the smaller of
//! - the memory the system has available (`MemAvailable` in `/proc/meminfo`), and
//! - the address space left under the process's `RLIMIT_AS` (`ulimit -v`): its soft limit less
//!   what the process has mapped already (`VmSize` in `/proc/self/status`) and less, per worker
//!   thread, its stack and the malloc arena it reserves on first use.
//!
//! Either is left out when it cannot be read (not Linux, no limit); with neither there is no
//! bound.

use std::fmt;

/// Address space a worker thread reserves besides its work: glibc's per-thread arena (64 MiB on
/// 64-bit systems) and a 2 MiB stack.
const THREAD_RESERVE_BYTES: u64 = 66 << 20;

/// Where a [`MemoryBound`] comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BoundSource {
    /// `MemAvailable` of `/proc/meminfo`.
    SystemAvailable,
    /// What is left under `RLIMIT_AS`.
    AddressSpaceLimit,
}

impl fmt::Display for BoundSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::SystemAvailable => "the memory available (MemAvailable)",
            Self::AddressSpaceLimit => "the address space left under ulimit -v",
        })
    }
}

/// Bytes a command may still allocate, and why.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MemoryBound {
    pub bytes: u64,
    pub source: BoundSource,
}

/// The bound for work on `threads` worker threads, if any is known (see the module
/// documentation).
pub fn memory_bound(threads: usize) -> Option<MemoryBound> {
    let available = system_available().map(|bytes| MemoryBound {
        bytes,
        source: BoundSource::SystemAvailable,
    });
    let address_space = address_space_left(threads).map(|bytes| MemoryBound {
        bytes,
        source: BoundSource::AddressSpaceLimit,
    });
    [available, address_space]
        .into_iter()
        .flatten()
        .min_by_key(|bound| bound.bytes)
}

/// A byte count in words: `3.2 GB`, `850 MB`.
pub fn in_words(bytes: u64) -> String {
    let gigabytes = bytes as f64 / 1e9;
    if gigabytes >= 1.0 {
        format!("{gigabytes:.1} GB")
    } else {
        format!("{:.0} MB", bytes as f64 / 1e6)
    }
}

/// `MemAvailable` of `/proc/meminfo`, in bytes.
fn system_available() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    kibibytes_field(&text, "MemAvailable:")
}

/// The soft `RLIMIT_AS` less the process's `VmSize` and the threads' reserve; `None` when
/// unlimited or unknown.
fn address_space_left(threads: usize) -> Option<u64> {
    let limit = address_space_limit()?;
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let mapped = kibibytes_field(&status, "VmSize:")?;
    let reserve = THREAD_RESERVE_BYTES.saturating_mul(threads as u64);
    Some(limit.saturating_sub(mapped).saturating_sub(reserve))
}

#[cfg(unix)]
fn address_space_limit() -> Option<u64> {
    let mut limit = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: getrlimit writes the limit into the struct it is given, which lives on this frame.
    let status = unsafe { libc::getrlimit(libc::RLIMIT_AS, &mut limit) };
    (status == 0 && limit.rlim_cur != libc::RLIM_INFINITY).then_some(limit.rlim_cur)
}

#[cfg(not(unix))]
fn address_space_limit() -> Option<u64> {
    None
}

/// The value of a `Name:   1234 kB` line, in bytes.
fn kibibytes_field(text: &str, name: &str) -> Option<u64> {
    let line = text.lines().find(|line| line.starts_with(name))?;
    let value = line[name.len()..].trim().strip_suffix("kB")?.trim();
    value.parse::<u64>().ok()?.checked_mul(1024)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_are_read_in_bytes() {
        let text = "MemTotal:       24000000 kB\nMemAvailable:    1000 kB\n";
        assert_eq!(kibibytes_field(text, "MemAvailable:"), Some(1_024_000));
        assert_eq!(kibibytes_field(text, "VmSize:"), None);
        assert_eq!(kibibytes_field("VmSize: many kB", "VmSize:"), None);
        assert_eq!(in_words(3_200_000_000), "3.2 GB");
        assert_eq!(in_words(850_000_000), "850 MB");
    }
}
