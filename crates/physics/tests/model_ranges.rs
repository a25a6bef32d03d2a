//! Every number of a nominal model file is checked against its physical range when it is read
//! (issue 31, class 11): each numeric field of a valid model, set to an absurd value (zero or a
//! negative where the quantity is positive, far above or below its range, a number written as a
//! string, null), is refused with one line naming the file and the field. Seeded: every run tries
//! the same cases.

use std::path::Path;

use physics::NominalModel;
use physics::ranges::{self, PhysicalRange};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use serde_json::{Value, json};

/// A valid mixer model with every optional field given.
fn valid_model() -> Value {
    json!({
        "mass_kg": 1.8,
        "gravity_m_s2": 9.81,
        "inertia_kg_m2": [0.02, 0.02, 0.035],
        "thrust_source": "mixer",
        "mixer": {
            "pwm_offset": 1000.0,
            "pwm_scale": 1000.0,
            "b0": [[9.0, 9.0, 9.0, 9.0], [-1.08, 1.08, 1.08, -1.08],
                   [1.08, -1.08, 1.08, -1.08], [0.144, 0.144, -0.144, -0.144]]
        },
        "ground_height_m": 0.0,
        "logger": {"command": "sample", "command_time_offset_s": 0.002,
                   "rate_low_pass_hz": 40.0, "controller_rate_hz": 500.0}
    })
}

/// A numeric field of the model: its JSON pointer, its name in errors, and its range.
struct NumericField {
    pointer: String,
    name: String,
    min: f64,
    max: f64,
    /// Whether null means absent (a valid value) for this field.
    optional: bool,
}

fn field(pointer: &str, name: &str, range: (f64, f64)) -> NumericField {
    NumericField {
        pointer: pointer.to_string(),
        name: name.to_string(),
        min: range.0,
        max: range.1,
        optional: name == "logger.rate_low_pass_hz" || name == "logger.controller_rate_hz",
    }
}

fn bounds(range: &PhysicalRange) -> (f64, f64) {
    (range.min, range.max)
}

/// Every numeric field of [`valid_model`].
fn numeric_fields() -> Vec<NumericField> {
    let mut fields = vec![
        field("/mass_kg", "mass_kg", bounds(&ranges::MASS_KG)),
        field(
            "/gravity_m_s2",
            "gravity_m_s2",
            bounds(&ranges::GRAVITY_M_S2),
        ),
        field(
            "/ground_height_m",
            "ground_height_m",
            bounds(&ranges::GROUND_HEIGHT_M),
        ),
        field(
            "/mixer/pwm_offset",
            "mixer.pwm_offset",
            bounds(&ranges::PWM_OFFSET),
        ),
        field(
            "/mixer/pwm_scale",
            "mixer.pwm_scale",
            bounds(&ranges::PWM_SCALE),
        ),
        field(
            "/logger/command_time_offset_s",
            "logger.command_time_offset_s",
            (
                -physics::MAX_COMMAND_OFFSET_S,
                physics::MAX_COMMAND_OFFSET_S,
            ),
        ),
        field(
            "/logger/rate_low_pass_hz",
            "logger.rate_low_pass_hz",
            (physics::MIN_RATE_LOW_PASS_HZ, physics::MAX_RATE_LOW_PASS_HZ),
        ),
        field(
            "/logger/controller_rate_hz",
            "logger.controller_rate_hz",
            bounds(&ranges::CONTROLLER_RATE_HZ),
        ),
    ];
    for i in 0..3 {
        fields.push(field(
            &format!("/inertia_kg_m2/{i}"),
            &format!("inertia_kg_m2[{i}]"),
            bounds(&ranges::INERTIA_KG_M2),
        ));
    }
    for i in 0..4 {
        let range = if i == 0 {
            &ranges::ROTOR_THRUST_N
        } else {
            &ranges::ROTOR_TORQUE_N_M
        };
        for j in 0..4 {
            fields.push(field(
                &format!("/mixer/b0/{i}/{j}"),
                &format!("mixer.b0[{i}][{j}]"),
                bounds(range),
            ));
        }
    }
    fields
}

/// An absurd value for a field.
#[derive(Clone, Debug)]
enum Absurd {
    /// Zero (only for a quantity whose range excludes it).
    Zero,
    /// Minus the field's valid value (only for a quantity whose range is not negative).
    Negative,
    /// Ten to the power `0..=300` times the top of the range, times ten.
    Huge(i32),
    /// The bottom of a positive range divided by ten to the power `1..=300`.
    Tiny(i32),
    /// A number in a string: `"NaN"`, `"inf"`, `"1e300"`, `"1.8"`.
    Text(&'static str),
    /// Null (only for a field that null does not leave out).
    Null,
}

fn absurd() -> impl Strategy<Value = Absurd> {
    prop_oneof![
        Just(Absurd::Zero),
        Just(Absurd::Negative),
        (0..=300i32).prop_map(Absurd::Huge),
        (1..=300i32).prop_map(Absurd::Tiny),
        prop::sample::select(vec!["NaN", "inf", "1e300", "1.8"]).prop_map(Absurd::Text),
        Just(Absurd::Null),
    ]
}

/// The value `kind` stands for in `field` (whose valid value is `valid`), or `None` when that kind
/// would be a valid value of the field.
fn absurd_value(kind: &Absurd, field: &NumericField, valid: f64) -> Option<Value> {
    let number = |x: f64| Some(json!(x));
    match *kind {
        Absurd::Zero if field.min > 0.0 => number(0.0),
        Absurd::Negative if field.min >= 0.0 && valid > 0.0 => number(-valid),
        Absurd::Huge(power) => {
            let value = 10.0 * field.max.abs().max(1.0) * 10f64.powi(power);
            value.is_finite().then(|| json!(value))
        }
        Absurd::Tiny(power) if field.min > 0.0 => number(field.min / 10f64.powi(power)),
        Absurd::Text(text) => Some(json!(text)),
        Absurd::Null if !field.optional => Some(Value::Null),
        _ => None,
    }
}

#[test]
fn every_numeric_field_set_to_an_absurd_value_is_refused_naming_it() {
    let fields = numeric_fields();
    let model = valid_model();
    assert!(NominalModel::from_json(&model.to_string(), Path::new("model.json")).is_ok());
    let config = Config {
        cases: 256,
        failure_persistence: None,
        ..Config::default()
    };
    let mut runner =
        TestRunner::new_with_rng(config, TestRng::from_seed(RngAlgorithm::ChaCha, &[31; 32]));
    let strategy = (0..fields.len(), absurd());
    runner
        .run(&strategy, |(index, kind)| {
            let field = &fields[index];
            let valid = model.pointer(&field.pointer).unwrap().as_f64().unwrap();
            let Some(value) = absurd_value(&kind, field, valid) else {
                return Ok(());
            };
            let mut changed = model.clone();
            *changed.pointer_mut(&field.pointer).unwrap() = value.clone();
            let outcome = NominalModel::from_json(&changed.to_string(), Path::new("model.json"));
            let message = match outcome {
                Ok(_) => {
                    return Err(TestCaseError::fail(format!(
                        "{} = {value} accepted",
                        field.name
                    )));
                }
                Err(error) => error.to_string(),
            };
            prop_assert!(!message.contains('\n'), "not one line: {message}");
            prop_assert!(
                message.starts_with("model.json: field '")
                    && message.contains(&format!("'{}'", field.name)),
                "{} = {value}: the field is not named: {message}",
                field.name
            );
            Ok(())
        })
        .unwrap();
}

/// The reproductions, and the weight the rotors must lift.
#[test]
fn the_probes_values_are_refused_with_the_range() {
    let refused = |pointer: &str, value: Value| {
        let mut model = valid_model();
        *model.pointer_mut(pointer).unwrap() = value;
        NominalModel::from_json(&model.to_string(), Path::new("model.json"))
            .unwrap_err()
            .to_string()
    };
    assert_eq!(
        refused("/mass_kg", json!(1e300)),
        "model.json: field 'mass_kg': the vehicle's mass must be between 0.001 and 1000 kg, found 1e300"
    );
    let message = refused("/logger/controller_rate_hz", json!(1e-9));
    assert!(
        message.contains("'logger.controller_rate_hz'") && message.contains("between 1 and"),
        "{message}"
    );
    let message = refused("/gravity_m_s2", json!(1e308));
    assert!(message.contains("'gravity_m_s2'"), "{message}");
    // 20 kg in range, but 36 N of rotors cannot lift 196 N.
    let message = refused("/mass_kg", json!(20.0));
    assert!(
        message.contains("'mixer.b0[0]'") && message.contains("over the weight"),
        "{message}"
    );
}
