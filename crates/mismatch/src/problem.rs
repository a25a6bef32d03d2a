//! The comparison at derivative level: the smoothed derivative of the recording (target), the
//! model's matched prediction, the residual and its noise floor, per channel.

use data::Derivative;
use physics::{Effects, NominalModel};

use crate::error::{MismatchError, Result};
use crate::filter::{MatchedSmoother, white_noise_sigma};
use crate::forward::predict_intervals;
use crate::recording::Recording;

/// Channel names in output order: translational then angular accelerations.
pub const CHANNEL_NAMES: [&str; 6] = ["vdot_x", "vdot_y", "vdot_z", "wdot_x", "wdot_y", "wdot_z"];

/// Mean of the nominal thrust acceleration `T / m` over a recording, m/s².
fn nominal_thrust_acceleration(recording: &Recording, model: &NominalModel) -> f64 {
    let total: f64 = recording
        .commands
        .iter()
        .map(|u| model.wrench(u).thrust / model.mass_kg)
        .sum();
    total / recording.len() as f64
}

/// One value per channel (angular channels unused when the model has no torques).
pub type Channels = [f64; 6];

/// A recording compared with a model.
#[derive(Clone, Debug)]
pub struct Problem {
    pub recording: Recording,
    pub model: NominalModel,
    pub smoother: MatchedSmoother,
    /// 3 (translational only) or 6.
    pub channels: usize,
    /// Time of each analysed row (the rows where the smoothed derivative is centred).
    pub time: Vec<f64>,
    /// Smoothed derivative of the recorded velocity and body rate.
    pub target: Vec<Channels>,
    /// Standard deviation of the residual expected from measurement noise alone.
    pub noise_floor: Channels,
    /// Analysed rows `[0, split)` are fitted, `[split, len)` are held out.
    pub split: usize,
}

impl Problem {
    /// Builds the comparison; `heldout_fraction` of the analysed rows (the last ones) are held out.
    pub fn new(
        recording: Recording,
        model: NominalModel,
        derivative: Derivative,
        heldout_fraction: f64,
    ) -> Result<Self> {
        let smoother = MatchedSmoother::new(derivative)?;
        let half = smoother.half_window();
        let n = recording.len();
        // At least one analysed row to fit and one held out.
        if n < 2 * half + 2 {
            return Err(MismatchError::Recording {
                path: recording.path.clone(),
                message: format!(
                    "{n} rows, the derivative's window of {} rows needs at least {}",
                    2 * half + 1,
                    2 * half + 2
                ),
            });
        }
        let channels = if model.predicts_torque() { 6 } else { 3 };
        let dt = recording.dt;
        let mut target = vec![[0.0; 6]; n - 2 * half];
        let mut noise_floor = [0.0; 6];
        for c in 0..channels {
            let signal: Vec<f64> = if c < 3 {
                recording.velocity.iter().map(|v| v[c]).collect()
            } else {
                recording.body_rate.iter().map(|w| w[c - 3]).collect()
            };
            for (row, value) in target.iter_mut().zip(smoother.derivative_of(&signal, dt)) {
                row[c] = value;
            }
            let measured = white_noise_sigma(&signal) * smoother.sample_noise_gain() / dt;
            // The recorded commands are exact; what is noisy on the model side is the measured
            // attitude tilting the thrust (the gyroscopic term's rate noise is negligible).
            let model_side = if c < 3 {
                let direction: Vec<f64> = recording.rotation.iter().map(|r| r[c][2]).collect();
                let mean_thrust = nominal_thrust_acceleration(&recording, &model);
                white_noise_sigma(&direction) * mean_thrust * smoother.interval_noise_gain()
            } else {
                0.0
            };
            noise_floor[c] = measured.hypot(model_side).max(1e-12);
        }
        let rows = target.len();
        let split = ((1.0 - heldout_fraction) * rows as f64).round() as usize;
        if !(1..=rows).contains(&split) {
            return Err(MismatchError::Recording {
                path: recording.path.clone(),
                message: format!(
                    "a held-out fraction of {heldout_fraction} of {rows} analysed rows leaves no rows to fit"
                ),
            });
        }
        Ok(Self {
            time: recording.time[half..n - half].to_vec(),
            recording,
            model,
            smoother,
            channels,
            target,
            noise_floor,
            split,
        })
    }

    /// Number of analysed rows.
    pub fn rows(&self) -> usize {
        self.target.len()
    }

    /// The model's smoothed-derivative prediction with a set of effects, per analysed row.
    pub fn predict(&self, effects: &Effects) -> Vec<Channels> {
        let intervals = predict_intervals(&self.recording, &self.model, effects);
        let mut out = vec![[0.0; 6]; self.rows()];
        for c in 0..self.channels {
            let series: Vec<f64> = if c < 3 {
                intervals.translational.iter().map(|a| a[c]).collect()
            } else {
                intervals
                    .angular
                    .as_ref()
                    .expect("angular channels")
                    .iter()
                    .map(|a| a[c - 3])
                    .collect()
            };
            for (row, value) in out.iter_mut().zip(self.smoother.smooth_intervals(&series)) {
                row[c] = value;
            }
        }
        out
    }

    /// Target minus prediction.
    pub fn residual(&self, effects: &Effects) -> Vec<Channels> {
        let predicted = self.predict(effects);
        self.target
            .iter()
            .zip(&predicted)
            .map(|(t, p)| {
                let mut r = [0.0; 6];
                for c in 0..self.channels {
                    r[c] = t[c] - p[c];
                }
                r
            })
            .collect()
    }

    /// Mean square of a residual over rows `range` and all channels (raw units).
    pub fn mse(&self, residual: &[Channels], range: std::ops::Range<usize>) -> f64 {
        let count = (range.len() * self.channels).max(1) as f64;
        residual[range]
            .iter()
            .map(|r| r[..self.channels].iter().map(|v| v * v).sum::<f64>())
            .sum::<f64>()
            / count
    }

    /// Sum of squares of a residual over rows `range`, each channel divided by its noise floor.
    pub fn whitened_sse(&self, residual: &[Channels], range: std::ops::Range<usize>) -> f64 {
        residual[range]
            .iter()
            .map(|r| {
                (0..self.channels)
                    .map(|c| (r[c] / self.noise_floor[c]).powi(2))
                    .sum::<f64>()
            })
            .sum()
    }
}
