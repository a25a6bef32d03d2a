//! Every kind of bad input gives a one-line error naming the file, row and column.

mod common;

use common::{synthetic_csv, temp_dir};
use data::{FlightLog, NumericTable};

fn error_of(text: &str, name: &str) -> String {
    let dir = temp_dir(name);
    let path = dir.join("bad.csv");
    std::fs::write(&path, text).unwrap();
    let message = FlightLog::read(&path).unwrap_err().to_string();
    assert!(!message.contains('\n'), "one line: {message}");
    assert!(message.contains("bad.csv"), "names the file: {message}");
    message
}

/// Replaces, on data row `index` (0-based), the cell of the given column.
fn replace_cell(text: &str, index: usize, column: usize, value: &str) -> String {
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let line = &lines[index + 1];
    let mut cells = split_cells(line);
    cells[column] = value.to_string();
    lines[index + 1] = cells.join(",");
    lines.join("\n") + "\n"
}

fn split_cells(line: &str) -> Vec<String> {
    let mut cells = vec![String::new()];
    let mut quoted = false;
    for c in line.chars() {
        match c {
            '"' => {
                quoted = !quoted;
                cells.last_mut().unwrap().push(c);
            }
            ',' if !quoted => cells.push(String::new()),
            _ => cells.last_mut().unwrap().push(c),
        }
    }
    cells
}

fn column_index(text: &str, name: &str) -> usize {
    text.lines()
        .next()
        .unwrap()
        .split(',')
        .position(|c| c == name)
        .unwrap()
}

#[test]
fn a_clean_synthetic_log_round_trips() {
    let dir = temp_dir("clean");
    let (path, _) = synthetic_csv(&dir, 50);
    let log = FlightLog::read(&path).unwrap();
    let original = common::synthetic_log(50);
    assert_eq!(log.len(), 50);
    assert_eq!(log.position, original.position);
    assert_eq!(log.rotation, original.rotation);
    assert_eq!(log.motor_command, original.motor_command);
    assert_eq!(log.meta.unwrap().condition, "35wind");
}

#[test]
fn missing_column() {
    let (_, text) = synthetic_csv(&temp_dir("missing-src"), 20);
    let header = text.lines().next().unwrap().replace(",pwm", ",motors");
    let body: Vec<&str> = text.lines().skip(1).collect();
    let message = error_of(&format!("{header}\n{}\n", body.join("\n")), "missing");
    assert!(message.contains("missing column 'pwm'"), "{message}");
}

#[test]
fn unparseable_cell() {
    let (_, text) = synthetic_csv(&temp_dir("cell-src"), 20);
    let broken = replace_cell(&text, 6, column_index(&text, "v"), "\"[0.1, zero, 0.3]\"");
    let message = error_of(&broken, "cell");
    assert!(message.contains("bad.csv:8:v:"), "{message}");
    assert!(message.contains("'zero' is not a number"), "{message}");
}

#[test]
fn array_of_the_wrong_length() {
    let (_, text) = synthetic_csv(&temp_dir("len-src"), 20);
    let broken = replace_cell(
        &text,
        3,
        column_index(&text, "pwm"),
        "\"[1000.0, 1000.0, 1000.0]\"",
    );
    let message = error_of(&broken, "len");
    assert!(
        message.contains("bad.csv:5:pwm: expected 4 values, found 3"),
        "{message}"
    );
}

#[test]
fn nan_and_infinite_values() {
    let (_, text) = synthetic_csv(&temp_dir("nan-src"), 20);
    let broken = replace_cell(&text, 10, column_index(&text, "w"), "\"[0.0, NaN, 0.0]\"");
    let message = error_of(&broken, "nan");
    assert!(
        message.contains("bad.csv:12:w: value is not finite (NaN)"),
        "{message}"
    );
    let broken = replace_cell(&text, 2, column_index(&text, "T_sp"), "[inf]");
    let message = error_of(&broken, "inf");
    assert!(
        message.contains("bad.csv:4:T_sp: value is not finite (inf)"),
        "{message}"
    );
}

#[test]
fn empty_file_and_header_only() {
    let message = error_of("", "empty");
    assert!(message.contains("empty"), "{message}");
    let (_, text) = synthetic_csv(&temp_dir("header-src"), 20);
    let message = error_of(&format!("{}\n", text.lines().next().unwrap()), "header");
    assert!(
        message.contains("empty") || message.contains("no data rows"),
        "{message}"
    );
}

#[test]
fn time_not_strictly_increasing() {
    let (_, text) = synthetic_csv(&temp_dir("time-src"), 20);
    let broken = replace_cell(&text, 7, column_index(&text, "t"), "0.1");
    let message = error_of(&broken, "time");
    assert!(
        message.contains("bad.csv:9:t: time is not strictly increasing (0.12 then 0.1)"),
        "{message}"
    );
}

#[test]
fn non_uniform_sampling_reports_the_worst_gap() {
    let (_, text) = synthetic_csv(&temp_dir("gap-src"), 20);
    // A dropped sample at the end: the last interval is 0.04 s instead of 0.02 s.
    let broken = replace_cell(&text, 19, column_index(&text, "t"), "0.4");
    let message = error_of(&broken, "gap");
    assert!(
        message.contains("bad.csv:21:t: sample interval is not uniform: worst gap 0.0"),
        "{message}"
    );
    assert!(message.contains("against a median of 0.02"), "{message}");
}

#[test]
fn truncated_file_names_the_row() {
    let (_, text) = synthetic_csv(&temp_dir("trunc-src"), 20);
    let cut = text.len() - 60;
    let message = error_of(&text[..cut], "trunc");
    assert!(message.contains("bad.csv"), "{message}");
    assert!(
        message.contains(":21:") || message.contains("CSV"),
        "{message}"
    );
}

#[test]
fn numeric_tables_name_missing_and_bad_columns() {
    let dir = temp_dir("numeric");
    let path = dir.join("plain.csv");
    std::fs::write(&path, "t,x,y\n0,1,2\n0.1,1.5,abc\n0.2,2,3\n").unwrap();
    let message = NumericTable::read(&path, &["t", "x", "z"])
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("missing column 'z'") && message.contains("t, x, y"),
        "{message}"
    );
    let message = NumericTable::read(&path, &["y"]).unwrap_err().to_string();
    assert!(message.contains("plain.csv:3:y:"), "{message}");
    let (time, table) = NumericTable::read_with_time(&path, "t", &["x"]).unwrap();
    assert_eq!(time, vec![0.0, 0.1, 0.2]);
    assert_eq!(table.column("x").unwrap(), &[1.0, 1.5, 2.0]);
}

#[test]
fn a_recorded_rotation_that_is_not_a_rotation() {
    let (_, text) = synthetic_csv(&temp_dir("rotation-src"), 20);
    let column = column_index(&text, "R");
    let scaled = "\"[[2.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 2.0]]\"";
    let message = error_of(&replace_cell(&text, 5, column, scaled), "rotation");
    assert!(
        message.contains("bad.csv:7:R:") && message.contains("not a rotation matrix"),
        "{message}"
    );
    // A reflection keeps R Rᵀ = I but is not a rotation either.
    let reflection = "\"[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]]\"";
    let message = error_of(&replace_cell(&text, 5, column, reflection), "reflection");
    assert!(message.contains("determinant -1"), "{message}");
    // A rotation, but not the one q describes.
    let turned = "\"[[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]\"";
    let message = error_of(&replace_cell(&text, 5, column, turned), "disagree");
    assert!(
        message.contains("bad.csv:7:R:") && message.contains("does not match the rotation of q"),
        "{message}"
    );
}
