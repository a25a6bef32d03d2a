//! Sparse identification of nonlinear dynamics (SINDy) on matrices, with PySINDy's semantics.
//!
//! # What it is for
//! Fitting sparse models ẋ = Ξ·Θ(x, u) to trajectories with control inputs from a Rust program,
//! with the parts PySINDy has:
//! - differentiation ([`differentiation`], [`Derivative`]): forward and central differences,
//!   Savitzky–Golay;
//! - feature libraries ([`FeatureLibrary`], [`LibrarySpec`]): polynomial, Fourier, custom
//!   functions and concatenations, with PySINDy's feature order and names (`1`, `x`, `x^2`,
//!   `x*y`, `sin(x)`, `cos(2*x)`);
//! - optimizers ([`Optimizer`]): [`Stlsq`] (`pysindy.STLSQ` to rounding), [`Lasso`] (a quadratic
//!   program solved by clarabel) and [`Ridge`], all solving one representation of the regression,
//!   [`Problem`]; [`OptimizerSpec`] is the serialisable choice a model records;
//! - models: [`SindyParams`] fits ([`SindyParams::fit`] on [`Trajectory`]s,
//!   [`SindyParams::fit_matrices`] on arrays, [`SindyParams::fit_streamed`] on rows arriving in
//!   blocks); a [`SindyModel`] predicts, scores, prints its equations, simulates (RK4) and is
//!   saved and loaded as JSON.
//!
//! Beyond PySINDy: regularised regressions of targets on any feature matrix with the penalty
//! chosen by blocked cross-validation, and bagged ensembles with a predictive band
//! ([`RegressionSpec`]); the weak form of an equation through a smooth test function
//! ([`weak_form`], as PySINDy's weak libraries), on evenly spaced or logged time stamps
//! ([`sampling`]); forward stepwise selection of column groups
//! with time-blocked cross-validation and stability selection over block-bootstrap resamples
//! ([`stability`]).
//!
//! # What it is not for
//! Reading recordings or CSV files (the `data` crate does: this crate depends on no file reader
//! or data frame, its inputs are [`Mat`]s), the paper's protocol (`evaluation`), meta-learning
//! (`learn`), tables and figures (`report`). Nor is it a linear-algebra library: its dense
//! computations are private, [`least_squares`] aside.
//!
//! # Fitting a model
//! ```
//! use sindy::{FeatureLibrary, LibrarySpec, Mat, OptimizerSpec, SindyParams, Trajectory};
//! // ẋ = −0.5 x, sampled exactly
//! let time: Vec<f64> = (0..200).map(|k| k as f64 * 0.01).collect();
//! let states = Mat::from_fn(200, 1, |i, _| (-0.5 * time[i]).exp());
//! let derivatives = Mat::from_fn(200, 1, |i, _| -0.5 * states[(i, 0)]);
//! let trajectory = Trajectory::new(time, states)?.with_derivatives(derivatives)?;
//! let model = SindyParams::new(&["x"], &[])
//!     .library(FeatureLibrary::from_spec(&LibrarySpec::parse("poly:2")?)?)
//!     .optimizer(OptimizerSpec::stlsq(0.1))
//!     .fit(std::slice::from_ref(&trajectory))?;
//! assert_eq!(model.equations(3), vec!["x' = -0.500 x"]);
//! assert!(model.score(&trajectory)?.r2 > 0.999_999);
//! # Ok::<(), sindy::SindyError>(())
//! ```
//!
//! `examples/lorenz.rs` does the same for the Lorenz system, from simulated arrays to equations,
//! score and simulation, then runs STLSQ, LASSO and ridge side by side on its library matrix
//! (`cargo run -p sindy --example lorenz`).
//!
//! # Large libraries and long recordings
//! A library of more than [`LARGE_LIBRARY_ENTRIES`] entries is evaluated by row blocks and
//! reduced as it is built to the triangle of a QR factorisation (see [`Problem::reduced`]): from
//! its Gram matrix where that is as accurate ([`GRAM_CONDITION_LIMIT`], [`GRAM_RESIDUAL_SHARE`]),
//! by Householder QR otherwise ([`RowReduction`]); [`SindyParams::fit_streamed`] fits a recording
//! whose rows arrive in blocks, in memory that does not grow with its length. The coefficients
//! are those of the whole matrix up to rounding.
//!
//! # STLSQ semantics
//! See [`Stlsq`]: ridge `‖Θξ − y‖² + α‖ξ‖²` (no column normalisation), threshold `|ξ| ≥ t`,
//! up to `max_iter` iterations stopping when the non-zero pattern stops changing (the first
//! comparison is against the plain least-squares solution, i.e. all active), then an unregularised
//! least-squares refit of the kept terms; each target column is independent.
//!
//! # Numerics
//! Matrices are faer's (re-exported as [`Mat`] and [`MatRef`]). Every dense computation runs in
//! one private module, which also clears the processor's vector state after faer's kernels (left
//! in use, it slowed the scalar feature evaluation that follows a fit ~20x).
//!
//! Every error is a [`SindyError`] with a one-line message.

pub mod differentiation;
mod error;
mod library;
mod linalg;
pub mod median;
mod memory;
mod model;
mod optimizers;
mod persist;
mod regression;
pub mod sampling;
pub mod stability;
mod stream;
pub mod weak_form;

pub use differentiation::{
    Derivative, DifferentiationError, SAVITZKY_GOLAY_STEP_TOLERANCE, UNIFORM_STEP_TOLERANCE,
};
pub use error::{Result, SindyError, field, shape};
pub use library::{CustomFunction, FeatureLibrary, LibrarySpec, MAX_FEATURES};
pub use linalg::least_squares;
pub use memory::{FitShape, RowSource};
pub use model::{
    LARGE_LIBRARY_ENTRIES, Score, SindyModel, SindyParams, Trajectory, mean_squared_error,
};
pub use optimizers::{
    DEFAULT_ALPHA, DEFAULT_MAX_ITER, GRAM_CONDITION_LIMIT, GRAM_RESIDUAL_SHARE, Lasso, Optimizer,
    OptimizerSpec, Problem, Reduction, Ridge, RowReduction, Stlsq, StlsqFit, kkt_violation,
};
pub use regression::{
    Bagging, BlockedFolds, EnsemblePrediction, LinearFit, MAX_BAGGING_BLOCK, MAX_BAGGING_MEMBERS,
    MAX_FOLDS, MAX_PENALTY, MAX_PENALTY_CANDIDATES, Penalty, RegressionFit, RegressionSpec,
    Selection,
};
pub use stream::{RowBlock, StreamedFit};

/// Re-exported so that users name the same matrix types.
pub use faer::{Mat, MatRef};
