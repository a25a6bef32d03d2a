//! What a ULog holds for a flight analysis: [`inspect`] → [`UlogInspection`].

use serde::Serialize;
use statrs::statistics::{Data, OrderStatistics};
use ulog::{Column, Log, Topic};

use super::rates::{ColumnPattern, NewSamples};
use crate::time::GAP_INTERVALS;

/// The topics a flight analysis reads and their key columns; `{rotor}` stands for each motor
/// index below the rotor count (`CA_ROTOR_COUNT`, else 4).
const KEY_TOPICS: &[(&str, &[&str])] = &[
    (
        "vehicle_local_position",
        &["x", "y", "z", "vx", "vy", "vz", "ax", "ay", "az"],
    ),
    ("vehicle_attitude", &["q[0]", "q[1]", "q[2]", "q[3]"]),
    ("vehicle_angular_velocity", &["xyz[0]", "xyz[1]", "xyz[2]"]),
    ("vehicle_acceleration", &["xyz[0]", "xyz[1]", "xyz[2]"]),
    ("sensor_combined", &["gyro_rad[0]", "accelerometer_m_s2[2]"]),
    ("actuator_motors", &["control[{rotor}]"]),
    ("actuator_outputs", &["output[{rotor}]"]),
    ("esc_status", &["esc[{rotor}].esc_rpm"]),
    ("vehicle_thrust_setpoint", &["xyz[0]", "xyz[1]", "xyz[2]"]),
    ("vehicle_torque_setpoint", &["xyz[0]", "xyz[1]", "xyz[2]"]),
    ("vehicle_rates_setpoint", &["roll", "pitch", "yaw"]),
    ("battery_status", &["voltage_v", "current_a"]),
    ("vehicle_air_data", &["baro_alt_meter"]),
    ("wind", &["windspeed_north", "windspeed_east"]),
    // Its `landed` field gives the airborne time; its rate is that of its events.
    ("vehicle_land_detected", &[]),
];

/// The vehicle and autopilot the log names (info fields and parameters).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct VehicleInfo {
    /// `sys_name` (PX4).
    pub system: Option<String>,
    /// `ver_hw` (the flight controller board, `PX4_SITL` in simulation).
    pub hardware: Option<String>,
    /// The release (`ver_sw_release`, as pyulog renders it) or else the `ver_sw` commit.
    pub software: Option<String>,
    /// `SYS_AUTOSTART`: the airframe.
    pub airframe: Option<i64>,
    /// `CA_ROTOR_COUNT`.
    pub rotor_count: Option<i64>,
}

/// Airborne time from `vehicle_land_detected` (`landed` false), seconds from the log's start.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Airborne {
    pub total_s: f64,
    pub intervals: Vec<[f64; 2]>,
}

/// Spread of a topic's sample steps (ms): the median and the 5th and 95th percentiles.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StepSpread {
    pub median_ms: f64,
    pub p05_ms: f64,
    pub p95_ms: f64,
}

/// Steps longer than [`GAP_INTERVALS`] median steps, and steps that do not move forward.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Gaps {
    pub count: usize,
    pub longest_s: f64,
    /// When the longest starts, seconds from the log's start.
    pub longest_at_s: f64,
    pub not_increasing: usize,
}

/// The stretch of the log over which the key columns' rates are judged.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RatesOver {
    /// The airborne intervals (on the ground most values rest, which would read as held).
    Airborne,
    /// The whole log (no airborne time known).
    WholeLog,
}

/// How often one key column really changes.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ColumnRate {
    pub name: String,
    pub pattern: ColumnPattern,
    /// New values per second (the changes of a held column, the knots of an interpolated one).
    pub effective_rate_hz: f64,
}

/// One topic instance a flight analysis reads.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TopicInspection {
    pub name: String,
    pub multi_id: u8,
    pub samples: usize,
    /// One over the median step (`None` for one sample).
    pub median_rate_hz: Option<f64>,
    /// `None` under three samples.
    pub steps: Option<StepSpread>,
    pub gaps: Gaps,
    pub columns: Vec<ColumnRate>,
}

/// The logger's dropouts (data it could not write).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DropoutSummary {
    pub count: usize,
    pub total_ms: u64,
    pub longest_ms: u64,
}

/// What a ULog holds for a flight analysis.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct UlogInspection {
    pub vehicle: VehicleInfo,
    /// Logging start, µs since boot.
    pub start_time_us: u64,
    /// From the start to the latest sample.
    pub duration_s: f64,
    /// `None` without a `vehicle_land_detected` topic.
    pub airborne: Option<Airborne>,
    /// Where the key columns' effective rates are measured.
    pub rates_over: RatesOver,
    /// The analysis topics present (a topic whose time stamps go back, or with under three
    /// samples, has no column rates), in [`KEY_TOPICS`] order, every instance with samples.
    pub topics: Vec<TopicInspection>,
    /// Analysis topics the log does not have.
    pub absent_topics: Vec<String>,
    /// Topic instances with samples besides the analysis topics.
    pub other_topics: usize,
    pub dropouts: DropoutSummary,
    /// Where the file ends inside a message, if it does.
    pub truncated_at: Option<u64>,
    /// Messages the autopilot logged at warning level or worse.
    pub warnings: usize,
    /// What the motor commands' rate leaves out of reach (`None` without motor commands).
    pub timing_limit: Option<TimingLimit>,
}

/// A command's effect is seen only as often as the command changes: timing shorter than the
/// motor commands' interval (a delay, a motor lag) cannot be identified from the log.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TimingLimit {
    /// The topic instance the motor commands come from (`actuator_motors[0]` first).
    pub topic: String,
    /// The slowest effective rate of its columns that change, Hz.
    pub command_rate_hz: f64,
    /// One over that rate: the shortest timing the log can resolve, s.
    pub shortest_s: f64,
    /// Slower than [`SLOW_COMMAND_RATE_HZ`]: PX4's high-rate logging profile would do better.
    pub slow: bool,
}

/// Below this rate of new motor commands, PX4's high-rate logging profile is worth naming.
pub const SLOW_COMMAND_RATE_HZ: f64 = 100.0;

/// The timing limit of the first motor-command topic whose columns change.
fn timing_limit(topics: &[TopicInspection]) -> Option<TimingLimit> {
    ["actuator_motors", "actuator_outputs"]
        .iter()
        .flat_map(|name| topics.iter().filter(move |t| t.name == *name))
        .find_map(|topic| {
            let rate = topic
                .columns
                .iter()
                .filter(|c| c.pattern != ColumnPattern::Constant && c.effective_rate_hz > 0.0)
                .map(|c| c.effective_rate_hz)
                .min_by(f64::total_cmp)?;
            Some(TimingLimit {
                topic: format!("{}[{}]", topic.name, topic.multi_id),
                command_rate_hz: rate,
                shortest_s: 1.0 / rate,
                slow: rate < SLOW_COMMAND_RATE_HZ,
            })
        })
}

/// Inspects a parsed log (see [`UlogInspection`]).
pub fn inspect(log: &Log) -> UlogInspection {
    let rotors = log
        .parameters
        .value("CA_ROTOR_COUNT")
        .map(|v| v.as_f64())
        .filter(|&n| (1.0..=12.0).contains(&n))
        .map_or(4, |n| n as usize);
    let airborne_us = airborne_intervals(log);
    let (windows, rates_over) = match &airborne_us {
        Some(intervals) if !intervals.is_empty() => (intervals.clone(), RatesOver::Airborne),
        _ => (vec![[0, u64::MAX]], RatesOver::WholeLog),
    };
    let mut topics = Vec::new();
    let mut absent_topics = Vec::new();
    for &(name, columns) in KEY_TOPICS {
        let instances: Vec<&Topic> = log
            .topics
            .iter()
            .filter(|t| t.name == name && !t.is_empty())
            .collect();
        if instances.is_empty() {
            absent_topics.push(name.to_string());
        }
        let columns = expand(columns, rotors);
        topics.extend(
            instances
                .into_iter()
                .map(|topic| inspect_topic(topic, &columns, log.start_time_us, &windows)),
        );
    }
    let other_topics = log
        .topics
        .iter()
        .filter(|t| !t.is_empty() && !KEY_TOPICS.iter().any(|(name, _)| *name == t.name))
        .count();
    let durations = log.dropouts.iter().map(|d| u64::from(d.duration_ms));
    let timing_limit = timing_limit(&topics);
    UlogInspection {
        vehicle: vehicle(log),
        start_time_us: log.start_time_us,
        duration_s: seconds(log.last_time_us, log.start_time_us),
        airborne: airborne_us.map(|intervals| airborne(&intervals, log.start_time_us)),
        rates_over,
        topics,
        absent_topics,
        other_topics,
        dropouts: DropoutSummary {
            count: log.dropouts.len(),
            total_ms: durations.clone().sum(),
            longest_ms: durations.max().unwrap_or(0),
        },
        truncated_at: log.truncated.map(|t| t.offset),
        warnings: log
            .messages
            .iter()
            .filter(|m| {
                use ulog::LogLevel::*;
                matches!(m.level, Emergency | Alert | Critical | Error | Warning)
            })
            .count(),
        timing_limit,
    }
}

fn expand(columns: &[&str], rotors: usize) -> Vec<String> {
    columns
        .iter()
        .flat_map(|column| match column.contains("{rotor}") {
            true => (0..rotors)
                .map(|k| column.replace("{rotor}", &k.to_string()))
                .collect(),
            false => vec![column.to_string()],
        })
        .collect()
}

/// Seconds from `from` to `to` (µs; negative if `to` is earlier).
fn seconds(to: u64, from: u64) -> f64 {
    (to as f64 - from as f64) * 1e-6
}

fn vehicle(log: &Log) -> VehicleInfo {
    let text = |key: &str| log.info_text(key).map(str::to_string);
    let integer = |name: &str| log.parameters.value(name).map(|v| v.as_f64() as i64);
    let release = log
        .info
        .get("ver_sw_release")
        .and_then(ulog::Value::as_f64)
        .and_then(|v| release_name(v as u32));
    VehicleInfo {
        system: text("sys_name"),
        hardware: text("ver_hw"),
        software: release.or_else(|| text("ver_sw")),
        airframe: integer("SYS_AUTOSTART"),
        rotor_count: integer("CA_ROTOR_COUNT"),
    }
}

/// `ver_sw_release` (major, minor, patch, type bytes) as pyulog names it: `v1.14.0`, with
/// `(alpha)`, `(beta)` or `(RC)`; `None` for a development build (type below 64).
fn release_name(release: u32) -> Option<String> {
    let [kind, patch, minor, major] = release.to_le_bytes();
    let suffix = match kind {
        0..64 => return None,
        64..128 => " (alpha)",
        128..192 => " (beta)",
        192..255 => " (RC)",
        255 => "",
    };
    Some(format!("v{major}.{minor}.{patch}{suffix}"))
}

/// Airborne intervals (µs) from `vehicle_land_detected`: from a sample with `landed` false to the
/// next with it true, or to the log's end.
fn airborne_intervals(log: &Log) -> Option<Vec<[u64; 2]>> {
    let topic = log.topic("vehicle_land_detected", 0)?;
    let landed = topic.column_f64("landed")?;
    let mut intervals = Vec::new();
    let mut took_off = None;
    for (&time, &landed) in topic.timestamps().iter().zip(&landed) {
        match (took_off, landed != 0.0) {
            (None, false) => took_off = Some(time),
            (Some(start), true) => {
                intervals.push([start, time]);
                took_off = None;
            }
            _ => {}
        }
    }
    if let Some(start) = took_off {
        intervals.push([start, log.last_time_us]);
    }
    Some(intervals)
}

fn airborne(intervals: &[[u64; 2]], start_time_us: u64) -> Airborne {
    let intervals: Vec<[f64; 2]> = intervals
        .iter()
        .map(|&[a, b]| [seconds(a, start_time_us), seconds(b, start_time_us)])
        .collect();
    Airborne {
        total_s: intervals.iter().map(|[a, b]| b - a).sum(),
        intervals,
    }
}

fn inspect_topic(
    topic: &Topic,
    columns: &[String],
    start_time_us: u64,
    windows: &[[u64; 2]],
) -> TopicInspection {
    let stamps = topic.timestamps();
    let steps_ms: Vec<f64> = stamps
        .windows(2)
        .map(|w| (w[1] as f64 - w[0] as f64) * 1e-3)
        .collect();
    let mut spread = Data::new(steps_ms.clone());
    let median_ms = if steps_ms.is_empty() {
        f64::NAN
    } else {
        spread.median()
    };
    let steps = (steps_ms.len() >= 2).then(|| StepSpread {
        median_ms,
        p05_ms: spread.quantile(0.05),
        p95_ms: spread.quantile(0.95),
    });
    let times: Vec<f64> = stamps.iter().map(|&t| seconds(t, start_time_us)).collect();
    let columns = if stamps.len() >= 3 && stamps.is_sorted() {
        column_rates(topic, columns, &times, windows)
    } else {
        Vec::new()
    };
    TopicInspection {
        name: topic.name.clone(),
        multi_id: topic.multi_id,
        samples: topic.len(),
        median_rate_hz: (!steps_ms.is_empty()).then(|| 1e3 / median_ms),
        steps,
        gaps: gaps(&steps_ms, median_ms, &times),
        columns,
    }
}

/// The effective rate of each key column over the samples inside `windows` (µs).
fn column_rates(
    topic: &Topic,
    columns: &[String],
    times: &[f64],
    windows: &[[u64; 2]],
) -> Vec<ColumnRate> {
    let stamps = topic.timestamps();
    let ranges: Vec<std::ops::Range<usize>> = windows
        .iter()
        .map(|&[a, b]| stamps.partition_point(|&t| t < a)..stamps.partition_point(|&t| t <= b))
        .filter(|range| range.len() >= 2)
        .collect();
    let duration: f64 = ranges
        .iter()
        .map(|r| times[r.end - 1] - times[r.start])
        .sum();
    columns
        .iter()
        .filter_map(|name| {
            let column = topic.column(name)?;
            let epsilon = match column {
                Column::Float(_) => f64::from(f32::EPSILON),
                _ => f64::EPSILON,
            };
            let values = column.to_f64();
            let counts = ranges.iter().fold(NewSamples::default(), |sum, r| {
                sum.and(NewSamples::count(
                    &times[r.clone()],
                    &values[r.clone()],
                    epsilon,
                ))
            });
            let (pattern, new) = counts.pattern();
            let intervals = new.saturating_sub(ranges.len());
            Some(ColumnRate {
                name: name.clone(),
                pattern,
                effective_rate_hz: if duration > 0.0 {
                    intervals as f64 / duration
                } else {
                    0.0
                },
            })
        })
        .collect()
}

fn gaps(steps_ms: &[f64], median_ms: f64, times: &[f64]) -> Gaps {
    let long: Vec<usize> = (0..steps_ms.len())
        .filter(|&k| steps_ms[k] > GAP_INTERVALS * median_ms)
        .collect();
    let longest = (0..steps_ms.len()).max_by(|&a, &b| steps_ms[a].total_cmp(&steps_ms[b]));
    Gaps {
        count: long.len(),
        longest_s: longest.map_or(0.0, |k| steps_ms[k] * 1e-3),
        longest_at_s: longest.map_or(0.0, |k| times[k]),
        not_increasing: steps_ms.iter().filter(|&&s| s <= 0.0).count(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn releases_are_named_as_pyulog_names_them() {
        assert_eq!(release_name(0x010e_00ff).as_deref(), Some("v1.14.0"));
        assert_eq!(release_name(0x010f_02c0).as_deref(), Some("v1.15.2 (RC)"));
        assert_eq!(release_name(0x010f_0200), None);
    }
}
