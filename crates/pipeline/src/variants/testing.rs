//! What the variants' tests share: variants files written to temporary files, and a synthetic
//! segment.

use crate::segment::Segment;
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
        .prefix(&format!("pipeline-variants-{name}-"))
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
