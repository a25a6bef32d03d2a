//! Small dense solvers on top of faer: least squares (as `numpy.linalg.lstsq` / scikit-learn's
//! `LinearRegression`) and the ridge normal equations (as scikit-learn's `ridge_regression`,
//! Cholesky solver).

use faer::linalg::solvers::{Qr, Solve, SolveLstsq};
use faer::{Mat, MatRef, Side};

/// Minimum-norm least-squares solution of `a·x ≈ b` (every column of `b` a right-hand side).
///
/// Full column rank (the usual case): Householder QR. Otherwise the SVD pseudo-inverse with
/// singular values below `ε·max(m, n)·σ_max` treated as zero, like LAPACK's `gelsd` in NumPy.
pub fn least_squares(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    if a.ncols() == 0 {
        return Mat::zeros(0, b.ncols());
    }
    let solution = match full_rank_qr(a) {
        Some((qr, _)) => qr.solve_lstsq(b),
        None => pseudo_inverse_solve(a, b),
    };
    clear_upper_vector_state();
    solution
}

/// The Householder QR of a tall `a` and its triangular factor R, if no diagonal entry of R is
/// negligible (`|R_ii| ≤ 1000·ε·max(m, n)·max|R_jj|` counts as rank-deficient).
pub fn full_rank_qr(a: MatRef<'_, f64>) -> Option<(Qr<f64>, Mat<f64>)> {
    if a.nrows() < a.ncols() {
        return None;
    }
    let qr = a.qr();
    let r = qr.thin_R().to_owned();
    clear_upper_vector_state();
    let diagonal: Vec<f64> = (0..r.ncols()).map(|i| r[(i, i)].abs()).collect();
    let largest = diagonal.iter().copied().fold(0.0, f64::max);
    let tolerance = 1e3 * rank_tolerance(a) * largest;
    clear_upper_vector_state();
    (largest > 0.0 && diagonal.iter().all(|&d| d > tolerance)).then_some((qr, r))
}

fn rank_tolerance(a: MatRef<'_, f64>) -> f64 {
    f64::EPSILON * a.nrows().max(a.ncols()) as f64
}

fn pseudo_inverse_solve(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    let Ok(svd) = a.thin_svd() else {
        return Mat::from_fn(a.ncols(), b.ncols(), |_, _| f64::NAN);
    };
    let (u, s, v) = (svd.U(), svd.S().column_vector(), svd.V());
    let largest = (0..s.nrows()).map(|i| s[i]).fold(0.0, f64::max);
    let cutoff = rank_tolerance(a) * largest;
    let mut projected = u.transpose() * b;
    for i in 0..s.nrows() {
        let inverse = if s[i] > cutoff { 1.0 / s[i] } else { 0.0 };
        for j in 0..projected.ncols() {
            projected[(i, j)] *= inverse;
        }
    }
    v * projected
}

/// Solves the ridge normal equations `(G + α·I)·x = g` for a symmetric positive semi-definite
/// Gram matrix `G = AᵀA` and `g = Aᵀb`: Cholesky, or the pseudo-inverse if `G + αI` is singular.
pub fn ridge_from_gram(gram: MatRef<'_, f64>, rhs: MatRef<'_, f64>, alpha: f64) -> Mat<f64> {
    let mut shifted = gram.to_owned();
    for i in 0..shifted.nrows() {
        shifted[(i, i)] += alpha;
    }
    let solution = match shifted.llt(Side::Lower) {
        Ok(cholesky) => cholesky.solve(rhs),
        Err(_) => pseudo_inverse_solve(shifted.as_ref(), rhs),
    };
    clear_upper_vector_state();
    solution
}

/// Clears the upper halves of the AVX registers (`vzeroupper`).
///
/// faer's SIMD kernels can return with the upper register state dirty; the scalar code that follows
/// (compiled for baseline x86-64, SSE encoding), and libm's `sin`/`cos` with it, then pays a
/// transition penalty on every instruction: measured ~20x slower feature evaluation after a fit.
#[inline]
pub(crate) fn clear_upper_vector_state() {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the CPU supports AVX, checked just above.
        unsafe { zero_upper() }
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
fn zero_upper() {
    std::arch::x86_64::_mm256_zeroupper();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn least_squares_solves_full_rank_and_minimum_norm_problems() {
        let a = Mat::from_fn(6, 2, |i, j| (i as f64 + 1.0).powi(j as i32));
        let b = Mat::from_fn(6, 1, |i, _| 2.0 - 0.5 * (i as f64 + 1.0));
        let x = least_squares(a.as_ref(), b.as_ref());
        assert!((x[(0, 0)] - 2.0).abs() < 1e-12 && (x[(1, 0)] + 0.5).abs() < 1e-12);

        // Two identical columns: the minimum-norm solution splits the weight equally.
        let twin = Mat::from_fn(5, 2, |i, _| i as f64 + 1.0);
        let y = Mat::from_fn(5, 1, |i, _| 2.0 * (i as f64 + 1.0));
        let x = least_squares(twin.as_ref(), y.as_ref());
        assert!((x[(0, 0)] - 1.0).abs() < 1e-10 && (x[(1, 0)] - 1.0).abs() < 1e-10);
    }

    #[test]
    fn ridge_matches_the_closed_form() {
        let a = Mat::from_fn(8, 3, |i, j| ((i * 3 + j) as f64 * 0.7).sin());
        let b = Mat::from_fn(8, 1, |i, _| i as f64 * 0.1);
        let gram = a.transpose() * &a;
        let rhs = a.transpose() * &b;
        let x = ridge_from_gram(gram.as_ref(), rhs.as_ref(), 0.3);
        // gradient of ||Ax − b||² + α||x||² vanishes
        let residual = &a * &x - &b;
        let gradient = a.transpose() * residual + &x * faer::Scale(0.3);
        assert!(gradient.norm_max() < 1e-12, "{}", gradient.norm_max());
    }
}
