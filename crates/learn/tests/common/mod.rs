//! Synthetic tasks, the workspace and temporary directories for the behaviour tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use learn::{Architecture, Batch, TaskData};

/// A small architecture for fast tests: 2 inputs, 1 state, P = 2.
pub fn small_architecture() -> Architecture {
    Architecture {
        input_dim: 2,
        state_dim: 1,
        basis_per_input: 2,
        hidden: vec![8, 8],
    }
}

/// y = a·sin(2·x0) + b·x1 on a time-ordered sweep of x; the task parameters (a, b) vary by task.
pub fn synthetic_batch(a: f64, b: f64, rows: usize, phase: f64) -> Batch {
    let mut batch = Batch::default();
    for k in 0..rows {
        let t = k as f64 / rows as f64 * 6.0 + phase;
        let (x0, x1) = (t.sin() * 1.5, (0.7 * t).cos());
        batch.inputs.extend([x0, x1]);
        batch.targets.push(a * (2.0 * x0).sin() + b * x1);
    }
    batch
}

/// Tasks with a in [0.5, 1.5], b in [−1, 1].
pub fn synthetic_tasks(count: usize) -> Vec<TaskData> {
    (0..count)
        .map(|i| {
            let a = 0.5 + i as f64 / count as f64;
            let b = -1.0 + 2.0 * ((i * 7) % count) as f64 / count as f64;
            TaskData {
                name: format!("task {i}"),
                support: synthetic_batch(a, b, 200, 0.0),
                query: synthetic_batch(a, b, 200, 3.0),
            }
        })
        .collect()
}

/// The workspace root.
pub fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A fresh temporary directory for one test, removed with everything in it when dropped.
pub fn temp_dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("{name}-"))
        .tempdir()
        .unwrap()
}
