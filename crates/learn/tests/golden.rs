//! Parity with JAX: the exact second-order and the first-order meta-gradients of two tasks (two
//! inner rounds) against `jax.grad` through the inner updates, computed by the JAX reference that
//! `make bench` times (values from `scripts/golden/learn_golden.py`, stored in
//! `scripts/golden/learn_golden.json`).

use std::path::Path;

use learn::{Architecture, Batch, InnerLoop, MetaOrder, Task, meta_gradient};
use serde_json::Value;

/// Agreement expected of two f64 implementations of the same sums in different orders.
const TOLERANCE: f64 = 1e-12;

fn golden() -> Value {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scripts/golden/learn_golden.json");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap()
}

fn numbers(value: &Value) -> Vec<f64> {
    serde_json::from_value(value.clone()).unwrap()
}

fn relative_error(ours: &[f64], theirs: &[f64]) -> f64 {
    assert_eq!(ours.len(), theirs.len());
    let difference: f64 = ours
        .iter()
        .zip(theirs)
        .map(|(a, b)| (a - b) * (a - b))
        .sum();
    let scale: f64 = theirs.iter().map(|b| b * b).sum();
    (difference / scale).sqrt()
}

#[test]
fn meta_gradients_match_jax() {
    let golden = golden();
    let architecture: Architecture =
        serde_json::from_value(golden["architecture"].clone()).unwrap();
    let parameters = numbers(&golden["parameters"]);
    assert_eq!(parameters.len(), architecture.parameter_count());
    let inner = InnerLoop {
        step: golden["inner_step"].as_f64().unwrap(),
        rounds: golden["inner_rounds"].as_u64().unwrap() as usize,
    };
    let tasks = golden["tasks"].as_array().unwrap();
    assert_eq!(tasks.len(), 2);
    for expected in tasks {
        let task = Task {
            support: Batch {
                inputs: numbers(&expected["support_inputs"]),
                targets: numbers(&expected["support_targets"]),
            },
            query: Batch {
                inputs: numbers(&expected["query_inputs"]),
                targets: numbers(&expected["query_targets"]),
            },
        };
        let second = meta_gradient(&architecture, &parameters, &task, inner, MetaOrder::Second);
        let first = meta_gradient(&architecture, &parameters, &task, inner, MetaOrder::First);
        let support_loss = expected["support_loss"].as_f64().unwrap();
        let query_loss = expected["query_loss"].as_f64().unwrap();
        assert!((second.support_loss - support_loss).abs() <= TOLERANCE * support_loss);
        assert!((second.query_loss - query_loss).abs() <= TOLERANCE * query_loss);
        let jax_second = numbers(&expected["second_order"]);
        let jax_first = numbers(&expected["first_order"]);
        let error = relative_error(&second.gradient, &jax_second);
        assert!(error < TOLERANCE, "second order: relative error {error:e}");
        let error = relative_error(&first.gradient, &jax_first);
        assert!(error < TOLERANCE, "first order: relative error {error:e}");
        // The two orders differ by far more than the tolerance, so each check tells them apart.
        assert!(relative_error(&jax_first, &jax_second) > 1e-3);
    }
}
