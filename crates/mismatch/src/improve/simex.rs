//! The bias the noise on the model's inputs leaves in the final estimate, measured by simulation
//! and removed by extrapolation (SIMEX: Cook and Stefanski, 1994).
//!
//! Instantaneous samples of a faster controller's commands carry its step-to-step reaction to its
//! sensors' noise, which the vehicle averaged over the row ([`crate::recording::noise_reaction`]). Two biases
//! follow:
//!
//! - **Correlation with the recorded rate.** Sampled with the state, the commands' reaction to the
//!   logged rate's noise is correlated with the same noise in the rate the model is compared with;
//!   no kinematic relation separates that noise from the motion. (The reaction to the logged
//!   attitude, position and velocity noise is removed before the analysis.)
//! - **Attenuation.** Sampled at another time than the state (configuration C: one control step
//!   late), the samples' white noise is an error of the model's inputs, uncorrelated with the
//!   recording: a factor estimated through them (an inertia scale, a motor lag) comes out too far
//!   from the data, by about the noise's share of the model's signal (1–2 % of `k` on C).
//!
//! Both are of second order in the noise: adding the same noise once more moves the estimate by
//! the same amount again. Each draw adds, in the first case, white noise of the logged rate's
//! standard deviation to the recorded rate and its unfelt reaction (the identified gains times
//! `1 − 1/N`) to the commands; in the second, white noise to the commands with `1 − 1/N` of the
//! samples' own white-noise covariance, in the domain the mixer is linear in (where the reaction
//! adds: added to the speeds, it would give their squares a mean they do not have). The estimate
//! is fitted again from the final values with the final weights; a draw and its negative form a
//! pair, so that the first-order change cancels. Where the reaction to the logged attitude noise
//! was removed, each draw also adds the unfelt reaction to a draw of that noise's estimation error
//! (the smoother's posterior): what the removal left in the commands is an error of the inputs.
//! The estimate minus the mean change is the estimate at no noise (linear extrapolation in the
//! noise variance).

use physics::vector::Vec3;
use physics::{Actuators, MAX_ACTUATORS};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use rayon::prelude::*;
use serde::Serialize;
use sindy::sampling::Sampling;

use crate::explain::fit::FittedSet;
use crate::locate::problem::Problem;
use crate::model::refine::{FitRows, levenberg_marquardt};
use crate::recording::noise_reaction;

/// Settings of the correction (recorded in the output).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SimexSettings {
    /// Pairs of draws (a draw and its negative).
    pub pairs: usize,
    /// Seed of the draws.
    pub seed: u64,
}

impl Default for SimexSettings {
    fn default() -> Self {
        Self {
            pairs: 4,
            seed: 2026,
        }
    }
}

/// The noises added to measure the bias.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct NoiseSources {
    /// The logged rate's noise with its unfelt reaction (commands sampled with the state).
    pub rate: bool,
    /// The error of the attitude noise's estimate, through the unfelt reaction the analysis
    /// removed with it (commands sampled with the state).
    pub attitude_estimate: bool,
    /// The command samples' unfelt white noise (samples from which no reaction was removed).
    pub command_samples: bool,
}

/// The measured bias, per parameter of the set.
#[derive(Clone, Debug, PartialEq)]
pub struct NoiseBias {
    /// What was added.
    pub sources: NoiseSources,
    /// The mean change of the estimate when the noise is added once more.
    pub bias: Vec<f64>,
    /// The Monte Carlo standard error of `bias` (from the spread between pairs).
    pub standard_error: Vec<f64>,
}

/// The bias of `set` (estimated on `rows`) from the noise on the model's inputs, when the
/// recording's commands are instantaneous samples of a faster controller (`None` otherwise).
pub fn noise_bias(
    problem: &Problem,
    set: &FittedSet,
    rows: &FitRows,
    settings: &SimexSettings,
    iterations: usize,
) -> Option<NoiseBias> {
    let reaction = problem.recording.noise_reaction.as_ref();
    let command_noise = command_sample_noise(problem);
    if (reaction.is_none() && command_noise.is_none())
        || set.parameters.is_empty()
        || settings.pairs == 0
    {
        return None;
    }
    let sigma: Vec3 = std::array::from_fn(|a| {
        let series: Vec<f64> = problem.recording.body_rate.iter().map(|w| w[a]).collect();
        problem.recording.white_noise_sigma(&series)
    });
    let length = problem.recording.len();
    let draw_rate = |rng: &mut ChaCha8Rng| -> Vec<Vec3> {
        (0..length)
            .map(|_| std::array::from_fn(|a| gaussian(rng, sigma[a])))
            .collect()
    };
    let command_factor = command_noise.map(|covariance| square_root(&covariance));
    let changes: Vec<Vec<f64>> = (0..settings.pairs)
        .into_par_iter()
        .map(|pair| {
            let mut rng = ChaCha8Rng::seed_from_u64(settings.seed.wrapping_add(pair as u64));
            let noise = reaction.map(|_| draw_rate(&mut rng));
            let extra: Option<Vec<Actuators>> = command_factor.as_ref().map(|factor| {
                let count = factor.len();
                (0..length)
                    .map(|_| {
                        let z: Vec<f64> = (0..count).map(|_| gaussian(&mut rng, 1.0)).collect();
                        let mut draw = [0.0; MAX_ACTUATORS];
                        for (value, row) in draw.iter_mut().zip(factor) {
                            *value = row.iter().zip(&z).map(|(f, z)| f * z).sum();
                        }
                        draw
                    })
                    .collect()
            });
            let attitude: Option<Vec<Actuators>> = reaction.map(|r| {
                let mut normal = || gaussian(&mut rng, 1.0);
                noise_reaction::attitude_estimate_error_response(&problem.recording, r, &mut normal)
            });
            let mut mean = vec![0.0; set.parameters.len()];
            for sign in [1.0, -1.0] {
                let perturbed = with_noise(
                    problem,
                    reaction.zip(noise.as_deref()),
                    attitude.as_deref(),
                    extra.as_deref(),
                    sign,
                );
                let values =
                    levenberg_marquardt(&perturbed, &set.parameters, &set.values, rows, iterations)
                        .values;
                for ((m, v), v0) in mean.iter_mut().zip(&values).zip(&set.values) {
                    *m += 0.5 * (v - v0);
                }
            }
            mean
        })
        .collect();
    let (bias, standard_error) = mean_and_standard_error(&changes, set.parameters.len());
    Some(NoiseBias {
        sources: NoiseSources {
            rate: reaction.is_some(),
            attitude_estimate: reaction.is_some(),
            command_samples: command_factor.is_some(),
        },
        bias,
        standard_error,
    })
}

/// Per parameter, the mean of the pairs' changes and its Monte Carlo standard error (from their
/// spread; NaN with fewer than two pairs).
fn mean_and_standard_error(changes: &[Vec<f64>], parameters: usize) -> (Vec<f64>, Vec<f64>) {
    let pairs = changes.len() as f64;
    let bias: Vec<f64> = (0..parameters)
        .map(|j| changes.iter().map(|c| c[j]).sum::<f64>() / pairs)
        .collect();
    let standard_error = (0..parameters)
        .map(|j| {
            if changes.len() < 2 {
                return f64::NAN;
            }
            let spread = changes
                .iter()
                .map(|c| (c[j] - bias[j]).powi(2))
                .sum::<f64>()
                / (pairs - 1.0);
            (spread / pairs).sqrt()
        })
        .collect();
    (bias, standard_error)
}

/// The problem with `sign · noise` added to the recorded body rate and its unfelt reaction to the
/// commands, `sign · attitude` to the commands (in their units) and `sign · extra` to the commands
/// (in the domain the mixer is linear in).
fn with_noise(
    problem: &Problem,
    rate: Option<(&noise_reaction::NoiseReaction, &[Vec3])>,
    attitude: Option<&[Actuators]>,
    extra: Option<&[Actuators]>,
    sign: f64,
) -> Problem {
    let mut recording = problem.recording.clone();
    let mut commands = recording.commands.clone();
    if let Some((reaction, noise)) = rate {
        let signed: Vec<Vec3> = noise.iter().map(|n| n.map(|v| sign * v)).collect();
        let response = noise_reaction::rate_noise_response(&recording, reaction, &signed);
        for ((rate, command), (n, change)) in recording
            .body_rate
            .iter_mut()
            .zip(commands.iter_mut())
            .zip(signed.iter().zip(&response))
        {
            for a in 0..3 {
                rate[a] += n[a];
            }
            for (c, d) in command.iter_mut().zip(change) {
                *c += d;
            }
        }
    }
    if let Some(attitude) = attitude {
        for (command, change) in commands.iter_mut().zip(attitude) {
            for (c, d) in command.iter_mut().zip(change) {
                *c += sign * d;
            }
        }
    }
    if let Some(extra) = extra {
        let domain = recording.samples.domain;
        for (command, e) in commands.iter_mut().zip(extra) {
            for (c, d) in command.iter_mut().zip(e) {
                *c = domain.to_command(domain.to_domain(*c) + sign * d);
            }
        }
    }
    recording.set_commands(commands);
    problem.with_recording(recording)
}

/// For instantaneous samples of a faster controller from which no reaction to the logged noise was
/// removed ([`crate::recording::noise_reaction`]), the covariance of their unfelt white noise in the domain
/// the mixer is linear in (where the controller's reaction adds): `1 − 1/N` of the samples' own
/// (`N` control steps per row); `None` otherwise. Where the reaction was removed, what remains of
/// the samples' white noise is mostly the reaction to the row's other steps' noise, which the
/// vehicle felt: not an error of the inputs.
fn command_sample_noise(problem: &Problem) -> Option<Vec<Vec<f64>>> {
    let logger = &problem.model.logger;
    let steps = logger.controller_rate_hz? * problem.recording.dt();
    let sampled = logger.command == physics::CommandLogging::Sample;
    if !sampled
        || steps < noise_reaction::MIN_STEPS_PER_ROW
        || problem.recording.noise_reaction.is_some()
    {
        return None;
    }
    let samples = &problem.recording.samples;
    let in_domain: Vec<Actuators> = problem
        .recording
        .commands
        .iter()
        .map(|c| c.map(|v| samples.domain.to_domain(v)))
        .collect();
    let covariance = white_covariance(&in_domain, samples.count, &problem.recording.sampling);
    let unfelt = 1.0 - 1.0 / steps;
    Some(
        covariance
            .into_iter()
            .map(|row| row.into_iter().map(|c| unfelt * c).collect())
            .collect(),
    )
}

/// The covariance of the white noise on the first `count` of smooth series sampled at
/// `sampling`, by polarisation of [`Sampling::white_noise_sigma`]:
/// `cov(a, b) = (σ(a + b)² − σ(a − b)²) / 4`.
fn white_covariance(series: &[Actuators], count: usize, sampling: &Sampling) -> Vec<Vec<f64>> {
    let sigma2 = |f: &dyn Fn(&Actuators) -> f64| {
        let values: Vec<f64> = series.iter().map(f).collect();
        sampling.white_noise_sigma(&values).powi(2)
    };
    (0..count)
        .map(|i| {
            (0..count)
                .map(|j| {
                    if i == j {
                        sigma2(&|x| x[i])
                    } else {
                        0.25 * (sigma2(&|x| x[i] + x[j]) - sigma2(&|x| x[i] - x[j]))
                    }
                })
                .collect()
        })
        .collect()
}

/// A square root `L` (`L Lᵀ = C`) of a symmetric matrix with its negative eigenvalues set to zero.
fn square_root(matrix: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let n = matrix.len();
    let m = faer::Mat::from_fn(n, n, |i, j| 0.5 * (matrix[i][j] + matrix[j][i]));
    let Ok(eigen) = m.self_adjoint_eigen(faer::Side::Lower) else {
        return vec![vec![0.0; n]; n];
    };
    let (u, s) = (eigen.U(), eigen.S());
    (0..n)
        .map(|i| (0..n).map(|j| u[(i, j)] * s[j].max(0.0).sqrt()).collect())
        .collect()
}

/// A standard normal draw times `sigma`.
pub(crate) fn gaussian(rng: &mut ChaCha8Rng, sigma: f64) -> f64 {
    let draw: f64 = StandardNormal.sample(rng);
    sigma * draw
}
