//! LeARN on your own data through the binary: from a folder of CSVs to a meta-trained model
//! (`meta-train --tasks`), an evaluation on a new recording next to SINDy (`evaluate`) and its
//! equations (`explain`); and every bad input as a one-line error naming the file, row or field.

mod common;

use std::path::{Path, PathBuf};

use common::{learn_in, scratch};

/// `t,x,v,u`: x' = v, v' = −k·x − c·v + u, u = cos(1.3 t), sampled every `dt` s (semi-implicit
/// Euler, 10 substeps). `list`: x and v in one list column `s` = `[x, v]` instead.
fn oscillator(k: f64, c: f64, rows: usize, dt: f64, list: bool) -> String {
    let mut text = String::from(if list { "t,s,u\n" } else { "t,x,v,u\n" });
    let (mut x, mut v) = (0.5, 0.0);
    let h = dt / 10.0;
    for row in 0..rows {
        let t = row as f64 * dt;
        let u = (1.3 * t).cos();
        if list {
            text.push_str(&format!("{t},\"[{x}, {v}]\",{u}\n"));
        } else {
            text.push_str(&format!("{t},{x},{v},{u}\n"));
        }
        for step in 0..10 {
            let force = (1.3 * (t + step as f64 * h)).cos();
            v += h * (-k * x - c * v + force);
            x += h * v;
        }
    }
    text
}

/// The training draws of (k, c).
const DRAWS: [(f64, f64); 4] = [(0.5, 0.1), (1.5, 0.3), (2.5, 0.2), (3.5, 0.4)];

/// Four task files `train-*.csv` and a small configuration, in `dir`.
fn task_folder(dir: &Path, list: bool) -> PathBuf {
    for (i, (k, c)) in DRAWS.into_iter().enumerate() {
        let text = oscillator(k, c, 200, 0.05, list);
        std::fs::write(dir.join(format!("train-{i}.csv")), text).unwrap();
    }
    std::fs::write(
        dir.join("unseen.csv"),
        oscillator(2.0, 0.25, 300, 0.05, list),
    )
    .unwrap();
    let config = dir.join("small.json");
    std::fs::write(
        &config,
        r#"{"hidden_layers": [8, 8], "meta_training": {"iterations": 60}, "adaptation": {"passes": 2, "step": 0.01}}"#,
    )
    .unwrap();
    config
}

fn meta_train(dir: &Path, pattern: &str, extra: &[&str]) -> common::Run {
    let mut args = vec![
        "meta-train",
        "--tasks",
        pattern,
        "--state",
        "x,v",
        "--control",
        "u",
        "--config",
        "small.json",
        "--out",
        "model.json",
    ];
    args.extend_from_slice(extra);
    learn_in(dir, &args)
}

#[test]
fn a_folder_of_csvs_gives_a_model_an_evaluation_and_equations() {
    let dir = scratch("own-data-flow");
    task_folder(&dir, false);
    let out = meta_train(&dir, "train-*.csv", &["--seed", "3"])
        .success()
        .to_string();
    assert!(out.contains("meta-trained on 4 tasks"), "{out}");
    let model = learn::MetaTrainedModel::load(&dir.join("model.json")).unwrap();
    assert_eq!(model.seed, 3);
    assert_eq!(model.input_names(), ["x", "v", "u"]);
    // Every hyper-parameter the file did not name is recorded with its default.
    assert_eq!(model.config.meta_training.inner_step, 0.1);
    assert_eq!(model.data_files.len(), 4);

    let args = [
        "evaluate",
        "--model",
        "model.json",
        "--csv",
        "unseen.csv",
        "--support-rows",
        "0:150",
        "--query-rows",
        "150:300",
    ];
    let mut json_args = args.to_vec();
    json_args.push("--json");
    let json: serde_json::Value =
        serde_json::from_str(learn_in(&dir, &json_args).success()).unwrap();
    for method in ["learn", "sindy"] {
        for metric in ["adapt", "gen"] {
            let value = json[method][metric].as_f64().unwrap_or(f64::NAN);
            assert!(
                value.is_finite() && value >= 0.0,
                "{method}.{metric}: {json}"
            );
        }
    }
    let table = learn_in(&dir, &args).success().to_string();
    assert!(
        table.contains("LeARN (adapted)") && table.contains("SINDy"),
        "{table}"
    );

    let equations = learn_in(&dir, &["explain", "model.json", "--csv", "unseen.csv"]);
    let text = equations.success();
    assert!(text.contains("x' =") && text.contains("v' ="), "{text}");
    assert!(text.contains("adapted online on rows 0:150"), "{text}");
}

#[test]
fn list_cells_and_a_task_column_are_read_as_documented() {
    let dir = scratch("own-data-layouts");
    task_folder(&dir, true);
    let args = [
        "meta-train",
        "--tasks",
        "train-*.csv",
        "--state",
        "s[0],s[1]",
        "--control",
        "u",
        "--config",
        "small.json",
        "--out",
        "model.json",
    ];
    learn_in(&dir, &args).success();
    let model = learn::MetaTrainedModel::load(&dir.join("model.json")).unwrap();
    assert_eq!(model.output_names(), ["s[0]'", "s[1]'"]);

    let mut all = String::from("task,t,x,v,u\n");
    for (i, (k, c)) in DRAWS.into_iter().enumerate() {
        for line in oscillator(k, c, 200, 0.05, false).lines().skip(1) {
            all.push_str(&format!("draw{i},{line}\n"));
        }
    }
    std::fs::write(dir.join("all.csv"), all).unwrap();
    let run = meta_train(&dir, "all.csv", &["--task-column", "task", "--force"]);
    assert!(
        run.success().contains("meta-trained on 4 tasks"),
        "{}",
        run.stdout
    );
}

#[test]
fn bad_task_sets_are_one_line_errors_naming_the_file() {
    let dir = scratch("own-data-bad-tasks");
    task_folder(&dir, false);
    meta_train(&dir, "nothing-*.csv", &[]).one_line_error(&["nothing-*.csv", "matches no file"]);

    std::fs::write(dir.join("train-9.csv"), "t,x,v\n0,1,2\n0.05,1,2\n0.1,1,2\n").unwrap();
    meta_train(&dir, "train-*.csv", &[]).one_line_error(&["train-9.csv", "missing column 'u'"]);

    std::fs::write(
        dir.join("train-9.csv"),
        oscillator(1.0, 0.1, 200, 0.1, false),
    )
    .unwrap();
    meta_train(&dir, "train-*.csv", &[]).one_line_error(&["train-9.csv", "sampling interval"]);

    std::fs::write(
        dir.join("train-9.csv"),
        oscillator(1.0, 0.1, 5, 0.05, false),
    )
    .unwrap();
    meta_train(&dir, "train-*.csv", &[]).one_line_error(&["train-9.csv", "5 data rows"]);

    let mut broken = oscillator(1.0, 0.1, 20, 0.05, false);
    broken.push_str("1.0,0.1,abc,0.5\n");
    std::fs::write(dir.join("train-9.csv"), broken).unwrap();
    meta_train(&dir, "train-*.csv", &[]).one_line_error(&["train-9.csv:22:v", "abc"]);
    std::fs::remove_file(dir.join("train-9.csv")).unwrap();

    std::fs::write(
        dir.join("bad.json"),
        r#"{"meta_training": {"iteratons": 5}}"#,
    )
    .unwrap();
    let run = learn_in(
        &dir,
        &[
            "meta-train",
            "--tasks",
            "train-*.csv",
            "--state",
            "x,v",
            "--config",
            "bad.json",
            "--out",
            "model.json",
        ],
    );
    run.one_line_error(&["bad.json", "meta_training.iteratons"]);
    // A batch the configuration names larger than the tasks hold is refused by name.
    std::fs::write(
        dir.join("big.json"),
        r#"{"meta_training": {"task_batch": 9}}"#,
    )
    .unwrap();
    let run = learn_in(
        &dir,
        &[
            "meta-train",
            "--tasks",
            "train-*.csv",
            "--state",
            "x,v",
            "--config",
            "big.json",
            "--out",
            "model.json",
        ],
    );
    run.one_line_error(&["big.json", "meta_training.task_batch", "at most 4"]);
    learn_in(
        &dir,
        &[
            "meta-train",
            "--tasks",
            "train-*.csv",
            "--out",
            "model.json",
        ],
    )
    .one_line_error(&["--state"]);
    meta_train(&dir, "train-*.csv", &["--formulation", "full"]).one_line_usage_error(&["--tasks"]);
    assert!(!dir.join("model.json").exists());
}

#[test]
fn bad_evaluations_are_one_line_errors_naming_the_file_and_rows() {
    let dir = scratch("own-data-bad-evaluations");
    task_folder(&dir, false);
    meta_train(&dir, "train-*.csv", &[]).success();
    let evaluate = |csv: &str, support: &str, query: &str| {
        learn_in(
            &dir,
            &[
                "evaluate",
                "--model",
                "model.json",
                "--csv",
                csv,
                "--support-rows",
                support,
                "--query-rows",
                query,
            ],
        )
    };
    evaluate("unseen.csv", "0:5000", "5000:5100").one_line_error(&[
        "unseen.csv",
        "support rows 0:5000",
        "300 data rows",
    ]);
    evaluate("unseen.csv", "0:2", "100:300").one_line_error(&["unseen.csv", "support rows 0:2"]);
    evaluate("unseen.csv", "0:150", "100:300").one_line_error(&["overlap"]);
    // Fewer support rows than the features of SINDy's default library (poly:2 on 3 inputs: 10).
    evaluate("unseen.csv", "0:8", "100:300").one_line_error(&["unseen.csv", "0:8", "features"]);
    evaluate("unseen.csv", "10", "100:300").one_line_usage_error(&["A:B"]);
    std::fs::write(dir.join("slow.csv"), oscillator(1.0, 0.1, 300, 0.1, false)).unwrap();
    evaluate("slow.csv", "0:150", "150:300").one_line_error(&["slow.csv", "sampled every 0.1 s"]);
    std::fs::write(dir.join("partial.csv"), "t,x,u\n0,1,2\n0.05,1,2\n").unwrap();
    evaluate("partial.csv", "0:1", "1:2").one_line_error(&["partial.csv", "missing column 'v'"]);
    // A flight model is not a model of CSV tasks.
    let mut value: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("model.json")).unwrap()).unwrap();
    value.as_object_mut().unwrap().remove("trained_on");
    value["formulation"] = serde_json::json!("translational");
    value["protocol"] = serde_json::json!("paper");
    std::fs::write(dir.join("flight.json"), value.to_string()).unwrap();
    learn_in(
        &dir,
        &[
            "evaluate",
            "--model",
            "flight.json",
            "--csv",
            "unseen.csv",
            "--support-rows",
            "0:150",
            "--query-rows",
            "150:300",
        ],
    )
    .one_line_error(&["flight.json"]);
    learn_in(&dir, &["explain", "model.json"]).one_line_error(&["model.json", "--csv"]);
    // The model is never replaced without --force.
    meta_train(&dir, "train-*.csv", &[]).one_line_error(&["model.json"]);
}

#[test]
fn sindy_reads_list_elements_alike_whole_and_streamed() {
    let dir = scratch("own-data-sindy-elements");
    std::fs::write(dir.join("list.csv"), oscillator(2.0, 0.25, 300, 0.05, true)).unwrap();
    let args = [
        "sindy",
        "--csv",
        "list.csv",
        "--state",
        "s[0],s[1]",
        "--control",
        "u",
    ];
    let whole = learn_in(&dir, &args).success().to_string();
    assert!(whole.contains("s[1]' = -1.998 s[0]"), "{whole}");
    let mut streamed = args.to_vec();
    streamed.push("--stream");
    assert_eq!(learn_in(&dir, &streamed).success(), whole);
    let missing = ["sindy", "--csv", "list.csv", "--state", "s[2]"];
    learn_in(&dir, &missing).one_line_error(&["list.csv:2:s[2]", "no element [2]"]);
    let mut missing_streamed = missing.to_vec();
    missing_streamed.push("--stream");
    learn_in(&dir, &missing_streamed).one_line_error(&["list.csv:2:s[2]", "no element [2]"]);
}
