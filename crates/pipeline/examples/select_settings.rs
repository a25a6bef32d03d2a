//! Chooses LeARN settings without touching any evaluation flight of the fold they serve: nested
//! leave-one-condition-out validation inside each fold's meta-training set
//! ([`Experiment::nested_validation`]). For fold c, a candidate's score is the mean, over the other
//! evaluation conditions c′, of the generalisation MSE on c′'s evaluation flight after meta-training
//! on fold c's flights without condition c′. Prints, per formulation and fold, every candidate's
//! score and the one fold c's own validation prefers, and writes all numbers as JSON.
//!
//! cargo run -p pipeline --example select_settings -- [OUT_JSON] [SEED] [grid|iterations|averaging|adaptation-averaging|lipschitz|batch|passes|outer|regularisation|window|basis|clamp|tasks|restarts]

use std::collections::BTreeMap;
use std::path::Path;

use data::ExperimentConditions;
use learn::{AdaptationConfig, Formulation, LearnConfig};
use pipeline::{Experiment, Protocol, Segmentation};
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
    // `tasks`: one meta-training task per wind condition (the paper's task) instead of per flight;
    // `restarts`: several initialisations (seeds) per model, keeping the one with the lowest
    // support-tail MSE, or averaging their predictions (an ensemble), against a single seed.
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
        Segmentation::PAPER,
    )?;
    let folds = experiment.evaluation_conditions();
    if stage == "restarts" {
        return restarts(&experiment, &folds, &out);
    }

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

    let candidate_indices: Vec<usize> = (0..candidates.len()).collect();
    let jobs = pair_jobs(&folds, &candidate_indices);
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

/// Seeds meta-trained per model in stage `restarts`, and how many of them a strategy draws.
const RESTART_SEEDS: [u64; 6] = [1, 2, 3, 4, 5, 6];
const RESTART_GROUP: usize = 3;
/// The share of the support segment held out (its end) to score an initialisation.
const SUPPORT_TAIL: f64 = 0.2;

/// Stage `restarts`: is a model built from several initialisations better than one? For every
/// nested pair and seed of [`RESTART_SEEDS`], meta-trains and adapts with the configured settings
/// ([`Experiment::nested_validation_detail`]). For every group of [`RESTART_GROUP`] seeds, three
/// strategies: `select-by-support-tail` keeps the seed whose model, adapted on the first 80% of the
/// support segment, scores best on its last 20% (uses the support segment only); `ensemble`
/// averages the adapted models' predictions (no longer the paper's single pair of networks);
/// `best-by-query` keeps the seed with the lowest generalisation MSE (unattainable: it looks at
/// the query, a reference for how much choosing could give). `single-seed` is the mean over the
/// seeds. A strategy's score is its mean over all groups.
fn restarts(
    experiment: &Experiment,
    folds: &[String],
    out: &str,
) -> Result<(), Box<dyn std::error::Error>> {
    let jobs = pair_jobs(folds, &RESTART_SEEDS);
    eprintln!("{} meta-trainings", jobs.len());
    let results: Vec<[pipeline::ValidationDetail; 2]> = jobs
        .par_iter()
        .map(|(formulation, a, b, seed)| {
            experiment.nested_validation_detail(*formulation, [a, b], *seed, SUPPORT_TAIL)
        })
        .collect::<Result<_, _>>()?;
    // details[(formulation, fold, validated condition)][seed index]: fold a's validation scores
    // condition b and fold b's scores condition a.
    let mut details: BTreeMap<(String, String, String), Vec<&pipeline::ValidationDetail>> =
        BTreeMap::new();
    for ((formulation, a, b, _), [on_a, on_b]) in jobs.iter().zip(&results) {
        let name = formulation.name().to_string();
        details
            .entry((name.clone(), a.clone(), b.clone()))
            .or_default()
            .push(on_b);
        details
            .entry((name, b.clone(), a.clone()))
            .or_default()
            .push(on_a);
    }
    let groups = groups_of(RESTART_SEEDS.len(), RESTART_GROUP);
    let strategies: [(&str, Strategy); 4] = [
        ("single-seed", |seeds, _| {
            seeds.iter().map(|d| d.generalisation).sum::<f64>() / seeds.len() as f64
        }),
        ("select-by-support-tail", |seeds, group| {
            let chosen = group
                .iter()
                .min_by(|&&i, &&j| {
                    seeds[i]
                        .support_tail_mse
                        .total_cmp(&seeds[j].support_tail_mse)
                })
                .copied()
                .unwrap_or(0);
            seeds[chosen].generalisation
        }),
        ("ensemble", |seeds, group| {
            let targets = &seeds[group[0]].query_targets;
            let mut sum = 0.0;
            for (k, target) in targets.iter().enumerate() {
                let mean = group
                    .iter()
                    .map(|&i| seeds[i].query_predictions[k])
                    .sum::<f64>()
                    / group.len() as f64;
                sum += (mean - target) * (mean - target);
            }
            sum / targets.len() as f64
        }),
        ("best-by-query", |seeds, group| {
            group
                .iter()
                .map(|&i| seeds[i].generalisation)
                .fold(f64::INFINITY, f64::min)
        }),
    ];
    let mut report = Vec::new();
    let mut summary = Vec::new();
    for formulation in ["translational", "attitude", "full"] {
        let mut correlations = Vec::new();
        for ((f, _, _), seeds) in &details {
            if f == formulation {
                let tail: Vec<f64> = seeds.iter().map(|d| d.support_tail_mse).collect();
                let query: Vec<f64> = seeds.iter().map(|d| d.generalisation).collect();
                correlations.push(correlation(&tail, &query));
            }
        }
        let mut means = serde_json::Map::new();
        for (name, strategy) in &strategies {
            let mut fold_scores = Vec::new();
            for fold in folds {
                let per_condition: Vec<f64> = details
                    .iter()
                    .filter(|((f, c, _), _)| f == formulation && c == fold)
                    .map(|(_, seeds)| {
                        groups.iter().map(|g| strategy(seeds, g)).sum::<f64>() / groups.len() as f64
                    })
                    .collect();
                let mean = per_condition.iter().sum::<f64>() / per_condition.len() as f64;
                fold_scores.push(mean);
                report.push(json!({
                    "formulation": formulation,
                    "fold": fold,
                    "meta_training": name,
                    "adaptation": "configured",
                    "validation_gen_mse": mean,
                    "per_condition": per_condition,
                }));
            }
            let mean = fold_scores.iter().sum::<f64>() / fold_scores.len() as f64;
            means.insert(name.to_string(), json!(mean));
            let formatted: Vec<String> = fold_scores.iter().map(|v| format!("{v:.4}")).collect();
            println!(
                "{formulation:14} {name:24} mean {mean:.4} folds {}",
                formatted.join(" ")
            );
        }
        let correlation = correlations.iter().sum::<f64>() / correlations.len() as f64;
        println!(
            "{formulation:14} correlation of support-tail and generalisation MSE over seeds: {correlation:.2}"
        );
        summary.push(json!({
            "formulation": formulation,
            "mean_over_folds": means,
            "support_tail_query_correlation": correlation,
        }));
    }
    let document = json!({
        "protocol": "nested leave-one-condition-out inside each fold's meta-training set",
        "seeds": RESTART_SEEDS,
        "group_size": RESTART_GROUP,
        "support_tail_fraction": SUPPORT_TAIL,
        "folds": folds,
        "scores": report,
        "summary": summary,
    });
    if let Some(parent) = Path::new(out).parent() {
        std::fs::create_dir_all(parent)?;
    }
    std::fs::write(out, serde_json::to_string_pretty(&document)? + "\n")?;
    eprintln!("wrote {out}");
    Ok(())
}

/// A way to build one model from a group of seeds (indices into the per-seed details), scored by
/// its generalisation MSE.
type Strategy = fn(&[&pipeline::ValidationDetail], &[usize]) -> f64;

/// Every subset of `size` indices out of `0..count`, in lexicographic order.
fn groups_of(count: usize, size: usize) -> Vec<Vec<usize>> {
    let mut groups = Vec::new();
    let mut current = Vec::with_capacity(size);
    fn extend(
        start: usize,
        count: usize,
        size: usize,
        current: &mut Vec<usize>,
        groups: &mut Vec<Vec<usize>>,
    ) {
        if current.len() == size {
            groups.push(current.clone());
            return;
        }
        for i in start..count {
            current.push(i);
            extend(i + 1, count, size, current, groups);
            current.pop();
        }
    }
    extend(0, count, size, &mut current, &mut groups);
    groups
}

/// Pearson's correlation of two equally long samples (NaN if either is constant).
fn correlation(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (a, b) in x.iter().zip(y) {
        sxy += (a - mx) * (b - my);
        sxx += (a - mx) * (a - mx);
        syy += (b - my) * (b - my);
    }
    sxy / (sxx * syy).sqrt()
}
