//! The one form every optimizer works on: a linear least-squares problem `Θ·ξ ≈ Y`.
//!
//! - The ridge and LASSO steps read the Gram matrix ΘᵀΘ and the moments ΘᵀY (PySINDy's Cholesky
//!   ridge solves the same normal equations).
//! - The least-squares steps (STLSQ's first solution on every feature, its unregularised refits on
//!   a support) run on the triangle of a QR factorisation: with `Θ = Q·R`, `Z = QᵀY`, for every
//!   subset A of the columns `min ‖Θ_A ξ − y_j‖` is `min ‖R_A ξ − z_j‖` (p rows instead of n),
//!   as accurate as a QR of Θ_A itself. Forming only ΘᵀΘ would square the condition number
//!   (`docs/sindy-scale.md`).
//!
//! A problem is made from Θ and Y given whole ([`Problem::new`]; R by CholeskyQR2 from the Gram
//! matrix, or by Householder when Θ is too ill-conditioned for it, made when a least-squares step
//! first asks; Θ itself when it is wide or rank-deficient), or reduced by blocks of rows as they
//! are evaluated ([`Problem::reduced`], and the large-library and streaming fits through
//! [`super::row_blocks`]), where R, Z and the residual outside Θ's range are all that is kept. Either
//! way the optimizers see the same interface, and every dense computation runs in
//! [`crate::linalg`].

use std::sync::OnceLock;

use faer::{Mat, MatRef};

use crate::linalg::{
    CholeskyQr, full_rank_triangular_rows, householder_least_squares, least_squares, product,
    ridge_from_gram, solve_upper,
};

/// `Θ·ξ ≈ Y` (n rows, p features, m targets) in the form the optimizers work on: ΘᵀΘ, ΘᵀY and
/// the least-squares form (see the module documentation).
///
/// ```
/// use sindy::{Lasso, Mat, Optimizer, Problem, Stlsq};
/// // y = 3·θ₀ − θ₂ exactly, four features
/// let theta = Mat::from_fn(100, 4, |i, j| ((i * (j + 1)) as f64 * 0.1).sin());
/// let y = Mat::from_fn(100, 1, |i, _| 3.0 * theta[(i, 0)] - theta[(i, 2)]);
/// let problem = Problem::new(theta.as_ref(), y.as_ref());
/// let optimizers: [&dyn Optimizer; 2] = [&Stlsq::new(0.1, 0.0, 20)?, &Lasso::new(1e-3)?];
/// for optimizer in optimizers {
///     let xi = optimizer.solve(&problem)?; // one row per target
///     assert!((xi[(0, 0)] - 3.0).abs() < 1e-3 && (xi[(0, 2)] + 1.0).abs() < 1e-3);
///     assert!(xi[(0, 1)].abs() < 1e-3 && xi[(0, 3)].abs() < 1e-3);
/// }
/// # Ok::<(), sindy::SindyError>(())
/// ```
pub struct Problem<'a> {
    gram: Mat<f64>,
    moments: Mat<f64>,
    rows: usize,
    /// Θ and Y when given whole (their least-squares form is made on first use).
    whole: Option<(MatRef<'a, f64>, MatRef<'a, f64>)>,
    least_squares: OnceLock<LeastSquares>,
    /// Per target: `‖s_j‖²`, the part of y_j outside Θ's range (reduced problems only).
    residual_squares: Option<Vec<f64>>,
    target_names: Vec<String>,
}

/// What the least-squares steps run on, and the least-squares solution on every feature.
struct LeastSquares {
    basis: Basis,
    /// p × m.
    solution: Mat<f64>,
}

enum Basis {
    /// R (p × p, upper triangular) and Z = QᵀY (p × m).
    Triangle {
        triangular: Mat<f64>,
        projected: Mat<f64>,
    },
    /// Θ and Y themselves (the problem's own): Θ is wide or rank-deficient.
    Rows,
}

impl<'a> Problem<'a> {
    /// The problem of Θ (n × p) and Y (n × m) given whole.
    ///
    /// # Panics
    /// If Θ and Y have different numbers of rows.
    pub fn new(theta: MatRef<'a, f64>, targets: MatRef<'a, f64>) -> Self {
        let gram = product(theta.transpose(), theta);
        Self::with_gram(theta, targets, gram)
    }

    /// [`Self::new`] with ΘᵀΘ already formed (as [`Self::new`] forms it), e.g. shared by the
    /// problems of several target columns.
    pub(crate) fn with_gram(
        theta: MatRef<'a, f64>,
        targets: MatRef<'a, f64>,
        gram: Mat<f64>,
    ) -> Self {
        assert_eq!(
            theta.nrows(),
            targets.nrows(),
            "a problem's library and targets need the same rows"
        );
        let moments = product(theta.transpose(), targets);
        Self {
            gram,
            moments,
            rows: theta.nrows(),
            whole: Some((theta, targets)),
            least_squares: OnceLock::new(),
            residual_squares: None,
            target_names: Vec::new(),
        }
    }

    /// Names the targets in errors (by default `column 0`, `column 1`, …).
    pub fn with_target_names(mut self, names: &[String]) -> Self {
        self.target_names = names.to_vec();
        self
    }

    /// ΘᵀΘ (p × p).
    pub fn gram(&self) -> MatRef<'_, f64> {
        self.gram.as_ref()
    }

    /// ΘᵀY (p × m).
    pub fn moments(&self) -> MatRef<'_, f64> {
        self.moments.as_ref()
    }

    /// n, the rows of Θ.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// p, the columns of Θ.
    pub fn features(&self) -> usize {
        self.gram.ncols()
    }

    /// m, the columns of Y.
    pub fn targets(&self) -> usize {
        self.moments.ncols()
    }

    /// The name of target `j` in errors.
    pub(crate) fn target_name(&self, j: usize) -> String {
        self.target_names
            .get(j)
            .cloned()
            .unwrap_or_else(|| format!("column {j}"))
    }

    /// The minimum-norm least-squares solution on every feature (p × m).
    pub fn least_squares_solution(&self) -> MatRef<'_, f64> {
        self.least_squares().solution.as_ref()
    }

    /// The least-squares coefficients of target `j` on the features `columns` only (zero
    /// elsewhere; p values): `min ‖Θ_columns ξ − y_j‖`.
    pub fn least_squares_on(&self, j: usize, columns: &[usize]) -> Vec<f64> {
        let mut coefficients = vec![0.0; self.features()];
        if columns.is_empty() {
            return coefficients;
        }
        let solution = match &self.least_squares().basis {
            Basis::Triangle {
                triangular,
                projected,
            } => {
                let sub = Mat::from_fn(triangular.nrows(), columns.len(), |i, a| {
                    triangular[(i, columns[a])]
                });
                least_squares(sub.as_ref(), projected.col(j).as_mat())
            }
            Basis::Rows => {
                let (theta, targets) = self.whole.expect("only Θ given whole is kept");
                let sub = Mat::from_fn(theta.nrows(), columns.len(), |i, a| theta[(i, columns[a])]);
                least_squares(sub.as_ref(), targets.col(j).as_mat())
            }
        };
        for (a, &column) in columns.iter().enumerate() {
            coefficients[column] = solution[(a, 0)];
        }
        coefficients
    }

    /// The solution of the ridge normal equations on the features `columns`:
    /// `(G + α·I)·x = rhs` with G the Gram matrix of those columns and `rhs` one row per column
    /// (e.g. their moments), any number of right-hand sides.
    pub fn ridge_on(&self, columns: &[usize], rhs: MatRef<'_, f64>, alpha: f64) -> Mat<f64> {
        let sub_gram = Mat::from_fn(columns.len(), columns.len(), |a, b| {
            self.gram[(columns[a], columns[b])]
        });
        ridge_from_gram(sub_gram.as_ref(), rhs, alpha)
    }

    /// The work of one least-squares step, to decide whether targets are fitted in parallel:
    /// p³ on the triangle, n·p² on Θ itself.
    pub(crate) fn least_squares_work(&self) -> usize {
        let p = self.features();
        match self.least_squares().basis {
            Basis::Triangle { .. } => p * p * p,
            Basis::Rows => self.rows * p * p,
        }
    }

    /// `‖Θ ξ_j − y_j‖²` for each target j, ξ one row per target (as an optimizer returns it):
    /// from R, Z and `‖s_j‖²` when reduced, from Θ and Y otherwise.
    pub fn residual_sum_of_squares(&self, coefficients: MatRef<'_, f64>) -> Vec<f64> {
        let (fitted, actual) = match self.whole {
            Some((theta, targets)) => (product(theta, coefficients.transpose()), targets),
            None => match &self.least_squares().basis {
                Basis::Triangle {
                    triangular,
                    projected,
                } => (
                    product(triangular.as_ref(), coefficients.transpose()),
                    projected.as_ref(),
                ),
                Basis::Rows => unreachable!("a reduced problem keeps its triangle"),
            },
        };
        (0..actual.ncols())
            .map(|j| {
                let inside: f64 = (0..actual.nrows())
                    .map(|i| (fitted[(i, j)] - actual[(i, j)]).powi(2))
                    .sum();
                inside + self.residual_squares.as_ref().map_or(0.0, |s| s[j])
            })
            .collect()
    }

    fn least_squares(&self) -> &LeastSquares {
        self.least_squares.get_or_init(|| {
            let (theta, targets) = self.whole.expect("a reduced problem is made with its form");
            factor_whole(theta, targets, self.gram.as_ref())
        })
    }
}

impl Problem<'static> {
    /// Θ (n × p) and Y reduced by rows to the QR triangle, as a large library is reduced block by
    /// block (see [`crate::LARGE_LIBRARY_ENTRIES`] and [`crate::RowReduction`]): the optimizers
    /// give the same coefficients up to rounding, and [`Problem::residual_sum_of_squares`] needs
    /// no row of Θ.
    pub fn reduced(theta: MatRef<'_, f64>, targets: MatRef<'_, f64>) -> Self {
        super::row_blocks::reduce(theta, targets)
    }

    /// The problem of R (p × p, upper triangular), Z = QᵀY and `‖s_j‖²` from the reduction of
    /// `rows` rows.
    pub(crate) fn from_triangle(
        triangular: Mat<f64>,
        projected: Mat<f64>,
        residual_squares: Vec<f64>,
        rows: usize,
    ) -> Self {
        let gram = product(triangular.transpose(), triangular.as_ref());
        let moments = product(triangular.transpose(), projected.as_ref());
        let solution = match full_rank_triangular_rows(triangular.as_ref(), rows) {
            true => solve_upper(triangular.as_ref(), projected.as_ref()),
            false => least_squares(triangular.as_ref(), projected.as_ref()),
        };
        let basis = Basis::Triangle {
            triangular,
            projected,
        };
        Self {
            gram,
            moments,
            rows,
            whole: None,
            least_squares: OnceLock::from(LeastSquares { basis, solution }),
            residual_squares: Some(residual_squares),
            target_names: Vec::new(),
        }
    }
}

/// The least-squares form of Θ and Y given whole: R from CholeskyQR2 on the Gram matrix, or
/// from Householder when Θ is too ill-conditioned for it; Θ itself when it is wide or
/// rank-deficient.
fn factor_whole(
    theta: MatRef<'_, f64>,
    targets: MatRef<'_, f64>,
    gram: MatRef<'_, f64>,
) -> LeastSquares {
    if let Some(qr) = CholeskyQr::new(theta, gram) {
        let projected = qr.project(targets);
        let solution = solve_upper(qr.r(), projected.as_ref());
        let basis = Basis::Triangle {
            triangular: qr.r().to_owned(),
            projected,
        };
        return LeastSquares { basis, solution };
    }
    if let Some((triangular, solution)) = householder_least_squares(theta, targets) {
        // Qᵀy = R·ξ_ls.
        let projected = product(triangular.as_ref(), solution.as_ref());
        let basis = Basis::Triangle {
            triangular,
            projected,
        };
        return LeastSquares { basis, solution };
    }
    LeastSquares {
        basis: Basis::Rows,
        solution: least_squares(theta, targets),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A well-conditioned library, one whose last column nearly repeats the first (left to
    /// Householder), and one with a repeated column (rank-deficient: solved on Θ itself).
    fn libraries() -> Vec<Mat<f64>> {
        let base = |i: usize, j: usize| ((i * (2 * j + 3)) as f64 * 0.37).sin() + 0.1 * j as f64;
        vec![
            Mat::from_fn(200, 4, base),
            Mat::from_fn(200, 4, |i, j| match j {
                3 => base(i, 0) + 1e-7 * base(i, 3),
                _ => base(i, j),
            }),
            Mat::from_fn(200, 4, |i, j| base(i, j.min(2))),
        ]
    }

    #[test]
    fn every_form_solves_the_same_least_squares_problems() {
        for theta in libraries() {
            let y = Mat::from_fn(200, 2, |i, j| {
                (0..4)
                    .map(|k| theta[(i, k)] * (k as f64 - j as f64))
                    .sum::<f64>()
                    + 0.01 * ((i * 7 + j) as f64).cos()
            });
            let whole = Problem::new(theta.as_ref(), y.as_ref());
            let reduced = Problem::reduced(theta.as_ref(), y.as_ref());
            assert_eq!(
                (whole.rows(), whole.features(), whole.targets()),
                (200, 4, 2)
            );
            let direct = least_squares(theta.as_ref(), y.as_ref());
            for problem in [&whole, &reduced] {
                let gram = theta.transpose() * &theta;
                assert!((problem.gram() - &gram).norm_max() < 1e-10 * gram.norm_max());
                // The residual of the least-squares solution, and of a refit on two columns.
                let solution = problem.least_squares_solution();
                let residual = |xi: &Mat<f64>| problem.residual_sum_of_squares(xi.as_ref());
                let best = residual(&solution.transpose().to_owned());
                let expected = residual(&direct.transpose().to_owned());
                for (a, b) in best.iter().zip(&expected) {
                    assert!((a - b).abs() <= 1e-8 * b.max(1e-12), "{a} {b}");
                }
                let refit = problem.least_squares_on(1, &[0, 2]);
                let sub = Mat::from_fn(200, 2, |i, a| theta[(i, [0, 2][a])]);
                let expected = least_squares(sub.as_ref(), y.col(1).as_mat());
                assert_eq!((refit[1], refit[3]), (0.0, 0.0));
                assert!((refit[0] - expected[(0, 0)]).abs() < 1e-9);
                assert!((refit[2] - expected[(1, 0)]).abs() < 1e-9);
            }
        }
    }
}
