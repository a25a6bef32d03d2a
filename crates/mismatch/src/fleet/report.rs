//! What the joint analysis writes: the vehicle, every flight's air velocity (joint fit and
//! validation) against the known wind speeds, the targets, held-out errors; JSON, Markdown, SVG.
//! The Markdown, the terminal lines and the figure are rendered by the `report` crate
//! ([`report::mismatch::fleet`]) from the view [`FleetReport::view`] fills.

use std::path::Path;

use physics::{EffectId, EffectParameters, Effects, NominalModel};
use report::mismatch::fleet::{
    AttitudeCheck, FleetView, FlightHeldout, FlightWind, ScaleReport, SelectionLine, Targets,
    VehicleEffectLine,
};
use serde::Serialize;

use super::scale_report::scale_report;
use super::{Air, FleetFlight, Identification, SelectionStep};
use crate::error::Result;
use crate::explain::describe::describe;
use crate::settings::FleetRecord;

/// One vehicle effect: id, parameters, plain words.
#[derive(Clone, Debug, Serialize)]
pub struct VehicleEffect {
    pub id: EffectId,
    pub parameters: VehicleParameters,
    pub description: String,
}

/// A vehicle effect's parameters: fitted for the vehicle, or kept with each flight.
#[derive(Clone, Copy, Debug, Serialize)]
#[serde(untagged)]
pub enum VehicleParameters {
    Fitted(EffectParameters),
    /// Where in the report the per-flight values are (`flights[].gradient_per_m`).
    PerFlight {
        per_flight: &'static str,
    },
}

/// Everything written to `<model stem>.json`.
#[derive(Clone, Debug, Serialize)]
pub struct FleetReport {
    pub model: String,
    pub conditions: String,
    pub vehicle: VehicleReport,
    pub flights: Vec<FlightWind>,
    pub targets: Vec<Targets>,
    pub heldout: Vec<FlightHeldout>,
    pub selection: Vec<SelectionStep>,
    /// The angular channels, when the model predicts no torques.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub attitude: Option<AttitudeCheck>,
    /// How the winds move with the drag lag across what the calm flights leave open.
    pub scale: Option<ScaleReport>,
    /// Per validation group: the vehicle fitted without it.
    pub validation_vehicles: Vec<(String, Effects)>,
    pub settings: FleetRecord,
    /// What the reader should know about how the numbers were made.
    pub notes: Vec<String>,
}

/// The identified vehicle: the nominal model and the effects added to it.
#[derive(Clone, Debug, Serialize)]
pub struct VehicleReport {
    pub mass_kg: f64,
    pub gravity_m_s2: f64,
    pub effects: Vec<VehicleEffect>,
}

/// The air's spatial variation: a property of each windy flight's air, summarised.
fn gradient_effect(airs: &[Air]) -> VehicleEffect {
    let largest = airs
        .iter()
        .flat_map(|a| a.values.iter().skip(3))
        .fold(0.0f64, |m, v| m.max(v.abs()));
    VehicleEffect {
        id: EffectId::WindGradient,
        parameters: VehicleParameters::PerFlight {
            per_flight: "flights[].gradient_per_m",
        },
        description: format!(
            "The air is not uniform where the vehicle flies: each windy flight's air velocity varies along the axes the flight spans, by up to {largest:.2} m/s per metre (the per-flight gradients are with the flights)."
        ),
    }
}

fn flight_wind(flight: &FleetFlight, role: &str, air: &Air) -> FlightWind {
    let w = air.velocity();
    let horizontal = w[0].hypot(w[1]);
    FlightWind {
        condition: flight.condition.clone(),
        controller: flight.controller.clone(),
        fan_speed_m_s: flight.mean_wind_m_s,
        role: role.to_string(),
        calm: flight.calm,
        w_air: w,
        gradient_per_m: (!air.axes.is_empty()).then(|| {
            let mut g = [[0.0; 3]; 3];
            for (k, &axis) in air.axes.iter().enumerate() {
                for c in 0..3 {
                    g[c][axis] = air.values[3 + 3 * k + c];
                }
            }
            g
        }),
        horizontal_speed_m_s: horizontal,
        azimuth_deg: w[1].atan2(w[0]).to_degrees(),
        speed_error_m_s: flight.mean_wind_m_s.map(|s| horizontal - s),
    }
}

fn targets(flights: &[FlightWind], role: &str) -> Targets {
    let of_role: Vec<&FlightWind> = flights.iter().filter(|f| f.role == role).collect();
    let windy: Vec<&&FlightWind> = of_role
        .iter()
        .filter(|f| !f.calm && f.fan_speed_m_s.is_some())
        .collect();
    let errors: Vec<f64> = windy
        .iter()
        .filter_map(|f| f.speed_error_m_s.map(f64::abs))
        .collect();
    let (sx, sy) = windy.iter().fold((0.0, 0.0), |(x, y), f| {
        let h = f.horizontal_speed_m_s.max(1e-12);
        (x + f.w_air[0] / h, y + f.w_air[1] / h)
    });
    let axis = sy.atan2(sx).to_degrees();
    let deviation = |azimuth: f64| {
        let d = (azimuth - axis + 540.0).rem_euclid(360.0) - 180.0;
        d.abs()
    };
    Targets {
        role: role.to_string(),
        within_1_5: errors.iter().filter(|e| **e <= 1.5).count(),
        within_1_0: errors.iter().filter(|e| **e <= 1.0).count(),
        windy: windy.len(),
        max_speed_error_m_s: errors.iter().fold(0.0, |a, b| a.max(*b)),
        max_calm_speed_m_s: of_role
            .iter()
            .filter(|f| f.calm)
            .map(|f| f.horizontal_speed_m_s)
            .fold(0.0, f64::max),
        axis_azimuth_deg: axis,
        max_direction_deviation_deg: windy
            .iter()
            .map(|f| deviation(f.azimuth_deg))
            .fold(0.0, f64::max),
    }
}

impl FleetReport {
    pub fn new(
        attitude: Option<AttitudeCheck>,
        flights: &[FleetFlight],
        found: &Identification,
        model: &NominalModel,
        model_name: &str,
        conditions: &str,
        settings: FleetRecord,
    ) -> Self {
        let effects = found.vehicle.effects(None);
        let vehicle = VehicleReport {
            mass_kg: model.mass_kg,
            gravity_m_s2: model.gravity_m_s2,
            effects: found
                .vehicle
                .ids()
                .into_iter()
                .map(|id| {
                    if id == EffectId::WindGradient {
                        return gradient_effect(&found.airs);
                    }
                    VehicleEffect {
                        id,
                        parameters: VehicleParameters::Fitted(
                            effects.parameters(id).expect("an effect of the vehicle"),
                        ),
                        description: describe(id, &effects, model.gravity_m_s2),
                    }
                })
                .collect(),
        };
        let mut winds: Vec<FlightWind> = flights
            .iter()
            .zip(&found.airs)
            .map(|(f, a)| flight_wind(f, "fit", a))
            .collect();
        winds.extend(
            flights
                .iter()
                .zip(&found.validation_airs)
                .map(|(f, a)| flight_wind(f, "validation", a)),
        );
        let heldout = flights
            .iter()
            .zip(&found.heldout)
            .zip(&found.residual_force_explained)
            .map(|((f, (nominal, model)), explained)| FlightHeldout {
                condition: f.condition.clone(),
                controller: f.controller.clone(),
                mse_nominal: *nominal,
                mse_model: *model,
                residual_force_explained: *explained,
            })
            .collect();
        let notes = vec![
            "Known wind speeds (mean_wind_m_s of the conditions file) are compared with the estimates only; no fit or choice uses them.".to_string(),
            "The calm flights' air velocity is zero by declaration in the fit role; in the validation role each calm flight's air velocity is fitted with the vehicle identified from the other flights.".to_string(),
            "The drag lag is the minimum of the calm flights' held-out error over a grid of lags, the delay is fitted on the calm flights' first part with that lag, and both are then held (all calm flights are used, including the one a calm validation leaves out); the effects are chosen once, by the transfer error over all windy conditions; each validation refits the vehicle's values without the left-out flights.".to_string(),
            "Speeds are horizontal (√(w_x² + w_y²)): a fan blows horizontally, and the vertical component is weakly identified.".to_string(),
        ];
        let targets = vec![targets(&winds, "fit"), targets(&winds, "validation")];
        Self {
            model: model_name.to_string(),
            conditions: conditions.to_string(),
            vehicle,
            flights: winds,
            targets,
            heldout,
            selection: found.selection.clone(),
            attitude,
            scale: found
                .lag_sensitivity
                .as_ref()
                .map(|s| scale_report(flights, s)),
            validation_vehicles: found
                .validation_vehicles
                .iter()
                .map(|(name, v)| (name.clone(), v.effects(None)))
                .collect(),
            settings,
            notes,
        }
    }

    /// What the Markdown, the terminal lines and the figure say: the plain parts borrowed, the
    /// vehicle's effects and the selection by their names.
    pub fn view(&self) -> FleetView<'_> {
        FleetView {
            model: &self.model,
            conditions: &self.conditions,
            vehicle: self
                .vehicle
                .effects
                .iter()
                .map(|e| VehicleEffectLine {
                    id: e.id.name(),
                    parameters: serde_json::to_string(&e.parameters).expect("parameters serialise"),
                    description: &e.description,
                })
                .collect(),
            selection: self
                .selection
                .iter()
                .map(|s| SelectionLine {
                    stage: &s.stage,
                    candidate: s.candidate.name(),
                    error_before: s.error_before,
                    error_with: s.error_with,
                    accepted: s.accepted,
                })
                .collect(),
            min_step: self.settings.fleet.min_step,
            heldout_fraction: self.settings.comparison.heldout_fraction,
            flights: &self.flights,
            targets: &self.targets,
            heldout: &self.heldout,
            attitude: self.attitude.as_ref(),
            scale: self.scale.as_ref(),
            notes: &self.notes,
        }
    }
}

/// The names of the joint analysis's files for a nominal model whose file is `<stem>.json`:
/// `<stem>.json`, `<stem>.md` and `<stem>.svg`, in the order of [`FleetReport::render`].
pub fn file_names(stem: &str) -> [String; 3] {
    ["json", "md", "svg"].map(|ext| format!("{stem}.{ext}"))
}

impl FleetReport {
    /// The contents of the files [`file_names`] names for `stem`, to be written in `dir` (which
    /// the figure's errors name): the JSON, the Markdown (linking the figure) and the SVG.
    pub fn render(&self, dir: &Path, stem: &str) -> Result<[String; 3]> {
        let [_, _, figure] = file_names(stem);
        let text = serde_json::to_string_pretty(self).expect("the report serialises");
        let view = self.view();
        let svg = view.svg(&dir.join(&figure))?;
        Ok([text + "\n", view.markdown(&figure), svg])
    }
}
