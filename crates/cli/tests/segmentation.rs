//! A run configuration's `split` and `derivative` are honoured, not only accepted: every cell of a
//! run is cut with them, and SINDy and LeARN are scored against the targets they give. On the
//! small generated experiment (`common::sweep`), through the library (`evaluation::run`).

mod common;

use std::path::Path;

use common::sweep::small_experiment;
use common::{scratch, workspace};
use evaluation::Segment;
use learn::Formulation;
use serde_json::{Value, json};
use sindy::Derivative;

fn read_json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Mean over samples `range` and every output of (prediction − truth)², as the tables score.
fn mse(prediction: &[Vec<f64>], truth: &[Vec<f64>], range: std::ops::Range<usize>) -> f64 {
    let mut sum = 0.0;
    for (p, t) in prediction.iter().zip(truth) {
        sum += range.clone().map(|i| (p[i] - t[i]).powi(2)).sum::<f64>();
    }
    sum / (range.len() * truth.len()) as f64
}

#[test]
fn a_run_cuts_every_cell_with_the_configured_split_and_derivative() {
    let dir = scratch("segmentation");
    let experiment = small_experiment(&dir);
    let mut run = read_json(&experiment.run);
    run["split"] = json!({"kind": "fraction", "support": 0.75});
    run["derivative"] = json!({"kind": "central"});
    run["learn"]["seeds"] = json!([1]);
    std::fs::write(&experiment.run, run.to_string()).unwrap();
    let config = evaluation::RunConfig::load(&experiment.run, &workspace()).unwrap();
    let outcome = evaluation::run(
        &config,
        &experiment.data,
        &workspace(),
        &evaluation::NoProgress,
    )
    .unwrap();
    // Every formulation × the two evaluation conditions, each flight 400 samples: 300 / 100.
    assert_eq!(outcome.figures.len(), 6);
    assert_eq!(outcome.summary.cells.len(), 6);
    for cell in &outcome.summary.cells {
        assert_eq!((cell.support_rows, cell.query_rows), ([0, 300], [300, 400]));
    }
    for (name, figure) in &outcome.figures {
        let formulation = Formulation::parse(&figure.table).unwrap();
        let path = experiment.data.join(format!(
            "experiment/custom_figure8_baseline_{}.csv",
            figure.condition
        ));
        let log = data::FlightLog::read(&path).unwrap();
        let cut = |rows| Segment::cut(&log, formulation, rows, Derivative::Central).unwrap();
        let (support, query) = (cut(0..300), cut(300..400));
        assert_eq!(figure.split, 300, "{name}");
        // The truth the methods were scored against: central differences on each segment.
        for (j, truth) in figure.truth.iter().enumerate() {
            let expected: Vec<f64> = (0..300)
                .map(|i| support.targets[(i, j)])
                .chain((0..100).map(|i| query.targets[(i, j)]))
                .collect();
            assert_eq!(truth, &expected, "{name} output {j}");
        }
        let record = outcome
            .summary
            .cells
            .iter()
            .find(|c| c.table == figure.table && c.label == figure.condition)
            .unwrap();
        let scored = [
            (
                "SINDy",
                record.sindy.adaptation,
                record.sindy.generalisation,
            ),
            (
                "LeARN",
                record.learn.adaptation,
                record.learn.generalisation,
            ),
        ];
        for (method, adaptation, generalisation) in scored {
            let trace = figure.methods.iter().find(|m| m.method == method).unwrap();
            let close = |a: f64, b: f64| (a - b).abs() <= 1e-10 * b.abs().max(1e-12);
            let on_support = mse(&trace.prediction, &figure.truth, 0..300);
            let on_query = mse(&trace.prediction, &figure.truth, 300..400);
            assert!(close(adaptation, on_support), "{name} {method} adaptation");
            assert!(
                close(generalisation, on_query),
                "{name} {method} generalisation"
            );
        }
    }
}
