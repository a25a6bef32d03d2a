//! Timing of the paper's SINDy baseline (run by `make bench` through `scripts/bench/sindy.sh`;
//! `cargo bench --profile dev -p evaluation --bench sindy_paper`). Prints readable lines, then one `BENCH_JSON {...}` line.
//!
//! - one fit (library + STLSQ + refit) of each formulation on the 35wind support segment;
//! - the whole 12-cell table: reading and parsing the four CSV files (in parallel), building the
//!   segments, fitting and predicting; plus that total without the CSV parsing.
//!
//! Each number is the median of repeated runs. Needs the flight data (`make data`).

use std::hint::black_box;
use std::path::PathBuf;
use std::time::Instant;

use data::{ExperimentConditions, FlightLog, SplitSpec, resolve_data_dir};
use evaluation::Segment;
use evaluation::{SindyConfig, evaluate_flight};
use learn::Formulation;
use rayon::prelude::*;
use sindy::{Derivative, FeatureLibrary, SindyParams};
use statrs::statistics::{Data, OrderStatistics};

fn median_seconds(runs: usize, mut work: impl FnMut()) -> f64 {
    let times: Vec<f64> = (0..runs)
        .map(|_| {
            let start = Instant::now();
            work();
            start.elapsed().as_secs_f64()
        })
        .collect();
    // Of an even count the larger middle value.
    Data::new(times).order_statistic(runs / 2 + 1)
}

fn flight_paths() -> Vec<(String, PathBuf)> {
    let workspace = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let conditions = ExperimentConditions::load(&workspace.join("experiments/conditions.json"))
        .expect("experiments/conditions.json");
    let data_dir = resolve_data_dir(None)
        .or_else(|_| resolve_data_dir(Some(&workspace.join("data/neural-fly"))))
        .expect("flight data (run `make data`)");
    conditions
        .evaluation()
        .map(|c| {
            let path = conditions.flight_path(&data_dir, c, &conditions.evaluation_controller);
            (c.label().to_string(), path)
        })
        .collect()
}

fn table(paths: &[(String, PathBuf)], config: &SindyConfig) -> Vec<f64> {
    let logs: Vec<FlightLog> = paths
        .par_iter()
        .map(|(_, path)| FlightLog::read(path).expect("a valid flight"))
        .collect();
    cells(&logs, config)
}

fn cells(logs: &[FlightLog], config: &SindyConfig) -> Vec<f64> {
    let jobs: Vec<(&FlightLog, Formulation)> = logs
        .iter()
        .flat_map(|log| Formulation::ALL.map(|f| (log, f)))
        .collect();
    jobs.par_iter()
        .flat_map(|(log, formulation)| {
            let e = evaluate_flight(
                config,
                log,
                *formulation,
                SplitSpec::Halves,
                Derivative::Forward,
            )
            .expect("a cell");
            [e.adaptation, e.generalisation]
        })
        .collect()
}

fn main() {
    let paths = flight_paths();
    let config = SindyConfig::paper();
    let first = FlightLog::read(&paths[0].1).expect("a valid flight");
    let split = SplitSpec::Halves.split(first.len()).unwrap();
    let mut fits = Vec::new();
    for formulation in Formulation::ALL {
        let support = Segment::cut(
            &first,
            formulation,
            split.support.clone(),
            Derivative::Forward,
        )
        .unwrap();
        let inputs = support.inputs();
        let params = SindyParams::new(&formulation.state_names(), &formulation.control_names())
            .library(FeatureLibrary::from_spec(&config.library).unwrap())
            .optimizer(config.optimizer);
        let seconds = median_seconds(301, || {
            black_box(
                params
                    .fit_matrices(inputs.as_ref(), support.targets.as_ref())
                    .unwrap(),
            );
        });
        println!(
            "rust  one fit {:<13} ({} samples): {:>9.1} µs",
            formulation.name(),
            support.len(),
            seconds * 1e6
        );
        fits.push((formulation.name(), seconds));
    }
    let logs: Vec<FlightLog> = paths
        .iter()
        .map(|(_, p)| FlightLog::read(p).unwrap())
        .collect();
    let parse = median_seconds(5, || {
        black_box(
            paths
                .par_iter()
                .map(|(_, p)| FlightLog::read(p).unwrap())
                .collect::<Vec<_>>(),
        );
    });
    let fitting = median_seconds(21, || {
        black_box(cells(&logs, &config));
    });
    let whole = median_seconds(5, || {
        black_box(table(&paths, &config));
    });
    println!(
        "rust  CSV parsing of the 4 flights (parallel): {:>9.1} ms",
        parse * 1e3
    );
    println!(
        "rust  12 cells without parsing:                 {:>9.1} ms",
        fitting * 1e3
    );
    println!(
        "rust  whole 12-cell table incl. CSV parsing:    {:>9.1} ms",
        whole * 1e3
    );
    let fits_json: Vec<String> = fits
        .iter()
        .map(|(name, s)| format!("\"{name}\": {s:e}"))
        .collect();
    println!(
        "BENCH_JSON {{\"fit\": {{{}}}, \"parse\": {parse:e}, \"cells\": {fitting:e}, \"table\": {whole:e}, \"threads\": {}}}",
        fits_json.join(", "),
        rayon::current_num_threads()
    );
}
