//! Several flights of one vehicle analysed together (`<model stem>.md`, the terminal lines and the
//! figure [`FleetView::svg`]): the plain parts of the joint analysis's results (every flight's air
//! velocity, the targets, the held-out errors, the attitude check, the winds' scale), which its JSON
//! records as they are, and [`FleetView`], what the Markdown says of the rest (the vehicle and the
//! selection) with names and numbers in place of the analysis's types.

use std::fmt::Write as _;

use serde::{Deserialize, Serialize};

pub use super::scale::{FlightSpeedRange, ScaleReport};

/// One flight's air velocity as estimated.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
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
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
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
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
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

/// What the attitude check finds (the angular channels, when the model predicts no torques).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct AttitudeCheck {
    /// The smallest and largest motor command logged.
    pub pwm_range: [f64; 2],
    /// The mean of the four motor commands as `offset + slope · T_sp`, with its residual RMS, at
    /// the lag (rows behind `T_sp`) that fits best.
    pub mean_pwm_offset: f64,
    pub mean_pwm_slope: f64,
    pub mean_pwm_lag_rows: usize,
    pub mean_pwm_lag_s: f64,
    pub mean_pwm_residual_rms: f64,
    /// The lag (rows) of the torque map `ω̇ = c + B · pwm` chosen on the calm flights' held-out
    /// part.
    pub torque_map_lag_rows: usize,
    /// Share of the weak-form `ω̇` variance (per body axis) the map explains: on the calm flights'
    /// held-out part, and on the windy flights (not fitted on them at all).
    pub explained_calm_heldout: [f64; 3],
    pub explained_windy: Option<[f64; 3]>,
}

/// One effect of the identified vehicle.
#[derive(Clone, Debug, PartialEq)]
pub struct VehicleEffectLine<'a> {
    /// The effect's id as the outputs spell it (`thrust_tilt`).
    pub id: &'a str,
    /// Its parameters as compact JSON (`{"d":[0.39,0.7]}`), as the report's JSON records them.
    pub parameters: String,
    pub description: &'a str,
}

/// A step of the selection of the vehicle's effects.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SelectionLine<'a> {
    /// `calm` or `transfer`.
    pub stage: &'a str,
    /// The candidate effect's id.
    pub candidate: &'a str,
    pub error_before: f64,
    pub error_with: f64,
    pub accepted: bool,
}

/// What the joint analysis's Markdown, terminal lines and figure say.
#[derive(Clone, Debug, PartialEq)]
pub struct FleetView<'a> {
    /// The model file and the conditions file, as given.
    pub model: &'a str,
    pub conditions: &'a str,
    pub vehicle: Vec<VehicleEffectLine<'a>>,
    pub selection: Vec<SelectionLine<'a>>,
    /// An effect joins when it lowers the error by at least this fraction.
    pub min_step: f64,
    /// Fraction of each flight held out, at its end.
    pub heldout_fraction: f64,
    /// Every flight in both roles: `fit` first, then `validation`.
    pub flights: &'a [FlightWind],
    pub targets: &'a [Targets],
    pub heldout: &'a [FlightHeldout],
    pub attitude: Option<&'a AttitudeCheck>,
    pub scale: Option<&'a ScaleReport>,
    pub notes: &'a [String],
}

impl FleetView<'_> {
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
        if let Some(scale) = self.scale {
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
        for t in self.targets {
            lines.push(format!(
                "{}: {} of {} windy flights within ±1.5 m/s (max error {:.2}), calm at most {:.2} m/s, directions within ±{:.1}° of {:.1}°",
                t.role, t.within_1_5, t.windy, t.max_speed_error_m_s, t.max_calm_speed_m_s, t.max_direction_deviation_deg, t.axis_azimuth_deg
            ));
        }
        lines
    }

    /// The report in Markdown; `figure` is the figure's file name, linked from the text.
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
        self.vehicle_markdown(&mut md);
        self.targets_markdown(&mut md);
        self.flights_markdown(&mut md);
        let _ = writeln!(md, "\n![estimated against known wind speed]({figure})\n");
        if let Some(scale) = self.scale {
            scale.markdown(self.min_step, &mut md);
        }
        self.heldout_markdown(&mut md);
        self.attitude_markdown(&mut md);
        let _ = writeln!(md, "\n## Notes\n");
        for n in self.notes {
            let _ = writeln!(md, "- {n}");
        }
        md
    }

    /// The vehicle's effects and how they were chosen.
    fn vehicle_markdown(&self, md: &mut String) {
        let _ = writeln!(md, "## The vehicle\n");
        for e in &self.vehicle {
            let _ = writeln!(
                md,
                "- **{}** `{}` — {}",
                e.id,
                e.parameters.replace(',', ", "),
                e.description
            );
        }
        let _ = writeln!(
            md,
            "\nHow the effects were chosen (an effect joins when it lowers the error by at least {:.0}%):\n",
            100.0 * self.min_step
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
            100.0 * (1.0 - self.heldout_fraction)
        );
    }

    fn targets_markdown(&self, md: &mut String) {
        let _ = writeln!(md, "## Against the known wind speeds\n");
        let _ = writeln!(
            md,
            "| role | windy flights within ±1.5 m/s | within ±1.0 m/s | largest error (m/s) | calm flights' largest speed (m/s; target < 0.8) | directions: axis, largest deviation (target ±5°) |\n|---|---|---|---|---|---|"
        );
        for t in self.targets {
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
        let Some(a) = self.attitude else { return };
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
            100.0 * self.heldout_fraction
        );
        let _ = writeln!(
            md,
            "| condition | flights | MSE nominal | MSE with the vehicle's effects | reduction | fa explained |\n|---|---|---|---|---|---|"
        );
        let mut conditions: Vec<&str> = Vec::new();
        for h in self.heldout {
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
