//! Every example vehicle description in `experiments/vehicles/` reads, is controllable (allocation
//! rank 4) and is the layout it says; the Crazyflie's thrust map gives the firmware's per-motor
//! force of a logged row; the PX4 airframe example is what the sample log's parameters say.

use std::path::{Path, PathBuf};

use physics::{Layout, VehicleDescription};

fn examples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../experiments/vehicles")
}

fn load(name: &str) -> VehicleDescription {
    VehicleDescription::load(&examples().join(name)).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn every_example_reads_and_is_controllable() {
    let mut names: Vec<String> = std::fs::read_dir(examples())
        .unwrap()
        .map(|entry| entry.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name.ends_with(".json"))
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "crazyflie-2.1-parrot.json",
            "hexa-plus.json",
            "jmavsim-iris.json",
            "px4-airframe-10017.json"
        ]
    );
    for name in &names {
        let vehicle = load(name);
        assert_eq!(vehicle.allocation().rank(), 4, "{name}");
        // What is written is what is read back.
        let again = VehicleDescription::from_json(&vehicle.to_json(), Path::new(name)).unwrap();
        assert_eq!(again, vehicle, "{name}");
    }
    assert_eq!(load("jmavsim-iris.json").layout(), Layout::QuadX);
    assert_eq!(load("crazyflie-2.1-parrot.json").layout(), Layout::QuadX);
    assert_eq!(load("hexa-plus.json").layout(), Layout::HexaPlus);
    assert_eq!(
        load("px4-airframe-10017.json").layout(),
        Layout::QuadXUnequalArms
    );
}

#[test]
fn jmavsim_hovers_at_about_px4s_hover_throttle() {
    // 0.8 kg (jMAVSim) at 9.81 m/s²: 1.962 N per rotor of 4.0 N at full command, linear.
    let vehicle = load("jmavsim-iris.json");
    let wrench = vehicle.wrench(&[0.4905; 4], None).unwrap();
    assert!((wrench[0] - 0.8 * 9.81).abs() < 1e-9, "{wrench:?}");
    assert!(wrench[1..].iter().all(|t| t.abs() < 1e-12), "{wrench:?}");
}

#[test]
fn the_crazyflie_map_gives_the_logged_motor_forces() {
    // First row of randomwalk_l_cf102_01.csv (shared/data/crazyflie): u1..u4[PWM] as fractions,
    // Vbat 3.832 V, and the firmware's u1..u4[N]; the upstream fit (score 0.995) is within 2 %.
    let vehicle = load("crazyflie-2.1-parrot.json");
    let fractions = [0.565765, 0.668747, 0.609375, 0.599365];
    let logged_n = [0.143619, 0.18313, 0.159379, 0.15565];
    let commands = fractions.map(|p| p * 65536.0);
    let thrusts = vehicle.rotor_thrusts(&commands, Some(3.832)).unwrap();
    for (thrust, logged) in thrusts.iter().zip(logged_n) {
        let ratio = thrust / logged;
        assert!(
            (0.98..=1.0).contains(&ratio),
            "{thrusts:?} against {logged_n:?}"
        );
    }
    // The same commands on a fuller battery push harder.
    let full = vehicle.rotor_thrusts(&commands, Some(4.2)).unwrap();
    assert!(full.iter().zip(&thrusts).all(|(f, t)| f > t));
    assert!(vehicle.rotor_thrusts(&commands, None).is_err());
}

#[test]
fn the_px4_example_is_what_the_sample_log_says() {
    let workspace = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let Some(path) = data::ulog_file_for_tests(&workspace, "sample_px4_events.ulg") else {
        return;
    };
    let log = ulog::Log::read(&path).unwrap();
    let read =
        VehicleDescription::from_px4_parameters(&data::ulog::parameter_table(&log).values).unwrap();
    let example = load("px4-airframe-10017.json");
    assert_eq!(read.command_map, example.command_map);
    for (a, b) in read.rotors.iter().zip(&example.rotors) {
        assert_eq!(a.spin, b.spin);
        for (x, y) in a.position_m.iter().zip(&b.position_m) {
            assert!((x - y).abs() < 1e-6, "{a:?} against {b:?}");
        }
        assert!((a.thrust_coefficient_n - b.thrust_coefficient_n).abs() < 1e-6);
        assert!((a.moment_ratio_m - b.moment_ratio_m).abs() < 1e-6);
    }
}
