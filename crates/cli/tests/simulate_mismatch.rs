//! `learn simulate` and `learn mismatch` on bad input: every scenario, model and demo manifest is
//! checked when it is read, and a bad one gives a one-line error naming the file and the field,
//! before any work (no panic, no abort, no hang, nothing written outside the output directories).

mod common;

use std::path::{Path, PathBuf};

use common::{Scratch, learn_in, scratch};
use serde_json::{Value, json};

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A scratch directory holding the demo model (`quad.json`) and the committed control scenario
/// (`control.json`) pointing at it.
fn setup(test: &str) -> Scratch {
    let dir = scratch(test);
    std::fs::copy(
        workspace().join("experiments/mismatch/vehicles/quad-a.json"),
        dir.join("quad.json"),
    )
    .unwrap();
    write_scenario(&dir, "control.json", |_| {});
    dir
}

/// Writes the control scenario, changed by `change`, as `name` in `dir`.
fn write_scenario(dir: &Path, name: &str, change: impl FnOnce(&mut Value)) {
    let text =
        std::fs::read_to_string(workspace().join("experiments/mismatch/configurations/d.json"))
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
        |s| s["trajectory"]["first"] = json!([500, 0, 0]),
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

/// Writes a demo manifest of one configuration (`d`, the control scenario) and one no-effect case
/// per name.
fn write_manifest(dir: &Path, names: &[&str]) {
    write_manifest_of(dir, &[("d", "control.json")], names);
}

/// Writes a demo manifest of the configurations (name, scenario file) and one no-effect case per
/// name.
fn write_manifest_of(dir: &Path, configurations: &[(&str, &str)], names: &[&str]) {
    let cases: Vec<Value> = names
        .iter()
        .map(|name| json!({"name": name, "effects": {}, "purpose": "test"}))
        .collect();
    let configurations: Vec<Value> = configurations
        .iter()
        .map(|(name, scenario)| json!({"name": name, "scenario": scenario, "description": "test"}))
        .collect();
    std::fs::write(
        dir.join("demo.json"),
        json!({ "configurations": configurations, "cases": cases }).to_string(),
    )
    .unwrap();
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
    write_manifest_of(
        &dir,
        &[("good", "control.json"), ("bad", "bad.json")],
        &["control"],
    );
    demo(&dir).one_line_error(&["bad.json", "gains.integral_limit"]);
    assert!(!dir.join("work").exists());
}

/// Effect ids are checked where a file is read: an unknown one (a typo) in a scenario's or a demo
/// case's effects is a one-line field error that lists the known ids, before any work. A demo's
/// `pairs` name cases, not effects: a name that is no case is refused too.
#[test]
fn an_unknown_effect_id_is_a_field_error_listing_the_known_ids() {
    let known = physics::EffectId::ALL.map(physics::EffectId::name);
    let dir = setup("effect-id-scenario");
    write_scenario(&dir, "s.json", |s| {
        s["effects"] = json!({"drag": {"c": 0.05}});
    });
    let run = learn_in(
        &dir,
        &["simulate", "--scenario", "s.json", "--out", "f.csv"],
    );
    let message =
        run.one_line_error(&[&["s.json: field 'effects.drag ", "`drag`"], &known[..]].concat());
    assert!(!message.contains("not valid JSON"), "{message}");
    assert!(!dir.join("f.csv").exists());

    let dir = setup("effect-id-demo");
    write_manifest(&dir, &["control"]);
    let mut manifest: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("demo.json")).unwrap()).unwrap();
    manifest["cases"][0]["effects"] = json!({"lineardrag": {"d": [0.1, 0.1, 0.1]}});
    std::fs::write(dir.join("demo.json"), manifest.to_string()).unwrap();
    demo(&dir).one_line_error(
        &[
            &["demo.json", "cases[0].effects.lineardrag", "`lineardrag`"],
            &known[..],
        ]
        .concat(),
    );
    manifest["cases"][0]["effects"] = json!({});
    manifest["pairs"] = json!(["control", "wind"]);
    std::fs::write(dir.join("demo.json"), manifest.to_string()).unwrap();
    demo(&dir).one_line_error(&["demo.json", "pairs[1]", "\"wind\" is not a case"]);
    assert!(!dir.join("work").exists() && !dir.join("out").exists());
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

/// The model a scenario names is read by `simulate` as much as the scenario: it is never the output,
/// even with `--force`, whatever the spelling of the path.
#[test]
fn simulate_never_writes_over_the_scenarios_model() {
    let dir = setup("sim-model-out");
    let model = std::fs::read_to_string(dir.join("quad.json")).unwrap();
    std::fs::create_dir(dir.join("sub")).unwrap();
    for out in ["quad.json", "./sub/../quad.json"] {
        let run = learn_in(
            &dir,
            &[
                "simulate",
                "--scenario",
                "control.json",
                "--out",
                out,
                "--force",
            ],
        );
        run.one_line_error(&[out, "model", "control.json", "even with --force"]);
    }
    assert_eq!(
        std::fs::read_to_string(dir.join("quad.json")).unwrap(),
        model
    );
}

/// Settings that would give a log the data tools refuse ("outside the plausible range") are
/// refused when the scenario is read, naming the field; a model that drives a logged column out
/// of range is refused before anything is written, naming the column and the model's settings.
#[test]
fn simulate_writes_only_logs_the_data_tools_read() {
    simulate_changed(
        "sim-center-huge",
        |s| s["trajectory"]["center"] = json!([1e300, 0, 1.5]),
        &["trajectory.center", "1e300 m"],
    );
    simulate_changed(
        "sim-center-high",
        |s| s["trajectory"]["center"] = json!([0, 0, 1e6]),
        &["trajectory.center"],
    );
    simulate_changed(
        "sim-throttle-tiny",
        |s| s["hover_throttle"] = json!(1e-300),
        &["hover_throttle", "1e-300"],
    );
    simulate_changed(
        "sim-noise-huge",
        |s| s["noise"]["rate_rad_s"] = json!(1e5),
        &["noise.rate_rad_s"],
    );
    let dir = setup("sim-pwm-scale");
    let mut model: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("quad.json")).unwrap()).unwrap();
    // Each within its range, but the commands near hover exceed the pwm column's 1e5.
    model["mixer"]["pwm_offset"] = json!(99_000.0);
    model["mixer"]["pwm_scale"] = json!(10_000.0);
    std::fs::write(dir.join("big.json"), model.to_string()).unwrap();
    write_scenario(&dir, "s.json", |s| s["model"] = json!("big.json"));
    let run = learn_in(
        &dir,
        &["simulate", "--scenario", "s.json", "--out", "f.csv"],
    );
    run.one_line_error(&["s.json", "pwm", "mixer.pwm_scale", "nothing written"]);
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name.contains("f.csv"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
    // A scenario near the position bound (975 m of 1000 m) at the lowest hover throttle gives a
    // log that `data inspect` and `mismatch` read.
    write_scenario(&dir, "edge.json", |s| {
        s["duration_s"] = json!(5.0);
        s["hover_throttle"] = json!(0.05);
        s["trajectory"]["center"] = json!([975, -975, 975]);
    });
    learn_in(
        &dir,
        &["simulate", "--scenario", "edge.json", "--out", "edge.csv"],
    )
    .success();
    learn_in(&dir, &["data", "inspect", "edge.csv"]).success();
}

/// A huge number in an error reads as a number, not as 309 digits.
#[test]
fn huge_values_are_named_readably() {
    let dir = setup("sim-dur-readable");
    write_scenario(&dir, "s.json", |s| s["duration_s"] = json!(1e308));
    let run = learn_in(
        &dir,
        &["simulate", "--scenario", "s.json", "--out", "f.csv"],
    );
    let message = run.one_line_error(&["s.json", "duration_s", "1e308"]);
    assert!(message.len() < 200, "{message}");
}

/// The demo writes files in `--work` (each case's recording and analysis): existing ones are user
/// files, replaced only with `--force`, and the refusal comes before any case runs.
#[test]
fn demo_does_not_replace_files_in_work_without_force() {
    let dir = setup("demo-work-notes");
    write_manifest(&dir, &["control"]);
    for name in ["mismatch.md", "recording.csv"] {
        let case = dir.join("work/w/d/control");
        let _ = std::fs::remove_dir_all(&case);
        std::fs::create_dir_all(&case).unwrap();
        std::fs::write(case.join(name), "notes").unwrap();
        demo(&dir).one_line_error(&[
            &format!("work/w/d/control/{name}"),
            "already exists",
            "--force",
        ]);
        assert_eq!(std::fs::read_to_string(case.join(name)).unwrap(), "notes");
        assert_eq!(std::fs::read_dir(&case).unwrap().count(), 1);
        assert!(!dir.join("out").exists());
    }
}

/// No file the demo writes (summaries in --out, case files in --work) may be one of the files it
/// reads (manifest, scenarios, the models they name), even with --force.
#[test]
fn demo_never_writes_over_its_inputs_even_with_force() {
    let dir = setup("demo-inputs");
    // the manifest inside the output directory, as one of the summaries
    std::fs::create_dir(dir.join("o")).unwrap();
    std::fs::copy(dir.join("quad.json"), dir.join("o/quad.json")).unwrap();
    write_scenario(&dir.join("o"), "control.json", |_| {});
    write_manifest(&dir.join("o"), &["control"]);
    std::fs::rename(dir.join("o/demo.json"), dir.join("o/summary.json")).unwrap();
    let manifest = std::fs::read_to_string(dir.join("o/summary.json")).unwrap();
    let run = learn_in(
        &dir,
        &[
            "mismatch",
            "--demo",
            "o/summary.json",
            "--work",
            "w",
            "--out",
            "o",
            "--force",
        ],
    );
    run.one_line_error(&["o/summary.json", "demo manifest", "even with --force"]);
    assert_eq!(
        std::fs::read_to_string(dir.join("o/summary.json")).unwrap(),
        manifest
    );
    // a scenario where a case writes its recording
    std::fs::create_dir_all(dir.join("w/d/control")).unwrap();
    write_scenario(&dir.join("w/d/control"), "recording.csv", |s| {
        s["model"] = json!("../../../quad.json");
    });
    write_manifest_of(&dir, &[("d", "w/d/control/recording.csv")], &["control"]);
    let run = learn_in(
        &dir,
        &[
            "mismatch",
            "--demo",
            "demo.json",
            "--work",
            "w",
            "--out",
            "out",
            "--force",
        ],
    );
    run.one_line_error(&[
        "w/d/control/recording.csv",
        "scenario of demo configuration \"d\"",
    ]);
    // the model a scenario names, as a summary
    write_scenario(&dir, "s.json", |s| s["model"] = json!("out/summary.md"));
    std::fs::create_dir(dir.join("out")).unwrap();
    std::fs::copy(dir.join("quad.json"), dir.join("out/summary.md")).unwrap();
    write_manifest_of(&dir, &[("d", "s.json")], &["control"]);
    let run = learn_in(
        &dir,
        &[
            "mismatch",
            "--demo",
            "demo.json",
            "--work",
            "w2",
            "--out",
            "out",
            "--force",
        ],
    );
    run.one_line_error(&["out/summary.md", "model of demo configuration \"d\""]);
    assert!(!dir.join("w2").exists());
}

/// With --recording, neither the recording nor the model may be an output, even with --force; an
/// output directory below a file is refused before the analysis.
#[test]
fn recording_outputs_are_checked_before_work() {
    let dir = setup("mm-recording-outputs");
    std::fs::create_dir(dir.join("out")).unwrap();
    std::fs::write(dir.join("out/mismatch.json"), "recording").unwrap();
    std::fs::copy(dir.join("quad.json"), dir.join("out/mismatch.md")).unwrap();
    for (recording, model, needle) in [
        ("out/mismatch.json", "quad.json", "--recording"),
        ("r.csv", "out/mismatch.md", "--model"),
    ] {
        let run = learn_in(
            &dir,
            &[
                "mismatch",
                "--recording",
                recording,
                "--model",
                model,
                "--out",
                "out",
                "--force",
            ],
        );
        run.one_line_error(&["out/mismatch.", needle, "even with --force"]);
    }
    assert_eq!(
        std::fs::read_to_string(dir.join("out/mismatch.json")).unwrap(),
        "recording"
    );
    // an output directory below a file: refused before the recording is even read
    let run = learn_in(
        &dir,
        &[
            "mismatch",
            "--recording",
            "absent.csv",
            "--model",
            "quad.json",
            "--out",
            "control.json/sub",
        ],
    );
    run.one_line_error(&["control.json/sub", "not a directory", "--out"]);
}

/// --work belongs to --demo: the other modes refuse it instead of ignoring it.
#[test]
fn work_is_refused_outside_the_demo() {
    let dir = setup("mm-work-flag");
    for mode in [["--recording", "r.csv"], ["--flights", "c.json"]] {
        let run = learn_in(
            &dir,
            &[
                "mismatch",
                mode[0],
                mode[1],
                "--model",
                "quad.json",
                "--out",
                "o",
                "--work",
                "zz",
            ],
        );
        run.one_line_usage_error(&[mode[0], "--work", "cannot be used with"]);
    }
    let run = learn_in(&dir, &["mismatch", "--out", "o"]);
    assert_eq!(run.code, Some(2), "{}", run.stderr);
}

/// A data directory for `--flights` in `dir/data` holding every controller's flights of
/// `conditions` (empty files: the checks under test come before any flight is read).
fn flights_dir(dir: &Path, conditions: &[&str]) -> PathBuf {
    let data = dir.join("data");
    std::fs::create_dir_all(data.join("experiment")).unwrap();
    for condition in conditions {
        for controller in ["baseline", "indi", "L1", "NF", "NF-C", "NF-T"] {
            std::fs::write(
                data.join(format!(
                    "experiment/custom_figure8_{controller}_{condition}.csv"
                )),
                "",
            )
            .unwrap();
        }
    }
    data
}

fn flights(dir: &Path, extra: &[&str]) -> common::Run {
    let conditions = workspace().join("experiments/conditions.json");
    learn_in(
        dir,
        &[
            &[
                "--data",
                "data",
                "mismatch",
                "--flights",
                conditions.to_str().unwrap(),
                "--model",
                "quad.json",
                "--out",
                "o",
            ],
            extra,
        ]
        .concat(),
    )
}

/// Every output of --flights (`<out>/<model stem>.{json,md,svg}`) is checked before the first
/// flight is read.
#[test]
fn flights_check_every_output_before_work() {
    let dir = setup("mm-flights-outputs");
    flights_dir(
        &dir,
        &["nowind", "35wind", "70p20sint", "70wind", "100wind"],
    );
    std::fs::create_dir_all(dir.join("o")).unwrap();
    std::fs::write(dir.join("o/quad.svg"), "mine").unwrap();
    flights(&dir, &[]).one_line_error(&["o/quad.svg", "already exists"]);
    assert_eq!(
        std::fs::read_to_string(dir.join("o/quad.svg")).unwrap(),
        "mine"
    );
    assert!(!dir.join("o/quad.md").exists());
    // an output that is a directory
    std::fs::remove_file(dir.join("o/quad.svg")).unwrap();
    std::fs::create_dir(dir.join("o/quad.md")).unwrap();
    flights(&dir, &["--force"]).one_line_error(&["o/quad.md", "directory"]);
    std::fs::remove_dir(dir.join("o/quad.md")).unwrap();
    // the model and the conditions file are inputs, even with --force
    std::fs::copy(dir.join("quad.json"), dir.join("o/quad.json")).unwrap();
    let conditions = workspace().join("experiments/conditions.json");
    let run = learn_in(
        &dir,
        &[
            "--data",
            "data",
            "mismatch",
            "--flights",
            conditions.to_str().unwrap(),
            "--model",
            "o/quad.json",
            "--out",
            "o",
            "--force",
        ],
    );
    run.one_line_error(&["o/quad.json", "--model", "even with --force"]);
    std::fs::copy(&conditions, dir.join("o/quad.md")).unwrap();
    let run = learn_in(
        &dir,
        &[
            "--data",
            "data",
            "mismatch",
            "--flights",
            "o/quad.md",
            "--model",
            "quad.json",
            "--out",
            "o",
            "--force",
        ],
    );
    run.one_line_error(&["o/quad.md", "conditions file", "even with --force"]);
}

/// No flight at all in the data directory is an error naming it; a declared flight that is
/// missing (the calm ones here) is an error naming its condition and file.
#[test]
fn flights_need_a_flight_and_a_calm_one() {
    let dir = setup("mm-flights-none");
    flights_dir(&dir, &[]);
    flights(&dir, &[]).one_line_error(&["data", "none of the 30 flights"]);
    assert!(!dir.join("o").exists());
    flights_dir(&dir, &["35wind", "70p20sint", "70wind", "100wind"]);
    flights(&dir, &[]).one_line_error(&[
        "conditions.json",
        "the baseline flight of condition 'nowind' is missing",
        "custom_figure8_baseline_nowind.csv",
        "6 of the 30",
    ]);
    assert!(!dir.join("o").exists());
}

/// `--flights` names the files it wrote by their final paths (the run writes them in a staging
/// folder first); two short simulated flights, one in still air and one in wind.
#[test]
fn flights_name_the_files_they_wrote_by_their_final_paths() {
    let dir = setup("mm-flights-wrote");
    std::fs::create_dir_all(dir.join("data/experiment")).unwrap();
    for (condition, effects) in [
        ("still", json!({"linear_drag": {"d": [0.3, 0.3, 0.1]}})),
        (
            "breeze",
            json!({"linear_drag": {"d": [0.3, 0.3, 0.1]}, "wind": {"w_air": [-3.0, 0.0, 0.0]}}),
        ),
    ] {
        write_scenario(&dir, "s.json", |s| {
            s["duration_s"] = json!(16.0);
            s["effects"] = effects;
        });
        let out = format!("data/experiment/flight_only_{condition}.csv");
        learn_in(&dir, &["simulate", "--scenario", "s.json", "--out", &out]).success();
    }
    let conditions = json!({
        "file_pattern": "experiment/flight_{controller}_{condition}.csv",
        "controllers": ["only"],
        "evaluation_controller": "only",
        "conditions": [
            {"name": "still", "wind_speed": "0 m/s", "calm": true, "role": "meta-training"},
            {"name": "breeze", "wind_speed": "3 m/s", "mean_wind_m_s": 3.0, "role": "evaluation"}
        ],
        "paper_training": {"file_pattern": "training/flight_{condition}.csv",
            "conditions": [{"name": "still", "wind_speed": "0 m/s", "role": "meta-training"}]}
    });
    std::fs::write(dir.join("c.json"), conditions.to_string()).unwrap();
    let run = learn_in(
        &dir,
        &[
            "--data",
            "data",
            "mismatch",
            "--flights",
            "c.json",
            "--model",
            "quad.json",
            "--out",
            "o",
            "--quiet",
        ],
    );
    let printed = run.success();
    for ext in ["json", "md", "svg"] {
        assert!(
            printed.contains(&format!("wrote o/quad.{ext}")),
            "{printed}"
        );
        assert!(dir.join(format!("o/quad.{ext}")).exists());
    }
    assert!(!printed.contains(".learn-staging"), "{printed}");
}
