//! Numbers from the cells of a CSV, shared by the whole-file reader and the block reader so that
//! a cell reads the same, or fails with the same message, whichever reads it. A message shows a
//! cell through [`bounded_read::Excerpt`] only: at most 80 characters, once.

use std::path::Path;

use bounded_read::Excerpt;

use crate::error::{DataError, Result};
use crate::table::ColumnRef;

/// At most this many column names are listed in an error message.
const LISTED_COLUMNS: usize = 40;

/// Why a cell holds no list of numbers.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum CellFault {
    /// The text at these bytes of the cell (between separators) is not a number.
    NotANumber(std::ops::Range<usize>),
    UnbalancedBrackets,
    NoNumber,
}

impl CellFault {
    /// The reason shown after the cell: the bad part is quoted only when it is not the whole cell
    /// (which the message quotes already).
    pub fn reason(&self, cell: &str) -> String {
        match self {
            Self::NotANumber(range) if cell[range.clone()] == *cell.trim() => {
                "not a number".to_string()
            }
            Self::NotANumber(range) => {
                format!(
                    "'{}' is not a number",
                    Excerpt::of(&cell[range.clone()]).unquoted()
                )
            }
            Self::UnbalancedBrackets => "unbalanced brackets".to_string(),
            Self::NoNumber => "no number in cell".to_string(),
        }
    }
}

/// Parses `"1.5"`, `"[1.0, 2.0]"` or `"[[1, 2], [3, 4]]"` into its numbers, in reading order.
///
/// One pass over the bytes: brackets are counted, tokens end at `,`, `[` or `]`.
pub fn parse_numbers(cell: &str, out: &mut Vec<f64>) -> std::result::Result<(), CellFault> {
    let bytes = cell.as_bytes();
    let start_len = out.len();
    let mut depth: i64 = 0;
    let mut token_start = 0;
    for (i, &byte) in bytes.iter().chain(std::iter::once(&b',')).enumerate() {
        if !matches!(byte, b',' | b'[' | b']') {
            continue;
        }
        let end = i.min(cell.len());
        let token = cell[token_start..end].trim();
        if !token.is_empty() {
            let value: f64 = token.parse().map_err(|_| {
                let leading =
                    cell[token_start..end].len() - cell[token_start..end].trim_start().len();
                let start = token_start + leading;
                CellFault::NotANumber(start..start + token.len())
            })?;
            out.push(value);
        }
        token_start = (i + 1).min(cell.len());
        match byte {
            b'[' => depth += 1,
            b']' => {
                depth -= 1;
                if depth < 0 {
                    return Err(CellFault::UnbalancedBrackets);
                }
            }
            _ => {}
        }
    }
    if depth != 0 {
        return Err(CellFault::UnbalancedBrackets);
    }
    if out.len() == start_len {
        return Err(CellFault::NoNumber);
    }
    Ok(())
}

/// The error for `cell` (row on line `line`, column `column`) that cannot be read: the cell shown
/// as an [`Excerpt`].
pub fn bad_cell(path: &Path, line: usize, column: &str, cell: &str, reason: String) -> DataError {
    DataError::BadCell {
        path: path.to_path_buf(),
        row: line,
        column: column.to_string(),
        value: Excerpt::of(cell).to_string(),
        reason,
    }
}

/// The numbers of `cell` (at least one), into `buffer`; an empty cell is an error of its own.
pub fn cell_numbers(
    path: &Path,
    line: usize,
    column: &str,
    cell: &str,
    buffer: &mut Vec<f64>,
) -> Result<()> {
    buffer.clear();
    if cell.is_empty() {
        return Err(bad_cell(path, line, column, cell, "empty cell".to_string()));
    }
    parse_numbers(cell, buffer)
        .map_err(|fault| bad_cell(path, line, column, cell, fault.reason(cell)))
}

/// Fails on the first value of `values` that is not finite.
pub fn check_finite(path: &Path, line: usize, column: &str, values: &[f64]) -> Result<()> {
    match values.iter().find(|v| !v.is_finite()) {
        Some(value) => Err(DataError::NonFinite {
            path: path.to_path_buf(),
            row: line,
            column: column.to_string(),
            value: value.to_string(),
        }),
        None => Ok(()),
    }
}

/// A column named by the user, found in a header: plain numbers, or element `k` of list cells
/// ([`ColumnRef`]).
#[derive(Clone, Debug)]
pub struct NumericColumn {
    /// The name as given (`v[2]`), which errors name.
    pub name: String,
    /// The field of the header that holds it.
    pub field: usize,
    /// The element of its list cells, for a name `v[k]`.
    pub element: Option<usize>,
}

impl NumericColumn {
    /// Finds each of `columns` in `header`; a missing one is an error listing the names present.
    pub fn resolve(path: &Path, header: &[String], columns: &[&str]) -> Result<Vec<Self>> {
        let position = |name: &str| header.iter().position(|n| n == name);
        columns
            .iter()
            .map(|&column| {
                let (field, element) = match ColumnRef::resolve(column, |n| position(n).is_some()) {
                    ColumnRef::Whole(name) => (name, None),
                    ColumnRef::Element { base, index } => (base, Some(index)),
                };
                let field = position(field).ok_or_else(|| DataError::MissingColumn {
                    path: path.to_path_buf(),
                    column: column.to_string(),
                    present: column_list(header),
                })?;
                Ok(Self {
                    name: column.to_string(),
                    field,
                    element,
                })
            })
            .collect()
    }

    /// The number `cell` holds for this column (on line `line`): its one number, or the
    /// element named.
    pub fn number(
        &self,
        path: &Path,
        line: usize,
        cell: &str,
        buffer: &mut Vec<f64>,
    ) -> Result<f64> {
        // A plain number first: what it parses, `cell_numbers` reads as its one number (a cell
        // with a ',', '[' or ']' does not parse as one).
        if self.element.is_none()
            && let Ok(value) = cell.trim().parse::<f64>()
            && value.is_finite()
        {
            return Ok(value);
        }
        cell_numbers(path, line, &self.name, cell, buffer)?;
        let value = match self.element {
            Some(element) => *buffer.get(element).ok_or_else(|| {
                let reason = format!("{} value(s), no element [{element}]", buffer.len());
                bad_cell(path, line, &self.name, cell, reason)
            })?,
            None if buffer.len() == 1 => buffer[0],
            None => {
                return Err(DataError::WrongLength {
                    path: path.to_path_buf(),
                    row: line,
                    column: self.name.clone(),
                    expected: 1,
                    found: buffer.len(),
                });
            }
        };
        check_finite(path, line, &self.name, &[value])?;
        Ok(value)
    }
}

/// Column names for an error message, comma-separated: the first [`LISTED_COLUMNS`] (each as an
/// [`Excerpt`]), then how many more (a file may have 10,000 columns; the message stays readable).
pub fn column_list(names: &[String]) -> String {
    let mut list = names
        .iter()
        .take(LISTED_COLUMNS)
        .map(|name| Excerpt::of(name).unquoted())
        .collect::<Vec<_>>()
        .join(", ");
    if names.len() > LISTED_COLUMNS {
        list.push_str(&format!(" and {} more", names.len() - LISTED_COLUMNS));
    }
    list
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_scalars_lists_and_matrices() {
        let mut out = Vec::new();
        parse_numbers("0.5", &mut out).unwrap();
        parse_numbers("[1.0, -2e-3]", &mut out).unwrap();
        parse_numbers("[[1, 2], [3, 4]]", &mut out).unwrap();
        assert_eq!(out, vec![0.5, 1.0, -2e-3, 1.0, 2.0, 3.0, 4.0]);
    }

    #[test]
    fn rejects_garbage_and_unbalanced_brackets() {
        let mut out = Vec::new();
        let cell = "[1.0,  abc ]";
        let fault = parse_numbers(cell, &mut out).unwrap_err();
        assert_eq!(fault, CellFault::NotANumber(7..10));
        assert_eq!(fault.reason(cell), "'abc' is not a number");
        let fault = parse_numbers(" abc ", &mut out).unwrap_err();
        assert_eq!(fault.reason(" abc "), "not a number");
        assert_eq!(
            parse_numbers("[1.0, 2.0", &mut out),
            Err(CellFault::UnbalancedBrackets)
        );
        assert_eq!(
            parse_numbers("[]", &mut Vec::new()),
            Err(CellFault::NoNumber)
        );
    }

    #[test]
    fn nan_parses_so_the_caller_can_name_it() {
        let mut out = Vec::new();
        parse_numbers("[NaN, inf]", &mut out).unwrap();
        assert!(out[0].is_nan() && out[1].is_infinite());
    }

    #[test]
    fn a_huge_cell_is_quoted_once_and_shortly() {
        // A whole cell that is not a number is shown once, cut to 80 characters with its length.
        let cell = "abc".repeat(1_000_000);
        let mut buffer = Vec::new();
        let message = cell_numbers(Path::new("f.csv"), 7, "x", &cell, &mut buffer)
            .unwrap_err()
            .to_string();
        assert_eq!(
            message,
            format!(
                "f.csv:7:x: cannot parse \"{}…\" (3000000 characters): not a number",
                &cell[..80]
            )
        );
        // A bad element of a long list: the cell and the element each cut.
        let cell = format!("[{}, {}]", "1,".repeat(100_000), "z".repeat(500));
        let message = cell_numbers(Path::new("f.csv"), 7, "x", &cell, &mut buffer)
            .unwrap_err()
            .to_string();
        assert!(message.len() < 400, "{message}");
        assert!(
            message.ends_with(" (500 characters)' is not a number"),
            "{message}"
        );
    }
}
