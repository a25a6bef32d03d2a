//! Small flight logs made by the tests themselves.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use data::FlightLog;
use rotation::rotation_from_quaternion;

/// A smooth synthetic flight of `n` samples at 50 Hz with every column present.
pub fn synthetic_log(n: usize) -> FlightLog {
    let time: Vec<f64> = (0..n).map(|k| k as f64 * 0.02).collect();
    let quaternion: Vec<[f64; 4]> = time
        .iter()
        .map(|t| {
            let half = 0.1 * (t * 0.7).sin() / 2.0;
            [half.sin(), 0.0, 0.0, half.cos()]
        })
        .collect();
    FlightLog {
        path: PathBuf::from("synthetic.csv"),
        meta: None,
        position: time
            .iter()
            .map(|t| [1.25 * t.sin(), 0.0, 0.75 * (2.0 * t).sin()])
            .collect(),
        velocity: time
            .iter()
            .map(|t| [1.25 * t.cos(), 0.0, 1.5 * (2.0 * t).cos()])
            .collect(),
        rotation: quaternion.iter().map(rotation_from_quaternion).collect(),
        quaternion,
        body_rate: time
            .iter()
            .map(|t| [0.07 * (t * 0.7).cos(), 0.0, 0.01])
            .collect(),
        thrust_setpoint: time.iter().map(|t| 0.6 + 0.05 * t.sin()).collect(),
        hover_throttle: vec![0.47; n],
        motor_command: time
            .iter()
            .map(|t| {
                [
                    1300.0 + 50.0 * t.sin(),
                    1310.0,
                    1290.0,
                    1305.0 + 20.0 * t.cos(),
                ]
            })
            .collect(),
        position_desired: Some(vec![[0.0; 3]; n]),
        battery_voltage: None,
        declared_rate_frame: None,
        velocity_desired: Some(vec![[0.0; 3]; n]),
        attitude_setpoint: Some(vec![[0.0, 0.0, 0.0, 1.0]; n]),
        residual_force: Some(vec![[0.1, -0.2, 0.3]; n]),
        time,
    }
}

/// A fresh temporary directory for one test, removed with everything in it when dropped: keep it
/// alive for as long as the test uses the path.
pub fn temp_dir(name: &str) -> Scratch {
    Scratch(
        tempfile::Builder::new()
            .prefix(&format!("data-tests-{name}-"))
            .tempdir()
            .unwrap(),
    )
}

/// A temporary directory, used as its path.
pub struct Scratch(tempfile::TempDir);

impl std::ops::Deref for Scratch {
    type Target = Path;
    fn deref(&self) -> &Path {
        self.0.path()
    }
}

impl AsRef<Path> for Scratch {
    fn as_ref(&self) -> &Path {
        self.0.path()
    }
}

/// Writes a synthetic log and returns its text.
pub fn synthetic_csv(dir: &Path, n: usize) -> (PathBuf, String) {
    let path = dir.join("custom_figure8_baseline_35wind.csv");
    synthetic_log(n).write_csv(&path).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    (path, text)
}

/// The real data directory (see `data::real_data_dir_for_tests`: skips locally, fails under CI).
pub fn real_data_dir() -> Option<PathBuf> {
    data::real_data_dir_for_tests(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../.."))
}
