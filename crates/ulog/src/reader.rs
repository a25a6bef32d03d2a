//! The parse of a ULog byte stream: header, then messages (3-byte header: u16 payload size, u8
//! type) in the definitions and data sections, little-endian throughout.

use std::collections::{BTreeMap, HashMap};
use std::sync::Arc;

use crate::error::{ParseError, Problem};
use crate::format::{FieldType, Formats, parse_format};
use crate::log::{
    Dropout, Log, LogLevel, LoggedMessage, ParameterChange, ParameterNumber, Parameters, Topic,
    Truncation, Value,
};

const MAGIC: [u8; 7] = [b'U', b'L', b'o', b'g', 0x01, 0x12, 0x35];
const HEADER_BYTES: usize = 16;
/// Incompatible flag bit 0 of byte 0: data appended at the flag bits' offsets.
const DATA_APPENDED: u8 = 1;

/// Parses a whole ULog file held in memory. A file that ends inside a message is kept up to it
/// ([`Log::truncated`]); anything malformed is an error at the offending message's offset.
pub fn parse(bytes: &[u8]) -> Result<Log, ParseError> {
    let at_start = |problem| ParseError { offset: 0, problem };
    if bytes.len() < MAGIC.len() || bytes[..MAGIC.len()] != MAGIC {
        return Err(at_start(Problem::NotUlog));
    }
    if bytes.len() < HEADER_BYTES {
        return Err(at_start(Problem::HeaderTooShort));
    }
    let start_time_us = u64_at(bytes, 8);
    let mut reader = Reader {
        log: Log {
            version: bytes[7],
            start_time_us,
            last_time_us: start_time_us,
            appended_data: false,
            info: BTreeMap::new(),
            multi_info: BTreeMap::new(),
            parameters: Parameters::default(),
            topics: Vec::new(),
            dropouts: Vec::new(),
            messages: Vec::new(),
            truncated: None,
            unknown_messages: 0,
        },
        formats: Formats::default(),
        subscriptions: HashMap::new(),
        in_data_section: false,
        appended_offsets: Vec::new(),
    };
    reader.read_messages(bytes)?;
    let mut log = reader.log;
    log.topics
        .sort_by(|a, b| (&a.name, a.multi_id).cmp(&(&b.name, b.multi_id)));
    Ok(log)
}

struct Reader {
    log: Log,
    formats: Formats,
    /// Message id → index of its topic in `log.topics`.
    subscriptions: HashMap<u16, usize>,
    /// Set by the first subscription or logged message: parameters after it are changes.
    in_data_section: bool,
    /// Where the flag bits say appended parts start: pyulog reads up to each, then continues
    /// at it.
    appended_offsets: Vec<u64>,
}

fn u16_at(bytes: &[u8], at: usize) -> u16 {
    u16::from_le_bytes([bytes[at], bytes[at + 1]])
}

fn u64_at(bytes: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(bytes[at..at + 8].try_into().expect("8 bytes"))
}

/// Text of a ULog string: UTF-8 with invalid bytes replaced.
fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

impl Reader {
    fn read_messages(&mut self, bytes: &[u8]) -> Result<(), ParseError> {
        let file_end = bytes.len() as u64;
        let mut position = HEADER_BYTES as u64;
        let mut segment_end = file_end;
        // Where the appended parts start, the next one last.
        let mut appended_starts: Vec<u64> = Vec::new();
        loop {
            let remaining = segment_end - position;
            let size = (remaining >= 3).then(|| u64::from(u16_at(bytes, position as usize)));
            let Some(size) = size.filter(|size| 3 + size <= remaining) else {
                if let Some(start) = appended_starts.pop() {
                    // An appended part starts here: pyulog drops what precedes it unread.
                    position = start;
                    segment_end = appended_starts.last().copied().unwrap_or(file_end);
                    continue;
                }
                if remaining > 0 {
                    self.log.truncated = Some(Truncation {
                        offset: position,
                        available: remaining,
                    });
                }
                return Ok(());
            };
            let start = position as usize;
            let kind = bytes[start + 2];
            let payload = &bytes[start + 3..start + 3 + size as usize];
            let offset = position;
            let fail = move |problem| ParseError { offset, problem };
            self.message(kind, payload, position).map_err(fail)?;
            position += 3 + size;
            if !self.appended_offsets.is_empty() {
                // The flag bits just named the appended parts: read up to the first of them.
                let offsets = std::mem::take(&mut self.appended_offsets);
                let mut previous = position;
                for &offset in &offsets {
                    if offset < previous || offset > file_end {
                        return Err(fail(Problem::BadAppendedOffset { offset }));
                    }
                    previous = offset;
                }
                segment_end = offsets[0];
                appended_starts = offsets.into_iter().rev().collect();
            }
        }
    }

    fn message(&mut self, kind: u8, payload: &[u8], position: u64) -> Result<(), Problem> {
        match kind {
            b'B' => self.flag_bits(payload, position),
            b'F' => {
                let format = parse_format(&text(payload))?;
                self.formats.define(format);
                Ok(())
            }
            b'I' => {
                let (key, value) = key_value(payload, 'I')?;
                self.log.info.insert(key, value);
                Ok(())
            }
            b'M' => self.multi_info(payload),
            b'P' => self.parameter(payload),
            b'Q' => self.default_parameter(payload),
            b'A' => self.subscribe(payload),
            b'R' => {
                need(payload, 'R', 2)?;
                self.subscriptions.remove(&u16_at(payload, 0));
                Ok(())
            }
            b'D' => self.data(payload),
            b'L' => self.logged(payload, false),
            b'C' => self.logged(payload, true),
            b'O' => {
                need(payload, 'O', 2)?;
                self.log.dropouts.push(Dropout {
                    time_us: self.log.last_time_us,
                    duration_ms: u16_at(payload, 0),
                });
                Ok(())
            }
            b'S' => Ok(()),
            // A message type added to the format after this reader: skipped, as the format
            // asks. A zero type or an empty unknown message is what corruption looks like.
            _ if kind.is_ascii_alphabetic() && !payload.is_empty() => {
                self.log.unknown_messages += 1;
                Ok(())
            }
            _ => Err(Problem::CorruptHeader(kind)),
        }
    }

    fn flag_bits(&mut self, payload: &[u8], position: u64) -> Result<(), Problem> {
        if position != HEADER_BYTES as u64 {
            return Err(Problem::LateFlagBits);
        }
        need(payload, 'B', 40)?;
        let incompatible: [u8; 8] = payload[8..16].try_into().expect("8 bytes");
        if incompatible[0] & !DATA_APPENDED != 0 || incompatible[1..].iter().any(|&b| b != 0) {
            return Err(Problem::IncompatibleFlags(incompatible));
        }
        self.log.appended_data = incompatible[0] & DATA_APPENDED != 0;
        if self.log.appended_data {
            self.appended_offsets = (0..3)
                .map(|k| u64_at(payload, 16 + 8 * k))
                .filter(|&offset| offset != 0)
                .collect();
        }
        Ok(())
    }

    fn multi_info(&mut self, payload: &[u8]) -> Result<(), Problem> {
        need(payload, 'M', 2)?;
        let continued = payload[0] != 0;
        let (key, value) = key_value(&payload[1..], 'M')?;
        let lists = self.log.multi_info.entry(key).or_default();
        match lists.last_mut() {
            Some(list) if continued => list.push(value),
            _ => lists.push(vec![value]),
        }
        Ok(())
    }

    fn parameter(&mut self, payload: &[u8]) -> Result<(), Problem> {
        let (name, value) = parameter(payload, 'P')?;
        if self.in_data_section {
            self.log.parameters.changes.push(ParameterChange {
                time_us: self.log.last_time_us,
                name,
                value,
            });
        } else {
            self.log.parameters.initial.insert(name, value);
        }
        Ok(())
    }

    fn default_parameter(&mut self, payload: &[u8]) -> Result<(), Problem> {
        need(payload, 'Q', 2)?;
        let kinds = payload[0];
        let (name, value) = parameter(&payload[1..], 'Q')?;
        let parameters = &mut self.log.parameters;
        if kinds & 1 != 0 {
            parameters.system_defaults.insert(name.clone(), value);
        }
        if kinds & 2 != 0 {
            parameters.configuration_defaults.insert(name, value);
        }
        Ok(())
    }

    fn subscribe(&mut self, payload: &[u8]) -> Result<(), Problem> {
        self.in_data_section = true;
        need(payload, 'A', 4)?;
        let multi_id = payload[0];
        let message_id = u16_at(payload, 1);
        let name = text(&payload[3..]);
        let layout = self.formats.layout(&name)?;
        let topics = &mut self.log.topics;
        let index = match topics
            .iter()
            .position(|t| t.name == name && t.multi_id == multi_id)
        {
            Some(index) if topics[index].layout != layout => {
                return Err(Problem::FormatChanged { name, multi_id });
            }
            Some(index) => index,
            None => {
                topics.push(Topic {
                    name,
                    multi_id,
                    layout,
                    timestamps: Vec::new(),
                    rows: Vec::new(),
                });
                topics.len() - 1
            }
        };
        self.subscriptions.insert(message_id, index);
        Ok(())
    }

    fn data(&mut self, payload: &[u8]) -> Result<(), Problem> {
        need(payload, 'D', 2)?;
        let message_id = u16_at(payload, 0);
        let index = *self
            .subscriptions
            .get(&message_id)
            .ok_or(Problem::UnknownMessageId(message_id))?;
        let topic = &mut self.log.topics[index];
        let layout = Arc::clone(&topic.layout);
        let sample = &payload[2..];
        if !(layout.min_size..=layout.max_size).contains(&sample.len()) {
            return Err(Problem::DataSize {
                topic: topic.name.clone(),
                size: sample.len(),
                min: layout.min_size,
                max: layout.max_size,
            });
        }
        let at = layout
            .timestamp_offset
            .ok_or_else(|| Problem::NoTimestamp(topic.name.clone()))?;
        let timestamp = u64_at(sample, at);
        topic.timestamps.push(timestamp);
        topic.rows.extend_from_slice(&sample[..layout.min_size]);
        self.log.last_time_us = self.log.last_time_us.max(timestamp);
        Ok(())
    }

    fn logged(&mut self, payload: &[u8], tagged: bool) -> Result<(), Problem> {
        self.in_data_section = true;
        let (kind, header) = if tagged { ('C', 11) } else { ('L', 9) };
        need(payload, kind, header)?;
        let tag = tagged.then(|| u16_at(payload, 1));
        let time_at = if tagged { 3 } else { 1 };
        self.log.messages.push(LoggedMessage {
            time_us: u64_at(payload, time_at),
            level: LogLevel::from_byte(payload[0]),
            tag,
            text: text(&payload[header..]),
        });
        Ok(())
    }
}

fn need(payload: &[u8], kind: char, needed: usize) -> Result<(), Problem> {
    if payload.len() < needed {
        return Err(Problem::MessageTooShort {
            kind,
            size: payload.len(),
            needed,
        });
    }
    Ok(())
}

/// The key and value of an info-like message: u8 key length, key `type name`, value bytes.
fn key_value(payload: &[u8], kind: char) -> Result<(String, Value), Problem> {
    typed_key_value(payload, kind).map(|(name, _, value)| (name, value))
}

/// [`key_value`] with the value's type name.
fn typed_key_value(payload: &[u8], kind: char) -> Result<(String, String, Value), Problem> {
    need(payload, kind, 1)?;
    let key_length = usize::from(payload[0]);
    need(payload, kind, 1 + key_length)?;
    let key = text(&payload[1..1 + key_length]);
    let (type_name, name) = key
        .split_once(' ')
        .filter(|(t, n)| !t.is_empty() && !n.is_empty())
        .ok_or_else(|| Problem::BadKey(key.clone()))?;
    let bytes = &payload[1 + key_length..];
    let value = if type_name == "char" || type_name.starts_with("char[") {
        Value::Text(text(bytes))
    } else if let Some(field_type) = FieldType::from_name(type_name) {
        scalar(field_type, bytes).ok_or_else(|| Problem::BadValueSize {
            key: name.to_string(),
            type_name: type_name.to_string(),
            size: bytes.len(),
            expected: field_type.size(),
        })?
    } else {
        Value::Raw {
            type_name: type_name.to_string(),
            bytes: bytes.to_vec(),
        }
    };
    Ok((name.to_string(), type_name.to_string(), value))
}

/// A basic value from exactly its size of bytes.
fn scalar(field_type: FieldType, bytes: &[u8]) -> Option<Value> {
    macro_rules! le {
        ($type:ty) => {
            <$type>::from_le_bytes(bytes.try_into().ok()?)
        };
    }
    Some(match field_type {
        FieldType::Int8 => Value::Int(le!(i8).into()),
        FieldType::UInt8 => Value::UInt(le!(u8).into()),
        FieldType::Int16 => Value::Int(le!(i16).into()),
        FieldType::UInt16 => Value::UInt(le!(u16).into()),
        FieldType::Int32 => Value::Int(le!(i32).into()),
        FieldType::UInt32 => Value::UInt(le!(u32).into()),
        FieldType::Int64 => Value::Int(le!(i64)),
        FieldType::UInt64 => Value::UInt(le!(u64)),
        FieldType::Float => Value::Float(le!(f32).into()),
        FieldType::Double => Value::Float(le!(f64)),
        FieldType::Bool => Value::Bool(le!(u8) != 0),
        FieldType::Char => Value::Text(text(bytes)),
    })
}

/// A parameter's name and value: an info-like payload of type `int32_t` or `float`.
fn parameter(payload: &[u8], kind: char) -> Result<(String, ParameterNumber), Problem> {
    let (name, type_name, value) = typed_key_value(payload, kind)?;
    let value = match (type_name.as_str(), value) {
        ("int32_t", Value::Int(v)) => i32::try_from(v).ok().map(ParameterNumber::Int),
        ("float", Value::Float(v)) => Some(ParameterNumber::Float(v as f32)),
        _ => None,
    };
    let value = value.ok_or(Problem::ParameterType {
        key: name.clone(),
        type_name,
    })?;
    Ok((name, value))
}
