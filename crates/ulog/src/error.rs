//! The reader's errors: where in the file ([`ParseError`]: byte offset and [`Problem`]) and which
//! file ([`UlogError`]); each renders as one line.

use std::path::PathBuf;

use crate::format::{MAX_FIELDS, MAX_NESTING};

/// What is wrong with a ULog byte stream.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum Problem {
    #[error("not a ULog file (the magic bytes 'ULog' 01 12 35 are missing)")]
    NotUlog,
    #[error("the file ends inside its 16-byte header")]
    HeaderTooShort,
    #[error("incompatible flags {0:?} that this reader does not know: the log cannot be read")]
    IncompatibleFlags([u8; 8]),
    #[error("a flag-bits message after the first message")]
    LateFlagBits,
    #[error("appended-data offset {offset} does not lie after the previous one inside the file")]
    BadAppendedOffset { offset: u64 },
    #[error("a '{kind}' message of {size} bytes, at least {needed} expected")]
    MessageTooShort {
        kind: char,
        size: usize,
        needed: usize,
    },
    #[error("message type {0:#04x} with an empty or invalid header: the file is corrupt")]
    CorruptHeader(u8),
    #[error("malformed format definition '{text}': {fault}")]
    BadFormat { text: String, fault: FormatFault },
    #[error("'{0}' is used but no format defines it")]
    UnknownFormat(String),
    #[error("formats nested more than {MAX_NESTING} deep under '{0}' (a cycle?)")]
    NestingTooDeep(String),
    #[error("format '{name}' needs more than {limit} bytes, more than a message can hold")]
    FormatTooLarge { name: String, limit: usize },
    #[error("the subscribed formats flatten to more than {MAX_FIELDS} fields")]
    TooManyFields,
    #[error("topic '{0}' has no top-level uint64_t timestamp field")]
    NoTimestamp(String),
    #[error("topic '{name}' instance {multi_id} subscribed again with a different format")]
    FormatChanged { name: String, multi_id: u8 },
    #[error("data for message id {0}, which no subscription names")]
    UnknownMessageId(u16),
    #[error("a '{topic}' sample of {size} bytes, its format needs {min} to {max}")]
    DataSize {
        topic: String,
        size: usize,
        min: usize,
        max: usize,
    },
    #[error("malformed key '{0}' ('type name' expected)")]
    BadKey(String),
    #[error("'{key}' of type {type_name} holds {size} bytes, {expected} expected")]
    BadValueSize {
        key: String,
        type_name: String,
        size: usize,
        expected: usize,
    },
    #[error("parameter '{key}' has type {type_name}, int32_t or float expected")]
    ParameterType { key: String, type_name: String },
}

/// What is wrong with one field declaration of a format message.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum FormatFault {
    #[error("no ':' between the name and the fields")]
    NoColon,
    #[error("an empty format name")]
    EmptyName,
    #[error("field '{0}' is not 'type name'")]
    NotTypeAndName(String),
    #[error("field '{0}' has an array size that is not 1 to 65535")]
    BadArraySize(String),
}

/// A [`Problem`] at a byte offset of the stream (the start of the message that has it).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("byte {offset}: {problem}")]
pub struct ParseError {
    pub offset: u64,
    pub problem: Problem,
}

/// Reading a ULog file failed: one line naming the file (and the byte offset for a parse error).
#[derive(Debug, thiserror::Error)]
pub enum UlogError {
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: {source}", path.display())]
    Parse { path: PathBuf, source: ParseError },
}
