//! A wrong value deep in a configuration file is reported by its field path (and position), so
//! the user knows which setting to fix without counting lines.

mod common;

use common::{learn_in, scratch};

#[test]
fn a_wrong_type_in_learn_json_names_the_field() {
    let dir = scratch("config-field");
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut config: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(root.join("experiments/learn.json")).unwrap(),
    )
    .unwrap();
    config["meta_training"]["average_last"] = serde_json::json!(-1);
    std::fs::write(
        dir.join("learn.json"),
        serde_json::to_string_pretty(&config).unwrap(),
    )
    .unwrap();
    let run = learn_in(&dir, &["meta-train", "--config", "learn.json"]);
    let message = run.one_line_error(&["learn.json", "meta_training.average_last (line "]);
    assert!(message.contains("invalid value: integer `-1`"), "{message}");
}

#[test]
fn an_array_in_place_of_a_settings_object_is_refused_by_its_field() {
    // serde would read the array as the object's fields in declaration order.
    let dir = scratch("config-array");
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut config: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(root.join("experiments/learn.json")).unwrap(),
    )
    .unwrap();
    config["adaptation"] = serde_json::json!([0.0005, 16, 1, 0.01, 1.0, false]);
    std::fs::write(dir.join("learn.json"), config.to_string()).unwrap();
    let run = learn_in(&dir, &["meta-train", "--config", "learn.json"]);
    let message = run.one_line_error(&["learn.json", "adaptation"]);
    assert!(
        message.contains("expected a JSON object, found an array"),
        "{message}"
    );
}
