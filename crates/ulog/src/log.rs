//! What a ULog file holds, as typed values: [`Log`] and its parts.

use std::collections::BTreeMap;
use std::sync::Arc;

use crate::format::{Field, FieldType, Layout};

/// A value of an info message, a multi-info message or a default parameter.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    Int(i64),
    UInt(u64),
    Float(f64),
    Bool(bool),
    /// A `char[n]` (or `char`) value, UTF-8 with invalid bytes replaced.
    Text(String),
    /// A value of any other type (an array of numbers, say): its type name and bytes.
    Raw {
        type_name: String,
        bytes: Vec<u8>,
    },
}

impl Value {
    /// The text of a `char[n]` value.
    pub fn as_text(&self) -> Option<&str> {
        match self {
            Self::Text(text) => Some(text),
            _ => None,
        }
    }

    /// A numeric value as f64 (integers beyond 2^53 rounded).
    pub fn as_f64(&self) -> Option<f64> {
        match *self {
            Self::Int(v) => Some(v as f64),
            Self::UInt(v) => Some(v as f64),
            Self::Float(v) => Some(v),
            Self::Bool(v) => Some(f64::from(u8::from(v))),
            _ => None,
        }
    }
}

/// A parameter's value: PX4 parameters are `int32_t` or `float`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParameterNumber {
    Int(i32),
    Float(f32),
}

impl ParameterNumber {
    pub fn as_f64(self) -> f64 {
        match self {
            Self::Int(v) => f64::from(v),
            Self::Float(v) => f64::from(v),
        }
    }
}

/// A parameter set during the flight, at the time of the latest sample logged before it.
#[derive(Clone, Debug, PartialEq)]
pub struct ParameterChange {
    pub time_us: u64,
    pub name: String,
    pub value: ParameterNumber,
}

/// The log's parameters: their values when logging started, changes during it, and the defaults
/// the log declares (system defaults and the airframe configuration's defaults).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Parameters {
    pub initial: BTreeMap<String, ParameterNumber>,
    pub changes: Vec<ParameterChange>,
    pub system_defaults: BTreeMap<String, ParameterNumber>,
    pub configuration_defaults: BTreeMap<String, ParameterNumber>,
}

impl Parameters {
    /// The value of `name` at the end of the log (its last change, else its initial value).
    pub fn value(&self, name: &str) -> Option<ParameterNumber> {
        self.changes
            .iter()
            .rev()
            .find(|change| change.name == name)
            .map(|change| change.value)
            .or_else(|| self.initial.get(name).copied())
    }
}

/// Data the logger could not write (its buffer overflowed): from `time_us` (the latest sample
/// logged before it) for `duration_ms`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Dropout {
    pub time_us: u64,
    pub duration_ms: u16,
}

/// The severity of a logged message (syslog levels, as PX4 writes them: '0' to '7').
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LogLevel {
    Emergency,
    Alert,
    Critical,
    Error,
    Warning,
    Notice,
    Info,
    Debug,
    /// A byte outside '0' to '7'.
    Unknown(u8),
}

impl LogLevel {
    pub(crate) fn from_byte(byte: u8) -> Self {
        match byte {
            b'0' => Self::Emergency,
            b'1' => Self::Alert,
            b'2' => Self::Critical,
            b'3' => Self::Error,
            b'4' => Self::Warning,
            b'5' => Self::Notice,
            b'6' => Self::Info,
            b'7' => Self::Debug,
            other => Self::Unknown(other),
        }
    }
}

/// A text message the autopilot logged ('L'; 'C' messages carry a tag too).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LoggedMessage {
    pub time_us: u64,
    pub level: LogLevel,
    pub tag: Option<u16>,
    pub text: String,
}

/// The file ended inside a message: what came before it is kept.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Truncation {
    /// Where the incomplete message starts.
    pub offset: u64,
    /// Bytes the file still had from there.
    pub available: u64,
}

/// One values column of a topic, in the field's own type.
#[derive(Clone, Debug, PartialEq)]
pub enum Column {
    Int8(Vec<i8>),
    UInt8(Vec<u8>),
    Int16(Vec<i16>),
    UInt16(Vec<u16>),
    Int32(Vec<i32>),
    UInt32(Vec<u32>),
    Int64(Vec<i64>),
    UInt64(Vec<u64>),
    Float(Vec<f32>),
    Double(Vec<f64>),
    Bool(Vec<bool>),
    Char(Vec<u8>),
}

impl Column {
    pub fn len(&self) -> usize {
        match self {
            Self::Int8(v) => v.len(),
            Self::UInt8(v) | Self::Char(v) => v.len(),
            Self::Int16(v) => v.len(),
            Self::UInt16(v) => v.len(),
            Self::Int32(v) => v.len(),
            Self::UInt32(v) => v.len(),
            Self::Int64(v) => v.len(),
            Self::UInt64(v) => v.len(),
            Self::Float(v) => v.len(),
            Self::Double(v) => v.len(),
            Self::Bool(v) => v.len(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The values as f64 (64-bit integers beyond 2^53 rounded, booleans 0 or 1).
    pub fn to_f64(&self) -> Vec<f64> {
        fn widen<T: Copy>(values: &[T], to: impl Fn(T) -> f64) -> Vec<f64> {
            values.iter().map(|&v| to(v)).collect()
        }
        match self {
            Self::Int8(v) => widen(v, f64::from),
            Self::UInt8(v) | Self::Char(v) => widen(v, f64::from),
            Self::Int16(v) => widen(v, f64::from),
            Self::UInt16(v) => widen(v, f64::from),
            Self::Int32(v) => widen(v, f64::from),
            Self::UInt32(v) => widen(v, f64::from),
            Self::Int64(v) => widen(v, |x| x as f64),
            Self::UInt64(v) => widen(v, |x| x as f64),
            Self::Float(v) => widen(v, f64::from),
            Self::Double(v) => v.clone(),
            Self::Bool(v) => widen(v, |x| f64::from(u8::from(x))),
        }
    }
}

/// One instance of a logged topic (`vehicle_local_position`, instance `multi_id`): its samples'
/// own timestamps and their fields as columns. Nothing is resampled.
#[derive(Clone, Debug)]
pub struct Topic {
    pub name: String,
    pub multi_id: u8,
    pub(crate) layout: Arc<Layout>,
    pub(crate) timestamps: Vec<u64>,
    /// The samples' bytes, `layout.min_size` each.
    pub(crate) rows: Vec<u8>,
}

impl Topic {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.timestamps.len()
    }

    pub fn is_empty(&self) -> bool {
        self.timestamps.is_empty()
    }

    /// Each sample's `timestamp` field (µs since boot), in the order logged.
    pub fn timestamps(&self) -> &[u64] {
        &self.timestamps
    }

    /// The flattened fields, padding left out, in the order of the format.
    pub fn fields(&self) -> &[Field] {
        &self.layout.fields
    }

    /// The column of the field `name` (`x`, `control[0]`, `esc[1].esc_rpm`).
    pub fn column(&self, name: &str) -> Option<Column> {
        let field = self.layout.fields.iter().find(|f| f.name == name)?;
        Some(self.decode(field))
    }

    /// The column of the field `name` as f64.
    pub fn column_f64(&self, name: &str) -> Option<Vec<f64>> {
        self.column(name).map(|column| column.to_f64())
    }

    fn decode(&self, field: &Field) -> Column {
        let stride = self.layout.min_size;
        let at = field.offset;
        let cells = || {
            self.rows
                .chunks_exact(stride)
                .map(move |row| &row[at..at + field.field_type.size()])
        };
        macro_rules! numbers {
            ($variant:ident, $type:ty) => {
                Column::$variant(
                    cells()
                        .map(|b| <$type>::from_le_bytes(b.try_into().expect("field size")))
                        .collect(),
                )
            };
        }
        match field.field_type {
            FieldType::Int8 => numbers!(Int8, i8),
            FieldType::UInt8 => numbers!(UInt8, u8),
            FieldType::Int16 => numbers!(Int16, i16),
            FieldType::UInt16 => numbers!(UInt16, u16),
            FieldType::Int32 => numbers!(Int32, i32),
            FieldType::UInt32 => numbers!(UInt32, u32),
            FieldType::Int64 => numbers!(Int64, i64),
            FieldType::UInt64 => numbers!(UInt64, u64),
            FieldType::Float => numbers!(Float, f32),
            FieldType::Double => numbers!(Double, f64),
            FieldType::Bool => Column::Bool(cells().map(|b| b[0] != 0).collect()),
            FieldType::Char => Column::Char(cells().map(|b| b[0]).collect()),
        }
    }
}

/// A parsed ULog file.
#[derive(Clone, Debug)]
pub struct Log {
    /// The format version of the header (PX4 writes 1).
    pub version: u8,
    /// When logging started (µs since boot; the header's timestamp).
    pub start_time_us: u64,
    /// The latest sample timestamp in the log (the start time if none is later).
    pub last_time_us: u64,
    /// Whether the flag bits say that data was appended after the log was closed.
    pub appended_data: bool,
    /// Info messages by key (`sys_name`, `ver_hw`…); a later message replaces an earlier one.
    pub info: BTreeMap<String, Value>,
    /// Multi-info messages by key: one list per message sequence (continued messages joined).
    pub multi_info: BTreeMap<String, Vec<Vec<Value>>>,
    pub parameters: Parameters,
    /// Every subscribed topic instance, sorted by name and instance (some may have no sample).
    pub topics: Vec<Topic>,
    pub dropouts: Vec<Dropout>,
    pub messages: Vec<LoggedMessage>,
    /// Set when the file ends inside a message.
    pub truncated: Option<Truncation>,
    /// Messages of a type this reader does not know, skipped as the format asks.
    pub unknown_messages: usize,
}

impl Log {
    /// The instance `multi_id` of topic `name`.
    pub fn topic(&self, name: &str, multi_id: u8) -> Option<&Topic> {
        self.topics
            .iter()
            .find(|t| t.name == name && t.multi_id == multi_id)
    }

    /// The text of the info field `key` (`sys_name`, `ver_hw`).
    pub fn info_text(&self, key: &str) -> Option<&str> {
        self.info.get(key).and_then(Value::as_text)
    }
}
