//! Stage `restarts`: is a model built from several initialisations better than one?

use std::collections::BTreeMap;

use evaluation::{Experiment, ValidationDetail};
use rayon::prelude::*;
use serde::Serialize;

use crate::{NESTED_PROTOCOL, ScoreRow, pair_jobs, write_document};

/// Seeds meta-trained per model, and how many of them a strategy draws.
const RESTART_SEEDS: [u64; 6] = [1, 2, 3, 4, 5, 6];
const RESTART_GROUP: usize = 3;
/// The share of the support segment held out (its end) to score an initialisation.
const SUPPORT_TAIL: f64 = 0.2;

/// A way to build one model from a group of seeds (indices into the per-seed details), scored by
/// its generalisation MSE.
type Strategy = fn(&[&ValidationDetail], &[usize]) -> f64;

/// Per formulation: each strategy's mean over the folds, and how well the support tail ranks seeds.
#[derive(Serialize)]
struct FormulationSummary {
    formulation: String,
    mean_over_folds: BTreeMap<String, f64>,
    support_tail_query_correlation: f64,
}

#[derive(Serialize)]
struct RestartsDocument<'a> {
    folds: &'a [String],
    group_size: usize,
    protocol: &'static str,
    scores: Vec<ScoreRow>,
    seeds: [u64; 6],
    summary: Vec<FormulationSummary>,
    support_tail_fraction: f64,
}

/// For every nested pair and seed of [`RESTART_SEEDS`], meta-trains and adapts with the configured
/// settings ([`Experiment::nested_validation_detail`]). For every group of [`RESTART_GROUP`] seeds,
/// three strategies: `select-by-support-tail` keeps the seed whose model, adapted on the first 80%
/// of the support segment, scores best on its last 20% (uses the support segment only);
/// `ensemble` averages the adapted models' predictions (no longer the paper's single pair of
/// networks); `best-by-query` keeps the seed with the lowest generalisation MSE (unattainable: it
/// looks at the query, a reference for how much choosing could give). `single-seed` is the mean
/// over the seeds. A strategy's score is its mean over all groups.
pub fn restarts(
    experiment: &Experiment,
    folds: &[String],
    out: &str,
) -> Result<(), Box<dyn std::error::Error>> {
    let jobs = pair_jobs(folds, &RESTART_SEEDS);
    eprintln!("{} meta-trainings", jobs.len());
    let results: Vec<[ValidationDetail; 2]> = jobs
        .par_iter()
        .map(|(formulation, a, b, seed)| {
            experiment.nested_validation_detail(*formulation, [a, b], *seed, SUPPORT_TAIL)
        })
        .collect::<Result<_, _>>()?;
    // details[(formulation, fold, validated condition)][seed index]: fold a's validation scores
    // condition b and fold b's scores condition a.
    let mut details: BTreeMap<(String, String, String), Vec<&ValidationDetail>> = BTreeMap::new();
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
    let mut scores = Vec::new();
    let summary = ["translational", "attitude", "full"]
        .into_iter()
        .map(|formulation| summarise(formulation, folds, &details, &mut scores))
        .collect();
    let document = RestartsDocument {
        folds,
        group_size: RESTART_GROUP,
        protocol: NESTED_PROTOCOL,
        scores,
        seeds: RESTART_SEEDS,
        summary,
        support_tail_fraction: SUPPORT_TAIL,
    };
    write_document(out, &document)
}

/// Every strategy's score per fold of one formulation (pushed to `scores` and printed), and
/// their means.
fn summarise(
    formulation: &str,
    folds: &[String],
    details: &BTreeMap<(String, String, String), Vec<&ValidationDetail>>,
    scores: &mut Vec<ScoreRow>,
) -> FormulationSummary {
    let groups = groups_of(RESTART_SEEDS.len(), RESTART_GROUP);
    let correlations: Vec<f64> = details
        .iter()
        .filter(|((f, _, _), _)| f == formulation)
        .map(|(_, seeds)| {
            let tail: Vec<f64> = seeds.iter().map(|d| d.support_tail_mse).collect();
            let query: Vec<f64> = seeds.iter().map(|d| d.generalisation).collect();
            correlation(&tail, &query)
        })
        .collect();
    let mut mean_over_folds = BTreeMap::new();
    for (name, strategy) in strategies() {
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
            scores.push(ScoreRow {
                adaptation: "configured".to_string(),
                fold: fold.clone(),
                formulation: formulation.to_string(),
                meta_training: name.to_string(),
                per_condition,
                validation_gen_mse: mean,
            });
        }
        let mean = fold_scores.iter().sum::<f64>() / fold_scores.len() as f64;
        mean_over_folds.insert(name.to_string(), mean);
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
    FormulationSummary {
        formulation: formulation.to_string(),
        mean_over_folds,
        support_tail_query_correlation: correlation,
    }
}

/// The strategies compared, named.
fn strategies() -> [(&'static str, Strategy); 4] {
    [
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
    ]
}

/// Every subset of `size` indices out of `0..count`, in lexicographic order.
fn groups_of(count: usize, size: usize) -> Vec<Vec<usize>> {
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
    let mut groups = Vec::new();
    extend(0, count, size, &mut Vec::with_capacity(size), &mut groups);
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
