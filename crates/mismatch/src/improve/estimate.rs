//! The final estimate of the named effects' parameters.
//!
//! The evidence rule judges the effects with parameters fitted on the fit part, so that the
//! held-out part can test them ([`crate::explain::evidence`]). Once the effects are named, their parameters
//! are estimated again on every analysed row, with robust weights: per channel, a residual beyond
//! `huber_threshold` robust standard deviations counts linearly instead of quadratically (Huber's
//! loss, by iteratively reweighted least squares from the judged values): rows far off stop pulling
//! the parameters, and on the rows that fit the estimate stays least squares.
//!
//! A sampled command that steps between two samples says nothing of when within the interval it
//! stepped, and the curve through the samples misplaces the step by up to half a row. Such steps
//! are found in the commands alone ([`crate::recording::command_samples::CommandSamples::unplaced_steps`]);
//! each step's time is a nuisance parameter, profiled out: per channel, the weighted residual's
//! component along the test functions' value at the step (what moving the step changes) is left
//! out of the fit. Unlike a robust weight, this does not depend on the noise level: with more
//! noise, Huber's threshold grows and the rows around a step pulled the parameters more.
//!
//! When the commands are instantaneous samples of a faster controller, the bias their noise (and
//! its correlation with the recorded rate's) leaves is measured and subtracted ([`crate::improve::simex`]).
//!
//! The standard errors have the form of the fit part's (`refine::standard_errors`) with the
//! weighted residual and Jacobian on all rows: `√diag(κ s² (JᵀWJ)⁻¹)`, with the Monte Carlo error
//! of the subtracted bias added in quadrature. `s²` keeps the steps' components of the residual
//! (leaving them out, tried, made the errors 0–4 % smaller and covered fewer true values in A: 75
//! of 88 instead of 78).

use serde::Serialize;
use sindy::median::robust_standard_deviation;

use crate::explain::evidence::autocorrelation_factor;
use crate::explain::fit::FittedSet;
use crate::improve::simex::{NoiseBias, SimexSettings, noise_bias};
use crate::locate::problem::{Channels, Problem};
use crate::model::least_squares::Termination;
use crate::model::refine::{FitRows, StepBasis, levenberg_marquardt, precision};
use crate::model::weight::WeightSpan;

/// Settings of the final estimate (recorded in the output).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct EstimateSettings {
    /// Residuals beyond this many robust standard deviations of their channel are downweighted.
    pub huber_threshold: f64,
    /// Reweighting passes.
    pub passes: usize,
    /// The correction of the bias the noise on sampled commands leaves ([`crate::improve::simex`]).
    pub noise_bias: SimexSettings,
}

impl Default for EstimateSettings {
    fn default() -> Self {
        Self {
            huber_threshold: 2.5,
            passes: 4,
            noise_bias: SimexSettings::default(),
        }
    }
}

/// The parameters estimated on all rows.
#[derive(Clone, Debug)]
pub struct Estimate {
    pub set: FittedSet,
    pub standard_errors: Vec<f64>,
    /// Per parameter, the stretch of the recording holding half of its weight
    /// ([`crate::model::weight`]); `None` where the fit does not determine it.
    pub weight_spans: Vec<Option<WeightSpan>>,
    /// Share of the (row, channel) residuals that carry a weight below 1 at the end.
    pub downweighted_fraction: f64,
    /// The bias removed from the values, when the commands are instantaneous samples of a faster
    /// controller ([`crate::improve::simex`]).
    pub noise_bias: Option<NoiseBias>,
    /// Times of the command steps between samples whose place within their interval was left free.
    pub step_times: Vec<f64>,
    /// Why the last reweighting pass's fit stopped (none when no fit ran: no parameters or passes).
    pub termination: Option<Termination>,
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
    let step_times = step_times(problem);
    if set.parameters.is_empty() {
        return Estimate {
            set,
            standard_errors: Vec::new(),
            weight_spans: Vec::new(),
            downweighted_fraction: 0.0,
            noise_bias: None,
            step_times,
            termination: None,
        };
    }
    let mut residual = problem.residual(&set.effects());
    let mut weights = huber_weights(problem, &residual, settings);
    let mut termination = None;
    for _ in 0..settings.passes {
        let weighted = FitRows {
            range: all.clone(),
            weights: Some(&weights),
            steps: None,
        };
        let steps = StepBasis::new(problem, &weighted, &step_times);
        let rows = FitRows {
            steps: Some(&steps),
            ..weighted
        };
        let solution =
            levenberg_marquardt(problem, &set.parameters, &set.values, &rows, iterations);
        set.values = solution.values;
        termination = Some(solution.termination);
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
    let weighted_rows = FitRows {
        range: all,
        weights: Some(&weights),
        steps: None,
    };
    let steps = StepBasis::new(problem, &weighted_rows, &step_times);
    let rows = FitRows {
        steps: Some(&steps),
        ..weighted_rows
    };
    let precision = precision(problem, &set.parameters, &set.values, &rows, scale);
    let mut standard_errors = precision.standard_errors;
    let weight_spans = precision
        .half_weight_rows
        .iter()
        .map(|rows| rows.map(|(first, last)| stretch(problem, first, last)))
        .collect();
    let noise_bias = noise_bias(problem, &set, &rows, &settings.noise_bias, iterations);
    if let Some(bias) = &noise_bias {
        for (j, parameter) in set.parameters.iter().enumerate() {
            set.values[j] = parameter.clamp(set.values[j] - bias.bias[j]);
            if bias.standard_error[j].is_finite() {
                standard_errors[j] = standard_errors[j].hypot(bias.standard_error[j]);
            }
        }
    }
    let downweighted = weights
        .iter()
        .map(|w| w[..problem.channels].iter().filter(|&&v| v < 1.0).count())
        .sum::<usize>();
    Estimate {
        set,
        standard_errors,
        weight_spans,
        downweighted_fraction: downweighted as f64 / count,
        noise_bias,
        step_times,
        termination,
    }
}

/// The recording's stretch that analysed rows `first..=last` read: from the first one's test
/// function's start to the last one's end.
fn stretch(problem: &Problem, first: usize, last: usize) -> WeightSpan {
    let time = &problem.recording.time;
    let half = problem.weak_form.function.half_width_s;
    WeightSpan {
        start_s: (problem.time[first] - half).max(time[0]),
        end_s: (problem.time[last] + half).min(time[time.len() - 1]),
    }
}

/// Huber weights of a residual: per channel, `min(1, c / |z|)` with `z` the residual over its
/// channel's robust standard deviation (`sindy::median::robust_standard_deviation` of the noise-normalised residuals).
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
        let sigma = robust_standard_deviation(scaled.iter().copied());
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

/// The times of the command steps the samples cannot place
/// ([`crate::recording::command_samples::CommandSamples::unplaced_steps`]): adjacent flagged intervals count
/// as one step, at the middle of their span.
pub(crate) fn step_times(problem: &Problem) -> Vec<f64> {
    let time = &problem.recording.time;
    let mut times = Vec::new();
    let mut run: Option<(usize, usize)> = None;
    for k in problem.recording.samples.unplaced_steps() {
        run = match run {
            Some((first, last)) if k == last + 1 => Some((first, k)),
            Some((first, last)) => {
                times.push(0.5 * (time[first] + time[last + 1]));
                Some((k, k))
            }
            None => Some((k, k)),
        };
    }
    if let Some((first, last)) = run {
        times.push(0.5 * (time[first] + time[last + 1]));
    }
    times
}
