//! Property-based hostile input (issue 18): a small generated flight CSV and every kind of
//! configuration the tool reads, mutated (byte flips, truncations, BOM, CRLF, extreme numbers,
//! wide headers; wrong types, absurd values, keys given twice, unknown keys, CSV for JSON). Each
//! mutated file is read or refused with one line naming it; nothing panics. Seeded: every run
//! tries the same cases ([`FLIGHT_CASES`] + [`CONFIG_CASES`] per kind, a few seconds).

mod common;
#[path = "../../data/tests/common/mod.rs"]
mod flight;

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};

use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use serde_json::Value;

/// Mutated flights per run.
const FLIGHT_CASES: u32 = 192;
/// Mutated files per configuration kind per run.
const CONFIG_CASES: u32 = 32;
/// Every how many flight cases one also goes through `learn data inspect`.
const THROUGH_THE_BINARY: usize = 8;

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .unwrap()
}

fn runner(cases: u32, seed: u8) -> TestRunner {
    let config = Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    };
    TestRunner::new_with_rng(
        config,
        TestRng::from_seed(RngAlgorithm::ChaCha, &[seed; 32]),
    )
}

/// Runs `read` on `path`: it must return, not panic, and an error must be one line naming the file.
fn read_or_refuse(path: &Path, read: &dyn Fn(&Path) -> Result<(), String>) -> Result<(), String> {
    let outcome = catch_unwind(AssertUnwindSafe(|| read(path)))
        .map_err(|_| format!("{}: panicked", path.display()))?;
    match outcome {
        Ok(()) => Ok(()),
        Err(message) if message.contains('\n') => Err(format!("not one line: {message}")),
        Err(message) if !message.contains(&path.display().to_string()) => {
            Err(format!("the file is not named: {message}"))
        }
        Err(_) => Ok(()),
    }
}

/// Hostile replacements for one cell of a CSV.
const CELLS: [&str; 14] = [
    "1e308",
    "-1e-300",
    "1e50",
    "1e150",
    "NaN",
    "inf",
    "",
    "1,5",
    "[1.0, 2.0]",
    "\"",
    "0x10",
    "99999999999999999999999999999999999999999999999999999999999999999999999999999",
    "-0",
    "1e-320",
];

/// One mutation of a CSV text.
#[derive(Clone, Debug)]
enum CsvMutation {
    FlipByte(usize, u8),
    Truncate(usize),
    Bom,
    Crlf,
    Cell(usize, usize, usize),
    WideHeader(usize),
    DropLine(usize),
    DoubleLine(usize),
}

fn csv_mutation() -> impl Strategy<Value = CsvMutation> {
    prop_oneof![
        (any::<usize>(), any::<u8>()).prop_map(|(at, byte)| CsvMutation::FlipByte(at, byte)),
        any::<usize>().prop_map(CsvMutation::Truncate),
        Just(CsvMutation::Bom),
        Just(CsvMutation::Crlf),
        (any::<usize>(), any::<usize>(), 0..CELLS.len())
            .prop_map(|(row, column, value)| CsvMutation::Cell(row, column, value)),
        (1usize..20_000).prop_map(CsvMutation::WideHeader),
        any::<usize>().prop_map(CsvMutation::DropLine),
        any::<usize>().prop_map(CsvMutation::DoubleLine),
    ]
}

fn mutate_csv(text: &str, mutation: &CsvMutation) -> Vec<u8> {
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    match *mutation {
        CsvMutation::FlipByte(at, byte) => {
            let mut bytes = text.as_bytes().to_vec();
            let at = at % bytes.len();
            bytes[at] = byte;
            return bytes;
        }
        CsvMutation::Truncate(at) => return text.as_bytes()[..at % text.len()].to_vec(),
        CsvMutation::Bom => return [&b"\xEF\xBB\xBF"[..], text.as_bytes()].concat(),
        CsvMutation::Crlf => return text.replace('\n', "\r\n").into_bytes(),
        CsvMutation::Cell(row, column, value) => {
            let row = 1 + row % (lines.len() - 1);
            let mut cells: Vec<String> = lines[row].split(',').map(String::from).collect();
            let column = column % cells.len();
            cells[column] = CELLS[value].to_string();
            lines[row] = cells.join(",");
        }
        CsvMutation::WideHeader(extra) => {
            let names: String = (0..extra).map(|i| format!(",extra{i}")).collect();
            lines[0].push_str(&names);
        }
        CsvMutation::DropLine(line) => {
            lines.remove(line % lines.len());
        }
        CsvMutation::DoubleLine(line) => {
            let line = line % lines.len();
            lines.insert(line, lines[line].clone());
        }
    }
    (lines.join("\n") + "\n").into_bytes()
}

#[test]
fn mutated_flights_are_read_or_refused_in_one_line() {
    let dir = flight::temp_dir("hostile-flights");
    let (_, text) = flight::synthetic_csv(&dir, 60);
    let path = dir.join("mutated.csv");
    let case = std::cell::Cell::new(0usize);
    runner(FLIGHT_CASES, 18)
        .run(&csv_mutation(), |mutation| {
            std::fs::write(&path, mutate_csv(&text, &mutation)).unwrap();
            let read = |p: &Path| {
                data::FlightLog::read(p)
                    .map(drop)
                    .map_err(|e| e.to_string())
            };
            read_or_refuse(&path, &read).map_err(TestCaseError::fail)?;
            case.set(case.get() + 1);
            if case.get().is_multiple_of(THROUGH_THE_BINARY) {
                through_the_binary(&path).map_err(TestCaseError::fail)?;
            }
            Ok(())
        })
        .unwrap();
}

/// `learn data inspect` on the file: success, or exit 1 with one line naming it; never a panic.
fn through_the_binary(path: &Path) -> Result<(), String> {
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_learn"))
        .args(["data", "inspect"])
        .arg(path)
        .env("RUST_BACKTRACE", "0")
        .output()
        .map_err(|e| e.to_string())?;
    let stderr = String::from_utf8_lossy(&output.stderr);
    match output.status.code() {
        Some(0) => Ok(()),
        Some(1) if stderr.trim_end().lines().count() == 1 && stderr.contains("mutated.csv") => {
            Ok(())
        }
        code => Err(format!("exit {code:?}: {stderr}")),
    }
}

/// Hostile values for a field of a configuration.
fn hostile_value(index: usize) -> Value {
    match index {
        0 => Value::from(42),
        1 => Value::from(-1),
        2 => Value::from(1e308),
        3 => Value::from(-1e-300),
        4 => Value::from(""),
        5 => Value::from("x"),
        6 => Value::Null,
        7 => Value::Array(Vec::new()),
        8 => serde_json::json!({}),
        9 => Value::from(true),
        10 => Value::from("../../../../etc/passwd"),
        11 => Value::from(u64::MAX),
        12 => Value::from("x".repeat(4096)),
        _ => serde_json::json!([[[[{"a": [1e300]}]]]]),
    }
}

/// One mutation of a JSON document.
#[derive(Clone, Debug)]
enum JsonMutation {
    Replace(usize, usize),
    Remove(usize),
    DuplicateKey(usize),
    UnknownKey,
    Bom,
    Truncate(usize),
    Csv,
}

fn json_mutation() -> impl Strategy<Value = JsonMutation> {
    prop_oneof![
        4 => (any::<usize>(), 0usize..14).prop_map(|(at, value)| JsonMutation::Replace(at, value)),
        1 => any::<usize>().prop_map(JsonMutation::Remove),
        1 => any::<usize>().prop_map(JsonMutation::DuplicateKey),
        1 => Just(JsonMutation::UnknownKey),
        1 => Just(JsonMutation::Bom),
        1 => any::<usize>().prop_map(JsonMutation::Truncate),
        1 => Just(JsonMutation::Csv),
    ]
}

/// JSON pointers of every value in `value`.
fn pointers(value: &Value, at: String, out: &mut Vec<String>) {
    match value {
        Value::Object(map) => {
            for (key, inner) in map {
                pointers(inner, format!("{at}/{key}"), out);
            }
        }
        Value::Array(items) => {
            for (index, inner) in items.iter().enumerate() {
                pointers(inner, format!("{at}/{index}"), out);
            }
        }
        _ => {}
    }
    out.push(at);
}

fn mutate_json(document: &Value, mutation: &JsonMutation) -> String {
    let mut value = document.clone();
    let mut all = Vec::new();
    pointers(&value, String::new(), &mut all);
    let pick = |at: usize| all[at % all.len()].clone();
    match *mutation {
        JsonMutation::Replace(at, hostile) => {
            if let Some(slot) = value.pointer_mut(&pick(at)) {
                *slot = hostile_value(hostile);
            }
        }
        JsonMutation::Remove(at) => {
            let pointer = pick(at);
            if let Some((parent, key)) = pointer.rsplit_once('/')
                && let Some(Value::Object(map)) = value.pointer_mut(parent)
            {
                map.remove(key);
            }
        }
        JsonMutation::DuplicateKey(at) => {
            let text = serde_json::to_string_pretty(&value).unwrap();
            let keys: Vec<&str> = value
                .as_object()
                .map(|m| m.keys().map(String::as_str).collect())
                .unwrap_or_default();
            if keys.is_empty() {
                return text;
            }
            let key = keys[at % keys.len()];
            return text.replacen('{', &format!("{{\"{key}\": 0,"), 1);
        }
        JsonMutation::UnknownKey => {
            if let Some(map) = value.as_object_mut() {
                map.insert("unexpected".into(), Value::from("y".repeat(1000)));
            }
        }
        JsonMutation::Bom => return format!("\u{feff}{value}"),
        JsonMutation::Truncate(at) => {
            let text = value.to_string();
            let mut end = at % text.len();
            while !text.is_char_boundary(end) {
                end -= 1;
            }
            return text[..end].to_string();
        }
        JsonMutation::Csv => return "t,x,y\n0,1,2\n".to_string(),
    }
    serde_json::to_string_pretty(&value).unwrap()
}

type Loader = Box<dyn Fn(&Path) -> Result<(), String>>;

fn err(e: impl std::fmt::Display) -> String {
    e.to_string()
}

/// A nominal model read as the `learn` command reads it: bounded, under the JSON policy.
fn load_model(path: &Path) -> Result<(), String> {
    let text =
        bounded_read::read_json_text(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let text =
        bounded_read::json::checked_text(&text).map_err(|e| format!("{}: {e}", path.display()))?;
    physics::NominalModel::from_json(text, path)
        .map(drop)
        .map_err(err)
}

/// Each configuration kind: its name, a valid document (relative paths made absolute), how the
/// tool reads it.
fn kinds(scratch: &Path) -> Vec<(&'static str, Value, Loader)> {
    let root = workspace();
    let read = |relative: &str| -> Value {
        serde_json::from_str(&std::fs::read_to_string(root.join(relative)).unwrap()).unwrap()
    };
    let absolute = |mut value: Value, pointers: &[&str], base: &Path| {
        for pointer in pointers {
            if let Some(Value::String(p)) = value.pointer_mut(pointer) {
                *p = base.join(&*p).to_str().unwrap().to_string();
            }
        }
        value
    };
    let mut run = read("experiments/reproduce.json");
    run = absolute(
        run,
        &["/conditions", "/published", "/learn/config", "/variants"],
        &root,
    );
    let mut variants = read("experiments/variants.json");
    variants = absolute(variants, &["/run"], &root);
    let scenario = absolute(
        read("experiments/mismatch/configurations/a.json"),
        &["/model"],
        &root.join("experiments/mismatch/configurations"),
    );
    let mut demo = read("experiments/mismatch/demo.json");
    let configurations = demo["configurations"].as_array().map_or(0, Vec::len);
    let scenarios: Vec<String> = (0..configurations)
        .map(|i| format!("/configurations/{i}/scenario"))
        .collect();
    let scenarios: Vec<&str> = scenarios.iter().map(String::as_str).collect();
    demo = absolute(demo, &scenarios, &root.join("experiments/mismatch"));
    let sindy_model = sindy_model(scratch);
    let work = scratch.join("work");
    let root_for_run = root.clone();
    let root_for_variants = root.clone();
    vec![
        (
            "learn.json",
            read("experiments/learn.json"),
            Box::new(|p: &Path| learn::LearnConfig::load(p).map(drop).map_err(err)) as Loader,
        ),
        (
            "reproduce.json",
            run,
            Box::new(move |p: &Path| {
                evaluation::RunConfig::load(p, &root_for_run)
                    .map(drop)
                    .map_err(err)
            }),
        ),
        (
            "variants.json",
            variants,
            Box::new(move |p: &Path| {
                evaluation::VariantsConfig::load(p, &root_for_variants)
                    .map(drop)
                    .map_err(err)
            }),
        ),
        (
            "conditions.json",
            read("experiments/conditions.json"),
            Box::new(|p: &Path| data::ExperimentConditions::load(p).map(drop).map_err(err)),
        ),
        (
            "published.json",
            read("paper/published.json"),
            Box::new(|p: &Path| report::PublishedTables::load(p).map(drop).map_err(err)),
        ),
        (
            "tolerances.json",
            read("paper/tolerances.json"),
            Box::new(|p: &Path| report::Tolerances::load(p).map(drop).map_err(err)),
        ),
        (
            "model.json",
            read("experiments/mismatch/neural-fly.json"),
            Box::new(load_model),
        ),
        (
            "scenario.json",
            scenario,
            Box::new(|p: &Path| physics::Scenario::load(p).map(drop).map_err(err)),
        ),
        (
            "demo.json",
            demo,
            Box::new(move |p: &Path| {
                mismatch::demo::DemoPlan::load(p, &work)
                    .map(drop)
                    .map_err(err)
            }),
        ),
        (
            "sindy-model.json",
            sindy_model,
            Box::new(|p: &Path| sindy::SindyModel::load(p).map(drop).map_err(err)),
        ),
    ]
}

/// A SINDy model file as `learn sindy --out` writes it.
fn sindy_model(dir: &Path) -> Value {
    let time: Vec<f64> = (0..100).map(|i| f64::from(i) * 0.01).collect();
    let states = sindy::Mat::from_fn(
        100,
        2,
        |i, j| {
            if j == 0 { time[i].sin() } else { time[i].cos() }
        },
    );
    let trajectory = sindy::Trajectory::new(time, states).unwrap();
    let model = sindy::SindyParams::new(&["x", "y"], &[])
        .fit(std::slice::from_ref(&trajectory))
        .unwrap();
    let path = dir.join("fitted.json");
    model.save(&path, true).unwrap();
    serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap()
}

#[test]
fn mutated_configurations_are_read_or_refused_in_one_line() {
    let dir = flight::temp_dir("hostile-configs");
    for (seed, (name, document, load)) in (0u8..).zip(kinds(&dir)) {
        // The valid document itself is read.
        let path = dir.join(name);
        std::fs::write(&path, serde_json::to_string_pretty(&document).unwrap()).unwrap();
        if let Err(message) = load(&path) {
            panic!("{name}: the valid document is refused: {message}");
        }
        runner(CONFIG_CASES, seed)
            .run(&json_mutation(), |mutation| {
                std::fs::write(&path, mutate_json(&document, &mutation)).unwrap();
                let fail = |m: String| TestCaseError::fail(format!("{name}: {mutation:?}: {m}"));
                read_or_refuse(&path, &*load).map_err(fail)?;
                // One policy for every kind: a BOM is accepted, a key given twice refused.
                match (&mutation, load(&path)) {
                    (JsonMutation::Bom, Err(message)) => {
                        Err(fail(format!("BOM refused: {message}")))
                    }
                    (JsonMutation::DuplicateKey(_), Ok(())) => {
                        Err(fail("a key given twice is accepted".to_string()))
                    }
                    (JsonMutation::DuplicateKey(_), Err(message)) if !message.contains("twice") => {
                        Err(fail(format!("not named as a key given twice: {message}")))
                    }
                    _ => Ok(()),
                }
            })
            .unwrap();
    }
}

/// Mutated numeric recordings (the CSV mutations above, on `t,x,y,u`) through `learn sindy`,
/// read whole and with `--stream`: each run succeeds or fails with one line naming the file, and
/// the two readings agree: both fail, or both print the same equations to 4 decimals (the two
/// paths reduce the library differently, so a badly conditioned mutation differs near 1e-10).
#[test]
fn mutated_recordings_fit_the_same_whole_and_streamed() {
    let dir = flight::temp_dir("hostile-stream");
    let text = common::signal(400);
    let path = dir.join("mutated.csv");
    runner(STREAM_CASES, 20)
        .run(&csv_mutation(), |mutation| {
            std::fs::write(&path, mutate_csv(&text, &mutation)).unwrap();
            let whole = fit_through_the_binary(&path, false).map_err(TestCaseError::fail)?;
            let streamed = fit_through_the_binary(&path, true).map_err(TestCaseError::fail)?;
            match (whole, streamed) {
                (Some(a), Some(b)) if a != b => Err(TestCaseError::fail(format!(
                    "{mutation:?}: whole and streamed fits differ:\n{a}\n{b}"
                ))),
                (a, b) if a.is_some() != b.is_some() => Err(TestCaseError::fail(format!(
                    "{mutation:?}: read whole {}, streamed {}",
                    if a.is_some() { "fits" } else { "is refused" },
                    if b.is_some() { "fits" } else { "is refused" },
                ))),
                _ => Ok(()),
            }
        })
        .unwrap();
}

/// Recordings `learn sindy` reads whole and streamed per run.
const STREAM_CASES: u32 = 64;

/// `learn sindy` on the file: `Some(equations)` on success, `None` after a one-line error naming
/// the file; anything else (a panic, several lines, another exit) is the error.
fn fit_through_the_binary(path: &Path, stream: bool) -> Result<Option<String>, String> {
    let mut command = std::process::Command::new(env!("CARGO_BIN_EXE_learn"));
    command
        .args([
            "sindy",
            "--quiet",
            "--state",
            "x,y",
            "--control",
            "u",
            "--precision",
            "4",
        ])
        .arg("--csv")
        .arg(path)
        .env("RUST_BACKTRACE", "0");
    if stream {
        command.arg("--stream");
    }
    let output = command.output().map_err(|e| e.to_string())?;
    let stderr = String::from_utf8_lossy(&output.stderr);
    match output.status.code() {
        Some(0) => Ok(Some(String::from_utf8_lossy(&output.stdout).into_owned())),
        Some(1) if stderr.trim_end().lines().count() == 1 && stderr.contains("mutated.csv") => {
            Ok(None)
        }
        code => Err(format!("stream {stream}: exit {code:?}: {stderr}")),
    }
}
