//! Plain numeric CSV files read by column name (for `learn sindy` on any data).

use std::path::{Path, PathBuf};

use crate::cells::NumericColumn;
use crate::error::{DataError, Result};
use crate::records::CsvRecords;
use crate::stream::NumericRows;
use crate::table::TextTable;
use crate::time::check_time_axis_at;

/// Selected columns of a numeric CSV, validated (every cell a finite number).
#[derive(Clone, Debug)]
pub struct NumericTable {
    pub path: PathBuf,
    pub names: Vec<String>,
    pub columns: Vec<Vec<f64>>,
    /// The line of the file on which each row starts (the header is line 1).
    lines: Vec<usize>,
}

impl NumericTable {
    /// Reads the named columns of `path`, in the order given. A name `v[k]` that is not a column
    /// of the file reads element k of the list cells of column `v` ([`crate::ColumnRef`]).
    ///
    /// The rows are read as [`crate::NumericStream`] reads them, by the same code from a source
    /// read once (a file or a pipe, at most [`bounded_read::MAX_CSV_BYTES`]): the same values, or the
    /// same first error in file order.
    ///
    /// A Parquet file ([`crate::is_parquet`]) is read by [`crate::NumericStream`]'s Parquet
    /// reader; its rows are numbered from 1 in place of lines.
    pub fn read(path: &Path, columns: &[&str]) -> Result<Self> {
        if crate::columnar::is_parquet(path) {
            return Self::from_parquet(path, columns);
        }
        Self::from_records(path, CsvRecords::open(path)?, columns)
    }

    /// Every row of the named columns of a Parquet file.
    fn from_parquet(path: &Path, columns: &[&str]) -> Result<Self> {
        let mut stream = crate::NumericStream::open(path, columns)?;
        let block = stream
            .next_block(usize::MAX)?
            .expect("a file without rows is an error");
        Ok(Self::from_columns(
            path,
            columns.iter().map(|s| s.to_string()).collect(),
            block.columns,
            block.lines,
        ))
    }

    /// The named columns of every row `records` (of `path`) holds.
    fn from_records<R: std::io::BufRead>(
        path: &Path,
        records: CsvRecords<R>,
        columns: &[&str],
    ) -> Result<Self> {
        let mut rows = NumericRows::new(path, records, columns)?;
        let block = rows
            .next_block(usize::MAX)?
            .expect("a file without rows is an error");
        Ok(Self {
            path: path.to_path_buf(),
            names: columns.iter().map(|s| s.to_string()).collect(),
            columns: block.columns,
            lines: block.lines,
        })
    }

    /// [`NumericTable::read`] of a file whose header line begins with `prefix`, which is not part
    /// of the first column's name (a header written as a comment, `# a,b,c`, as numpy's `savetxt`
    /// writes it); the error names the file when its first line does not begin so.
    pub fn read_after_header_prefix(path: &Path, prefix: &str, columns: &[&str]) -> Result<Self> {
        use std::io::BufRead;
        if crate::columnar::is_parquet(path) {
            return Err(DataError::Config {
                path: path.to_path_buf(),
                field: "header_prefix".into(),
                message: "a Parquet file has no header line (remove header_prefix)".into(),
            });
        }
        let io = |source| DataError::Io {
            path: path.to_path_buf(),
            source,
        };
        let file = bounded_read::open(path, bounded_read::InputKind::Csv).map_err(io)?;
        let mut input = std::io::BufReader::with_capacity(1 << 16, file);
        let start = input.fill_buf().map_err(io)?;
        if !start.starts_with(prefix.as_bytes()) {
            return Err(DataError::Config {
                path: path.to_path_buf(),
                field: "header_prefix".into(),
                message: format!("the file's first line does not begin with {prefix:?}"),
            });
        }
        input.consume(prefix.len());
        Self::from_records(path, CsvRecords::new(path, input), columns)
    }

    /// The named columns of a table already read, parsed row by row (as [`crate::NumericStream`]
    /// reads them, so that the first bad cell named is the same).
    pub(crate) fn from_text(table: &TextTable, columns: &[&str]) -> Result<Self> {
        let path = table.path();
        let selected = NumericColumn::resolve(path, table.names(), columns)?;
        let mut cells: Vec<_> = selected
            .iter()
            .map(|column| table.field_cells(column.field))
            .collect();
        let mut parsed = vec![Vec::with_capacity(table.lines().len()); selected.len()];
        let mut buffer = Vec::new();
        for &line in table.lines() {
            for ((column, cells), values) in selected.iter().zip(&mut cells).zip(&mut parsed) {
                let cell = cells.next().expect("every column has a cell per row");
                values.push(column.number(path, line, cell, &mut buffer)?);
            }
        }
        Ok(Self {
            path: path.to_path_buf(),
            names: columns.iter().map(|s| s.to_string()).collect(),
            columns: parsed,
            lines: table.lines().to_vec(),
        })
    }

    /// A table of columns already read elsewhere (a ULog's), each row's "line" given.
    pub(crate) fn from_columns(
        path: &Path,
        names: Vec<String>,
        columns: Vec<Vec<f64>>,
        lines: Vec<usize>,
    ) -> Self {
        Self {
            path: path.to_path_buf(),
            names,
            columns,
            lines,
        }
    }

    /// The rows `rows` of every column, each keeping its line of the file.
    pub fn rows_subset(&self, rows: std::ops::Range<usize>) -> Self {
        Self {
            path: self.path.clone(),
            names: self.names.clone(),
            columns: self
                .columns
                .iter()
                .map(|c| c[rows.clone()].to_vec())
                .collect(),
            lines: (rows.start..rows.end).map(|row| self.line(row)).collect(),
        }
    }

    /// Reads the named columns and checks that `time` is a strictly increasing, uniform time axis.
    pub fn read_with_time(path: &Path, time: &str, columns: &[&str]) -> Result<(Vec<f64>, Self)> {
        let mut names = vec![time];
        names.extend_from_slice(columns);
        let mut table = Self::read(path, &names)?;
        let time_values = table.columns.remove(0);
        table.names.remove(0);
        check_time_axis_at(
            path,
            time,
            &time_values,
            crate::time::DEFAULT_UNIFORM_TOLERANCE,
            &|k| table.line(k),
        )?;
        Ok((time_values, table))
    }

    /// Reads the named columns and checks that `time` is strictly increasing, with at least two
    /// samples; its steps may vary (for estimators that use the true time stamps).
    pub fn read_with_increasing_time(
        path: &Path,
        time: &str,
        columns: &[&str],
    ) -> Result<(Vec<f64>, Self)> {
        let mut names = vec![time];
        names.extend_from_slice(columns);
        Self::read(path, &names)?.split_increasing_time()
    }

    /// The first column, checked as a strictly increasing time axis (its steps may vary), and the
    /// table of the others.
    pub(crate) fn split_increasing_time(mut self) -> Result<(Vec<f64>, Self)> {
        let time = self.columns.remove(0);
        let name = self.names.remove(0);
        check_time_axis_at(&self.path, &name, &time, f64::INFINITY, &|k| self.line(k))?;
        Ok((time, self))
    }

    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.columns.first().map_or(0, Vec::len)
    }

    /// The line of the file on which row `index` (0-based) starts; the header is line 1.
    pub fn line(&self, index: usize) -> usize {
        self.lines
            .get(index)
            .copied()
            .unwrap_or(crate::table::file_row(index))
    }

    /// Rows `range` only, each keeping its line (`None` when the range reaches past the rows).
    pub fn rows_in(&self, range: std::ops::Range<usize>) -> Option<Self> {
        if range.start > range.end || range.end > self.rows() {
            return None;
        }
        Some(Self {
            path: self.path.clone(),
            names: self.names.clone(),
            columns: self
                .columns
                .iter()
                .map(|c| c[range.clone()].to_vec())
                .collect(),
            lines: range.map(|k| self.line(k)).collect(),
        })
    }

    /// A column by name.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.names
            .iter()
            .position(|n| n == name)
            .map(|i| self.columns[i].as_slice())
    }
}
