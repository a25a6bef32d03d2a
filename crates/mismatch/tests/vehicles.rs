//! Vehicles other than the demo's quadrotor: a hexarotor's flight analysed with its six motor
//! commands, a vehicle whose thrust map reads the logged battery voltage, and a recording whose
//! motor count does not match the model refused with a one-line error.

use mismatch::analyze;
use physics::{
    Battery, EffectId, Effects, MotorLag, NominalModel, Scenario, ThrustScale, simulate,
};

mod common;

use common::{fast_settings, scenario};

/// The hexarotor of the vehicles matrix (six rotors on a 0.17 m ring), with the test scenario's
/// logger.
fn hexarotor() -> NominalModel {
    NominalModel {
        logger: scenario(Effects::default(), 0).logger(),
        ..common::model("vehicles/hexa-x.json")
    }
}

#[test]
fn a_hexarotor_thrust_loss_and_motor_lag_are_found_through_its_six_rotors() {
    let model = hexarotor();
    let effects = Effects {
        thrust_scale: Some(ThrustScale { k: 0.92 }),
        motor_lag: Some(MotorLag { tau_s: 0.05 }),
        ..Effects::default()
    };
    let log = simulate(&model, &scenario(effects, 21), "hexa").unwrap();
    assert_eq!(log.motor_command.count(), 6);
    let analysis = analyze(&log, &model, "demo", &fast_settings()).unwrap();
    assert_eq!(
        analysis.fitted.ids(),
        [EffectId::ThrustScale, EffectId::MotorLag]
    );
    let k = analysis.fitted.thrust_scale.unwrap().k;
    let tau = analysis.fitted.motor_lag.unwrap().tau_s;
    assert!((k - 0.92).abs() < 0.01, "{k}");
    assert!((tau - 0.05).abs() < 0.01, "{tau}");
}

#[test]
fn a_recording_with_another_motor_count_is_refused_naming_both() {
    let quad = common::model_for_scenario();
    let log = simulate(&quad, &scenario(Effects::default(), 22), "quad").unwrap();
    let message = analyze(&log, &hexarotor(), "demo", &fast_settings())
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("4 motor commands a row") && message.contains("6 rotors"),
        "{message}"
    );
    assert!(!message.contains('\n'), "{message}");
}

/// A quadrotor whose rotors' thrust depends on the battery voltage (a voltage polynomial through
/// its vehicle description), flown on a battery that drains and sags: nothing is named on the
/// control, and a concealed thrust loss is found through the logged voltage.
#[test]
fn a_voltage_dependent_thrust_map_reads_the_logged_voltage() {
    let model = NominalModel {
        logger: scenario(Effects::default(), 0).logger(),
        ..common::model("vehicles/quad-voltage.json")
    };
    let flight = |effects: Effects, seed: u64| {
        let scenario = Scenario {
            battery: Some(Battery {
                voltage_v: 16.4,
                drop_v_per_s: 0.02,
                sag_v_per_n: 0.02,
            }),
            ..scenario(effects, seed)
        };
        simulate(&model, &scenario, "voltage").unwrap()
    };
    let control = analyze(
        &flight(Effects::default(), 23),
        &model,
        "demo",
        &fast_settings(),
    )
    .unwrap();
    assert!(
        control.report.effects.is_empty(),
        "{:?}",
        control.report.effects
    );
    let effects = Effects {
        thrust_scale: Some(ThrustScale { k: 0.93 }),
        ..Effects::default()
    };
    let analysis = analyze(&flight(effects, 24), &model, "demo", &fast_settings()).unwrap();
    assert_eq!(analysis.fitted.ids(), [EffectId::ThrustScale]);
    let k = analysis.fitted.thrust_scale.unwrap().k;
    assert!((k - 0.93).abs() < 0.01, "{k}");
}
