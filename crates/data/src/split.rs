//! Support / query splits of one flight.

use std::ops::Range;

use serde::{Deserialize, Serialize};

use crate::error::{DataError, Result};

/// How a flight of n samples is cut into a support segment (fit, adapt) and a query segment
/// (generalisation, never used to fit or choose anything).
///
/// JSON: `{"kind": "halves"}` or `{"kind": "fraction", "support": 0.7}`; any other field is an
/// error (also next to `halves`, which serde would otherwise ignore in a unit variant).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(
    tag = "kind",
    rename_all = "snake_case",
    deny_unknown_fields,
    from = "SplitSpecFields"
)]
pub enum SplitSpec {
    /// The paper's protocol: support = rows [0, n/2), query = rows [n/2, n) (integer division).
    Halves,
    /// Contiguous: support = the first ⌊fraction·n⌋ rows, query = the rest.
    Fraction { support: f64 },
}

/// What a [`SplitSpec`] is read from: the same JSON, every variant a struct variant, so that
/// `deny_unknown_fields` applies to `halves` too.
#[derive(Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
enum SplitSpecFields {
    Halves {},
    Fraction { support: f64 },
}

impl From<SplitSpecFields> for SplitSpec {
    fn from(fields: SplitSpecFields) -> Self {
        match fields {
            SplitSpecFields::Halves {} => Self::Halves,
            SplitSpecFields::Fraction { support } => Self::Fraction { support },
        }
    }
}

/// The two contiguous segments of a split.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Split {
    pub support: Range<usize>,
    pub query: Range<usize>,
}

impl SplitSpec {
    /// Checks the settings (a support fraction strictly between 0 and 1), whatever the rows.
    pub fn validate(&self) -> Result<()> {
        if let Self::Fraction { support } = *self
            && !(support > 0.0 && support < 1.0)
        {
            return Err(DataError::Invalid {
                what: "split".to_string(),
                message: format!("support fraction {support} must lie in (0, 1)"),
            });
        }
        Ok(())
    }

    /// Cuts `n` rows; both segments must keep at least two rows.
    pub fn split(&self, n: usize) -> Result<Split> {
        self.validate()?;
        let cut = match *self {
            Self::Halves => n / 2,
            Self::Fraction { support } => (support * n as f64).floor() as usize,
        };
        if cut < 2 || n - cut < 2 {
            return Err(DataError::Invalid {
                what: "split".to_string(),
                message: format!("{n} rows are too few to split ({cut} / {})", n - cut),
            });
        }
        Ok(Split {
            support: 0..cut,
            query: cut..n,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn halves_use_integer_division() {
        let split = SplitSpec::Halves.split(2511).unwrap();
        assert_eq!(split.support, 0..1255);
        assert_eq!(split.query, 1255..2511);
    }

    #[test]
    fn fractions_are_checked() {
        assert_eq!(
            SplitSpec::Fraction { support: 0.25 }
                .split(100)
                .unwrap()
                .query,
            25..100
        );
        assert!(SplitSpec::Fraction { support: 1.5 }.split(100).is_err());
        assert!(SplitSpec::Halves.split(3).is_err());
    }

    #[test]
    fn unknown_fields_are_errors_in_every_kind() {
        let read = |text: &str| bounded_read::json::from_str::<SplitSpec>(text);
        assert_eq!(read(r#"{"kind": "halves"}"#).unwrap(), SplitSpec::Halves);
        assert_eq!(
            read(r#"{"support": 0.25, "kind": "fraction"}"#).unwrap(),
            SplitSpec::Fraction { support: 0.25 }
        );
        for text in [
            r#"{"kind": "halves", "ratio": 0.3}"#,
            r#"{"kind": "halves", "support": 0.3}"#,
            r#"{"kind": "fraction", "support": 0.3, "ratio": 0.3}"#,
        ] {
            let message = read(text).unwrap_err().to_string();
            assert!(message.contains("unknown field"), "{text}: {message}");
        }
        // Written as before.
        for spec in [SplitSpec::Halves, SplitSpec::Fraction { support: 0.5 }] {
            let text = serde_json::to_string(&spec).unwrap();
            assert_eq!(read(&text).unwrap(), spec, "{text}");
        }
        assert_eq!(
            serde_json::to_string(&SplitSpec::Halves).unwrap(),
            r#"{"kind":"halves"}"#
        );
    }
}
