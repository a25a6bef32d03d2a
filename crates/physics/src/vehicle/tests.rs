//! The allocation of each layout against matrices written by hand, the command maps, layout
//! recognition, and the JSON policy.

use std::path::Path;

use super::*;

const K: f64 = 0.02;

fn assert_rows(vehicle: &VehicleDescription, expected: [&[f64]; 4]) {
    let rows = vehicle.allocation().rows();
    for (r, (got, want)) in rows.iter().zip(expected).enumerate() {
        assert_eq!(got.len(), want.len(), "row {r}");
        for (i, (g, w)) in got.iter().zip(want).enumerate() {
            assert!((g - w).abs() < 1e-12, "row {r} rotor {i}: {g} against {w}");
        }
    }
}

#[test]
fn quad_x_allocation_is_the_hand_written_matrix() {
    // Arm √2 · 0.1: rotors at (±0.1, ±0.1); τ = r × (0, 0, F) = (y F, −x F, 0), yaw ∓ km F.
    let quad = VehicleDescription::quad_x(0.1 * 2f64.sqrt(), 6.5, K).unwrap();
    let d = 0.1;
    assert_rows(
        &quad,
        [
            &[1.0, 1.0, 1.0, 1.0],
            &[-d, d, d, -d],
            &[-d, d, -d, d],
            &[-K, -K, K, K],
        ],
    );
    assert_eq!(quad.layout(), Layout::QuadX);
    assert_eq!(quad.allocation().rank(), 4);
}

#[test]
fn quad_plus_allocation_is_the_hand_written_matrix() {
    let a = 0.2;
    let quad = VehicleDescription::quad_plus(a, 6.5, K).unwrap();
    assert_rows(
        &quad,
        [
            &[1.0, 1.0, 1.0, 1.0],
            &[-a, a, 0.0, 0.0],
            &[0.0, 0.0, -a, a],
            &[-K, -K, K, K],
        ],
    );
    assert_eq!(quad.layout(), Layout::QuadPlus);
}

#[test]
fn hexa_plus_allocation_is_the_hand_written_matrix() {
    // Rotor k at k · 60° from the nose towards the left, arm 0.2: (0.2, 0), (0.1, 0.1732…), …
    let hexa = VehicleDescription::hexa_plus(0.2, 6.5, K).unwrap();
    let h = 0.1 * 3f64.sqrt();
    assert_rows(
        &hexa,
        [
            &[1.0; 6],
            &[0.0, h, h, 0.0, -h, -h],
            &[-0.2, -0.1, 0.1, 0.2, 0.1, -0.1],
            &[-K, K, -K, K, -K, K],
        ],
    );
    assert_eq!(hexa.layout(), Layout::HexaPlus);
    assert_eq!(
        VehicleDescription::hexa_x(0.2, 6.5, K).unwrap().layout(),
        Layout::HexaX
    );
}

#[test]
fn octo_x_allocation_is_the_hand_written_matrix() {
    // Arm 1: rotors at 22.5° + k · 45°; cos 22.5° = 0.92388, sin 22.5° = 0.38268.
    let octo = VehicleDescription::octo_x(1.0, 6.5, K).unwrap();
    let (c, s) = (0.923_879_532_511_286_7, 0.382_683_432_365_089_8);
    assert_rows(
        &octo,
        [
            &[1.0; 8],
            &[s, c, c, s, -s, -c, -c, -s],
            &[-c, -s, s, c, c, s, -s, -c],
            &[-K, K, -K, K, -K, K, -K, K],
        ],
    );
    assert_eq!(octo.layout(), Layout::OctoX);
    assert_eq!(
        VehicleDescription::octo_plus(1.0, 6.5, K).unwrap().layout(),
        Layout::OctoPlus
    );
}

#[test]
fn coaxial_pairs_separate_yaw_only_through_km() {
    // X8: arms at 45° + k · 90°, rotors at (±0.1, ±0.1, ±0.05), upper first; the height does not
    // enter the torques of vertical rotors.
    let x8 = VehicleDescription::coaxial(4, 0.1 * 2f64.sqrt(), 0.1, 6.5, K).unwrap();
    let d = 0.1;
    assert_rows(
        &x8,
        [
            &[1.0; 8],
            &[d, d, d, d, -d, -d, -d, -d],
            &[-d, -d, d, d, d, d, -d, -d],
            &[-K, K, K, -K, -K, K, K, -K],
        ],
    );
    assert_eq!(x8.layout(), Layout::Coaxial { arms: 4 });
    assert_eq!(x8.allocation().rank(), 4);
    // Without km an upper and a lower rotor are the same column: yaw is lost.
    let no_km = VehicleDescription::coaxial(4, 0.1, 0.1, 6.5, 0.0).unwrap();
    assert_eq!(no_km.allocation().rank(), 3);
    let y6 = VehicleDescription::coaxial(3, 0.3, 0.1, 6.5, K).unwrap();
    assert_eq!(y6.layout(), Layout::Coaxial { arms: 3 });
    assert_eq!(y6.allocation().rank(), 4);
}

#[test]
fn a_symmetric_layout_shares_a_pure_thrust_equally() {
    let layouts = [
        VehicleDescription::quad_x(0.165, 4.0, K).unwrap(),
        VehicleDescription::quad_plus(0.2, 4.0, K).unwrap(),
        VehicleDescription::hexa_x(0.3, 4.0, K).unwrap(),
        VehicleDescription::hexa_plus(0.3, 4.0, K).unwrap(),
        VehicleDescription::octo_x(0.4, 4.0, K).unwrap(),
        VehicleDescription::octo_plus(0.4, 4.0, K).unwrap(),
        VehicleDescription::coaxial(4, 0.3, 0.1, 4.0, K).unwrap(),
    ];
    for vehicle in layouts {
        let allocation = vehicle.allocation();
        let n = vehicle.rotors.len() as f64;
        let thrusts = allocation.thrusts_for(&[12.0, 0.0, 0.0, 0.0]);
        for f in &thrusts {
            assert!(
                (f - 12.0 / n).abs() < 1e-12,
                "{}: {thrusts:?}",
                vehicle.name
            );
        }
        // B B⁺ = I: every wrench is reached.
        let wrench = [10.0, 0.3, -0.2, 0.05];
        let back = allocation.wrench(&allocation.thrusts_for(&wrench));
        for (b, w) in back.iter().zip(wrench) {
            assert!((b - w).abs() < 1e-12, "{}: {back:?}", vehicle.name);
        }
    }
}

#[test]
fn a_centre_of_mass_ahead_of_the_rotors_pitches_the_nose_down() {
    let mut quad = VehicleDescription::quad_x(0.2, 4.0, K).unwrap();
    quad.centre_of_mass_m = [0.01, 0.0, 0.0];
    let wrench = quad.allocation().wrench(&[2.0; 4]);
    // τy = Σ −(x − 0.01) F = 4 · 0.01 · 2.
    assert!((wrench[2] - 0.08).abs() < 1e-12, "{wrench:?}");
    assert!(wrench[1].abs() < 1e-12 && wrench[3].abs() < 1e-12);
}

#[test]
fn a_tilted_rotor_thrusts_along_its_axis() {
    let mut rotor = Rotor::upright([0.0, -0.2, 0.0], Spin::CounterClockwise, 4.0, K);
    rotor.axis = [0.0, 3.0, 4.0];
    let vehicle =
        VehicleDescription::new("one", vec![rotor], CommandMap::px4(0.0), [0.0; 3]).unwrap();
    // Axis (0, 0.6, 0.8): T = 0.8; r × a = (−0.2 · 0.8, 0, 0); drag torque −km a.
    assert_rows(&vehicle, [&[0.8], &[-0.16], &[-0.6 * K], &[-0.8 * K]]);
    assert_eq!(vehicle.allocation().rank(), 1);
}

#[test]
fn geometries_that_are_no_named_layout_are_unrecognised() {
    let mut bent = VehicleDescription::quad_x(0.2, 4.0, K).unwrap();
    bent.rotors[0].position_m[0] *= 1.2;
    assert_eq!(bent.layout(), Layout::Unrecognised { rotors: 4 });
    let mut same_spin = VehicleDescription::quad_x(0.2, 4.0, K).unwrap();
    same_spin.rotors[2].spin = Spin::CounterClockwise;
    assert_eq!(same_spin.layout(), Layout::Unrecognised { rotors: 4 });
    let penta = VehicleDescription::ring("penta", 5, 0.0, 0.2, 4.0, K).unwrap();
    assert_eq!(penta.layout(), Layout::Unrecognised { rotors: 5 });
    // The 3DR Iris: front arms wider than the rear ones, mirrored left and right.
    let iris = [
        ([0.1515, -0.245], Spin::CounterClockwise),
        ([-0.1515, 0.1875], Spin::CounterClockwise),
        ([0.1515, 0.245], Spin::Clockwise),
        ([-0.1515, -0.1875], Spin::Clockwise),
    ];
    let iris = VehicleDescription::placed("iris", &iris, 6.5, 0.05).unwrap();
    assert_eq!(iris.layout(), Layout::QuadXUnequalArms);
    assert_eq!(
        Layout::Unrecognised { rotors: 5 }.to_string(),
        "unrecognised: 5 rotors"
    );
}

#[test]
fn command_scales_clip_to_the_motor_range() {
    let pwm = CommandScale::PwmMicroseconds {
        min_us: 1000.0,
        max_us: 2000.0,
    };
    assert_eq!(pwm.scaled(1250.0), 0.25);
    assert_eq!(pwm.scaled(900.0), 0.0);
    assert_eq!(pwm.scaled(2100.0), 1.0);
    assert_eq!(CommandScale::Fraction65536.scaled(16384.0), 0.25);
    assert_eq!(CommandScale::Normalised.scaled(0.7), 0.7);
    assert_eq!(CommandScale::Normalised.scaled(-0.1), 0.0);
}

#[test]
fn px4_thrust_model_blends_linear_and_quadratic() {
    // (1 − 0.3) · 0.5 + 0.3 · 0.25 = 0.425 of CT 6.5.
    let map = CommandMap::px4(0.3);
    let thrust = map.rotor_thrust(6.5, 0.5, None).unwrap();
    assert!((thrust - 6.5 * 0.425).abs() < 1e-12, "{thrust}");
    let quadratic = CommandMap::px4(1.0).rotor_thrust(2.0, 0.5, None).unwrap();
    assert!((quadratic - 0.5).abs() < 1e-12);
    let linear = CommandMap::px4(0.0).rotor_thrust(2.0, 0.5, None).unwrap();
    assert!((linear - 1.0).abs() < 1e-12);
    assert!(CommandMap::px4(1.5).check().is_err());
}

fn polynomial() -> CommandMap {
    // n = 1 + 2u + 3v + 4uv − 8u², v = V / 4.
    let term = |i, j, c| PolynomialTerm {
        command_power: i,
        voltage_power: j,
        coefficient: c,
    };
    CommandMap {
        command: CommandScale::Fraction65536,
        thrust: ThrustCurve::VoltagePolynomial {
            reference_voltage_v: 4.0,
            terms: vec![
                term(0, 0, 1.0),
                term(1, 0, 2.0),
                term(0, 1, 3.0),
                term(1, 1, 4.0),
                term(2, 0, -8.0),
            ],
        },
    }
}

#[test]
fn a_voltage_polynomial_needs_the_voltage_and_never_pulls() {
    let map = polynomial();
    // u = 0.5, v = 0.5: 1 + 1 + 1.5 + 1 − 2 = 2.5; CT 0.01 N per unit.
    let thrust = map.rotor_thrust(0.01, 32768.0, Some(2.0)).unwrap();
    assert!((thrust - 0.025).abs() < 1e-15, "{thrust}");
    // The same command on a fuller battery (v = 1): 1 + 1 + 3 + 2 − 2 = 5.
    let full = map.rotor_thrust(0.01, 32768.0, Some(4.0)).unwrap();
    assert!((full - 0.05).abs() < 1e-15, "{full}");
    let error = map.rotor_thrust(0.01, 32768.0, None).unwrap_err();
    assert!(error.to_string().contains("battery voltage"), "{error}");
    // u = 1, v = 0: 1 + 2 − 8 < 0 is clipped.
    assert_eq!(map.rotor_thrust(0.01, 65536.0, Some(0.0)).unwrap(), 0.0);
}

fn table(points: Vec<[f64; 2]>) -> CommandMap {
    CommandMap {
        command: CommandScale::Normalised,
        thrust: ThrustCurve::Table { points },
    }
}

#[test]
fn a_table_interpolates_and_must_be_monotone() {
    let map = table(vec![[0.1, 0.0], [0.5, 0.2], [1.0, 1.0]]);
    map.check().unwrap();
    let at = |u: f64| map.rotor_thrust(1.0, u, None).unwrap();
    assert!((at(0.3) - 0.1).abs() < 1e-12);
    assert!((at(0.75) - 0.6).abs() < 1e-12);
    assert_eq!(at(0.05), 0.0);
    assert_eq!(at(1.0), 1.0);
    let falling = table(vec![[0.0, 0.0], [0.5, 0.6], [1.0, 0.5]]).check();
    let message = falling.unwrap_err().to_string();
    assert!(
        message.contains("points[2]") && message.contains("monotone"),
        "{message}"
    );
    let repeated = table(vec![[0.0, 0.0], [0.5, 0.2], [0.5, 0.3]]).check();
    assert!(
        repeated
            .unwrap_err()
            .to_string()
            .contains("does not increase")
    );
    assert!(table(vec![[0.0, 0.0]]).check().is_err());
}

#[test]
fn a_description_survives_a_json_round_trip() {
    let mut vehicle = VehicleDescription::hexa_x(0.3, 5.0, K)
        .unwrap()
        .with_command_map(table(vec![[0.0, 0.0], [0.5, 0.3], [1.0, 1.0]]))
        .unwrap();
    vehicle.centre_of_mass_m = [0.01, -0.002, 0.03];
    vehicle.rotors[1].axis = [0.0, 0.6, 0.8];
    let text = vehicle.to_json();
    let back = VehicleDescription::from_json(&text, Path::new("hexa.json")).unwrap();
    assert_eq!(back, vehicle);
    let quad = VehicleDescription::quad_x(0.2, 4.0, K)
        .unwrap()
        .with_command_map(polynomial())
        .unwrap();
    let back = VehicleDescription::from_json(&quad.to_json(), Path::new("q.json")).unwrap();
    assert_eq!(back, quad);
}

fn refusal(text: &str) -> String {
    VehicleDescription::from_json(text, Path::new("v.json"))
        .unwrap_err()
        .to_string()
}

const ROTOR: &str = r#"{"position_m": [0.1, 0.1, 0], "spin": "ccw", "thrust_coefficient_n": 4, "moment_ratio_m": 0.02}"#;
const MAP: &str =
    r#"{"command": {"kind": "normalised"}, "thrust": {"kind": "thrust_model", "factor": 0}}"#;

#[test]
fn a_minimal_description_reads() {
    let text = format!(r#"{{"rotors": [{ROTOR}], "command_map": {MAP}}}"#);
    let vehicle = VehicleDescription::from_json(&text, Path::new("v.json")).unwrap();
    assert_eq!(vehicle.rotors[0].axis, [0.0, 0.0, 1.0]);
    assert_eq!(vehicle.centre_of_mass_m, [0.0; 3]);
}

#[test]
fn bad_descriptions_are_refused_naming_the_field() {
    let unknown = refusal(&format!(
        r#"{{"rotors": [{}], "command_map": {MAP}}}"#,
        ROTOR.replace("}", r#", "colour": "red"}"#)
    ));
    assert!(
        unknown.contains("v.json") && unknown.contains("rotors[0]") && unknown.contains("colour"),
        "{unknown}"
    );
    let missing = refusal(&format!(
        r#"{{"rotors": [{ROTOR}, {}], "command_map": {MAP}}}"#,
        ROTOR.replace(r#""spin": "ccw", "#, "")
    ));
    assert!(
        missing.contains("rotors[1]") && missing.contains("spin"),
        "{missing}"
    );
    let nan = refusal(&format!(
        r#"{{"rotors": [{}], "command_map": {MAP}}}"#,
        ROTOR.replace("0.02", "NaN")
    ));
    assert!(
        nan.contains("v.json") && nan.contains("rotors[0].moment_ratio_m"),
        "{nan}"
    );
    let negative = refusal(&format!(
        r#"{{"rotors": [{}], "command_map": {MAP}}}"#,
        ROTOR.replace("0.02", "-0.02")
    ));
    assert!(
        negative.contains("field 'rotors[0].moment_ratio_m'")
            && negative.contains("spin gives the sign"),
        "{negative}"
    );
    let pwm = refusal(&format!(
        r#"{{"rotors": [{ROTOR}], "command_map": {}}}"#,
        MAP.replace(
            r#"{"kind": "normalised"}"#,
            r#"{"kind": "pwm_microseconds", "min_us": 2000, "max_us": 1000}"#
        )
    ));
    assert!(pwm.contains("command_map.command.max_us"), "{pwm}");
    let no_rotor = refusal(&format!(r#"{{"rotors": [], "command_map": {MAP}}}"#));
    assert!(
        no_rotor.contains("'rotors'") && no_rotor.contains("0 rotors"),
        "{no_rotor}"
    );
    let twice = refusal(&format!(
        r#"{{"rotors": [{ROTOR}], "rotors": [], "command_map": {MAP}}}"#
    ));
    assert!(twice.contains("rotors"), "{twice}");
    for error in [&unknown, &missing, &nan, &negative, &pwm, &no_rotor, &twice] {
        assert!(!error.contains('\n'), "{error}");
    }
}

#[test]
fn commands_for_the_wrong_number_of_rotors_are_refused() {
    let quad = VehicleDescription::quad_x(0.2, 4.0, K).unwrap();
    let error = quad.wrench(&[0.5; 3], None).unwrap_err().to_string();
    assert!(error.contains("3 commands for 4 rotors"), "{error}");
    let hover = quad.wrench(&[0.5; 4], None).unwrap();
    assert!(
        (hover[0] - 8.0).abs() < 1e-12 && hover[3].abs() < 1e-15,
        "{hover:?}"
    );
}

/// The simulator writes the command whose thrust a speed asks for: the inverse of each map within
/// its range, the range's ends beyond it.
#[test]
fn a_command_map_is_inverted_within_its_range() {
    let pwm = CommandMap {
        command: CommandScale::PwmMicroseconds {
            min_us: 1000.0,
            max_us: 2000.0,
        },
        thrust: ThrustCurve::ThrustModel { factor: 0.6 },
    };
    let maps = [
        (pwm, None),
        (table(vec![[0.0, 0.0], [0.5, 0.2], [1.0, 1.0]]), None),
        (
            CommandMap {
                command: CommandScale::Fraction65536,
                thrust: ThrustCurve::VoltagePolynomial {
                    reference_voltage_v: 16.0,
                    terms: vec![
                        PolynomialTerm {
                            command_power: 1,
                            voltage_power: 1,
                            coefficient: 0.3,
                        },
                        PolynomialTerm {
                            command_power: 2,
                            voltage_power: 2,
                            coefficient: 0.7,
                        },
                    ],
                },
            },
            Some(15.2),
        ),
    ];
    for (map, volts) in maps {
        for n in [0.05, 0.3, 0.61] {
            let command = map.command_for(n, volts).unwrap();
            let back = map.rotor_thrust(1.0, command, volts).unwrap();
            assert!(
                (back - n).abs() < 1e-12,
                "{map:?}: {n} -> {command} -> {back}"
            );
        }
        let full = map.command_for(5.0, volts).unwrap();
        assert_eq!(map.command.scaled(full), 1.0);
        assert_eq!(
            map.command.scaled(map.command_for(0.0, volts).unwrap()),
            0.0
        );
    }
    assert_eq!(polynomial().command_for(0.5, None), None);
}
