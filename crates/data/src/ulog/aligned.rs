//! Columns of several topics of a ULog on one clock, as a numeric table (for `learn sindy` on a
//! `.ulg`). A column is named `topic.field`, or `topic[k].field` for instance `k` of a topic
//! logged more than once (`vehicle_angular_velocity.xyz[0]`, `actuator_motors.control[2]`). The
//! rows are the samples of one base topic; a column of another topic takes, at each base time,
//! its latest sample at or before it (an as-of join: a value is held, never interpolated), and
//! the rows before every topic has logged a sample are left out. How long each held column was
//! held is reported, so that a 10 Hz column on a 50 Hz clock is seen for what it is.

use std::path::Path;

use ulog::{Log, Topic};

use crate::error::{DataError, Result};
use crate::numeric::NumericTable;
use crate::time::{check_time_axis_at, median_interval};

/// A ULog's columns on the clock of one topic.
#[derive(Clone, Debug)]
pub struct AlignedTable {
    /// The base topic's time stamps, s.
    pub time: Vec<f64>,
    /// The columns, in the order asked; a row's "line" is its sample's number in the base topic
    /// (1-based), which error messages name.
    pub table: NumericTable,
    /// The base topic (`name` or `name[k]`).
    pub base: String,
    /// Every column of another topic than the base, with how its values were held.
    pub held: Vec<HeldColumn>,
}

/// A column taken as of the base clock from a topic with its own.
#[derive(Clone, Debug, PartialEq)]
pub struct HeldColumn {
    pub column: String,
    /// The column's topic's median rate, Hz.
    pub median_rate_hz: f64,
    /// The longest time a value of it was held over the rows kept, s.
    pub longest_hold_s: f64,
}

/// A column's topic (name and instance) and field.
pub(super) struct ColumnName<'a> {
    pub topic: &'a str,
    pub instance: u8,
    pub field: &'a str,
}

/// Splits `topic.field` or `topic[k].field`.
pub(super) fn column_name(column: &str) -> Option<ColumnName<'_>> {
    let (topic, field) = column.split_once('.')?;
    let (topic, instance) = topic_name(topic)?;
    (!field.is_empty()).then_some(ColumnName {
        topic,
        instance,
        field,
    })
}

/// Splits `topic` or `topic[k]`.
pub(super) fn topic_name(text: &str) -> Option<(&str, u8)> {
    match text.strip_suffix(']').and_then(|t| t.split_once('[')) {
        Some((topic, instance)) => Some((topic, instance.parse().ok()?)),
        None => Some((text, 0)),
    }
    .filter(|(topic, _)| !topic.is_empty())
}

/// The columns `columns` of `log` (read from `path`) on the clock of topic `base` (`name` or
/// `name[k]`; the first column's topic when `None`).
pub fn aligned_table(
    log: &Log,
    path: &Path,
    base: Option<&str>,
    columns: &[&str],
) -> Result<AlignedTable> {
    let bad = |field: &str, message: String| DataError::Config {
        path: path.to_path_buf(),
        field: field.to_string(),
        message,
    };
    let topic_of = |name: &str, instance: u8, what: &str| {
        log.topic(name, instance)
            .filter(|topic| !topic.is_empty())
            .ok_or_else(|| {
                bad(
                    what,
                    format!("the log has no samples of topic {name}[{instance}]"),
                )
            })
    };
    let mut sources = Vec::with_capacity(columns.len());
    for &column in columns {
        let name = column_name(column).ok_or_else(|| {
            bad(
                column,
                "a ULog column is named topic.field or topic[k].field".into(),
            )
        })?;
        let topic = topic_of(name.topic, name.instance, column)?;
        let values = topic.column_f64(name.field).ok_or_else(|| {
            bad(
                column,
                format!("topic {} has no field '{}'", name.topic, name.field),
            )
        })?;
        sources.push((topic, values));
    }
    let base_topic = match base {
        Some(text) => {
            let (name, instance) =
                topic_name(text).ok_or_else(|| bad(text, "not a topic name".into()))?;
            topic_of(name, instance, text)?
        }
        None => sources
            .first()
            .map(|(topic, _)| *topic)
            .ok_or_else(|| bad("columns", "no column named".into()))?,
    };
    let sources: Vec<(TopicClock, Vec<f64>)> = sources
        .into_iter()
        .map(|(topic, values)| (clock_of(topic), values))
        .collect();
    join(path, &clock_of(base_topic), columns, sources)
}

fn clock_of(topic: &Topic) -> TopicClock<'_> {
    TopicClock {
        label: format!("{}[{}]", topic.name, topic.multi_id),
        timestamps: topic.timestamps(),
    }
}

/// One topic's clock: its label (`name[k]`) and its samples' time stamps, µs.
pub(super) struct TopicClock<'a> {
    pub label: String,
    pub timestamps: &'a [u64],
}

/// The columns `columns`, each given by its topic's clock and values in `sources`, as of each
/// sample of `base` (a topic's label names it; the base's own columns are not held).
pub(super) fn join(
    path: &Path,
    base: &TopicClock,
    columns: &[&str],
    sources: Vec<(TopicClock, Vec<f64>)>,
) -> Result<AlignedTable> {
    let clock = base.timestamps;
    // Rows before every column's topic has a sample have nothing to hold.
    let start = sources
        .iter()
        .map(|(topic, _)| clock.partition_point(|&t| t < topic.timestamps[0]))
        .max()
        .unwrap_or(0);
    let rows = start..clock.len();
    let mut held = Vec::new();
    let mut values = Vec::with_capacity(columns.len());
    for (&column, (topic, column_values)) in columns.iter().zip(&sources) {
        let picked = as_of(topic.timestamps, &clock[rows.clone()]);
        if topic.label != base.label {
            held.push(HeldColumn {
                column: column.to_string(),
                median_rate_hz: median_rate_hz(topic.timestamps),
                longest_hold_s: picked
                    .iter()
                    .zip(&clock[rows.clone()])
                    .map(|(&sample, &t)| (t - topic.timestamps[sample]) as f64 * 1e-6)
                    .fold(0.0, f64::max),
            });
        }
        values.push(picked.iter().map(|&sample| column_values[sample]).collect());
    }
    let names = columns.iter().map(|c| c.to_string()).collect();
    let time: Vec<f64> = clock[rows.clone()]
        .iter()
        .map(|&t| t as f64 * 1e-6)
        .collect();
    // A clock that stands still or runs back has no derivative: its sample is named.
    check_time_axis_at(path, &base.label, &time, f64::INFINITY, &|k| start + k + 1)?;
    let lines = rows.map(|row| row + 1).collect();
    Ok(AlignedTable {
        time,
        table: NumericTable::from_columns(path, names, values, lines),
        base: base.label.clone(),
        held,
    })
}

/// For each time of `clock` (increasing, none before `samples[0]`), the index of the latest of
/// `samples` (increasing) at or before it.
fn as_of(samples: &[u64], clock: &[u64]) -> Vec<usize> {
    let mut latest = 0;
    clock
        .iter()
        .map(|&t| {
            while latest + 1 < samples.len() && samples[latest + 1] <= t {
                latest += 1;
            }
            latest
        })
        .collect()
}

/// One over the median step of a topic's time stamps (0 for fewer than two samples).
fn median_rate_hz(timestamps: &[u64]) -> f64 {
    let seconds: Vec<f64> = timestamps.iter().map(|&t| t as f64 * 1e-6).collect();
    let median = median_interval(&seconds);
    if median > 0.0 { 1.0 / median } else { 0.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_value_is_held_from_its_sample_on_never_before() {
        assert_eq!(
            as_of(&[10, 20, 30], &[10, 15, 20, 29, 30, 45]),
            [0, 0, 1, 1, 2, 2]
        );
    }

    #[test]
    fn column_names_split_into_topic_instance_and_field() {
        let name = column_name("actuator_motors.control[2]").unwrap();
        assert_eq!(
            (name.topic, name.instance, name.field),
            ("actuator_motors", 0, "control[2]")
        );
        let name = column_name("esc_status[1].esc[0].esc_rpm").unwrap();
        assert_eq!(
            (name.topic, name.instance, name.field),
            ("esc_status", 1, "esc[0].esc_rpm")
        );
        for bad in ["x", ".x", "t.", "t[a].x", "[1].x"] {
            assert!(column_name(bad).is_none(), "{bad}");
        }
    }
}
