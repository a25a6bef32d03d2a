//! Issue 31, classes 8 and 9: `learn sindy` on a CSV read whole and read in blocks (`--stream`,
//! and every file over 8 MiB) gives the same fit or the same one-line error, and an error quotes
//! at most 80 characters of a cell, within bounded memory.

use std::path::Path;
use std::process::Command;

use crate::common::{Run, learn_in, scratch, signal};

/// `learn sindy` on `csv` in `dir` with states `states` and `extra` arguments.
fn sindy(dir: &Path, csv: &str, states: &str, extra: &[&str]) -> Run {
    let mut args = vec![
        "sindy",
        "--csv",
        csv,
        "--state",
        states,
        "--library",
        "poly:2",
        "--precision",
        "9",
    ];
    args.extend_from_slice(extra);
    learn_in(dir, &args)
}

/// Runs `learn sindy` on `csv` read whole and with `--stream`: both must give the same equations
/// and score, or fail with the same one-line message. Returns the whole-file run.
fn same_whole_and_streamed(dir: &Path, csv: &str, states: &str) -> Run {
    let whole = sindy(dir, csv, states, &[]);
    let streamed = sindy(dir, csv, states, &["--stream"]);
    assert_eq!(
        (whole.code, &whole.stdout, &whole.stderr),
        (streamed.code, &streamed.stdout, &streamed.stderr),
        "{csv}: whole (left) and streamed (right) differ"
    );
    whole
}

/// `signal(rows)` with line `line` (1-based, the header is line 1) replaced by `new`.
fn with_line(text: &str, line: usize, new: &str) -> String {
    let mut lines: Vec<&str> = text.lines().collect();
    lines[line - 1] = new;
    lines.join("\n") + "\n"
}

/// `signal(rows)` with `new` inserted before line `line`.
fn with_inserted(text: &str, line: usize, new: &str) -> String {
    let mut lines: Vec<&str> = text.lines().collect();
    lines.insert(line - 1, new);
    lines.join("\n") + "\n"
}

#[test]
fn a_repeated_header_name_is_refused_whole_and_streamed() {
    let dir = scratch("second-probe-repeated-name");
    let text = signal(300).replacen("t,x,y,u", "t,x,x,u", 1);
    std::fs::write(dir.join("dup.csv"), text).unwrap();
    same_whole_and_streamed(&dir, "dup.csv", "x")
        .one_line_error(&["dup.csv:1:x: column 'x' appears twice in the header (fields 2 and 3)"]);
}

#[test]
fn blank_and_comment_lines_are_named_by_their_own_line_whole_and_streamed() {
    let dir = scratch("second-probe-blank-comment");
    let blank = with_inserted(&signal(300), 100, "");
    std::fs::write(dir.join("blank.csv"), blank).unwrap();
    same_whole_and_streamed(&dir, "blank.csv", "x,y")
        .one_line_error(&["blank.csv:100: blank line between data rows"]);
    let comment = with_inserted(&signal(300), 200, "# calibrated again here");
    std::fs::write(dir.join("comment.csv"), comment).unwrap();
    same_whole_and_streamed(&dir, "comment.csv", "x,y")
        .one_line_error(&["comment.csv:200: a '#' comment line"]);
}

/// `signal(rows)` with a `note` column, quoted and over two lines on row `multi_line_row`
/// (1-based data row), with an escaped quote.
fn with_notes(rows: usize, multi_line_row: usize) -> String {
    signal(rows)
        .lines()
        .enumerate()
        .map(|(index, line)| match index {
            0 => format!("{line},note\n"),
            k if k == multi_line_row => format!("{line},\"said \"\"hi\"\",\nthen left\"\n"),
            _ => format!("{line},ok\n"),
        })
        .collect()
}

#[test]
fn a_quoted_cell_over_two_lines_is_read_whole_and_streamed_and_later_lines_are_exact() {
    let dir = scratch("second-probe-multi-line");
    std::fs::write(dir.join("notes.csv"), with_notes(300, 50)).unwrap();
    let fitted = same_whole_and_streamed(&dir, "notes.csv", "x,y");
    assert!(fitted.success().contains("x' = "), "{}", fitted.stdout);
    // The same fit as without the note column.
    std::fs::write(dir.join("plain.csv"), signal(300)).unwrap();
    assert_eq!(
        sindy(&dir, "plain.csv", "x,y", &["--stream"]).success(),
        fitted.stdout
    );
    // Row 200 (t = 1.99) starts on line 202, row 50's note taking two lines: a bad cell there
    // is named so.
    let text = with_row(&with_notes(300, 50), "1.99", "1.99,oops,0,0,ok");
    std::fs::write(dir.join("bad-after.csv"), text).unwrap();
    same_whole_and_streamed(&dir, "bad-after.csv", "x,y").one_line_error(&["bad-after.csv:202:x"]);
    // A fit error found after the row's block was dropped (x² overflows on row 250, line 252).
    let text = with_row(&with_notes(300, 50), "2.49", "2.49,1e200,0,0,ok");
    std::fs::write(dir.join("huge-after.csv"), text).unwrap();
    same_whole_and_streamed(&dir, "huge-after.csv", "x,y")
        .one_line_error(&["huge-after.csv:252:", "not finite"]);
}

/// `text` with the line of the row at time `time` replaced by `new`.
fn with_row(text: &str, time: &str, new: &str) -> String {
    let start = text
        .find(&format!("\n{time},"))
        .expect("a row at that time")
        + 1;
    let end = start + text[start..].find('\n').expect("the row ends");
    format!("{}{new}{}", &text[..start], &text[end..])
}

#[test]
fn carriage_return_line_endings_are_refused_alike_whole_and_streamed() {
    let dir = scratch("second-probe-cr");
    std::fs::write(dir.join("mac.csv"), signal(300).replace('\n', "\r")).unwrap();
    same_whole_and_streamed(&dir, "mac.csv", "x,y").one_line_error(&[
        "mac.csv:1: line endings are CR only (classic Mac): convert the file to LF or CRLF",
    ]);
    // CRLF is read as LF.
    std::fs::write(dir.join("crlf.csv"), signal(300).replace('\n', "\r\n")).unwrap();
    std::fs::write(dir.join("lf.csv"), signal(300)).unwrap();
    assert_eq!(
        same_whole_and_streamed(&dir, "crlf.csv", "x,y").success(),
        sindy(&dir, "lf.csv", "x,y", &[]).success()
    );
}

#[test]
fn a_long_cell_is_quoted_once_and_at_most_80_characters_whole_and_streamed() {
    let dir = scratch("second-probe-long-cell");
    let cell = "abc".repeat(1_000_000);
    let text = with_line(&signal(300), 2, &format!("0.00,{cell},0,0"));
    std::fs::write(dir.join("long.csv"), text).unwrap();
    let run = same_whole_and_streamed(&dir, "long.csv", "x,y");
    // The cell once, its first 80 characters, and its length.
    let message = run.one_line_error(&["long.csv:2:x"]);
    assert_eq!(
        message,
        format!(
            "error: long.csv:2:x: cannot parse \"{}…\" (3000000 characters): not a number",
            &cell[..80]
        )
    );
}

/// Class 8 as found: a 300 MB cell gave a 600 MB message and took 2.9 GB. A 150 MB cell (read in
/// blocks: the file is over 8 MiB) under 1 GiB of address space: one short line, within seconds.
#[test]
fn a_huge_cell_is_refused_in_one_short_line_within_bounded_memory() {
    let dir = scratch("second-probe-huge-cell");
    let cell = "7x".repeat(75_000_000);
    let text = with_line(&signal(300), 3, &format!("0.01,0.5,{cell},0"));
    std::fs::write(dir.join("huge.csv"), text).unwrap();
    drop(cell);
    let output = Command::new("sh")
        .arg("-c")
        .arg("ulimit -v 1048576 && exec \"$@\"")
        .arg("sh")
        .arg(env!("CARGO_BIN_EXE_learn"))
        .args(["sindy", "--csv", "huge.csv", "--state", "x,y"])
        .current_dir(&dir)
        .env("RUST_BACKTRACE", "0")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{:.2000}", stderr);
    let message = stderr.trim_end();
    assert_eq!(message.lines().count(), 1, "{:.2000}", message);
    assert!(message.len() < 300, "{:.2000}", message);
    assert!(
        message.contains("huge.csv:3:y: cannot parse \"7x7x")
            && message.ends_with("…\" (150000000 characters): not a number"),
        "{message}"
    );
}
