//! The reader against pyulog on the two public PX4 logs of `data/ulog` (a link to
//! `../shared/data/ulog` made by `make data`): values from `scripts/golden/ulog_golden.py`,
//! stored in `scripts/golden/ulog_golden.json`. Without the logs the tests skip, except under CI
//! (`CI=true`), where they fail.

use std::path::{Path, PathBuf};

use serde_json::Value;
use ulog::{Log, ParameterNumber};

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn golden() -> Value {
    let text = std::fs::read_to_string(workspace().join("scripts/golden/ulog_golden.json"))
        .expect("golden values");
    serde_json::from_str(&text).expect("golden JSON")
}

/// The log `file` of `data/ulog`, or `None` (skipping) where the logs are absent outside CI.
fn read(file: &str) -> Option<Log> {
    let path = workspace().join("data/ulog").join(file);
    if !path.is_file() {
        assert!(
            std::env::var("CI").map_or(true, |ci| ci != "true"),
            "CI=true but no ULog file at {} (run `make data`)",
            path.display()
        );
        eprintln!(
            "skipping: no ULog file at {} (run `make data`)",
            path.display()
        );
        return None;
    }
    Some(Log::read(&path).unwrap_or_else(|e| panic!("{e}")))
}

fn each_log(check: impl Fn(&Log, &Value)) {
    for expected in golden()["logs"].as_array().unwrap() {
        if let Some(log) = read(expected["file"].as_str().unwrap()) {
            check(&log, expected);
        }
    }
}

#[test]
fn header_info_and_messages_agree_with_pyulog() {
    each_log(|log, expected| {
        assert_eq!(
            log.start_time_us,
            expected["start_timestamp"].as_u64().unwrap()
        );
        assert_eq!(
            log.last_time_us,
            expected["last_timestamp"].as_u64().unwrap()
        );
        for (key, value) in expected["info"].as_object().unwrap() {
            assert_eq!(log.info_text(key), value.as_str(), "{key}");
        }
        let keys: Vec<&str> = log.info.keys().map(String::as_str).collect();
        let expected_keys: Vec<&str> = expected["info_keys"]
            .as_array()
            .unwrap()
            .iter()
            .map(|k| k.as_str().unwrap())
            .collect();
        assert_eq!(keys, expected_keys);
        let multi: Vec<&str> = log.multi_info.keys().map(String::as_str).collect();
        assert_eq!(
            serde_json::json!(multi),
            expected["multi_info_keys"],
            "multi-info keys"
        );
        let plain = log.messages.iter().filter(|m| m.tag.is_none()).count();
        assert_eq!(plain as u64, expected["logged_messages"].as_u64().unwrap());
        let tagged = log.messages.len() - plain;
        assert_eq!(
            tagged as u64,
            expected["tagged_logged_messages"].as_u64().unwrap()
        );
        let first = &log.messages[0];
        assert_eq!(
            serde_json::json!([first.time_us, first.text]),
            expected["first_logged_message"]
        );
        let dropouts: Vec<[u64; 2]> = log
            .dropouts
            .iter()
            .map(|d| [d.time_us, u64::from(d.duration_ms)])
            .collect();
        assert_eq!(serde_json::json!(dropouts), expected["dropouts"]);
        assert!(log.truncated.is_none() && !log.appended_data);
    });
}

#[test]
fn parameters_agree_with_pyulog() {
    each_log(|log, expected| {
        let parameters = &log.parameters;
        for (name, value) in expected["parameters"].as_object().unwrap() {
            let read = parameters.value(name).unwrap_or_else(|| panic!("{name}"));
            match read {
                ParameterNumber::Int(v) => assert_eq!(Some(i64::from(v)), value.as_i64(), "{name}"),
                ParameterNumber::Float(v) => {
                    assert_eq!(Some(f64::from(v)), value.as_f64(), "{name}")
                }
            }
        }
        let count = |key: &str| expected[key].as_u64().unwrap() as usize;
        assert_eq!(parameters.initial.len(), count("parameter_count"));
        assert_eq!(
            parameters.system_defaults.len(),
            count("system_default_count")
        );
        assert_eq!(
            parameters.configuration_defaults.len(),
            count("configuration_default_count")
        );
        assert_eq!(
            parameters.changes.len(),
            expected["changed_parameters"].as_array().unwrap().len()
        );
    });
}

#[test]
fn every_topic_instance_has_pyulogs_sample_count() {
    each_log(|log, expected| {
        let read: Vec<Value> = log
            .topics
            .iter()
            .filter(|t| !t.is_empty())
            .map(|t| serde_json::json!([t.name, t.multi_id, t.len()]))
            .collect();
        assert_eq!(Value::Array(read), expected["topics"]);
    });
}

#[test]
fn checked_topics_have_pyulogs_fields_timestamps_and_values() {
    each_log(|log, expected| {
        for topic_expected in expected["checked_topics"].as_array().unwrap() {
            let name = topic_expected["name"].as_str().unwrap();
            let topic = log.topic(name, 0).unwrap_or_else(|| panic!("{name}"));
            let times = topic.timestamps();
            assert_eq!(
                times.len() as u64,
                topic_expected["samples"].as_u64().unwrap()
            );
            assert_eq!(
                times[0],
                topic_expected["first_timestamp"].as_u64().unwrap()
            );
            assert_eq!(
                times[times.len() - 1],
                topic_expected["last_timestamp"].as_u64().unwrap()
            );
            let fields: Vec<&str> = topic.fields().iter().map(|f| f.name.as_str()).collect();
            assert_eq!(
                serde_json::json!(fields),
                topic_expected["fields"],
                "{name}"
            );
            for (field, values) in topic_expected["values"].as_object().unwrap() {
                let column = topic.column_f64(field).unwrap_or_else(|| panic!("{field}"));
                for (index, value) in values.as_object().unwrap() {
                    let index: usize = index.parse().unwrap();
                    // The float32 widened to f64 that pyulog's JSON holds, up to serde_json's
                    // parse of it (within an f64 ulp or two without its float_roundtrip feature).
                    let value = value.as_f64().unwrap();
                    assert!(
                        (column[index] - value).abs() <= 1e-15 * value.abs(),
                        "{name}.{field}[{index}]: {} against {value}",
                        column[index]
                    );
                }
            }
        }
    });
}
