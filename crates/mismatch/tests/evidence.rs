//! What is named on recordings the vocabulary or the log cannot wholly support: each effect is
//! judged on the channels it acts on, so a residual left in one channel group does not hide an
//! effect of the other; timing shorter than the log's commands resolve is not named.

use mismatch::{CheckedSettings, Settings, analyze};
use physics::{Delay, EffectId, Effects, NominalModel, ThrustScale, simulate};

mod common;

use common::scenario;

fn model() -> NominalModel {
    common::model_for_scenario()
}

fn settings() -> CheckedSettings {
    let mut settings = Settings::default();
    settings.analysis.block_s = 0.5;
    settings.analysis.selection.resamples = 20;
    settings.checked().unwrap()
}

/// Adds to the logged body rate a smooth wobble no effect of the vocabulary describes: two
/// incommensurate sines per axis, so the angular channels keep a residual far above their noise.
fn with_rate_wobble(mut log: data::FlightLog) -> data::FlightLog {
    let t0 = log.time[0];
    for (t, w) in log.time.iter().zip(log.body_rate.iter_mut()) {
        let s = t - t0;
        let tau = std::f64::consts::TAU;
        w[0] += 0.3 * (tau * 0.7 * s).sin() + 0.2 * (tau * 1.3 * s + 1.0).sin();
        w[1] += 0.25 * (tau * 0.9 * s + 2.0).sin() + 0.2 * (tau * 1.7 * s).sin();
        w[2] += 0.2 * (tau * 0.5 * s + 0.5).sin();
    }
    log
}

#[test]
fn an_unexplained_angular_residual_does_not_hide_a_translational_effect() {
    let effects = Effects {
        thrust_scale: Some(ThrustScale { k: 0.99 }),
        ..Effects::default()
    };
    let log = with_rate_wobble(simulate(&model(), &scenario(effects, 5), "wobble.csv").unwrap());
    let analysis = analyze(&log, &model(), "demo", &settings()).unwrap();
    let report = &analysis.report;
    assert!(report.channels[3].residual_rms > 20.0 * report.channels[3].noise_floor);
    let thrust = report
        .effects
        .iter()
        .find(|e| e.id == EffectId::ThrustScale)
        .unwrap_or_else(|| panic!("thrust_scale not named: {:?}", report.selection.dropped));
    assert_eq!(
        thrust.evidence.judged_on,
        physics::ChannelGroup::Translational
    );
    let k = analysis.fitted.thrust_scale.unwrap().k;
    assert!((k - 0.99).abs() < 0.003, "{k}");
}

/// The motor commands of a 50 Hz log held for three rows (16.7 new values per second, as a logger
/// that writes its motor topic slowly does): a concealed 50 ms delay, less the held commands' mean
/// age of one row, is shorter than the 60 ms the commands resolve, and is reported as such
/// instead of named.
#[test]
fn a_delay_shorter_than_the_commands_resolve_is_not_named() {
    let effects = Effects {
        delay: Some(Delay { delay_s: 0.05 }),
        ..Effects::default()
    };
    let mut log = simulate(&model(), &scenario(effects, 6), "held.csv").unwrap();
    let held: Vec<[f64; 4]> = (0..log.len())
        .map(|k| log.motor_command[k - k % 3])
        .collect();
    log.motor_command = held;
    let analysis = analyze(&log, &model(), "demo", &settings()).unwrap();
    let report = &analysis.report;
    let content = report.log_content.as_ref().expect("held commands");
    let limit = content.timing_limit_s.unwrap();
    assert!((limit - 0.06).abs() < 0.002, "{limit}");
    assert!(
        report
            .effects
            .iter()
            .all(|e| !matches!(e.id, EffectId::Delay | EffectId::MotorLag)),
        "{:?}",
        report.effects.iter().map(|e| e.id).collect::<Vec<_>>()
    );
    let below = &report.selection.below_resolution;
    assert_eq!(below.len(), 1, "{below:?}");
    assert!(
        below[0].id == EffectId::Delay && below[0].value_s < limit,
        "{below:?}"
    );
}

/// The motor commands logged in another order than the model numbers its rotors (each shifted by
/// one): the model's torques are then unrelated to the recorded angular accelerations, the
/// angular channels are left out with the response that shows it, and no angular effect is named.
#[test]
fn torques_unrelated_to_the_recording_are_not_compared() {
    let mut log = simulate(&model(), &scenario(Effects::default(), 7), "shifted.csv").unwrap();
    for u in &mut log.motor_command {
        u.rotate_left(1);
    }
    let analysis = analyze(&log, &model(), "demo", &settings()).unwrap();
    let report = &analysis.report;
    let response = report.uninformative_torques.expect("the torques left out");
    assert!(!response.informative(), "{response:?}");
    assert_eq!(report.channels.len(), 3);
    assert!(
        report
            .effects
            .iter()
            .all(|e| e.id.acts_on() != physics::ChannelGroup::Angular),
        "{:?}",
        report.effects.iter().map(|e| e.id).collect::<Vec<_>>()
    );
}
