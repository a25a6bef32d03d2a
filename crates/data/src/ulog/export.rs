//! A flight log written as a PX4 ULog: the topics and frames PX4 logs (north-east-down world,
//! forward-right-down body), so that a log of known physics takes the whole ULog path — the
//! reader, a layout description, the as-of join — as a real autopilot's log does.

use ulog::writer::{Sample, TopicFormat, write};

use crate::flight_log::FlightLog;

/// The topics written, in this order, and what each holds (all at every row's time):
/// `vehicle_local_position` (`x, y, z, vx, vy, vz`, NED), `vehicle_attitude` (`q`, body FRD to
/// NED, `w` first), `vehicle_angular_velocity` (`xyz`, FRD), `actuator_outputs` (`output`, the
/// four motor commands as logged), `vehicle_thrust_setpoint` (`xyz`, FRD: the thrust setpoint
/// along −z) and `hover_thrust_estimate` (`hover_thrust`).
fn topics(motors: usize, battery: bool) -> Vec<TopicFormat> {
    let topic = |name: &str, fields: &[(&str, usize)]| TopicFormat {
        name: name.to_string(),
        fields: fields.iter().map(|(f, n)| (f.to_string(), *n)).collect(),
    };
    let mut topics = vec![
        topic(
            "vehicle_local_position",
            &[
                ("x", 1),
                ("y", 1),
                ("z", 1),
                ("vx", 1),
                ("vy", 1),
                ("vz", 1),
            ],
        ),
        topic("vehicle_attitude", &[("q", 4)]),
        topic("vehicle_angular_velocity", &[("xyz", 3)]),
        topic("actuator_outputs", &[("output", motors)]),
        topic("vehicle_thrust_setpoint", &[("xyz", 3)]),
        topic("hover_thrust_estimate", &[("hover_thrust", 1)]),
    ];
    if battery {
        topics.push(topic("battery_status", &[("voltage_v", 1)]));
    }
    topics
}

/// When the written log's logging starts, µs (the rows' times count from it).
pub const START_TIME_US: u64 = 1_000_000;

/// The bytes of `log` as a ULog (see [`topics`]); each row's time is `START_TIME_US` plus its
/// time in whole microseconds. Fails on a time before zero or a message the format cannot hold.
pub fn flight_log_as_ulog(log: &FlightLog) -> Result<Vec<u8>, String> {
    let mut samples = Vec::with_capacity(7 * log.len());
    for k in 0..log.len() {
        let t = log.time[k];
        if !(t >= 0.0 && t.is_finite()) {
            return Err(format!("row {k}: time {t} s is before the log's start"));
        }
        let time_us = START_TIME_US + (t * 1e6).round() as u64;
        // North-west-up / forward-left-up to north-east-down / forward-right-down.
        let ned = |v: [f64; 3]| [v[0], -v[1], -v[2]];
        let [px, py, pz] = ned(log.position[k]);
        let [vx, vy, vz] = ned(log.velocity[k]);
        let [x, y, z, w] = log.quaternion[k];
        let mut rows: Vec<Vec<f64>> = vec![
            vec![px, py, pz, vx, vy, vz],
            vec![w, x, -y, -z],
            ned(log.body_rate[k]).to_vec(),
            log.motor_command.row(k).to_vec(),
            vec![0.0, 0.0, -log.thrust_setpoint[k]],
            vec![log.hover_throttle[k]],
        ];
        if let Some(volts) = &log.battery_voltage {
            rows.push(vec![volts[k]]);
        }
        for (topic, values) in rows.into_iter().enumerate() {
            samples.push(Sample {
                topic,
                time_us,
                values: values.into_iter().map(|v| v as f32).collect(),
            });
        }
    }
    let topics = topics(log.motor_command.count(), log.battery_voltage.is_some());
    write(START_TIME_US, &topics, &samples)
}
