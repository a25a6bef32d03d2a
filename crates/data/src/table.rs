//! The whole-file CSV reader: the rows of [`CsvRecords`] (the splitter and layout checks shared
//! with the block reader, [`crate::NumericStream`]) kept as text, column by column, and parsed
//! into typed values on demand with errors that name the file, the line and the column.
//!
//! Reading every column as text (no schema inference) is deliberate: the list columns of the
//! Neural-Fly logs are strings such as `"[1.0, 2.0]"` anyway, and parsing numbers ourselves lets a bad
//! cell be reported at its exact line instead of silently turning a whole column into strings.
//! Each row keeps the line it starts on, so that errors name the right line after a cell that
//! spans lines.

use std::path::{Path, PathBuf};

use crate::cells::{bad_cell, cell_numbers, check_finite, column_list};
use crate::error::{DataError, Result};
use crate::motors::{MAX_MOTORS, MotorCommands};
use crate::records::{CsvRecords, Record};

/// Rows of a CSV file, every column kept as text, in file order.
pub struct TextTable {
    path: PathBuf,
    names: Vec<String>,
    columns: Vec<TextColumn>,
    /// The line of the file on which each data row starts (the header is line 1).
    lines: Vec<usize>,
}

/// The cells of one column end to end in one string, with where each ends: one allocation per
/// column, not per cell.
#[derive(Clone, Debug, Default)]
struct TextColumn {
    text: String,
    ends: Vec<usize>,
}

impl TextColumn {
    fn push(&mut self, cell: &str) {
        self.text.push_str(cell);
        self.ends.push(self.text.len());
    }

    /// The cells in row order.
    fn cells(&self) -> impl Iterator<Item = &str> {
        let starts = std::iter::once(0).chain(self.ends.iter().copied());
        starts
            .zip(&self.ends)
            .map(|(start, &end)| &self.text[start..end])
    }
}

/// A cell buffer longer than this is not kept for the next row: a long cell is then held by the
/// table alone.
const KEPT_CELL_BYTES: usize = 1 << 16;

/// The line of the file that holds data row `index` (0-based) when no cell spans lines; the header
/// is line 1. [`TextTable::line`] gives the exact line of any row.
pub fn file_row(index: usize) -> usize {
    index + 2
}

impl TextTable {
    /// Reads `path` (a file, or a pipe: the bytes are read, whatever the length reported) and checks
    /// its layout ([`CsvRecords`]). Errors name the file and the line.
    pub fn read(path: &Path) -> Result<Self> {
        if crate::columnar::is_parquet(path) {
            return Err(DataError::Config {
                path: path.to_path_buf(),
                field: "(Parquet)".into(),
                message: "read here as CSV text (a Neural-Fly log's list cells, a column of \
                          labels); a Parquet file is read by column name (learn sindy --csv, \
                          learn meta-train --tasks) or through a layout (--layout: \
                          docs/layouts.md)"
                    .into(),
            });
        }
        let mut records = CsvRecords::open(path)?;
        let names = records.header()?;
        let mut columns = vec![TextColumn::default(); names.len()];
        let mut lines = Vec::new();
        let mut record = Record::default();
        while records.next_row(&mut record, &names)? {
            for (column, cell) in columns.iter_mut().zip(&mut record.fields) {
                column.push(cell);
                if cell.capacity() > KEPT_CELL_BYTES {
                    *cell = String::new();
                }
            }
            lines.push(record.line);
        }
        if lines.is_empty() {
            return Err(DataError::Empty {
                path: path.to_path_buf(),
            });
        }
        Ok(Self {
            path: path.to_path_buf(),
            names,
            columns,
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
        self.names.clone()
    }

    /// The column names for an error message ([`column_list`]).
    pub fn column_list(&self) -> String {
        column_list(&self.names)
    }

    /// Whether a column of this name exists.
    pub fn has_column(&self, name: &str) -> bool {
        self.names.iter().any(|n| n == name)
    }

    /// The header's names, in file order.
    pub(crate) fn names(&self) -> &[String] {
        &self.names
    }

    /// The cells of field `field` (0-based) in row order.
    pub(crate) fn field_cells(&self, field: usize) -> impl Iterator<Item = &str> {
        self.columns[field].cells()
    }

    fn text_column(&self, name: &str) -> Result<&TextColumn> {
        let field = self.names.iter().position(|n| n == name);
        field
            .map(|field| &self.columns[field])
            .ok_or_else(|| DataError::MissingColumn {
                path: self.path.clone(),
                column: name.to_string(),
                present: self.column_list(),
            })
    }

    /// The cells of column `name` as text (labels, e.g. a task column); an empty cell is an error.
    pub fn labels(&self, name: &str) -> Result<Vec<String>> {
        let column = self.text_column(name)?;
        column
            .cells()
            .enumerate()
            .map(|(index, cell)| {
                if cell.is_empty() {
                    let line = self.line(index);
                    return Err(bad_cell(
                        &self.path,
                        line,
                        name,
                        cell,
                        "empty cell".to_string(),
                    ));
                }
                Ok(cell.to_string())
            })
            .collect()
    }

    /// Parses a column of plain numbers (a one-element list such as `[0.5]` is accepted too).
    pub fn scalars(&self, name: &str) -> Result<Vec<f64>> {
        Ok(self.arrays::<1>(name)?.into_iter().map(|[v]| v).collect())
    }

    /// Parses a column whose cells hold exactly `N` numbers, written `[a, b, ...]` (nested brackets,
    /// as in a 3x3 matrix, are flattened row by row).
    pub fn arrays<const N: usize>(&self, name: &str) -> Result<Vec<[f64; N]>> {
        let mut out = Vec::new();
        self.lists(
            name,
            |_| Ok(N),
            |values, rows| {
                if out.is_empty() {
                    out.reserve_exact(rows);
                }
                let mut array = [0.0; N];
                array.copy_from_slice(values);
                out.push(array);
            },
        )?;
        Ok(out)
    }

    /// Parses a column of motor commands, `[a, b, ...]`: as many values on every row as on the
    /// first, 1 to [`MAX_MOTORS`].
    pub fn motor_commands(&self, name: &str) -> Result<MotorCommands> {
        let first = |length: usize| {
            if (1..=MAX_MOTORS).contains(&length) {
                Ok(length)
            } else {
                Err(format!("{length} motors; expected 1 to {MAX_MOTORS}"))
            }
        };
        let mut out: Option<MotorCommands> = None;
        self.lists(name, first, |values, rows| {
            out.get_or_insert_with(|| MotorCommands::with_capacity(values.len(), rows))
                .push(values)
        })?;
        Ok(out.unwrap_or_default())
    }

    /// Reads every cell of column `name` as a list of finite numbers, each as long as `length`
    /// says from the first list's length (its error refuses the first cell), and gives each list
    /// with the column's row count to `take`, in order. Errors name the file, line and column.
    fn lists(
        &self,
        name: &str,
        length: impl FnOnce(usize) -> std::result::Result<usize, String>,
        mut take: impl FnMut(&[f64], usize),
    ) -> Result<()> {
        let column = self.text_column(name)?;
        let rows = column.ends.len();
        let mut buffer = Vec::new();
        let mut length = Some(length);
        let mut expected = 0;
        for (index, cell) in column.cells().enumerate() {
            let row = self.line(index);
            cell_numbers(&self.path, row, name, cell, &mut buffer)?;
            if let Some(length) = length.take() {
                expected = length(buffer.len())
                    .map_err(|reason| bad_cell(&self.path, row, name, cell, reason))?;
            }
            if buffer.len() != expected {
                return Err(DataError::WrongLength {
                    path: self.path.clone(),
                    row,
                    column: name.to_string(),
                    expected,
                    found: buffer.len(),
                });
            }
            check_finite(&self.path, row, name, &buffer)?;
            take(&buffer, rows);
        }
        Ok(())
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

#[cfg(test)]
mod tests {
    use super::*;

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
}
