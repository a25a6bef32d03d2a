//! The effects as documented in the module's table, and the registry's contract.

use super::*;
use crate::vector::Mat3;

#[test]
fn parses_the_vocabulary_and_rejects_unknown_ids() {
    let effects: Effects = serde_json::from_str(
        r#"{"quadratic_drag": {"c": 0.05}, "wind": {"w_air": [2, 0, 0]}, "delay": {"delay_s": 0.03}}"#,
    )
    .unwrap();
    assert_eq!(
        effects.ids(),
        [EffectId::QuadraticDrag, EffectId::Wind, EffectId::Delay]
    );
    assert!(effects.validate().is_ok());
    assert!(serde_json::from_str::<Effects>(r#"{"drag": {"c": 1}}"#).is_err());
    let lonely_wind: Effects = serde_json::from_str(r#"{"wind": {"w_air": [1, 0, 0]}}"#).unwrap();
    assert_eq!(lonely_wind.validate().unwrap_err().0, "wind");
}

/// Every effect present at once (the parameters are only placeholders; an effect added to the
/// registry later is present at its neutral values).
fn every_effect() -> Effects {
    let mut every = Effects {
        linear_drag: Some(LinearDrag { d: [0.1; 3] }),
        quadratic_drag: Some(QuadraticDrag { c: 0.1 }),
        wind: Some(Wind { w_air: [1.0; 3] }),
        thrust_scale: Some(ThrustScale { k: 0.9 }),
        motor_lag: Some(MotorLag { tau_s: 0.02 }),
        ground_effect: Some(GroundEffect { r_m: 0.3 }),
        torque_bias: Some(TorqueBias { b: [0.1; 3] }),
        inertia_scale: Some(InertiaScale { k: [1.1; 3] }),
        delay: Some(Delay { delay_s: 0.02 }),
        thrust_map: Some(ThrustMap { k: [1.0, 1.0, 0.0] }),
        thrust_tilt: Some(ThrustTilt {
            angles_rad: [0.01; 2],
        }),
        rotor_drag: Some(RotorDrag { d: [0.3, 0.1] }),
        translational_lift: Some(TranslationalLift { c: 0.001 }),
        drag_lag: Some(DragLag { tau_s: 0.2 }),
        wind_gradient: Some(WindGradient {
            per_m: [[0.0; 3]; 3],
            reference_m: [0.0; 3],
        }),
        ..Effects::default()
    };
    for id in EffectId::ALL {
        if !every.contains(id) {
            every.insert(id.neutral());
        }
    }
    every
}

/// Each id is the key of its effect in the JSON, and `contains`, `remove` and `ids` act on
/// exactly that effect.
#[test]
fn the_ids_are_the_keys_of_the_effects() {
    let every = every_effect();
    assert_eq!(every.ids(), EffectId::ALL);
    let json = serde_json::to_value(every).unwrap();
    let mut keys: Vec<&str> = json
        .as_object()
        .unwrap()
        .keys()
        .map(|k| k.as_str())
        .collect();
    let mut names = EffectId::ALL.map(EffectId::name);
    keys.sort_unstable();
    names.sort_unstable();
    assert_eq!(keys, names);
    for id in EffectId::ALL {
        let mut without = every;
        without.remove(id);
        assert!(every.contains(id) && !without.contains(id));
        let json = serde_json::to_value(without).unwrap();
        assert!(json.get(id.name()).is_none(), "{id}");
        assert_eq!(json.as_object().unwrap().len(), EffectId::ALL.len() - 1);
    }
}

/// An effect's typed parameters serialise exactly as its entry in the set's JSON, and know
/// their id; absent effects have none.
#[test]
fn typed_parameters_are_the_entries_of_the_set() {
    let every = every_effect();
    let json = serde_json::to_value(every).unwrap();
    for id in EffectId::ALL {
        let parameters = every.parameters(id).unwrap();
        assert_eq!(parameters.id(), id);
        assert_eq!(serde_json::to_value(parameters).unwrap(), json[id.name()]);
        assert!(Effects::default().parameters(id).is_none(), "{id}");
    }
}

/// The named values of each effect's parameters are its JSON entry's keys, in order, with its
/// values; their display is the compact JSON of the value.
#[test]
fn named_values_are_the_entries_keys_and_values() {
    let every = every_effect();
    let json = serde_json::to_value(every).unwrap();
    for id in EffectId::ALL {
        let values = every.parameters(id).unwrap().values();
        let entry = json[id.name()].as_object().unwrap();
        let keys: Vec<&str> = entry.keys().map(|k| k.as_str()).collect();
        let names: Vec<&str> = values.iter().map(|(name, _)| *name).collect();
        assert_eq!(names, keys, "{id}");
        for (name, value) in &values {
            assert_eq!(
                &serde_json::to_value(value).unwrap(),
                &entry[*name],
                "{id}.{name}"
            );
            assert_eq!(
                value.to_string(),
                entry[*name].to_string().replace(',', ", ")
            );
            assert_eq!(value.map(|x| x).numbers(), value.numbers());
        }
    }
    let matrix = ParameterValue::Matrix(vec![vec![1.0, 2.5], vec![3.0, 4.0]]);
    assert_eq!(matrix.numbers(), [1.0, 2.5, 3.0, 4.0]);
    assert_eq!(
        matrix.map(|x| 2.0 * x).to_string(),
        "[[2.0, 5.0], [6.0, 8.0]]"
    );
}

#[test]
fn drag_opposes_the_relative_air_velocity() {
    let effects = Effects {
        quadratic_drag: Some(QuadraticDrag { c: 0.1 }),
        wind: Some(Wind {
            w_air: [1.0, 0.0, 0.0],
        }),
        linear_drag: Some(LinearDrag { d: [0.5, 0.5, 0.2] }),
        ..Effects::default()
    };
    let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let a = effects.drag_acceleration(&identity, [3.0, 0.0, 0.0], [0.0; 3]);
    // quadratic: −0.1·2·2 = −0.4; linear: −0.5·(3 − 1) = −1.0
    assert!((a[0] + 1.4).abs() < 1e-12 && a[1] == 0.0 && a[2] == 0.0);
}

#[test]
fn ground_effect_grows_near_the_ground_and_is_capped() {
    let effects = Effects {
        ground_effect: Some(GroundEffect { r_m: 0.4 }),
        ..Effects::default()
    };
    let gain = |height: f64| effects.thrust_ratio(1.0, height, [0.0; 3]);
    assert!((gain(0.4) - 1.0 / (1.0 - 1.0 / 16.0)).abs() < 1e-12);
    assert!(gain(5.0) < 1.001);
    assert_eq!(gain(0.0), 2.0);
}

fn model() -> NominalModel {
    NominalModel::from_json(
        r#"{"mass_kg": 2.0, "gravity_m_s2": 10.0, "inertia_kg_m2": [0.03, 0.03, 0.05], "thrust_source": "T_sp"}"#,
        std::path::Path::new("m.json"),
    )
    .unwrap()
}

const LEVEL: Mat3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// The effects found on real vehicles, each on its own: a thrust map, a tilted thrust axis,
/// rotor drag scaled by the thrust, translational lift, and air that varies in space.
#[test]
fn the_vehicle_effects_act_as_documented() {
    let m = model();
    let hover = 20.0;
    let map = Effects {
        thrust_map: Some(ThrustMap {
            k: [0.98, 1.2, 0.5],
        }),
        ..Effects::default()
    };
    // Asking 1.5 m g gives 0.98 + 1.2 · 0.5 + 0.5 · 0.25 = 1.705 m g.
    let a = map.translational_acceleration(&m, &LEVEL, [0.0; 3], [0.0, 0.0, 5.0], 1.5 * hover);
    assert!((a[2] - (10.0 * 1.705 - 10.0)).abs() < 1e-12, "{a:?}");
    let tilt = Effects {
        thrust_tilt: Some(ThrustTilt {
            angles_rad: [0.0, 0.1],
        }),
        ..Effects::default()
    };
    let a = tilt.translational_acceleration(&m, &LEVEL, [0.0; 3], [0.0, 0.0, 5.0], hover);
    assert!((a[0] - 10.0 * 0.1f64.sin()).abs() < 1e-12 && a[1].abs() < 1e-12);
    let drag = Effects {
        rotor_drag: Some(RotorDrag { d: [0.3, 0.6] }),
        wind: Some(Wind {
            w_air: [1.0, 0.0, 0.0],
        }),
        ..Effects::default()
    };
    // At twice the hover thrust the drag doubles: −2 · 0.3 · (3 − 1) edgewise, −2 · 0.6 · 1 axial.
    let a =
        drag.translational_acceleration(&m, &LEVEL, [3.0, 0.0, 1.0], [0.0, 0.0, 5.0], 2.0 * hover);
    assert!(
        (a[0] + 1.2).abs() < 1e-12 && (a[2] - (20.0 - 10.0 - 1.2)).abs() < 1e-12,
        "{a:?}"
    );
    let lift = Effects {
        translational_lift: Some(TranslationalLift { c: 0.01 }),
        ..Effects::default()
    };
    let a = lift.translational_acceleration(&m, &LEVEL, [3.0, 4.0, 0.0], [0.0, 0.0, 5.0], hover);
    assert!((a[2] - 10.0 * 0.25).abs() < 1e-12, "{a:?}");
    let field = Effects {
        quadratic_drag: Some(QuadraticDrag { c: 0.1 }),
        wind: Some(Wind {
            w_air: [2.0, 0.0, 0.0],
        }),
        wind_gradient: Some(WindGradient {
            per_m: [[0.0, 0.0, 0.5], [0.0; 3], [0.0; 3]],
            reference_m: [0.0, 0.0, 1.0],
        }),
        ..Effects::default()
    };
    // At 3 m the air moves at 2 + 0.5 · 2 = 3 m/s: a vehicle at rest feels −0.1 · 3 · (−3).
    assert_eq!(field.air_velocity_at([0.0, 0.0, 3.0]), [3.0, 0.0, 0.0]);
    let a = field.drag_acceleration(&LEVEL, [0.0; 3], [0.0, 0.0, 3.0]);
    assert!((a[0] - 0.9).abs() < 1e-12, "{a:?}");
    assert!(field.validate().is_ok());
    let without_wind = Effects {
        wind: None,
        ..field
    };
    assert_eq!(without_wind.validate().unwrap_err().0, "wind_gradient");
    let tilted_far = Effects {
        thrust_tilt: Some(ThrustTilt {
            angles_rad: [0.0, 0.9],
        }),
        ..Effects::default()
    };
    assert_eq!(
        tilted_far.validate().unwrap_err().0,
        "thrust_tilt.angles_rad"
    );
}

/// Every effect, through the registry: its numbers read back as the same parameters, its neutral
/// values leave the equations of motion unchanged and lie within its fit ranges, and its
/// description is a sentence.
#[test]
fn every_registered_effect_keeps_the_registry_contract() {
    let m = model();
    let rotation: Mat3 = [[0.8, -0.6, 0.0], [0.6, 0.8, 0.0], [0.0, 0.0, 1.0]];
    let (velocity, position, rate, torque) = (
        [1.0, -2.0, 0.5],
        [0.3, 0.2, 0.7],
        [0.2, -0.1, 0.3],
        [0.01, 0.02, -0.01],
    );
    let nominal = Effects::default();
    let every = every_effect();
    for id in EffectId::ALL {
        let parameters = every.parameters(id).unwrap();
        let numbers = parameters.numbers();
        assert_eq!(
            EffectParameters::from_numbers(id, &numbers),
            parameters,
            "{id}"
        );
        assert_eq!(EffectNumber::all_of(id).len(), numbers.len(), "{id}");
        let mut neutral = Effects::default();
        neutral.insert(id.neutral());
        assert_eq!(
            neutral.translational_acceleration(&m, &rotation, velocity, position, 25.0),
            nominal.translational_acceleration(&m, &rotation, velocity, position, 25.0),
            "{id}"
        );
        assert_eq!(
            neutral.angular_acceleration(&m, rate, torque, velocity),
            nominal.angular_acceleration(&m, rate, torque, velocity),
            "{id}"
        );
        for number in EffectNumber::all_of(id) {
            let (low, high) = number.fit_range();
            assert!(
                low <= number.neutral() && number.neutral() <= high,
                "{number:?}"
            );
            assert!(number.typical() > 0.0, "{number:?}");
        }
        let sentence = parameters.describe(m.gravity_m_s2);
        assert!(
            sentence.ends_with('.') && sentence.len() > 20,
            "{id}: {sentence}"
        );
    }
}

/// Adding a number to an absent effect starts it at its neutral values; removing the only drag
/// removes the wind (and its gradient) that acted through it.
#[test]
fn numbers_are_set_and_dependants_removed_through_the_registry() {
    let mut effects = Effects::default();
    effects.set_number(EffectNumber::new(EffectId::InertiaScale, 1), 1.2);
    assert_eq!(
        effects.inertia_scale,
        Some(InertiaScale { k: [1.0, 1.2, 1.0] })
    );
    let every = every_effect();
    let mut drags_gone = every
        .without(EffectId::LinearDrag)
        .without(EffectId::QuadraticDrag);
    assert!(drags_gone.contains(EffectId::Wind));
    drags_gone = drags_gone.without(EffectId::RotorDrag);
    assert!(drags_gone.contains(EffectId::Wind));
    drags_gone = drags_gone.without(EffectId::RotorSpeedDrag);
    assert!(!drags_gone.contains(EffectId::Wind) && !drags_gone.contains(EffectId::WindGradient));
    assert!(drags_gone.validate().is_ok());
}

/// The effect added as one file: climbing through the air at 2 m/s with `c = 0.1 s/m` leaves
/// 80% of the thrust; descending does not add any beyond `1 + c |v_bz|`, and it is checked.
#[test]
fn axial_thrust_loss_acts_as_documented() {
    let m = model();
    let hover = 20.0;
    let loss = Effects {
        axial_thrust_loss: Some(AxialThrustLoss { c: 0.1 }),
        ..Effects::default()
    };
    let climbing =
        loss.translational_acceleration(&m, &LEVEL, [0.0, 0.0, 2.0], [0.0, 0.0, 5.0], hover);
    assert!(
        (climbing[2] - (10.0 * 0.8 - 10.0)).abs() < 1e-12,
        "{climbing:?}"
    );
    let descending =
        loss.translational_acceleration(&m, &LEVEL, [0.0, 0.0, -2.0], [0.0, 0.0, 5.0], hover);
    assert!(
        (descending[2] - (10.0 * 1.2 - 10.0)).abs() < 1e-12,
        "{descending:?}"
    );
    let negative = Effects {
        axial_thrust_loss: Some(AxialThrustLoss { c: -0.1 }),
        ..Effects::default()
    };
    assert_eq!(negative.validate().unwrap_err().0, "axial_thrust_loss.c");
}

/// Rotor drag proportional to the rotor speed: at four times the hover thrust it doubles (the
/// speeds double), against the airspeed; a negative coefficient is refused.
#[test]
fn rotor_speed_drag_grows_with_the_square_root_of_the_thrust() {
    let m = model();
    let hover = 20.0;
    let drag = Effects {
        rotor_speed_drag: Some(RotorSpeedDrag { d: [0.3, 0.6] }),
        wind: Some(Wind {
            w_air: [1.0, 0.0, 0.0],
        }),
        ..Effects::default()
    };
    // −2 · 0.3 · (3 − 1) edgewise, −2 · 0.6 · 1 axial, on a thrust of 4 m g.
    let a =
        drag.translational_acceleration(&m, &LEVEL, [3.0, 0.0, 1.0], [0.0, 0.0, 5.0], 4.0 * hover);
    assert!(
        (a[0] + 1.2).abs() < 1e-12 && (a[2] - (40.0 - 10.0 - 1.2)).abs() < 1e-12,
        "{a:?}"
    );
    let at_hover = drag.translational_acceleration(&m, &LEVEL, [3.0, 0.0, 1.0], [0.0; 3], hover);
    assert!((at_hover[0] + 0.6).abs() < 1e-12, "{at_hover:?}");
    let negative = Effects {
        rotor_speed_drag: Some(RotorSpeedDrag { d: [-0.1, 0.0] }),
        ..Effects::default()
    };
    assert_eq!(negative.validate().unwrap_err().0, "rotor_speed_drag.d");
}

/// A drag acting above the centre of mass pitches the nose up in forward flight and rolls away
/// from a sideways airspeed; the torque follows the air, not the ground speed.
#[test]
fn aerodynamic_torque_follows_the_body_airspeed() {
    let m = model();
    let effects = Effects {
        aerodynamic_torque: Some(AerodynamicTorque { k: [0.5, 0.25] }),
        linear_drag: Some(LinearDrag { d: [0.1; 3] }),
        wind: Some(Wind {
            w_air: [1.0, 0.0, 0.0],
        }),
        ..Effects::default()
    };
    let air_body = effects.body_airspeed(&LEVEL, [3.0, 2.0, 0.0], [0.0; 3]);
    assert_eq!(air_body, [2.0, 2.0, 0.0]);
    let nominal = Effects::default().angular_acceleration(&m, [0.0; 3], [0.0; 3], air_body);
    let a = effects.angular_acceleration(&m, [0.0; 3], [0.0; 3], air_body);
    assert_eq!(nominal, [0.0; 3]);
    assert!(
        (a[0] - 1.0).abs() < 1e-12 && (a[1] + 0.5).abs() < 1e-12 && a[2] == 0.0,
        "{a:?}"
    );
    let nan = Effects {
        aerodynamic_torque: Some(AerodynamicTorque { k: [f64::NAN, 0.0] }),
        ..Effects::default()
    };
    assert_eq!(nan.validate().unwrap_err().0, "aerodynamic_torque.k");
}

/// A profile search tries only values a fit may keep: every grid point inside the number's fit
/// range, both ends reached, and the profiled numbers (ground radius, delay, motor lag) present.
#[test]
fn every_profile_grid_spans_its_fit_range() {
    let mut profiled = Vec::new();
    for id in EffectId::ALL {
        for number in EffectNumber::all_of(id) {
            let grid = number.profile_grid();
            if grid.is_empty() {
                continue;
            }
            let (low, high) = number.fit_range();
            assert!(
                grid.iter().all(|v| (low..=high + 1e-12).contains(v)),
                "{number:?}"
            );
            assert_eq!(grid[0], low, "{number:?}");
            assert!((grid[grid.len() - 1] - high).abs() < 1e-9, "{number:?}");
            profiled.push(id);
        }
    }
    assert_eq!(
        profiled,
        [EffectId::MotorLag, EffectId::GroundEffect, EffectId::Delay]
    );
}
