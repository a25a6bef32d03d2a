//! The CSV layer: the `csv` crate splits the file into rows, which become a polars frame with every
//! column as text, and this module parses the cells into typed values with errors that name the
//! file, the row and the column.
//!
//! Reading every column as text (no schema inference) is deliberate: the list columns of the
//! Neural-Fly logs are strings such as `"[1.0, 2.0]"` anyway, and parsing numbers ourselves lets a bad
//! cell be reported at its exact row instead of silently turning a whole column into strings.
//!
//! The layout faults the csv crate reads without complaint are checked on the way, each named by
//! its line: text that is not UTF-8 or holds control bytes, a repeated column name, a row with more
//! or fewer fields than the header, an unpaired quote, a blank or `#` line between rows. Each row
//! keeps the line it starts on, so that errors name the right line after a cell that spans lines.

use std::path::{Path, PathBuf};

use csv::StringRecord;
use polars::prelude::{Column, DataFrame, StringChunked};

use crate::error::{DataError, Result};

/// Rows of a CSV file, every column kept as text, in file order.
pub struct TextTable {
    path: PathBuf,
    frame: DataFrame,
    /// The line of the file on which each data row starts (the header is line 1).
    lines: Vec<usize>,
}

/// At most this many column names are listed in an error message.
const LISTED_COLUMNS: usize = 40;

/// The line of the file that holds data row `index` (0-based) when no cell spans lines; the header
/// is line 1. [`TextTable::line`] gives the exact line of any row.
pub fn file_row(index: usize) -> usize {
    index + 2
}

impl TextTable {
    /// Reads `path` (a file, or a pipe: the bytes are read, whatever the length reported) and checks
    /// its layout: UTF-8 text, unique column names, every row with as many fields as the header,
    /// quotes paired, no blank or `#` line between rows. Errors name the file and the line.
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
        let bytes = inputs::read_bytes(path, inputs::InputKind::Csv).map_err(io)?;
        let text = check_text(path, &bytes)?;
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        check_width(path, text)?;
        let records = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .from_reader(text.as_bytes())
            .into_records()
            .collect::<Result<Vec<_>, _>>()
            .map_err(|error| DataError::Csv {
                path: path.to_path_buf(),
                message: first_line(&error.to_string()),
            })?;
        if records.len() < 2 {
            return Err(DataError::Empty {
                path: path.to_path_buf(),
            });
        }
        let lines = check_layout(path, text.as_bytes(), &records)?;
        let (header, rows) = records.split_at(1);
        // An empty cell is missing (null), as polars reads it.
        let columns = header[0]
            .iter()
            .enumerate()
            .map(|(index, name)| {
                let cells: Vec<Option<&str>> = rows
                    .iter()
                    .map(|row| Some(&row[index]).filter(|cell| !cell.is_empty()))
                    .collect();
                Column::new(name.into(), cells)
            })
            .collect();
        let frame = DataFrame::new(rows.len(), columns).map_err(|error| DataError::Csv {
            path: path.to_path_buf(),
            message: first_line(&error.to_string()),
        })?;
        Ok(Self {
            path: path.to_path_buf(),
            frame,
            lines,
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

    /// The column names for an error message, comma-separated: the first [`LISTED_COLUMNS`], then
    /// how many more (a file may have a million columns; the message stays readable).
    pub fn column_list(&self) -> String {
        let names = self.frame.get_column_names();
        let mut list = names
            .iter()
            .take(LISTED_COLUMNS)
            .map(|name| name.as_str())
            .collect::<Vec<_>>()
            .join(", ");
        if names.len() > LISTED_COLUMNS {
            list.push_str(&format!(" and {} more", names.len() - LISTED_COLUMNS));
        }
        list
    }

    /// Whether a column of this name exists.
    pub fn has_column(&self, name: &str) -> bool {
        self.frame.column(name).is_ok()
    }

    fn text_column(&self, name: &str) -> Result<&StringChunked> {
        let missing = || DataError::MissingColumn {
            path: self.path.clone(),
            column: name.to_string(),
            present: self.column_list(),
        };
        let column = self.frame.column(name).map_err(|_| missing())?;
        column.str().map_err(|error| DataError::Csv {
            path: self.path.clone(),
            message: first_line(&error.to_string()),
        })
    }

    /// The cells of column `name` as text (labels, e.g. a task column); an empty cell is an error.
    pub fn labels(&self, name: &str) -> Result<Vec<String>> {
        let column = self.text_column(name)?;
        column
            .iter()
            .enumerate()
            .map(|(index, cell)| {
                cell.map(str::to_string)
                    .ok_or_else(|| self.bad_cell(self.line(index), name, "", "empty cell"))
            })
            .collect()
    }

    /// Parses the column `name` ([`ColumnRef`]): a column of that name holding plain numbers, or,
    /// when there is none, element `k` of the list cells of column `base` for a name `base[k]`.
    pub fn numbers(&self, name: &str) -> Result<Vec<f64>> {
        match ColumnRef::resolve(name, |column| self.has_column(column)) {
            ColumnRef::Whole(column) => self.scalars(column),
            ColumnRef::Element { base, index } => self.elements(name, base, index),
        }
    }

    /// Element `index` of every list cell of column `base`, errors naming the column `name`.
    fn elements(&self, name: &str, base: &str, index: usize) -> Result<Vec<f64>> {
        let column = self.text_column(base)?;
        let mut out = Vec::with_capacity(column.len());
        let mut buffer = Vec::new();
        for (position, cell) in column.iter().enumerate() {
            let row = self.line(position);
            let cell = cell.ok_or_else(|| self.bad_cell(row, name, "", "empty cell"))?;
            buffer.clear();
            parse_numbers(cell, &mut buffer)
                .map_err(|reason| self.bad_cell(row, name, cell, &reason))?;
            let value = *buffer.get(index).ok_or_else(|| {
                let reason = format!("{} value(s), no element [{index}]", buffer.len());
                self.bad_cell(row, name, cell, &reason)
            })?;
            if !value.is_finite() {
                return Err(DataError::NonFinite {
                    path: self.path.clone(),
                    row,
                    column: name.to_string(),
                    value: value.to_string(),
                });
            }
            out.push(value);
        }
        Ok(out)
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

/// What a column name given by the user refers to: a column of the file, or one element of the
/// list cells (`[1.0, 2.0, 3.0]`, the flight-log layout) of a column.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColumnRef<'a> {
    /// The column of this name, plain numbers.
    Whole(&'a str),
    /// Element `index` (0-based) of each cell of column `base`: written `base[index]`.
    Element { base: &'a str, index: usize },
}

impl<'a> ColumnRef<'a> {
    /// `name` as a column of the file when `exists(name)`; otherwise `base[k]` (k a whole
    /// number) as element k of column `base` when `exists(base)`; otherwise the whole column
    /// `name` (which the reader then reports missing).
    pub fn resolve(name: &'a str, exists: impl Fn(&str) -> bool) -> Self {
        if exists(name) {
            return Self::Whole(name);
        }
        let element = name
            .strip_suffix(']')
            .and_then(|rest| rest.rsplit_once('['))
            .filter(|(base, digits)| {
                !base.is_empty() && !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit())
            })
            .and_then(|(base, digits)| Some((base, digits.parse().ok()?)));
        match element {
            Some((base, index)) if exists(base) => Self::Element { base, index },
            _ => Self::Whole(name),
        }
    }
}

/// Refuses a header of more than [`inputs::MAX_CSV_COLUMNS`] names before any row is kept:
/// the cost of a table grows with rows × columns.
fn check_width(path: &Path, text: &str) -> Result<()> {
    let header = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .from_reader(text.as_bytes())
        .into_records()
        .next();
    let columns = match header {
        Some(Ok(record)) => record.len(),
        _ => return Ok(()),
    };
    if columns > inputs::MAX_CSV_COLUMNS {
        return Err(DataError::BadRow {
            path: path.to_path_buf(),
            row: 1,
            message: format!(
                "{columns} columns in the header, more than the {} a CSV may have",
                inputs::MAX_CSV_COLUMNS
            ),
        });
    }
    Ok(())
}

/// Checks the text before the csv crate splits it (which accepts any bytes): UTF-8, and no control
/// bytes other than tab and line ends (a binary file). Errors name the line of the offending byte.
fn check_text<'a>(path: &Path, bytes: &'a [u8]) -> Result<&'a str> {
    let not_text = |at: usize, reason: String| DataError::NotText {
        path: path.to_path_buf(),
        row: 1 + bytes[..at].iter().filter(|&&b| b == b'\n').count(),
        reason,
    };
    let text = std::str::from_utf8(bytes).map_err(|error| {
        let at = error.valid_up_to();
        not_text(at, format!("byte 0x{:02X} is not UTF-8 text", bytes[at]))
    })?;
    match bytes
        .iter()
        .position(|&b| b < 0x20 && !matches!(b, b'\t' | b'\n' | b'\r'))
    {
        Some(at) => Err(not_text(
            at,
            format!("control byte 0x{:02X} (binary data?)", bytes[at]),
        )),
        None => Ok(text),
    }
}

/// Checks what the csv crate reads without complaint: a `#` line, a blank line between rows (it
/// skips them), an unpaired quote (it reads an unclosed quote to the end of the file), text after
/// a closing quote (it joins `"1"2` into `12`), a repeated
/// column name, a row with more or fewer fields than the header. Returns the line on which each
/// data row starts.
fn check_layout(path: &Path, bytes: &[u8], records: &[StringRecord]) -> Result<Vec<usize>> {
    let bad_row = |row, message: &str| DataError::BadRow {
        path: path.to_path_buf(),
        row,
        message: message.to_string(),
    };
    let newlines = |cells: &[&str]| cells.iter().map(|c| c.matches('\n').count()).sum::<usize>();
    let header: Vec<&str> = records[0].iter().collect();
    let mut lines = Vec::with_capacity(records.len() - 1);
    let mut next_line = 0;
    for (index, record) in records.iter().enumerate() {
        // A record's position is where the previous record ended: before the blank lines the
        // reader skipped and, after a `\r\n`, before its `\n`. Its own text starts past them.
        let position = record
            .position()
            .expect("records read from a reader have a position");
        let end = records
            .get(index + 1)
            .and_then(StringRecord::position)
            .map_or(bytes.len(), |next| next.byte() as usize);
        let raw = &bytes[position.byte() as usize..end];
        let skipped = raw.iter().take_while(|b| matches!(b, b'\r' | b'\n'));
        let line = position.line() as usize + skipped.clone().filter(|&&b| b == b'\n').count();
        let raw = &raw[skipped.count()..];
        let cells: Vec<&str> = record.iter().collect();
        if index > 0 && line > next_line {
            return Err(bad_row(next_line, "blank line between data rows"));
        }
        next_line = line + newlines(&cells) + 1;
        if raw.starts_with(b"#") {
            return Err(bad_row(
                line,
                if index == 0 {
                    "a '#' comment line: the header must come first (no comments)"
                } else {
                    "a '#' comment line (comments are not allowed)"
                },
            ));
        }
        if let Some(after) = text_after_a_closing_quote(raw) {
            let at = line + raw[..after].iter().filter(|&&b| b == b'\n').count();
            return Err(bad_row(
                at,
                "text after the closing quote of a quoted cell (quote the whole cell)",
            ));
        }
        if raw.iter().filter(|&&b| b == b'"').count() % 2 == 1 {
            return Err(if index + 1 == records.len() {
                // An unclosed quote is read to the end of the file as the last cell of the last
                // row: it opened on that cell's line.
                let opened = line + newlines(&cells[..cells.len() - 1]);
                bad_row(
                    opened,
                    "a quoted cell opened here is never closed (or a stray '\"')",
                )
            } else {
                bad_row(
                    line,
                    "a quote inside an unquoted cell (quote the whole cell)",
                )
            });
        }
        if index == 0 {
            // One pass with the first position of each name: linear in the number of columns.
            let mut seen = std::collections::HashMap::with_capacity(header.len());
            for (second, &name) in header.iter().enumerate() {
                if let Some(&first) = seen.get(name) {
                    return Err(DataError::DuplicateColumn {
                        path: path.to_path_buf(),
                        row: line,
                        column: name.to_string(),
                        first: first + 1,
                        second: second + 1,
                    });
                }
                seen.insert(name, second);
            }
            continue;
        }
        let (fields, columns) = (cells.len(), header.len());
        if fields > columns {
            return Err(bad_row(
                line,
                &format!(
                    "{fields} fields, more than the {columns} columns of the header \
                     (a ',' in an unquoted cell, e.g. a decimal comma?)"
                ),
            ));
        } else if fields < columns {
            return Err(bad_row(
                line,
                &format!(
                    "too few fields: {fields} of the header's {columns}, no value for '{}'",
                    header[fields]
                ),
            ));
        }
        lines.push(line);
    }
    Ok(lines)
}

/// The offset in a record's `raw` bytes of a character that follows the closing quote of a
/// quoted cell without a ',' or the line's end in between, as in `"1"2` (which the csv crate
/// reads as `12`). A doubled quote inside a quoted cell is an escaped quote, not a closing one.
fn text_after_a_closing_quote(raw: &[u8]) -> Option<usize> {
    #[derive(PartialEq)]
    enum State {
        CellStart,
        Unquoted,
        Quoted,
        AfterQuote,
    }
    let mut state = State::CellStart;
    for (at, &byte) in raw.iter().enumerate() {
        state = match (state, byte) {
            (State::Quoted, b'"') => State::AfterQuote,
            (State::Quoted, _) | (State::AfterQuote, b'"') => State::Quoted,
            (State::AfterQuote, b'\n' | b'\r') => return None,
            (State::AfterQuote, b',') | (_, b',') => State::CellStart,
            (State::AfterQuote, _) => return Some(at),
            (State::CellStart, b'"') => State::Quoted,
            (_, b'\n' | b'\r') => return None,
            _ => State::Unquoted,
        };
    }
    None
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
    fn a_column_name_with_an_index_selects_an_element_unless_a_column_has_that_name() {
        let exists = |name: &str| ["v", "w[1]"].contains(&name);
        assert_eq!(
            ColumnRef::resolve("v[2]", exists),
            ColumnRef::Element {
                base: "v",
                index: 2
            }
        );
        assert_eq!(ColumnRef::resolve("w[1]", exists), ColumnRef::Whole("w[1]"));
        assert_eq!(ColumnRef::resolve("v", exists), ColumnRef::Whole("v"));
        for missing in ["u[0]", "v[]", "v[x]", "[0]", "v[-1]"] {
            assert_eq!(
                ColumnRef::resolve(missing, exists),
                ColumnRef::Whole(missing)
            );
        }
    }

    #[test]
    fn nan_parses_so_the_caller_can_name_it() {
        let mut out = Vec::new();
        parse_numbers("[NaN, inf]", &mut out).unwrap();
        assert!(out[0].is_nan() && out[1].is_infinite());
    }
}
