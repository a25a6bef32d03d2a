//! Behaviour of the simulator: tracking, concealment by the closed loop, determinism, the log format.

mod common;

use physics::{Effects, NominalModel, Scenario, ThrustScale, simulate};

fn demo_model() -> NominalModel {
    NominalModel::load(&common::workspace().join("experiments/mismatch/vehicles/quad-a.json"))
        .unwrap()
}

fn scenario(effects: Effects, seed: u64) -> Scenario {
    Scenario {
        effects,
        ..Scenario::figure_eight("quad-a.json", seed)
    }
}

fn max_tracking_error(log: &data::FlightLog) -> f64 {
    let desired = log.position_desired.as_ref().unwrap();
    log.position
        .iter()
        .zip(desired)
        .map(|(p, d)| {
            ((p[0] - d[0]).powi(2) + (p[1] - d[1]).powi(2) + (p[2] - d[2]).powi(2)).sqrt()
        })
        .fold(0.0, f64::max)
}

#[test]
fn tracks_the_figure8_and_writes_a_readable_body_rate_log() {
    let model = demo_model();
    let log = simulate(&model, &scenario(Effects::default(), 1), "nominal").unwrap();
    assert_eq!(log.len(), 301);
    assert!(
        max_tracking_error(&log) < 0.05,
        "{}",
        max_tracking_error(&log)
    );
    let dir = common::temp_dir("roundtrip");
    let path = dir.path().join("nominal.csv");
    log.write_csv(&path).unwrap();
    let back = data::FlightLog::read(&path).unwrap();
    assert_eq!(back.position, log.position);
    assert_eq!(back.motor_command, log.motor_command);
    // The simulator records the body rate, and the frame check agrees.
    assert_eq!(back.rate_frame().0, data::RateFrame::Body);
}

#[test]
fn the_closed_loop_conceals_a_thrust_loss_and_runs_are_deterministic() {
    let model = demo_model();
    let effects = Effects {
        thrust_scale: Some(ThrustScale { k: 0.85 }),
        ..Effects::default()
    };
    let a = simulate(&model, &scenario(effects, 7), "weak").unwrap();
    let b = simulate(&model, &scenario(effects, 7), "weak").unwrap();
    assert_eq!(a.position, b.position);
    assert!(max_tracking_error(&a) < 0.15, "{}", max_tracking_error(&a));
    // The effect shows in the control effort: more thrust than the nominal hover needs.
    let nominal = simulate(&model, &scenario(Effects::default(), 7), "nominal").unwrap();
    let mean = |log: &data::FlightLog| log.thrust_setpoint.iter().sum::<f64>() / log.len() as f64;
    assert!(
        mean(&a) > 1.1 * mean(&nominal),
        "{} vs {}",
        mean(&a),
        mean(&nominal)
    );
}

/// A scenario at the edges of what a scenario may ask for (a figure-8 whose reference reaches the
/// position bound, the smallest hover throttle, the largest position noise) still gives
/// a log the data tools read: the scenario's bounds keep the simulated values inside the data
/// crate's plausible ranges.
/// (Larger noise of the other measurements may make this closed loop diverge, an error of its own.)
#[test]
fn a_scenario_at_its_bounds_gives_a_log_the_data_tools_accept() {
    let model = demo_model();
    let edge = physics::MAX_POSITION_M;
    let figure_eight = Scenario::figure_eight("quad-a.json", 3);
    let mut scenario = Scenario {
        hover_throttle: physics::MIN_HOVER_THROTTLE,
        noise: physics::Noise {
            position_m: physics::MAX_NOISE.position_m,
            ..figure_eight.noise
        },
        ..figure_eight
    };
    // The figure-8 moved so that each axis reaches the bound: its center one amplitude inside.
    let physics::Trajectory::Figure8 {
        center,
        first,
        second,
        ..
    } = &mut scenario.trajectory
    else {
        panic!("Scenario::figure_eight flies a figure-8");
    };
    *center = [edge - first[0], -(edge - second[1]), edge - second[2]];
    scenario
        .validate_with_model(&model, std::path::Path::new("edge.json"))
        .unwrap();
    let log = simulate(&model, &scenario, "edge").unwrap();
    let dir = common::temp_dir("edge");
    let path = dir.path().join("edge.csv");
    physics::write_readable(&log, &path, std::path::Path::new("edge.json")).unwrap();
    let back = data::FlightLog::read(&path).unwrap();
    assert_eq!(back.len(), log.len());
    // The reference comes within centimetres of the bound (the centre is one amplitude inside it).
    let farthest = back
        .position_desired
        .unwrap()
        .iter()
        .flatten()
        .fold(0.0_f64, |far, x| far.max(x.abs()));
    assert!(
        farthest <= physics::MAX_POSITION_M && farthest > physics::MAX_POSITION_M - 0.05,
        "{farthest}"
    );
}

/// A flight logged as a real logger logs it (jittered, with drops and a gap) is written: the
/// writer reads it back with any spacing, though a reader of uniform samples refuses it.
#[test]
fn a_jittered_log_with_drops_and_a_gap_is_written() {
    let scenario = Scenario {
        duration_s: 12.0,
        controller_rate_hz: Some(500.0),
        log_timing: Some(physics::LogTiming {
            jitter_s: 0.006,
            dropped_fraction: 0.1,
            gaps: vec![[4.0, 0.5]],
        }),
        ..scenario(Effects::default(), 5)
    };
    scenario
        .validate(std::path::Path::new("timed.json"))
        .unwrap();
    let log = simulate(&demo_model(), &scenario, "timed").unwrap();
    let dir = common::temp_dir("timed");
    let path = dir.path().join("timed.csv");
    physics::write_readable(&log, &path, std::path::Path::new("timed.json")).unwrap();
    let back = data::FlightLog::read_spaced(&path, data::Spacing::Any).unwrap();
    assert_eq!(back.time, log.time);
    assert_eq!(back.motor_command, log.motor_command);
    let message = data::FlightLog::read(&path).unwrap_err().to_string();
    assert!(
        message.contains("sample interval is not uniform"),
        "{message}"
    );
}

/// `log_timing` is read from a scenario file with the other fields, each error naming its field;
/// a scenario without one is written as before (no `log_timing` key).
#[test]
fn a_scenario_file_names_its_log_timing() {
    let base = serde_json::to_value(Scenario::figure_eight("quad-a.json", 1)).unwrap();
    assert!(base.get("log_timing").is_none(), "{base}");
    let with = |timing: serde_json::Value| {
        let mut value = base.clone();
        value["controller_rate_hz"] = 500.0.into();
        value["log_timing"] = timing;
        bounded_read::json::from_str::<Scenario>(&value.to_string())
    };
    let scenario = with(serde_json::json!({"jitter_s": 0.004, "gaps": [[1.0, 0.5]]})).unwrap();
    assert_eq!(
        scenario.log_timing,
        Some(physics::LogTiming {
            jitter_s: 0.004,
            dropped_fraction: 0.0,
            gaps: vec![[1.0, 0.5]],
        })
    );
    scenario.validate(std::path::Path::new("s.json")).unwrap();
    let error = with(serde_json::json!({"jitter": 0.004})).unwrap_err();
    assert!(error.field.starts_with("log_timing"), "{error:?}");
    assert!(error.message.contains("jitter"), "{error:?}");
}
