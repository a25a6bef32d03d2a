//! The time stamps of a recording: evenly spaced, or as a logger wrote them (jittered, with dropped
//! samples and gaps).
//!
//! Every operator that reads time (the weak form's quadratures, noise estimates from fourth
//! differences, the row a time falls in) asks a [`Sampling`]. An evenly spaced recording is
//! described by its interval alone, so that its operators are the exact ones of a fixed step; a
//! stamped one keeps its stamps, and an interval longer than [`GAP_FACTOR`] nominal intervals is a
//! gap that no window of an operator may span (the recording falls into segments).

use crate::median::median;

/// Largest relative deviation of an interval from the mean interval for which a recording counts
/// as evenly spaced (rounding of written time stamps: the Neural-Fly logs deviate by ~1e-12).
pub const UNIFORM_TOLERANCE: f64 = 1e-6;

/// An interval longer than this many nominal (median) intervals is a gap: the samples on either
/// side belong to different segments.
pub const GAP_FACTOR: f64 = 3.0;

/// The fourth difference of evenly spaced samples: `Δ⁴x_k = Σ_j c_j x_{k+j}`.
pub const FOURTH_DIFFERENCE: [f64; 5] = [1.0, -4.0, 6.0, -4.0, 1.0];

/// `Σ c_j²` of [`FOURTH_DIFFERENCE`]: the variance gain of white noise.
const FOURTH_DIFFERENCE_GAIN: f64 = 70.0;

/// The median of χ²₁, which turns the median of squared differences into a variance.
const MEDIAN_CHI_SQUARED_1: f64 = 0.4549;

/// When a recording's samples were taken.
#[derive(Clone, Debug, PartialEq)]
pub enum Sampling {
    /// `t_k = start + k · interval`, `len` samples.
    Uniform {
        start: f64,
        interval: f64,
        len: usize,
    },
    /// The logged stamps (strictly increasing) and their median interval.
    Stamped { time: Vec<f64>, interval: f64 },
}

impl Sampling {
    /// Evenly spaced when every interval lies within [`UNIFORM_TOLERANCE`] of the mean one (the
    /// interval is then the mean), stamped otherwise. `time` must be strictly increasing with at
    /// least two samples (the readers check it).
    pub fn new(time: &[f64]) -> Self {
        let n = time.len();
        let mean = (time[n - 1] - time[0]) / (n - 1) as f64;
        let even = time
            .windows(2)
            .all(|w| ((w[1] - w[0]) - mean).abs() <= UNIFORM_TOLERANCE * mean);
        if even {
            Self::Uniform {
                start: time[0],
                interval: mean,
                len: n,
            }
        } else {
            let intervals: Vec<f64> = time.windows(2).map(|w| w[1] - w[0]).collect();
            Self::Stamped {
                time: time.to_vec(),
                interval: median(intervals),
            }
        }
    }

    /// Whether the samples are evenly spaced.
    pub fn is_uniform(&self) -> bool {
        matches!(self, Self::Uniform { .. })
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        match self {
            Self::Uniform { len, .. } => *len,
            Self::Stamped { time, .. } => time.len(),
        }
    }

    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The nominal interval: the interval of an evenly spaced recording, the median of a stamped one.
    pub fn interval(&self) -> f64 {
        match self {
            Self::Uniform { interval, .. } | Self::Stamped { interval, .. } => *interval,
        }
    }

    /// `t_{k+1} − t_k`.
    pub fn interval_at(&self, k: usize) -> f64 {
        match self {
            Self::Uniform { interval, .. } => *interval,
            Self::Stamped { time, .. } => time[k + 1] - time[k],
        }
    }

    /// `t_k − t_0`.
    pub fn offset(&self, k: usize) -> f64 {
        match self {
            Self::Uniform { interval, .. } => k as f64 * interval,
            Self::Stamped { time, .. } => time[k] - time[0],
        }
    }

    /// The time `t` (from the first sample) in rows: `k + s` when `t` lies a fraction `s` of the
    /// way from sample `k` to sample `k + 1`; beyond the ends at the nominal interval.
    pub fn position(&self, t: f64) -> f64 {
        match self {
            Self::Uniform { interval, .. } => t / interval,
            Self::Stamped { time, interval } => {
                let n = time.len();
                let absolute = time[0] + t;
                if absolute <= time[0] {
                    return t / interval;
                }
                if absolute >= time[n - 1] {
                    return (n - 1) as f64 + (absolute - time[n - 1]) / interval;
                }
                let k = time.partition_point(|&x| x <= absolute) - 1;
                k as f64 + (absolute - time[k]) / (time[k + 1] - time[k])
            }
        }
    }

    /// Whether the interval after sample `k` is a gap ([`GAP_FACTOR`]).
    pub fn is_gap(&self, k: usize) -> bool {
        match self {
            Self::Uniform { .. } => false,
            Self::Stamped { .. } => self.interval_at(k) > GAP_FACTOR * self.interval(),
        }
    }

    /// The intervals that are gaps, by their first sample.
    pub fn gaps(&self) -> Vec<usize> {
        (0..self.len().saturating_sub(1))
            .filter(|&k| self.is_gap(k))
            .collect()
    }

    /// Weights `w_j` of the fourth difference of the five samples from `first`, `Σ w_j x_{first+j}`:
    /// [`FOURTH_DIFFERENCE`] when evenly spaced; on stamps the divided difference (zero on any cubic
    /// in time) scaled to the same white-noise gain `Σ w_j² = 70`. `None` across a gap.
    pub fn fourth_difference_weights(&self, first: usize) -> Option<[f64; 5]> {
        let Self::Stamped { time, .. } = self else {
            return Some(FOURTH_DIFFERENCE);
        };
        if (first..first + 4).any(|k| self.is_gap(k)) {
            return None;
        }
        let t = &time[first..first + 5];
        let mut weights: [f64; 5] = std::array::from_fn(|m| {
            let product: f64 = (0..5)
                .filter(|&l| l != m)
                .map(|l| (t[m] - t[l]) / self.interval())
                .product();
            1.0 / product
        });
        let gain = weights.iter().map(|w| w * w).sum::<f64>();
        let scale = (FOURTH_DIFFERENCE_GAIN / gain).sqrt();
        weights.iter_mut().for_each(|w| *w *= scale);
        Some(weights)
    }

    /// Robust standard deviation of the white noise on a smooth signal sampled here, from its
    /// fourth differences ([`crate::weak_form::white_noise_sigma`] when evenly spaced).
    pub fn white_noise_sigma(&self, x: &[f64]) -> f64 {
        if self.is_uniform() {
            return crate::weak_form::white_noise_sigma(x);
        }
        if x.len() < 5 {
            return 0.0;
        }
        let fourth: Vec<f64> = (0..x.len() - 4)
            .filter_map(|k| {
                let w = self.fourth_difference_weights(k)?;
                Some((0..5).map(|j| w[j] * x[k + j]).sum())
            })
            .collect();
        white_noise_sigma_of_fourth_differences(&fourth)
    }
}

/// Robust standard deviation of white noise from fourth differences of unit gain 70 (`Δ⁴` of white
/// noise has variance 70 σ²).
pub fn white_noise_sigma_of_fourth_differences(fourth: &[f64]) -> f64 {
    let squares: Vec<f64> = fourth.iter().map(|d| d * d).collect();
    (median(squares) / (FOURTH_DIFFERENCE_GAIN * MEDIAN_CHI_SQUARED_1)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn jittered(n: usize, dt: f64, amplitude: f64) -> Vec<f64> {
        // A deterministic jitter of ±amplitude, not periodic within the test's length.
        (0..n)
            .map(|k| k as f64 * dt + amplitude * dt * ((k as f64 * 2.399).sin()))
            .collect()
    }

    #[test]
    fn evenly_spaced_stamps_are_uniform_and_jittered_ones_are_not() {
        let even: Vec<f64> = (0..100).map(|k| 3.0 + k as f64 * 0.02).collect();
        let sampling = Sampling::new(&even);
        assert!(sampling.is_uniform());
        assert!((sampling.interval() - 0.02).abs() < 1e-15);
        assert_eq!(
            sampling.fourth_difference_weights(7),
            Some(FOURTH_DIFFERENCE)
        );
        let stamped = Sampling::new(&jittered(100, 0.01, 0.15));
        assert!(!stamped.is_uniform());
        assert!((stamped.interval() - 0.01).abs() < 0.003);
        assert!(stamped.gaps().is_empty());
    }

    /// On stamps the fourth difference still annihilates cubics in time, keeps the white-noise
    /// gain 70, and equals the evenly spaced one on even stamps.
    #[test]
    fn stamped_fourth_differences_annihilate_cubics() {
        let time = jittered(50, 0.01, 0.2);
        let sampling = Sampling::new(&time);
        let cubic: Vec<f64> = time
            .iter()
            .map(|t| 2.0 - 3.0 * t + 40.0 * t * t + 700.0 * t * t * t)
            .collect();
        for k in 0..time.len() - 4 {
            let w = sampling.fourth_difference_weights(k).unwrap();
            let value: f64 = (0..5).map(|j| w[j] * cubic[k + j]).sum();
            assert!(value.abs() < 1e-9, "{value}");
            assert!((w.iter().map(|x| x * x).sum::<f64>() - 70.0).abs() < 1e-9);
        }
        // Even stamps given as stamps (a gap elsewhere makes the recording stamped).
        let mut time: Vec<f64> = (0..40).map(|k| k as f64 * 0.01).collect();
        time.extend((0..40).map(|k| 1.0 + k as f64 * 0.01));
        let sampling = Sampling::new(&time);
        assert_eq!(sampling.gaps(), vec![39]);
        assert_eq!(sampling.fourth_difference_weights(37), None);
        let w = sampling.fourth_difference_weights(3).unwrap();
        for j in 0..5 {
            assert!((w[j] - FOURTH_DIFFERENCE[j]).abs() < 1e-9, "{w:?}");
        }
    }

    /// The noise of a smooth signal on jittered stamps is found; ignoring the stamps (the evenly
    /// spaced estimate) mistakes the jitter for noise.
    #[test]
    fn white_noise_on_stamps_ignores_the_jitter() {
        let time = jittered(4000, 0.01, 0.15);
        let sampling = Sampling::new(&time);
        let mut state = 7u64;
        let x: Vec<f64> = time
            .iter()
            .map(|t| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let u = (state >> 11) as f64 / (1u64 << 53) as f64;
                3.0 * (2.0 * t).sin() + 0.001 * (u - 0.5) * 12f64.sqrt()
            })
            .collect();
        let sigma = sampling.white_noise_sigma(&x);
        assert!((sigma / 0.001 - 1.0).abs() < 0.15, "{sigma}");
        assert!(crate::weak_form::white_noise_sigma(&x) > 3.0 * 0.001);
    }

    #[test]
    fn positions_are_rows_and_fractions() {
        let time = vec![0.0, 0.01, 0.025, 0.03, 0.2, 0.21];
        let sampling = Sampling::new(&time);
        assert!((sampling.position(0.0175) - 1.5).abs() < 1e-12);
        assert!((sampling.position(0.03) - 3.0).abs() < 1e-12);
        assert_eq!(sampling.gaps(), vec![3]);
        let uniform = Sampling::new(&[1.0, 1.5, 2.0]);
        assert_eq!(uniform.position(0.75), 1.5);
    }
}
