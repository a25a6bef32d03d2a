//! The nominal quadrotor model read from JSON: mass, gravity, inertia and how the collective thrust
//! (and, with a mixer, the body torques) follow from a recorded command.
//!
//! Equations (z up, gravity along −z, `R` body to world, `ω` body rate):
//! `m v̇ = m [0, 0, −g] + R [0, 0, T]` and `J ω̇ = −ω × (J ω) + τ`.
//! With `"thrust_source": "T_sp"`, `T = m g T_sp / hover_throttle` and the torques are unknown;
//! with `"mixer"`, `[T, τx, τy, τz] = b0 · s²` where `s_i = (pwm_i − pwm_offset) / pwm_scale`.
//! `b0` has a column per rotor (4 to [`crate::MAX_ACTUATORS`]). A `"vehicle"` description (a file
//! beside the model, or inline) gives the mixer instead: `s_i² = n_i` the rotor's thrust in units of its coefficient, from its logged command
//! (and the battery voltage) through the vehicle's command map.

use std::path::{Path, PathBuf};

use serde::Serialize;
use serde_json::{Map, Value};

use crate::error::{PhysicsError, Result};
use crate::logger::Logger;
use crate::mixer::{Actuators, Mixer};
use crate::ranges::{self, PhysicalRange};
use crate::vector::{E3, Vec3, add, cross, hadamard, mat_vec, scale};
use crate::vehicle::VehicleDescription;

/// Where the collective thrust comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum ThrustSource {
    /// The motor commands through the mixer matrix (thrust and torques).
    #[serde(rename = "mixer")]
    Mixer,
    /// The normalised thrust setpoint scaled by the hover throttle (thrust only).
    #[serde(rename = "T_sp")]
    ThrustSetpoint,
}

/// Which of the recording's channels the model is compared on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ComparedChannels {
    /// Translational and, with a mixer, angular accelerations.
    #[default]
    All,
    /// The translational accelerations only: the model's torques are not trusted (an inertia or
    /// rotor geometry that is not known).
    Translational,
}

impl ComparedChannels {
    fn is_all(&self) -> bool {
        *self == Self::All
    }
}

/// Thrust (N) and, when the model knows them, body torques (N·m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wrench {
    pub thrust: f64,
    pub torque: Option<Vec3>,
}

/// The nominal model.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NominalModel {
    pub mass_kg: f64,
    pub gravity_m_s2: f64,
    /// Diagonal of the inertia matrix, kg·m².
    pub inertia_kg_m2: Vec3,
    pub thrust_source: ThrustSource,
    pub mixer: Option<Mixer>,
    /// Height of the ground plane in the world frame (optional field, default 0), m.
    pub ground_height_m: f64,
    /// How the recordings compared with this model were logged (optional field; default: the
    /// command sampled at each row's time, no rate filter).
    #[serde(skip_serializing_if = "Logger::is_default")]
    pub logger: Logger,
    /// The vehicle the mixer was derived from, when the model file gave one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vehicle: Option<VehicleDescription>,
    /// The channels compared (optional field; default all).
    #[serde(skip_serializing_if = "ComparedChannels::is_all")]
    pub compared_channels: ComparedChannels,
}

impl NominalModel {
    /// Reads and validates a model file.
    pub fn load(path: &Path) -> Result<Self> {
        let text = bounded_read::read_json_text(path).map_err(|source| PhysicsError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_json(&text, path)
    }

    /// Parses and validates model JSON under the project's reading policy (a byte-order mark
    /// accepted, a key given twice refused); every number must lie in its physical range
    /// ([`crate::ranges`]); `origin` names the file in errors.
    pub fn from_json(text: &str, origin: &Path) -> Result<Self> {
        let text = bounded_read::json::checked_text(text).map_err(|error| PhysicsError::Json {
            path: origin.to_path_buf(),
            message: format!("{}: {}", error.field, error.message),
        })?;
        let value: Value = serde_json::from_str(text).map_err(|error| PhysicsError::Json {
            path: origin.to_path_buf(),
            message: error.to_string(),
        })?;
        let fields = FieldReader {
            path: origin.to_path_buf(),
        };
        let object = value
            .as_object()
            .ok_or_else(|| fields.error("(top level)", "expected a JSON object"))?;
        fields.known_keys(object, "", &MODEL_KEYS)?;
        let mass_kg = fields.in_range(object, &ranges::MASS_KG)?;
        let gravity_m_s2 = fields.in_range(object, &ranges::GRAVITY_M_S2)?;
        let inertia = fields.numbers(object, "inertia_kg_m2", 3)?;
        for (i, value) in inertia.iter().enumerate() {
            ranges::INERTIA_KG_M2
                .check(*value)
                .map_err(|message| fields.error(&format!("inertia_kg_m2[{i}]"), &message))?;
        }
        let thrust_source = match object.get("thrust_source") {
            None => {
                return Err(
                    fields.error("thrust_source", "missing (expected \"mixer\" or \"T_sp\")")
                );
            }
            Some(Value::String(s)) if s == "mixer" => ThrustSource::Mixer,
            Some(Value::String(s)) if s == "T_sp" => ThrustSource::ThrustSetpoint,
            Some(other) => {
                return Err(fields.error(
                    "thrust_source",
                    &format!("expected \"mixer\" or \"T_sp\", found {other}"),
                ));
            }
        };
        let vehicle = match object.get("vehicle") {
            None | Some(Value::Null) => None,
            Some(value) => Some(fields.vehicle(value)?),
        };
        let mixer = match (object.get("mixer"), &vehicle) {
            (None | Some(Value::Null), None) => None,
            (None | Some(Value::Null), Some(vehicle)) => Some(fields.vehicle_mixer(vehicle)?),
            (Some(_), Some(_)) => {
                return Err(fields.error(
                    "mixer",
                    "give a mixer or a vehicle, not both (the vehicle's gives the mixer)",
                ));
            }
            (Some(Value::Object(mixer)), None) => Some(fields.mixer(mixer)?),
            (Some(other), None) => {
                return Err(fields.error("mixer", &format!("expected an object, found {other}")));
            }
        };
        if thrust_source == ThrustSource::Mixer && mixer.is_none() {
            return Err(fields.error(
                "mixer",
                "missing, but thrust_source is \"mixer\" (give a mixer or a vehicle)",
            ));
        }
        if let (Some(mixer), None) = (&mixer, &vehicle) {
            fields.check_lift(mixer, mass_kg * gravity_m_s2)?;
        }
        let ground_height_m = match object.get("ground_height_m") {
            None => 0.0,
            Some(_) => fields.in_range(object, &ranges::GROUND_HEIGHT_M)?,
        };
        let compared_channels = match object.get("compared_channels") {
            None | Some(Value::Null) => ComparedChannels::All,
            Some(Value::String(s)) if s == "all" => ComparedChannels::All,
            Some(Value::String(s)) if s == "translational" => ComparedChannels::Translational,
            Some(other) => {
                return Err(fields.error(
                    "compared_channels",
                    &format!("expected \"all\" or \"translational\", found {other}"),
                ));
            }
        };
        let logger = match object.get("logger") {
            None | Some(Value::Null) => Logger::default(),
            Some(value) => fields.logger(value)?,
        };
        Ok(Self {
            mass_kg,
            gravity_m_s2,
            inertia_kg_m2: [inertia[0], inertia[1], inertia[2]],
            thrust_source,
            mixer,
            ground_height_m,
            logger,
            vehicle,
            compared_channels,
        })
    }

    /// Serialises the model in the documented JSON schema (with a vehicle, the vehicle inline
    /// instead of the mixer derived from it).
    pub fn to_json(&self) -> String {
        let mut value = serde_json::to_value(self).expect("a model serialises");
        if self.vehicle.is_some()
            && let Some(object) = value.as_object_mut()
        {
            object.remove("mixer");
        }
        serde_json::to_string_pretty(&value).expect("a model serialises")
    }

    /// Whether the motor commands need the battery voltage to give thrust.
    pub fn needs_battery_voltage(&self) -> bool {
        self.thrust_source == ThrustSource::Mixer
            && self
                .mixer
                .as_ref()
                .is_some_and(Mixer::needs_battery_voltage)
    }

    /// Whether the model predicts body torques (it has a mixer and uses it, and its angular
    /// channels are compared).
    pub fn predicts_torque(&self) -> bool {
        self.thrust_source == ThrustSource::Mixer && self.compared_channels == ComparedChannels::All
    }

    /// The actuator states the recorded command asks for: the normalised motor speeds with a
    /// mixer (`pwm` a command per rotor), or `[T, 0, …]` (N) with `T_sp`. Delays and lags act on
    /// these.
    pub fn actuator_command(
        &self,
        thrust_setpoint: f64,
        hover_throttle: f64,
        pwm: &[f64],
        battery_v: Option<f64>,
    ) -> Actuators {
        match self.thrust_source {
            ThrustSource::Mixer => self
                .mixer
                .as_ref()
                .expect("validated: a mixer model has a mixer")
                .speeds(pwm, battery_v),
            ThrustSource::ThrustSetpoint => {
                let mut thrust = [0.0; crate::MAX_ACTUATORS];
                thrust[0] = self.mass_kg * self.gravity_m_s2 * thrust_setpoint / hover_throttle;
                thrust
            }
        }
    }

    /// How many entries of an actuator command are used (a motor each, or 1 thrust).
    pub fn actuator_count(&self) -> usize {
        match (&self.mixer, self.thrust_source) {
            (Some(mixer), ThrustSource::Mixer) => mixer.rotors(),
            _ => 1,
        }
    }

    /// How many motor commands a recording must have a row (none with `T_sp`).
    pub fn motor_count(&self) -> Option<usize> {
        match (&self.mixer, self.thrust_source) {
            (Some(mixer), ThrustSource::Mixer) => Some(mixer.rotors()),
            _ => None,
        }
    }

    /// Thrust and torques produced by actuator states whose values spread within the time they
    /// stand for with variances `spread` (a mixer's squares see the spread; `T_sp` is linear).
    pub fn wrench_with_spread(&self, actuators: &Actuators, spread: &Actuators) -> Wrench {
        match (&self.mixer, self.thrust_source) {
            (Some(mixer), ThrustSource::Mixer) => {
                let mut w = mixer.wrench(actuators);
                for (total, extra) in w.iter_mut().zip(mixer.spread_wrench(spread)) {
                    *total += extra;
                }
                Wrench {
                    thrust: w[0],
                    torque: Some([w[1], w[2], w[3]]),
                }
            }
            _ => self.wrench(actuators),
        }
    }

    /// Thrust and torques produced by actuator states.
    pub fn wrench(&self, actuators: &Actuators) -> Wrench {
        match self.thrust_source {
            ThrustSource::Mixer => {
                let w = self
                    .mixer
                    .as_ref()
                    .expect("validated: a mixer model has a mixer")
                    .wrench(actuators);
                Wrench {
                    thrust: w[0],
                    torque: Some([w[1], w[2], w[3]]),
                }
            }
            ThrustSource::ThrustSetpoint => Wrench {
                thrust: actuators[0],
                torque: None,
            },
        }
    }

    /// Nominal `v̇ = [0, 0, −g] + R e3 T / m`.
    pub fn translational_acceleration(&self, rotation: &crate::vector::Mat3, thrust: f64) -> Vec3 {
        add(
            [0.0, 0.0, -self.gravity_m_s2],
            scale(mat_vec(rotation, E3), thrust / self.mass_kg),
        )
    }

    /// Nominal `ω̇ = J⁻¹ (τ − ω × J ω)`.
    pub fn angular_acceleration(&self, rate: Vec3, torque: Vec3) -> Vec3 {
        angular_acceleration_with_inertia(self.inertia_kg_m2, rate, torque)
    }

    /// The residual force `fa = m v̇ − m [0, 0, −g] − R e3 T` (N) for an acceleration `v̇`.
    pub fn residual_force(
        &self,
        acceleration: Vec3,
        rotation: &crate::vector::Mat3,
        thrust: f64,
    ) -> Vec3 {
        let predicted = self.translational_acceleration(rotation, thrust);
        scale(crate::vector::sub(acceleration, predicted), self.mass_kg)
    }
}

/// `ω̇ = J⁻¹ (τ − ω × J ω)` for a diagonal inertia `J`.
pub fn angular_acceleration_with_inertia(inertia: Vec3, rate: Vec3, torque: Vec3) -> Vec3 {
    let gyroscopic = cross(rate, hadamard(inertia, rate));
    let net = crate::vector::sub(torque, gyroscopic);
    [
        net[0] / inertia[0],
        net[1] / inertia[1],
        net[2] / inertia[2],
    ]
}

/// The fields of a model file; any other is an error (as `deny_unknown_fields` elsewhere).
const MODEL_KEYS: [&str; 9] = [
    "mass_kg",
    "gravity_m_s2",
    "inertia_kg_m2",
    "thrust_source",
    "mixer",
    "ground_height_m",
    "logger",
    "vehicle",
    "compared_channels",
];
/// The fields of the `mixer` object.
const MIXER_KEYS: [&str; 3] = ["pwm_offset", "pwm_scale", "b0"];

struct FieldReader {
    path: PathBuf,
}

impl FieldReader {
    fn error(&self, field: &str, message: &str) -> PhysicsError {
        PhysicsError::Field {
            path: self.path.clone(),
            field: field.to_string(),
            message: message.to_string(),
        }
    }

    /// Fails on the first key of `object` that is not in `known` (`prefix` names the object).
    fn known_keys(&self, object: &Map<String, Value>, prefix: &str, known: &[&str]) -> Result<()> {
        match object.keys().find(|key| !known.contains(&key.as_str())) {
            Some(key) => Err(self.error(
                &format!("{prefix}{key}"),
                &format!("unknown field, expected one of {}", known.join(", ")),
            )),
            None => Ok(()),
        }
    }

    fn finite_value(&self, value: Option<&Value>, field: &str) -> Result<f64> {
        match value {
            None => Err(self.error(field, "missing")),
            Some(Value::Number(n)) => n
                .as_f64()
                .filter(|v| v.is_finite())
                .ok_or_else(|| self.error(field, "not a finite number")),
            Some(other) => Err(self.error(field, &format!("expected a number, found {other}"))),
        }
    }

    /// A number of `object` named by `range.field`, within the range.
    fn in_range(&self, object: &Map<String, Value>, range: &PhysicalRange) -> Result<f64> {
        self.checked(object.get(range.field), range.field, range)
    }

    /// The number `value` of `field`, within `range`.
    fn checked(&self, value: Option<&Value>, field: &str, range: &PhysicalRange) -> Result<f64> {
        let value = self.finite_value(value, field)?;
        range
            .check(value)
            .map_err(|message| self.error(field, &message))
    }

    /// The rotors at full speed must lift `weight_n` (and no vehicle lifts a hundred times it).
    fn check_lift(&self, mixer: &Mixer, weight_n: f64) -> Result<()> {
        let full_thrust: f64 = mixer.row(0).iter().sum();
        ranges::THRUST_TO_WEIGHT
            .check(full_thrust / weight_n)
            .map(drop)
            .map_err(|message| {
                let detail = format!(
                    "{message} (thrust {} N, weight {} N)",
                    crate::error::readable(full_thrust),
                    crate::error::readable(weight_n)
                );
                self.error("mixer.b0[0]", &detail)
            })
    }

    fn numbers_of(&self, value: Option<&Value>, field: &str, count: usize) -> Result<Vec<f64>> {
        let array = match value {
            None => return Err(self.error(field, "missing")),
            Some(Value::Array(a)) => a,
            Some(other) => {
                return Err(self.error(
                    field,
                    &format!("expected a list of {count} numbers, found {other}"),
                ));
            }
        };
        if array.len() != count {
            return Err(self.error(
                field,
                &format!("expected {count} numbers, found {}", array.len()),
            ));
        }
        array
            .iter()
            .enumerate()
            .map(|(i, v)| self.finite_value(Some(v), &format!("{field}[{i}]")))
            .collect()
    }

    fn numbers(&self, object: &Map<String, Value>, field: &str, count: usize) -> Result<Vec<f64>> {
        self.numbers_of(object.get(field), field, count)
    }

    fn logger(&self, value: &Value) -> Result<Logger> {
        let Value::Object(object) = value else {
            return Err(self.error("logger", &format!("expected an object, found {value}")));
        };
        self.known_keys(
            object,
            "logger.",
            &[
                "command",
                "command_time_offset_s",
                "rate_low_pass_hz",
                "controller_rate_hz",
            ],
        )?;
        // Read from its own text, the error's position is not the file's: only its field is kept.
        let logger: Logger = bounded_read::json::from_str(&value.to_string()).map_err(|error| {
            let field = error.field.split(" (").next().unwrap_or_default();
            let field = if field.starts_with("the document") {
                "logger".to_string()
            } else {
                format!("logger.{field}")
            };
            self.error(&field, &error.message)
        })?;
        logger
            .validate()
            .map_err(|(field, message)| self.error(&format!("logger.{field}"), &message))?;
        Ok(logger)
    }

    /// The `vehicle` field: a vehicle description file's path (relative to the model file) or the
    /// description itself.
    fn vehicle(&self, value: &Value) -> Result<VehicleDescription> {
        match value {
            Value::String(relative) => {
                let path = self.path.parent().unwrap_or(Path::new(".")).join(relative);
                VehicleDescription::load(&path)
            }
            Value::Object(_) => VehicleDescription::from_json(&value.to_string(), &self.path),
            other => Err(self.error(
                "vehicle",
                &format!("expected a file name or an object, found {other}"),
            )),
        }
    }

    /// The mixer of a vehicle of 4 to [`crate::MAX_ACTUATORS`] rotors.
    fn vehicle_mixer(&self, vehicle: &VehicleDescription) -> Result<Mixer> {
        Mixer::from_vehicle(vehicle).ok_or_else(|| {
            self.error(
                "vehicle",
                &format!(
                    "the model takes a vehicle of 4 to {} rotors that set thrust and the three torques independently (allocation rank 4); this one has {} rotors and rank {}",
                    crate::MAX_ACTUATORS,
                    vehicle.rotors.len(),
                    vehicle.allocation().rank()
                ),
            )
        })
    }

    fn mixer(&self, mixer: &Map<String, Value>) -> Result<Mixer> {
        self.known_keys(mixer, "mixer.", &MIXER_KEYS)?;
        let pwm_offset = self.checked(
            mixer.get("pwm_offset"),
            ranges::PWM_OFFSET.field,
            &ranges::PWM_OFFSET,
        )?;
        let pwm_scale = self.checked(
            mixer.get("pwm_scale"),
            ranges::PWM_SCALE.field,
            &ranges::PWM_SCALE,
        )?;
        let shape = format!(
            "expected 4 rows of 4 to {} numbers, one per rotor",
            crate::MAX_ACTUATORS
        );
        let rows = match mixer.get("b0") {
            None => return Err(self.error("mixer.b0", "missing")),
            Some(Value::Array(rows)) if rows.len() == 4 => rows,
            Some(_) => return Err(self.error("mixer.b0", &shape)),
        };
        let rotors = match &rows[0] {
            Value::Array(first) if (4..=crate::MAX_ACTUATORS).contains(&first.len()) => first.len(),
            _ => return Err(self.error("mixer.b0[0]", &shape)),
        };
        let mut b0: [Vec<f64>; 4] = Default::default();
        for (i, row) in rows.iter().enumerate() {
            b0[i] = self.numbers_of(Some(row), &format!("mixer.b0[{i}]"), rotors)?;
        }
        // Row 0 maps the squared motor speeds to the collective thrust: every motor pushes up.
        if let Some(j) = b0[0].iter().position(|v| *v <= 0.0) {
            return Err(self.error(
                &format!("mixer.b0[0][{j}]"),
                &format!(
                    "the thrust row must be positive (each motor adds thrust), found {}",
                    b0[0][j]
                ),
            ));
        }
        for (i, row) in b0.iter().enumerate() {
            let range = if i == 0 {
                &ranges::ROTOR_THRUST_N
            } else {
                &ranges::ROTOR_TORQUE_N_M
            };
            for (j, value) in row.iter().enumerate() {
                range
                    .check(*value)
                    .map_err(|message| self.error(&format!("mixer.b0[{i}][{j}]"), &message))?;
            }
        }
        Mixer::new(pwm_offset, pwm_scale, &b0).ok_or_else(|| {
            self.error(
                "mixer.b0",
                "the matrix is singular (rank below 4: thrust and the three torques are not independent)",
            )
        })
    }
}

#[cfg(test)]
mod tests;
