//! Issue 31, classes 3, 6, 7 (Savitzky–Golay), 10 and 12 (threads): shard results covered by
//! their hash, a fit's memory estimated and bounded before the work, Savitzky–Golay settings
//! without a derivative or with an unbounded cost refused when parsed, and the banner's thread
//! count the pool's.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use serde_json::Value;

use crate::common::sweep::{SmallExperiment, learn_at_once, small_experiment};
use crate::common::{Run, learn_in, scratch};

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

/// The two shards of the translational seed spread of `experiment`, in `s-0` and `s-1`.
fn spread_shards(experiment: &SmallExperiment) -> Vec<PathBuf> {
    let dirs: Vec<PathBuf> = (0..2)
        .map(|k| experiment.dir.join(format!("s-{k}")))
        .collect();
    let runs: Vec<Vec<String>> = dirs
        .iter()
        .enumerate()
        .map(|(k, dir)| {
            [
                "--quiet",
                "--data",
                SmallExperiment::arg(&experiment.data),
                "meta-train",
                "--config",
                SmallExperiment::arg(&experiment.learn),
                "--conditions",
                SmallExperiment::arg(&experiment.conditions),
                "--protocol",
                "leave-condition-out",
                "--formulation",
                "translational",
                "--seed-spread",
                "--shard",
                &format!("{k}/2"),
                "--out",
                SmallExperiment::arg(dir),
            ]
            .iter()
            .map(|a| a.to_string())
            .collect()
        })
        .collect();
    for run in learn_at_once(&experiment.dir, &runs) {
        run.success();
    }
    dirs
}

/// The first floating-point number under `value` (depth first), changed by one part in a
/// thousand; whether one was found.
fn nudge_first_float(value: &mut Value) -> bool {
    match value {
        Value::Number(number) if number.is_f64() => {
            let nudged = number.as_f64().unwrap() * 1.001 + 1e-3;
            *value = serde_json::json!(nudged);
            true
        }
        Value::Array(items) => items.iter_mut().any(nudge_first_float),
        Value::Object(fields) => fields.values_mut().any(nudge_first_float),
        _ => false,
    }
}

/// Writes `shard` as `dir/<name>/shard.json`; the folder.
fn write_shard(dir: &Path, name: &str, shard: &Value) -> PathBuf {
    let folder = dir.join(name);
    std::fs::create_dir_all(&folder).unwrap();
    std::fs::write(folder.join("shard.json"), shard.to_string()).unwrap();
    folder
}

fn merge(experiment: &SmallExperiment, shards: &[&Path]) -> Run {
    let mut args = vec!["merge", "--out", "merged.json"];
    args.extend(shards.iter().map(|s| SmallExperiment::arg(s)));
    learn_in(&experiment.dir, &args)
}

/// Class 3: a result, or the provenance, edited in a shard is refused by the merge in one line
/// naming the file; so is a shard of the earlier format, whose results no hash covered.
#[test]
fn an_edited_shard_result_is_refused_by_the_merge() {
    let dir = scratch("second-probe-shard-hash");
    let experiment = small_experiment(&dir);
    let shards = spread_shards(&experiment);
    let text = std::fs::read_to_string(shards[1].join("shard.json")).unwrap();
    let written: Value = serde_json::from_str(&text).unwrap();

    let mut result = written.clone();
    assert!(nudge_first_float(&mut result["results"]), "a float result");
    let mut host = written.clone();
    host["provenance"]["host"] = "elsewhere".into();
    for (name, edited) in [("edited-result", result), ("edited-host", host)] {
        let folder = write_shard(&dir, name, &edited);
        let run = merge(&experiment, &[&shards[0], &folder]);
        run.one_line_error(&[
            &format!("{name}/shard.json: content_sha256:"),
            "the file was changed after it was written",
        ]);
        assert!(!dir.join("merged.json").exists());
    }

    let mut earlier = written.clone();
    earlier["format"] = "learn-shard/1".into();
    let folder = write_shard(&dir, "earlier", &earlier);
    merge(&experiment, &[&shards[0], &folder]).one_line_error(&[
        "earlier/shard.json: format: a shard of an earlier learn ('learn-shard/1'",
        "run the shard again",
    ]);

    // The shards as written merge.
    let copy = write_shard(&dir, "copy", &written);
    merge(&experiment, &[&shards[0], &copy]).success();
    assert!(dir.join("merged.json").exists());
}

/// `t,x0,…,x{states-1}` for `rows` rows of small varied numbers (short cells: the file stays
/// a few MB).
fn wide_csv(path: &Path, states: usize, rows: usize) {
    let mut text = String::from("t");
    for j in 0..states {
        text.push_str(&format!(",x{j}"));
    }
    text.push('\n');
    for k in 0..rows {
        text.push_str(&format!("{}", k as f64 * 0.01));
        for j in 0..states {
            text.push_str(&format!(",{}", (k * 7 + j * 13) % 97));
        }
        text.push('\n');
    }
    std::fs::write(path, text).unwrap();
}

/// Runs `learn args` in `dir` under `ulimit -v kib`.
fn learn_limited(dir: &Path, kib: u64, args: &[&str]) -> Run {
    let output = Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {kib} && exec \"$@\""))
        .arg("sh")
        .arg(env!("CARGO_BIN_EXE_learn"))
        .args(args)
        .current_dir(dir)
        .env("RUST_BACKTRACE", "0")
        .output()
        .unwrap();
    Run {
        code: output.status.code(),
        stdout: String::from_utf8_lossy(&output.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&output.stderr).into_owned(),
    }
}

/// Class 6: `poly:2` on 139 states (9,870 features, under the 10,000 limit) needs gigabytes; under
/// a 2 GiB address-space limit it is refused in one line stating the estimate, within seconds,
/// whether read whole or streamed, instead of exiting 101 inside faer. A small fit under the same
/// limit still runs.
#[test]
fn a_fit_beyond_the_memory_bound_is_refused_before_the_work() {
    let dir = scratch("second-probe-memory");
    wide_csv(&dir.join("wide.csv"), 139, 9_900);
    let states: Vec<String> = (0..139).map(|j| format!("x{j}")).collect();
    let states = states.join(",");
    let two_gib = 2 << 20;
    for extra in [&[][..], &["--stream"][..]] {
        let start = Instant::now();
        let mut args = vec![
            "sindy",
            "--csv",
            "wide.csv",
            "--state",
            &states,
            "--library",
            "poly:2",
        ];
        args.extend(extra);
        let run = learn_limited(&dir, two_gib, &args);
        let message = run.one_line_error(&[
            "wide.csv: a fit of 9900 rows on the 9870 features of library poly:2 needs about",
            "GB of memory, more than the address space left under ulimit -v",
        ]);
        assert!(run.stdout.is_empty(), "{message}");
        assert!(
            start.elapsed() < Duration::from_secs(20),
            "{extra:?} took {:?}",
            start.elapsed()
        );
    }
    std::fs::write(dir.join("sine.csv"), crate::common::signal(400)).unwrap();
    let run = learn_limited(
        &dir,
        two_gib,
        &[
            "sindy",
            "--csv",
            "sine.csv",
            "--state",
            "x,y",
            "--control",
            "u",
        ],
    );
    assert!(run.success().contains("x' = "), "{}", run.stdout);
}

/// `t,x` with x = 3 + 2·t on `rows` rows.
fn line_csv(path: &Path, rows: usize) {
    let mut text = String::from("t,x\n");
    for k in 0..rows {
        let t = k as f64 * 0.01;
        text.push_str(&format!("{t},{}\n", 3.0 + 2.0 * t));
    }
    std::fs::write(path, text).unwrap();
}

/// Classes 7 and 10: order 0 (no derivative) and a window beyond the bound are usage errors
/// before anything is read; a window longer than the recording is refused naming the file.
#[test]
fn savitzky_golay_settings_without_a_derivative_or_a_bound_are_refused() {
    let dir = scratch("second-probe-savgol");
    line_csv(&dir.join("line.csv"), 300);
    let sindy = |derivative: &str| {
        learn_in(
            &dir,
            &[
                "sindy",
                "--csv",
                "line.csv",
                "--state",
                "x",
                "--library",
                "poly:1",
                "--derivative",
                derivative,
            ],
        )
    };
    sindy("savgol:5:0").one_line_usage_error(&["--derivative", "order 0", "at least 1"]);
    let start = Instant::now();
    sindy("savgol:99999:2").one_line_usage_error(&["window 99999 is longer than 1001"]);
    assert!(start.elapsed() < Duration::from_secs(5));
    sindy("savgol:7:9").one_line_usage_error(&["window 7 must be odd"]);
    sindy("savgol:501:2").one_line_error(&[
        "line.csv: 300 data rows, too few: the savgol:501:2 estimator needs at least 501",
    ]);
    let output = sindy("savgol:5:1").success().to_string();
    assert_eq!(output.trim_end(), "x' = 2.000");
}

/// Classes 7 and 10 as a family: every window and order `learn sindy` accepts gives the slope of
/// a line as its derivative (a finite, non-zero fit); every one it refuses is a one-line usage
/// error.
#[test]
fn every_accepted_savitzky_golay_setting_differentiates_a_line() {
    let dir = scratch("second-probe-savgol-grid");
    line_csv(&dir.join("line.csv"), 2_100);
    let settings = (0usize..1_200, 0usize..12);
    runner(40, 31)
        .run(&settings, |(window, order)| {
            let derivative = format!("savgol:{window}:{order}");
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
                    "--derivative",
                    &derivative,
                ],
            );
            let acceptable = (1..=sindy::differentiation::MAX_SAVITZKY_GOLAY_ORDER)
                .contains(&order)
                && window % 2 == 1
                && window > order
                && window <= sindy::differentiation::MAX_SAVITZKY_GOLAY_WINDOW;
            if acceptable {
                let output = run.success();
                prop_assert_eq!(output.trim_end(), "x' = 2.000", "{}", derivative);
            } else {
                run.one_line_usage_error(&["--derivative", &derivative, "Savitzky-Golay"]);
            }
            Ok(())
        })
        .unwrap();
}

/// Class 12: the banner names the threads of rayon's pool (`RAYON_NUM_THREADS`), not the
/// processors of the machine.
#[test]
fn the_banner_reports_the_threads_the_run_uses() {
    let dir = scratch("second-probe-threads");
    let experiment = small_experiment(&dir);
    for (threads, words) in [("1", "(1 thread)"), ("3", "(3 threads)")] {
        let output = Command::new(env!("CARGO_BIN_EXE_learn"))
            .args([
                "--quiet",
                "--data",
                SmallExperiment::arg(&experiment.data),
                "reproduce",
                "--root",
                SmallExperiment::arg(&dir),
                "--config",
                SmallExperiment::arg(&experiment.run),
                "--shard",
                "0/4",
                "--out",
                &format!("shard-{threads}"),
            ])
            .current_dir(&dir)
            .env_remove("NEURAL_FLY_DIR")
            .env("RUST_BACKTRACE", "0")
            .env("RAYON_NUM_THREADS", threads)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(0), "{stderr}");
        let banner = stderr
            .lines()
            .find(|line| line.starts_with("run '"))
            .unwrap_or_else(|| panic!("no banner: {stderr}"));
        assert!(banner.ends_with(words), "{threads}: {banner}");
        let shard: Value = serde_json::from_str(
            &std::fs::read_to_string(dir.join(format!("shard-{threads}/shard.json"))).unwrap(),
        )
        .unwrap();
        assert_eq!(shard["provenance"]["threads"].to_string(), threads);
    }
}
