//! What the joint analysis writes: the vehicle, every flight's air velocity (joint fit and
//! validation) against the known wind speeds, the targets, held-out errors; JSON, Markdown, SVG.

use std::fmt::Write as _;
use std::path::PathBuf;

use physics::{EffectId, EffectParameters, Effects, NominalModel};
use plotters::prelude::*;
use serde::Serialize;

use super::{
    Air, AttitudeCheck, FleetFlight, FleetSettings, Identification, ScaleReport, SelectionStep,
};
use crate::describe::describe;
use crate::error::{MismatchError, Result, io_error};

/// One flight's air velocity as estimated.
#[derive(Clone, Debug, Serialize)]
pub struct FlightWind {
    pub condition: String,
    pub controller: String,
    /// The known mean wind speed (validation only; never a fit input).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fan_speed_m_s: Option<f64>,
    /// `fit`: from the joint fit of all flights; `validation`: with the vehicle fitted without this
    /// flight's condition (without the flight itself for a calm flight).
    pub role: String,
    pub calm: bool,
    /// The air velocity at the flight's mean position, m/s.
    pub w_air: [f64; 3],
    /// How it changes along the position axes the flight spreads over (1/s; rows: component of
    /// the air velocity, columns: position coordinate), when the air may vary in space.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gradient_per_m: Option<[[f64; 3]; 3]>,
    /// `√(w_x² + w_y²)`, m/s (the fan blows horizontally; the vertical part is weakly identified).
    pub horizontal_speed_m_s: f64,
    /// Direction the air moves towards, degrees from +x towards +y.
    pub azimuth_deg: f64,
    /// Horizontal speed minus the known speed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub speed_error_m_s: Option<f64>,
}

/// The targets of the real-flight test and whether they hold, per role.
#[derive(Clone, Debug, Serialize)]
pub struct Targets {
    pub role: String,
    /// Windy flights within ±1.5 m/s (and ±1.0) of their known speed, of how many.
    pub within_1_5: usize,
    pub within_1_0: usize,
    pub windy: usize,
    /// The largest speed error of a windy flight, m/s.
    pub max_speed_error_m_s: f64,
    /// The largest horizontal speed of a calm flight, m/s (target below 0.8).
    pub max_calm_speed_m_s: f64,
    /// The common wind axis (mean direction of the windy flights) and the largest deviation from
    /// it, degrees (target within ±5).
    pub axis_azimuth_deg: f64,
    pub max_direction_deviation_deg: f64,
}

/// Held-out errors of one flight.
#[derive(Clone, Debug, Serialize)]
pub struct FlightHeldout {
    pub condition: String,
    pub controller: String,
    /// Weak-form MSE summed over x, y, z, on the last part of the flight, (m/s²)².
    pub mse_nominal: f64,
    pub mse_model: f64,
    /// Share of the log's residual force's (`fa / m`) mean square the model removes there.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub residual_force_explained: Option<f64>,
}

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
    pub settings: FleetSettings,
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
        settings: FleetSettings,
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
                        description: describe(id, &effects),
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
                .map(|s| ScaleReport::new(flights, s)),
            validation_vehicles: found
                .validation_vehicles
                .iter()
                .map(|(name, v)| (name.clone(), v.effects(None)))
                .collect(),
            settings,
            notes,
        }
    }

    /// One line per flight and the targets, for the terminal.
    pub fn lines(&self) -> Vec<String> {
        let mut lines: Vec<String> = self
            .flights
            .iter()
            .map(|f| {
                format!(
                    "{:<10} {:<10} {:<10} w_air [{:6.2}, {:6.2}, {:5.2}] m/s, horizontal {:5.2}{}",
                    f.role,
                    f.condition,
                    f.controller,
                    f.w_air[0],
                    f.w_air[1],
                    f.w_air[2],
                    f.horizontal_speed_m_s,
                    f.fan_speed_m_s
                        .map(|s| format!(" (known {s})"))
                        .unwrap_or_default()
                )
            })
            .collect();
        if let Some(scale) = &self.scale {
            let covered = scale
                .flights
                .iter()
                .filter(|f| f.covers_known() == Some(true))
                .count();
            lines.push(format!(
                "scale: the calm flights leave the drag lag open from {:.1} to {:.1} s; {covered} of {} windy flights' known speeds lie between their speeds at the two ends",
                scale.lag_band_s.0,
                scale.lag_band_s.1,
                scale.flights.len()
            ));
        }
        for t in &self.targets {
            lines.push(format!(
                "{}: {} of {} windy flights within ±1.5 m/s (max error {:.2}), calm at most {:.2} m/s, directions within ±{:.1}° of {:.1}°",
                t.role, t.within_1_5, t.windy, t.max_speed_error_m_s, t.max_calm_speed_m_s, t.max_direction_deviation_deg, t.axis_azimuth_deg
            ));
        }
        lines
    }

    /// The report in Markdown.
    pub fn markdown(&self, figure: &str) -> String {
        let mut md = String::new();
        let _ = writeln!(
            md,
            "# One vehicle, many flights: the missing physics and the wind\n"
        );
        let _ = writeln!(
            md,
            "Generated by `learn mismatch --flights {} --model {}`: every flight of every condition, analysed together in the weak form (translational channels; the model's thrust comes from `T_sp`). One vehicle is identified for all flights and one constant air velocity per flight that is not declared calm. Known wind speeds are used only to check the estimates.\n",
            self.conditions, self.model
        );
        let _ = writeln!(md, "## The vehicle\n");
        for e in &self.vehicle.effects {
            let _ = writeln!(
                md,
                "- **{}** `{}` — {}",
                e.id,
                serde_json::to_string(&e.parameters)
                    .expect("parameters serialise")
                    .replace(',', ", "),
                e.description
            );
        }
        let _ = writeln!(
            md,
            "\nHow the effects were chosen (an effect joins when it lowers the error by at least {:.0}%):\n",
            100.0 * self.settings.min_step
        );
        let _ = writeln!(
            md,
            "| stage | candidate | error before | with it | joined |\n|---|---|---|---|---|"
        );
        for s in &self.selection {
            let _ = writeln!(
                md,
                "| {} | {} | {:.4} | {:.4} | {} |",
                s.stage,
                s.candidate,
                s.error_before,
                s.error_with,
                if s.accepted { "yes" } else { "no" }
            );
        }
        let _ = writeln!(
            md,
            "\n`calm`: held-out weak-form MSE (sum over x, y, z, (m/s²)²) of the calm flights, fitted on their first {:.0}%. `transfer`: for each windy condition, its flights' held-out MSE with the vehicle fitted on the other conditions and only their air velocities fitted, averaged over the conditions.\n",
            100.0 * (1.0 - self.settings.heldout_fraction)
        );
        self.targets_markdown(&mut md);
        self.flights_markdown(&mut md);
        let _ = writeln!(md, "\n![estimated against known wind speed]({figure})\n");
        if let Some(scale) = &self.scale {
            scale.markdown(self.settings.min_step, &mut md);
        }
        self.heldout_markdown(&mut md);
        self.attitude_markdown(&mut md);
        let _ = writeln!(md, "\n## Notes\n");
        for n in &self.notes {
            let _ = writeln!(md, "- {n}");
        }
        md
    }

    fn targets_markdown(&self, md: &mut String) {
        let _ = writeln!(md, "## Against the known wind speeds\n");
        let _ = writeln!(
            md,
            "| role | windy flights within ±1.5 m/s | within ±1.0 m/s | largest error (m/s) | calm flights' largest speed (m/s; target < 0.8) | directions: axis, largest deviation (target ±5°) |\n|---|---|---|---|---|---|"
        );
        for t in &self.targets {
            let _ = writeln!(
                md,
                "| {} | {} of {} | {} of {} | {:.2} | {:.2} | {:.1}°, ±{:.1}° |",
                t.role,
                t.within_1_5,
                t.windy,
                t.within_1_0,
                t.windy,
                t.max_speed_error_m_s,
                t.max_calm_speed_m_s,
                t.axis_azimuth_deg,
                t.max_direction_deviation_deg
            );
        }
    }

    fn flights_markdown(&self, md: &mut String) {
        let _ = writeln!(md, "\n## Every flight\n");
        let _ = writeln!(
            md,
            "| condition | controller | known speed (m/s) | joint fit w_air (m/s) | horizontal speed | error | validation w_air (m/s) | horizontal speed | error |\n|---|---|---|---|---|---|---|---|---|"
        );
        let fits = self.flights.iter().filter(|f| f.role == "fit");
        for fit in fits {
            let validation = self.flights.iter().find(|v| {
                v.role == "validation"
                    && v.condition == fit.condition
                    && v.controller == fit.controller
            });
            let cell = |f: &FlightWind| {
                (
                    format!("[{:.2}, {:.2}, {:.2}]", f.w_air[0], f.w_air[1], f.w_air[2]),
                    format!("{:.2}", f.horizontal_speed_m_s),
                    f.speed_error_m_s
                        .map(|e| format!("{e:+.2}"))
                        .unwrap_or_else(|| "–".into()),
                )
            };
            let (a, b, c) = cell(fit);
            let (d, e, g) = validation
                .map(cell)
                .unwrap_or(("–".into(), "–".into(), "–".into()));
            let _ = writeln!(
                md,
                "| {} | {} | {} | {a}{} | {b} | {c} | {d} | {e} | {g} |",
                fit.condition,
                fit.controller,
                fit.fan_speed_m_s
                    .map(|s| format!("{s}"))
                    .unwrap_or_else(|| "–".into()),
                if fit.calm { " (calm)" } else { "" }
            );
        }
    }

    fn attitude_markdown(&self, md: &mut String) {
        let Some(a) = &self.attitude else { return };
        let _ = writeln!(md, "\n## The angular channels\n");
        let _ = writeln!(
            md,
            "The model's thrust comes from `T_sp`, so it predicts no torques. What the logs allow instead: the motor commands (`pwm`) run from {:.0} to {:.0}, not a 1000–2000 signal with a 1000 offset; their mean follows {:.1} + {:.1} · T_sp, {} rows ({:.0} ms) behind it, within {:.1} (RMS).\n",
            a.pwm_range[0],
            a.pwm_range[1],
            a.mean_pwm_offset,
            a.mean_pwm_slope,
            a.mean_pwm_lag_rows,
            1000.0 * a.mean_pwm_lag_s,
            a.mean_pwm_residual_rms
        );
        let axes = |v: &[f64; 3]| {
            format!(
                "{:.0}% / {:.0}% / {:.0}%",
                100.0 * v[0],
                100.0 * v[1],
                100.0 * v[2]
            )
        };
        let enough = a.explained_calm_heldout.iter().all(|e| *e >= 0.5);
        let _ = writeln!(
            md,
            "A torque map `ω̇ = c + B · pwm` (B 3 × 4, the commands {} rows late), fitted on the calm flights' first part in the weak form, explains {} (roll / pitch / yaw) of the body's angular acceleration on their held-out part{}. {}",
            a.torque_map_lag_rows,
            axes(&a.explained_calm_heldout),
            a.explained_windy
                .map(|w| format!(", and {} on the windy flights", axes(&w)))
                .unwrap_or_default(),
            if enough {
                "A nominal torque model can be built on it (give the model a mixer) before any attitude effect is looked for."
            } else {
                "That is too little for a nominal torque model: the inertia ratios cannot be identified from these logs, and no attitude effect is named in wind."
            }
        );
    }

    fn heldout_markdown(&self, md: &mut String) {
        let _ = writeln!(md, "## Held out\n");
        let _ = writeln!(
            md,
            "Weak-form MSE (sum over x, y, z, (m/s²)²) on the last {:.0}% of each flight, with the vehicle and air velocities fitted on the first part; and the share of the log's own residual force (`fa / m`, the nominal model's residual as the dataset computes it) that the model explains there.\n",
            100.0 * self.settings.heldout_fraction
        );
        let _ = writeln!(
            md,
            "| condition | flights | MSE nominal | MSE with the vehicle's effects | reduction | fa explained |\n|---|---|---|---|---|---|"
        );
        let mut conditions: Vec<&str> = Vec::new();
        for h in &self.heldout {
            if !conditions.contains(&h.condition.as_str()) {
                conditions.push(&h.condition);
            }
        }
        for condition in conditions {
            let rows: Vec<&FlightHeldout> = self
                .heldout
                .iter()
                .filter(|h| h.condition == condition)
                .collect();
            let n = rows.len() as f64;
            let nominal = rows.iter().map(|h| h.mse_nominal).sum::<f64>() / n;
            let model = rows.iter().map(|h| h.mse_model).sum::<f64>() / n;
            let explained: Vec<f64> = rows
                .iter()
                .filter_map(|h| h.residual_force_explained)
                .collect();
            let _ = writeln!(
                md,
                "| {condition} | {} | {nominal:.4} | {model:.4} | {:.1}% | {} |",
                rows.len(),
                100.0 * (1.0 - model / nominal.max(1e-300)),
                if explained.is_empty() {
                    "–".to_string()
                } else {
                    format!(
                        "{:.1}%",
                        100.0 * explained.iter().sum::<f64>() / explained.len() as f64
                    )
                }
            );
        }
    }
}

/// Writes the JSON, Markdown and SVG (paths in that order); existing files replaced only with
/// `force` (checked before any work by the caller too).
pub fn write(report: &FleetReport, outputs: &[PathBuf], force: bool) -> Result<()> {
    let [json, markdown, svg] = outputs else {
        unreachable!("three outputs");
    };
    for path in outputs {
        if !force && path.exists() {
            return Err(MismatchError::Exists { path: path.clone() });
        }
    }
    if let Some(parent) = json.parent() {
        std::fs::create_dir_all(parent).map_err(io_error(parent))?;
    }
    let text = serde_json::to_string_pretty(report).expect("the report serialises");
    std::fs::write(json, text + "\n").map_err(io_error(json))?;
    write_figure(report, svg)?;
    let figure = svg
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    std::fs::write(markdown, report.markdown(&figure)).map_err(io_error(markdown))?;
    Ok(())
}

/// Estimated horizontal wind speed against the known one, both roles.
fn write_figure(report: &FleetReport, path: &PathBuf) -> Result<()> {
    let plot_error = |e: &dyn std::fmt::Display| MismatchError::Plot {
        path: path.clone(),
        message: e.to_string(),
    };
    let points: Vec<(&FlightWind, f64)> = report
        .flights
        .iter()
        .filter_map(|f| f.fan_speed_m_s.map(|s| (f, s)))
        .collect();
    let top = points
        .iter()
        .map(|(f, s)| f.horizontal_speed_m_s.max(*s))
        .fold(1.0, f64::max)
        .max(
            report
                .scale
                .iter()
                .flat_map(|s| s.flights.iter().map(|f| f.range().1))
                .fold(0.0, f64::max),
        )
        * 1.1;
    if !top.is_finite() {
        return Err(plot_error(&"a wind speed is not finite"));
    }
    let root = SVGBackend::new(path, (720, 620)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| plot_error(&e))?;
    let mut chart = ChartBuilder::on(&root)
        .margin(16)
        .caption(
            "Estimated against known wind speed (horizontal), every flight",
            ("sans-serif", 17),
        )
        .x_label_area_size(40)
        .y_label_area_size(50)
        .build_cartesian_2d(-0.5..top, -0.5..top)
        .map_err(|e| plot_error(&e))?;
    chart
        .configure_mesh()
        .x_desc("known mean wind speed (m/s)")
        .y_desc("estimated (m/s)")
        .draw()
        .map_err(|e| plot_error(&e))?;
    let band = RGBColor(225, 235, 245);
    chart
        .draw_series(std::iter::once(Polygon::new(
            vec![(0.0, -1.5), (top, top - 1.5), (top, top + 1.5), (0.0, 1.5)],
            band.filled(),
        )))
        .map_err(|e| plot_error(&e))?
        .label("±1.5 m/s")
        .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 14, y + 5)], band.filled()));
    chart
        .draw_series(LineSeries::new(
            vec![(0.0, 0.0), (top, top)],
            BLACK.stroke_width(1),
        ))
        .map_err(|e| plot_error(&e))?;
    if let Some(scale) = &report.scale {
        let (low, high) = scale.lag_band_s;
        let grey = RGBColor(120, 120, 120);
        chart
            .draw_series(scale.flights.iter().filter_map(|f| {
                let (a, b) = f.range();
                f.fan_speed_m_s.map(|s| {
                    PathElement::new(vec![(s - 0.12, a), (s - 0.12, b)], grey.stroke_width(2))
                })
            }))
            .map_err(|e| plot_error(&e))?
            .label(format!(
                "joint fit with the drag lag from {low:.1} to {high:.1} s"
            ))
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y - 6), (x, y + 6)], grey.stroke_width(2))
            });
    }
    for (role, color, dx) in [("fit", BLUE, -0.12), ("validation", RED, 0.12)] {
        chart
            .draw_series(
                points
                    .iter()
                    .filter(|(f, _)| f.role == role)
                    .map(|(f, s)| Circle::new((s + dx, f.horizontal_speed_m_s), 4, color.filled())),
            )
            .map_err(|e| plot_error(&e))?
            .label(if role == "fit" {
                "joint fit of all flights"
            } else {
                "vehicle identified without the flight's condition"
            })
            .legend(move |(x, y)| Circle::new((x + 7, y), 4, color.filled()));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .draw()
        .map_err(|e| plot_error(&e))?;
    root.present().map_err(|e| plot_error(&e))?;
    Ok(())
}
