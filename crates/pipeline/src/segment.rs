//! A flight cut into segments of one formulation: the support and query data both methods are
//! fitted or adapted on and scored on, and the same data as LeARN's regression batches.

use data::{FlightLog, Formulation, Segment, SplitSpec};
use learn::{Batch, row_major};
use sindy::Derivative;

use crate::error::{Result, in_flight};

/// The support and query segments of `log` (cut by `split`, targets by `derivative` on each
/// segment); errors name the flight's file.
pub fn flight_segments(
    log: &FlightLog,
    formulation: Formulation,
    split: SplitSpec,
    derivative: Derivative,
) -> Result<(Segment, Segment)> {
    let segments = || -> std::result::Result<(Segment, Segment), data::DataError> {
        let rows = split.split(log.len())?;
        let support = formulation.segment(log, rows.support, derivative)?;
        let query = formulation.segment(log, rows.query, derivative)?;
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
            motor_command: vec![[1500.0; 4]; n],
            position_desired: None,
            velocity_desired: None,
            attitude_setpoint: None,
            residual_force: None,
        }
    }

    #[test]
    fn a_flight_too_short_to_split_is_named() {
        let short = still_flight("/data/experiment/short.csv", 3);
        let message = flight_segments(
            &short,
            Formulation::Full,
            SplitSpec::Halves,
            Derivative::Forward,
        )
        .unwrap_err()
        .to_string();
        assert_eq!(
            message,
            "/data/experiment/short.csv: split: 3 rows are too few to split (1 / 2)"
        );
        let (support, query) = flight_segments(
            &still_flight("long.csv", 10),
            Formulation::Full,
            SplitSpec::Halves,
            Derivative::Forward,
        )
        .unwrap();
        assert_eq!((support.rows, query.rows), (0..5, 5..10));
    }
}
