//! Reading JSON configuration files with errors that name the field: a wrong type, an unknown key
//! or a bad value deep in a file is reported as `meta_training.average_last (line 22 column 20):
//! invalid value: integer -1, expected usize`, not by its position alone. Every crate's loaders use
//! this and wrap [`JsonError`] in their own error type with the file's path.
//!
//! serde reads a struct from a JSON array as well as from an object (the fields in declaration
//! order), so `"optimizer": ["stlsq", 0.2]` would be taken silently for an object. Both readers
//! refuse that: the value read is written back and compared in shape with the document, and an
//! array where the type holds an object is an error naming the field.

use serde::Serialize;
use serde::de::DeserializeOwned;
use serde_json::Value;

/// Where a JSON document failed to deserialise, and why.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct JsonError {
    /// The path of the offending field (`rules[3].tolerance`) and, for text, its line and column;
    /// `the document (line L column C)` at the document's root (a missing top-level field, text
    /// after the document).
    pub field: String,
    /// What is wrong, without the position (which `field` holds).
    pub message: String,
}

impl std::fmt::Display for JsonError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.field, self.message)
    }
}

/// Deserialises `text` (a leading byte-order mark is ignored, as editors may write one), naming
/// the field that fails; a key given twice in one object is refused (see [`checked_text`]).
pub fn from_str<T: DeserializeOwned + Serialize>(text: &str) -> Result<T, JsonError> {
    let text = checked_text(text)?;
    let mut deserializer = serde_json::Deserializer::from_str(text);
    let value = serde_path_to_error::deserialize(&mut deserializer).map_err(|error| {
        let path = field_path(error.path());
        let inner = error.into_inner();
        let position = format!("line {} column {}", inner.line(), inner.column());
        JsonError {
            field: match path {
                Some(path) => format!("{path} ({position})"),
                // A missing top-level field, or a document that is not an object at all.
                None => format!("the document ({position})"),
            },
            message: plain_message(without_position(&inner)),
        }
    })?;
    // Trailing characters after the document are an error too (as in `serde_json::from_str`).
    deserializer.end().map_err(|error| JsonError {
        field: format!(
            "the document (line {} column {})",
            error.line(),
            error.column()
        ),
        message: without_position(&error),
    })?;
    let document: Value = serde_json::from_str(text).map_err(|error| JsonError {
        field: "the document".to_string(),
        message: without_position(&error),
    })?;
    objects_not_arrays(&document, &value)?;
    Ok(value)
}

/// The project's reading policy for any JSON text, before it is interpreted: a leading
/// byte-order mark is dropped (returned text is without it), the text must be one JSON document
/// (a CSV or other text is named as such), and no object may give a key twice (serde would keep
/// the last value silently). Errors name the place; other syntax errors are left to the reader
/// that interprets the text, which names the field they are in.
pub fn checked_text(text: &str) -> Result<&str, JsonError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let duplicate = std::cell::RefCell::new(None);
    let mut deserializer = serde_json::Deserializer::from_str(text);
    let scanned = serde::de::DeserializeSeed::deserialize(
        KeyScan {
            path: String::new(),
            duplicate: &duplicate,
        },
        &mut deserializer,
    )
    .and_then(|()| deserializer.end());
    let Err(error) = scanned else {
        return Ok(text);
    };
    let position = format!("line {} column {}", error.line(), error.column());
    if let Some((path, key)) = duplicate.into_inner() {
        return Err(JsonError {
            field: format!("{} ({position})", display_path(&path)),
            message: format!(
                "key `{}` is given twice (refused: which one is meant?)",
                crate::Excerpt::of(&key).unquoted()
            ),
        });
    }
    if error.is_syntax() && !text.trim_start().starts_with(['{', '[']) {
        let first = text.trim_start().lines().next().unwrap_or("");
        return Err(JsonError {
            field: "the document (line 1 column 1)".to_string(),
            message: format!(
                "not JSON: it starts with {} (a CSV or other text?)",
                crate::Excerpt::of(first)
            ),
        });
    }
    // Any other fault is reported by the reader that interprets the text, with its field.
    Ok(text)
}

fn display_path(path: &str) -> &str {
    if path.is_empty() {
        "the document"
    } else {
        path
    }
}

/// Walks a JSON document, refusing a key given twice in one object; the first such key and the
/// path of its object are left in `duplicate`.
struct KeyScan<'a> {
    path: String,
    duplicate: &'a std::cell::RefCell<Option<(String, String)>>,
}

impl<'de> serde::de::DeserializeSeed<'de> for KeyScan<'_> {
    type Value = ();
    fn deserialize<D: serde::Deserializer<'de>>(self, deserializer: D) -> Result<(), D::Error> {
        deserializer.deserialize_any(self)
    }
}

impl<'de> serde::de::Visitor<'de> for KeyScan<'_> {
    type Value = ();
    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("a JSON value")
    }
    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<(), A::Error> {
        let mut seen = std::collections::HashSet::new();
        while let Some(key) = map.next_key::<String>()? {
            let inner = if self.path.is_empty() {
                key.clone()
            } else {
                format!("{}.{key}", self.path)
            };
            if !seen.insert(key.clone()) {
                *self.duplicate.borrow_mut() = Some((self.path.clone(), key));
                return Err(serde::de::Error::custom("duplicate key"));
            }
            map.next_value_seed(KeyScan {
                path: inner,
                duplicate: self.duplicate,
            })?;
        }
        Ok(())
    }
    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<(), A::Error> {
        let mut index = 0;
        while seq
            .next_element_seed(KeyScan {
                path: format!("{}[{index}]", self.path),
                duplicate: self.duplicate,
            })?
            .is_some()
        {
            index += 1;
        }
        Ok(())
    }
    fn visit_bool<E>(self, _: bool) -> Result<(), E> {
        Ok(())
    }
    fn visit_i64<E>(self, _: i64) -> Result<(), E> {
        Ok(())
    }
    fn visit_u64<E>(self, _: u64) -> Result<(), E> {
        Ok(())
    }
    fn visit_f64<E>(self, _: f64) -> Result<(), E> {
        Ok(())
    }
    fn visit_str<E>(self, _: &str) -> Result<(), E> {
        Ok(())
    }
    fn visit_unit<E>(self) -> Result<(), E> {
        Ok(())
    }
}

/// Deserialises an already parsed `value` (e.g. a configuration after a merge patch), naming the
/// field that fails.
pub fn from_value<T: DeserializeOwned + Serialize>(value: Value) -> Result<T, JsonError> {
    let read: T = serde_path_to_error::deserialize(value.clone()).map_err(|error| JsonError {
        field: field_path(error.path()).unwrap_or_else(|| "the document".to_string()),
        message: without_position(error.inner()),
    })?;
    objects_not_arrays(&value, &read)?;
    Ok(read)
}

/// Refuses a `document` that gives an array where `read` (the value deserialised from it) holds
/// an object: `read` is serialised again and walked beside the document.
fn objects_not_arrays<T: Serialize>(document: &Value, read: &T) -> Result<(), JsonError> {
    let written = serde_json::to_value(read).map_err(|error| JsonError {
        field: "the document".to_string(),
        message: format!("cannot be checked: {error}"),
    })?;
    match array_for_object(document, &written, "") {
        None => Ok(()),
        Some(path) => Err(JsonError {
            field: if path.is_empty() {
                "the document".to_string()
            } else {
                path
            },
            message: "expected a JSON object, found an array".to_string(),
        }),
    }
}

/// The path (`a.b[2]`) of the first place where `document` has an array and `written` an object.
fn array_for_object(document: &Value, written: &Value, path: &str) -> Option<String> {
    match (document, written) {
        (Value::Array(_), Value::Object(_)) => Some(path.to_string()),
        (Value::Object(document), Value::Object(written)) => {
            written.iter().find_map(|(key, written)| {
                let inner = if path.is_empty() {
                    key.clone()
                } else {
                    format!("{path}.{key}")
                };
                array_for_object(document.get(key)?, written, &inner)
            })
        }
        (Value::Array(document), Value::Array(written)) => document
            .iter()
            .zip(written)
            .enumerate()
            .find_map(|(index, (document, written))| {
                array_for_object(document, written, &format!("{path}[{index}]"))
            }),
        _ => None,
    }
}

/// The path as `a.b[2].c`, or `None` at the document's root.
fn field_path(path: &serde_path_to_error::Path) -> Option<String> {
    let text = path.to_string();
    (text != ".").then_some(text)
}

/// serde_json's `expected value` (its word for a number or other non-string where an enum's name
/// is expected) in plain words.
fn plain_message(message: String) -> String {
    if message == "expected value" {
        "expected one of this field's names, as a string in quotes".to_string()
    } else {
        message
    }
}

/// serde_json's message without the ` at line L column C` it appends.
fn without_position(error: &serde_json::Error) -> String {
    let text = error.to_string();
    let suffix = format!(" at line {} column {}", error.line(), error.column());
    text.strip_suffix(&suffix).unwrap_or(&text).to_string()
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Deserialize;

    #[derive(Debug, Deserialize, Serialize)]
    #[serde(deny_unknown_fields)]
    struct Outer {
        #[allow(dead_code)]
        inner: Inner,
        #[allow(dead_code)]
        rules: Vec<Inner>,
    }

    #[derive(Debug, Deserialize, Serialize)]
    #[serde(deny_unknown_fields)]
    struct Inner {
        count: usize,
    }

    #[test]
    fn a_wrong_value_is_named_by_its_path_and_position() {
        let text = "{\"inner\": {\"count\": 1},\n \"rules\": [{\"count\": 2}, {\"count\": -1}]}";
        let error = from_str::<Outer>(text).unwrap_err();
        assert_eq!(error.field, "rules[1].count (line 2 column 37)");
        assert_eq!(error.message, "invalid value: integer `-1`, expected usize");
    }

    #[test]
    fn an_unknown_key_and_a_syntax_error_are_named() {
        let error = from_str::<Outer>("{\"inner\": {\"cuont\": 1}, \"rules\": []}").unwrap_err();
        assert!(error.field.starts_with("inner.cuont"), "{error}");
        assert!(error.message.contains("unknown field `cuont`"), "{error}");
        let error = from_str::<Outer>("{\"inner\": ").unwrap_err();
        assert_eq!(error.field, "inner (line 1 column 10)");
        assert_eq!(error.message, "EOF while parsing a value");
        assert!(!error.message.contains(" at line "), "{error}");
        let error = from_str::<Inner>("{\"count\": 1} x").unwrap_err();
        assert_eq!(error.field, "the document (line 1 column 14)");
    }

    #[test]
    fn a_missing_top_level_field_names_the_document() {
        let error = from_str::<Outer>("{\"inner\": {\"count\": 1}}").unwrap_err();
        assert_eq!(error.field, "the document (line 1 column 23)");
        assert_eq!(error.message, "missing field `rules`");
        assert_eq!(
            error.to_string(),
            "the document (line 1 column 23): missing field `rules`"
        );
        let error = from_str::<Outer>("7").unwrap_err();
        assert!(
            error.field.starts_with("the document (line 1 column"),
            "{error}"
        );
    }

    #[test]
    fn a_key_given_twice_is_refused_by_its_place() {
        let error = from_str::<Outer>("{\"inner\": {\"count\": 1, \"count\": 2}, \"rules\": []}")
            .unwrap_err();
        assert!(error.field.starts_with("inner (line 1 column"), "{error}");
        assert!(error.message.contains("`count` is given twice"), "{error}");
        let error = checked_text("{\"a\": [{}, {\"b\": 1, \"b\": 1}]}").unwrap_err();
        assert!(error.field.starts_with("a[1] ("), "{error}");
        let error = checked_text("{\"m\": 1,\n \"m\": 2}").unwrap_err();
        assert!(error.field.starts_with("the document (line 2"), "{error}");
    }

    #[test]
    fn a_number_where_a_name_is_expected_is_said_plainly() {
        #[derive(Debug, Deserialize, Serialize)]
        enum Kind {
            A,
        }
        let error = from_str::<Vec<Kind>>("[42]").unwrap_err();
        assert_eq!(
            error.to_string(),
            "[0] (line 1 column 2): expected one of this field's names, as a string in quotes"
        );
    }

    #[test]
    fn a_csv_where_json_is_expected_is_named_as_such() {
        let error = checked_text("t,x,y\n0,1,2\n").unwrap_err();
        assert_eq!(
            error.to_string(),
            "the document (line 1 column 1): not JSON: it starts with \"t,x,y\" (a CSV or other text?)"
        );
    }

    #[test]
    fn a_byte_order_mark_is_ignored() {
        let parsed: Inner = from_str("\u{feff}{\"count\": 3}").unwrap();
        assert_eq!(parsed.count, 3);
    }

    #[test]
    fn values_are_named_by_path_alone() {
        let value = serde_json::json!({"inner": {"count": "many"}, "rules": []});
        let error = from_value::<Outer>(value).unwrap_err();
        assert_eq!(error.field, "inner.count");
        assert!(error.message.starts_with("invalid type: string"), "{error}");
    }

    #[test]
    fn an_array_in_place_of_an_object_is_refused_by_its_path() {
        let error = from_str::<Outer>("{\"inner\": [1], \"rules\": []}").unwrap_err();
        assert_eq!(
            error.to_string(),
            "inner: expected a JSON object, found an array"
        );
        let error =
            from_str::<Outer>("{\"inner\": {\"count\": 1}, \"rules\": [{\"count\": 2}, [3]]}")
                .unwrap_err();
        assert_eq!(error.field, "rules[1]");
        let error = from_str::<Outer>("[{\"count\": 1}, []]").unwrap_err();
        assert_eq!(error.field, "the document");
        let error =
            from_value::<Outer>(serde_json::json!({"inner": [4], "rules": []})).unwrap_err();
        assert_eq!(error.field, "inner");
        // Arrays where the type holds arrays are fine.
        let read: Outer =
            from_str("{\"inner\": {\"count\": 1}, \"rules\": [{\"count\": 2}]}").unwrap();
        assert_eq!(read.rules.len(), 1);
    }
}
