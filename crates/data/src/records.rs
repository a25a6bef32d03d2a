//! The one CSV splitter of the crate: the whole-file reader ([`crate::table`]) and the block reader
//! ([`crate::stream`]) both take their rows from [`CsvRecords`], so that they accept the same
//! files, read the same cells and name the same line for the same fault.
//!
//! It is strict RFC 4180 read in one pass over the bytes, in memory bounded by the longest row:
//! the `csv` crate reads `"1"2` as `12`, skips blank lines, splits at a lone carriage return and
//! keeps no trace of the bytes it read, so none of the faults below could be named by its line
//! from its records alone. Each fault is a [`LayoutFault`] naming the line it is on:
//! text that is not UTF-8 or holds control bytes, a `#` comment line, a blank line between rows,
//! a quote inside an unquoted cell, text after a closing quote, a quoted cell never closed, a
//! carriage return that is not followed by a line feed (classic Mac line endings), a header wider
//! than [`bounded_read::MAX_CSV_COLUMNS`] or with a name given twice, a row with more or fewer fields
//! than the header. Lines are counted by line feeds, including those inside quoted cells.

use std::io::BufRead;
use std::path::{Path, PathBuf};

use bounded_read::{Excerpt, MAX_CSV_COLUMNS};

use crate::error::{DataError, Result};

/// What is wrong with the layout of a CSV file at one line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum LayoutFault {
    /// A `#` line before the header.
    CommentBeforeHeader,
    /// A `#` line after the header.
    Comment,
    /// An empty line with rows after it (blank lines at the end of the file are ignored).
    BlankLine,
    /// A `"` in a cell that does not start with one.
    QuoteInUnquotedCell,
    /// Text between a closing quote and the next `,` or line end, as in `"1"2`.
    TextAfterClosingQuote,
    /// A quoted cell still open at the end of the file (it opened on the line named).
    UnclosedQuote,
    /// A carriage return not followed by a line feed, on the first line: the file's line
    /// endings are CR only.
    CarriageReturnLineEndings,
    /// A carriage return not followed by a line feed, outside a quoted cell, after LF or CRLF
    /// line ends.
    LoneCarriageReturn,
    /// A header of more names than a CSV may have.
    HeaderTooWide { columns: usize },
    /// A row of more fields than the header has names.
    TooManyFields { fields: usize, columns: usize },
    /// A row of fewer fields than the header has names; `missing` is the first name without a
    /// value.
    TooFewFields {
        fields: usize,
        columns: usize,
        missing: String,
    },
}

impl std::fmt::Display for LayoutFault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::CommentBeforeHeader => {
                write!(
                    f,
                    "a '#' comment line: the header must come first (no comments)"
                )
            }
            Self::Comment => write!(f, "a '#' comment line (comments are not allowed)"),
            Self::BlankLine => write!(f, "blank line between data rows"),
            Self::QuoteInUnquotedCell => {
                write!(f, "a quote inside an unquoted cell (quote the whole cell)")
            }
            Self::TextAfterClosingQuote => write!(
                f,
                "text after the closing quote of a quoted cell (quote the whole cell)"
            ),
            Self::UnclosedQuote => write!(
                f,
                "a quoted cell opened here is never closed (or a stray '\"')"
            ),
            Self::CarriageReturnLineEndings => write!(
                f,
                "line endings are CR only (classic Mac): convert the file to LF or CRLF line endings"
            ),
            Self::LoneCarriageReturn => write!(
                f,
                "a carriage return (CR) not followed by a line feed outside a quoted cell \
                 (mixed line endings?)"
            ),
            Self::HeaderTooWide { columns } => write!(
                f,
                "{columns} columns in the header, more than the {MAX_CSV_COLUMNS} a CSV may have"
            ),
            Self::TooManyFields { fields, columns } => write!(
                f,
                "{fields} fields, more than the {columns} columns of the header \
                 (a ',' in an unquoted cell, e.g. a decimal comma?)"
            ),
            Self::TooFewFields {
                fields,
                columns,
                missing,
            } => write!(
                f,
                "too few fields: {fields} of the header's {columns}, no value for '{missing}'"
            ),
        }
    }
}

/// One row of a CSV file.
#[derive(Clone, Debug, Default)]
pub struct Record {
    /// The cells, at most as many as the reader keeps (see [`CsvRecords::next_row`]).
    pub fields: Vec<String>,
    /// How many fields the row has, kept or not.
    pub count: usize,
    /// The line of the file on which the row starts (the first line is 1).
    pub line: usize,
}

/// Where the splitter is within a record.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum State {
    /// No byte of the record read yet.
    RecordStart,
    /// At the start of a field after a `,`.
    FieldStart,
    Unquoted,
    Quoted,
    /// Just after a `"` inside a quoted cell: a second one is an escaped quote, a `,` or a line
    /// end closes the cell.
    QuoteInQuoted,
    /// After a carriage return ending a record (or a blank line): a line feed must follow.
    CarriageReturn {
        blank: bool,
    },
}

/// Rows of a CSV text read from `input` in one pass, checked as they come (see the module).
pub struct CsvRecords<R> {
    input: R,
    splitter: Splitter,
}

/// The splitter's state between bytes.
struct Splitter {
    path: PathBuf,
    /// The line of the next byte (the first line is 1).
    line: usize,
    /// Bytes of the leading byte-order mark matched so far; `None` once past it.
    byte_order_mark: Option<usize>,
    /// The number of fields of the header, once it is read.
    width: Option<usize>,
    /// The line of the first blank line since the last record.
    blank_since: Option<usize>,
    /// The bytes of the current field.
    field: Vec<u8>,
    /// The line on which the current field (and so a quoted cell) starts.
    field_line: usize,
}

const BYTE_ORDER_MARK: [u8; 3] = [0xEF, 0xBB, 0xBF];

impl CsvRecords<std::io::BufReader<bounded_read::BoundedFile>> {
    /// The records of the file or pipe `path`, read once within [`bounded_read::MAX_CSV_BYTES`]; a
    /// directory or an unreadable path is an error naming it.
    pub(crate) fn open(path: &Path) -> Result<Self> {
        let io = |source| DataError::Io {
            path: path.to_path_buf(),
            source,
        };
        if std::fs::metadata(path).map_err(io)?.is_dir() {
            return Err(DataError::IsDirectory {
                path: path.to_path_buf(),
            });
        }
        let file = bounded_read::open(path, bounded_read::InputKind::Csv).map_err(io)?;
        Ok(Self::new(
            path,
            std::io::BufReader::with_capacity(1 << 16, file),
        ))
    }
}

impl<R: BufRead> CsvRecords<R> {
    /// A splitter of the text `input` read from `path` (named in errors).
    pub fn new(path: &Path, input: R) -> Self {
        Self {
            input,
            splitter: Splitter {
                path: path.to_path_buf(),
                line: 1,
                byte_order_mark: Some(0),
                width: None,
                blank_since: None,
                field: Vec::new(),
                field_line: 1,
            },
        }
    }

    /// A splitter of the data rows of a file whose header (of `width` fields) was read elsewhere:
    /// `input` begins at a record start on line `line`, after the header and any byte-order mark
    /// ([`crate::pieces`]).
    pub(crate) fn continuing(path: &Path, input: R, line: usize, width: usize) -> Self {
        let mut records = Self::new(path, input);
        records.splitter.line = line;
        records.splitter.field_line = line;
        records.splitter.byte_order_mark = None;
        records.splitter.width = Some(width);
        records
    }

    /// The input not read yet, and the line it begins on.
    pub(crate) fn into_rest(self) -> (R, usize) {
        (self.input, self.splitter.line)
    }

    /// The header's names: at most [`MAX_CSV_COLUMNS`], each once. Must be read first.
    pub fn header(&mut self) -> Result<Vec<String>> {
        let mut record = Record::default();
        if !self.read_record(MAX_CSV_COLUMNS, &mut record)? {
            return Err(DataError::Empty {
                path: self.splitter.path.clone(),
            });
        }
        if record.count > MAX_CSV_COLUMNS {
            let columns = record.count;
            return Err(self
                .splitter
                .fault(record.line, LayoutFault::HeaderTooWide { columns }));
        }
        // One pass with the first position of each name: linear in the number of columns.
        let mut seen = std::collections::HashMap::with_capacity(record.count);
        for (second, name) in record.fields.iter().enumerate() {
            if let Some(&first) = seen.get(name.as_str()) {
                return Err(DataError::DuplicateColumn {
                    path: self.splitter.path.clone(),
                    row: record.line,
                    column: Excerpt::of(name).unquoted(),
                    first: first + 1,
                    second: second + 1,
                });
            }
            seen.insert(name.as_str(), second);
        }
        self.splitter.width = Some(record.count);
        Ok(record.fields)
    }

    /// Reads the next row into `record` (its buffers reused); `false` at the end of the file. A
    /// row must have as many fields as `header` (read by [`Self::header`]) has names.
    pub fn next_row(&mut self, record: &mut Record, header: &[String]) -> Result<bool> {
        let columns = header.len();
        if !self.read_record(columns, record)? {
            return Ok(false);
        }
        let fields = record.count;
        let fault = if fields > columns {
            LayoutFault::TooManyFields { fields, columns }
        } else if fields < columns {
            LayoutFault::TooFewFields {
                fields,
                columns,
                missing: Excerpt::of(&header[fields]).unquoted(),
            }
        } else {
            return Ok(true);
        };
        Err(self.splitter.fault(record.line, fault))
    }

    /// Reads one record, keeping its first `keep` fields; `false` when only blank lines (or
    /// nothing) are left.
    fn read_record(&mut self, keep: usize, record: &mut Record) -> Result<bool> {
        record.count = 0;
        let mut state = State::RecordStart;
        loop {
            let buffer = match self.input.fill_buf() {
                Ok(buffer) => buffer,
                Err(error) if error.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(source) => {
                    return Err(DataError::Io {
                        path: self.splitter.path.clone(),
                        source,
                    });
                }
            };
            if buffer.is_empty() {
                return self.splitter.finish_record(state, keep, record);
            }
            let mut taken = 0;
            let mut complete = false;
            while taken < buffer.len() && !complete {
                let (used, next) = self.splitter.step(state, &buffer[taken..], keep, record)?;
                taken += used;
                match next {
                    Some(next) => state = next,
                    None => complete = true,
                }
            }
            self.input.consume(taken);
            if complete {
                return Ok(true);
            }
        }
    }
}

impl Splitter {
    fn fault(&self, line: usize, fault: LayoutFault) -> DataError {
        DataError::Layout {
            path: self.path.clone(),
            row: line,
            fault,
        }
    }

    /// The end of the file reached in `state`.
    fn finish_record(&mut self, state: State, keep: usize, record: &mut Record) -> Result<bool> {
        if self
            .byte_order_mark
            .is_some_and(|matched| matched > 0 && matched < 3)
        {
            // The file is the start of a byte-order mark: not UTF-8 text.
            return Err(self.not_utf8(self.line, BYTE_ORDER_MARK[0]));
        }
        match state {
            State::RecordStart | State::CarriageReturn { blank: true } => return Ok(false),
            State::Quoted => return Err(self.fault(self.field_line, LayoutFault::UnclosedQuote)),
            // A last line ended by a carriage return alone: its line end.
            State::CarriageReturn { blank: false } => {}
            State::FieldStart | State::Unquoted | State::QuoteInQuoted => {
                self.end_field(keep, record)?;
            }
        }
        record.fields.truncate(record.count.min(keep));
        Ok(true)
    }

    /// Ends the current field: checks its text and keeps it as field `record.count` when fewer
    /// than `keep` are kept.
    fn end_field(&mut self, keep: usize, record: &mut Record) -> Result<()> {
        let index = record.count;
        if index >= keep {
            self.check_utf8()?;
            record.count += 1;
            self.field.clear();
            return Ok(());
        }
        // The field's bytes become the cell without a copy (checked as UTF-8 once, there); the
        // cell's old buffer is reused.
        let mut bytes = record
            .fields
            .get_mut(index)
            .map(|cell| std::mem::take(cell).into_bytes())
            .unwrap_or_default();
        bytes.clear();
        std::mem::swap(&mut bytes, &mut self.field);
        let cell = match String::from_utf8(bytes) {
            Ok(cell) => cell,
            Err(error) => {
                let at = error.utf8_error().valid_up_to();
                self.field = error.into_bytes();
                return Err(self.utf8_fault(at));
            }
        };
        record.count += 1;
        match record.fields.get_mut(index) {
            Some(slot) => *slot = cell,
            None => record.fields.push(cell),
        }
        Ok(())
    }

    /// The record ended by a line end: the line counted, the cells of a longer earlier record
    /// dropped.
    fn end_record(&mut self, keep: usize, record: &mut Record) {
        self.line += 1;
        record.fields.truncate(record.count.min(keep));
    }

    /// Fails at the first byte of the current field that is not UTF-8, naming its line.
    fn check_utf8(&self) -> Result<()> {
        match std::str::from_utf8(&self.field) {
            Ok(_) => Ok(()),
            Err(error) => Err(self.utf8_fault(error.valid_up_to())),
        }
    }

    /// The current field's first byte that is not UTF-8, at `at`, named by its line.
    fn utf8_fault(&self, at: usize) -> DataError {
        let line = self.field_line + lines_in(&self.field[..at]);
        self.not_utf8(line, self.field[at])
    }

    fn not_utf8(&self, line: usize, byte: u8) -> DataError {
        DataError::NotText {
            path: self.path.clone(),
            row: line,
            reason: format!("byte 0x{byte:02X} is not UTF-8 text"),
        }
    }

    /// A control byte at the current line; a UTF-8 fault earlier in the field is named first.
    fn control_byte(&self, byte: u8) -> DataError {
        if let Err(error) = self.check_utf8() {
            return error;
        }
        // A ULog's header begins "ULog" followed by control bytes.
        let reason = if self.line == 1 && self.field.starts_with(b"ULog") {
            "a PX4 ULog, which `learn data inspect` reads (no analysis imports ULog yet)"
                .to_string()
        } else {
            format!("control byte 0x{byte:02X} (binary data?)")
        };
        DataError::NotText {
            path: self.path.clone(),
            row: self.line,
            reason,
        }
    }

    /// Reads from the front of `chunk` in `state`: how many bytes were used and the state after
    /// them, `None` when the record is complete.
    fn step(
        &mut self,
        state: State,
        chunk: &[u8],
        keep: usize,
        record: &mut Record,
    ) -> Result<(usize, Option<State>)> {
        // Runs of plain cell text are copied at once.
        let special = match state {
            State::Unquoted => Some(&UNQUOTED_SPECIAL),
            State::Quoted => Some(&QUOTED_SPECIAL),
            _ => None,
        };
        if let Some(special) = special {
            let run = chunk
                .iter()
                .position(|&b| special[usize::from(b)])
                .unwrap_or(chunk.len());
            if run > 0 {
                self.field.extend_from_slice(&chunk[..run]);
                return Ok((run, Some(state)));
            }
        }
        let byte = chunk[0];
        if let Some(matched) = self.byte_order_mark {
            if matched < BYTE_ORDER_MARK.len() && byte == BYTE_ORDER_MARK[matched] {
                self.byte_order_mark = Some(matched + 1);
                return Ok((1, Some(state)));
            }
            if matched > 0 && matched < BYTE_ORDER_MARK.len() {
                return Err(self.not_utf8(self.line, BYTE_ORDER_MARK[0]));
            }
            self.byte_order_mark = None;
        }
        let next = match (state, byte) {
            (State::CarriageReturn { blank }, b'\n') => {
                if !blank {
                    self.end_record(keep, record);
                    return Ok((1, None));
                }
                self.line += 1;
                State::RecordStart
            }
            (State::CarriageReturn { .. }, _) => {
                let fault = if self.line == 1 {
                    LayoutFault::CarriageReturnLineEndings
                } else {
                    LayoutFault::LoneCarriageReturn
                };
                return Err(self.fault(self.line, fault));
            }
            (_, byte) if byte < 0x20 && !matches!(byte, b'\t' | b'\n' | b'\r') => {
                return Err(self.control_byte(byte));
            }
            (State::RecordStart, b'\n') => {
                self.blank_since.get_or_insert(self.line);
                self.line += 1;
                State::RecordStart
            }
            (State::RecordStart, b'\r') => {
                self.blank_since.get_or_insert(self.line);
                State::CarriageReturn { blank: true }
            }
            (State::RecordStart, _) => {
                self.start_record(byte, record)?;
                return self.field_start(byte, keep, record);
            }
            (State::FieldStart, _) => return self.field_start(byte, keep, record),
            (State::Unquoted | State::QuoteInQuoted, b',') => {
                self.end_field(keep, record)?;
                State::FieldStart
            }
            (State::Unquoted | State::QuoteInQuoted, b'\n') => {
                self.end_field(keep, record)?;
                self.end_record(keep, record);
                return Ok((1, None));
            }
            (State::Unquoted | State::QuoteInQuoted, b'\r') => {
                self.end_field(keep, record)?;
                State::CarriageReturn { blank: false }
            }
            (State::Unquoted, b'"') => {
                return Err(self.fault(self.line, LayoutFault::QuoteInUnquotedCell));
            }
            (State::QuoteInQuoted, b'"') => {
                self.field.push(b'"');
                State::Quoted
            }
            (State::QuoteInQuoted, _) => {
                return Err(self.fault(self.line, LayoutFault::TextAfterClosingQuote));
            }
            (State::Quoted, b'"') => State::QuoteInQuoted,
            (State::Unquoted | State::Quoted, _) => {
                // A tab, or a line end inside a quoted cell: part of the cell.
                if byte == b'\n' {
                    self.line += 1;
                }
                self.field.push(byte);
                state
            }
        };
        Ok((1, Some(next)))
    }

    /// The first byte of a record that is not a blank line.
    fn start_record(&mut self, byte: u8, record: &mut Record) -> Result<()> {
        if byte == b'#' {
            let fault = if self.width.is_none() {
                LayoutFault::CommentBeforeHeader
            } else {
                LayoutFault::Comment
            };
            return Err(self.fault(self.line, fault));
        }
        // Blank lines before the header are ignored, as are those at the end of the file.
        if let Some(blank) = self.blank_since.take()
            && self.width.is_some()
        {
            return Err(self.fault(blank, LayoutFault::BlankLine));
        }
        record.line = self.line;
        Ok(())
    }

    /// The first byte of a field (not a control byte).
    fn field_start(
        &mut self,
        byte: u8,
        keep: usize,
        record: &mut Record,
    ) -> Result<(usize, Option<State>)> {
        self.field_line = self.line;
        let next = match byte {
            b'"' => State::Quoted,
            b',' => {
                self.end_field(keep, record)?;
                State::FieldStart
            }
            b'\n' => {
                self.end_field(keep, record)?;
                self.end_record(keep, record);
                return Ok((1, None));
            }
            b'\r' => {
                self.end_field(keep, record)?;
                State::CarriageReturn { blank: false }
            }
            _ => {
                self.field.push(byte);
                State::Unquoted
            }
        };
        Ok((1, Some(next)))
    }
}

/// The bytes that end a run of plain text outside quotes: control bytes but the tab, the
/// separator and the quote.
const UNQUOTED_SPECIAL: [bool; 256] = special_bytes(true);
/// Inside quotes: control bytes but the tab, and the quote.
const QUOTED_SPECIAL: [bool; 256] = special_bytes(false);

const fn special_bytes(separator: bool) -> [bool; 256] {
    let mut table = [false; 256];
    let mut byte = 0;
    while byte < 0x20 {
        table[byte] = byte != b'\t' as usize;
        byte += 1;
    }
    table[b'"' as usize] = true;
    table[b',' as usize] = separator;
    table
}

fn lines_in(bytes: &[u8]) -> usize {
    bytes.iter().filter(|&&b| b == b'\n').count()
}
