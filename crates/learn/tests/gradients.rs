//! Every derivative against central finite differences in f64.

use learn::{
    Architecture, Batch, InnerLoop, MetaOrder, MetaWorkspace, ModelWorkspace, Task,
    hessian_vector_product, inner_updates, meta_gradient, meta_gradient_in, meta_gradients,
    meta_gradients_into, reference_hessian_vector_product, reference_meta_gradient,
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

/// A task of the paper's sizes (the `full` formulation: I = 6, U = 4) on random data.
fn paper_sized_setup() -> (Architecture, Vec<f64>, Task) {
    let architecture = Architecture {
        input_dim: 10,
        state_dim: 6,
        basis_per_input: 2,
        hidden: learn::PAPER_HIDDEN.to_vec(),
    };
    let mut rng = ChaCha8Rng::seed_from_u64(21);
    let parameters = architecture.initial_parameters(9);
    let task = Task {
        support: random_batch(&mut rng, 64, &architecture),
        query: random_batch(&mut rng, 13, &architecture),
    };
    (architecture, parameters, task)
}

#[test]
fn batched_fast_path_equals_the_generic_reference() {
    for (architecture, parameters, task) in [setup(), paper_sized_setup()] {
        let batch = &task.support;
        let prediction = architecture.predict(&parameters, &batch.inputs);
        let reference = architecture.reference_predict(&parameters, &batch.inputs);
        assert!(relative_error(&prediction, &reference) < 1e-12);
        let (loss, gradient) =
            architecture.loss_and_gradient(&parameters, &batch.inputs, &batch.targets);
        let (reference_loss, reference_gradient) =
            architecture.reference_loss_and_gradient(&parameters, &batch.inputs, &batch.targets);
        assert!((loss - reference_loss).abs() < 1e-12 * reference_loss);
        let error = relative_error(&gradient, &reference_gradient);
        assert!(error < 1e-12, "gradient: {error:e}");
        let direction: Vec<f64> = parameters.iter().map(|p| (p * 37.0).sin()).collect();
        let (_, product) = hessian_vector_product(&architecture, &parameters, &direction, batch);
        let (_, reference_product) =
            reference_hessian_vector_product(&architecture, &parameters, &direction, batch);
        let error = relative_error(&product, &reference_product);
        assert!(error < 1e-12, "H·v: {error:e}");
        for rounds in [0, 1, 2] {
            for order in [MetaOrder::Second, MetaOrder::First] {
                let inner = InnerLoop { step: 0.3, rounds };
                let fast = meta_gradient(&architecture, &parameters, &task, inner, order);
                let reference =
                    reference_meta_gradient(&architecture, &parameters, &task, inner, order);
                let error = relative_error(&fast.gradient, &reference.gradient);
                assert!(error < 1e-12, "meta-gradient n = {rounds}: {error:e}");
                assert!(
                    (fast.query_loss - reference.query_loss).abs() < 1e-12 * reference.query_loss
                );
                assert!(
                    (fast.support_loss - reference.support_loss).abs()
                        < 1e-12 * reference.support_loss
                );
            }
        }
    }
}

#[test]
fn reused_workspaces_give_the_same_meta_gradient_as_fresh_ones() {
    let (architecture, parameters, task) = paper_sized_setup();
    let (_, _, other) = setup();
    let inner = InnerLoop {
        step: 0.2,
        rounds: 2,
    };
    let mut workspace = MetaWorkspace::new(&architecture);
    // A different batch size first, so the buffers have to be resized.
    let small_task = Task {
        support: Batch {
            inputs: task.support.inputs[..30].to_vec(),
            targets: task.support.targets[..18].to_vec(),
        },
        query: task.query.clone(),
    };
    let _ = meta_gradient_in(
        &mut workspace,
        &parameters,
        &small_task,
        inner,
        MetaOrder::Second,
    );
    let reused = meta_gradient_in(&mut workspace, &parameters, &task, inner, MetaOrder::Second);
    let fresh = meta_gradient(&architecture, &parameters, &task, inner, MetaOrder::Second);
    assert_eq!(reused, fresh);
    assert!(other.support.inputs.len() != task.support.inputs.len());
}

#[test]
fn meta_gradients_of_a_batch_do_not_depend_on_the_number_of_workspaces() {
    let (architecture, parameters, _) = setup();
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let tasks: Vec<Task> = (0..5)
        .map(|_| Task {
            support: random_batch(&mut rng, 6, &architecture),
            query: random_batch(&mut rng, 5, &architecture),
        })
        .collect();
    let inner = InnerLoop {
        step: 0.3,
        rounds: 1,
    };
    let one_by_one: Vec<_> = tasks
        .iter()
        .map(|task| meta_gradient(&architecture, &parameters, task, inner, MetaOrder::Second))
        .collect();
    for count in [1, 2, 3, 7] {
        let mut workspaces = vec![MetaWorkspace::new(&architecture); count];
        let batch = meta_gradients(
            &mut workspaces,
            &parameters,
            &tasks,
            inner,
            MetaOrder::Second,
        );
        assert_eq!(batch, one_by_one, "{count} workspaces");
    }
    // Reused result buffers (a longer list first, so it has to shrink) give the same bits.
    let mut workspaces = vec![MetaWorkspace::new(&architecture); 2];
    let mut results = Vec::new();
    let longer: Vec<Task> = tasks.iter().chain(&tasks).cloned().collect();
    for batch in [&longer, &tasks, &tasks] {
        meta_gradients_into(
            &mut workspaces,
            &parameters,
            batch,
            inner,
            MetaOrder::Second,
            &mut results,
        );
    }
    assert_eq!(results, one_by_one);
}

#[test]
fn a_workspace_for_gradients_only_gives_the_same_bits_and_refuses_hessian_products() {
    let (architecture, parameters, task) = paper_sized_setup();
    let batch = &task.support;
    let mut full = ModelWorkspace::new(&architecture);
    let mut gradients_only = ModelWorkspace::new(&architecture).for_gradients_only();
    let mut gradient = vec![0.0; parameters.len()];
    let mut gradient_only = vec![0.0; parameters.len()];
    let loss = full.mse_and_gradient(&parameters, &batch.inputs, &batch.targets, &mut gradient);
    let loss_only = gradients_only.mse_and_gradient(
        &parameters,
        &batch.inputs,
        &batch.targets,
        &mut gradient_only,
    );
    assert_eq!((loss, &gradient), (loss_only, &gradient_only));
    let refused = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let mut product = vec![0.0; parameters.len()];
        gradients_only.hessian_vector_product(&parameters, &gradient, &mut product);
    }));
    assert!(refused.is_err());
}
