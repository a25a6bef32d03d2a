//! The experiments of the paper, end to end: what `make reproduce` and `learn reproduce` run.
//!
//! What it is for: reading a run configuration ([`RunConfig`], `experiments/reproduce.json` or
//! `experiments/ci.json`); running SINDy (`sindy`) and LeARN (`learn`) on every formulation ×
//! evaluation condition of `experiments/conditions.json` ([`run`]); turning the numbers and
//! predictions into the paper's tables and figures and a `summary.json` with full provenance
//! ([`write_outputs`]); and the check of the results against the paper ([`check_paper`]).
//!
//! LeARN on your own data ([`own_data`]): a model of CSV tasks next to SINDy on the same rows of a
//! new recording ([`own_data::compare_on_recording`], `learn evaluate`) and the worked example's
//! learning curve ([`own_data::example`], `make own-data-example`).
//!
//! What it is not for: any model or metric (those live in `sindy` and `learn`), rendering (the
//! `report` crate), argument parsing (the `learn` binary).
//!
//! Adding a wind condition needs no code: a flight in the data directory and one entry in the
//! conditions file make a new row in every table and a new figure per table.
//!
//! Definitions, shared by both methods: support = the first half of each evaluation flight, query =
//! the second half; targets = forward differences on each segment. **Adaptation MSE**: the model
//! fitted (SINDy) or adapted online (LeARN) on the support segment, scored on that segment.
//! **Generalisation MSE**: the same model, unchanged, scored on the query segment.

mod causal_library;
mod config;
mod error;
mod output;
pub mod own_data;
mod run;
mod sindy_column;
mod sindy_variant;
mod summary;
mod variants;

pub use causal_library::{CausalLibrary, MAX_CONTROL_LAGS, first_order_lag};
pub use config::{CheckedRunConfig, LearnRun, MAX_SEEDS, RunConfig, merge_patch};
pub use error::{PipelineError, Result};
pub use output::{
    OutputPaths, README_BEGIN, README_END, ablation_files, check_paper, check_readme, latex_files,
    result_files, update_readme, updated_readme, write_outputs,
};
pub use run::{
    GENERATED_PATHS, RunOptions, RunOutcome, figure_file_name, git_commit, run, uncommitted_inputs,
};
pub use sindy_column::{SegmentEvaluation, SindyConfig, evaluate_flight, fit_and_evaluate};
pub use sindy_variant::{
    LibraryRegression, SegmentPredictions, VariantEvaluation, evaluate_features,
};
pub use summary::{
    CellRecord, FileRef, LearnCell, LearnSeedCell, Provenance, SUMMARY_FORMAT, SindyCell,
    StageTiming, Summary, Timings,
};
pub use variants::{
    AblationProvenance, AblationRow, Ablations, AblationsOutcome, CheckedVariants,
    ENSEMBLE_SEED_STRIDE, LearnedBasisSpec, MAX_ENSEMBLE_MEMBERS, MAX_VARIANTS, Outcome, SeedCell,
    VariantCell, VariantKind, VariantSpec, VariantsConfig, ablations_markdown,
    ensemble_member_seeds, evaluate_variants, reproduce_columns, run_variants, write_ablations,
};
