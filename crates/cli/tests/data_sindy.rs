//! `learn sindy`, `learn data inspect` and `learn conditions` on bad input: a one-line error naming
//! the file, the line and the column or field, exit code 1, never a panic; and valid input that
//! used to be refused (a pipe) or misreported (absent columns) is handled; a `--data` that is not a
//! directory is named.

mod common;

use std::path::Path;

use common::{learn_in, scratch, signal};

/// `text` with line `line` (1-based) replaced by `new` (which may hold several lines).
fn with_line(text: &str, line: usize, new: &str) -> String {
    let mut lines: Vec<&str> = text.lines().collect();
    lines[line - 1] = new;
    lines.join("\n") + "\n"
}

fn sindy(dir: &Path, csv: &str, library: &str, extra: &[&str]) -> common::Run {
    let mut args = vec![
        "sindy",
        "--csv",
        csv,
        "--state",
        "x,y",
        "--control",
        "u",
        "--library",
        library,
    ];
    args.extend_from_slice(extra);
    learn_in(dir, &args)
}

#[test]
fn a_library_that_repeats_a_feature_is_refused_before_anything_is_written() {
    let dir = scratch("sindy-dup-features");
    std::fs::write(dir.join("s.csv"), signal(200)).unwrap();
    let run = sindy(&dir, "s.csv", "poly:2+poly:2", &["--out", "model.json"]);
    run.one_line_error(&["library 'poly:2+poly:2'", "twice"]);
    assert!(!dir.join("model.json").exists());
    let run = sindy(&dir, "s.csv", "poly:1:noconstant+fourier:1", &[]);
    assert!(run.success().contains("x' ="));
}

#[test]
fn fewer_rows_than_features_is_an_error_naming_the_counts() {
    let dir = scratch("sindy-underdetermined");
    std::fs::write(dir.join("short.csv"), signal(5)).unwrap();
    let run = sindy(&dir, "short.csv", "poly:3", &[]);
    run.one_line_error(&["short.csv", "5 data rows", "20 features", "poly:3"]);
    // As many rows as features is enough.
    std::fs::write(dir.join("twenty.csv"), signal(20)).unwrap();
    sindy(&dir, "twenty.csv", "poly:3", &[]).success();
}

#[test]
fn an_overflowing_feature_names_the_line_and_the_feature() {
    let dir = scratch("sindy-overflow");
    let text = with_line(&signal(100), 5, "0.03,1e200,0.5,0.1");
    std::fs::write(dir.join("huge.csv"), text).unwrap();
    let run = sindy(&dir, "huge.csv", "poly:2", &[]);
    // Data row 3 (t = 0.03) is line 5 of the file.
    let message = run.one_line_error(&["huge.csv:5:", "feature 'x^2'", "not finite"]);
    assert!(!message.contains("row 3, column"), "{message}");
}

#[test]
fn a_too_long_savgol_window_is_named_as_written() {
    let dir = scratch("sindy-savgol");
    std::fs::write(dir.join("s.csv"), signal(100)).unwrap();
    let run = sindy(&dir, "s.csv", "poly:1", &["--derivative", "savgol:101:2"]);
    let message = run.one_line_error(&["s.csv", "savgol:101:2 estimator needs at least 101"]);
    assert!(!message.contains("SavitzkyGolay"), "{message}");
}

#[test]
fn csv_layout_faults_name_the_file_and_line() {
    let dir = scratch("sindy-layout");
    let good = signal(50);
    let mut noted: Vec<String> = good.lines().map(|l| format!("{l},n")).collect();
    noted[0] = "t,x,y,u,note".to_string();
    noted[2] = noted[2].replace(",n", ",\"two\nlines\"");
    noted[6] = "0.05,abc,0.5,0.1,n".to_string();
    let noted = noted.join("\n") + "\n";
    let cases = [
        (
            "dup.csv",
            with_line(&good, 1, "t,x,x,u"),
            vec!["dup.csv:1:x:", "twice"],
        ),
        (
            "extra.csv",
            with_line(&good, 7, "0.05,1,2,3,4"),
            vec!["extra.csv:7:", "5 fields"],
        ),
        (
            "few.csv",
            with_line(&good, 7, "0.05,1"),
            vec!["few.csv:7:", "too few fields", "'y'"],
        ),
        (
            "comment.csv",
            with_line(&good, 7, "# note, here"),
            vec!["comment.csv:7:", "comment"],
        ),
        // The note of data row 2 spans two lines: row 6 starts on line 8.
        ("note.csv", noted, vec!["note.csv:8:x:", "abc"]),
    ];
    for (name, text, needles) in cases {
        std::fs::write(dir.join(name), text).unwrap();
        let run = sindy(&dir, name, "poly:1", &[]);
        run.one_line_error(&needles);
    }
}

#[test]
fn a_directory_or_a_binary_file_is_named_as_such() {
    let dir = scratch("sindy-not-csv");
    std::fs::create_dir_all(dir.join("folder")).unwrap();
    // A folder is read as a PX4 log exported to CSV, whose columns are `topic.field`.
    sindy(&dir, "folder", "poly:1", &[])
        .one_line_error(&["folder: x: is a directory, read as a PX4 CSV export"]);
    std::fs::write(dir.join("blob.csv"), b"\x00\x01\x02binary\xc3\xbf\n").unwrap();
    sindy(&dir, "blob.csv", "poly:1", &[]).one_line_error(&["blob.csv:1: not a CSV text file"]);
}

#[cfg(unix)]
#[test]
fn a_pipe_is_read_like_a_file() {
    let dir = scratch("sindy-fifo");
    std::fs::write(dir.join("s.csv"), signal(200)).unwrap();
    let from_file = sindy(&dir, "s.csv", "poly:2", &[]);
    let made = std::process::Command::new("mkfifo")
        .arg(dir.join("pipe.csv"))
        .status()
        .expect("mkfifo runs");
    assert!(made.success());
    let writer = {
        let fifo = dir.join("pipe.csv");
        std::thread::spawn(move || std::fs::write(fifo, signal(200)).unwrap())
    };
    let from_pipe = sindy(&dir, "pipe.csv", "poly:2", &[]);
    writer.join().unwrap();
    assert_eq!(from_pipe.success(), from_file.success());
    assert_eq!(from_pipe.stderr, from_file.stderr);
}

/// A 5-row flight log with the given columns (`q` and/or `R`).
fn flight(with_q: bool, with_r: bool) -> String {
    let times: Vec<String> = (0..5).map(|k| format!("{:.2}", k as f64 * 0.02)).collect();
    flight_at(with_q, with_r, &times)
}

/// A flight log with the given columns, a row at each of `times`.
fn flight_at(with_q: bool, with_r: bool, times: &[String]) -> String {
    let mut header = vec!["t", "p", "v"];
    if with_q {
        header.push("q");
    }
    if with_r {
        header.push("R");
    }
    header.extend(["w", "T_sp", "hover_throttle", "pwm", "battery"]);
    let mut text = header.join(",") + "\n";
    for time in times {
        let mut cells = vec![
            time.clone(),
            "\"[0.0, 0.0, 1.0]\"".to_string(),
            "\"[0.0, 0.0, 0.0]\"".to_string(),
        ];
        if with_q {
            cells.push("\"[0.0, 0.0, 0.0, 1.0]\"".to_string());
        }
        if with_r {
            cells.push("\"[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]\"".to_string());
        }
        cells.extend([
            "\"[0.0, 0.0, 0.0]\"".to_string(),
            "0.5".to_string(),
            "0.5".to_string(),
            "\"[1300.0, 1300.0, 1300.0, 1300.0]\"".to_string(),
            "16.0".to_string(),
        ]);
        text.push_str(&(cells.join(",") + "\n"));
    }
    text
}

#[test]
fn inspect_lists_the_columns_the_file_has() {
    let dir = scratch("inspect-columns");
    std::fs::write(dir.join("q_only.csv"), flight(true, false)).unwrap();
    std::fs::write(dir.join("r_only.csv"), flight(false, true)).unwrap();
    let q_only = learn_in(&dir, &["data", "inspect", "q_only.csv"]);
    let line = q_only
        .success()
        .lines()
        .find(|l| l.starts_with("columns:"))
        .unwrap()
        .to_string();
    assert!(
        line.contains("q, R (absent, derived from q)") && line.contains("p_d (absent)"),
        "{line}"
    );
    assert!(line.contains("not used: battery"), "{line}");
    assert!(
        q_only.stdout.contains("[1300.0, 1300.0] (4 motors)"),
        "{}",
        q_only.stdout
    );
    // Named `battery_voltage`, the column is the optional battery voltage, read and ranged.
    std::fs::write(
        dir.join("volts.csv"),
        flight(true, false).replacen("battery", "battery_voltage", 1),
    )
    .unwrap();
    let volts = learn_in(&dir, &["data", "inspect", "volts.csv"]);
    let text = volts.success();
    assert!(text.contains("fa (absent), battery_voltage\n"), "{text}");
    assert!(
        text.contains("battery_voltage [V] [16.000, 16.000]"),
        "{text}"
    );
    let r_only = learn_in(&dir, &["data", "inspect", "r_only.csv"]);
    assert!(
        r_only.success().contains("q (absent, derived from R), R,"),
        "{}",
        r_only.stdout
    );
    std::fs::write(
        dir.join("dup.csv"),
        flight(true, false).replacen("battery", "pwm", 1),
    )
    .unwrap();
    learn_in(&dir, &["data", "inspect", "dup.csv"])
        .one_line_error(&["dup.csv:1:pwm:", "appears twice"]);
}

/// A deterministic pseudo-random offset in [−1, 1] for sample `k` (a SplitMix64 hash).
fn offset(k: usize) -> f64 {
    let mut z = (k as u64)
        .wrapping_add(1)
        .wrapping_mul(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^= z >> 31;
    2.0 * (z >> 11) as f64 / (1u64 << 53) as f64 - 1.0
}

/// `learn data inspect` reads a log however its samples are spaced and says how: one line for
/// uniform samples; the median, the jitter and the gaps of a real logger's time stamps.
#[test]
fn inspect_reports_how_the_samples_are_spaced() {
    let dir = scratch("inspect-spacing");
    let uniform: Vec<String> = (0..400)
        .map(|k| format!("{:.2}", k as f64 * 0.02))
        .collect();
    std::fs::write(dir.join("uniform.csv"), flight_at(true, false, &uniform)).unwrap();
    let run = learn_in(&dir, &["data", "inspect", "uniform.csv"]);
    let out = run.success();
    assert!(
        out.contains("\nspacing:   uniform, every interval within 1 % of the median 0.020000 s\n"),
        "{out}"
    );
    assert!(!out.contains("gaps:"), "{out}");
    // Each stamp moved by up to ±20 % of the interval, every tenth row dropped, and no row from
    // t = 4 s to 5 s: refused as not uniform before.
    let uneven: Vec<String> = (0..400)
        .filter(|k| k % 10 != 7)
        .map(|k| k as f64 * 0.02 + 0.004 * offset(k))
        .filter(|t| !(4.0..5.0).contains(t))
        .map(|t| format!("{t}"))
        .collect();
    std::fs::write(dir.join("uneven.csv"), flight_at(true, false, &uneven)).unwrap();
    let run = learn_in(&dir, &["data", "inspect", "uneven.csv"]);
    let out = run.success();
    // The drops double a tenth of the intervals: the 99th percentile is above 2.
    assert!(
        out.contains(
            "\nspacing:   uneven (readers of uniform samples, as the paper's pipelines, refuse it): median interval 0.020390 s (49.043 Hz), 1st to 99th percentile 0.663 to 2.248 × the median\n\
             gaps:      1 interval over 3 × the median; the longest interval 1.003893 s (49.2 × the median) from t = 3.999 s\n"
        ),
        "{out}"
    );
    assert!(out.contains("\nsamples:   316\n"), "{out}");
}

fn conditions(pattern: &str, conditions: &str) -> String {
    format!(
        r#"{{"file_pattern": "{pattern}", "controllers": ["baseline"], "evaluation_controller": "baseline",
  "conditions": [{conditions}],
  "paper_training": {{"file_pattern": "training/{{condition}}.csv",
    "conditions": [{{"name": "10wind", "wind_speed": "1 m/s", "role": "meta-training"}}]}}}}"#
    )
}

#[test]
fn inconsistent_conditions_are_refused_naming_the_file_and_field() {
    let dir = scratch("conditions-bad");
    let pattern = "experiment/{controller}_{condition}.csv";
    let a = r#"{"name": "35wind", "wind_speed": "4 m/s", "role": "evaluation"}"#;
    let b =
        r#"{"name": "70p20sint", "label": "35wind", "wind_speed": "8 m/s", "role": "evaluation"}"#;
    let c = r#"{"name": "", "wind_speed": "8 m/s", "role": "evaluation"}"#;
    let d = r#"{"name": "nowind", "wind_speed": "0 m/s", "role": "meta-training"}"#;
    let cases = [
        (
            "label.json",
            conditions(pattern, &format!("{a}, {b}")),
            vec!["conditions[1].label", "'35wind'"],
        ),
        (
            "name.json",
            conditions(pattern, &format!("{a}, {c}")),
            vec!["conditions[1].name", "empty"],
        ),
        (
            "ctrl.json",
            conditions("experiment/{ctrl}_{condition}.csv", a),
            vec!["file_pattern", "{ctrl}"],
        ),
        (
            "brace.json",
            conditions("experiment/{controller_{condition}.csv", a),
            vec!["file_pattern", "not closed"],
        ),
        (
            "none.json",
            conditions(pattern, ""),
            vec!["conditions", "no condition is declared"],
        ),
        (
            "train.json",
            conditions(pattern, d),
            vec!["conditions", "no condition has role \"evaluation\""],
        ),
    ];
    for (name, text, mut needles) in cases {
        std::fs::write(dir.join(name), text).unwrap();
        needles.push(name);
        learn_in(&dir, &["conditions", "--config", name]).one_line_error(&needles);
    }
    // Six controllers and a pattern without {controller}: one file would stand for six flights.
    let six = conditions("experiment/custom_figure8_baseline_{condition}.csv", a).replace(
        r#""controllers": ["baseline"]"#,
        r#""controllers": ["baseline", "indi", "L1", "NF", "NF-C", "NF-T"]"#,
    );
    std::fs::write(dir.join("six.json"), six).unwrap();
    learn_in(&dir, &["conditions", "--config", "six.json"]).one_line_error(&[
        "six.json: file_pattern: 'experiment/custom_figure8_baseline_{condition}.csv' must \
         contain {controller}",
    ]);
    // A pattern reaching out of the data directory, as an absolute one would.
    std::fs::write(
        dir.join("up.json"),
        conditions("../{controller}_{condition}.csv", a),
    )
    .unwrap();
    learn_in(&dir, &["conditions", "--config", "up.json"]).one_line_error(&[
        "up.json: file_pattern: '../{controller}_{condition}.csv' must be a path relative to \
         the data directory, inside it (no '..')",
    ]);
    std::fs::write(
        dir.join("good.json"),
        conditions(pattern, &format!("{a}, {d}")),
    )
    .unwrap();
    let listing = learn_in(&dir, &["conditions", "--config", "good.json"]);
    assert!(listing.success().contains("35wind"), "{}", listing.stdout);
}

#[test]
fn an_unusable_fit_or_precision_is_an_error_not_inf() {
    let dir = scratch("sindy-tiny-steps");
    // Time steps of 1e-300: finite values whose derivatives overflow.
    let rows: String = (0..40)
        .map(|i| {
            format!(
                "{:e},{},{}\n",
                i as f64 * 1e-300,
                (i as f64 * 0.1).sin(),
                i % 3
            )
        })
        .collect();
    std::fs::write(dir.join("tiny.csv"), format!("t,x,u\n{rows}")).unwrap();
    let run = learn_in(
        &dir,
        &[
            "sindy",
            "--csv",
            "tiny.csv",
            "--state",
            "x",
            "--control",
            "u",
        ],
    );
    run.one_line_error(&["tiny.csv", "the fit is not finite"]);
    assert!(!run.stdout.contains("inf"), "{}", run.stdout);
    let run = learn_in(
        &dir,
        &[
            "sindy",
            "--csv",
            "tiny.csv",
            "--state",
            "x",
            "--precision",
            "18",
        ],
    );
    assert_eq!(run.code, Some(2), "{}", run.stderr);
    assert!(run.stderr.contains("--precision"), "{}", run.stderr);
}

#[test]
fn a_data_directory_that_is_a_file_is_named_by_every_command() {
    let dir = scratch("data-is-a-file");
    std::fs::write(dir.join("flights.csv"), "t\n0\n").unwrap();
    let workspace = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let conditions = workspace.join("experiments/conditions.json");
    let conditions = conditions.to_str().unwrap();
    let learn_json = workspace.join("experiments/learn.json");
    let commands: [&[&str]; 2] = [
        &["conditions", "--config", conditions],
        &[
            "meta-train",
            "--config",
            learn_json.to_str().unwrap(),
            "--conditions",
            conditions,
        ],
    ];
    for given in ["flights.csv", "absent"] {
        for command in commands {
            let mut args = vec!["--data", given];
            args.extend_from_slice(command);
            let run = learn_in(&dir, &args);
            let message = run.one_line_error(&[given, "--data"]);
            assert!(
                message.starts_with(&format!("error: {given}: ")),
                "{message}"
            );
            assert!(run.stdout.is_empty(), "{command:?}: {}", run.stdout);
        }
    }
    // Without --data (nor NEURAL_FLY_DIR) and no data/neural-fly, `conditions` still lists them.
    let run = learn_in(&dir, &["conditions", "--config", conditions]);
    assert!(
        run.success().contains("no data directory"),
        "{}",
        run.stdout
    );
}

#[test]
fn flags_of_the_other_optimizer_are_refused_not_ignored() {
    let dir = scratch("sindy-optimizer-flags");
    std::fs::write(dir.join("s.csv"), signal(200)).unwrap();
    let lasso = ["--optimizer", "lasso", "--lambda", "0.01"];
    let with = |extra: &[&str]| {
        let mut args = lasso.to_vec();
        args.extend_from_slice(extra);
        sindy(&dir, "s.csv", "poly:1", &args)
    };
    with(&["--threshold", "5", "--alpha", "3", "--max-iter", "1"]).one_line_error(&[
        "--threshold, --alpha, --max-iter apply to --optimizer stlsq only, not lasso",
    ]);
    with(&["--max-iter", "1"])
        .one_line_error(&["--max-iter applies to --optimizer stlsq only, not lasso"]);
    assert!(with(&[]).success().contains("x' ="));
    // And the other way round, as before.
    sindy(&dir, "s.csv", "poly:1", &["--lambda", "0.01"])
        .one_line_error(&["--lambda applies to --optimizer lasso only"]);
    // The STLSQ flags still act on STLSQ: a threshold above every coefficient leaves none.
    let run = sindy(&dir, "s.csv", "poly:1", &["--threshold", "1e6"]);
    assert!(!run.success().contains(" u"), "{}", run.stdout);
}

#[test]
fn a_model_file_in_a_directory_that_does_not_exist_yet_is_written_there() {
    let dir = scratch("sindy-out-new-dir");
    std::fs::write(dir.join("s.csv"), signal(200)).unwrap();
    let run = sindy(&dir, "s.csv", "poly:1", &["--out", "new/sub/m.json"]);
    assert!(run.success().contains("x' ="), "{}", run.stderr);
    assert!(
        run.stderr.contains("model written to new/sub/m.json"),
        "{}",
        run.stderr
    );
    let model = sindy::SindyModel::load(&dir.join("new/sub/m.json")).unwrap();
    assert_eq!(model.feature_names().len(), 4);
    // Below a file nothing can be made: refused before the fit.
    std::fs::write(dir.join("file"), "").unwrap();
    let run = sindy(&dir, "s.csv", "poly:1", &["--out", "file/m.json"]);
    run.one_line_error(&["file/m.json", "is not a directory"]);
    assert!(run.stdout.is_empty(), "{}", run.stdout);
}

#[test]
fn a_constant_derivative_has_no_r2() {
    let dir = scratch("sindy-constant-target");
    let rows: String = (0..50)
        .map(|k| format!("{:.1},{}\n", k as f64 * 0.1, 2.0 * k as f64 * 0.1))
        .collect();
    std::fs::write(dir.join("line.csv"), format!("t,x\n{rows}")).unwrap();
    let run = learn_in(
        &dir,
        &[
            "sindy",
            "--csv",
            "line.csv",
            "--state",
            "x",
            "--library",
            "poly:1",
        ],
    );
    assert_eq!(run.success().trim(), "x' = 2.000");
    assert!(
        run.stderr
            .contains("MSE 0.000000, R² n/a (constant target)"),
        "{}",
        run.stderr
    );
    // With a second, varying state, R² is given for that state alone and the constant one named.
    let rows: String = (0..200)
        .map(|k| {
            let t = k as f64 * 0.01;
            format!("{t:.2},{},{}\n", 2.0 * t, t.sin())
        })
        .collect();
    std::fs::write(dir.join("two.csv"), format!("t,x,y\n{rows}")).unwrap();
    let run = learn_in(
        &dir,
        &[
            "sindy",
            "--csv",
            "two.csv",
            "--state",
            "x,y",
            "--library",
            "fourier:1",
        ],
    );
    run.success();
    assert!(
        run.stderr
            .contains(" over the 1 of 2 states whose target varies (x' constant: no R²)"),
        "{}",
        run.stderr
    );
}

/// `--stream` reads the file in blocks and fits as it reads: the same equations and score as the
/// whole file, and bad input named by file, line and column as there.
#[test]
fn a_streamed_file_fits_as_the_whole_file_and_names_bad_lines() {
    let dir = scratch("sindy-stream");
    std::fs::write(dir.join("s.csv"), signal(3000)).unwrap();
    for derivative in ["central", "savgol:11:3"] {
        let extra = ["--derivative", derivative, "--precision", "9"];
        let whole = sindy(&dir, "s.csv", "poly:2", &extra);
        let mut streamed_args = extra.to_vec();
        streamed_args.push("--stream");
        let streamed = sindy(&dir, "s.csv", "poly:2", &streamed_args);
        assert_eq!(streamed.success(), whole.success(), "{derivative}");
    }
    let text = with_line(&signal(3000), 2048, "20.46,0.5,oops,0.1");
    std::fs::write(dir.join("bad.csv"), text).unwrap();
    sindy(&dir, "bad.csv", "poly:2", &["--stream"]).one_line_error(&["bad.csv:2048:y", "oops"]);
    let text = with_line(&signal(3000), 2900, "28.98,1e200,0.5,0.1");
    std::fs::write(dir.join("huge.csv"), text).unwrap();
    sindy(&dir, "huge.csv", "poly:2", &["--stream"]).one_line_error(&[
        "huge.csv:2900:",
        "feature 'x^2'",
        "not finite",
    ]);
    let text = with_line(&signal(3000), 2500, "24.90,0.5,0.5,0.1");
    std::fs::write(dir.join("back.csv"), text).unwrap();
    sindy(&dir, "back.csv", "poly:2", &["--stream"])
        .one_line_error(&["back.csv:2500:t", "not strictly increasing"]);
    let text = with_line(&signal(3000), 2600, "25.985,0.5,0.5,0.1");
    std::fs::write(dir.join("gap.csv"), text).unwrap();
    // An uneven step: central differences take the time stamps, Savitzky–Golay names the line.
    sindy(&dir, "gap.csv", "poly:2", &["--stream"]).success();
    sindy(
        &dir,
        "gap.csv",
        "poly:2",
        &["--stream", "--derivative", "savgol:11:3"],
    )
    .one_line_error(&["gap.csv:2600:t"]);
    let text = with_line(&signal(3000), 1500, "14.98,0.5,0.5");
    std::fs::write(dir.join("short-row.csv"), text).unwrap();
    sindy(&dir, "short-row.csv", "poly:2", &["--stream"])
        .one_line_error(&["short-row.csv:1500", "too few fields: 3 of the header's 4"]);
}

/// A Parquet file (known by its content, whatever its name) fits as the CSV of its values does,
/// read whole or in blocks; a null is named by its row, counted from 1.
#[test]
fn a_parquet_recording_fits_as_its_csv() {
    let dir = scratch("sindy-parquet");
    std::fs::write(dir.join("s.csv"), signal(3000)).unwrap();
    let names = ["t", "x", "y", "u"];
    let table = data::NumericTable::read(&dir.join("s.csv"), &names).unwrap();
    data::write_numeric_parquet(&dir.join("s.parquet"), &table.names, &table.columns).unwrap();
    std::fs::copy(dir.join("s.parquet"), dir.join("s.bin")).unwrap();
    let extra = ["--precision", "9"];
    let csv = sindy(&dir, "s.csv", "poly:2", &extra);
    for file in ["s.parquet", "s.bin"] {
        assert_eq!(sindy(&dir, file, "poly:2", &extra).success(), csv.success());
        let streamed = sindy(&dir, file, "poly:2", &["--precision", "9", "--stream"]);
        assert_eq!(streamed.success(), csv.success(), "{file}");
    }
    let mut columns = table.columns.clone();
    columns[2][1234] = f64::NAN;
    data::write_numeric_parquet(&dir.join("nan.parquet"), &table.names, &columns).unwrap();
    for extra in [&[][..], &["--stream"]] {
        sindy(&dir, "nan.parquet", "poly:2", extra)
            .one_line_error(&["nan.parquet:1235:y", "not finite (NaN)"]);
    }
}
