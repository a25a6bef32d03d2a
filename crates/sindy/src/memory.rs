//! The memory a fit needs, estimated from its shape before any of it is allocated, so that a
//! caller can refuse a fit the machine cannot hold instead of failing inside it (faer's
//! matrices and solvers abort or panic when an allocation fails; they have no fallible form).
//!
//! The estimate counts the f64 entries alive together at the peak of each phase of the path the
//! fit takes, with n rows, p features, m targets, W = p + m, and `threads` workers, and takes
//! the largest:
//!
//! - **Θ whole** (n·p ≤ [`crate::LARGE_LIBRARY_ENTRIES`]): Θ and its QR (CholeskyQR2's Q₁ or
//!   Householder's copy), 2·n·p, the Gram matrix, R and their factors, 5·p², and per target
//!   fitted at once (up to `threads`) the STLSQ steps on Θ itself: 9·p².
//! - **Row blocks** (larger libraries; streamed recordings always): every segment being reduced
//!   holds its triangle (r = min(segment rows, W) rows of W), one block of Θ and Y (B rows) and
//!   the stacked matrix with its QR copy: (4·r + 3·B)·W. Reduced segments wait with their
//!   triangles (all of them for a matrix given whole, one batch of `threads` when streamed); the
//!   merge of two triangles holds 6·W². The optimizer then holds R, the Gram matrix and their
//!   solution, 3·p² + 3·p·m, and per target fitted at once a sub-Gram matrix, its shifted copy
//!   and factor, and a refit's QR or SVD: 6·p².
//! - The LASSO's quadratic program and its factorisation: 8·p² per target instead of STLSQ's.
//!
//! Measured (peak resident memory less the process's 30 MB, two threads): 1,000 rows × 861
//! features 147 MB against 149 MB estimated; 2,000 × 1,891: 598 MB against 718 MB; 3,400 ×
//! 3,321 (row blocks) 840 MB, rank-deficient 636 MB, against 1.3 GB.

use crate::optimizers::OptimizerSpec;
use crate::optimizers::row_blocks::{BLOCK_ROWS, SEGMENT_ROWS};

/// Bytes of one matrix entry.
const ENTRY_BYTES: f64 = 8.0;

/// How the rows of a fit arrive.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RowSource {
    /// In memory, as [`crate::SindyParams::fit`] and [`crate::SindyParams::fit_matrices`] take
    /// them.
    Whole,
    /// In blocks, as [`crate::SindyParams::fit_streamed`] takes them.
    Streamed,
}

/// The shape of a fit: what its memory depends on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FitShape {
    pub rows: usize,
    pub features: usize,
    pub targets: usize,
    pub source: RowSource,
    /// The worker threads (rayon's pool).
    pub threads: usize,
}

impl FitShape {
    /// The estimated peak bytes of the fit with `optimizer` (see the module documentation);
    /// counted in floating point, so that absurd shapes saturate at `u64::MAX`.
    pub fn peak_bytes(&self, optimizer: &OptimizerSpec) -> u64 {
        let entries = if self.library_whole() {
            self.reduction_entries() + self.optimizer_entries(optimizer)
        } else {
            self.reduction_entries()
                .max(self.optimizer_entries(optimizer))
        };
        // `as` saturates a float too large for u64.
        (entries * ENTRY_BYTES) as u64
    }

    /// Whether the fit forms Θ whole (kept while the optimizer runs) rather than by row blocks.
    fn library_whole(&self) -> bool {
        self.source == RowSource::Whole
            && self.rows.saturating_mul(self.features) <= crate::LARGE_LIBRARY_ENTRIES
    }

    /// Entries of the library and its reduction (Θ whole, or by row blocks).
    fn reduction_entries(&self) -> f64 {
        let (n, p, m) = (self.rows as f64, self.features as f64, self.targets as f64);
        let threads = self.threads.max(1) as f64;
        if self.library_whole() {
            return 2.0 * n * p + 2.0 * n * m + 5.0 * p * p;
        }
        let width = p + m;
        let segment_rows = n.min(SEGMENT_ROWS as f64);
        let block_rows = n.min(BLOCK_ROWS as f64);
        let triangle_rows = segment_rows.min(width);
        let segments = (n / SEGMENT_ROWS as f64).ceil().max(1.0);
        let reducing = segments.min(threads);
        let waiting = match self.source {
            RowSource::Whole => segments,
            RowSource::Streamed => threads.min(segments),
        };
        let per_segment = (4.0 * triangle_rows + 3.0 * block_rows) * width;
        let reduce = reducing * per_segment + (waiting - reducing) * triangle_rows * width;
        let merge = waiting * triangle_rows * width + 6.0 * width * width;
        reduce.max(merge)
    }

    /// Entries of the optimizer on the reduced problem (beyond Θ and its factors when whole).
    fn optimizer_entries(&self, optimizer: &OptimizerSpec) -> f64 {
        let (p, m) = (self.features as f64, self.targets as f64);
        let at_once = (self.threads.max(1) as f64).min(m.max(1.0));
        let (shared, per_target) = match (optimizer, self.library_whole()) {
            (OptimizerSpec::Lasso { .. }, _) => (3.0, 8.0),
            (OptimizerSpec::Stlsq { .. }, true) => (0.0, 9.0),
            (OptimizerSpec::Stlsq { .. }, false) => (3.0, 6.0),
        };
        shared * p * p + 3.0 * p * m + at_once * per_target * p * p
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shape(rows: usize, features: usize, source: RowSource, threads: usize) -> FitShape {
        FitShape {
            rows,
            features,
            targets: 3,
            source,
            threads,
        }
    }

    #[test]
    fn small_fits_are_small_and_large_libraries_grow_with_features_squared() {
        let stlsq = OptimizerSpec::stlsq(0.1);
        let small = shape(1000, 10, RowSource::Whole, 2).peak_bytes(&stlsq);
        assert!(small < 1 << 20, "{small}");
        let thousand = shape(20_000, 1000, RowSource::Whole, 2).peak_bytes(&stlsq);
        let two_thousand = shape(20_000, 2000, RowSource::Whole, 2).peak_bytes(&stlsq);
        assert!(
            two_thousand > 3 * thousand && two_thousand < 5 * thousand,
            "{thousand} {two_thousand}"
        );
        // More threads hold more at once; a streamed recording holds one batch of triangles.
        let one = shape(500_000, 2000, RowSource::Whole, 1).peak_bytes(&stlsq);
        let four = shape(500_000, 2000, RowSource::Whole, 4).peak_bytes(&stlsq);
        let streamed = shape(500_000, 2000, RowSource::Streamed, 4).peak_bytes(&stlsq);
        assert!(one < four && streamed < four, "{one} {four} {streamed}");
        // Absurd shapes saturate instead of overflowing.
        let absurd = shape(usize::MAX, usize::MAX, RowSource::Whole, 64);
        assert_eq!(absurd.peak_bytes(&stlsq), u64::MAX);
    }
}
