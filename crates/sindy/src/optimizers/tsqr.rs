//! A [`Problem`] with many rows, reduced as it is built to the triangle of a QR factorisation, so
//! that no later step touches the rows again (libraries of more than
//! [`crate::LARGE_LIBRARY_ENTRIES`] entries, and streamed recordings).
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

use super::Problem;
use crate::linalg::qr_triangle;

/// Rows of one block of the library (the memory of the reduction is about this many rows of Θ
/// per thread).
pub(crate) const BLOCK_ROWS: usize = 4096;
/// Blocks of one segment: segments are reduced in parallel, blocks within one in order.
const SEGMENT_BLOCKS: usize = 8;
/// Rows of one segment: the rows are cut into segments from the first row on, whatever the
/// number of threads or the way they arrive, so the result is the same.
pub(crate) const SEGMENT_ROWS: usize = BLOCK_ROWS * SEGMENT_BLOCKS;

/// Reduces the rows `0..rows`; `block(range)` returns Θ and Y on those rows (p and m columns),
/// or an error that stops the reduction.
pub(crate) fn reduce_row_blocks<E: Send>(
    rows: usize,
    features: usize,
    targets: usize,
    block: impl Fn(Range<usize>) -> std::result::Result<(Mat<f64>, Mat<f64>), E> + Sync,
) -> std::result::Result<Problem<'static>, E> {
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
pub(crate) fn reduce(theta: MatRef<'_, f64>, targets: MatRef<'_, f64>) -> Problem<'static> {
    let reduced: std::result::Result<_, std::convert::Infallible> =
        reduce_row_blocks(theta.nrows(), theta.ncols(), targets.ncols(), |range| {
            Ok((
                theta.subrows(range.start, range.len()).to_owned(),
                targets.subrows(range.start, range.len()).to_owned(),
            ))
        });
    match reduced {
        Ok(reduced) => reduced,
    }
}

/// The triangle of one segment's rows `0..rows` (at most [`SEGMENT_ROWS`]), its blocks in order.
pub(crate) fn segment_triangle<E>(
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
pub(crate) struct Reduction {
    triangle: Mat<f64>,
    features: usize,
    rows: usize,
}

impl Reduction {
    pub(crate) fn new(features: usize, targets: usize) -> Self {
        Self {
            triangle: Mat::zeros(0, features + targets),
            features,
            rows: 0,
        }
    }

    /// Merges the triangle of the next segment (of `rows` rows).
    pub(crate) fn merge(&mut self, segment: &Mat<f64>, rows: usize) {
        let (upper, lower) = segment.split_at_col(self.features);
        self.triangle = stacked_triangle(self.triangle.as_ref(), upper, lower);
        self.rows += rows;
    }

    /// `[[R, Z], [0, S]]` split into R, Z and the squared column norms of S.
    pub(crate) fn finish(self) -> Problem<'static> {
        let (triangle, features) = (self.triangle.as_ref(), self.features);
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
        Problem::from_triangle(triangular, projected, residual_squares, self.rows)
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
        let reduced = reduce(theta.as_ref(), y.as_ref());
        let gram = theta.transpose() * &theta;
        let moments = theta.transpose() * &y;
        let scale = gram.norm_max();
        assert_eq!(reduced.rows(), theta.nrows());
        assert!((reduced.gram() - &gram).norm_max() < 1e-11 * scale);
        assert!((reduced.moments() - &moments).norm_max() < 1e-11 * scale);
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
        let reduced = reduce(theta.as_ref(), y.as_ref());
        assert_eq!((reduced.features(), reduced.targets()), (6, 2));
        let gram = theta.transpose() * &theta;
        assert!((reduced.gram() - &gram).norm_max() < 1e-12 * gram.norm_max());
    }
}
