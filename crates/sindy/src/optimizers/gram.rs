//! The Gram reduction of many rows, kept only where it is as accurate as the QR triangle.
//!
//! The sums `G = [Θ Y]ᵀ[Θ Y]` over the row blocks (a symmetric rank-k update: half the flops of
//! Householder's TSQR, at the rate of a matrix product) give the same reduced problem as the
//! triangle: with `ΘᵀΘ = RᵀR` (Cholesky), `Z = R⁻ᵀ ΘᵀY` and `‖s_j‖² = ‖y_j‖² − ‖z_j‖²`.
//!
//! Forming G squares the condition number, so the solution's relative error grows as
//! `κ(Θ)²·ε` against the triangle's `κ(Θ)·ε` (plus, for both, `κ(Θ)²·ε` times the relative
//! residual, which the noise of real data makes the larger term). The reduction is kept only if
//!
//! - the Cholesky factorisation succeeds;
//! - with D the columns' norms, `κ_F(R·D⁻¹) = ‖R·D⁻¹‖_F·‖D·R⁻¹‖_F ≤` [`GRAM_CONDITION_LIMIT`]: the
//!   scaled condition number (the one Cholesky's accuracy depends on, van der Sluis), bounded from
//!   above, so that `κ₂² ε ≤ 2·10⁻⁸`;
//! - the model chosen on it leaves every target at least [`GRAM_RESIDUAL_SHARE`] of its sum of
//!   squares as residual, so that the score's `‖y_j‖² − ‖z_j‖²` part does not lose more than six
//!   of its digits to cancellation (checked by [`super::row_blocks`] once the model is solved).
//!
//! Otherwise the caller reduces the rows again by Householder QR ([`super::row_blocks`]).

use faer::{Mat, MatRef};

use super::Problem;
use super::row_blocks::Finished;
use crate::linalg::{cholesky_upper, invert_upper, solve_upper_transposed};

/// Largest scaled condition number `κ_F(R·D⁻¹)` at which the Gram reduction is kept.
pub const GRAM_CONDITION_LIMIT: f64 = 1e4;

/// Smallest share of a target's sum of squares left as the chosen model's residual at which the
/// Gram reduction is kept.
pub const GRAM_RESIDUAL_SHARE: f64 = 1e-6;

/// The reduced problem of the sums `sums` (lower triangle of `[Θ Y]ᵀ[Θ Y]`, `features` columns of
/// Θ) over `rows` rows, with its scaled condition number; no problem when the checks above refuse
/// it.
pub(crate) fn reduced_from_sums(sums: MatRef<'_, f64>, features: usize, rows: usize) -> Finished {
    let library = sums.submatrix(0, 0, features, features);
    let Some(triangular) = cholesky_upper(library) else {
        return Finished::refused(None);
    };
    let condition = scaled_condition(triangular.as_ref(), library);
    if !condition.is_some_and(|condition| condition <= GRAM_CONDITION_LIMIT) {
        return Finished::refused(condition);
    }
    let targets = sums.ncols() - features;
    let cross = sums.submatrix(features, 0, targets, features).transpose();
    let projected = solve_upper_transposed(triangular.as_ref(), cross);
    let target_squares: Vec<f64> = (0..targets)
        .map(|j| sums[(features + j, features + j)])
        .collect();
    let residual_squares = (target_squares.iter().enumerate())
        .map(|(j, total)| {
            let explained: f64 = projected.col(j).iter().map(|z| z * z).sum();
            (total - explained).max(0.0)
        })
        .collect();
    Finished {
        problem: Some(Problem::from_triangle(
            triangular,
            projected,
            residual_squares,
            rows,
        )),
        gram_condition: condition,
        target_squares: Some(target_squares),
    }
}

/// Whether the model `coefficients` (one row per target) chosen on a Gram reduction leaves every
/// target at least [`GRAM_RESIDUAL_SHARE`] of its sum of squares `target_squares` as residual.
pub(crate) fn residual_resolved(
    problem: &Problem<'_>,
    coefficients: MatRef<'_, f64>,
    target_squares: &[f64],
) -> bool {
    let residuals = problem.residual_sum_of_squares(coefficients);
    (residuals.iter().zip(target_squares))
        .all(|(residual, total)| *residual >= GRAM_RESIDUAL_SHARE * total)
}

/// `‖R·D⁻¹‖_F·‖D·R⁻¹‖_F`, with D the square roots of the Gram matrix's diagonal; `None` for a
/// zero column.
fn scaled_condition(triangular: MatRef<'_, f64>, gram: MatRef<'_, f64>) -> Option<f64> {
    let norms: Vec<f64> = (0..gram.nrows()).map(|j| gram[(j, j)].sqrt()).collect();
    if !norms.iter().all(|&norm| norm > 0.0) {
        return None;
    }
    let scaled = Mat::from_fn(triangular.nrows(), triangular.ncols(), |i, j| {
        triangular[(i, j)] / norms[j]
    });
    let inverse = invert_upper(scaled.as_ref());
    Some(frobenius(scaled.as_ref()) * frobenius(inverse.as_ref()))
}

fn frobenius(matrix: MatRef<'_, f64>) -> f64 {
    let squares = |j: usize| matrix.col(j).iter().map(|x| x * x).sum::<f64>();
    (0..matrix.ncols()).map(squares).sum::<f64>().sqrt()
}
