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
