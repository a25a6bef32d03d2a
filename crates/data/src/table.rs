//! The CSV layer: polars reads the file, every column as text, and this module parses the cells into
//! typed values with errors that name the file, the row and the column.
//!
//! Reading every column as text (no schema inference) is deliberate: the list columns of the
//! Neural-Fly logs are strings such as `"[1.0, 2.0]"` anyway, and parsing numbers ourselves lets a bad
//! cell be reported at its exact row instead of silently turning a whole column into strings.
//!
//! Before polars parses the bytes, one pass over them checks the layout polars would otherwise
//! accept silently or report without a line: UTF-8 text, no repeated column name (polars renames
//! a copy `x_duplicated_0`), as many fields on every row as in the header, closed quotes, no blank
//! or `#` line between rows. The same pass records the line each row starts on, so that errors name
//! the right line after a quoted cell that spans lines.

use std::path::{Path, PathBuf};

use polars::prelude::*;

use crate::error::{DataError, Result};

/// Rows of a CSV file, every column kept as text, in file order.
pub struct TextTable {
    path: PathBuf,
    frame: DataFrame,
    /// The line of the file on which each data row starts (the header is line 1).
    lines: Vec<usize>,
}

/// The line of the file that holds data row `index` (0-based) when no cell spans lines; the header
/// is line 1. [`TextTable::line`] gives the exact line of any row.
pub fn file_row(index: usize) -> usize {
    index + 2
}

impl TextTable {
    /// Reads `path` (a file, or a pipe: the bytes are read, whatever the length reported) and checks
    /// its layout before polars parses it: UTF-8 text, unique column names, every row with as many
    /// fields as the header, quotes closed. Errors name the file and the line.
    pub fn read(path: &Path) -> Result<Self> {
        let io = |source| DataError::Io {
            path: path.to_path_buf(),
            source,
        };
        if std::fs::metadata(path).map_err(io)?.is_dir() {
            return Err(DataError::IsDirectory {
                path: path.to_path_buf(),
            });
        }
        let bytes = std::fs::read(path).map_err(io)?;
        if bytes.is_empty() {
            return Err(DataError::Empty {
                path: path.to_path_buf(),
            });
        }
        let layout = Layout::scan(path, &bytes)?;
        if layout.lines.is_empty() {
            return Err(DataError::Empty {
                path: path.to_path_buf(),
            });
        }
        let frame = CsvReadOptions::default()
            .with_has_header(true)
            .with_infer_schema_length(Some(0))
            .into_reader_with_file_handle(std::io::Cursor::new(bytes))
            .finish()
            .map_err(|error| DataError::Csv {
                path: path.to_path_buf(),
                message: first_line(&error.to_string()),
            })?;
        // polars reads each blank line at the end as a row of empty cells; the layout does not.
        let frame = if frame.height() == layout.lines.len() + layout.trailing_blank_lines {
            frame.head(Some(layout.lines.len()))
        } else {
            return Err(DataError::Csv {
                path: path.to_path_buf(),
                message: format!(
                    "{} rows parsed, but the file has {} data rows",
                    frame.height(),
                    layout.lines.len()
                ),
            });
        };
        Ok(Self {
            path: path.to_path_buf(),
            frame,
            lines: layout.lines,
        })
    }

    /// The line of the file on which data row `index` (0-based) starts; the header is line 1.
    pub fn line(&self, index: usize) -> usize {
        self.lines.get(index).copied().unwrap_or(file_row(index))
    }

    /// The file read.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The line of each data row, in order.
    pub fn lines(&self) -> &[usize] {
        &self.lines
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
            let row = self.line(index);
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

/// What the layout check of a CSV file found: where each data row starts.
struct Layout {
    /// The line on which each data row starts (1-based, the header being line 1 unless blank lines
    /// precede it).
    lines: Vec<usize>,
    /// Blank lines after the last data row (accepted, not rows).
    trailing_blank_lines: usize,
}

impl Layout {
    /// Checks the text of a CSV file the way it is split into rows and fields (RFC 4180: `,`
    /// separates fields, a field may be quoted with `"`, `""` inside quotes is a quote, a quoted
    /// field may span lines; `\n` or `\r\n` ends a row).
    fn scan(path: &Path, bytes: &[u8]) -> Result<Self> {
        let text = std::str::from_utf8(bytes).map_err(|error| {
            let at = error.valid_up_to();
            DataError::NotText {
                path: path.to_path_buf(),
                row: line_at(bytes, at),
                reason: format!("byte 0x{:02X} is not UTF-8 text", bytes[at]),
            }
        })?;
        if let Some(at) = text
            .bytes()
            .position(|b| b < 0x20 && !matches!(b, b'\t' | b'\n' | b'\r'))
        {
            return Err(DataError::NotText {
                path: path.to_path_buf(),
                row: line_at(bytes, at),
                reason: format!("control byte 0x{:02X} (binary data?)", bytes[at]),
            });
        }
        let mut scanner = Scanner {
            path,
            bytes: text.as_bytes(),
            position: text.strip_prefix('\u{feff}').map_or(0, |_| 3),
            line: 1,
        };
        // Blank lines before the header are skipped (as polars does).
        while scanner.at_line_end() && !scanner.at_end() {
            scanner.skip_line_end();
        }
        if scanner.at_end() {
            return Ok(Self {
                lines: Vec::new(),
                trailing_blank_lines: 0,
            });
        }
        let header_line = scanner.line;
        if text[scanner.position..].starts_with('#') {
            return Err(DataError::BadRow {
                path: path.to_path_buf(),
                row: header_line,
                message: "a '#' comment line: the header must come first (no comments)".to_string(),
            });
        }
        let mut header = Vec::new();
        scanner.record(Some(&mut header))?;
        for (index, name) in header.iter().enumerate() {
            if let Some(first) = header[..index].iter().position(|n| n == name) {
                return Err(DataError::DuplicateColumn {
                    path: path.to_path_buf(),
                    row: header_line,
                    column: name.clone(),
                    first: first + 1,
                    second: index + 1,
                });
            }
        }
        let mut lines = Vec::new();
        let mut blank: Option<usize> = None;
        let mut trailing_blank_lines = 0;
        while !scanner.at_end() {
            let line = scanner.line;
            if scanner.at_line_end() {
                scanner.skip_line_end();
                blank.get_or_insert(line);
                trailing_blank_lines += 1;
                continue;
            }
            if let Some(blank) = blank {
                return Err(DataError::BadRow {
                    path: path.to_path_buf(),
                    row: blank,
                    message: "blank line between data rows".to_string(),
                });
            }
            if text[scanner.position..].starts_with('#') {
                return Err(DataError::BadRow {
                    path: path.to_path_buf(),
                    row: line,
                    message: "a '#' comment line (comments are not allowed)".to_string(),
                });
            }
            let fields = scanner.record(None)?;
            if fields != header.len() {
                let message = if fields > header.len() {
                    format!(
                        "{fields} fields, more than the {} columns of the header \
                         (a ',' in an unquoted cell, e.g. a decimal comma?)",
                        header.len()
                    )
                } else {
                    format!(
                        "too few fields: {fields} of the header's {}, no value for '{}'",
                        header.len(),
                        header[fields]
                    )
                };
                return Err(DataError::BadRow {
                    path: path.to_path_buf(),
                    row: line,
                    message,
                });
            }
            lines.push(line);
        }
        Ok(Self {
            lines,
            trailing_blank_lines,
        })
    }
}

/// The line (1-based) holding byte `offset` of `bytes`.
fn line_at(bytes: &[u8], offset: usize) -> usize {
    1 + bytes[..offset].iter().filter(|&&b| b == b'\n').count()
}

/// A cursor over the bytes of a CSV file that knows its line.
struct Scanner<'a> {
    path: &'a Path,
    bytes: &'a [u8],
    position: usize,
    line: usize,
}

impl Scanner<'_> {
    fn at_end(&self) -> bool {
        self.position >= self.bytes.len()
    }

    fn peek(&self, ahead: usize) -> Option<u8> {
        self.bytes.get(self.position + ahead).copied()
    }

    /// At `\n`, `\r\n`, a `\r` ending the file, or the end of the file.
    fn at_line_end(&self) -> bool {
        match self.peek(0) {
            None | Some(b'\n') => true,
            Some(b'\r') => matches!(self.peek(1), None | Some(b'\n')),
            _ => false,
        }
    }

    fn skip_line_end(&mut self) {
        if self.peek(0) == Some(b'\r') {
            self.position += 1;
        }
        if self.peek(0) == Some(b'\n') {
            self.position += 1;
            self.line += 1;
        }
    }

    fn bad_row(&self, row: usize, message: &str) -> DataError {
        DataError::BadRow {
            path: self.path.to_path_buf(),
            row,
            message: message.to_string(),
        }
    }

    /// Reads one row up to and including its line end; returns its number of fields and, when
    /// `names` is given, collects the fields' text (quotes removed).
    fn record(&mut self, mut names: Option<&mut Vec<String>>) -> Result<usize> {
        let mut fields = 0;
        loop {
            fields += 1;
            let start = self.position;
            let mut field = String::new();
            if self.peek(0) == Some(b'"') {
                let opened = self.line;
                self.position += 1;
                let mut from = self.position;
                loop {
                    match self.peek(0) {
                        None => {
                            return Err(
                                self.bad_row(opened, "a quoted cell opened here is never closed")
                            );
                        }
                        Some(b'"') if self.peek(1) == Some(b'"') => {
                            if names.is_some() {
                                field.push_str(self.text(from, self.position + 1));
                            }
                            self.position += 2;
                            from = self.position;
                        }
                        Some(b'"') => break,
                        Some(b'\n') => {
                            self.line += 1;
                            self.position += 1;
                        }
                        Some(_) => self.position += 1,
                    }
                }
                if names.is_some() {
                    field.push_str(self.text(from, self.position));
                }
                self.position += 1;
                if !(self.at_line_end() || self.peek(0) == Some(b',')) {
                    return Err(self.bad_row(self.line, "text after the closing quote of a cell"));
                }
            } else {
                while !(self.at_line_end() || self.peek(0) == Some(b',')) {
                    if self.peek(0) == Some(b'"') {
                        return Err(self.bad_row(
                            self.line,
                            "a quote inside an unquoted cell (quote the whole cell)",
                        ));
                    }
                    self.position += 1;
                }
                if names.is_some() {
                    field.push_str(self.text(start, self.position));
                }
            }
            if let Some(names) = names.as_deref_mut() {
                names.push(field);
            }
            if self.peek(0) == Some(b',') {
                self.position += 1;
                continue;
            }
            self.skip_line_end();
            return Ok(fields);
        }
    }

    fn text(&self, from: usize, to: usize) -> &str {
        // Field boundaries are ASCII bytes, so they are character boundaries of the UTF-8 text.
        std::str::from_utf8(&self.bytes[from..to]).unwrap_or_default()
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
