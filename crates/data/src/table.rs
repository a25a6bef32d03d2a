//! The CSV layer: polars reads the file, every column as text, and this module parses the cells into
//! typed values with errors that name the file, the row and the column.
//!
//! Reading every column as text (no schema inference) is deliberate: the list columns of the
//! Neural-Fly logs are strings such as `"[1.0, 2.0]"` anyway, and parsing numbers ourselves lets a bad
//! cell be reported at its exact row instead of silently turning a whole column into strings.

use std::path::{Path, PathBuf};

use polars::prelude::*;

use crate::error::{DataError, Result};

/// Rows of a CSV file, every column kept as text, in file order.
pub struct TextTable {
    path: PathBuf,
    frame: DataFrame,
}

/// The line of the file that holds data row `index` (0-based); the header is line 1.
pub fn file_row(index: usize) -> usize {
    index + 2
}

impl TextTable {
    /// Reads `path` with polars; fails on a missing, empty or malformed file.
    pub fn read(path: &Path) -> Result<Self> {
        let metadata = std::fs::metadata(path).map_err(|source| DataError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        if metadata.len() == 0 {
            return Err(DataError::Empty {
                path: path.to_path_buf(),
            });
        }
        let frame = CsvReadOptions::default()
            .with_has_header(true)
            .with_infer_schema_length(Some(0))
            .try_into_reader_with_file_path(Some(path.to_path_buf()))
            .and_then(|reader| reader.finish())
            .map_err(|error| DataError::Csv {
                path: path.to_path_buf(),
                message: first_line(&error.to_string()),
            })?;
        if frame.height() == 0 {
            return Err(DataError::Empty {
                path: path.to_path_buf(),
            });
        }
        Ok(Self {
            path: path.to_path_buf(),
            frame,
        })
    }

    /// Column names in file order.
    pub fn column_names(&self) -> Vec<String> {
        self.frame
            .get_column_names()
            .iter()
            .map(|name| name.to_string())
            .collect()
    }

    /// Whether a column of this name exists.
    pub fn has_column(&self, name: &str) -> bool {
        self.frame.column(name).is_ok()
    }

    fn text_column(&self, name: &str) -> Result<&StringChunked> {
        let missing = || DataError::MissingColumn {
            path: self.path.clone(),
            column: name.to_string(),
            present: self.column_names().join(", "),
        };
        let column = self.frame.column(name).map_err(|_| missing())?;
        column.str().map_err(|error| DataError::Csv {
            path: self.path.clone(),
            message: first_line(&error.to_string()),
        })
    }

    /// Parses a column of plain numbers (a one-element list such as `[0.5]` is accepted too).
    pub fn scalars(&self, name: &str) -> Result<Vec<f64>> {
        Ok(self.arrays::<1>(name)?.into_iter().map(|[v]| v).collect())
    }

    /// Parses a column whose cells hold exactly `N` numbers, written `[a, b, ...]` (nested brackets,
    /// as in a 3x3 matrix, are flattened row by row).
    pub fn arrays<const N: usize>(&self, name: &str) -> Result<Vec<[f64; N]>> {
        let column = self.text_column(name)?;
        let mut out = Vec::with_capacity(column.len());
        let mut buffer = Vec::with_capacity(N);
        for (index, cell) in column.iter().enumerate() {
            let row = file_row(index);
            let cell = cell.ok_or_else(|| self.bad_cell(row, name, "", "empty cell"))?;
            buffer.clear();
            parse_numbers(cell, &mut buffer)
                .map_err(|reason| self.bad_cell(row, name, cell, &reason))?;
            if buffer.len() != N {
                return Err(DataError::WrongLength {
                    path: self.path.clone(),
                    row,
                    column: name.to_string(),
                    expected: N,
                    found: buffer.len(),
                });
            }
            if let Some(value) = buffer.iter().find(|v| !v.is_finite()) {
                return Err(DataError::NonFinite {
                    path: self.path.clone(),
                    row,
                    column: name.to_string(),
                    value: value.to_string(),
                });
            }
            let mut array = [0.0; N];
            array.copy_from_slice(&buffer);
            out.push(array);
        }
        Ok(out)
    }

    fn bad_cell(&self, row: usize, column: &str, value: &str, reason: &str) -> DataError {
        DataError::BadCell {
            path: self.path.clone(),
            row,
            column: column.to_string(),
            value: value.to_string(),
            reason: reason.to_string(),
        }
    }
}

/// Parses `"1.5"`, `"[1.0, 2.0]"` or `"[[1, 2], [3, 4]]"` into its numbers, in reading order.
///
/// One pass over the bytes: brackets are counted, tokens end at `,`, `[` or `]`.
pub fn parse_numbers(cell: &str, out: &mut Vec<f64>) -> std::result::Result<(), String> {
    let bytes = cell.as_bytes();
    let start_len = out.len();
    let mut depth: i64 = 0;
    let mut token_start = 0;
    for (i, &byte) in bytes.iter().chain(std::iter::once(&b',')).enumerate() {
        if !matches!(byte, b',' | b'[' | b']') {
            continue;
        }
        let token = cell[token_start..i.min(cell.len())].trim();
        if !token.is_empty() {
            let value: f64 = token
                .parse()
                .map_err(|_| format!("'{token}' is not a number"))?;
            out.push(value);
        }
        token_start = (i + 1).min(cell.len());
        match byte {
            b'[' => depth += 1,
            b']' => {
                depth -= 1;
                if depth < 0 {
                    return Err("unbalanced brackets".to_string());
                }
            }
            _ => {}
        }
    }
    if depth != 0 {
        return Err("unbalanced brackets".to_string());
    }
    if out.len() == start_len {
        return Err("no number in cell".to_string());
    }
    Ok(())
}

fn first_line(message: &str) -> String {
    message
        .lines()
        .next()
        .unwrap_or_default()
        .trim()
        .to_string()
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
        assert!(
            parse_numbers("[1.0, abc]", &mut out)
                .unwrap_err()
                .contains("abc")
        );
        assert!(parse_numbers("[1.0, 2.0", &mut out).is_err());
        assert!(parse_numbers("[]", &mut Vec::new()).is_err());
    }

    #[test]
    fn nan_parses_so_the_caller_can_name_it() {
        let mut out = Vec::new();
        parse_numbers("[NaN, inf]", &mut out).unwrap();
        assert!(out[0].is_nan() && out[1].is_infinite());
    }
}
