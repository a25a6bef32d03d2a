//! Class 11 (degenerate recordings and models reported as physics) and the mismatch half of class
//! 7 (its cost unbounded, no progress): through `learn simulate` and `learn mismatch`, each
//! reproduction of the probe is refused with one line naming the file and what is wrong, before any
//! analysis.

use std::path::Path;

use serde_json::{Value, json};

use crate::common::{Scratch, learn_in, scratch, workspace};

/// A scratch folder with the demo vehicle (`quad.json`), a scenario of configuration D flown with
/// `noise` (null: D's own) as `flight.json`, and the tool's model for its logs (`held.json`: commands held row to
/// row, as D's controller runs at the log rate).
fn setup(test: &str, noise: Value) -> Scratch {
    let dir = scratch(test);
    let vehicle = workspace().join("experiments/mismatch/vehicles/quad-a.json");
    std::fs::copy(&vehicle, dir.join("quad.json")).unwrap();
    let mut model: Value =
        serde_json::from_str(&std::fs::read_to_string(&vehicle).unwrap()).unwrap();
    model["logger"] = json!({"command": "held"});
    std::fs::write(dir.join("held.json"), model.to_string()).unwrap();
    let configuration = workspace().join("experiments/mismatch/configurations/d.json");
    let mut scenario: Value =
        serde_json::from_str(&std::fs::read_to_string(configuration).unwrap()).unwrap();
    scenario["model"] = json!("quad.json");
    if !noise.is_null() {
        scenario["noise"] = noise;
    }
    std::fs::write(dir.join("flight.json"), scenario.to_string()).unwrap();
    dir
}

fn no_noise() -> Value {
    json!({"position_m": 0.0, "velocity_m_s": 0.0, "attitude_rad": 0.0, "rate_rad_s": 0.0})
}

/// Configuration D's own noise.
fn demo_noise() -> Value {
    Value::Null
}

/// Simulates `flight.json` into `flight.csv`.
fn simulate(dir: &Path) {
    learn_in(
        dir,
        &[
            "simulate",
            "--scenario",
            "flight.json",
            "--out",
            "flight.csv",
        ],
    )
    .success();
}

/// `learn mismatch --recording RECORDING --model MODEL --out out` (plus `extra`).
fn mismatch(dir: &Path, recording: &str, model: &str, extra: &[&str]) -> crate::common::Run {
    let args = [
        &[
            "mismatch",
            "--recording",
            recording,
            "--model",
            model,
            "--out",
            "out",
        ],
        extra,
    ]
    .concat();
    learn_in(dir, &args)
}

/// Rewrites `flight.csv` as `name`, every row changed by `change`.
fn changed_flight(dir: &Path, name: &str, change: impl Fn(&mut data::FlightLog)) {
    let mut log = data::FlightLog::read(&dir.join("flight.csv")).unwrap();
    change(&mut log);
    log.write_csv(&dir.join(name)).unwrap();
}

/// A recording without noise of the exact nominal model used to give "unexplained residual on
/// vdot_x, 0.2–39.8 s" with gains near 1e11; now it is refused, and with noise the same flight is
/// analysed and explains nothing.
#[test]
fn a_recording_without_noise_is_refused() {
    let dir = setup("degenerate-noise-free", no_noise());
    simulate(&dir);
    let run = mismatch(&dir, "flight.csv", "held.json", &[]);
    run.one_line_error(&[
        "flight.csv: degenerate recording, no measurement noise on vdot_x",
        "simulated without noise?",
    ]);
    assert!(!dir.join("out/mismatch.json").exists());
    let dir = setup("degenerate-noisy", demo_noise());
    simulate(&dir);
    let output = mismatch(&dir, "flight.csv", "held.json", &[]);
    assert!(
        output.success().contains("effects: none"),
        "{}",
        output.stdout
    );
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("out/mismatch.json")).unwrap())
            .unwrap();
    assert_eq!(report["unexplained"], json!([]));
    // Off a terminal nothing is drawn: standard error stays empty.
    assert_eq!(output.stderr, "");
}

/// Identical rows gave gains of 2.7e22; a thrust setpoint of 0 on every row gave a linear drag and
/// a 183 m/s wind.
#[test]
fn constant_rows_and_zero_thrust_are_refused_naming_the_columns() {
    let dir = setup("degenerate-constant", demo_noise());
    simulate(&dir);
    changed_flight(&dir, "constant.csv", |log| {
        let first = log.clone();
        for k in 0..log.len() {
            log.position[k] = first.position[0];
            log.velocity[k] = first.velocity[0];
            log.quaternion[k] = first.quaternion[0];
            log.rotation[k] = first.rotation[0];
            log.body_rate[k] = first.body_rate[0];
            log.thrust_setpoint[k] = first.thrust_setpoint[0];
            log.motor_command
                .row_mut(k)
                .copy_from_slice(first.motor_command.row(0));
        }
    });
    let neural_fly = workspace().join("experiments/mismatch/neural-fly.json");
    let neural_fly = neural_fly.to_str().unwrap();
    for model in ["held.json", neural_fly] {
        mismatch(&dir, "constant.csv", model, &[]).one_line_error(&[
            "constant.csv: degenerate recording, no excitation",
            "v_x, v_y, v_z",
            "the same on every row",
        ]);
    }
    changed_flight(&dir, "unpowered.csv", |log| {
        log.thrust_setpoint.iter_mut().for_each(|t| *t = 0.0);
    });
    mismatch(&dir, "unpowered.csv", neural_fly, &[]).one_line_error(&[
        "unpowered.csv: degenerate recording, no thrust",
        "from T_sp",
        "cannot have flown",
    ]);
    assert!(!dir.join("out").exists());
}

/// `--flights` skipped a declared condition whose file was missing; now the first missing flight
/// is named, with its condition and controller.
#[test]
fn a_declared_flight_that_is_missing_is_an_error() {
    let dir = scratch("degenerate-flights");
    std::fs::copy(
        workspace().join("experiments/mismatch/neural-fly.json"),
        dir.join("quad.json"),
    )
    .unwrap();
    let conditions = workspace().join("experiments/conditions.json");
    let config: Value =
        serde_json::from_str(&std::fs::read_to_string(&conditions).unwrap()).unwrap();
    let experiment = dir.join("data/experiment");
    std::fs::create_dir_all(&experiment).unwrap();
    // Every flight but the NF controller's at 70wind (empty files: the check comes first).
    for condition in config["conditions"].as_array().unwrap() {
        for controller in config["controllers"].as_array().unwrap() {
            let (condition, controller) = (
                condition["name"].as_str().unwrap(),
                controller.as_str().unwrap(),
            );
            if (condition, controller) != ("70wind", "NF") {
                let name = format!("custom_figure8_{controller}_{condition}.csv");
                std::fs::write(experiment.join(name), "").unwrap();
            }
        }
    }
    let run = learn_in(
        &dir,
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
    );
    run.one_line_error(&[
        "conditions.json: the NF flight of condition '70wind' is missing",
        "data/experiment/custom_figure8_NF_70wind.csv",
        "1 of the 30 flights",
    ]);
    assert!(!dir.join("o").exists());
}

/// A nominal mass of 1e300 kg and a controller rate of 1e-9 Hz were accepted, and gravity 1e308
/// blamed the recording: each is refused when the model is read, by `mismatch` and by `simulate`.
#[test]
fn absurd_model_numbers_are_refused_naming_the_field() {
    let dir = setup("degenerate-model", demo_noise());
    let model: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("held.json")).unwrap()).unwrap();
    std::fs::write(dir.join("flight.csv"), "").unwrap();
    for (pointer, value, field) in [
        ("/mass_kg", json!(1e300), "'mass_kg'"),
        (
            "/logger/controller_rate_hz",
            json!(1e-9),
            "'logger.controller_rate_hz'",
        ),
        ("/gravity_m_s2", json!(1e308), "'gravity_m_s2'"),
        ("/inertia_kg_m2/1", json!(0.0), "'inertia_kg_m2[1]'"),
    ] {
        let mut changed = model.clone();
        if pointer.starts_with("/logger/") {
            changed["logger"] = json!({"command": "sample"});
        }
        let parent = pointer.rsplit_once('/').unwrap().0;
        let key = pointer.rsplit_once('/').unwrap().1;
        match changed.pointer_mut(parent).unwrap() {
            Value::Array(items) => items[key.parse::<usize>().unwrap()] = value,
            object => object[key] = value,
        }
        std::fs::write(dir.join("bad.json"), changed.to_string()).unwrap();
        mismatch(&dir, "flight.csv", "bad.json", &[]).one_line_error(&[
            "bad.json: field ",
            field,
            "must be between",
        ]);
        if pointer.starts_with("/logger/") {
            continue;
        }
        std::fs::write(dir.join("quad.json"), changed.to_string()).unwrap();
        let run = learn_in(
            &dir,
            &["simulate", "--scenario", "flight.json", "--out", "f.csv"],
        );
        run.one_line_error(&["quad.json: field ", field, "must be between"]);
        assert!(!dir.join("f.csv").exists());
    }
}

/// A recording longer than one analysis is analysed in consecutive parts (here parts of 1,500 rows
/// through `--part-rows`, so that the test stays short), each part listed and the effects pooled;
/// a part length out of its range is refused before any work.
#[test]
fn a_recording_longer_than_a_part_is_analysed_in_parts() {
    let dir = setup("degenerate-long", demo_noise());
    let mut scenario: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("flight.json")).unwrap()).unwrap();
    scenario["duration_s"] = json!(60.0);
    scenario["effects"] = json!({"linear_drag": {"d": [0.35, 0.35, 0.1]}});
    std::fs::write(dir.join("flight.json"), scenario.to_string()).unwrap();
    simulate(&dir);
    for bad in ["100", &(mismatch_bound() + 1).to_string()] {
        let start = std::time::Instant::now();
        mismatch(&dir, "flight.csv", "held.json", &["--part-rows", bad]).one_line_error(&[
            &format!("setting 'part_rows': {bad} rows per part; it must be from 1250"),
            &mismatch_bound().to_string(),
        ]);
        assert!(start.elapsed().as_secs_f64() < 30.0, "refused before work");
        assert!(!dir.join("out").exists());
    }
    let run = mismatch(
        &dir,
        "flight.csv",
        "held.json",
        &["--rows", "0:3000", "--part-rows", "1500"],
    );
    run.success();
    assert!(
        run.stdout
            .contains("3000 rows in 2 parts; effects: linear_drag (2 of 2 parts)"),
        "{}",
        run.stdout
    );
    let markdown = std::fs::read_to_string(dir.join("out/mismatch.md")).unwrap();
    assert!(markdown.contains("analysed in 2 consecutive parts of at most 1500 rows"));
    assert!(
        markdown.contains("| 2 | 1500:3000 | 30.0–60.0 | linear_drag |"),
        "{markdown}"
    );
    let report: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("out/mismatch.json")).unwrap())
            .unwrap();
    let d = &report["effects"][0]["parameters"][0]["numbers"];
    for (axis, truth) in [0.35, 0.35, 0.1].into_iter().enumerate() {
        let found = d[axis]["value"].as_f64().unwrap();
        assert!((found - truth).abs() < 0.1 * truth, "d[{axis}] = {found}");
    }
    assert_eq!(report["parts"][1]["rows"], json!([1500, 3000]));
    assert_eq!(
        report["parts"][1]["report"]["effects"][0]["id"],
        "linear_drag"
    );
    assert!(
        std::fs::read_to_string(dir.join("out/mismatch.svg"))
            .unwrap()
            .contains("linear_drag.d")
    );
    mismatch(
        &dir,
        "flight.csv",
        "held.json",
        &["--rows", "10:3005", "--force"],
    )
    .one_line_error(&["flight.csv: rows 10:3005 reach past its 3001 data rows"]);
}

/// The bound the refusal states, as the library has it.
fn mismatch_bound() -> usize {
    mismatch::recording::degenerate::MAX_ANALYSED_ROWS
}
