//! Degenerate recordings are refused, never reported as physics (issue 31, class 11): a recording
//! without measurement noise of the exact nominal model, a constant recording, one whose thrust
//! commands never lift the vehicle, and one longer than the analysis's cost bound. Each refusal is
//! one line naming the recording and what is degenerate.

use std::path::PathBuf;

use mismatch::recording::degenerate::{MAX_ANALYSED_ROWS, MIN_THRUST_TO_WEIGHT};
use mismatch::{CheckedSettings, MismatchError, NoiseFree, Settings, analyze};
use physics::{Effects, Noise, Scenario, simulate};

mod common;

use common::{model, model_for_scenario};

/// A 12 s simulated figure-8 of the demo vehicle with `noise`, named `generated/flight.csv`.
fn flight(noise: Noise) -> data::FlightLog {
    let scenario = Scenario {
        duration_s: 12.0,
        noise,
        ..common::scenario(Effects::default(), 7)
    };
    let mut log = simulate(&model("vehicles/quad-a.json"), &scenario, "test").unwrap();
    log.path = PathBuf::from("generated/flight.csv");
    log
}

fn noisy() -> Noise {
    common::scenario(Effects::default(), 0).noise
}

fn unchecked_settings() -> Settings {
    let mut settings = Settings::default();
    settings.analysis.block_s = 0.5;
    settings.analysis.selection.resamples = 10;
    settings
}

fn settings() -> CheckedSettings {
    unchecked_settings().checked().unwrap()
}

/// The analysis's refusal: a degenerate-recording error, one line naming the recording.
fn refusal(log: &data::FlightLog, model: &physics::NominalModel) -> String {
    let error = match analyze(log, model, "test", &settings()) {
        Ok(analysis) => panic!(
            "accepted: effects {:?}, unexplained {:?}",
            analysis.fitted.ids(),
            analysis.report.unexplained
        ),
        Err(error) => error,
    };
    let message = error.to_string();
    assert!(
        matches!(error, MismatchError::Degenerate { .. }),
        "{message}"
    );
    assert!(!message.contains('\n'), "one line: {message}");
    assert!(
        message.starts_with("generated/flight.csv: degenerate recording"),
        "{message}"
    );
    message
}

/// Without noise the exact nominal model used to leave "unexplained residual" on every channel
/// over the whole flight (its floor ~1e-7, the comparison's own error ~1e-4).
#[test]
fn a_recording_without_noise_is_refused_not_explained() {
    let message = refusal(&flight(Noise::default()), &model_for_scenario());
    assert!(
        message
            .contains("no measurement noise on vdot_x, vdot_y, vdot_z, wdot_x, wdot_y and wdot_z"),
        "{message}"
    );
    assert!(message.contains("simulated without noise?"), "{message}");
    // For development the analysis can still be asked for; its evidence is then no evidence
    // (on this flight the exact model had three effects named on the comparison's own error).
    let mut development = unchecked_settings();
    development.analysis.noise_free = NoiseFree::Analyse;
    let development = development.checked().unwrap();
    let analysis = analyze(
        &flight(Noise::default()),
        &model_for_scenario(),
        "test",
        &development,
    )
    .unwrap();
    assert!(analysis.report.channels.len() == 6);
    // With the demo's noise the same flight is analysed, and nothing is found.
    let analysis = analyze(&flight(noisy()), &model_for_scenario(), "test", &settings()).unwrap();
    assert!(analysis.report.effects.is_empty());
    assert!(analysis.report.unexplained.is_empty());
}

/// Every row a copy of the first (times kept): gains of 1e22 were reported as physics.
#[test]
fn a_constant_recording_is_refused_naming_the_constant_columns() {
    let mut log = flight(noisy());
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
    for model_name in ["neural-fly.json", "vehicles/quad-a.json"] {
        let message = refusal(&log, &model(model_name));
        assert!(
            message.contains("no excitation: v_x, v_y, v_z, w_x, w_y, w_z, p, q, T_sp and pwm are the same on every row"),
            "{message}"
        );
    }
    // One compared component held is enough: it has nothing to differentiate.
    let mut log = flight(noisy());
    for v in &mut log.velocity {
        v[2] = 0.0;
    }
    let message = refusal(&log, &model("neural-fly.json"));
    assert!(
        message.contains("no excitation: v_z is the same"),
        "{message}"
    );
    // A constant rate is not compared by a thrust-only model, but is by a mixer model.
    let mut log = flight(noisy());
    for w in &mut log.body_rate {
        *w = [0.0; 3];
    }
    let message = refusal(&log, &model_for_scenario());
    assert!(
        message.contains("w_x, w_y and w_z are the same"),
        "{message}"
    );
}

/// A thrust setpoint of 0 on every row was explained by a linear drag and a 183 m/s wind.
#[test]
fn a_recording_without_thrust_is_refused_naming_the_column() {
    let mut log = flight(noisy());
    for thrust in &mut log.thrust_setpoint {
        *thrust = 0.0;
    }
    let message = refusal(&log, &model("neural-fly.json"));
    assert!(
        message.contains("no thrust: the thrust the model reads from T_sp stays below 0.1 of the weight on every row (at most 0.000)"),
        "{message}"
    );
    // The motors at their zero-speed command, for a mixer model.
    let mut log = flight(noisy());
    for pwm in log.motor_command.rows_mut() {
        pwm.fill(1000.0);
    }
    let message = refusal(&log, &model_for_scenario());
    assert!(message.contains("reads from pwm"), "{message}");
    // Just above the bound on one row is flight enough to compare.
    let mut log = flight(noisy());
    let hover = log.hover_throttle[0];
    for thrust in &mut log.thrust_setpoint {
        *thrust = 0.0;
    }
    log.thrust_setpoint[300] = 1.01 * MIN_THRUST_TO_WEIGHT * hover;
    let error = analyze(&log, &model("neural-fly.json"), "test", &settings());
    assert!(
        !matches!(error, Err(MismatchError::Degenerate { .. })),
        "{:?}",
        error.err()
    );
}

/// The cost bound is checked before any work.
#[test]
fn a_recording_over_the_cost_bound_is_refused_before_the_work() {
    let scenario = Scenario {
        duration_s: MAX_ANALYSED_ROWS as f64 / 50.0,
        warmup_s: 0.0,
        noise: noisy(),
        ..common::scenario(Effects::default(), 7)
    };
    let mut log = simulate(&model("vehicles/quad-a.json"), &scenario, "test").unwrap();
    log.path = PathBuf::from("generated/flight.csv");
    assert_eq!(log.len(), MAX_ANALYSED_ROWS + 1);
    let start = std::time::Instant::now();
    let error = analyze(&log, &model_for_scenario(), "test", &settings()).unwrap_err();
    assert!(start.elapsed().as_secs_f64() < 1.0, "refused before work");
    let message = error.to_string();
    assert!(matches!(error, MismatchError::TooLong { .. }), "{message}");
    assert!(!message.contains('\n'), "one line: {message}");
    assert!(
        message.starts_with(&format!(
            "generated/flight.csv: {} rows, more than the {MAX_ANALYSED_ROWS}",
            MAX_ANALYSED_ROWS + 1
        )) && message.contains("8 KB per row")
            && message.contains("analyze_in_parts"),
        "{message}"
    );
}

/// A long recording analysed in parts lists a part where nothing moves with its reason and pools
/// the others; when every part is refused, the analysis is an error naming the first reason.
#[test]
fn a_part_where_nothing_moves_is_listed_and_the_others_pooled() {
    let scenario = Scenario {
        duration_s: 50.0,
        noise: noisy(),
        effects: Effects {
            linear_drag: Some(physics::LinearDrag {
                d: [0.35, 0.35, 0.1],
            }),
            ..Effects::default()
        },
        ..common::scenario(Effects::default(), 7)
    };
    let mut log = simulate(&model("vehicles/quad-a.json"), &scenario, "test").unwrap();
    log.path = PathBuf::from("generated/flight.csv");
    // Two parts: the first up to row `held`, the second from it.
    let held = log.len() / 2;
    let first = log.clone();
    for k in held..log.len() {
        log.velocity[k] = first.velocity[held];
        log.body_rate[k] = first.body_rate[held];
    }
    let in_two_parts = |log: &data::FlightLog| {
        mismatch::analyze_in_parts(
            log,
            held + 1,
            &model_for_scenario(),
            "test",
            &settings(),
            &|_, _, _| {},
        )
    };
    let parted = in_two_parts(&log).unwrap();
    let [analysed, refused] = parted.parts.as_slice() else {
        panic!("{} parts", parted.parts.len());
    };
    assert!(analysed.report.is_some() && analysed.refused.is_none());
    let reason = refused.refused.as_deref().unwrap();
    assert!(
        reason.starts_with("generated/flight.csv: degenerate recording, no excitation"),
        "{reason}"
    );
    let [drag] = parted.effects.as_slice() else {
        panic!("{:?}", parted.effects);
    };
    assert_eq!(
        (drag.id.as_str(), drag.named_in, drag.named),
        ("linear_drag", 1, true)
    );
    for (number, truth) in drag.parameters[0].numbers.iter().zip([0.35, 0.35, 0.1]) {
        assert!((number.value - truth).abs() < 0.1 * truth, "{number:?}");
        assert!(number.per_part[1].is_none());
    }
    // Every part held: nothing to pool.
    for k in 0..log.len() {
        log.velocity[k] = first.velocity[0];
    }
    let error = in_two_parts(&log).unwrap_err().to_string();
    assert!(
        error.starts_with("generated/flight.csv: no part of the recording could be analysed (the first: generated/flight.csv: degenerate recording"),
        "{error}"
    );
}
