//! The joint analysis of several flights of one vehicle, on simulated flights whose air is known: a
//! calm flight calibrates a tilted thrust axis and the rotor drag, and each windy flight's air
//! velocity comes out of the joint fit, also with the vehicle fitted without that flight's condition.

use std::path::PathBuf;

use mismatch::fleet::FleetPlan;
use physics::{Effects, NominalModel, RotorDrag, Scenario, ThrustTilt, Wind, simulate};

mod common;

fn scratch() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mismatch-fleet-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("data/experiment")).unwrap();
    dir
}

/// The vehicle's own effects, in air moving at `wind` (none: still air).
fn vehicle_effects(wind: Option<[f64; 3]>) -> Effects {
    Effects {
        thrust_tilt: Some(ThrustTilt {
            angles_rad: [0.015, -0.03],
        }),
        rotor_drag: Some(RotorDrag { d: [0.35, 0.3] }),
        wind: wind.map(|w_air| Wind { w_air }),
        ..Effects::default()
    }
}

#[test]
fn the_winds_of_several_flights_come_out_of_one_vehicle() {
    let dir = scratch();
    let vehicle = common::model("vehicles/quad-a.json");
    let conditions = [
        ("still", None, 0.0),
        ("breeze", Some([-3.0, 0.5, 0.0]), 3.0),
        ("gale", Some([-6.0, -1.0, 0.0]), 6.0),
    ];
    for (k, (name, wind, _)) in conditions.iter().enumerate() {
        let scenario = Scenario {
            duration_s: 24.0,
            effects: vehicle_effects(*wind),
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
        "conditions": conditions.iter().map(|(name, _, speed)| serde_json::json!({
            "name": name, "wind_speed": format!("{speed} m/s"), "mean_wind_m_s": speed,
            "calm": *name == "still",
            "role": if *name == "still" { "meta-training" } else { "evaluation" }
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
    let out = dir.join("out");
    let plan = FleetPlan::load(
        &dir.join("conditions.json"),
        &dir.join("data"),
        &dir.join("vehicle.json"),
        &out,
    )
    .unwrap();
    let (report, _) = plan.run(&model, "vehicle.json", false).unwrap();
    let ids: Vec<&str> = report
        .vehicle
        .effects
        .iter()
        .map(|e| e.id.as_str())
        .collect();
    assert!(
        ids.contains(&"thrust_tilt") && ids.contains(&"rotor_drag"),
        "{ids:?}"
    );
    for role in ["fit", "validation"] {
        for (name, wind, _) in &conditions {
            let found = report
                .flights
                .iter()
                .find(|f| f.role == role && f.condition == *name)
                .unwrap();
            let truth = wind.unwrap_or([0.0; 3]);
            let error =
                ((found.w_air[0] - truth[0]).powi(2) + (found.w_air[1] - truth[1]).powi(2)).sqrt();
            assert!(
                error < 0.5,
                "{role} {name}: {:?} for {truth:?}",
                found.w_air
            );
        }
    }
    for ext in ["json", "md", "svg"] {
        assert!(out.join(format!("vehicle.{ext}")).exists());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
