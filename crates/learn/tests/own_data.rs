//! LeARN on a multi-task set in memory (the recordings of CSV tasks): a small generated family
//! meta-trains, adapts better than the unadapted model on an unseen draw, and its checkpoint
//! round-trips; the paper's checkpoints keep their layout.

use std::path::Path;

use learn::{ColumnSpec, MetaTrainedModel, Recording, TaskConfig, TaskSet, TaskSource, TrainedOn};
use sindy::Derivative;

/// A temporary folder, removed when dropped.
fn scratch(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("learn-own-data-{name}-"))
        .tempdir()
        .unwrap()
}

/// The sampling interval of the generated recordings, seconds.
const INTERVAL: f64 = 0.05;

/// x' = v, v' = −k·x − c·v + u with u = cos(1.3 t), sampled every 0.05 s (RK4, 4 substeps): the
/// columns x, v and u.
fn oscillator(k: f64, c: f64, rows: usize) -> Vec<Vec<f64>> {
    let derivative = |[x, v]: [f64; 2], t: f64| [v, -k * x - c * v + (1.3 * t).cos()];
    let (dt, substeps) = (INTERVAL, 4);
    let h = dt / substeps as f64;
    let mut state = [0.5, 0.0];
    let mut columns = vec![Vec::new(); 3];
    for row in 0..rows {
        let t = row as f64 * dt;
        for (column, value) in columns
            .iter_mut()
            .zip([state[0], state[1], (1.3 * t).cos()])
        {
            column.push(value);
        }
        for s in 0..substeps {
            let t = t + s as f64 * h;
            let add = |a: [f64; 2], b: [f64; 2], w: f64| [a[0] + w * b[0], a[1] + w * b[1]];
            let k1 = derivative(state, t);
            let k2 = derivative(add(state, k1, h / 2.0), t + h / 2.0);
            let k3 = derivative(add(state, k2, h / 2.0), t + h / 2.0);
            let k4 = derivative(add(state, k3, h), t + h);
            for i in 0..2 {
                state[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
        }
    }
    columns
}

/// A recording named `name` (its file in errors) holding `columns`.
fn recording<'a>(name: &'a str, columns: &'a [Vec<f64>]) -> Recording<'a> {
    Recording {
        name,
        path: Path::new(name),
        columns,
        interval: INTERVAL,
    }
}

fn spec() -> ColumnSpec {
    ColumnSpec {
        time: "t".to_string(),
        state: vec!["x".to_string(), "v".to_string()],
        control: vec!["u".to_string()],
        derivative: Derivative::Central,
    }
}

/// Six training draws of (k, c), a small network and a short budget (well under a second).
fn meta_trained(dir: &Path) -> MetaTrainedModel {
    let draws: Vec<(String, Vec<Vec<f64>>)> = [
        (0.5, 0.1),
        (1.0, 0.3),
        (2.0, 0.2),
        (3.0, 0.5),
        (1.5, 0.05),
        (4.0, 0.4),
    ]
    .into_iter()
    .enumerate()
    .map(|(i, (k, c))| (format!("task-{i}.csv"), oscillator(k, c, 240)))
    .collect();
    let config = dir.join("config.json");
    std::fs::write(
        &config,
        r#"{"hidden_layers": [16, 16], "meta_training": {"iterations": 300},
            "adaptation": {"step": 0.01, "passes": 4}}"#,
    )
    .unwrap();
    let settings = TaskConfig::load(Some(&config)).unwrap();
    let source = TaskSource::Files {
        pattern: format!("{}/task-*.csv", dir.display()),
    };
    let tasks: Vec<Recording> = draws
        .iter()
        .map(|(name, columns)| recording(name, columns))
        .collect();
    let set = TaskSet {
        source: &source,
        spec: &spec(),
        tasks: &tasks,
        files: Vec::new(),
    };
    learn::meta_train_tasks(set, &settings, &|_| {}).unwrap()
}

#[test]
fn a_meta_trained_model_adapts_to_an_unseen_draw_better_than_without_adaptation() {
    let scratch_dir = scratch("adapt");
    let dir = scratch_dir.path().to_path_buf();
    let model = meta_trained(&dir);
    let TrainedOn::Columns(columns) = &model.trained_on else {
        panic!("a model of CSV tasks");
    };
    assert_eq!(columns.state, ["x", "v"]);
    assert_eq!(model.output_names(), ["x'", "v'"]);
    assert_eq!(columns.tasks.len(), 6);
    // The default batches fit in the 6 tasks and their 120-row halves: kept.
    assert_eq!(model.config.meta_training.task_batch, 4);
    assert_eq!(model.config.meta_training.support_batch, 64);
    let unseen = oscillator(2.5, 0.35, 400);
    let recording = recording("unseen.csv", &unseen);
    let evaluation = learn::evaluate_recording(&model, recording, 0..200, 200..400).unwrap();
    assert!(
        evaluation.generalisation < 0.8 * evaluation.unadapted_generalisation,
        "adapted {} against unadapted {}",
        evaluation.generalisation,
        evaluation.unadapted_generalisation
    );
    assert!(evaluation.adaptation < evaluation.unadapted_adaptation);

    // The checkpoint round-trips, with what it was trained on.
    let path = dir.join("model.json");
    model.save(&path).unwrap();
    let loaded = MetaTrainedModel::load(&path).unwrap();
    assert_eq!(loaded, model);
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.starts_with(r#"{"format":"learn-checkpoint/1","trained_on":{"time":"t""#),
        "{}",
        &text[..80]
    );

    // Rows outside the recording, or too few for the derivative, name the file and the rows.
    let message = learn::evaluate_recording(&model, recording, 0..500, 200..400)
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("unseen.csv") && message.contains("support rows 0:500"),
        "{message}"
    );
    let message = learn::evaluate_recording(&model, recording, 0..2, 200..400)
        .unwrap_err()
        .to_string();
    assert!(message.contains("fewer than the 3"), "{message}");
}

#[test]
fn a_checkpoint_is_either_a_flight_model_or_a_model_of_csv_tasks() {
    let scratch_dir = scratch("layout");
    let dir = scratch_dir.path().to_path_buf();
    let model = meta_trained(&dir);
    let path = dir.join("model.json");
    model.save(&path).unwrap();
    let mut value: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    value["formulation"] = serde_json::json!("full");
    std::fs::write(&path, value.to_string()).unwrap();
    let message = MetaTrainedModel::load(&path).unwrap_err().to_string();
    assert!(message.contains("either 'trained_on'"), "{message}");
    value.as_object_mut().unwrap().remove("formulation");
    value["trained_on"]["target_scale"] = serde_json::json!([1.0]);
    std::fs::write(&path, value.to_string()).unwrap();
    let message = MetaTrainedModel::load(&path).unwrap_err().to_string();
    assert!(message.contains("target_scale"), "{message}");
}

#[test]
fn a_flight_checkpoint_is_written_with_the_fields_it_always_had() {
    let config: learn::LearnConfig =
        serde_json::from_str(include_str!("../../../experiments/learn.json")).unwrap();
    let formulation = learn::Formulation::Attitude;
    let architecture = learn::architecture(formulation, &config);
    let model = MetaTrainedModel {
        format: learn::CHECKPOINT_FORMAT.to_string(),
        trained_on: TrainedOn::Flights(learn::FlightTraining {
            formulation,
            protocol: "paper".to_string(),
            held_out_condition: None,
        }),
        seed: 1,
        parameters: architecture.initial_parameters(1),
        standardiser: learn::Standardiser::identity(architecture.input_dim),
        architecture,
        config,
        data_files: Vec::new(),
        meta_loss_history: vec![0.5],
    };
    let value = serde_json::to_value(&model).unwrap();
    let keys: Vec<&str> = value
        .as_object()
        .unwrap()
        .keys()
        .map(String::as_str)
        .collect();
    // serde_json sorts keys in a Value; the text keeps the order of the fields.
    assert_eq!(keys.len(), 11);
    let text = serde_json::to_string(&model).unwrap();
    assert!(
        text.starts_with(
            r#"{"format":"learn-checkpoint/1","formulation":"attitude","protocol":"paper","held_out_condition":null,"seed":1,"config":"#
        ),
        "{}",
        &text[..120]
    );
    let read: MetaTrainedModel = bounded_read::json::from_str(&text).unwrap();
    assert_eq!(read, model);
}
