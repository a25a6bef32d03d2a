//! Time per meta-iteration of LeARN (exact second order) at the paper's sizes, the Rust side of
//! `scripts/bench/learn.sh`. Synthetic data of the shape of the `full` formulation (I = 6, U = 4).
//!
//! cargo run -p learn --example meta_iteration_timing -- [TASKS] [SUPPORT] [QUERY] [ROUNDS] [REPEATS]
//!
//! Prints one JSON line: seconds per meta-iteration (median and minimum of the repeats) on one
//! thread and on the default rayon pool, with one reusable workspace per task as in `meta_train`.

use std::time::Instant;

use learn::{
    Architecture, Batch, InnerLoop, MetaOrder, MetaWorkspace, PAPER_HIDDEN, Task,
    meta_gradients_into,
};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use statrs::statistics::{Data, Min, OrderStatistics};

fn batch(rng: &mut ChaCha8Rng, rows: usize, architecture: &Architecture) -> Batch {
    Batch {
        inputs: (0..rows * architecture.input_dim)
            .map(|_| rng.random_range(-2.0..2.0))
            .collect(),
        targets: (0..rows * architecture.state_dim)
            .map(|_| rng.random_range(-1.0..1.0))
            .collect(),
    }
}

/// (median, minimum): of an even count the larger middle value.
fn median_and_min(values: Vec<f64>) -> (f64, f64) {
    let mut data = Data::new(values);
    let order = data.len() / 2 + 1;
    (data.order_statistic(order), data.min())
}

fn main() {
    let arguments: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("arguments are whole numbers"))
        .collect();
    let get = |i: usize, default: usize| arguments.get(i).copied().unwrap_or(default);
    let (tasks, support, query, rounds, repeats) =
        (get(0, 4), get(1, 64), get(2, 64), get(3, 1), get(4, 20));
    let architecture = Architecture {
        input_dim: 10,
        state_dim: 6,
        basis_per_input: 2,
        hidden: PAPER_HIDDEN.to_vec(),
    };
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    let task_list: Vec<Task> = (0..tasks)
        .map(|_| Task {
            support: batch(&mut rng, support, &architecture),
            query: batch(&mut rng, query, &architecture),
        })
        .collect();
    let mut parameters = architecture.initial_parameters(0);
    let inner = InnerLoop { step: 0.05, rounds };
    // Workspaces reused across iterations, as in `meta_train`: one per thread, or one in all.
    let mut pool_workspaces =
        vec![MetaWorkspace::new(&architecture); rayon::current_num_threads().clamp(1, tasks)];
    let mut single_workspace = vec![MetaWorkspace::new(&architecture)];
    // Per-task results and their mean reused across iterations, as in `meta_train`.
    let mut results = Vec::new();
    let mut gradient = vec![0.0; parameters.len()];
    let mut iteration = |parallel: bool, parameters: &mut Vec<f64>| {
        let started = Instant::now();
        let workspaces = if parallel {
            &mut pool_workspaces
        } else {
            &mut single_workspace
        };
        meta_gradients_into(
            workspaces,
            parameters,
            &task_list,
            inner,
            MetaOrder::Second,
            &mut results,
        );
        // The mean over tasks, as `meta_train` forms it.
        let scale = 1.0 / tasks as f64;
        gradient.fill(0.0);
        for result in &results {
            for (g, r) in gradient.iter_mut().zip(&result.gradient) {
                *g += r * scale;
            }
        }
        for (p, g) in parameters.iter_mut().zip(&gradient) {
            *p -= 1e-3 * g;
        }
        started.elapsed().as_secs_f64()
    };
    iteration(false, &mut parameters);
    let (one_thread, one_thread_min) = median_and_min(
        (0..repeats)
            .map(|_| iteration(false, &mut parameters))
            .collect(),
    );
    let (pool, pool_min) = median_and_min(
        (0..repeats)
            .map(|_| iteration(true, &mut parameters))
            .collect(),
    );
    println!(
        "{{\"implementation\": \"rust\", \"tasks\": {tasks}, \"support\": {support}, \"query\": {query}, \"inner_rounds\": {rounds}, \"parameters\": {}, \"threads\": {}, \"seconds_per_iteration_one_thread\": {one_thread:.6e}, \"seconds_per_iteration_one_thread_min\": {one_thread_min:.6e}, \"seconds_per_iteration\": {pool:.6e}, \"seconds_per_iteration_min\": {pool_min:.6e}}}",
        architecture.parameter_count(),
        rayon::current_num_threads()
    );
}
