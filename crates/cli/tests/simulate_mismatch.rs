//! `learn simulate` and `learn mismatch` on bad input: every scenario, model and demo manifest is
//! checked when it is read, and a bad one gives a one-line error naming the file and the field,
//! before any work (no panic, no abort, no hang, nothing written outside the output directories).

mod common;

use std::path::{Path, PathBuf};

use common::{learn_in, scratch};
use serde_json::{Value, json};

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A scratch directory holding the demo model (`quad.json`) and the committed control scenario
/// (`control.json`) pointing at it.
fn setup(test: &str) -> PathBuf {
    let dir = scratch(test);
    std::fs::copy(
        workspace().join("experiments/mismatch/demo-quad.json"),
        dir.join("quad.json"),
    )
    .unwrap();
    write_scenario(&dir, "control.json", |_| {});
    dir
}

/// Writes the control scenario, changed by `change`, as `name` in `dir`.
fn write_scenario(dir: &Path, name: &str, change: impl FnOnce(&mut Value)) {
    let text =
        std::fs::read_to_string(workspace().join("experiments/mismatch/scenarios/control.json"))
            .unwrap();
    let mut scenario: Value = serde_json::from_str(&text).unwrap();
    scenario["model"] = json!("quad.json");
    change(&mut scenario);
    std::fs::write(dir.join(name), scenario.to_string()).unwrap();
}

/// Runs `simulate` on the control scenario changed by `change` and returns the run's error.
fn simulate_changed(test: &str, change: impl FnOnce(&mut Value), needles: &[&str]) {
    let dir = setup(test);
    write_scenario(&dir, "s.json", change);
    let run = learn_in(
        &dir,
        &["simulate", "--scenario", "s.json", "--out", "f.csv"],
    );
    run.one_line_error(&[&["s.json"], needles].concat());
    assert!(!dir.join("f.csv").exists());
}

#[test]
fn a_negative_integral_limit_is_a_field_error_not_a_panic() {
    simulate_changed(
        "sim-intlim",
        |s| s["gains"] = json!({"integral_limit": -1}),
        &["gains.integral_limit"],
    );
    simulate_changed(
        "sim-gain-neg",
        |s| s["gains"] = json!({"position": -6}),
        &["gains.position"],
    );
}

#[test]
fn huge_sizes_are_refused_before_any_work() {
    let start = std::time::Instant::now();
    simulate_changed(
        "sim-dur-huge",
        |s| s["duration_s"] = json!(1e7),
        &["duration_s"],
    );
    simulate_changed(
        "sim-phys-huge",
        |s| s["physics_rate_hz"] = json!(5e8),
        &["physics_rate_hz"],
    );
    simulate_changed(
        "sim-warm-huge",
        |s| s["warmup_s"] = json!(1e7),
        &["warmup_s"],
    );
    simulate_changed(
        "sim-count-huge",
        |s| {
            s["trajectory"] = json!({"kind": "random_waypoints", "seed": 1, "count": 1_000_000_000u64,
                "box_min": [-2, -2, 1], "box_max": [2, 2, 2], "segment_s": 2.5});
        },
        &["trajectory.count"],
    );
    assert!(start.elapsed().as_secs() < 60, "{:?}", start.elapsed());
}

#[test]
fn a_too_short_flight_is_refused_and_the_shortest_accepted_one_is_usable() {
    simulate_changed(
        "sim-dur-tiny",
        |s| s["duration_s"] = json!(0.001),
        &["duration_s", "rows"],
    );
    let dir = setup("sim-dur-short");
    write_scenario(&dir, "short.json", |s| s["duration_s"] = json!(5.0));
    let run = learn_in(
        &dir,
        &["simulate", "--scenario", "short.json", "--out", "short.csv"],
    );
    assert!(run.success().contains("251 rows"), "{}", run.stdout);
    learn_in(&dir, &["data", "inspect", "short.csv"]).success();
    learn_in(
        &dir,
        &[
            "mismatch",
            "--recording",
            "short.csv",
            "--model",
            "quad.json",
            "--out",
            "out",
        ],
    )
    .success();
}

#[test]
fn trajectory_settings_are_field_errors_not_a_divergence() {
    simulate_changed(
        "sim-yaw-period",
        |s| s["trajectory"]["yaw_period_s"] = json!(0),
        &["trajectory.yaw_period_s"],
    );
    simulate_changed(
        "sim-amplitude",
        |s| s["trajectory"]["first"] = json!([1e6, 0, 0]),
        &["trajectory", "reference accelerates"],
    );
    simulate_changed(
        "sim-underground",
        |s| {
            s["trajectory"]["low_passes"] =
                json!([{"start_s": 8, "end_s": 20, "height_m": -1, "ramp_s": 2}]);
        },
        &["trajectory", "ground"],
    );
}

#[test]
fn simulate_refuses_a_directory_as_output() {
    let dir = setup("sim-out-dir");
    std::fs::create_dir(dir.join("out.csv")).unwrap();
    let run = learn_in(
        &dir,
        &[
            "simulate",
            "--scenario",
            "control.json",
            "--out",
            "out.csv",
            "--force",
        ],
    );
    run.one_line_error(&["out.csv", "directory"]);
}

/// Writes a demo manifest with one case per name, each the control scenario.
fn write_manifest(dir: &Path, names: &[&str]) {
    let cases: Vec<Value> = names
        .iter()
        .map(|name| json!({"name": name, "scenario": "control.json", "purpose": "test"}))
        .collect();
    std::fs::write(dir.join("demo.json"), json!({ "cases": cases }).to_string()).unwrap();
}

fn demo(dir: &Path) -> common::Run {
    learn_in(
        dir,
        &[
            "mismatch",
            "--demo",
            "demo.json",
            "--work",
            "work/w",
            "--out",
            "out",
        ],
    )
}

#[test]
fn demo_case_names_cannot_leave_the_work_directory_or_repeat() {
    let dir = setup("demo-names");
    let outside = dir.join("outside");
    let absolute = outside.to_str().unwrap();
    for (names, field) in [
        (vec![absolute], "cases[0].name"),
        (vec!["control", "../../escape"], "cases[1].name"),
        (vec![""], "cases[0].name"),
        (vec!["control", "control"], "cases[1].name"),
        (vec![], "cases"),
    ] {
        write_manifest(&dir, &names);
        demo(&dir).one_line_error(&["demo.json", field]);
        assert!(!dir.join("work").exists() && !dir.join("out").exists());
        assert!(!outside.exists() && !dir.join("escape").exists());
    }
}

#[test]
fn demo_checks_every_scenario_before_running_a_case() {
    let dir = setup("demo-bad-scenario");
    write_scenario(&dir, "bad.json", |s| {
        s["gains"] = json!({"integral_limit": -1});
    });
    std::fs::write(
        dir.join("demo.json"),
        r#"{"cases": [{"name": "control", "scenario": "control.json", "purpose": "p"},
                      {"name": "bad", "scenario": "bad.json", "purpose": "p"}]}"#,
    )
    .unwrap();
    demo(&dir).one_line_error(&["bad.json", "gains.integral_limit"]);
    assert!(!dir.join("work").exists());
}

#[test]
fn demo_refuses_a_file_as_work_directory_before_running() {
    let dir = setup("demo-work-file");
    write_manifest(&dir, &["control"]);
    std::fs::create_dir(dir.join("work")).unwrap();
    std::fs::write(dir.join("work/w"), "mine").unwrap();
    demo(&dir).one_line_error(&["work/w", "not a directory"]);
    assert_eq!(std::fs::read_to_string(dir.join("work/w")).unwrap(), "mine");
}

#[test]
fn demo_does_not_take_a_model() {
    let dir = setup("demo-model");
    write_manifest(&dir, &["control"]);
    let run = learn_in(
        &dir,
        &[
            "mismatch",
            "--demo",
            "demo.json",
            "--model",
            "quad.json",
            "--out",
            "out",
        ],
    );
    assert_eq!(run.code, Some(2), "{}", run.stderr);
    assert!(run.stderr.contains("cannot be used with"), "{}", run.stderr);
}

/// The model file is read strictly: an unknown key (a typo) is an error, not silently dropped.
#[test]
fn mismatch_model_rejects_unknown_fields() {
    let dir = setup("mm-model-typo");
    let model: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("quad.json")).unwrap()).unwrap();
    let mut typo = model.clone();
    typo.as_object_mut().unwrap().remove("ground_height_m");
    typo["ground_height"] = json!(0.5);
    std::fs::write(dir.join("typo.json"), typo.to_string()).unwrap();
    let mut in_mixer = model.clone();
    in_mixer["mixer"]["extra"] = json!(1);
    std::fs::write(dir.join("mixer.json"), in_mixer.to_string()).unwrap();
    let mut no_thrust = model;
    no_thrust["mixer"]["b0"][0] = json!([9.0, 0.0, 9.0, 9.0]);
    std::fs::write(dir.join("thrust.json"), no_thrust.to_string()).unwrap();
    for (file, field) in [
        ("typo.json", "'ground_height'"),
        ("mixer.json", "'mixer.extra'"),
        ("thrust.json", "'mixer.b0[0][1]'"),
    ] {
        let run = learn_in(
            &dir,
            &[
                "mismatch",
                "--recording",
                "missing.csv",
                "--model",
                file,
                "--out",
                "out",
            ],
        );
        run.one_line_error(&[file, field]);
    }
}
