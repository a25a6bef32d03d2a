//! A [`Problem`] with many rows, reduced as it is built to p rows (the triangle of a QR
//! factorisation), so that no later step touches the rows again (libraries of more than
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
//! Two ways to R ([`RowReduction`]): the Gram matrix `[Θ Y]ᵀ[Θ Y]` summed over row blocks and
//! factored once (half the flops, at the speed of a matrix product), kept only where its checks
//! find it as accurate as the triangle ([`super::gram`]); otherwise a tall-skinny QR over row
//! blocks (TSQR): each block of the library is appended below the running triangle and
//! factorised again (Householder), backward stable whatever the conditioning. Memory is one
//! block and one triangle (or Gram matrix) per thread whatever the number of rows.
//!
//! Deterministic whatever the number of threads: the rows are cut into segments of a fixed size,
//! each reduced on its own (in parallel), and the segments' parts are combined in order.

use std::ops::Range;

use faer::{Mat, MatRef};
use rayon::prelude::*;

use super::Problem;
use super::gram::{reduced_from_sums, residual_resolved};
use crate::linalg::{add_gram, qr_triangle};

/// Rows of one block of the library (the memory of the reduction is about this many rows of Θ
/// per thread).
pub(crate) const BLOCK_ROWS: usize = 4096;
/// Blocks of one segment: segments are reduced in parallel, blocks within one in order.
const SEGMENT_BLOCKS: usize = 8;
/// Rows of one segment: the rows are cut into segments from the first row on, whatever the
/// number of threads or the way they arrive, so the result is the same.
pub(crate) const SEGMENT_ROWS: usize = BLOCK_ROWS * SEGMENT_BLOCKS;

/// How the rows of a fit too long to hold whole are reduced to the p rows of R.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RowReduction {
    /// The Gram matrix, kept when its checks find it as accurate as the QR triangle
    /// ([`crate::GRAM_CONDITION_LIMIT`], [`crate::GRAM_RESIDUAL_SHARE`]), the rows reduced again
    /// by [`RowReduction::Householder`] otherwise.
    #[default]
    Gram,
    /// Householder QR by row blocks (TSQR), whatever the conditioning.
    Householder,
}

/// How a fit's rows were reduced: the method that made the problem, and the Gram matrix's scaled
/// condition number `κ_F(R·D⁻¹)` when it was factored (also when it was then refused).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reduction {
    pub method: RowReduction,
    pub gram_condition: Option<f64>,
}

/// Reduces the rows `0..rows` by `method` (Householder as well, if the Gram matrix is refused)
/// and solves the problem with `solve` (which returns it, and ξ with one row per target);
/// `block(range, theta)` writes Θ on those rows into `theta` (p columns) and returns Y (m
/// columns), or an error that stops it.
pub(crate) fn reduce_row_blocks<E: Send>(
    method: RowReduction,
    (rows, features, targets): (usize, usize, usize),
    block: impl Fn(Range<usize>, &mut Mat<f64>) -> std::result::Result<Mat<f64>, E> + Sync,
    solve: impl FnMut(Problem<'static>) -> std::result::Result<Solved, E>,
) -> std::result::Result<(Solved, Reduction), E> {
    let segments: Vec<Range<usize>> = (0..rows.div_ceil(SEGMENT_ROWS))
        .map(|s| s * SEGMENT_ROWS..((s + 1) * SEGMENT_ROWS).min(rows))
        .collect();
    let attempt = |method| {
        let parts = segments
            .par_iter()
            .map(|segment| {
                segment_part(method, segment.len(), features + targets, |local, theta| {
                    block(
                        segment.start + local.start..segment.start + local.end,
                        theta,
                    )
                })
            })
            .collect::<std::result::Result<Vec<_>, E>>()?;
        let mut merge = RowMerge::new(method, features, targets);
        for (segment, part) in segments.iter().zip(&parts) {
            merge.add(part, segment.len());
        }
        Ok((merge, ()))
    };
    let (solved, (), reduction) = reduce_by(method, attempt, solve)?;
    Ok((solved, reduction))
}

/// A reduced problem and the coefficients solved on it (one row per target).
pub(crate) type Solved = (Problem<'static>, Mat<f64>);

/// The problem of the first of `method`'s reductions kept, solved: `attempt` reduces every row by
/// the method it is given (with something of its own, `T`) and `solve` solves it; Householder
/// follows a Gram matrix refused before the solve (its conditioning) or after (the chosen
/// model's residual, [`residual_resolved`]).
pub(crate) fn reduce_by<T, E>(
    method: RowReduction,
    mut attempt: impl FnMut(RowReduction) -> std::result::Result<(RowMerge, T), E>,
    mut solve: impl FnMut(Problem<'static>) -> std::result::Result<Solved, E>,
) -> std::result::Result<(Solved, T, Reduction), E> {
    let mut gram_condition = None;
    for &method in methods_from(method) {
        let (merge, own) = attempt(method)?;
        let finished = merge.finish();
        gram_condition = gram_condition.or(finished.gram_condition);
        let Some(problem) = finished.problem else {
            continue;
        };
        let (problem, coefficients) = solve(problem)?;
        if let Some(squares) = &finished.target_squares
            && !residual_resolved(&problem, coefficients.as_ref(), squares)
        {
            continue;
        }
        let reduction = Reduction {
            method,
            gram_condition,
        };
        return Ok(((problem, coefficients), own, reduction));
    }
    unreachable!("the Householder reduction always gives a problem")
}

/// The methods to try in order: `method`, then Householder if it was the Gram matrix.
fn methods_from(method: RowReduction) -> &'static [RowReduction] {
    match method {
        RowReduction::Gram => &[RowReduction::Gram, RowReduction::Householder],
        RowReduction::Householder => &[RowReduction::Householder],
    }
}

/// Reduces Θ and Y given whole (the Gram matrix judged by the least-squares solution's residual).
pub(crate) fn reduce(theta: MatRef<'_, f64>, targets: MatRef<'_, f64>) -> Problem<'static> {
    reduce_whole(RowReduction::default(), theta, targets).0
}

/// [`reduce`] by `method`, with how the rows were reduced.
fn reduce_whole(
    method: RowReduction,
    theta: MatRef<'_, f64>,
    targets: MatRef<'_, f64>,
) -> (Problem<'static>, Reduction) {
    let shape = (theta.nrows(), theta.ncols(), targets.ncols());
    let block = |range: Range<usize>, out: &mut Mat<f64>| {
        let rows = theta.subrows(range.start, range.len());
        out.resize_with(rows.nrows(), rows.ncols(), |_, _| 0.0);
        out.copy_from(rows);
        Ok(targets.subrows(range.start, range.len()).to_owned())
    };
    let solve = |problem: Problem<'static>| {
        let coefficients = problem.least_squares_solution().transpose().to_owned();
        Ok((problem, coefficients))
    };
    let reduced: std::result::Result<_, std::convert::Infallible> =
        reduce_row_blocks(method, shape, block, solve);
    match reduced {
        Ok(((problem, _), reduction)) => (problem, reduction),
    }
}

/// One segment's rows `0..rows` (at most [`SEGMENT_ROWS`]) reduced by `method`, its blocks in
/// order: their Gram matrix's lower triangle, or their QR triangle.
pub(crate) fn segment_part<E>(
    method: RowReduction,
    rows: usize,
    width: usize,
    mut block: impl FnMut(Range<usize>, &mut Mat<f64>) -> std::result::Result<Mat<f64>, E>,
) -> std::result::Result<Mat<f64>, E> {
    let mut part = match method {
        RowReduction::Gram => Mat::<f64>::zeros(width, width),
        RowReduction::Householder => Mat::<f64>::zeros(0, width),
    };
    // One Θ for the segment's blocks: its pages are mapped once, not once per block.
    let mut theta = Mat::new();
    for start in (0..rows).step_by(BLOCK_ROWS) {
        let y = block(start..(start + BLOCK_ROWS).min(rows), &mut theta)?;
        match method {
            RowReduction::Gram => add_gram(part.as_mut(), theta.as_ref(), y.as_ref()),
            RowReduction::Householder => {
                part = stacked_triangle(part.as_ref(), theta.as_ref(), y.as_ref());
            }
        }
    }
    Ok(part)
}

/// Segments' parts merged in row order into one reduced problem.
pub(crate) struct RowMerge {
    method: RowReduction,
    part: Mat<f64>,
    features: usize,
    rows: usize,
}

/// A finished merge: its problem (`None` when the Gram matrix was refused), the Gram matrix's
/// scaled condition number, and each target's sum of squares (from a Gram matrix: what its
/// chosen model's residual is compared with).
pub(crate) struct Finished {
    pub(crate) problem: Option<Problem<'static>>,
    pub(crate) gram_condition: Option<f64>,
    pub(crate) target_squares: Option<Vec<f64>>,
}

impl Finished {
    /// The Gram matrix refused, its scaled condition number if it was factored.
    pub(crate) fn refused(gram_condition: Option<f64>) -> Self {
        Self {
            problem: None,
            gram_condition,
            target_squares: None,
        }
    }
}

impl RowMerge {
    pub(crate) fn new(method: RowReduction, features: usize, targets: usize) -> Self {
        let width = features + targets;
        let part = match method {
            RowReduction::Gram => Mat::zeros(width, width),
            RowReduction::Householder => Mat::zeros(0, width),
        };
        Self {
            method,
            part,
            features,
            rows: 0,
        }
    }

    /// Merges the part of the next segment (of `rows` rows).
    pub(crate) fn add(&mut self, segment: &Mat<f64>, rows: usize) {
        match self.method {
            RowReduction::Gram => self.part += segment,
            RowReduction::Householder => {
                let (upper, lower) = segment.split_at_col(self.features);
                self.part = stacked_triangle(self.part.as_ref(), upper, lower);
            }
        }
        self.rows += rows;
    }

    /// The reduced problem, for the Householder triangle `[[R, Z], [0, S]]` split into R, Z and
    /// the squared column norms of S.
    pub(crate) fn finish(self) -> Finished {
        if self.method == RowReduction::Gram {
            return reduced_from_sums(self.part.as_ref(), self.features, self.rows);
        }
        let (triangle, features) = (self.part.as_ref(), self.features);
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
        Finished {
            problem: Some(Problem::from_triangle(
                triangular,
                projected,
                residual_squares,
                self.rows,
            )),
            gram_condition: None,
            target_squares: None,
        }
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
    use crate::{GRAM_CONDITION_LIMIT, Problem};

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

    /// Θ and Y reduced by `method`, with how.
    fn reduced_by(
        method: RowReduction,
        theta: &Mat<f64>,
        y: &Mat<f64>,
    ) -> (Problem<'static>, Reduction) {
        reduce_whole(method, theta.as_ref(), y.as_ref())
    }

    /// A noisy least-squares problem: Θ well conditioned, Y a tenth noise.
    fn noisy(rows: usize, features: usize) -> (Mat<f64>, Mat<f64>) {
        let (theta, y) = sample(rows, features);
        let noise = |i: usize, j: usize| ((i * 31 + j * 17) as f64 * 0.618).sin();
        let scale = y.norm_max();
        (
            theta,
            Mat::from_fn(rows, 2, |i, j| y[(i, j)] + 0.1 * scale * noise(i, j)),
        )
    }

    #[test]
    fn the_reduced_problem_has_the_library_gram_matrix_and_residuals() {
        // More rows than one segment, with a short last block; both methods.
        let (theta, y) = noisy(SEGMENT_ROWS + 3 * BLOCK_ROWS + 17, 6);
        for method in [RowReduction::Gram, RowReduction::Householder] {
            let (reduced, reduction) = reduced_by(method, &theta, &y);
            assert_eq!(reduction.method, method);
            assert_eq!(
                reduction.gram_condition.is_some(),
                method == RowReduction::Gram
            );
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
    }

    #[test]
    fn the_gram_matrix_is_refused_where_it_would_lose_digits() {
        let rows = SEGMENT_ROWS + 5;
        let (theta, y) = noisy(rows, 6);
        let householder = |reduction: Reduction| reduction.method == RowReduction::Householder;
        // Two nearly equal columns: scaled κ far over the limit.
        let near = Mat::from_fn(rows, 6, |i, j| match j {
            5 => theta[(i, 4)] * (1.0 + 1e-7 * (i as f64 * 0.1).cos()),
            _ => theta[(i, j)],
        });
        let (_, reduction) = reduced_by(RowReduction::Gram, &near, &y);
        assert!(householder(reduction));
        assert!(reduction.gram_condition.unwrap() > GRAM_CONDITION_LIMIT);
        // Targets in Θ's range up to rounding: no residual left to take from the Gram matrix.
        let exact = Mat::from_fn(rows, 2, |i, j| theta[(i, j)] - theta[(i, 3)]);
        let (_, reduction) = reduced_by(RowReduction::Gram, &theta, &exact);
        assert!(householder(reduction));
        assert!(reduction.gram_condition.unwrap() <= GRAM_CONDITION_LIMIT);
        // A column of zeros: not positive definite.
        let zero = Mat::from_fn(rows, 6, |i, j| if j == 2 { 0.0 } else { theta[(i, j)] });
        let (_, reduction) = reduced_by(RowReduction::Gram, &zero, &y);
        assert!(householder(reduction) && reduction.gram_condition.is_none());
        // Either way the problem is the triangle's.
        let (refused, _) = reduced_by(RowReduction::Gram, &near, &y);
        let (triangle, _) = reduced_by(RowReduction::Householder, &near, &y);
        assert_eq!(refused.gram(), triangle.gram());
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
