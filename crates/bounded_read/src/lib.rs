//! Reading input files safely.
//!
//! What it is for: reading a file a command was given with bounded cost ([`read_bytes`],
//! [`read_text`], [`read_json_text`]: a regular file, or a pipe for a CSV, within a size limit per
//! [`InputKind`]; [`open`] to read one in pieces), showing an input's text in a message
//! ([`Excerpt`]: at most [`EXCERPT_CHARACTERS`] characters), and deserialising JSON under one policy ([`json`]: a byte-order mark ignored, a
//! duplicated key or an array in place of an object refused, errors naming the failing field).
//!
//! What it is not for: what the files mean. Flight logs and numeric tables are read by `data`,
//! models by `sindy` and `learn`; writing results is the `output_set` crate's.
//!
//! Errors are `std::io::Error`s (reading) and [`json::JsonError`]s (deserialising); each crate's
//! loader wraps them with the file's path in its own error type.

mod bounded;
mod excerpt;
pub mod json;

pub use bounded::{
    BoundedFile, InputKind, MAX_CSV_BYTES, MAX_CSV_COLUMNS, MAX_JSON_BYTES, MAX_SHARD_BYTES,
    MAX_ULOG_BYTES, open, read_bytes, read_json_text, read_text,
};
pub use excerpt::{EXCERPT_CHARACTERS, Excerpt};
