//! Closed-loop simulation of the real plant (nominal model plus switchable effects) under the
//! geometric controller, written as a Neural-Fly flight log.
//!
//! Timing: the controller runs at the logging rate (50 Hz by default) and each logged row holds the
//! measured state at `t_k` and the command issued at `t_k`, which the actuators receive (after any
//! delay) and hold until the next command. The rigid body is integrated with RK4 at
//! `physics_rate_hz` (≥ 500 Hz); with a motor lag the four motor speeds are part of the state.
//! Measurement noise (Gaussian, from the scenario's seed) is added to position, velocity, attitude
//! and body rate; the controller sees the noisy values, as on a real vehicle.

use std::path::{Path, PathBuf};

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use data::{FlightLog, quaternion_from_rotation, rotation_from_quaternion};

use crate::controller::{Gains, GeometricController, MeasuredState};
use crate::effects::Effects;
use crate::error::{PhysicsError, Result};
use crate::model::NominalModel;
use crate::trajectory::Trajectory;
use crate::vector::{
    Vec3, add, mat_mul, norm, quaternion_multiply, quaternion_normalize,
    rotation_from_rotation_vector, scale, sub,
};

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

impl Scenario {
    /// Reads a scenario and its model (resolved relative to the scenario file).
    pub fn load(path: &Path) -> Result<(Self, NominalModel)> {
        let text = std::fs::read_to_string(path).map_err(|source| PhysicsError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let scenario: Self = serde_json::from_str(&text).map_err(|error| PhysicsError::Json {
            path: path.to_path_buf(),
            message: error.to_string(),
        })?;
        scenario.validate(path)?;
        let model_path = path
            .parent()
            .unwrap_or(Path::new("."))
            .join(&scenario.model);
        let model = NominalModel::load(&model_path)?;
        Ok((scenario, model))
    }

    /// Checks the settings; errors name the field.
    pub fn validate(&self, origin: &Path) -> Result<()> {
        let field = |field: String, message: String| PhysicsError::Field {
            path: origin.to_path_buf(),
            field,
            message,
        };
        let positive = |name: &str, value: f64| {
            if value.is_finite() && value > 0.0 {
                Ok(())
            } else {
                Err(field(
                    name.to_string(),
                    format!("must be positive, found {value}"),
                ))
            }
        };
        positive("duration_s", self.duration_s)?;
        if !(self.warmup_s.is_finite() && self.warmup_s >= 0.0) {
            return Err(field("warmup_s".into(), "must be ≥ 0".into()));
        }
        positive("log_rate_hz", self.log_rate_hz)?;
        positive("hover_throttle", self.hover_throttle)?;
        if self.physics_rate_hz.is_nan() || self.physics_rate_hz < 500.0 {
            return Err(field(
                "physics_rate_hz".into(),
                format!("must be at least 500, found {}", self.physics_rate_hz),
            ));
        }
        let ratio = self.physics_rate_hz / self.log_rate_hz;
        if (ratio - ratio.round()).abs() > 1e-9 || ratio < 1.0 {
            return Err(field(
                "physics_rate_hz".into(),
                "must be a whole multiple of log_rate_hz".into(),
            ));
        }
        self.effects
            .validate()
            .map_err(|(f, m)| field(format!("effects.{f}"), m))?;
        self.trajectory.validate().map_err(|(f, m)| field(f, m))?;
        let n = self.noise;
        if [n.position_m, n.velocity_m_s, n.attitude_rad, n.rate_rad_s]
            .iter()
            .any(|v| !(v.is_finite() && *v >= 0.0))
        {
            return Err(field(
                "noise".into(),
                "standard deviations must be ≥ 0".into(),
            ));
        }
        Ok(())
    }
}

/// The true state of the plant.
#[derive(Clone, Copy, Debug)]
struct PlantState {
    position: Vec3,
    velocity: Vec3,
    /// Body to world, `[x, y, z, w]`.
    quaternion: [f64; 4],
    body_rate: Vec3,
    /// Normalised motor speeds (only integrated with a motor lag).
    speeds: [f64; 4],
}

#[derive(Clone, Copy, Debug)]
struct Derivative {
    velocity: Vec3,
    acceleration: Vec3,
    quaternion: [f64; 4],
    angular_acceleration: Vec3,
    speeds: [f64; 4],
}

struct Plant<'a> {
    model: &'a NominalModel,
    effects: Effects,
}

impl Plant<'_> {
    fn derivative(&self, state: &PlantState, commanded_speeds: [f64; 4]) -> Derivative {
        let lag = self.effects.lag_s();
        let speeds = if lag > 0.0 {
            state.speeds
        } else {
            commanded_speeds
        };
        let wrench = self.model.wrench(&speeds);
        let rotation = rotation_from_quaternion(&state.quaternion);
        let height = state.position[2] - self.model.ground_height_m;
        let acceleration = self.effects.translational_acceleration(
            self.model,
            &rotation,
            state.velocity,
            height,
            wrench.thrust,
        );
        let torque = wrench.torque.unwrap_or([0.0; 3]);
        let angular_acceleration =
            self.effects
                .angular_acceleration(self.model, state.body_rate, torque);
        let w = state.body_rate;
        let quaternion =
            quaternion_multiply(state.quaternion, [w[0], w[1], w[2], 0.0]).map(|v| 0.5 * v);
        let speeds_rate = if lag > 0.0 {
            let mut out = [0.0; 4];
            for i in 0..4 {
                out[i] = (commanded_speeds[i] - state.speeds[i]) / lag;
            }
            out
        } else {
            [0.0; 4]
        };
        Derivative {
            velocity: state.velocity,
            acceleration,
            quaternion,
            angular_acceleration,
            speeds: speeds_rate,
        }
    }
}

fn advance(state: &PlantState, derivative: &Derivative, h: f64) -> PlantState {
    let mut quaternion = state.quaternion;
    let mut speeds = state.speeds;
    for i in 0..4 {
        quaternion[i] += h * derivative.quaternion[i];
        speeds[i] += h * derivative.speeds[i];
    }
    PlantState {
        position: add(state.position, scale(derivative.velocity, h)),
        velocity: add(state.velocity, scale(derivative.acceleration, h)),
        quaternion,
        body_rate: add(state.body_rate, scale(derivative.angular_acceleration, h)),
        speeds,
    }
}

fn rk4_step(plant: &Plant, state: &PlantState, command: [f64; 4], h: f64) -> PlantState {
    let k1 = plant.derivative(state, command);
    let k2 = plant.derivative(&advance(state, &k1, h / 2.0), command);
    let k3 = plant.derivative(&advance(state, &k2, h / 2.0), command);
    let k4 = plant.derivative(&advance(state, &k3, h), command);
    let combine = |a: f64, b: f64, c: f64, d: f64| (a + 2.0 * b + 2.0 * c + d) / 6.0;
    let mut combined = k1;
    for i in 0..3 {
        combined.velocity[i] = combine(
            k1.velocity[i],
            k2.velocity[i],
            k3.velocity[i],
            k4.velocity[i],
        );
        combined.acceleration[i] = combine(
            k1.acceleration[i],
            k2.acceleration[i],
            k3.acceleration[i],
            k4.acceleration[i],
        );
        combined.angular_acceleration[i] = combine(
            k1.angular_acceleration[i],
            k2.angular_acceleration[i],
            k3.angular_acceleration[i],
            k4.angular_acceleration[i],
        );
    }
    for i in 0..4 {
        combined.quaternion[i] = combine(
            k1.quaternion[i],
            k2.quaternion[i],
            k3.quaternion[i],
            k4.quaternion[i],
        );
        combined.speeds[i] = combine(k1.speeds[i], k2.speeds[i], k3.speeds[i], k4.speeds[i]);
    }
    let mut next = advance(state, &combined, h);
    next.quaternion = quaternion_normalize(next.quaternion);
    next
}

struct Gaussian {
    rng: ChaCha8Rng,
}

impl Gaussian {
    fn sample(&mut self) -> f64 {
        // Box–Muller; 1 − u keeps the logarithm finite.
        let u: f64 = 1.0 - self.rng.random::<f64>();
        let v: f64 = self.rng.random::<f64>();
        (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
    }

    fn vector(&mut self, sigma: f64) -> Vec3 {
        [
            self.sample() * sigma,
            self.sample() * sigma,
            self.sample() * sigma,
        ]
    }
}

/// Simulates a scenario with its model and returns the flight log (path set to `name.csv`).
pub fn simulate(model: &NominalModel, scenario: &Scenario, name: &str) -> Result<FlightLog> {
    scenario.validate(Path::new(name))?;
    let mixer = model.mixer.as_ref().ok_or_else(|| {
        PhysicsError::Simulation(
            "the simulator needs a model with a mixer (thrust_source \"mixer\")".into(),
        )
    })?;
    let control_dt = 1.0 / scenario.log_rate_hz;
    let substeps = (scenario.physics_rate_hz / scenario.log_rate_hz).round() as usize;
    let h = control_dt / substeps as f64;
    let rows = (scenario.duration_s * scenario.log_rate_hz).floor() as usize + 1;
    let warmup_rows = (scenario.warmup_s * scenario.log_rate_hz).round() as usize;
    let delay_steps = (scenario.effects.delay_s() / h).round() as usize;
    let generator = scenario.trajectory.generator();
    let mut controller = GeometricController::new(model, scenario.gains);
    let plant = Plant {
        model,
        effects: scenario.effects,
    };
    let mut noise = Gaussian {
        rng: ChaCha8Rng::seed_from_u64(scenario.seed),
    };
    let start = generator.at(-(warmup_rows as f64) * control_dt);
    let hover_speeds = mixer.speeds_for(&[model.mass_kg * model.gravity_m_s2, 0.0, 0.0, 0.0]);
    let mut state = PlantState {
        position: start.position,
        velocity: start.velocity,
        quaternion: quaternion_from_rotation(&controller.initial_rotation(&start)),
        body_rate: [0.0; 3],
        speeds: hover_speeds,
    };
    // Commands per physics step, so that a delay of any multiple of the physics step is exact.
    let mut applied: Vec<[f64; 4]> = Vec::with_capacity(rows * substeps);
    let mut log = empty_log(name, rows);
    for step in 0..warmup_rows + rows {
        let t = (step as f64 - warmup_rows as f64) * control_dt;
        let reference = generator.at(t);
        let measured = measure(&state, &scenario.noise, &mut noise);
        let output = controller.update(&measured, &reference, control_dt);
        let wrench = [
            output.thrust,
            output.torque[0],
            output.torque[1],
            output.torque[2],
        ];
        let speeds = mixer.speeds_for(&wrench);
        if step < warmup_rows {
            for _ in 0..substeps {
                applied.push(speeds);
                let command = delayed(&applied, delay_steps);
                state = rk4_step(&plant, &state, command, h);
            }
            check_state(&state, &reference.position, t)?;
            continue;
        }
        let k = step - warmup_rows;
        let issued_thrust = mixer.wrench(&speeds)[0];
        log.time.push(t);
        log.position.push(measured.position);
        log.velocity.push(measured.velocity);
        let quaternion = quaternion_from_rotation(&measured.rotation);
        log.quaternion.push(quaternion);
        log.rotation.push(measured.rotation);
        log.body_rate.push(measured.body_rate);
        log.thrust_setpoint
            .push(issued_thrust / (model.mass_kg * model.gravity_m_s2) * scenario.hover_throttle);
        log.hover_throttle.push(scenario.hover_throttle);
        log.motor_command.push(mixer.pwm(&speeds));
        push(&mut log.position_desired, reference.position);
        push(&mut log.velocity_desired, reference.velocity);
        if let Some(setpoints) = log.attitude_setpoint.as_mut() {
            setpoints.push(quaternion_from_rotation(&output.desired_rotation));
        }
        if k + 1 == rows {
            break;
        }
        for _ in 0..substeps {
            applied.push(speeds);
            let command = delayed(&applied, delay_steps);
            state = rk4_step(&plant, &state, command, h);
        }
        check_state(&state, &reference.position, t)?;
    }
    Ok(log)
}

/// The command the actuators receive now: the one issued `delay_steps` physics steps ago (the first
/// command before that).
fn delayed(applied: &[[f64; 4]], delay_steps: usize) -> [f64; 4] {
    let index = applied.len() - 1;
    if index >= delay_steps {
        applied[index - delay_steps]
    } else {
        applied[0]
    }
}

fn push(column: &mut Option<Vec<Vec3>>, value: Vec3) {
    if let Some(values) = column.as_mut() {
        values.push(value);
    }
}

fn measure(state: &PlantState, noise: &Noise, gaussian: &mut Gaussian) -> MeasuredState {
    let rotation = rotation_from_quaternion(&state.quaternion);
    let tilt = rotation_from_rotation_vector(gaussian.vector(noise.attitude_rad));
    MeasuredState {
        position: add(state.position, gaussian.vector(noise.position_m)),
        velocity: add(state.velocity, gaussian.vector(noise.velocity_m_s)),
        rotation: mat_mul(&rotation, &tilt),
        body_rate: add(state.body_rate, gaussian.vector(noise.rate_rad_s)),
    }
}

fn check_state(state: &PlantState, reference: &Vec3, t: f64) -> Result<()> {
    let finite = state
        .position
        .iter()
        .chain(&state.velocity)
        .chain(&state.body_rate)
        .all(|v| v.is_finite());
    if !finite || norm(sub(state.position, *reference)) > 20.0 {
        return Err(PhysicsError::Simulation(format!(
            "the closed loop diverged at t = {t:.2} s (position error above 20 m)"
        )));
    }
    Ok(())
}

fn empty_log(name: &str, rows: usize) -> FlightLog {
    FlightLog {
        path: PathBuf::from(format!("{name}.csv")),
        meta: None,
        time: Vec::with_capacity(rows),
        position: Vec::with_capacity(rows),
        velocity: Vec::with_capacity(rows),
        quaternion: Vec::with_capacity(rows),
        rotation: Vec::with_capacity(rows),
        body_rate: Vec::with_capacity(rows),
        thrust_setpoint: Vec::with_capacity(rows),
        hover_throttle: Vec::with_capacity(rows),
        motor_command: Vec::with_capacity(rows),
        position_desired: Some(Vec::with_capacity(rows)),
        velocity_desired: Some(Vec::with_capacity(rows)),
        attitude_setpoint: Some(Vec::with_capacity(rows)),
        residual_force: None,
    }
}
