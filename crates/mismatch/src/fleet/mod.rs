//! Several flights of one vehicle analysed together: the vehicle's missing physics identified once
//! for all of them, and one air velocity per flight.
//!
//! What a single recording cannot separate, several can: a tilted thrust axis reads, in one flight,
//! as a steady wind; a drag coefficient trades against the wind speed. The flights declared calm
//! (still air) calibrate what only still air reveals, and every flight shares one vehicle.
//!
//! Method ([`identify`]), on the weak-form residual of each flight's translational channels
//! ([`crate::weak_form`]), every fit on the first part of each flight and every choice on the
//! held-out rest:
//! 1. **Calm calibration.** On the calm flights alone (air velocity zero), vehicle effects are added
//!    one at a time, the one that lowers the held-out error most, while it lowers it by at least
//!    [`crate::FleetSettings::min_step`]: a thrust map, a thrust-axis tilt, rotor drag, quadratic drag, a
//!    command delay, a lag of the air forces. The delay and the lag are fixed here: in still air
//!    nothing else trades against them, while with wind their values slide with the wind's scale.
//! 2. **Transfer.** On all flights, each not calm with its own air, the effects only moving air
//!    shows (translational lift; an air velocity that varies in space, `wind_gradient`) are added
//!    while they lower the *transfer* error by at least the same step: for each windy condition,
//!    the vehicle fitted on the other conditions' flights, only the air fitted on this condition's
//!    flights, scored on their held-out part. An effect is kept only if the vehicle it describes
//!    carries over to conditions it was not fitted on. Drag laws are chosen in step 1 only: where
//!    the airspeed is known; with unknown winds a drag law's shape trades against the winds' scale.
//! 3. **Winds.** The vehicle and every air velocity fitted on all rows of all flights (role `fit`),
//!    and, for validation, each windy condition's air velocities with the vehicle fitted without
//!    that condition, each calm flight's with the vehicle fitted without that flight (role
//!    `validation`).
//!
//! Known wind speeds (`mean_wind_m_s` in the conditions file) are only compared with the estimates.

mod attitude;
mod joint;
mod report;
mod scale_report;
mod sensitivity;
#[cfg(test)]
mod tests;

use std::path::{Path, PathBuf};

use crate::settings::CheckedSettings;
use data::ExperimentConditions;
use physics::{EffectId, EffectNumber, NominalModel};
use rayon::prelude::*;
use serde::Serialize;

use crate::error::{MismatchError, Result};
use crate::locate::problem::Problem;
use crate::model::least_squares::Termination;
use crate::recording::Recording;
use crate::recording::degenerate;

pub use self::report::{FleetReport, file_names};
pub use ::report::mismatch::fleet::{
    AttitudeCheck, FlightHeldout, FlightSpeedRange, FlightWind, ScaleReport, Targets,
};
pub use joint::{Air, Vehicle};
use joint::{JointFit, JointFlight, JointSettings};
pub use scale_report::scale_report;
pub use sensitivity::{LAG_GRID_S, LagProfile, LagSensitivity};

/// Effects the calm flights are tried with, in this order.
const CALM_CANDIDATES: [EffectId; 6] = [
    EffectId::ThrustMap,
    EffectId::ThrustTilt,
    EffectId::RotorDrag,
    EffectId::QuadraticDrag,
    EffectId::Delay,
    EffectId::DragLag,
];
/// Effects only moving air shows, tried on all flights. Drag laws are not among them: they are
/// identified where the airspeed is known (in still air), since with unknown winds a drag law's
/// shape trades against the winds' scale (a term growing with the square of the airspeed can
/// shrink every wind in proportion).
const WIND_CANDIDATES: [EffectId; 2] = [EffectId::WindGradient, EffectId::TranslationalLift];

/// The spread of positions (standard deviation) along an axis from which a flight's air gradient
/// is fitted along it, m.
pub const GRADIENT_SPREAD_M: f64 = 0.25;

/// The mean position and the axes along which positions spread at least [`GRADIENT_SPREAD_M`].
fn spread(positions: &[[f64; 3]]) -> ([f64; 3], Vec<usize>) {
    let n = positions.len().max(1) as f64;
    let mut mean = [0.0; 3];
    for p in positions {
        for i in 0..3 {
            mean[i] += p[i] / n;
        }
    }
    let axes = (0..3)
        .filter(|&i| {
            let variance = positions
                .iter()
                .map(|p| (p[i] - mean[i]).powi(2))
                .sum::<f64>()
                / n;
            variance.sqrt() >= GRADIENT_SPREAD_M
        })
        .collect();
    (mean, axes)
}

/// (controller, condition index, path) of every flight `conditions` declares under `data_dir`,
/// those present and those missing ([`ExperimentConditions::condition_flight_files`]).
type DeclaredFlight = (String, usize, PathBuf);

fn declared_flights(
    conditions: &ExperimentConditions,
    data_dir: &Path,
) -> (Vec<DeclaredFlight>, Vec<DeclaredFlight>) {
    let mut present = Vec::new();
    let mut missing = Vec::new();
    for file in conditions.condition_flight_files(data_dir) {
        let index = conditions
            .conditions
            .iter()
            .position(|condition| condition.name == file.condition)
            .expect("a file of a declared condition");
        let flight = (file.controller, index, file.path);
        if file.present {
            present.push(flight);
        } else {
            missing.push(flight);
        }
    }
    (present, missing)
}

/// One flight of the fleet.
pub struct FleetFlight {
    pub controller: String,
    pub condition: String,
    pub label: String,
    pub calm: bool,
    /// The known mean wind speed, for validation only.
    pub mean_wind_m_s: Option<f64>,
    pub problem: Problem,
    /// Where the flight's air velocity is reported (its mean position), m.
    pub reference_m: [f64; 3],
    /// The position axes along which the flight spreads (standard deviation at least
    /// [`GRADIENT_SPREAD_M`]): those its air's gradient can be fitted along.
    pub axes: Vec<usize>,
    /// The logged motor commands and thrust setpoint (for the attitude check).
    pub pwm: data::MotorCommands,
    pub thrust_setpoint: Vec<f64>,
    /// The weak form of the log's own residual force over the mass (`fa / m`), when it has one.
    pub residual_force: Option<Vec<[f64; 3]>>,
}

/// Flights of a conditions file, found and checked, ready to analyse; what the run reads.
#[derive(Clone, Debug)]
pub struct FleetPlan {
    conditions_path: PathBuf,
    conditions: ExperimentConditions,
    /// (controller, condition index, path) of every flight present.
    flights: Vec<(String, usize, PathBuf)>,
}

impl FleetPlan {
    /// Finds every flight the conditions file declares under `data_dir`. Fails if no condition
    /// is declared calm, or if a declared flight is missing (all of them: naming the data
    /// directory).
    pub fn load(conditions_path: &Path, data_dir: &Path) -> Result<Self> {
        let conditions = ExperimentConditions::load(conditions_path)?;
        if !conditions.conditions.iter().any(|c| c.calm) {
            return Err(MismatchError::Config {
                path: conditions_path.to_path_buf(),
                field: "conditions".into(),
                message: "no condition is declared calm (\"calm\": true): the joint analysis calibrates the vehicle on still-air flights".into(),
            });
        }
        let (flights, missing) = declared_flights(&conditions, data_dir);
        if flights.is_empty() {
            return Err(MismatchError::NoFlights {
                data_dir: data_dir.to_path_buf(),
                conditions: conditions_path.to_path_buf(),
                count: missing.len(),
                example: missing.first().map(|(_, _, path)| path.clone()),
            });
        }
        if let Some((controller, index, path)) = missing.first() {
            return Err(MismatchError::MissingFlight {
                conditions: conditions_path.to_path_buf(),
                condition: conditions.conditions[*index].name.clone(),
                controller: controller.clone(),
                path: path.clone(),
                missing: missing.len(),
                declared: missing.len() + flights.len(),
            });
        }
        Ok(Self {
            conditions_path: conditions_path.to_path_buf(),
            conditions,
            flights,
        })
    }

    /// Every file the run reads: the conditions file and every flight present.
    pub fn inputs(&self) -> Vec<(String, PathBuf)> {
        let mut inputs = vec![(
            "the conditions file (--flights)".to_string(),
            self.conditions_path.clone(),
        )];
        for (controller, index, path) in &self.flights {
            inputs.push((
                format!(
                    "the {controller} flight at {}",
                    self.conditions.conditions[*index].name
                ),
                path.clone(),
            ));
        }
        inputs
    }

    /// Reads every flight and prepares its comparison with `model`.
    pub fn read(
        &self,
        model: &NominalModel,
        settings: &CheckedSettings,
    ) -> Result<Vec<FleetFlight>> {
        self.flights
            .iter()
            .map(|(controller, index, path)| {
                let condition = &self.conditions.conditions[*index];
                let log = data::FlightLog::read(path)?;
                let recording = Recording::new(&log, model, 40)?;
                let problem = Problem::new(
                    recording,
                    model.clone(),
                    settings.comparison.test_function,
                    settings.comparison.heldout_fraction,
                )?;
                degenerate::check_noise(&problem).map_err(|degeneracy| {
                    MismatchError::Degenerate {
                        path: path.clone(),
                        degeneracy,
                    }
                })?;
                let residual_force = log.residual_force.as_ref().map(|fa| {
                    let per_mass: Vec<[f64; 3]> =
                        fa.iter().map(|f| f.map(|v| v / model.mass_kg)).collect();
                    problem.weak_form.integrate_rows(&per_mass)
                });
                let (reference_m, axes) = spread(&problem.recording.position);
                Ok(FleetFlight {
                    pwm: log.motor_command.clone(),
                    thrust_setpoint: log.thrust_setpoint.clone(),
                    reference_m,
                    axes,
                    controller: controller.clone(),
                    condition: condition.name.clone(),
                    label: condition.label().to_string(),
                    calm: condition.calm,
                    mean_wind_m_s: condition.mean_wind_m_s,
                    problem,
                    residual_force,
                })
            })
            .collect()
    }

    /// Runs the analysis: the report (its files: [`FleetReport::render`]; its terminal lines:
    /// `report.view().lines()`).
    pub fn run(
        &self,
        model: &NominalModel,
        model_name: &str,
        settings: &CheckedSettings,
    ) -> Result<FleetReport> {
        let flights = self.read(model, settings)?;
        let identification = identify(&flights, settings);
        let attitude = (!model.predicts_torque())
            .then(|| attitude::check(&flights))
            .flatten();
        let report = FleetReport::new(
            attitude,
            &flights,
            &identification,
            model,
            model_name,
            &self.conditions_path.display().to_string(),
            settings.fleet_record(),
        );
        Ok(report)
    }
}

/// A step of the selection: the error with the vehicle before and with the candidate.
#[derive(Clone, Debug, Serialize)]
pub struct SelectionStep {
    /// `calm` (held-out error of the calm flights) or `transfer` (held-out error of each windy
    /// condition with the vehicle fitted without it).
    pub stage: String,
    pub candidate: EffectId,
    pub error_before: f64,
    pub error_with: f64,
    pub accepted: bool,
}

/// Everything [`identify`] finds.
pub struct Identification {
    /// The vehicle fitted on all rows of all flights.
    pub vehicle: Vehicle,
    /// Per flight: the air from the joint fit.
    pub airs: Vec<Air>,
    /// Why the solver stopped in that joint fit (its second, whitened pass).
    pub termination: Termination,
    /// Per flight: the air with the vehicle fitted without its condition (without the flight
    /// itself for calm ones).
    pub validation_airs: Vec<Air>,
    /// Per left-out group: the vehicle of the validation.
    pub validation_vehicles: Vec<(String, Vehicle)>,
    /// Per flight: held-out MSE (sum over x, y, z) of the nominal model and of the vehicle fitted
    /// on the first part of every flight.
    pub heldout: Vec<(f64, f64)>,
    /// Per flight: share of the weak-form `fa / m` mean square the held-out model removes.
    pub residual_force_explained: Vec<Option<f64>>,
    pub selection: Vec<SelectionStep>,
    /// How the winds move with the drag lag across what the calm flights leave open.
    pub lag_sensitivity: Option<LagSensitivity>,
}

fn joint_flights(flights: &[FleetFlight], rows: Rows) -> Vec<JointFlight<'_>> {
    flights
        .iter()
        .map(|f| joint_flight(f, f.calm, rows))
        .collect()
}

fn joint_flight(f: &FleetFlight, calm: bool, rows: Rows) -> JointFlight<'_> {
    JointFlight {
        problem: &f.problem,
        calm,
        rows: match rows {
            Rows::Fit => 0..f.problem.split,
            Rows::Heldout => f.problem.split..f.problem.rows(),
            Rows::All => 0..f.problem.rows(),
        },
        reference_m: f.reference_m,
        axes: &f.axes,
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Rows {
    Fit,
    Heldout,
    All,
}

/// Fits the vehicle (the `fixed` parameters held) and the air of each flight that is not calm, in
/// two passes, the second whitened by the first's residual RMS per channel. Without `fit_vehicle`,
/// only the airs.
fn fit_two_step(
    flights: &[JointFlight],
    start: &Vehicle,
    fixed: &[EffectNumber],
    fit_vehicle: bool,
    iterations: usize,
) -> JointFit {
    let airs: Vec<Air> = flights.iter().map(|f| f.still_air(start)).collect();
    let mut settings = JointSettings {
        fixed: fixed.to_vec(),
        fit_vehicle,
        scale: [1.0; 3],
        iterations,
    };
    let first = joint::fit(flights, start, &airs, &settings);
    settings.scale = joint::residual_rms(flights, &first.vehicle, &first.airs);
    joint::fit(flights, &first.vehicle, &first.airs, &settings)
}

/// Raw held-out MSE (sum over the three channels, mean over rows) of the flights in `indices`,
/// with the airs `airs` (one per flight of `flights`).
fn heldout_error(
    flights: &[FleetFlight],
    indices: &[usize],
    vehicle: &Vehicle,
    airs: &[Air],
) -> f64 {
    let selected: Vec<JointFlight> = indices
        .iter()
        .map(|&i| joint_flight(&flights[i], flights[i].calm, Rows::Heldout))
        .collect();
    let airs: Vec<Air> = indices.iter().map(|&i| airs[i].clone()).collect();
    let sums = joint::scaled_sse_on(&selected, vehicle, &airs, &[1.0; 3]);
    let rows: usize = selected.iter().map(|f| f.rows.len()).sum();
    sums.iter().sum::<f64>() / rows.max(1) as f64
}

/// Still air for every flight.
fn still_airs(flights: &[FleetFlight], vehicle: &Vehicle) -> Vec<Air> {
    flights
        .iter()
        .map(|f| Air::still(f.reference_m, &f.axes, vehicle.gradient))
        .collect()
}

/// Starting values tried for effect `id`: its fit starts (several for the nonlinear effects), or
/// one at its neutral values (`None`).
fn starts(id: EffectId) -> Vec<Option<Vec<f64>>> {
    let starts = id.fit_starts();
    if starts.is_empty() {
        vec![None]
    } else {
        starts.into_iter().map(Some).collect()
    }
}

/// Stage 1: effects added on the calm flights (fit part) while the held-out error falls.
fn calibrate_calm(
    flights: &[FleetFlight],
    settings: &CheckedSettings,
    selection: &mut Vec<SelectionStep>,
) -> Vehicle {
    let calm: Vec<usize> = (0..flights.len()).filter(|&i| flights[i].calm).collect();
    let fit_rows: Vec<JointFlight> = calm
        .iter()
        .map(|&i| joint_flight(&flights[i], true, Rows::Fit))
        .collect();
    let still = still_airs(flights, &Vehicle::default());
    let score = |vehicle: &Vehicle| heldout_error(flights, &calm, vehicle, &still);
    let start = Vehicle::default();
    let error = score(&start);
    forward_select(
        "calm",
        start,
        error,
        settings.fleet.min_step,
        selection,
        |vehicle| {
            let trials: Vec<(EffectId, Option<Vec<f64>>)> = CALM_CANDIDATES
                .into_iter()
                .filter(|id| !vehicle.ids().contains(id))
                .filter(|id| *id != EffectId::DragLag || vehicle.feels_wind())
                .flat_map(|id| starts(id).into_iter().map(move |start| (id, start)))
                .collect();
            let scored: Vec<(EffectId, Vehicle, f64)> = trials
                .par_iter()
                .map(|(id, start)| {
                    let trial = vehicle.with(*id, start.as_deref());
                    let fitted =
                        fit_two_step(&fit_rows, &trial, &[], true, settings.fleet.iterations);
                    let trial_error = score(&fitted.vehicle);
                    (*id, fitted.vehicle, trial_error)
                })
                .collect();
            first_lowest(scored)
        },
    )
}

/// The trial with the lowest error, the first in order among equals.
fn first_lowest(trials: Vec<(EffectId, Vehicle, f64)>) -> Option<(EffectId, Vehicle, f64)> {
    trials.into_iter().fold(None, |best, trial| match best {
        Some(b) if b.2 <= trial.2 => Some(b),
        _ => Some(trial),
    })
}

/// Adds, one at a time, the candidate `best_candidate` proposes (id, vehicle with it, its error)
/// while it lowers the error by at least `min_step`; records every step.
fn forward_select(
    stage: &str,
    mut vehicle: Vehicle,
    mut error: f64,
    min_step: f64,
    selection: &mut Vec<SelectionStep>,
    best_candidate: impl Fn(&Vehicle) -> Option<(EffectId, Vehicle, f64)>,
) -> Vehicle {
    while let Some((id, candidate, candidate_error)) = best_candidate(&vehicle) {
        let accepted = candidate_error <= (1.0 - min_step) * error;
        selection.push(SelectionStep {
            stage: stage.into(),
            candidate: id,
            error_before: error,
            error_with: candidate_error,
            accepted,
        });
        if !accepted {
            break;
        }
        vehicle = candidate;
        error = candidate_error;
    }
    vehicle
}

/// The parameters held at their calm-calibrated values once other flights join.
fn timing_parameters(vehicle: &Vehicle) -> Vec<EffectNumber> {
    vehicle
        .parameters
        .iter()
        .copied()
        .filter(|p| matches!(p.effect, EffectId::Delay | EffectId::DragLag))
        .collect()
}

/// The windy conditions (each a group of flight indices).
fn windy_groups(flights: &[FleetFlight]) -> Vec<(String, Vec<usize>)> {
    let mut groups: Vec<(String, Vec<usize>)> = Vec::new();
    for (i, f) in flights.iter().enumerate() {
        if f.calm {
            continue;
        }
        match groups.iter_mut().find(|g| g.0 == f.condition) {
            Some(g) => g.1.push(i),
            None => groups.push((f.condition.clone(), vec![i])),
        }
    }
    groups
}

/// The vehicle fitted on the flights not in `left_out` (rows `rows`), then only the airs of the
/// left-out flights fitted on the same rows with it held (a left-out calm flight gets a free air);
/// returns the vehicle and every flight's air (the left-out ones from the second fit).
fn leave_out(
    flights: &[FleetFlight],
    left_out: &[usize],
    vehicle: &Vehicle,
    settings: &CheckedSettings,
    rows: Rows,
) -> (Vehicle, Vec<Air>) {
    let fixed = timing_parameters(vehicle);
    let kept_indices: Vec<usize> = (0..flights.len())
        .filter(|i| !left_out.contains(i))
        .collect();
    let kept: Vec<JointFlight> = kept_indices
        .iter()
        .map(|&i| joint_flight(&flights[i], flights[i].calm, rows))
        .collect();
    let fitted = fit_two_step(&kept, vehicle, &fixed, true, settings.fleet.iterations);
    let mut airs = still_airs(flights, &fitted.vehicle);
    for (k, &i) in kept_indices.iter().enumerate() {
        airs[i] = fitted.airs[k].clone();
    }
    let held: Vec<JointFlight> = left_out
        .iter()
        .map(|&i| joint_flight(&flights[i], false, rows))
        .collect();
    let only_airs = fit_two_step(
        &held,
        &fitted.vehicle,
        &[],
        false,
        settings.fleet.iterations,
    );
    for (k, &i) in left_out.iter().enumerate() {
        airs[i] = only_airs.airs[k].clone();
    }
    (fitted.vehicle, airs)
}

/// The transfer error of a vehicle structure: for each windy condition, the held-out error of its
/// flights with the vehicle fitted (fit rows) on the other flights and only their airs fitted.
fn transfer_error(flights: &[FleetFlight], vehicle: &Vehicle, settings: &CheckedSettings) -> f64 {
    let groups = windy_groups(flights);
    let errors: Vec<f64> = groups
        .par_iter()
        .map(|(_, members)| {
            let (fitted, airs) = leave_out(flights, members, vehicle, settings, Rows::Fit);
            heldout_error(flights, members, &fitted, &airs)
        })
        .collect();
    let total: f64 = errors.iter().sum();
    total / groups.len().max(1) as f64
}

/// Stage 2: effects that need airspeed added while the transfer error falls.
fn add_wind_effects(
    flights: &[FleetFlight],
    vehicle: Vehicle,
    settings: &CheckedSettings,
    selection: &mut Vec<SelectionStep>,
) -> Vehicle {
    if windy_groups(flights).len() < 2 {
        return vehicle;
    }
    let error = transfer_error(flights, &vehicle, settings);
    forward_select(
        "transfer",
        vehicle,
        error,
        settings.fleet.min_step,
        selection,
        |vehicle| {
            // Every wind candidate needs a drag for the air to act through.
            let trials: Vec<(EffectId, Option<Vec<f64>>)> = WIND_CANDIDATES
                .into_iter()
                .filter(|id| !vehicle.ids().contains(id) && vehicle.feels_wind())
                .flat_map(|id| starts(id).into_iter().map(move |start| (id, start)))
                .collect();
            let scored: Vec<(EffectId, Vehicle, f64)> = trials
                .par_iter()
                .map(|(id, start)| {
                    let trial = vehicle.with(*id, start.as_deref());
                    let trial_error = transfer_error(flights, &trial, settings);
                    (*id, trial, trial_error)
                })
                .collect();
            first_lowest(scored)
        },
    )
}

/// The whole joint analysis (see the module's documentation).
pub fn identify(flights: &[FleetFlight], settings: &CheckedSettings) -> Identification {
    let mut selection = Vec::new();
    let mut calm_vehicle = calibrate_calm(flights, settings, &mut selection);
    // The lag is held from here on: at its calm held-out minimum, not its fit-part optimum.
    let lag_profile = LagProfile::measure(flights, &calm_vehicle, settings);
    if let Some(profile) = &lag_profile {
        calm_vehicle =
            LagProfile::vehicle_at(flights, &calm_vehicle, profile.best_lag_s(), settings);
    }
    let structure = add_wind_effects(flights, calm_vehicle, settings, &mut selection);
    let fixed = timing_parameters(&structure);
    // Held-out check: fitted on the first part of every flight.
    let fit_part = joint_flights(flights, Rows::Fit);
    let on_fit_part = fit_two_step(
        &fit_part,
        &structure,
        &fixed,
        true,
        settings.fleet.iterations,
    );
    let nominal_airs = still_airs(flights, &Vehicle::default());
    let heldout: Vec<(f64, f64)> = (0..flights.len())
        .map(|i| {
            (
                heldout_error(flights, &[i], &Vehicle::default(), &nominal_airs),
                heldout_error(flights, &[i], &on_fit_part.vehicle, &on_fit_part.airs),
            )
        })
        .collect();
    let residual_force_explained = flights
        .iter()
        .enumerate()
        .map(|(i, f)| residual_force_share(f, &on_fit_part.vehicle, &on_fit_part.airs[i]))
        .collect();
    // The airs: all rows of all flights.
    let all_rows = joint_flights(flights, Rows::All);
    let full = fit_two_step(
        &all_rows,
        &on_fit_part.vehicle,
        &fixed,
        true,
        settings.fleet.iterations,
    );
    // Left out in turn: each windy condition, then each calm flight that has calm siblings.
    let mut groups = windy_groups(flights);
    groups.extend(
        (0..flights.len())
            .filter(|&i| flights[i].calm)
            .filter(|&i| flights.iter().enumerate().any(|(j, f)| j != i && f.calm))
            .map(|i| {
                let f = &flights[i];
                (format!("{} {}", f.controller, f.condition), vec![i])
            }),
    );
    let left_out: Vec<(Vehicle, Vec<Air>)> = groups
        .par_iter()
        .map(|(_, members)| leave_out(flights, members, &full.vehicle, settings, Rows::All))
        .collect();
    let mut validation_airs = still_airs(flights, &full.vehicle);
    let mut validation_vehicles = Vec::new();
    for ((name, members), (vehicle, airs)) in groups.into_iter().zip(left_out) {
        for &i in &members {
            validation_airs[i] = airs[i].clone();
        }
        validation_vehicles.push((name, vehicle));
    }
    let lag_sensitivity = lag_profile
        .as_ref()
        .and_then(|p| p.sensitivity(flights, &full.vehicle, settings));
    Identification {
        lag_sensitivity,
        vehicle: full.vehicle,
        airs: full.airs,
        termination: full.termination,
        validation_airs,
        validation_vehicles,
        heldout,
        residual_force_explained,
        selection,
    }
}

/// The share of the weak-form `fa / m` mean square (held-out rows) that the model's residual no
/// longer has: `1 − Σ r² / Σ fa²`.
fn residual_force_share(flight: &FleetFlight, vehicle: &Vehicle, air: &Air) -> Option<f64> {
    let fa = flight.residual_force.as_ref()?;
    let rows = flight.problem.split..flight.problem.rows();
    let air = (!flight.calm).then_some(air);
    let residual = flight.problem.residual(&vehicle.effects(air));
    let model: f64 = residual[rows.clone()]
        .iter()
        .map(|r| r[..3].iter().map(|v| v * v).sum::<f64>())
        .sum();
    let total: f64 = fa[rows]
        .iter()
        .map(|r| r.iter().map(|v| v * v).sum::<f64>())
        .sum();
    (total > 0.0).then(|| 1.0 - model / total)
}
