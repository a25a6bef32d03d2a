//! The checks of a variants file: when it is read ([`VariantsConfig::read`]: names, references,
//! every variant's settings, the seeds), with the run it names ([`VariantsConfig::load`]: the
//! learned-basis LeARN configuration), and against a support segment before any fit
//! ([`VariantsConfig::check_rows`]: folds and bagging blocks).

use std::path::Path;

use super::schema::{
    CheckedVariants, ENSEMBLE_SEED_STRIDE, LearnedBasisSpec, MAX_ENSEMBLE_MEMBERS, MAX_VARIANTS,
    VariantKind, VariantsConfig, ensemble_member_seeds,
};
use crate::config::{RunConfig, check_seeds, merge_patch};
use crate::error::{EvaluationError, Result};

/// A check's refusal: the field (e.g. `variants[2] (s).candidates`) and the message.
type Refusal = (String, String);

fn refuse(field: impl Into<String>, message: String) -> Refusal {
    (field.into(), message)
}

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

impl VariantKind {
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
                             (evaluation::MAX_ENSEMBLE_MEMBERS), each a full meta-training"
                        ),
                    })
                }
            }
            Self::Select { .. } | Self::Learn | Self::Average { .. } => Ok(()),
        }
    }
}

impl LearnedBasisSpec {
    /// Checks the fixed library and the regression, as [`crate::LibraryRegression::validate`]
    /// does.
    pub fn validate(&self) -> sindy::Result<()> {
        if let Some(library) = &self.library {
            library.validate().map_err(|e| e.within("library"))?;
        }
        self.regression
            .validate()
            .map_err(|e| e.within("regression"))
    }
}

impl VariantsConfig {
    /// Reads and checks `path` alone (names, candidates, headline), without the run it names.
    pub fn read(path: &Path) -> Result<VariantsConfig> {
        let text = bounded_read::read_json_text(path).map_err(|source| EvaluationError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let raw: VariantsConfig =
            bounded_read::json::from_str(&text).map_err(|e| EvaluationError::json(path, e))?;
        raw.check()
            .map_err(|(field, message)| EvaluationError::Config {
                path: path.to_path_buf(),
                field,
                message,
            })?;
        Ok(raw)
    }

    /// Every check of [`Self::read`], in the order their refusals take precedence.
    fn check(&self) -> std::result::Result<(), Refusal> {
        check_seeds(&self.seeds).map_err(|message| refuse("seeds", message))?;
        if self.variants.len() > MAX_VARIANTS {
            return Err(refuse(
                "variants",
                format!(
                    "{} variants, more than the limit of {MAX_VARIANTS} (evaluation::MAX_VARIANTS)",
                    self.variants.len()
                ),
            ));
        }
        self.check_names()?;
        self.check_variants()?;
        self.check_named_variants()?;
        self.check_ensembles()
    }

    /// Every name non-empty, made of name characters, declared once.
    fn check_names(&self) -> std::result::Result<(), Refusal> {
        let names: Vec<&str> = self.variants.iter().map(|v| v.name.as_str()).collect();
        for (index, name) in names.iter().enumerate() {
            let field = format!("variants[{index}].name");
            if name.trim().is_empty() {
                return Err(refuse(field, format!("variant {} has no name", index + 1)));
            }
            if let Some(bad) = name.chars().find(|&c| !is_name_character(c)) {
                return Err(refuse(
                    field,
                    format!(
                        "{} has the character {bad:?}; a name (a table column and a Markdown \
                         code span) may hold only letters, digits, '-', '_', '.' and '+'",
                        shown(name)
                    ),
                ));
            }
            if names[..index].contains(name) {
                return Err(refuse(field, format!("{} is declared twice", shown(name))));
            }
        }
        Ok(())
    }

    /// Every variant's settings, and the candidates of a `select` and members of an `average`:
    /// at least one, each a variant declared before it and listed once (a candidate must fit a
    /// regression, to have a score to select by).
    fn check_variants(&self) -> std::result::Result<(), Refusal> {
        let names: Vec<&str> = self.variants.iter().map(|v| v.name.as_str()).collect();
        for (own, variant) in self.variants.iter().enumerate() {
            let at = format!("variants[{own}] ({})", variant.name);
            variant.kind.validate().map_err(|e| match e.within("") {
                sindy::SindyError::Field { field, message } => {
                    refuse(format!("{at}.{field}"), message)
                }
                other => refuse(&at, other.to_string()),
            })?;
            let (others, what, list) = match &variant.kind {
                VariantKind::Select { candidates } => (candidates, "candidate", "candidates"),
                VariantKind::Average { members } => (members, "member", "members"),
                _ => continue,
            };
            let field = format!("{at}.{list}");
            if others.is_empty() {
                return Err(refuse(field, format!("name at least one {what}")));
            }
            for (position, other) in others.iter().enumerate() {
                let Some(index) = names[..own].iter().position(|n| n == other) else {
                    return Err(refuse(
                        field,
                        format!(
                            "{what} {} must be a variant declared before it",
                            shown(other)
                        ),
                    ));
                };
                if others[..position].contains(other) {
                    return Err(refuse(
                        field,
                        format!("{what} {} is listed twice", shown(other)),
                    ));
                }
                if what == "candidate" && !self.variants[index].kind.is_regression() {
                    return Err(refuse(
                        field,
                        format!(
                            "candidate {} has no support cross-validation score to select by",
                            shown(other)
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// The headline, figure variant and `reproduce` columns are declared variants (each
    /// `reproduce` column listed once).
    fn check_named_variants(&self) -> std::result::Result<(), Refusal> {
        let named = [
            ("headline", Some(&self.headline)),
            ("figure_variant", self.figure_variant.as_ref()),
        ]
        .into_iter()
        .chain(self.reproduce.iter().map(|n| ("reproduce", Some(n))));
        for (field, name) in named {
            if let Some(name) = name
                && !self.variants.iter().any(|v| &v.name == name)
            {
                return Err(refuse(
                    field,
                    format!("{} is not a declared variant", shown(name)),
                ));
            }
        }
        for (index, name) in self.reproduce.iter().enumerate() {
            if self.reproduce[..index].contains(name) {
                return Err(refuse(
                    "reproduce",
                    format!("{} is listed twice", shown(name)),
                ));
            }
        }
        Ok(())
    }

    /// Every `learn_ensemble`'s member seeds exist for every seed, and no ensemble is among the
    /// `reproduce` columns (or their members).
    fn check_ensembles(&self) -> std::result::Result<(), Refusal> {
        for (index, variant) in self.variants.iter().enumerate() {
            if let VariantKind::LearnEnsemble { members } = variant.kind
                && let Some(seed) = self
                    .seeds
                    .iter()
                    .find(|&&seed| ensemble_member_seeds(seed, members).is_none())
            {
                return Err(refuse(
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
        if let Some(ensemble) = self
            .reproduce_variants()
            .iter()
            .find(|v| matches!(v.kind, VariantKind::LearnEnsemble { .. }))
        {
            return Err(refuse(
                "reproduce",
                format!(
                    "{} (or a member of a listed variant) is a learn_ensemble, which needs more \
                     meta-trained models than the run's one per cell; show it in make ablations",
                    shown(&ensemble.name)
                ),
            ));
        }
        Ok(())
    }

    /// Reads and checks `path` and the run configuration it names; relative paths start at `root`.
    pub fn load(path: &Path, root: &Path) -> Result<CheckedVariants> {
        let raw = Self::read(path)?;
        if raw.run.as_os_str().is_empty() {
            return Err(EvaluationError::Config {
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
                EvaluationError::Config {
                    path: path.to_path_buf(),
                    field: format!("variants[{index}] ({}).{field}", variant.name),
                    message: format!("{message} ({segment})"),
                }
            })?;
        }
        Ok(())
    }
}

/// The run's LeARN configuration with the variants file's `learn_overrides`, checked; errors name
/// the variants file and `learn_overrides`.
pub(super) fn learned_basis_config(config: &CheckedVariants) -> Result<learn::CheckedConfig> {
    let run = &config.run;
    let error = |message: String| EvaluationError::Config {
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
        bounded_read::json::from_value(value).map_err(|e| with_overrides(e.to_string()))?;
    learn_config.check(&config.path).map_err(|e| match e {
        learn::LearnError::Config { field, message, .. } => {
            with_overrides(format!("field '{field}': {message}"))
        }
        other => with_overrides(other.to_string()),
    })
}

#[cfg(test)]
mod tests;
