//! Meta-training, adaptation, determinism and checkpoints on synthetic tasks.

mod common;

use common::{small_architecture, synthetic_batch, synthetic_tasks};
use learn::{
    AdaptationConfig, CHECKPOINT_FORMAT, InputRange, LearnConfig, MetaOrder, MetaTrainedModel,
    MetaTrainingConfig, Optimizer, Standardiser, TaskGrouping, adapt_online, meta_train,
};

fn meta_config(iterations: usize) -> MetaTrainingConfig {
    MetaTrainingConfig {
        inner_step: 0.05,
        inner_rounds: 1,
        outer_step: 0.01,
        optimizer: Optimizer::Adam,
        meta_regularisation: 1e-6,
        order: MetaOrder::Second,
        tasks: TaskGrouping::Flight,
        task_batch: 4,
        support_batch: 16,
        query_batch: 16,
        iterations,
        average_last: 0,
    }
}

fn adaptation(step: f64) -> AdaptationConfig {
    AdaptationConfig {
        step,
        passes: 3,
        window: 1,
        lipschitz_weight: 0.0,
        lipschitz_bound: 0.0,
        average_last_pass: false,
    }
}

fn mean(values: &[f64]) -> f64 {
    values.iter().sum::<f64>() / values.len() as f64
}

#[test]
fn meta_loss_decreases_and_adaptation_beats_the_meta_initialisation() {
    let architecture = small_architecture();
    let tasks = synthetic_tasks(8);
    let outcome = meta_train(&architecture, &tasks, &meta_config(150), 7).unwrap();
    let history = &outcome.meta_loss_history;
    let (early, late) = (mean(&history[..15]), mean(&history[history.len() - 15..]));
    assert!(late < 0.5 * early, "meta-loss {early} -> {late}");

    // A task never seen in meta-training.
    let support = synthetic_batch(1.8, 1.3, 200, 0.0);
    let query = synthetic_batch(1.8, 1.3, 200, 3.0);
    let before = architecture.loss(&outcome.parameters, &query.inputs, &query.targets);
    let adapted = adapt_online(
        &architecture,
        &outcome.parameters,
        &support.inputs,
        &support.targets,
        &adaptation(0.01),
    );
    let after = architecture.loss(&adapted, &query.inputs, &query.targets);
    assert!(after < 0.7 * before, "query MSE {before} -> {after}");
}

#[test]
fn averaged_adaptation_is_the_mean_of_the_last_pass_iterates() {
    let architecture = small_architecture();
    let start = architecture.initial_parameters(3);
    let support = synthetic_batch(1.0, 0.5, 150, 0.0);
    // Two updates per pass (windows of 75 samples), three passes.
    let plain_config = AdaptationConfig {
        window: 75,
        ..adaptation(0.05)
    };
    let adapt = |parameters: &[f64], rows: usize, config: &AdaptationConfig| {
        adapt_online(
            &architecture,
            parameters,
            &support.inputs[..rows * 2],
            &support.targets[..rows],
            config,
        )
    };
    let last = adapt(&start, 150, &plain_config);
    let before_last_pass = adapt(
        &start,
        150,
        &AdaptationConfig {
            passes: 2,
            ..plain_config.clone()
        },
    );
    let first_of_last_pass = adapt(
        &before_last_pass,
        75,
        &AdaptationConfig {
            passes: 1,
            ..plain_config.clone()
        },
    );
    let averaged = adapt(
        &start,
        150,
        &AdaptationConfig {
            average_last_pass: true,
            ..plain_config.clone()
        },
    );
    assert_ne!(averaged, last);
    for j in 0..averaged.len() {
        let mean = 0.5 * (first_of_last_pass[j] + last[j]);
        assert!(
            (averaged[j] - mean).abs() <= 1e-12 * mean.abs().max(1.0),
            "{j}"
        );
    }
}

#[test]
fn adaptation_with_step_zero_changes_nothing_and_the_lipschitz_term_smooths() {
    let architecture = small_architecture();
    let parameters = architecture.initial_parameters(2);
    let support = synthetic_batch(1.0, 0.5, 150, 0.0);
    let unchanged = adapt_online(
        &architecture,
        &parameters,
        &support.inputs,
        &support.targets,
        &adaptation(0.0),
    );
    assert_eq!(unchanged, parameters);

    // Noisy targets: the regulariser (bound 0) must reduce the jumps between consecutive predictions.
    let mut noisy = support.clone();
    for (k, t) in noisy.targets.iter_mut().enumerate() {
        *t += if k % 2 == 0 { 0.8 } else { -0.8 };
    }
    let total_variation = |p: &[f64]| -> f64 {
        let y = architecture.predict(p, &noisy.inputs);
        y.windows(2).map(|w| (w[1] - w[0]).abs()).sum()
    };
    let plain = adapt_online(
        &architecture,
        &parameters,
        &noisy.inputs,
        &noisy.targets,
        &adaptation(0.02),
    );
    let smooth = adapt_online(
        &architecture,
        &parameters,
        &noisy.inputs,
        &noisy.targets,
        &AdaptationConfig {
            lipschitz_weight: 0.5,
            ..adaptation(0.02)
        },
    );
    assert!(
        total_variation(&smooth) < total_variation(&plain),
        "{} !< {}",
        total_variation(&smooth),
        total_variation(&plain)
    );
}

#[test]
fn meta_training_is_bit_identical_for_one_and_two_threads() {
    let architecture = small_architecture();
    let tasks = synthetic_tasks(6);
    let config = meta_config(12);
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| meta_train(&architecture, &tasks, &config, 3).unwrap())
    };
    let (one, two) = (run(1), run(2));
    assert_eq!(one.parameters, two.parameters);
    assert_eq!(one.meta_loss_history, two.meta_loss_history);
    let other_seed = meta_train(&architecture, &tasks, &config, 4).unwrap();
    assert_ne!(one.parameters, other_seed.parameters);
}

#[test]
fn iterate_averaging_returns_the_mean_of_the_last_iterates() {
    let architecture = small_architecture();
    let tasks = synthetic_tasks(6);
    // A run of n iterations passes through the final iterates of the runs of n − 2 and n − 1.
    let finals: Vec<Vec<f64>> = [18, 19, 20]
        .iter()
        .map(|&n| {
            meta_train(&architecture, &tasks, &meta_config(n), 5)
                .unwrap()
                .parameters
        })
        .collect();
    let averaged = meta_train(
        &architecture,
        &tasks,
        &MetaTrainingConfig {
            average_last: 3,
            ..meta_config(20)
        },
        5,
    )
    .unwrap();
    assert_ne!(averaged.parameters, finals[2]);
    for (j, &value) in averaged.parameters.iter().enumerate() {
        let mean = (finals[0][j] + finals[1][j] + finals[2][j]) / 3.0;
        assert!((value - mean).abs() <= 1e-12 * mean.abs().max(1.0), "{j}");
    }
    // The loss histories are those of the plain run: averaging changes only the result.
    assert_eq!(averaged.meta_loss_history.len(), 20);
    let too_long = LearnConfig::load(&common::workspace().join("experiments/learn.json"))
        .unwrap()
        .get()
        .clone();
    let mut bad = too_long;
    bad.meta_training.average_last = bad.meta_training.iterations + 1;
    let error = bad.check(std::path::Path::new("learn.json")).unwrap_err();
    assert!(error.to_string().contains("average_last"), "{error}");
}

#[test]
fn first_order_is_an_option_and_learns_too() {
    let architecture = small_architecture();
    let tasks = synthetic_tasks(8);
    let config = MetaTrainingConfig {
        order: MetaOrder::First,
        ..meta_config(100)
    };
    let outcome = meta_train(&architecture, &tasks, &config, 7).unwrap();
    let history = &outcome.meta_loss_history;
    assert!(mean(&history[history.len() - 10..]) < mean(&history[..10]));
}

fn example_model() -> MetaTrainedModel {
    let config = LearnConfig::load(&common::workspace().join("experiments/learn.json")).unwrap();
    let architecture = learn::architecture(learn::Formulation::Translational, config.get());
    MetaTrainedModel {
        format: CHECKPOINT_FORMAT.to_string(),
        trained_on: learn::TrainedOn::Flights(learn::FlightTraining {
            formulation: learn::Formulation::Translational,
            protocol: "leave-condition-out".to_string(),
            held_out_condition: Some("35wind".to_string()),
        }),
        seed: 9,
        config: config.get().clone(),
        parameters: architecture.initial_parameters(9),
        standardiser: Standardiser::identity(architecture.input_dim),
        architecture,
        data_files: vec![],
        meta_loss_history: vec![1.0, 0.5],
    }
}

#[test]
fn checkpoints_round_trip_and_bad_ones_name_the_file() {
    let dir = common::temp_dir("learn-checkpoint");
    // In a folder that does not exist yet: saving makes it.
    let path = dir.path().join("checkpoints/model.json");
    let model = example_model();
    model.save(&path).unwrap();
    assert_eq!(MetaTrainedModel::load(&path).unwrap(), model);

    let mut short = model.clone();
    short.parameters.pop();
    short.save(&path).unwrap();
    let message = MetaTrainedModel::load(&path).unwrap_err().to_string();
    assert!(
        message.contains("model.json") && message.contains("parameters"),
        "{message}"
    );

    // A kept input range must fit the inputs; a clamping standardiser must have one.
    let dim = model.architecture.input_dim;
    let range = InputRange {
        low: vec![-1.0; dim],
        high: vec![1.0; dim],
    };
    let mut ranged = model.clone();
    ranged.standardiser = ranged.standardiser.with_range(range.clone(), true);
    ranged.save(&path).unwrap();
    assert_eq!(MetaTrainedModel::load(&path).unwrap(), ranged);
    let mut short_range = ranged.clone();
    short_range.standardiser.range.as_mut().unwrap().high.pop();
    short_range.save(&path).unwrap();
    let message = MetaTrainedModel::load(&path).unwrap_err().to_string();
    assert!(message.contains("standardiser"), "{message}");
    let mut no_range = ranged;
    no_range.standardiser.range = None;
    no_range.save(&path).unwrap();
    let message = MetaTrainedModel::load(&path).unwrap_err().to_string();
    assert!(message.contains("clamps but has no range"), "{message}");

    std::fs::write(&path, "{\"format\": 3}").unwrap();
    let message = MetaTrainedModel::load(&path).unwrap_err().to_string();
    assert!(message.contains("model.json"), "{message}");
}

#[test]
fn checkpoints_with_unknown_fields_anywhere_are_refused() {
    let dir = common::temp_dir("learn-checkpoint-fields");
    // In a folder that does not exist yet: saving makes it.
    let path = dir.path().join("checkpoints/model.json");
    let mut model = example_model();
    model.data_files = vec![learn::DataFile {
        path: "experiment/a.csv".into(),
        sha256: "0".repeat(64),
    }];
    model.save(&path).unwrap();
    assert_eq!(MetaTrainedModel::load(&path).unwrap(), model);
    let text = std::fs::read_to_string(&path).unwrap();
    // The field's path in the message: at the top, and inside every object of the checkpoint.
    for (pointer, field) in [
        ("", "extra"),
        ("/architecture", "architecture.extra"),
        ("/standardiser", "standardiser.extra"),
        ("/config", "config.extra"),
        ("/data_files/0", "data_files[0].extra"),
    ] {
        let mut value: serde_json::Value = serde_json::from_str(&text).unwrap();
        value
            .pointer_mut(pointer)
            .unwrap()
            .as_object_mut()
            .unwrap()
            .insert("extra".to_string(), serde_json::json!(1));
        std::fs::write(&path, value.to_string()).unwrap();
        let message = MetaTrainedModel::load(&path).unwrap_err().to_string();
        assert!(
            message.contains("model.json")
                && message.contains(field)
                && message.contains("unknown field"),
            "{pointer}: {message}"
        );
    }
}

#[test]
fn bad_configurations_name_the_file_and_field() {
    let dir = common::temp_dir("learn-config");
    let path = dir.path().join("learn.json");
    let text = std::fs::read_to_string(common::workspace().join("experiments/learn.json")).unwrap();
    std::fs::write(
        &path,
        text.replace("\"task_batch\": ", "\"task_batch\": 0, \"x\": "),
    )
    .unwrap();
    let message = LearnConfig::load(&path).unwrap_err().to_string();
    assert!(message.contains("learn.json"), "{message}");
    let mut value: serde_json::Value = serde_json::from_str(&text).unwrap();
    value["meta_training"]["inner_step"] = serde_json::json!(-1.0);
    std::fs::write(&path, value.to_string()).unwrap();
    let message = LearnConfig::load(&path).unwrap_err().to_string();
    assert!(
        message.contains("learn.json") && message.contains("meta_training.inner_step"),
        "{message}"
    );
}

#[test]
fn meta_training_batches_are_bounded_by_the_tasks_they_are_drawn_from() {
    let architecture = small_architecture();
    let tasks = synthetic_tasks(3);
    for (config, field) in [
        (
            MetaTrainingConfig {
                task_batch: 4,
                ..meta_config(2)
            },
            "meta_training.task_batch",
        ),
        (
            MetaTrainingConfig {
                support_batch: 201,
                task_batch: 3,
                ..meta_config(2)
            },
            "meta_training.support_batch",
        ),
        (
            MetaTrainingConfig {
                query_batch: 10_000_000,
                task_batch: 3,
                ..meta_config(2)
            },
            "meta_training.query_batch",
        ),
    ] {
        let message = meta_train(&architecture, &tasks, &config, 1)
            .unwrap_err()
            .to_string();
        assert!(message.starts_with(field), "{message}");
    }
    let full = MetaTrainingConfig {
        task_batch: 3,
        support_batch: 200,
        query_batch: 200,
        ..meta_config(2)
    };
    assert!(meta_train(&architecture, &tasks, &full, 1).is_ok());
}

#[test]
fn an_overflow_in_the_last_meta_update_is_divergence_not_a_result() {
    let architecture = small_architecture();
    let tasks = synthetic_tasks(4);
    let config = MetaTrainingConfig {
        // Every gradient is finite (about 2μθ ~ 1e299); the update θ − β·g is not.
        optimizer: Optimizer::Sgd,
        meta_regularisation: 1e300,
        outer_step: 1e10,
        ..meta_config(1)
    };
    let error = meta_train(&architecture, &tasks, &config, 1).unwrap_err();
    assert!(
        matches!(error, learn::LearnError::Diverged { iteration: 0, .. }),
        "{error}"
    );
}

#[test]
fn checkpoints_with_unusable_standardisers_or_settings_are_refused() {
    let dir = common::temp_dir("learn-checkpoint-check");
    // In a folder that does not exist yet: saving makes it.
    let path = dir.path().join("checkpoints/model.json");
    let model = example_model();
    let mut cases: Vec<(MetaTrainedModel, &str)> = Vec::new();
    let mut zero_std = model.clone();
    zero_std.standardiser.std[2] = 0.0;
    cases.push((zero_std, "field 'standardiser.std[2]'"));
    let mut negative_std = model.clone();
    negative_std.standardiser.std[0] = -1.0;
    cases.push((negative_std, "field 'standardiser.std[0]'"));
    let mut no_step = model.clone();
    no_step.config.adaptation.step = 0.0;
    cases.push((no_step, "field 'config.adaptation.step'"));
    let mut no_passes = model.clone();
    no_passes.config.adaptation.passes = 0;
    cases.push((no_passes, "field 'config.adaptation.passes'"));
    let mut other_architecture = model.clone();
    other_architecture.config.hidden_layers = vec![8, 8];
    cases.push((other_architecture, "architecture does not match"));
    for (bad, expected) in cases {
        bad.save(&path).unwrap();
        let message = MetaTrainedModel::load(&path).unwrap_err().to_string();
        assert!(
            message.contains("model.json") && message.contains(expected),
            "{expected}: {message}"
        );
    }
}
