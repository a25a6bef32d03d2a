//! The joint analysis of several flights of one vehicle, on simulated flights whose air is known: a
//! calm flight calibrates a tilted thrust axis and the rotor drag, and each windy flight's air
//! velocity comes out of the joint fit, also with the vehicle fitted without that flight's condition.

use mismatch::fleet::FleetPlan;
use mismatch::fleet::FleetReport;
use physics::{
    DragLag, EffectId, Effects, NominalModel, RotorDrag, Scenario, ThrustTilt, Wind, simulate,
};

mod common;

/// A temporary directory (removed when dropped) with an empty `data/experiment`.
fn scratch(name: &str) -> tempfile::TempDir {
    let dir = common::temp_dir(&format!("fleet-{name}"));
    std::fs::create_dir_all(dir.path().join("data/experiment")).unwrap();
    dir
}

/// The vehicle's own effects, in air moving at `wind` (none: still air), the air forces lagging
/// the velocity by `lag_s` when given.
fn vehicle_effects(wind: Option<[f64; 3]>, lag_s: Option<f64>) -> Effects {
    Effects {
        drag_lag: lag_s.map(|tau_s| DragLag { tau_s }),
        thrust_tilt: Some(ThrustTilt {
            angles_rad: [0.015, -0.03],
        }),
        rotor_drag: Some(RotorDrag { d: [0.35, 0.3] }),
        wind: wind.map(|w_air| Wind { w_air }),
        ..Effects::default()
    }
}

/// A condition: name, air velocity (none: calm), known speed.
type Condition = (&'static str, Option<[f64; 3]>, f64);

/// Simulates one flight per condition with the vehicle's effects (air forces lagging by
/// `lag_s`), runs the joint analysis on them and returns its report.
fn analyse(name: &str, conditions: &[Condition], lag_s: Option<f64>) -> FleetReport {
    analyse_vehicle(name, conditions, lag_s, "vehicles/quad-a.json")
}

/// [`analyse`] of flights of the simulated `vehicle` (a model of `experiments/mismatch/`).
fn analyse_vehicle(
    name: &str,
    conditions: &[Condition],
    lag_s: Option<f64>,
    vehicle: &str,
) -> FleetReport {
    let tmp = scratch(name);
    let dir = tmp.path();
    let vehicle = common::model(vehicle);
    for (k, (name, wind, _)) in conditions.iter().enumerate() {
        let scenario = Scenario {
            duration_s: 24.0,
            effects: vehicle_effects(*wind, lag_s),
            ..common::scenario(Effects::default(), 40 + k as u64)
        };
        let log = simulate(&vehicle, &scenario, name).unwrap();
        log.write_csv(&dir.join(format!("data/experiment/flight_only_{name}.csv")))
            .unwrap();
    }
    let conditions_json = serde_json::json!({
        "file_pattern": "experiment/flight_{controller}_{condition}.csv",
        "controllers": ["only"],
        "evaluation_controller": "only",
        "conditions": conditions.iter().map(|(name, wind, speed)| serde_json::json!({
            "name": name, "wind_speed": format!("{speed} m/s"), "mean_wind_m_s": speed,
            "calm": wind.is_none(),
            "role": if wind.is_none() { "meta-training" } else { "evaluation" }
        })).collect::<Vec<_>>(),
        "paper_training": {"file_pattern": "training/flight_{condition}.csv",
            "conditions": [{"name": "still", "wind_speed": "0 m/s", "role": "meta-training"}]}
    });
    std::fs::write(dir.join("conditions.json"), conditions_json.to_string()).unwrap();
    // The tool's model: the thrust from T_sp, each command held until the next row.
    let model = NominalModel::from_json(
        r#"{"mass_kg": 1.8, "gravity_m_s2": 9.81, "inertia_kg_m2": [0.02, 0.02, 0.035],
            "thrust_source": "T_sp", "logger": {"command": "held"}}"#,
        &dir.join("vehicle.json"),
    )
    .unwrap();
    let plan = FleetPlan::load(&dir.join("conditions.json"), &dir.join("data")).unwrap();
    let report = plan
        .run(
            &model,
            "vehicle.json",
            &mismatch::CheckedSettings::standard(),
        )
        .unwrap();
    let [json, markdown, svg] = report.render(&dir.join("out"), "vehicle").unwrap();
    assert!(json.ends_with("}\n") && markdown.contains("(vehicle.svg)") && svg.contains("<svg"));
    report
}

fn effect_ids(report: &FleetReport) -> Vec<EffectId> {
    report.vehicle.effects.iter().map(|e| e.id).collect()
}

/// Every flight's estimated air (both roles) within `tolerance` m/s of the truth, horizontally.
fn assert_winds(report: &FleetReport, conditions: &[Condition], tolerance: f64) {
    for role in ["fit", "validation"] {
        for (name, wind, _) in conditions {
            let found = report
                .flights
                .iter()
                .find(|f| f.role == role && f.condition == *name)
                .unwrap();
            let truth = wind.unwrap_or([0.0; 3]);
            let error =
                ((found.w_air[0] - truth[0]).powi(2) + (found.w_air[1] - truth[1]).powi(2)).sqrt();
            assert!(
                error < tolerance,
                "{role} {name}: {:?} for {truth:?}",
                found.w_air
            );
        }
    }
}

#[test]
fn the_winds_of_several_flights_come_out_of_one_vehicle() {
    let conditions: [Condition; 3] = [
        ("still", None, 0.0),
        ("breeze", Some([-3.0, 0.5, 0.0]), 3.0),
        ("gale", Some([-6.0, -1.0, 0.0]), 6.0),
    ];
    let report = analyse("plain", &conditions, None);
    let ids = effect_ids(&report);
    assert!(
        ids.contains(&EffectId::ThrustTilt) && ids.contains(&EffectId::RotorDrag),
        "{ids:?}"
    );
    assert_winds(&report, &conditions, 0.5);
}

/// With air forces that lag the velocity, the lag is chosen on the calm flights' held-out parts,
/// the winds come out at their scale, and the band of lags the calm flights leave open brackets
/// every wind's true speed.
#[test]
fn a_lag_of_the_air_forces_is_found_in_still_air_and_bounds_the_winds_scale() {
    let conditions: [Condition; 4] = [
        ("still", None, 0.0),
        ("calm", None, 0.0),
        ("breeze", Some([-3.0, 0.5, 0.0]), 3.04),
        ("gale", Some([-6.0, -1.0, 0.0]), 6.08),
    ];
    let report = analyse("lag", &conditions, Some(0.3));
    let ids = effect_ids(&report);
    assert!(ids.contains(&EffectId::DragLag), "{ids:?}");
    let scale = report
        .scale
        .as_ref()
        .expect("a scale section with a drag lag");
    assert!(
        (scale.chosen_lag_s - 0.3).abs() < 0.08,
        "lag {}",
        scale.chosen_lag_s
    );
    assert!(scale.lag_band_s.0 <= 0.3 && 0.3 <= scale.lag_band_s.1);
    for f in &scale.flights {
        let (low, high) = f.range();
        let known = f.fan_speed_m_s.unwrap();
        assert!(low - 0.2 <= known && known <= high + 0.2, "{f:?}");
    }
    assert_winds(&report, &conditions, 0.6);
}

/// A hexarotor's flights: the attitude check maps its six motor commands to the body's angular
/// acceleration (it was a map from four, and skipped for other motor counts).
#[test]
fn a_hexarotors_attitude_check_reads_its_six_motors() {
    let conditions: [Condition; 2] = [
        ("still", None, 0.0),
        ("breeze", Some([-3.0, 0.5, 0.0]), 3.0),
    ];
    let report = analyse_vehicle("hexa", &conditions, None, "vehicles/hexa-x.json");
    let attitude = report.attitude.expect("an attitude check");
    assert!(attitude.pwm_range[0] >= 1000.0 && attitude.pwm_range[1] <= 2000.0);
    assert!(
        attitude.explained_calm_heldout.iter().all(|e| *e > 0.5),
        "{attitude:?}"
    );
}
