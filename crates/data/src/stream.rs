//! Named numeric columns of a CSV file read a block of rows at a time, in memory bounded by the
//! block, for recordings too long to hold whole (see [`NumericTable`](crate::NumericTable) for
//! files that fit). The same layout rules as the whole-file reader: a header of unique names,
//! every row as wide as the header, one line per row, plain numbers in the named columns (or one
//! element `v[k]` of a list column, as [`crate::ColumnRef`]); errors name the file, line and column.

use std::fs::File;
use std::io::BufReader;
use std::path::{Path, PathBuf};

use crate::error::{DataError, Result};
use crate::table::{ColumnRef, parse_numbers};
use inputs::MAX_CSV_COLUMNS;

/// A reader of named numeric columns, row blocks in file order.
pub struct NumericStream {
    path: PathBuf,
    reader: csv::Reader<BufReader<File>>,
    names: Vec<String>,
    /// Field index of each named column, and the element of its list cells for a name `v[k]`
    /// ([`crate::ColumnRef::Element`]).
    indices: Vec<(usize, Option<usize>)>,
    width: usize,
    record: csv::StringRecord,
    /// Rows returned so far.
    rows: usize,
}

/// Consecutive rows of the named columns.
#[derive(Clone, Debug, Default)]
pub struct NumericBlock {
    /// One vector per named column, in the order named.
    pub columns: Vec<Vec<f64>>,
    /// The index of the block's first row in the file (0-based, header excluded).
    pub first_row: usize,
}

impl NumericBlock {
    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.columns.first().map_or(0, Vec::len)
    }
}

impl NumericStream {
    /// Opens `path` (a regular file) and finds `columns` in its header.
    pub fn open(path: &Path, columns: &[&str]) -> Result<Self> {
        let io = |source| DataError::Io {
            path: path.to_path_buf(),
            source,
        };
        let metadata = std::fs::metadata(path).map_err(io)?;
        if metadata.is_dir() {
            return Err(DataError::IsDirectory {
                path: path.to_path_buf(),
            });
        }
        if !metadata.is_file() {
            return Err(io(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "not a regular file: a recording read in blocks must be a file",
            )));
        }
        let file = File::open(path).map_err(io)?;
        // Records end at '\n' only, so that the line count is exact with '\r\n' line ends too
        // (each record's last field then ends in '\r', dropped below).
        let mut reader = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .terminator(csv::Terminator::Any(b'\n'))
            .from_reader(BufReader::with_capacity(1 << 20, file));
        let mut header = csv::StringRecord::new();
        let csv_error = |error: csv::Error| DataError::Csv {
            path: path.to_path_buf(),
            message: error.to_string(),
        };
        if !reader.read_record(&mut header).map_err(csv_error)? {
            return Err(DataError::Empty {
                path: path.to_path_buf(),
            });
        }
        let names: Vec<String> = header
            .iter()
            .enumerate()
            .map(|(i, name)| {
                let name = if i == 0 {
                    name.trim_start_matches('\u{feff}')
                } else {
                    name
                };
                name.strip_suffix('\r').unwrap_or(name).to_string()
            })
            .collect();
        if names.len() > MAX_CSV_COLUMNS {
            return Err(DataError::BadRow {
                path: path.to_path_buf(),
                row: 1,
                message: format!(
                    "{} columns, more than the {MAX_CSV_COLUMNS} a CSV may have",
                    names.len()
                ),
            });
        }
        let position = |name: &str| names.iter().position(|n| n == name);
        let indices = columns
            .iter()
            .map(|column| {
                let (field, element) =
                    match ColumnRef::resolve(column, |name| position(name).is_some()) {
                        ColumnRef::Whole(name) => (name, None),
                        ColumnRef::Element { base, index } => (base, Some(index)),
                    };
                position(field)
                    .map(|index| (index, element))
                    .ok_or_else(|| DataError::MissingColumn {
                        path: path.to_path_buf(),
                        column: column.to_string(),
                        present: names.join(", "),
                    })
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Self {
            path: path.to_path_buf(),
            reader,
            width: names.len(),
            names: columns.iter().map(|c| c.to_string()).collect(),
            indices,
            record: csv::StringRecord::new(),
            rows: 0,
        })
    }

    /// The next block of at most `max_rows` rows; `None` at the end of the file.
    pub fn next_block(&mut self, max_rows: usize) -> Result<Option<NumericBlock>> {
        let mut block = NumericBlock {
            columns: vec![Vec::with_capacity(max_rows.min(1 << 16)); self.indices.len()],
            first_row: self.rows,
        };
        let mut values = Vec::with_capacity(1);
        while block.rows() < max_rows {
            let read =
                self.reader
                    .read_record(&mut self.record)
                    .map_err(|error| DataError::Csv {
                        path: self.path.clone(),
                        message: error.to_string(),
                    })?;
            if !read {
                break;
            }
            // One line per row: row k (0-based) is on line k + 2.
            let line = self.rows + 2;
            let at_line = self.record.position().map_or(line as u64, |p| p.line()) as usize;
            if at_line != line || self.record.len() != self.width {
                return Err(DataError::BadRow {
                    path: self.path.clone(),
                    row: at_line,
                    message: format!(
                        "expected one line of {} fields (as the header), found {} fields{}",
                        self.width,
                        self.record.len(),
                        if at_line != line {
                            " after a blank, comment or multi-line row"
                        } else {
                            ""
                        }
                    ),
                });
            }
            for (k, &(index, element)) in self.indices.iter().enumerate() {
                let cell = &self.record[index];
                let cell = cell.strip_suffix('\r').unwrap_or(cell);
                values.clear();
                let parsed = parse_numbers(cell, &mut values);
                let selected = match element {
                    None => values.as_slice(),
                    Some(element) if parsed.is_ok() => {
                        let Some(value) = values.get(element) else {
                            let reason =
                                format!("{} value(s), no element [{element}]", values.len());
                            return Err(self.bad_cell(line, k, cell, &reason));
                        };
                        std::slice::from_ref(value)
                    }
                    Some(_) => &[],
                };
                let value = match (parsed, selected) {
                    (Ok(()), [value]) if value.is_finite() => *value,
                    (Ok(()), [value]) => {
                        return Err(DataError::NonFinite {
                            path: self.path.clone(),
                            row: line,
                            column: self.names[k].clone(),
                            value: value.to_string(),
                        });
                    }
                    (Err(reason), _) => return Err(self.bad_cell(line, k, cell, &reason)),
                    (Ok(()), _) => {
                        return Err(self.bad_cell(line, k, cell, "expected one number"));
                    }
                };
                block.columns[k].push(value);
            }
            self.rows += 1;
        }
        Ok((block.rows() > 0).then_some(block))
    }

    fn bad_cell(&self, line: usize, column: usize, value: &str, reason: &str) -> DataError {
        DataError::BadCell {
            path: self.path.clone(),
            row: line,
            column: self.names[column].clone(),
            value: value.to_string(),
            reason: if value.is_empty() {
                "empty cell".to_string()
            } else {
                reason.to_string()
            },
        }
    }
}
