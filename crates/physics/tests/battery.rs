//! A vehicle whose thrust depends on the battery voltage, flown by the simulator: the log carries
//! the voltage the battery model gives, and each logged command, read through the vehicle's map at
//! the logged voltage, gives the thrust the controller asked for.

mod common;

use physics::{Battery, NominalModel, Scenario, simulate};

fn vehicle_model() -> NominalModel {
    NominalModel::load(&common::workspace().join("experiments/mismatch/vehicles/quad-voltage.json"))
        .unwrap()
}

fn scenario(battery: Option<Battery>) -> Scenario {
    Scenario {
        battery,
        ..Scenario::figure_eight("quad-voltage.json", 5)
    }
}

#[test]
fn the_log_carries_the_voltage_and_the_commands_give_the_thrust_asked_for() {
    let model = vehicle_model();
    let battery = Battery {
        voltage_v: 16.4,
        drop_v_per_s: 0.01,
        sag_v_per_n: 0.02,
    };
    let log = simulate(&model, &scenario(Some(battery)), "voltage").unwrap();
    let volts = log.battery_voltage.as_ref().expect("a battery is logged");
    let weight = model.mass_kg * model.gravity_m_s2;
    for k in [0, log.len() / 2, log.len() - 1] {
        // The commanded thrust from T_sp (hover throttle 0.5) and the battery's law at that load
        // (the sag follows the previous control step's thrust, within a newton of this one's).
        let thrust = log.thrust_setpoint[k] / 0.5 * weight;
        let expected = battery.voltage(log.time[k], thrust);
        assert!(
            (volts[k] - expected).abs() < battery.sag_v_per_n,
            "row {k}: {} {expected}",
            volts[k]
        );
        let actuators = model.actuator_command(0.0, 1.0, log.motor_command.row(k), Some(volts[k]));
        let from_commands = model.wrench(&actuators).thrust;
        assert!(
            (from_commands - thrust).abs() < 1e-6 * weight,
            "row {k}: {from_commands} {thrust}"
        );
    }
    // The same commands read at the battery's start voltage give another thrust: the map's
    // voltage is not a formality.
    let last = log.len() - 1;
    let start = model.actuator_command(0.0, 1.0, log.motor_command.row(last), Some(16.4));
    let at_end = model.actuator_command(0.0, 1.0, log.motor_command.row(last), Some(volts[last]));
    assert!(model.wrench(&start).thrust > 1.03 * model.wrench(&at_end).thrust);
    let csv = log.csv_text();
    assert!(
        csv.lines()
            .next()
            .unwrap()
            .ends_with(",pwm,battery_voltage")
    );
}

#[test]
fn a_voltage_map_needs_a_battery_and_a_battery_must_last() {
    let model = vehicle_model();
    let message = simulate(&model, &scenario(None), "none")
        .unwrap_err()
        .to_string();
    assert!(message.contains("battery"), "{message}");
    let flat = Battery {
        voltage_v: 10.0,
        drop_v_per_s: 1.0,
        sag_v_per_n: 0.0,
    };
    let message = simulate(&model, &scenario(Some(flat)), "flat")
        .expect_err("refused")
        .to_string();
    assert!(
        message.contains("'battery'") && message.contains("below half"),
        "{message}"
    );
    let negative = Battery {
        sag_v_per_n: -0.1,
        ..flat
    };
    let message = simulate(&model, &scenario(Some(negative)), "negative")
        .unwrap_err()
        .to_string();
    assert!(message.contains("battery.sag_v_per_n"), "{message}");
}
