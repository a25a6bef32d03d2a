//! LeARN: learnable and adaptive representations for nonlinear dynamics.
//!
//! What it is for: the paper's model y = Θ(X; ψ)·ℰ(X; φ)ᵀ (two GELU networks, [`Architecture`]),
//! meta-trained with MAML (exact second order by default, [`meta_train`]), adapted online on a new
//! flight with the Lipschitz regulariser ([`adapt_online`]), explained through ℰ ([`explain`]), and
//! the experiment behind the paper's LeARN columns ([`Experiment`]).
//!
//! What it is not for: reading flight files or estimating derivatives (the `data` crate), SINDy
//! (`sindy`), tables and figures (`report`), the command line (`cli`).
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
//!   set of cells in parallel (rayon), [`Experiment::seed_spread`] repeats them over seeds.
//! - Building blocks: [`Architecture`] (forward, gradient, prediction), [`meta_gradient`],
//!   [`hessian_vector_product`], [`inner_updates`], [`meta_train`], [`adapt_online`], [`explain`].
//!
//! # Definitions
//!
//! Split, inputs and targets are those of the SINDy columns: support = first half of the flight,
//! query = second half ([`data::SplitSpec::Halves`]), targets the forward difference of the state on
//! each segment ([`data::Derivative::Forward`]). **Adaptation MSE**: the model adapted online on the
//! support segment, evaluated on that segment; **generalisation MSE**: the same model, frozen, on the
//! query segment. MSE = mean over all samples and all output dimensions. Inputs are z-scored with
//! the meta-training statistics (stored in the checkpoint).
//!
//! # Derivatives and speed
//!
//! One hand-written forward and backward pass, generic over [`Scalar`]: with `f64` it gives the
//! loss gradient, with [`Dual`] numbers (θ + ε·v) the Hessian-vector product H·v
//! (forward-over-reverse), which the exact meta-gradient chains as g ← g − α·H_s(θ_k)·g. Every
//! derivative is checked against central finite differences (`tests/gradients.rs`). On x86-64 the
//! passes run in a copy compiled for AVX2 when the CPU has it (no FMA, so results are bit-identical
//! to the portable build). Checkpoints are written with shortest round-trip floats and read back
//! exactly (serde_json `float_roundtrip`).
//!
//! # Determinism
//!
//! Initialisation and task sampling come from ChaCha8 streams seeded by the recorded seed; per-task
//! gradients are computed in parallel and summed in task order, so results are bit-identical
//! whatever the number of threads.

mod adapt;
mod config;
mod dataset;
mod error;
mod experiment;
mod explain;
mod maml;
mod model;
mod network;
mod scalar;
mod train;
pub mod variants;

pub use adapt::adapt_online;
pub use config::{AdaptationConfig, CheckedConfig, LearnConfig, MetaTrainingConfig, Optimizer};
pub use dataset::{
    Protocol, Standardiser, flight_segments, from_row_major, row_major, segment_batch,
};
pub use error::{LearnError, Result};
pub use experiment::{
    CellResult, CellSummary, Experiment, SegmentPrediction, Spread, SpreadCell, architecture,
    explain_flight,
};
pub use explain::{
    EquationRule, Explanation, InputImportance, OutputExplanation, Term, explain, output_symbol,
};
pub use maml::{
    Batch, InnerLoop, MetaGradient, MetaOrder, Task, hessian_vector_product, inner_updates,
    meta_gradient,
};
pub use model::{CHECKPOINT_FORMAT, DataFile, MetaTrainedModel};
pub use network::{Architecture, PAPER_HIDDEN, mean_squared_error};
pub use scalar::{Dual, Scalar, gelu, gelu_derivative, gelu_second_derivative};
pub use train::{MetaTrainingOutcome, TaskData, meta_train, meta_train_from};
