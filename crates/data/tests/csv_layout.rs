//! The layout of a CSV file (header, fields per row, quotes, encoding, what the path is) is checked
//! on load, and each fault is a one-line error naming the file and the line.

mod common;

use std::path::{Path, PathBuf};

use common::{Scratch, temp_dir};
use data::{FlightLog, NumericTable};

/// A file written in a temporary directory of its own (both removed when dropped).
struct Written {
    path: PathBuf,
    _dir: Scratch,
}

impl std::ops::Deref for Written {
    type Target = Path;
    fn deref(&self) -> &Path {
        &self.path
    }
}

fn write(name: &str, text: &[u8]) -> Written {
    let dir = temp_dir("layout");
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    Written { path, _dir: dir }
}

fn numeric_error(path: &Path, columns: &[&str]) -> String {
    let message = NumericTable::read_with_time(path, "t", columns)
        .unwrap_err()
        .to_string();
    assert!(!message.contains('\n'), "one line: {message}");
    assert!(
        message.contains(&path.display().to_string()),
        "names the file: {message}"
    );
    message
}

/// `t,x,y` rows for t = 0, 0.1, ... with `rows` rows.
fn plain(rows: usize) -> String {
    let mut text = String::from("t,x,y\n");
    for k in 0..rows {
        text.push_str(&format!("{:.1},{},{}\n", k as f64 * 0.1, k, 2 * k));
    }
    text
}

#[test]
fn a_repeated_column_name_is_an_error_not_a_renamed_copy() {
    let path = write("dup.csv", b"t,x,x\n0,1,2\n0.1,1,2\n");
    let message = numeric_error(&path, &["x"]);
    assert!(
        message.contains("dup.csv:1:x: column 'x' appears twice in the header (fields 2 and 3)"),
        "{message}"
    );
}

/// `t,x,c0..c{n-1}` with `rows` rows of ones, x = the row index.
fn wide(columns: usize, rows: usize) -> String {
    let names: Vec<String> = (0..columns).map(|k| format!("c{k}")).collect();
    let mut text = format!("t,x,{}\n", names.join(","));
    let ones = vec!["1"; columns].join(",");
    for k in 0..rows {
        text.push_str(&format!("{:.1},{k},{ones}\n", k as f64 * 0.1));
    }
    text
}

#[test]
fn a_wide_file_is_read_and_a_duplicate_far_apart_is_named_with_both_positions() {
    // The widest file read (10 000 columns): the header check is one pass (it was quadratic).
    let columns = bounded_read::MAX_CSV_COLUMNS - 2;
    let good = write("wide.csv", wide(columns, 5).as_bytes());
    let last = format!("c{}", columns - 1);
    let table = NumericTable::read_with_time(&good, "t", &["x", &last]).unwrap();
    assert_eq!(table.1.rows(), 5);
    assert_eq!(table.1.columns[0], vec![0.0, 1.0, 2.0, 3.0, 4.0]);
    assert_eq!(table.1.columns[1], vec![1.0; 5]);

    // The last column renamed to the first: fields 3 and 10 000, far apart.
    let text = wide(columns, 5).replacen(&format!(",{last}\n"), ",c0\n", 1);
    let path = write("wide-dup.csv", text.as_bytes());
    let message = numeric_error(&path, &["x"]);
    assert!(
        message.contains(&format!(
            "wide-dup.csv:1:c0: column 'c0' appears twice in the header (fields 3 and {})",
            columns + 2
        )),
        "{message}"
    );

    // A missing column lists the first names and counts the rest: one short line.
    let message = numeric_error(&good, &["nope"]);
    assert!(message.contains("missing column 'nope'"), "{message}");
    assert!(message.contains("t, x, c0, c1, "), "{message}");
    assert!(
        message.ends_with(&format!(" and {} more)", columns + 2 - 40)),
        "{message}"
    );
    assert!(message.len() < 1000, "{message}");

    // One column more is refused at once, by the header's line (issue 18: a 200 000-name header
    // cost 5 GB).
    let wider = write("wider.csv", wide(columns + 1, 5).as_bytes());
    let message = numeric_error(&wider, &["x"]);
    assert!(
        message.contains("wider.csv:1: 10001 columns in the header, more than the 10000"),
        "{message}"
    );
}

#[test]
fn a_row_with_an_extra_field_names_its_line() {
    let text = plain(5).replacen("0.2,2,4\n", "0.2,2,4,9\n", 1);
    let message = numeric_error(&write("extra.csv", text.as_bytes()), &["x"]);
    assert!(
        message.contains("extra.csv:4: 4 fields, more than the 3 columns of the header"),
        "{message}"
    );
    // A decimal comma gives the same fault, with the hint.
    let text = plain(5).replacen("0.2,2,4\n", "0.2,2,4,5\n", 1);
    let message = numeric_error(&write("comma.csv", text.as_bytes()), &["x"]);
    assert!(
        message.contains("comma.csv:4:") && message.contains("decimal comma"),
        "{message}"
    );
}

#[test]
fn a_row_with_too_few_fields_says_so_instead_of_an_empty_cell() {
    let text = plain(5).replacen("0.3,3,6\n", "0.3,3\n", 1);
    let message = numeric_error(&write("short.csv", text.as_bytes()), &["x"]);
    assert!(
        message.contains("short.csv:5: too few fields: 2 of the header's 3, no value for 'y'"),
        "{message}"
    );
    // An empty cell is still an empty cell.
    let text = plain(5).replacen("0.3,3,6\n", "0.3,,6\n", 1);
    let message = numeric_error(&write("empty-cell.csv", text.as_bytes()), &["x"]);
    assert!(
        message.contains("empty-cell.csv:5:x: cannot parse \"\": empty cell"),
        "{message}"
    );
}

#[test]
fn comment_lines_are_named() {
    let text = plain(5).replacen("0.2,2,4\n", "# a note, here\n0.2,2,4\n", 1);
    let message = numeric_error(&write("comment.csv", text.as_bytes()), &["x"]);
    assert!(
        message.contains("comment.csv:4: a '#' comment line"),
        "{message}"
    );
    let message = numeric_error(
        &write(
            "comment-first.csv",
            format!("# made by hand\n{}", plain(3)).as_bytes(),
        ),
        &["x"],
    );
    assert!(
        message.contains("comment-first.csv:1: a '#' comment line"),
        "{message}"
    );
}

#[test]
fn line_numbers_count_the_lines_inside_quoted_cells() {
    // The note of row 2 spans two lines: the bad cell of the next row is on line 5, not 4.
    let text = "t,x,note\n0,1,\"one\"\n0.1,2,\"two\nlines\"\n0.2,abc,three\n";
    let message = numeric_error(&write("note.csv", text.as_bytes()), &["x"]);
    assert!(message.contains("note.csv:5:x: cannot parse"), "{message}");
    // Time errors too.
    let text = "t,x,note\n0,1,\"one\"\n0.1,2,\"two\nlines\"\n0.1,3,three\n";
    let message = numeric_error(&write("note-time.csv", text.as_bytes()), &["x"]);
    assert!(
        message.contains("note-time.csv:5:t: time is not strictly increasing"),
        "{message}"
    );
    let text = "t,x,note\n0,1,\"one\"\n0.1,2,\"two\nlines\"\n0.2,3,three\n";
    let (_, table) =
        NumericTable::read_with_time(&write("note-ok.csv", text.as_bytes()), "t", &["x"]).unwrap();
    assert_eq!(table.column("x").unwrap(), &[1.0, 2.0, 3.0]);
    assert_eq!((0..3).map(|k| table.line(k)).collect::<Vec<_>>(), [2, 3, 5]);
}

#[test]
fn a_quote_left_open_names_the_line_it_opens_on() {
    let text = "t,x\n0,1\n0.1,\"2\n0.2,3\n";
    let message = numeric_error(&write("open.csv", text.as_bytes()), &["x"]);
    assert!(
        message.contains("open.csv:3: a quoted cell opened here is never closed"),
        "{message}"
    );
}

#[test]
fn text_after_a_closing_quote_is_an_error_not_joined_to_the_cell() {
    let text = "t,x\n0,1\n0.1,\"1\"2\n0.2,3\n";
    let message = numeric_error(&write("joined.csv", text.as_bytes()), &["x"]);
    assert!(
        message.contains("joined.csv:3: text after the closing quote"),
        "{message}"
    );
    // In the last cell of a multi-line quoted cell's row, the line is where the text is.
    let text = "t,note,x\n0,\"a\nb\"c,1\n";
    let message = numeric_error(&write("joined-lines.csv", text.as_bytes()), &["x"]);
    assert!(
        message.contains("joined-lines.csv:3: text after the closing quote"),
        "{message}"
    );
    // Escaped quotes, quoted cells before a ',' or the line's end, and a CRLF file are fine.
    let text = "t,note,x\r\n0,\"say \"\"hi\"\"\",\"1\"\r\n0.1,\"\",2\r\n";
    let (_, table) =
        NumericTable::read_with_time(&write("quoted.csv", text.as_bytes()), "t", &["x"]).unwrap();
    assert_eq!(table.column("x").unwrap(), &[1.0, 2.0]);
}

#[test]
fn a_blank_line_between_rows_is_named_and_blank_lines_at_the_end_are_ignored() {
    let text = plain(5).replacen("0.2,2,4\n", "0.2,2,4\n\n", 1);
    let message = numeric_error(&write("blank.csv", text.as_bytes()), &["x"]);
    assert!(
        message.contains("blank.csv:5: blank line between data rows"),
        "{message}"
    );
    let path = write("trailing.csv", format!("{}\n\r\n", plain(5)).as_bytes());
    let (time, _) = NumericTable::read_with_time(&path, "t", &["x"]).unwrap();
    assert_eq!(time.len(), 5);
}

#[test]
fn a_directory_is_not_a_csv_file() {
    let dir = temp_dir("layout-dir");
    let message = numeric_error(&dir, &["x"]);
    assert!(
        message.ends_with("is a directory, not a CSV file"),
        "{message}"
    );
    let message = FlightLog::read(&dir).unwrap_err().to_string();
    assert!(message.contains("is a directory"), "{message}");
}

#[test]
fn binary_and_non_utf8_files_are_not_text() {
    let message = numeric_error(
        &write("binary.csv", b"\x00\x01\x02binary\xc3\xbf\n"),
        &["x"],
    );
    assert!(
        message.contains("binary.csv:1: not a CSV text file: control byte 0x00"),
        "{message}"
    );
    // A ULog given where a CSV belongs is named for what it is, by the flight-log reader too.
    let ulog = write(
        "flight.ulg",
        b"ULog\x01\x12\x35\x01\x00\x00\x00\x00\x00\x00\x00",
    );
    for message in [
        numeric_error(&ulog, &["x"]),
        FlightLog::read(&ulog).unwrap_err().to_string(),
    ] {
        assert!(
            message.contains("flight.ulg:1: not a CSV text file: a PX4 ULog"),
            "{message}"
        );
    }
    let message = numeric_error(&write("latin1.csv", b"t,x\n0,1\n0.1,caf\xe9\n"), &["x"]);
    assert!(
        message.contains("latin1.csv:3: not a CSV text file: byte 0xE9 is not UTF-8"),
        "{message}"
    );
}

#[test]
fn crlf_byte_order_mark_and_quotes_read_as_plain_rows() {
    let expected =
        NumericTable::read_with_time(&write("plain.csv", plain(6).as_bytes()), "t", &["x", "y"])
            .unwrap();
    let crlf = plain(6).replace('\n', "\r\n");
    let mut bom = b"\xef\xbb\xbf".to_vec();
    bom.extend_from_slice(plain(6).as_bytes());
    let quoted: String = plain(6)
        .lines()
        .map(|line| {
            let cells: Vec<String> = line.split(',').map(|c| format!("\"{c}\"")).collect();
            cells.join(",") + "\n"
        })
        .collect();
    for (name, bytes) in [
        ("crlf.csv", crlf.into_bytes()),
        ("bom.csv", bom),
        ("quoted.csv", quoted.into_bytes()),
    ] {
        let read = NumericTable::read_with_time(&write(name, &bytes), "t", &["x", "y"])
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(read.0, expected.0, "{name}");
        assert_eq!(read.1.columns, expected.1.columns, "{name}");
    }
}

#[cfg(unix)]
#[test]
fn a_pipe_is_read_to_its_end() {
    let dir = temp_dir("layout-fifo");
    let fifo = dir.join("fifo.csv");
    let _ = std::fs::remove_file(&fifo);
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .expect("mkfifo runs");
    assert!(made.success());
    let writer = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::write(&fifo, plain(20)).unwrap())
    };
    let (time, table) = NumericTable::read_with_time(&fifo, "t", &["x"]).unwrap();
    writer.join().unwrap();
    assert_eq!(time.len(), 20);
    assert_eq!(table.column("x").unwrap()[19], 19.0);
}

#[test]
fn carriage_return_line_endings_are_refused_by_name() {
    let mac = plain(5).replace('\n', "\r");
    let message = numeric_error(&write("mac.csv", mac.as_bytes()), &["x"]);
    assert!(
        message.ends_with(
            "mac.csv:1: line endings are CR only (classic Mac): convert the file to LF or CRLF line endings"
        ),
        "{message}"
    );
    // A lone CR after LF lines, outside quotes: named by its line.
    let text = plain(5).replacen("0.2,2,4\n", "0.2,2,4\r0.25,2,4\n", 1);
    let message = numeric_error(&write("lone-cr.csv", text.as_bytes()), &["x"]);
    assert!(
        message.contains("lone-cr.csv:4: a carriage return (CR) not followed by a line feed"),
        "{message}"
    );
    // Inside a quoted cell a CR is text, and a last line ended by a CR alone is a line.
    let text = "t,x,note\r\n0,1,\"a\rb\"\r\n0.1,2,c\r";
    let (time, table) =
        NumericTable::read_with_time(&write("cr-in-cell.csv", text.as_bytes()), "t", &["x"])
            .unwrap();
    assert_eq!(time, [0.0, 0.1]);
    assert_eq!(table.column("x").unwrap(), &[1.0, 2.0]);
}

#[test]
fn a_long_header_name_is_cut_in_messages() {
    let name = "n".repeat(100_000);
    let text = format!("t,{name},{name}\n0,1,2\n0.1,1,2\n");
    let message = numeric_error(&write("long-name.csv", text.as_bytes()), &["x"]);
    assert!(message.len() < 400, "{message}");
    assert!(
        message.contains("… (100000 characters)' appears twice in the header (fields 2 and 3)"),
        "{message}"
    );
    let text = format!("t,x,{name}\n0,1\n");
    let message = numeric_error(&write("long-missing.csv", text.as_bytes()), &["x"]);
    assert!(message.len() < 400, "{message}");
    assert!(message.contains("no value for 'nnn"), "{message}");
}
