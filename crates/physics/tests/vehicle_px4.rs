//! Vehicle descriptions from PX4's airframe parameters: both public logs of `data/ulog` (a link to
//! `../shared/data/ulog` made by `make data`; without them the tests skip, except under CI), and
//! parameter maps written here for the errors.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use physics::vehicle::px4::inspect_airframe;
use physics::{Layout, Spin, VehicleDescription};

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn parameters(file: &str) -> Option<data::ulog::ParameterTable> {
    let path = data::ulog_file_for_tests(&workspace(), file)?;
    let log = ulog::Log::read(&path).unwrap_or_else(|e| panic!("{e}"));
    Some(data::ulog::parameter_table(&log))
}

#[test]
fn the_jmavsim_log_carries_the_3dr_iris_geometry_of_its_airframe_script() {
    let Some(table) = parameters("sample_px4_events.ulg") else {
        return;
    };
    let vehicle = VehicleDescription::from_px4_parameters(&table.values).unwrap();
    // CA_ROTOR0 (0.1515, 0.245) FRD is front right: y = −0.245 in FLU.
    let positions: Vec<[f64; 3]> = vehicle.rotors.iter().map(|r| r.position_m).collect();
    let expected = [
        [0.1515, -0.245, 0.0],
        [-0.1515, 0.1875, 0.0],
        [0.1515, 0.245, 0.0],
        [-0.1515, -0.1875, 0.0],
    ];
    for (got, want) in positions.iter().zip(expected) {
        for (g, w) in got.iter().zip(want) {
            assert!((g - w).abs() < 1e-6, "{positions:?}");
        }
    }
    let spins: Vec<Spin> = vehicle.rotors.iter().map(|r| r.spin).collect();
    use Spin::*;
    assert_eq!(
        spins,
        [CounterClockwise, CounterClockwise, Clockwise, Clockwise]
    );
    assert!(vehicle.rotors.iter().all(|r| r.axis == [0.0, 0.0, 1.0]));
    let inspection = inspect_airframe(&table).unwrap().unwrap();
    assert_eq!(inspection.airframe, Some(10017));
    assert_eq!(inspection.layout, Layout::QuadXUnequalArms);
    assert_eq!(inspection.allocation_rank, 4);
    assert_eq!(inspection.thrust_model_factor, 0.0);
    // Front arms 0.288 m, rear 0.241 m: not jMAVSim's 0.165 m X (its README).
    let arms = &inspection.arm_lengths_m;
    assert!(
        (arms[0] - 0.2880).abs() < 1e-4 && (arms[1] - 0.2411).abs() < 1e-4,
        "{arms:?}"
    );
    assert!(
        inspection
            .thrust_coefficients_n
            .iter()
            .all(|&ct| (ct - 6.5).abs() < 1e-6)
    );
    assert!(
        inspection
            .moment_ratios_m
            .iter()
            .all(|&km| (km - 0.05).abs() < 1e-6)
    );
    // Every CA_ROTOR* is the airframe's default, CT and |KM| are PX4's built-in ones.
    assert!(inspection.defaults.declared);
    assert!(
        inspection.defaults.set_for_vehicle.is_empty(),
        "{:?}",
        inspection.defaults
    );
    assert!(inspection.defaults.builtin_coefficients);
}

#[test]
fn the_real_flight_carries_the_unit_geometry_of_px4s_generic_quad() {
    let Some(table) = parameters("quadrotor_local.ulg") else {
        return;
    };
    let inspection = inspect_airframe(&table).unwrap().unwrap();
    assert_eq!(inspection.airframe, Some(4001));
    assert_eq!(inspection.layout, Layout::QuadX);
    // (±1, ±1) m: √2 m arms, a placeholder geometry (PX4's allocation normalises the scale).
    for arm in &inspection.arm_lengths_m {
        assert!(
            (arm - 2f64.sqrt()).abs() < 1e-6,
            "{:?}",
            inspection.arm_lengths_m
        );
    }
    assert!(inspection.defaults.declared);
    assert!(inspection.defaults.set_for_vehicle.is_empty());
    assert!(inspection.defaults.builtin_coefficients);
}

fn quad_parameters() -> BTreeMap<String, f64> {
    let mut values = BTreeMap::from([("CA_ROTOR_COUNT".to_string(), 4.0)]);
    for (i, (x, y, km)) in [
        (1.0, 1.0, 0.05),
        (-1.0, -1.0, 0.05),
        (1.0, -1.0, -0.05),
        (-1.0, 1.0, -0.05),
    ]
    .into_iter()
    .enumerate()
    {
        values.insert(format!("CA_ROTOR{i}_PX"), x * 0.1);
        values.insert(format!("CA_ROTOR{i}_PY"), y * 0.1);
        values.insert(format!("CA_ROTOR{i}_KM"), km);
        values.insert(format!("CA_ROTOR{i}_CT"), 6.5);
    }
    values
}

#[test]
fn px4_parameters_make_the_same_quad_as_the_constructor() {
    let mut values = quad_parameters();
    values.insert("THR_MDL_FAC".into(), 0.3);
    let read = VehicleDescription::from_px4_parameters(&values).unwrap();
    let built = VehicleDescription::quad_x(0.1 * 2f64.sqrt(), 6.5, 0.05).unwrap();
    let (a, b) = (read.allocation().rows(), built.allocation().rows());
    for (ra, rb) in a.iter().zip(&b) {
        for (x, y) in ra.iter().zip(rb) {
            assert!((x - y).abs() < 1e-12, "{a:?} against {b:?}");
        }
    }
    assert_eq!(read.command_map, physics::CommandMap::px4(0.3));
    // A tilted axis: AX = 1, AZ = 0 points forward (FRD x is FLU x).
    values.insert("CA_ROTOR0_AX".into(), 1.0);
    values.insert("CA_ROTOR0_AZ".into(), 0.0);
    let tilted = VehicleDescription::from_px4_parameters(&values).unwrap();
    assert_eq!(tilted.rotors[0].axis, [1.0, 0.0, 0.0]);
}

#[test]
fn missing_or_bad_parameters_are_named() {
    let error = |values: &BTreeMap<String, f64>| {
        VehicleDescription::from_px4_parameters(values)
            .unwrap_err()
            .to_string()
    };
    let mut values = quad_parameters();
    values.remove("CA_ROTOR2_PY");
    assert_eq!(error(&values), "PX4 parameter CA_ROTOR2_PY: missing");
    let mut values = quad_parameters();
    values.insert("CA_ROTOR_COUNT".into(), 0.0);
    assert!(error(&values).starts_with("PX4 parameter CA_ROTOR_COUNT: 0 is not a rotor count"));
    let mut values = quad_parameters();
    values.insert("CA_ROTOR1_CT".into(), 0.0);
    assert!(error(&values).starts_with("PX4 parameter CA_ROTOR1_CT:"));
    let mut values = quad_parameters();
    values.insert("THR_MDL_FAC".into(), 2.0);
    assert!(error(&values).starts_with("PX4 parameter THR_MDL_FAC:"));
    let mut values = quad_parameters();
    values.insert("CA_ROTOR3_PX".into(), f64::NAN);
    assert!(error(&values).starts_with("PX4 parameter CA_ROTOR3_PX: NaN"));
    assert!(error(&BTreeMap::new()).starts_with("PX4 parameter CA_ROTOR_COUNT: missing"));
    // No CA_ROTOR_COUNT: no airframe section, not an error.
    let table = data::ulog::ParameterTable::default();
    assert_eq!(inspect_airframe(&table).unwrap(), None);
}

#[test]
fn parameters_set_for_the_vehicle_are_told_from_airframe_defaults() {
    let values = quad_parameters();
    // PX4 logs a default only where the value differs: here CA_ROTOR0_PX was changed.
    let table = data::ulog::ParameterTable {
        system_defaults: Some(BTreeMap::from([("CA_ROTOR0_PX".into(), 0.0)])),
        airframe_defaults: Some(BTreeMap::from([("CA_ROTOR0_PX".into(), 0.15)])),
        values,
    };
    let inspection = inspect_airframe(&table).unwrap().unwrap();
    assert_eq!(inspection.defaults.set_for_vehicle, ["CA_ROTOR0_PX"]);
    assert!(inspection.defaults.builtin_coefficients);
    let undeclared = data::ulog::ParameterTable {
        system_defaults: None,
        airframe_defaults: None,
        ..table
    };
    assert!(
        !inspect_airframe(&undeclared)
            .unwrap()
            .unwrap()
            .defaults
            .declared
    );
}
