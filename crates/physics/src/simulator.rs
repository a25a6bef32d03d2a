//! Closed-loop simulation of the real plant (nominal model plus switchable effects) under the
//! geometric controller, written as a Neural-Fly flight log.
//!
//! Timing: the controller runs at `controller_rate_hz` (by default the log rate) and each command
//! is held by the actuators (after any delay, exact even between physics steps) until the next one.
//! Every `controller_rate_hz / log_rate_hz` control steps a row is logged: the measured state at
//! that instant and the command as the scenario's [`crate::Logger`] records it (the instantaneous
//! command, the mean over the log period, either shifted by whole control steps; each command held
//! to the next row when the controller runs at the log rate). The rigid body is integrated with RK4
//! at `physics_rate_hz`; with a motor lag the four motor speeds are part of the state. Measurement
//! noise (Gaussian, from the scenario's seed) is added to position, velocity, attitude and body
//! rate, the rate after the logger's optional first-order filter; the controller sees the noisy
//! values, as on a real vehicle. An optional band-limited [`crate::Jitter`] is added to the
//! commands (and logged with them).

use std::collections::VecDeque;
use std::path::{Path, PathBuf};

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use data::{FlightLog, quaternion_from_rotation, rotation_from_quaternion};

use crate::controller::{ControlOutput, GeometricController, MeasuredState};
use crate::effects::Effects;
use crate::error::{PhysicsError, Result};
use crate::jitter::JitterSignal;
use crate::logger::CommandLogging;
use crate::model::NominalModel;
use crate::scenario::{Noise, Scenario};
use crate::vector::{
    Vec3, add, mat_mul, norm, quaternion_multiply, quaternion_normalize,
    rotation_from_rotation_vector, scale, sub,
};

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
    /// The velocity the air terms see (only integrated with a drag lag).
    drag_velocity: Vec3,
}

#[derive(Clone, Copy, Debug)]
struct Derivative {
    velocity: Vec3,
    acceleration: Vec3,
    quaternion: [f64; 4],
    angular_acceleration: Vec3,
    speeds: [f64; 4],
    drag_velocity: Vec3,
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
        let drag_lag = self.effects.drag_lag_s();
        let air_velocity = if drag_lag > 0.0 {
            state.drag_velocity
        } else {
            state.velocity
        };
        let acceleration = self.effects.translational_acceleration(
            self.model,
            &rotation,
            air_velocity,
            state.position,
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
            drag_velocity,
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
        drag_velocity: add(state.drag_velocity, scale(derivative.drag_velocity, h)),
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
    scenario.validate_with_model(model, Path::new(name))?;
    let mixer = model.mixer.as_ref().ok_or_else(|| {
        PhysicsError::Simulation(
            "the simulator needs a model with a mixer (thrust_source \"mixer\")".into(),
        )
    })?;
    let mut flight = Flight::new(model, mixer, scenario);
    let per_row = scenario.controller_steps_per_row();
    let warmup_steps = scenario.warmup_rows() * per_row;
    let rows = scenario.rows();
    let last_row_step = warmup_steps + (rows - 1) * per_row;
    // Run on after the last row until the commands a look-ahead logger records exist.
    let last_step = last_row_step + flight.look_ahead_steps();
    let mut log = empty_log(name, rows);
    let mut commands = CommandLog::new(scenario, rows);
    for step in 0..=last_step {
        let t = (step as f64 - warmup_steps as f64) * flight.control_dt;
        let reference = flight.generator.at(t);
        let measured = flight.measure();
        let output = flight
            .controller
            .update(&measured, &reference, flight.control_dt);
        let speeds = flight.speeds_for(&output, t);
        commands.issue(step, speeds, mixer.wrench(&speeds)[0]);
        if step >= warmup_steps && (step - warmup_steps) % per_row == 0 && step <= last_row_step {
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
    mixer: &'a crate::model::Mixer,
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
    fn new(model: &'a NominalModel, mixer: &'a crate::model::Mixer, scenario: &Scenario) -> Self {
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

    /// The motor speeds the controller commands, jitter included.
    fn speeds_for(&self, output: &ControlOutput, t: f64) -> [f64; 4] {
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
        self.mixer.speeds_for(&wrench)
    }

    /// Integrates one control period with the commanded speeds.
    fn advance(
        &mut self,
        speeds: [f64; 4],
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
    fn integrate(&mut self, command: [f64; 4], h: f64) {
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

/// Motor speeds and collective thrust (N) as logged.
type LoggedCommand = ([f64; 4], f64);

/// The commands the logger writes: for each row, the issued commands it reads (one, or the mean
/// over a log period), found in a window of the most recent control steps.
struct CommandLog {
    logging: CommandLogging,
    offset_steps: i64,
    per_row: usize,
    /// Recent control steps: (step, motor speeds, thrust).
    recent: VecDeque<(usize, [f64; 4], f64)>,
    /// Per row: its control step (from the first row) and, once known, its command.
    rows: Vec<(usize, Option<LoggedCommand>)>,
    warmup_steps: usize,
    first: Option<LoggedCommand>,
    /// Rows before this one are filled (rows are filled in order).
    next: usize,
}

impl CommandLog {
    fn new(scenario: &Scenario, rows: usize) -> Self {
        let logger = scenario.logger();
        let per_row = scenario.controller_steps_per_row();
        Self {
            logging: logger.command,
            offset_steps: (logger.command_time_offset_s * scenario.controller_rate()).round()
                as i64,
            per_row,
            recent: VecDeque::new(),
            rows: Vec::with_capacity(rows),
            warmup_steps: scenario.warmup_rows() * per_row,
            first: None,
            next: 0,
        }
    }

    /// The control steps a row recorded at `step` reads: `[low, high]`.
    fn span(&self, step: usize) -> (i64, i64) {
        let at = step as i64 + self.offset_steps;
        match self.logging {
            CommandLogging::Sample | CommandLogging::Held => (at, at),
            CommandLogging::PeriodMean => (at - self.per_row as i64, at - 1),
        }
    }

    fn issue(&mut self, step: usize, speeds: [f64; 4], thrust: f64) {
        self.first.get_or_insert((speeds, thrust));
        self.recent.push_back((step, speeds, thrust));
        let keep = self.per_row + self.offset_steps.unsigned_abs() as usize + 2;
        while self.recent.len() > keep {
            self.recent.pop_front();
        }
    }

    fn add_row(&mut self, step_from_first_row: usize) {
        self.rows.push((step_from_first_row, None));
    }

    /// Fills every pending row whose commands have all been issued by `step`.
    fn fill_ready(&mut self, step: usize) {
        while self.next < self.rows.len() {
            let index = self.next;
            let row_step = self.rows[index].0 + self.warmup_steps;
            let (low, high) = self.span(row_step);
            if high > step as i64 {
                return;
            }
            self.next += 1;
            let first = self.first.expect("a command was issued");
            let mut sum = ([0.0; 4], 0.0);
            for wanted in low..=high {
                let (speeds, thrust) = self
                    .recent
                    .iter()
                    .find(|(s, _, _)| *s as i64 == wanted)
                    .map(|(_, speeds, thrust)| (*speeds, *thrust))
                    .unwrap_or(first);
                for i in 0..4 {
                    sum.0[i] += speeds[i];
                }
                sum.1 += thrust;
            }
            let count = (high - low + 1) as f64;
            self.rows[index].1 = Some((sum.0.map(|v| v / count), sum.1 / count));
        }
    }

    fn write_into(
        self,
        log: &mut FlightLog,
        model: &NominalModel,
        mixer: &crate::model::Mixer,
        hover_throttle: f64,
    ) {
        for (_, command) in self.rows {
            let (speeds, thrust) = command.expect("every row's command is issued by the last step");
            log.thrust_setpoint
                .push(thrust / (model.mass_kg * model.gravity_m_s2) * hover_throttle);
            log.hover_throttle.push(hover_throttle);
            log.motor_command.push(mixer.pwm(&speeds));
        }
    }
}

/// The commands issued per physics step, of which only the last `delay_steps + 2` (and the very
/// first) are kept. A delay of `delay_steps + fraction` steps is exact: over each step the
/// actuators receive the command issued `delay_steps + 1` steps ago for its first `fraction`,
/// and the one issued `delay_steps` ago for the rest.
struct CommandQueue {
    delay_steps: usize,
    fraction: f64,
    first: Option<[f64; 4]>,
    recent: VecDeque<[f64; 4]>,
}

impl CommandQueue {
    /// A queue for a delay of `steps` physics steps (any non-negative number).
    fn new(steps: f64) -> Self {
        // Within rounding of a whole number of steps, the delay is that number.
        let nearest = steps.round();
        let (whole, fraction) = if (steps - nearest).abs() < 1e-9 {
            (nearest, 0.0)
        } else {
            (steps.floor(), steps - steps.floor())
        };
        let delay_steps = whole as usize;
        Self {
            delay_steps,
            fraction,
            first: None,
            recent: VecDeque::with_capacity(delay_steps + 2),
        }
    }

    /// Records a command and returns the two the actuators receive over this step: the one
    /// issued `delay_steps + 1` physics steps ago (for the first `fraction` of it) and the one
    /// issued `delay_steps` ago (the first command before those).
    fn push(&mut self, command: [f64; 4]) -> ([f64; 4], [f64; 4]) {
        let first = *self.first.get_or_insert(command);
        self.recent.push_back(command);
        if self.recent.len() > self.delay_steps + 2 {
            self.recent.pop_front();
        }
        let issued_ago = |steps: usize| {
            let len = self.recent.len();
            if len > steps {
                self.recent[len - 1 - steps]
            } else {
                first
            }
        };
        (
            issued_ago(self.delay_steps + 1),
            issued_ago(self.delay_steps),
        )
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::jitter::Jitter;
    use crate::logger::Logger;
    use crate::scenario::*;
    use crate::trajectory::{MAX_POSITION_M, Trajectory};

    const MODEL: &str = r#"{"mass_kg": 1.8, "gravity_m_s2": 9.81, "inertia_kg_m2": [0.02, 0.02, 0.035],
        "thrust_source": "mixer",
        "mixer": {"pwm_offset": 1000.0, "pwm_scale": 1000.0,
                  "b0": [[9.0, 9.0, 9.0, 9.0], [-1.08, 1.08, 1.08, -1.08], [1.08, -1.08, 1.08, -1.08], [0.144, 0.144, -0.144, -0.144]]}}"#;

    fn model() -> NominalModel {
        NominalModel::from_json(MODEL, Path::new("quad.json")).unwrap()
    }

    fn scenario() -> Scenario {
        Scenario::figure_eight("quad.json", 1)
    }

    /// The field named by the validation error of a changed scenario.
    /// Adds a low pass at `height_m` (1 s to 5 s) to the figure-8 of `s`.
    fn add_low_pass(s: &mut Scenario, height_m: f64) {
        if let Trajectory::Figure8 { low_passes, .. } = &mut s.trajectory {
            low_passes.push(crate::trajectory::LowPass {
                start_s: 1.0,
                end_s: 5.0,
                height_m,
                ramp_s: 1.0,
            });
        }
    }

    /// Replaces the trajectory of `s` with `count` random waypoints in a box from
    /// (-1, -1, 1) to `box_max`.
    fn random_waypoints(s: &mut Scenario, count: usize, box_max: [f64; 3]) {
        s.trajectory = Trajectory::RandomWaypoints {
            seed: 1,
            count,
            box_min: [-1.0, -1.0, 1.0],
            box_max,
            segment_s: 2.5,
            low_passes: Vec::new(),
            yaw_amplitude_rad: 0.0,
            yaw_period_s: 10.0,
        };
    }

    fn rejected_field(change: impl FnOnce(&mut Scenario)) -> String {
        let mut s = scenario();
        change(&mut s);
        let error = s
            .validate(Path::new("s.json"))
            .and_then(|()| s.validate_with_model(&model(), Path::new("s.json")))
            .unwrap_err();
        let text = error.to_string();
        assert!(!text.contains('\n'), "{text}");
        assert!(text.starts_with("s.json: field '"), "{text}");
        match error {
            PhysicsError::Field { field, .. } => field,
            other => panic!("not a field error: {other}"),
        }
    }

    #[test]
    fn a_valid_scenario_passes() {
        let s = scenario();
        s.validate(Path::new("s.json")).unwrap();
        s.validate_with_model(&model(), Path::new("s.json"))
            .unwrap();
    }

    #[test]
    fn a_negative_integral_limit_is_a_field_error_not_a_panic() {
        assert_eq!(
            rejected_field(|s| s.gains.integral_limit = -1.0),
            "gains.integral_limit"
        );
        assert_eq!(
            rejected_field(|s| s.gains.position = -6.0),
            "gains.position"
        );
        assert_eq!(rejected_field(|s| s.gains.rate = 0.0), "gains.rate");
        // and the simulator itself refuses it rather than panicking in f64::clamp
        let mut s = scenario();
        s.gains.integral_limit = -1.0;
        assert!(simulate(&model(), &s, "x").is_err());
    }

    #[test]
    fn sizes_are_bounded_above_and_below() {
        assert_eq!(rejected_field(|s| s.duration_s = 1e7), "duration_s");
        assert_eq!(rejected_field(|s| s.duration_s = 0.001), "duration_s");
        // 4 s at 50 Hz is 201 rows: too few for the analysis
        assert_eq!(rejected_field(|s| s.duration_s = 4.0), "duration_s");
        assert_eq!(
            rejected_field(|s| {
                s.duration_s = 3000.0;
                s.log_rate_hz = 500.0;
            }),
            "duration_s"
        );
        assert_eq!(rejected_field(|s| s.warmup_s = 1e7), "warmup_s");
        assert_eq!(rejected_field(|s| s.warmup_s = -1.0), "warmup_s");
        assert_eq!(
            rejected_field(|s| s.physics_rate_hz = 5e8),
            "physics_rate_hz"
        );
        assert_eq!(
            rejected_field(|s| s.physics_rate_hz = f64::NAN),
            "physics_rate_hz"
        );
        assert_eq!(rejected_field(|s| s.hover_throttle = 1.5), "hover_throttle");
        let mut s = scenario();
        s.duration_s = MAX_DURATION_S;
        s.warmup_s = MAX_WARMUP_S;
        s.validate(Path::new("s.json")).unwrap();
    }

    /// The message of the validation error of a changed scenario.
    fn rejection(change: impl FnOnce(&mut Scenario)) -> String {
        let mut s = scenario();
        change(&mut s);
        s.validate(Path::new("s.json"))
            .and_then(|()| s.validate_with_model(&model(), Path::new("s.json")))
            .unwrap_err()
            .to_string()
    }

    fn set_center(center: Vec3) -> impl FnOnce(&mut Scenario) {
        move |s: &mut Scenario| {
            if let Trajectory::Figure8 { center: c, .. } = &mut s.trajectory {
                *c = center;
            }
        }
    }

    /// Settings that would give a log the data tools refuse ("outside the plausible range") are
    /// refused when the scenario is read, naming the field.
    #[test]
    fn settings_that_would_leave_the_plausible_ranges_are_field_errors() {
        assert_eq!(
            rejected_field(set_center([1e300, 0.0, 1.5])),
            "trajectory.center"
        );
        assert_eq!(
            rejected_field(set_center([0.0, 0.0, 1e6])),
            "trajectory.center"
        );
        assert!(
            rejection(set_center([1e300, 0.0, 1.5])).contains("1e300 m"),
            "{}",
            rejection(set_center([1e300, 0.0, 1.5]))
        );
        assert_eq!(
            rejected_field(|s| s.hover_throttle = 1e-300),
            "hover_throttle"
        );
        assert_eq!(
            rejected_field(|s| s.hover_throttle = MIN_HOVER_THROTTLE / 2.0),
            "hover_throttle"
        );
        for (name, change) in [
            (
                "noise.position_m",
                (|s: &mut Scenario| s.noise.position_m = 1e5) as fn(&mut Scenario),
            ),
            ("noise.velocity_m_s", |s| s.noise.velocity_m_s = 1e5),
            ("noise.attitude_rad", |s| s.noise.attitude_rad = 10.0),
            ("noise.rate_rad_s", |s| s.noise.rate_rad_s = 1e5),
        ] {
            assert_eq!(rejected_field(change), name);
        }
        assert_eq!(
            rejected_field(|s| add_low_pass(s, 1e9)),
            "trajectory.low_passes[0].height_m"
        );
        assert_eq!(
            rejected_field(|s| random_waypoints(s, 4, [1.0, 1.0, 1e7])),
            "trajectory.box_max"
        );
        // every field within the bound, their sum (center + first + second) beyond it
        assert_eq!(
            rejected_field(|s| {
                if let Trajectory::Figure8 {
                    center,
                    first,
                    period_s,
                    ..
                } = &mut s.trajectory
                {
                    *center = [900.0, 0.0, 1.5];
                    *first = [900.0, 0.0, 0.0];
                    *period_s = 60.0;
                }
            }),
            "trajectory"
        );
        // the bounds themselves are accepted
        let mut s = scenario();
        s.hover_throttle = MIN_HOVER_THROTTLE;
        s.noise = MAX_NOISE;
        set_center([MAX_POSITION_M - 2.0, -(MAX_POSITION_M - 2.0), 1.5])(&mut s);
        s.validate(Path::new("s.json")).unwrap();
        s.validate_with_model(&model(), Path::new("s.json"))
            .unwrap();
    }

    /// Huge numbers in messages read as numbers, not as hundreds of digits.
    #[test]
    fn huge_values_are_named_readably() {
        let message = rejection(|s| s.duration_s = 1e308);
        assert!(message.contains("found 1e308"), "{message}");
        assert!(message.len() < 200, "{message}");
        let message = rejection(|s| s.gains.position = -1e300);
        assert!(message.contains("found -1e300"), "{message}");
    }

    #[test]
    fn trajectory_fields_are_field_errors_not_divergence() {
        let set_yaw_period = |value: f64| {
            move |s: &mut Scenario| {
                if let Trajectory::Figure8 { yaw_period_s, .. } = &mut s.trajectory {
                    *yaw_period_s = value;
                }
            }
        };
        assert_eq!(
            rejected_field(set_yaw_period(0.0)),
            "trajectory.yaw_period_s"
        );
        // a yaw rate no vehicle follows (0.2 rad amplitude every 0.1 s)
        assert_eq!(
            rejected_field(set_yaw_period(0.1)),
            "trajectory.yaw_period_s"
        );
        // within the position bound, but a reference no vehicle follows
        assert_eq!(
            rejected_field(|s| {
                if let Trajectory::Figure8 { first, .. } = &mut s.trajectory {
                    first[0] = 500.0;
                }
            }),
            "trajectory"
        );
        assert_eq!(rejected_field(|s| add_low_pass(s, -1.0)), "trajectory");
        assert_eq!(
            rejected_field(|s| random_waypoints(s, 1_000_000_000, [1.0, 1.0, 2.0])),
            "trajectory.count"
        );
    }

    #[test]
    fn noise_delay_and_model_errors_name_the_field() {
        assert_eq!(
            rejected_field(|s| s.noise.rate_rad_s = -0.1),
            "noise.rate_rad_s"
        );
        assert_eq!(
            rejected_field(|s| {
                s.effects.delay = Some(crate::effects::Delay { delay_s: 1e9 });
            }),
            "effects.delay.delay_s"
        );
        let thrust_only = NominalModel::from_json(
            r#"{"mass_kg": 2.6, "gravity_m_s2": 9.81, "inertia_kg_m2": [0.03, 0.03, 0.05], "thrust_source": "T_sp"}"#,
            Path::new("nf.json"),
        )
        .unwrap();
        let error = scenario()
            .validate_with_model(&thrust_only, Path::new("s.json"))
            .unwrap_err()
            .to_string();
        assert!(error.contains("field 'model'"), "{error}");
    }

    /// The logger reads the commands its description says: with commands numbered by their control
    /// step, a row at step s holds s (sample), s + 1 (one step late), or the mean of s − 10 … s − 1
    /// (the mean over the preceding log period of 10 control steps).
    #[test]
    fn the_command_log_reads_what_the_logger_describes() {
        let logged = |logger: Logger| -> Vec<f64> {
            let mut s = scenario();
            s.controller_rate_hz = Some(500.0);
            s.logger = Some(logger);
            s.warmup_s = 0.2;
            let mut commands = CommandLog::new(&s, 3);
            let warmup_steps = s.warmup_rows() * 10;
            for step in 0..warmup_steps + 40 {
                commands.issue(step, [step as f64; 4], 2.0 * step as f64);
                if step >= warmup_steps
                    && (step - warmup_steps) % 10 == 0
                    && step < warmup_steps + 30
                {
                    commands.add_row(step - warmup_steps);
                }
                commands.fill_ready(step);
            }
            commands
                .rows
                .iter()
                .map(|(step, command)| {
                    let (speeds, thrust) = command.unwrap();
                    assert_eq!(thrust, 2.0 * speeds[0]);
                    speeds[0] - (step + warmup_steps) as f64
                })
                .collect()
        };
        assert_eq!(logged(Logger::default()), [0.0; 3]);
        let late = Logger {
            command_time_offset_s: 0.002,
            ..Logger::default()
        };
        assert_eq!(logged(late), [1.0; 3]);
        let mean = Logger {
            command: CommandLogging::PeriodMean,
            ..Logger::default()
        };
        assert_eq!(logged(mean), [-5.5; 3]);
    }

    #[test]
    fn the_logger_must_match_the_controller_rate() {
        assert_eq!(
            rejected_field(|s| s.logger = Some(Logger::default())),
            "logger.command"
        );
        assert_eq!(
            rejected_field(|s| {
                s.controller_rate_hz = Some(500.0);
                s.logger = Some(Logger {
                    command: CommandLogging::Held,
                    ..Logger::default()
                });
            }),
            "logger.command"
        );
        assert_eq!(
            rejected_field(|s| s.controller_rate_hz = Some(75.0)),
            "controller_rate_hz"
        );
        assert_eq!(
            rejected_field(|s| {
                s.controller_rate_hz = Some(500.0);
                s.logger = Some(Logger {
                    command_time_offset_s: 0.0013,
                    ..Logger::default()
                });
            }),
            "logger.command_time_offset_s"
        );
        let mut s = scenario();
        assert_eq!(s.logger().command, CommandLogging::Held);
        s.controller_rate_hz = Some(500.0);
        assert_eq!(s.logger().command, CommandLogging::Sample);
        s.jitter = Some(Jitter {
            translational_m_s2: 0.3,
            angular_rad_s2: 2.0,
            band_hz: [1.0, 5.0],
        });
        s.logger = Some(Logger {
            command: CommandLogging::PeriodMean,
            command_time_offset_s: -0.004,
            rate_low_pass_hz: Some(40.0),
            controller_rate_hz: None,
        });
        s.physics_rate_hz = 1000.0;
        s.validate(Path::new("s.json")).unwrap();
        let log = simulate(&model(), &s, "fast").unwrap();
        assert_eq!(log.len(), s.rows());
        assert_eq!(
            simulate(&model(), &s, "fast").unwrap().motor_command,
            log.motor_command
        );
    }

    /// The queue gives exactly what indexing the whole history gave.
    #[test]
    fn the_command_queue_delays_like_the_full_history() {
        for delay_steps in [0, 1, 3, 17] {
            let mut queue = CommandQueue::new(delay_steps as f64);
            assert_eq!(queue.fraction, 0.0);
            let mut history: Vec<[f64; 4]> = Vec::new();
            for k in 0..60 {
                let command = [k as f64, 0.5 * k as f64, 1.0, -(k as f64)];
                history.push(command);
                let index = history.len() - 1;
                let issued_ago = |steps: usize| history[index.saturating_sub(steps)];
                assert_eq!(
                    queue.push(command),
                    (issued_ago(delay_steps + 1), issued_ago(delay_steps))
                );
            }
            assert!(queue.recent.len() <= delay_steps + 2);
        }
        let queue = CommandQueue::new(12.5);
        assert_eq!((queue.delay_steps, queue.fraction), (12, 0.5));
    }

    /// A delay that is not a whole number of physics steps is applied as configured, not rounded
    /// to the step: 25 ms at 500 Hz (12.5 steps) flies as 25 ms at 2000 Hz does, far closer than
    /// the 26 ms that rounding gave.
    #[test]
    fn a_delay_between_physics_steps_is_exact() {
        let flight = |physics_rate_hz: f64, delay_s: f64| {
            let mut s = scenario();
            s.physics_rate_hz = physics_rate_hz;
            s.effects.delay = Some(crate::effects::Delay { delay_s });
            s.validate(Path::new("s.json")).unwrap();
            simulate(&model(), &s, "delay").unwrap()
        };
        let distance = |a: &FlightLog, b: &FlightLog| {
            a.body_rate
                .iter()
                .zip(&b.body_rate)
                .map(|(x, y)| (0..3).map(|i| (x[i] - y[i]).powi(2)).sum::<f64>())
                .sum::<f64>()
                .sqrt()
        };
        let reference = flight(2000.0, 0.025);
        let coarse = flight(500.0, 0.025);
        let one_ms_later = flight(2000.0, 0.026);
        let (error, scale) = (
            distance(&coarse, &reference),
            distance(&one_ms_later, &reference),
        );
        assert!(error < 0.2 * scale, "{error} vs {scale}");
    }
}
