//! Typed Neural-Fly flight logs.

use std::path::{Path, PathBuf};

use rotation::{
    Mat3, mat_mul, mat_scale, mat_sub, quaternion_from_rotation, rotation_from_quaternion,
    transpose, vee,
};
use serde::{Deserialize, Serialize};

use crate::error::{DataError, Result};
use crate::motors::MotorCommands;
use crate::table::TextTable;
use crate::time::{
    SampleTiming, Spacing, check_interval_range, check_time_axis_at, median_interval,
};

/// `<vehicle>_<trajectory>_<method>_<condition>.csv`, as the Neural-Fly data names its files.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct FlightMeta {
    pub vehicle: String,
    pub trajectory: String,
    pub method: String,
    pub condition: String,
}

impl FlightMeta {
    /// Parses the metadata from a file name; `None` when it does not follow the scheme.
    pub fn from_file_name(path: &Path) -> Option<Self> {
        let stem = path.file_stem()?.to_str()?;
        let mut parts = stem.splitn(4, '_');
        let vehicle = parts.next()?.to_string();
        let trajectory = parts.next()?.to_string();
        let rest: Vec<&str> = parts.collect();
        if rest.len() != 2 || rest.iter().any(|p| p.is_empty()) || vehicle.is_empty() {
            return None;
        }
        // The method may itself contain '_' in other datasets; the condition never does.
        let (method, condition) = match rest[1].rsplit_once('_') {
            Some((extra, condition)) => (format!("{}_{extra}", rest[0]), condition.to_string()),
            None => (rest[0].to_string(), rest[1].to_string()),
        };
        Some(Self {
            vehicle,
            trajectory,
            method,
            condition,
        })
    }
}

/// One flight: every sample of a Neural-Fly CSV log, typed.
///
/// Conventions (see `UPSTREAM-README.md` of the data): world frame z up, gravity along −z;
/// `rotation` maps body to world; quaternions are `[x, y, z, w]` (scalar last); thrust acts along the
/// third column of `rotation`. `body_rate` is the `w` column as recorded: check its frame with
/// [`FlightLog::rate_frame`] before relying on it.
#[derive(Clone, Debug)]
pub struct FlightLog {
    pub path: PathBuf,
    pub meta: Option<FlightMeta>,
    /// Time in seconds, strictly increasing (at a uniform rate when read with [`Spacing::Uniform`]).
    pub time: Vec<f64>,
    /// World position, m; NaN on every row when the log has none ([`FlightLog::position_logged`]).
    pub position: Vec<[f64; 3]>,
    pub velocity: Vec<[f64; 3]>,
    pub quaternion: Vec<[f64; 4]>,
    /// Body to world, row-major.
    pub rotation: Vec<Mat3>,
    /// The `w` column, rad/s.
    pub body_rate: Vec<[f64; 3]>,
    /// `T_sp`: normalised thrust setpoint.
    pub thrust_setpoint: Vec<f64>,
    pub hover_throttle: Vec<f64>,
    /// `pwm`: the motor commands, one per rotor (four in the Neural-Fly logs, about 1000 to 2000;
    /// as logged in another layout: [`crate::layout`]).
    pub motor_command: MotorCommands,
    /// Battery voltage, V, when the file has it (the optional `battery_voltage` column of the
    /// Neural-Fly layout, which the upstream logs never have; a layout's `battery_voltage`).
    pub battery_voltage: Option<Vec<f64>>,
    /// The frame of `body_rate` when the file's layout declares it (a layout description's body
    /// rate is in the body frame); `None` for the Neural-Fly layout, whose `w` column's frame
    /// [`FlightLog::rate_frame`] finds.
    pub declared_rate_frame: Option<RateFrame>,
    pub position_desired: Option<Vec<[f64; 3]>>,
    pub velocity_desired: Option<Vec<[f64; 3]>>,
    pub attitude_setpoint: Option<Vec<[f64; 4]>>,
    /// `fa`: the residual force computed upstream, N.
    pub residual_force: Option<Vec<[f64; 3]>>,
}

/// The columns a flight log must have (and `q` or `R`, at least one of them).
pub const REQUIRED_COLUMNS: [&str; 7] = ["t", "p", "v", "w", "T_sp", "hover_throttle", "pwm"];

/// A generous physically plausible range of one recorded quantity: every component of every row of
/// its column must lie in `[min, max]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlausibleRange {
    pub column: &'static str,
    pub min: f64,
    pub max: f64,
    /// Empty, or the unit with a leading space.
    pub unit: &'static str,
    pub quantity: &'static str,
}

impl PlausibleRange {
    const fn symmetric(
        column: &'static str,
        bound: f64,
        unit: &'static str,
        quantity: &'static str,
    ) -> Self {
        Self {
            column,
            min: -bound,
            max: bound,
            unit,
            quantity,
        }
    }
}

/// A flight log is a physical recording: values far outside these ranges are corrupt (or in other
/// units), and would only reach the analyses as overflowing or meaningless numbers. The ranges are
/// orders of magnitude wider than anything in the 30 Neural-Fly flights, whose observed extremes
/// are given for each. Checked per component on every row; optional columns when present.
pub const PLAUSIBLE_RANGES: [PlausibleRange; 11] = [
    // Observed: −1.58 to 3.09 m (a motion-capture room).
    PlausibleRange::symmetric("p", 1e4, " m", "a position component"),
    // Observed: −1.00 to 2.90 m.
    PlausibleRange::symmetric("p_d", 1e4, " m", "a desired position component"),
    // Observed: −1.69 to 1.61 m/s.
    PlausibleRange::symmetric("v", 1e3, " m/s", "a velocity component"),
    // Observed: −1.50 to 1.50 m/s.
    PlausibleRange::symmetric("v_d", 1e3, " m/s", "a desired velocity component"),
    // Observed: −1.20 to 1.35 rad/s.
    PlausibleRange::symmetric("w", 1e3, " rad/s", "an angular rate component"),
    // Observed: 0.215 to 1.062 (normalised throttle).
    PlausibleRange {
        column: "T_sp",
        min: 0.0,
        max: 100.0,
        unit: "",
        quantity: "the normalised thrust setpoint",
    },
    // Observed: 0.444 to 0.517 (normalised; T = m g T_sp / hover_throttle divides by it).
    PlausibleRange {
        column: "hover_throttle",
        min: 1e-3,
        max: 10.0,
        unit: "",
        quantity: "the normalised hover throttle",
    },
    // Observed: 548 to 1999 (motor commands, about 1000 to 2000).
    PlausibleRange {
        column: "pwm",
        min: 0.0,
        max: 1e5,
        unit: "",
        quantity: "a motor command",
    },
    // Not in the Neural-Fly logs; written by the simulator with a battery (a 24-cell pack is
    // about 100 V).
    PlausibleRange {
        column: "battery_voltage",
        min: 0.0,
        max: 1000.0,
        unit: " V",
        quantity: "a battery voltage",
    },
    // Observed: −27.7 to 14.2 N (a 2.6 kg vehicle weighs 26 N).
    PlausibleRange::symmetric("fa", 1e5, " N", "a residual force component"),
    // Observed: −1.0 to 0.12 (a quaternion: components of a unit one are within ±1).
    PlausibleRange::symmetric("q_sp", 2.0, "", "an attitude setpoint quaternion component"),
];

/// The plausible range of a flight log's sample interval, s (observed: 0.01999999999998 to
/// 0.02000798722045 s, i.e. 50 Hz): each interval must lie in it, which rejects times in other
/// units (ms, µs) and corrupted time columns. The lower end, 100 kHz, leaves room for rounding
/// at the simulator's fastest rate (10 kHz).
pub const SAMPLE_INTERVAL_RANGE_S: (f64, f64) = (1e-5, 10.0);

/// The plausible range of `column`, if it has one.
pub fn plausible_range(column: &str) -> Option<&'static PlausibleRange> {
    PLAUSIBLE_RANGES.iter().find(|r| r.column == column)
}

/// Fails on the first row whose value (any component) lies outside the column's plausible range.
fn check_plausible<'a>(
    table: &TextTable,
    column: &str,
    rows: impl Iterator<Item = &'a [f64]>,
) -> Result<()> {
    let range = plausible_range(column).expect("every checked column has a range");
    for (index, row) in rows.enumerate() {
        if let Some(&value) = row.iter().find(|v| !(range.min..=range.max).contains(*v)) {
            return Err(DataError::Implausible {
                path: table.path().to_path_buf(),
                row: table.line(index),
                column: column.to_string(),
                value,
                min: range.min,
                max: range.max,
                unit: range.unit,
                quantity: range.quantity,
            });
        }
    }
    Ok(())
}

/// The frame in which the recorded angular rate `w` is expressed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RateFrame {
    Body,
    World,
}

impl FlightLog {
    /// Reads and validates a uniformly sampled log ([`Spacing::Uniform`]: the paper's pipelines
    /// difference at a fixed step). Errors name the file, row and column. Besides the layout and
    /// the attitude, the values must be physically plausible: every sample interval in
    /// `SAMPLE_INTERVAL_RANGE_S` and every quantity in its `PLAUSIBLE_RANGES` (see this module).
    pub fn read(path: &Path) -> Result<Self> {
        Self::read_spaced(path, Spacing::Uniform)
    }

    /// [`FlightLog::read`] with the samples spaced as `spacing` allows ([`Spacing::Any`]: a real
    /// logger's jitter, dropped samples and gaps).
    pub fn read_spaced(path: &Path, spacing: Spacing) -> Result<Self> {
        Self::read_with_columns(path, spacing).map(|(log, _)| log)
    }

    /// [`FlightLog::read_spaced`], also returning the names of the file's columns in file order
    /// (what a log does not keep: which of `q` and `R` were recorded, and columns it does not use).
    pub fn read_with_columns(path: &Path, spacing: Spacing) -> Result<(Self, Vec<String>)> {
        let table = TextTable::read(path)?;
        let time = table.scalars("t")?;
        check_time_axis_at(path, "t", &time, spacing.tolerance(), &|k| table.line(k))?;
        check_interval_range(path, "t", &time, SAMPLE_INTERVAL_RANGE_S, &|k| {
            table.line(k)
        })?;
        let has_q = table.has_column("q");
        let has_r = table.has_column("R");
        if !has_q && !has_r {
            return Err(DataError::MissingColumn {
                path: path.to_path_buf(),
                column: "q (or R)".to_string(),
                present: table.column_list(),
            });
        }
        let quaternion = if has_q {
            Some(table.arrays::<4>("q")?)
        } else {
            None
        };
        let rotation = if has_r {
            Some(
                table
                    .arrays::<9>("R")?
                    .into_iter()
                    .map(|m| [[m[0], m[1], m[2]], [m[3], m[4], m[5]], [m[6], m[7], m[8]]])
                    .collect::<Vec<_>>(),
            )
        } else {
            None
        };
        let (quaternion, rotation) = match (quaternion, rotation) {
            (Some(q), Some(r)) => (q, r),
            (Some(q), None) => {
                let r = q.iter().map(rotation_from_quaternion).collect();
                (q, r)
            }
            (None, Some(r)) => (r.iter().map(quaternion_from_rotation).collect(), r),
            (None, None) => unreachable!("checked above"),
        };
        check_unit_quaternions(&table, &quaternion, has_q)?;
        check_rotations(&table, &rotation, has_r)?;
        if has_q && has_r {
            check_agreement(&table, &quaternion, &rotation)?;
        }
        let arrays3 = |name: &str| -> Result<Vec<[f64; 3]>> {
            let values = table.arrays::<3>(name)?;
            check_plausible(&table, name, values.iter().map(|v| v.as_slice()))?;
            Ok(values)
        };
        let optional3 = |name: &str| -> Result<Option<Vec<[f64; 3]>>> {
            if table.has_column(name) {
                arrays3(name).map(Some)
            } else {
                Ok(None)
            }
        };
        let scalars = |name: &str| -> Result<Vec<f64>> {
            let values = table.scalars(name)?;
            check_plausible(&table, name, values.iter().map(std::slice::from_ref))?;
            Ok(values)
        };
        let arrays4 = |name: &str| -> Result<Vec<[f64; 4]>> {
            let values = table.arrays::<4>(name)?;
            check_plausible(&table, name, values.iter().map(|v| v.as_slice()))?;
            Ok(values)
        };
        let log = Self {
            path: path.to_path_buf(),
            meta: FlightMeta::from_file_name(path),
            position: arrays3("p")?,
            velocity: arrays3("v")?,
            body_rate: arrays3("w")?,
            thrust_setpoint: scalars("T_sp")?,
            hover_throttle: scalars("hover_throttle")?,
            motor_command: {
                let commands = table.motor_commands("pwm")?;
                check_plausible(&table, "pwm", commands.rows())?;
                commands
            },
            battery_voltage: if table.has_column("battery_voltage") {
                Some(scalars("battery_voltage")?)
            } else {
                None
            },
            declared_rate_frame: None,
            position_desired: optional3("p_d")?,
            velocity_desired: optional3("v_d")?,
            attitude_setpoint: if table.has_column("q_sp") {
                Some(arrays4("q_sp")?)
            } else {
                None
            },
            residual_force: optional3("fa")?,
            time,
            quaternion,
            rotation,
        };
        Ok((log, table.column_names()))
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.time.len()
    }

    /// Whether the log holds the position (a layout may map none: its positions are then NaN).
    pub fn position_logged(&self) -> bool {
        self.position
            .first()
            .is_some_and(|p| p.iter().all(|x| x.is_finite()))
    }

    /// Whether the log has no samples (never true for a log that was read successfully).
    pub fn is_empty(&self) -> bool {
        self.time.is_empty()
    }

    /// The data rows `rows` (counted from 0, the end excluded) as a log of their own, with the
    /// same path and times; `None` unless `rows` is a non-empty range inside the log.
    pub fn row_range(&self, rows: std::ops::Range<usize>) -> Option<Self> {
        if rows.is_empty() || rows.end > self.len() {
            return None;
        }
        let part = |values: &Option<Vec<_>>| values.as_ref().map(|v| v[rows.clone()].to_vec());
        Some(Self {
            path: self.path.clone(),
            meta: self.meta.clone(),
            time: self.time[rows.clone()].to_vec(),
            position: self.position[rows.clone()].to_vec(),
            velocity: self.velocity[rows.clone()].to_vec(),
            quaternion: self.quaternion[rows.clone()].to_vec(),
            rotation: self.rotation[rows.clone()].to_vec(),
            body_rate: self.body_rate[rows.clone()].to_vec(),
            thrust_setpoint: self.thrust_setpoint[rows.clone()].to_vec(),
            hover_throttle: self.hover_throttle[rows.clone()].to_vec(),
            motor_command: self.motor_command.range(rows.clone()),
            battery_voltage: self
                .battery_voltage
                .as_ref()
                .map(|v| v[rows.clone()].to_vec()),
            declared_rate_frame: self.declared_rate_frame,
            position_desired: part(&self.position_desired),
            velocity_desired: part(&self.velocity_desired),
            attitude_setpoint: self
                .attitude_setpoint
                .as_ref()
                .map(|v| v[rows.clone()].to_vec()),
            residual_force: part(&self.residual_force),
        })
    }

    /// The mean sample interval, s.
    pub fn sample_interval(&self) -> f64 {
        (self.time[self.len() - 1] - self.time[0]) / (self.len() - 1) as f64
    }

    /// The median sample interval, s (of an even count of intervals the larger middle one).
    pub fn median_interval(&self) -> f64 {
        median_interval(&self.time)
    }

    /// How the samples are spaced: median interval, jitter, gaps (`None` under two samples).
    pub fn sample_timing(&self) -> Option<SampleTiming> {
        SampleTiming::of(&self.time)
    }

    /// The wind condition from the file name, or `"unknown"`.
    pub fn condition(&self) -> &str {
        self.meta
            .as_ref()
            .map(|m| m.condition.as_str())
            .unwrap_or("unknown")
    }

    /// Decides in which frame `w` was recorded by comparing it with the rates implied by the rotation
    /// matrices: world frame vee(Ṙ Rᵀ) and body frame vee(Rᵀ Ṙ), with Ṙ by central differences.
    /// Returns the frame with the smaller RMS error and both errors (body, world).
    pub fn rate_frame(&self) -> (RateFrame, f64, f64) {
        let n = self.len();
        let (mut body_error, mut world_error, mut count) = (0.0, 0.0, 0usize);
        for k in 1..n.saturating_sub(1) {
            let dt = self.time[k + 1] - self.time[k - 1];
            let rdot = mat_scale(
                &mat_sub(&self.rotation[k + 1], &self.rotation[k - 1]),
                1.0 / dt,
            );
            let r = &self.rotation[k];
            let world = vee(&mat_mul(&rdot, &transpose(r)));
            let body = vee(&mat_mul(&transpose(r), &rdot));
            let w = self.body_rate[k];
            for i in 0..3 {
                body_error += (w[i] - body[i]).powi(2);
                world_error += (w[i] - world[i]).powi(2);
            }
            count += 3;
        }
        let body_rms = (body_error / count.max(1) as f64).sqrt();
        let world_rms = (world_error / count.max(1) as f64).sqrt();
        let frame = if world_rms < body_rms {
            RateFrame::World
        } else {
            RateFrame::Body
        };
        (frame, body_rms, world_rms)
    }
}

fn check_unit_quaternions(
    table: &TextTable,
    quaternion: &[[f64; 4]],
    recorded: bool,
) -> Result<()> {
    if !recorded {
        return Ok(());
    }
    for (index, q) in quaternion.iter().enumerate() {
        let norm = q.iter().map(|v| v * v).sum::<f64>().sqrt();
        if (norm - 1.0).abs() > 1e-3 {
            return Err(DataError::BadCell {
                path: table.path().to_path_buf(),
                row: table.line(index),
                column: "q".to_string(),
                value: format!("\"{q:?}\""),
                reason: format!("not a unit quaternion (norm {norm:.6})"),
            });
        }
    }
    Ok(())
}

/// The largest |a_ij − b_ij|.
fn largest_difference(a: &Mat3, b: &Mat3) -> f64 {
    a.iter()
        .flatten()
        .zip(b.iter().flatten())
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Largest deviation of R Rᵀ from the identity accepted for a recorded `R` (the Neural-Fly logs
/// deviate by at most 3e-4).
const ROTATION_TOLERANCE: f64 = 1e-2;

fn check_rotations(table: &TextTable, rotation: &[Mat3], recorded: bool) -> Result<()> {
    if !recorded {
        return Ok(());
    }
    for (index, r) in rotation.iter().enumerate() {
        let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let deviation = largest_difference(&mat_mul(r, &transpose(r)), &identity);
        let determinant = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1])
            - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0])
            + r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
        if deviation > ROTATION_TOLERANCE || determinant <= 0.0 {
            return Err(DataError::BadCell {
                path: table.path().to_path_buf(),
                row: table.line(index),
                column: "R".to_string(),
                value: format!("\"{r:?}\""),
                reason: format!(
                    "not a rotation matrix (largest |R Rᵀ − I| entry {deviation:.6}, determinant {determinant:.6})"
                ),
            });
        }
    }
    Ok(())
}

/// When both are recorded, `q` and `R` must describe the same attitude (the Neural-Fly logs differ
/// by at most 2e-4 per entry).
fn check_agreement(table: &TextTable, quaternion: &[[f64; 4]], rotation: &[Mat3]) -> Result<()> {
    for (index, (q, r)) in quaternion.iter().zip(rotation).enumerate() {
        let difference = largest_difference(&rotation_from_quaternion(q), r);
        if difference > ROTATION_TOLERANCE {
            return Err(DataError::BadCell {
                path: table.path().to_path_buf(),
                row: table.line(index),
                column: "R".to_string(),
                value: format!("\"{r:?}\""),
                reason: format!(
                    "does not match the rotation of q {q:?} (largest entry difference {difference:.6})"
                ),
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn file_names_follow_the_neural_fly_scheme() {
        let meta =
            FlightMeta::from_file_name(Path::new("x/custom_figure8_NF-C_70p20sint.csv")).unwrap();
        assert_eq!(meta.vehicle, "custom");
        assert_eq!(meta.trajectory, "figure8");
        assert_eq!(meta.method, "NF-C");
        assert_eq!(meta.condition, "70p20sint");
        assert!(FlightMeta::from_file_name(Path::new("flight.csv")).is_none());
    }
}
