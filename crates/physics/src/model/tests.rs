//! Reading nominal models: mixers of 4 to 8 rotors, vehicles, the JSON policy, errors naming the field.

use super::*;

const MIXER_MODEL: &str = r#"{"mass_kg": 1.8, "gravity_m_s2": 9.81, "inertia_kg_m2": [0.02, 0.02, 0.035],
    "thrust_source": "mixer",
    "mixer": {"pwm_offset": 1000.0, "pwm_scale": 1000.0,
              "b0": [[9.7, 9.7, 9.7, 9.7], [-1.0, 1.0, 1.0, -1.0], [1.0, -1.0, 1.0, -1.0], [0.15, 0.15, -0.15, -0.15]]}}"#;

fn parse(text: &str) -> Result<NominalModel> {
    NominalModel::from_json(text, Path::new("model.json"))
}

#[test]
fn a_key_given_twice_is_refused_and_a_byte_order_mark_accepted() {
    let twice = r#"{"mass_kg": 2.644, "mass_kg": 100.0, "gravity_m_s2": 9.81,
        "inertia_kg_m2": [0.03, 0.03, 0.05], "thrust_source": "T_sp"}"#;
    let message = parse(twice).unwrap_err().to_string();
    assert!(
        message.contains("model.json") && message.contains("mass_kg"),
        "{message}"
    );
    let with_mark = format!("\u{feff}{}", twice.replacen(r#""mass_kg": 100.0, "#, "", 1));
    assert_eq!(parse(&with_mark).unwrap().mass_kg, 2.644);
}

#[test]
fn reads_a_mixer_model_and_inverts_the_mixer() {
    let model = parse(MIXER_MODEL).unwrap();
    assert!(model.predicts_torque());
    let mixer = model.mixer.as_ref().unwrap();
    let speeds = [0.6, 0.7, 0.65, 0.62, 0.0, 0.0, 0.0, 0.0];
    let back = mixer.speeds_for(&mixer.wrench(&speeds));
    for i in 0..4 {
        assert!((back[i] - speeds[i]).abs() < 1e-12);
    }
}

#[test]
fn a_hexarotor_is_read_from_its_mixer_or_its_vehicle_and_nine_rotors_are_refused() {
    let hexa = VehicleDescription::hexa_x(0.17, 6.0, 0.016).unwrap();
    let by_vehicle = format!(
        r#"{{"mass_kg": 1.8, "gravity_m_s2": 9.81, "inertia_kg_m2": [0.02, 0.02, 0.035],
            "thrust_source": "mixer", "vehicle": {}}}"#,
        hexa.to_json()
    );
    let model = parse(&by_vehicle).unwrap();
    assert_eq!((model.actuator_count(), model.motor_count()), (6, Some(6)));
    let mixer = model.mixer.as_ref().unwrap();
    let rows: [Vec<f64>; 4] = std::array::from_fn(|i| mixer.row(i).to_vec());
    let written = serde_json::json!({"pwm_offset": 1000.0, "pwm_scale": 1000.0, "b0": rows});
    let by_mixer = MIXER_MODEL.replace(
        &MIXER_MODEL[MIXER_MODEL.find("{\"pwm_offset").unwrap()..MIXER_MODEL.len() - 1],
        &written.to_string(),
    );
    let read = parse(&by_mixer).unwrap();
    assert_eq!(read.actuator_count(), 6);
    // PX4's linear map: half command, half thrust; the mixer's: half speed, a quarter.
    let half_command = model.actuator_command(0.0, 1.0, &[0.5; 6], None);
    assert!((model.wrench(&half_command).thrust - 18.0).abs() < 1e-12);
    let half_speed = read.actuator_command(0.0, 1.0, &[1500.0; 6], None);
    assert!((read.wrench(&half_speed).thrust - 9.0).abs() < 1e-12);
    let nine = by_mixer.replace(
        "[6.0,6.0,6.0,6.0,6.0,6.0]",
        "[6.0,6.0,6.0,6.0,6.0,6.0,6.0,6.0,6.0]",
    );
    let error = parse(&nine).unwrap_err().to_string();
    assert!(
        error.contains("mixer.b0[0]") && error.contains("4 to 8"),
        "{error}"
    );
}

#[test]
fn errors_name_the_field() {
    let missing = MIXER_MODEL.replace("\"mass_kg\": 1.8,", "");
    let error = parse(&missing).unwrap_err().to_string();
    assert!(
        error.contains("mass_kg") && error.contains("missing"),
        "{error}"
    );
    let bad_row = MIXER_MODEL.replace("[0.15, 0.15, -0.15, -0.15]", "[0.15, 0.15]");
    let error = parse(&bad_row).unwrap_err().to_string();
    assert!(error.contains("mixer.b0[3]"), "{error}");
    let singular = MIXER_MODEL.replace("[0.15, 0.15, -0.15, -0.15]", "[9.7, 9.7, 9.7, 9.7]");
    assert!(
        parse(&singular)
            .unwrap_err()
            .to_string()
            .contains("singular")
    );
    let source = MIXER_MODEL.replace("\"mixer\",", "\"motors\",");
    assert!(
        parse(&source)
            .unwrap_err()
            .to_string()
            .contains("thrust_source")
    );
    let inertia = MIXER_MODEL.replace("0.035]", "-0.035]");
    assert!(
        parse(&inertia)
            .unwrap_err()
            .to_string()
            .contains("inertia_kg_m2[2]")
    );
    assert!(!parse("{").unwrap_err().to_string().contains('\n'));
}

#[test]
fn unknown_fields_are_rejected_with_their_name() {
    let typo = MIXER_MODEL.replace("\"mass_kg\"", "\"ground_height\": 0.5, \"mass_kg\"");
    let error = parse(&typo).unwrap_err().to_string();
    assert!(
        error.contains("field 'ground_height'") && error.contains("unknown"),
        "{error}"
    );
    let in_mixer = MIXER_MODEL.replace("\"pwm_scale\"", "\"pwm_gain\": 2, \"pwm_scale\"");
    let error = parse(&in_mixer).unwrap_err().to_string();
    assert!(error.contains("field 'mixer.pwm_gain'"), "{error}");
    let spelled_out = MIXER_MODEL.replace("\"mass_kg\"", "\"ground_height_m\": 0.5, \"mass_kg\"");
    assert_eq!(parse(&spelled_out).unwrap().ground_height_m, 0.5);
}

#[test]
fn the_thrust_row_of_the_mixer_must_be_positive() {
    let negative = MIXER_MODEL.replace("[9.7, 9.7, 9.7, 9.7]", "[9.7, 9.7, -9.7, 9.7]");
    let error = parse(&negative).unwrap_err().to_string();
    assert!(error.contains("mixer.b0[0][2]"), "{error}");
}

#[test]
fn thrust_setpoint_model_scales_by_hover_throttle() {
    let model = parse(
        r#"{"mass_kg": 2.644, "gravity_m_s2": 9.81, "inertia_kg_m2": [0.03, 0.03, 0.05], "thrust_source": "T_sp"}"#,
    )
    .unwrap();
    let command = model.actuator_command(0.5, 0.5, &[], None);
    assert!((model.wrench(&command).thrust - 2.644 * 9.81).abs() < 1e-12);
    let level = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let a = model.translational_acceleration(&level, 2.644 * 9.81);
    assert!(a.iter().all(|v| v.abs() < 1e-12));
}
