//! A cell's data as both methods see it: the support and query segments of an evaluation flight,
//! and the qualitative figure drawn over them.

use data::{Condition, FlightLog, Formulation, Mat, Segment, SplitSpec};
use report::{MethodTrace, OutputAxis, QualitativeFigure};
use sindy::Derivative;

use crate::error::{Result, in_flight};

/// The support and query segments of `log` (cut by `split`, targets by `derivative` on each
/// segment); errors name the flight's file.
pub(crate) fn flight_segments(
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

/// Column `j` of two stacked matrices.
fn stacked_column(top: &Mat<f64>, bottom: &Mat<f64>, j: usize) -> Vec<f64> {
    (0..top.nrows())
        .map(|i| top[(i, j)])
        .chain((0..bottom.nrows()).map(|i| bottom[(i, j)]))
        .collect()
}

/// Every column of two stacked matrices (support rows, then query rows).
pub(crate) fn stacked_columns(top: &Mat<f64>, bottom: &Mat<f64>) -> Vec<Vec<f64>> {
    (0..top.ncols())
        .map(|j| stacked_column(top, bottom, j))
        .collect()
}

/// The qualitative figure of one cell (time and ground truth over both segments, one trace per
/// method) and its file name.
pub(crate) fn cell_figure(
    formulation: Formulation,
    condition: &Condition,
    support: &Segment,
    query: &Segment,
    methods: Vec<MethodTrace>,
) -> Result<(String, QualitativeFigure)> {
    let figure = QualitativeFigure {
        table: formulation.name().to_string(),
        condition: condition.label().to_string(),
        time: support.time.iter().chain(&query.time).copied().collect(),
        split: support.len(),
        outputs: formulation
            .target_names()
            .iter()
            .map(|o| OutputAxis::for_target(o))
            .collect(),
        truth: stacked_columns(&support.targets, &query.targets),
        methods,
    };
    figure.validate()?;
    Ok((
        figure_file_name(formulation.name(), condition.label()),
        figure,
    ))
}

/// The figure's file name: table and condition label, with anything unusual replaced by `-`.
pub fn figure_file_name(table: &str, label: &str) -> String {
    let clean: String = label
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '.' {
                c
            } else {
                '-'
            }
        })
        .collect();
    format!("{table}_{clean}.svg")
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

    #[test]
    fn figure_names_are_safe() {
        assert_eq!(figure_file_name("full", "70psin20"), "full_70psin20.svg");
        assert_eq!(
            figure_file_name("attitude", "8 m/s gust"),
            "attitude_8-m-s-gust.svg"
        );
    }

    #[test]
    fn stacked_columns_follow_time_order() {
        let top = Mat::from_fn(2, 2, |i, j| (i * 10 + j) as f64);
        let bottom = Mat::from_fn(1, 2, |_, j| 100.0 + j as f64);
        assert_eq!(stacked_column(&top, &bottom, 1), vec![1.0, 11.0, 101.0]);
    }
}
