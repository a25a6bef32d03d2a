//! The crate's dense linear algebra on faer, and the only module that calls faer's kernels: least
//! squares (as `numpy.linalg.lstsq` / scikit-learn's `LinearRegression`), the ridge normal
//! equations (as scikit-learn's `ridge_regression`, Cholesky solver), products, QR triangles and
//! triangular solves.
//!
//! # The vector state after faer
//! faer's matrix products (its assembly gemm kernels) return with the upper halves of the vector
//! registers still in use. The scalar code that follows — compiled for baseline x86-64 in the SSE
//! encoding, libm's `sin`/`cos` with it — then pays a penalty on every instruction until a
//! `vzeroupper`: the feature evaluation after a fit ran ~20x slower on the machine that found it
//! (2.6x for `sin` on an AMD EPYC). Every function here therefore runs its faer calls inside
//! [`kernels`], the one place that clears that state (thread by thread: the optimizers call these
//! functions from rayon's workers too), so that nothing built on this module — an optimizer, a
//! prediction, the row-block reduction — can forget it. `tests/vector_state.rs` checks it on every
//! public entry point.

use faer::linalg::matmul::triangular::{BlockStructure, matmul};
use faer::linalg::solvers::{Qr, Solve, SolveLstsq};
use faer::linalg::triangular_solve::{
    solve_lower_triangular_in_place, solve_upper_triangular_in_place,
};
use faer::{Accum, Mat, MatMut, MatRef, Par, Side};

/// Runs `work`, which calls faer, and leaves the vector registers' upper halves clear (see the
/// module documentation): every faer call of the crate runs inside it.
fn kernels<T>(work: impl FnOnce() -> T) -> T {
    let result = work();
    clear_upper_vector_state();
    result
}

/// Minimum-norm least-squares solution of `a·x ≈ b` (every column of `b` a right-hand side).
///
/// Full column rank (the usual case): Householder QR. Otherwise the SVD pseudo-inverse with
/// singular values below `ε·max(m, n)·σ_max` treated as zero, like LAPACK's `gelsd` in NumPy.
///
/// ```
/// use sindy::{Mat, least_squares};
/// // y = 2 − 0.5·t at t = 1..6
/// let a = Mat::from_fn(6, 2, |i, j| (i as f64 + 1.0).powi(j as i32));
/// let b = Mat::from_fn(6, 1, |i, _| 2.0 - 0.5 * (i as f64 + 1.0));
/// let x = least_squares(a.as_ref(), b.as_ref());
/// assert!((x[(0, 0)] - 2.0).abs() < 1e-12 && (x[(1, 0)] + 0.5).abs() < 1e-12);
/// ```
pub fn least_squares(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    kernels(|| {
        if a.ncols() == 0 {
            return Mat::zeros(0, b.ncols());
        }
        match full_rank_qr(a) {
            Some((qr, _)) => qr.solve_lstsq(b),
            None => pseudo_inverse_solve(a, b),
        }
    })
}

/// The product `a·b` (`a.transpose()` for `aᵀ·b`: the Gram matrix, the moments).
pub(crate) fn product(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    kernels(|| a * b)
}

/// Householder least squares of a tall `a` of full column rank: its triangular factor R and the
/// solution for every column of `b`; `None` when `a` is wide or rank-deficient (see
/// [`full_rank_qr`]).
pub(crate) fn householder_least_squares(
    a: MatRef<'_, f64>,
    b: MatRef<'_, f64>,
) -> Option<(Mat<f64>, Mat<f64>)> {
    kernels(|| {
        let (qr, r) = full_rank_qr(a)?;
        Some((r, qr.solve_lstsq(b)))
    })
}

/// The Householder QR of a tall `a` and its triangular factor R, if no diagonal entry of R is
/// negligible (`|R_ii| ≤ 1000·ε·max(m, n)·max|R_jj|` counts as rank-deficient). Inside
/// [`kernels`] only.
fn full_rank_qr(a: MatRef<'_, f64>) -> Option<(Qr<f64>, Mat<f64>)> {
    if a.nrows() < a.ncols() {
        return None;
    }
    let qr = a.qr();
    let r = qr.thin_R().to_owned();
    full_rank_triangular(a, r.as_ref()).then_some((qr, r))
}

/// The upper triangle R (at most `stacked.ncols()` rows) of the QR factorisation of `stacked`.
pub(crate) fn qr_triangle(stacked: MatRef<'_, f64>) -> Mat<f64> {
    kernels(|| stacked.qr().thin_R().to_owned())
}

/// `r⁻¹·rhs` for an upper triangular `r`.
pub(crate) fn solve_upper(r: MatRef<'_, f64>, rhs: MatRef<'_, f64>) -> Mat<f64> {
    kernels(|| {
        let mut solution = rhs.to_owned();
        solve_upper_triangular_in_place(r, solution.as_mut(), Par::Seq);
        solution
    })
}

/// Adds the lower triangle of `[a b]ᵀ[a b]` to `sums` (p + m square, for `a` of p columns and `b`
/// of m): `aᵀa` and `bᵀb` as lower triangles, `bᵀa` whole below them. Each product is summed in
/// one fixed order, whatever the thread count.
pub(crate) fn add_gram(sums: MatMut<'_, f64>, a: MatRef<'_, f64>, b: MatRef<'_, f64>) {
    let p = a.ncols();
    let (top, bottom) = sums.split_at_row_mut(p);
    let (library, _) = top.split_at_col_mut(p);
    let (cross, targets) = bottom.split_at_col_mut(p);
    kernels(|| {
        let lower = |dst: MatMut<'_, f64>, left: MatRef<'_, f64>| {
            let rect = BlockStructure::Rectangular;
            let structure = BlockStructure::TriangularLower;
            matmul(
                dst,
                structure,
                Accum::Add,
                left.transpose(),
                rect,
                left,
                rect,
                1.0,
                Par::Seq,
            );
        };
        lower(library, a);
        lower(targets, b);
        faer::linalg::matmul::matmul(cross, Accum::Add, b.transpose(), a, 1.0, Par::Seq);
    })
}

/// The upper triangular R with RᵀR = `gram` (its lower triangle read), if it is numerically
/// positive definite.
pub(crate) fn cholesky_upper(gram: MatRef<'_, f64>) -> Option<Mat<f64>> {
    kernels(|| upper_cholesky(gram))
}

/// The inverse of an upper triangular `r`.
pub(crate) fn invert_upper(r: MatRef<'_, f64>) -> Mat<f64> {
    kernels(|| upper_triangular_inverse(r))
}

/// `r⁻ᵀ·rhs` for an upper triangular `r`.
pub(crate) fn solve_upper_transposed(r: MatRef<'_, f64>, rhs: MatRef<'_, f64>) -> Mat<f64> {
    kernels(|| {
        let mut solution = rhs.to_owned();
        solve_lower_triangular_in_place(r.transpose(), solution.as_mut(), Par::Seq);
        solution
    })
}

/// `a·(aᵀa)⁻¹·d` (full-pivoting LU of the small Gram matrix): the weights of a least-squares
/// projection, e.g. a Savitzky–Golay filter's from its Vandermonde matrix `a`.
pub(crate) fn projection_weights(a: MatRef<'_, f64>, d: MatRef<'_, f64>) -> Mat<f64> {
    kernels(|| {
        let gram = a.transpose() * a;
        let solved = gram.full_piv_lu().solve(d);
        a * &solved
    })
}

/// A thin QR factorisation `a = Q·R` (Q: n × p with orthonormal columns, R: p × p upper
/// triangular) of a tall, well-conditioned `a` by CholeskyQR2 (Yamamoto, Nakatsukasa, Yanagisawa
/// and Fukaya, 2015), from its Gram matrix `aᵀa`:
///
/// R₁ = chol(aᵀa), Q₁ = a·R₁⁻¹, R₂ = chol(Q₁ᵀQ₁), Q = Q₁·R₂⁻¹, R = R₂·R₁.
///
/// The second pass restores the orthogonality the first loses (‖Q₁ᵀQ₁ − I‖ ≈ κ(a)²·ε), so Q and
/// R are as accurate as Householder's while costing a few small matrix products instead of a
/// column-by-column factorisation (for a 1255 × 14 library: well under 100 µs against ~400 µs
/// for faer's Householder QR). Q is kept as Q₁ and R₂ (Qᵀb = R₂⁻ᵀ·Q₁ᵀb), one n × p matrix.
pub(crate) struct CholeskyQr {
    first_q: Mat<f64>,
    second_r: Mat<f64>,
    r: Mat<f64>,
}

impl CholeskyQr {
    /// The factorisation of `a` given `gram = aᵀa`. `None` (use Householder) when `a` is wide, a
    /// Cholesky factorisation fails, or R₁'s diagonal spans more than [`CHOLESKY_QR_CONDITION`]
    /// (κ(a) large enough for the first pass to lose the orthogonality the second pass needs).
    pub(crate) fn new(a: MatRef<'_, f64>, gram: MatRef<'_, f64>) -> Option<Self> {
        let p = a.ncols();
        if a.nrows() < p || p == 0 || gram.nrows() != p || gram.ncols() != p {
            return None;
        }
        kernels(|| Self::factor(a, gram))
    }

    fn factor(a: MatRef<'_, f64>, gram: MatRef<'_, f64>) -> Option<Self> {
        let first_r = upper_cholesky(gram)?;
        let diagonal: Vec<f64> = (0..a.ncols()).map(|i| first_r[(i, i)].abs()).collect();
        let largest = diagonal.iter().copied().fold(0.0, f64::max);
        let smallest = diagonal.iter().copied().fold(f64::INFINITY, f64::min);
        if !(smallest > 0.0 && largest / smallest < CHOLESKY_QR_CONDITION) {
            return None;
        }
        let first_q = a * upper_triangular_inverse(first_r.as_ref());
        let second_r = upper_cholesky((first_q.transpose() * &first_q).as_ref())?;
        let r = &second_r * &first_r;
        Some(Self {
            first_q,
            second_r,
            r,
        })
    }

    /// The triangular factor R.
    pub(crate) fn r(&self) -> MatRef<'_, f64> {
        self.r.as_ref()
    }

    /// Qᵀ·b for every column of `b` (n rows).
    pub(crate) fn project(&self, b: MatRef<'_, f64>) -> Mat<f64> {
        kernels(|| {
            let mut projected = self.first_q.transpose() * b;
            solve_lower_triangular_in_place(
                self.second_r.transpose(),
                projected.as_mut(),
                Par::Seq,
            );
            projected
        })
    }
}

/// Largest ratio between R₁'s diagonal entries that [`CholeskyQr::new`] accepts (a lower bound of
/// κ(a); CholeskyQR2 is stable for κ(a) up to about ε^(-1/2) ≈ 10⁸).
pub(crate) const CHOLESKY_QR_CONDITION: f64 = 1e6;

/// The upper triangular R with RᵀR = `gram`, if `gram` is numerically positive definite.
fn upper_cholesky(gram: MatRef<'_, f64>) -> Option<Mat<f64>> {
    let factor = gram.llt(Side::Lower).ok()?;
    Some(factor.L().transpose().to_owned())
}

fn upper_triangular_inverse(r: MatRef<'_, f64>) -> Mat<f64> {
    let mut inverse = Mat::zeros(r.nrows(), r.ncols());
    faer::linalg::triangular_inverse::invert_upper_triangular(inverse.as_mut(), r, Par::Seq);
    inverse
}

/// Whether the triangular factor R of a tall matrix `a` has full numerical rank: no diagonal
/// entry `|R_ii| ≤ 1000·ε·max(m, n)·max|R_jj|`.
fn full_rank_triangular(a: MatRef<'_, f64>, r: MatRef<'_, f64>) -> bool {
    let diagonal: Vec<f64> = (0..r.ncols()).map(|i| r[(i, i)].abs()).collect();
    let largest = diagonal.iter().copied().fold(0.0, f64::max);
    let tolerance = 1e3 * rank_tolerance(a) * largest;
    largest > 0.0 && diagonal.iter().all(|&d| d > tolerance)
}

/// [`full_rank_triangular`] for the triangle R of a matrix with `rows` rows and R's columns.
pub(crate) fn full_rank_triangular_rows(r: MatRef<'_, f64>, rows: usize) -> bool {
    let diagonal: Vec<f64> = (0..r.ncols()).map(|i| r[(i, i)].abs()).collect();
    let largest = diagonal.iter().copied().fold(0.0, f64::max);
    let tolerance = 1e3 * f64::EPSILON * rows.max(r.ncols()) as f64 * largest;
    rows >= r.ncols() && largest > 0.0 && diagonal.iter().all(|&d| d > tolerance)
}

fn rank_tolerance(a: MatRef<'_, f64>) -> f64 {
    f64::EPSILON * a.nrows().max(a.ncols()) as f64
}

/// Inside [`kernels`] only.
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
pub(crate) fn ridge_from_gram(gram: MatRef<'_, f64>, rhs: MatRef<'_, f64>, alpha: f64) -> Mat<f64> {
    let mut shifted = gram.to_owned();
    for i in 0..shifted.nrows() {
        shifted[(i, i)] += alpha;
    }
    kernels(|| match shifted.llt(Side::Lower) {
        Ok(cholesky) => cholesky.solve(rhs),
        Err(_) => pseudo_inverse_solve(shifted.as_ref(), rhs),
    })
}

/// Clears the upper halves of the AVX registers (`vzeroupper`); called by [`kernels`] after faer
/// and by [`crate::FeatureLibrary::transform`] before its scalar `sin`/`cos`, against state a
/// caller's own vector code left behind.
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
    fn cholesky_qr_matches_householder_and_declines_ill_conditioned_matrices() {
        // pseudo-random entries in [0, 1) (a multiplicative hash of the position)
        let random = |i: usize, j: usize| {
            ((i * 9 + j) as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15) as f64 / 2f64.powi(64)
        };
        let a = Mat::from_fn(400, 9, random);
        let b = Mat::from_fn(400, 2, |i, j| (i as f64 * 0.01 + j as f64).cos());
        let gram = a.transpose() * &a;
        let qr = CholeskyQr::new(a.as_ref(), gram.as_ref()).expect("well conditioned");
        // QᵀQ = I through the projection of a's own columns (Qᵀa = R), and RᵀR = aᵀa.
        let projected_a = qr.project(a.as_ref());
        assert!((&projected_a - qr.r()).norm_max() < 1e-12 * qr.r().norm_max());
        let product = qr.r().transpose() * qr.r();
        assert!((&product - &gram).norm_max() < 1e-12 * gram.norm_max());
        // The least-squares solution R⁻¹Qᵀb equals Householder's.
        let mut solution = qr.project(b.as_ref());
        faer::linalg::triangular_solve::solve_upper_triangular_in_place(
            qr.r(),
            solution.as_mut(),
            Par::Seq,
        );
        let householder = least_squares(a.as_ref(), b.as_ref());
        assert!(
            (&solution - &householder).norm_max() < 1e-12,
            "{solution:?}"
        );

        // Nearly dependent columns (κ ≈ 1e9): left to Householder and the SVD.
        let ill = Mat::from_fn(400, 3, |i, j| {
            let t = i as f64 * 0.01;
            if j == 2 {
                t + 1e-9 * t.sin()
            } else {
                t.powi(j as i32)
            }
        });
        let ill_gram = ill.transpose() * &ill;
        assert!(CholeskyQr::new(ill.as_ref(), ill_gram.as_ref()).is_none());
        // Wide matrices have no thin QR.
        let wide = Mat::from_fn(2, 3, |i, j| (i + j) as f64);
        assert!(CholeskyQr::new(wide.as_ref(), (wide.transpose() * &wide).as_ref()).is_none());
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
