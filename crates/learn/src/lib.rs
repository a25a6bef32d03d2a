//! LeARN: learnable and adaptive representations for nonlinear dynamics.
//!
//! What it is for: the paper's model y = Θ(X; ψ)·ℰ(X; φ)ᵀ (two GELU networks, [`Architecture`]),
//! meta-trained with MAML (exact second order by default, [`meta_train`]), adapted online on a new
//! flight with the Lipschitz regulariser ([`adapt_online`]), explained through ℰ ([`explain`]), and
//! the experiment behind the paper's LeARN columns ([`Experiment`]), and the same model on any
//! multi-task CSV set ([`meta_train_tasks`], [`evaluate_recording`], [`explain_recording`]).
//!
//! What it is not for: reading flight files (the `data` crate), estimating derivatives
//! (`sindy::differentiation`), SINDy (`sindy`), tables and figures (`report`), the command line
//! (`cli`).
//!
//! # Public API
//!
//! - [`LearnConfig::load`] reads `experiments/learn.json` into a [`CheckedConfig`] (all
//!   hyper-parameters: α, β, n, μ, batches, iterations, λ, L, P, adaptation passes, seeds).
//! - [`Experiment::load`] resolves the [`Protocol`] (`paper` when its flights are present, else
//!   `leave-condition-out`) and reads every flight it needs once. Then, for one formulation and one
//!   evaluation condition: [`Experiment::meta_train`] → [`MetaTrainedModel`] (the JSON checkpoint:
//!   weights, configuration, seed, protocol, SHA-256 of the data files), and
//!   [`Experiment::evaluate`] → [`CellResult`] (adaptation MSE, generalisation MSE, predictions on
//!   both segments, adapted θ); [`Experiment::run_cell`] does both; [`Experiment::run_cells`] runs a
//!   set of cells in parallel (rayon), [`Experiment::seed_spread`] repeats them over seeds. Both
//!   enumerate their work as [`WorkItem`]s ([`Experiment::work_items`]: one meta-training and the
//!   cells it serves) and run each with [`Experiment::run_item`], as a sharded sweep does.
//! - CSV tasks: [`read_column_tasks`] reads the tasks of a [`data::TaskSource`] with the columns
//!   of a [`ColumnSpec`]; [`TaskConfig::load`] gives the settings (the paper's by default, any
//!   subset overridden by a file); [`meta_train_tasks`] → [`MetaTrainedModel`] whose
//!   [`TrainedOn::Columns`] records the columns, derivative, sampling interval, target scales and
//!   tasks; [`evaluate_recording`] adapts it on support rows of a new recording and scores the query
//!   rows ([`RecordingEvaluation`]); [`explain_recording`]. See `docs/own-data.md`.
//! - Building blocks: [`Architecture`] (forward, gradient, prediction), [`meta_gradient`]
//!   ([`meta_gradient_in`] with reusable [`MetaWorkspace`] buffers, [`meta_gradients_into`] for a
//!   batch of tasks in parallel into reused results), [`hessian_vector_product`],
//!   [`inner_updates`], [`meta_train`], [`adapt_online`], [`explain`]; [`ModelWorkspace`] for
//!   repeated passes; `reference_*` for the generic reference implementation.
//!
//! # Definitions
//!
//! Split, inputs and targets are those of the SINDy columns: support = first half of the flight,
//! query = second half ([`data::SplitSpec::Halves`]), targets the forward difference of the state on
//! each segment ([`sindy::Derivative::Forward`]). **Adaptation MSE**: the model adapted online on the
//! support segment, evaluated on that segment; **generalisation MSE**: the same model, frozen, on the
//! query segment. MSE = mean over all samples and all output dimensions. Inputs are z-scored with
//! the meta-training statistics (stored in the checkpoint).
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
mod dataset;
mod error;
mod explain;
mod formulation;
mod kernels;
mod maml;
mod model;
mod network;
mod scalar;
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
pub use dataset::{
    InputCoverage, InputRange, RangeCoverage, Standardiser, from_row_major, row_major,
};
pub use error::{LearnError, Result};
pub use explain::{
    EquationRule, Explanation, InputImportance, ModelNames, OutputExplanation, Term, explain,
    explain_named, output_symbol,
};
pub use formulation::architecture;
pub use maml::{
    Batch, InnerLoop, MetaGradient, MetaOrder, MetaWorkspace, Task, hessian_vector_product,
    inner_updates, meta_gradient, meta_gradient_in, meta_gradient_into, meta_gradients,
    meta_gradients_into, reference_hessian_vector_product, reference_meta_gradient,
};
pub use model::{CHECKPOINT_FORMAT, DataFile, FlightTraining, MetaTrainedModel, TrainedOn};
pub use network::{Architecture, PAPER_HIDDEN, mean_squared_error};
pub use scalar::{Dual, Scalar, gelu, gelu_derivative, gelu_second_derivative};
pub use tasks::{
    Recording, RecordingEvaluation, TaskSet, column_training, evaluate_recording,
    explain_recording, meta_train_tasks, segment_data,
};
pub use train::{
    MetaTrainingOutcome, TaskData, check_sampling, meta_train, meta_train_from, meta_train_observed,
};
