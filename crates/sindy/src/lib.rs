//! Sparse identification of nonlinear dynamics (SINDy), with PySINDy's semantics.
//!
//! What it is for: fitting sparse models ẋ = ξ·Θ(x, u) from trajectories with control inputs;
//! feature libraries ([`FeatureLibrary`]: polynomial, Fourier, custom functions, concatenations,
//! with the exact feature names `1`, `x`, `x^2`, `x*y`, `sin(x)`, `cos(2*x)`); optimizers
//! ([`OptimizerSpec`]: STLSQ matching `pysindy.STLSQ` to rounding, LASSO solved by clarabel);
//! models that predict, score, print their equations, simulate with RK4 and save/load as JSON
//! ([`SindyModel`]); derivative estimators ([`differentiation`]: forward, central,
//! Savitzky–Golay); regularised regressions with a penalty chosen by blocked cross-validation
//! ([`RegressionSpec`]).
//!
//! What it is not for: reading recordings (the `data` crate does), the paper's protocol (the
//! `pipeline` crate runs SINDy on its flights), meta-learning (`learn`), tables (`report`). It
//! depends on no CSV reader and no data-frame library: its inputs are matrices.
//!
//! # Fitting a model
//! ```
//! use sindy::{FeatureLibrary, LibrarySpec, OptimizerSpec, SindyParams, Trajectory};
//! use faer::Mat;
//! // ẋ = −0.5 x, sampled exactly
//! let time: Vec<f64> = (0..200).map(|k| k as f64 * 0.01).collect();
//! let states = Mat::from_fn(200, 1, |i, _| (-0.5 * time[i]).exp());
//! let derivatives = Mat::from_fn(200, 1, |i, _| -0.5 * states[(i, 0)]);
//! let trajectory = Trajectory::new(time, states).unwrap().with_derivatives(derivatives).unwrap();
//! let model = SindyParams::new(&["x"], &[])
//!     .library(FeatureLibrary::from_spec(&LibrarySpec::parse("poly:2").unwrap()).unwrap())
//!     .optimizer(OptimizerSpec::stlsq(0.1))
//!     .fit(&[trajectory])
//!     .unwrap();
//! assert_eq!(model.equations(3), vec!["x' = -0.500 x"]);
//! ```
//!
//! `examples/lorenz.rs` does the same for the Lorenz system, from simulation to equations
//! (`cargo run -p sindy --example lorenz`).
//!
//! # Large libraries and long recordings
//! A library of more than [`LARGE_LIBRARY_ENTRIES`] entries is evaluated by row blocks and
//! reduced as it is built ([`ReducedProblem`]); [`SindyParams::fit_streamed`] fits a recording
//! whose rows arrive in blocks, in memory that does not grow with its length.
//!
//! # STLSQ semantics
//! See [`Stlsq`]: ridge `‖Θξ − y‖² + α‖ξ‖²` (no column normalisation), threshold `|ξ| ≥ t`,
//! up to `max_iter` iterations stopping when the non-zero pattern stops changing (the first
//! comparison is against the plain least-squares solution, i.e. all active), then an unregularised
//! least-squares refit of the kept terms; each target column is independent.
//!
//! Every error is a [`SindyError`] with a one-line message.

pub mod differentiation;
mod error;
mod library;
mod linalg;
mod model;
mod optimizers;
mod persist;
mod regression;
mod stream;

pub use differentiation::{Derivative, DifferentiationError};
pub use error::{Result, SindyError, field, shape};
pub use library::{CustomFunction, FeatureLibrary, LibrarySpec, MAX_FEATURES};
pub use linalg::least_squares;
pub use model::{
    LARGE_LIBRARY_ENTRIES, Score, SindyModel, SindyParams, Trajectory, mean_squared_error, r2_score,
};
pub use optimizers::{
    DEFAULT_ALPHA, DEFAULT_MAX_ITER, Lasso, Optimizer, OptimizerSpec, Problem, Ridge, Stlsq,
    StlsqFit, kkt_violation,
};
pub use persist::MODEL_FORMAT;
pub use regression::{
    Bagging, BlockedFolds, EnsemblePrediction, LinearFit, MAX_BAGGING_BLOCK, MAX_BAGGING_MEMBERS,
    MAX_FOLDS, MAX_PENALTY, MAX_PENALTY_CANDIDATES, Penalty, RegressionFit, RegressionSpec,
    Selection,
};
pub use stream::{RowBlock, StreamedFit};

/// Re-exported so that users name the same matrix types.
pub use faer::{Mat, MatRef};
