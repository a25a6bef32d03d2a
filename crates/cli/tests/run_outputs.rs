//! `learn reproduce` and `learn ablations` check every file they will write or replace against
//! every file they read (configuration, conditions, published numbers, LeARN configuration),
//! before any work: an input inside an output directory is a one-line error, and nothing is
//! written. No option allows it.

mod common;

use std::path::{Path, PathBuf};

use common::{learn_in, scratch};

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .unwrap()
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Every file under `dir`, relative to it, sorted.
fn files_under(dir: &Path) -> Vec<PathBuf> {
    common::sweep::files_under(dir, &[]).into_keys().collect()
}

#[test]
fn ablations_refuse_an_output_directory_holding_their_configuration() {
    let dir = scratch("ablations-config-in-out");
    let root = workspace();
    let root = root.to_str().unwrap();
    std::fs::create_dir(dir.join("out")).unwrap();
    let mut variants = json(&workspace().join("experiments/variants.json"));
    variants["seeds"] = serde_json::json!([1]);
    let config = dir.join("out/ablations.json");
    std::fs::write(&config, variants.to_string()).unwrap();
    let before = std::fs::read_to_string(&config).unwrap();
    let args = [
        "ablations",
        "--root",
        root,
        "--config",
        "out/ablations.json",
        "--out",
        "out",
    ];
    learn_in(&dir, &args).one_line_error(&[
        "out/ablations.json: is the --config input, which this run reads",
        "refusing to write over it",
    ]);
    assert_eq!(std::fs::read_to_string(&config).unwrap(), before);
    assert_eq!(files_under(&dir), vec![PathBuf::from("out/ablations.json")]);

    // The run configuration the variants name, as the file the ablations write.
    std::fs::copy(workspace().join("experiments/reproduce.json"), &config).unwrap();
    variants["run"] = config.to_str().unwrap().into();
    std::fs::write(dir.join("v.json"), variants.to_string()).unwrap();
    let args = [
        "ablations",
        "--root",
        root,
        "--config",
        "v.json",
        "--out",
        "out",
    ];
    learn_in(&dir, &args).one_line_error(&["ablations.json: is the run of v.json input"]);
}

#[test]
fn reproduce_refuses_inputs_among_the_files_it_writes_or_replaces() {
    let dir = scratch("reproduce-inputs-in-out");
    let root = workspace();
    let root = root.to_str().unwrap();
    std::fs::create_dir_all(dir.join("res/tables")).unwrap();
    let run = json(&workspace().join("experiments/reproduce.json"));
    // `reproduce` with `config`, writing to res/ and tex/, updating `readme` if given.
    let reproduce = |config: &str, readme: Option<&str>| {
        let mut args = vec![
            "reproduce",
            "--root",
            root,
            "--config",
            config,
            "--out",
            "res",
            "--latex-dir",
            "tex",
        ];
        args.extend(
            readme
                .map(|readme| ["--readme", readme])
                .into_iter()
                .flatten(),
        );
        learn_in(&dir, &args)
    };

    // The configuration as one of the tables the run writes.
    std::fs::write(dir.join("res/tables/translational.json"), run.to_string()).unwrap();
    reproduce("res/tables/translational.json", None).one_line_error(&[
        "res/tables/translational.json: is the --config input, which this run reads",
    ]);

    // The published numbers the configuration names, as the run's summary.
    let mut moved = run.clone();
    let published = dir.join("res/summary.json");
    std::fs::copy(workspace().join("paper/published.json"), &published).unwrap();
    moved["published"] = published.to_str().unwrap().into();
    std::fs::write(dir.join("r.json"), moved.to_string()).unwrap();
    reproduce("r.json", None).one_line_error(&[
        "res/summary.json: is the published of r.json input",
        "refusing to write over it",
    ]);

    // The README to update may be no input and no other output.
    std::fs::write(dir.join("r.json"), run.to_string()).unwrap();
    reproduce("r.json", Some("r.json"))
        .one_line_error(&["r.json: is the --config input, which this run reads: refusing"]);
    reproduce("r.json", Some("res/timings.json"))
        .one_line_error(&["res/timings.json: the --readme to update is also an output of the run"]);
    // Nothing was made: no directory, no probe file.
    assert_eq!(
        files_under(&dir),
        vec![
            PathBuf::from("r.json"),
            PathBuf::from("res/summary.json"),
            PathBuf::from("res/tables/translational.json")
        ]
    );
}

/// A variants file with one cheap variant (`lag-ridge-cv`), one seed, on a run configuration with
/// one formulation, written in `dir`; returns its path.
fn tiny_variants(dir: &Path) -> PathBuf {
    let root = workspace();
    let mut run = json(&root.join("experiments/ci.json"));
    run["formulations"] = serde_json::json!(["translational"]);
    run["learn"]["protocol"] = "leave-condition-out".into();
    for (field, file) in [
        ("/conditions", "experiments/conditions.json"),
        ("/published", "paper/published.json"),
        ("/learn/config", "experiments/learn.json"),
    ] {
        *run.pointer_mut(field).unwrap() = root.join(file).to_str().unwrap().into();
    }
    std::fs::write(dir.join("run.json"), run.to_string()).unwrap();
    let mut variants = json(&root.join("experiments/variants.json"));
    variants["run"] = dir.join("run.json").to_str().unwrap().into();
    variants["seeds"] = serde_json::json!([1]);
    let kept: Vec<serde_json::Value> = variants["variants"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|v| v["name"] == "lag-ridge-cv")
        .cloned()
        .collect();
    variants["variants"] = kept.into();
    variants["headline"] = "lag-ridge-cv".into();
    variants["reproduce"] = serde_json::json!([]);
    variants.as_object_mut().unwrap().remove("figure_variant");
    let path = dir.join("tiny.json");
    std::fs::write(&path, variants.to_string()).unwrap();
    path
}

#[test]
fn ablations_print_no_progress_lines_when_standard_error_is_not_a_terminal() {
    let Some(data) = data::real_data_dir_for_tests(&workspace()) else {
        return;
    };
    let dir = scratch("ablations-quiet-log");
    tiny_variants(&dir);
    let data = data.to_str().unwrap();
    let args = [
        "--data",
        data,
        "ablations",
        "--config",
        "tiny.json",
        "--out",
        "out",
    ];
    let run = learn_in(&dir, &args);
    assert!(run.success().contains("# Ablations"), "{}", run.stdout);
    // Standard error is a pipe here: only the final summary, no line per cell.
    let lines: Vec<&str> = run.stderr.lines().collect();
    assert_eq!(lines.len(), 1, "{}", run.stderr);
    assert!(
        lines[0].ends_with("total; wrote 2 files under out"),
        "{}",
        run.stderr
    );
    assert!(dir.join("out/ablations.json").is_file());
}

#[test]
fn ablations_render_only_refuses_the_options_it_would_ignore() {
    let dir = scratch("ablations-render-only");
    for (args, flag) in [
        (
            vec!["ablations", "--render-only", "--config", "/nonexistent"],
            "--config",
        ),
        (
            vec!["ablations", "--render-only", "--root", "/nonexistent"],
            "--root",
        ),
    ] {
        learn_in(&dir, &args).one_line_usage_error(&["'--render-only' cannot be used with", flag]);
    }
}
