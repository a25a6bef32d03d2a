//! Named numeric columns of a Parquet file, a block of rows at a time (the `parquet` crate's
//! column readers, the columns of a block decoded in parallel), with the checks and messages of
//! the CSV readers: a missing column lists the file's, and a null or non-finite value is named by
//! `file:row:column`, the row counted from 1 (a Parquet file has no header line). Top-level
//! columns of doubles, floats or integers are read; a list, a text, a decimal or a codec this
//! build does not decode is refused by name.

use std::fs::File;
use std::io::{BufReader, Read};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use parquet::basic::{Compression, ConvertedType, Type as PhysicalType};
use parquet::column::reader::{ColumnReader, ColumnReaderImpl};
use parquet::data_type::DataType;
use parquet::file::reader::{ChunkReader, FileReader, Length, SerializedFileReader};
use rayon::prelude::*;

use crate::cells::column_list;
use crate::error::{DataError, Result};
use crate::stream::NumericBlock;

/// The bytes a Parquet file begins (and ends) with.
const MAGIC: &[u8; 4] = b"PAR1";

/// Whether `path` is a Parquet file: a regular file that begins with Parquet's magic bytes
/// (whatever its name). A CSV cannot begin so and be read as one.
pub fn is_parquet(path: &Path) -> bool {
    let mut start = [0u8; 4];
    path.is_file()
        && File::open(path)
            .and_then(|mut file| file.read_exact(&mut start))
            .is_ok()
        && &start == MAGIC
}

/// A file read at given offsets without a shared position (`pread`), so that the column readers
/// of a row group can decode in parallel: `File`'s own reader seeks a position its clones share.
struct PositionedFile {
    file: Arc<File>,
    length: u64,
}

/// A reader of a [`PositionedFile`] from an offset.
struct PositionedRead {
    file: Arc<File>,
    position: u64,
}

impl Read for PositionedRead {
    fn read(&mut self, buffer: &mut [u8]) -> std::io::Result<usize> {
        let read = read_at(&self.file, buffer, self.position)?;
        self.position += read as u64;
        Ok(read)
    }
}

#[cfg(unix)]
fn read_at(file: &File, buffer: &mut [u8], offset: u64) -> std::io::Result<usize> {
    std::os::unix::fs::FileExt::read_at(file, buffer, offset)
}

#[cfg(windows)]
fn read_at(file: &File, buffer: &mut [u8], offset: u64) -> std::io::Result<usize> {
    std::os::windows::fs::FileExt::seek_read(file, buffer, offset)
}

impl Length for PositionedFile {
    fn len(&self) -> u64 {
        self.length
    }
}

impl ChunkReader for PositionedFile {
    type T = BufReader<PositionedRead>;

    fn get_read(&self, start: u64) -> parquet::errors::Result<Self::T> {
        Ok(BufReader::new(PositionedRead {
            file: Arc::clone(&self.file),
            position: start,
        }))
    }

    fn get_bytes(&self, start: u64, length: usize) -> parquet::errors::Result<bytes::Bytes> {
        let mut buffer = vec![0u8; length];
        let mut reader = PositionedRead {
            file: Arc::clone(&self.file),
            position: start,
        };
        reader.read_exact(&mut buffer)?;
        Ok(buffer.into())
    }
}

/// A column reader of the open row group, by the column's physical type.
enum Values {
    Double(ColumnReaderImpl<parquet::data_type::DoubleType>),
    Float(ColumnReaderImpl<parquet::data_type::FloatType>),
    Int32(ColumnReaderImpl<parquet::data_type::Int32Type>),
    Int64(ColumnReaderImpl<parquet::data_type::Int64Type>),
}

/// One named column: its index among the file's leaf columns and whether it may hold nulls.
#[derive(Clone, Debug)]
struct Selected {
    name: String,
    leaf: usize,
    optional: bool,
}

/// Named numeric columns of a Parquet file, read in row order a block at a time.
pub(crate) struct ParquetRows {
    path: PathBuf,
    file: SerializedFileReader<PositionedFile>,
    selected: Vec<Selected>,
    /// The next row group to open.
    next_group: usize,
    /// The open row group's readers (one per selected column) and its rows not yet read.
    readers: Vec<Values>,
    left_in_group: usize,
    /// Rows returned so far.
    returned: usize,
}

impl ParquetRows {
    /// Opens `path` and finds `columns` among its top-level columns.
    pub(crate) fn open(path: &Path, columns: &[&str]) -> Result<Self> {
        let io = |source| DataError::Io {
            path: path.to_path_buf(),
            source,
        };
        let file = File::open(path).map_err(io)?;
        let length = file.metadata().map_err(io)?.len();
        let file = PositionedFile {
            file: Arc::new(file),
            length,
        };
        let file = SerializedFileReader::new(file).map_err(|error| parquet_error(path, error))?;
        let selected = select_columns(path, &file, columns)?;
        check_codecs(path, &file, &selected)?;
        Ok(Self {
            path: path.to_path_buf(),
            file,
            selected,
            next_group: 0,
            readers: Vec::new(),
            left_in_group: 0,
            returned: 0,
        })
    }

    /// The next block of at most `max_rows` rows (across row groups); `None` after the last. A
    /// file without rows is an error, as for a CSV.
    pub(crate) fn next_block(&mut self, max_rows: usize) -> Result<Option<NumericBlock>> {
        let mut block = NumericBlock {
            columns: vec![Vec::new(); self.selected.len()],
            lines: Vec::new(),
            first_row: self.returned,
        };
        while block.lines.len() < max_rows {
            if self.left_in_group == 0 && !self.open_next_group()? {
                break;
            }
            let count = self.left_in_group.min(max_rows - block.lines.len());
            let first = self.returned + block.lines.len();
            let columns = self.read_rows(count, first)?;
            for (all, part) in block.columns.iter_mut().zip(columns) {
                all.extend(part);
            }
            block.lines.extend(first + 1..first + count + 1);
            self.left_in_group -= count;
        }
        if block.lines.is_empty() {
            if self.returned == 0 {
                return Err(DataError::Empty {
                    path: self.path.clone(),
                });
            }
            return Ok(None);
        }
        self.returned += block.lines.len();
        Ok(Some(block))
    }

    /// Opens the next row group with rows; `false` after the last.
    fn open_next_group(&mut self) -> Result<bool> {
        while self.next_group < self.file.num_row_groups() {
            let group = self.next_group;
            self.next_group += 1;
            let rows = self.file.metadata().row_group(group).num_rows();
            let reader = self
                .file
                .get_row_group(group)
                .map_err(|error| parquet_error(&self.path, error))?;
            self.readers = (self.selected.iter())
                .map(|column| match reader.get_column_reader(column.leaf) {
                    Ok(ColumnReader::DoubleColumnReader(values)) => Ok(Values::Double(values)),
                    Ok(ColumnReader::FloatColumnReader(values)) => Ok(Values::Float(values)),
                    Ok(ColumnReader::Int32ColumnReader(values)) => Ok(Values::Int32(values)),
                    Ok(ColumnReader::Int64ColumnReader(values)) => Ok(Values::Int64(values)),
                    Ok(_) => Err(not_numeric(&self.path, &column.name)),
                    Err(error) => Err(parquet_error(&self.path, error)),
                })
                .collect::<Result<_>>()?;
            self.left_in_group = usize::try_from(rows).unwrap_or(0);
            if self.left_in_group > 0 {
                return Ok(true);
            }
        }
        Ok(false)
    }

    /// `count` rows of every selected column of the open group (the columns decoded in
    /// parallel), checked: the first null or non-finite value in row order is the error.
    fn read_rows(&mut self, count: usize, first: usize) -> Result<Vec<Vec<f64>>> {
        let path = &self.path;
        let read: Vec<(Vec<f64>, Option<RowFault>)> = (self.readers.par_iter_mut())
            .zip(&self.selected)
            .map(|(values, column)| {
                let decoded = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                    values.read(count, column.optional)
                }));
                let values = match decoded {
                    Ok(Ok(values)) => values,
                    Ok(Err(message)) => return Err(corrupt(path, &column.name, message)),
                    Err(_) => return Err(corrupt(path, &column.name, "a page cannot be decoded")),
                };
                if values.len() < count {
                    return Err(corrupt(path, &column.name, "fewer values than rows"));
                }
                let fault = first_fault(&values);
                Ok((values.into_iter().map(|(value, _)| value).collect(), fault))
            })
            .collect::<Result<_>>()?;
        let first_fault = (read.iter().zip(&self.selected))
            .filter_map(|((_, fault), column)| fault.map(|(row, fault)| (row, column, fault)))
            .min_by_key(|(row, ..)| *row);
        if let Some((row, column, fault)) = first_fault {
            return Err(fault.error(path, first + row + 1, &column.name));
        }
        Ok(read.into_iter().map(|(values, _)| values).collect())
    }
}

/// A column's first faulty row in a block, and its fault.
type RowFault = (usize, Fault);

/// What is wrong with a value.
#[derive(Clone, Copy, Debug)]
enum Fault {
    Null,
    NotFinite(f64),
}

impl Fault {
    fn error(self, path: &Path, row: usize, column: &str) -> DataError {
        match self {
            Fault::Null => DataError::NonFinite {
                path: path.to_path_buf(),
                row,
                column: column.to_string(),
                value: "null".to_string(),
            },
            Fault::NotFinite(value) => DataError::NonFinite {
                path: path.to_path_buf(),
                row,
                column: column.to_string(),
                value: value.to_string(),
            },
        }
    }
}

/// The first row whose value is missing or not finite.
fn first_fault(values: &[(f64, bool)]) -> Option<RowFault> {
    (values.iter().enumerate()).find_map(|(row, &(value, present))| match present {
        false => Some((row, Fault::Null)),
        true => (!value.is_finite()).then_some((row, Fault::NotFinite(value))),
    })
}

impl Values {
    /// The next `count` values, each with whether it is present (not null).
    fn read(
        &mut self,
        count: usize,
        optional: bool,
    ) -> std::result::Result<Vec<(f64, bool)>, String> {
        match self {
            Values::Double(reader) => read_typed(reader, count, optional, |&v| v),
            Values::Float(reader) => read_typed(reader, count, optional, |&v| f64::from(v)),
            Values::Int32(reader) => read_typed(reader, count, optional, |&v| f64::from(v)),
            Values::Int64(reader) => read_typed(reader, count, optional, |&v| v as f64),
        }
    }
}

/// `count` records of one column as numbers, a null where its definition level says so.
fn read_typed<T: DataType>(
    reader: &mut ColumnReaderImpl<T>,
    count: usize,
    optional: bool,
    number: impl Fn(&T::T) -> f64,
) -> std::result::Result<Vec<(f64, bool)>, String>
where
    T::T: Clone,
{
    let mut values = Vec::with_capacity(count);
    let mut levels = Vec::with_capacity(if optional { count } else { 0 });
    let mut records = 0;
    while records < count {
        let levels_out = optional.then_some(&mut levels);
        let (read, _, _) = (reader.read_records(count - records, levels_out, None, &mut values))
            .map_err(|error| error.to_string())?;
        if read == 0 {
            break;
        }
        records += read;
    }
    if !optional {
        return Ok(values.iter().map(|value| (number(value), true)).collect());
    }
    let mut present = values.iter();
    Ok(levels
        .iter()
        .map(|&level| match level > 0 {
            true => present
                .next()
                .map_or((0.0, false), |value| (number(value), true)),
            false => (0.0, false),
        })
        .collect())
}

/// The leaf column of each of `columns`, refusing one the file lacks or cannot give as numbers.
fn select_columns(
    path: &Path,
    file: &SerializedFileReader<PositionedFile>,
    columns: &[&str],
) -> Result<Vec<Selected>> {
    let schema = file.metadata().file_metadata().schema_descr();
    let leaves = schema.columns();
    let names: Vec<String> = leaves.iter().map(|leaf| leaf.path().string()).collect();
    columns
        .iter()
        .map(|&name| {
            let leaf =
                names
                    .iter()
                    .position(|n| n == name)
                    .ok_or_else(|| DataError::MissingColumn {
                        path: path.to_path_buf(),
                        column: name.to_string(),
                        present: column_list(&names),
                    })?;
            let descriptor = &leaves[leaf];
            let numeric = matches!(
                descriptor.physical_type(),
                PhysicalType::DOUBLE
                    | PhysicalType::FLOAT
                    | PhysicalType::INT32
                    | PhysicalType::INT64
            );
            if descriptor.max_rep_level() > 0 || !numeric {
                return Err(not_numeric(path, name));
            }
            if descriptor.converted_type() == ConvertedType::DECIMAL {
                return Err(DataError::Config {
                    path: path.to_path_buf(),
                    field: name.to_string(),
                    message: "a decimal column (store it as double)".into(),
                });
            }
            Ok(Selected {
                name: name.to_string(),
                leaf,
                optional: descriptor.max_def_level() > 0,
            })
        })
        .collect()
}

/// Refuses a selected column compressed by a codec this build does not decode.
fn check_codecs(
    path: &Path,
    file: &SerializedFileReader<PositionedFile>,
    selected: &[Selected],
) -> Result<()> {
    for group in file.metadata().row_groups() {
        for column in selected {
            let codec = group.column(column.leaf).compression();
            let known = matches!(
                codec,
                Compression::UNCOMPRESSED
                    | Compression::SNAPPY
                    | Compression::ZSTD(_)
                    | Compression::LZ4
                    | Compression::LZ4_RAW
            );
            if !known {
                return Err(DataError::Config {
                    path: path.to_path_buf(),
                    field: column.name.clone(),
                    message: format!(
                        "compressed with {codec}, which this build does not read (it reads \
                         uncompressed, snappy, zstd and lz4 Parquet)"
                    ),
                });
            }
        }
    }
    Ok(())
}

fn not_numeric(path: &Path, column: &str) -> DataError {
    DataError::Config {
        path: path.to_path_buf(),
        field: column.to_string(),
        message: "not a column of numbers (doubles, floats or integers, one per row)".into(),
    }
}

fn corrupt(path: &Path, column: &str, message: impl std::fmt::Display) -> DataError {
    DataError::Config {
        path: path.to_path_buf(),
        field: column.to_string(),
        message: format!("cannot be decoded: {message}"),
    }
}

fn parquet_error(path: &Path, error: parquet::errors::ParquetError) -> DataError {
    DataError::Config {
        path: path.to_path_buf(),
        field: "(Parquet)".into(),
        message: error.to_string(),
    }
}

/// Rows of one row group written by [`write_numeric_parquet`].
const WRITTEN_GROUP_ROWS: usize = 1 << 16;

/// Writes named numeric columns of equal length as a Parquet file (required doubles, snappy, row
/// groups of 65,536 rows): what [`crate::NumericTable::read`] and [`crate::NumericStream`] read
/// back, bit for bit.
pub fn write_numeric_parquet(path: &Path, names: &[String], columns: &[Vec<f64>]) -> Result<()> {
    use parquet::basic::Repetition;
    use parquet::data_type::DoubleType;
    use parquet::file::properties::WriterProperties;
    use parquet::file::writer::SerializedFileWriter;
    use parquet::schema::types::Type;

    let failed = |error: parquet::errors::ParquetError| parquet_error(path, error);
    let fields = (names.iter())
        .map(|name| {
            Type::primitive_type_builder(name, PhysicalType::DOUBLE)
                .with_repetition(Repetition::REQUIRED)
                .build()
                .map(Arc::new)
        })
        .collect::<parquet::errors::Result<Vec<_>>>()
        .map_err(failed)?;
    let schema = Type::group_type_builder("schema")
        .with_fields(fields)
        .build()
        .map_err(failed)?;
    let properties = WriterProperties::builder()
        .set_compression(Compression::SNAPPY)
        .build();
    let file = File::create(path).map_err(|source| DataError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let mut writer =
        SerializedFileWriter::new(file, Arc::new(schema), Arc::new(properties)).map_err(failed)?;
    let rows = columns.first().map_or(0, Vec::len);
    for start in (0..rows).step_by(WRITTEN_GROUP_ROWS) {
        let end = (start + WRITTEN_GROUP_ROWS).min(rows);
        let mut group = writer.next_row_group().map_err(failed)?;
        for values in columns {
            let Some(mut column) = group.next_column().map_err(failed)? else {
                break;
            };
            (column.typed::<DoubleType>())
                .write_batch(&values[start..end], None, None)
                .map_err(failed)?;
            column.close().map_err(failed)?;
        }
        group.close().map_err(failed)?;
    }
    writer.close().map_err(failed)?;
    Ok(())
}
