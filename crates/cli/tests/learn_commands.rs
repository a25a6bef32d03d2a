//! `learn meta-train` and `learn explain` on bad settings, bad checkpoints and outputs that would
//! replace a file: a one-line error naming the file and field, exit 1, nothing replaced.

mod common;

use std::path::{Path, PathBuf};

use common::{learn_in, scratch};
use evaluation::Protocol;
use learn::{CHECKPOINT_FORMAT, LearnConfig, MetaTrainedModel, Standardiser};
use serde_json::{Value, json};

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn path_str(path: &Path) -> &str {
    path.to_str().expect("UTF-8 path")
}

/// The real flights (skipped without them, an error under CI).
fn real_data() -> Option<PathBuf> {
    data::real_data_dir_for_tests(&workspace())
}

/// experiments/learn.json with a tiny budget, changed by `edit`, written as `dir/learn.json`.
fn small_config(dir: &Path, edit: impl FnOnce(&mut Value)) -> PathBuf {
    let text = std::fs::read_to_string(workspace().join("experiments/learn.json")).unwrap();
    let mut value: Value = serde_json::from_str(&text).unwrap();
    value["meta_training"]["iterations"] = json!(3);
    value["adaptation"]["passes"] = json!(1);
    edit(&mut value);
    let path = dir.join("learn.json");
    std::fs::write(&path, value.to_string()).unwrap();
    path
}

/// `meta-train` on one cell (translational, 35wind) with the real flights and `extra` arguments.
fn meta_train(dir: &Path, data: &Path, extra: &[&str]) -> common::Run {
    let conditions = workspace().join("experiments/conditions.json");
    let mut args = vec![
        "--data",
        path_str(data),
        "meta-train",
        "--conditions",
        path_str(&conditions),
        "--protocol",
        "leave-condition-out",
        "--formulation",
        "translational",
        "--condition",
        "35wind",
    ];
    args.extend_from_slice(extra);
    learn_in(dir, &args)
}

/// An untrained translational checkpoint (the configuration of experiments/learn.json, changed by
/// `edit`), written as `dir/name`.
fn checkpoint(dir: &Path, name: &str, edit: impl FnOnce(&mut MetaTrainedModel)) -> PathBuf {
    let config = LearnConfig::load(&workspace().join("experiments/learn.json")).unwrap();
    let formulation = learn::Formulation::Translational;
    let architecture = learn::architecture(formulation, config.get());
    let mut model = MetaTrainedModel {
        format: CHECKPOINT_FORMAT.to_string(),
        trained_on: learn::TrainedOn::Flights(learn::FlightTraining {
            formulation,
            protocol: Protocol::LeaveConditionOut.name().to_string(),
            held_out_condition: Some("35wind".to_string()),
        }),
        seed: 1,
        config: config.get().clone(),
        parameters: architecture.initial_parameters(1),
        standardiser: Standardiser::identity(architecture.input_dim),
        architecture,
        data_files: vec![],
        meta_loss_history: vec![],
    };
    edit(&mut model);
    let path = dir.join(name);
    model.save(&path).unwrap();
    path
}

#[test]
fn meta_train_rejects_settings_that_make_results_meaningless_naming_the_field() {
    let dir = scratch("meta-train-bad-settings");
    let cases: [(&str, Value, &str); 10] = [
        (
            "iterations",
            json!({"meta_training": {"iterations": 0}}),
            "meta_training.iterations",
        ),
        (
            "rounds",
            json!({"meta_training": {"inner_rounds": 0}}),
            "meta_training.inner_rounds",
        ),
        (
            "passes",
            json!({"adaptation": {"passes": 0}}),
            "adaptation.passes",
        ),
        (
            "step",
            json!({"adaptation": {"step": 0.0}}),
            "adaptation.step",
        ),
        (
            "duplicate seeds",
            json!({"spread_seeds": [1, 1]}),
            "spread_seeds",
        ),
        ("no seeds", json!({"spread_seeds": []}), "spread_seeds"),
        // A sample standard deviation over one seed is undefined (it used to be written as 0).
        ("one seed", json!({"spread_seeds": [1]}), "spread_seeds"),
        (
            "basis",
            json!({"basis_per_input": 100000}),
            "basis_per_input",
        ),
        (
            "widths",
            json!({"hidden_layers": [1000000000]}),
            "hidden_layers",
        ),
        (
            "iterations too many",
            json!({"meta_training": {"iterations": 1u64 << 60}}),
            "meta_training.iterations",
        ),
    ];
    for (what, patch, field) in cases {
        let config = small_config(&dir, |value| {
            for (section, fields) in patch.as_object().unwrap() {
                match fields.as_object() {
                    Some(fields) => {
                        for (key, v) in fields {
                            value[section][key] = v.clone();
                        }
                    }
                    None => value[section] = fields.clone(),
                }
            }
        });
        let run = learn_in(&dir, &["meta-train", "--config", path_str(&config)]);
        let message = run.one_line_error(&["learn.json", field]);
        assert!(!message.contains("NaN"), "{what}: {message}");
    }
}

#[test]
fn meta_train_bounds_batches_and_window_by_the_flights() {
    let Some(data) = real_data() else {
        return;
    };
    let dir = scratch("meta-train-batches");
    for (section, key, value, field) in [
        (
            "meta_training",
            "task_batch",
            100_000,
            "meta_training.task_batch",
        ),
        (
            "meta_training",
            "support_batch",
            10_000_000,
            "meta_training.support_batch",
        ),
        (
            "meta_training",
            "query_batch",
            10_000_000,
            "meta_training.query_batch",
        ),
        ("adaptation", "window", 100_000, "adaptation.window"),
    ] {
        let config = small_config(&dir, |v| v[section][key] = json!(value));
        let run = meta_train(&dir, &data, &["--config", path_str(&config)]);
        run.one_line_error(&["learn.json", field]);
    }
}

#[test]
fn meta_train_reports_non_finite_results_instead_of_printing_nan() {
    let Some(data) = real_data() else {
        return;
    };
    let dir = scratch("meta-train-non-finite");
    let config = small_config(&dir, |v| v["adaptation"]["step"] = json!(1e308));
    let run = meta_train(&dir, &data, &["--config", path_str(&config)]);
    run.one_line_error(&["translational 35wind", "adaptation.step", "learn.json"]);
    assert!(
        !dir.join("results").exists(),
        "nothing written, no folder left"
    );
}

#[test]
fn meta_train_never_replaces_a_given_output_without_force() {
    let dir = scratch("meta-train-out");
    std::fs::write(dir.join("mine.json"), "mine").unwrap();
    let config = workspace().join("experiments/learn.json");
    let run = learn_in(
        &dir,
        &[
            "meta-train",
            "--config",
            path_str(&config),
            "--out",
            "mine.json",
        ],
    );
    run.one_line_error(&["mine.json", "already exists", "--force"]);
    assert_eq!(
        std::fs::read_to_string(dir.join("mine.json")).unwrap(),
        "mine"
    );
}

#[test]
fn meta_train_never_writes_over_an_input_even_with_force() {
    let dir = scratch("meta-train-input");
    let config = small_config(&dir, |_| {});
    let before = std::fs::read_to_string(&config).unwrap();
    for extra in [
        &["--out", "learn.json"][..],
        &["--seed-spread", "--spread-out", "learn.json"],
    ] {
        let mut args = vec!["meta-train", "--config", "learn.json", "--force"];
        args.extend_from_slice(extra);
        let run = learn_in(&dir, &args);
        run.one_line_error(&["learn.json", "--config"]);
    }
    // Also under another spelling of the same file.
    let run = learn_in(
        &dir,
        &[
            "meta-train",
            "--config",
            "./learn.json",
            "--out",
            path_str(&config),
            "--force",
        ],
    );
    run.one_line_error(&["learn.json", "--config"]);
    assert_eq!(std::fs::read_to_string(&config).unwrap(), before);
}

#[test]
fn meta_train_refuses_to_replace_a_checkpoint_in_a_given_directory() {
    let Some(data) = real_data() else {
        return;
    };
    let dir = scratch("meta-train-checkpoints");
    let config = small_config(&dir, |_| {});
    std::fs::create_dir_all(dir.join("ck")).unwrap();
    let existing = dir.join("ck/leave-condition-out-translational-35wind-seed1.json");
    std::fs::write(&existing, "mine").unwrap();
    let run_with = |extra: &[&str]| {
        let mut args = vec![
            "--config",
            path_str(&config),
            "--checkpoints",
            "ck",
            "--out",
            "a.json",
        ];
        args.extend(extra);
        meta_train(&dir, &data, &args)
    };
    // A file the command did not write is never replaced, even with --force (issue 18).
    for extra in [&[][..], &["--force"]] {
        let run = run_with(extra);
        run.one_line_error(&[
            "leave-condition-out-translational-35wind-seed1.json",
            "not written by learn",
        ]);
    }
    assert_eq!(std::fs::read_to_string(&existing).unwrap(), "mine");
    assert!(!dir.join("a.json").exists());
    std::fs::remove_file(&existing).unwrap();
    let run = run_with(&[]);
    let stdout = run.success();
    assert!(MetaTrainedModel::load(&existing).is_ok());
    // Its own checkpoint is replaced only with --force.
    std::fs::remove_file(dir.join("a.json")).unwrap();
    run_with(&[]).one_line_error(&[
        "leave-condition-out-translational-35wind-seed1.json",
        "--force",
    ]);
    // The SINDy column is the published number (this command runs no SINDy), and says so.
    assert!(stdout.contains("| SINDy gen (paper) |"), "{stdout}");
    // No progress bar when standard error is not a terminal.
    assert!(run.stderr.is_empty(), "{}", run.stderr);
}

#[test]
fn meta_train_never_writes_the_summary_over_one_of_its_checkpoints_whatever_the_spelling() {
    let dir = scratch("meta-train-out-is-checkpoint");
    let config = small_config(&dir, |_| {});
    std::fs::create_dir_all(dir.join("ck")).unwrap();
    // Without the real flights the refusal must come all the same: it comes before any work.
    let data = real_data().unwrap_or_else(|| dir.to_path_buf());
    let name = "leave-condition-out-translational-35wind-seed1.json";
    let mut spellings = vec![format!("./ck/{name}"), format!("ck/../ck/{name}")];
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(dir.join("ck"), dir.join("link")).unwrap();
        spellings.push(format!("link/{name}"));
    }
    for out in &spellings {
        for force in [false, true] {
            let mut args = vec!["--config", path_str(&config), "--checkpoints", "ck"];
            args.extend(["--out", out.as_str()]);
            if force {
                args.push("--force");
            }
            let run = meta_train(&dir, &data, &args);
            run.one_line_error(&[out, "--out", "checkpoint of this run"]);
            assert!(run.stdout.is_empty(), "{out}: work began: {}", run.stdout);
            assert_eq!(std::fs::read_dir(dir.join("ck")).unwrap().count(), 0);
        }
    }
    // An existing checkpoint given as --out with --force is not replaced either.
    let existing = dir.join("ck").join(name);
    std::fs::write(&existing, "mine").unwrap();
    let out = format!("ck/../ck/{name}");
    let run = meta_train(
        &dir,
        &data,
        &[
            "--config",
            path_str(&config),
            "--checkpoints",
            "ck",
            "--out",
            &out,
            "--force",
        ],
    );
    run.one_line_error(&[&out, "--out", "checkpoint of this run"]);
    assert_eq!(std::fs::read_to_string(&existing).unwrap(), "mine");
}

#[test]
fn meta_train_refuses_a_condition_that_is_not_an_evaluation_condition() {
    let dir = scratch("meta-train-meta-training-condition");
    let config = small_config(&dir, |_| {});
    let data = real_data().unwrap_or_else(|| dir.to_path_buf());
    let conditions = workspace().join("experiments/conditions.json");
    let run = learn_in(
        &dir,
        &[
            "--data",
            path_str(&data),
            "meta-train",
            "--config",
            path_str(&config),
            "--conditions",
            path_str(&conditions),
            "--condition",
            "nowind",
            "--checkpoints",
            "ck",
            "--out",
            "a.json",
        ],
    );
    run.one_line_error(&[
        "--condition nowind",
        "not an evaluation condition",
        "meta-training",
        "35wind, 70p20sint, 70wind, 100wind",
    ]);
    assert!(run.stdout.is_empty(), "work began: {}", run.stdout);
    assert!(!dir.join("ck").exists() && !dir.join("a.json").exists());
}

/// `learn` with `args` in `dir` under a pseudo-terminal (util-linux `script`), standard output and
/// error mixed; `None` where `script` is not installed.
fn learn_on_a_terminal(dir: &Path, args: &[&str]) -> Option<String> {
    let command = std::iter::once(env!("CARGO_BIN_EXE_learn"))
        .chain(args.iter().copied())
        .collect::<Vec<_>>()
        .join(" ");
    let output = std::process::Command::new("script")
        .args(["-qec", &command, "/dev/null"])
        .current_dir(dir)
        .env_remove("NEURAL_FLY_DIR")
        .output()
        .ok()?;
    assert!(output.status.success(), "{output:?}");
    Some(String::from_utf8_lossy(&output.stdout).into_owned())
}

#[test]
fn meta_train_shows_progress_over_the_cells_on_a_terminal_unless_quiet() {
    let Some(data) = real_data() else {
        return;
    };
    let dir = scratch("meta-train-progress");
    let config = small_config(&dir, |_| {});
    let conditions = workspace().join("experiments/conditions.json");
    for (quiet, out) in [(false, "a.json"), (true, "b.json")] {
        let mut args = vec!["--data", path_str(&data)];
        if quiet {
            args.push("--quiet");
        }
        args.extend([
            "meta-train",
            "--config",
            path_str(&config),
            "--conditions",
            path_str(&conditions),
            "--formulation",
            "translational",
            "--checkpoints",
            "ck",
            "--out",
            out,
            "--force",
        ]);
        let Some(output) = learn_on_a_terminal(&dir, &args) else {
            return;
        };
        let drawn = output.contains("meta-train [") && output.contains("/4 cells");
        assert_eq!(drawn, !quiet, "quiet {quiet}: {output}");
        assert!(output.contains("wrote"), "{output}");
    }
}

#[test]
fn meta_train_refuses_outputs_it_cannot_write_before_any_work() {
    let dir = scratch("meta-train-unwritable");
    let config = small_config(&dir, |_| {});
    std::fs::write(dir.join("file"), "mine").unwrap();
    std::fs::create_dir_all(dir.join("folder")).unwrap();
    // With the real flights the run could start: it must not, not even load them.
    let data = real_data().unwrap_or_else(|| dir.to_path_buf());
    let conditions = workspace().join("experiments/conditions.json");
    let cases: [(&[&str], &[&str]); 5] = [
        (
            &["--checkpoints", "file", "--out", "a.json"],
            &["file", "--checkpoints", "not a directory"],
        ),
        (
            &["--checkpoints", "file/ck", "--out", "a.json"],
            &["file/ck", "--checkpoints", "not a directory"],
        ),
        (
            &["--checkpoints", "ck", "--out", "folder", "--force"],
            &["folder", "--out", "is a directory"],
        ),
        (
            &["--checkpoints", "ck", "--out", "file/a.json"],
            &["file/a.json", "--out", "not a directory"],
        ),
        (
            &["--seed-spread", "--spread-out", "folder", "--force"],
            &["folder", "--spread-out", "is a directory"],
        ),
    ];
    for (extra, needles) in cases {
        let mut args = vec!["--config", path_str(&config)];
        args.extend_from_slice(extra);
        let run = if extra[0] == "--seed-spread" {
            // Every condition (no --condition) and the real flights: a spread run could start.
            let mut all = vec![
                "--data",
                path_str(&data),
                "meta-train",
                "--conditions",
                path_str(&conditions),
            ];
            all.extend_from_slice(&args);
            learn_in(&dir, &all)
        } else {
            meta_train(&dir, &data, &args)
        };
        run.one_line_error(needles);
        assert!(
            run.stdout.is_empty(),
            "{extra:?}: work began before the error: {}",
            run.stdout
        );
        assert_eq!(std::fs::read_to_string(dir.join("file")).unwrap(), "mine");
        assert!(!dir.join("ck").exists() && !dir.join("a.json").exists());
        assert_eq!(std::fs::read_dir(dir.join("folder")).unwrap().count(), 0);
        assert!(!dir.join("results").exists(), "{extra:?}: nothing written");
    }
}

#[test]
fn meta_train_seed_spread_refuses_the_flags_it_would_ignore() {
    let dir = scratch("meta-train-spread-outputs");
    let config = small_config(&dir, |_| {});
    for (flag, value) in [
        ("--out", "a.json"),
        ("--checkpoints", "ck"),
        ("--seed", "7"),
        ("--published", "p.json"),
    ] {
        let run = learn_in(
            &dir,
            &[
                "meta-train",
                "--config",
                path_str(&config),
                "--seed-spread",
                "--spread-out",
                "spread.json",
                flag,
                value,
            ],
        );
        run.one_line_usage_error(&["--seed-spread", flag, "cannot be used with"]);
        assert!(run.stdout.is_empty(), "{}", run.stdout);
        for written in ["a.json", "ck", "spread.json", "results"] {
            assert!(!dir.join(written).exists(), "{flag}: {written} written");
        }
    }
    // And --spread-out means nothing without --seed-spread.
    let run = learn_in(
        &dir,
        &[
            "meta-train",
            "--config",
            path_str(&config),
            "--spread-out",
            "spread.json",
        ],
    );
    run.one_line_usage_error(&["required arguments were not provided: --seed-spread"]);
    assert!(run.stdout.is_empty() && !dir.join("spread.json").exists());
}

#[test]
fn meta_train_published_file_given_must_exist_and_parse() {
    let dir = scratch("meta-train-published");
    let config = workspace().join("experiments/learn.json");
    let config = path_str(&config);
    let run = learn_in(
        &dir,
        &["meta-train", "--config", config, "--published", "nope.json"],
    );
    run.one_line_error(&["nope.json"]);
    std::fs::write(dir.join("bad.json"), "{\"tables\": ").unwrap();
    let run = learn_in(
        &dir,
        &["meta-train", "--config", config, "--published", "bad.json"],
    );
    run.one_line_error(&["bad.json", "line 1"]);
    // The default file may be absent (the next error is about the conditions), not invalid.
    let run = learn_in(&dir, &["meta-train", "--config", config]);
    let message = run.one_line_error(&["conditions.json"]);
    assert!(!message.contains("published"), "{message}");
    std::fs::create_dir_all(dir.join("paper")).unwrap();
    std::fs::write(dir.join("paper/published.json"), "not json").unwrap();
    let run = learn_in(&dir, &["meta-train", "--config", config]);
    run.one_line_error(&["paper/published.json"]);
}

#[test]
fn explain_never_writes_json_over_an_input_or_an_existing_file() {
    let dir = scratch("explain-json");
    let model = checkpoint(&dir, "model.json", |_| {});
    let before = std::fs::read(&model).unwrap();
    let run = learn_in(
        &dir,
        &["explain", "model.json", "--json", "model.json", "--force"],
    );
    run.one_line_error(&["model.json", "checkpoint"]);
    std::fs::write(dir.join("flight.csv"), "t\n0\n").unwrap();
    let run = learn_in(
        &dir,
        &[
            "explain",
            "model.json",
            "--flight",
            "flight.csv",
            "--json",
            "./flight.csv",
            "--force",
        ],
    );
    run.one_line_error(&["flight.csv", "--flight"]);
    std::fs::write(dir.join("mine.json"), "mine").unwrap();
    let run = learn_in(&dir, &["explain", "model.json", "--json", "mine.json"]);
    run.one_line_error(&["mine.json", "already exists", "--force"]);
    assert_eq!(std::fs::read(&model).unwrap(), before);
    assert_eq!(
        std::fs::read_to_string(dir.join("mine.json")).unwrap(),
        "mine"
    );
    assert_eq!(
        std::fs::read_to_string(dir.join("flight.csv")).unwrap(),
        "t\n0\n"
    );
}

#[test]
fn explain_rejects_a_checkpoint_with_a_degenerate_standardiser_or_bad_settings() {
    let dir = scratch("explain-checkpoint");
    checkpoint(&dir, "zero-std.json", |model| {
        model.standardiser.std.iter_mut().for_each(|s| *s = 0.0);
    });
    let run = learn_in(&dir, &["explain", "zero-std.json"]);
    run.one_line_error(&["zero-std.json", "standardiser.std"]);
    checkpoint(&dir, "no-passes.json", |model| {
        model.config.adaptation.passes = 0
    });
    let run = learn_in(&dir, &["explain", "no-passes.json"]);
    run.one_line_error(&["no-passes.json", "config.adaptation.passes"]);
    let run = learn_in(&dir, &["explain", "zero-std.json", "--max-terms", "0"]);
    run.one_line_error(&["--max-terms"]);
}

#[test]
fn explain_names_a_flight_too_short_to_split() {
    let Some(data) = real_data() else {
        return;
    };
    let dir = scratch("explain-short-flight");
    checkpoint(&dir, "model.json", |_| {});
    let text = std::fs::read_to_string(data.join("experiment/custom_figure8_baseline_35wind.csv"))
        .unwrap();
    let head: Vec<&str> = text.lines().take(4).collect();
    std::fs::write(dir.join("short.csv"), head.join("\n") + "\n").unwrap();
    let run = learn_in(&dir, &["explain", "model.json", "--flight", "short.csv"]);
    run.one_line_error(&["short.csv", "too few"]);
}

#[test]
fn explain_blames_the_checkpoint_not_the_adaptation_when_it_is_not_finite_before_adapting() {
    let Some(data) = real_data() else {
        return;
    };
    let dir = scratch("explain-bad-checkpoint");
    let flight = data.join("experiment/custom_figure8_baseline_35wind.csv");
    type Edit = fn(&mut MetaTrainedModel);
    let cases: [(&str, Edit); 4] = [
        ("parameter.json", |model| model.parameters[0] = 1e308),
        ("std.json", |model| model.standardiser.std[0] = 1e-300),
        ("mean.json", |model| model.standardiser.mean[0] = 1e308),
        // (x + 1e308) / 1e-10 overflows: the standardised inputs themselves are not finite.
        ("inputs.json", |model| {
            model.standardiser.mean[0] = -1e308;
            model.standardiser.std[0] = 1e-10;
        }),
    ];
    for (name, edit) in cases {
        checkpoint(&dir, name, edit);
        for adapt in [true, false] {
            let mut args = vec!["explain", name, "--flight", path_str(&flight)];
            if !adapt {
                args.push("--no-adapt");
            }
            let run = learn_in(&dir, &args);
            let message = run.one_line_error(&[
                "custom_figure8_baseline_35wind.csv",
                "standardiser",
                "not finite",
                "before any adaptation",
            ]);
            if name == "inputs.json" {
                assert!(message.contains("standardised inputs"), "{message}");
            }
            assert!(
                !message.contains("adaptation.step") && !message.contains("too large"),
                "{name}: {message}"
            );
        }
    }
}

#[test]
fn explain_refuses_an_unknown_field_in_the_checkpoint_architecture() {
    let dir = scratch("explain-architecture-field");
    let path = checkpoint(&dir, "model.json", |_| {});
    let mut value: Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    value["architecture"]["hiden"] = json!([4]);
    std::fs::write(&path, value.to_string()).unwrap();
    let run = learn_in(&dir, &["explain", "model.json"]);
    run.one_line_error(&["model.json", "architecture.hiden", "unknown field"]);
}

#[test]
fn explain_reports_non_finite_adaptation_instead_of_printing_nan() {
    let Some(data) = real_data() else {
        return;
    };
    let dir = scratch("explain-non-finite");
    checkpoint(&dir, "model.json", |model| {
        model.config.adaptation.step = 1e308
    });
    let flight = data.join("experiment/custom_figure8_baseline_35wind.csv");
    let run = learn_in(
        &dir,
        &["explain", "model.json", "--flight", path_str(&flight)],
    );
    let message = run.one_line_error(&[
        "translational",
        "custom_figure8_baseline_35wind.csv",
        "adaptation.step",
    ]);
    // Blamed only because the meta-trained parameters alone give finite predictions.
    assert!(
        message.contains("finite predictions before adaptation"),
        "{message}"
    );
}

#[test]
fn explain_rejects_a_window_longer_than_the_support_segment_and_non_finite_coefficients() {
    let Some(data) = real_data() else {
        return;
    };
    let dir = scratch("explain-window");
    let flight = data.join("experiment/custom_figure8_baseline_35wind.csv");
    checkpoint(&dir, "window.json", |model| {
        model.config.adaptation.window = 100_000
    });
    let run = learn_in(
        &dir,
        &["explain", "window.json", "--flight", path_str(&flight)],
    );
    run.one_line_error(&["custom_figure8_baseline_35wind.csv", "adaptation.window"]);
    // Parameters whose products overflow: the coefficients are not finite.
    checkpoint(&dir, "huge.json", |model| {
        model.parameters.iter_mut().for_each(|p| *p = 1e200)
    });
    let run = learn_in(
        &dir,
        &[
            "explain",
            "huge.json",
            "--no-adapt",
            "--flight",
            path_str(&flight),
        ],
    );
    run.one_line_error(&["custom_figure8_baseline_35wind.csv", "not finite"]);
}

#[test]
fn explain_refuses_conditions_with_a_flight_it_would_ignore() {
    let dir = scratch("explain-conditions-flight");
    let run = learn_in(
        &dir,
        &[
            "explain",
            "model.json",
            "--flight",
            "flight.csv",
            "--conditions",
            "conditions.json",
        ],
    );
    run.one_line_usage_error(&["--conditions", "--flight", "cannot be used with"]);
    assert!(run.stdout.is_empty(), "{}", run.stdout);
}
