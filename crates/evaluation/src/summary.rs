//! `results/summary.json`: every number of a run and where it came from. Wall times are kept
//! apart (`timings.json`) so that two runs of the same commit write byte-identical summaries.

use std::path::PathBuf;

use crate::sindy_column::SindyConfig;
use data::SplitSpec;
use learn::{DataFile, Explanation, LearnConfig, RangeCoverage};
use report::ResultsTable;
use serde::{Deserialize, Serialize};
use sindy::Derivative;

/// The format tag of `summary.json`.
pub const SUMMARY_FORMAT: &str = "learn-results/1";

/// A configuration file a run read.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FileRef {
    /// As written in the run configuration (relative to the project root).
    pub path: PathBuf,
    pub sha256: String,
}

/// Where the numbers come from.
#[derive(Clone, Debug, Serialize)]
pub struct Provenance {
    /// The last commit that changed an input of the run (see `evaluation::git_commit`).
    pub git_commit: String,
    pub run_config: FileRef,
    pub conditions: FileRef,
    pub published: FileRef,
    pub learn_config: FileRef,
    /// The merge patch applied to the LeARN configuration.
    pub learn_overrides: serde_json::Value,
    /// Every flight read (relative to the data directory), with its SHA-256.
    pub data_files: Vec<DataFile>,
    /// The LeARN protocol (`paper` or `leave-condition-out`).
    pub protocol: String,
    pub split: SplitSpec,
    pub derivative: Derivative,
    pub seeds: Vec<u64>,
    pub sindy: SindyConfig,
    /// The LeARN configuration in effect (after the overrides).
    pub learn: LearnConfig,
}

/// SINDy on one flight.
#[derive(Clone, Debug, Serialize)]
pub struct SindyCell {
    #[serde(rename = "adapt")]
    pub adaptation: f64,
    #[serde(rename = "gen")]
    pub generalisation: f64,
    /// The fitted equations, three decimals.
    pub equations: Vec<String>,
    /// SINDy's generalisation MSE over the query samples inside the range of the LeARN
    /// meta-training inputs, and over those outside it (the samples counted in
    /// `learn.query_coverage`), when there are such samples.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gen_inside_range: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gen_outside_range: Option<f64>,
    /// Per input with query samples outside its range, what those samples add to SINDy's
    /// generalisation MSE (as `contribution_to_mse` in `learn.query_coverage`), in X order.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub gen_added_outside_range: Vec<InputContribution>,
}

/// What the samples outside one input's range add to a method's MSE.
#[derive(Clone, Debug, Serialize)]
pub struct InputContribution {
    pub input: String,
    pub contribution_to_mse: f64,
}

/// LeARN on one flight with one seed.
#[derive(Clone, Debug, Serialize)]
pub struct LearnSeedCell {
    pub seed: u64,
    #[serde(rename = "adapt")]
    pub adaptation: f64,
    #[serde(rename = "gen")]
    pub generalisation: f64,
    /// The meta-trained model before online adaptation.
    pub unadapted_adapt: f64,
    pub unadapted_gen: f64,
    /// Mean meta-loss of the last meta-iteration.
    pub final_meta_loss: Option<f64>,
}

/// LeARN on one flight: the mean over seeds, each seed, and the adapted model explained.
#[derive(Clone, Debug, Serialize)]
pub struct LearnCell {
    #[serde(rename = "adapt")]
    pub adaptation: f64,
    #[serde(rename = "gen")]
    pub generalisation: f64,
    pub seeds: Vec<LearnSeedCell>,
    /// The first seed's adapted model, explained over the support segment.
    pub explanation: Explanation,
    /// How much of each segment lies outside the range of the meta-training inputs (the same for
    /// every seed: it depends on the meta-training flights only), with LeARN's MSE inside and
    /// outside that range averaged over the seeds.
    pub support_coverage: Option<RangeCoverage>,
    pub query_coverage: Option<RangeCoverage>,
}

/// One table cell row: one formulation on one evaluation flight.
#[derive(Clone, Debug, Serialize)]
pub struct CellRecord {
    pub table: String,
    /// The condition's file name, e.g. `70p20sint`.
    pub condition: String,
    /// As printed in the tables, e.g. `70psin20`.
    pub label: String,
    pub flight: DataFile,
    /// Rows of the flight in the support and query segments, `[start, end)`.
    pub support_rows: [usize; 2],
    pub query_rows: [usize; 2],
    pub sindy: SindyCell,
    pub learn: LearnCell,
}

/// The whole `summary.json`.
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    pub format: String,
    /// The run configuration's name, e.g. `reproduce`.
    pub run: String,
    pub description: String,
    pub provenance: Provenance,
    pub tables: Vec<ResultsTable>,
    pub cells: Vec<CellRecord>,
}

/// Wall time of one stage.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StageTiming {
    pub stage: String,
    pub seconds: f64,
}

/// `timings.json`: what changes between two runs of the same inputs: wall times, threads, and
/// whether the working tree had uncommitted changes to the inputs.
#[derive(Clone, Debug, Serialize)]
pub struct Timings {
    pub run: String,
    /// Tracked inputs differed from `git_commit` when the run started (`None`: not a checkout).
    pub uncommitted_inputs: Option<bool>,
    /// Rayon worker threads.
    pub threads: usize,
    pub stages: Vec<StageTiming>,
    pub total_seconds: f64,
}
