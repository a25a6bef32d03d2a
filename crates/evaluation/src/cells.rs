//! The qualitative figure of a cell: time and ground truth over both segments of an evaluation
//! flight, one trace per method.

use data::Condition;
use faer::Mat;
use learn::Formulation;
use report::{MethodTrace, OutputAxis, QualitativeFigure};

use crate::error::Result;
use crate::segment::Segment;

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
    use super::*;

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
