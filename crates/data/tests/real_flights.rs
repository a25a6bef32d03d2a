//! The 30 public Neural-Fly figure-8 flights load, with the documented facts.

mod common;

use data::{ExperimentConditions, FlightLog, RateFrame};

#[test]
fn all_thirty_shared_flights_load() {
    let Some(dir) = common::real_data_dir() else {
        return;
    };
    let config = ExperimentConditions::load(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../experiments/conditions.json"),
    )
    .unwrap();
    let files: Vec<_> = config
        .flight_files(&dir)
        .into_iter()
        .filter(|f| f.controller != "paper-training")
        .collect();
    assert_eq!(files.len(), 30);
    for file in files {
        assert!(file.present, "{} missing", file.path.display());
        let log = FlightLog::read(&file.path).unwrap();
        // Measured on the shared copy: 2505 (NF nowind) to 2514 (baseline 100wind) rows.
        assert!(
            (2505..=2514).contains(&log.len()),
            "{}: {}",
            file.path.display(),
            log.len()
        );
        assert!((log.sample_interval() - 0.02).abs() < 1e-4);
        assert_eq!(log.meta.as_ref().unwrap().condition, file.condition);
        assert!(log.residual_force.is_some() && log.attitude_setpoint.is_some());
    }
}

#[test]
fn known_values_of_one_row() {
    let Some(dir) = common::real_data_dir() else {
        return;
    };
    let log = FlightLog::read(&dir.join("experiment/custom_figure8_L1_100wind.csv")).unwrap();
    assert_eq!(log.len(), 2511);
    assert_eq!(log.time[0], 0.0);
    assert_eq!(log.time[1], 0.020007968127487175);
    assert_eq!(
        log.position[0],
        [
            -1.4686956022615438,
            -0.08878635925913493,
            1.8793619899200615
        ]
    );
    assert_eq!(log.quaternion[0][3], -0.9715547909044133);
    assert_eq!(
        log.rotation[0][2],
        [
            -0.45986562646558715,
            -0.011335556571867123,
            0.8879162445709627
        ]
    );
    assert_eq!(log.thrust_setpoint[0], 0.6249672087747932);
    assert_eq!(log.hover_throttle[0], 0.46920177902800003);
    assert_eq!(
        log.motor_command.row(0),
        [
            1132.8906071381034,
            1247.0587696335963,
            1133.4350315912113,
            1251.6668925673055
        ]
    );
    assert_eq!(
        log.residual_force.as_ref().unwrap()[0],
        [-15.881234222213582, -0.5969980222922529, -4.738452643400084]
    );
    let baseline =
        FlightLog::read(&dir.join("experiment/custom_figure8_baseline_100wind.csv")).unwrap();
    assert_eq!(baseline.len(), 2514);
}

#[test]
fn recorded_rate_matches_the_world_frame() {
    let Some(dir) = common::real_data_dir() else {
        return;
    };
    let log = FlightLog::read(&dir.join("experiment/custom_figure8_baseline_35wind.csv")).unwrap();
    let (frame, body, world) = log.rate_frame();
    assert_eq!(frame, RateFrame::World, "body {body} world {world}");
}
