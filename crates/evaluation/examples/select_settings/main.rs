//! Chooses LeARN settings without touching any evaluation flight of the fold they serve: nested
//! leave-one-condition-out validation inside each fold's meta-training set
//! ([`Experiment::nested_validation`]). For fold c, a candidate's score is the mean, over the other
//! evaluation conditions c′, of the generalisation MSE on c′'s evaluation flight after meta-training
//! on fold c's flights without condition c′. Prints, per formulation and fold, every candidate's
//! score and the one fold c's own validation prefers, and writes all numbers as JSON.
//!
//! cargo run -p evaluation --example select_settings -- [OUT_JSON] [SEED] [STAGE]
//!
//! STAGE (default `grid`) is one of the comparisons of [`stage::Stage`]: grid, iterations,
//! averaging, adaptation-averaging, lipschitz, batch, passes, outer, regularisation, window, basis,
//! clamp, tasks, restarts.

mod restarts;
mod stage;

use std::collections::BTreeMap;
use std::path::Path;

use data::ExperimentConditions;
use evaluation::{Experiment, Protocol, Segmentation};
use learn::{AdaptationConfig, Formulation, LearnConfig};
use rayon::prelude::*;
use serde::Serialize;

use stage::Stage;

/// How the scores were obtained (written with them).
const NESTED_PROTOCOL: &str = "nested leave-one-condition-out inside each fold's meta-training set";

/// One candidate's validation score on one formulation and fold (fields in the JSON's order).
#[derive(Serialize)]
struct ScoreRow {
    adaptation: String,
    fold: String,
    formulation: String,
    meta_training: String,
    per_condition: Vec<f64>,
    validation_gen_mse: f64,
}

/// The setting a fold's own validation prefers.
#[derive(Serialize)]
struct Preferred {
    fold: String,
    formulation: String,
    setting: String,
    validation_gen_mse: f64,
}

#[derive(Serialize)]
struct SelectionDocument<'a> {
    folds: &'a [String],
    preferred: Vec<Preferred>,
    protocol: &'static str,
    scores: Vec<ScoreRow>,
    seed: u64,
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let arguments: Vec<String> = std::env::args().skip(1).collect();
    let out = arguments
        .first()
        .cloned()
        .unwrap_or_else(|| "results/.scratch/learn-selection.json".to_string());
    let seed: u64 = arguments.get(1).map_or(Ok(1), |s| s.parse())?;
    let stage = Stage::parse(arguments.get(2).map_or("grid", String::as_str))?;
    let checked = LearnConfig::load(Path::new("experiments/learn.json"))?;
    let base = checked.get().clone();
    let conditions = ExperimentConditions::load(Path::new("experiments/conditions.json"))?;
    let data_dir = data::resolve_data_dir(None)?;
    let experiment = Experiment::load(
        checked,
        conditions,
        &data_dir,
        Some(Protocol::LeaveConditionOut),
        Segmentation::PAPER,
    )?;
    let folds = experiment.evaluation_conditions();
    if stage == Stage::Restarts {
        return restarts::restarts(&experiment, &folds, &out);
    }
    let candidates = stage::meta_training_candidates(stage, &base);
    let adaptations = stage::adaptation_candidates(stage, &base);
    let scores = validation_scores(&experiment, &folds, &candidates, &adaptations, seed)?;
    let rows: Vec<ScoreRow> = scores
        .into_iter()
        .map(
            |((formulation, fold, candidate, adaptation), values)| ScoreRow {
                adaptation: adaptations[adaptation].0.clone(),
                fold,
                formulation,
                meta_training: candidates[candidate].0.clone(),
                validation_gen_mse: values.iter().sum::<f64>() / values.len() as f64,
                per_condition: values,
            },
        )
        .collect();
    let preferred = preferred_settings(&rows);
    print_scores(&rows, &preferred);
    let document = SelectionDocument {
        folds: &folds,
        preferred,
        protocol: NESTED_PROTOCOL,
        scores: rows,
        seed,
    };
    write_document(&out, &document)
}

/// Key of a score: formulation, fold, candidate and adaptation setting (indices).
type ScoreKey = (String, String, usize, usize);

/// Meta-trains every candidate on every nested pair and scores every adaptation setting:
/// for each key, the generalisation MSEs on the fold's other conditions.
fn validation_scores(
    experiment: &Experiment,
    folds: &[String],
    candidates: &[(String, LearnConfig)],
    adaptations: &[(String, AdaptationConfig)],
    seed: u64,
) -> Result<BTreeMap<ScoreKey, Vec<f64>>, Box<dyn std::error::Error>> {
    let settings: Vec<AdaptationConfig> = adaptations.iter().map(|(_, a)| a.clone()).collect();
    let indices: Vec<usize> = (0..candidates.len()).collect();
    let jobs = pair_jobs(folds, &indices);
    eprintln!("{} meta-trainings", jobs.len());
    let results: Vec<[Vec<f64>; 2]> = jobs
        .par_iter()
        .map(|(formulation, a, b, candidate)| {
            experiment.nested_validation(
                *formulation,
                [a, b],
                &candidates[*candidate].1,
                &settings,
                seed,
            )
        })
        .collect::<Result<_, _>>()?;
    let mut scores: BTreeMap<ScoreKey, Vec<f64>> = BTreeMap::new();
    for ((formulation, a, b, candidate), [on_a, on_b]) in jobs.iter().zip(&results) {
        let name = formulation.name().to_string();
        for adaptation in 0..adaptations.len() {
            // Fold a's validation scores condition b, and fold b's scores condition a.
            scores
                .entry((name.clone(), a.clone(), *candidate, adaptation))
                .or_default()
                .push(on_b[adaptation]);
            scores
                .entry((name.clone(), b.clone(), *candidate, adaptation))
                .or_default()
                .push(on_a[adaptation]);
        }
    }
    Ok(scores)
}

/// Per formulation and fold, the setting with the lowest averaged score.
fn preferred_settings(rows: &[ScoreRow]) -> Vec<Preferred> {
    let mut best: BTreeMap<(&str, &str), (f64, String)> = BTreeMap::new();
    for row in rows {
        let entry = best
            .entry((&row.formulation, &row.fold))
            .or_insert((f64::INFINITY, String::new()));
        if row.validation_gen_mse < entry.0 {
            *entry = (
                row.validation_gen_mse,
                format!("{} {}", row.meta_training, row.adaptation),
            );
        }
    }
    best.into_iter()
        .map(|((formulation, fold), (value, setting))| Preferred {
            fold: fold.to_string(),
            formulation: formulation.to_string(),
            setting,
            validation_gen_mse: value,
        })
        .collect()
}

/// The preferred setting per formulation and fold, then every setting's score per fold.
fn print_scores(rows: &[ScoreRow], preferred: &[Preferred]) {
    for p in preferred {
        println!(
            "{:14} {:10} best {} ({:.4})",
            p.formulation, p.fold, p.setting, p.validation_gen_mse
        );
    }
    let mut table: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    for row in rows {
        let name = format!(
            "{} {} {}",
            row.formulation, row.meta_training, row.adaptation
        );
        table.entry(name).or_default().push(row.validation_gen_mse);
    }
    for (name, values) in &table {
        let formatted: Vec<String> = values.iter().map(|v| format!("{v:.4}")).collect();
        println!("{name:70} folds {}", formatted.join(" "));
    }
}

/// One job per formulation, unordered pair of folds (a before b) and item (a candidate, a seed).
fn pair_jobs<T: Copy>(folds: &[String], items: &[T]) -> Vec<(Formulation, String, String, T)> {
    let mut jobs = Vec::new();
    for formulation in [
        Formulation::Translational,
        Formulation::Attitude,
        Formulation::Full,
    ] {
        for (i, a) in folds.iter().enumerate() {
            for b in &folds[i + 1..] {
                for &item in items {
                    jobs.push((formulation, a.clone(), b.clone(), item));
                }
            }
        }
    }
    jobs
}

/// Writes `document` as pretty JSON to `out`, creating its folder.
fn write_document(out: &str, document: &impl Serialize) -> Result<(), Box<dyn std::error::Error>> {
    if let Some(parent) = Path::new(out).parent() {
        std::fs::create_dir_all(parent)?;
    }
    std::fs::write(out, serde_json::to_string_pretty(document)? + "\n")?;
    eprintln!("wrote {out}");
    Ok(())
}
