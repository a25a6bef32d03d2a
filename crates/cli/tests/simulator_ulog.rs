//! The whole ULog path on a log of known physics: `learn simulate` writes a flight as PX4 logs it
//! (NED/FRD topics in a `.ulg`), `learn mismatch` reads it back through a layout description and
//! finds the concealed effect as it does from the same flight written as a Neural-Fly CSV.

mod common;

use std::path::{Path, PathBuf};

use common::{learn_in, scratch};
use serde_json::{Value, json};

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The concealed thrust scale `learn mismatch` found in `dir/name/mismatch.json`.
fn thrust_scale(dir: &Path, name: &str) -> f64 {
    let text = std::fs::read_to_string(dir.join(name).join("mismatch.json")).unwrap();
    let report: Value = serde_json::from_str(&text).unwrap();
    let effects = report["effects"].as_array().unwrap();
    assert_eq!(effects.len(), 1, "{}", report["effects"]);
    assert_eq!(effects[0]["id"], "thrust_scale");
    effects[0]["parameters"]["k"].as_f64().unwrap()
}

#[test]
fn a_simulated_ulog_is_analysed_through_its_layout_as_its_csv_is() {
    let dir = scratch("simulator-ulog");
    std::fs::copy(
        workspace().join("experiments/mismatch/vehicles/quad-a.json"),
        dir.join("quad.json"),
    )
    .unwrap();
    let text =
        std::fs::read_to_string(workspace().join("experiments/mismatch/configurations/d.json"))
            .unwrap();
    let mut scenario: Value = serde_json::from_str(&text).unwrap();
    scenario["model"] = json!("quad.json");
    scenario["duration_s"] = json!(16.0);
    scenario["effects"] = json!({"thrust_scale": {"k": 0.9}});
    std::fs::write(dir.join("s.json"), scenario.to_string()).unwrap();
    for out in ["flight.ulg", "flight.csv"] {
        let run = learn_in(&dir, &["simulate", "--scenario", "s.json", "--out", out]);
        run.success();
    }
    let layout = workspace().join("experiments/layouts/simulator-ulog.json");
    let layout = layout.display().to_string();
    let runs: [&[&str]; 2] = [
        &[
            "--recording",
            "flight.ulg",
            "--layout",
            &layout,
            "--out",
            "ulog",
        ],
        &["--recording", "flight.csv", "--out", "csv"],
    ];
    for args in runs {
        let mut all = vec!["mismatch", "--model", "quad.json", "--quiet"];
        all.extend(args);
        learn_in(&dir, &all).success();
    }
    let (from_ulog, from_csv) = (thrust_scale(&dir, "ulog"), thrust_scale(&dir, "csv"));
    assert!((from_ulog - 0.9).abs() < 0.01, "{from_ulog}");
    // The ULog holds single-precision values: the two reads agree to their rounding's effect.
    assert!(
        (from_ulog - from_csv).abs() < 1e-3,
        "{from_ulog} {from_csv}"
    );
}

/// A hexarotor's simulated ULog: its six `actuator_outputs` read through a layout that names six,
/// and the concealed thrust scale found from them.
#[test]
fn a_hexarotor_ulog_is_analysed_through_its_six_motor_outputs() {
    let dir = scratch("simulator-ulog-hexa");
    std::fs::copy(
        workspace().join("experiments/mismatch/vehicles/hexa-x.json"),
        dir.join("hexa.json"),
    )
    .unwrap();
    let text =
        std::fs::read_to_string(workspace().join("experiments/mismatch/configurations/g.json"))
            .unwrap();
    let mut scenario: Value = serde_json::from_str(&text).unwrap();
    scenario["model"] = json!("hexa.json");
    scenario["duration_s"] = json!(16.0);
    scenario["effects"] = json!({"thrust_scale": {"k": 0.9}});
    std::fs::write(dir.join("s.json"), scenario.to_string()).unwrap();
    learn_in(
        &dir,
        &["simulate", "--scenario", "s.json", "--out", "hexa.ulg"],
    )
    .success();
    let layout =
        std::fs::read_to_string(workspace().join("experiments/layouts/simulator-ulog.json"))
            .unwrap();
    let mut layout: Value = serde_json::from_str(&layout).unwrap();
    layout["motor_commands"] = json!(
        (0..6)
            .map(|i| format!("actuator_outputs.output[{i}]"))
            .collect::<Vec<_>>()
    );
    std::fs::write(dir.join("hexa-layout.json"), layout.to_string()).unwrap();
    let args = [
        "mismatch",
        "--model",
        "hexa.json",
        "--quiet",
        "--recording",
        "hexa.ulg",
        "--layout",
        "hexa-layout.json",
        "--out",
        "ulog",
    ];
    learn_in(&dir, &args).success();
    let k = thrust_scale(&dir, "ulog");
    assert!((k - 0.9).abs() < 0.01, "{k}");
}

/// A vehicle whose thrust map reads the battery voltage, simulated on a draining battery and
/// written as a ULog: the layout maps `battery_status.voltage_v`, and the concealed thrust scale
/// is found through the vehicle's map at the logged voltage.
#[test]
fn a_voltage_map_vehicle_ulog_is_analysed_through_its_logged_battery() {
    let dir = scratch("simulator-ulog-voltage");
    std::fs::copy(
        workspace().join("experiments/mismatch/vehicles/quad-voltage.json"),
        dir.join("quad.json"),
    )
    .unwrap();
    let text =
        std::fs::read_to_string(workspace().join("experiments/mismatch/configurations/h.json"))
            .unwrap();
    let mut scenario: Value = serde_json::from_str(&text).unwrap();
    scenario["model"] = json!("quad.json");
    scenario["duration_s"] = json!(16.0);
    scenario["effects"] = json!({"thrust_scale": {"k": 0.9}});
    std::fs::write(dir.join("s.json"), scenario.to_string()).unwrap();
    learn_in(
        &dir,
        &["simulate", "--scenario", "s.json", "--out", "v.ulg"],
    )
    .success();
    let layout =
        std::fs::read_to_string(workspace().join("experiments/layouts/simulator-ulog.json"))
            .unwrap();
    let mut layout: Value = serde_json::from_str(&layout).unwrap();
    layout["battery_voltage"] = json!("battery_status.voltage_v");
    std::fs::write(dir.join("v-layout.json"), layout.to_string()).unwrap();
    let args = [
        "mismatch",
        "--model",
        "quad.json",
        "--quiet",
        "--recording",
        "v.ulg",
        "--layout",
        "v-layout.json",
        "--out",
        "ulog",
    ];
    learn_in(&dir, &args).success();
    let k = thrust_scale(&dir, "ulog");
    assert!((k - 0.9).abs() < 0.01, "{k}");
}
