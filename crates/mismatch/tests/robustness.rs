//! Recordings whose values overflow the comparison give a one-line error naming the recording —
//! never a panic, a hang, or NaN and infinite numbers in the outputs. The flights are generated and
//! corrupted in memory (the data crate's reader rejects such values in files before they get here).

use std::path::{Path, PathBuf};

use mismatch::{Analysis, CheckedSettings, MismatchError, Settings, analyze};
use physics::{Effects, Scenario, simulate};

mod common;

use common::model;

/// A 12 s simulated figure-8 (with a mixer, so with motor commands and a thrust setpoint).
fn flight() -> data::FlightLog {
    let scenario = Scenario {
        duration_s: 12.0,
        ..common::scenario(Effects::default(), 7)
    };
    let mut log = simulate(&model("vehicles/quad-a.json"), &scenario, "test").unwrap();
    log.path = PathBuf::from("generated/corrupt_flight.csv");
    log
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

/// The analysis of a corrupted flight must fail with one line naming the recording.
fn error_of(log: &data::FlightLog, model_name: &str) -> String {
    let message = match analyze(log, &model(model_name), "test", &settings()) {
        Ok(analysis) => panic!(
            "accepted, held-out MSE {} -> {}",
            analysis.report.fit.heldout.before.mse, analysis.report.fit.heldout.after.mse
        ),
        Err(error) => error.to_string(),
    };
    assert!(!message.contains('\n'), "one line: {message}");
    assert!(
        message.starts_with("generated/corrupt_flight.csv: "),
        "names the recording: {message}"
    );
    message
}

#[test]
fn an_overflowing_velocity_is_an_error_not_infinite_results() {
    for value in [1e200, 1e308] {
        let mut log = flight();
        log.velocity[100] = [value, 0.0, 0.0];
        let message = error_of(&log, "neural-fly.json");
        // The derivative overflows (1e308) or its square does (1e200).
        assert!(
            message.contains("gives a non-finite residual of the nominal model in vdot_x")
                || message.contains("gives a non-finite channels[0].residual_rms in the report"),
            "{message}"
        );
    }
}

#[test]
fn a_tiny_hover_throttle_or_huge_thrust_setpoint_is_an_error() {
    let mut log = flight();
    log.hover_throttle[100] = 1e-300;
    let message = error_of(&log, "neural-fly.json");
    assert!(message.contains("non-finite"), "{message}");
    let mut log = flight();
    log.thrust_setpoint[100] = 1e308;
    let message = error_of(&log, "neural-fly.json");
    assert!(message.contains("non-finite"), "{message}");
}

#[test]
fn an_overflowing_rate_is_an_error_even_on_channels_not_compared() {
    // The T_sp model compares only vdot; the rate still enters the frame check of the report.
    let mut log = flight();
    log.body_rate[100] = [0.0, 0.0, 1e300];
    let message = error_of(&log, "neural-fly.json");
    assert!(
        message.contains("non-finite rate_frame.body_rms in the report"),
        "{message}"
    );
    let mut log = flight();
    log.body_rate[100] = [0.0, 0.0, 1e300];
    let message = error_of(&log, "vehicles/quad-a.json");
    assert!(message.contains("non-finite"), "{message}");
}

#[test]
fn times_scaled_by_1e_minus_300_do_not_overflow_the_window_arithmetic() {
    // Used to panic with `attempt to add with overflow` in the moving-window location.
    let mut log = flight();
    for t in &mut log.time {
        *t *= 1e-300;
    }
    let message = error_of(&log, "neural-fly.json");
    assert!(message.contains("test function"), "{message}");
    assert!(message.len() < 250, "numbers print short: {message}");
}

fn valid_analysis() -> Analysis {
    analyze(&flight(), &model("neural-fly.json"), "test", &settings()).unwrap()
}

#[test]
fn figures_are_never_drawn_from_non_finite_or_undrawable_data() {
    let valid = valid_analysis();
    valid.figure_svg(Path::new("valid.svg")).unwrap();

    let mut nan = valid.clone();
    nan.after[3][1] = f64::NAN;
    let mut infinite = valid.clone();
    infinite.before[5][0] = f64::INFINITY;
    // Finite, but the axis would span more than the largest f64.
    let mut huge = valid.clone();
    huge.before[5][2] = 1e308;
    huge.after[6][2] = -1e308;
    let mut time = valid.clone();
    time.problem.time[0] = f64::NAN;
    let mut window = valid.clone();
    window.report.windows.push(mismatch::Window {
        channel: "vdot_x".into(),
        t_start: f64::NEG_INFINITY,
        t_end: 1.0,
    });
    // Tiny but drawable spans still give a figure (and return).
    let mut tiny = valid.clone();
    for t in &mut tiny.problem.time {
        *t *= 1e-300;
    }
    for w in &mut tiny.report.windows {
        w.t_start *= 1e-300;
        w.t_end *= 1e-300;
    }
    tiny.figure_svg(Path::new("tiny.svg")).unwrap();
    let mut subnormal = valid.clone();
    for t in &mut subnormal.problem.time {
        *t *= 1e-320;
    }
    subnormal.report.windows.clear();
    for (name, analysis) in [
        ("subnormal", subnormal),
        ("nan", nan),
        ("infinite", infinite),
        ("huge", huge),
        ("time", time),
        ("window", window),
    ] {
        let path = PathBuf::from(format!("{name}.svg"));
        let error = analysis.figure_svg(&path).unwrap_err();
        assert!(
            matches!(error, MismatchError::Plot { .. }),
            "{name}: {error}"
        );
        let message = error.to_string();
        assert!(!message.contains('\n'), "{name}: {message}");
        assert!(
            message.contains(&format!("{name}.svg: cannot draw the figure")),
            "{message}"
        );
    }
}

#[test]
fn no_file_is_rendered_from_non_finite_results() {
    let mut analysis = valid_analysis();
    analysis.report.fit.after.mse = f64::INFINITY;
    let dir = Path::new("out");
    let message = analysis.render(dir).unwrap_err().to_string();
    assert_eq!(
        message,
        "generated/corrupt_flight.csv: the analysis of this recording gives a non-finite fit.after.mse in the report: its values are outside the range the analysis can handle"
    );
    let mut analysis = valid_analysis();
    analysis.after[10][2] = f64::NAN;
    let message = analysis.render(dir).unwrap_err().to_string();
    assert!(
        message.contains("non-finite residual of the fitted model in vdot_z (NaN at t = "),
        "{message}"
    );
}

#[test]
fn too_few_rows_or_no_fit_rows_are_errors_not_underflows() {
    let log = flight();
    let mut settings = unchecked_settings();
    settings.comparison.heldout_fraction = 1.0;
    let message = settings.checked().unwrap_err().to_string();
    assert!(message.contains("comparison.heldout_fraction"), "{message}");
    settings.comparison.heldout_fraction = 0.9999;
    let settings = settings.checked().unwrap();
    let message = analyze(&log, &model("neural-fly.json"), "test", &settings)
        .unwrap_err()
        .to_string();
    assert!(message.contains("leaves no rows to fit"), "{message}");
}
