//! A least-squares problem `Θ ξ ≈ Y` with many rows, reduced as it is built to the triangle of a
//! QR factorisation, so that no later step touches the rows again.
//!
//! With `[Θ Y] = Q [[R, Z], [0, S]]` (Q with orthonormal columns, R: p × p, Z: p × m, S: m × m
//! upper triangular), for every ξ and every subset of columns `A`
//!
//! `‖Θ_A ξ − y_j‖² = ‖R_A ξ − z_j‖² + ‖s_j‖²`,
//!
//! so every least-squares, ridge and LASSO problem of STLSQ on Θ is the same problem on the
//! p-row matrix R, and the training residual of any ξ follows without Θ.
//!
//! The triangle is built by a tall-skinny QR over row blocks (TSQR): each block of the library
//! is evaluated, appended below the running triangle and factorised again, so memory is one
//! block and one triangle whatever the number of rows. A QR rather than the Gram matrix ΘᵀΘ:
//! the Gram matrix squares the condition number (a cubic library of raw, unscaled inputs easily
//! has κ(Θ) ≈ 10⁶, so κ² ≈ 10¹² and six significant digits left), while R from Householder QR is
//! backward stable and the refits on R are as accurate as a QR of Θ itself. The ridge steps use
//! RᵀR, as PySINDy's Cholesky ridge uses ΘᵀΘ.
//!
//! Deterministic whatever the number of threads: the rows are cut into segments of a fixed size,
//! each reduced on its own (in parallel), and the segments' triangles are combined in order.

use std::ops::Range;

use faer::{Mat, MatRef};
use rayon::prelude::*;

use crate::linalg::{product, qr_triangle};

/// Rows of one block of the library (the memory of the reduction is about this many rows of Θ
/// per thread).
pub const BLOCK_ROWS: usize = 4096;
/// Blocks of one segment: segments are reduced in parallel, blocks within one in order.
const SEGMENT_BLOCKS: usize = 8;
/// Rows of one segment: the rows are cut into segments from the first row on, whatever the
/// number of threads or the way they arrive, so the result is the same.
pub const SEGMENT_ROWS: usize = BLOCK_ROWS * SEGMENT_BLOCKS;

/// `Θ ξ ≈ Y` reduced to `R`, `Z = QᵀY` and the norms of the part of `Y` outside Θ's range.
#[derive(Clone, Debug)]
pub struct ReducedProblem {
    triangular: Mat<f64>,
    projected: Mat<f64>,
    /// Per target column: `‖s_j‖²`, the squared residual of the least-squares fit on all of Θ.
    residual_squares: Vec<f64>,
    rows: usize,
}

impl ReducedProblem {
    /// Reduces the rows `0..rows`; `block(range)` returns Θ and Y on those rows (p and m
    /// columns), or an error that stops the reduction.
    pub fn from_row_blocks<E: Send>(
        rows: usize,
        features: usize,
        targets: usize,
        block: impl Fn(Range<usize>) -> std::result::Result<(Mat<f64>, Mat<f64>), E> + Sync,
    ) -> std::result::Result<Self, E> {
        let segments: Vec<Range<usize>> = (0..rows.div_ceil(SEGMENT_ROWS))
            .map(|s| s * SEGMENT_ROWS..((s + 1) * SEGMENT_ROWS).min(rows))
            .collect();
        let triangles = segments
            .par_iter()
            .map(|segment| {
                segment_triangle(segment.len(), features + targets, |local| {
                    block(segment.start + local.start..segment.start + local.end)
                })
            })
            .collect::<std::result::Result<Vec<_>, E>>()?;
        let mut reduction = Reduction::new(features, targets);
        for (segment, triangle) in segments.iter().zip(&triangles) {
            reduction.merge(triangle, segment.len());
        }
        Ok(reduction.finish())
    }

    /// Reduces Θ and Y given whole.
    pub fn new(theta: MatRef<'_, f64>, targets: MatRef<'_, f64>) -> Self {
        let reduced: std::result::Result<Self, std::convert::Infallible> =
            Self::from_row_blocks(theta.nrows(), theta.ncols(), targets.ncols(), |range| {
                Ok((
                    theta.subrows(range.start, range.len()).to_owned(),
                    targets.subrows(range.start, range.len()).to_owned(),
                ))
            });
        match reduced {
            Ok(reduced) => reduced,
        }
    }

    fn from_triangle(triangle: MatRef<'_, f64>, features: usize, rows: usize) -> Self {
        let width = triangle.ncols();
        // Fewer rows than columns: the missing rows of the triangle are zero.
        let entry = |i: usize, j: usize| {
            if i < triangle.nrows() {
                triangle[(i, j)]
            } else {
                0.0
            }
        };
        let triangular = Mat::from_fn(features, features, &entry);
        let projected = Mat::from_fn(features, width - features, |i, j| entry(i, features + j));
        let residual_squares = (features..width)
            .map(|j| (features..width).map(|i| entry(i, j).powi(2)).sum())
            .collect();
        Self {
            triangular,
            projected,
            residual_squares,
            rows,
        }
    }

    /// R (p × p, upper triangular).
    pub fn triangular(&self) -> MatRef<'_, f64> {
        self.triangular.as_ref()
    }

    /// Z = QᵀY (p × m).
    pub fn projected(&self) -> MatRef<'_, f64> {
        self.projected.as_ref()
    }

    /// The number of rows of Θ.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// ΘᵀΘ = RᵀR.
    pub fn gram(&self) -> Mat<f64> {
        product(self.triangular.transpose(), self.triangular.as_ref())
    }

    /// ΘᵀY = RᵀZ.
    pub fn moments(&self) -> Mat<f64> {
        product(self.triangular.transpose(), self.projected.as_ref())
    }

    /// `‖Θ ξ_j − y_j‖²` for each target j, ξ one row per target (as [`crate::StlsqFit`]).
    pub fn residual_sum_of_squares(&self, coefficients: MatRef<'_, f64>) -> Vec<f64> {
        let fitted = product(self.triangular.as_ref(), coefficients.transpose());
        (0..self.projected.ncols())
            .map(|j| {
                let inside: f64 = (0..self.projected.nrows())
                    .map(|i| (fitted[(i, j)] - self.projected[(i, j)]).powi(2))
                    .sum();
                inside + self.residual_squares[j]
            })
            .collect()
    }
}

/// The triangle of one segment's rows `0..rows` (at most [`SEGMENT_ROWS`]), its blocks in order.
pub fn segment_triangle<E>(
    rows: usize,
    width: usize,
    block: impl Fn(Range<usize>) -> std::result::Result<(Mat<f64>, Mat<f64>), E>,
) -> std::result::Result<Mat<f64>, E> {
    let mut triangle = Mat::<f64>::zeros(0, width);
    for start in (0..rows).step_by(BLOCK_ROWS) {
        let (theta, y) = block(start..(start + BLOCK_ROWS).min(rows))?;
        triangle = stacked_triangle(triangle.as_ref(), theta.as_ref(), y.as_ref());
    }
    Ok(triangle)
}

/// Segments' triangles merged in row order into one reduced problem.
pub struct Reduction {
    triangle: Mat<f64>,
    features: usize,
    rows: usize,
}

impl Reduction {
    pub fn new(features: usize, targets: usize) -> Self {
        Self {
            triangle: Mat::zeros(0, features + targets),
            features,
            rows: 0,
        }
    }

    /// Merges the triangle of the next segment (of `rows` rows).
    pub fn merge(&mut self, segment: &Mat<f64>, rows: usize) {
        let (upper, lower) = segment.split_at_col(self.features);
        self.triangle = stacked_triangle(self.triangle.as_ref(), upper, lower);
        self.rows += rows;
    }

    pub fn finish(self) -> ReducedProblem {
        ReducedProblem::from_triangle(self.triangle.as_ref(), self.features, self.rows)
    }
}

/// The upper triangle (at most `width` rows) of the QR factorisation of
/// `[[triangle], [theta, y]]`.
fn stacked_triangle(
    triangle: MatRef<'_, f64>,
    theta: MatRef<'_, f64>,
    y: MatRef<'_, f64>,
) -> Mat<f64> {
    let width = triangle.ncols();
    let (above, below) = (triangle.nrows(), theta.nrows());
    let features = theta.ncols();
    let stacked = Mat::from_fn(above + below, width, |i, j| {
        if i < above {
            triangle[(i, j)]
        } else if j < features {
            theta[(i - above, j)]
        } else {
            y[(i - above, j - features)]
        }
    });
    if stacked.nrows() == 0 {
        return stacked;
    }
    qr_triangle(stacked.as_ref())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(rows: usize, features: usize) -> (Mat<f64>, Mat<f64>) {
        let theta = Mat::from_fn(rows, features, |i, j| {
            let x = (i as f64 * 0.37 + j as f64 * 1.3).sin();
            x.powi(j as i32 % 3 + 1) + 0.1 * j as f64
        });
        let y = Mat::from_fn(rows, 2, |i, j| {
            (0..features)
                .map(|k| theta[(i, k)] * (k as f64 - j as f64))
                .sum::<f64>()
                + 0.01 * ((i * 7 + j) as f64).cos()
        });
        (theta, y)
    }

    #[test]
    fn the_reduced_problem_has_the_library_gram_matrix_and_residuals() {
        // More rows than one segment, with a short last block.
        let (theta, y) = sample(SEGMENT_ROWS + 3 * BLOCK_ROWS + 17, 6);
        let reduced = ReducedProblem::new(theta.as_ref(), y.as_ref());
        let gram = theta.transpose() * &theta;
        let moments = theta.transpose() * &y;
        let scale = gram.norm_max();
        assert!((&reduced.gram() - &gram).norm_max() < 1e-11 * scale);
        assert!((&reduced.moments() - &moments).norm_max() < 1e-11 * scale);
        let xi = Mat::from_fn(2, 6, |j, k| 0.3 * k as f64 - j as f64);
        let direct: Vec<f64> = (0..2)
            .map(|j| {
                (0..theta.nrows())
                    .map(|i| {
                        let p: f64 = (0..6).map(|k| theta[(i, k)] * xi[(j, k)]).sum();
                        (p - y[(i, j)]).powi(2)
                    })
                    .sum()
            })
            .collect();
        let reduced_rss = reduced.residual_sum_of_squares(xi.as_ref());
        for (a, b) in direct.iter().zip(&reduced_rss) {
            assert!((a - b).abs() < 1e-9 * a.abs().max(1.0), "{a} {b}");
        }
    }

    #[test]
    fn fewer_rows_than_columns_give_a_padded_triangle() {
        let (theta, y) = sample(3, 6);
        let reduced = ReducedProblem::new(theta.as_ref(), y.as_ref());
        assert_eq!(reduced.triangular().shape(), (6, 6));
        let gram = theta.transpose() * &theta;
        assert!((&reduced.gram() - &gram).norm_max() < 1e-12 * gram.norm_max());
    }
}
