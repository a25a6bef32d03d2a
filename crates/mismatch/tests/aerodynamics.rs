//! The aerodynamics of real rotors that the single-recording analysis names: a rotor drag
//! proportional to the rotor speed (Gazebo's and PX4 SITL's form), screened as a drag along the
//! body axes and named in its place, and a torque from a drag acting above the centre of mass,
//! found on the angular channels instead of being absorbed as a wrong inertia. A log without
//! position is analysed without the ground effect.

use data::FlightLog;
use mismatch::{Analysis, analyze};
use physics::{AerodynamicTorque, AxialThrustLoss, Effects, RotorSpeedDrag, simulate};

mod common;

use common::{fast_settings, scenario};

/// The test scenario flown with `effects`, its log changed by `edit`, analysed; the analysis
/// must name `effects` alone.
fn named_alone(effects: Effects, seed: u64, edit: impl FnOnce(&mut FlightLog)) -> Analysis {
    let model = common::model_for_scenario();
    let mut log = simulate(&model, &scenario(effects, seed), "aerodynamics").unwrap();
    edit(&mut log);
    let analysis = analyze(&log, &model, "demo", &fast_settings()).unwrap();
    assert_eq!(analysis.fitted.ids(), effects.ids());
    analysis
}

fn rotor_speed_drag() -> Effects {
    Effects {
        rotor_speed_drag: Some(RotorSpeedDrag { d: [0.35, 0.1] }),
        ..Effects::default()
    }
}

fn assert_rotor_speed_drag(analysis: &Analysis) {
    let d = analysis.fitted.rotor_speed_drag.unwrap().d;
    assert!(
        (d[0] - 0.35).abs() < 0.02 && (d[1] - 0.1).abs() < 0.02,
        "{d:?}"
    );
}

#[test]
fn a_rotor_drag_proportional_to_the_rotor_speed_is_named_in_place_of_a_body_axis_drag() {
    let analysis = named_alone(rotor_speed_drag(), 41, |_| {});
    assert_rotor_speed_drag(&analysis);
}

#[test]
fn a_torque_from_drag_above_the_centre_of_mass_is_named_not_an_inertia() {
    let effects = Effects {
        aerodynamic_torque: Some(AerodynamicTorque { k: [0.4, 0.3] }),
        ..Effects::default()
    };
    let analysis = named_alone(effects, 42, |_| {});
    let k = analysis.fitted.aerodynamic_torque.unwrap().k;
    assert!(
        (k[0] - 0.4).abs() < 0.03 && (k[1] - 0.3).abs() < 0.03,
        "{k:?}"
    );
}

/// A log without position (a layout may leave it out): the ground effect is not looked for, the
/// rest is analysed as with it, and the report says what is missing.
#[test]
fn a_log_without_position_is_analysed_without_the_ground_effect() {
    let analysis = named_alone(rotor_speed_drag(), 41, |log| {
        log.position = vec![[f64::NAN; 3]; log.len()];
    });
    assert_rotor_speed_drag(&analysis);
    let json = serde_json::to_value(&analysis.report).unwrap();
    assert_eq!(json["not_logged"], serde_json::json!(["position"]));
    let screened: Vec<&str> = json["selection"]["candidates"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["id"].as_str().unwrap())
        .collect();
    assert!(!screened.contains(&"ground_effect"), "{screened:?}");
    assert!(screened.contains(&"linear_drag"), "{screened:?}");
}

/// A thrust loss with axial airspeed (`T ×= 1 − c v_bz`) is the axial part of a rotor drag
/// proportional to the thrust, `dv = g c`: it is named so, in place of the body-axis drag.
#[test]
fn a_thrust_loss_with_axial_airspeed_is_named_as_the_rotor_drags_axial_part() {
    let effects = Effects {
        axial_thrust_loss: Some(AxialThrustLoss { c: 0.03 }),
        ..Effects::default()
    };
    let model = common::model_for_scenario();
    let log = simulate(&model, &scenario(effects, 43), "axial").unwrap();
    let analysis = analyze(&log, &model, "demo", &fast_settings()).unwrap();
    let d = analysis.fitted.rotor_drag.expect("a rotor drag").d;
    let axial = model.gravity_m_s2 * 0.03;
    assert!(d[0] < 0.02 && (d[1] - axial).abs() < 0.1 * axial, "{d:?}");
}
