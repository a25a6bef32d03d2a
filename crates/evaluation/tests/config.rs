//! Run configurations: checked once, with one-line errors naming the file and field.

use std::path::{Path, PathBuf};

use evaluation::RunConfig;
use serde_json::{Value, json};

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn committed(name: &str) -> Value {
    serde_json::from_str(&std::fs::read_to_string(workspace().join(name)).unwrap()).unwrap()
}

/// A fresh temporary directory, removed with everything in it when dropped.
fn temp_dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("evaluation-{name}-"))
        .tempdir()
        .unwrap()
}

/// Writes `config` to a temporary file and loads it against the workspace root.
fn load(name: &str, config: &Value) -> Result<evaluation::CheckedRunConfig, String> {
    let dir = temp_dir("config");
    load_in(dir.path(), name, config)
}

/// Writes `config` as `{name}.json` in `dir` and loads it against the workspace root.
fn load_in(dir: &Path, name: &str, config: &Value) -> Result<evaluation::CheckedRunConfig, String> {
    let path = dir.join(format!("{name}.json"));
    std::fs::write(&path, config.to_string()).unwrap();
    RunConfig::load(&path, &workspace()).map_err(|e| e.to_string())
}

#[test]
fn the_committed_configurations_share_the_protocol_and_differ_in_budget() {
    let reproduce = RunConfig::load(
        &workspace().join("experiments/reproduce.json"),
        &workspace(),
    )
    .unwrap();
    let ci = RunConfig::load(&workspace().join("experiments/ci.json"), &workspace()).unwrap();
    assert_eq!(reproduce.raw.formulations, ci.raw.formulations);
    assert_eq!(reproduce.raw.conditions, ci.raw.conditions);
    assert_eq!(reproduce.raw.split, ci.raw.split);
    assert_eq!(reproduce.raw.derivative, ci.raw.derivative);
    assert_eq!(reproduce.raw.sindy, ci.raw.sindy);
    assert_eq!(reproduce.raw.learn.protocol, ci.raw.learn.protocol);
    let (full, small) = (reproduce.learn.get(), ci.learn.get());
    assert_eq!(full.adaptation, small.adaptation);
    assert_eq!(full.hidden_layers, small.hidden_layers);
    assert!(small.meta_training.iterations <= full.meta_training.iterations);
}

#[test]
fn overrides_are_merged_before_the_learn_configuration_is_checked() {
    let mut config = committed("experiments/reproduce.json");
    config["learn"]["overrides"] = json!({"meta_training": {"iterations": 3}});
    let checked = load("overrides", &config).unwrap();
    assert_eq!(checked.learn.get().meta_training.iterations, 3);

    config["learn"]["overrides"] = json!({"meta_training": {"iterationz": 3}});
    let message = load("unknown-override", &config).unwrap_err();
    assert!(
        message.contains("learn.overrides") && message.contains("iterationz"),
        "{message}"
    );
    config["learn"]["overrides"] = json!({"meta_training": {"inner_step": -1.0}});
    let message = load("bad-override", &config).unwrap_err();
    assert!(message.contains("inner_step"), "{message}");
}

#[test]
fn a_bad_value_set_by_the_overrides_is_blamed_on_the_overrides() {
    let mut config = committed("experiments/reproduce.json");
    config["learn"]["overrides"] = json!({"meta_training": {"iterations": 0}});
    let dir = temp_dir("config");
    let message = load_in(dir.path(), "zero-iterations", &config).unwrap_err();
    assert!(
        message.starts_with(&format!(
            "{}: learn.overrides: ",
            dir.path().join("zero-iterations.json").display()
        )) && message
            .contains("learn.json with these overrides: field 'meta_training.iterations': "),
        "{message}"
    );
    assert!(!message.contains('\n'), "{message}");
}

#[test]
fn bad_values_name_the_file_and_field() {
    let base = committed("experiments/reproduce.json");
    let cases = [
        (
            "split",
            json!({"kind": "fraction", "support": 1.5}),
            "split: support fraction 1.5 must lie in (0, 1)",
        ),
        (
            "derivative",
            json!({"kind": "savitzky_golay", "window": 4, "order": 2}),
            "derivative: ",
        ),
        ("formulations", json!([]), "formulations"),
    ];
    for (field, value, expected) in cases {
        let mut config = base.clone();
        config[field] = value;
        let message = load(field, &config).unwrap_err();
        assert!(
            message.contains(&format!("{field}.json")) && message.contains(expected),
            "{message}"
        );
    }
    let mut config = base.clone();
    config["learn"]["seeds"] = json!([1, 1]);
    assert!(load("seeds", &config).unwrap_err().contains("learn.seeds"));
    let mut config = base.clone();
    config["learn"]["protocol"] = json!("sometimes");
    assert!(load("protocol", &config).unwrap_err().contains("sometimes"));
    let mut config = base.clone();
    config["conditions"] = json!("experiments/no-such-file.json");
    assert!(
        load("conditions", &config)
            .unwrap_err()
            .contains("no-such-file.json")
    );
    // Everything the run reads later is checked when the configuration is loaded, so a bad
    // value does not surface only after the flights are loaded and LeARN is meta-trained.
    let mut config = base.clone();
    config["sindy"]["optimizer"]["alpha"] = json!(-1.0);
    let message = load("sindy-alpha", &config).unwrap_err();
    assert!(
        message.contains("sindy-alpha.json") && message.contains("sindy.optimizer"),
        "{message}"
    );
    let mut config = base.clone();
    config["sindy"]["library"] = json!({"kind": "fourier", "frequencies": 0});
    let message = load("sindy-library", &config).unwrap_err();
    assert!(message.contains("sindy.library"), "{message}");
    for (field, missing) in [
        ("published", "paper/no-such-published.json"),
        ("variants", "experiments/no-such-variants.json"),
    ] {
        let mut config = base.clone();
        config[field] = json!(missing);
        let message = load(field, &config).unwrap_err();
        assert!(message.contains(missing), "{message}");
    }
}

#[test]
fn a_library_too_large_for_the_inputs_is_refused_when_the_configuration_is_loaded() {
    let base = committed("experiments/reproduce.json");
    for (name, library, expected) in [
        (
            "fourier-huge",
            json!({"kind": "fourier", "frequencies": 1_000_000_000u64}),
            "single input",
        ),
        (
            "fourier-1e5",
            json!({"kind": "fourier", "frequencies": 100_000}),
            "single input",
        ),
        (
            "poly-50",
            json!({"kind": "polynomial", "degree": 50, "constant": true}),
            "formulation",
        ),
        (
            "poly-huge",
            json!({"kind": "polynomial", "degree": u64::MAX, "constant": true}),
            "limit of 10000",
        ),
    ] {
        let mut config = base.clone();
        config["sindy"]["library"] = library;
        let start = std::time::Instant::now();
        let message = load(name, &config).unwrap_err();
        assert!(
            message.contains(&format!("{name}.json: sindy.library: "))
                && message.contains(expected)
                && message.contains("limit of 10000"),
            "{message}"
        );
        assert!(
            start.elapsed().as_secs() < 5,
            "{name} took {:?}",
            start.elapsed()
        );
    }
    // Within the limit on every formulation: accepted.
    let mut config = base.clone();
    config["sindy"]["library"] = json!({"kind": "polynomial", "degree": 2, "constant": true});
    load("poly-2", &config).unwrap();
}

#[test]
fn split_and_derivative_refuse_fields_their_kind_does_not_have() {
    let base = committed("experiments/reproduce.json");
    for (name, field, value) in [
        (
            "split-ratio",
            "split",
            json!({"kind": "halves", "ratio": 0.3}),
        ),
        (
            "derivative-window",
            "derivative",
            json!({"kind": "forward", "window": 5}),
        ),
    ] {
        let mut config = base.clone();
        config[field] = value;
        let message = load(name, &config).unwrap_err();
        assert!(
            message.contains(&format!("{name}.json: {field}")) && message.contains("unknown field"),
            "{message}"
        );
    }
    let mut config = base.clone();
    config["sindy"]["fit_derivative"] = json!({"kind": "central", "order": 2});
    let message = load("fit-derivative", &config).unwrap_err();
    assert!(message.contains("unknown field `order`"), "{message}");
    config["sindy"]["fit_derivative"] = json!({"kind": "savitzky_golay", "window": 4, "order": 2});
    let message = load("fit-derivative", &config).unwrap_err();
    assert!(message.contains("sindy.fit_derivative"), "{message}");
}

#[test]
fn seeds_are_capped() {
    let mut config = committed("experiments/reproduce.json");
    config["learn"]["seeds"] = json!((0..100_000).collect::<Vec<u64>>());
    let start = std::time::Instant::now();
    let message = load("many-seeds", &config).unwrap_err();
    assert!(
        message.contains("learn.seeds: 100000 seeds, more than the limit of 100"),
        "{message}"
    );
    assert!(start.elapsed().as_secs() < 5);
}

#[test]
fn a_fault_of_the_learn_configuration_itself_is_named_in_that_file() {
    let dir = temp_dir("learn-own");
    let mut learn = committed("experiments/learn.json");
    learn.as_object_mut().unwrap().remove("seed");
    let learn_path = dir.path().join("noseed.json");
    std::fs::write(&learn_path, learn.to_string()).unwrap();
    let mut config = committed("experiments/reproduce.json");
    config["learn"]["config"] = learn_path.to_str().unwrap().into();
    let message = load("learn-without-seed", &config).unwrap_err();
    // No overrides: not blamed on them, and the position in the file is given.
    assert!(!message.contains("overrides"), "{message}");
    assert!(
        message.contains("noseed.json: the document (line 1 column ")
            && message.ends_with("missing field `seed`"),
        "{message}"
    );
}

#[test]
fn any_valid_split_and_derivative_is_taken_as_the_run_s_segmentation() {
    let mut config = committed("experiments/reproduce.json");
    config["split"] = json!({"kind": "fraction", "support": 0.7});
    config["derivative"] = json!({"kind": "savitzky_golay", "window": 5, "order": 2});
    let checked = load("segmentation", &config).unwrap();
    assert_eq!(
        checked.segmentation(),
        evaluation::Segmentation {
            split: data::SplitSpec::Fraction { support: 0.7 },
            derivative: sindy::Derivative::SavitzkyGolay {
                window: 5,
                order: 2
            },
        }
    );
    let committed = load("committed", &committed("experiments/reproduce.json")).unwrap();
    assert_eq!(committed.segmentation(), evaluation::Segmentation::PAPER);
}
