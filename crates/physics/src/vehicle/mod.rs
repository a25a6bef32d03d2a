//! Vehicle descriptions for any multirotor: where each rotor sits and which way it spins, its
//! thrust and moment coefficients, how a motor command becomes thrust, and the centre of mass
//! ([`VehicleDescription`], read from JSON or built by a named constructor); derived from it the
//! allocation (effectiveness) matrix from rotor thrusts to `[T, τx, τy, τz]`, its rank and
//! pseudo-inverse ([`Allocation`]), and the layout's name ([`Layout`]); read from PX4's airframe
//! parameters ([`px4`]).
//!
//! Frame: the body frame is FLU (x forward, y left, z up), positions in metres; PX4's FRD values
//! are converted when read. Torques are about the centre of mass. Fields, units and examples:
//! docs/vehicles.md.

mod allocation;
mod command_map;
mod layout;
pub mod px4;

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{PhysicsError, Result, readable};
use crate::vector::{Vec3, norm, scale, sub};

pub use allocation::Allocation;
pub use command_map::{
    CommandMap, CommandScale, FRACTION_FULL_SCALE, MAX_POLYNOMIAL_POWER, PolynomialTerm,
    ThrustCurve,
};
pub use layout::Layout;

use command_map::invalid;

/// At most this many rotors.
pub const MAX_ROTORS: usize = 16;
/// Rotor positions and the centre of mass lie within this distance of the origin on each axis, m.
pub const MAX_POSITION_M: f64 = 50.0;
/// Largest thrust coefficient, N (per unit of the thrust curve's output).
pub const MAX_THRUST_COEFFICIENT_N: f64 = 1e5;
/// Largest moment-to-thrust ratio, m.
pub const MAX_MOMENT_RATIO_M: f64 = 10.0;

/// Which way a rotor turns, seen from above (from the side its thrust points to). Its drag
/// torque on the body turns the other way: `−km · F · axis` for counter-clockwise.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Spin {
    #[serde(rename = "ccw")]
    CounterClockwise,
    #[serde(rename = "cw")]
    Clockwise,
}

impl Spin {
    /// The sign of the drag torque along the rotor's axis: −1 counter-clockwise, +1 clockwise.
    pub fn torque_sign(self) -> f64 {
        match self {
            Self::CounterClockwise => -1.0,
            Self::Clockwise => 1.0,
        }
    }

    /// The other direction.
    pub fn reversed(self) -> Self {
        match self {
            Self::CounterClockwise => Self::Clockwise,
            Self::Clockwise => Self::CounterClockwise,
        }
    }
}

fn up() -> Vec3 {
    [0.0, 0.0, 1.0]
}

fn is_up(axis: &Vec3) -> bool {
    *axis == up()
}

/// One rotor.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Rotor {
    /// The hub in the body frame (FLU), m.
    pub position_m: Vec3,
    pub spin: Spin,
    /// Thrust (N) per unit of the thrust curve's output: the full-command thrust when the curve
    /// gives a fraction (PX4's `CA_ROTORi_CT`).
    pub thrust_coefficient_n: f64,
    /// km: the drag torque about the axis per newton of thrust, m (≥ 0; the spin gives the sign).
    pub moment_ratio_m: f64,
    /// The direction of the thrust (FLU), a unit vector; up unless given.
    #[serde(default = "up", skip_serializing_if = "is_up")]
    pub axis: Vec3,
}

/// A multirotor: its rotors, their command map and the centre of mass.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VehicleDescription {
    /// What the vehicle is (free text, optional).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub name: String,
    pub rotors: Vec<Rotor>,
    pub command_map: CommandMap,
    /// The centre of mass in the frame of the rotor positions (FLU), m; the origin unless given.
    #[serde(default)]
    pub centre_of_mass_m: Vec3,
}

impl Rotor {
    /// A rotor thrusting up.
    pub fn upright(position_m: Vec3, spin: Spin, thrust_coefficient_n: f64, km: f64) -> Self {
        Self {
            position_m,
            spin,
            thrust_coefficient_n,
            moment_ratio_m: km,
            axis: up(),
        }
    }

    fn check(&mut self, k: usize) -> Result<()> {
        let field = |name: &str| format!("rotors[{k}].{name}");
        check_position(&self.position_m, &field("position_m"))?;
        let ct = self.thrust_coefficient_n;
        if !(ct > 0.0 && ct <= MAX_THRUST_COEFFICIENT_N) {
            return Err(invalid(
                &field("thrust_coefficient_n"),
                format!(
                    "{} is outside (0, {}]",
                    readable(ct),
                    readable(MAX_THRUST_COEFFICIENT_N)
                ),
            ));
        }
        let km = self.moment_ratio_m;
        if !(0.0..=MAX_MOMENT_RATIO_M).contains(&km) {
            return Err(invalid(
                &field("moment_ratio_m"),
                format!(
                    "{} is outside [0, {MAX_MOMENT_RATIO_M}] (the spin gives the sign)",
                    readable(km)
                ),
            ));
        }
        let length = norm(self.axis);
        if !(length.is_finite() && length > 1e-9) {
            return Err(invalid(
                &field("axis"),
                "expected a finite, non-zero direction".into(),
            ));
        }
        self.axis = scale(self.axis, 1.0 / length);
        Ok(())
    }
}

fn check_position(position: &Vec3, field: &str) -> Result<()> {
    for (i, value) in position.iter().enumerate() {
        if !(-MAX_POSITION_M..=MAX_POSITION_M).contains(value) {
            return Err(invalid(
                &format!("{field}[{i}]"),
                format!("{} is outside ±{MAX_POSITION_M} m", readable(*value)),
            ));
        }
    }
    Ok(())
}

impl VehicleDescription {
    /// A checked description (axes made unit length); the error names the field.
    pub fn new(
        name: &str,
        rotors: Vec<Rotor>,
        command_map: CommandMap,
        centre_of_mass_m: Vec3,
    ) -> Result<Self> {
        let mut description = Self {
            name: name.to_string(),
            rotors,
            command_map,
            centre_of_mass_m,
        };
        description.check()?;
        Ok(description)
    }

    fn check(&mut self) -> Result<()> {
        if self.rotors.is_empty() || self.rotors.len() > MAX_ROTORS {
            return Err(invalid(
                "rotors",
                format!("{} rotors; expected 1 to {MAX_ROTORS}", self.rotors.len()),
            ));
        }
        for (k, rotor) in self.rotors.iter_mut().enumerate() {
            rotor.check(k)?;
        }
        check_position(&self.centre_of_mass_m, "centre_of_mass_m")?;
        self.command_map.check()
    }

    /// Reads and checks a description file (the project's JSON policy: unknown fields refused, a
    /// key given twice refused, errors name the field).
    pub fn load(path: &Path) -> Result<Self> {
        let text = bounded_read::read_json_text(path).map_err(|source| PhysicsError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_json(&text, path)
    }

    /// Parses and checks description JSON; `origin` names the file in errors.
    pub fn from_json(text: &str, origin: &Path) -> Result<Self> {
        let mut description: Self =
            bounded_read::json::from_str(text).map_err(|error| PhysicsError::Json {
                path: origin.to_path_buf(),
                message: error.to_string(),
            })?;
        description.check().map_err(|error| match error {
            PhysicsError::Description { field, message } => PhysicsError::Field {
                path: origin.to_path_buf(),
                field,
                message,
            },
            other => other,
        })?;
        Ok(description)
    }

    /// The description as JSON (what [`VehicleDescription::from_json`] reads back).
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("a description serialises")
    }

    /// The rotors' positions relative to the centre of mass, m.
    pub fn lever_arms_m(&self) -> Vec<Vec3> {
        self.rotors
            .iter()
            .map(|r| sub(r.position_m, self.centre_of_mass_m))
            .collect()
    }

    /// Each rotor's distance from the centre of mass in the body's x-y plane, m.
    pub fn arm_lengths_m(&self) -> Vec<f64> {
        self.lever_arms_m()
            .iter()
            .map(|r| r[0].hypot(r[1]))
            .collect()
    }

    /// The allocation matrix from rotor thrusts to `[T, τx, τy, τz]`, its rank and pseudo-inverse.
    pub fn allocation(&self) -> Allocation {
        Allocation::of(self)
    }

    /// The layout's name, if the geometry is one ([`Layout`]).
    pub fn layout(&self) -> Layout {
        Layout::recognise(self)
    }

    /// Each rotor's thrust (N) at its command; `battery_v` is needed by a voltage polynomial.
    pub fn rotor_thrusts(&self, commands: &[f64], battery_v: Option<f64>) -> Result<Vec<f64>> {
        if commands.len() != self.rotors.len() {
            return Err(invalid(
                "rotors",
                format!(
                    "{} commands for {} rotors",
                    commands.len(),
                    self.rotors.len()
                ),
            ));
        }
        self.rotors
            .iter()
            .zip(commands)
            .map(|(rotor, &command)| {
                self.command_map
                    .rotor_thrust(rotor.thrust_coefficient_n, command, battery_v)
            })
            .collect()
    }

    /// `[T, τx, τy, τz]` (N, N·m) at the rotors' commands.
    pub fn wrench(&self, commands: &[f64], battery_v: Option<f64>) -> Result<[f64; 4]> {
        let thrusts = self.rotor_thrusts(commands, battery_v)?;
        Ok(self.allocation().wrench(&thrusts))
    }
}

#[cfg(test)]
mod tests;
