//! Chooses LeARN settings without touching any evaluation flight of the fold they serve: nested
//! leave-one-condition-out validation inside each fold's meta-training set
//! ([`Experiment::nested_validation`]). For fold c, a candidate's score is the mean, over the other
//! evaluation conditions c′, of the generalisation MSE on c′'s evaluation flight after meta-training
//! on fold c's flights without condition c′. Prints, per formulation and fold, every candidate's
//! score and the one fold c's own validation prefers, and writes all numbers as JSON.
//!
//! cargo run -p learn --example select_settings -- [OUT_JSON] [SEED] [grid|iterations|averaging|adaptation-averaging|lipschitz|batch|passes|outer|regularisation|window|basis|clamp|tasks]

use std::collections::BTreeMap;
use std::path::Path;

use data::{ExperimentConditions, Formulation};
use learn::{AdaptationConfig, Experiment, LearnConfig, Protocol};
use rayon::prelude::*;
use serde_json::json;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let arguments: Vec<String> = std::env::args().skip(1).collect();
    let out = arguments
        .first()
        .cloned()
        .unwrap_or_else(|| "results/.scratch/learn-selection.json".to_string());
    let seed: u64 = arguments.get(1).map_or(Ok(1), |s| s.parse())?;
    // `grid` (the default): the first comparison; `iterations`: how far more meta-iterations help;
    // `averaging`: whether averaging the last meta-iterates (Polyak–Ruppert) helps;
    // `adaptation-averaging`: whether averaged SGD in the online adaptation helps;
    // `lipschitz`: the weight λ and bound L of the adaptation's Lipschitz regulariser;
    // `batch`: support and query batches of 128 points per task instead of 64;
    // `passes`: more adaptation passes (8, 16, 24) at the configured and at half the step;
    // `outer`: the outer (Adam) step β at half and twice the configured value;
    // `regularisation`: the meta-regulariser μ from 0 to 1e-3;
    // `window`: adaptation updates on windows of 2 or 4 consecutive samples (1: the paper);
    // `basis`: P = 1 or 3 learned basis functions per input instead of the paper's 2;
    // `clamp`: inputs clamped to the range they span in the meta-training flights;
    // `tasks`: one meta-training task per wind condition (the paper's task) instead of per flight.
    let stage = arguments.get(2).map_or("grid", String::as_str);
    let checked = LearnConfig::load(Path::new("experiments/learn.json"))?;
    let base = checked.get().clone();
    let conditions = ExperimentConditions::load(Path::new("experiments/conditions.json"))?;
    let data_dir = data::resolve_data_dir(None)?;
    let experiment = Experiment::load(
        checked,
        conditions,
        &data_dir,
        Some(Protocol::LeaveConditionOut),
    )?;
    let folds = experiment.evaluation_conditions();

    // Meta-training candidates (all within the reproduce budget: iterations × tasks ≤ 3200).
    let mut candidates: Vec<(String, LearnConfig)> = Vec::new();
    // (iterations, tasks, α, iterates averaged)
    let grid: &[(usize, usize, f64, usize)] = match stage {
        "iterations" => &[(800, 4, 0.1, 0), (1600, 4, 0.1, 0)],
        "averaging" => &[(800, 4, 0.1, 0), (800, 4, 0.1, 200), (800, 4, 0.1, 400)],
        "adaptation-averaging"
        | "lipschitz"
        | "batch"
        | "passes"
        | "outer"
        | "regularisation"
        | "window"
        | "basis"
        | "clamp"
        | "tasks" => &[(800, 4, 0.1, 0)],
        _ => &[
            (200, 4, 0.1, 0),
            (800, 4, 0.1, 0),
            (400, 8, 0.1, 0),
            (800, 4, 0.05, 0),
        ],
    };
    for &(iterations, task_batch, inner_step, average_last) in grid {
        let mut config = base.clone();
        config.meta_training.iterations = iterations;
        config.meta_training.task_batch = task_batch;
        config.meta_training.inner_step = inner_step;
        config.meta_training.average_last = average_last;
        let averaged = if average_last > 0 {
            format!("_average{average_last}")
        } else {
            String::new()
        };
        candidates.push((
            format!("it{iterations}_tasks{task_batch}_alpha{inner_step}{averaged}"),
            config,
        ));
    }
    if stage == "batch" {
        let mut config = candidates[0].1.clone();
        config.meta_training.support_batch = 128;
        config.meta_training.query_batch = 128;
        candidates.push(("it800_tasks4_alpha0.1_batch128".to_string(), config));
    }
    if stage == "outer" {
        for factor in [0.5, 2.0] {
            let mut config = candidates[0].1.clone();
            config.meta_training.outer_step *= factor;
            let name = format!(
                "it800_tasks4_alpha0.1_beta{}",
                config.meta_training.outer_step
            );
            candidates.push((name, config));
        }
    }
    if stage == "basis" {
        for basis_per_input in [1, 3] {
            let mut config = candidates[0].1.clone();
            config.basis_per_input = basis_per_input;
            candidates.push((format!("it800_tasks4_alpha0.1_P{basis_per_input}"), config));
        }
    }
    if stage == "clamp" {
        let mut config = candidates[0].1.clone();
        config.clamp_inputs = true;
        candidates.push(("it800_tasks4_alpha0.1_clamped".to_string(), config));
    }
    if stage == "tasks" {
        // One task per wind condition. A nested-validation meta-training set holds three
        // conditions (a fold's holds four), so a batch draws at most three: three tasks of 64
        // points, and two tasks of 128 points (the same points per meta-iteration as now).
        for (task_batch, points) in [(3, 64), (2, 128)] {
            let mut config = candidates[0].1.clone();
            config.meta_training.tasks = learn::TaskGrouping::Condition;
            config.meta_training.task_batch = task_batch;
            config.meta_training.support_batch = points;
            config.meta_training.query_batch = points;
            candidates.push((
                format!("it800_conditions{task_batch}_batch{points}_alpha0.1"),
                config,
            ));
        }
    }
    if stage == "regularisation" {
        for mu in [0.0, 1e-4, 1e-3] {
            let mut config = candidates[0].1.clone();
            config.meta_training.meta_regularisation = mu;
            candidates.push((format!("it800_tasks4_alpha0.1_mu{mu}"), config));
        }
    }
    let adaptations: Vec<(String, AdaptationConfig)> = if stage == "window" {
        // (window, step) at the configured passes: the same step, and the step scaled with the
        // window (the same distance per pass as one-sample updates).
        [(1, 0.0005), (2, 0.0005), (2, 0.001), (4, 0.001), (4, 0.002)]
            .into_iter()
            .map(|(window, step)| {
                (
                    format!("window{window}_step{step}_passes{}", base.adaptation.passes),
                    AdaptationConfig {
                        window,
                        step,
                        ..base.adaptation.clone()
                    },
                )
            })
            .collect()
    } else if stage == "lipschitz" {
        // λ = 0 (no regulariser), then λ × L; the other adaptation settings as configured.
        [
            (0.0, 1.0),
            (0.01, 1.0),
            (0.01, 0.1),
            (0.1, 1.0),
            (0.1, 0.1),
            (1.0, 1.0),
            (1.0, 0.1),
        ]
        .into_iter()
        .map(|(lipschitz_weight, lipschitz_bound)| {
            (
                format!("lambda{lipschitz_weight}_bound{lipschitz_bound}"),
                AdaptationConfig {
                    lipschitz_weight,
                    lipschitz_bound,
                    ..base.adaptation.clone()
                },
            )
        })
        .collect()
    } else {
        let passes_grid: &[usize] = match stage {
            "grid" => &[4, 8],
            "passes" => &[8, 16, 24],
            "basis" | "clamp" | "tasks" => &[16],
            _ => &[8],
        };
        // (step, averaged SGD over the last pass)
        let steps: &[(f64, bool)] = match stage {
            "averaging" => &[(0.0005, false)],
            "adaptation-averaging" => &[(0.0005, false), (0.0005, true), (0.001, true)],
            "passes" | "outer" | "regularisation" => &[(0.0005, false), (0.00025, false)],
            "basis" | "clamp" | "tasks" => &[(0.0005, false)],
            _ => &[(0.0005, false), (0.001, false)],
        };
        let mut adaptations = Vec::new();
        for &(step, average_last_pass) in steps {
            for &passes in passes_grid {
                let averaged = if average_last_pass { "_averaged" } else { "" };
                adaptations.push((
                    format!("step{step}_passes{passes}{averaged}"),
                    AdaptationConfig {
                        step,
                        passes,
                        average_last_pass,
                        ..base.adaptation.clone()
                    },
                ));
            }
        }
        adaptations
    };
    let adaptation_settings: Vec<AdaptationConfig> =
        adaptations.iter().map(|(_, a)| a.clone()).collect();

    let mut jobs = Vec::new();
    for formulation in [
        Formulation::Translational,
        Formulation::Attitude,
        Formulation::Full,
    ] {
        for (i, a) in folds.iter().enumerate() {
            for b in &folds[i + 1..] {
                for candidate in 0..candidates.len() {
                    jobs.push((formulation, a.clone(), b.clone(), candidate));
                }
            }
        }
    }
    eprintln!("{} meta-trainings", jobs.len());
    let results: Vec<[Vec<f64>; 2]> = jobs
        .par_iter()
        .map(|(formulation, a, b, candidate)| {
            experiment.nested_validation(
                *formulation,
                [a, b],
                &candidates[*candidate].1,
                &adaptation_settings,
                seed,
            )
        })
        .collect::<Result<_, _>>()?;

    // score[(formulation, fold, candidate, adaptation)] = scores on the other conditions.
    let mut scores: BTreeMap<(String, String, usize, usize), Vec<f64>> = BTreeMap::new();
    for ((formulation, a, b, candidate), [on_a, on_b]) in jobs.iter().zip(&results) {
        for adaptation in 0..adaptations.len() {
            // Fold a's validation scores condition b, and fold b's scores condition a.
            scores
                .entry((
                    formulation.name().to_string(),
                    a.clone(),
                    *candidate,
                    adaptation,
                ))
                .or_default()
                .push(on_b[adaptation]);
            scores
                .entry((
                    formulation.name().to_string(),
                    b.clone(),
                    *candidate,
                    adaptation,
                ))
                .or_default()
                .push(on_a[adaptation]);
        }
    }
    let mut report = Vec::new();
    for ((formulation, fold, candidate, adaptation), values) in &scores {
        let mean = values.iter().sum::<f64>() / values.len() as f64;
        report.push(json!({
            "formulation": formulation,
            "fold": fold,
            "meta_training": candidates[*candidate].0,
            "adaptation": adaptations[*adaptation].0,
            "validation_gen_mse": mean,
            "per_condition": values,
        }));
    }
    // Per formulation and fold: the preferred setting, and the ranking of the averaged score.
    let mut best: BTreeMap<(String, String), (f64, String)> = BTreeMap::new();
    for row in &report {
        let key = (
            row["formulation"].as_str().unwrap_or_default().to_string(),
            row["fold"].as_str().unwrap_or_default().to_string(),
        );
        let value = row["validation_gen_mse"].as_f64().unwrap_or(f64::INFINITY);
        let name = format!("{} {}", row["meta_training"], row["adaptation"]);
        let entry = best.entry(key).or_insert((f64::INFINITY, String::new()));
        if value < entry.0 {
            *entry = (value, name);
        }
    }
    for ((formulation, fold), (value, name)) in &best {
        println!("{formulation:14} {fold:10} best {name} ({value:.4})");
    }
    let mut table: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    for row in &report {
        let name = format!(
            "{} {} {}",
            row["formulation"].as_str().unwrap_or_default(),
            row["meta_training"],
            row["adaptation"]
        );
        table
            .entry(name)
            .or_default()
            .push(row["validation_gen_mse"].as_f64().unwrap_or(f64::NAN));
    }
    for (name, values) in &table {
        let formatted: Vec<String> = values.iter().map(|v| format!("{v:.4}")).collect();
        println!("{name:70} folds {}", formatted.join(" "));
    }
    let document = json!({
        "protocol": "nested leave-one-condition-out inside each fold's meta-training set",
        "seed": seed,
        "folds": folds,
        "scores": report,
        "preferred": best.iter().map(|((f, c), (v, n))| json!({"formulation": f, "fold": c, "setting": n, "validation_gen_mse": v})).collect::<Vec<_>>(),
    });
    if let Some(parent) = Path::new(&out).parent() {
        std::fs::create_dir_all(parent)?;
    }
    std::fs::write(&out, serde_json::to_string_pretty(&document)? + "\n")?;
    eprintln!("wrote {out}");
    Ok(())
}
