//! A PX4 log exported to CSV (pyulog's `ulog2csv`: one `<log>_<topic>_<k>.csv` per topic instance,
//! each with its own `timestamp` in µs) read through the same layout as the `.ulg`: the same rows,
//! times and values. The export is written here from the shared jMAVSim log as `ulog2csv` writes it
//! (header `timestamp,<fields>`), so the test needs no Python.

use std::path::{Path, PathBuf};

use data::layout::{RecordingLayout, read_rows_with_layout};

mod common;

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn layout() -> RecordingLayout {
    RecordingLayout::load(&workspace().join("experiments/layouts/px4-ulog.json")).unwrap()
}

/// Writes every topic instance of `log` that `topics` names as `ulog2csv` would, into `dir`.
fn export(log: &ulog::Log, topics: &[&str], dir: &Path) {
    for topic in log
        .topics
        .iter()
        .filter(|t| topics.contains(&t.name.as_str()))
    {
        let fields: Vec<&str> = topic
            .fields()
            .iter()
            .map(|f| f.name.as_str())
            .filter(|name| *name != "timestamp")
            .collect();
        let columns: Vec<Vec<f64>> = fields
            .iter()
            .map(|f| topic.column_f64(f).unwrap())
            .collect();
        let mut text = format!("timestamp,{}\n", fields.join(","));
        for (row, stamp) in topic.timestamps().iter().enumerate() {
            text.push_str(&stamp.to_string());
            for column in &columns {
                text.push_str(&format!(",{:?}", column[row]));
            }
            text.push('\n');
        }
        let name = format!("flight_{}_{}.csv", topic.name, topic.multi_id);
        std::fs::write(dir.join(name), text).unwrap();
    }
}

/// Rewrites the file at `path` with its lines changed by `edit`; returns its text before.
fn edit_lines(path: &Path, edit: impl FnOnce(&mut Vec<String>)) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    edit(&mut lines);
    std::fs::write(path, lines.join("\n") + "\n").unwrap();
    text
}

const TOPICS: [&str; 5] = [
    "vehicle_local_position",
    "vehicle_attitude",
    "vehicle_angular_velocity",
    "actuator_motors",
    "battery_status",
];

#[test]
fn an_export_reads_as_its_ulog() {
    let Some(path) = data::ulog_file_for_tests(&workspace(), "sample_px4_events.ulg") else {
        return;
    };
    let log = ulog::Log::read(&path).unwrap();
    let dir = common::temp_dir("px4-export");
    export(&log, &TOPICS, &dir);
    let rows = Some(160..280);
    let from_ulog = read_rows_with_layout(&path, &layout(), rows.clone()).unwrap();
    let from_csv = read_rows_with_layout(&dir, &layout(), rows).unwrap();
    assert_eq!(from_csv.len(), from_ulog.len());
    let shift = from_csv.time[0] - from_ulog.time[0];
    for k in 0..from_ulog.len() {
        assert!((from_csv.time[k] - from_ulog.time[k] - shift).abs() < 1e-9);
    }
    assert_eq!(from_csv.position, from_ulog.position);
    assert_eq!(from_csv.velocity, from_ulog.velocity);
    assert_eq!(from_csv.quaternion, from_ulog.quaternion);
    assert_eq!(from_csv.body_rate, from_ulog.body_rate);
    assert_eq!(from_csv.motor_command, from_ulog.motor_command);
    assert_eq!(from_csv.battery_voltage, from_ulog.battery_voltage);
}

/// A topic without its file, two logs in one folder, rows out of time order and a time stamp that
/// is not a whole number of microseconds are refused in one line naming the folder or file, topic
/// and line.
#[test]
fn a_bad_export_is_refused_naming_what_is_wrong() {
    let Some(path) = data::ulog_file_for_tests(&workspace(), "sample_px4_events.ulg") else {
        return;
    };
    let log = ulog::Log::read(&path).unwrap();
    let message = |dir: &Path| {
        read_rows_with_layout(dir, &layout(), None)
            .unwrap_err()
            .to_string()
    };
    let dir = common::temp_dir("px4-export-missing");
    export(&log, &TOPICS[..4], &dir);
    let missing = message(&dir);
    assert!(
        missing.contains("battery_status[0]") && missing.contains("_battery_status_0.csv"),
        "{missing}"
    );
    assert!(!missing.contains('\n'), "{missing}");

    export(&log, &TOPICS[4..], &dir);
    let second = dir.join("other_battery_status_0.csv");
    std::fs::copy(dir.join("flight_battery_status_0.csv"), &second).unwrap();
    let twice = message(&dir);
    assert!(
        twice.contains("2 files end in _battery_status_0.csv"),
        "{twice}"
    );
    std::fs::remove_file(&second).unwrap();

    let battery = dir.join("flight_battery_status_0.csv");
    let text = edit_lines(&battery, |lines| lines.swap(5, 6));
    let unordered = message(&dir);
    assert!(
        unordered.contains("flight_battery_status_0.csv")
            && unordered.contains("7")
            && unordered.contains("in time order"),
        "{unordered}"
    );
    std::fs::write(&battery, text).unwrap();

    let attitude = dir.join("flight_vehicle_attitude_0.csv");
    edit_lines(&attitude, |lines| {
        lines[3] = lines[3].replacen(',', ".5,", 1)
    });
    let fraction = message(&dir);
    assert!(
        fraction.contains("flight_vehicle_attitude_0.csv")
            && fraction.contains("4")
            && fraction.contains("whole number of microseconds"),
        "{fraction}"
    );
}
