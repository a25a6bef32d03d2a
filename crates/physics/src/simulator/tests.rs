//! The simulator's tests: timing, logging, validation and the plant's response to effects.

use super::*;
use crate::jitter::Jitter;
use crate::logger::{CommandLogging, Logger};
use crate::scenario::*;
use crate::trajectory::{MAX_POSITION_M, Trajectory};

const MODEL: &str = r#"{"mass_kg": 1.8, "gravity_m_s2": 9.81, "inertia_kg_m2": [0.02, 0.02, 0.035],
    "thrust_source": "mixer",
    "mixer": {"pwm_offset": 1000.0, "pwm_scale": 1000.0,
              "b0": [[9.0, 9.0, 9.0, 9.0], [-1.08, 1.08, 1.08, -1.08], [1.08, -1.08, 1.08, -1.08], [0.144, 0.144, -0.144, -0.144]]}}"#;

pub(super) fn model() -> NominalModel {
    NominalModel::from_json(MODEL, Path::new("quad.json")).unwrap()
}

pub(super) fn scenario() -> Scenario {
    Scenario::figure_eight("quad.json", 1)
}

/// The field named by the validation error of a changed scenario.
/// Adds a low pass at `height_m` (1 s to 5 s) to the figure-8 of `s`.
fn add_low_pass(s: &mut Scenario, height_m: f64) {
    if let Trajectory::Figure8 { low_passes, .. } = &mut s.trajectory {
        low_passes.push(crate::trajectory::LowPass {
            start_s: 1.0,
            end_s: 5.0,
            height_m,
            ramp_s: 1.0,
        });
    }
}

/// Replaces the trajectory of `s` with `count` random waypoints in a box from
/// (-1, -1, 1) to `box_max`.
fn random_waypoints(s: &mut Scenario, count: usize, box_max: [f64; 3]) {
    s.trajectory = Trajectory::RandomWaypoints {
        seed: 1,
        count,
        box_min: [-1.0, -1.0, 1.0],
        box_max,
        segment_s: 2.5,
        low_passes: Vec::new(),
        yaw_amplitude_rad: 0.0,
        yaw_period_s: 10.0,
    };
}

pub(super) fn rejected_field(change: impl FnOnce(&mut Scenario)) -> String {
    let mut s = scenario();
    change(&mut s);
    let error = s
        .validate(Path::new("s.json"))
        .and_then(|()| s.validate_with_model(&model(), Path::new("s.json")))
        .unwrap_err();
    let text = error.to_string();
    assert!(!text.contains('\n'), "{text}");
    assert!(text.starts_with("s.json: field '"), "{text}");
    match error {
        PhysicsError::Field { field, .. } => field,
        other => panic!("not a field error: {other}"),
    }
}

#[test]
fn a_valid_scenario_passes() {
    let s = scenario();
    s.validate(Path::new("s.json")).unwrap();
    s.validate_with_model(&model(), Path::new("s.json"))
        .unwrap();
}

#[test]
fn a_negative_integral_limit_is_a_field_error_not_a_panic() {
    assert_eq!(
        rejected_field(|s| s.gains.integral_limit = -1.0),
        "gains.integral_limit"
    );
    assert_eq!(
        rejected_field(|s| s.gains.position = -6.0),
        "gains.position"
    );
    assert_eq!(rejected_field(|s| s.gains.rate = 0.0), "gains.rate");
    // and the simulator itself refuses it rather than panicking in f64::clamp
    let mut s = scenario();
    s.gains.integral_limit = -1.0;
    assert!(simulate(&model(), &s, "x").is_err());
}

#[test]
fn sizes_are_bounded_above_and_below() {
    assert_eq!(rejected_field(|s| s.duration_s = 1e7), "duration_s");
    assert_eq!(rejected_field(|s| s.duration_s = 0.001), "duration_s");
    // 4 s at 50 Hz is 201 rows: too few for the analysis
    assert_eq!(rejected_field(|s| s.duration_s = 4.0), "duration_s");
    assert_eq!(
        rejected_field(|s| {
            s.duration_s = 3000.0;
            s.log_rate_hz = 500.0;
        }),
        "duration_s"
    );
    assert_eq!(rejected_field(|s| s.warmup_s = 1e7), "warmup_s");
    assert_eq!(rejected_field(|s| s.warmup_s = -1.0), "warmup_s");
    assert_eq!(
        rejected_field(|s| s.physics_rate_hz = 5e8),
        "physics_rate_hz"
    );
    assert_eq!(
        rejected_field(|s| s.physics_rate_hz = f64::NAN),
        "physics_rate_hz"
    );
    assert_eq!(rejected_field(|s| s.hover_throttle = 1.5), "hover_throttle");
    let mut s = scenario();
    s.duration_s = MAX_DURATION_S;
    s.warmup_s = MAX_WARMUP_S;
    s.validate(Path::new("s.json")).unwrap();
}

/// The message of the validation error of a changed scenario.
fn rejection(change: impl FnOnce(&mut Scenario)) -> String {
    let mut s = scenario();
    change(&mut s);
    s.validate(Path::new("s.json"))
        .and_then(|()| s.validate_with_model(&model(), Path::new("s.json")))
        .unwrap_err()
        .to_string()
}

fn set_center(center: Vec3) -> impl FnOnce(&mut Scenario) {
    move |s: &mut Scenario| {
        if let Trajectory::Figure8 { center: c, .. } = &mut s.trajectory {
            *c = center;
        }
    }
}

/// Settings that would give a log the data tools refuse ("outside the plausible range") are
/// refused when the scenario is read, naming the field.
#[test]
fn settings_that_would_leave_the_plausible_ranges_are_field_errors() {
    assert_eq!(
        rejected_field(set_center([1e300, 0.0, 1.5])),
        "trajectory.center"
    );
    assert_eq!(
        rejected_field(set_center([0.0, 0.0, 1e6])),
        "trajectory.center"
    );
    assert!(
        rejection(set_center([1e300, 0.0, 1.5])).contains("1e300 m"),
        "{}",
        rejection(set_center([1e300, 0.0, 1.5]))
    );
    assert_eq!(
        rejected_field(|s| s.hover_throttle = 1e-300),
        "hover_throttle"
    );
    assert_eq!(
        rejected_field(|s| s.hover_throttle = MIN_HOVER_THROTTLE / 2.0),
        "hover_throttle"
    );
    for (name, change) in [
        (
            "noise.position_m",
            (|s: &mut Scenario| s.noise.position_m = 1e5) as fn(&mut Scenario),
        ),
        ("noise.velocity_m_s", |s| s.noise.velocity_m_s = 1e5),
        ("noise.attitude_rad", |s| s.noise.attitude_rad = 10.0),
        ("noise.rate_rad_s", |s| s.noise.rate_rad_s = 1e5),
    ] {
        assert_eq!(rejected_field(change), name);
    }
    assert_eq!(
        rejected_field(|s| add_low_pass(s, 1e9)),
        "trajectory.low_passes[0].height_m"
    );
    assert_eq!(
        rejected_field(|s| random_waypoints(s, 4, [1.0, 1.0, 1e7])),
        "trajectory.box_max"
    );
    // every field within the bound, their sum (center + first + second) beyond it
    assert_eq!(
        rejected_field(|s| {
            if let Trajectory::Figure8 {
                center,
                first,
                period_s,
                ..
            } = &mut s.trajectory
            {
                *center = [900.0, 0.0, 1.5];
                *first = [900.0, 0.0, 0.0];
                *period_s = 60.0;
            }
        }),
        "trajectory"
    );
    // the bounds themselves are accepted
    let mut s = scenario();
    s.hover_throttle = MIN_HOVER_THROTTLE;
    s.noise = MAX_NOISE;
    set_center([MAX_POSITION_M - 2.0, -(MAX_POSITION_M - 2.0), 1.5])(&mut s);
    s.validate(Path::new("s.json")).unwrap();
    s.validate_with_model(&model(), Path::new("s.json"))
        .unwrap();
}

/// Huge numbers in messages read as numbers, not as hundreds of digits.
#[test]
fn huge_values_are_named_readably() {
    let message = rejection(|s| s.duration_s = 1e308);
    assert!(message.contains("found 1e308"), "{message}");
    assert!(message.len() < 200, "{message}");
    let message = rejection(|s| s.gains.position = -1e300);
    assert!(message.contains("found -1e300"), "{message}");
}

#[test]
fn trajectory_fields_are_field_errors_not_divergence() {
    let set_yaw_period = |value: f64| {
        move |s: &mut Scenario| {
            if let Trajectory::Figure8 { yaw_period_s, .. } = &mut s.trajectory {
                *yaw_period_s = value;
            }
        }
    };
    assert_eq!(
        rejected_field(set_yaw_period(0.0)),
        "trajectory.yaw_period_s"
    );
    // a yaw rate no vehicle follows (0.2 rad amplitude every 0.1 s)
    assert_eq!(
        rejected_field(set_yaw_period(0.1)),
        "trajectory.yaw_period_s"
    );
    // within the position bound, but a reference no vehicle follows
    assert_eq!(
        rejected_field(|s| {
            if let Trajectory::Figure8 { first, .. } = &mut s.trajectory {
                first[0] = 500.0;
            }
        }),
        "trajectory"
    );
    assert_eq!(rejected_field(|s| add_low_pass(s, -1.0)), "trajectory");
    assert_eq!(
        rejected_field(|s| random_waypoints(s, 1_000_000_000, [1.0, 1.0, 2.0])),
        "trajectory.count"
    );
}

#[test]
fn noise_delay_and_model_errors_name_the_field() {
    assert_eq!(
        rejected_field(|s| s.noise.rate_rad_s = -0.1),
        "noise.rate_rad_s"
    );
    assert_eq!(
        rejected_field(|s| {
            s.effects.delay = Some(crate::effects::Delay { delay_s: 1e9 });
        }),
        "effects.delay.delay_s"
    );
    let thrust_only = NominalModel::from_json(
        r#"{"mass_kg": 2.6, "gravity_m_s2": 9.81, "inertia_kg_m2": [0.03, 0.03, 0.05], "thrust_source": "T_sp"}"#,
        Path::new("nf.json"),
    )
    .unwrap();
    let error = scenario()
        .validate_with_model(&thrust_only, Path::new("s.json"))
        .unwrap_err()
        .to_string();
    assert!(error.contains("field 'model'"), "{error}");
}

/// The logger reads the commands its description says: with commands numbered by their control
/// step, a row at step s holds s (sample), s + 1 (one step late), or the mean of s − 10 … s − 1
/// (the mean over the preceding log period of 10 control steps).
#[test]
fn the_command_log_reads_what_the_logger_describes() {
    let logged = |logger: Logger| -> Vec<f64> {
        let mut s = scenario();
        s.controller_rate_hz = Some(500.0);
        s.logger = Some(logger);
        s.warmup_s = 0.2;
        let mut commands = CommandLog::new(&s, 3);
        let warmup_steps = s.warmup_rows() * 10;
        for step in 0..warmup_steps + 40 {
            commands.issue(step, ([step as f64; MAX_ACTUATORS], 2.0 * step as f64, 0.0));
            if step >= warmup_steps
                && (step - warmup_steps).is_multiple_of(10)
                && step < warmup_steps + 30
            {
                commands.add_row(step - warmup_steps);
            }
            commands.fill_ready(step);
        }
        commands
            .rows
            .iter()
            .map(|(step, command)| {
                let (speeds, thrust, _) = command.unwrap();
                assert_eq!(thrust, 2.0 * speeds[0]);
                speeds[0] - (step + warmup_steps) as f64
            })
            .collect()
    };
    assert_eq!(logged(Logger::default()), [0.0; 3]);
    let late = Logger {
        command_time_offset_s: 0.002,
        ..Logger::default()
    };
    assert_eq!(logged(late), [1.0; 3]);
    let mean = Logger {
        command: CommandLogging::PeriodMean,
        ..Logger::default()
    };
    assert_eq!(logged(mean), [-5.5; 3]);
}

#[test]
fn the_logger_must_match_the_controller_rate() {
    assert_eq!(
        rejected_field(|s| s.logger = Some(Logger::default())),
        "logger.command"
    );
    assert_eq!(
        rejected_field(|s| {
            s.controller_rate_hz = Some(500.0);
            s.logger = Some(Logger {
                command: CommandLogging::Held,
                ..Logger::default()
            });
        }),
        "logger.command"
    );
    assert_eq!(
        rejected_field(|s| s.controller_rate_hz = Some(75.0)),
        "controller_rate_hz"
    );
    assert_eq!(
        rejected_field(|s| {
            s.controller_rate_hz = Some(500.0);
            s.logger = Some(Logger {
                command_time_offset_s: 0.0013,
                ..Logger::default()
            });
        }),
        "logger.command_time_offset_s"
    );
    let mut s = scenario();
    assert_eq!(s.logger().command, CommandLogging::Held);
    s.controller_rate_hz = Some(500.0);
    assert_eq!(s.logger().command, CommandLogging::Sample);
    s.jitter = Some(Jitter {
        translational_m_s2: 0.3,
        angular_rad_s2: 2.0,
        band_hz: [1.0, 5.0],
    });
    s.logger = Some(Logger {
        command: CommandLogging::PeriodMean,
        command_time_offset_s: -0.004,
        rate_low_pass_hz: Some(40.0),
        controller_rate_hz: None,
    });
    s.physics_rate_hz = 1000.0;
    s.validate(Path::new("s.json")).unwrap();
    let log = simulate(&model(), &s, "fast").unwrap();
    assert_eq!(log.len(), s.rows());
    assert_eq!(
        simulate(&model(), &s, "fast").unwrap().motor_command,
        log.motor_command
    );
}

/// The queue gives exactly what indexing the whole history gave.
#[test]
fn the_command_queue_delays_like_the_full_history() {
    for delay_steps in [0, 1, 3, 17] {
        let mut queue = CommandQueue::new(delay_steps as f64);
        assert_eq!(queue.fraction, 0.0);
        let mut history: Vec<Actuators> = Vec::new();
        for k in 0..60 {
            let command = [
                k as f64,
                0.5 * k as f64,
                1.0,
                -(k as f64),
                0.0,
                0.0,
                0.0,
                2.0,
            ];
            history.push(command);
            let index = history.len() - 1;
            let issued_ago = |steps: usize| history[index.saturating_sub(steps)];
            assert_eq!(
                queue.push(command),
                (issued_ago(delay_steps + 1), issued_ago(delay_steps))
            );
        }
        assert!(queue.recent.len() <= delay_steps + 2);
    }
    let queue = CommandQueue::new(12.5);
    assert_eq!((queue.delay_steps, queue.fraction), (12, 0.5));
}

/// A delay that is not a whole number of physics steps is applied as configured, not rounded
/// to the step: 25 ms at 500 Hz (12.5 steps) flies as 25 ms at 2000 Hz does, far closer than
/// the 26 ms that rounding gave.
#[test]
fn a_delay_between_physics_steps_is_exact() {
    let flight = |physics_rate_hz: f64, delay_s: f64| {
        let mut s = scenario();
        s.physics_rate_hz = physics_rate_hz;
        s.effects.delay = Some(crate::effects::Delay { delay_s });
        s.validate(Path::new("s.json")).unwrap();
        simulate(&model(), &s, "delay").unwrap()
    };
    let distance = |a: &FlightLog, b: &FlightLog| {
        a.body_rate
            .iter()
            .zip(&b.body_rate)
            .map(|(x, y)| (0..3).map(|i| (x[i] - y[i]).powi(2)).sum::<f64>())
            .sum::<f64>()
            .sqrt()
    };
    let reference = flight(2000.0, 0.025);
    let coarse = flight(500.0, 0.025);
    let one_ms_later = flight(2000.0, 0.026);
    let (error, scale) = (
        distance(&coarse, &reference),
        distance(&one_ms_later, &reference),
    );
    assert!(error < 0.2 * scale, "{error} vs {scale}");
}
