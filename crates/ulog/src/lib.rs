//! PX4 ULog flight logs (`.ulg`), read natively.
//!
//! What it is for: reading a ULog file ([`Log::read`], or [`Log::parse`] of bytes) into typed
//! values: the start time, info and multi-info fields, parameters (initial values, changes with
//! their times, declared defaults), every subscribed topic instance (name, `multi_id`) with its
//! samples' own timestamps (µs) and its fields as typed [`Column`]s named as pyulog names them
//! (`x`, `control[0]`, `esc[1].esc_rpm`; padding left out), dropouts, logged messages, data
//! appended after a crash, and a truncated last message (reported, the rest kept). Reading is
//! bounded: the file's size ([`bounded_read::MAX_ULOG_BYTES`]), how deep formats nest and how many
//! fields they flatten to. The format is PX4's "ULog File Format"; pyulog is the reference
//! (`docs/ulog.md`).
//!
//! It also writes the part of the format a simulator needs ([`writer::write`]: `float` topics, no
//! parameters), so that a log of known physics takes the whole ULog path.
//!
//! What it is not for: resampling topics onto a common time axis, naming what a topic means for a
//! flight analysis or judging a log's rates (the `data` crate's).
//!
//! Errors are one line: the file, the byte offset of the offending message and what is wrong
//! ([`UlogError`]); no input makes the reader panic.

mod error;
mod format;
mod log;
mod reader;
pub mod writer;

use std::path::Path;

pub use error::{FormatFault, ParseError, Problem, UlogError};
pub use format::{Field, FieldType, MAX_FIELDS, MAX_NESTING};
pub use log::{
    Column, Dropout, Log, LogLevel, LoggedMessage, ParameterChange, ParameterNumber, Parameters,
    Topic, Truncation, Value,
};

impl Log {
    /// Parses a ULog file held in memory.
    pub fn parse(bytes: &[u8]) -> Result<Self, ParseError> {
        reader::parse(bytes)
    }

    /// Reads and parses the ULog file `path` (a regular file of bounded size).
    pub fn read(path: &Path) -> Result<Self, UlogError> {
        let bytes =
            bounded_read::read_bytes(path, bounded_read::InputKind::Ulog).map_err(|source| {
                UlogError::Io {
                    path: path.to_path_buf(),
                    source,
                }
            })?;
        Self::parse(&bytes).map_err(|source| UlogError::Parse {
            path: path.to_path_buf(),
            source,
        })
    }
}
