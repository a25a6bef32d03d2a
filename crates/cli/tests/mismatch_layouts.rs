//! `learn mismatch --layout`: recordings of other loggers (the public Crazyflie flight and PX4 logs)
//! through the layouts and models in `experiments/`, their time stamps as logged, with what each
//! log allows; bad layouts and models refused with one line naming the file and field.

mod common;

use common::{learn_in, scratch, workspace};

fn root(path: &str) -> String {
    workspace().join(path).display().to_string()
}

/// `learn mismatch` on `log` through a layout and model of `experiments/`, into `dir/out`, quiet,
/// with `extra` arguments.
fn learn_through_layout(
    log: &std::path::Path,
    (layout, model): (&str, &str),
    dir: &std::path::Path,
    extra: &[&str],
) -> common::Run {
    let mut args = vec![
        "mismatch".to_string(),
        "--recording".into(),
        log.display().to_string(),
        "--layout".into(),
        root(layout),
        "--model".into(),
        root(model),
        "--out".into(),
        dir.join("out").display().to_string(),
        "--quiet".into(),
    ];
    args.extend(extra.iter().map(|s| s.to_string()));
    learn_in(dir, &args.iter().map(String::as_str).collect::<Vec<_>>())
}

/// The report `learn mismatch` wrote in `dir/out`.
fn report_in(dir: &std::path::Path) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("out/mismatch.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// Seven seconds of the Crazyflie flight near the floor: read with its layout, compared on its
/// jittering stamps with a model built from its vehicle description (voltage-dependent thrust).
#[test]
fn the_crazyflie_flight_is_analysed_through_its_layout() {
    let Some(flight) =
        data::shared_file_for_tests(&workspace(), "crazyflie", "randomwalk_l_cf102_01.csv")
    else {
        return;
    };
    let dir = scratch("crazyflie");
    let files = (
        "experiments/layouts/crazyflie-neural-swarm.json",
        "experiments/mismatch/vehicles/crazyflie-parrot.json",
    );
    learn_through_layout(&flight, files, &dir, &["--rows", "0:700"]).success();
    let report = report_in(&dir);
    let stamps = &report["time_stamps"];
    let median = stamps["median_interval_s"].as_f64().unwrap();
    assert!((0.0095..0.0105).contains(&median), "{stamps}");
    assert_eq!(report["channels"].as_array().unwrap().len(), 3);
    let text = std::fs::read_to_string(dir.join("out/mismatch.md")).unwrap();
    assert!(
        text.contains("`compared_channels` is \"translational\""),
        "{text}"
    );
    assert!(
        text.contains("The time stamps are not evenly spaced"),
        "{text}"
    );
}

/// The PX4 log's positions come at ~10 Hz: the default ±0.2 s window is refused with what to do.
#[test]
fn a_slow_ulog_needs_a_wider_window() {
    let Some(log) = data::ulog_file_for_tests(&workspace(), "sample_px4_events.ulg") else {
        return;
    };
    let dir = scratch("slow-ulog");
    let files = (
        "experiments/layouts/px4-ulog.json",
        "experiments/mismatch/vehicles/jmavsim-iris.json",
    );
    let refused = learn_through_layout(&log, files, &dir, &[]);
    refused.one_line_error(&["sample_px4_events.ulg", "±0.2 s", "it needs 3"]);
    // The rows in the air: the climb starts at 18.9 s and the wheels touch at 25.9 s.
    let window = ["--half-width", "0.4", "--rows", "186:262"];
    learn_through_layout(&log, files, &dir, &window).success();
    let report = report_in(&dir);
    // Times since the log's start, as `learn data inspect` counts them (airborne 16.7–28.1 s).
    let start = report["fit"]["t_start"].as_f64().unwrap();
    assert!((15.0..20.0).contains(&start), "{start}");
    // What the log allows: motor commands held over two rows put timing under ~0.2 s out of
    // reach; torques computed from them say nothing about the body rate, so only the
    // translational channels are compared; jMAVSim has no wind, and none is named.
    let limit = report["log_content"]["timing_limit_s"].as_f64().unwrap();
    assert!((0.15..0.25).contains(&limit), "{limit}");
    assert!(report["uninformative_torques"].is_object(), "{report}");
    assert_eq!(report["channels"].as_array().unwrap().len(), 3);
    let named: Vec<&str> = report["effects"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["id"].as_str().unwrap())
        .collect();
    assert!(!named.contains(&"wind"), "{named:?}");
    assert_every_kept_candidate_is_accounted_for(&report);
    // In the air the nominal thrust (jMAVSim's 4 N per unit command) holds: the vertical residual
    // is a few noise floors (2.3 m/s² RMS with the rows on the ground, which holds the vehicle).
    let vertical = report["channels"][2]["residual_rms"].as_f64().unwrap();
    assert!(vertical < 0.2, "{vertical}");
}

/// Every candidate the screen kept is in the report's account of it: named, not separable,
/// replaced by a stand-in, dropped by the evidence rule or shorter than the log resolves (the
/// timing term may also resolve to no timing at all).
fn assert_every_kept_candidate_is_accounted_for(report: &serde_json::Value) {
    let ids = |list: &serde_json::Value| -> Vec<String> {
        list.as_array()
            .map(|items| {
                items
                    .iter()
                    .map(|e| e["id"].as_str().unwrap().to_string())
                    .collect()
            })
            .unwrap_or_default()
    };
    let selection = &report["selection"];
    let mut accounted = ids(&report["effects"]);
    accounted.extend(ids(&report["not_separable"]));
    accounted.extend(ids(&selection["replaced"]));
    accounted.extend(ids(&selection["dropped"]));
    accounted.extend(ids(&selection["below_resolution"]));
    for candidate in selection["candidates"].as_array().unwrap() {
        let id = candidate["id"].as_str().unwrap();
        if candidate["kept"].as_bool().unwrap() && id != "delay_or_motor_lag" {
            assert!(
                accounted.iter().any(|a| a == id),
                "{id} kept but not reported: {accounted:?}"
            );
        }
    }
}

/// A real flight of a vehicle whose rotors and mass are not known, compared through its thrust
/// setpoint and PX4's hover-thrust estimate: the estimate's NaN after landing is named unless the
/// rows stop before it; on the rows in the air a large residual remains and nothing the
/// vocabulary holds explains it on the held-out part, so nothing is named.
#[test]
fn an_unknown_vehicle_is_compared_through_its_thrust_setpoint() {
    let Some(log) = data::ulog_file_for_tests(&workspace(), "quadrotor_local.ulg") else {
        return;
    };
    let dir = scratch("thrust-setpoint");
    let files = (
        "experiments/layouts/px4-ulog-thrust-setpoint.json",
        "experiments/mismatch/vehicles/px4-thrust-setpoint.json",
    );
    let refused = learn_through_layout(&log, files, &dir, &["--half-width", "0.4"]);
    refused.one_line_error(&[
        "quadrotor_local.ulg",
        "hover_thrust_estimate.hover_thrust",
        "NaN",
    ]);
    let window = ["--half-width", "0.4", "--rows", "0:720"];
    learn_through_layout(&log, files, &dir, &window).success();
    let report = report_in(&dir);
    assert_eq!(report["channels"].as_array().unwrap().len(), 3);
    assert!(report["channels"][0]["significant"].as_bool().unwrap());
    assert_eq!(
        report["effects"].as_array().unwrap().len(),
        0,
        "{}",
        report["effects"]
    );
}

#[test]
fn a_bad_layout_or_vehicle_model_is_named() {
    let dir = scratch("bad-layout");
    std::fs::write(dir.join("flight.csv"), "t,x\n0,1\n").unwrap();
    std::fs::write(
        dir.join("layout.json"),
        r#"{"time": {"column": "t", "unit": "fortnights"}}"#,
    )
    .unwrap();
    let run = learn_in(
        &dir,
        &[
            "mismatch",
            "--recording",
            "flight.csv",
            "--layout",
            "layout.json",
            "--model",
            &root("experiments/mismatch/vehicles/crazyflie-parrot.json"),
            "--out",
            "out",
        ],
    );
    run.one_line_error(&["layout.json", "fortnights"]);
    std::fs::write(
        dir.join("model.json"),
        r#"{"mass_kg": 1.0, "gravity_m_s2": 9.81, "inertia_kg_m2": [0.01, 0.01, 0.02],
            "thrust_source": "mixer", "vehicle": "tri.json"}"#,
    )
    .unwrap();
    // Three of a hexarotor's rotors: no yaw torque of their own (allocation rank 3).
    let hexa =
        std::fs::read_to_string(workspace().join("experiments/vehicles/hexa-plus.json")).unwrap();
    let mut three: serde_json::Value = serde_json::from_str(&hexa).unwrap();
    three["rotors"].as_array_mut().unwrap().truncate(3);
    std::fs::write(dir.join("tri.json"), three.to_string()).unwrap();
    let run = learn_in(
        &dir,
        &[
            "mismatch",
            "--recording",
            "flight.csv",
            "--model",
            "model.json",
            "--out",
            "out",
        ],
    );
    run.one_line_error(&["model.json", "vehicle", "3 rotors and rank 3"]);
    let Some(flight) =
        data::shared_file_for_tests(&workspace(), "crazyflie", "randomwalk_l_cf102_01.csv")
    else {
        return;
    };
    let run = learn_in(
        &dir,
        &[
            "mismatch",
            "--recording",
            &flight.display().to_string(),
            "--layout",
            &root("experiments/layouts/crazyflie-neural-swarm.json"),
            "--model",
            &root("experiments/mismatch/neural-fly.json"),
            "--out",
            "out",
        ],
    );
    run.one_line_error(&["randomwalk_l_cf102_01.csv", "T_sp", "no thrust setpoint"]);
}

/// The Crazyflie flight saved as Parquet (its columns as doubles) is analysed as its CSV is,
/// through the same layout without the CSV's header prefix.
#[test]
fn a_parquet_recording_is_analysed_as_its_csv() {
    let Some(flight) =
        data::shared_file_for_tests(&workspace(), "crazyflie", "randomwalk_l_cf102_01.csv")
    else {
        return;
    };
    let dir = scratch("crazyflie-parquet");
    let text = std::fs::read_to_string(&flight).unwrap();
    let header = text.lines().next().unwrap().trim_start_matches("# ");
    let names: Vec<&str> = header.split(',').collect();
    let table = data::NumericTable::read_after_header_prefix(&flight, "# ", &names).unwrap();
    let parquet = dir.join("flight.parquet");
    data::write_numeric_parquet(&parquet, &table.names, &table.columns).unwrap();
    let layout = "experiments/layouts/crazyflie-neural-swarm.json";
    let mut fields: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(root(layout)).unwrap()).unwrap();
    fields.as_object_mut().unwrap().remove("header_prefix");
    let parquet_layout = dir.join("layout.json");
    std::fs::write(&parquet_layout, fields.to_string()).unwrap();
    let model = "experiments/mismatch/vehicles/crazyflie-parrot.json";
    let rows = ["--rows", "0:700"];
    learn_through_layout(&flight, (layout, model), &dir, &rows).success();
    let from_csv = report_in(&dir);
    // An absolute layout path is kept as it is by `root`.
    let files = (parquet_layout.to_str().unwrap(), model);
    learn_through_layout(&parquet, files, &dir, &["--rows", "0:700", "--force"]).success();
    let from_parquet = report_in(&dir);
    for field in ["time_stamps", "channels", "effects", "fit"] {
        assert_eq!(from_parquet[field], from_csv[field], "{field}");
    }
    // The CSV layout's header prefix is refused for a Parquet file, by name.
    let refused = learn_through_layout(&parquet, (layout, model), &dir, &["--force"]);
    refused.one_line_error(&["flight.parquet", "header_prefix", "no header line"]);
    // Without a layout, the Neural-Fly layout's CSV text is expected: the error says what to do.
    let args = [
        "mismatch",
        "--recording",
        "flight.parquet",
        "--model",
        &root(model),
    ];
    let bare = learn_in(&dir, &[&args[..], &["--out", "bare", "--quiet"]].concat());
    bare.one_line_error(&["flight.parquet", "read by column name", "--layout"]);
}
