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

/// The `pwm` lists hold a command per rotor: six read as a hexarotor's, nine are refused.
#[test]
fn pwm_lists_hold_one_command_per_rotor() {
    let (_, text) = synthetic_csv(&temp_dir("six-src"), 20);
    let column = column_index(&text, "pwm");
    let mut six = text.clone();
    for row in 0..20 {
        six = replace_cell(
            &six,
            row,
            column,
            "\"[1000.0, 1100.0, 1200.0, 1300.0, 1400.0, 1500.0]\"",
        );
    }
    let dir = temp_dir("six");
    let path = dir.join("six.csv");
    std::fs::write(&path, &six).unwrap();
    let log = FlightLog::read(&path).unwrap();
    assert_eq!(log.motor_command.count(), 6);
    assert_eq!(log.motor_command.row(19)[5], 1500.0);
    let nine = replace_cell(
        &text,
        0,
        column,
        &format!("\"[{}]\"", ["1000.0"; 9].join(", ")),
    );
    let message = error_of(&nine, "nine");
    assert!(
        message.contains("bad.csv:2:pwm") && message.contains("9 motors; expected 1 to 8"),
        "{message}"
    );
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

/// `error_of` for a copy of the synthetic log with one cell replaced on data row 100 (line 102).
fn error_with_cell(column: &str, value: &str, name: &str) -> String {
    let (_, text) = synthetic_csv(&temp_dir(&format!("{name}-src")), 150);
    error_of(
        &replace_cell(&text, 100, column_index(&text, column), value),
        name,
    )
}

#[test]
fn physically_implausible_values_name_file_line_and_column() {
    let cases = [
        (
            "p",
            "\"[0.1, 1e308, 0.3]\"",
            "bad.csv:102:p: 1e308 is outside the plausible range [-10000, 10000] m of a position component",
        ),
        (
            "v",
            "\"[1e308, 0.0, 0.0]\"",
            "bad.csv:102:v: 1e308 is outside the plausible range [-1000, 1000] m/s of a velocity component",
        ),
        (
            "v",
            "\"[1e200, 0.0, 0.0]\"",
            "bad.csv:102:v: 1e200 is outside",
        ),
        (
            "v",
            "\"[0.0, -1000.5, 0.0]\"",
            "bad.csv:102:v: -1000.5 is outside",
        ),
        (
            "w",
            "\"[0.0, 0.0, 1e300]\"",
            "bad.csv:102:w: 1e300 is outside the plausible range [-1000, 1000] rad/s of an angular rate component",
        ),
        (
            "T_sp",
            "[1e308]",
            "bad.csv:102:T_sp: 1e308 is outside the plausible range [0, 100] of the normalised thrust setpoint",
        ),
        (
            "T_sp",
            "[-0.5]",
            "bad.csv:102:T_sp: -0.5 is outside the plausible range [0, 100]",
        ),
        (
            "hover_throttle",
            "[1e-300]",
            "bad.csv:102:hover_throttle: 1e-300 is outside the plausible range [0.001, 10] of the normalised hover throttle",
        ),
        (
            "hover_throttle",
            "[0.0]",
            "bad.csv:102:hover_throttle: 0 is outside",
        ),
        (
            "hover_throttle",
            "[-0.47]",
            "bad.csv:102:hover_throttle: -0.47 is outside",
        ),
        (
            "pwm",
            "\"[1300.0, 1e308, 1300.0, 1300.0]\"",
            "bad.csv:102:pwm: 1e308 is outside the plausible range [0, 100000] of a motor command",
        ),
        (
            "pwm",
            "\"[1300.0, -1.0, 1300.0, 1300.0]\"",
            "bad.csv:102:pwm: -1 is outside",
        ),
        (
            "p_d",
            "\"[0.0, 0.0, 2e4]\"",
            "bad.csv:102:p_d: 20000 is outside",
        ),
        (
            "v_d",
            "\"[0.0, 5e3, 0.0]\"",
            "bad.csv:102:v_d: 5000 is outside",
        ),
        (
            "fa",
            "\"[1e300, 0.0, 0.0]\"",
            "bad.csv:102:fa: 1e300 is outside the plausible range [-100000, 100000] N of a residual force component",
        ),
        (
            "q_sp",
            "\"[0.0, 0.0, 0.0, 1e9]\"",
            "bad.csv:102:q_sp: 1000000000 is outside",
        ),
    ];
    for (k, (column, value, expected)) in cases.into_iter().enumerate() {
        let message = error_with_cell(column, value, &format!("implausible-{k}"));
        assert!(
            message.starts_with(&std::env::temp_dir().display().to_string()),
            "{message}"
        );
        assert!(message.contains(expected), "{column} = {value}: {message}");
    }
}

#[test]
fn values_inside_the_plausible_ranges_still_load() {
    let (_, text) = synthetic_csv(&temp_dir("plausible-src"), 150);
    let mut text = replace_cell(
        &text,
        100,
        column_index(&text, "v"),
        "\"[999.0, -999.0, 0.0]\"",
    );
    for (column, value) in [
        ("p", "\"[9999.0, -9999.0, 0.0]\""),
        ("w", "\"[999.0, 0.0, -999.0]\""),
        ("T_sp", "[0.0]"),
        ("hover_throttle", "[0.001]"),
        ("pwm", "\"[0.0, 99999.0, 1000.0, 2000.0]\""),
    ] {
        text = replace_cell(&text, 100, column_index(&text, column), value);
    }
    let dir = temp_dir("plausible");
    let path = dir.join("edge.csv");
    std::fs::write(&path, text).unwrap();
    let log = FlightLog::read(&path).unwrap();
    assert_eq!(log.velocity[100], [999.0, -999.0, 0.0]);
    assert_eq!(log.hover_throttle[100], 0.001);
    assert_eq!(log.motor_command.row(100), [0.0, 99999.0, 1000.0, 2000.0]);
}

/// The synthetic log with every time multiplied by `factor` (written with full precision).
fn error_with_time_scaled(factor: f64, name: &str) -> String {
    let mut log = common::synthetic_log(150);
    for t in &mut log.time {
        *t *= factor;
    }
    let dir = temp_dir(name);
    let path = dir.join("bad.csv");
    log.write_csv(&path).unwrap();
    let message = FlightLog::read(&path).unwrap_err().to_string();
    assert!(!message.contains('\n'), "one line: {message}");
    message
}

#[test]
fn implausible_sample_intervals_are_rejected() {
    // Every time × 1e-300: strictly increasing and uniform, but 2e-302 s apart.
    let message = error_with_time_scaled(1e-300, "time-tiny");
    assert!(
        message.contains("bad.csv:3:t: sample interval 2"),
        "{message}"
    );
    assert!(
        message.contains(
            "e-302 s is outside the plausible range [1e-5, 10] s of a flight log (is the time in seconds?)"
        ),
        "{message}"
    );
    // Milliseconds instead of seconds, and microseconds.
    let message = error_with_time_scaled(1000.0, "time-ms");
    assert!(
        message.contains("bad.csv:3:t: sample interval 20"),
        "{message}"
    );
    let message = error_with_time_scaled(1e-6, "time-us");
    assert!(
        message.contains("bad.csv:3:t: sample interval 2"),
        "{message}"
    );
    assert!(message.contains("e-8 s is outside"), "{message}");
    let message = error_with_time_scaled(501.0, "time-10s");
    assert!(
        message.contains("bad.csv:3:t: sample interval 10.02"),
        "{message}"
    );
    // 10 kHz (the simulator's fastest rate) and 0.1 Hz logs are still plausible.
    for (factor, name) in [(5e-3, "time-10khz"), (499.0, "time-slow")] {
        let mut log = common::synthetic_log(150);
        for t in &mut log.time {
            *t *= factor;
        }
        let dir = temp_dir(name);
        let path = dir.join("ok.csv");
        log.write_csv(&path).unwrap();
        FlightLog::read(&path).unwrap();
    }
}

#[test]
fn a_numeric_time_axis_error_names_its_own_column() {
    let dir = temp_dir("numeric-time");
    let path = dir.join("plain.csv");
    std::fs::write(&path, "time,x\n0,1\n0.1,2\n0.05,3\n0.3,4\n").unwrap();
    let message = NumericTable::read_with_time(&path, "time", &["x"])
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("plain.csv:4:time: time is not strictly increasing (0.1 then 0.05)"),
        "{message}"
    );
    std::fs::write(&path, "time,x\n0,1\n0.1,2\n0.2,3\n0.5,4\n").unwrap();
    let message = NumericTable::read_with_time(&path, "time", &["x"])
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("plain.csv:5:time: sample interval is not uniform"),
        "{message}"
    );
}

/// A part of a log (`learn mismatch --rows A:B`): the rows asked for, every column cut alike;
/// nothing for an empty range or one past the end.
#[test]
fn a_row_range_cuts_every_column_alike() {
    let log = common::synthetic_log(100);
    let part = log.row_range(10..40).unwrap();
    assert_eq!(part.len(), 30);
    assert_eq!(part.time[0], log.time[10]);
    assert_eq!(part.motor_command.row(29), log.motor_command.row(39));
    assert_eq!(part.residual_force.as_ref().unwrap().len(), 30);
    assert_eq!(part.attitude_setpoint.as_ref().unwrap().len(), 30);
    assert_eq!(part.path, log.path);
    assert!(log.row_range(90..101).is_none());
    assert!(log.row_range(5..5).is_none());
    assert_eq!(log.row_range(0..100).unwrap().len(), 100);
}
