//! How far the calm flights pin the drag lag, and how the winds' scale moves across that range.
//!
//! The calm flights have no mean airspeed: they show the drag's response to the flight's own
//! velocity oscillation, never its steady part. A windy flight's air velocity is its steady drag
//! over the steady gain, and with a lag of the air forces (`drag_lag`) the steady gain is larger
//! than the in-phase gain at the flight's frequency by `1 + (ω τ)²`. So the winds' scale rests on
//! the lag the calm flights choose, and a flat calm minimum leaves the scale open. This module
//! measures that: the calm held-out error over a grid of lags (every other parameter refitted),
//! the lags the selection rule cannot tell from the best (error within `min_step` of it), and
//! every flight's air with the lag at either end of that band.

use physics::{EffectId, EffectNumber};
use rayon::prelude::*;
use serde::Serialize;

use super::joint::{Air, Vehicle};
use super::{
    CheckedSettings, FleetFlight, Rows, fit_two_step, heldout_error, joint_flight, joint_flights,
    still_airs, timing_parameters,
};

/// The drag lags of the calm profile, s.
pub const LAG_GRID_S: [f64; 9] = [0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8];

/// The calm flights' verdict on the drag lag and the winds at the ends of what it leaves open.
#[derive(Clone, Debug, Serialize)]
pub struct LagSensitivity {
    /// (drag lag s, calm held-out error) over [`LAG_GRID_S`].
    pub profile: Vec<(f64, f64)>,
    /// The smallest and largest lag of the grid whose calm held-out error is at most the best
    /// over `1 − min_step` (the selection rule would not prefer the best over it), s.
    pub band_s: (f64, f64),
    /// The lag the analysis holds: the calm held-out minimum ([`LagProfile::best_lag_s`]), s.
    pub chosen_s: f64,
    /// Per flight: the air of the joint fit on all rows with the lag at the band's low end.
    #[serde(skip)]
    pub airs_low: Vec<Air>,
    /// The same at the band's high end.
    #[serde(skip)]
    pub airs_high: Vec<Air>,
}

/// The drag lag's time constant, the number this sensitivity varies.
const DRAG_LAG: EffectNumber = EffectNumber::new(EffectId::DragLag, 0);

/// `vehicle` with the value of `parameter` replaced (unchanged if it has none).
fn with_value(vehicle: &Vehicle, parameter: EffectNumber, value: f64) -> Vehicle {
    let mut out = vehicle.clone();
    for (p, v) in out.parameters.iter().zip(out.values.iter_mut()) {
        if *p == parameter {
            *v = value;
        }
    }
    out
}

/// The calm vehicle refitted (first part of the calm flights) with the lag held at `lag_s`, and
/// its held-out error on them.
fn calm_fit_at(
    flights: &[FleetFlight],
    calm_vehicle: &Vehicle,
    lag_s: f64,
    settings: &CheckedSettings,
) -> (Vehicle, f64) {
    let calm: Vec<usize> = (0..flights.len()).filter(|&i| flights[i].calm).collect();
    let fit_rows: Vec<_> = calm
        .iter()
        .map(|&i| joint_flight(&flights[i], true, Rows::Fit))
        .collect();
    let start = with_value(calm_vehicle, DRAG_LAG, lag_s);
    let fitted = fit_two_step(
        &fit_rows,
        &start,
        &[DRAG_LAG],
        true,
        settings.fleet.iterations,
    );
    let still = still_airs(flights, &Vehicle::default());
    let error = heldout_error(flights, &calm, &fitted.vehicle, &still);
    (fitted.vehicle, error)
}

/// The airs of the joint fit on all rows with the vehicle's timing (delay and lag) taken from
/// `calm_at_lag` and held.
fn airs_at(
    flights: &[FleetFlight],
    full_vehicle: &Vehicle,
    calm_at_lag: &Vehicle,
    settings: &CheckedSettings,
) -> Vec<Air> {
    let mut start = full_vehicle.clone();
    for parameter in timing_parameters(full_vehicle) {
        if let Some(k) = calm_at_lag.parameters.iter().position(|p| *p == parameter) {
            start = with_value(&start, parameter, calm_at_lag.values[k]);
        }
    }
    let all_rows = joint_flights(flights, Rows::All);
    let fixed = timing_parameters(&start);
    fit_two_step(&all_rows, &start, &fixed, true, settings.fleet.iterations).airs
}

/// The calm flights' held-out error over the lag grid, each with the calm vehicle refitted at it.
pub struct LagProfile {
    fits: Vec<(f64, Vehicle, f64)>,
}

impl LagProfile {
    /// The profile of `calm_vehicle` (which must have a drag lag), or `None` without one.
    pub fn measure(
        flights: &[FleetFlight],
        calm_vehicle: &Vehicle,
        settings: &CheckedSettings,
    ) -> Option<Self> {
        if !calm_vehicle.parameters.contains(&DRAG_LAG) {
            return None;
        }
        let fits = LAG_GRID_S
            .par_iter()
            .map(|&lag| {
                let (vehicle, error) = calm_fit_at(flights, calm_vehicle, lag, settings);
                (lag, vehicle, error)
            })
            .collect();
        Some(Self { fits })
    }

    /// The lag of least held-out error: the vertex of the parabola through the best grid point and
    /// its neighbours (the grid point itself at an end of the grid or for a flat triple).
    pub fn best_lag_s(&self) -> f64 {
        let k = (0..self.fits.len()).fold(0, |b, i| {
            if self.fits[i].2 < self.fits[b].2 {
                i
            } else {
                b
            }
        });
        if k == 0 || k + 1 == self.fits.len() {
            return self.fits[k].0;
        }
        let (x0, e0) = (self.fits[k - 1].0, self.fits[k - 1].2);
        let (x1, e1) = (self.fits[k].0, self.fits[k].2);
        let (x2, e2) = (self.fits[k + 1].0, self.fits[k + 1].2);
        let curvature = e0 - 2.0 * e1 + e2;
        if curvature <= 0.0 {
            return x1;
        }
        // Equal spacing: vertex at x1 − h (e2 − e0) / (2 curvature), within the bracket.
        let h = x1 - x0;
        (x1 - h * (e2 - e0) / (2.0 * curvature)).clamp(x0, x2)
    }

    /// The calm vehicle refitted with the lag held at `lag_s`.
    pub fn vehicle_at(
        flights: &[FleetFlight],
        calm_vehicle: &Vehicle,
        lag_s: f64,
        settings: &CheckedSettings,
    ) -> Vehicle {
        calm_fit_at(flights, calm_vehicle, lag_s, settings).0
    }

    /// The airs at the ends of the band of lags the selection rule cannot tell from the best.
    pub fn sensitivity(
        &self,
        flights: &[FleetFlight],
        full_vehicle: &Vehicle,
        settings: &CheckedSettings,
    ) -> Option<LagSensitivity> {
        if !full_vehicle.parameters.contains(&DRAG_LAG) {
            return None;
        }
        let best = self.fits.iter().map(|f| f.2).fold(f64::INFINITY, f64::min);
        let open: Vec<&(f64, Vehicle, f64)> = self
            .fits
            .iter()
            .filter(|f| best >= (1.0 - settings.fleet.min_step) * f.2)
            .collect();
        let (low, high) = (open.first()?, open.last()?);
        let (airs_low, airs_high) = rayon::join(
            || airs_at(flights, full_vehicle, &low.1, settings),
            || airs_at(flights, full_vehicle, &high.1, settings),
        );
        Some(LagSensitivity {
            profile: self.fits.iter().map(|f| (f.0, f.2)).collect(),
            band_s: (low.0, high.0),
            chosen_s: self.best_lag_s(),
            airs_low,
            airs_high,
        })
    }
}
