//! Model-agnostic meta-learning for one task: the inner SGD rounds and the exact meta-gradient.
//!
//! With θ₀ = θ and θ_{k+1} = θ_k − α·∇L_s(θ_k) (k < n), the meta-loss of a task is L_q(θ_n) and
//! its exact gradient is
//!
//! ∇_θ L_q(θ_n) = (I − α·H_s(θ₀)) ⋯ (I − α·H_s(θ_{n−1})) · ∇L_q(θ_n),
//!
//! evaluated right to left with Hessian-vector products (g ← g − α·H_s(θ_k)·g for k = n−1 … 0), each
//! one a reverse pass run on dual numbers (forward-over-reverse). The first-order variant keeps only
//! ∇L_q(θ_n).

use serde::{Deserialize, Serialize};

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
#[derive(Clone, Debug, PartialEq)]
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
    let dual: Vec<Dual> = parameters
        .iter()
        .zip(direction)
        .map(|(&p, &v)| Dual::new(p, v))
        .collect();
    let (_, gradient) = architecture.loss_and_gradient(&dual, &batch.inputs, &batch.targets);
    gradient.into_iter().map(|d| (d.value, d.tangent)).unzip()
}

/// θ₀ … θ_n of the inner SGD rounds on `support`, and L_s(θ₀).
pub fn inner_updates(
    architecture: &Architecture,
    parameters: &[f64],
    support: &Batch,
    inner: InnerLoop,
) -> (Vec<Vec<f64>>, f64) {
    let mut trajectory = vec![parameters.to_vec()];
    let mut first_loss = f64::NAN;
    for round in 0..inner.rounds {
        let current = &trajectory[round];
        let (loss, gradient) =
            architecture.loss_and_gradient(current, &support.inputs, &support.targets);
        if round == 0 {
            first_loss = loss;
        }
        let next = current
            .iter()
            .zip(&gradient)
            .map(|(p, g)| p - inner.step * g)
            .collect();
        trajectory.push(next);
    }
    if inner.rounds == 0 {
        first_loss = architecture.loss(parameters, &support.inputs, &support.targets);
    }
    (trajectory, first_loss)
}

/// The meta-gradient of one task (see the module documentation).
pub fn meta_gradient(
    architecture: &Architecture,
    parameters: &[f64],
    task: &Task,
    inner: InnerLoop,
    order: MetaOrder,
) -> MetaGradient {
    let (trajectory, support_loss) = inner_updates(architecture, parameters, &task.support, inner);
    let adapted = trajectory.last().expect("the trajectory starts with θ");
    let (query_loss, mut gradient) =
        architecture.loss_and_gradient(adapted, &task.query.inputs, &task.query.targets);
    if order == MetaOrder::Second {
        for point in trajectory[..inner.rounds].iter().rev() {
            let (_, product) =
                hessian_vector_product(architecture, point, &gradient, &task.support);
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
