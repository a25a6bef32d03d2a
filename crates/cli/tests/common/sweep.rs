//! A small experiment the tests make themselves (no real flight needed): generated flights for one
//! meta-training and two evaluation conditions plus two paper-training flights, a conditions file,
//! a LeARN configuration with a tiny budget, a run configuration and a variants file over them.
//! A whole `learn reproduce`, `ablations` or seed spread on it takes about a second.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use data::FlightLog;
use physics::vector::rotation_from_quaternion;
use serde_json::{Value, json};

use super::Run;

/// Samples per generated flight (8 s at 50 Hz).
const SAMPLES: usize = 400;

/// The files of a small experiment under its folder (all paths absolute).
pub struct SmallExperiment {
    pub dir: PathBuf,
    pub data: PathBuf,
    pub learn: PathBuf,
    pub conditions: PathBuf,
    pub run: PathBuf,
    pub variants: PathBuf,
}

/// Writes a small experiment into `dir` (see the module documentation).
pub fn small_experiment(dir: &Path) -> SmallExperiment {
    let data = dir.join("data");
    std::fs::create_dir_all(data.join("experiment")).unwrap();
    std::fs::create_dir_all(data.join("training")).unwrap();
    for (name, wind) in [("calm", 0.0), ("gust", 1.0), ("storm", 2.0)] {
        let path = data.join(format!("experiment/custom_figure8_baseline_{name}.csv"));
        flight(wind).write_csv(&path).unwrap();
    }
    for (name, wind) in [("t1", 0.5), ("t2", 1.5)] {
        flight(wind)
            .write_csv(&data.join(format!("training/{name}.csv")))
            .unwrap();
    }
    let experiment = SmallExperiment {
        dir: dir.to_path_buf(),
        learn: dir.join("learn.json"),
        conditions: dir.join("conditions.json"),
        run: dir.join("run.json"),
        variants: dir.join("variants.json"),
        data,
    };
    write_json(&experiment.conditions, &conditions());
    write_json(&experiment.learn, &learn_config());
    write_json(&experiment.run, &run_config(&experiment));
    write_json(&experiment.variants, &variants(&experiment));
    experiment
}

impl SmallExperiment {
    /// A path as an argument.
    pub fn arg(path: &Path) -> &str {
        path.to_str().expect("UTF-8 path")
    }
}

fn write_json(path: &Path, value: &Value) {
    std::fs::write(path, serde_json::to_string_pretty(value).unwrap()).unwrap();
}

/// A smooth flight of [`SAMPLES`] samples at 50 Hz whose motion and controls depend on `wind`.
pub fn flight(wind: f64) -> FlightLog {
    let n = SAMPLES;
    let time: Vec<f64> = (0..n).map(|k| k as f64 * 0.02).collect();
    let quaternion: Vec<[f64; 4]> = time
        .iter()
        .map(|t| {
            let half = (0.1 + 0.02 * wind) * (t * 0.7 + wind).sin() / 2.0;
            [half.sin(), 0.3 * half.sin(), 0.0, half.cos()]
        })
        .collect();
    let wobble = |t: f64, f: f64| (f * t + wind).sin() + 0.3 * (2.7 * f * t).cos();
    FlightLog {
        path: PathBuf::from("generated.csv"),
        meta: None,
        position: time
            .iter()
            .map(|t| {
                [
                    1.25 * t.sin(),
                    0.5 * (0.5 * t).sin(),
                    0.75 * (2.0 * t).sin(),
                ]
            })
            .collect(),
        velocity: time
            .iter()
            .map(|&t| {
                [
                    1.25 * t.cos() + 0.1 * wind * wobble(t, 1.3),
                    0.25 * (0.5 * t).cos() + 0.05 * wobble(t, 0.9),
                    1.5 * (2.0 * t).cos() - 0.1 * wind,
                ]
            })
            .collect(),
        rotation: quaternion.iter().map(rotation_from_quaternion).collect(),
        quaternion,
        body_rate: time
            .iter()
            .map(|&t| {
                [
                    0.07 * (t * 0.7).cos() + 0.02 * wind * wobble(t, 2.1),
                    0.03 * wobble(t, 1.7),
                    0.01 + 0.01 * wobble(t, 0.4),
                ]
            })
            .collect(),
        thrust_setpoint: time
            .iter()
            .map(|&t| 0.6 + 0.05 * t.sin() + 0.01 * wind * wobble(t, 1.1))
            .collect(),
        hover_throttle: vec![0.47; n],
        motor_command: time
            .iter()
            .map(|&t| {
                [
                    1300.0 + 50.0 * t.sin() + 10.0 * wind,
                    1310.0 + 20.0 * wobble(t, 1.9),
                    1290.0 - 15.0 * wobble(t, 0.8),
                    1305.0 + 20.0 * t.cos(),
                ]
            })
            .collect(),
        position_desired: None,
        battery_voltage: None,
        declared_rate_frame: None,
        velocity_desired: None,
        attitude_setpoint: None,
        residual_force: None,
        time,
    }
}

fn conditions() -> Value {
    json!({
        "file_pattern": "experiment/custom_figure8_{controller}_{condition}.csv",
        "controllers": ["baseline"],
        "evaluation_controller": "baseline",
        "conditions": [
            {"name": "calm", "wind_speed": "0 m/s", "role": "meta-training"},
            {"name": "gust", "wind_speed": "1 m/s", "role": "evaluation"},
            {"name": "storm", "wind_speed": "2 m/s", "role": "evaluation"}
        ],
        "paper_training": {
            "file_pattern": "training/{condition}.csv",
            "conditions": [
                {"name": "t1", "wind_speed": "0.5 m/s", "role": "meta-training"},
                {"name": "t2", "wind_speed": "1.5 m/s", "role": "meta-training"}
            ]
        }
    })
}

/// experiments/learn.json with a tiny budget and network.
fn learn_config() -> Value {
    let text = std::fs::read_to_string(super::workspace().join("experiments/learn.json")).unwrap();
    let mut config: Value = serde_json::from_str(&text).unwrap();
    config["hidden_layers"] = json!([6, 6]);
    config["meta_training"]["iterations"] = json!(3);
    config["meta_training"]["task_batch"] = json!(2);
    config["meta_training"]["support_batch"] = json!(16);
    config["meta_training"]["query_batch"] = json!(16);
    config["adaptation"]["passes"] = json!(1);
    config["spread_seeds"] = json!([1, 2, 3]);
    config
}

/// Every formulation, two seeds, leave-condition-out, the variants file's reproduce columns.
fn run_config(experiment: &SmallExperiment) -> Value {
    let text =
        std::fs::read_to_string(super::workspace().join("experiments/reproduce.json")).unwrap();
    let mut run: Value = serde_json::from_str(&text).unwrap();
    let path = |p: &Path| Value::from(p.to_str().unwrap());
    run["conditions"] = path(&experiment.conditions);
    run["published"] = path(&super::workspace().join("paper/published.json"));
    run["learn"]["config"] = path(&experiment.learn);
    run["learn"]["protocol"] = "leave-condition-out".into();
    run["learn"]["seeds"] = json!([1, 2]);
    run["variants"] = path(&experiment.variants);
    run
}

/// Five variants of experiments/variants.json (a library, a bagged one drawn in the figures,
/// LeARN, the headline average) and a two-member LeARN ensemble, two seeds.
fn variants(experiment: &SmallExperiment) -> Value {
    let text =
        std::fs::read_to_string(super::workspace().join("experiments/variants.json")).unwrap();
    let mut variants: Value = serde_json::from_str(&text).unwrap();
    let kept = [
        "lag-ridge-cv",
        "lag-ridge-bagged",
        "learn",
        "learn-lag-average",
    ];
    let mut list: Vec<Value> = variants["variants"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|v| kept.contains(&v["name"].as_str().unwrap()))
        .cloned()
        .collect();
    list.push(
        json!({"name": "learn-ensemble2", "description": "two members",
                     "kind": "learn_ensemble", "members": 2}),
    );
    variants["variants"] = list.into();
    variants["run"] = experiment.run.to_str().unwrap().into();
    variants["seeds"] = json!([1, 2]);
    variants["reproduce"] = json!(["lag-ridge-cv", "learn-lag-average"]);
    variants
}

/// Runs `learn` once per argument list, all at the same time, in `dir`; waits for every one.
pub fn learn_at_once(dir: &Path, runs: &[Vec<String>]) -> Vec<Run> {
    let children: Vec<_> = runs
        .iter()
        .map(|args| {
            Command::new(env!("CARGO_BIN_EXE_learn"))
                .args(args)
                .current_dir(dir)
                .env_remove("NEURAL_FLY_DIR")
                .env("RUST_BACKTRACE", "0")
                .stdout(std::process::Stdio::piped())
                .stderr(std::process::Stdio::piped())
                .spawn()
                .expect("the learn binary runs")
        })
        .collect();
    children
        .into_iter()
        .map(|child| {
            let output = child.wait_with_output().unwrap();
            Run {
                code: output.status.code(),
                stdout: String::from_utf8_lossy(&output.stdout).into_owned(),
                stderr: String::from_utf8_lossy(&output.stderr).into_owned(),
            }
        })
        .collect()
}

/// Every file under `dir` (relative path → bytes), but those named in `except`.
pub fn files_under(dir: &Path, except: &[&str]) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut files = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(next) = stack.pop() {
        for entry in std::fs::read_dir(&next).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if !except.iter().any(|e| path.ends_with(e)) {
                let relative = path.strip_prefix(dir).unwrap().to_path_buf();
                files.insert(relative, std::fs::read(&path).unwrap());
            }
        }
    }
    files
}
