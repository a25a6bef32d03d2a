//! What the mismatch behaviour tests share: the workspace's demo models and one simulated
//! figure-8 scenario.

#![allow(dead_code)]

use std::path::{Path, PathBuf};

use mismatch::{CheckedSettings, Settings};
use physics::{Effects, Noise, NominalModel, Scenario, Trajectory};

pub fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A fresh temporary directory for one test, removed with everything in it when dropped.
pub fn temp_dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("mismatch-{name}-"))
        .tempdir()
        .unwrap()
}

/// The analysis settings of the short test flights: half-second blocks, 20 resamples.
pub fn fast_settings() -> CheckedSettings {
    let mut settings = Settings::default();
    settings.analysis.block_s = 0.5;
    settings.analysis.selection.resamples = 20;
    settings.checked().unwrap()
}

/// A nominal model of `experiments/mismatch/`, e.g. `vehicles/quad-a.json`.
pub fn model(name: &str) -> NominalModel {
    NominalModel::load(&workspace().join("experiments/mismatch").join(name)).unwrap()
}

/// The demo vehicle as the tool is given it for logs of [`scenario`]'s simulator: with the
/// scenario's logger (each command held until the next row).
pub fn model_for_scenario() -> NominalModel {
    let scenario = scenario(Effects::default(), 0);
    NominalModel {
        logger: scenario.logger(),
        ..model("vehicles/quad-a.json")
    }
}

/// A 14 s figure-8 with small sensor noise and the given effects.
pub fn scenario(effects: Effects, seed: u64) -> Scenario {
    Scenario {
        model: "quad-a.json".into(),
        duration_s: 14.0,
        warmup_s: 3.0,
        seed,
        physics_rate_hz: 500.0,
        log_rate_hz: 50.0,
        hover_throttle: 0.5,
        trajectory: Trajectory::Figure8 {
            center: [0.0, 0.0, 1.5],
            first: [1.8, 0.0, 0.0],
            second: [0.0, 0.9, 0.4],
            period_s: 6.0,
            low_passes: Vec::new(),
            yaw_amplitude_rad: 0.3,
            yaw_period_s: 9.0,
        },
        effects,
        noise: Noise {
            position_m: 0.002,
            velocity_m_s: 0.005,
            attitude_rad: 0.002,
            rate_rad_s: 0.008,
        },
        gains: Default::default(),
        controller_rate_hz: None,
        logger: None,
        jitter: None,
        log_timing: None,
        battery: None,
    }
}
