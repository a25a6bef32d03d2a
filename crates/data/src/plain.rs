//! The rows of a piece of plain CSV text, read without the general splitter: the fast path of
//! [`crate::chunked`], taken only where it reads what [`crate::records::CsvRecords`] reads.
//!
//! A piece is plain when every byte is printable ASCII other than `"`, a tab, a line feed or a
//! carriage return just before a line feed; no line is blank or begins with `#`; every line has
//! the header's number of fields; and every cell named reads as a finite number. On such text the
//! splitter finds no fault, its cells are the bytes between the commas and each row is one line,
//! so the rows, their lines and their values are the splitter's (the cells are read by the same
//! [`NumericColumn::number`]). Anything else, a fault to name among it, is declined and the piece
//! is read by the splitter, which names the fault.

use std::path::Path;

use crate::cells::NumericColumn;
use crate::chunked::ParsedRows;

/// The rows of `text`, a piece that begins at a record start on line `line` of the file `path`
/// whose header has `width` fields: the values of `columns` and the line of each row, or `None`
/// when the piece is not plain (see the module).
pub(crate) fn plain_rows(
    path: &Path,
    text: &[u8],
    line: usize,
    width: usize,
    columns: &[NumericColumn],
) -> Option<ParsedRows> {
    if !plain_bytes(text) || !carriage_returns_end_lines(text) {
        return None;
    }
    // ASCII: every comma and line feed is a character boundary.
    let text = std::str::from_utf8(text).ok()?;
    let mut piece = ParsedRows::new(columns.len());
    let mut fields = Vec::with_capacity(width);
    let mut buffer = Vec::with_capacity(1);
    let mut start = 0;
    let mut line = line;
    while start < text.len() {
        let end =
            memchr::memchr(b'\n', &text.as_bytes()[start..]).map_or(text.len(), |i| start + i);
        let content = &text[start..end];
        let content = content.strip_suffix('\r').unwrap_or(content);
        if content.is_empty() || content.starts_with('#') {
            return None;
        }
        fields.clear();
        let mut field_start = 0;
        for comma in memchr::memchr_iter(b',', content.as_bytes()) {
            fields.push(field_start..comma);
            field_start = comma + 1;
        }
        fields.push(field_start..content.len());
        if fields.len() != width {
            return None;
        }
        for (values, column) in piece.columns.iter_mut().zip(columns) {
            let cell = &content[fields[column.field].clone()];
            values.push(column.number(path, line, cell, &mut buffer).ok()?);
        }
        piece.lines.push(line);
        line += 1;
        start = end + 1;
    }
    Some(piece)
}

/// Whether every byte of `text` is printable ASCII but `"`, or a tab, line feed or carriage
/// return (in blocks, so that the test vectorises).
fn plain_bytes(text: &[u8]) -> bool {
    let odd = |byte: u8| {
        let unprintable = byte.wrapping_sub(0x20) > 0x7E - 0x20;
        (unprintable & (byte != b'\t') & (byte != b'\n') & (byte != b'\r')) | (byte == b'"')
    };
    !text
        .chunks(64)
        .any(|block| block.iter().fold(false, |any, &byte| any | odd(byte)))
}

/// Whether every carriage return of `text` is followed by a line feed.
fn carriage_returns_end_lines(text: &[u8]) -> bool {
    memchr::memchr_iter(b'\r', text).all(|i| text.get(i + 1) == Some(&b'\n'))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::records::{CsvRecords, Record};

    const HEADER: &str = "t,x,y\n";

    fn columns() -> Vec<NumericColumn> {
        let header: Vec<String> = ["t", "x", "y"].map(String::from).to_vec();
        NumericColumn::resolve(Path::new("f.csv"), &header, &["y", "t"]).unwrap()
    }

    /// The splitter's reading of `text` (rows after the header): values of y and t, and lines.
    fn splitter_rows(text: &str) -> (Vec<[f64; 2]>, Vec<usize>) {
        let path = Path::new("f.csv");
        let full = format!("{HEADER}{text}");
        let mut records = CsvRecords::new(path, full.as_bytes());
        let header = records.header().unwrap();
        let columns = columns();
        let (mut rows, mut lines) = (Vec::new(), Vec::new());
        let mut record = Record::default();
        let mut buffer = Vec::new();
        while records.next_row(&mut record, &header).unwrap() {
            let mut value = |column: &NumericColumn| {
                let cell = &record.fields[column.field];
                column.number(path, record.line, cell, &mut buffer).unwrap()
            };
            rows.push([value(&columns[0]), value(&columns[1])]);
            lines.push(record.line);
        }
        (rows, lines)
    }

    fn fast_rows(text: &str) -> Option<(Vec<[f64; 2]>, Vec<usize>)> {
        let piece = plain_rows(Path::new("f.csv"), text.as_bytes(), 2, 3, &columns())?;
        let rows = (0..piece.lines.len())
            .map(|r| [piece.columns[0][r], piece.columns[1][r]])
            .collect();
        Some((rows, piece.lines))
    }

    #[test]
    fn plain_text_reads_as_the_splitter_reads_it() {
        for text in [
            "0,1,2\n0.5, 3 ,-4e-3\n",
            "0,1,2\r\n1,\t2,3.25\r\n",
            "0,1,2\n1,2,[7.5]",
            "0,1,2\n",
            "",
        ] {
            assert_eq!(fast_rows(text), Some(splitter_rows(text)), "{text:?}");
        }
    }

    #[test]
    fn anything_the_splitter_must_judge_is_declined() {
        for text in [
            "0,1,\"2\"\n",      // a quote
            "0,1,2\n\n1,2,3\n", // a blank line between rows
            "0,1,2\n\n",        // a blank line at the end (allowed, judged by the splitter)
            "# note\n0,1,2\n",  // a comment
            "0,1\n",            // too few fields
            "0,1,2,3\n",        // too many
            "0,1,x\n",          // not a number
            "0,1,\n",           // an empty cell
            "0,1,NaN\n",        // not finite
            "0,1,2\r3\n",       // a lone carriage return
            "0,1,2\u{1}\n",     // a control byte
            "0,1,2é\n",         // not ASCII
            "0,1,2\u{7f}\n",    // DEL
        ] {
            assert_eq!(fast_rows(text), None, "{text:?}");
        }
    }
}
