//! The worked example of LeARN on your own data (`make own-data-example`): a family of forced,
//! damped Duffing oscillators ([`super::simulate_task`]), meta-trained on some parameter draws and
//! evaluated on unseen ones, as a learning curve of the generalisation MSE against the number of
//! support samples, for LeARN (adapted online on the support rows), SINDy fitted on the same
//! rows, a ridge regression on a fixed library fitted on the same rows, and LeARN before
//! adaptation. The configuration (`experiments/own-data/example.json`) declares what is compared
//! and how it is judged; the tasks are written as CSV files and read back through the same code as
//! `learn meta-train --tasks` and `learn evaluate`.

use std::ops::Range;
use std::path::{Path, PathBuf};

use data::TaskTable;
use learn::{Batch, ColumnSpec, MetaTrainedModel, TaskConfig, TaskSet, TaskSource};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use sindy::Derivative;
use sindy::{BlockedFolds, FeatureLibrary, LibrarySpec, OptimizerSpec, Penalty, RegressionSpec};
use statrs::statistics::{Data, Median};

use super::family::{FamilyConfig, SimulatedTask, TaskParameters, simulate_task};
use super::{SindySettings, matrix, mse, sindy_scores};
use crate::error::{EvaluationError, Result};

/// Where the test tasks' indices start in the family's streams (the training tasks use 0, 1, …):
/// no test draw is a training draw.
const TEST_STREAM_OFFSET: u64 = 1 << 32;

/// The SINDy baseline: `learn sindy --library L --threshold T --alpha A`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SindyBaseline {
    pub library: String,
    pub threshold: f64,
    pub alpha: f64,
}

/// The fixed-library ridge baseline: every term of `library` kept, λ chosen from `lambdas` by
/// blocked cross-validation inside the support rows.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RidgeBaseline {
    pub library: String,
    pub lambdas: Vec<f64>,
    /// Contiguous validation blocks of the cross-validation.
    pub folds: usize,
}

/// `experiments/own-data/example.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExampleConfig {
    pub description: String,
    /// What is compared and how it is judged, written before the first run.
    pub declared: String,
    pub family: FamilyConfig,
    pub training_tasks: usize,
    pub test_tasks: usize,
    /// The seed of the family's draws.
    pub data_seed: u64,
    /// LeARN settings over the defaults (`learn meta-train --tasks --config`); none: the defaults.
    pub learn_config: Option<PathBuf>,
    /// The meta-training seed of the curve.
    pub seed: u64,
    /// Further meta-training seeds, for LeARN's seed-to-seed spread alone.
    #[serde(default)]
    pub spread_seeds: Vec<u64>,
    /// Support rows: the first N rows of each test task, for each N.
    pub support_sizes: Vec<usize>,
    /// The query rows of every test task, `[start, end)`, after the largest support.
    pub query_rows: [usize; 2],
    /// The derivative estimator of every method's targets.
    pub derivative: String,
    pub sindy: SindyBaseline,
    pub ridge: RidgeBaseline,
}

impl ExampleConfig {
    /// Reads and checks the configuration; errors name the file and the field.
    pub fn load(path: &Path) -> Result<Self> {
        let text = bounded_read::read_json_text(path).map_err(|source| EvaluationError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let config: Self = bounded_read::json::from_str(&text)
            .map_err(|error| EvaluationError::json(path, error))?;
        config.check(path)?;
        Ok(config)
    }

    fn check(&self, path: &Path) -> Result<()> {
        let bad = |field: &str, message: String| EvaluationError::Config {
            path: path.to_path_buf(),
            field: field.to_string(),
            message,
        };
        let family = &self.family;
        if !(family.sample_interval > 0.0 && family.sample_interval.is_finite()) {
            return Err(bad(
                "family.sample_interval",
                "must be a positive number".into(),
            ));
        }
        if !(1..=100_000).contains(&family.rows) || !(1..=1000).contains(&family.substeps) {
            return Err(bad(
                "family.rows",
                "rows from 1 to 100000, substeps from 1 to 1000".into(),
            ));
        }
        if !(2..=1000).contains(&self.training_tasks) || !(1..=1000).contains(&self.test_tasks) {
            return Err(bad(
                "training_tasks",
                "2 to 1000 training and 1 to 1000 test tasks".into(),
            ));
        }
        let [start, end] = self.query_rows;
        let largest = self.support_sizes.iter().copied().max().unwrap_or(0);
        if self.support_sizes.is_empty() || largest > start || start >= end || end > family.rows {
            return Err(bad(
                "query_rows",
                format!(
                    "[{start}, {end}) must follow the largest support size {largest} and end by family.rows {}",
                    family.rows
                ),
            ));
        }
        Derivative::parse(&self.derivative).map_err(|e| bad("derivative", e.to_string()))?;
        Ok(())
    }

    /// The columns every task is read with: t; states x, v; control u.
    pub fn spec(&self) -> Result<ColumnSpec> {
        Ok(ColumnSpec {
            time: "t".to_string(),
            state: vec!["x".to_string(), "v".to_string()],
            control: vec!["u".to_string()],
            derivative: Derivative::parse(&self.derivative).map_err(sindy::SindyError::from)?,
        })
    }

    /// The training draws (stream 0, 1, …) and the test draws (streams after
    /// `TEST_STREAM_OFFSET`), in parallel.
    pub fn simulate(&self) -> (Vec<SimulatedTask>, Vec<SimulatedTask>) {
        let draw = |offset: u64, count: usize| -> Vec<SimulatedTask> {
            (0..count as u64)
                .into_par_iter()
                .map(|i| simulate_task(&self.family, self.data_seed, offset + i))
                .collect()
        };
        (
            draw(0, self.training_tasks),
            draw(TEST_STREAM_OFFSET, self.test_tasks),
        )
    }
}

/// The methods of the learning curve.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum CurveMethod {
    /// LeARN adapted online on the support rows.
    Learn,
    /// SINDy fitted on the support rows.
    Sindy,
    /// Ridge on a fixed library, fitted on the support rows.
    Ridge,
    /// The meta-trained LeARN model before adaptation (uses no support row).
    LearnUnadapted,
}

impl CurveMethod {
    pub const ALL: [CurveMethod; 4] = [Self::Learn, Self::Sindy, Self::Ridge, Self::LearnUnadapted];

    /// The name in tables and figures.
    pub fn label(self) -> &'static str {
        match self {
            Self::Learn => "LeARN (adapted)",
            Self::Sindy => "SINDy",
            Self::Ridge => "ridge (fixed library)",
            Self::LearnUnadapted => "LeARN (not adapted)",
        }
    }
}

/// One method at one support size over the test tasks.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CurvePoint {
    pub method: CurveMethod,
    pub support: usize,
    /// Generalisation MSE per test task, in task order.
    pub per_task: Vec<f64>,
    pub median: f64,
    pub mean: f64,
    /// Test tasks on which adapted LeARN's generalisation MSE is lower than this method's.
    pub learn_lower_on: usize,
}

/// One test task: its parameters and file.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TestTask {
    pub file: PathBuf,
    pub parameters: TaskParameters,
}

/// What the example measured.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LearningCurve {
    pub config: ExampleConfig,
    /// The LeARN settings used (the defaults with `learn_config` over them, fitted to the tasks).
    pub learn_settings: learn::LearnConfig,
    pub meta_training_seconds: f64,
    pub final_meta_loss: f64,
    pub test_tasks: Vec<TestTask>,
    pub points: Vec<CurvePoint>,
    /// LeARN's medians for `seed` then each of `spread_seeds`.
    pub seed_spread: Vec<SeedCurve>,
}

/// Meta-trains on the training task files matched by `training_pattern`, then measures the
/// learning curve on `test_files` (the tasks written from [`ExampleConfig::simulate`]), and
/// LeARN's alone for each of `spread_seeds`. `iteration_done` is called after each
/// meta-iteration of the first model.
pub fn run_example(
    config: &ExampleConfig,
    training_pattern: &str,
    test: &[(PathBuf, TaskParameters)],
    iteration_done: &dyn Fn(usize),
) -> Result<LearningCurve> {
    let spec = config.spec()?;
    let source = TaskSource::Files {
        pattern: training_pattern.to_string(),
    };
    let tables = super::read_tasks(&source, &spec)?;
    let tasks: Vec<learn::Recording> = tables.iter().map(super::recording).collect();
    let settings = TaskConfig::load(config.learn_config.as_deref())?;
    let meta_train = |seed: u64, observe: &dyn Fn(usize)| {
        let set = TaskSet {
            source: &source,
            spec: &spec,
            tasks: &tasks,
            files: Vec::new(),
        };
        learn::meta_train_tasks(set, &settings.with_seed(seed), observe)
    };
    let started = std::time::Instant::now();
    let model = meta_train(config.seed, iteration_done)?;
    let meta_training_seconds = started.elapsed().as_secs_f64();
    let recordings: Vec<TaskTable> = test
        .iter()
        .map(|(path, _)| super::read_recording(path, &spec))
        .collect::<Result<_>>()?;
    let baselines = Baselines::new(config)?;
    let query = config.query_rows[0]..config.query_rows[1];
    // scores[task][size] = [learn, sindy, ridge, unadapted]
    let scores: Vec<Vec<[f64; 4]>> = recordings
        .par_iter()
        .map(|recording| {
            config
                .support_sizes
                .iter()
                .map(|&n| score_task(&model, recording, 0..n, query.clone(), &baselines))
                .collect::<Result<Vec<_>>>()
        })
        .collect::<Result<_>>()?;
    let mut seed_spread = vec![SeedCurve::of(config.seed, &scores)];
    for &seed in &config.spread_seeds {
        let model = meta_train(seed, &|_| {})?;
        let scores = learn_scores(&model, &recordings, &config.support_sizes, &query)?;
        seed_spread.push(SeedCurve::of(seed, &scores));
    }
    Ok(LearningCurve {
        config: config.clone(),
        learn_settings: model.config.clone(),
        meta_training_seconds,
        final_meta_loss: model.meta_loss_history.last().copied().unwrap_or(f64::NAN),
        test_tasks: test
            .iter()
            .map(|(file, parameters)| TestTask {
                file: file.clone(),
                parameters: *parameters,
            })
            .collect(),
        points: curve_points(&config.support_sizes, &scores),
        seed_spread,
    })
}

/// LeARN's generalisation MSE alone, per task and size: `[adapted, NaN, NaN, unadapted]` (the
/// layout of the full scores, without the baselines).
fn learn_scores(
    model: &MetaTrainedModel,
    recordings: &[TaskTable],
    sizes: &[usize],
    query: &Range<usize>,
) -> Result<Vec<Vec<[f64; 4]>>> {
    recordings
        .par_iter()
        .map(|recording| {
            sizes
                .iter()
                .map(|&n| {
                    let e = super::tasks::evaluate_on(model, recording, 0..n, query.clone())?;
                    Ok([
                        e.generalisation,
                        f64::NAN,
                        f64::NAN,
                        e.unadapted_generalisation,
                    ])
                })
                .collect::<Result<Vec<_>>>()
        })
        .collect()
}

/// LeARN's medians over the test tasks for one meta-training seed.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SeedCurve {
    pub seed: u64,
    /// Adapted, per support size.
    pub learn_median: Vec<f64>,
    /// Before adaptation (the same at every size).
    pub unadapted_median: Vec<f64>,
}

impl SeedCurve {
    fn of(seed: u64, scores: &[Vec<[f64; 4]>]) -> Self {
        let sizes = scores.first().map_or(0, Vec::len);
        let column = |s: usize, m: usize| -> Vec<f64> { scores.iter().map(|t| t[s][m]).collect() };
        Self {
            seed,
            learn_median: (0..sizes)
                .map(|s| Data::new(column(s, 0)).median())
                .collect(),
            unadapted_median: (0..sizes)
                .map(|s| Data::new(column(s, 3)).median())
                .collect(),
        }
    }
}

/// The two baselines' fitted forms.
struct Baselines {
    sindy: SindySettings,
    ridge_library: FeatureLibrary,
    ridge_lambdas: Vec<f64>,
    ridge_folds: usize,
}

impl Baselines {
    fn new(config: &ExampleConfig) -> Result<Self> {
        let library = |text: &str| -> Result<FeatureLibrary> {
            Ok(FeatureLibrary::from_spec(&LibrarySpec::parse(text)?)?)
        };
        Ok(Self {
            sindy: SindySettings {
                library: library(&config.sindy.library)?,
                optimizer: OptimizerSpec::Stlsq {
                    threshold: config.sindy.threshold,
                    alpha: config.sindy.alpha,
                    max_iter: sindy::DEFAULT_MAX_ITER,
                },
            },
            ridge_library: library(&config.ridge.library)?,
            ridge_lambdas: config.ridge.lambdas.clone(),
            ridge_folds: config.ridge.folds,
        })
    }

    /// Ridge fitted on `fit` (λ by blocked cross-validation there), its MSE on `query`.
    fn ridge(&self, fit: &Batch, query: &Batch, dims: (usize, usize)) -> Result<f64> {
        let (inputs, states) = dims;
        let theta = self
            .ridge_library
            .transform(matrix(&fit.inputs, inputs).as_ref());
        let rows = theta.nrows();
        let spec = RegressionSpec {
            penalty: Penalty::Ridge {
                lambdas: self.ridge_lambdas.clone(),
            },
            intercept: true,
            // A gap of 4% of the rows (at most 10) between training and validation blocks.
            folds: BlockedFolds {
                folds: self.ridge_folds,
                gap: (rows / 25).min(10),
            },
            bagging: None,
        };
        let fitted = spec.fit(theta.as_ref(), matrix(&fit.targets, states).as_ref(), 0)?;
        let query_theta = self
            .ridge_library
            .transform(matrix(&query.inputs, inputs).as_ref());
        Ok(mse(&fitted.predict(query_theta.as_ref()), &query.targets))
    }
}

/// The generalisation MSE of every method on one test task with `support` rows.
fn score_task(
    model: &MetaTrainedModel,
    recording: &TaskTable,
    support: Range<usize>,
    query: Range<usize>,
    baselines: &Baselines,
) -> Result<[f64; 4]> {
    let columns = learn::column_training(model, "the example")?;
    let dims = (
        columns.state.len() + columns.control.len(),
        columns.state.len(),
    );
    let rows_text = format!(
        "{}: support rows {}:{}",
        recording.path.display(),
        support.start,
        support.end
    );
    let evaluation = super::tasks::evaluate_on(model, recording, support, query)?;
    let (sindy, _) = sindy_scores(
        &baselines.sindy.params(columns),
        &baselines.sindy.library,
        &evaluation.support,
        &evaluation.query,
        dims,
        &rows_text,
    )?;
    let ridge = baselines.ridge(&evaluation.support, &evaluation.query, dims)?;
    Ok([
        evaluation.generalisation,
        sindy.generalisation,
        ridge,
        evaluation.unadapted_generalisation,
    ])
}

/// Median, mean and LeARN's wins of every method at every size.
fn curve_points(sizes: &[usize], scores: &[Vec<[f64; 4]>]) -> Vec<CurvePoint> {
    let mut points = Vec::new();
    for (m, method) in CurveMethod::ALL.into_iter().enumerate() {
        for (s, &support) in sizes.iter().enumerate() {
            let per_task: Vec<f64> = scores.iter().map(|task| task[s][m]).collect();
            let learn_lower_on = scores.iter().filter(|task| task[s][0] < task[s][m]).count();
            points.push(CurvePoint {
                method,
                support,
                median: Data::new(per_task.clone()).median(),
                mean: per_task.iter().sum::<f64>() / per_task.len().max(1) as f64,
                per_task,
                learn_lower_on,
            });
        }
    }
    points
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_and_wins_per_method_and_size() {
        // statrs' median, as the curve's numbers were made: the mean of the two middle values.
        let median = |values: Vec<f64>| Data::new(values).median();
        assert_eq!(median(vec![3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(vec![4.0, 1.0, 2.0, 3.0]), 2.5);
        assert!(median(Vec::new()).is_nan());
        let scores = vec![
            vec![[1.0, 2.0, 0.5, 3.0]],
            vec![[1.0, 0.5, 2.0, 3.0]],
            vec![[1.0, 4.0, 4.0, 0.1]],
        ];
        let points = curve_points(&[20], &scores);
        let sindy = points
            .iter()
            .find(|p| p.method == CurveMethod::Sindy)
            .unwrap();
        assert_eq!((sindy.median, sindy.learn_lower_on), (2.0, 2));
        let ridge = points
            .iter()
            .find(|p| p.method == CurveMethod::Ridge)
            .unwrap();
        assert_eq!(ridge.learn_lower_on, 2);
        assert_eq!(ridge.mean, 6.5 / 3.0);
    }
}
