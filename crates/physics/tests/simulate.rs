//! Behaviour of the simulator: tracking, concealment by the closed loop, determinism, the log format.

mod common;

use physics::{Effects, Noise, NominalModel, Scenario, ThrustScale, Trajectory, simulate};

fn demo_model() -> NominalModel {
    NominalModel::load(&common::workspace().join("experiments/mismatch/demo-quad.json")).unwrap()
}

fn scenario(effects: Effects, seed: u64) -> Scenario {
    Scenario {
        model: "demo-quad.json".into(),
        duration_s: 6.0,
        warmup_s: 4.0,
        seed,
        physics_rate_hz: 500.0,
        log_rate_hz: 50.0,
        hover_throttle: 0.5,
        trajectory: Trajectory::Figure8 {
            center: [0.0, 0.0, 1.5],
            first: [1.5, 0.0, 0.0],
            second: [0.0, 0.8, 0.3],
            period_s: 6.0,
            low_passes: Vec::new(),
            yaw_amplitude_rad: 0.2,
            yaw_period_s: 10.0,
        },
        effects,
        noise: Noise {
            position_m: 0.002,
            velocity_m_s: 0.005,
            attitude_rad: 0.002,
            rate_rad_s: 0.008,
        },
        gains: Default::default(),
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
    let path = dir.join("nominal.csv");
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
