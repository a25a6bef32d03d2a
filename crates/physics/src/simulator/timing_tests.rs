//! The simulator's log timing: rows at listed control steps, jittered, dropped or missing over
//! gaps, and without a log timing the very log of before.

use super::tests::{model, rejected_field, scenario};
use super::*;
use crate::effects::Delay;
use crate::jitter::Jitter;
use crate::log_timing::LogTiming;
use crate::logger::{CommandLogging, Logger};

/// The simulator as it was before the row steps were listed (commit 0c0ebf8): a row every
/// `controller_steps_per_row()` control steps. The reference for "without a log timing nothing
/// changes".
fn simulate_evenly(model: &NominalModel, scenario: &Scenario, name: &str) -> FlightLog {
    let mixer = model.mixer.as_ref().unwrap();
    let mut flight = Flight::new(model, mixer, scenario);
    let per_row = scenario.controller_steps_per_row();
    let warmup_steps = scenario.warmup_rows() * per_row;
    let rows = scenario.rows();
    let last_row_step = warmup_steps + (rows - 1) * per_row;
    let last_step = last_row_step + flight.look_ahead_steps();
    let mut log = empty_log(name, rows, 4, false);
    let mut commands = CommandLog::new(scenario, rows);
    for step in 0..=last_step {
        let t = (step as f64 - warmup_steps as f64) * flight.control_dt;
        let reference = flight.generator.at(t);
        let measured = flight.measure();
        let output = flight
            .controller
            .update(&measured, &reference, flight.control_dt);
        let speeds = flight.speeds_for(&output, t, None);
        commands.issue(step, (speeds, mixer.wrench(&speeds)[0], 0.0));
        if step >= warmup_steps
            && (step - warmup_steps).is_multiple_of(per_row)
            && step <= last_row_step
        {
            record_row(&mut log, &measured, &reference, &output, t);
            commands.add_row(step - warmup_steps);
        }
        commands.fill_ready(step);
        if step == last_step {
            break;
        }
        flight.advance(speeds, t, &reference).unwrap();
    }
    commands.write_into(&mut log, model, mixer, scenario.hover_throttle);
    log
}

/// The figure-8 with a 500 Hz controller sampled at 50 Hz (10 control steps per row).
fn sampled() -> Scenario {
    Scenario {
        controller_rate_hz: Some(500.0),
        ..scenario()
    }
}

fn with_timing(jitter_s: f64, dropped_fraction: f64, gaps: Vec<[f64; 2]>) -> Scenario {
    Scenario {
        log_timing: Some(LogTiming {
            jitter_s,
            dropped_fraction,
            gaps,
        }),
        ..sampled()
    }
}

fn simulated(s: &Scenario) -> FlightLog {
    s.validate(Path::new("s.json")).unwrap();
    simulate(&model(), s, "timed").unwrap()
}

#[test]
fn without_a_log_timing_the_log_is_the_one_of_before() {
    let jitter = Jitter {
        translational_m_s2: 0.3,
        angular_rad_s2: 2.0,
        band_hz: [1.0, 5.0],
    };
    let mut late = sampled();
    late.jitter = Some(jitter);
    late.effects.delay = Some(Delay { delay_s: 0.013 });
    late.logger = Some(Logger {
        command_time_offset_s: 0.004,
        ..Logger::default()
    });
    let mut mean = scenario();
    mean.controller_rate_hz = Some(200.0);
    mean.physics_rate_hz = 1000.0;
    mean.logger = Some(Logger {
        command: CommandLogging::PeriodMean,
        command_time_offset_s: -0.005,
        rate_low_pass_hz: Some(40.0),
        controller_rate_hz: None,
    });
    for s in [scenario(), sampled(), late, mean] {
        let log = simulated(&s);
        assert_eq!(log.len(), s.rows());
        assert_eq!(
            log.csv_text(),
            simulate_evenly(&model(), &s, "timed").csv_text()
        );
    }
    // A log timing that moves nothing changes nothing (its draws are a stream of their own).
    assert_eq!(
        simulated(&with_timing(0.0, 0.0, Vec::new())).csv_text(),
        simulated(&sampled()).csv_text()
    );
}

#[test]
fn jittered_rows_are_stamped_with_their_control_step() {
    let s = with_timing(0.008, 0.0, Vec::new());
    let log = simulated(&s);
    assert_eq!(log.len(), s.rows());
    let intervals: Vec<f64> = log.time.windows(2).map(|w| w[1] - w[0]).collect();
    let (low, high) = intervals
        .iter()
        .fold((f64::INFINITY, 0.0_f64), |(l, h), &i| (l.min(i), h.max(i)));
    assert!(low < 0.012 && high > 0.028, "{low} {high}");
    assert!(intervals.iter().all(|&i| i > 0.0));
    for &t in &log.time {
        let periods = (t - log.time[0]) * 500.0;
        assert!((periods - periods.round()).abs() < 1e-6, "{t}");
    }
    // Each row is the flight at its own time: the reference there, and, where a row fell on its
    // nominal step, the very row of the evenly spaced log (the flight itself is unchanged).
    let generator = s.trajectory.generator();
    let desired = log.position_desired.as_ref().unwrap();
    for (k, &t) in log.time.iter().enumerate() {
        assert_eq!(desired[k], generator.at(t).position);
    }
    let even = simulated(&sampled());
    let mut on_time = 0;
    for (k, t) in log.time.iter().enumerate() {
        if let Some(j) = even.time.iter().position(|u| u == t) {
            on_time += 1;
            assert_eq!(log.position[k], even.position[j]);
            assert_eq!(log.body_rate[k], even.body_rate[j]);
            assert_eq!(log.motor_command.row(k), even.motor_command.row(j));
            assert_eq!(log.thrust_setpoint[k], even.thrust_setpoint[j]);
        }
    }
    assert!((10..150).contains(&on_time), "{on_time}");
}

#[test]
fn dropped_rows_thin_the_log_by_their_fraction() {
    let s = Scenario {
        duration_s: 30.0,
        ..with_timing(0.0, 0.3, Vec::new())
    };
    let log = simulated(&s);
    let kept = log.len() as f64 / s.rows() as f64;
    assert!((kept - 0.7).abs() < 0.04, "{kept}");
    let median = log.median_interval();
    assert!((median - 0.02).abs() < 1e-9, "{median}");
    assert!(log.time.windows(2).any(|w| w[1] - w[0] > 0.05));
}

#[test]
fn no_row_is_logged_inside_a_gap() {
    let log = simulated(&Scenario {
        duration_s: 12.0,
        ..with_timing(0.004, 0.05, vec![[2.0, 1.5]])
    });
    assert!(log.time.iter().all(|t| !(2.0..3.5).contains(t)));
    let before = log.time.iter().rposition(|&t| t < 2.0).unwrap();
    assert!(log.time[before] > 1.9 && log.time[before + 1] < 3.6);
}

#[test]
fn bad_log_timings_are_refused_naming_the_field() {
    let timing = |jitter_s: f64, dropped_fraction: f64, gaps: Vec<[f64; 2]>| {
        Some(LogTiming {
            jitter_s,
            dropped_fraction,
            gaps,
        })
    };
    // The default logger at the log rate holds each command until the next row.
    assert_eq!(
        rejected_field(|s| s.log_timing = timing(0.0, 0.0, Vec::new())),
        "log_timing"
    );
    assert_eq!(
        rejected_field(|s| {
            s.controller_rate_hz = Some(500.0);
            s.logger = Some(Logger {
                command: CommandLogging::PeriodMean,
                ..Logger::default()
            });
            s.log_timing = timing(0.0, 0.0, Vec::new());
        }),
        "log_timing"
    );
    let timed = |jitter_s: f64, dropped_fraction: f64, gaps: Vec<[f64; 2]>| {
        move |s: &mut Scenario| {
            s.controller_rate_hz = Some(500.0);
            s.log_timing = timing(jitter_s, dropped_fraction, gaps);
        }
    };
    assert_eq!(
        rejected_field(timed(0.01, 0.0, Vec::new())),
        "log_timing.jitter_s"
    );
    assert_eq!(
        rejected_field(timed(0.0, 0.51, Vec::new())),
        "log_timing.dropped_fraction"
    );
    assert_eq!(
        rejected_field(timed(0.0, 0.0, vec![[5.0, 2.0]])),
        "log_timing.gaps[0]"
    );
    assert_eq!(
        rejected_field(timed(0.0, 0.0, vec![[1.0, -1.0]])),
        "log_timing.gaps[0]"
    );
    // 301 rows due: half of them dropped, or a 2 s gap, leaves fewer than a log needs.
    assert_eq!(rejected_field(timed(0.0, 0.5, Vec::new())), "log_timing");
    assert_eq!(
        rejected_field(timed(0.0, 0.0, vec![[1.0, 2.0]])),
        "log_timing"
    );
    // No reader accepts 10 s without a sample.
    assert_eq!(
        rejected_field(|s| {
            timed(0.0, 0.0, vec![[5.0, 12.0]])(s);
            s.duration_s = 30.0;
        }),
        "log_timing"
    );
}
