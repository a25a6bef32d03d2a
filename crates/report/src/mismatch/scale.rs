//! The joint analysis's part on the winds' scale: the calm lag profile, its band and every windy
//! flight's speed at the band's two ends.

use std::fmt::Write as _;

use serde::{Deserialize, Serialize};

/// One windy flight's horizontal air speed with the drag lag at either end of the band.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FlightSpeedRange {
    pub condition: String,
    pub controller: String,
    pub fan_speed_m_s: Option<f64>,
    pub speed_low_lag_m_s: f64,
    pub speed_high_lag_m_s: f64,
}

impl FlightSpeedRange {
    /// The smaller and the larger of the two speeds.
    pub fn range(&self) -> (f64, f64) {
        let (a, b) = (self.speed_low_lag_m_s, self.speed_high_lag_m_s);
        (a.min(b), a.max(b))
    }

    /// Whether the known speed lies between the two.
    pub fn covers_known(&self) -> Option<bool> {
        let (low, high) = self.range();
        self.fan_speed_m_s.map(|s| (low..=high).contains(&s))
    }
}

/// The scale part of the report.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ScaleReport {
    /// (drag lag s, calm held-out error).
    pub calm_profile: Vec<(f64, f64)>,
    pub lag_band_s: (f64, f64),
    /// The lag the analysis holds (the calm held-out minimum), s.
    pub chosen_lag_s: f64,
    pub flights: Vec<FlightSpeedRange>,
}

impl ScaleReport {
    /// The section in Markdown: profile, band, per-condition ranges (`min_step`: the selection's
    /// least relative step, which bounds the band).
    pub(crate) fn markdown(&self, min_step: f64, md: &mut String) {
        let _ = writeln!(md, "\n## How firmly the data fix the winds' scale\n");
        let _ = writeln!(
            md,
            "Still air shows the drag's response to the flight's own velocity swings, never its steady part, and a windy flight's air speed is its steady drag over the steady gain. With a lag of the air forces the steady gain exceeds the swing's in-phase gain, so the winds' scale rests on the lag the calm flights choose. Calm held-out error with the lag held (every other parameter refitted on the calm flights):\n"
        );
        let _ = writeln!(md, "| drag lag (s) | calm held-out error |\n|---|---|");
        for (lag, error) in &self.calm_profile {
            let _ = writeln!(md, "| {lag:.1} | {error:.4} |");
        }
        let (low, high) = self.lag_band_s;
        let _ = writeln!(
            md,
            "\nThe analysis holds the lag at {:.3} s, the vertex of the parabola through the best grid point and its neighbours. Lags from {low:.1} to {high:.1} s are within {:.0}% of the best (the selection rule would not choose between them). The winds with the lag at either end (joint fit, all rows):\n",
            self.chosen_lag_s,
            100.0 * min_step
        );
        let _ = writeln!(
            md,
            "| condition | known speed (m/s) | horizontal speed, lag {low:.1} s | lag {high:.1} s | flights whose known speed is in the range |\n|---|---|---|---|---|"
        );
        for (condition, members) in self.by_condition() {
            let mean = |f: fn(&FlightSpeedRange) -> f64| {
                members.iter().map(|m| f(m)).sum::<f64>() / members.len() as f64
            };
            let covered = members
                .iter()
                .filter(|m| m.covers_known() == Some(true))
                .count();
            let known = members[0]
                .fan_speed_m_s
                .map(|s| format!("{s}"))
                .unwrap_or_else(|| "—".into());
            let _ = writeln!(
                md,
                "| {condition} | {known} | {:.2} | {:.2} | {covered} of {} |",
                mean(|m| m.speed_low_lag_m_s),
                mean(|m| m.speed_high_lag_m_s),
                members.len()
            );
        }
        let _ = writeln!(md);
    }

    /// The flights grouped by condition, in order of appearance.
    fn by_condition(&self) -> Vec<(String, Vec<&FlightSpeedRange>)> {
        let mut groups: Vec<(String, Vec<&FlightSpeedRange>)> = Vec::new();
        for f in &self.flights {
            match groups.iter_mut().find(|g| g.0 == f.condition) {
                Some(g) => g.1.push(f),
                None => groups.push((f.condition.clone(), vec![f])),
            }
        }
        groups
    }
}
