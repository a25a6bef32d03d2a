//! Recordings whose time stamps are not evenly spaced, as real loggers write them: each sample's
//! time is exact, the spacing jitters by a third of the interval, samples are dropped and the log
//! has a gap. The flights are simulated at 150 Hz with a 300 Hz controller whose commands the log
//! samples, then every third row is kept, one row early or late at random, some dropped and 0.3 s
//! cut out: what a 50 Hz logger with a jittering clock would have written.

use mismatch::analyze;
use physics::{
    CommandLogging, Delay, EffectId, Effects, Logger, NominalModel, ThrustScale, simulate,
};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

mod common;

use common::fast_settings;

fn model() -> NominalModel {
    NominalModel {
        logger: Logger {
            command: CommandLogging::Sample,
            controller_rate_hz: Some(300.0),
            ..Logger::default()
        },
        ..common::model("vehicles/quad-a.json")
    }
}

/// The rows of `log` at `rows`, in order.
fn rows_of(log: &data::FlightLog, rows: &[usize]) -> data::FlightLog {
    let pick = |k: usize| log.row_range(k..k + 1).unwrap();
    let mut out = pick(rows[0]);
    for &k in &rows[1..] {
        let row = pick(k);
        out.time.extend(row.time);
        out.position.extend(row.position);
        out.velocity.extend(row.velocity);
        out.quaternion.extend(row.quaternion);
        out.rotation.extend(row.rotation);
        out.body_rate.extend(row.body_rate);
        out.thrust_setpoint.extend(row.thrust_setpoint);
        out.hover_throttle.extend(row.hover_throttle);
        out.motor_command.extend(&row.motor_command);
    }
    out.position_desired = None;
    out.velocity_desired = None;
    out.attitude_setpoint = None;
    out.residual_force = None;
    out
}

/// A 50 Hz log with a jittering clock (±1 row of 150 Hz), 3% of its samples dropped and no
/// samples for 0.3 s from t = 9 s.
fn jittered_flight(effects: Effects, seed: u64) -> data::FlightLog {
    let scenario = physics::Scenario {
        log_rate_hz: 150.0,
        physics_rate_hz: 600.0,
        controller_rate_hz: Some(300.0),
        ..common::scenario(effects, seed)
    };
    let fast = simulate(&model(), &scenario, "jittered.csv").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(seed + 1000);
    let mut rows = Vec::new();
    for k in 1..fast.len() / 3 - 1 {
        let row = (3 * k as i64 + rng.random_range(-1..=1i64)) as usize;
        let t = fast.time[row] - fast.time[0];
        let dropped = rng.random::<f64>() < 0.03;
        if !dropped && !(9.0..9.3).contains(&t) {
            rows.push(row);
        }
    }
    rows_of(&fast, &rows)
}

#[test]
fn the_log_is_what_a_jittering_logger_writes() {
    let log = jittered_flight(Effects::default(), 1);
    let intervals: Vec<f64> = log.time.windows(2).map(|w| w[1] - w[0]).collect();
    let shortest = intervals.iter().copied().fold(f64::INFINITY, f64::min);
    let longest = intervals.iter().copied().fold(0.0, f64::max);
    assert!(shortest < 0.014 && longest > 0.3, "{shortest} {longest}");
    let median = {
        let mut sorted = intervals.clone();
        sorted.sort_by(f64::total_cmp);
        sorted[sorted.len() / 2]
    };
    assert!((median - 0.02).abs() < 1e-9, "{median}");
}

#[test]
fn nothing_is_named_on_noise_alone() {
    for seed in [1, 2] {
        let analysis = analyze(
            &jittered_flight(Effects::default(), seed),
            &model(),
            "demo",
            &fast_settings(),
        )
        .unwrap();
        assert!(
            analysis.report.effects.is_empty(),
            "seed {seed}: {:?}",
            analysis.report.effects
        );
        let stamps = analysis
            .report
            .time_stamps
            .as_ref()
            .expect("a stamped recording");
        assert_eq!(stamps.gaps, 1);
        assert!(stamps.compared_rows < stamps.rows - 20);
        let [low, high] = stamps.interval_ratio_percentiles;
        assert!(low < 0.7 && high > 1.3, "{low} {high}");
    }
}

#[test]
fn a_concealed_delay_is_timed_on_the_stamps() {
    let effects = Effects {
        delay: Some(Delay { delay_s: 0.03 }),
        ..Effects::default()
    };
    let analysis = analyze(
        &jittered_flight(effects, 3),
        &model(),
        "demo",
        &fast_settings(),
    )
    .unwrap();
    assert_eq!(analysis.fitted.ids(), [EffectId::Delay]);
    let delay = analysis.fitted.delay_s();
    assert!((delay - 0.03).abs() < 0.003, "{delay}");
}

#[test]
fn a_concealed_thrust_loss_is_fitted_across_the_gap() {
    let effects = Effects {
        thrust_scale: Some(ThrustScale { k: 0.9 }),
        ..Effects::default()
    };
    let analysis = analyze(
        &jittered_flight(effects, 4),
        &model(),
        "demo",
        &fast_settings(),
    )
    .unwrap();
    assert_eq!(analysis.fitted.ids(), [EffectId::ThrustScale]);
    let k = analysis.fitted.thrust_scale.unwrap().k;
    assert!((k - 0.9).abs() < 0.01, "{k}");
    let fit = &analysis.report.fit;
    assert!(
        fit.heldout.after.mse < 0.4 * fit.heldout.before.mse,
        "{fit:?}"
    );
}

/// What `learn data inspect` calls a gap is what splits the comparison (the readers cannot depend on
/// the analysis, so each crate names the threshold; they must agree).
#[test]
fn the_inspection_and_the_comparison_split_at_the_same_gaps() {
    assert_eq!(data::GAP_INTERVALS, sindy::sampling::GAP_FACTOR);
}
