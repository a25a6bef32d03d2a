//! Named numeric columns of a CSV file read a block of rows at a time, in memory bounded by the
//! block and a chunk of the file per thread (and the longest row), for recordings too long to hold
//! whole (see [`NumericTable`](crate::NumericTable) for files that fit). Each chunk is cut into
//! pieces parsed in parallel ([`crate::chunked`]). The rows come from the same splitter
//! and layout checks as the whole-file reader's ([`CsvRecords`]) and the cells are read by the same
//! code ([`NumericColumn`]): a file is read by both or by neither, to the same values, and a fault
//! is named by the same `file:line:column` message. [`NumericStream::read_ahead`] reads the same
//! blocks on a thread of its own, so that parsing overlaps the work done on the blocks before.

use std::fs::File;
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{Receiver, sync_channel};
use std::thread::JoinHandle;

use crate::cells::NumericColumn;
use crate::chunked::{CHUNK_BYTES_PER_THREAD, ChunkedRows, ParsedRows, row_numbers};
use crate::columnar::ParquetRows;
use crate::error::{DataError, Result};
use crate::records::{CsvRecords, Record};

/// A reader of named numeric columns of a regular file, row blocks in file order: a CSV (each
/// chunk of the file parsed in parallel pieces: [`crate::chunked`]) or a Parquet file (its column
/// chunks decoded in parallel: [`crate::columnar`]).
pub struct NumericStream {
    source: StreamSource,
}

/// What a [`NumericStream`] reads.
enum StreamSource {
    Csv(Box<CsvBlocks>),
    Parquet(Box<ParquetRows>),
}

/// The rows of a CSV, parsed a chunk at a time.
struct CsvBlocks {
    rows: ChunkedRows,
    parsed: ParsedRows,
    /// Rows of `parsed` handed out already.
    taken: usize,
    /// Rows returned so far.
    returned: usize,
}

/// Named numeric columns read from any text source, row by row: the code of both readers.
pub(crate) struct NumericRows<R> {
    path: PathBuf,
    records: CsvRecords<R>,
    header: Vec<String>,
    columns: Vec<NumericColumn>,
    record: Record,
    /// Rows returned so far.
    rows: usize,
}

/// Consecutive rows of the named columns.
#[derive(Clone, Debug, Default)]
pub struct NumericBlock {
    /// One vector per named column, in the order named.
    pub columns: Vec<Vec<f64>>,
    /// The line of the file on which each row starts (the header is line 1).
    pub lines: Vec<usize>,
    /// The index of the block's first row in the file (0-based, header excluded).
    pub first_row: usize,
}

impl NumericBlock {
    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.lines.len()
    }
}

impl NumericStream {
    /// Opens `path` (a regular file: a CSV, or a Parquet file whatever its name,
    /// [`crate::is_parquet`]) and finds `columns` in its header or schema.
    pub fn open(path: &Path, columns: &[&str]) -> Result<Self> {
        let chunk_bytes = CHUNK_BYTES_PER_THREAD * rayon::current_num_threads().max(1);
        Self::open_in_chunks(path, columns, chunk_bytes)
    }

    /// [`Self::open`], reading `chunk_bytes` of the file at a time (cut into pieces parsed in
    /// parallel): the rows and errors are the same whatever the size.
    pub fn open_in_chunks(path: &Path, columns: &[&str], chunk_bytes: usize) -> Result<Self> {
        check_regular_file(path)?;
        if crate::columnar::is_parquet(path) {
            let rows = ParquetRows::open(path, columns)?;
            return Ok(Self {
                source: StreamSource::Parquet(Box::new(rows)),
            });
        }
        let rows = ChunkedRows::open(path, columns, chunk_bytes)?;
        Ok(Self {
            source: StreamSource::Csv(Box::new(CsvBlocks {
                parsed: ParsedRows::new(rows.width()),
                rows,
                taken: 0,
                returned: 0,
            })),
        })
    }

    /// The next block of at most `max_rows` rows; `None` at the end of the file. A file without
    /// data rows is an error, as for the whole-file reader; in a CSV, the rows before a fault are
    /// returned before it (in a Parquet file, the block holding a fault is the error). A Parquet
    /// file's "lines" are its rows counted from 1.
    pub fn next_block(&mut self, max_rows: usize) -> Result<Option<NumericBlock>> {
        match &mut self.source {
            StreamSource::Csv(csv) => csv.next_block(max_rows),
            StreamSource::Parquet(parquet) => parquet.next_block(max_rows),
        }
    }

    /// The same blocks of at most `max_rows` rows, read on a thread of its own while the caller
    /// works: at most `blocks` of them wait to be taken (memory is bounded by those), and the
    /// first error ends the stream after the blocks before it, as [`Self::next_block`] does.
    pub fn read_ahead(mut self, max_rows: usize, blocks: usize) -> ReadAhead {
        let (sender, receiver) = sync_channel(blocks.max(1));
        let reader = std::thread::spawn(move || {
            loop {
                let item = self.next_block(max_rows);
                let last = !matches!(item, Ok(Some(_)));
                // A receiver gone (the caller stopped early) ends the reading too.
                if sender.send(item).is_err() || last {
                    return;
                }
            }
        });
        ReadAhead {
            receiver: Some(receiver),
            reader: Some(reader),
            ended: false,
        }
    }

    /// The line of the file on which data row `row` (0-based) starts, found by reading the file
    /// again to that row (for an error about a row found after its block was dropped); `None` if
    /// the file no longer has that row.
    pub fn line_of_row(path: &Path, row: usize) -> Option<usize> {
        if crate::columnar::is_parquet(path) {
            return Some(row + 1);
        }
        let mut records = open_records(path).ok()?;
        let header = records.header().ok()?;
        let mut record = Record::default();
        for _ in 0..=row {
            if !records.next_row(&mut record, &header).ok()? {
                return None;
            }
        }
        Some(record.line)
    }
}

impl CsvBlocks {
    /// [`NumericStream::next_block`] of a CSV.
    fn next_block(&mut self, max_rows: usize) -> Result<Option<NumericBlock>> {
        while self.parsed.lines.len() - self.taken < max_rows
            && self.parsed.error.is_none()
            && !self.rows.finished()
        {
            self.compact();
            self.rows.parse_more(&mut self.parsed)?;
        }
        let count = (self.parsed.lines.len() - self.taken).min(max_rows);
        if count == 0 {
            if let Some(error) = self.parsed.error.take() {
                return Err(error);
            }
            if self.returned == 0 {
                return Err(DataError::Empty {
                    path: self.rows.path().to_path_buf(),
                });
            }
            return Ok(None);
        }
        let rows = self.taken..self.taken + count;
        let block = NumericBlock {
            columns: (self.parsed.columns.iter())
                .map(|column| column[rows.clone()].to_vec())
                .collect(),
            lines: self.parsed.lines[rows].to_vec(),
            first_row: self.returned,
        };
        self.taken += count;
        self.returned += count;
        Ok(Some(block))
    }

    /// Drops the rows handed out from the parsed ones.
    fn compact(&mut self) {
        for column in &mut self.parsed.columns {
            column.drain(..self.taken);
        }
        self.parsed.lines.drain(..self.taken);
        self.taken = 0;
    }
}

/// The blocks of a [`NumericStream`] read ahead ([`NumericStream::read_ahead`]).
pub struct ReadAhead {
    receiver: Option<Receiver<Result<Option<NumericBlock>>>>,
    reader: Option<JoinHandle<()>>,
    ended: bool,
}

impl ReadAhead {
    /// The next block, in file order; `None` at the end of the file, and after an error.
    pub fn next_block(&mut self) -> Result<Option<NumericBlock>> {
        if self.ended {
            return Ok(None);
        }
        let received = self
            .receiver
            .as_ref()
            .and_then(|receiver| receiver.recv().ok());
        let item = match received {
            Some(item) => item,
            // The reader ended without its last item: it panicked, and so does the caller.
            None => {
                if let Some(Err(panic)) = self.reader.take().map(JoinHandle::join) {
                    std::panic::resume_unwind(panic);
                }
                Ok(None)
            }
        };
        self.ended = !matches!(item, Ok(Some(_)));
        item
    }
}

impl Drop for ReadAhead {
    /// Stops the reader (its next send fails) and waits for it.
    fn drop(&mut self) {
        drop(self.receiver.take());
        if let Some(reader) = self.reader.take() {
            let _ = reader.join();
        }
    }
}

impl<R: BufRead> NumericRows<R> {
    /// Reads the header of `records` (of the file `path`) and finds `columns` in it.
    pub(crate) fn new(path: &Path, mut records: CsvRecords<R>, columns: &[&str]) -> Result<Self> {
        let header = records.header()?;
        let columns = NumericColumn::resolve(path, &header, columns)?;
        Ok(Self {
            path: path.to_path_buf(),
            records,
            header,
            columns,
            record: Record::default(),
            rows: 0,
        })
    }

    /// The next block of at most `max_rows` rows (see [`NumericStream::next_block`]).
    pub(crate) fn next_block(&mut self, max_rows: usize) -> Result<Option<NumericBlock>> {
        let mut block = NumericBlock {
            columns: vec![Vec::with_capacity(max_rows.min(1 << 16)); self.columns.len()],
            lines: Vec::with_capacity(max_rows.min(1 << 16)),
            first_row: self.rows,
        };
        let mut buffer = Vec::with_capacity(1);
        let mut row = Vec::with_capacity(self.columns.len());
        while block.rows() < max_rows && self.records.next_row(&mut self.record, &self.header)? {
            row_numbers(
                &self.path,
                &self.columns,
                &self.record,
                &mut buffer,
                &mut row,
            )?;
            for (values, &value) in block.columns.iter_mut().zip(&row) {
                values.push(value);
            }
            block.lines.push(self.record.line);
            self.rows += 1;
        }
        if self.rows == 0 {
            return Err(DataError::Empty {
                path: self.path.clone(),
            });
        }
        Ok((!block.lines.is_empty()).then_some(block))
    }
}

/// The rows of `path`, a regular file (it is read twice: a pipe cannot be).
fn open_records(path: &Path) -> Result<CsvRecords<BufReader<File>>> {
    check_regular_file(path)?;
    let file = File::open(path).map_err(|source| DataError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(CsvRecords::new(
        path,
        BufReader::with_capacity(1 << 20, file),
    ))
}

/// Refuses a directory, and anything but a regular file (a stream is read twice).
fn check_regular_file(path: &Path) -> Result<()> {
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
    Ok(())
}
