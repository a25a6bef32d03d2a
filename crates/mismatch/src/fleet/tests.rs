//! The committed joint analysis of the Neural-Fly flights (`results/mismatch/neural-fly.*`): read
//! back from its JSON, the report writes the committed Markdown and figure byte for byte, and its
//! JSON again.

use std::path::{Path, PathBuf};

use physics::{EffectId, Effects};
use serde::de::DeserializeOwned;
use serde_json::Value;
use sindy::weak_form::TestFunction;

use super::report::{VehicleEffect, VehicleParameters, VehicleReport, file_names};
use super::{
    AttitudeCheck, FleetReport, FlightHeldout, FlightSpeedRange, FlightWind, ScaleReport,
    SelectionStep, Targets,
};
use crate::settings::{ComparisonSettings, FleetRecord, FleetSettings};

fn committed(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../results/mismatch")
        .join(name)
}

fn from<T: DeserializeOwned>(value: &Value) -> T {
    serde_json::from_value(value.clone()).unwrap()
}

fn items(value: &Value) -> &Vec<Value> {
    value.as_array().unwrap()
}

fn vehicle_effect(e: &Value) -> VehicleEffect {
    let id: EffectId = from(&e["id"]);
    let parameters = match e["parameters"].get("per_flight") {
        Some(place) => {
            assert_eq!(place, "flights[].gradient_per_m");
            VehicleParameters::PerFlight {
                per_flight: "flights[].gradient_per_m",
            }
        }
        None => {
            let effects: Effects = from(&serde_json::json!({ id.name(): e["parameters"].clone() }));
            VehicleParameters::Fitted(effects.parameters(id).unwrap())
        }
    };
    VehicleEffect {
        id,
        parameters,
        description: from(&e["description"]),
    }
}

fn flight(f: &Value) -> FlightWind {
    FlightWind {
        condition: from(&f["condition"]),
        controller: from(&f["controller"]),
        fan_speed_m_s: from(&f["fan_speed_m_s"]),
        role: from(&f["role"]),
        calm: from(&f["calm"]),
        w_air: from(&f["w_air"]),
        gradient_per_m: from(&f["gradient_per_m"]),
        horizontal_speed_m_s: from(&f["horizontal_speed_m_s"]),
        azimuth_deg: from(&f["azimuth_deg"]),
        speed_error_m_s: from(&f["speed_error_m_s"]),
    }
}

fn targets(t: &Value) -> Targets {
    Targets {
        role: from(&t["role"]),
        within_1_5: from(&t["within_1_5"]),
        within_1_0: from(&t["within_1_0"]),
        windy: from(&t["windy"]),
        max_speed_error_m_s: from(&t["max_speed_error_m_s"]),
        max_calm_speed_m_s: from(&t["max_calm_speed_m_s"]),
        axis_azimuth_deg: from(&t["axis_azimuth_deg"]),
        max_direction_deviation_deg: from(&t["max_direction_deviation_deg"]),
    }
}

fn heldout(h: &Value) -> FlightHeldout {
    FlightHeldout {
        condition: from(&h["condition"]),
        controller: from(&h["controller"]),
        mse_nominal: from(&h["mse_nominal"]),
        mse_model: from(&h["mse_model"]),
        residual_force_explained: from(&h["residual_force_explained"]),
    }
}

fn step(s: &Value) -> SelectionStep {
    SelectionStep {
        stage: from(&s["stage"]),
        candidate: from(&s["candidate"]),
        error_before: from(&s["error_before"]),
        error_with: from(&s["error_with"]),
        accepted: from(&s["accepted"]),
    }
}

fn attitude(a: &Value) -> AttitudeCheck {
    AttitudeCheck {
        pwm_range: from(&a["pwm_range"]),
        mean_pwm_offset: from(&a["mean_pwm_offset"]),
        mean_pwm_slope: from(&a["mean_pwm_slope"]),
        mean_pwm_lag_rows: from(&a["mean_pwm_lag_rows"]),
        mean_pwm_lag_s: from(&a["mean_pwm_lag_s"]),
        mean_pwm_residual_rms: from(&a["mean_pwm_residual_rms"]),
        torque_map_lag_rows: from(&a["torque_map_lag_rows"]),
        explained_calm_heldout: from(&a["explained_calm_heldout"]),
        explained_windy: from(&a["explained_windy"]),
    }
}

fn scale(s: &Value) -> ScaleReport {
    ScaleReport {
        calm_profile: from(&s["calm_profile"]),
        lag_band_s: from(&s["lag_band_s"]),
        chosen_lag_s: from(&s["chosen_lag_s"]),
        flights: items(&s["flights"])
            .iter()
            .map(|f| FlightSpeedRange {
                condition: from(&f["condition"]),
                controller: from(&f["controller"]),
                fan_speed_m_s: from(&f["fan_speed_m_s"]),
                speed_low_lag_m_s: from(&f["speed_low_lag_m_s"]),
                speed_high_lag_m_s: from(&f["speed_high_lag_m_s"]),
            })
            .collect(),
    }
}

fn settings(s: &Value) -> FleetRecord {
    FleetRecord {
        comparison: ComparisonSettings {
            test_function: TestFunction {
                half_width_s: from(&s["test_function"]["half_width_s"]),
                power: from(&s["test_function"]["power"]),
            },
            heldout_fraction: from(&s["heldout_fraction"]),
        },
        fleet: FleetSettings {
            min_step: from(&s["min_step"]),
            iterations: from(&s["iterations"]),
        },
    }
}

/// The report as the committed JSON records it.
fn committed_report(json: &Value) -> FleetReport {
    let vehicle = &json["vehicle"];
    FleetReport {
        model: from(&json["model"]),
        conditions: from(&json["conditions"]),
        vehicle: VehicleReport {
            mass_kg: from(&vehicle["mass_kg"]),
            gravity_m_s2: from(&vehicle["gravity_m_s2"]),
            effects: items(&vehicle["effects"])
                .iter()
                .map(vehicle_effect)
                .collect(),
        },
        flights: items(&json["flights"]).iter().map(flight).collect(),
        targets: items(&json["targets"]).iter().map(targets).collect(),
        heldout: items(&json["heldout"]).iter().map(heldout).collect(),
        selection: items(&json["selection"]).iter().map(step).collect(),
        attitude: (!json["attitude"].is_null()).then(|| attitude(&json["attitude"])),
        scale: (!json["scale"].is_null()).then(|| scale(&json["scale"])),
        validation_vehicles: from(&json["validation_vehicles"]),
        settings: settings(&json["settings"]),
        notes: from(&json["notes"]),
    }
}

#[test]
fn the_committed_report_renders_its_committed_markdown_and_figure() {
    let json: Value =
        serde_json::from_str(&std::fs::read_to_string(committed("neural-fly.json")).unwrap())
            .unwrap();
    let report = committed_report(&json);
    let names = file_names("neural-fly");
    let rendered = report
        .render(Path::new("results/mismatch"), "neural-fly")
        .unwrap();
    for (name, contents) in names.iter().zip(&rendered).skip(1) {
        assert!(
            contents.as_bytes() == std::fs::read(committed(name)).unwrap(),
            "{name} differs from the committed one"
        );
    }
    // The JSON read back whole (as values: the last digit of a float may parse either way).
    assert_eq!(names[0], "neural-fly.json");
    let written: Value = serde_json::from_str(&rendered[0]).unwrap();
    assert_eq!(written, json);
}

#[test]
fn the_committed_report_prints_one_line_per_flight_and_the_targets() {
    let json: Value =
        serde_json::from_str(&std::fs::read_to_string(committed("neural-fly.json")).unwrap())
            .unwrap();
    let lines = committed_report(&json).view().lines();
    assert_eq!(lines.len(), 63);
    assert_eq!(
        lines[30],
        "validation nowind     baseline   w_air [ -0.29,  -0.04,  0.11] m/s, horizontal  0.29 (known 0)"
    );
    assert_eq!(
        lines[60],
        "scale: the calm flights leave the drag lag open from 0.2 to 0.4 s; 22 of 24 windy flights' known speeds lie between their speeds at the two ends"
    );
    assert_eq!(
        lines[62],
        "validation: 24 of 24 windy flights within ±1.5 m/s (max error 1.09), calm at most 0.46 m/s, directions within ±2.5° of -178.8°"
    );
}
