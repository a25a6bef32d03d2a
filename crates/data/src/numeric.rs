//! Plain numeric CSV files read by column name (for `learn sindy` on any data).

use std::path::{Path, PathBuf};

use crate::error::Result;
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
    pub fn read(path: &Path, columns: &[&str]) -> Result<Self> {
        Self::from_text(&TextTable::read(path)?, columns)
    }

    /// The named columns of a table already read.
    pub(crate) fn from_text(table: &TextTable, columns: &[&str]) -> Result<Self> {
        let parsed = columns
            .iter()
            .map(|name| table.numbers(name))
            .collect::<Result<Vec<_>>>()?;
        Ok(Self {
            path: table.path().to_path_buf(),
            names: columns.iter().map(|s| s.to_string()).collect(),
            columns: parsed,
            lines: table.lines().to_vec(),
        })
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
        let mut table = Self::read(path, &names)?;
        let time_values = table.columns.remove(0);
        table.names.remove(0);
        check_time_axis_at(path, time, &time_values, f64::INFINITY, &|k| table.line(k))?;
        Ok((time_values, table))
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

    /// A column by name.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.names
            .iter()
            .position(|n| n == name)
            .map(|i| self.columns[i].as_slice())
    }
}
