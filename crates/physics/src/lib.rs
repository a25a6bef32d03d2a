//! Multirotor rigid-body physics for the sim-to-real mismatch tool.
//!
//! What it is for: the nominal model read from JSON ([`NominalModel`]: mass, gravity, inertia, and
//! how thrust and torques follow from a recorded command); the vocabulary of unmodelled effects
//! ([`effects`]: one file per effect implementing [`Effect`] and [`EffectKind`], listed by its
//! registry; a set of them is [`Effects`], each named by an [`EffectId`]; ids and parameter names
//! are an output contract); a
//! closed-loop simulator ([`simulate`]: RK4 rigid body, geometric tracking controller that knows
//! only the nominal model, figure-8 and random-waypoint [`Trajectory`]s, measurement [`Noise`], rows
//! jittered, dropped or missing over gaps as a real logger writes them ([`LogTiming`]); a
//! [`Scenario`] is read from JSON or, for examples and tests, built by [`Scenario::figure_eight`])
//! that writes Neural-Fly logs the data tools read back ([`write_readable`]), for 4 to 8 rotors
//! through a [`Mixer`] (or a vehicle's command map) and with a [`Battery`] whose voltage a
//! thrust map may read; and the residual
//! force of a recorded flight ([`residual_force`], the `fa` column); descriptions of any multirotor
//! ([`vehicle`]: rotors, command map, the allocation matrix, PX4's airframe parameters).
//!
//! What it is not for: analysing mismatches (the `mismatch` crate), reading CSVs (the `data` crate).
//!
//! Conventions: world z up, gravity along −z; `R` body to world; quaternions `[x, y, z, w]`;
//! `m v̇ = m [0, 0, −g] + R [0, 0, T]`, `J ω̇ = −ω × (J ω) + τ` with `ω` the body rate.

// Index loops over 3- and 4-vectors read like the formulas they implement.
#![allow(clippy::needless_range_loop)]

mod battery;
mod controller;
mod effect_id;
pub mod effects;
mod error;
mod jitter;
mod log_timing;
mod logger;
mod mixer;
mod model;
pub mod ranges;
mod residual;
mod scenario;
mod simulator;
mod trajectory;
pub mod vector;
pub mod vehicle;
mod writer;

pub use battery::{Battery, MAX_BATTERY_V};
pub use controller::{ControlOutput, Gains, GeometricController, MeasuredState};
pub use effect_id::UnknownEffectId;
pub use effects::*;
pub use error::{PhysicsError, Result};
pub use jitter::{Jitter, JitterSignal, MAX_JITTER};
pub use log_timing::{LogTiming, MAX_DROPPED_FRACTION};
pub use logger::{
    CommandLogging, Logger, MAX_COMMAND_OFFSET_S, MAX_RATE_LOW_PASS_HZ, MIN_RATE_LOW_PASS_HZ,
};
pub use mixer::{Actuators, MAX_ACTUATORS, Mixer, actuators};
pub use model::{
    ComparedChannels, NominalModel, ThrustSource, Wrench, angular_acceleration_with_inertia,
};
pub use residual::{five_point_derivative, residual_force};
pub use scenario::{
    MAX_DELAY_S, MAX_DURATION_S, MAX_LOG_ROWS, MAX_NOISE, MAX_PHYSICS_RATE_HZ,
    MAX_REFERENCE_ACCELERATION_M_S2, MAX_WARMUP_S, MIN_HOVER_THROTTLE, MIN_LOG_ROWS,
    MIN_PHYSICS_RATE_HZ, Noise, Scenario,
};
pub use simulator::simulate;
pub use trajectory::{
    LowPass, MAX_POSITION_M, MAX_WAYPOINTS, MAX_YAW_RATE_RAD_S, Reference, ReferenceGenerator,
    Trajectory,
};
pub use vehicle::{Allocation, CommandMap, Layout, Rotor, Spin, VehicleDescription};
pub use writer::write_readable;
