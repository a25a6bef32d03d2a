//! Model selection of every variant happens inside the support segment: perturbing the query
//! segment (states, controls and targets) changes the generalisation error but leaves every chosen
//! hyper-parameter, the selected library and the support predictions exactly as they were.
//! Uses one real flight and the variants of `experiments/variants.json`; the learned-basis variants
//! get untrained networks (their meta-training never reads the evaluation flight).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use data::{FlightLog, SplitSpec};
use evaluation::{
    EvaluationCell, Flight, Method, Models, Outcome, Protocol, Runner, Segment, VariantKind,
    VariantsConfig,
};
use learn::Formulation;
use learn::{CHECKPOINT_FORMAT, LearnConfig, MetaTrainedModel, Standardiser};
use sindy::Derivative;

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The real data directory (see `data::real_data_dir_for_tests`: skips locally, fails under CI).
fn real_data_dir() -> Option<PathBuf> {
    data::real_data_dir_for_tests(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../.."))
}

/// Scales, shifts and wiggles every column of the query segment.
fn perturbed(query: &Segment) -> Segment {
    let mut changed = query.clone();
    for matrix in [
        &mut changed.states,
        &mut changed.controls,
        &mut changed.targets,
    ] {
        for j in 0..matrix.ncols() {
            for i in 0..matrix.nrows() {
                matrix[(i, j)] = 1.7 * matrix[(i, j)] + 0.3 + 0.2 * ((i * (j + 3)) as f64).sin();
            }
        }
    }
    changed
}

fn untrained_model(formulation: Formulation, config: &LearnConfig) -> MetaTrainedModel {
    let architecture = learn::architecture(formulation, config);
    MetaTrainedModel {
        format: CHECKPOINT_FORMAT.to_string(),
        trained_on: learn::TrainedOn::Flights(learn::FlightTraining {
            formulation,
            protocol: Protocol::LeaveConditionOut.name().to_string(),
            held_out_condition: None,
        }),
        seed: 1,
        config: config.clone(),
        parameters: architecture.initial_parameters(1),
        standardiser: Standardiser::identity(architecture.input_dim),
        architecture,
        data_files: Vec::new(),
        meta_loss_history: Vec::new(),
    }
}

/// Every variant of `config` on the cell of `support` and `query` of the flight `log`, seed 3,
/// the networks given by `model`.
fn evaluate(
    config: &VariantsConfig,
    log: &FlightLog,
    support: Segment,
    query: Segment,
    model: &MetaTrainedModel,
) -> Vec<Outcome> {
    let cell = EvaluationCell {
        formulation: support.formulation,
        condition: serde_json::from_str(
            r#"{"name": "70wind", "wind_speed": "12.0 m/s", "role": "evaluation"}"#,
        )
        .unwrap(),
        flight: Arc::new(Flight {
            log: log.clone(),
            file: learn::DataFile {
                path: log.path.clone(),
                sha256: String::new(),
            },
        }),
        support,
        query,
    };
    let train = |_: &EvaluationCell, _: u64| Ok(model.clone());
    let runner = Runner::new(
        config.variants.iter().map(|v| v as &dyn Method),
        Some(&train),
    );
    runner
        .evaluate(&cell, 3, &mut Models::new(&cell, Some(&train)))
        .unwrap()
}

#[test]
fn perturbing_the_query_changes_no_choice() {
    let Some(data_dir) = real_data_dir() else {
        return;
    };
    let root = workspace();
    let config = VariantsConfig::load(&root.join("experiments/variants.json"), &root).unwrap();
    let log =
        FlightLog::read(&data_dir.join("experiment/custom_figure8_baseline_70wind.csv")).unwrap();
    // The first 1200 samples, cut in halves, keep the test fast.
    let split = SplitSpec::Halves.split(1200.min(log.len())).unwrap();
    // Attitude: every kind of feature (inputs, sin/cos, control lags, learned basis) is present.
    for formulation in [Formulation::Attitude] {
        let support = Segment::cut(
            &log,
            formulation,
            split.support.clone(),
            Derivative::Forward,
        )
        .unwrap();
        let query =
            Segment::cut(&log, formulation, split.query.clone(), Derivative::Forward).unwrap();
        let changed = perturbed(&query);
        let model = untrained_model(formulation, config.run.learn.get());
        let original = evaluate(&config.raw, &log, support.clone(), query, &model);
        let again = evaluate(&config.raw, &log, support, changed, &model);
        for ((spec, a), b) in config.raw.variants.iter().zip(&original).zip(&again) {
            let what = format!("{} {}", formulation.name(), spec.name);
            // `learn`, `learn_ensemble` and `average` choose nothing; every other variant records its choices.
            let chooses = !matches!(
                spec.kind,
                VariantKind::Learn
                    | VariantKind::LearnEnsemble { .. }
                    | VariantKind::Average { .. }
            );
            assert_eq!(!a.chosen.is_empty(), chooses, "{what}: choices recorded");
            assert_eq!(a.chosen, b.chosen, "{what}: a choice moved with the query");
            assert_eq!(a.support_cv, b.support_cv, "{what}");
            assert_eq!(a.predictions.adaptation, b.predictions.adaptation, "{what}");
            assert_eq!(
                a.predictions.support_prediction, b.predictions.support_prediction,
                "{what}"
            );
            assert_ne!(
                a.predictions.generalisation, b.predictions.generalisation,
                "{what}: not perturbed"
            );
        }
    }
}
