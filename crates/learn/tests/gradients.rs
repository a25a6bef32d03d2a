//! Every derivative against central finite differences in f64.

use learn::{
    Architecture, Batch, InnerLoop, MetaOrder, Task, hessian_vector_product, inner_updates,
    meta_gradient,
};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

const STEP: f64 = 1e-5;
const TOLERANCE: f64 = 1e-6;

fn small_architecture() -> Architecture {
    Architecture {
        input_dim: 3,
        state_dim: 2,
        basis_per_input: 2,
        hidden: vec![5, 4],
    }
}

fn random_batch(rng: &mut ChaCha8Rng, rows: usize, architecture: &Architecture) -> Batch {
    Batch {
        inputs: (0..rows * architecture.input_dim)
            .map(|_| rng.random_range(-1.5..1.5))
            .collect(),
        targets: (0..rows * architecture.state_dim)
            .map(|_| rng.random_range(-1.0..1.0))
            .collect(),
    }
}

fn relative_error(a: &[f64], b: &[f64]) -> f64 {
    let difference: f64 = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum();
    let scale = a
        .iter()
        .map(|x| x * x)
        .sum::<f64>()
        .max(b.iter().map(|x| x * x).sum::<f64>());
    (difference / scale).sqrt()
}

/// Central differences of a scalar function of θ, one coordinate at a time.
fn numerical_gradient(parameters: &[f64], f: impl Fn(&[f64]) -> f64) -> Vec<f64> {
    let mut point = parameters.to_vec();
    (0..parameters.len())
        .map(|i| {
            point[i] = parameters[i] + STEP;
            let up = f(&point);
            point[i] = parameters[i] - STEP;
            let down = f(&point);
            point[i] = parameters[i];
            (up - down) / (2.0 * STEP)
        })
        .collect()
}

fn setup() -> (Architecture, Vec<f64>, Task) {
    let architecture = small_architecture();
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let parameters = architecture.initial_parameters(5);
    let task = Task {
        support: random_batch(&mut rng, 6, &architecture),
        query: random_batch(&mut rng, 7, &architecture),
    };
    (architecture, parameters, task)
}

#[test]
fn loss_gradient_of_both_networks_matches_finite_differences() {
    let (architecture, parameters, task) = setup();
    let batch = &task.support;
    let (_, analytic) = architecture.loss_and_gradient(&parameters, &batch.inputs, &batch.targets);
    let numeric = numerical_gradient(&parameters, |p| {
        architecture.loss(p, &batch.inputs, &batch.targets)
    });
    let split = architecture.library_parameter_count();
    let library = relative_error(&analytic[..split], &numeric[..split]);
    let selection = relative_error(&analytic[split..], &numeric[split..]);
    assert!(
        library < TOLERANCE,
        "Θ (ψ) gradient: relative error {library:e}"
    );
    assert!(
        selection < TOLERANCE,
        "ℰ (φ) gradient: relative error {selection:e}"
    );
}

#[test]
fn hessian_vector_product_matches_finite_differences_of_the_gradient() {
    let (architecture, parameters, task) = setup();
    let batch = &task.support;
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let direction: Vec<f64> = (0..parameters.len())
        .map(|_| rng.random_range(-1.0..1.0))
        .collect();
    let (_, product) = hessian_vector_product(&architecture, &parameters, &direction, batch);
    let shifted = |sign: f64| -> Vec<f64> {
        let point: Vec<f64> = parameters
            .iter()
            .zip(&direction)
            .map(|(p, v)| p + sign * STEP * v)
            .collect();
        architecture
            .loss_and_gradient(&point, &batch.inputs, &batch.targets)
            .1
    };
    let (up, down) = (shifted(1.0), shifted(-1.0));
    let numeric: Vec<f64> = up
        .iter()
        .zip(&down)
        .map(|(a, b)| (a - b) / (2.0 * STEP))
        .collect();
    let error = relative_error(&product, &numeric);
    assert!(error < TOLERANCE, "H·v: relative error {error:e}");
}

#[test]
fn inner_updated_parameters_have_the_predicted_jacobian() {
    // θ′(θ) = θ − α∇L_s(θ); its Jacobian-vector product is v − α·H_s(θ)·v.
    let (architecture, parameters, task) = setup();
    let inner = InnerLoop {
        step: 0.3,
        rounds: 1,
    };
    let mut rng = ChaCha8Rng::seed_from_u64(8);
    let direction: Vec<f64> = (0..parameters.len())
        .map(|_| rng.random_range(-1.0..1.0))
        .collect();
    let (_, product) =
        hessian_vector_product(&architecture, &parameters, &direction, &task.support);
    let analytic: Vec<f64> = direction
        .iter()
        .zip(&product)
        .map(|(v, hv)| v - inner.step * hv)
        .collect();
    let adapted = |sign: f64| -> Vec<f64> {
        let point: Vec<f64> = parameters
            .iter()
            .zip(&direction)
            .map(|(p, v)| p + sign * STEP * v)
            .collect();
        inner_updates(&architecture, &point, &task.support, inner).0[1].clone()
    };
    let (up, down) = (adapted(1.0), adapted(-1.0));
    let numeric: Vec<f64> = up
        .iter()
        .zip(&down)
        .map(|(a, b)| (a - b) / (2.0 * STEP))
        .collect();
    let error = relative_error(&analytic, &numeric);
    assert!(error < TOLERANCE, "dθ′/dθ·v: relative error {error:e}");
}

fn meta_loss(
    architecture: &Architecture,
    parameters: &[f64],
    task: &Task,
    inner: InnerLoop,
) -> f64 {
    let (trajectory, _) = inner_updates(architecture, parameters, &task.support, inner);
    architecture.loss(
        trajectory.last().unwrap(),
        &task.query.inputs,
        &task.query.targets,
    )
}

#[test]
fn second_order_meta_gradient_matches_finite_differences_and_first_order_does_not() {
    let (architecture, parameters, task) = setup();
    for rounds in [1, 2, 3] {
        let inner = InnerLoop { step: 0.4, rounds };
        let numeric =
            numerical_gradient(&parameters, |p| meta_loss(&architecture, p, &task, inner));
        let second = meta_gradient(&architecture, &parameters, &task, inner, MetaOrder::Second);
        let first = meta_gradient(&architecture, &parameters, &task, inner, MetaOrder::First);
        let second_error = relative_error(&second.gradient, &numeric);
        let first_error = relative_error(&first.gradient, &numeric);
        assert!(
            second_error < TOLERANCE,
            "n = {rounds}: second-order relative error {second_error:e}"
        );
        assert!(
            first_error > 1e3 * TOLERANCE,
            "n = {rounds}: first order should differ, relative error {first_error:e}"
        );
        assert!(relative_error(&first.gradient, &second.gradient) > 1e-3);
        let loss = meta_loss(&architecture, &parameters, &task, inner);
        assert!((second.query_loss - loss).abs() < 1e-14 * loss);
    }
}
