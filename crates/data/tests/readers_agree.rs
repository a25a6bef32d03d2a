//! The whole-file reader ([`NumericTable`]) and the block reader ([`NumericStream`], used by
//! `learn sindy --stream` and for every CSV over 8 MiB, directly or read ahead) agree (issue 31, class 9): on generated
//! files with blank and comment lines, quoted cells (multi-line, escaped quotes), LF, CRLF and
//! CR-only line endings, repeated header names, ragged rows, a byte-order mark and cells that are
//! not numbers, both read the same values on the same lines, or both fail with the same message.
//! Files generated without any fault read to the values written. Seeded (ChaCha, no persistence
//! files): every run tries the same [`CASES`] files, in well under a second.

mod common;

use std::path::Path;

use data::{NumericStream, NumericTable};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

/// Generated files per run.
const CASES: u32 = 3000;

/// How the lines of a generated file end.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Ending {
    Lf,
    CrLf,
    /// Classic Mac: a carriage return alone.
    Cr,
    /// LF or CRLF chosen per line.
    Mixed,
}

/// One cell of a generated row.
#[derive(Clone, Debug)]
enum Cell {
    Number(f64),
    QuotedNumber(f64),
    /// `"[a, b]"`, read as `v[0]`, `v[1]`.
    List(f64, f64),
    /// A quoted text over two lines, with an escaped quote.
    MultiLineText,
    Empty,
    NotANumber,
    /// `1,5` unquoted: a decimal comma, one field too many.
    DecimalComma,
}

/// A fault written before or into a row.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Fault {
    None,
    BlankLineBefore,
    CommentBefore,
    QuoteInCell,
    TextAfterClosingQuote,
    DropLastCell,
    ExtraCell,
    /// A quoted cell opened and never closed (the file's last row).
    UnclosedQuote,
}

#[derive(Clone, Debug)]
struct Row {
    cells: [Cell; 4],
    fault: Fault,
}

#[derive(Clone, Debug)]
struct GeneratedFile {
    byte_order_mark: bool,
    ending: Ending,
    /// The header is `t,x,v,note`; with this, `note` is named `x` again.
    repeated_name: bool,
    quoted_header: bool,
    rows: Vec<Row>,
    /// Line ends per row for [`Ending::Mixed`] (true: CRLF).
    mixed: Vec<bool>,
    final_line_end: bool,
    trailing_blank_lines: usize,
    /// Blank lines before the header.
    leading_blank_lines: usize,
}

fn number() -> impl Strategy<Value = f64> {
    prop_oneof![
        (-1000i32..1000).prop_map(f64::from),
        (-1e6f64..1e6),
        Just(1e300),
        Just(-0.0),
    ]
}

fn cell(clean: bool) -> BoxedStrategy<Cell> {
    let good = prop_oneof![
        4 => number().prop_map(Cell::Number),
        1 => number().prop_map(Cell::QuotedNumber),
    ];
    if clean {
        return good.boxed();
    }
    prop_oneof![
        60 => good,
        1 => Just(Cell::Empty),
        1 => Just(Cell::NotANumber),
        1 => Just(Cell::DecimalComma),
    ]
    .boxed()
}

fn row() -> impl Strategy<Value = Row> {
    let fault = prop_oneof![
        150 => Just(Fault::None),
        1 => Just(Fault::BlankLineBefore),
        1 => Just(Fault::CommentBefore),
        1 => Just(Fault::QuoteInCell),
        1 => Just(Fault::TextAfterClosingQuote),
        1 => Just(Fault::DropLastCell),
        1 => Just(Fault::ExtraCell),
        1 => Just(Fault::UnclosedQuote),
    ];
    let note = prop_oneof![
        3 => Just(Cell::MultiLineText),
        1 => Just(Cell::Empty),
        1 => Just(Cell::NotANumber),
    ];
    (
        cell(false),
        cell(false),
        (number(), number(), prop::bool::weighted(0.97)),
        note,
        fault,
    )
        .prop_map(|(t, x, (a, b, list), note, fault)| Row {
            cells: [
                t,
                x,
                if list { Cell::List(a, b) } else { Cell::Empty },
                note,
            ],
            fault,
        })
}

fn generated_file() -> impl Strategy<Value = GeneratedFile> {
    let ending = prop_oneof![
        6 => Just(Ending::Lf),
        4 => Just(Ending::CrLf),
        1 => Just(Ending::Cr),
        2 => Just(Ending::Mixed),
    ];
    (
        any::<bool>(),
        ending,
        prop::bool::weighted(0.05),
        any::<bool>(),
        prop::collection::vec(row(), 0..9),
        prop::collection::vec(any::<bool>(), 9),
        prop::bool::weighted(0.8),
        0usize..3,
        prop::bool::weighted(0.1).prop_map(usize::from),
    )
        .prop_map(
            |(
                byte_order_mark,
                ending,
                repeated_name,
                quoted_header,
                rows,
                mixed,
                final_line_end,
                trailing_blank_lines,
                leading_blank_lines,
            )| GeneratedFile {
                byte_order_mark,
                ending,
                repeated_name,
                quoted_header,
                rows,
                mixed,
                final_line_end,
                trailing_blank_lines,
                leading_blank_lines,
            },
        )
}

/// A file with no fault: LF or CRLF, unique names, good cells, the list column filled.
fn clean_file() -> impl Strategy<Value = GeneratedFile> {
    let row = (cell(true), cell(true), number(), number()).prop_map(|(t, x, a, b)| Row {
        cells: [t, x, Cell::List(a, b), Cell::MultiLineText],
        fault: Fault::None,
    });
    (
        generated_file(),
        prop::collection::vec(row, 1..9),
        prop_oneof![Just(Ending::Lf), Just(Ending::CrLf), Just(Ending::Mixed)],
    )
        .prop_map(|(file, rows, ending)| GeneratedFile {
            repeated_name: false,
            rows,
            ending,
            ..file
        })
}

impl GeneratedFile {
    fn line_end(&self, index: usize) -> &'static str {
        match self.ending {
            Ending::Lf => "\n",
            Ending::CrLf => "\r\n",
            Ending::Cr => "\r",
            Ending::Mixed if self.mixed[index % self.mixed.len()] => "\r\n",
            Ending::Mixed => "\n",
        }
    }

    fn bytes(&self) -> Vec<u8> {
        let mut text = String::new();
        if self.byte_order_mark {
            text.push('\u{feff}');
        }
        for index in 0..self.leading_blank_lines {
            text.push_str(self.line_end(index));
        }
        let last = if self.repeated_name { "x" } else { "note" };
        let names = ["t", "x", "v", last];
        let header: Vec<String> = names
            .iter()
            .map(|name| match self.quoted_header {
                true => format!("\"{name}\""),
                false => name.to_string(),
            })
            .collect();
        text.push_str(&header.join(","));
        for (index, row) in self.rows.iter().enumerate() {
            let end = self.line_end(index);
            text.push_str(end);
            match row.fault {
                Fault::BlankLineBefore => text.push_str(end),
                Fault::CommentBefore => text.push_str(&format!("# a note{end}")),
                _ => {}
            }
            let mut cells: Vec<String> = row.cells.iter().map(|cell| render(cell, end)).collect();
            match row.fault {
                Fault::QuoteInCell => cells[1].push('"'),
                Fault::TextAfterClosingQuote => cells[1] = format!("\"{}\"9", cells[1]),
                Fault::DropLastCell => {
                    cells.pop();
                }
                Fault::ExtraCell => cells.push("1".to_string()),
                Fault::UnclosedQuote => cells[3] = "\"never closed".to_string(),
                _ => {}
            }
            text.push_str(&cells.join(","));
            if row.fault == Fault::UnclosedQuote {
                break;
            }
        }
        if self.final_line_end {
            text.push_str(self.line_end(self.rows.len()));
        }
        for index in 0..self.trailing_blank_lines {
            text.push_str(self.line_end(index));
        }
        text.into_bytes()
    }

    /// The values of `t`, `x` and `v[1]` written, when every row is clean.
    fn written(&self) -> Vec<[f64; 3]> {
        let value = |cell: &Cell| match *cell {
            Cell::Number(v) | Cell::QuotedNumber(v) => v,
            _ => panic!("not a clean cell: {cell:?}"),
        };
        let element = |cell: &Cell| match *cell {
            Cell::List(_, b) => b,
            _ => panic!("not a list: {cell:?}"),
        };
        self.rows
            .iter()
            .map(|row| {
                [
                    value(&row.cells[0]),
                    value(&row.cells[1]),
                    element(&row.cells[2]),
                ]
            })
            .collect()
    }
}

fn render(cell: &Cell, end: &str) -> String {
    match cell {
        Cell::Number(v) => v.to_string(),
        Cell::QuotedNumber(v) => format!("\"{v}\""),
        Cell::List(a, b) => format!("\"[{a}, {b}]\""),
        Cell::MultiLineText => format!("\"said \"\"hi\"\",{end}then left\""),
        Cell::Empty => String::new(),
        Cell::NotANumber => "abc".to_string(),
        Cell::DecimalComma => "1,5".to_string(),
    }
}

/// What a reader made of a file: per row its line and values, or the error message.
type Reading = Result<Vec<(usize, Vec<u64>)>, String>;

fn read_whole(path: &Path, columns: &[&str]) -> Reading {
    let table = NumericTable::read(path, columns).map_err(|e| e.to_string())?;
    Ok((0..table.rows())
        .map(|k| {
            let values = table.columns.iter().map(|c| c[k].to_bits()).collect();
            (table.line(k), values)
        })
        .collect())
}

fn read_streamed(path: &Path, columns: &[&str], block_rows: usize) -> Reading {
    let stream = NumericStream::open(path, columns).map_err(|e| e.to_string())?;
    read_blocks(stream, block_rows)
}

/// The block reader parsing `chunk_bytes` of the file at a time, each chunk cut into pieces.
fn read_in_chunks(path: &Path, columns: &[&str], block_rows: usize, chunk_bytes: usize) -> Reading {
    let stream =
        NumericStream::open_in_chunks(path, columns, chunk_bytes).map_err(|e| e.to_string())?;
    read_blocks(stream, block_rows)
}

fn read_blocks(mut stream: NumericStream, block_rows: usize) -> Reading {
    let mut rows = Vec::new();
    while let Some(block) = stream.next_block(block_rows).map_err(|e| e.to_string())? {
        for (k, &line) in block.lines.iter().enumerate() {
            rows.push((line, block.columns.iter().map(|c| c[k].to_bits()).collect()));
        }
    }
    Ok(rows)
}

/// The same blocks read ahead on a thread of their own ([`NumericStream::read_ahead`]).
fn read_ahead(path: &Path, columns: &[&str], block_rows: usize) -> Reading {
    let stream = NumericStream::open(path, columns).map_err(|e| e.to_string())?;
    let mut stream = stream.read_ahead(block_rows, 2);
    let mut rows = Vec::new();
    while let Some(block) = stream.next_block().map_err(|e| e.to_string())? {
        for (k, &line) in block.lines.iter().enumerate() {
            rows.push((line, block.columns.iter().map(|c| c[k].to_bits()).collect()));
        }
    }
    // After the end (or an error), the stream stays ended.
    assert!(matches!(stream.next_block(), Ok(None)));
    Ok(rows)
}

fn runner(seed: u8) -> TestRunner {
    let config = Config {
        cases: CASES,
        failure_persistence: None,
        ..Config::default()
    };
    TestRunner::new_with_rng(
        config,
        TestRng::from_seed(RngAlgorithm::ChaCha, &[seed; 32]),
    )
}

/// The column selections read from every file: plain columns, an element of a list column.
const SELECTIONS: [&[&str]; 2] = [&["t", "x"], &["x", "v[1]", "t"]];

#[test]
fn the_whole_file_and_block_readers_agree_on_generated_files() {
    let dir = common::temp_dir("readers-agree");
    let path = dir.join("generated.csv");
    let outcomes = std::cell::Cell::new([0usize; 2]);
    runner(31)
        .run(
            &(generated_file(), 1usize..4, 1usize..96),
            |(file, block_rows, chunk)| {
                std::fs::write(&path, file.bytes()).unwrap();
                for columns in SELECTIONS {
                    let whole = read_whole(&path, columns);
                    let streamed = read_streamed(&path, columns, block_rows);
                    prop_assert_eq!(&whole, &streamed, "{:?} {:?}", columns, file);
                    let chunked = read_in_chunks(&path, columns, block_rows, chunk);
                    prop_assert_eq!(
                        &whole,
                        &chunked,
                        "chunks of {}: {:?} {:?}",
                        chunk,
                        columns,
                        file
                    );
                    let ahead = read_ahead(&path, columns, block_rows);
                    prop_assert_eq!(&whole, &ahead, "read ahead: {:?} {:?}", columns, file);
                    if let Err(message) = &whole {
                        prop_assert!(!message.contains('\n'), "one line: {}", message);
                        prop_assert!(message.starts_with(&path.display().to_string()));
                    }
                    let mut counts = outcomes.get();
                    counts[usize::from(whole.is_ok())] += 1;
                    outcomes.set(counts);
                }
                Ok(())
            },
        )
        .unwrap();
    // Both outcomes are exercised, not only refusals.
    let [refused, read] = outcomes.get();
    eprintln!("{read} read, {refused} refused");
    assert!(
        read > 1500 && refused > 1500,
        "{read} read, {refused} refused"
    );
}

#[test]
fn generated_files_without_a_fault_read_to_the_values_written() {
    let dir = common::temp_dir("readers-clean");
    let path = dir.join("clean.csv");
    runner(32)
        .run(
            &(clean_file(), 1usize..4, 1usize..96),
            |(file, block_rows, chunk)| {
                std::fs::write(&path, file.bytes()).unwrap();
                let columns = ["t", "x", "v[1]"];
                let whole = read_whole(&path, &columns);
                prop_assert_eq!(&whole, &read_streamed(&path, &columns, block_rows));
                let chunked = read_in_chunks(&path, &columns, block_rows, chunk);
                prop_assert_eq!(&whole, &chunked, "chunks of {}", chunk);
                let rows = whole.map_err(TestCaseError::fail)?;
                let written = file.written();
                prop_assert_eq!(rows.len(), written.len());
                // Each row after the first starts two lines after the one before: the note of every
                // row spans two lines.
                let header_line = 1 + file.leading_blank_lines;
                for (k, ((line, values), expected)) in rows.iter().zip(&written).enumerate() {
                    prop_assert_eq!(*line, header_line + 1 + 2 * k);
                    let expected: Vec<u64> = expected.iter().map(|v| v.to_bits()).collect();
                    prop_assert_eq!(values, &expected);
                }
                Ok(())
            },
        )
        .unwrap();
}

#[test]
fn a_stream_read_ahead_and_left_early_stops_its_reader() {
    let dir = common::temp_dir("read-ahead-left");
    let path = dir.join("long.csv");
    let mut text = String::from("t,x\n");
    for k in 0..20_000 {
        text.push_str(&format!("{k},{}\n", k * 2));
    }
    std::fs::write(&path, text).unwrap();
    let mut stream = NumericStream::open(&path, &["x"])
        .unwrap()
        .read_ahead(100, 1);
    let first = stream.next_block().unwrap().unwrap();
    assert_eq!(first.columns[0][..3], [0.0, 2.0, 4.0]);
    assert_eq!(first.lines[..2], [2, 3]);
    // Dropped with 199 blocks unread: the reader, blocked on a full queue, ends and is joined.
    drop(stream);
}

/// A line of a generated file without quotes.
#[derive(Clone, Copy, Debug)]
enum PlainLine {
    Row(u16),
    Blank,
    Comment,
    ExtraCell,
    NotANumber,
    TooFewCells,
    EmptyCell,
    NotFinite,
    Tab,
    LoneCarriageReturn,
    ControlByte,
    NotAscii,
}

/// Files without a quote, whose pieces are cut without looking at every byte and read by the fast
/// path where they are plain: plain rows with blank lines (between rows, an error; at the end,
/// allowed), comments, bad rows and bytes the fast path leaves to the splitter among them.
fn plain_file() -> impl Strategy<Value = (Vec<PlainLine>, bool, bool)> {
    let line = prop_oneof![
        60 => any::<u16>().prop_map(PlainLine::Row),
        3 => Just(PlainLine::Blank),
        1 => Just(PlainLine::Comment),
        1 => Just(PlainLine::ExtraCell),
        1 => Just(PlainLine::NotANumber),
        1 => Just(PlainLine::TooFewCells),
        1 => Just(PlainLine::EmptyCell),
        1 => Just(PlainLine::NotFinite),
        2 => Just(PlainLine::Tab),
        1 => Just(PlainLine::LoneCarriageReturn),
        1 => Just(PlainLine::ControlByte),
        1 => Just(PlainLine::NotAscii),
    ];
    (
        proptest::collection::vec(line, 0..40),
        any::<bool>(),
        any::<bool>(),
    )
}

/// The text of `lines`, with CRLF line ends or LF, and a line end after the last line or not.
fn plain_text(lines: &[PlainLine], crlf: bool, last_end: bool) -> Vec<u8> {
    let end = if crlf { "\r\n" } else { "\n" };
    let mut text = format!("t,x{end}");
    for line in lines {
        let body = match line {
            PlainLine::Row(v) => format!("{v},{}", f64::from(*v) / 8.0),
            PlainLine::Blank => String::new(),
            PlainLine::Comment => "# note".to_string(),
            PlainLine::ExtraCell => "1,2,3".to_string(),
            PlainLine::NotANumber => "1,x".to_string(),
            PlainLine::TooFewCells => "1".to_string(),
            PlainLine::EmptyCell => "1,".to_string(),
            PlainLine::NotFinite => "1,inf".to_string(),
            PlainLine::Tab => "1,\t2.5".to_string(),
            PlainLine::LoneCarriageReturn => "1,2\r5".to_string(),
            PlainLine::ControlByte => "1,2\u{1}".to_string(),
            PlainLine::NotAscii => "1,2é".to_string(),
        };
        text.push_str(&body);
        text.push_str(end);
    }
    if !last_end {
        text.truncate(text.len() - end.len());
    }
    text.into_bytes()
}

#[test]
fn files_without_quotes_read_the_same_in_pieces() {
    let dir = common::temp_dir("readers-plain");
    let path = dir.join("plain.csv");
    runner(33)
        .run(
            &(plain_file(), 1usize..4, 1usize..1024),
            |((lines, crlf, last_end), block_rows, chunk)| {
                std::fs::write(&path, plain_text(&lines, crlf, last_end)).unwrap();
                let whole = read_whole(&path, &["x", "t"]);
                let chunked = read_in_chunks(&path, &["x", "t"], block_rows, chunk);
                prop_assert_eq!(&whole, &chunked, "chunks of {}: {:?}", chunk, lines);
                Ok(())
            },
        )
        .unwrap();
}
