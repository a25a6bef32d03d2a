//! Recordings in other layouts than Neural-Fly's: a short description, written by a user from their
//! logger's documentation, says which columns (of a CSV file, or `topic.field` of a PX4 ULog) hold
//! time, position, velocity, attitude, body rate, motor commands and battery voltage, in which units
//! and frames; [`read_with_layout`] turns such a file into a [`FlightLog`]. Fields and examples:
//! docs/layouts.md.
//!
//! The flight log is z up: a north-east-down world and forward-right-down body (PX4) become
//! north-west-up and forward-left-up by negating the second and third axes of both frames, which
//! keeps gravity along −z and the thrust along the body's third axis.

use std::path::Path;

use rotation::rotation_from_quaternion;
use serde::Deserialize;

use crate::error::{DataError, Result};
use crate::flight_log::{FlightLog, FlightMeta, SAMPLE_INTERVAL_RANGE_S};
use crate::numeric::NumericTable;
use crate::time::check_interval_range;

/// The unit of a time column.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TimeUnit {
    S,
    Ms,
    Us,
    Ns,
}

impl TimeUnit {
    /// Seconds per unit.
    pub fn seconds(self) -> f64 {
        match self {
            Self::S => 1.0,
            Self::Ms => 1e-3,
            Self::Us => 1e-6,
            Self::Ns => 1e-9,
        }
    }
}

/// The frames of a recording's world vectors and body vectors.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Frames {
    /// World z up (east-north-up or any z-up frame), body forward-left-up.
    EnuFlu,
    /// World north-east-down, body forward-right-down (PX4, ArduPilot).
    NedFrd,
}

/// The time column and its unit (ignored for a ULog, whose clock is in microseconds).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeColumn {
    pub column: String,
    pub unit: TimeUnit,
}

/// The columns of a unit quaternion rotating body vectors into the world frame, by component.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct QuaternionColumns {
    pub w: String,
    pub x: String,
    pub y: String,
    pub z: String,
}

/// Where a recording's quantities are, in a CSV file or a ULog.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RecordingLayout {
    /// What the layout is for (free text).
    #[serde(default)]
    pub description: String,
    /// For a CSV file: the time column. For a ULog: the topic whose clock the rows take
    /// (`column` a topic name, the unit ignored).
    pub time: TimeColumn,
    pub frames: Frames,
    /// World position, m.
    pub position: [String; 3],
    /// World velocity, m/s.
    pub velocity: [String; 3],
    pub quaternion: QuaternionColumns,
    /// Body rate in the body frame, rad/s.
    pub body_rate: [String; 3],
    /// The four motor commands as logged, in the order of the vehicle description's rotors.
    pub motor_commands: [String; 4],
    /// Multiplies the logged motor commands into the unit the vehicle's command map reads (e.g.
    /// 65536 for a log that writes a Crazyflie's command as a fraction of 65536); 1 unless given.
    #[serde(default = "unit_scale")]
    pub motor_command_scale: f64,
    /// Battery voltage, V (for a thrust map that depends on it).
    #[serde(default)]
    pub battery_voltage: Option<String>,
    /// A CSV header line that begins with this text, not part of the first name (`"# "` for a
    /// header written as a comment).
    #[serde(default)]
    pub header_prefix: Option<String>,
}

fn unit_scale() -> f64 {
    1.0
}

impl RecordingLayout {
    /// Reads a layout file (JSON; unknown fields refused).
    pub fn load(path: &Path) -> Result<Self> {
        let text = bounded_read::read_json_text(path).map_err(|source| DataError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let text = bounded_read::json::checked_text(&text).map_err(|error| DataError::Config {
            path: path.to_path_buf(),
            field: error.field,
            message: error.message,
        })?;
        serde_json::from_str(text).map_err(|error| DataError::Config {
            path: path.to_path_buf(),
            field: "(layout)".into(),
            message: error.to_string(),
        })
    }

    /// The data columns in reading order: position, velocity, quaternion (w, x, y, z), body rate,
    /// motor commands, battery voltage.
    fn columns(&self) -> Vec<&str> {
        let q = &self.quaternion;
        let mut columns: Vec<&str> = self
            .position
            .iter()
            .chain(&self.velocity)
            .chain([&q.w, &q.x, &q.y, &q.z])
            .chain(&self.body_rate)
            .chain(&self.motor_commands)
            .map(String::as_str)
            .collect();
        columns.extend(self.battery_voltage.as_deref());
        columns
    }
}

/// Reads `path` (a CSV file, or a PX4 ULog when its extension is `.ulg`) as `layout` says. The
/// time stamps are kept as logged (strictly increasing, every interval within
/// [`SAMPLE_INTERVAL_RANGE_S`]); errors name the file, line and column.
pub fn read_with_layout(path: &Path, layout: &RecordingLayout) -> Result<FlightLog> {
    let columns = layout.columns();
    let (time, table) = if is_ulog(path) {
        let log = ulog::Log::read(path).map_err(|error| DataError::Config {
            path: path.to_path_buf(),
            field: "(ULog)".into(),
            message: error.to_string(),
        })?;
        let aligned = crate::ulog::aligned_table(&log, path, Some(&layout.time.column), &columns)?;
        // Seconds since the log started, as the ULog inspection counts them.
        let start = log.start_time_us as f64 * 1e-6;
        let time: Vec<f64> = aligned.time.iter().map(|t| t - start).collect();
        (time, aligned.table)
    } else {
        let mut names = vec![layout.time.column.as_str()];
        names.extend(&columns);
        let table = match &layout.header_prefix {
            Some(prefix) => NumericTable::read_after_header_prefix(path, prefix, &names)?,
            None => NumericTable::read(path, &names)?,
        };
        let (time, table) = table.split_increasing_time()?;
        let unit = layout.time.unit.seconds();
        (time.into_iter().map(|t| t * unit).collect(), table)
    };
    let line = |k: usize| table.line(k);
    check_interval_range(
        path,
        &layout.time.column,
        &time,
        SAMPLE_INTERVAL_RANGE_S,
        &line,
    )?;
    let column = |i: usize| &table.columns[i];
    // The same flip for world (NED → NWU) and body (FRD → FLU) vectors.
    let flip = layout.frames == Frames::NedFrd;
    let vector = |first: usize| -> Vec<[f64; 3]> {
        (0..time.len())
            .map(|k| {
                let v = [column(first)[k], column(first + 1)[k], column(first + 2)[k]];
                if flip { [v[0], -v[1], -v[2]] } else { v }
            })
            .collect()
    };
    for (first, range, names) in [
        (0, "p", &layout.position),
        (3, "v", &layout.velocity),
        (10, "w", &layout.body_rate),
    ] {
        check_plausible(&table, first, range, names)?;
    }
    let quaternion = quaternions(&table, layout)?;
    let rotation = quaternion.iter().map(rotation_from_quaternion).collect();
    let motor_command = (0..time.len())
        .map(|k| std::array::from_fn(|i| column(13 + i)[k] * layout.motor_command_scale))
        .collect();
    Ok(FlightLog {
        path: path.to_path_buf(),
        meta: FlightMeta::from_file_name(path),
        position: vector(0),
        velocity: vector(3),
        body_rate: vector(10),
        thrust_setpoint: vec![f64::NAN; time.len()],
        hover_throttle: vec![f64::NAN; time.len()],
        motor_command,
        battery_voltage: layout.battery_voltage.as_ref().map(|_| column(17).clone()),
        declared_rate_frame: Some(crate::RateFrame::Body),
        position_desired: None,
        velocity_desired: None,
        attitude_setpoint: None,
        residual_force: None,
        quaternion,
        rotation,
        time,
    })
}

/// Fails on the first value of the three columns from `first` outside the plausible range of the
/// Neural-Fly column `range` (as [`FlightLog::read`] checks it), naming the layout's column.
fn check_plausible(
    table: &NumericTable,
    first: usize,
    range: &str,
    names: &[String; 3],
) -> Result<()> {
    let range = crate::flight_log::plausible_range(range).expect("a checked column");
    for (axis, name) in names.iter().enumerate() {
        let values = &table.columns[first + axis];
        if let Some(k) = values
            .iter()
            .position(|v| !(range.min..=range.max).contains(v))
        {
            return Err(DataError::Implausible {
                path: table.path.clone(),
                row: table.line(k),
                column: name.clone(),
                value: values[k],
                min: range.min,
                max: range.max,
                unit: range.unit,
                quantity: range.quantity,
            });
        }
    }
    Ok(())
}

/// The attitude as `[x, y, z, w]` quaternions in the z-up frames, each checked to be a unit one.
fn quaternions(table: &NumericTable, layout: &RecordingLayout) -> Result<Vec<[f64; 4]>> {
    let column = |i: usize| &table.columns[i];
    (0..table.rows())
        .map(|k| {
            let (w, x, y, z) = (column(6)[k], column(7)[k], column(8)[k], column(9)[k]);
            let norm = (w * w + x * x + y * y + z * z).sqrt();
            if (norm - 1.0).abs() > 1e-3 {
                return Err(DataError::BadCell {
                    path: table.path.clone(),
                    row: table.line(k),
                    column: layout.quaternion.w.clone(),
                    value: format!("[w {w}, x {x}, y {y}, z {z}]"),
                    reason: format!("not a unit quaternion (norm {norm:.6})"),
                });
            }
            // S R S with S = diag(1, −1, −1): the quaternion's y and z change sign.
            Ok(match layout.frames {
                Frames::EnuFlu => [x, y, z, w],
                Frames::NedFrd => [x, -y, -z, w],
            })
        })
        .collect()
}

/// Whether `path` names a PX4 ULog (by its extension).
pub fn is_ulog(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("ulg"))
}
