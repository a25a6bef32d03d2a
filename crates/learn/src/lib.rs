//! LeARN: learnable and adaptive representations for nonlinear dynamics.
//!
//! What it is for — the method, on data in memory: the paper's model y = Θ(X; ψ)·ℰ(X; φ)ᵀ (two
//! GELU networks, [`Architecture`]), meta-trained with MAML on tasks of regression data
//! (exact second order by default, [`meta_train`] on [`TaskData`]), adapted online with the
//! Lipschitz regulariser ([`adapt_online`], [`MetaTrainedModel::adapt_on`]), explained through ℰ
//! ([`explain`]); input standardisation ([`Standardiser`]); the model file (the JSON checkpoint,
//! [`MetaTrainedModel`]), which names the [`Formulation`] of a flight model or the columns of a
//! model of CSV tasks ([`ColumnTraining`]); and the same model on any multi-task set of
//! recordings in memory ([`meta_train_tasks`], [`evaluate_recording`], [`explain_recording`] on
//! [`Recording`]s).
//!
//! What it is not for: reading anything but its own configuration and checkpoints — flight logs,
//! CSV files and file hashes are the `data` crate's, and the paper's protocol is the `evaluation`
//! crate's (the experiment: which flights meta-train the model for an evaluation condition, how a
//! flight is cut into support and query segments and a formulation's columns built from its log,
//! the evaluation, the seed spread; reading CSV tasks). Nor estimating derivatives
//! (`sindy::differentiation`), SINDy (`sindy`), tables and figures (`report`), the command line
//! (`cli`). A test (`crates/cli/tests/layering.rs`) keeps `data`, CSV readers and data frames out of its
//! dependencies.
//!
//! # Public API
//!
//! - [`LearnConfig::load`] reads `experiments/learn.json` into a [`CheckedConfig`] (all
//!   hyper-parameters: α, β, n, μ, batches, iterations, λ, L, P, adaptation passes, seeds).
//! - Flight models: [`architecture`] gives the networks of a [`Formulation`]; a caller (the
//!   `evaluation` crate's experiment) standardises the meta-training tasks ([`Standardiser::fit`],
//!   [`InputRange::spanned`]), checks its batch sizes against them ([`check_sampling`]),
//!   meta-trains ([`meta_train`]) and records a [`MetaTrainedModel`] with
//!   [`TrainedOn::Flights`] (formulation, protocol name, held-out condition); the model adapts on
//!   raw inputs and targets ([`MetaTrainedModel::adapt_on`]) and predicts
//!   ([`MetaTrainedModel::predict_with`]); [`Standardiser::coverage_with_errors`] tells how much of
//!   a segment lies outside the meta-training inputs.
//! - Multi-task sets: [`TaskConfig::load`] gives the settings (the paper's by default, any subset
//!   overridden by a file); [`meta_train_tasks`] on a [`TaskSet`] of [`Recording`]s →
//!   [`MetaTrainedModel`] whose [`TrainedOn::Columns`] records the columns, derivative, sampling
//!   interval, target scales, tasks and their [`TaskSource`]; [`evaluate_recording`] adapts it on
//!   support rows of a new recording and scores the query rows ([`RecordingEvaluation`]);
//!   [`explain_recording`]. See `docs/own-data.md`.
//! - Building blocks: [`Architecture`] (forward, gradient, prediction), [`meta_gradient`]
//!   ([`meta_gradient_in`] with reusable [`MetaWorkspace`] buffers, [`meta_gradients_into`] for a
//!   batch of tasks in parallel into reused results), [`hessian_vector_product`],
//!   [`inner_updates`], [`meta_train`], [`adapt_online`], [`explain`]; [`ModelWorkspace`] for
//!   repeated passes; `reference_*` for the generic reference implementation;
//!   [`variants::learned_features`] for the networks as a feature library.
//!
//! # Definitions
//!
//! **Adaptation MSE**: the model adapted online on the support data, evaluated on that data;
//! **generalisation MSE**: the same model, frozen, on the query data. MSE = mean over all samples
//! and all output dimensions ([`mean_squared_error`]). Inputs are z-scored with the meta-training
//! statistics (stored in the checkpoint). How the paper cuts a flight into support and query
//! segments and estimates their targets is the `evaluation` crate's (`docs/protocol.md`).
//!
//! # Derivatives and speed
//!
//! The hot path ([`ModelWorkspace`], [`MetaWorkspace`]) runs each layer over the whole batch as a
//! matrix product (register-tiled AVX-512 / AVX2+FMA kernels chosen at run time, a portable
//! fallback), with the exact GELU and its two derivatives vectorised (Cephes' erf/erfc rational
//! approximations, one exponential). Hessian-vector products are Pearlmutter's R-operator with
//! separate value and tangent arrays; they reuse the forward and backward passes of the inner
//! round, and run in the buffers of the finished query pass (a smaller working set per core). Every kernel sums each output in the same order with fused multiply-adds, so all
//! instruction sets give bit-identical results. The generic code over [`Scalar`] (`f64` for
//! gradients, [`Dual`] numbers for H·v, forward-over-reverse) is kept as the reference
//! (`reference_*`): the tests hold the fast path to it (relative 1e-12) and both to central finite
//! differences (`tests/gradients.rs`). Checkpoints are written with shortest round-trip floats and
//! read back exactly (serde_json `float_roundtrip`).
//!
//! # Determinism
//!
//! Initialisation and task sampling come from ChaCha8 streams seeded by the recorded seed; per-task
//! gradients are computed in parallel and summed in task order, so results are bit-identical
//! whatever the number of threads.

mod adapt;
mod averaging;
mod batched;
mod columns;
mod config;
mod error;
mod explain;
mod formulation;
mod kernels;
mod maml;
mod model;
mod network;
mod scalar;
mod standardiser;
mod tasks;
mod train;
pub mod variants;

pub use adapt::adapt_online;
pub use batched::ModelWorkspace;
pub use columns::{ColumnSpec, ColumnTraining, TaskConfig, TaskRows, TaskSource};
pub use config::{
    AdaptationConfig, CheckedConfig, LearnConfig, MetaTrainingConfig, Optimizer, TaskGrouping,
    limits,
};
pub use error::{LearnError, Result};
pub use explain::{
    EquationRule, Explanation, InputImportance, ModelNames, OutputExplanation, Term, explain,
    explain_named, output_symbol,
};
pub use formulation::{Formulation, architecture};
pub use maml::{
    Batch, InnerLoop, MetaGradient, MetaOrder, MetaWorkspace, Task, hessian_vector_product,
    inner_updates, meta_gradient, meta_gradient_in, meta_gradient_into, meta_gradients,
    meta_gradients_into, reference_hessian_vector_product, reference_meta_gradient,
};
pub use model::{CHECKPOINT_FORMAT, DataFile, FlightTraining, MetaTrainedModel, TrainedOn};
pub use network::{Architecture, PAPER_HIDDEN, mean_squared_error};
pub use scalar::{Dual, Scalar, gelu, gelu_derivative, gelu_second_derivative};
pub use standardiser::{
    InputCoverage, InputRange, RangeCoverage, Standardiser, from_row_major, row_major,
};
pub use tasks::{
    Recording, RecordingEvaluation, TaskSet, column_training, evaluate_recording,
    explain_recording, meta_train_tasks, segment_data,
};
pub use train::{
    MetaTrainingOutcome, TaskData, check_sampling, meta_train, meta_train_from, meta_train_observed,
};
