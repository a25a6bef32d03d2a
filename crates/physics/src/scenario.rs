//! A simulation scenario: what is flown (trajectory, duration, rates), how it is logged (logger,
//! jitter, noise) and the plant's effects, read from JSON and checked against the bounds below.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::battery::Battery;
use crate::controller::Gains;
use crate::effects::Effects;
use crate::error::{PhysicsError, Result, readable};
use crate::jitter::Jitter;
use crate::log_timing::LogTiming;
use crate::logger::{CommandLogging, Logger};
use crate::model::NominalModel;
use crate::trajectory::{MAX_POSITION_M, Trajectory};
use crate::vector::norm;

/// Standard deviations of the measurement noise.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Noise {
    pub position_m: f64,
    pub velocity_m_s: f64,
    pub attitude_rad: f64,
    pub rate_rad_s: f64,
}

/// One simulated flight, as read from a scenario JSON file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// The nominal model file, relative to the scenario file.
    pub model: PathBuf,
    pub duration_s: f64,
    /// Flight time before the recording starts (the integrators settle meanwhile), s.
    #[serde(default)]
    pub warmup_s: f64,
    pub seed: u64,
    #[serde(default = "default_physics_rate")]
    pub physics_rate_hz: f64,
    #[serde(default = "default_log_rate")]
    pub log_rate_hz: f64,
    /// Written to the `hover_throttle` column; `T_sp = T / (m g) · hover_throttle`.
    #[serde(default = "default_hover_throttle")]
    pub hover_throttle: f64,
    pub trajectory: Trajectory,
    #[serde(default)]
    pub effects: Effects,
    #[serde(default)]
    pub noise: Noise,
    #[serde(default)]
    pub gains: Gains,
    /// How often the controller runs, Hz (default: the log rate). A whole multiple of the log rate
    /// and a whole divisor of the physics rate.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub controller_rate_hz: Option<f64>,
    /// How the log is made (default: each command held until the next row when the controller
    /// runs at the log rate, the instantaneous command otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub logger: Option<Logger>,
    /// Band-limited jitter added to the controller's commands (none by default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub jitter: Option<Jitter>,
    /// A real logger's timing: rows jittered, dropped, or missing over gaps (none by default:
    /// every row on time). Needs a `sample` logger of a controller faster than the log.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub log_timing: Option<LogTiming>,
    /// The battery, whose voltage the log records and a voltage-dependent thrust map reads (none
    /// by default; needed by such a map).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub battery: Option<Battery>,
}

fn default_physics_rate() -> f64 {
    500.0
}
fn default_log_rate() -> f64 {
    50.0
}
fn default_hover_throttle() -> f64 {
    0.5
}

/// The longest flight a scenario may record, s.
pub const MAX_DURATION_S: f64 = 3600.0;
/// The longest warm-up before the recording, s.
pub const MAX_WARMUP_S: f64 = 60.0;
/// The lowest and the highest physics rate, Hz.
pub const MIN_PHYSICS_RATE_HZ: f64 = 500.0;
pub const MAX_PHYSICS_RATE_HZ: f64 = 10_000.0;
/// The fewest rows a simulated log may have (`⌊duration_s · log_rate_hz⌋ + 1`): enough for the
/// mismatch analysis (8 Savitzky–Golay windows of 21 rows) and the data tools.
pub const MIN_LOG_ROWS: usize = 250;
/// The most rows a simulated log may have.
pub const MAX_LOG_ROWS: usize = 500_000;
/// The longest actuator delay the simulator accepts, s.
pub const MAX_DELAY_S: f64 = 1.0;
/// The largest reference acceleration (sampled at every control step of the flight, warm-up
/// included) a scenario may ask for, m/s² (about 2 g).
pub const MAX_REFERENCE_ACCELERATION_M_S2: f64 = 20.0;
/// The lowest `hover_throttle` a scenario may set: a normalised throttle well below any real
/// vehicle's hover (Neural-Fly: 0.44 to 0.52), and above the smallest the data tools accept (they
/// divide by it).
pub const MIN_HOVER_THROTTLE: f64 = 0.05;
/// The largest standard deviation of each measurement noise (position m, velocity m/s, attitude
/// rad, body rate rad/s): far above any real sensor's, and small enough that every noisy value
/// stays inside the ranges the data tools accept. (Near these bounds the closed loop, which sees
/// the noisy values, may well diverge: [`crate::simulate`] then fails with an error.)
pub const MAX_NOISE: Noise = Noise {
    position_m: 1.0,
    velocity_m_s: 1.0,
    attitude_rad: 0.5,
    rate_rad_s: 1.0,
};

impl Scenario {
    /// A short figure-8 flight built in code, for examples and tests: 6 s recorded (301 rows at
    /// 50 Hz, just over [`MIN_LOG_ROWS`]) after 4 s of warm-up, a 6 s figure-8 around (0, 0, 1.5) m
    /// (±1.5 m in x, ±0.8 m in y, ±0.3 m in z) with ±0.2 rad of yaw every 10 s, the sensor noise of
    /// the demo configurations in `experiments/mismatch/configurations/`, no effects and the default rates,
    /// throttle and gains. `model` is the nominal model file, as in a scenario file. Change any
    /// field with struct update syntax:
    ///
    /// ```
    /// use physics::{Effects, Scenario, ThrustScale};
    ///
    /// let weak = Scenario {
    ///     effects: Effects { thrust_scale: Some(ThrustScale { k: 0.85 }), ..Effects::default() },
    ///     ..Scenario::figure_eight("quad-a.json", 7)
    /// };
    /// weak.validate(std::path::Path::new("weak.json")).unwrap();
    /// ```
    pub fn figure_eight(model: impl Into<PathBuf>, seed: u64) -> Self {
        Self {
            model: model.into(),
            duration_s: 6.0,
            warmup_s: 4.0,
            seed,
            physics_rate_hz: default_physics_rate(),
            log_rate_hz: default_log_rate(),
            hover_throttle: default_hover_throttle(),
            trajectory: Trajectory::Figure8 {
                center: [0.0, 0.0, 1.5],
                first: [1.5, 0.0, 0.0],
                second: [0.0, 0.8, 0.3],
                period_s: 6.0,
                low_passes: Vec::new(),
                yaw_amplitude_rad: 0.2,
                yaw_period_s: 10.0,
            },
            effects: Effects::default(),
            noise: Noise {
                position_m: 0.002,
                velocity_m_s: 0.005,
                attitude_rad: 0.002,
                rate_rad_s: 0.008,
            },
            gains: Gains::default(),
            controller_rate_hz: None,
            logger: None,
            jitter: None,
            log_timing: None,
            battery: None,
        }
    }

    /// The model file a scenario read from `scenario_path` names (its `model`, relative to the
    /// scenario file): an input of the simulation as much as the scenario itself.
    pub fn model_path(&self, scenario_path: &Path) -> PathBuf {
        scenario_path
            .parent()
            .unwrap_or(Path::new("."))
            .join(&self.model)
    }

    /// Reads a scenario and its model (resolved relative to the scenario file), and checks both
    /// (together: the simulator needs a mixer, and the reference must stay above the ground).
    /// What the file holds is checked as it is read, each error naming the field: an unknown key,
    /// an effect id that is not one of [`crate::EffectId::ALL`] among them.
    pub fn load(path: &Path) -> Result<(Self, NominalModel)> {
        let text = std::fs::read_to_string(path).map_err(|source| PhysicsError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let scenario: Self =
            bounded_read::json::from_str(&text).map_err(|error| PhysicsError::Field {
                path: path.to_path_buf(),
                field: error.field,
                message: error.message,
            })?;
        scenario.validate(path)?;
        let model = NominalModel::load(&scenario.model_path(path))?;
        scenario.validate_with_model(&model, path)?;
        Ok((scenario, model))
    }

    /// Checks the settings; errors name the field. Bounds: `duration_s` at most
    /// [`MAX_DURATION_S`], giving between [`MIN_LOG_ROWS`] and [`MAX_LOG_ROWS`] rows; `warmup_s` in
    /// [0, [`MAX_WARMUP_S`]]; `physics_rate_hz` in [[`MIN_PHYSICS_RATE_HZ`],
    /// [`MAX_PHYSICS_RATE_HZ`]] and a whole multiple of `log_rate_hz`; `hover_throttle` in
    /// [[`MIN_HOVER_THROTTLE`], 1]; noise standard deviations in [0, [`MAX_NOISE`]]; gains, effects
    /// and trajectory as their own checks say, a delay of at most [`MAX_DELAY_S`], and a reference
    /// that stays within [`MAX_POSITION_M`] of the origin (per coordinate) and accelerates at most
    /// at [`MAX_REFERENCE_ACCELERATION_M_S2`]; a log timing as [`LogTiming::validate`] says, with
    /// a `sample` logger, a controller at least twice the log rate, and at least [`MIN_LOG_ROWS`]
    /// rows left. Together these keep every value of the simulated log inside the ranges the data
    /// tools accept (`PLAUSIBLE_RANGES` and `SAMPLE_INTERVAL_RANGE_S` of the data crate).
    pub fn validate(&self, origin: &Path) -> Result<()> {
        self.validate_rates(origin)?;
        self.validate_timing(origin)?;
        let rows = self.rows();
        if !(MIN_LOG_ROWS..=MAX_LOG_ROWS).contains(&rows) {
            return Err(field_error(
                origin,
                "duration_s".into(),
                format!(
                    "duration_s · log_rate_hz gives {rows} rows, a log needs between {MIN_LOG_ROWS} and {MAX_LOG_ROWS}"
                ),
            ));
        }
        self.validate_logged_rows(origin)?;
        self.validate_vehicle(origin)?;
        self.validate_reference(origin)
    }

    /// Duration, warm-up, log and physics rates, hover throttle.
    fn validate_rates(&self, origin: &Path) -> Result<()> {
        let field = |field: String, message: String| field_error(origin, field, message);
        let positive = |name: &str, value: f64| {
            if value.is_finite() && value > 0.0 {
                Ok(())
            } else {
                Err(field(
                    name.to_string(),
                    format!("must be positive, found {}", readable(value)),
                ))
            }
        };
        positive("duration_s", self.duration_s)?;
        if self.duration_s > MAX_DURATION_S {
            return Err(field(
                "duration_s".into(),
                format!(
                    "at most {MAX_DURATION_S} s, found {}",
                    readable(self.duration_s)
                ),
            ));
        }
        if !(self.warmup_s.is_finite() && (0.0..=MAX_WARMUP_S).contains(&self.warmup_s)) {
            return Err(field(
                "warmup_s".into(),
                format!(
                    "must be between 0 and {MAX_WARMUP_S} s, found {}",
                    readable(self.warmup_s)
                ),
            ));
        }
        positive("log_rate_hz", self.log_rate_hz)?;
        positive("hover_throttle", self.hover_throttle)?;
        if !(MIN_HOVER_THROTTLE..=1.0).contains(&self.hover_throttle) {
            return Err(field(
                "hover_throttle".into(),
                format!(
                    "a normalised throttle, must be between {MIN_HOVER_THROTTLE} and 1, found {}",
                    readable(self.hover_throttle)
                ),
            ));
        }
        if !(MIN_PHYSICS_RATE_HZ..=MAX_PHYSICS_RATE_HZ).contains(&self.physics_rate_hz) {
            return Err(field(
                "physics_rate_hz".into(),
                format!(
                    "must be between {MIN_PHYSICS_RATE_HZ} and {MAX_PHYSICS_RATE_HZ}, found {}",
                    readable(self.physics_rate_hz)
                ),
            ));
        }
        let ratio = self.physics_rate_hz / self.log_rate_hz;
        if (ratio - ratio.round()).abs() > 1e-9 || ratio < 1.0 {
            return Err(field(
                "physics_rate_hz".into(),
                "must be a whole multiple of log_rate_hz".into(),
            ));
        }
        Ok(())
    }

    /// Gains, effects (with the delay's bound) and noise levels.
    fn validate_vehicle(&self, origin: &Path) -> Result<()> {
        let field = |field: String, message: String| field_error(origin, field, message);
        self.gains
            .validate()
            .map_err(|(f, m)| field(format!("gains.{f}"), m))?;
        self.effects
            .validate()
            .map_err(|(f, m)| field(format!("effects.{f}"), m))?;
        if self.effects.delay_s() > MAX_DELAY_S {
            return Err(field(
                "effects.delay.delay_s".into(),
                format!(
                    "at most {MAX_DELAY_S} s, found {}",
                    readable(self.effects.delay_s())
                ),
            ));
        }
        let (n, max) = (self.noise, MAX_NOISE);
        for (name, value, max, unit) in [
            ("position_m", n.position_m, max.position_m, "m"),
            ("velocity_m_s", n.velocity_m_s, max.velocity_m_s, "m/s"),
            ("attitude_rad", n.attitude_rad, max.attitude_rad, "rad"),
            ("rate_rad_s", n.rate_rad_s, max.rate_rad_s, "rad/s"),
        ] {
            if !(value.is_finite() && (0.0..=max).contains(&value)) {
                return Err(field(
                    format!("noise.{name}"),
                    format!(
                        "a standard deviation, must be between 0 and {max} {unit}, found {}",
                        readable(value)
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The trajectory's own checks, and a reference that stays near the origin and accelerates
    /// within bounds at every control time.
    fn validate_reference(&self, origin: &Path) -> Result<()> {
        let field = |field: String, message: String| field_error(origin, field, message);
        self.trajectory.validate().map_err(|(f, m)| field(f, m))?;
        let generator = self.trajectory.generator();
        for t in self.control_times() {
            let reference = generator.at(t);
            if let Some(p) = reference
                .position
                .iter()
                .find(|p| p.is_nan() || p.abs() > MAX_POSITION_M)
            {
                return Err(field(
                    "trajectory".into(),
                    format!(
                        "the reference reaches the coordinate {} m at t = {t:.2} s, farther than the {MAX_POSITION_M} m from the origin allowed",
                        readable(*p)
                    ),
                ));
            }
            let a = norm(reference.acceleration);
            if a.is_nan() || a > MAX_REFERENCE_ACCELERATION_M_S2 {
                return Err(field(
                    "trajectory".into(),
                    format!(
                        "the reference accelerates at {a:.4} m/s² at t = {t:.2} s, more than the {MAX_REFERENCE_ACCELERATION_M_S2} m/s² allowed"
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The controller rate, Hz (the log rate unless set).
    pub fn controller_rate(&self) -> f64 {
        self.controller_rate_hz.unwrap_or(self.log_rate_hz)
    }

    /// The logger: as set, or by default the commands held from row to row when the controller
    /// runs at the log rate and sampled at each row's time otherwise. This is what a model file
    /// given to the mismatch tool with this scenario's logs should say (`"logger"`).
    /// A `sample` or `period_mean` logger gets the controller rate when it has none.
    pub fn logger(&self) -> Logger {
        let mut logger = self.logger.unwrap_or_else(|| Logger {
            command: if self.controller_steps_per_row() == 1 {
                CommandLogging::Held
            } else {
                CommandLogging::Sample
            },
            ..Logger::default()
        });
        if logger.command != CommandLogging::Held && logger.controller_rate_hz.is_none() {
            logger.controller_rate_hz = Some(self.controller_rate());
        }
        logger
    }

    /// Control steps per logged row.
    pub(crate) fn controller_steps_per_row(&self) -> usize {
        (self.controller_rate() / self.log_rate_hz).round().max(1.0) as usize
    }

    /// Checks the controller rate, the logger and the jitter against the log and physics rates.
    fn validate_timing(&self, origin: &Path) -> Result<()> {
        let field = |field: &str, message: String| PhysicsError::Field {
            path: origin.to_path_buf(),
            field: field.to_string(),
            message,
        };
        let whole = |ratio: f64| ratio >= 1.0 - 1e-9 && (ratio - ratio.round()).abs() <= 1e-9;
        let control = self.controller_rate();
        if !(control.is_finite()
            && whole(control / self.log_rate_hz)
            && whole(self.physics_rate_hz / control))
        {
            return Err(field(
                "controller_rate_hz",
                format!(
                    "must be a whole multiple of log_rate_hz ({}) and a whole divisor of physics_rate_hz ({}), found {}",
                    readable(self.log_rate_hz),
                    readable(self.physics_rate_hz),
                    readable(control)
                ),
            ));
        }
        let logger = self.logger();
        logger
            .validate()
            .map_err(|(f, m)| field(&format!("logger.{f}"), m))?;
        let at_log_rate = self.controller_steps_per_row() == 1;
        if at_log_rate != (logger.command == CommandLogging::Held) {
            return Err(field(
                "logger.command",
                if at_log_rate {
                    format!(
                        "with the controller at the log rate each command is held until the next row: the logger's command is \"held\", found \"{}\"",
                        logger.command.name()
                    )
                } else {
                    "\"held\" needs the controller at the log rate (controller_rate_hz = log_rate_hz)".to_string()
                },
            ));
        }
        if let Some(rate) = logger.controller_rate_hz
            && (rate - control).abs() > 1e-9 * control
        {
            return Err(field(
                "logger.controller_rate_hz",
                format!(
                    "the commands a row averages come from the controller: {}, found {}",
                    readable(control),
                    readable(rate)
                ),
            ));
        }
        let steps = logger.command_time_offset_s * control;
        if (steps - steps.round()).abs() > 1e-6 {
            return Err(field(
                "logger.command_time_offset_s",
                format!(
                    "the simulated logger reads the controller's commands: a whole number of control periods (1/{} s), found {}",
                    readable(control),
                    readable(logger.command_time_offset_s)
                ),
            ));
        }
        if let Some(jitter) = &self.jitter {
            jitter
                .validate()
                .map_err(|(f, m)| field(&format!("jitter.{f}"), m))?;
        }
        if let Some(timing) = &self.log_timing {
            if logger.command != CommandLogging::Sample || self.controller_steps_per_row() < 2 {
                return Err(field(
                    "log_timing",
                    "needs a \"sample\" logger of a controller at least twice the log rate (a held or period-mean command is defined relative to evenly spaced rows)".to_string(),
                ));
            }
            timing
                .validate(self.log_rate_hz, self.duration_s)
                .map_err(|(f, m)| field(&format!("log_timing.{f}"), m))?;
        }
        Ok(())
    }

    /// With a log timing: rows enough left after the drops and gaps, and no interval between
    /// rows longer than a flight log's reader accepts.
    fn validate_logged_rows(&self, origin: &Path) -> Result<()> {
        if self.log_timing.is_none() {
            return Ok(());
        }
        let field = |message: String| field_error(origin, "log_timing".into(), message);
        let steps = self.row_steps();
        if steps.len() < MIN_LOG_ROWS {
            return Err(field(format!(
                "the drops and gaps leave {} of the {} rows, a log needs at least {MIN_LOG_ROWS}",
                steps.len(),
                self.rows()
            )));
        }
        let control_dt = 1.0 / self.controller_rate();
        let longest = data::SAMPLE_INTERVAL_RANGE_S.1;
        if let Some(w) = steps
            .windows(2)
            .find(|w| (w[1] - w[0]) as f64 * control_dt > longest)
        {
            return Err(field(format!(
                "no row between t = {:.3} s and {:.3} s, longer than the {longest} s between samples a flight log's reader accepts",
                w[0] as f64 * control_dt,
                w[1] as f64 * control_dt
            )));
        }
        Ok(())
    }

    /// Checks the scenario against its model: the simulator needs a mixer, and the reference must
    /// stay above the model's ground plane.
    pub fn validate_with_model(&self, model: &NominalModel, origin: &Path) -> Result<()> {
        let field = |field: &str, message: String| PhysicsError::Field {
            path: origin.to_path_buf(),
            field: field.to_string(),
            message,
        };
        if model.mixer.is_none() || !model.predicts_torque() {
            return Err(field(
                "model",
                format!(
                    "{}: the simulator needs a model with a mixer (thrust_source \"mixer\")",
                    self.model.display()
                ),
            ));
        }
        if let (Some(battery), Some(mixer)) = (&self.battery, &model.mixer) {
            let max_thrust: f64 = mixer.row(0).iter().sum();
            let span = (-self.warmup_s, self.duration_s);
            battery
                .check(span, max_thrust)
                .map_err(|(name, message)| field(&name, message))?;
        }
        let generator = self.trajectory.generator();
        for t in self.control_times() {
            let z = generator.at(t).position[2];
            if z.is_nan() || z <= model.ground_height_m {
                return Err(field(
                    "trajectory",
                    format!(
                        "the reference is at height {z:.3} m at t = {t:.2} s, not above the model's ground (ground_height_m = {})",
                        model.ground_height_m
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Number of rows due (`⌊duration_s · log_rate_hz⌋ + 1`; the log timing may drop some).
    pub(crate) fn rows(&self) -> usize {
        (self.duration_s * self.log_rate_hz).floor() as usize + 1
    }

    /// The control step of each logged row, counted from the first row's, strictly increasing:
    /// every `controller_steps_per_row()` steps, or as the log timing spaces them.
    pub(crate) fn row_steps(&self) -> Vec<usize> {
        let per_row = self.controller_steps_per_row();
        match &self.log_timing {
            None => (0..self.rows()).map(|k| k * per_row).collect(),
            Some(timing) => {
                timing.row_steps(self.rows(), per_row, self.controller_rate(), self.seed)
            }
        }
    }

    /// Number of control steps flown before the recording starts.
    pub(crate) fn warmup_rows(&self) -> usize {
        (self.warmup_s * self.log_rate_hz).round() as usize
    }

    /// The time of every logged row, warm-up included (the references checked at load).
    fn control_times(&self) -> impl Iterator<Item = f64> {
        let row_dt = 1.0 / self.log_rate_hz;
        let warmup_rows = self.warmup_rows();
        (0..warmup_rows + self.rows()).map(move |step| (step as f64 - warmup_rows as f64) * row_dt)
    }
}
/// A scenario field's error, naming the file.
fn field_error(origin: &Path, field: String, message: String) -> PhysicsError {
    PhysicsError::Field {
        path: origin.to_path_buf(),
        field,
        message,
    }
}
