//! Recordings read through a layout description: units and frames converted, a header written as a
//! comment, bad layouts and files refused with the file and field named, and the public Crazyflie
//! flight read as its README describes it.

use std::path::Path;

use data::layout::{Frames, RecordingLayout, read_with_layout};

fn layout(json: &str) -> RecordingLayout {
    serde_json::from_str(json).unwrap()
}

const PX4_LIKE: &str = r#"{
  "time": {"column": "timestamp", "unit": "ms"},
  "frames": "ned_frd",
  "position": ["x", "y", "z"],
  "velocity": ["vx", "vy", "vz"],
  "quaternion": {"w": "q0", "x": "q1", "y": "q2", "z": "q3"},
  "body_rate": ["p", "q", "r"],
  "motor_commands": ["m1", "m2", "m3", "m4"],
  "battery_voltage": "volts"
}"#;

/// A row of a NED/FRD log: yaw `psi` about the down axis, level, at height `h`, climbing.
fn ned_row(k: usize, psi: f64, h: f64) -> String {
    let (w, z) = ((psi / 2.0).cos(), (psi / 2.0).sin());
    let t = 1000.0 + 10.0 * k as f64 + if k % 2 == 1 { 1.5 } else { 0.0 };
    format!(
        "{t},1.0,2.0,{},0.5,-0.25,-1.0,{w},0.0,0.0,{z},0.1,0.2,0.3,1500,1510,1490,1505,11.1\n",
        -h
    )
}

fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn a_ned_frd_log_reads_z_up_in_seconds_on_its_own_stamps() {
    let dir = tempfile::tempdir().unwrap();
    let mut text = String::from("timestamp,x,y,z,vx,vy,vz,q0,q1,q2,q3,p,q,r,m1,m2,m3,m4,volts\n");
    for k in 0..6 {
        text.push_str(&ned_row(k, 0.4, 2.0));
    }
    let path = write(dir.path(), "px4.csv", &text);
    let log = read_with_layout(&path, &layout(PX4_LIKE)).unwrap();
    assert_eq!(log.len(), 6);
    assert!((log.time[1] - log.time[0] - 0.0115).abs() < 1e-12);
    // Height up, climbing: z and vz change sign; the second axes too (north-west-up).
    assert_eq!(log.position[0], [1.0, -2.0, 2.0]);
    assert_eq!(log.velocity[0], [0.5, 0.25, 1.0]);
    assert_eq!(log.body_rate[0], [0.1, -0.2, -0.3]);
    // Level: the body's third axis (the thrust) points up; a yaw to the east in NED (clockwise
    // from above) is a yaw to the west in NWU (counter-clockwise from above, negative angle).
    let r = log.rotation[0];
    assert!((r[2][2] - 1.0).abs() < 1e-12);
    assert!((r[1][0] - (-0.4f64).sin()).abs() < 1e-12, "{r:?}");
    assert_eq!(log.motor_command.row(0), [1500.0, 1510.0, 1490.0, 1505.0]);
    assert_eq!(log.battery_voltage.as_ref().unwrap()[0], 11.1);
    assert_eq!(layout(PX4_LIKE).frames, Frames::NedFrd);
}

/// A layout without position reads the rest; the log says it holds no position.
#[test]
fn a_layout_without_position_reads_the_rest() {
    let dir = tempfile::tempdir().unwrap();
    let mut text = String::from("timestamp,x,y,z,vx,vy,vz,q0,q1,q2,q3,p,q,r,m1,m2,m3,m4,volts\n");
    for k in 0..6 {
        text.push_str(&ned_row(k, 0.4, 2.0));
    }
    let path = write(dir.path(), "px4.csv", &text);
    let without = PX4_LIKE.replace(r#""position": ["x", "y", "z"],"#, "");
    let log = read_with_layout(&path, &layout(&without)).unwrap();
    assert!(!log.position_logged());
    assert_eq!(log.velocity[0], [0.5, 0.25, 1.0]);
    assert_eq!(log.body_rate[0], [0.1, -0.2, -0.3]);
    assert_eq!(log.motor_command.row(0), [1500.0, 1510.0, 1490.0, 1505.0]);
    let with = read_with_layout(&path, &layout(PX4_LIKE)).unwrap();
    assert!(with.position_logged());
    assert_eq!(with.velocity, log.velocity);
    assert_eq!(with.quaternion, log.quaternion);
}

#[test]
fn a_header_written_as_a_comment_needs_its_prefix_declared() {
    let dir = tempfile::tempdir().unwrap();
    let mut text = String::from("# timestamp,x,y,z,vx,vy,vz,q0,q1,q2,q3,p,q,r,m1,m2,m3,m4,volts\n");
    for k in 0..6 {
        text.push_str(&ned_row(k, 0.0, 1.0));
    }
    let path = write(dir.path(), "commented.csv", &text);
    let plain = read_with_layout(&path, &layout(PX4_LIKE))
        .unwrap_err()
        .to_string();
    assert!(
        plain.contains("commented.csv:1") && plain.contains("comment"),
        "{plain}"
    );
    let with_prefix = PX4_LIKE.replacen('{', "{\"header_prefix\": \"# \",", 1);
    assert_eq!(
        read_with_layout(&path, &layout(&with_prefix))
            .unwrap()
            .len(),
        6
    );
    let wrong = PX4_LIKE.replacen('{', "{\"header_prefix\": \"% \",", 1);
    let message = read_with_layout(&path, &layout(&wrong))
        .unwrap_err()
        .to_string();
    assert!(message.contains("header_prefix"), "{message}");
}

#[test]
fn bad_layouts_and_cells_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let unknown = write(
        dir.path(),
        "layout.json",
        &PX4_LIKE.replacen('{', "{\"colour\": 1,", 1),
    );
    let message = RecordingLayout::load(&unknown).unwrap_err().to_string();
    assert!(
        message.contains("layout.json") && message.contains("colour"),
        "{message}"
    );
    let mut text = String::from("timestamp,x,y,z,vx,vy,vz,q0,q1,q2,q3,p,q,r,m1,m2,m3,m4,volts\n");
    for k in 0..6 {
        text.push_str(&ned_row(k, 0.0, 1.0));
    }
    let half_quaternion = text.replacen(",1,0.0,0.0,0,", ",0.5,0.0,0.0,0,", 1);
    let path = write(dir.path(), "bad.csv", &half_quaternion);
    let message = read_with_layout(&path, &layout(PX4_LIKE))
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("bad.csv:2") && message.contains("q0"),
        "{message}"
    );
    let runaway = text.replacen(",0.5,-0.25,-1.0,", ",5e9,-0.25,-1.0,", 1);
    let path = write(dir.path(), "runaway.csv", &runaway);
    let message = read_with_layout(&path, &layout(PX4_LIKE))
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("runaway.csv:2") && message.contains("vx"),
        "{message}"
    );
    let missing = PX4_LIKE.replace("\"volts\"", "\"vbat\"");
    let path = write(dir.path(), "ok.csv", &text);
    let message = read_with_layout(&path, &layout(&missing))
        .unwrap_err()
        .to_string();
    assert!(message.contains("vbat"), "{message}");
}

/// The public Crazyflie flight through the layout in `experiments/layouts/`: its README's time unit
/// (µs), its jitter (9–11 ms) and its command range (a fraction of 65536, times the scale).
#[test]
fn the_crazyflie_flight_reads_as_its_readme_describes() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let Some(path) = data::shared_file_for_tests(&root, "crazyflie", "randomwalk_l_cf102_01.csv")
    else {
        return;
    };
    let layout =
        RecordingLayout::load(&root.join("experiments/layouts/crazyflie-neural-swarm.json"))
            .unwrap();
    let log = read_with_layout(&path, &layout).unwrap();
    let intervals: Vec<f64> = log.time.windows(2).map(|w| w[1] - w[0]).collect();
    let mut sorted = intervals.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    assert!((0.0095..0.0105).contains(&median), "{median}");
    let duration = log.time[log.len() - 1] - log.time[0];
    assert!((55.0..70.0).contains(&duration), "{duration}");
    let commands = log.motor_command.rows().flatten();
    assert!(commands.clone().all(|c| (0.0..=65536.0).contains(c)));
    assert!(commands.clone().any(|c| *c > 30000.0));
    let heights = log.position.iter().map(|p| p[2]);
    assert!(heights.clone().all(|z| (0.0..0.5).contains(&z)));
    let volts = log.battery_voltage.unwrap();
    assert!(volts.iter().all(|v| (3.0..4.3).contains(v)));
}

/// A thrust setpoint logged down the FRD body axis reads scaled to the upward `T_sp`, with its
/// hover throttle; the rows asked for are taken before the checks, so an implausible hover estimate
/// after them (a ULog's NaN after landing, here a zero) is left out, and one inside them is named
/// with its line.
#[test]
fn a_thrust_setpoint_is_scaled_and_the_rows_are_taken_before_the_checks() {
    let dir = tempfile::tempdir().unwrap();
    let header = "timestamp,x,y,z,vx,vy,vz,q0,q1,q2,q3,p,q,r,m1,m2,m3,m4,volts,tz,hover\n";
    let mut text = String::from(header);
    for k in 0..8 {
        let row = ned_row(k, 0.0, 1.0);
        let hover = if k == 7 { "0" } else { "0.42" };
        text.push_str(&format!("{},-0.45,{hover}\n", row.trim_end()));
    }
    let path = write(dir.path(), "thrust.csv", &text);
    let with_setpoint = PX4_LIKE.replacen(
        '{',
        r#"{"thrust_setpoint": {"column": "tz", "scale": -1.0}, "hover_throttle": "hover","#,
        1,
    );
    let layout = layout(&with_setpoint);
    let log = data::layout::read_rows_with_layout(&path, &layout, Some(0..7)).unwrap();
    assert_eq!(log.len(), 7);
    assert_eq!(log.thrust_setpoint[0], 0.45);
    assert_eq!(log.hover_throttle[6], 0.42);
    let whole = read_with_layout(&path, &layout).unwrap_err().to_string();
    assert!(
        whole.contains("thrust.csv:9")
            && whole.contains("hover")
            && whole.contains("hover throttle"),
        "{whole}"
    );
    let past = data::layout::read_rows_with_layout(&path, &layout, Some(2..9))
        .unwrap_err()
        .to_string();
    assert!(
        past.contains("rows 2:9 reach past its 8 data rows"),
        "{past}"
    );
}

/// A thrust setpoint without the hover throttle it is divided by is refused when the layout loads.
#[test]
fn a_thrust_setpoint_needs_its_hover_throttle() {
    let dir = tempfile::tempdir().unwrap();
    let text = PX4_LIKE.replacen('{', r#"{"thrust_setpoint": {"column": "tz"},"#, 1);
    let path = write(dir.path(), "layout.json", &text);
    let error = RecordingLayout::load(&path).unwrap_err().to_string();
    assert!(
        error.contains("layout.json")
            && error.contains("thrust_setpoint")
            && error.contains("hover_throttle"),
        "{error}"
    );
}

/// A hexarotor's log: six motor command columns read in the layout's order; a layout of nine (or
/// none) is refused naming its field.
#[test]
fn a_hexarotor_log_reads_its_six_motor_commands() {
    let dir = tempfile::tempdir().unwrap();
    let six = PX4_LIKE.replace(
        r#"["m1", "m2", "m3", "m4"]"#,
        r#"["m1", "m2", "m3", "m4", "m5", "m6"]"#,
    );
    let mut text =
        String::from("timestamp,x,y,z,vx,vy,vz,q0,q1,q2,q3,p,q,r,m1,m2,m3,m4,volts,m5,m6\n");
    for k in 0..6 {
        text.push_str(&ned_row(k, 0.0, 1.0).replace('\n', ",1400,1600\n"));
    }
    let path = write(dir.path(), "hexa.csv", &text);
    let log = read_with_layout(&path, &layout(&six)).unwrap();
    assert_eq!(log.motor_command.count(), 6);
    assert_eq!(
        log.motor_command.row(5),
        [1500.0, 1510.0, 1490.0, 1505.0, 1400.0, 1600.0]
    );
    let nine = six.replace(r#""m6"]"#, r#""m6", "m7", "m8", "m9"]"#);
    let file = write(dir.path(), "nine.json", &nine);
    let message = RecordingLayout::load(&file).unwrap_err().to_string();
    assert!(
        message.contains("nine.json")
            && message.contains("motor_commands")
            && message.contains("9 columns; expected 1 to 8"),
        "{message}"
    );
    let none = six.replace(r#"["m1", "m2", "m3", "m4", "m5", "m6"]"#, "[]");
    let message = read_with_layout(&path, &layout(&none))
        .unwrap_err()
        .to_string();
    assert!(message.contains("motor_commands"), "{message}");
}
