//! What the variants' tests share: variants files written to temporary files, a synthetic
//! segment, a cell of two segments and the variants run on it.

use std::sync::Arc;

use crate::error::Result;
use crate::experiment::EvaluationCell;
use crate::flights::Flight;
use crate::runner::{Method, Models, Outcome, Runner, Train};
use crate::segment::Segment;
use crate::variants::VariantSpec;
use learn::Formulation;
use sindy::Mat;

/// A synthetic attitude segment of `n` samples with targets that depend on the inputs.
pub(super) fn segment(n: usize, phase: f64) -> Segment {
    let states = Mat::from_fn(n, 3, |i, j| (0.05 * i as f64 + j as f64 + phase).sin());
    let controls = Mat::from_fn(n, 4, |i, j| 1.0 + 0.2 * (0.03 * i as f64 - j as f64).cos());
    let targets = Mat::from_fn(n, 3, |i, j| {
        0.7 * states[(i, j)] - 0.4 * controls[(i, j + 1)] + 0.05 * ((i * 7919) % 13) as f64
    });
    Segment {
        formulation: Formulation::Attitude,
        rows: 0..n,
        time: (0..n).map(|i| i as f64 * 0.02).collect(),
        states,
        controls,
        targets,
    }
}

/// A temporary `.json` file holding `text`, removed when dropped.
pub(super) fn write(name: &str, text: &str) -> tempfile::TempPath {
    let mut file = tempfile::Builder::new()
        .prefix(&format!("evaluation-variants-{name}-"))
        .suffix(".json")
        .tempfile()
        .unwrap();
    std::io::Write::write_all(&mut file, text.as_bytes()).unwrap();
    file.into_temp_path()
}

/// A variants file with `variants` (headline `a`) and the `extra` fields.
pub(super) fn config(variants: &str, extra: &str) -> String {
    format!(
        r#"{{"name": "t", "description": "d", "run": "experiments/reproduce.json",
           "seeds": [1], "headline": "a", {extra} "variants": [{variants}]}}"#
    )
}

pub(super) const RIDGE: &str = r#""kind": "library", "library": {"linear": true},
    "regression": {"penalty": {"kind": "ridge", "lambdas": [0.0]}}"#;
pub(super) const LEARNED: &str = r#""kind": "learned_basis", "features": "basis",
    "regression": {"penalty": {"kind": "ridge", "lambdas": [0.0]}}"#;

/// A cell of `support` and `query` on a flight without samples (the variants read the segments
/// only).
pub(super) fn cell(support: Segment, query: Segment) -> EvaluationCell {
    let log = data::FlightLog {
        path: "synthetic.csv".into(),
        meta: None,
        time: Vec::new(),
        position: Vec::new(),
        velocity: Vec::new(),
        quaternion: Vec::new(),
        rotation: Vec::new(),
        body_rate: Vec::new(),
        thrust_setpoint: Vec::new(),
        hover_throttle: Vec::new(),
        motor_command: Default::default(),
        battery_voltage: None,
        declared_rate_frame: None,
        position_desired: None,
        velocity_desired: None,
        attitude_setpoint: None,
        residual_force: None,
    };
    EvaluationCell {
        formulation: support.formulation,
        condition: serde_json::from_str(
            r#"{"name": "synthetic", "wind_speed": "0 m/s", "role": "evaluation"}"#,
        )
        .unwrap(),
        flight: Arc::new(Flight {
            log,
            file: learn::DataFile {
                path: "synthetic.csv".into(),
                sha256: String::new(),
            },
        }),
        support,
        query,
    }
}

/// Every variant of `variants` on `cell` with `seed`, in order, the networks meta-trained by
/// `train`.
pub(super) fn evaluate(
    variants: &[VariantSpec],
    train: &Train<'_>,
    cell: &EvaluationCell,
    seed: u64,
) -> Result<Vec<Outcome>> {
    let runner = Runner::new(variants.iter().map(|v| v as &dyn Method), Some(train));
    runner.evaluate(cell, seed, &mut Models::new(cell, Some(train)))
}
