//! The final estimate of the named effects' parameters.
//!
//! The evidence rule judges the effects with parameters fitted on the fit part, so that the
//! held-out part can test them ([`crate::evidence`]). Once the effects are named, their parameters
//! are estimated again on every analysed row, with robust weights: per channel, a residual beyond
//! `huber_threshold` robust standard deviations counts linearly instead of quadratically (Huber's
//! loss, by iteratively reweighted least squares from the judged values). Rows whose model side the
//! log cannot reconstruct (a command that steps between two samples, so that no sample says when)
//! then stop pulling the parameters, and on the rows that fit the estimate stays least squares.
//!
//! The standard errors have the form of the fit part's (`refine::standard_errors`) with
//! the weighted residual and Jacobian on all rows: `√diag(κ s² (JᵀWJ)⁻¹)`.

use serde::Serialize;

use crate::evidence::autocorrelation_factor;
use crate::fit::FittedSet;
use crate::noise_reaction::median;
use crate::problem::{Channels, Problem};
use crate::refine::{FitRows, levenberg_marquardt, standard_errors};

/// Settings of the final estimate (recorded in the output).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct EstimateSettings {
    /// Residuals beyond this many robust standard deviations of their channel are downweighted.
    pub huber_threshold: f64,
    /// Reweighting passes.
    pub passes: usize,
}

impl Default for EstimateSettings {
    fn default() -> Self {
        Self {
            huber_threshold: 2.5,
            passes: 4,
        }
    }
}

/// The parameters estimated on all rows.
#[derive(Clone, Debug)]
pub struct Estimate {
    pub set: FittedSet,
    pub standard_errors: Vec<f64>,
    /// Share of the (row, channel) residuals that carry a weight below 1 at the end.
    pub downweighted_fraction: f64,
}

/// Estimates the parameters of `judged` (the evidence rule's set) on all rows with Huber weights.
pub fn estimate(
    problem: &Problem,
    judged: &FittedSet,
    settings: &EstimateSettings,
    iterations: usize,
) -> Estimate {
    let all = 0..problem.rows();
    let mut set = judged.clone();
    if set.parameters.is_empty() {
        return Estimate {
            set,
            standard_errors: Vec::new(),
            downweighted_fraction: 0.0,
        };
    }
    let mut residual = problem.residual(&set.effects());
    let mut weights = huber_weights(problem, &residual, settings);
    for _ in 0..settings.passes {
        let rows = FitRows {
            range: all.clone(),
            weights: Some(&weights),
        };
        set.values =
            levenberg_marquardt(problem, &set.parameters, &set.values, &rows, iterations).0;
        residual = problem.residual(&set.effects());
        weights = huber_weights(problem, &residual, settings);
    }
    let weighted: Vec<Channels> = residual
        .iter()
        .zip(&weights)
        .map(|(r, w)| std::array::from_fn(|c| w[c].sqrt() * r[c] / problem.noise_floor[c]))
        .collect();
    let count = (weighted.len() * problem.channels).max(1) as f64;
    let variance = weighted
        .iter()
        .map(|r| r[..problem.channels].iter().map(|v| v * v).sum::<f64>())
        .sum::<f64>()
        / count;
    let scale = autocorrelation_factor(problem, &weighted, 2 * problem.weak_form.half) * variance;
    let rows = FitRows {
        range: all,
        weights: Some(&weights),
    };
    let standard_errors = standard_errors(problem, &set.parameters, &set.values, &rows, scale);
    let downweighted = weights
        .iter()
        .map(|w| w[..problem.channels].iter().filter(|&&v| v < 1.0).count())
        .sum::<usize>();
    Estimate {
        set,
        standard_errors,
        downweighted_fraction: downweighted as f64 / count,
    }
}

/// Huber weights of a residual: per channel, `min(1, c / |z|)` with `z` the residual over its
/// channel's robust standard deviation (the median absolute noise-normalised residual / 0.6745).
fn huber_weights(
    problem: &Problem,
    residual: &[Channels],
    settings: &EstimateSettings,
) -> Vec<Channels> {
    let mut weights = vec![[1.0; 6]; residual.len()];
    for c in 0..problem.channels {
        let scaled: Vec<f64> = residual
            .iter()
            .map(|r| (r[c] / problem.noise_floor[c]).abs())
            .collect();
        let sigma = median(scaled.clone()) / 0.6745;
        if !(sigma.is_finite() && sigma > 0.0) {
            continue;
        }
        for (w, z) in weights.iter_mut().zip(&scaled) {
            let z = z / sigma;
            w[c] = if z <= settings.huber_threshold {
                1.0
            } else {
                settings.huber_threshold / z
            };
        }
    }
    weights
}
