//! A formulation's regression data of a flight (the file side of the paper's formulations): which
//! log columns, with which scalings, make the states x and controls u of [`Formulation`]
//! ([`Segment::cut`]), a flight cut into support and query segments ([`Segmentation`],
//! [`flight_segments`]) and a segment as LeARN's regression data ([`segment_batch`],
//! [`SegmentModel`]).
//!
//! | formulation | state x (I) | control u (U) | target |
//! |---|---|---|---|
//! | `Translational` | v (3) | R·[0, 0, T], T = raw `T_sp` (3) | v̇ |
//! | `Attitude` | ω (3) | motor speeds nᵢ = pwmᵢ/1000 (4) | ω̇ |
//! | `Full` | [v; ω] (6) | squared speeds nᵢ² = (pwmᵢ/1000)² (4) | [v̇; ω̇] |
//!
//! These scalings (thrust as the normalised setpoint, not newtons; pwm divided by 1000) are the ones
//! that reproduce the paper's SINDy columns. The learned models see X = [x, u] in that order.

use std::ops::Range;

use data::{FlightLog, SplitSpec};
use faer::Mat;
use learn::{AdaptationConfig, Batch, Formulation, MetaTrainedModel, row_major};
use serde::{Deserialize, Serialize};
use sindy::Derivative;

use crate::error::{EvaluationError, Result, in_flight};

/// Regression data of one contiguous stretch of a flight.
#[derive(Clone, Debug)]
pub struct Segment {
    pub formulation: Formulation,
    /// The rows of the flight this segment covers.
    pub rows: Range<usize>,
    /// Time of each sample, s.
    pub time: Vec<f64>,
    /// x, one row per sample.
    pub states: Mat<f64>,
    /// u, one row per sample.
    pub controls: Mat<f64>,
    /// ẋ estimated on this segment, one row per sample.
    pub targets: Mat<f64>,
}

impl Segment {
    /// The regression data of `formulation` on rows `rows` of `log`: states, controls and the
    /// derivative of the states estimated on this segment alone.
    pub fn cut(
        log: &FlightLog,
        formulation: Formulation,
        rows: Range<usize>,
        derivative: Derivative,
    ) -> Result<Self> {
        if rows.end > log.len() || rows.start >= rows.end {
            return Err(EvaluationError::Mismatch {
                what: log.path.display().to_string(),
                message: format!("rows {rows:?} are outside the {} samples", log.len()),
            });
        }
        let n = rows.len();
        let (dim_x, dim_u) = (formulation.state_dim(), formulation.control_dim());
        let mut buffer = Vec::with_capacity(dim_x + dim_u);
        let mut states = Mat::<f64>::zeros(n, dim_x);
        let mut controls = Mat::<f64>::zeros(n, dim_u);
        for (i, k) in rows.clone().enumerate() {
            buffer.clear();
            state(formulation, log, k, &mut buffer);
            control(formulation, log, k, &mut buffer);
            for j in 0..dim_x {
                states[(i, j)] = buffer[j];
            }
            for j in 0..dim_u {
                controls[(i, j)] = buffer[dim_x + j];
            }
        }
        let targets = derivative
            .apply_columns(states.as_ref(), log.sample_interval())
            .map_err(sindy::SindyError::from)?;
        Ok(Self {
            formulation,
            time: log.time[rows.clone()].to_vec(),
            rows,
            states,
            controls,
            targets,
        })
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.states.nrows()
    }

    /// Whether the segment has no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// X = [x, u], one row per sample.
    pub fn inputs(&self) -> Mat<f64> {
        let (n, dim_x, dim_u) = (self.len(), self.states.ncols(), self.controls.ncols());
        Mat::from_fn(n, dim_x + dim_u, |i, j| {
            if j < dim_x {
                self.states[(i, j)]
            } else {
                self.controls[(i, j - dim_x)]
            }
        })
    }
}

/// The state x of `formulation` at row `k` of `log`, appended to `out`.
fn state(formulation: Formulation, log: &FlightLog, k: usize, out: &mut Vec<f64>) {
    match formulation {
        Formulation::Translational => out.extend(log.velocity[k]),
        Formulation::Attitude => out.extend(log.body_rate[k]),
        Formulation::Full => {
            out.extend(log.velocity[k]);
            out.extend(log.body_rate[k]);
        }
    }
}

/// The control u of `formulation` at row `k` of `log`, appended to `out`.
fn control(formulation: Formulation, log: &FlightLog, k: usize, out: &mut Vec<f64>) {
    match formulation {
        Formulation::Translational => {
            let thrust = log.thrust_setpoint[k];
            out.extend(log.rotation[k].iter().map(|row| row[2] * thrust));
        }
        Formulation::Attitude => out.extend(log.motor_command.row(k).iter().map(|p| p / 1000.0)),
        Formulation::Full => out.extend(
            log.motor_command
                .row(k)
                .iter()
                .map(|p| (p / 1000.0).powi(2)),
        ),
    }
}

/// How every flight of a run is cut into a support and a query segment and how their targets
/// are estimated: the run configuration's `split` and `derivative` (the paper: halves, forward
/// differences on each segment). SINDy, LeARN, its meta-training tasks and every variant use the
/// segments of one [`Segmentation`], so all methods see the same targets by construction.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Segmentation {
    pub split: SplitSpec,
    pub derivative: Derivative,
}

impl Segmentation {
    /// The paper's: support = first half, query = second half, forward differences on each.
    pub const PAPER: Segmentation = Segmentation {
        split: SplitSpec::Halves,
        derivative: Derivative::Forward,
    };

    /// The protocol in words, e.g. `support = first half, query = second half, forward-difference
    /// targets on each segment`.
    pub fn describe(&self) -> String {
        let split = match self.split {
            SplitSpec::Halves => "support = first half, query = second half".to_string(),
            SplitSpec::Fraction { support } => {
                format!("support = first {support} of the flight, query = the rest")
            }
        };
        let targets = match self.derivative {
            Derivative::Forward => "forward-difference".to_string(),
            Derivative::Central => "central-difference".to_string(),
            Derivative::SavitzkyGolay { window, order } => {
                format!("Savitzky–Golay (window {window}, order {order})")
            }
        };
        format!("{split}, {targets} targets on each segment")
    }
}

/// The support and query segments of `log` (cut by `segmentation.split`, targets by
/// `segmentation.derivative` on each segment); errors name the flight's file.
pub fn flight_segments(
    log: &FlightLog,
    formulation: Formulation,
    segmentation: Segmentation,
) -> Result<(Segment, Segment)> {
    let Segmentation { split, derivative } = segmentation;
    let segments = || -> Result<(Segment, Segment)> {
        let rows = split.split(log.len())?;
        let support = Segment::cut(log, formulation, rows.support, derivative)?;
        let query = Segment::cut(log, formulation, rows.query, derivative)?;
        Ok((support, query))
    };
    segments().map_err(|error| in_flight(&log.path, error))
}

/// A segment as LeARN's regression data: raw (not standardised) inputs X = [x, u] and targets ẋ,
/// row-major.
pub fn segment_batch(segment: &Segment) -> Batch {
    Batch {
        inputs: row_major(&segment.inputs()),
        targets: row_major(&segment.targets),
    }
}

/// A meta-trained model used on flight segments: adapted online on one, predicting on any.
pub trait SegmentModel {
    /// θ adapted online on `support` ([`MetaTrainedModel::adapt_on`] on its raw inputs and
    /// targets, in time order).
    fn adapt(&self, support: &Segment, adaptation: &AdaptationConfig) -> Vec<f64>;

    /// Predictions (samples × I, row-major) of the networks with `parameters` (e.g. adapted by
    /// [`SegmentModel::adapt`]) on every sample of `segment`.
    fn predict_segment(&self, parameters: &[f64], segment: &Segment) -> Vec<f64>;
}

impl SegmentModel for MetaTrainedModel {
    fn adapt(&self, support: &Segment, adaptation: &AdaptationConfig) -> Vec<f64> {
        let batch = segment_batch(support);
        self.adapt_on(&batch.inputs, &batch.targets, adaptation)
    }

    fn predict_segment(&self, parameters: &[f64], segment: &Segment) -> Vec<f64> {
        self.predict_with(parameters, &row_major(&segment.inputs()))
    }
}

#[cfg(test)]
mod tests {
    use std::path::PathBuf;

    use super::*;

    /// A still flight of `n` samples at 50 Hz read from `path`.
    fn still_flight(path: &str, n: usize) -> FlightLog {
        FlightLog {
            path: PathBuf::from(path),
            meta: None,
            time: (0..n).map(|k| k as f64 * 0.02).collect(),
            position: vec![[0.0; 3]; n],
            velocity: vec![[0.0; 3]; n],
            quaternion: vec![[0.0, 0.0, 0.0, 1.0]; n],
            rotation: vec![[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]; n],
            body_rate: vec![[0.0; 3]; n],
            thrust_setpoint: vec![0.5; n],
            hover_throttle: vec![0.5; n],
            motor_command: vec![[1500.0; 4]; n].into_iter().collect(),
            battery_voltage: None,
            declared_rate_frame: None,
            position_desired: None,
            velocity_desired: None,
            attitude_setpoint: None,
            residual_force: None,
        }
    }

    #[test]
    fn the_segmentation_is_described_in_words() {
        // The paper's words are those `ablations.json` has always recorded as its protocol.
        assert_eq!(
            Segmentation::PAPER.describe(),
            "support = first half, query = second half, forward-difference targets on each segment"
        );
        let other = Segmentation {
            split: SplitSpec::Fraction { support: 0.75 },
            derivative: Derivative::SavitzkyGolay {
                window: 7,
                order: 3,
            },
        };
        assert_eq!(
            other.describe(),
            "support = first 0.75 of the flight, query = the rest, Savitzky–Golay (window 7, order 3) targets on each segment"
        );
    }

    #[test]
    fn a_flight_too_short_to_split_is_named() {
        let short = still_flight("/data/experiment/short.csv", 3);
        let message = flight_segments(&short, Formulation::Full, Segmentation::PAPER)
            .unwrap_err()
            .to_string();
        assert_eq!(
            message,
            "/data/experiment/short.csv: split: 3 rows are too few to split (1 / 2)"
        );
        let (support, query) = flight_segments(
            &still_flight("long.csv", 10),
            Formulation::Full,
            Segmentation::PAPER,
        )
        .unwrap();
        assert_eq!((support.rows, query.rows), (0..5, 5..10));
    }
}
