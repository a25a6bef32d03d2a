//! Variants beyond the paper (`experiments/variants.json`, `make ablations`): every variant on every
//! formulation × evaluation condition, over several seeds, on the paper's protocol, beside the
//! published columns and an estimate of the targets' noise floor.
//!
//! Protocol (the same as the paper's tables): support = first half of the flight, query = second
//! half, forward-difference targets on each segment, inputs X = [x, u] of `learn::Formulation`.
//! Every hyper-parameter of a variant (penalty, library for `select`) is chosen by blocked
//! cross-validation inside the support segment; the query segment is only ever scored.
//!
//! Variant kinds:
//! - `library`: a [`crate::causal_library::CausalLibrary`] and a [`sindy::RegressionSpec`];
//! - `select`: per cell, the candidate variant (by name) with the lowest support cross-validation
//!   error (mean over outputs of each output's best penalty score);
//! - `learned_basis`: the meta-trained LeARN library Θ(X; ψ) as features, optionally beside a fixed
//!   causal library (the hybrid), with a regression on the support segment: closed-form adaptation
//!   of the coefficients on the learned basis instead of SGD steps ([`learn::variants`]);
//! - `learn`: the paper's LeARN itself, the meta-trained networks adapted online on the support
//!   segment with the model's adaptation settings (the LeARN column of the tables);
//! - `average`: the mean of the predictions of earlier variants (equal weights: nothing is chosen,
//!   so nothing can be chosen on the query segment).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::causal_library::CausalLibrary;
use crate::experiment::Experiment;
use crate::flights::Flight;
use crate::segment::{Segment, SegmentModel};
use crate::sindy_variant::LibraryRegression;
use crate::sindy_variant::SegmentPredictions;
use crate::sindy_variant::VariantEvaluation;
use crate::sindy_variant::evaluate_features;
use learn::variants::{LearnedFeatures, learned_features};
use learn::{Formulation, MetaTrainedModel};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use sindy::{Mat, RegressionFit, RegressionSpec};

use crate::config::{CheckedRunConfig, RunConfig, check_seeds, merge_patch};
use crate::error::{PipelineError, Result};

/// The most variants a variants file may declare (every variant runs on every cell and seed; the
/// committed file declares 14).
pub const MAX_VARIANTS: usize = 200;

/// Whether `c` may appear in a variant's name: the name is a table column, a Markdown code span
/// and a JSON key, so no `|`, backtick, space or line break.
fn is_name_character(c: char) -> bool {
    c.is_alphanumeric() || matches!(c, '-' | '_' | '.' | '+')
}

/// A name as a message shows it: quoted, escaped when it holds control characters (so that the
/// message stays on one line).
fn shown(name: &str) -> String {
    if name.chars().any(char::is_control) {
        format!("{name:?}")
    } else {
        format!("'{name}'")
    }
}

/// One variant as declared in the configuration.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct VariantSpec {
    /// The column name, e.g. `lag-ridge-cv`.
    pub name: String,
    pub description: String,
    #[serde(flatten)]
    pub kind: VariantKind,
}

/// What a variant fits.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum VariantKind {
    Library(LibraryRegression),
    Select {
        candidates: Vec<String>,
    },
    LearnedBasis(LearnedBasisSpec),
    /// The paper's LeARN: the meta-trained networks adapted online on the support segment.
    Learn,
    /// The mean of the members' predictions (variants declared before it), equal weights.
    Average {
        members: Vec<String>,
    },
    /// The mean prediction of `members` LeARN models, each meta-trained from its own seed
    /// ([`ensemble_member_seeds`]) and adapted online as in `learn`: still of the form Θ·ℰᵀ, with
    /// the members' basis functions side by side and their coefficients divided by `members`.
    LearnEnsemble {
        members: usize,
    },
}

/// The most members a `learn_ensemble` variant may have (each is a full meta-training).
pub const MAX_ENSEMBLE_MEMBERS: usize = 8;

/// How far apart the seeds of a `learn_ensemble`'s members are: member k of the run seed s is
/// meta-trained with seed s + k·stride, so the members of different run seeds never share one.
pub const ENSEMBLE_SEED_STRIDE: u64 = 1_000_000;

/// The seeds of the members of a `learn_ensemble` for the run seed `seed`: `seed` itself (the
/// `learn` variant's model), then `seed + k·ENSEMBLE_SEED_STRIDE`; `None` on overflow.
pub fn ensemble_member_seeds(seed: u64, members: usize) -> Option<Vec<u64>> {
    (0..members as u64)
        .map(|k| seed.checked_add(k.checked_mul(ENSEMBLE_SEED_STRIDE)?))
        .collect()
}

impl VariantKind {
    /// Whether the variant needs the meta-trained LeARN networks (the paper's LeARN and the
    /// closed-form adaptations over its basis).
    pub(crate) fn needs_meta_training(&self) -> bool {
        matches!(
            self,
            Self::LearnedBasis(_) | Self::Learn | Self::LearnEnsemble { .. }
        )
    }

    /// Whether the variant fits a regression (and so has a support cross-validation score and
    /// equations).
    fn is_regression(&self) -> bool {
        matches!(
            self,
            Self::Library(_) | Self::Select { .. } | Self::LearnedBasis(_)
        )
    }

    /// The regression the variant fits itself (not through another variant).
    fn own_regression(&self) -> Option<&RegressionSpec> {
        match self {
            Self::Library(variant) => Some(&variant.regression),
            Self::LearnedBasis(variant) => Some(&variant.regression),
            _ => None,
        }
    }

    /// Checks the settings that do not depend on the data (libraries, penalties, folds,
    /// bagging); errors name the field inside the variant (`regression.penalty.lambdas`).
    fn validate(&self) -> sindy::Result<()> {
        match self {
            Self::Library(variant) => variant.validate(),
            Self::LearnedBasis(variant) => variant.validate(),
            Self::LearnEnsemble { members } => {
                if (2..=MAX_ENSEMBLE_MEMBERS).contains(members) {
                    Ok(())
                } else {
                    Err(sindy::SindyError::Field {
                        field: "members".to_string(),
                        message: format!(
                            "{members} members; an ensemble has 2 to {MAX_ENSEMBLE_MEMBERS} \
                             (pipeline::MAX_ENSEMBLE_MEMBERS), each a full meta-training"
                        ),
                    })
                }
            }
            Self::Select { .. } | Self::Learn | Self::Average { .. } => Ok(()),
        }
    }
}

/// Closed-form adaptation over the meta-trained LeARN networks' outputs, optionally beside a fixed
/// causal library (the hybrid library).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LearnedBasisSpec {
    pub features: LearnedFeatures,
    /// The fixed part of a hybrid library (e.g. sin/cos terms), placed before the learned features.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub library: Option<CausalLibrary>,
    pub regression: RegressionSpec,
}

impl LearnedBasisSpec {
    /// Checks the fixed library and the regression, as [`LibraryRegression::validate`] does.
    pub fn validate(&self) -> sindy::Result<()> {
        if let Some(library) = &self.library {
            library.validate().map_err(|e| e.within("library"))?;
        }
        self.regression
            .validate()
            .map_err(|e| e.within("regression"))
    }

    /// Features of both segments from the frozen networks (and the fixed library), regression
    /// fitted and its penalty chosen on the support segment.
    pub fn evaluate(
        &self,
        model: &MetaTrainedModel,
        support: &Segment,
        query: &Segment,
        seed: u64,
    ) -> Result<VariantEvaluation> {
        let features = |segment: &Segment| -> Result<(Mat<f64>, Vec<String>)> {
            let (learned, learned_names) =
                learned_features(model, &segment.inputs(), self.features);
            let Some(library) = &self.library else {
                return Ok((learned, learned_names));
            };
            let (fixed, mut names) = library.features(segment)?;
            names.extend(learned_names);
            let theta = Mat::from_fn(segment.len(), fixed.ncols() + learned.ncols(), |i, j| {
                if j < fixed.ncols() {
                    fixed[(i, j)]
                } else {
                    learned[(i, j - fixed.ncols())]
                }
            });
            Ok((theta, names))
        };
        let (support_theta, names) = features(support)?;
        let (query_theta, _) = features(query)?;
        Ok(evaluate_features(
            &self.regression,
            names,
            support_theta.as_ref(),
            support.targets.as_ref(),
            query_theta.as_ref(),
            query.targets.as_ref(),
            seed,
        )?)
    }
}

/// `experiments/variants.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VariantsConfig {
    pub name: String,
    pub description: String,
    /// The run configuration whose formulations, conditions, split, derivative, published numbers,
    /// SINDy baseline and LeARN configuration are used (`experiments/reproduce.json`).
    pub run: PathBuf,
    /// Seeds: of the bagging resamples and of the LeARN meta-training of learned-basis variants.
    pub seeds: Vec<u64>,
    /// Merge patch applied to the LeARN configuration for the learned-basis variants' meta-training.
    #[serde(default, skip_serializing_if = "serde_json::Value::is_null")]
    pub learn_overrides: serde_json::Value,
    /// The variant declared in advance as the headline column (compared with the target).
    pub headline: String,
    /// A bagged variant whose band is drawn in the figures.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub figure_variant: Option<String>,
    /// Variants that `make reproduce` adds as extra table columns; those that need the LeARN
    /// networks use the run's own meta-trained model (its first seed), so they cost no training.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub reproduce: Vec<String>,
    pub variants: Vec<VariantSpec>,
}

/// A checked variants configuration and the run configuration it names.
pub struct CheckedVariants {
    pub raw: VariantsConfig,
    pub path: PathBuf,
    pub run: CheckedRunConfig,
    /// The project root (for the git commit of the inputs).
    pub root: PathBuf,
}

impl CheckedVariants {
    /// Every file the ablations read besides the flights (this file, given by `option`, the run
    /// configuration it names and that one's inputs), each with what names it: outputs must be
    /// none of them.
    pub fn input_files(&self, option: &str) -> Vec<(String, PathBuf)> {
        let mut inputs = vec![(option.to_string(), self.path.clone())];
        inputs.extend(
            self.run
                .input_files(&format!("run of {}", self.path.display())),
        );
        inputs
    }
}

impl VariantsConfig {
    /// Reads and checks `path` alone (names, candidates, headline), without the run it names.
    pub fn read(path: &Path) -> Result<VariantsConfig> {
        let text = inputs::read_json_text(path).map_err(|source| PipelineError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let error = |field: &str, message: String| PipelineError::Config {
            path: path.to_path_buf(),
            field: field.to_string(),
            message,
        };
        let raw: VariantsConfig =
            inputs::json::from_str(&text).map_err(|e| PipelineError::json(path, e))?;
        check_seeds(&raw.seeds).map_err(|message| error("seeds", message))?;
        if raw.variants.len() > MAX_VARIANTS {
            return Err(error(
                "variants",
                format!(
                    "{} variants, more than the limit of {MAX_VARIANTS} (pipeline::MAX_VARIANTS)",
                    raw.variants.len()
                ),
            ));
        }
        let names: Vec<&str> = raw.variants.iter().map(|v| v.name.as_str()).collect();
        for (index, name) in names.iter().enumerate() {
            let field = format!("variants[{index}].name");
            if name.trim().is_empty() {
                return Err(error(&field, format!("variant {} has no name", index + 1)));
            }
            if let Some(bad) = name.chars().find(|&c| !is_name_character(c)) {
                return Err(error(
                    &field,
                    format!(
                        "{} has the character {bad:?}; a name (a table column and a Markdown \
                         code span) may hold only letters, digits, '-', '_', '.' and '+'",
                        shown(name)
                    ),
                ));
            }
            if names[..index].contains(name) {
                return Err(error(&field, format!("{} is declared twice", shown(name))));
            }
        }
        for (own, variant) in raw.variants.iter().enumerate() {
            let at = format!("variants[{own}] ({})", variant.name);
            variant.kind.validate().map_err(|e| match e.within("") {
                sindy::SindyError::Field { field, message } => {
                    error(&format!("{at}.{field}"), message)
                }
                other => error(&at, other.to_string()),
            })?;
            let (others, what, list) = match &variant.kind {
                VariantKind::Select { candidates } => (candidates, "candidate", "candidates"),
                VariantKind::Average { members } => (members, "member", "members"),
                _ => continue,
            };
            let field = format!("{at}.{list}");
            if others.is_empty() {
                return Err(error(&field, format!("name at least one {what}")));
            }
            for (position, other) in others.iter().enumerate() {
                let Some(index) = names[..own].iter().position(|n| n == other) else {
                    return Err(error(
                        &field,
                        format!(
                            "{what} {} must be a variant declared before it",
                            shown(other)
                        ),
                    ));
                };
                if others[..position].contains(other) {
                    return Err(error(
                        &field,
                        format!("{what} {} is listed twice", shown(other)),
                    ));
                }
                if what == "candidate" && !raw.variants[index].kind.is_regression() {
                    return Err(error(
                        &field,
                        format!(
                            "candidate {} has no support cross-validation score to select by",
                            shown(other)
                        ),
                    ));
                }
            }
        }
        let named = [
            ("headline", Some(&raw.headline)),
            ("figure_variant", raw.figure_variant.as_ref()),
        ]
        .into_iter()
        .chain(raw.reproduce.iter().map(|n| ("reproduce", Some(n))));
        for (field, name) in named {
            if let Some(name) = name
                && !names.contains(&name.as_str())
            {
                return Err(error(
                    field,
                    format!("{} is not a declared variant", shown(name)),
                ));
            }
        }
        for (index, name) in raw.reproduce.iter().enumerate() {
            if raw.reproduce[..index].contains(name) {
                return Err(error(
                    "reproduce",
                    format!("{} is listed twice", shown(name)),
                ));
            }
        }
        for (index, variant) in raw.variants.iter().enumerate() {
            if let VariantKind::LearnEnsemble { members } = variant.kind
                && let Some(seed) = raw
                    .seeds
                    .iter()
                    .find(|&&seed| ensemble_member_seeds(seed, members).is_none())
            {
                return Err(error(
                    "seeds",
                    format!(
                        "seed {seed} leaves no room for the member seeds of variants[{index}] \
                         ({}): seed + k·{ENSEMBLE_SEED_STRIDE} overflows",
                        variant.name
                    ),
                ));
            }
        }
        // `make reproduce` evaluates its columns with the run's one meta-trained model per cell.
        if let Some(ensemble) = raw
            .reproduce_variants()
            .iter()
            .find(|v| matches!(v.kind, VariantKind::LearnEnsemble { .. }))
        {
            return Err(error(
                "reproduce",
                format!(
                    "{} (or a member of a listed variant) is a learn_ensemble, which needs more \
                     meta-trained models than the run's one per cell; show it in make ablations",
                    shown(&ensemble.name)
                ),
            ));
        }
        Ok(raw)
    }

    /// Reads and checks `path` and the run configuration it names; relative paths start at `root`.
    pub fn load(path: &Path, root: &Path) -> Result<CheckedVariants> {
        let raw = Self::read(path)?;
        if raw.run.as_os_str().is_empty() {
            return Err(PipelineError::Config {
                path: path.to_path_buf(),
                field: "run".to_string(),
                message: "an empty path (name a file)".to_string(),
            });
        }
        let run_path = if raw.run.is_absolute() {
            raw.run.clone()
        } else {
            root.join(&raw.run)
        };
        let run = RunConfig::load(&run_path, root)
            .map_err(|e| crate::config::named_in(path, "run", e))?;
        let checked = CheckedVariants {
            raw,
            path: path.to_path_buf(),
            run,
            root: root.to_path_buf(),
        };
        // The learned-basis variants' LeARN configuration, checked now rather than after the
        // flights are loaded.
        learned_basis_config(&checked)?;
        Ok(checked)
    }

    /// The variant whose equations describe `name`: itself when it fits a regression, for an
    /// average its first member that does (recursively), none for `learn`.
    pub fn equations_variant<'a>(&'a self, name: &'a str) -> Option<&'a str> {
        match &self.variants.iter().find(|v| v.name == name)?.kind {
            kind if kind.is_regression() => Some(name),
            VariantKind::Average { members } => {
                members.iter().find_map(|m| self.equations_variant(m))
            }
            _ => None,
        }
    }

    /// Checks, before any fit, what depends on a support segment of `rows` samples (described by
    /// `segment` in the message): the cross-validation folds and bagging blocks of every variant
    /// that fits a regression (with `reproduce_only`, of those `make reproduce` runs). `path` is
    /// this file.
    pub(crate) fn check_rows(
        &self,
        path: &Path,
        rows: usize,
        segment: &str,
        reproduce_only: bool,
    ) -> Result<()> {
        let wanted: Vec<String> = if reproduce_only {
            self.reproduce_variants()
                .into_iter()
                .map(|v| v.name)
                .collect()
        } else {
            self.variants.iter().map(|v| v.name.clone()).collect()
        };
        for (index, variant) in self.variants.iter().enumerate() {
            let Some(regression) = variant.kind.own_regression() else {
                continue;
            };
            if !wanted.contains(&variant.name) {
                continue;
            }
            regression.check_rows(rows).map_err(|e| {
                let (field, message) = match e.within("regression") {
                    sindy::SindyError::Field { field, message } => (field, message),
                    other => ("regression".to_string(), other.to_string()),
                };
                PipelineError::Config {
                    path: path.to_path_buf(),
                    field: format!("variants[{index}] ({}).{field}", variant.name),
                    message: format!("{message} ({segment})"),
                }
            })?;
        }
        Ok(())
    }

    /// The `reproduce` variants (and the variants they select from or average), in declaration
    /// order.
    fn reproduce_variants(&self) -> Vec<VariantSpec> {
        let mut needed: Vec<&str> = self.reproduce.iter().map(String::as_str).collect();
        for variant in self.variants.iter().rev() {
            if !needed.contains(&variant.name.as_str()) {
                continue;
            }
            if let VariantKind::Select { candidates: others }
            | VariantKind::Average { members: others } = &variant.kind
            {
                needed.extend(others.iter().map(String::as_str));
            }
        }
        self.variants
            .iter()
            .filter(|v| needed.contains(&v.name.as_str()))
            .cloned()
            .collect()
    }
}

/// The extra columns `make reproduce` shows: the `reproduce` variants of the variants file
/// `config`, for each (support, query, the run's meta-trained LeARN model) of a cell, with the
/// first seed of that file.
pub fn reproduce_columns(
    config: &VariantsConfig,
    cells: &[(&Segment, &Segment, &MetaTrainedModel)],
) -> Result<Vec<BTreeMap<String, report::Mse>>> {
    let variants = config.reproduce_variants();
    let seed = config.seeds[0];
    cells
        .par_iter()
        .map(|(support, query, model)| {
            // The run's model serves every variant; `read` refused ensembles in these columns.
            let run_model = |_seed: u64| -> Result<MetaTrainedModel> { Ok((*model).clone()) };
            let outcomes = evaluate_variants(&variants, run_model, support, query, seed)?;
            Ok(variants
                .iter()
                .zip(outcomes)
                .filter(|(spec, _)| config.reproduce.contains(&spec.name))
                .map(|(spec, outcome)| {
                    (
                        spec.name.clone(),
                        report::Mse {
                            adaptation: outcome.predictions.support_mse,
                            generalisation: outcome.predictions.query_mse,
                        },
                    )
                })
                .collect())
        })
        .collect()
}

/// One variant's outcome on one cell and seed, with its traces.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// Predictions and MSE on both segments (and the band of a bagged variant).
    pub predictions: SegmentPredictions,
    /// The feature names and the fitted regression, for variants that fit one.
    pub regression: Option<(Vec<String>, RegressionFit)>,
    /// Everything chosen inside the support segment (per output penalty; `variant` for select).
    pub chosen: BTreeMap<String, serde_json::Value>,
    /// Mean over outputs of the best support cross-validation MSE (variants that fit a
    /// regression).
    pub support_cv: Option<f64>,
}

impl Outcome {
    /// A variant without a regression (nothing chosen, no band): its predictions, scored on both
    /// segments.
    fn unfitted(
        support_prediction: Mat<f64>,
        query_prediction: Mat<f64>,
        support: &Segment,
        query: &Segment,
    ) -> Self {
        Self {
            predictions: SegmentPredictions::scored(
                support_prediction,
                query_prediction,
                support.targets.as_ref(),
                query.targets.as_ref(),
            ),
            regression: None,
            chosen: BTreeMap::new(),
            support_cv: None,
        }
    }
}

/// The run's LeARN configuration with the variants file's `learn_overrides`, checked; errors name
/// the variants file and `learn_overrides`.
fn learned_basis_config(config: &CheckedVariants) -> Result<learn::CheckedConfig> {
    let run = &config.run;
    let error = |message: String| PipelineError::Config {
        path: config.path.clone(),
        field: "learn_overrides".to_string(),
        message,
    };
    let with_overrides = |message: String| {
        error(format!(
            "{} with these overrides: {message}",
            run.learn_config_path.display()
        ))
    };
    let mut value = serde_json::to_value(run.learn.get()).map_err(|e| error(e.to_string()))?;
    merge_patch(&mut value, &config.raw.learn_overrides);
    let learn_config: learn::LearnConfig =
        inputs::json::from_value(value).map_err(|e| with_overrides(e.to_string()))?;
    learn_config.check(&config.path).map_err(|e| match e {
        learn::LearnError::Config { field, message, .. } => {
            with_overrides(format!("field '{field}': {message}"))
        }
        other => with_overrides(other.to_string()),
    })
}

pub(crate) fn learned_basis_experiment(
    config: &CheckedVariants,
    data_dir: &Path,
    evaluation: &[Arc<Flight>],
) -> Result<Experiment> {
    let run = &config.run;
    Experiment::load_with(
        learned_basis_config(config)?,
        run.conditions.clone(),
        data_dir,
        run.protocol,
        evaluation,
    )
}

/// Every variant of `variants` on one support/query pair with one seed, in declaration order.
/// `meta_train(s)` meta-trains the LeARN networks with seed `s`: with `seed` when a learned-basis
/// variant needs them, with each member seed of a `learn_ensemble`, at most once per seed. It must
/// not read the query segment (the pipeline's leaves the evaluation flight out entirely).
pub fn evaluate_variants(
    variants: &[VariantSpec],
    meta_train: impl Fn(u64) -> Result<MetaTrainedModel>,
    support: &Segment,
    query: &Segment,
    seed: u64,
) -> Result<Vec<Outcome>> {
    let mut outcomes: Vec<Outcome> = Vec::with_capacity(variants.len());
    let mut meta_trained = MetaTrainedModels {
        train: &meta_train,
        models: BTreeMap::new(),
    };
    for spec in variants {
        // The indices of the variants `names` (each declared before this one).
        let earlier = |names: &[String], what: &str| -> Result<Vec<usize>> {
            let found: Vec<usize> = names
                .iter()
                .filter_map(|name| variants.iter().position(|v| &v.name == name))
                .filter(|&index| index < outcomes.len())
                .collect();
            if found.len() != names.len() || found.is_empty() {
                return Err(PipelineError::Mismatch {
                    what: format!("variant '{}'", spec.name),
                    message: format!("every {what} must be declared before it"),
                });
            }
            Ok(found)
        };
        let outcome = (|| -> Result<Outcome> {
            Ok(match &spec.kind {
                VariantKind::Library(variant) => {
                    let evaluation = variant.evaluate(support, query, seed)?;
                    outcome_of(evaluation, BTreeMap::new(), &support.formulation)
                }
                VariantKind::Select { candidates } => {
                    let score = |index: usize| outcomes[index].support_cv.unwrap_or(f64::INFINITY);
                    let best = earlier(candidates, "candidate")?
                        .into_iter()
                        .min_by(|&a, &b| score(a).total_cmp(&score(b)))
                        .expect("at least one candidate");
                    let chosen_outcome = &outcomes[best];
                    let mut chosen = chosen_outcome.chosen.clone();
                    chosen.insert(
                        "variant".to_string(),
                        serde_json::Value::String(variants[best].name.clone()),
                    );
                    Outcome {
                        chosen,
                        ..chosen_outcome.clone()
                    }
                }
                VariantKind::LearnedBasis(variant) => {
                    let model = meta_trained.get(seed)?;
                    let evaluation = variant.evaluate(model, support, query, seed)?;
                    outcome_of(evaluation, BTreeMap::new(), &support.formulation)
                }
                VariantKind::Learn => {
                    let model = meta_trained.get(seed)?;
                    let [on_support, on_query] = adapted_predictions(model, support, query);
                    Outcome::unfitted(on_support, on_query, support, query)
                }
                VariantKind::LearnEnsemble { members } => {
                    let seeds = ensemble_member_seeds(seed, *members).ok_or_else(|| {
                        PipelineError::Mismatch {
                            what: format!("seed {seed}"),
                            message: "its ensemble member seeds overflow".to_string(),
                        }
                    })?;
                    let mut sums: Option<[Mat<f64>; 2]> = None;
                    for member_seed in seeds {
                        let predictions =
                            adapted_predictions(meta_trained.get(member_seed)?, support, query);
                        match &mut sums {
                            None => sums = Some(predictions),
                            Some(sums) => {
                                for (sum, prediction) in sums.iter_mut().zip(&predictions) {
                                    *sum += prediction;
                                }
                            }
                        }
                    }
                    let scale = 1.0 / *members as f64;
                    let [on_support, on_query] = sums.expect("at least two members");
                    Outcome::unfitted(
                        Mat::from_fn(on_support.nrows(), on_support.ncols(), |i, j| {
                            on_support[(i, j)] * scale
                        }),
                        Mat::from_fn(on_query.nrows(), on_query.ncols(), |i, j| {
                            on_query[(i, j)] * scale
                        }),
                        support,
                        query,
                    )
                }
                VariantKind::Average { members } => {
                    let members: Vec<&SegmentPredictions> = earlier(members, "member")?
                        .into_iter()
                        .map(|index| &outcomes[index].predictions)
                        .collect();
                    let mean = |prediction: fn(&SegmentPredictions) -> &Mat<f64>| {
                        let first = prediction(members[0]);
                        Mat::from_fn(first.nrows(), first.ncols(), |i, j| {
                            members.iter().map(|m| prediction(m)[(i, j)]).sum::<f64>()
                                / members.len() as f64
                        })
                    };
                    Outcome::unfitted(
                        mean(|e| &e.support_prediction),
                        mean(|e| &e.query_prediction),
                        support,
                        query,
                    )
                }
            })
        })()
        .map_err(|error| match error {
            error @ PipelineError::Mismatch { .. } => error,
            error => PipelineError::Mismatch {
                what: format!("variant '{}'", spec.name),
                message: error.to_string(),
            },
        })?;
        outcomes.push(outcome);
    }
    Ok(outcomes)
}

/// The meta-trained models of one cell, each trained by `train` on first use of its seed.
struct MetaTrainedModels<'t, F> {
    train: &'t F,
    models: BTreeMap<u64, MetaTrainedModel>,
}

impl<F: Fn(u64) -> Result<MetaTrainedModel>> MetaTrainedModels<'_, F> {
    fn get(&mut self, seed: u64) -> Result<&MetaTrainedModel> {
        if !self.models.contains_key(&seed) {
            let model = (self.train)(seed)?;
            self.models.insert(seed, model);
        }
        Ok(&self.models[&seed])
    }
}

/// `model` adapted online on `support` (its own adaptation settings), predicting both segments.
fn adapted_predictions(
    model: &MetaTrainedModel,
    support: &Segment,
    query: &Segment,
) -> [Mat<f64>; 2] {
    let adapted = model.adapt(support, &model.config.adaptation);
    [support, query].map(|segment| {
        learn::from_row_major(
            &model.predict_segment(&adapted, segment),
            model.architecture.state_dim,
        )
    })
}

fn outcome_of(
    evaluation: VariantEvaluation,
    mut chosen: BTreeMap<String, serde_json::Value>,
    formulation: &Formulation,
) -> Outcome {
    let selections = &evaluation.fit.selections;
    for (selection, output) in selections.iter().zip(formulation.target_names()) {
        chosen.insert(output, serde_json::json!(selection.chosen));
    }
    let support_cv = selections
        .iter()
        .map(|s| s.scores.iter().copied().fold(f64::INFINITY, f64::min))
        .sum::<f64>()
        / selections.len().max(1) as f64;
    Outcome {
        predictions: evaluation.predictions,
        regression: Some((evaluation.feature_names, evaluation.fit)),
        chosen,
        support_cv: Some(support_cv),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::flights::Protocol;
    use learn::{CHECKPOINT_FORMAT, Standardiser};

    /// A synthetic attitude segment of `n` samples with targets that depend on the inputs.
    fn segment(n: usize, phase: f64) -> Segment {
        let states = Mat::from_fn(n, 3, |i, j| (0.05 * i as f64 + j as f64 + phase).sin());
        let controls = Mat::from_fn(n, 4, |i, j| 1.0 + 0.2 * (0.03 * i as f64 - j as f64).cos());
        let targets = Mat::from_fn(n, 3, |i, j| {
            0.7 * states[(i, j)] - 0.4 * controls[(i, j + 1)] + 0.05 * ((i * 7919) % 13) as f64
        });
        Segment {
            formulation: Formulation::Attitude,
            rows: 0..n,
            time: (0..n).map(|i| i as f64 * 0.02).collect(),
            states,
            controls,
            targets,
        }
    }

    fn untrained_model() -> MetaTrainedModel {
        let mut config: learn::LearnConfig =
            serde_json::from_str(include_str!("../../../experiments/learn.json")).unwrap();
        config.hidden_layers = vec![5, 4];
        config.adaptation.passes = 2;
        let architecture = learn::architecture(Formulation::Attitude, &config);
        MetaTrainedModel {
            format: CHECKPOINT_FORMAT.to_string(),
            trained_on: learn::TrainedOn::Flights(learn::FlightTraining {
                formulation: Formulation::Attitude,
                protocol: Protocol::LeaveConditionOut.name().to_string(),
                held_out_condition: None,
            }),
            seed: 2,
            parameters: architecture.initial_parameters(2),
            standardiser: Standardiser::identity(architecture.input_dim),
            architecture,
            config,
            data_files: Vec::new(),
            meta_loss_history: Vec::new(),
        }
    }

    #[test]
    fn learn_is_the_adapted_network_and_average_the_mean_of_its_members() {
        let text = config(
            &format!(
                r#"{{"name": "a", "description": "", {RIDGE}}},
                   {{"name": "l", "description": "", "kind": "learn"}},
                   {{"name": "m", "description": "", "kind": "average", "members": ["l", "a"]}}"#
            ),
            "",
        );
        let read = VariantsConfig::read(&write("evaluate", &text)).unwrap();
        let (support, query) = (segment(60, 0.0), segment(40, 1.3));
        let model = untrained_model();
        let outcomes =
            evaluate_variants(&read.variants, |_| Ok(model.clone()), &support, &query, 1).unwrap();
        let adapted = model.adapt(&support, &model.config.adaptation);
        assert_ne!(adapted, model.parameters, "adaptation moved nothing");
        let expected = model.predict_segment(&adapted, &query);
        let learn = &outcomes[1].predictions;
        for i in 0..query.len() {
            for j in 0..3 {
                assert_eq!(learn.query_prediction[(i, j)], expected[i * 3 + j]);
                let mean = 0.5
                    * (learn.query_prediction[(i, j)]
                        + outcomes[0].predictions.query_prediction[(i, j)]);
                assert_eq!(outcomes[2].predictions.query_prediction[(i, j)], mean);
            }
        }
        let error = |prediction: &Mat<f64>, segment: &Segment| {
            sindy::mean_squared_error(prediction.as_ref(), segment.targets.as_ref())
        };
        assert_eq!(learn.query_mse, error(&learn.query_prediction, &query));
        let average = &outcomes[2].predictions;
        assert_eq!(
            average.support_mse,
            error(&average.support_prediction, &support)
        );
        assert!(outcomes[1].support_cv.is_none() && outcomes[2].chosen.is_empty());
        assert!(outcomes[0].support_cv.is_some() && outcomes[2].regression.is_none());
    }

    #[test]
    fn learn_ensemble_is_the_mean_of_its_members_each_meta_trained_once_from_its_own_seed() {
        let text = config(
            r#"{"name": "l", "description": "", "kind": "learn"},
               {"name": "a", "description": "", "kind": "learn_ensemble", "members": 3}"#,
            "",
        );
        let read = VariantsConfig::read(&write("ensemble", &text)).unwrap();
        let (support, query) = (segment(60, 0.0), segment(40, 1.3));
        // A different (untrained) model per seed; the seeds asked for are recorded.
        let asked = std::sync::Mutex::new(Vec::new());
        let model_for = |seed: u64| {
            let mut model = untrained_model();
            model.seed = seed;
            model.parameters = model.architecture.initial_parameters(seed);
            model
        };
        let train = |seed: u64| {
            asked.lock().unwrap().push(seed);
            Ok(model_for(seed))
        };
        let outcomes = evaluate_variants(&read.variants, train, &support, &query, 7).unwrap();
        // The `learn` model (seed 7) is the ensemble's first member, trained once.
        assert_eq!(*asked.lock().unwrap(), vec![7, 1_000_007, 2_000_007]);
        assert_eq!(
            ensemble_member_seeds(7, 3),
            Some(vec![7, 1_000_007, 2_000_007])
        );
        let members: Vec<[Mat<f64>; 2]> = [7, 1_000_007, 2_000_007]
            .into_iter()
            .map(|seed| adapted_predictions(&model_for(seed), &support, &query))
            .collect();
        let ensemble = &outcomes[1].predictions;
        for i in 0..query.len() {
            for j in 0..3 {
                let mean = members.iter().map(|m| m[1][(i, j)]).sum::<f64>() / 3.0;
                assert!(
                    (ensemble.query_prediction[(i, j)] - mean).abs() <= 1e-12 * mean.abs().max(1.0)
                );
            }
        }
        assert_eq!(outcomes[0].predictions.query_prediction, members[0][1]);
        assert_ne!(
            members[0][1], members[1][1],
            "the members are different models"
        );
        assert!(outcomes[1].chosen.is_empty() && outcomes[1].support_cv.is_none());
    }

    #[test]
    fn a_learn_ensemble_is_checked_when_the_file_is_read() {
        let ensemble = |members: &str| {
            format!(
                r#"{{"name": "a", "description": "", "kind": "learn_ensemble", "members": {members}}}"#
            )
        };
        let message = read_error("ensemble-one", &ensemble("1"), "");
        assert!(
            message.ends_with(
                "variants[0] (a).members: 1 members; an ensemble has 2 to 8 (pipeline::MAX_ENSEMBLE_MEMBERS), each a full meta-training"
            ),
            "{message}"
        );
        let message = read_error("ensemble-many", &ensemble("100"), "");
        assert!(message.contains("100 members"), "{message}");
        let overflow = config(&ensemble("3"), "")
            .replace(r#""seeds": [1]"#, r#""seeds": [1, 18446744073709551000]"#);
        let path = write("ensemble-overflow", &overflow);
        let message = VariantsConfig::read(&path).unwrap_err().to_string();
        assert!(
            message.contains("seeds: seed 18446744073709551000 leaves no room"),
            "{message}"
        );
        // Shown in make reproduce's columns, directly or through an average: refused.
        let a = format!(r#"{{"name": "r", "description": "", {RIDGE}}}"#);
        let average =
            r#"{"name": "m", "description": "", "kind": "average", "members": ["r", "a"]}"#;
        for (name, extra) in [
            ("ensemble-reproduce", r#""reproduce": ["a"],"#),
            ("ensemble-reproduce-member", r#""reproduce": ["m"],"#),
        ] {
            let variants = format!("{a}, {}, {average}", ensemble("3"));
            let message = read_error(name, &variants, extra);
            assert!(
                message.contains(
                    "reproduce: 'a' (or a member of a listed variant) is a learn_ensemble"
                ),
                "{name}: {message}"
            );
        }
    }

    /// A temporary `.json` file holding `text`, removed when dropped.
    fn write(name: &str, text: &str) -> tempfile::TempPath {
        let mut file = tempfile::Builder::new()
            .prefix(&format!("pipeline-variants-{name}-"))
            .suffix(".json")
            .tempfile()
            .unwrap();
        std::io::Write::write_all(&mut file, text.as_bytes()).unwrap();
        file.into_temp_path()
    }

    fn config(variants: &str, extra: &str) -> String {
        format!(
            r#"{{"name": "t", "description": "d", "run": "experiments/reproduce.json",
               "seeds": [1], "headline": "a", {extra} "variants": [{variants}]}}"#
        )
    }

    const RIDGE: &str = r#""kind": "library", "library": {"linear": true},
        "regression": {"penalty": {"kind": "ridge", "lambdas": [0.0]}}"#;
    const LEARNED: &str = r#""kind": "learned_basis", "features": "basis",
        "regression": {"penalty": {"kind": "ridge", "lambdas": [0.0]}}"#;

    #[test]
    fn the_variants_file_is_checked() {
        let a = format!(r#"{{"name": "a", "description": "", {RIDGE}}}"#);
        let b = format!(r#"{{"name": "b", "description": "", {LEARNED}}}"#);
        let select = r#"{"name": "s", "description": "", "kind": "select", "candidates": ["a"]}"#;
        let good = write(
            "good",
            &config(&format!("{a}, {b}, {select}"), r#""reproduce": ["s"],"#),
        );
        let read = VariantsConfig::read(&good).unwrap();
        assert_eq!(read.reproduce_variants().len(), 2);

        let cases = [
            ("twice", config(&format!("{a}, {a}"), ""), "declared twice"),
            (
                "forward",
                config(&format!("{select}, {a}"), ""),
                "declared before it",
            ),
            (
                "headline",
                config(&b.replace("\"b\"", "\"c\""), ""),
                "'a' is not",
            ),
            (
                "member",
                config(
                    &format!(
                        r#"{a}, {{"name": "m", "description": "", "kind": "average", "members": ["a", "z"]}}"#
                    ),
                    "",
                ),
                "member 'z' must be a variant declared before it",
            ),
            (
                "no-score",
                config(
                    &format!(
                        r#"{a}, {{"name": "l", "description": "", "kind": "learn"}}, {{"name": "s", "description": "", "kind": "select", "candidates": ["a", "l"]}}"#
                    ),
                    "",
                ),
                "no support cross-validation score",
            ),
        ];
        let learn_average = write(
            "learn-average",
            &config(
                &format!(
                    r#"{a}, {{"name": "l", "description": "", "kind": "learn"}}, {{"name": "m", "description": "", "kind": "average", "members": ["l", "a"]}}"#
                ),
                "",
            ),
        );
        let read = VariantsConfig::read(&learn_average).unwrap();
        assert_eq!(read.equations_variant("m"), Some("a"));
        assert_eq!(read.equations_variant("l"), None);
        // The paper's LeARN needs the meta-trained networks as much as a learned basis does.
        let needs: Vec<bool> = read
            .variants
            .iter()
            .map(|v| v.kind.needs_meta_training())
            .collect();
        assert_eq!(needs, [false, true, false]);
        let cases = cases.into_iter().chain([
            (
                "seeds",
                config(&a, "").replace("[1]", "[1, 1]"),
                "seed 1 is listed twice",
            ),
            (
                "unnamed",
                config(&a.replace("\"a\"", "\" \""), ""),
                "variant 1 has no name",
            ),
        ]);
        for (name, text, expected) in cases {
            let message = VariantsConfig::read(&write(name, &text))
                .err()
                .unwrap_or_else(|| panic!("{name} was accepted"))
                .to_string();
            assert!(message.contains(expected), "{name}: {message}");
        }
    }

    /// `VariantsConfig::read`'s error for the variants `variants` (headline `a`), one line.
    fn read_error(name: &str, variants: &str, extra: &str) -> String {
        let path = write(name, &config(variants, extra));
        let start = std::time::Instant::now();
        let message = VariantsConfig::read(&path)
            .err()
            .unwrap_or_else(|| panic!("{name} was accepted"))
            .to_string();
        assert!(
            start.elapsed().as_secs() < 5,
            "{name}: {:?}",
            start.elapsed()
        );
        assert!(!message.contains('\n'), "{name}: {message}");
        assert!(
            message.starts_with(&format!("{}: ", path.display())),
            "{name}: {message}"
        );
        message
    }

    #[test]
    fn every_variant_spec_is_checked_when_the_file_is_read() {
        let library = |library: &str, regression: &str| {
            format!(
                r#"{{"name": "a", "description": "", "kind": "library", "library": {library}, "regression": {regression}}}"#
            )
        };
        let linear = r#"{"linear": true}"#;
        let ridge = r#"{"penalty": {"kind": "ridge", "lambdas": [0.0]}}"#;
        let many = |count: usize, value: &str| vec![value; count].join(", ");
        let cases = [
            (
                "bag-block0",
                library(
                    linear,
                    r#"{"penalty": {"kind": "ridge", "lambdas": [0.0]}, "bagging": {"members": 3, "block": 0}}"#,
                ),
                "variants[0] (a).regression.bagging.block: 0 must be from 1",
            ),
            (
                "bag-huge",
                library(
                    linear,
                    r#"{"penalty": {"kind": "ridge", "lambdas": [0.0]}, "bagging": {"members": 1000000000, "block": 125}}"#,
                ),
                "variants[0] (a).regression.bagging.members: 1000000000 must be from 2 to 1000",
            ),
            (
                "fractions-bad",
                library(
                    linear,
                    r#"{"penalty": {"kind": "lasso", "fractions": [0.1, 2]}}"#,
                ),
                "variants[0] (a).regression.penalty.fractions: 2 must be in (0, 1]",
            ),
            (
                "lambdas-neg",
                library(
                    linear,
                    r#"{"penalty": {"kind": "ridge", "lambdas": [0.1, -1]}}"#,
                ),
                "variants[0] (a).regression.penalty.lambdas: -1 must be ≥ 0",
            ),
            (
                "lambdas-many",
                library(
                    linear,
                    &format!(
                        r#"{{"penalty": {{"kind": "ridge", "lambdas": [{}]}}}}"#,
                        many(1_000_000, "0.5")
                    ),
                ),
                "variants[0] (a).regression.penalty.lambdas: 1000000 candidates, more than the limit of 100",
            ),
            (
                "thresholds-neg",
                library(
                    linear,
                    r#"{"penalty": {"kind": "stlsq", "thresholds": [-0.1], "alpha": 0.05}}"#,
                ),
                "variants[0] (a).regression.penalty.thresholds: -0.1 must be ≥ 0",
            ),
            (
                "lib-empty",
                library("{}", ridge),
                "variants[0] (a).library: the library has no feature",
            ),
            (
                "lags-bad",
                library(r#"{"control_lags": [0.5, 1.5]}"#, ridge),
                "variants[0] (a).library.control_lags: pole 1.5 must lie in [0, 1)",
            ),
            (
                "lags-twice",
                library(r#"{"control_lags": [0.5, 0.8, 0.8]}"#, ridge),
                "variants[0] (a).library.control_lags: pole 0.8 is listed twice",
            ),
            (
                "lags-many",
                library(
                    &format!(r#"{{"control_lags": [{}]}}"#, many(100_000, "0.5")),
                    ridge,
                ),
                "variants[0] (a).library.control_lags: 100000 lags, more than the limit of 100",
            ),
            (
                "fourier-huge",
                library(r#"{"fourier": 1000000000}"#, ridge),
                "variants[0] (a).library.fourier: 1000000000 frequencies",
            ),
            (
                "folds",
                library(
                    linear,
                    r#"{"penalty": {"kind": "ridge", "lambdas": [0.0]}, "folds": {"folds": 1}}"#,
                ),
                "variants[0] (a).regression.folds.folds: 1 must be from 2",
            ),
            (
                "learned-basis",
                format!(
                    r#"{{"name": "a", "description": "", "kind": "learned_basis", "features": "basis", "library": {{"fourier": 1000000}}, "regression": {ridge}}}"#
                ),
                "variants[0] (a).library.fourier",
            ),
        ];
        for (name, variants, expected) in cases {
            let message = read_error(name, &variants, "");
            assert!(message.contains(expected), "{name}: {message}");
        }
        let a = library(linear, ridge);
        let seeds = config(&a, "").replace(
            r#""seeds": [1]"#,
            &format!(
                r#""seeds": [{}]"#,
                (0..100_000)
                    .map(|s| s.to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        );
        let message = VariantsConfig::read(&write("seeds-many", &seeds))
            .unwrap_err()
            .to_string();
        assert!(
            message.contains("seeds: 100000 seeds, more than the limit of 100"),
            "{message}"
        );
        let select =
            r#"{"name": "s", "description": "", "kind": "select", "candidates": ["a", "a"]}"#;
        let message = read_error("candidates-twice", &format!("{a}, {select}"), "");
        assert!(
            message.contains("variants[1] (s).candidates: candidate 'a' is listed twice"),
            "{message}"
        );
        let message = read_error("reproduce-twice", &a, r#""reproduce": ["a", "a"],"#);
        assert!(
            message.contains("reproduce: 'a' is listed twice"),
            "{message}"
        );
        let many_variants = (0..=MAX_VARIANTS)
            .map(|k| a.replace(r#""a""#, &format!(r#""a{k}""#)))
            .collect::<Vec<_>>()
            .join(", ");
        let message = read_error("variants-many", &many_variants, "");
        assert!(
            message.contains("201 variants, more than the limit of 200"),
            "{message}"
        );
    }

    #[test]
    fn variant_names_that_break_tables_or_files_are_refused() {
        let variant = |name: &str| {
            format!(
                r#"{{"name": {}, "description": "", {RIDGE}}}"#,
                serde_json::to_string(name).unwrap()
            )
        };
        for (index, name) in ["a|b\nc", "a b", "`a`", "a/b", "a\\b", "<a>"]
            .iter()
            .enumerate()
        {
            let message = read_error(&format!("name-{index}"), &variant(name), "");
            assert!(
                message.contains("variants[0].name: ") && message.contains("may hold only"),
                "{name}: {message}"
            );
        }
        for name in ["lag-ridge-cv", "a_b.c+d", "ridge2"] {
            let text = config(&variant(name), "")
                .replace(r#""headline": "a""#, &format!(r#""headline": "{name}""#));
            VariantsConfig::read(&write("name-good", &text)).unwrap();
        }
    }

    #[test]
    fn an_error_while_evaluating_names_the_variant() {
        // Bagging blocks longer than the support segment: found against the segment.
        let text = config(
            r#"{"name": "a", "description": "", "kind": "library", "library": {"linear": true},
               "regression": {"penalty": {"kind": "ridge", "lambdas": [0.0]}, "bagging": {"members": 3, "block": 500}}}"#,
            "",
        );
        let read = VariantsConfig::read(&write("evaluate-error", &text)).unwrap();
        let (support, query) = (segment(60, 0.0), segment(40, 1.3));
        let message = evaluate_variants(
            &read.variants,
            |_| Ok(untrained_model()),
            &support,
            &query,
            1,
        )
        .unwrap_err()
        .to_string();
        assert!(
            message.starts_with("variant 'a': ") && message.contains("bagging.block"),
            "{message}"
        );
    }

    #[test]
    fn folds_and_blocks_are_checked_against_the_segment_before_any_fit() {
        let bagged = r#"{"name": "b", "description": "", "kind": "library", "library": {"linear": true},
               "regression": {"penalty": {"kind": "ridge", "lambdas": [0.0]}, "bagging": {"members": 3, "block": 500}}}"#;
        let a = format!(r#"{{"name": "a", "description": "", {RIDGE}}}"#);
        let path = write(
            "check-rows",
            &config(&format!("{a}, {bagged}"), r#""reproduce": ["a"],"#),
        );
        let read = VariantsConfig::read(&path).unwrap();
        read.check_rows(&path, 1255, "the segment", false).unwrap();
        let message = read
            .check_rows(&path, 400, "the full support segment of f.csv", false)
            .unwrap_err()
            .to_string();
        assert_eq!(
            message,
            format!(
                "{}: variants[1] (b).regression.bagging.block: blocks of 500 samples are longer \
                 than the segment's 400 samples (the full support segment of f.csv)",
                path.display()
            )
        );
        // `make reproduce` runs `a` only.
        read.check_rows(&path, 400, "the segment", true).unwrap();
        let message = read
            .check_rows(&path, 20, "the segment", true)
            .unwrap_err()
            .to_string();
        assert!(
            message.contains("variants[0] (a).regression.folds: 20 samples are too few"),
            "{message}"
        );
    }

    #[test]
    fn the_committed_variants_are_within_every_limit() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../experiments/variants.json");
        let read = VariantsConfig::read(&path).unwrap();
        assert_eq!(read.variants.len(), 15);
    }
}
