//! Variants beyond the paper (`experiments/variants.json`, `make ablations`): every variant on every
//! formulation × evaluation condition, over several seeds, on the paper's protocol, beside the
//! published columns and an estimate of the targets' noise floor.
//!
//! Protocol (the same as the paper's tables): support = first half of the flight, query = second
//! half, forward-difference targets on each segment, inputs X = [x, u] of `learn::Formulation`.
//! Every hyper-parameter of a variant (penalty, library for `select`) is chosen by blocked
//! cross-validation inside the support segment; the query segment is only ever scored.
//!
//! Variant kinds:
//! - `library`: a [`crate::causal_library::CausalLibrary`] and a [`sindy::RegressionSpec`];
//! - `select`: per cell, the candidate variant (by name) with the lowest support cross-validation
//!   error (mean over outputs of each output's best penalty score);
//! - `learned_basis`: the meta-trained LeARN library Θ(X; ψ) as features, optionally beside a fixed
//!   causal library (the hybrid), with a regression on the support segment: closed-form adaptation
//!   of the coefficients on the learned basis instead of SGD steps ([`learn::variants`]);
//! - `learn`: the paper's LeARN itself, the meta-trained networks adapted online on the support
//!   segment with the model's adaptation settings (the LeARN column of the tables);
//! - `average`: the mean of the predictions of earlier variants (equal weights: nothing is chosen,
//!   so nothing can be chosen on the query segment).
//!
//! The module's parts: `schema.rs` (the file's types), `checks.rs` (reading and checking it),
//! `run.rs` (a variant as a [`crate::Method`], run by the [`crate::Runner`] like SINDy and LeARN)
//! and `combinators.rs` (`select`, `average` and the ensemble mean, from other variants'
//! results).

mod checks;
mod combinators;
mod run;
mod schema;
#[cfg(test)]
mod testing;

pub(crate) use run::learned_basis_experiment;
pub use run::reproduce_columns;
pub use schema::{
    CheckedVariants, ENSEMBLE_SEED_STRIDE, LearnedBasisSpec, MAX_ENSEMBLE_MEMBERS, MAX_VARIANTS,
    VariantKind, VariantSpec, VariantsConfig, ensemble_member_seeds,
};
