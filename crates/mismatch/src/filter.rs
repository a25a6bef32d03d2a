//! The smoothed derivative of the recording and the same smoothing applied to the model.
//!
//! A Savitzky–Golay derivative `d_k = Σ_j h_j x_{k+j} / dt` (Σ h_j = 0) is, by summation by parts,
//! a weighted mean of the interval slopes: `d_k = Σ_j c_j (x_{k+j+1} − x_{k+j}) / dt` with
//! `c_j = −Σ_{i≤j} h_i` and `Σ c_j = 1`. Each interval slope of a velocity is the interval mean of
//! its acceleration, so applying the weights `c_j` to the model's interval means
//! ([`crate::forward`]) predicts the smoothed derivative exactly when the model is right: the
//! residual then holds only measurement noise, not smoothing bias.

use data::Derivative;

use crate::error::Result;

/// A derivative estimator and its matched interval weights.
#[derive(Clone, Debug)]
pub struct MatchedSmoother {
    pub derivative: Derivative,
    /// Sample weights `h_j` of the derivative at the centre of the window (for dt = 1).
    pub sample_weights: Vec<f64>,
    /// Interval weights `c_j` (one fewer than the samples).
    pub interval_weights: Vec<f64>,
}

impl MatchedSmoother {
    /// Builds the weights of a Savitzky–Golay estimator by applying it to unit impulses.
    pub fn new(derivative: Derivative) -> Result<Self> {
        derivative.validate()?;
        let window = match derivative {
            Derivative::SavitzkyGolay { window, .. } => window,
            Derivative::Central => 3,
            Derivative::Forward => 2,
        };
        let centre = window / 2;
        let mut sample_weights = Vec::with_capacity(window);
        for j in 0..window {
            let mut impulse = vec![0.0; window.max(derivative.min_samples())];
            impulse[j] = 1.0;
            sample_weights.push(derivative.apply(&impulse, 1.0)?[centre]);
        }
        let mut cumulative = 0.0;
        let interval_weights = sample_weights[..window - 1]
            .iter()
            .map(|h| {
                cumulative += h;
                -cumulative
            })
            .collect();
        Ok(Self {
            derivative,
            sample_weights,
            interval_weights,
        })
    }

    /// Rows lost at each end (where the estimator is not centred).
    pub fn half_window(&self) -> usize {
        self.sample_weights.len() / 2
    }

    /// The smoothed derivative of `x` at rows `half..n−half`.
    pub fn derivative_of(&self, x: &[f64], dt: f64) -> Vec<f64> {
        let half = self.half_window();
        (half..x.len() - half)
            .map(|k| {
                self.sample_weights
                    .iter()
                    .zip(&x[k - half..])
                    .map(|(w, v)| w * v)
                    .sum::<f64>()
                    / dt
            })
            .collect()
    }

    /// The matched smoothing of interval means (n − 1 of them) at rows `half..n−half`.
    pub fn smooth_intervals(&self, intervals: &[f64]) -> Vec<f64> {
        let half = self.half_window();
        let n = intervals.len() + 1;
        (half..n - half)
            .map(|k| {
                self.interval_weights
                    .iter()
                    .zip(&intervals[k - half..])
                    .map(|(w, v)| w * v)
                    .sum()
            })
            .collect()
    }

    /// Standard-deviation gain of the derivative on white noise of unit variance (for dt = 1).
    pub fn sample_noise_gain(&self) -> f64 {
        self.sample_weights
            .iter()
            .map(|w| w * w)
            .sum::<f64>()
            .sqrt()
    }

    /// Standard-deviation gain of the interval smoothing on white noise of unit variance.
    pub fn interval_noise_gain(&self) -> f64 {
        self.interval_weights
            .iter()
            .map(|w| w * w)
            .sum::<f64>()
            .sqrt()
    }
}

/// Robust standard deviation of the white noise on a smooth signal, from its fourth differences
/// (`Δ⁴` of white noise has variance 70 σ²; the median of χ²₁ is 0.4549).
pub fn white_noise_sigma(x: &[f64]) -> f64 {
    if x.len() < 5 {
        return 0.0;
    }
    let mut squares: Vec<f64> = x
        .windows(5)
        .map(|w| (w[0] - 4.0 * w[1] + 6.0 * w[2] - 4.0 * w[3] + w[4]).powi(2))
        .collect();
    let middle = squares.len() / 2;
    let (_, median, _) = squares.select_nth_unstable_by(middle, f64::total_cmp);
    (*median / (70.0 * 0.4549)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interval_weights_sum_to_one_and_reproduce_the_derivative() {
        let smoother = MatchedSmoother::new(Derivative::SMOOTH).unwrap();
        let sum: f64 = smoother.interval_weights.iter().sum();
        assert!((sum - 1.0).abs() < 1e-12, "{sum}");
        // For any signal: derivative of the samples = matched smoothing of the interval slopes.
        let dt = 0.02;
        let x: Vec<f64> = (0..80)
            .map(|k| (0.37 * k as f64).sin() + 0.01 * (k * k) as f64)
            .collect();
        let slopes: Vec<f64> = x.windows(2).map(|w| (w[1] - w[0]) / dt).collect();
        let direct = smoother.derivative_of(&x, dt);
        let matched = smoother.smooth_intervals(&slopes);
        assert_eq!(direct.len(), matched.len());
        for (a, b) in direct.iter().zip(&matched) {
            assert!((a - b).abs() < 1e-9, "{a} vs {b}");
        }
        let library = Derivative::SMOOTH.apply(&x, dt).unwrap();
        assert!((library[30] - direct[30 - smoother.half_window()]).abs() < 1e-9);
    }

    #[test]
    fn white_noise_sigma_ignores_smooth_signals() {
        let mut state = 99u64;
        let x: Vec<f64> = (0..4000)
            .map(|k| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let u = (state >> 11) as f64 / (1u64 << 53) as f64;
                (k as f64 * 0.01).sin() * 3.0 + 0.01 * (u - 0.5) * 12f64.sqrt()
            })
            .collect();
        let sigma = white_noise_sigma(&x);
        assert!((sigma / 0.01 - 1.0).abs() < 0.15, "{sigma}");
    }
}
