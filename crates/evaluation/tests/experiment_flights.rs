//! The formulations' segments and the LeARN experiment on the real flights, with a tiny budget
//! (skipped without data, fails under CI).

use std::path::{Path, PathBuf};

use data::ExperimentConditions;
use evaluation::{EvaluationError, Experiment, Protocol, Segment, Segmentation, explain_flight};
use learn::{EquationRule, Formulation, LearnConfig, MetaTrainedModel, TaskGrouping};
use sindy::Derivative;

mod common {
    use super::*;

    /// The real data directory (see `data::real_data_dir_for_tests`: skips locally, fails under
    /// CI).
    pub fn real_data_dir() -> Option<PathBuf> {
        data::real_data_dir_for_tests(&workspace())
    }

    /// The workspace root.
    pub fn workspace() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
    }

    /// A fresh temporary directory for one test, removed with everything in it when dropped.
    pub fn temp_dir(name: &str) -> tempfile::TempDir {
        tempfile::Builder::new()
            .prefix(&format!("{name}-"))
            .tempdir()
            .unwrap()
    }
}

fn log_rows(data_dir: &std::path::Path) -> usize {
    data::FlightLog::read(&data_dir.join("experiment/custom_figure8_baseline_70p20sint.csv"))
        .unwrap()
        .len()
}

#[test]
fn leave_condition_out_cell_runs_end_to_end() {
    let Some(data_dir) = common::real_data_dir() else {
        return;
    };
    let root = common::workspace();
    let config = LearnConfig::load(&root.join("experiments/learn.json")).unwrap();
    let mut small = config.get().clone();
    small.meta_training.iterations = 3;
    small.meta_training.support_batch = 16;
    small.meta_training.query_batch = 16;
    small.adaptation.passes = 1;
    let small = small.check(&root.join("experiments/learn.json")).unwrap();
    let conditions = ExperimentConditions::load(&root.join("experiments/conditions.json")).unwrap();
    let experiment = Experiment::load(
        small,
        conditions,
        &data_dir,
        Some(Protocol::LeaveConditionOut),
        Segmentation::PAPER,
    )
    .unwrap();
    assert_eq!(
        experiment.evaluation_conditions(),
        vec!["35wind", "70p20sint", "70wind", "100wind"]
    );
    let cell = experiment
        .run_cell(Formulation::Translational, "70psin20", 5)
        .unwrap();
    let model = &cell.model;
    let flights = model.flights().expect("a flight model");
    assert_eq!(flights.protocol, Protocol::LeaveConditionOut.name());
    assert_eq!(flights.held_out_condition.as_deref(), Some("70p20sint"));
    // 4 other conditions × 6 controllers; none of them the held-out condition.
    assert_eq!(model.data_files.len(), 24);
    assert!(
        model
            .data_files
            .iter()
            .all(|f| { !f.path.to_string_lossy().contains("70p20sint") && f.sha256.len() == 64 })
    );
    let summary = &cell.summary;
    assert!(summary.adaptation.is_finite() && summary.generalisation.is_finite());
    assert_eq!(summary.label, "70psin20");
    assert_eq!(
        cell.support.predictions.nrows() + cell.query.predictions.nrows(),
        log_rows(&data_dir)
    );
    assert_eq!(cell.support.time.len(), log_rows(&data_dir) / 2);
    assert_eq!(cell.query.predictions.ncols(), 3);
    // The MSE is the mean over samples and outputs of the returned predictions.
    let (p, t) = (&cell.query.predictions, &cell.query.targets);
    let mut sum = 0.0;
    for i in 0..p.nrows() {
        for j in 0..p.ncols() {
            sum += (p[(i, j)] - t[(i, j)]).powi(2);
        }
    }
    let mse = sum / (p.nrows() * p.ncols()) as f64;
    assert!((mse - summary.generalisation).abs() < 1e-12 * mse);
    // LeARN is scored against the experiment's cell, whose segments the run fits SINDy on: the
    // targets of the experiment's segmentation.
    let evaluation = experiment
        .cell(Formulation::Translational, "70p20sint")
        .unwrap();
    let log =
        data::FlightLog::read(&data_dir.join("experiment/custom_figure8_baseline_70p20sint.csv"))
            .unwrap();
    let (support, query) =
        evaluation::flight_segments(&log, Formulation::Translational, Segmentation::PAPER).unwrap();
    for (learn, cut, sindy) in [
        (
            &cell.support.targets,
            &support.targets,
            &evaluation.support.targets,
        ),
        (
            &cell.query.targets,
            &query.targets,
            &evaluation.query.targets,
        ),
    ] {
        assert!(learn == cut && learn == sindy);
    }

    // A model of another fold is refused; the checkpoint round-trips and explains.
    assert!(experiment.evaluate(model, "35wind").is_err());
    // A meta-training condition names no cell: refused by every entry point, before any work.
    for error in [
        experiment
            .run_cell(Formulation::Translational, "nowind", 5)
            .unwrap_err(),
        experiment
            .meta_train(Formulation::Translational, "nowind", 5)
            .unwrap_err(),
        experiment.evaluate(model, "nowind").unwrap_err(),
    ] {
        assert!(
            matches!(&error, EvaluationError::NotEvaluationCondition { condition, .. } if condition == "nowind"),
            "{error}"
        );
    }
    let dir = common::temp_dir("learn-real");
    let path = dir.path().join("learn-real.json");
    model.save(&path).unwrap();
    let loaded = MetaTrainedModel::load(&path).unwrap();
    assert_eq!(&loaded, model);
    let flight = data_dir.join("experiment/custom_figure8_baseline_70p20sint.csv");
    let log = data::FlightLog::read(&flight).unwrap();
    let explanation = explain_flight(
        &loaded,
        &log,
        Segmentation::PAPER,
        false,
        EquationRule::default(),
    )
    .unwrap();
    assert_eq!(explanation.outputs.len(), 3);
    assert!(explanation.outputs[0].equation.starts_with("v̇x = "));
    assert_eq!(explanation.outputs[0].inputs.len(), 6);
}

#[test]
fn nested_validation_checks_its_candidate_settings() {
    let Some(data_dir) = common::real_data_dir() else {
        return;
    };
    let root = common::workspace();
    let config = LearnConfig::load(&root.join("experiments/learn.json")).unwrap();
    let conditions = ExperimentConditions::load(&root.join("experiments/conditions.json")).unwrap();
    let experiment = Experiment::load(
        config.clone(),
        conditions,
        &data_dir,
        Some(Protocol::LeaveConditionOut),
        Segmentation::PAPER,
    )
    .unwrap();
    let base = config.get().clone();
    let mut no_rounds = base.clone();
    no_rounds.meta_training.inner_rounds = 0;
    let mut no_passes = base.adaptation.clone();
    no_passes.passes = 0;
    let pair = ["35wind", "70wind"];
    let run = |candidate: &LearnConfig, adaptation: &learn::AdaptationConfig| {
        experiment
            .nested_validation(
                Formulation::Translational,
                pair,
                candidate,
                std::slice::from_ref(adaptation),
                1,
            )
            .unwrap_err()
            .to_string()
    };
    let message = run(&no_rounds, &base.adaptation);
    assert!(message.contains("meta_training.inner_rounds"), "{message}");
    let message = run(&base, &no_passes);
    assert!(message.contains("adaptation.passes"), "{message}");
    let mut long_window = base.adaptation.clone();
    long_window.window = 100_000;
    let mut small = base.clone();
    small.meta_training.iterations = 1;
    let message = run(&small, &long_window);
    assert!(
        message.contains("adaptation.window") && message.contains("support segment"),
        "{message}"
    );
}

#[test]
fn condition_tasks_pool_the_flights_of_each_wind_condition() {
    let Some(data_dir) = common::real_data_dir() else {
        return;
    };
    let root = common::workspace();
    let origin = root.join("experiments/learn.json");
    let config = LearnConfig::load(&origin).unwrap();
    let experiment_with = |tasks: TaskGrouping, task_batch: usize| {
        let mut small = config.get().clone();
        small.meta_training.tasks = tasks;
        small.meta_training.task_batch = task_batch;
        small.meta_training.iterations = 2;
        small.meta_training.support_batch = 16;
        small.meta_training.query_batch = 16;
        let conditions =
            ExperimentConditions::load(&root.join("experiments/conditions.json")).unwrap();
        Experiment::load(
            small.check(&origin).unwrap(),
            conditions,
            &data_dir,
            Some(Protocol::LeaveConditionOut),
            Segmentation::PAPER,
        )
        .unwrap()
    };
    // The fold of 70psin20 meta-trains on 24 flights of 4 conditions: 4 condition tasks, and a
    // batch of 5 distinct tasks exists only per flight.
    let by_condition = experiment_with(TaskGrouping::Condition, 5)
        .meta_train(Formulation::Translational, "70psin20", 1)
        .unwrap_err()
        .to_string();
    assert!(
        by_condition.contains("meta_training.task_batch") && by_condition.contains("at most 4"),
        "{by_condition}"
    );
    let model = experiment_with(TaskGrouping::Condition, 4)
        .meta_train(Formulation::Translational, "70psin20", 1)
        .unwrap();
    assert_eq!(model.data_files.len(), 24);
    assert_eq!(model.config.meta_training.tasks, TaskGrouping::Condition);
    let by_flight = experiment_with(TaskGrouping::Flight, 5)
        .meta_train(Formulation::Translational, "70psin20", 1)
        .unwrap();
    assert_ne!(by_flight.parameters, model.parameters);
}

#[test]
fn every_finished_cell_is_reported_once() {
    let Some(data_dir) = common::real_data_dir() else {
        return;
    };
    let root = common::workspace();
    let origin = root.join("experiments/learn.json");
    let mut small = LearnConfig::load(&origin).unwrap().get().clone();
    small.meta_training.iterations = 2;
    small.meta_training.support_batch = 16;
    small.meta_training.query_batch = 16;
    small.adaptation.passes = 1;
    small.spread_seeds = vec![1, 2];
    let conditions = ExperimentConditions::load(&root.join("experiments/conditions.json")).unwrap();
    let experiment = Experiment::load(
        small.check(&origin).unwrap(),
        conditions,
        &data_dir,
        Some(Protocol::LeaveConditionOut),
        Segmentation::PAPER,
    )
    .unwrap();
    let seen = Units::default();
    let cells = experiment
        .run_cells(&[Formulation::Translational], 1, &seen)
        .unwrap();
    let mut seen = std::mem::take(&mut *seen.0.lock().unwrap());
    seen.sort();
    let mut expected: Vec<String> = cells
        .iter()
        .map(|c| format!("translational {} seed 1", c.summary.label))
        .collect();
    expected.sort();
    assert_eq!(cells.len(), 4);
    assert_eq!(seen, expected);
    let count = Units::default();
    let spread = experiment
        .seed_spread(&[Formulation::Translational], &[1, 2], &count)
        .unwrap();
    assert_eq!(spread.len(), 4);
    assert_eq!(count.0.lock().unwrap().len(), 8);
}

/// An observer that records every unit of work it is told of.
#[derive(Default)]
struct Units(std::sync::Mutex<Vec<String>>);

impl evaluation::Progress for Units {
    fn advance(&self, unit: std::fmt::Arguments<'_>) {
        self.0.lock().unwrap().push(unit.to_string());
    }
}

#[test]
fn nested_validation_detail_agrees_with_nested_validation() {
    let Some(data_dir) = common::real_data_dir() else {
        return;
    };
    let root = common::workspace();
    let path = root.join("experiments/learn.json");
    let mut small = LearnConfig::load(&path).unwrap().get().clone();
    small.meta_training.iterations = 3;
    small.meta_training.support_batch = 16;
    small.meta_training.query_batch = 16;
    small.adaptation.passes = 1;
    let checked = small.clone().check(&path).unwrap();
    let conditions = ExperimentConditions::load(&root.join("experiments/conditions.json")).unwrap();
    let experiment = Experiment::load(
        checked,
        conditions,
        &data_dir,
        Some(Protocol::LeaveConditionOut),
        Segmentation::PAPER,
    )
    .unwrap();
    let pair = ["35wind", "100wind"];
    let detail = experiment
        .nested_validation_detail(Formulation::Attitude, pair, 2, 0.2)
        .unwrap();
    let scores = experiment
        .nested_validation(
            Formulation::Attitude,
            pair,
            &small,
            std::slice::from_ref(&small.adaptation),
            2,
        )
        .unwrap();
    for (detail, score) in detail.iter().zip(&scores) {
        // The same meta-training and adaptation: the same generalisation MSE, bit for bit.
        assert_eq!(detail.generalisation, score[0]);
        assert_eq!(
            detail.generalisation,
            learn::mean_squared_error(&detail.query_predictions, &detail.query_targets)
        );
        assert_eq!(detail.query_predictions.len(), detail.query_targets.len());
        assert!(detail.support_tail_mse.is_finite() && detail.support_tail_mse > 0.0);
    }
    for fraction in [0.0, 1.0, f64::NAN] {
        let message = experiment
            .nested_validation_detail(Formulation::Attitude, pair, 2, fraction)
            .unwrap_err()
            .to_string();
        assert!(message.contains("between 0 and 1"), "{message}");
    }
}

#[test]
fn formulations_build_paper_segments() {
    let Some(dir) = common::real_data_dir() else {
        return;
    };
    let log =
        data::FlightLog::read(&dir.join("experiment/custom_figure8_baseline_35wind.csv")).unwrap();
    let split = data::SplitSpec::Halves.split(log.len()).unwrap();
    assert_eq!(split.support, 0..1255);
    let segment = Segment::cut(
        &log,
        Formulation::Full,
        split.query.clone(),
        Derivative::Forward,
    )
    .unwrap();
    assert_eq!(segment.len(), 1256);
    assert_eq!(segment.inputs().ncols(), 10);
    let k = split.query.start;
    let n1 = log.motor_command.row(k)[0] / 1000.0;
    assert!((segment.controls[(0, 0)] - n1 * n1).abs() < 1e-15);
    // target = forward difference on the segment alone
    let expected = (log.velocity[k + 1][0] - log.velocity[k][0]) / log.sample_interval();
    assert!((segment.targets[(0, 0)] - expected).abs() < 1e-9);
    let translational = Segment::cut(
        &log,
        Formulation::Translational,
        split.support,
        Derivative::Forward,
    )
    .unwrap();
    let thrust_z = log.rotation[0][2][2] * log.thrust_setpoint[0];
    assert!((translational.controls[(0, 2)] - thrust_z).abs() < 1e-15);
}
