//! What is named on recordings the vocabulary or the log cannot wholly support: each effect is
//! judged on the channels it acts on, so a residual left in one channel group does not hide an
//! effect of the other; a wind a vehicle effect explains as well is not named; timing shorter than
//! the log's commands resolve is not named, and torques unrelated to the recording not compared.

use data::ulog::ColumnPattern;
use mismatch::explain::confounds::{Separate, separate};
use mismatch::explain::evidence;
use mismatch::recording::content::{self, Signal};
use mismatch::{
    CheckedSettings, EvidenceSettings, FittedSet, Problem, Recording, Settings, analyze,
};
use physics::{
    Delay, EffectId, EffectNumber, Effects, LinearDrag, NominalModel, RotorDrag, ThrustScale,
    simulate,
};

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

/// Adds to the logged roll and pitch rates a smooth wobble no effect of the vocabulary describes:
/// two incommensurate sines per axis, so those channels keep a residual far above their noise.
fn with_rate_wobble(mut log: data::FlightLog) -> data::FlightLog {
    let t0 = log.time[0];
    for (t, w) in log.time.iter().zip(log.body_rate.iter_mut()) {
        let s = t - t0;
        let tau = std::f64::consts::TAU;
        w[0] += 0.15 * (tau * 0.7 * s).sin() + 0.1 * (tau * 1.3 * s + 1.0).sin();
        w[1] += 0.12 * (tau * 0.9 * s + 2.0).sin() + 0.1 * (tau * 1.7 * s).sin();
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
    // The model's torques still predict the body rate: the angular channels are compared.
    assert_eq!(
        report.channels.len(),
        6,
        "{:?}",
        report.uninformative_torques
    );
    assert!(report.channels[3].residual_rms > 10.0 * report.channels[3].noise_floor);
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
        .map(|k| log.motor_command.row(k - k % 3).try_into().unwrap())
        .collect();
    log.motor_command = held.into_iter().collect();
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
    for u in log.motor_command.rows_mut() {
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

/// A thrust loss taken for a vertical wind through a drag along the body axes: the evidence rule
/// alone names the wind (nothing else in the set explains the steady vertical force); the
/// separation puts the thrust scale in its place.
#[test]
fn a_wind_a_vehicle_effect_explains_as_well_is_not_named() {
    let effects = Effects {
        thrust_scale: Some(ThrustScale { k: 0.95 }),
        linear_drag: Some(LinearDrag { d: [0.3, 0.3, 0.4] }),
        ..Effects::default()
    };
    let log = simulate(&model(), &scenario(effects, 11), "confounded.csv").unwrap();
    let defaults = Settings::default().checked().unwrap();
    let recording = Recording::new(&log, &model(), 40).unwrap();
    let comparison = defaults.comparison;
    let problem = Problem::new(
        recording,
        model(),
        comparison.test_function,
        comparison.heldout_fraction,
    )
    .unwrap();
    let rule = EvidenceSettings::default();
    let block_rows = 25;
    let mut set = FittedSet {
        parameters: [EffectId::LinearDrag, EffectId::Wind]
            .into_iter()
            .flat_map(EffectNumber::all_of)
            .collect(),
        values: vec![0.3, 0.3, 0.4, 0.0, 0.0, 0.0],
    };
    set.refit(&problem, 40);
    let judged = evidence::apply(&problem, set, &rule, 20, block_rows);
    assert_eq!(judged.set.ids(), [EffectId::LinearDrag, EffectId::Wind]);
    let how = Separate {
        settings: &rule,
        iterations: 20,
        block_rows,
    };
    let separation = separate(&problem, judged, &how);
    let [replaced] = separation.replaced.as_slice() else {
        panic!("{:?}", separation.replaced);
    };
    assert!(
        replaced.id == EffectId::Wind && replaced.inseparable(),
        "{replaced:?}"
    );
    let mut ids = separation.judgement.set.ids();
    ids.sort_by_key(|id| id.name());
    assert_eq!(ids, [EffectId::LinearDrag, EffectId::ThrustScale]);
    let k = separation.judgement.set.effects().thrust_scale.unwrap().k;
    assert!((k - 0.95).abs() < 0.01, "{k}");
}

/// A simulated log is new at every row: nothing to say. Its motor commands held for five rows,
/// one motor barely moving (rounded, it changes every 40 rows only): the timing limit is the held
/// commands' interval, not the slow motor's.
#[test]
fn held_commands_set_the_timing_limit() {
    let mut log = simulate(&model(), &scenario(Effects::default(), 12), "held.csv").unwrap();
    assert_eq!(content::measure(&log), None);
    let held: Vec<[f64; 4]> = (0..log.len())
        .map(|k| {
            let mut u: [f64; 4] = log.motor_command.row(k - k % 5).try_into().unwrap();
            u[1] = 1500.0 + (k / 40) as f64;
            u
        })
        .collect();
    log.motor_command = held.into_iter().collect();
    let measured = content::measure(&log).expect("held commands");
    let commands = measured
        .signals
        .iter()
        .find(|s| s.signal == Signal::MotorCommands)
        .unwrap();
    assert_eq!(commands.pattern, ColumnPattern::Held);
    let limit = measured.timing_limit_s.unwrap();
    assert!((limit - 0.1).abs() < 0.002, "{limit}");
    assert!((measured.row_rate_hz - 50.0).abs() < 0.01);
}

/// Rotor drag proportional to the thrust (`rotor_drag`, not in the screen's library) on a flight
/// whose thrust varies: the screen finds a drag along the body axes, and the stand-in explains the
/// recording better, so it takes the drag's place and is named instead.
#[test]
fn a_stand_in_that_explains_better_replaces_the_named_effect() {
    let effects = Effects {
        rotor_drag: Some(RotorDrag { d: [0.35, 0.15] }),
        ..Effects::default()
    };
    let log = simulate(&model(), &scenario(effects, 15), "rotor.csv").unwrap();
    let analysis = analyze(&log, &model(), "demo", &settings()).unwrap();
    let report = &analysis.report;
    let named: Vec<EffectId> = report.effects.iter().map(|e| e.id).collect();
    assert_eq!(
        named,
        [EffectId::RotorDrag],
        "{:?}",
        report.selection.replaced
    );
    let replaced = &report.selection.replaced;
    assert!(
        replaced.len() == 1 && replaced[0].id == EffectId::LinearDrag,
        "{replaced:?}"
    );
    let d = analysis.fitted.rotor_drag.unwrap().d;
    assert!(
        (d[0] - 0.35).abs() < 0.03 && (d[1] - 0.15).abs() < 0.05,
        "{d:?}"
    );
}
