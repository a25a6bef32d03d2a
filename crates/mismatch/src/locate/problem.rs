//! The comparison in the weak form ([`crate::weak_form`]): the target of the recording (a smoothed
//! acceleration of the recorded velocity and body rate), the model's value of the same functional,
//! the residual and its noise floor, per channel.

use physics::{ChannelGroup, CommandLogging, Effects, NominalModel};
use sindy::stability::BlockDesign;
use sindy::weak_form::{TestFunction, WeakForm};

use crate::error::{MismatchError, Result};
use crate::locate::forward::{
    RowPrediction, SUBSTEPS, WrenchTrace, accelerations_at_rows, predict_at_rows,
    predict_substeps_with,
};
use crate::recording::Recording;

/// The fewest test-function windows a recording must span.
pub const MIN_WINDOWS: usize = 8;

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
    pub weak_form: WeakForm,
    /// 3 (translational only) or 6.
    pub channels: usize,
    /// Time of each analysed row (the centre of its test function).
    pub time: Vec<f64>,
    /// The weak-form target of the recorded velocity and body rate.
    pub target: Vec<Channels>,
    /// Standard deviation of the residual expected from measurement noise alone.
    pub noise_floor: Channels,
    /// The part of the noise floor that is on the model's side (from the recorded commands and
    /// attitude the model reads), per channel: it attenuates fitted scale factors.
    pub model_noise: Channels,
    /// Analysed rows `[0, split)` are fitted, `[split, len)` are held out.
    pub split: usize,
}

impl Problem {
    /// The whitened regression of `residual` on `columns` over analysed rows `range`, by blocks
    /// of `block_rows` rows: every channel of a row is a sample, divided by the channel's noise
    /// floor.
    pub fn design(
        &self,
        residual: &[Channels],
        columns: &[Vec<Channels>],
        range: std::ops::Range<usize>,
        block_rows: usize,
    ) -> BlockDesign {
        let columns: Vec<&Vec<Channels>> = columns.iter().collect();
        self.design_of(residual, &columns, range, block_rows)
    }

    /// [`Self::design`] over borrowed columns; with an empty `residual` the target is 0 (for the
    /// columns' statistics alone).
    pub(crate) fn design_of(
        &self,
        residual: &[Channels],
        columns: &[&Vec<Channels>],
        range: std::ops::Range<usize>,
        block_rows: usize,
    ) -> BlockDesign {
        let channels = self.channels;
        let samples = range.len() * channels;
        BlockDesign::from_samples(samples, block_rows * channels, columns.len(), |i, x| {
            let (row, c) = (range.start + i / channels, i % channels);
            let scale = 1.0 / self.noise_floor[c];
            for (value, column) in x.iter_mut().zip(columns) {
                *value = column[row][c] * scale;
            }
            if residual.is_empty() {
                0.0
            } else {
                residual[row][c] * scale
            }
        })
    }

    /// Builds the comparison; `heldout_fraction` of the analysed rows (the last ones) are held out.
    pub fn new(
        recording: Recording,
        model: NominalModel,
        test_function: TestFunction,
        heldout_fraction: f64,
    ) -> Result<Self> {
        let bad = |message: String| MismatchError::Recording {
            path: recording.path.clone(),
            message,
        };
        let weak_form = test_function.on(&recording.sampling).map_err(bad)?;
        let half = weak_form.half;
        let n = recording.len();
        // Enough rows for several windows to fit and to hold out.
        let needed = MIN_WINDOWS * (2 * half + 1);
        if n < needed {
            return Err(bad(format!(
                "{n} rows, the analysis needs at least {needed} ({MIN_WINDOWS} of the comparison's windows of {} rows)",
                2 * half + 1
            )));
        }
        let centres = weak_form.centres.len();
        if centres + 2 * half < needed {
            return Err(bad(format!(
                "{centres} rows have a whole window of the comparison between gaps, the analysis needs at least {} ({} gaps longer than {} s)",
                needed - 2 * half,
                recording.sampling.gaps().len(),
                sindy::sampling::GAP_FACTOR * recording.dt()
            )));
        }
        let channels = if model.predicts_torque() { 6 } else { 3 };
        let target = targets(&recording, &weak_form, channels);
        let nominal = if model.logger.command == CommandLogging::Sample {
            Some(predict_at_rows(&recording, &model))
        } else {
            None
        };
        // With the commands' unfelt reaction to the logged noise removed, the residual keeps the
        // reaction to the rate noise and the reaction, felt, to the noise of the control steps the
        // log did not sample; the logged commands' step-to-step noise bounds both, as it bounded
        // the whole before (the floor), while the corrected commands' noise is what remains in the
        // model's inputs (the share that attenuates a factor).
        let logged = recording.noise_reaction.as_ref().map(|reaction| {
            accelerations_at_rows(
                &recording,
                &reaction.logged_commands,
                &model,
                &Effects::default(),
            )
        });
        let mut noise_floor = [0.0; 6];
        let mut model_noise = [0.0; 6];
        for c in 0..channels {
            let signal: Vec<f64> = if c < 3 {
                recording.velocity.iter().map(|v| v[c]).collect()
            } else {
                recording.body_rate.iter().map(|w| w[c - 3]).collect()
            };
            let measured = recording.white_noise_sigma(&signal) * weak_form.target_noise_gain();
            model_noise[c] = model_side_noise(&recording, &model, nominal.as_ref(), c)
                * weak_form.model_noise_gain();
            let floor_side = match &logged {
                Some(logged) => {
                    model_side_noise(&recording, &model, Some(logged), c)
                        * weak_form.model_noise_gain()
                }
                None => model_noise[c],
            };
            noise_floor[c] = measured.hypot(floor_side).max(1e-12);
        }
        let rows = target.len();
        let split = ((1.0 - heldout_fraction) * rows as f64).round() as usize;
        if !(1..rows).contains(&split) {
            return Err(bad(format!(
                "a held-out fraction of {heldout_fraction} of {rows} analysed rows leaves no rows to fit or none to hold out"
            )));
        }
        Ok(Self {
            time: weak_form
                .centres
                .iter()
                .map(|&k| recording.time[k])
                .collect(),
            recording,
            model,
            weak_form,
            channels,
            target,
            noise_floor,
            model_noise,
            split,
        })
    }

    /// The same comparison of another recording of the same rows (the target recomputed, the noise
    /// floor and the split kept).
    pub fn with_recording(&self, recording: Recording) -> Self {
        Self {
            target: targets(&recording, &self.weak_form, self.channels),
            recording,
            model: self.model.clone(),
            weak_form: self.weak_form.clone(),
            time: self.time.clone(),
            ..*self
        }
    }

    /// Number of analysed rows.
    pub fn rows(&self) -> usize {
        self.target.len()
    }

    /// The model's value of the weak form with a set of effects, per analysed row.
    pub fn predict(&self, effects: &Effects) -> Vec<Channels> {
        self.predict_with(
            effects,
            &WrenchTrace::new(&self.recording, &self.model, effects),
        )
    }

    /// [`Self::predict`] with the commands' wrench already traced for the effects' delay and motor
    /// lag ([`WrenchTrace`]); the same numbers, without tracing it again.
    pub fn predict_with(&self, effects: &Effects, wrenches: &WrenchTrace) -> Vec<Channels> {
        let substeps = predict_substeps_with(&self.recording, &self.model, effects, wrenches);
        let mut out = vec![[0.0; 6]; self.rows()];
        let translational = self
            .weak_form
            .integrate_channels(&substeps.translational, SUBSTEPS);
        for (row, value) in out.iter_mut().zip(translational) {
            row[..3].copy_from_slice(&value);
        }
        if self.channels == 6 {
            let angular = substeps.angular.as_ref().expect("angular channels");
            let angular = self.weak_form.integrate_channels(angular, SUBSTEPS);
            for (row, value) in out.iter_mut().zip(angular) {
                row[3..].copy_from_slice(&value);
            }
        }
        out
    }

    /// Target minus prediction.
    pub fn residual(&self, effects: &Effects) -> Vec<Channels> {
        self.residual_from(&self.predict(effects))
    }

    /// [`Self::residual`] with the commands' wrench already traced ([`Self::predict_with`]).
    pub fn residual_with(&self, effects: &Effects, wrenches: &WrenchTrace) -> Vec<Channels> {
        self.residual_from(&self.predict_with(effects, wrenches))
    }

    fn residual_from(&self, predicted: &[Channels]) -> Vec<Channels> {
        self.target
            .iter()
            .zip(predicted)
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
        self.whitened_sse_of(residual, range, 0..self.channels)
    }

    /// [`Self::whitened_sse`] over the channels `channels` only.
    pub fn whitened_sse_of(
        &self,
        residual: &[Channels],
        range: std::ops::Range<usize>,
        channels: std::ops::Range<usize>,
    ) -> f64 {
        residual[range]
            .iter()
            .map(|r| {
                channels
                    .clone()
                    .map(|c| (r[c] / self.noise_floor[c]).powi(2))
                    .sum::<f64>()
            })
            .sum()
    }

    /// The channel groups the problem compares, each with its channels: the translational
    /// accelerations, and the angular ones when the model predicts torques.
    pub fn channel_groups(&self) -> Vec<(ChannelGroup, std::ops::Range<usize>)> {
        let mut groups = vec![(ChannelGroup::Translational, 0..3)];
        if self.channels == 6 {
            groups.push((ChannelGroup::Angular, 3..6));
        }
        groups
    }
}

/// The weak-form target of the recorded velocity (translational channels) and body rate.
fn targets(recording: &Recording, weak_form: &WeakForm, channels: usize) -> Vec<Channels> {
    let rows = weak_form.centres.len();
    let mut target = vec![[0.0; 6]; rows];
    for c in 0..channels {
        let signal: Vec<f64> = if c < 3 {
            recording.velocity.iter().map(|v| v[c]).collect()
        } else {
            recording.body_rate.iter().map(|w| w[c - 3]).collect()
        };
        for (row, value) in target.iter_mut().zip(weak_form.target(&signal)) {
            row[c] = value;
        }
    }
    target
}

/// The noise per sample of the model's acceleration on channel `c`: the measured attitude tilting
/// the thrust (translational channels) and, when the commands are instantaneous samples of a faster
/// controller's, the part of the command that varies from sample to sample and that the samples
/// cannot resolve (estimated from the fourth differences of the nominal model's accelerations at
/// the rows, which include the attitude's part).
fn model_side_noise(
    recording: &Recording,
    model: &NominalModel,
    nominal: Option<&RowPrediction>,
    c: usize,
) -> f64 {
    let attitude = if c < 3 {
        let direction: Vec<f64> = recording.rotation.iter().map(|r| r[c][2]).collect();
        recording.white_noise_sigma(&direction) * nominal_thrust_acceleration(recording, model)
    } else {
        0.0
    };
    let Some((translational, angular)) = nominal else {
        return attitude;
    };
    let series: Vec<f64> = if c < 3 {
        translational.iter().map(|a| a[c]).collect()
    } else {
        let Some(angular) = angular.as_ref() else {
            return attitude;
        };
        angular.iter().map(|a| a[c - 3]).collect()
    };
    recording.white_noise_sigma(&series).max(attitude)
}
