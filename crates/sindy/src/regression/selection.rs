//! Model selection inside one segment: blocked time-series cross-validation.
//!
//! The support segment (n samples, in time order) is cut into `folds` contiguous blocks. Each block
//! in turn is the validation set; the training set is every other sample except `gap` samples on
//! each side of the block (neighbouring samples of a smooth flight are nearly copies of each other,
//! and forward-difference targets share a sample with their neighbour). The score of a candidate is
//! the mean squared error over all validation blocks. Only the rows handed in are ever used: the
//! caller passes the support segment alone, so the query segment cannot influence any choice.

use std::ops::Range;

use serde::{Deserialize, Serialize};

use crate::error::{Result, field, invalid};

/// The most cross-validation folds (every candidate is fitted once per fold; the committed
/// variants use the default, 5).
pub const MAX_FOLDS: usize = 100;

fn default_folds() -> usize {
    5
}

fn default_gap() -> usize {
    10
}

/// How a segment is cut for blocked cross-validation (unchecked; see [`BlockedFolds::validate`]
/// and [`crate::RegressionSpec::check_rows`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BlockedFolds {
    /// Number of contiguous validation blocks (at least 2).
    #[serde(default = "default_folds")]
    pub folds: usize,
    /// Samples dropped from the training set on each side of the validation block.
    #[serde(default = "default_gap")]
    pub gap: usize,
}

impl Default for BlockedFolds {
    fn default() -> Self {
        Self {
            folds: default_folds(),
            gap: default_gap(),
        }
    }
}

/// One fold: the training rows and the contiguous validation block.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Fold {
    pub training: Vec<usize>,
    pub validation: Range<usize>,
}

impl BlockedFolds {
    /// Checks the settings that do not depend on the segment: 2 to [`MAX_FOLDS`] folds. Errors
    /// are [`crate::SindyError::Field`] naming `folds.folds` (the field inside a
    /// [`crate::RegressionSpec`]).
    pub fn validate(&self) -> Result<()> {
        if !(2..=MAX_FOLDS).contains(&self.folds) {
            return Err(field(
                "folds.folds",
                format!(
                    "{} must be from 2 to {MAX_FOLDS} (sindy::MAX_FOLDS)",
                    self.folds
                ),
            ));
        }
        Ok(())
    }

    /// Checks the settings against a segment of `n` samples and returns its folds.
    pub(crate) fn checked(&self, n: usize) -> Result<Vec<Fold>> {
        self.validate()?;
        let block = n / self.folds;
        let needed = self
            .folds
            .saturating_mul(2)
            .saturating_add(self.gap.saturating_mul(2));
        if block < 2 || n < needed {
            return Err(field(
                "folds",
                format!(
                    "{n} samples are too few for {} folds with a gap of {}",
                    self.folds, self.gap
                ),
            ));
        }
        Ok((0..self.folds)
            .map(|k| {
                let start = k * n / self.folds;
                let end = (k + 1) * n / self.folds;
                let training = (0..start.saturating_sub(self.gap))
                    .chain(end.saturating_add(self.gap).min(n)..n)
                    .collect();
                Fold {
                    training,
                    validation: start..end,
                }
            })
            .collect())
    }
}

/// The cross-validation curve of one choice and the value it chose.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Selection {
    /// The candidate values, in the order tried.
    pub candidates: Vec<f64>,
    /// Mean validation MSE of each candidate.
    pub scores: Vec<f64>,
    /// The candidate with the lowest score (the first one on ties).
    pub chosen: f64,
}

/// Scores every candidate by blocked cross-validation and picks the lowest mean validation MSE.
/// `validation_mse(candidate, fold)` fits on `fold.training` and returns the MSE on
/// `fold.validation`; non-finite scores never win.
pub(crate) fn cross_validate(
    folds: &[Fold],
    candidates: &[f64],
    mut validation_mse: impl FnMut(f64, &Fold) -> Result<f64>,
) -> Result<Selection> {
    if candidates.is_empty() {
        return Err(invalid(
            "cross-validation",
            "no candidate value to choose from",
        ));
    }
    let mut scores = Vec::with_capacity(candidates.len());
    for &candidate in candidates {
        let mut total = 0.0;
        for fold in folds {
            total += validation_mse(candidate, fold)?;
        }
        scores.push(total / folds.len() as f64);
    }
    let best = (0..scores.len())
        .filter(|&i| scores[i].is_finite())
        .min_by(|&a, &b| scores[a].total_cmp(&scores[b]).then(a.cmp(&b)))
        .ok_or_else(|| invalid("cross-validation", "every candidate scored non-finite"))?;
    Ok(Selection {
        candidates: candidates.to_vec(),
        chosen: candidates[best],
        scores,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn folds_are_contiguous_disjoint_and_gapped() {
        let folds = BlockedFolds { folds: 4, gap: 3 }.checked(40).unwrap();
        assert_eq!(folds.len(), 4);
        let mut covered = Vec::new();
        for fold in &folds {
            covered.extend(fold.validation.clone());
            for &row in &fold.training {
                let distance = if row < fold.validation.start {
                    fold.validation.start - row
                } else {
                    row + 1 - fold.validation.end
                };
                assert!(distance > 3, "row {row} too close to {:?}", fold.validation);
            }
        }
        assert_eq!(covered, (0..40).collect::<Vec<_>>());
        assert!(BlockedFolds { folds: 1, gap: 0 }.checked(40).is_err());
        assert!(BlockedFolds { folds: 5, gap: 20 }.checked(40).is_err());
    }

    #[test]
    fn the_lowest_score_wins() {
        let folds = BlockedFolds { folds: 2, gap: 0 }.checked(10).unwrap();
        let selection = cross_validate(&folds, &[3.0, 1.0, 2.0, f64::NAN], |c, _| {
            Ok((c - 1.2).abs())
        })
        .unwrap();
        assert_eq!(selection.chosen, 1.0);
        assert_eq!(selection.scores.len(), 4);
    }
}
