//! Model selection on the residual: forward stepwise selection of candidate groups scored by
//! time-blocked cross-validation, repeated on block-bootstrap resamples (stability selection).
//!
//! Rows are whitened (each channel divided by its noise floor), so on noise alone the mean square
//! per row and channel is about 1. A group enters only when it lowers the cross-validated error in
//! every sense that matters: on average by at least `min_gain` (noise-floor units), and still by
//! `min_gain` once the two blocks that gain most are left out ([`trimmed_gain`]), so that an effect
//! present in only part of the flight, or much stronger in some blocks than in others, can enter,
//! while a term that fits one transient cannot. A
//! group is kept when it enters in at least
//! `stability_threshold` of the resamples. All sums go through per-block Gram matrices, so a
//! resample or a fold costs a few small solves.

use faer::Mat;
use faer::linalg::solvers::Solve;
use rand::{RngExt, SeedableRng};
use rayon::prelude::*;
use serde::Serialize;

use crate::problem::{Channels, Problem};

/// Settings of the selection (all recorded in the output).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SelectionSettings {
    pub folds: usize,
    pub resamples: usize,
    pub stability_threshold: f64,
    pub min_gain: f64,
    pub seed: u64,
}

impl Default for SelectionSettings {
    fn default() -> Self {
        Self {
            folds: 5,
            resamples: 40,
            stability_threshold: 0.7,
            min_gain: 0.05,
            seed: 20240611,
        }
    }
}

/// Per-block sufficient statistics of the whitened regression `residual ≈ columns · θ`.
#[derive(Clone, Debug)]
pub struct Design {
    grams: Vec<Mat<f64>>,
    cross: Vec<Vec<f64>>,
    target_squares: Vec<f64>,
    /// Row × channel count of each block.
    counts: Vec<f64>,
    parameters: usize,
}

impl Design {
    /// Builds the block statistics over analysed rows `range`.
    pub fn new(
        problem: &Problem,
        residual: &[Channels],
        columns: &[Vec<Channels>],
        range: std::ops::Range<usize>,
        block_rows: usize,
    ) -> Self {
        let p = columns.len();
        let mut design = Self {
            grams: Vec::new(),
            cross: Vec::new(),
            target_squares: Vec::new(),
            counts: Vec::new(),
            parameters: p,
        };
        let mut start = range.start;
        while start < range.end {
            let end = (start + block_rows).min(range.end);
            let mut gram = Mat::<f64>::zeros(p, p);
            let mut cross = vec![0.0; p];
            let mut squares = 0.0;
            let mut x = vec![0.0; p];
            for row in start..end {
                for c in 0..problem.channels {
                    let scale = 1.0 / problem.noise_floor[c];
                    let y = residual[row][c] * scale;
                    for j in 0..p {
                        x[j] = columns[j][row][c] * scale;
                    }
                    for i in 0..p {
                        cross[i] += x[i] * y;
                        for j in 0..=i {
                            gram[(i, j)] += x[i] * x[j];
                        }
                    }
                    squares += y * y;
                }
            }
            for i in 0..p {
                for j in 0..i {
                    gram[(j, i)] = gram[(i, j)];
                }
            }
            design.grams.push(gram);
            design.cross.push(cross);
            design.target_squares.push(squares);
            design
                .counts
                .push(((end - start) * problem.channels) as f64);
            start = end;
        }
        design
    }

    /// Number of blocks.
    pub fn blocks(&self) -> usize {
        self.grams.len()
    }

    /// Least-squares coefficients of `columns` using blocks weighted by `weights`.
    pub fn solve(&self, weights: &[f64], columns: &[usize]) -> Vec<f64> {
        let k = columns.len();
        if k == 0 {
            return Vec::new();
        }
        let mut gram = Mat::<f64>::zeros(k, k);
        let mut rhs = Mat::<f64>::zeros(k, 1);
        for (b, &w) in weights.iter().enumerate() {
            if w == 0.0 {
                continue;
            }
            for (i, &ci) in columns.iter().enumerate() {
                rhs[(i, 0)] += w * self.cross[b][ci];
                for (j, &cj) in columns.iter().enumerate() {
                    gram[(i, j)] += w * self.grams[b][(ci, cj)];
                }
            }
        }
        let trace: f64 = (0..k).map(|i| gram[(i, i)]).sum();
        let ridge = 1e-10 * trace / k as f64 + 1e-300;
        for i in 0..k {
            gram[(i, i)] += ridge;
        }
        let solution = gram.full_piv_lu().solve(&rhs);
        (0..k).map(|i| solution[(i, 0)]).collect()
    }

    /// Sum of squared whitened residuals of block `b` with coefficients `theta` on `columns`.
    fn block_sse(&self, b: usize, columns: &[usize], theta: &[f64]) -> f64 {
        let mut sse = self.target_squares[b];
        for (i, &ci) in columns.iter().enumerate() {
            sse -= 2.0 * theta[i] * self.cross[b][ci];
            for (j, &cj) in columns.iter().enumerate() {
                sse += theta[i] * theta[j] * self.grams[b][(ci, cj)];
            }
        }
        sse
    }

    /// Cross-validated mean square per row and channel of every block: each block is predicted by
    /// the fit on the folds it is not in. Blocks with zero weight give NaN.
    pub fn block_errors(
        &self,
        weights: &[f64],
        fold_of_block: &[usize],
        folds: usize,
        columns: &[usize],
    ) -> Vec<f64> {
        let mut errors = vec![f64::NAN; self.blocks()];
        for f in 0..folds {
            let train: Vec<f64> = weights
                .iter()
                .zip(fold_of_block)
                .map(|(w, fb)| if *fb == f { 0.0 } else { *w })
                .collect();
            let theta = self.solve(&train, columns);
            for b in 0..self.blocks() {
                if fold_of_block[b] == f && weights[b] > 0.0 {
                    errors[b] = self.block_sse(b, columns, &theta) / self.counts[b];
                }
            }
        }
        errors
    }

    /// In-sample whitened sum of squares with all blocks and least-squares coefficients.
    pub fn fitted_sse(&self, columns: &[usize]) -> f64 {
        let ones = vec![1.0; self.blocks()];
        let theta = self.solve(&ones, columns);
        (0..self.blocks())
            .map(|b| self.block_sse(b, columns, &theta))
            .sum()
    }

    /// Number of columns.
    pub fn parameters(&self) -> usize {
        self.parameters
    }
}

/// Blocks whose gains are left out by [`trimmed_gain`].
pub const TRIMMED_BLOCKS: f64 = 2.0;

/// The mean of per-block gains (each with a weight: a block drawn `w` times counts `w` times) once
/// the `TRIMMED_BLOCKS` largest are left out: what remains of a gain when the one or two blocks
/// that carry most of it are ignored. Near zero for a term that only fits a transient; most of the
/// mean for an effect present, however unevenly, through much of the flight.
pub fn trimmed_gain(gains: &[(f64, f64)]) -> f64 {
    let mut sorted: Vec<(f64, f64)> = gains.iter().copied().filter(|(w, _)| *w > 0.0).collect();
    sorted.sort_by(|a, b| b.1.total_cmp(&a.1));
    let total: f64 = sorted.iter().map(|(w, _)| w).sum();
    let mut to_remove = TRIMMED_BLOCKS;
    let mut sum = 0.0;
    for (w, g) in sorted {
        let removed = w.min(to_remove);
        to_remove -= removed;
        sum += (w - removed) * g;
    }
    sum / (total - TRIMMED_BLOCKS).max(1.0)
}

/// Forward stepwise selection of groups; returns the chosen group indices in order of entry.
pub fn stepwise(
    design: &Design,
    weights: &[f64],
    groups: &[Vec<usize>],
    settings: &SelectionSettings,
) -> Vec<usize> {
    let blocks = design.blocks();
    let folds = settings.folds.min(blocks).max(2);
    let fold_of_block: Vec<usize> = (0..blocks).map(|b| b * folds / blocks).collect();
    let mut chosen: Vec<usize> = Vec::new();
    let mut columns: Vec<usize> = Vec::new();
    let mut current = design.block_errors(weights, &fold_of_block, folds, &columns);
    loop {
        let mut best: Option<(usize, f64, Vec<f64>)> = None;
        for (g, group) in groups.iter().enumerate() {
            if chosen.contains(&g) {
                continue;
            }
            let trial_columns: Vec<usize> = columns.iter().chain(group).copied().collect();
            let errors = design.block_errors(weights, &fold_of_block, folds, &trial_columns);
            // Paired comparison over blocks, each counted as often as the resample drew it.
            let (mut total, mut count) = (0.0, 0.0);
            let mut positive = Vec::with_capacity(blocks);
            for b in 0..blocks {
                let gain = current[b] - errors[b];
                if weights[b] > 0.0 && gain.is_finite() {
                    total += weights[b] * gain;
                    count += weights[b];
                    positive.push((weights[b], gain));
                }
            }
            if count < 2.0 {
                continue;
            }
            let mean = total / count;
            let consistency = trimmed_gain(&positive);
            if mean >= settings.min_gain
                && consistency >= settings.min_gain
                && best.as_ref().is_none_or(|(_, m, _)| mean > *m)
            {
                best = Some((g, mean, errors));
            }
        }
        match best {
            Some((g, _, errors)) => {
                chosen.push(g);
                columns.extend(&groups[g]);
                current = errors;
            }
            None => return chosen,
        }
    }
}

/// The outcome of stability selection.
#[derive(Clone, Debug, Serialize)]
pub struct Selection {
    /// Groups chosen on the data as recorded (no resampling).
    pub chosen_on_data: Vec<usize>,
    /// Fraction of resamples in which each group was chosen.
    pub frequencies: Vec<f64>,
    /// Groups kept (frequency ≥ threshold), in library order.
    pub kept: Vec<usize>,
}

/// Stepwise selection on the data and on block-bootstrap resamples.
pub fn stability_selection(
    design: &Design,
    groups: &[Vec<usize>],
    settings: &SelectionSettings,
) -> Selection {
    let blocks = design.blocks();
    let ones = vec![1.0; blocks];
    let chosen_on_data = stepwise(design, &ones, groups, settings);
    let counts: Vec<Vec<usize>> = (0..settings.resamples)
        .into_par_iter()
        .map(|r| {
            let mut rng =
                rand_chacha::ChaCha8Rng::seed_from_u64(settings.seed.wrapping_add(r as u64));
            let mut weights = vec![0.0; blocks];
            for _ in 0..blocks {
                weights[rng.random_range(0..blocks)] += 1.0;
            }
            stepwise(design, &weights, groups, settings)
        })
        .collect();
    let frequencies: Vec<f64> = (0..groups.len())
        .map(|g| {
            counts.iter().filter(|c| c.contains(&g)).count() as f64
                / settings.resamples.max(1) as f64
        })
        .collect();
    let kept = (0..groups.len())
        .filter(|g| frequencies[*g] >= settings.stability_threshold)
        .collect();
    Selection {
        chosen_on_data,
        frequencies,
        kept,
    }
}
