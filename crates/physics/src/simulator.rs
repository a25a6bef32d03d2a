//! Closed-loop simulation of the real plant (nominal model plus switchable effects) under the
//! geometric controller, written as a Neural-Fly flight log.
//!
//! Timing: the controller runs at `controller_rate_hz` (by default the log rate) and each command
//! is held by the actuators (after any delay, exact even between physics steps) until the next one.
//! Every `controller_rate_hz / log_rate_hz` control steps a row is logged (or at the steps a
//! [`crate::LogTiming`] draws: jittered, dropped, gaps): the measured state at that instant and the
//! command as the scenario's [`crate::Logger`] records it (the instantaneous command, the mean over
//! the log period, either shifted by whole control steps; each command held to the next row when
//! the controller runs at the log rate). The rigid body is integrated with RK4 at
//! `physics_rate_hz`; with a motor lag the four motor speeds are part of the state. Measurement
//! noise (Gaussian, from the scenario's seed) is added to position, velocity, attitude and body
//! rate, the rate after the logger's optional first-order filter; the controller sees the noisy
//! values, as on a real vehicle. An optional band-limited [`crate::Jitter`] is added to the
//! commands (and logged with them).

use std::path::{Path, PathBuf};

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use data::{FlightLog, MotorCommands};

use crate::controller::{ControlOutput, GeometricController, MeasuredState};
use crate::effects::Effects;
use crate::error::{PhysicsError, Result};
use crate::jitter::JitterSignal;
use crate::mixer::{Actuators, MAX_ACTUATORS};
use crate::model::NominalModel;
use crate::scenario::{Noise, Scenario};
use crate::vector::{
    Vec3, add, mat_mul, norm, quaternion_from_rotation, quaternion_multiply, quaternion_normalize,
    rotation_from_quaternion, rotation_from_rotation_vector, scale, sub,
};
use command_log::{CommandLog, CommandQueue};

/// The true state of the plant.
#[derive(Clone, Copy, Debug)]
struct PlantState {
    position: Vec3,
    velocity: Vec3,
    /// Body to world, `[x, y, z, w]`.
    quaternion: [f64; 4],
    body_rate: Vec3,
    /// Normalised motor speeds (only integrated with a motor lag).
    speeds: Actuators,
    /// The velocity the air terms see (only integrated with a drag lag).
    drag_velocity: Vec3,
}

#[derive(Clone, Copy, Debug)]
struct Derivative {
    velocity: Vec3,
    acceleration: Vec3,
    quaternion: [f64; 4],
    angular_acceleration: Vec3,
    speeds: Actuators,
    drag_velocity: Vec3,
}

struct Plant<'a> {
    model: &'a NominalModel,
    effects: Effects,
}

impl Plant<'_> {
    fn derivative(&self, state: &PlantState, commanded_speeds: Actuators) -> Derivative {
        let lag = self.effects.lag_s();
        let speeds = if lag > 0.0 {
            state.speeds
        } else {
            commanded_speeds
        };
        let wrench = self.model.wrench(&speeds);
        let rotation = rotation_from_quaternion(&state.quaternion);
        let drag_lag = self.effects.drag_lag_s();
        let air_velocity = if drag_lag > 0.0 {
            state.drag_velocity
        } else {
            state.velocity
        };
        let air_body = self
            .effects
            .body_airspeed(&rotation, air_velocity, state.position);
        let acceleration = self.effects.translational_acceleration_in_air(
            self.model,
            &rotation,
            air_velocity,
            state.position,
            air_body,
            wrench.thrust,
        );
        let drag_velocity = if drag_lag > 0.0 {
            scale(sub(state.velocity, state.drag_velocity), 1.0 / drag_lag)
        } else {
            [0.0; 3]
        };
        let torque = wrench.torque.unwrap_or([0.0; 3]);
        let angular_acceleration =
            self.effects
                .angular_acceleration(self.model, state.body_rate, torque, air_body);
        let w = state.body_rate;
        let quaternion =
            quaternion_multiply(state.quaternion, [w[0], w[1], w[2], 0.0]).map(|v| 0.5 * v);
        let speeds_rate = if lag > 0.0 {
            let mut out = [0.0; MAX_ACTUATORS];
            for i in 0..MAX_ACTUATORS {
                out[i] = (commanded_speeds[i] - state.speeds[i]) / lag;
            }
            out
        } else {
            [0.0; MAX_ACTUATORS]
        };
        Derivative {
            velocity: state.velocity,
            acceleration,
            quaternion,
            angular_acceleration,
            speeds: speeds_rate,
            drag_velocity,
        }
    }
}

fn advance(state: &PlantState, derivative: &Derivative, h: f64) -> PlantState {
    let mut quaternion = state.quaternion;
    let mut speeds = state.speeds;
    for i in 0..4 {
        quaternion[i] += h * derivative.quaternion[i];
    }
    for i in 0..MAX_ACTUATORS {
        speeds[i] += h * derivative.speeds[i];
    }
    PlantState {
        position: add(state.position, scale(derivative.velocity, h)),
        velocity: add(state.velocity, scale(derivative.acceleration, h)),
        quaternion,
        body_rate: add(state.body_rate, scale(derivative.angular_acceleration, h)),
        speeds,
        drag_velocity: add(state.drag_velocity, scale(derivative.drag_velocity, h)),
    }
}

fn rk4_step(plant: &Plant, state: &PlantState, command: Actuators, h: f64) -> PlantState {
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
        combined.drag_velocity[i] = combine(
            k1.drag_velocity[i],
            k2.drag_velocity[i],
            k3.drag_velocity[i],
            k4.drag_velocity[i],
        );
    }
    for i in 0..4 {
        combined.quaternion[i] = combine(
            k1.quaternion[i],
            k2.quaternion[i],
            k3.quaternion[i],
            k4.quaternion[i],
        );
    }
    for i in 0..MAX_ACTUATORS {
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
        // Box–Muller (1 − u keeps the logarithm finite), kept rather than rand_distr's draw: this
        // stream is the noise of every committed simulated recording (docs/mismatch-history.md).
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
    scenario.validate_with_model(model, Path::new(name))?;
    let mixer = model.mixer.as_ref().ok_or_else(|| {
        PhysicsError::Simulation(
            "the simulator needs a model with a mixer (thrust_source \"mixer\")".into(),
        )
    })?;
    let battery = scenario.battery;
    if model.needs_battery_voltage() && battery.is_none() {
        return Err(PhysicsError::Simulation(
            "the model's thrust map depends on the battery voltage: give the scenario a battery"
                .into(),
        ));
    }
    let mut flight = Flight::new(model, mixer, scenario);
    let warmup_steps = scenario.warmup_rows() * scenario.controller_steps_per_row();
    // The control step of each row, from the first row's (validated: at least two rows).
    let row_steps = scenario.row_steps();
    let rows = row_steps.len();
    let last_row_step = warmup_steps + row_steps[rows - 1];
    // Run on after the last row until the commands a look-ahead logger records exist.
    let last_step = last_row_step + flight.look_ahead_steps();
    let mut log = empty_log(name, rows, mixer.rotors(), battery.is_some());
    // The load the battery sags under, from the last command (hover before the first).
    let mut thrust = model.mass_kg * model.gravity_m_s2;
    let mut commands = CommandLog::new(scenario, rows);
    let mut next_row = row_steps.iter().map(|s| s + warmup_steps).peekable();
    for step in 0..=last_step {
        let t = (step as f64 - warmup_steps as f64) * flight.control_dt;
        let reference = flight.generator.at(t);
        let measured = flight.measure();
        let output = flight
            .controller
            .update(&measured, &reference, flight.control_dt);
        let voltage = battery.map(|b| b.voltage(t, thrust));
        let speeds = flight.speeds_for(&output, t, voltage);
        thrust = mixer.wrench(&speeds)[0];
        commands.issue(step, (speeds, thrust, voltage.unwrap_or(0.0)));
        if next_row.next_if_eq(&step).is_some() {
            record_row(&mut log, &measured, &reference, &output, t);
            commands.add_row(step - warmup_steps);
        }
        commands.fill_ready(step);
        if step == last_step {
            break;
        }
        flight.advance(speeds, t, &reference)?;
    }
    commands.write_into(&mut log, model, mixer, scenario.hover_throttle);
    Ok(log)
}

/// The plant, controller and sensors of one simulated flight.
struct Flight<'a> {
    plant: Plant<'a>,
    mixer: &'a crate::mixer::Mixer,
    state: PlantState,
    controller: GeometricController,
    generator: crate::trajectory::ReferenceGenerator,
    noise: Gaussian,
    noise_levels: Noise,
    jitter: Option<JitterSignal>,
    /// Actuator commands per physics step, delayed as the `delay` effect says.
    applied: CommandQueue,
    /// The body rate after the logger's first-order filter (the true rate without one).
    filtered_rate: Vec3,
    rate_time_constant: f64,
    control_dt: f64,
    substeps: usize,
    look_ahead: usize,
}

impl<'a> Flight<'a> {
    fn new(model: &'a NominalModel, mixer: &'a crate::mixer::Mixer, scenario: &Scenario) -> Self {
        let control_dt = 1.0 / scenario.controller_rate();
        let substeps = (scenario.physics_rate_hz / scenario.controller_rate()).round() as usize;
        let h = control_dt / substeps as f64;
        let generator = scenario.trajectory.generator();
        let controller = GeometricController::new(model, scenario.gains);
        let warmup_s = scenario.warmup_rows() as f64 / scenario.log_rate_hz;
        let start = generator.at(-warmup_s);
        let hover_speeds = mixer.speeds_for(&[model.mass_kg * model.gravity_m_s2, 0.0, 0.0, 0.0]);
        let state = PlantState {
            position: start.position,
            velocity: start.velocity,
            quaternion: quaternion_from_rotation(&controller.initial_rotation(&start)),
            body_rate: [0.0; 3],
            speeds: hover_speeds,
            drag_velocity: start.velocity,
        };
        let logger = scenario.logger();
        let offset_steps = (logger.command_time_offset_s / control_dt).round() as i64;
        Self {
            plant: Plant {
                model,
                effects: scenario.effects,
            },
            mixer,
            state,
            controller,
            generator,
            noise: Gaussian {
                rng: ChaCha8Rng::seed_from_u64(scenario.seed),
            },
            noise_levels: scenario.noise,
            jitter: scenario
                .jitter
                .as_ref()
                .map(|j| JitterSignal::new(j, scenario.seed ^ 0x6a69_7474_6572)),
            applied: CommandQueue::new(scenario.effects.delay_s() / h),
            filtered_rate: [0.0; 3],
            rate_time_constant: logger.rate_time_constant_s(),
            control_dt,
            substeps,
            look_ahead: offset_steps.max(0) as usize,
        }
    }

    fn look_ahead_steps(&self) -> usize {
        self.look_ahead
    }

    /// What the sensors report now: the state with noise, the rate through the logger's filter.
    fn measure(&mut self) -> MeasuredState {
        let mut state = self.state;
        if self.rate_time_constant > 0.0 {
            state.body_rate = self.filtered_rate;
        }
        measure(&state, &self.noise_levels, &mut self.noise)
    }

    /// The motor speeds the controller commands, jitter included: with a vehicle's command map,
    /// those of the commands it logs (at the battery's voltage).
    fn speeds_for(&self, output: &ControlOutput, t: f64, battery_v: Option<f64>) -> Actuators {
        let mut wrench = [
            output.thrust,
            output.torque[0],
            output.torque[1],
            output.torque[2],
        ];
        if let Some(jitter) = &self.jitter {
            let j = jitter.at(t);
            let model = self.plant.model;
            wrench[0] += model.mass_kg * j[0];
            for i in 0..3 {
                wrench[i + 1] += model.inertia_kg_m2[i] * j[i + 1];
            }
        }
        let speeds = self.mixer.speeds_for(&wrench);
        if self.mixer.has_command_map() {
            self.mixer
                .speeds(&self.mixer.commands(&speeds, battery_v), battery_v)
        } else {
            speeds
        }
    }

    /// Integrates one control period with the commanded speeds.
    fn advance(
        &mut self,
        speeds: Actuators,
        t: f64,
        reference: &crate::trajectory::Reference,
    ) -> Result<()> {
        let h = self.control_dt / self.substeps as f64;
        let fraction = self.applied.fraction;
        for _ in 0..self.substeps {
            let (older, newer) = self.applied.push(speeds);
            if fraction > 0.0 && older != newer {
                // The delayed command changes within this step: integrate up to the change.
                self.integrate(older, fraction * h);
                self.integrate(newer, (1.0 - fraction) * h);
            } else {
                self.integrate(newer, h);
            }
        }
        check_state(&self.state, &reference.position, t)
    }

    /// One integration step of length `h` with the actuators held at `command`.
    fn integrate(&mut self, command: Actuators, h: f64) {
        self.state = rk4_step(&self.plant, &self.state, command, h);
        let gain = if self.rate_time_constant > 0.0 {
            1.0 - (-h / self.rate_time_constant).exp()
        } else {
            1.0
        };
        for i in 0..3 {
            self.filtered_rate[i] += gain * (self.state.body_rate[i] - self.filtered_rate[i]);
        }
    }
}

/// Appends one row's measured state and reference (its command is filled by [`CommandLog`]).
fn record_row(
    log: &mut FlightLog,
    measured: &MeasuredState,
    reference: &crate::trajectory::Reference,
    output: &ControlOutput,
    t: f64,
) {
    log.time.push(t);
    log.position.push(measured.position);
    log.velocity.push(measured.velocity);
    log.quaternion
        .push(quaternion_from_rotation(&measured.rotation));
    log.rotation.push(measured.rotation);
    log.body_rate.push(measured.body_rate);
    push(&mut log.position_desired, reference.position);
    push(&mut log.velocity_desired, reference.velocity);
    if let Some(setpoints) = log.attitude_setpoint.as_mut() {
        setpoints.push(quaternion_from_rotation(&output.desired_rotation));
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

fn empty_log(name: &str, rows: usize, motors: usize, battery: bool) -> FlightLog {
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
        motor_command: MotorCommands::with_capacity(motors, rows),
        battery_voltage: battery.then(|| Vec::with_capacity(rows)),
        declared_rate_frame: None,
        position_desired: Some(Vec::with_capacity(rows)),
        velocity_desired: Some(Vec::with_capacity(rows)),
        attitude_setpoint: Some(Vec::with_capacity(rows)),
        residual_force: None,
    }
}

mod command_log;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod timing_tests;
