//! Format messages ('F') and their flattening into the columns of a topic, named as pyulog names
//! them: `x`, `control[0]`, `esc[1].esc_rpm`. Fields whose name starts with `_padding` hold no
//! value and give no column; trailing ones may be left out of a logged sample.

use std::collections::HashMap;
use std::sync::Arc;

use crate::error::{FormatFault, Problem};

/// Deepest nesting of formats inside formats (PX4's deepest is 2); more means a cycle.
pub const MAX_NESTING: usize = 32;
/// Most fields that all subscribed formats may flatten to (a PX4 log has about 10,000).
pub const MAX_FIELDS: usize = 1_000_000;
/// Largest sample a data message can carry: its 16-bit size less the message id.
const MAX_SAMPLE_BYTES: usize = u16::MAX as usize - 2;

/// The basic types of a field.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum FieldType {
    Int8,
    UInt8,
    Int16,
    UInt16,
    Int32,
    UInt32,
    Int64,
    UInt64,
    Float,
    Double,
    Bool,
    Char,
}

impl FieldType {
    /// The type of a ULog type name (`uint8_t`, `float`…); `None` for a nested format's name.
    pub fn from_name(name: &str) -> Option<Self> {
        Some(match name {
            "int8_t" => Self::Int8,
            "uint8_t" => Self::UInt8,
            "int16_t" => Self::Int16,
            "uint16_t" => Self::UInt16,
            "int32_t" => Self::Int32,
            "uint32_t" => Self::UInt32,
            "int64_t" => Self::Int64,
            "uint64_t" => Self::UInt64,
            "float" => Self::Float,
            "double" => Self::Double,
            "bool" => Self::Bool,
            "char" => Self::Char,
            _ => return None,
        })
    }

    /// Bytes one value takes.
    pub fn size(self) -> usize {
        match self {
            Self::Int8 | Self::UInt8 | Self::Bool | Self::Char => 1,
            Self::Int16 | Self::UInt16 => 2,
            Self::Int32 | Self::UInt32 | Self::Float => 4,
            Self::Int64 | Self::UInt64 | Self::Double => 8,
        }
    }
}

/// What a declared field holds: a basic value or a nested format (by name).
#[derive(Clone, Debug, PartialEq, Eq)]
enum Element {
    Basic(FieldType),
    Nested(String),
}

/// One field as a format declares it: `type name` or `type[n] name`.
#[derive(Clone, Debug, PartialEq, Eq)]
struct Declaration {
    element: Element,
    array: Option<usize>,
    name: String,
}

/// A parsed format message: `name:type field;type[n] field;…`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Format {
    pub name: String,
    fields: Vec<Declaration>,
}

/// Parses the text of a format message.
pub(crate) fn parse_format(text: &str) -> Result<Format, Problem> {
    let fault = |fault| Problem::BadFormat {
        text: text.chars().take(80).collect(),
        fault,
    };
    let (name, fields) = text.split_once(':').ok_or(fault(FormatFault::NoColon))?;
    if name.is_empty() {
        return Err(fault(FormatFault::EmptyName));
    }
    let fields = fields
        .split(';')
        .filter(|field| !field.is_empty())
        .map(|field| parse_declaration(field).map_err(fault))
        .collect::<Result<_, _>>()?;
    Ok(Format {
        name: name.to_string(),
        fields,
    })
}

fn parse_declaration(field: &str) -> Result<Declaration, FormatFault> {
    let (type_text, name) = field
        .split_once(' ')
        .filter(|(t, n)| !t.is_empty() && !n.is_empty())
        .ok_or_else(|| FormatFault::NotTypeAndName(field.to_string()))?;
    let (type_name, array) = match type_text.split_once('[') {
        None => (type_text, None),
        Some((type_name, rest)) => {
            let size = rest
                .strip_suffix(']')
                .and_then(|n| n.parse::<usize>().ok())
                .filter(|n| (1..=0xFFFF).contains(n))
                .ok_or_else(|| FormatFault::BadArraySize(field.to_string()))?;
            (type_name, Some(size))
        }
    };
    let element = FieldType::from_name(type_name)
        .map_or_else(|| Element::Nested(type_name.to_string()), Element::Basic);
    Ok(Declaration {
        element,
        array,
        name: name.to_string(),
    })
}

/// One column of a topic: its flattened name, type and byte offset in a sample.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Field {
    pub name: String,
    pub field_type: FieldType,
    pub offset: usize,
}

/// A subscribed format flattened: its columns (without padding) and sample sizes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Layout {
    pub fields: Vec<Field>,
    /// Bytes of a sample without the trailing padding (which PX4 may leave out).
    pub min_size: usize,
    /// Bytes of a sample with every field.
    pub max_size: usize,
    pub timestamp_offset: Option<usize>,
}

/// The formats of a log by name, and the layouts flattened from them so far.
#[derive(Default)]
pub(crate) struct Formats {
    formats: HashMap<String, Format>,
    layouts: HashMap<String, Arc<Layout>>,
    fields_flattened: usize,
}

impl Formats {
    /// Adds (or redefines) a format.
    pub fn define(&mut self, format: Format) {
        self.layouts.remove(&format.name);
        self.formats.insert(format.name.clone(), format);
    }

    /// The layout of the format `name`, flattened once.
    pub fn layout(&mut self, name: &str) -> Result<Arc<Layout>, Problem> {
        if let Some(layout) = self.layouts.get(name) {
            return Ok(Arc::clone(layout));
        }
        let mut sizes = HashMap::new();
        let size = self.size_of(name, 0, &mut sizes)?;
        let mut fields = Vec::new();
        let mut trailing_padding_from = None;
        self.flatten(name, "", 0, &mut fields, &mut trailing_padding_from)?;
        self.fields_flattened += fields.len();
        if self.fields_flattened > MAX_FIELDS {
            return Err(Problem::TooManyFields);
        }
        let timestamp_offset = fields
            .iter()
            .find(|f| f.name == "timestamp" && f.field_type == FieldType::UInt64)
            .map(|f| f.offset);
        let layout = Arc::new(Layout {
            fields,
            min_size: trailing_padding_from.unwrap_or(size),
            max_size: size,
            timestamp_offset,
        });
        self.layouts.insert(name.to_string(), Arc::clone(&layout));
        Ok(layout)
    }

    fn format(&self, name: &str) -> Result<&Format, Problem> {
        self.formats
            .get(name)
            .ok_or_else(|| Problem::UnknownFormat(name.to_string()))
    }

    /// Bytes of a sample of `name` (memoised: nested formats are shared), refused beyond what a
    /// message can hold before anything is flattened.
    fn size_of(
        &self,
        name: &str,
        depth: usize,
        sizes: &mut HashMap<String, usize>,
    ) -> Result<usize, Problem> {
        if let Some(&size) = sizes.get(name) {
            return Ok(size);
        }
        if depth > MAX_NESTING {
            return Err(Problem::NestingTooDeep(name.to_string()));
        }
        let mut size = 0usize;
        for declaration in &self.format(name)?.fields {
            let element = match &declaration.element {
                Element::Basic(field_type) => field_type.size(),
                Element::Nested(nested) => self.size_of(nested, depth + 1, sizes)?,
            };
            size = size.saturating_add(element.saturating_mul(declaration.array.unwrap_or(1)));
            if size > MAX_SAMPLE_BYTES {
                return Err(Problem::FormatTooLarge {
                    name: name.to_string(),
                    limit: MAX_SAMPLE_BYTES,
                });
            }
        }
        sizes.insert(name.to_string(), size);
        Ok(size)
    }

    /// Appends the columns of format `name` under `prefix` from byte `offset`; returns the offset
    /// after it. `trailing_padding_from` is where the top level's trailing padding starts.
    fn flatten(
        &self,
        name: &str,
        prefix: &str,
        mut offset: usize,
        fields: &mut Vec<Field>,
        trailing_padding_from: &mut Option<usize>,
    ) -> Result<usize, Problem> {
        for declaration in &self.format(name)?.fields {
            let padding = declaration.name.starts_with("_padding");
            let start = offset;
            let count = declaration.array.unwrap_or(1);
            for index in 0..count {
                let element_name = match declaration.array {
                    Some(_) => format!("{prefix}{}[{index}]", declaration.name),
                    None => format!("{prefix}{}", declaration.name),
                };
                offset = match &declaration.element {
                    Element::Basic(field_type) => {
                        if !padding {
                            fields.push(Field {
                                name: element_name,
                                field_type: *field_type,
                                offset,
                            });
                        }
                        offset + field_type.size()
                    }
                    Element::Nested(nested) => {
                        let nested_prefix = format!("{element_name}.");
                        // A padding field of a nested type gives no columns either.
                        let mut padding_fields = Vec::new();
                        let into = if padding {
                            &mut padding_fields
                        } else {
                            &mut *fields
                        };
                        self.flatten(nested, &nested_prefix, offset, into, &mut None)?
                    }
                };
            }
            if prefix.is_empty() {
                *trailing_padding_from = match (padding, *trailing_padding_from) {
                    (true, None) => Some(start),
                    (true, kept) => kept,
                    (false, _) => None,
                };
            }
        }
        Ok(offset)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn formats(texts: &[&str]) -> Formats {
        let mut formats = Formats::default();
        for text in texts {
            formats.define(parse_format(text).unwrap());
        }
        formats
    }

    fn names(layout: &Layout) -> Vec<(&str, usize)> {
        layout
            .fields
            .iter()
            .map(|f| (f.name.as_str(), f.offset))
            .collect()
    }

    #[test]
    fn nested_formats_and_arrays_flatten_as_pyulog_names_them() {
        let mut formats = formats(&[
            "esc_report:uint32_t esc_errorcount;int32_t esc_rpm;",
            "esc_status:uint64_t timestamp;uint8_t esc_count;uint8_t[3] _padding0;esc_report[2] esc;float[1] one;",
        ]);
        let layout = formats.layout("esc_status").unwrap();
        assert_eq!(
            names(&layout),
            [
                ("timestamp", 0),
                ("esc_count", 8),
                ("esc[0].esc_errorcount", 12),
                ("esc[0].esc_rpm", 16),
                ("esc[1].esc_errorcount", 20),
                ("esc[1].esc_rpm", 24),
                ("one[0]", 28),
            ]
        );
        assert_eq!((layout.min_size, layout.max_size), (32, 32));
        assert_eq!(layout.timestamp_offset, Some(0));
    }

    #[test]
    fn trailing_padding_may_be_left_out_of_a_sample() {
        let mut formats = formats(&["t:uint64_t timestamp;uint8_t a;uint8_t[7] _padding0;"]);
        let layout = formats.layout("t").unwrap();
        assert_eq!(names(&layout), [("timestamp", 0), ("a", 8)]);
        assert_eq!((layout.min_size, layout.max_size), (9, 16));
    }

    #[test]
    fn a_padding_field_of_a_nested_type_gives_no_column() {
        let mut formats = formats(&[
            "pair:float a;float b;",
            "t:uint64_t timestamp;pair _padding0;",
        ]);
        let layout = formats.layout("t").unwrap();
        assert_eq!(names(&layout), [("timestamp", 0)]);
        assert_eq!((layout.min_size, layout.max_size), (8, 16));
    }

    #[test]
    fn a_cycle_of_formats_is_refused_not_followed() {
        let mut formats = formats(&["a:uint64_t timestamp;b x;", "b:a y;"]);
        assert!(matches!(
            formats.layout("a"),
            Err(Problem::NestingTooDeep(_))
        ));
    }

    #[test]
    fn a_format_larger_than_a_message_is_refused_before_flattening() {
        let mut formats = formats(&[
            "big:uint64_t timestamp;inner[65535] x;",
            "inner:double[65535] v;",
        ]);
        assert!(matches!(
            formats.layout("big"),
            Err(Problem::FormatTooLarge { .. })
        ));
    }

    #[test]
    fn malformed_declarations_are_named() {
        let fault = |text| match parse_format(text) {
            Err(Problem::BadFormat { fault, .. }) => fault,
            other => panic!("{other:?}"),
        };
        assert_eq!(fault("no colon"), FormatFault::NoColon);
        assert_eq!(fault(":float x;"), FormatFault::EmptyName);
        assert_eq!(
            fault("a:float;"),
            FormatFault::NotTypeAndName("float".to_string())
        );
        assert_eq!(
            fault("a:float[0] x;"),
            FormatFault::BadArraySize("float[0] x".to_string())
        );
        assert_eq!(
            fault("a:float[70000] x;"),
            FormatFault::BadArraySize("float[70000] x".to_string())
        );
    }
}
