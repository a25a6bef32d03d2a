//! The data rows of a CSV file parsed a chunk at a time, each chunk cut into pieces that parse in
//! parallel ([`crate::pieces`]); the rows, their lines and the first error come out in file order,
//! as one pass of the splitter over the file gives them.

use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};

use rayon::prelude::*;

use crate::cells::NumericColumn;
use crate::error::{DataError, Result};
use crate::pieces::cuts;
use crate::plain::plain_rows;
use crate::records::{CsvRecords, Record};

/// Bytes read at once per thread (the pieces of a chunk are about this size over two).
pub(crate) const CHUNK_BYTES_PER_THREAD: usize = 1 << 20;
/// Pieces per thread in a chunk: the pieces' rows differ in cost, two each balance them.
const PIECES_PER_THREAD: usize = 2;

/// Rows parsed from a file and not yet handed out, then the first error after them.
#[derive(Debug, Default)]
pub(crate) struct ParsedRows {
    pub columns: Vec<Vec<f64>>,
    pub lines: Vec<usize>,
    pub error: Option<DataError>,
}

impl ParsedRows {
    /// No rows yet, of `width` columns.
    pub(crate) fn new(width: usize) -> Self {
        Self {
            columns: vec![Vec::new(); width],
            ..Self::default()
        }
    }
}

/// The file after its header, read in chunks and parsed into [`ParsedRows`].
pub(crate) struct ChunkedRows {
    path: PathBuf,
    file: File,
    header: Vec<String>,
    columns: Vec<NumericColumn>,
    /// Bytes read and not parsed yet: they begin at a record start on line `text_line`.
    text: Vec<u8>,
    text_line: usize,
    end_of_file: bool,
    chunk_bytes: usize,
}

impl ChunkedRows {
    /// Opens `path` (a regular file, the caller checked) and reads its header; `columns` are
    /// found in it.
    pub(crate) fn open(path: &Path, columns: &[&str], chunk_bytes: usize) -> Result<Self> {
        let file = File::open(path).map_err(|source| DataError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let mut rows = Self {
            path: path.to_path_buf(),
            file,
            header: Vec::new(),
            columns: Vec::new(),
            text: Vec::new(),
            text_line: 1,
            end_of_file: false,
            chunk_bytes: chunk_bytes.max(1),
        };
        rows.read_header()?;
        rows.columns = NumericColumn::resolve(path, &rows.header, columns)?;
        Ok(rows)
    }

    /// Reads until the header is whole (the splitter stopped before the end of what was read, or
    /// the file ended), and keeps what follows it.
    fn read_header(&mut self) -> Result<()> {
        loop {
            self.read_chunk()?;
            let mut records = CsvRecords::new(&self.path, &self.text[..]);
            let header = records.header();
            let (rest, line) = records.into_rest();
            if rest.is_empty() && !self.end_of_file {
                continue;
            }
            self.header = header?;
            let consumed = self.text.len() - rest.len();
            self.text.drain(..consumed);
            self.text_line = line;
            return Ok(());
        }
    }

    /// Appends up to `chunk_bytes` of the file to the text; marks the end of the file.
    fn read_chunk(&mut self) -> Result<()> {
        let start = self.text.len();
        self.text.resize(start + self.chunk_bytes, 0);
        let mut filled = start;
        while filled < self.text.len() {
            match self.file.read(&mut self.text[filled..]) {
                Ok(0) => {
                    self.end_of_file = true;
                    break;
                }
                Ok(read) => filled += read,
                Err(error) if error.kind() == std::io::ErrorKind::Interrupted => {}
                Err(source) => {
                    return Err(DataError::Io {
                        path: self.path.clone(),
                        source,
                    });
                }
            }
        }
        self.text.truncate(filled);
        Ok(())
    }

    /// Whether every row of the file has been parsed.
    pub(crate) fn finished(&self) -> bool {
        self.end_of_file && self.text.is_empty()
    }

    /// Reads a chunk and parses every whole row read so far into `out` (after its rows), in
    /// parallel pieces; stops at the first error, which goes to `out.error`.
    pub(crate) fn parse_more(&mut self, out: &mut ParsedRows) -> Result<()> {
        if !self.end_of_file {
            self.read_chunk()?;
        }
        let pieces = PIECES_PER_THREAD * rayon::current_num_threads().max(1);
        let cut = cuts(&self.text, pieces);
        let (usable, feeds_before_usable) = match (self.end_of_file, cut.last) {
            // The rest is the last piece (the line after it is not needed).
            (true, _) => (self.text.len(), 0),
            (false, Some(last)) => (last, *cut.line_feeds.last().unwrap_or(&0)),
            // No row ends in what was read: read on.
            (false, None) => return Ok(()),
        };
        let mut bounds = Vec::with_capacity(cut.ends.len() + 1);
        let mut start = (0, 0);
        for (&end, &feeds) in cut.ends.iter().zip(&cut.line_feeds) {
            if end < usable {
                bounds.push((start.0..end, self.text_line + start.1));
                start = (end, feeds);
            }
        }
        bounds.push((start.0..usable, self.text_line + start.1));
        let parsed: Vec<ParsedRows> = bounds
            .par_iter()
            .map(|(range, line)| self.parse_piece(&self.text[range.clone()], *line))
            .collect();
        for piece in parsed {
            for (all, part) in out.columns.iter_mut().zip(piece.columns) {
                all.extend(part);
            }
            out.lines.extend(piece.lines);
            if piece.error.is_some() {
                out.error = piece.error;
                break;
            }
        }
        self.text.drain(..usable);
        self.text_line += feeds_before_usable;
        Ok(())
    }

    /// The rows of one piece that begins at a record start on line `line`, up to its first error:
    /// read by the fast path when the piece is plain text ([`crate::plain`]), else by the splitter.
    fn parse_piece(&self, text: &[u8], line: usize) -> ParsedRows {
        let width = self.header.len();
        if let Some(piece) = plain_rows(&self.path, text, line, width, &self.columns) {
            return piece;
        }
        let mut piece = ParsedRows::new(self.columns.len());
        if let Err(error) = self.read_piece(text, line, &mut piece) {
            piece.error = Some(error);
        }
        piece
    }

    /// Appends the rows of a piece to `piece` until its end or its first error.
    fn read_piece(&self, text: &[u8], line: usize, piece: &mut ParsedRows) -> Result<()> {
        let mut records = CsvRecords::continuing(&self.path, text, line, self.header.len());
        let mut record = Record::default();
        let mut buffer = Vec::with_capacity(1);
        let mut row = Vec::with_capacity(self.columns.len());
        while records.next_row(&mut record, &self.header)? {
            row_numbers(&self.path, &self.columns, &record, &mut buffer, &mut row)?;
            for (values, &value) in piece.columns.iter_mut().zip(&row) {
                values.push(value);
            }
            piece.lines.push(record.line);
        }
        Ok(())
    }

    /// The file read.
    pub(crate) fn path(&self) -> &Path {
        &self.path
    }

    /// Number of columns read.
    pub(crate) fn width(&self) -> usize {
        self.columns.len()
    }
}

/// The numbers of `columns` in `record` (of the file `path`), into `row`.
pub(crate) fn row_numbers(
    path: &Path,
    columns: &[NumericColumn],
    record: &Record,
    buffer: &mut Vec<f64>,
    row: &mut Vec<f64>,
) -> Result<()> {
    row.clear();
    for column in columns {
        let cell = &record.fields[column.field];
        row.push(column.number(path, record.line, cell, buffer)?);
    }
    Ok(())
}
