//! The variants file's schema: what a variant declares ([`VariantSpec`], [`VariantKind`]), the file
//! itself ([`VariantsConfig`]) and a checked file with the run it names ([`CheckedVariants`]). The
//! checks live in `checks.rs`, the evaluation in `run.rs`.

use std::path::PathBuf;

use crate::causal_library::CausalLibrary;
use crate::config::CheckedRunConfig;
use crate::sindy_variant::LibraryRegression;
use learn::variants::LearnedFeatures;
use serde::{Deserialize, Serialize};
use sindy::RegressionSpec;

/// The most variants a variants file may declare (every variant runs on every cell and seed; the
/// committed file declares 14).
pub const MAX_VARIANTS: usize = 200;

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
    pub(super) fn is_regression(&self) -> bool {
        matches!(
            self,
            Self::Library(_) | Self::Select { .. } | Self::LearnedBasis(_)
        )
    }

    /// The regression the variant fits itself (not through another variant).
    pub(super) fn own_regression(&self) -> Option<&RegressionSpec> {
        match self {
            Self::Library(variant) => Some(&variant.regression),
            Self::LearnedBasis(variant) => Some(&variant.regression),
            _ => None,
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

impl VariantsConfig {
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

    /// The `reproduce` variants (and the variants they select from or average), in declaration
    /// order.
    pub(super) fn reproduce_variants(&self) -> Vec<VariantSpec> {
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
