//! Meta-training (Algorithm 1 of the paper) over in-memory tasks.
//!
//! Each meta-iteration draws `task_batch` tasks (a fresh shuffle of all tasks, consumed in order),
//! then for each task `support_batch` rows of its support segment and `query_batch` rows of its query
//! segment (uniformly, with replacement). All random draws happen on one thread from one ChaCha8
//! stream; the per-task meta-gradients are computed in parallel with rayon and summed in task order,
//! so the result is bit-identical for any number of threads.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::averaging::IterateMean;
use crate::config::{MetaTrainingConfig, Optimizer};
use crate::error::{LearnError, Result};
use crate::maml::{Batch, InnerLoop, MetaGradient, MetaWorkspace, Task, meta_gradients_into};
use crate::network::Architecture;

/// The regression data of one meta-training task (one flight): its support and query segments.
#[derive(Clone, Debug, PartialEq)]
pub struct TaskData {
    /// Where the task comes from (a file name, or a label for synthetic data).
    pub name: String,
    pub support: Batch,
    pub query: Batch,
}

/// What meta-training returns.
#[derive(Clone, Debug, PartialEq)]
pub struct MetaTrainingOutcome {
    /// The meta-trained θ = [ψ; φ].
    pub parameters: Vec<f64>,
    /// Mean meta-loss L_q(θ_n) over the batch of tasks, per iteration.
    pub meta_loss_history: Vec<f64>,
    /// Mean support loss L_s(θ) before the inner rounds, per iteration.
    pub support_loss_history: Vec<f64>,
}

/// Adam's state.
struct Adam {
    first: Vec<f64>,
    second: Vec<f64>,
    step: i32,
}

impl Adam {
    fn new(size: usize) -> Self {
        Self {
            first: vec![0.0; size],
            second: vec![0.0; size],
            step: 0,
        }
    }

    fn update(&mut self, parameters: &mut [f64], gradient: &[f64], rate: f64) {
        const DECAY_FIRST: f64 = 0.9;
        const DECAY_SECOND: f64 = 0.999;
        const EPSILON: f64 = 1e-8;
        self.step += 1;
        let correction_first = 1.0 - DECAY_FIRST.powi(self.step);
        let correction_second = 1.0 - DECAY_SECOND.powi(self.step);
        for (((p, &g), m), v) in parameters
            .iter_mut()
            .zip(gradient)
            .zip(&mut self.first)
            .zip(&mut self.second)
        {
            *m = DECAY_FIRST * *m + (1.0 - DECAY_FIRST) * g;
            *v = DECAY_SECOND * *v + (1.0 - DECAY_SECOND) * g * g;
            let m_hat = *m / correction_first;
            let v_hat = *v / correction_second;
            *p -= rate * m_hat / (v_hat.sqrt() + EPSILON);
        }
    }
}

fn sample_rows(rng: &mut ChaCha8Rng, source: &Batch, input_dim: usize, count: usize) -> Batch {
    let output_dim = source.targets.len() * input_dim / source.inputs.len();
    let rows = source.inputs.len() / input_dim;
    let mut batch = Batch {
        inputs: Vec::with_capacity(count * input_dim),
        targets: Vec::with_capacity(count * output_dim),
    };
    for _ in 0..count {
        let row = rng.random_range(0..rows);
        batch
            .inputs
            .extend_from_slice(&source.inputs[row * input_dim..(row + 1) * input_dim]);
        batch
            .targets
            .extend_from_slice(&source.targets[row * output_dim..(row + 1) * output_dim]);
    }
    batch
}

/// Draws the tasks of every iteration up front (one stream), so that sampling never depends on
/// thread scheduling.
struct TaskSampler {
    rng: ChaCha8Rng,
    order: Vec<usize>,
    next: usize,
}

impl TaskSampler {
    fn new(seed: u64, task_count: usize) -> Self {
        Self {
            // Decorrelated from the initialisation stream, which uses `seed` itself.
            rng: ChaCha8Rng::seed_from_u64(seed ^ 0x5eed_7a5c_0b5e_55ed),
            order: (0..task_count).collect(),
            next: task_count,
        }
    }

    fn next_task(&mut self) -> usize {
        if self.next == self.order.len() {
            for i in (1..self.order.len()).rev() {
                let j = self.rng.random_range(0..=i);
                self.order.swap(i, j);
            }
            self.next = 0;
        }
        self.next += 1;
        self.order[self.next - 1]
    }

    fn draw(
        &mut self,
        tasks: &[TaskData],
        input_dim: usize,
        config: &MetaTrainingConfig,
    ) -> Vec<Task> {
        (0..config.task_batch)
            .map(|_| {
                let task = &tasks[self.next_task()];
                Task {
                    support: sample_rows(
                        &mut self.rng,
                        &task.support,
                        input_dim,
                        config.support_batch,
                    ),
                    query: sample_rows(&mut self.rng, &task.query, input_dim, config.query_batch),
                }
            })
            .collect()
    }
}

/// The bounds of the batch sizes that depend on the tasks: a batch of tasks holds distinct tasks
/// (they are drawn without replacement within a batch), and a task's support or query batch is no
/// larger than the segment it is drawn from (with replacement: a larger batch holds no sample the
/// segment does not, only repeats). `Err((field, message))` names the offending setting.
pub fn check_sampling(
    config: &MetaTrainingConfig,
    tasks: &[TaskData],
    input_dim: usize,
) -> std::result::Result<(), (&'static str, String)> {
    let bound = |value: usize, most: usize, what: String| {
        if value == 0 {
            Some("must be at least 1".to_string())
        } else if value > most {
            Some(format!("must be at most {most}, the {what}, not {value}"))
        } else {
            None
        }
    };
    if let Some(message) = bound(
        config.task_batch,
        tasks.len(),
        "meta-training tasks a batch draws from without replacement".to_string(),
    ) {
        return Err(("meta_training.task_batch", message));
    }
    for task in tasks {
        let rows = |batch: &Batch| batch.inputs.len() / input_dim.max(1);
        for (field, value, segment, data) in [
            (
                "meta_training.support_batch",
                config.support_batch,
                "support",
                &task.support,
            ),
            (
                "meta_training.query_batch",
                config.query_batch,
                "query",
                &task.query,
            ),
        ] {
            let what = format!("samples of the {segment} segment of {}", task.name);
            if let Some(message) = bound(value, rows(data), what) {
                return Err((field, message));
            }
        }
    }
    Ok(())
}

/// Meta-trains from the seeded initialisation on `tasks` (inputs already standardised).
pub fn meta_train(
    architecture: &Architecture,
    tasks: &[TaskData],
    config: &MetaTrainingConfig,
    seed: u64,
) -> Result<MetaTrainingOutcome> {
    meta_train_from(
        architecture,
        architecture.initial_parameters(seed),
        tasks,
        config,
        seed,
    )
}

/// Meta-trains from given parameters (the task stream is still seeded by `seed`).
pub fn meta_train_from(
    architecture: &Architecture,
    parameters: Vec<f64>,
    tasks: &[TaskData],
    config: &MetaTrainingConfig,
    seed: u64,
) -> Result<MetaTrainingOutcome> {
    meta_train_observed(architecture, parameters, tasks, config, seed, &|_| {})
}

/// [`meta_train_from`], calling `iteration_done` with the number of iterations finished after
/// each one (for a progress bar).
pub fn meta_train_observed(
    architecture: &Architecture,
    mut parameters: Vec<f64>,
    tasks: &[TaskData],
    config: &MetaTrainingConfig,
    seed: u64,
    iteration_done: &dyn Fn(usize),
) -> Result<MetaTrainingOutcome> {
    if tasks.is_empty() {
        return Err(LearnError::Mismatch {
            what: "meta-training".to_string(),
            message: "no tasks".to_string(),
        });
    }
    check_sampling(config, tasks, architecture.input_dim).map_err(|(what, message)| {
        LearnError::Mismatch {
            what: what.to_string(),
            message,
        }
    })?;
    let inner = InnerLoop {
        step: config.inner_step,
        rounds: config.inner_rounds,
    };
    let mut sampler = TaskSampler::new(seed, tasks.len());
    let mut adam = Adam::new(parameters.len());
    // One workspace per thread (not per task): a smaller working set per cache.
    let workspace_count = rayon::current_num_threads().clamp(1, config.task_batch.max(1));
    let mut workspaces = vec![MetaWorkspace::new(architecture); workspace_count];
    // The mean of the iterates after the last `average_last` updates.
    let first_averaged = config.iterations - config.average_last.min(config.iterations);
    let mut average = IterateMean::new(parameters.len(), config.average_last > 0);
    let mut meta_loss_history = Vec::with_capacity(config.iterations);
    let mut support_loss_history = Vec::with_capacity(config.iterations);
    // Buffers reused across iterations: the per-task meta-gradients and their mean.
    let mut results: Vec<MetaGradient> = Vec::new();
    let mut gradient = vec![0.0; parameters.len()];
    for iteration in 0..config.iterations {
        let batch = sampler.draw(tasks, architecture.input_dim, config);
        meta_gradients_into(
            &mut workspaces,
            &parameters,
            &batch,
            inner,
            config.order,
            &mut results,
        );
        let scale = 1.0 / results.len() as f64;
        for (g, p) in gradient.iter_mut().zip(&parameters) {
            *g = 2.0 * config.meta_regularisation * p;
        }
        let (mut meta_loss, mut support_loss) = (0.0, 0.0);
        for result in &results {
            meta_loss += result.query_loss * scale;
            support_loss += result.support_loss * scale;
            for (g, r) in gradient.iter_mut().zip(&result.gradient) {
                *g += r * scale;
            }
        }
        if !meta_loss.is_finite() || gradient.iter().any(|g| !g.is_finite()) {
            return Err(LearnError::Diverged {
                iteration,
                loss: meta_loss,
            });
        }
        meta_loss_history.push(meta_loss);
        support_loss_history.push(support_loss);
        match config.optimizer {
            Optimizer::Sgd => {
                for (p, g) in parameters.iter_mut().zip(&gradient) {
                    *p -= config.outer_step * g;
                }
            }
            Optimizer::Adam => adam.update(&mut parameters, &gradient, config.outer_step),
        }
        if iteration >= first_averaged {
            average.add(&parameters);
        }
        iteration_done(iteration + 1);
    }
    let parameters = average.finish(parameters);
    // The last update can overflow although every gradient was finite.
    if parameters.iter().any(|p| !p.is_finite()) {
        return Err(LearnError::Diverged {
            iteration: config.iterations.saturating_sub(1),
            loss: meta_loss_history.last().copied().unwrap_or(f64::NAN),
        });
    }
    Ok(MetaTrainingOutcome {
        parameters,
        meta_loss_history,
        support_loss_history,
    })
}
