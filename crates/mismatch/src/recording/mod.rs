//! A flight log turned into what the analysis needs: attitude, velocity, position, body rate and the
//! actuator commands the nominal model reads from the recorded command columns (step 0 of the
//! method): the actuator limits and the samples a command is reconstructed through
//! ([`command_samples`]), the reaction of sampled commands to logged noise removed
//! ([`noise_reaction`]), what the log really holds ([`content`]), and recordings no analysis can
//! use refused ([`degenerate`]).

pub mod command_samples;
pub mod content;
pub mod degenerate;
pub mod noise_reaction;

use std::path::PathBuf;

use data::{FlightLog, RateFrame};
use physics::vector::{Mat3, Vec3, mat_t_vec};
use physics::{Actuators, CommandLogging, MAX_ACTUATORS, NominalModel};
use sindy::sampling::Sampling;

use crate::error::{MismatchError, Result};
use command_samples::{ActuatorLimits, CommandSamples, SampleDomain, detect_limits};
use noise_reaction::NoiseReaction;

/// The recorded signals, per row.
#[derive(Clone, Debug)]
pub struct Recording {
    pub path: PathBuf,
    pub time: Vec<f64>,
    /// When the samples were taken: evenly spaced, or the logged stamps with their gaps.
    pub sampling: Sampling,
    pub rotation: Vec<Mat3>,
    pub velocity: Vec<Vec3>,
    /// Position, m (world frame).
    /// World position (NaN when the log has none: [`Recording::position_logged`]).
    pub position: Vec<Vec3>,
    /// Whether the log holds the position (without it the ground effect is not looked for and
    /// the commands' reaction to position noise is not removed).
    pub position_logged: bool,
    /// Body rate, rad/s (converted from the world frame when the `w` column is in the world frame).
    pub body_rate: Vec<Vec3>,
    /// The frame the `w` column was found to be in, with the RMS errors (body, world) of the check.
    pub rate_frame: RateFrame,
    pub rate_frame_errors: (f64, f64),
    /// Actuator commands (four normalised motor speeds, or `[T, 0, 0, 0]` in N), as logged.
    pub commands: Vec<Actuators>,
    /// Variance of each actuator command within a row, when the rows hold means over the log
    /// period of a faster controller's commands (zero otherwise): `(m − 1)` times the variance of the
    /// logged means' sample-to-sample noise, `m` commands per row, for white command noise.
    pub command_spread: Actuators,
    /// The rate of the commands a row averages, Hz (when known).
    pub command_rate_hz: Option<f64>,
    /// The limits the logged commands sit at ([`crate::recording::command_samples`]).
    pub command_limits: [ActuatorLimits; MAX_ACTUATORS],
    /// What the model's command is reconstructed through: for instantaneous samples, per-rotor
    /// thrusts with the runs at a limit continued; otherwise the commands as they are. Kept in step
    /// with `commands` by [`Recording::set_commands`].
    pub samples: CommandSamples,
    /// What was removed from sampled commands of a faster controller: their reaction to the
    /// logged attitude and position noise (and, after the analysis's first pass, velocity noise)
    /// that the vehicle did not feel ([`crate::recording::noise_reaction`]).
    pub noise_reaction: Option<NoiseReaction>,
}

impl Recording {
    /// Prepares a log for a model; needs at least `min_rows` rows.
    pub fn new(log: &FlightLog, model: &NominalModel, min_rows: usize) -> Result<Self> {
        let bad = |message: String| MismatchError::Recording {
            path: log.path.clone(),
            message,
        };
        if log.len() < min_rows {
            return Err(bad(format!(
                "{} rows, the analysis needs at least {min_rows}",
                log.len()
            )));
        }
        if model.thrust_source == physics::ThrustSource::ThrustSetpoint
            && log.thrust_setpoint.iter().all(|t| t.is_nan())
        {
            return Err(bad(
                "the model's thrust_source is \"T_sp\", and the recording has no thrust setpoint (a layout description maps none: give the model a vehicle or a mixer)".into(),
            ));
        }
        if model.thrust_source == physics::ThrustSource::ThrustSetpoint
            && let Some(row) = log
                .hover_throttle
                .iter()
                .position(|h| h.is_nan() || *h <= 0.0)
        {
            // `file:line:column`, the header being line 1.
            return Err(MismatchError::Recording {
                path: PathBuf::from(format!("{}:{}:hover_throttle", log.path.display(), row + 2)),
                message: format!(
                    "must be positive to scale T_sp (the model's thrust_source is \"T_sp\"), found {}",
                    log.hover_throttle[row]
                ),
            });
        }
        if let Some(rotors) = model.motor_count()
            && log.motor_command.count() != rotors
        {
            return Err(bad(format!(
                "{} motor commands a row, and the model's mixer has {rotors} rotors (the layout's motor_commands, or the pwm lists, give one command per rotor of the vehicle)",
                log.motor_command.count()
            )));
        }
        let degenerate = |degeneracy| MismatchError::Degenerate {
            path: log.path.clone(),
            degeneracy,
        };
        degenerate::check_excitation(log, model).map_err(degenerate)?;
        let (detected, body_rms, world_rms) = log.rate_frame();
        let frame = log.declared_rate_frame.unwrap_or(detected);
        let body_rate = match frame {
            RateFrame::Body => log.body_rate.clone(),
            RateFrame::World => log
                .rotation
                .iter()
                .zip(&log.body_rate)
                .map(|(r, w)| mat_t_vec(r, *w))
                .collect(),
        };
        if model.needs_battery_voltage() && log.battery_voltage.is_none() {
            return Err(bad(
                "the model's thrust map depends on the battery voltage, and the recording has none (map a battery_voltage column in its layout)".into(),
            ));
        }
        let commands: Vec<Actuators> = (0..log.len())
            .map(|k| {
                model.actuator_command(
                    log.thrust_setpoint[k],
                    log.hover_throttle[k],
                    log.motor_command.row(k),
                    log.battery_voltage.as_ref().map(|v| v[k]),
                )
            })
            .collect();
        degenerate::check_thrust(&commands, model).map_err(degenerate)?;
        let sampling = Sampling::new(&log.time);
        let dt = sampling.interval();
        let command_rate_hz = match model.logger.command {
            CommandLogging::PeriodMean => model.logger.controller_rate_hz,
            _ => None,
        };
        let mut command_spread = [0.0; MAX_ACTUATORS];
        if let Some(rate) = command_rate_hz {
            let per_row = (rate * dt).max(1.0);
            for i in 0..model.actuator_count() {
                let series: Vec<f64> = commands.iter().map(|c| c[i]).collect();
                command_spread[i] = (per_row - 1.0) * sampling.white_noise_sigma(&series).powi(2);
            }
        }
        let count = model.actuator_count();
        let command_limits = detect_limits(&commands, count);
        let samples = match model.logger.command {
            CommandLogging::Sample => {
                CommandSamples::new(&commands, count, SampleDomain::of(model), &command_limits)
            }
            _ => CommandSamples::plain(&commands, count),
        };
        let mut recording = Self {
            path: log.path.clone(),
            time: log.time.clone(),
            sampling,
            rotation: log.rotation.clone(),
            velocity: log.velocity.clone(),
            position: log.position.clone(),
            position_logged: log.position_logged(),
            body_rate,
            rate_frame: frame,
            rate_frame_errors: (body_rms, world_rms),
            commands,
            command_spread,
            command_rate_hz,
            command_limits,
            samples,
            noise_reaction: None,
        };
        noise_reaction::remove(&mut recording, &model.logger, count);
        Ok(recording)
    }

    /// Replaces the commands (corrected ones) and the samples reconstructed through them.
    pub fn set_commands(&mut self, commands: Vec<Actuators>) {
        self.samples = self.samples.with_commands(&commands);
        self.commands = commands;
    }

    /// The nominal sample interval (`sampling.interval()`), s.
    pub fn dt(&self) -> f64 {
        self.sampling.interval()
    }

    /// Robust standard deviation of the white noise on a smooth series given at the rows.
    pub fn white_noise_sigma(&self, series: &[f64]) -> f64 {
        self.sampling.white_noise_sigma(series)
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.time.len()
    }

    /// Whether there are no rows.
    pub fn is_empty(&self) -> bool {
        self.time.is_empty()
    }
}
