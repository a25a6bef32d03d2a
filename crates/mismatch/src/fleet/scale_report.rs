//! The report's part on the winds' scale ([`ScaleReport`], rendered by the `report` crate): the
//! calm lag profile, its band and every windy flight's speed at the band's two ends.

use report::mismatch::fleet::{FlightSpeedRange, ScaleReport};

use super::joint::Air;
use super::{FleetFlight, LagSensitivity};

fn horizontal(air: &Air) -> f64 {
    let w = air.velocity();
    w[0].hypot(w[1])
}

/// The scale part of the report from what the lag sensitivity found.
pub fn scale_report(flights: &[FleetFlight], found: &LagSensitivity) -> ScaleReport {
    let windy = flights
        .iter()
        .zip(found.airs_low.iter().zip(&found.airs_high))
        .filter(|(f, _)| !f.calm);
    ScaleReport {
        calm_profile: found.profile.clone(),
        lag_band_s: found.band_s,
        chosen_lag_s: found.chosen_s,
        flights: windy
            .map(|(f, (low, high))| FlightSpeedRange {
                condition: f.condition.clone(),
                controller: f.controller.clone(),
                fan_speed_m_s: f.mean_wind_m_s,
                speed_low_lag_m_s: horizontal(low),
                speed_high_lag_m_s: horizontal(high),
            })
            .collect(),
    }
}
