//! The evaluation protocol of the paper and the experiments run on it, end to end: what
//! `make reproduce` and `learn reproduce` run. The home of the paper's protocol, for every method.
//!
//! What it is for: reading a run configuration ([`RunConfig`], `experiments/reproduce.json` or
//! `experiments/ci.json`); the flights (each log read and hashed once, [`Flight`]); a
//! formulation's columns of a flight log and its support and query segments ([`Segment::cut`],
//! [`flight_segments`], cut by the run's [`Segmentation`]: the paper's halves, forward-difference
//! targets on each); the protocols choosing the
//! meta-training flights of an evaluation condition ([`Protocol`]); the LeARN experiment on them
//! ([`Experiment`]: meta-training per formulation and evaluation condition, adaptation on the
//! evaluation flight's support segment, prediction of its query segment, nested validation, the
//! seed spread), whose cells ([`EvaluationCell`]) SINDy (`sindy`) is fitted on too; SINDy, LeARN
//! and every variant as peer [`Method`]s run by one [`Runner`] over cells × methods × seeds;
//! running them on every formulation × evaluation condition of `experiments/conditions.json`
//! ([`run`]); turning the numbers and predictions into the paper's tables and figures and a
//! `summary.json` with full provenance ([`write_outputs`]); the noise floor of a segment's
//! forward-difference targets, which the ablation tables show ([`forward_difference_noise_floor`]);
//! and the check of the results against the paper ([`check_paper`]).
//!
//! LeARN on your own data ([`own_data`]): reading CSV tasks and recordings for `learn`
//! ([`own_data::read_tasks`], [`own_data::read_recording`]), a model of CSV tasks next to SINDy on
//! the same rows of a new recording ([`own_data::compare_on_recording`], `learn evaluate`) and the
//! worked example's learning curve ([`own_data::example`], `make own-data-example`).
//!
//! What it is not for: any model, training algorithm or metric (those live in `sindy` and
//! `learn`, which work on matrices in memory); parsing files (the `data` crate reads flight logs
//! and CSVs); rendering: every table, note and figure is drawn by the `report` crate from its typed
//! inputs, which this crate fills ([`report::ResultsTable`], [`report::AblationTables`] via
//! [`Ablations::tables`], [`report::QueryCoverage`], [`report::QualitativeFigure`]) and writes to
//! files; drawing progress: a run reports its stages and units of work to the caller's observer
//! ([`Progress`], [`NoProgress`] for none), and the `learn` binary draws the bars and prints the
//! stage times; argument parsing (the `learn` binary).
//!
//! **Work items and shards.** Each run enumerates its work once, in a fixed order, as
//! [`WorkItem`]s (one meta-training: formulation, cells, seed) — [`run`] and
//! [`run_variants`] (the ablations) and [`spread_sweep`] (the seed spread) alike — and renders the
//! items' results with one function per run. [`run_shard`], [`run_variants_shard`] and
//! [`run_spread`] with a [`ShardSpec`] run only the items at positions ≡ K (mod N) and return a
//! [`ShardFile`] (written as `shard.json`: configuration hash, data hashes, items, results);
//! [`merge`] checks shards and hands their results to the same rendering ([`merged_run`],
//! [`merged_ablations`], [`spread_document`]), so merged shards give the unsharded run's bytes.
//! `docs/cluster.md` describes running them under SLURM, Kubernetes or `xargs -P`.
//!
//! Adding a wind condition needs no code: a flight in the data directory and one entry in the
//! conditions file make a new row in every table and a new figure per table.
//!
//! Definitions, shared by both methods: support = the first half of each evaluation flight, query =
//! the second half; targets = forward differences on each segment ([`Segmentation::PAPER`], the
//! run configuration's `split` and `derivative`), built once per cell for both. **Adaptation MSE**: the model
//! fitted (SINDy) or adapted online (LeARN) on the support segment, scored on that segment.
//! **Generalisation MSE**: the same model, unchanged, scored on the query segment.

mod ablations;
mod causal_library;
mod cells;
mod config;
mod error;
mod experiment;
mod flights;
mod noise_floor;
mod output;
pub mod own_data;
mod progress;
mod run;
mod runner;
mod segment;
mod shard;
mod sindy_column;
mod sindy_variant;
mod spread;
mod summary;
mod tables;
mod variants;

pub use ablations::{
    AblationCell, AblationCellDetail, AblationProvenance, AblationSeedOutcome, Ablations,
    AblationsContext, AblationsOutcome, AblationsShard, merged_ablations, run_variants,
    run_variants_shard, write_ablations,
};
pub use causal_library::{CausalLibrary, MAX_CONTROL_LAGS, first_order_lag};
pub use cells::figure_file_name;
pub use config::{CheckedRunConfig, LearnRun, MAX_SEEDS, RunConfig, merge_patch};
pub use error::{EvaluationError, Result};
pub use experiment::{
    CellResult, CellSummary, Cells, EvaluationCell, Experiment, SegmentPrediction, Spread,
    SpreadCell, ValidationDetail, WorkItem, explain_flight, spread_cells,
};
pub use flights::{Flight, Protocol, evaluation_condition_of, read_evaluation_flights};
pub use noise_floor::forward_difference_noise_floor;
pub use output::{
    OutputPaths, README_BEGIN, README_END, ablation_files, check_paper, check_readme, latex_files,
    result_files, update_readme, updated_readme, write_outputs,
};
pub use progress::{NoProgress, Progress, Stage, Units};
pub use run::{
    GENERATED_PATHS, ReproduceShard, RunOutcome, git_commit, merged_run, run, run_shard,
    shard_timings, uncommitted_inputs, worker_threads,
};
pub use runner::{Fitted, Method, Models, Outcome, Runner, Train, Trial};
pub use segment::{Segment, SegmentModel, Segmentation, flight_segments, segment_batch};
pub use shard::{
    ItemResult, MergedSweep, SHARD_FILE, SHARD_FORMAT, ShardDocument, ShardFile, ShardProvenance,
    ShardSpec, Sweep, SweepKind, merge, read_shard, write_shard,
};
pub use sindy_column::{SegmentEvaluation, SindyConfig, evaluate_flight, fit_and_evaluate};
pub use sindy_variant::{
    LibraryRegression, SegmentPredictions, VariantEvaluation, evaluate_features,
};
pub use spread::{
    SPREAD_WHAT, SpreadContext, SpreadDocument, SpreadShard, run_spread, spread_document,
    spread_sweep,
};
pub use summary::{
    CellRecord, FileRef, LearnCell, LearnSeedCell, Provenance, SUMMARY_FORMAT, SindyCell,
    StageTiming, Summary, Timings,
};
pub use tables::{
    CellDetail, ConditionName, LearnCellOutcome, ReproduceContext, RunInputs, SindyOutcome,
};
pub use variants::{
    CheckedVariants, ENSEMBLE_SEED_STRIDE, LearnedBasisSpec, MAX_ENSEMBLE_MEMBERS, MAX_VARIANTS,
    VariantKind, VariantSpec, VariantsConfig, ensemble_member_seeds, reproduce_columns,
};
