//! Selection of groups of columns: forward stepwise selection scored by time-blocked
//! cross-validation, repeated on block-bootstrap resamples (stability selection, as PySINDy's
//! ensembles but over contiguous blocks of a time series).
//!
//! The regression `target ≈ columns · θ` is summarised per contiguous block of samples by its Gram
//! matrix ([`BlockDesign`]); the folds of the cross-validation are contiguous runs of blocks (block
//! `b` of `B` in fold `⌊b F / B⌋`), and a resample draws `B` blocks with replacement (a block drawn
//! `w` times has weight `w`). Samples are expected whitened (divided by their noise scale), so on
//! noise alone the mean square per sample is about 1. A group enters only when it lowers the
//! cross-validated error in
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

/// Per-block sufficient statistics of the whitened regression `target ≈ columns · θ`.
#[derive(Clone, Debug)]
pub struct BlockDesign {
    grams: Vec<Mat<f64>>,
    cross: Vec<Vec<f64>>,
    target_squares: Vec<f64>,
    /// Row × channel count of each block.
    counts: Vec<f64>,
    parameters: usize,
}

impl BlockDesign {
    /// Builds the block statistics of `samples` samples in order, cut into blocks of
    /// `block_samples` (the last may be shorter), with `parameters` columns: `sample(i, x)` writes
    /// the columns of sample `i` into `x` and returns its target.
    pub fn from_samples(
        samples: usize,
        block_samples: usize,
        parameters: usize,
        sample: impl FnMut(usize, &mut [f64]) -> f64,
    ) -> Self {
        let p = parameters;
        // The lower triangle, row by row: each entry summed over the samples in order.
        let lower = LowerTriangle {
            p,
            sums: vec![0.0; p * (p + 1) / 2],
        };
        Self::summed(samples, block_samples, p, sample, lower)
    }

    /// [`Self::from_samples`] over the columns `leading ++ trailing`, where `trailing` holds the
    /// statistics of the trailing columns alone over the same samples and blocks (built by
    /// `from_samples`; its target is not used). Only the entries that involve a leading column or
    /// the target are summed, each in the same order as `from_samples` sums it, so the result has
    /// the same bits: a search that changes the target and a few columns against fixed ones sums
    /// the fixed ones' Gram matrix once. `sample(i, x)` writes all `leading + trailing` columns.
    pub fn with_leading_columns(
        trailing: &Self,
        samples: usize,
        block_samples: usize,
        leading: usize,
        sample: impl FnMut(usize, &mut [f64]) -> f64,
    ) -> Self {
        let p = leading + trailing.parameters;
        let rows = LeadingRows {
            trailing,
            leading,
            p,
            sums: vec![0.0; leading * p],
        };
        let design = Self::summed(samples, block_samples, p, sample, rows);
        assert_eq!(
            design.blocks(),
            trailing.blocks(),
            "the same samples and blocks"
        );
        design
    }

    /// The blocks' statistics: the cross products with the target, its squares and the counts
    /// summed here, the Gram matrix by `gram`.
    fn summed(
        samples: usize,
        block_samples: usize,
        p: usize,
        mut sample: impl FnMut(usize, &mut [f64]) -> f64,
        mut gram: impl GramSums,
    ) -> Self {
        let mut design = Self {
            grams: Vec::new(),
            cross: Vec::new(),
            target_squares: Vec::new(),
            counts: Vec::new(),
            parameters: p,
        };
        let mut x = vec![0.0; p];
        let mut start = 0;
        while start < samples {
            let end = (start + block_samples.max(1)).min(samples);
            let mut cross = vec![0.0; p];
            let mut squares = 0.0;
            for k in start..end {
                let y = sample(k, &mut x);
                for (i, &xi) in x.iter().enumerate() {
                    cross[i] += xi * y;
                }
                gram.add(&x);
                squares += y * y;
            }
            design.grams.push(gram.take(design.grams.len()));
            design.cross.push(cross);
            design.target_squares.push(squares);
            design.counts.push((end - start) as f64);
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

    /// Sum of squared residuals of block `b` with coefficients `theta` on `columns`.
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

    /// Cross-validated mean square per sample of every block: each block is predicted by
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

    /// In-sample sum of squares with all blocks and least-squares coefficients.
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

/// How a block's Gram matrix is summed: each sample's columns added in order, then the block's
/// matrix taken (and the sums started again).
trait GramSums {
    fn add(&mut self, x: &[f64]);
    fn take(&mut self, block: usize) -> Mat<f64>;
}

/// Every entry of the lower triangle, row by row ([`BlockDesign::from_samples`]).
struct LowerTriangle {
    p: usize,
    sums: Vec<f64>,
}

impl GramSums for LowerTriangle {
    fn add(&mut self, x: &[f64]) {
        let mut row_start = 0;
        for (i, &xi) in x.iter().enumerate() {
            let row = &mut self.sums[row_start..row_start + i + 1];
            for (entry, &xj) in row.iter_mut().zip(x) {
                *entry += xi * xj;
            }
            row_start += i + 1;
        }
    }

    fn take(&mut self, _block: usize) -> Mat<f64> {
        let sums = &self.sums;
        let entry = |i: usize, j: usize| {
            let (row, column) = if j <= i { (i, j) } else { (j, i) };
            sums[row * (row + 1) / 2 + column]
        };
        let gram = Mat::<f64>::from_fn(self.p, self.p, entry);
        self.sums.fill(0.0);
        gram
    }
}

/// The leading columns' rows against every column, the rest from the trailing columns' own
/// design ([`BlockDesign::with_leading_columns`]).
struct LeadingRows<'a> {
    trailing: &'a BlockDesign,
    leading: usize,
    p: usize,
    sums: Vec<f64>,
}

impl GramSums for LeadingRows<'_> {
    fn add(&mut self, x: &[f64]) {
        let p = self.p;
        for (i, &xi) in x[..self.leading].iter().enumerate() {
            for (entry, &xj) in self.sums[i * p..(i + 1) * p].iter_mut().zip(x) {
                *entry += xi * xj;
            }
        }
    }

    fn take(&mut self, block: usize) -> Mat<f64> {
        let (leading, p, sums) = (self.leading, self.p, &self.sums);
        let fixed = &self.trailing.grams[block];
        let entry = |i: usize, j: usize| match (i < leading, j < leading) {
            (true, _) => sums[i * p + j],
            (false, true) => sums[j * p + i],
            (false, false) => fixed[(i - leading, j - leading)],
        };
        let gram = Mat::<f64>::from_fn(p, p, entry);
        self.sums.fill(0.0);
        gram
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
    design: &BlockDesign,
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
    design: &BlockDesign,
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

#[cfg(test)]
mod tests {
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};

    use super::*;

    /// `samples` whitened samples of `y = 0.8 x0 − 0.5 x1 + noise` with four columns in two
    /// groups of two ({x0, x1} acts, {x2, x3} is noise), in blocks of 50.
    fn design(samples: usize, signal: f64) -> BlockDesign {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let rows: Vec<([f64; 4], f64)> = (0..samples)
            .map(|_| {
                let x: [f64; 4] = std::array::from_fn(|_| StandardNormal.sample(&mut rng));
                let noise: f64 = StandardNormal.sample(&mut rng);
                (x, signal * (0.8 * x[0] - 0.5 * x[1]) + noise)
            })
            .collect();
        BlockDesign::from_samples(samples, 50, 4, |i, x| {
            x.copy_from_slice(&rows[i].0);
            rows[i].1
        })
    }

    const GROUPS: [&[usize]; 2] = [&[0, 1], &[2, 3]];

    fn groups() -> Vec<Vec<usize>> {
        GROUPS.iter().map(|g| g.to_vec()).collect()
    }

    #[test]
    fn the_acting_group_is_kept_and_the_other_is_not() {
        let design = design(2000, 1.0);
        assert_eq!(design.blocks(), 40);
        let settings = SelectionSettings::default();
        let selection = stability_selection(&design, &groups(), &settings);
        assert_eq!(selection.chosen_on_data, [0]);
        assert_eq!(selection.kept, [0]);
        assert!(selection.frequencies[0] > 0.95 && selection.frequencies[1] < 0.3);
        let theta = design.solve(&vec![1.0; design.blocks()], &[0, 1]);
        assert!(
            (theta[0] - 0.8).abs() < 0.05 && (theta[1] + 0.5).abs() < 0.05,
            "{theta:?}"
        );
    }

    #[test]
    fn on_noise_alone_nothing_is_kept() {
        let design = design(2000, 0.0);
        let selection = stability_selection(&design, &groups(), &SelectionSettings::default());
        assert!(selection.kept.is_empty(), "{selection:?}");
    }

    /// A gain carried by two blocks is trimmed away; one spread over every block is kept.
    #[test]
    fn the_trimmed_gain_ignores_the_two_largest_blocks() {
        let transient: Vec<(f64, f64)> = (0..10)
            .map(|b| (1.0, if b < 2 { 5.0 } else { 0.0 }))
            .collect();
        assert_eq!(trimmed_gain(&transient), 0.0);
        let spread: Vec<(f64, f64)> = (0..10).map(|_| (1.0, 0.2)).collect();
        assert!((trimmed_gain(&spread) - 0.2).abs() < 1e-12);
    }

    /// Summing only the entries that involve the leading columns or the target, beside the
    /// trailing columns' own statistics, gives `from_samples`'s bits (the last block shorter).
    #[test]
    fn leading_columns_beside_fixed_ones_give_the_same_bits() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let rows: Vec<([f64; 6], f64)> = (0..1037)
            .map(|_| {
                let x = std::array::from_fn(|_| StandardNormal.sample(&mut rng));
                (x, StandardNormal.sample(&mut rng))
            })
            .collect();
        for leading in 0..=2 {
            let whole = BlockDesign::from_samples(rows.len(), 100, 6, |i, x| {
                x.copy_from_slice(&rows[i].0);
                rows[i].1
            });
            let trailing = BlockDesign::from_samples(rows.len(), 100, 6 - leading, |i, x| {
                x.copy_from_slice(&rows[i].0[leading..]);
                f64::NAN
            });
            let parts =
                BlockDesign::with_leading_columns(&trailing, rows.len(), 100, leading, |i, x| {
                    x.copy_from_slice(&rows[i].0);
                    rows[i].1
                });
            assert_eq!(parts.blocks(), 11);
            let bits = |d: &BlockDesign| -> Vec<u64> {
                let mut out = Vec::new();
                for b in 0..d.blocks() {
                    for i in 0..6 {
                        out.extend((0..6).map(|j| d.grams[b][(i, j)].to_bits()));
                        out.push(d.cross[b][i].to_bits());
                    }
                    out.push(d.target_squares[b].to_bits());
                    out.push(d.counts[b].to_bits());
                }
                out
            };
            assert_eq!(bits(&parts), bits(&whole), "{leading} leading columns");
        }
    }
}
