//! The whole ULog path on a log of known physics: `learn simulate` writes a flight as PX4 logs it
//! (NED/FRD topics in a `.ulg`), `learn mismatch` reads it back through a layout description and
//! finds the concealed effect as it does from the same flight written as a Neural-Fly CSV; for a
//! quadrotor, a hexarotor's six motor outputs and a vehicle whose thrust map reads the logged
//! battery voltage.

mod common;

use std::path::{Path, PathBuf};

use common::{Scratch, learn_in, scratch};
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

/// A scratch folder holding `model.json` (a model of `experiments/mismatch/vehicles/`) and the
/// flight `flight.EXT` for each extension in `outputs`: 16 s of a configuration of
/// `experiments/mismatch/configurations/` with a concealed thrust scale of 0.9.
fn concealed_thrust_loss(
    test: &str,
    model: &str,
    configuration: &str,
    outputs: &[&str],
) -> Scratch {
    let dir = scratch(test);
    let mismatch = workspace().join("experiments/mismatch");
    std::fs::copy(
        mismatch.join("vehicles").join(model),
        dir.join("model.json"),
    )
    .unwrap();
    let text =
        std::fs::read_to_string(mismatch.join("configurations").join(configuration)).unwrap();
    let mut scenario: Value = serde_json::from_str(&text).unwrap();
    scenario["model"] = json!("model.json");
    scenario["duration_s"] = json!(16.0);
    scenario["effects"] = json!({"thrust_scale": {"k": 0.9}});
    std::fs::write(dir.join("s.json"), scenario.to_string()).unwrap();
    for extension in outputs {
        let out = format!("flight.{extension}");
        learn_in(&dir, &["simulate", "--scenario", "s.json", "--out", &out]).success();
    }
    dir
}

/// `learn mismatch` of `dir/flight.ulg` through the simulator's ULog layout, changed by `edit`,
/// into `dir/ulog`; returns the thrust scale found.
fn thrust_scale_through_layout(dir: &Path, edit: impl FnOnce(&mut Value)) -> f64 {
    let path = workspace().join("experiments/layouts/simulator-ulog.json");
    let mut layout: Value = serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    edit(&mut layout);
    std::fs::write(dir.join("layout.json"), layout.to_string()).unwrap();
    thrust_scale_of(dir, &["flight.ulg", "--layout", "layout.json"], "ulog")
}

/// `learn mismatch --recording RECORDING...` with `dir/model.json` into `dir/out`; returns the
/// thrust scale found.
fn thrust_scale_of(dir: &Path, recording: &[&str], out: &str) -> f64 {
    let mut args = vec![
        "mismatch",
        "--model",
        "model.json",
        "--quiet",
        "--recording",
    ];
    args.extend(recording);
    args.extend(["--out", out]);
    learn_in(dir, &args).success();
    thrust_scale(dir, out)
}

#[test]
fn a_simulated_ulog_is_analysed_through_its_layout_as_its_csv_is() {
    let dir = concealed_thrust_loss("simulator-ulog", "quad-a.json", "d.json", &["ulg", "csv"]);
    let from_ulog = thrust_scale_through_layout(&dir, |_| {});
    let from_csv = thrust_scale_of(&dir, &["flight.csv"], "csv");
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
    let dir = concealed_thrust_loss("simulator-ulog-hexa", "hexa-x.json", "g.json", &["ulg"]);
    let k = thrust_scale_through_layout(&dir, |layout| {
        let outputs: Vec<String> = (0..6)
            .map(|i| format!("actuator_outputs.output[{i}]"))
            .collect();
        layout["motor_commands"] = json!(outputs);
    });
    assert!((k - 0.9).abs() < 0.01, "{k}");
}

/// A vehicle whose thrust map reads the battery voltage, simulated on a draining battery and
/// written as a ULog: the layout maps `battery_status.voltage_v`, and the concealed thrust scale
/// is found through the vehicle's map at the logged voltage.
#[test]
fn a_voltage_map_vehicle_ulog_is_analysed_through_its_logged_battery() {
    let dir = concealed_thrust_loss(
        "simulator-ulog-voltage",
        "quad-voltage.json",
        "h.json",
        &["ulg"],
    );
    let k = thrust_scale_through_layout(&dir, |layout| {
        layout["battery_voltage"] = json!("battery_status.voltage_v");
    });
    assert!((k - 0.9).abs() < 0.01, "{k}");
}
