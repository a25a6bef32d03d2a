//! The bias the unfelt reaction to the gyro noise leaves in the final estimate, measured by
//! simulation and removed by extrapolation (SIMEX: Cook and Stefanski, 1994).
//!
//! A sampled command of a faster controller carries the controller's reaction to the noise of the
//! logged body rate, which the vehicle felt for one control step of the row's `N`
//! ([`crate::noise_reaction`]). No kinematic relation separates that noise from the motion, so the
//! reaction stays in the model's inputs while the same noise sits in the recorded rate the model is
//! compared with. The two are correlated, and a factor estimated through the commands (an inertia
//! scale above all) comes out biased, in either direction.
//!
//! The bias is of second order in the noise: adding the same noise once more, with its unfelt
//! reaction (the identified gains times `1 − 1/N`), moves the estimate by the same amount again.
//! Each draw adds white noise of the logged rate's standard deviation to the recorded rate and its
//! reaction to the commands, and estimates again from the final values with the final weights; a
//! draw and its negative form a pair, so that the first-order change cancels. The estimate minus
//! the mean change is the estimate at no noise (linear extrapolation in the noise variance).

use physics::vector::Vec3;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::Serialize;

use crate::fit::FittedSet;
use crate::noise_reaction;
use crate::problem::Problem;
use crate::refine::{FitRows, levenberg_marquardt};
use crate::weak_form::white_noise_sigma;

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

/// The measured bias, per parameter of the set.
#[derive(Clone, Debug, PartialEq)]
pub struct RateNoiseBias {
    /// The mean change of the estimate when the rate noise and its reaction are added once more.
    pub bias: Vec<f64>,
    /// The Monte Carlo standard error of `bias` (from the spread between pairs).
    pub standard_error: Vec<f64>,
}

/// The bias of `set` (estimated on `rows`) from the unfelt reaction to the rate noise, when the
/// recording's commands carry one (`None` otherwise).
pub fn rate_noise_bias(
    problem: &Problem,
    set: &FittedSet,
    rows: &FitRows,
    settings: &SimexSettings,
    iterations: usize,
) -> Option<RateNoiseBias> {
    let reaction = problem.recording.noise_reaction.as_ref()?;
    if set.parameters.is_empty() || settings.pairs == 0 {
        return None;
    }
    let sigma: Vec3 = std::array::from_fn(|a| {
        let series: Vec<f64> = problem.recording.body_rate.iter().map(|w| w[a]).collect();
        white_noise_sigma(&series)
    });
    let changes: Vec<Vec<f64>> = (0..settings.pairs)
        .into_par_iter()
        .map(|pair| {
            let mut rng = ChaCha8Rng::seed_from_u64(settings.seed.wrapping_add(pair as u64));
            let noise: Vec<Vec3> = (0..problem.recording.len())
                .map(|_| std::array::from_fn(|a| gaussian(&mut rng, sigma[a])))
                .collect();
            let mut mean = vec![0.0; set.parameters.len()];
            for sign in [1.0, -1.0] {
                let perturbed = with_rate_noise(problem, reaction, &noise, sign);
                let values =
                    levenberg_marquardt(&perturbed, &set.parameters, &set.values, rows, iterations)
                        .0;
                for ((m, v), v0) in mean.iter_mut().zip(&values).zip(&set.values) {
                    *m += 0.5 * (v - v0);
                }
            }
            mean
        })
        .collect();
    let pairs = changes.len() as f64;
    let parameters = set.parameters.len();
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
    Some(RateNoiseBias {
        bias,
        standard_error,
    })
}

/// The problem with `sign · noise` added to the recorded body rate and its unfelt reaction to the
/// commands.
fn with_rate_noise(
    problem: &Problem,
    reaction: &noise_reaction::NoiseReaction,
    noise: &[Vec3],
    sign: f64,
) -> Problem {
    let mut recording = problem.recording.clone();
    let signed: Vec<Vec3> = noise.iter().map(|n| n.map(|v| sign * v)).collect();
    let response = noise_reaction::rate_noise_response(&recording, reaction, &signed);
    let mut commands = recording.commands.clone();
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
    recording.set_commands(commands);
    problem.with_recording(recording)
}

/// A standard normal draw times `sigma` (Box–Muller).
pub(crate) fn gaussian(rng: &mut ChaCha8Rng, sigma: f64) -> f64 {
    let u: f64 = rng.random_range(f64::EPSILON..1.0);
    let v: f64 = rng.random_range(0.0..1.0);
    sigma * (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
}
