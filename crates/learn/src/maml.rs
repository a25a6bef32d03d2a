//! Model-agnostic meta-learning for one task: the inner SGD rounds and the exact meta-gradient.
//!
//! With θ₀ = θ and θ_{k+1} = θ_k − α·∇L_s(θ_k) (k < n), the meta-loss of a task is L_q(θ_n) and
//! its exact gradient is
//!
//! ∇_θ L_q(θ_n) = (I − α·H_s(θ₀)) ⋯ (I − α·H_s(θ_{n−1})) · ∇L_q(θ_n),
//!
//! evaluated right to left with Hessian-vector products (g ← g − α·H_s(θ_k)·g for k = n−1 … 0), each
//! one Pearlmutter's R-operator on the batched passes ([`ModelWorkspace`]), which reuses the support
//! forward and backward passes of the inner round at θ_k. The first-order variant keeps only
//! ∇L_q(θ_n). The `reference_*` functions compute the same quantities with the generic scalar code
//! (the Hessian-vector product as a reverse pass run on dual numbers); the tests hold the fast path
//! to them.

use serde::{Deserialize, Serialize};

use crate::batched::ModelWorkspace;
use crate::network::Architecture;
use crate::scalar::Dual;

/// Whether the meta-gradient differentiates through the inner updates.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum MetaOrder {
    /// Exact: through the inner updates (Hessian-vector products).
    Second,
    /// First-order MAML: the query gradient at the adapted parameters only.
    First,
}

/// Regression data of one batch: inputs batch × (I+U) and targets batch × I, row-major.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Batch {
    pub inputs: Vec<f64>,
    pub targets: Vec<f64>,
}

impl Batch {
    /// Appends `other`'s rows (same input and output widths) after this batch's.
    pub fn append(&mut self, other: Batch) {
        self.inputs.extend(other.inputs);
        self.targets.extend(other.targets);
    }
}

/// A task's support batch (inner updates) and query batch (meta-loss).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Task {
    pub support: Batch,
    pub query: Batch,
}

/// The inner loop settings: n rounds of SGD with step α.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InnerLoop {
    pub step: f64,
    pub rounds: usize,
}

/// The meta-gradient of one task and the losses seen on the way.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MetaGradient {
    /// L_s(θ), the support loss before adaptation.
    pub support_loss: f64,
    /// L_q(θ_n), the meta-loss after the inner rounds.
    pub query_loss: f64,
    /// ∇_θ L_q(θ_n).
    pub gradient: Vec<f64>,
}

/// H(θ)·v of the mean squared error on `batch`, with the gradient ∇L(θ) as a by-product.
pub fn hessian_vector_product(
    architecture: &Architecture,
    parameters: &[f64],
    direction: &[f64],
    batch: &Batch,
) -> (Vec<f64>, Vec<f64>) {
    let mut workspace = ModelWorkspace::new(architecture);
    let mut gradient = vec![0.0; parameters.len()];
    let mut product = vec![0.0; parameters.len()];
    workspace.mse_and_gradient(parameters, &batch.inputs, &batch.targets, &mut gradient);
    workspace.hessian_vector_product(parameters, direction, &mut product);
    (gradient, product)
}

/// [`hessian_vector_product`] by the generic reference code on dual numbers (forward-over-reverse).
pub fn reference_hessian_vector_product(
    architecture: &Architecture,
    parameters: &[f64],
    direction: &[f64],
    batch: &Batch,
) -> (Vec<f64>, Vec<f64>) {
    let dual: Vec<Dual> = parameters
        .iter()
        .zip(direction)
        .map(|(&p, &v)| Dual::new(p, v))
        .collect();
    let (_, gradient) =
        architecture.reference_loss_and_gradient(&dual, &batch.inputs, &batch.targets);
    gradient.into_iter().map(|d| (d.value, d.tangent)).unzip()
}

/// θ₀ … θ_n of the inner SGD rounds on `support`, and L_s(θ₀).
pub fn inner_updates(
    architecture: &Architecture,
    parameters: &[f64],
    support: &Batch,
    inner: InnerLoop,
) -> (Vec<Vec<f64>>, f64) {
    let mut workspace = MetaWorkspace::new(architecture);
    let support_loss = workspace.inner_rounds(parameters, support, inner);
    let mut trajectory = vec![parameters.to_vec()];
    trajectory.extend_from_slice(&workspace.trajectory[..inner.rounds]);
    (trajectory, support_loss)
}

/// Reusable buffers of [`meta_gradient_in`]: one support workspace per inner round (their passes
/// are reused by the Hessian-vector products), one for the query batch, the inner iterates
/// θ₁ … θ_n (θ₀ is the caller's parameters, not copied).
#[derive(Clone, Debug)]
pub struct MetaWorkspace {
    support: Vec<ModelWorkspace>,
    query: ModelWorkspace,
    trajectory: Vec<Vec<f64>>,
    gradient: Vec<f64>,
    product: Vec<f64>,
}

impl MetaWorkspace {
    /// Empty buffers for `architecture`.
    pub fn new(architecture: &Architecture) -> Self {
        Self {
            support: Vec::new(),
            // The query batch only ever takes a gradient (no Hessian product): no GELU″.
            query: ModelWorkspace::new(architecture).for_gradients_only(),
            trajectory: Vec::new(),
            gradient: Vec::new(),
            product: Vec::new(),
        }
    }

    /// Runs the inner rounds; `trajectory[..rounds]` holds θ₁ … θ_n. Returns L_s(θ₀).
    fn inner_rounds(&mut self, parameters: &[f64], support: &Batch, inner: InnerLoop) -> f64 {
        while self.support.len() < inner.rounds.max(1) {
            let architecture = self.query.architecture().clone();
            self.support.push(ModelWorkspace::new(&architecture));
        }
        self.trajectory
            .resize_with(self.trajectory.len().max(inner.rounds), Vec::new);
        self.gradient.resize(parameters.len(), 0.0);
        let mut first_loss = f64::NAN;
        for round in 0..inner.rounds {
            let (done, rest) = self.trajectory.split_at_mut(round);
            let current = inner_point(done, parameters, round);
            let loss = self.support[round].mse_and_gradient(
                current,
                &support.inputs,
                &support.targets,
                &mut self.gradient,
            );
            if round == 0 {
                first_loss = loss;
            }
            let next = &mut rest[0];
            next.clear();
            next.extend(
                current
                    .iter()
                    .zip(&self.gradient)
                    .map(|(p, g)| p - inner.step * g),
            );
        }
        if inner.rounds == 0 {
            let prediction = self.support[0].forward(parameters, &support.inputs);
            first_loss = crate::network::mean_squared_error(prediction, &support.targets);
        }
        first_loss
    }
}

/// The meta-gradient of one task (see the module documentation).
pub fn meta_gradient(
    architecture: &Architecture,
    parameters: &[f64],
    task: &Task,
    inner: InnerLoop,
    order: MetaOrder,
) -> MetaGradient {
    meta_gradient_in(
        &mut MetaWorkspace::new(architecture),
        parameters,
        task,
        inner,
        order,
    )
}

/// θ_round of the inner loop: the meta-parameters for round 0, else the stored inner iterate.
fn inner_point<'a>(trajectory: &'a [Vec<f64>], parameters: &'a [f64], round: usize) -> &'a [f64] {
    if round == 0 {
        parameters
    } else {
        &trajectory[round - 1]
    }
}

/// [`meta_gradient`] with reusable buffers (created for the same architecture).
pub fn meta_gradient_in(
    workspace: &mut MetaWorkspace,
    parameters: &[f64],
    task: &Task,
    inner: InnerLoop,
    order: MetaOrder,
) -> MetaGradient {
    let mut result = MetaGradient::default();
    meta_gradient_into(workspace, parameters, task, inner, order, &mut result);
    result
}

/// [`meta_gradient_in`] writing into `result`, whose gradient buffer is reused (no allocation
/// once it has the parameters' length).
pub fn meta_gradient_into(
    workspace: &mut MetaWorkspace,
    parameters: &[f64],
    task: &Task,
    inner: InnerLoop,
    order: MetaOrder,
    result: &mut MetaGradient,
) {
    result.support_loss = workspace.inner_rounds(parameters, &task.support, inner);
    let size = parameters.len();
    let gradient = &mut result.gradient;
    gradient.resize(size, 0.0);
    result.query_loss = workspace.query.mse_and_gradient(
        inner_point(&workspace.trajectory, parameters, inner.rounds),
        &task.query.inputs,
        &task.query.targets,
        gradient,
    );
    if order == MetaOrder::Second {
        workspace.product.resize(size, 0.0);
        for round in (0..inner.rounds).rev() {
            // The query pass is finished: its buffers serve as the Hessian product's scratch
            // (a smaller working set per thread), and are handed back afterwards.
            let support = &mut workspace.support[round];
            support.exchange_hessian_buffers(&mut workspace.query);
            support.hessian_vector_product(
                inner_point(&workspace.trajectory, parameters, round),
                gradient,
                &mut workspace.product,
            );
            support.exchange_hessian_buffers(&mut workspace.query);
            for (g, hv) in gradient.iter_mut().zip(&workspace.product) {
                *g -= inner.step * hv;
            }
        }
    }
}

/// The meta-gradients of `tasks`, in task order: the tasks are cut into `workspaces.len()`
/// contiguous chunks run in parallel (rayon), each chunk in order on its own workspace. A task's
/// result does not depend on the workspace or the chunking, so the output is bit-identical for any
/// number of workspaces and threads. One workspace per thread keeps each thread's buffers warm in
/// its cache.
pub fn meta_gradients(
    workspaces: &mut [MetaWorkspace],
    parameters: &[f64],
    tasks: &[Task],
    inner: InnerLoop,
    order: MetaOrder,
) -> Vec<MetaGradient> {
    let mut results = Vec::new();
    meta_gradients_into(workspaces, parameters, tasks, inner, order, &mut results);
    results
}

/// [`meta_gradients`] into `results` (one per task, resized to `tasks.len()`), reusing the
/// gradient buffers already there: the form a training loop calls every iteration.
pub fn meta_gradients_into(
    workspaces: &mut [MetaWorkspace],
    parameters: &[f64],
    tasks: &[Task],
    inner: InnerLoop,
    order: MetaOrder,
    results: &mut Vec<MetaGradient>,
) {
    use rayon::prelude::*;
    assert!(!workspaces.is_empty(), "at least one workspace");
    results.resize_with(tasks.len(), MetaGradient::default);
    let chunk = tasks.len().div_ceil(workspaces.len()).max(1);
    tasks
        .par_chunks(chunk)
        .zip(results.par_chunks_mut(chunk))
        .zip(workspaces.par_iter_mut())
        .for_each(|((chunk_tasks, chunk_results), workspace)| {
            for (task, result) in chunk_tasks.iter().zip(chunk_results) {
                meta_gradient_into(workspace, parameters, task, inner, order, result);
            }
        });
}

/// [`meta_gradient`] by the generic reference code (gradients in `f64`, Hessian-vector products
/// on dual numbers), kept as the reference the fast path is tested against.
pub fn reference_meta_gradient(
    architecture: &Architecture,
    parameters: &[f64],
    task: &Task,
    inner: InnerLoop,
    order: MetaOrder,
) -> MetaGradient {
    let mut trajectory = vec![parameters.to_vec()];
    let mut support_loss = f64::NAN;
    for round in 0..inner.rounds {
        let (loss, gradient) = architecture.reference_loss_and_gradient(
            &trajectory[round],
            &task.support.inputs,
            &task.support.targets,
        );
        if round == 0 {
            support_loss = loss;
        }
        let next = trajectory[round]
            .iter()
            .zip(&gradient)
            .map(|(p, g)| p - inner.step * g)
            .collect();
        trajectory.push(next);
    }
    if inner.rounds == 0 {
        support_loss = architecture
            .reference_loss_and_gradient(parameters, &task.support.inputs, &task.support.targets)
            .0;
    }
    let (query_loss, mut gradient) = architecture.reference_loss_and_gradient(
        &trajectory[inner.rounds],
        &task.query.inputs,
        &task.query.targets,
    );
    if order == MetaOrder::Second {
        for point in trajectory[..inner.rounds].iter().rev() {
            let (_, product) =
                reference_hessian_vector_product(architecture, point, &gradient, &task.support);
            for (g, hv) in gradient.iter_mut().zip(product) {
                *g -= inner.step * hv;
            }
        }
    }
    MetaGradient {
        support_loss,
        query_loss,
        gradient,
    }
}
