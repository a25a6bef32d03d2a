//! Regularised linear regression of targets on any feature matrix Θ, with the regularisation chosen
//! by blocked cross-validation inside the rows it is given ([`selection`]), and bagged
//! ensembles that give a spread.
//!
//! Columns of Θ are standardised with the training rows' statistics (centred when there is an
//! intercept, divided by their root mean square), so one penalty grid suits every library. Each
//! target column is fitted, and its penalty chosen, on its own:
//! - ridge: `min ‖y − ȳ − Zb‖²/n + λ‖b‖²` (λ per sample, scale-free);
//! - LASSO: `min ‖y − ȳ − Zb‖²/(2n) + λ‖b‖₁` (scikit-learn's `alpha` = λ; solved by the clarabel
//!   [`Lasso`] with `λ·n`), candidates given as fractions of λ_max = max|Zᵀ(y − ȳ)|/n, the smallest
//!   λ that keeps every coefficient at zero;
//! - STLSQ ([`Stlsq`], PySINDy's semantics) on Z, the threshold given as a fraction of the target's
//!   standard deviation.
//!
//! Bagging ([`Bagging`]): every member refits the chosen penalties on a moving-block bootstrap of
//! the rows (blocks of contiguous samples, drawn with replacement from a ChaCha8 stream seeded by
//! the recorded seed, the workspace's one generator); the prediction is the members' mean. The predictive band is
//! mean ± 2·√(s² + σ²): s² the members' variance at that sample (the model's uncertainty) and σ²
//! the output's cross-validation MSE on the support segment (what the model leaves unexplained,
//! noise included), so about 95 % of the targets should fall inside it if the errors are Gaussian.

use faer::{Mat, MatRef};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

mod selection;

use crate::error::{Result, field, shape};
use crate::linalg::product;
use crate::optimizers::{DEFAULT_MAX_ITER, Lasso, Optimizer, Problem, Ridge, Stlsq};
use selection::{Fold, cross_validate};

pub use selection::{BlockedFolds, MAX_FOLDS, Selection};

/// The most candidate values of a penalty (each is cross-validated on every fold; the committed
/// variants use up to 8).
pub const MAX_PENALTY_CANDIDATES: usize = 100;
/// The largest ridge λ and STLSQ α (both per sample, on standardised columns: 1 already shrinks
/// every coefficient hard; the committed variants use up to 1). Larger values overflow the
/// solvers' arithmetic instead of meaning anything.
pub const MAX_PENALTY: f64 = 1e6;
/// The most members of a bagged ensemble (the committed variants use 20).
pub const MAX_BAGGING_MEMBERS: usize = 1_000;
/// The longest bootstrap block, samples (the committed variants use 125; a block is also at most
/// the segment's length, checked when fitting).
pub const MAX_BAGGING_BLOCK: usize = 1_000_000;

fn default_true() -> bool {
    true
}

/// The penalty and its candidate values (unchecked; checked by [`RegressionSpec::fit`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Penalty {
    /// Ridge, candidates λ ≥ 0 (per sample, on standardised columns).
    Ridge { lambdas: Vec<f64> },
    /// LASSO, candidates as fractions of λ_max (in (0, 1]).
    Lasso { fractions: Vec<f64> },
    /// STLSQ with ridge strength `alpha`, thresholds as fractions of the target's standard deviation.
    Stlsq { thresholds: Vec<f64>, alpha: f64 },
}

impl Penalty {
    /// Errors name the field inside a [`RegressionSpec`]: `penalty.lambdas`, `penalty.fractions`,
    /// `penalty.thresholds` or `penalty.alpha`.
    fn check(&self) -> Result<()> {
        let (name, values, fraction) = match self {
            Self::Ridge { lambdas } => ("penalty.lambdas", lambdas, false),
            Self::Lasso { fractions } => ("penalty.fractions", fractions, true),
            Self::Stlsq { thresholds, alpha } => {
                if !(0.0..=MAX_PENALTY).contains(alpha) {
                    return Err(field(
                        "penalty.alpha",
                        format!("{alpha} must be from 0 to {MAX_PENALTY:e} (sindy::MAX_PENALTY)"),
                    ));
                }
                ("penalty.thresholds", thresholds, false)
            }
        };
        if values.is_empty() {
            return Err(field(name, "name at least one candidate"));
        }
        if values.len() > MAX_PENALTY_CANDIDATES {
            return Err(field(
                name,
                format!(
                    "{} candidates, more than the limit of {MAX_PENALTY_CANDIDATES} \
                     (sindy::MAX_PENALTY_CANDIDATES)",
                    values.len()
                ),
            ));
        }
        if let Some(bad) = values
            .iter()
            .find(|v| !(v.is_finite() && **v >= 0.0 && (!fraction || (**v > 0.0 && **v <= 1.0))))
        {
            let range = if fraction { "in (0, 1]" } else { "≥ 0" };
            return Err(field(name, format!("{bad} must be {range}")));
        }
        if let Self::Ridge { lambdas } = self
            && let Some(bad) = lambdas.iter().find(|v| **v > MAX_PENALTY)
        {
            return Err(field(
                name,
                format!("{bad:e} must be at most {MAX_PENALTY:e} (sindy::MAX_PENALTY)"),
            ));
        }
        Ok(())
    }

    fn candidates(&self) -> &[f64] {
        match self {
            Self::Ridge { lambdas } => lambdas,
            Self::Lasso { fractions } => fractions,
            Self::Stlsq { thresholds, .. } => thresholds,
        }
    }
}

/// Bootstrap ensemble settings.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Bagging {
    /// Number of members (at least 2).
    pub members: usize,
    /// Length of the resampled blocks, samples.
    pub block: usize,
}

/// A regression: penalty, intercept, cross-validation and optional bagging.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RegressionSpec {
    pub penalty: Penalty,
    /// Fit an unpenalised constant per target.
    #[serde(default = "default_true")]
    pub intercept: bool,
    #[serde(default)]
    pub folds: BlockedFolds,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bagging: Option<Bagging>,
}

/// One fitted linear map from features to targets.
#[derive(Clone, Debug, PartialEq)]
pub struct LinearFit {
    /// Per feature: subtracted centre and divisor.
    pub feature_centre: Vec<f64>,
    pub feature_scale: Vec<f64>,
    /// Per target: the intercept on standardised features.
    pub target_centre: Vec<f64>,
    /// features × targets, on standardised features.
    pub coefficients: Mat<f64>,
}

impl LinearFit {
    /// Predictions, one row per row of `theta`, one column per target.
    pub fn predict(&self, theta: MatRef<'_, f64>) -> Mat<f64> {
        let z = standardised(theta, &self.feature_centre, &self.feature_scale);
        let mut prediction = product(z.as_ref(), self.coefficients.as_ref());
        for j in 0..prediction.ncols() {
            for i in 0..prediction.nrows() {
                prediction[(i, j)] += self.target_centre[j];
            }
        }
        prediction
    }

    /// Coefficients in the units of the raw features (features × targets) and the intercepts.
    pub fn raw_coefficients(&self) -> (Mat<f64>, Vec<f64>) {
        let raw = Mat::from_fn(
            self.coefficients.nrows(),
            self.coefficients.ncols(),
            |i, j| self.coefficients[(i, j)] / self.feature_scale[i],
        );
        let intercepts = (0..raw.ncols())
            .map(|j| {
                self.target_centre[j]
                    - (0..raw.nrows())
                        .map(|i| raw[(i, j)] * self.feature_centre[i])
                        .sum::<f64>()
            })
            .collect();
        (raw, intercepts)
    }
}

/// A fitted regression: the chosen penalties and one or more members.
#[derive(Clone, Debug, PartialEq)]
pub struct RegressionFit {
    /// One cross-validation curve per target column.
    pub selections: Vec<Selection>,
    /// The fit on all rows with the chosen penalties, then the bagged members (if any).
    pub full: LinearFit,
    pub members: Vec<LinearFit>,
    /// The seed of the bootstrap.
    pub seed: u64,
}

/// An ensemble's mean prediction and its predictive band (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct EnsemblePrediction {
    pub mean: Mat<f64>,
    pub lower: Mat<f64>,
    pub upper: Mat<f64>,
}

impl RegressionFit {
    /// The prediction: the bagged members' mean, or the single fit without bagging.
    pub fn predict(&self, theta: MatRef<'_, f64>) -> Mat<f64> {
        match self.ensemble(theta) {
            Some(ensemble) => ensemble.mean,
            None => self.full.predict(theta),
        }
    }

    /// The members' mean and predictive band, when bagged.
    pub fn ensemble(&self, theta: MatRef<'_, f64>) -> Option<EnsemblePrediction> {
        if self.members.len() < 2 {
            return None;
        }
        let predictions: Vec<Mat<f64>> = self.members.iter().map(|m| m.predict(theta)).collect();
        let (n, m) = predictions[0].shape();
        let count = predictions.len() as f64;
        let mean = Mat::from_fn(n, m, |i, j| {
            predictions.iter().map(|p| p[(i, j)]).sum::<f64>() / count
        });
        let residual: Vec<f64> = self
            .selections
            .iter()
            .map(|s| s.scores.iter().copied().fold(f64::INFINITY, f64::min))
            .collect();
        let deviation = Mat::from_fn(n, m, |i, j| {
            let variance = predictions
                .iter()
                .map(|p| (p[(i, j)] - mean[(i, j)]).powi(2))
                .sum::<f64>()
                / (count - 1.0);
            2.0 * (variance + residual[j]).sqrt()
        });
        Some(EnsemblePrediction {
            lower: Mat::from_fn(n, m, |i, j| mean[(i, j)] - deviation[(i, j)]),
            upper: Mat::from_fn(n, m, |i, j| mean[(i, j)] + deviation[(i, j)]),
            mean,
        })
    }
}

impl RegressionSpec {
    /// Checks the settings that do not depend on the data: the penalty's candidates (at most
    /// [`MAX_PENALTY_CANDIDATES`], each in range), the folds (see [`BlockedFolds::validate`]) and
    /// the bagging (2 to [`MAX_BAGGING_MEMBERS`] members, blocks of 1 to [`MAX_BAGGING_BLOCK`]
    /// samples). Errors are [`crate::SindyError::Field`] naming the field, e.g.
    /// `penalty.lambdas` or `bagging.block`.
    pub fn validate(&self) -> Result<()> {
        self.penalty.check()?;
        self.folds.validate()?;
        if let Some(bagging) = self.bagging {
            if !(2..=MAX_BAGGING_MEMBERS).contains(&bagging.members) {
                return Err(field(
                    "bagging.members",
                    format!(
                        "{} must be from 2 to {MAX_BAGGING_MEMBERS} (sindy::MAX_BAGGING_MEMBERS)",
                        bagging.members
                    ),
                ));
            }
            if !(1..=MAX_BAGGING_BLOCK).contains(&bagging.block) {
                return Err(field(
                    "bagging.block",
                    format!(
                        "{} must be from 1 to {MAX_BAGGING_BLOCK} samples (sindy::MAX_BAGGING_BLOCK)",
                        bagging.block
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Checks the settings against a segment of `n` samples: the folds fit in it
    /// (at least two samples per fold besides the gaps) and a bagging block is at most `n`
    /// samples long.
    pub fn check_rows(&self, n: usize) -> Result<()> {
        self.folds.checked(n)?;
        if let Some(bagging) = self.bagging
            && bagging.block > n
        {
            return Err(field(
                "bagging.block",
                format!(
                    "blocks of {} samples are longer than the segment's {n} samples",
                    bagging.block
                ),
            ));
        }
        Ok(())
    }

    /// Chooses each target's penalty by blocked cross-validation on the rows of `theta` and
    /// `targets` (and nothing else), refits on all of them, then fits the bagged members.
    ///
    /// ```
    /// use sindy::{Mat, RegressionSpec};
    /// // y = 2 + 3·θ₀ (θ₁ irrelevant), ridge penalty chosen among three
    /// let theta = Mat::from_fn(200, 2, |i, j| ((i * (j + 2)) as f64 * 0.37).sin());
    /// let y = Mat::from_fn(200, 1, |i, _| 2.0 + 3.0 * theta[(i, 0)]);
    /// let spec: RegressionSpec = serde_json::from_str(
    ///     r#"{"penalty": {"kind": "ridge", "lambdas": [0, 0.01, 1]}}"#,
    /// ).unwrap();
    /// let fit = spec.fit(theta.as_ref(), y.as_ref(), 1)?;
    /// let (raw, intercepts) = fit.full.raw_coefficients();
    /// assert!((raw[(0, 0)] - 3.0).abs() < 1e-6 && (intercepts[0] - 2.0).abs() < 1e-6);
    /// # Ok::<(), sindy::SindyError>(())
    /// ```
    pub fn fit(
        &self,
        theta: MatRef<'_, f64>,
        targets: MatRef<'_, f64>,
        seed: u64,
    ) -> Result<RegressionFit> {
        self.validate()?;
        let n = theta.nrows();
        if targets.nrows() != n {
            return Err(shape(
                "regression",
                format!("{n} feature rows but {} target rows", targets.nrows()),
            ));
        }
        check_finite(theta, "features")?;
        check_finite(targets, "targets")?;
        self.check_rows(n)?;
        let folds = self.folds.checked(n)?;
        let all_rows: Vec<usize> = (0..n).collect();
        let selections = (0..targets.ncols())
            .map(|j| {
                let column = targets.col(j).as_mat();
                cross_validate(&folds, self.penalty.candidates(), |value, fold: &Fold| {
                    let fit = self.fit_rows(theta, column, &fold.training, &[value])?;
                    let rows: Vec<usize> = fold.validation.clone().collect();
                    let prediction = fit.predict(select_rows(theta, &rows).as_ref());
                    Ok(rows
                        .iter()
                        .enumerate()
                        .map(|(k, &i)| (prediction[(k, 0)] - column[(i, 0)]).powi(2))
                        .sum::<f64>()
                        / rows.len() as f64)
                })
            })
            .collect::<Result<Vec<_>>>()?;
        let chosen: Vec<f64> = selections.iter().map(|s| s.chosen).collect();
        let full = self.fit_rows(theta, targets, &all_rows, &chosen)?;
        let members = match self.bagging {
            None => Vec::new(),
            Some(bagging) => {
                let mut stream = ChaCha8Rng::seed_from_u64(seed);
                (0..bagging.members)
                    .map(|_| {
                        let rows = block_bootstrap(n, bagging.block, &mut stream);
                        self.fit_rows(theta, targets, &rows, &chosen)
                    })
                    .collect::<Result<Vec<_>>>()?
            }
        };
        Ok(RegressionFit {
            selections,
            full,
            members,
            seed,
        })
    }

    /// Fits every target column on `rows` with its own penalty value (`values[j]`).
    fn fit_rows(
        &self,
        theta: MatRef<'_, f64>,
        targets: MatRef<'_, f64>,
        rows: &[usize],
        values: &[f64],
    ) -> Result<LinearFit> {
        let x = select_rows(theta, rows);
        let y = select_rows(targets, rows);
        let (n, p) = x.shape();
        let (feature_centre, feature_scale) = column_statistics(x.as_ref(), self.intercept);
        let z = standardised(x.as_ref(), &feature_centre, &feature_scale);
        let target_centre: Vec<f64> = (0..y.ncols())
            .map(|j| {
                if self.intercept {
                    y.col(j).iter().sum::<f64>() / n as f64
                } else {
                    0.0
                }
            })
            .collect();
        // One Gram matrix for every target's problem.
        let gram = product(z.transpose(), z.as_ref());
        let mut coefficients = Mat::<f64>::zeros(p, y.ncols());
        for j in 0..y.ncols() {
            let centred = Mat::from_fn(n, 1, |i, _| y[(i, j)] - target_centre[j]);
            let value = values[j.min(values.len() - 1)];
            let problem = Problem::with_gram(z.as_ref(), centred.as_ref(), gram.clone())
                .with_target_names(&[format!("column {j}")]);
            let optimizer: Box<dyn Optimizer> = match &self.penalty {
                Penalty::Ridge { .. } => Box::new(Ridge::new(value * n as f64)?),
                Penalty::Lasso { .. } => {
                    let moments = problem.moments();
                    let largest = (0..p).map(|i| moments[(i, 0)].abs()).fold(0.0, f64::max);
                    Box::new(Lasso::new(value * largest)?)
                }
                Penalty::Stlsq { alpha, .. } => {
                    let deviation =
                        (centred.col(0).iter().map(|v| v * v).sum::<f64>() / n as f64).sqrt();
                    Box::new(Stlsq::new(value * deviation, *alpha, DEFAULT_MAX_ITER)?)
                }
            };
            let b = optimizer.solve(&problem)?;
            for i in 0..p {
                coefficients[(i, j)] = b[(0, i)];
            }
        }
        Ok(LinearFit {
            feature_centre,
            feature_scale,
            target_centre,
            coefficients,
        })
    }
}

fn check_finite(matrix: MatRef<'_, f64>, what: &str) -> Result<()> {
    for j in 0..matrix.ncols() {
        for i in 0..matrix.nrows() {
            if !matrix[(i, j)].is_finite() {
                return Err(crate::error::SindyError::NonFinite {
                    what: format!("regression {what}"),
                    row: i,
                    column: format!("column {j}"),
                    value: matrix[(i, j)],
                });
            }
        }
    }
    Ok(())
}

/// The rows `rows` of `matrix`, in that order.
fn select_rows(matrix: MatRef<'_, f64>, rows: &[usize]) -> Mat<f64> {
    Mat::from_fn(rows.len(), matrix.ncols(), |i, j| matrix[(rows[i], j)])
}

/// Per column: centre (the mean, or 0 without intercept) and the root mean square about it
/// (1 for a constant column).
fn column_statistics(x: MatRef<'_, f64>, centre: bool) -> (Vec<f64>, Vec<f64>) {
    let n = x.nrows() as f64;
    (0..x.ncols())
        .map(|j| {
            let mean = if centre {
                x.col(j).iter().sum::<f64>() / n
            } else {
                0.0
            };
            let rms = (x.col(j).iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
            (mean, if rms > 1e-12 { rms } else { 1.0 })
        })
        .unzip()
}

fn standardised(x: MatRef<'_, f64>, centre: &[f64], scale: &[f64]) -> Mat<f64> {
    Mat::from_fn(x.nrows(), x.ncols(), |i, j| {
        (x[(i, j)] - centre[j]) / scale[j]
    })
}

/// n row indices: blocks of `block` contiguous rows starting at uniform positions, concatenated
/// and cut to n.
fn block_bootstrap(n: usize, block: usize, stream: &mut ChaCha8Rng) -> Vec<usize> {
    let mut rows = Vec::with_capacity(n + block);
    while rows.len() < n {
        let start = stream.random_range(0..n - block + 1);
        rows.extend(start..start + block);
    }
    rows.truncate(n);
    rows
}

#[cfg(test)]
mod tests {
    use super::*;

    fn problem() -> (Mat<f64>, Mat<f64>) {
        // y = 2 + 3 x0 − x1 (+ a small deterministic wiggle); x2 is irrelevant.
        let theta = Mat::from_fn(300, 3, |i, j| {
            ((i * (j + 2)) as f64 * 0.37).sin() * (j + 1) as f64
        });
        let targets = Mat::from_fn(300, 1, |i, _| {
            2.0 + 3.0 * theta[(i, 0)] - theta[(i, 1)] + 0.01 * ((i * 7) as f64).cos()
        });
        (theta, targets)
    }

    #[test]
    fn every_penalty_recovers_a_linear_law() {
        let (theta, targets) = problem();
        let penalties = [
            Penalty::Ridge {
                lambdas: vec![0.0, 1e-4, 1.0],
            },
            Penalty::Lasso {
                fractions: vec![1e-4, 1e-2, 0.5],
            },
            Penalty::Stlsq {
                thresholds: vec![0.01, 0.1],
                alpha: 1e-6,
            },
        ];
        for penalty in penalties {
            let spec = RegressionSpec {
                penalty: penalty.clone(),
                intercept: true,
                folds: BlockedFolds::default(),
                bagging: None,
            };
            let fit = spec.fit(theta.as_ref(), targets.as_ref(), 1).unwrap();
            let (raw, intercepts) = fit.full.raw_coefficients();
            assert!((raw[(0, 0)] - 3.0).abs() < 0.02, "{penalty:?}: {raw:?}");
            assert!((raw[(1, 0)] + 1.0).abs() < 0.02, "{penalty:?}: {raw:?}");
            assert!(raw[(2, 0)].abs() < 0.02, "{penalty:?}: {raw:?}");
            assert!(
                (intercepts[0] - 2.0).abs() < 0.02,
                "{penalty:?}: {intercepts:?}"
            );
            // A heavy ridge penalty loses against the light ones in cross-validation.
            assert_ne!(fit.selections[0].chosen, 1.0);
        }
    }

    #[test]
    fn bagging_is_seeded_and_brackets_its_mean() {
        let (theta, targets) = problem();
        let spec = RegressionSpec {
            penalty: Penalty::Ridge {
                lambdas: vec![1e-3],
            },
            intercept: true,
            folds: BlockedFolds::default(),
            bagging: Some(Bagging {
                members: 8,
                block: 30,
            }),
        };
        let a = spec.fit(theta.as_ref(), targets.as_ref(), 7).unwrap();
        let b = spec.fit(theta.as_ref(), targets.as_ref(), 7).unwrap();
        let c = spec.fit(theta.as_ref(), targets.as_ref(), 8).unwrap();
        assert_eq!(a, b);
        assert_ne!(a.members, c.members);
        let ensemble = a.ensemble(theta.as_ref()).unwrap();
        for i in 0..theta.nrows() {
            assert!(ensemble.lower[(i, 0)] <= ensemble.mean[(i, 0)]);
            assert!(ensemble.mean[(i, 0)] <= ensemble.upper[(i, 0)]);
        }
        let bad = RegressionSpec {
            bagging: Some(Bagging {
                members: 1,
                block: 30,
            }),
            ..spec
        };
        assert!(bad.fit(theta.as_ref(), targets.as_ref(), 7).is_err());
    }

    /// The field named by a spec's error, and its message.
    fn field_error(spec: &RegressionSpec) -> (String, String) {
        match spec.validate().unwrap_err() {
            crate::SindyError::Field { field, message } => (field, message),
            other => panic!("{other}"),
        }
    }

    #[test]
    fn settings_are_checked_before_any_data_with_the_field_they_are_in() {
        let ridge = |lambdas: Vec<f64>| RegressionSpec {
            penalty: Penalty::Ridge { lambdas },
            intercept: true,
            folds: BlockedFolds::default(),
            bagging: None,
        };
        let bagged = |members, block| RegressionSpec {
            bagging: Some(Bagging { members, block }),
            ..ridge(vec![0.0])
        };
        let cases = [
            (ridge(vec![-1.0]), "penalty.lambdas", "-1 must be ≥ 0"),
            (ridge(Vec::new()), "penalty.lambdas", "at least one"),
            (
                ridge(vec![0.1; 1_000_000]),
                "penalty.lambdas",
                "1000000 candidates, more than the limit of 100",
            ),
            (
                RegressionSpec {
                    penalty: Penalty::Lasso {
                        fractions: vec![0.1, 2.0],
                    },
                    ..ridge(vec![0.0])
                },
                "penalty.fractions",
                "2 must be in (0, 1]",
            ),
            (
                RegressionSpec {
                    penalty: Penalty::Stlsq {
                        thresholds: vec![-0.1],
                        alpha: 0.05,
                    },
                    ..ridge(vec![0.0])
                },
                "penalty.thresholds",
                "-0.1 must be ≥ 0",
            ),
            (
                RegressionSpec {
                    penalty: Penalty::Stlsq {
                        thresholds: vec![0.1],
                        alpha: f64::NAN,
                    },
                    ..ridge(vec![0.0])
                },
                "penalty.alpha",
                "NaN must be from 0 to 1e6",
            ),
            (
                ridge(vec![0.0, 1e308]),
                "penalty.lambdas",
                "1e308 must be at most 1e6",
            ),
            (bagged(3, 0), "bagging.block", "0 must be from 1"),
            (
                bagged(1_000_000_000, 125),
                "bagging.members",
                "from 2 to 1000",
            ),
            (bagged(1, 125), "bagging.members", "from 2"),
            (bagged(3, usize::MAX), "bagging.block", "1000000"),
            (
                RegressionSpec {
                    folds: BlockedFolds {
                        folds: usize::MAX,
                        gap: 10,
                    },
                    ..ridge(vec![0.0])
                },
                "folds.folds",
                "from 2 to 100",
            ),
        ];
        for (spec, expected_field, expected) in cases {
            let (field, message) = field_error(&spec);
            assert_eq!(field, expected_field, "{message}");
            assert!(message.contains(expected), "{field}: {message}");
        }
        // Against the rows: a block longer than the segment, and a gap that overflowed before.
        bagged(20, 125).validate().unwrap();
        bagged(20, 125).check_rows(1255).unwrap();
        let message = bagged(20, 125).check_rows(100).unwrap_err().to_string();
        assert!(message.contains("bagging.block"), "{message}");
        let wide_gap = RegressionSpec {
            folds: BlockedFolds {
                folds: 5,
                gap: usize::MAX,
            },
            ..ridge(vec![0.0])
        };
        wide_gap.validate().unwrap();
        let message = wide_gap.check_rows(1255).unwrap_err().to_string();
        assert!(message.contains("too few"), "{message}");
    }
}
