//! Helpers shared by the behaviour tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use sindy::Mat;

/// The workspace root.
pub fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A JSON file of `scripts/golden/`.
pub fn golden(name: &str) -> serde_json::Value {
    json(&format!("scripts/golden/{name}"))
}

/// A JSON file of the workspace, by relative path.
pub fn json(relative: &str) -> serde_json::Value {
    let path = workspace().join(relative);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap()
}

/// A matrix from a JSON array of rows.
pub fn matrix(value: &serde_json::Value) -> Mat<f64> {
    let rows: Vec<Vec<f64>> = serde_json::from_value(value.clone()).unwrap();
    Mat::from_fn(rows.len(), rows[0].len(), |i, j| rows[i][j])
}

/// Fixed-step RK4 of `f` from `x0`, `steps` steps of `h`, returning every state (row per step).
pub fn integrate(
    f: impl Fn(f64, &[f64]) -> Vec<f64>,
    x0: &[f64],
    h: f64,
    steps: usize,
) -> Vec<Vec<f64>> {
    let mut out = vec![x0.to_vec()];
    let mut x = x0.to_vec();
    for k in 0..steps {
        let t = k as f64 * h;
        let add = |x: &[f64], d: &[f64], s: f64| -> Vec<f64> {
            x.iter().zip(d).map(|(a, b)| a + s * b).collect()
        };
        let k1 = f(t, &x);
        let k2 = f(t + h / 2.0, &add(&x, &k1, h / 2.0));
        let k3 = f(t + h / 2.0, &add(&x, &k2, h / 2.0));
        let k4 = f(t + h, &add(&x, &k3, h));
        for j in 0..x.len() {
            x[j] += h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]);
        }
        out.push(x.clone());
    }
    out
}
