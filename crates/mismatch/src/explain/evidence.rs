//! The evidence rule: an effect is named only when it buys an improvement clearly beyond noise.
//!
//! For every effect of the jointly fitted set, the set without it is refitted, and the effect
//! passes when all of these hold, each on the channels the effect acts on (its channel group:
//! translational, angular or both), so that a residual the vocabulary cannot explain in one group
//! does not hide an effect of the other:
//! - **significance** (fit part): the likelihood ratio `Λ = Σ_g ΔSSE_g / (κ_g s²_g)` over the
//!   effect's groups `g` is at least the `significance` quantile of χ² with as many degrees of
//!   freedom as the effect has parameters. `ΔSSE_g` is the noise-normalised sum of squares the
//!   effect removes from group `g`, `s²_g` the full model's residual variance per row and channel
//!   of that group (noise-normalised, ≈ 1 when the model is right), and `κ_g` the integrated
//!   autocorrelation of that residual over the test function's support: the weak form's rows share
//!   samples, so `κ` neighbouring rows carry about one row's worth of independent noise, and
//!   `ΔSSE` of a noise-only term is about `κ s² χ²_p`;
//! - **size** (fit part): the mean gain per row and channel of its groups is at least `min_gain`
//!   noise variances;
//! - **consistency** (every block): over the fit part's blocks (of about a second) and the
//!   held-out part's, cut alike and each scored with the parameters fitted on the fit part, the
//!   mean gain per row and channel is still at least `min_trimmed_gain` when the two blocks that
//!   gain most are left out ([`sindy::stability::trimmed_gain`]): not one or two transients, while
//!   an effect whose evidence recurs in the held-out part is credited for it;
//! - **held out**: on the held-out part, which no fit or choice has seen, the noise-normalised
//!   residual sum of squares of its groups (each divided by its `s²_g`) falls by at least
//!   `min_heldout_reduction` of its value without the effect.
//!
//! While an effect fails, the weakest failing one (smallest fit gain) is dropped and the rest
//! refitted; the rule is then applied again to every effect left.

use physics::{ChannelGroup, EffectId};
use rayon::prelude::*;
use serde::Serialize;
use sindy::stability::trimmed_gain;
use statrs::distribution::{ChiSquared, ContinuousCDF};

use crate::explain::fit::FittedSet;
use crate::locate::problem::{Channels, Problem};
use crate::model::refine::{FitRows, standard_errors};

/// The thresholds of the rule (recorded in the output).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct EvidenceSettings {
    pub significance: f64,
    pub min_gain: f64,
    pub min_trimmed_gain: f64,
    pub min_heldout_reduction: f64,
}

impl Default for EvidenceSettings {
    fn default() -> Self {
        Self {
            significance: 0.999,
            min_gain: 0.25,
            min_trimmed_gain: 0.1,
            min_heldout_reduction: 0.15,
        }
    }
}

/// The evidence for one effect of the final set.
#[derive(Clone, Debug, Serialize)]
pub struct Evidence {
    pub id: EffectId,
    /// The channels the effect was judged on (those it acts on, of those compared).
    pub judged_on: ChannelGroup,
    /// Parameters of the effect (the degrees of freedom of the test).
    pub parameters: usize,
    /// `Λ = ΔSSE / (κ s²)` and the χ² quantile it is compared with.
    pub likelihood_ratio: f64,
    pub likelihood_ratio_threshold: f64,
    /// Mean gain per row and channel on the fit part, in noise-floor units.
    pub fit_gain: f64,
    /// The mean gain over the fit and held-out blocks once the two that gain most are left out.
    pub trimmed_gain: f64,
    /// Held-out noise-normalised sum of squares without and with the effect.
    pub heldout_without: f64,
    pub heldout_with: f64,
    /// `1 − with / without`.
    pub heldout_reduction: f64,
    /// Fit-part noise-normalised sum of squares the effect removes (others refitted).
    pub fit_sse_removed: f64,
    pub passes: bool,
}

/// Noise-normalised sums of squares of a set's residual, per compared channel group (in the order
/// of [`Problem::channel_groups`]): per fit block, per held-out block, and over the held-out part.
struct Scores {
    /// `blocks[b][g]`: fit block `b`, group `g`.
    blocks: Vec<Vec<f64>>,
    /// Rows times channels of each fit block, per group.
    counts: Vec<Vec<f64>>,
    /// The held-out part cut into blocks as the fit part is, and their rows times channels.
    heldout_blocks: Vec<Vec<f64>>,
    heldout_counts: Vec<Vec<f64>>,
    heldout: Vec<f64>,
}

impl Scores {
    /// The sum over the fit blocks of group `g`.
    fn fit(&self, g: usize) -> f64 {
        self.blocks.iter().map(|b| b[g]).sum()
    }

    fn count(&self, g: usize) -> f64 {
        self.counts.iter().map(|b| b[g]).sum()
    }

    /// How much more these scores leave than `base` on the fit part of groups `groups`, each in
    /// units of its noise scale `κ_g s²_g`: a likelihood ratio.
    fn excess_over(&self, base: &Scores, groups: &[usize], noise: &[NoiseScale]) -> f64 {
        groups
            .iter()
            .map(|&g| (self.fit(g) - base.fit(g)) / noise[g].scale())
            .sum()
    }

    /// The held-out sum of groups `groups`, each divided by its `s²_g`.
    fn heldout_in(&self, groups: &[usize], noise: &[NoiseScale]) -> f64 {
        groups
            .iter()
            .map(|&g| self.heldout[g] / noise[g].variance.max(1e-300))
            .sum()
    }
}

fn scores(problem: &Problem, set: &FittedSet, block_rows: usize) -> Scores {
    scores_of(problem, &problem.residual(&set.effects()), block_rows)
}

/// The scores of a residual.
fn scores_of(problem: &Problem, residual: &[Channels], block_rows: usize) -> Scores {
    let (blocks, counts) = block_scores(problem, residual, 0..problem.split, block_rows);
    let (heldout_blocks, heldout_counts) =
        block_scores(problem, residual, problem.split..problem.rows(), block_rows);
    let heldout = problem
        .channel_groups()
        .iter()
        .map(|(_, channels)| {
            problem.whitened_sse_of(residual, problem.split..problem.rows(), channels.clone())
        })
        .collect();
    Scores {
        blocks,
        counts,
        heldout_blocks,
        heldout_counts,
        heldout,
    }
}

/// Per block of `block_rows` rows of `rows` (the last one shorter), the noise-normalised sum of
/// squares of each compared channel group and its rows times channels.
fn block_scores(
    problem: &Problem,
    residual: &[Channels],
    rows: std::ops::Range<usize>,
    block_rows: usize,
) -> (Vec<Vec<f64>>, Vec<Vec<f64>>) {
    let groups = problem.channel_groups();
    let (mut sums, mut counts) = (Vec::new(), Vec::new());
    let mut start = rows.start;
    while start < rows.end {
        let end = (start + block_rows.max(1)).min(rows.end);
        sums.push(
            groups
                .iter()
                .map(|(_, channels)| {
                    problem.whitened_sse_of(residual, start..end, channels.clone())
                })
                .collect(),
        );
        counts.push(
            groups
                .iter()
                .map(|(_, channels)| ((end - start) * channels.len()) as f64)
                .collect(),
        );
        start = end;
    }
    (sums, counts)
}

/// The integrated autocorrelation of a residual over lags up to `lags`, averaged over all compared
/// channels (at least 1).
pub(crate) fn autocorrelation_factor(problem: &Problem, residual: &[Channels], lags: usize) -> f64 {
    autocorrelation_of(residual, 0..problem.channels, lags)
}

/// [`autocorrelation_factor`] over the channels `channels`.
fn autocorrelation_of(residual: &[Channels], channels: std::ops::Range<usize>, lags: usize) -> f64 {
    let count = channels.len();
    let total: f64 = channels
        .map(|c| {
            let r: Vec<f64> = residual.iter().map(|x| x[c]).collect();
            integrated_autocorrelation(&r, lags).unwrap_or(0.0)
        })
        .sum();
    (total / count as f64).max(1.0)
}

/// `1 + 2 Σ ρ(lag)` of one series over lags up to `lags` (none for a series of zeros).
pub(crate) fn integrated_autocorrelation(r: &[f64], lags: usize) -> Option<f64> {
    let variance: f64 = r.iter().map(|v| v * v).sum();
    if variance <= 0.0 {
        return None;
    }
    let mut factor = 1.0;
    for lag in 1..=lags.min(r.len().saturating_sub(1)) {
        let covariance: f64 = r[lag..].iter().zip(r).map(|(a, b)| a * b).sum();
        factor += 2.0 * covariance / variance;
    }
    Some(factor)
}

/// The `q` quantile of χ² with `p` degrees of freedom (at least 1), exact (statrs).
pub fn chi_square_quantile(p: usize, q: f64) -> f64 {
    let degrees = p.max(1) as f64;
    ChiSquared::new(degrees)
        .map(|distribution| distribution.inverse_cdf(q.clamp(0.0, 1.0)))
        .unwrap_or(f64::NAN)
}

/// What the full set's residual says about the noise of one channel group: `κ` and `s²` on the
/// fit part.
#[derive(Clone, Copy, Debug)]
struct NoiseScale {
    autocorrelation: f64,
    variance: f64,
}

impl NoiseScale {
    fn of(problem: &Problem, whitened: &[Channels], channels: std::ops::Range<usize>) -> Self {
        let count = (whitened.len() * channels.len()).max(1) as f64;
        let variance = whitened
            .iter()
            .map(|r| channels.clone().map(|c| r[c] * r[c]).sum::<f64>())
            .sum::<f64>()
            / count;
        Self {
            autocorrelation: autocorrelation_of(whitened, channels, 2 * problem.weak_form.half),
            variance,
        }
    }

    fn scale(&self) -> f64 {
        (self.autocorrelation * self.variance).max(1e-300)
    }
}

/// The noise scale of a fit-part residual per compared channel group, and over all channels.
fn noise_scales(problem: &Problem, residual: &[Channels]) -> (Vec<NoiseScale>, NoiseScale) {
    let whitened: Vec<Channels> = residual[..problem.split]
        .iter()
        .map(|r| {
            let mut w = [0.0; 6];
            for c in 0..problem.channels {
                w[c] = r[c] / problem.noise_floor[c];
            }
            w
        })
        .collect();
    let groups = problem
        .channel_groups()
        .into_iter()
        .map(|(_, channels)| NoiseScale::of(problem, &whitened, channels))
        .collect();
    (
        groups,
        NoiseScale::of(problem, &whitened, 0..problem.channels),
    )
}

/// How much worse another set explains the recording than a baseline set, on the channel groups
/// of the effects compared, in the evidence rule's terms.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Worse {
    /// `Σ_g (SSE_g(other) − SSE_g(set)) / (κ_g s²_g)` on the fit part.
    pub likelihood_ratio: f64,
    /// `1 − SSE(set) / SSE(other)` on the held-out part, each group divided by its `s²_g`.
    pub heldout_increase: f64,
}

/// A set other sets are weighed against: its scores and its residual's noise scale per channel
/// group, from one evaluation of its residual.
pub(crate) struct Baseline {
    scores: Scores,
    noise: Vec<NoiseScale>,
    block_rows: usize,
}

impl Baseline {
    pub(crate) fn of(problem: &Problem, set: &FittedSet, block_rows: usize) -> Self {
        let residual = problem.residual(&set.effects());
        Self {
            scores: scores_of(problem, &residual, block_rows),
            noise: noise_scales(problem, &residual).0,
            block_rows,
        }
    }

    /// How much worse `other` does, on the groups the effects `ids` act on.
    pub(crate) fn worse(&self, problem: &Problem, other: &FittedSet, ids: &[EffectId]) -> Worse {
        let mut groups: Vec<usize> = ids
            .iter()
            .flat_map(|id| judged_groups(problem, *id).0)
            .collect();
        groups.sort_unstable();
        groups.dedup();
        let other = scores(problem, other, self.block_rows);
        let (full, noise) = (&self.scores, &self.noise);
        Worse {
            likelihood_ratio: other.excess_over(full, &groups, noise),
            heldout_increase: 1.0
                - full.heldout_in(&groups, noise) / other.heldout_in(&groups, noise).max(1e-300),
        }
    }
}

/// What every effect of one set is judged against.
struct Judge<'a> {
    problem: &'a Problem,
    set: &'a FittedSet,
    full: Scores,
    /// Per compared channel group.
    noise: Vec<NoiseScale>,
    settings: &'a EvidenceSettings,
    iterations: usize,
    block_rows: usize,
}

/// The compared groups (indices into [`Problem::channel_groups`]) an effect is judged on, and
/// the group it is reported as judged on.
fn judged_groups(problem: &Problem, id: EffectId) -> (Vec<usize>, ChannelGroup) {
    let groups = problem.channel_groups();
    let acts_on = id.acts_on();
    let judged: Vec<usize> = (0..groups.len())
        .filter(|&g| acts_on == ChannelGroup::Both || groups[g].0 == acts_on)
        .collect();
    match judged.as_slice() {
        [] => ((0..groups.len()).collect(), acts_on),
        [g] => (judged.clone(), groups[*g].0),
        _ => (judged, ChannelGroup::Both),
    }
}

/// The gain per row and channel of groups `groups` in every block, the fit part's and the held-out
/// part's (each scored with the parameters fitted on the fit part), weighted 1 each: what the
/// consistency test trims.
fn block_gains(without: &Scores, full: &Scores, groups: &[usize]) -> Vec<(f64, f64)> {
    let sum_over = |values: &[f64]| group_sum(values, groups);
    without
        .blocks
        .iter()
        .chain(&without.heldout_blocks)
        .zip(full.blocks.iter().chain(&full.heldout_blocks))
        .zip(full.counts.iter().chain(&full.heldout_counts))
        .map(|((w, f), n)| (1.0, (sum_over(w) - sum_over(f)) / sum_over(n)))
        .collect()
}

/// The sum of per-group `values` over groups `groups`.
fn group_sum(values: &[f64], groups: &[usize]) -> f64 {
    groups.iter().map(|&g| values[g]).sum()
}

/// The evidence for effect `id` of the judged set; returns it with the refitted set without the
/// effect.
fn evidence_for(judge: &Judge, id: EffectId) -> (Evidence, FittedSet) {
    let Judge {
        problem,
        set,
        full,
        noise,
        settings,
        iterations,
        block_rows,
    } = judge;
    let (problem, iterations, block_rows) = (*problem, *iterations, *block_rows);
    let mut reduced = set.without(id);
    reduced.refit(problem, iterations);
    let without = scores(problem, &reduced, block_rows);
    let (groups, judged_on) = judged_groups(problem, id);
    let trimmed = trimmed_gain(&block_gains(&without, full, &groups));
    let removed_in = |g: usize| without.fit(g) - full.fit(g);
    let removed: f64 = groups.iter().map(|&g| removed_in(g)).sum();
    let mean = removed / groups.iter().map(|&g| full.count(g)).sum::<f64>();
    let parameters = set.parameters.len() - reduced.parameters.len();
    let likelihood_ratio = without.excess_over(full, &groups, noise);
    let threshold = chi_square_quantile(parameters, settings.significance);
    let reduction =
        1.0 - full.heldout_in(&groups, noise) / without.heldout_in(&groups, noise).max(1e-300);
    let passes = likelihood_ratio >= threshold
        && mean >= settings.min_gain
        && trimmed >= settings.min_trimmed_gain
        && reduction >= settings.min_heldout_reduction;
    (
        Evidence {
            id,
            judged_on,
            parameters,
            likelihood_ratio,
            likelihood_ratio_threshold: threshold,
            fit_gain: mean,
            trimmed_gain: trimmed,
            heldout_without: group_sum(&without.heldout, &groups),
            heldout_with: group_sum(&full.heldout, &groups),
            heldout_reduction: reduction,
            fit_sse_removed: removed,
            passes,
        },
        reduced,
    )
}

/// The outcome of the rule.
#[derive(Clone, Debug)]
pub struct Judgement {
    /// The effects that pass, jointly refitted.
    pub set: FittedSet,
    /// The evidence for each of them, at the final set.
    pub evidence: Vec<Evidence>,
    /// The evidence of each effect dropped, when it was dropped (in order).
    pub dropped: Vec<Evidence>,
    /// The standard error of each value of `set` (`refine::standard_errors`, with the
    /// final set's residual variance and autocorrelation).
    pub standard_errors: Vec<f64>,
}

/// Applies the rule to a jointly fitted set.
pub fn apply(
    problem: &Problem,
    mut set: FittedSet,
    settings: &EvidenceSettings,
    iterations: usize,
    block_rows: usize,
) -> Judgement {
    let mut dropped = Vec::new();
    loop {
        let ids = set.ids();
        if ids.is_empty() {
            return Judgement {
                set,
                evidence: Vec::new(),
                dropped,
                standard_errors: Vec::new(),
            };
        }
        let residual = problem.residual(&set.effects());
        let full = scores_of(problem, &residual, block_rows);
        let (noise, all_channels) = noise_scales(problem, &residual);
        let judge = Judge {
            problem,
            set: &set,
            full,
            noise,
            settings,
            iterations,
            block_rows,
        };
        let outcomes: Vec<(Evidence, FittedSet)> =
            ids.par_iter().map(|id| evidence_for(&judge, *id)).collect();
        let weakest = outcomes
            .iter()
            .filter(|(e, _)| !e.passes)
            .min_by(|a, b| a.0.fit_gain.total_cmp(&b.0.fit_gain));
        match weakest {
            Some((evidence, reduced)) => {
                dropped.push(evidence.clone());
                set = reduced.clone();
            }
            None => {
                let standard_errors = standard_errors(
                    problem,
                    &set.parameters,
                    &set.values,
                    &FitRows::plain(0..problem.split),
                    all_channels.autocorrelation * all_channels.variance,
                );
                return Judgement {
                    evidence: outcomes.into_iter().map(|(e, _)| e).collect(),
                    set,
                    dropped,
                    standard_errors,
                };
            }
        }
    }
}

/// Each effect's share of the nominal model's fit-part noise-normalised sum of squares: the total
/// share the fitted set removes, `1 − SSE(set) / SSE(nominal)` (at least 0), divided among the
/// effects in proportion to what each one's removal brings back. Each share is in [0, 1] and they
/// sum to the total.
pub fn explained_fractions(evidence: &[Evidence], nominal_sse: f64, fitted_sse: f64) -> Vec<f64> {
    let total = (1.0 - fitted_sse / nominal_sse.max(1e-300)).clamp(0.0, 1.0);
    let weights: Vec<f64> = evidence
        .iter()
        .map(|e| e.fit_sse_removed.max(0.0))
        .collect();
    let sum: f64 = weights.iter().sum();
    weights
        .iter()
        .map(|w| {
            if sum > 0.0 {
                total * w / sum
            } else {
                total / weights.len().max(1) as f64
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn evidence(removed: f64) -> Evidence {
        Evidence {
            id: EffectId::ThrustScale,
            judged_on: ChannelGroup::Translational,
            parameters: 1,
            likelihood_ratio: 100.0,
            likelihood_ratio_threshold: 10.0,
            fit_gain: 1.0,
            trimmed_gain: 1.0,
            heldout_without: 2.0,
            heldout_with: 1.0,
            heldout_reduction: 0.5,
            fit_sse_removed: removed,
            passes: true,
        }
    }

    /// Shares stay in [0, 1] and sum to the total even when the removals overlap or exceed it.
    #[test]
    fn explained_fractions_are_shares_of_the_total() {
        let shares = explained_fractions(&[evidence(900.0), evidence(300.0)], 1000.0, 100.0);
        assert!((shares[0] - 0.675).abs() < 1e-12 && (shares[1] - 0.225).abs() < 1e-12);
        let worse = explained_fractions(&[evidence(-5.0)], 1000.0, 1200.0);
        assert_eq!(worse, [0.0]);
        assert!(shares.iter().all(|s| (0.0..=1.0).contains(s)));
    }

    /// Scores of four fit blocks and two held-out blocks, one group, 10 rows × channels each.
    fn block_scores_of(fit: [f64; 4], heldout: [f64; 2]) -> Scores {
        let per_block = |values: &[f64]| values.iter().map(|v| vec![*v]).collect::<Vec<_>>();
        Scores {
            blocks: per_block(&fit),
            counts: vec![vec![10.0]; 4],
            heldout_blocks: per_block(&heldout),
            heldout_counts: vec![vec![10.0]; 2],
            heldout: vec![heldout.iter().sum()],
        }
    }

    /// An effect whose gain sits in two transients of the fit part and recurs in both held-out
    /// blocks is consistent: the held-out blocks count, each with its own gain.
    #[test]
    fn consistency_counts_the_heldout_blocks() {
        let full = block_scores_of([10.0; 4], [10.0; 2]);
        let without = block_scores_of([110.0, 10.0, 110.0, 10.0], [60.0, 40.0]);
        let gains = block_gains(&without, &full, &[0]);
        assert_eq!(
            gains,
            [
                (1.0, 10.0),
                (1.0, 0.0),
                (1.0, 10.0),
                (1.0, 0.0),
                (1.0, 5.0),
                (1.0, 3.0)
            ]
        );
        // Trimming the two largest (both in the fit part) leaves 0, 0, 5 and 3.
        assert!((trimmed_gain(&gains) - 2.0).abs() < 1e-12);
        // Gains in the fit part's two transients alone, nothing held out: not consistent.
        let transient = block_scores_of([110.0, 10.0, 110.0, 10.0], [10.0; 2]);
        assert_eq!(trimmed_gain(&block_gains(&transient, &full, &[0])), 0.0);
    }

    #[test]
    fn chi_square_quantiles_are_the_tables() {
        // The tables' values, to their printed digits.
        for (p, exact) in [(1, 10.828), (3, 16.266), (4, 18.467), (6, 22.458)] {
            let q = chi_square_quantile(p, 0.999);
            assert!((q - exact).abs() < 5e-4, "{p}: {q} vs {exact}");
        }
        assert!((chi_square_quantile(2, 0.95) - 5.991).abs() < 5e-4);
    }
}
