//! `learn data inspect FILE.ulg` on the two public PX4 logs of `data/ulog` (a link to
//! `../shared/data/ulog` made by `make data`; without them the tests skip, except under CI): the
//! vehicle, the airborne time, each analysis topic's rates; a truncated copy is read up to its
//! last whole message and says so; a corrupt one is a one-line error naming the file and offset.

mod common;

use std::path::PathBuf;

use common::{learn_in, scratch, workspace};

/// The log `file` of `data/ulog` (absolute), or `None` (skipping) where the logs are absent
/// outside CI.
fn log_file(file: &str) -> Option<PathBuf> {
    data::ulog_file_for_tests(&workspace(), file).map(|path| path.canonicalize().unwrap())
}

fn inspect(path: &std::path::Path) -> String {
    let dir = scratch("ulog-inspect");
    learn_in(&dir, &["data", "inspect", path.to_str().unwrap()])
        .success()
        .to_string()
}

fn assert_lines(text: &str, expected: &[&str]) {
    for line in expected {
        assert!(
            text.lines().any(|l| l == *line),
            "{line:?} missing from:\n{text}"
        );
    }
}

#[test]
fn the_simulated_flight_is_described() {
    let Some(path) = log_file("sample_px4_events.ulg") else {
        return;
    };
    assert_lines(
        &inspect(&path),
        &[
            "vehicle:   PX4 on PX4_SITL, software cb09dde606861b90e38b1682eebd3fd91be17ab7, airframe 10017, 4 rotors",
            // The 3DR Iris geometry of the airframe's script, not jMAVSim's 0.165 m X.
            "airframe:  4 rotors, quad X with unequal front and rear arms; arms 0.288, 0.241, 0.288, 0.241 m; km 0.050 m (ccw, ccw, cw, cw); CT 6.50 N; THR_MDL_FAC 0; allocation rank 4 of 4",
            "           CA_ROTOR* are the airframe defaults of SYS_AUTOSTART 10017: the geometry may not be this vehicle's",
            "           CT and |KM| are PX4's built-in defaults: thrust and moment coefficients not measured on this vehicle",
            "airborne:  11.4 s (16.7-28.1 s)",
            "dropouts:  0 (0 ms in all, longest 0 ms)",
            "  actuator_motors[0]: 313 samples, logged at 10.0 Hz; step 100.0 ms (5-95%: 100.0-100.0)",
            "      control[0], control[1], control[2], control[3]: new every sample (~10.0 Hz)",
            "  vehicle_angular_velocity[0]: 1558 samples, logged at 50.0 Hz; step 20.0 ms (5-95%: 20.0-20.0)",
            // The simulated battery discharges linearly: a line between rare knots.
            "      voltage_v: interpolated, knots at ~0.1 Hz",
            "absent:    wind",
            "limits:    motor commands new at ~10.0 Hz (actuator_motors[0]): delays and motor lags shorter than ~0.100 s cannot be identified from this log (PX4's high-rate SDLOG_PROFILE logs actuator topics faster)",
        ],
    );
}

#[test]
fn the_real_flight_is_described() {
    let Some(path) = log_file("quadrotor_local.ulg") else {
        return;
    };
    assert_lines(
        &inspect(&path),
        &[
            "vehicle:   PX4 on PX4_FMU_V6C, software v1.16.1 (RC), airframe 4001, 4 rotors",
            // PX4's generic quad: a unit placeholder geometry.
            "airframe:  4 rotors, quad X; arms 1.414 m; km 0.050 m (ccw, ccw, cw, cw); CT 6.50 N; THR_MDL_FAC 0; allocation rank 4 of 4",
            "           CA_ROTOR* are the airframe defaults of SYS_AUTOSTART 4001: the geometry may not be this vehicle's",
            "airborne:  85.6 s (5.2-90.8 s)",
            "  vehicle_local_position[0]: 926 samples, logged at 10.1 Hz; step 98.9 ms (5-95%: 94.4-107.9)",
            "      x, y, z, vx, vy, vz, ax, ay, az: new every sample (~10.0 Hz)",
            "  actuator_outputs[1]: 1 samples, logged at ? Hz",
            "limits:    motor commands new at ~10.0 Hz (actuator_motors[0]): delays and motor lags shorter than ~0.100 s cannot be identified from this log (PX4's high-rate SDLOG_PROFILE logs actuator topics faster)",
        ],
    );
}

#[test]
fn a_truncated_log_is_read_up_to_its_last_whole_message() {
    let Some(path) = log_file("sample_px4_events.ulg") else {
        return;
    };
    let dir = scratch("ulog-truncated");
    let bytes = std::fs::read(&path).unwrap();
    let cut = dir.join("cut.ulg");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let text = inspect(&cut);
    let line = text
        .lines()
        .find(|l| l.starts_with("truncated: "))
        .expect(&text);
    assert!(line.contains("the rest was read"), "{line}");
}

#[test]
fn a_corrupt_log_is_a_one_line_error_naming_file_and_offset() {
    let Some(path) = log_file("sample_px4_events.ulg") else {
        return;
    };
    let dir = scratch("ulog-corrupt");
    let mut bytes = std::fs::read(&path).unwrap();
    bytes[18] = 0; // the type of the first message (the flag bits, at byte 16)
    std::fs::write(dir.join("bad.ulg"), &bytes).unwrap();
    learn_in(&dir, &["data", "inspect", "bad.ulg"])
        .one_line_error(&["bad.ulg: byte 16: message type 0x00"]);
    std::fs::write(dir.join("short.ulg"), b"ULog\x01\x12\x35").unwrap();
    learn_in(&dir, &["data", "inspect", "short.ulg"])
        .one_line_error(&["short.ulg: byte 0: the file ends inside its 16-byte header"]);
}

/// `learn sindy` reads a ULog's columns on one topic's clock and says which were held, and how
/// long; a field the log lacks is a one-line error naming the file and the column.
#[test]
fn sindy_fits_ulog_columns_on_one_clock() {
    let Some(path) = log_file("sample_px4_events.ulg") else {
        return;
    };
    let dir = scratch("ulog-sindy");
    let log = path.to_str().unwrap();
    let rates = "vehicle_angular_velocity.xyz[0],vehicle_angular_velocity.xyz[1]";
    let controls = "vehicle_torque_setpoint.xyz[0],actuator_motors.control[0]";
    let run = learn_in(
        &dir,
        &[
            "sindy",
            "--csv",
            log,
            "--state",
            rates,
            "--control",
            controls,
        ],
    );
    let text = run.success();
    assert_lines(
        text,
        &[
            &format!("{log}: 1558 rows on the clock of vehicle_angular_velocity[0]"),
            "  vehicle_torque_setpoint.xyz[0] held from its 50.0 Hz samples (at most 0.004 s)",
            "  actuator_motors.control[0] held from its 10.0 Hz samples (at most 0.080 s)",
        ],
    );
    assert!(
        text.contains("vehicle_angular_velocity.xyz[1]' = "),
        "{text}"
    );
    let run = learn_in(
        &dir,
        &[
            "sindy",
            "--csv",
            log,
            "--state",
            "vehicle_angular_velocity.rate",
        ],
    );
    run.one_line_error(&[&format!(
        "{log}: vehicle_angular_velocity.rate: topic vehicle_angular_velocity has no field 'rate'"
    )]);
}

/// `--vehicle-out` writes the description the airframe parameters give (the workspace's example
/// of airframe 10017), never over an existing file without `--force`, and only for a ULog.
#[test]
fn the_airframe_parameters_are_written_as_a_vehicle_description() {
    let Some(path) = log_file("sample_px4_events.ulg") else {
        return;
    };
    let dir = scratch("ulog-vehicle-out");
    let log = path.to_str().unwrap();
    let run = learn_in(&dir, &["data", "inspect", log, "--vehicle-out", "v.json"]);
    let text = run.success().to_string();
    assert!(
        text.contains("wrote v.json (4 rotors, quad X with unequal front and rear arms)"),
        "{text}"
    );
    let written = physics::VehicleDescription::load(&dir.join("v.json")).unwrap();
    let example = physics::VehicleDescription::load(
        &workspace().join("experiments/vehicles/px4-airframe-10017.json"),
    )
    .unwrap();
    assert_eq!(written.command_map, example.command_map);
    for (a, b) in written.rotors.iter().zip(&example.rotors) {
        assert_eq!(a.spin, b.spin);
        for (x, y) in a.position_m.iter().zip(&b.position_m) {
            assert!((x - y).abs() < 1e-6, "{a:?} against {b:?}");
        }
    }
    let again = learn_in(&dir, &["data", "inspect", log, "--vehicle-out", "v.json"]);
    again.one_line_error(&["v.json", "--force"]);
    std::fs::write(dir.join("flight.csv"), "t\n0\n").unwrap();
    let csv = learn_in(
        &dir,
        &["data", "inspect", "flight.csv", "--vehicle-out", "w.json"],
    );
    csv.one_line_error(&["flight.csv", "--vehicle-out", "not a .ulg"]);
    assert!(!dir.join("w.json").exists());
}

/// `learn sindy` reads a PX4 log exported to CSV (a folder of `<log>_<topic>_<k>.csv` files, each
/// with its own µs `timestamp`) as it reads the `.ulg`: a 100 Hz state decaying as `e^(−t)` and a
/// 20 Hz control held as of each of its rows.
#[test]
fn sindy_fits_the_columns_of_a_csv_export_on_one_clock() {
    let dir = scratch("ulog-csv-export");
    let export = dir.join("export");
    std::fs::create_dir(&export).unwrap();
    let mut rate = String::from("timestamp,x\n");
    let mut command = String::from("timestamp,u\n");
    for k in 0..400 {
        let t_us = 1_000_000 + 10_000 * k;
        rate.push_str(&format!("{t_us},{:?}\n", (-(k as f64) * 0.01).exp()));
        if k % 5 == 0 {
            command.push_str(&format!("{t_us},{:?}\n", 0.5 + 0.1 * ((k / 5) % 2) as f64));
        }
    }
    std::fs::write(export.join("flight_rate_0.csv"), rate).unwrap();
    std::fs::write(export.join("flight_command_0.csv"), command).unwrap();
    let sindy = |control: &str| {
        learn_in(
            &dir,
            &[
                "sindy",
                "--csv",
                "export",
                "--state",
                "rate.x",
                "--control",
                control,
            ],
        )
    };
    let run = sindy("command.u");
    let text = run.success();
    assert_lines(
        text,
        &[
            "export: 400 rows on the clock of rate[0]",
            "  command.u held from its 20.0 Hz samples (at most 0.040 s)",
        ],
    );
    assert!(text.contains("rate.x' = -1.000 rate.x"), "{text}");
    sindy("motor.u").one_line_error(&["export: motor[0]: no file named <log>_motor_0.csv"]);
}
