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
use crate::motors::{MAX_MOTORS, MotorCommands};
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

/// A column and the factor its values are multiplied by.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScaledColumn {
    pub column: String,
    #[serde(default = "unit_scale")]
    pub scale: f64,
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
    /// World position, m (optional: without it the ground effect is not looked for).
    #[serde(default)]
    pub position: Option<[String; 3]>,
    /// World velocity, m/s.
    pub velocity: [String; 3],
    pub quaternion: QuaternionColumns,
    /// Body rate in the body frame, rad/s.
    pub body_rate: [String; 3],
    /// The motor commands as logged (1 to [`MAX_MOTORS`]), in the order of the vehicle
    /// description's rotors.
    pub motor_commands: Vec<String>,
    /// Multiplies the logged motor commands into the unit the vehicle's command map reads (e.g.
    /// 65536 for a log that writes a Crazyflie's command as a fraction of 65536); 1 unless given.
    #[serde(default = "unit_scale")]
    pub motor_command_scale: f64,
    /// Battery voltage, V (for a thrust map that depends on it).
    #[serde(default)]
    pub battery_voltage: Option<String>,
    /// The normalised collective thrust setpoint, for a model whose thrust is `T_sp` (`T = m g
    /// T_sp / hover_throttle`: no rotor or mass parameters needed), times `scale` (−1 for PX4's
    /// `vehicle_thrust_setpoint.xyz[2]`, which points down the body's z axis).
    #[serde(default)]
    pub thrust_setpoint: Option<ScaledColumn>,
    /// The thrust setpoint that hovers, with `thrust_setpoint`: a column (PX4's
    /// `hover_thrust_estimate.hover_thrust`).
    #[serde(default)]
    pub hover_throttle: Option<String>,
    /// A CSV header line that begins with this text, not part of the first name (`"# "` for a
    /// header written as a comment).
    #[serde(default)]
    pub header_prefix: Option<String>,
}

/// Where the velocity, the quaternion (w, x, y, z), the body rate and the motor commands begin
/// among the layout's columns.
const VELOCITY_COLUMN: usize = 0;
const QUATERNION_COLUMN: usize = 3;
const BODY_RATE_COLUMN: usize = 7;
const FIRST_MOTOR_COLUMN: usize = 10;

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
        let layout: Self = serde_json::from_str(text).map_err(|error| DataError::Config {
            path: path.to_path_buf(),
            field: "(layout)".into(),
            message: error.to_string(),
        })?;
        layout.check_motor_count(path)?;
        if layout.thrust_setpoint.is_some() != layout.hover_throttle.is_some() {
            return Err(DataError::Config {
                path: path.to_path_buf(),
                field: "thrust_setpoint".into(),
                message: "a thrust setpoint needs the hover throttle it is divided by: give both `thrust_setpoint` and `hover_throttle`, or neither".into(),
            });
        }
        Ok(layout)
    }

    /// The data columns in reading order: velocity, quaternion (w, x, y, z), body rate, motor
    /// commands, then the optional ones present ([`Self::optional_columns`]).
    fn columns(&self) -> Vec<&str> {
        let q = &self.quaternion;
        let mut columns: Vec<&str> = self
            .velocity
            .iter()
            .chain([&q.w, &q.x, &q.y, &q.z])
            .chain(&self.body_rate)
            .chain(&self.motor_commands)
            .map(String::as_str)
            .collect();
        columns.extend(self.battery_voltage.as_deref());
        columns.extend(self.thrust_setpoint.as_ref().map(|c| c.column.as_str()));
        columns.extend(self.hover_throttle.as_deref());
        columns.extend(self.position.iter().flatten().map(String::as_str));
        columns
    }

    /// Fails unless the layout names 1 to [`MAX_MOTORS`] motor commands (`origin` names the file).
    fn check_motor_count(&self, origin: &Path) -> Result<()> {
        let count = self.motor_commands.len();
        if (1..=MAX_MOTORS).contains(&count) {
            return Ok(());
        }
        Err(DataError::Config {
            path: origin.to_path_buf(),
            field: "motor_commands".into(),
            message: format!("{count} columns; expected 1 to {MAX_MOTORS}, one per rotor"),
        })
    }

    /// Velocity, quaternion, body rate and motor commands: 3 + 4 + 3 + N columns.
    fn required_columns(&self) -> usize {
        FIRST_MOTOR_COLUMN + self.motor_commands.len()
    }

    /// Where the optional columns are among [`Self::columns`]: battery voltage, thrust setpoint,
    /// hover throttle, position (its first of three).
    fn optional_columns(&self) -> [Option<usize>; 4] {
        let mut next = self.required_columns();
        let mut place = |present: bool| {
            present.then(|| {
                next += 1;
                next - 1
            })
        };
        [
            place(self.battery_voltage.is_some()),
            place(self.thrust_setpoint.is_some()),
            place(self.hover_throttle.is_some()),
            place(self.position.is_some()),
        ]
    }
}

/// A recording for an analysis: in the Neural-Fly layout (any spacing), or as `layout` (a layout
/// description's file) describes it; only its data rows `rows` (counted from 0, the end excluded)
/// when given, taken before the layout's checks, which then see only them.
pub fn read_recording(
    path: &Path,
    layout: Option<&Path>,
    rows: Option<std::ops::Range<usize>>,
) -> Result<FlightLog> {
    if let Some(layout) = layout {
        return read_rows_with_layout(path, &RecordingLayout::load(layout)?, rows);
    }
    let log = FlightLog::read_spaced(path, crate::Spacing::Any)?;
    let Some(rows) = rows else {
        return Ok(log);
    };
    let count = log.len();
    log.row_range(rows.clone())
        .ok_or_else(|| DataError::RowsPastEnd {
            path: path.to_path_buf(),
            rows,
            count,
        })
}

/// Reads `path` (a CSV file, a PX4 ULog when its extension is `.ulg`, or a folder holding a PX4 log
/// exported to CSV, one file per topic) as `layout` says. The
/// time stamps are kept as logged (strictly increasing, every interval within
/// [`SAMPLE_INTERVAL_RANGE_S`]); errors name the file, line and column.
pub fn read_with_layout(path: &Path, layout: &RecordingLayout) -> Result<FlightLog> {
    read_rows_with_layout(path, layout, None)
}

/// [`read_with_layout`] of the data rows `rows` only (counted from 0, the end excluded): the
/// checks see only those rows, so a stretch a log fills with NaN (PX4's estimates after landing)
/// can be left out.
pub fn read_rows_with_layout(
    path: &Path,
    layout: &RecordingLayout,
    rows: Option<std::ops::Range<usize>>,
) -> Result<FlightLog> {
    layout.check_motor_count(path)?;
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
    } else if path.is_dir() {
        let (aligned, start) =
            crate::ulog::aligned_export_table(path, Some(&layout.time.column), &columns)?;
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
    let (time, table) = match rows {
        None => (time, table),
        Some(rows) => {
            let count = table.rows();
            let sliced = table
                .rows_in(rows.clone())
                .ok_or_else(|| DataError::RowsPastEnd {
                    path: path.to_path_buf(),
                    rows: rows.clone(),
                    count,
                })?;
            (time[rows].to_vec(), sliced)
        }
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
    let [battery, thrust_setpoint, hover_throttle, position] = layout.optional_columns();
    let position_columns = position.zip(layout.position.as_ref());
    for (first, range, names) in [
        (VELOCITY_COLUMN, "v", &layout.velocity),
        (BODY_RATE_COLUMN, "w", &layout.body_rate),
    ]
    .into_iter()
    .chain(position_columns.map(|(first, names)| (first, "p", names)))
    {
        check_plausible(&table, first, range, names)?;
    }
    let quaternion = quaternions(&table, layout)?;
    let rotation = quaternion.iter().map(rotation_from_quaternion).collect();
    let motors = layout.motor_commands.len();
    let mut motor_command = MotorCommands::with_capacity(motors, time.len());
    let mut row = vec![0.0; motors];
    for k in 0..time.len() {
        for (i, value) in row.iter_mut().enumerate() {
            *value = column(FIRST_MOTOR_COLUMN + i)[k] * layout.motor_command_scale;
        }
        motor_command.push(&row);
    }
    let scale = layout.thrust_setpoint.as_ref().map_or(1.0, |c| c.scale);
    let scaled = |index: Option<usize>, factor: f64, range: &str, name: Option<&String>| {
        let Some(i) = index else {
            return Ok(vec![f64::NAN; time.len()]);
        };
        let values: Vec<f64> = column(i).iter().map(|v| v * factor).collect();
        check_plausible_values(&table, &values, range, name.expect("a present column"))?;
        Ok::<_, DataError>(values)
    };
    let thrust_setpoint = scaled(
        thrust_setpoint,
        scale,
        "T_sp",
        layout.thrust_setpoint.as_ref().map(|c| &c.column),
    )?;
    let hover_throttle = scaled(
        hover_throttle,
        1.0,
        "hover_throttle",
        layout.hover_throttle.as_ref(),
    )?;
    Ok(FlightLog {
        path: path.to_path_buf(),
        meta: FlightMeta::from_file_name(path),
        // Not logged: NaN, which `FlightLog::position_logged` reports.
        position: match position {
            Some(first) => vector(first),
            None => vec![[f64::NAN; 3]; time.len()],
        },
        velocity: vector(VELOCITY_COLUMN),
        body_rate: vector(BODY_RATE_COLUMN),
        thrust_setpoint,
        hover_throttle,
        motor_command,
        battery_voltage: battery.map(|i| column(i).clone()),
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
    for (axis, name) in names.iter().enumerate() {
        check_plausible_values(table, &table.columns[first + axis], range, name)?;
    }
    Ok(())
}

/// Fails on the first of `values` (one per row of `table`, as scaled by the layout) outside the
/// plausible range of the Neural-Fly column `range`, naming the layout's column `name`.
fn check_plausible_values(
    table: &NumericTable,
    values: &[f64],
    range: &str,
    name: &str,
) -> Result<()> {
    let range = crate::flight_log::plausible_range(range).expect("a checked column");
    match values
        .iter()
        .position(|v| !(range.min..=range.max).contains(v))
    {
        Some(k) => Err(DataError::Implausible {
            path: table.path.clone(),
            row: table.line(k),
            column: name.to_string(),
            value: values[k],
            min: range.min,
            max: range.max,
            unit: range.unit,
            quantity: range.quantity,
        }),
        None => Ok(()),
    }
}

/// The attitude as `[x, y, z, w]` quaternions in the z-up frames, each checked to be a unit one.
fn quaternions(table: &NumericTable, layout: &RecordingLayout) -> Result<Vec<[f64; 4]>> {
    let column = |i: usize| &table.columns[i];
    (0..table.rows())
        .map(|k| {
            let [w, x, y, z] = std::array::from_fn(|i| column(QUATERNION_COLUMN + i)[k]);
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
