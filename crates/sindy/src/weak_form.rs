//! The comparison operator: the weak form of the equations of motion.
//!
//! For a smooth test function `φ` with compact support (`φ(s) = (1 − s²)^p` on `|s| ≤ 1`,
//! `s = (t − t_k) / h`, scaled so that `∫ φ dt = 1`), integration by parts gives, for any signal `x`
//! with derivative `ẋ`,
//!
//! `∫ φ(t − t_k) ẋ(t) dt = −∫ φ'(t − t_k) x(t) dt`.
//!
//! The recording's side is the right-hand integral over the logged samples of the velocity or body
//! rate (the *target* at row `k`, a smoothed acceleration); the model's side is the left-hand
//! integral of the model's acceleration, evaluated on a fine grid between the rows from the logged
//! commands ([`crate::forward`]). Both sides are quadratures of the same functional of the same
//! motion with a smooth weight, so a right model leaves only measurement noise whatever the command
//! bandwidth: no finite-difference or smoothing bias enters either side. The noise of the target is
//! `σ √(Σ ψ_j²)` for white sample noise `σ` and weights `ψ_j`; neighbouring rows share samples, so
//! their noises are correlated over the support (tests work on blocks longer than it).

use serde::Serialize;

use crate::median::median;

/// The test function's settings.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct TestFunction {
    /// Half the support `h`, s.
    pub half_width_s: f64,
    /// The exponent `p` of `(1 − s²)^p` (its first `p − 1` derivatives vanish at the ends).
    pub power: i32,
}

impl Default for TestFunction {
    fn default() -> Self {
        Self {
            half_width_s: 0.2,
            power: 4,
        }
    }
}

/// A number as it reads best in a message: plainly for ordinary magnitudes, in scientific
/// notation (4 digits) for tiny or huge ones.
fn short(value: f64) -> String {
    let magnitude = value.abs();
    if value == 0.0 || !value.is_finite() || (1e-4..1e9).contains(&magnitude) {
        format!("{value}")
    } else {
        format!("{value:.3e}")
    }
}

/// The fewest rows on each side of the centre.
pub const MIN_HALF_WIDTH_ROWS: usize = 3;

impl TestFunction {
    /// `φ(s)` before scaling.
    fn shape(&self, s: f64) -> f64 {
        if s.abs() >= 1.0 {
            0.0
        } else {
            (1.0 - s * s).powi(self.power)
        }
    }

    /// `dφ/ds` before scaling.
    fn shape_slope(&self, s: f64) -> f64 {
        if s.abs() >= 1.0 {
            0.0
        } else {
            -2.0 * self.power as f64 * s * (1.0 - s * s).powi(self.power - 1)
        }
    }

    /// The operator at sample interval `dt` (s); the error says why the interval does not fit.
    pub fn at_interval(&self, dt: f64) -> Result<WeakForm, String> {
        let rows = (self.half_width_s / dt).round();
        if !(rows.is_finite() && rows >= MIN_HALF_WIDTH_ROWS as f64 && rows <= 1e6) {
            return Err(format!(
                "the comparison's test function spans ±{} s, {} sample intervals of {} s on each side; it needs {MIN_HALF_WIDTH_ROWS} to 1e6",
                self.half_width_s,
                short(rows),
                short(dt)
            ));
        }
        let half = rows as usize;
        let width = half as f64 * dt;
        let offsets = -(half as i64)..=half as i64;
        let area: f64 = offsets
            .clone()
            .map(|j| self.shape(j as f64 / half as f64) * dt)
            .sum();
        let scale = 1.0 / area;
        let mut sample_weights: Vec<f64> = offsets
            .map(|j| -self.shape_slope(j as f64 / half as f64) / width * scale * dt)
            .collect();
        // Exact on a constant acceleration (Σ ψ_j j dt = 1), as the model side is (its weights sum
        // to 1): the two quadratures then differ only in terms of the curvature of the motion.
        let ramp: f64 = sample_weights
            .iter()
            .enumerate()
            .map(|(i, w)| w * (i as f64 - half as f64) * dt)
            .sum();
        for w in &mut sample_weights {
            *w /= ramp;
        }
        Ok(WeakForm {
            function: *self,
            half,
            dt,
            scale,
            sample_weights,
        })
    }
}

/// The test function at one sample interval: the target's sample weights and the model side's
/// weight at any time.
#[derive(Clone, Debug)]
pub struct WeakForm {
    pub function: TestFunction,
    /// Rows on each side of the centre.
    pub half: usize,
    pub dt: f64,
    /// `1 / ∫ φ dt` for the unscaled shape (by the samples' quadrature).
    scale: f64,
    /// `ψ_j = −φ'(j dt) dt`, `j = −half … half`: the target is `Σ ψ_j x_{k+j}`.
    pub sample_weights: Vec<f64>,
}

impl WeakForm {
    /// The scaled `φ` at `offset` seconds from the centre.
    pub fn weight(&self, offset: f64) -> f64 {
        self.function.shape(offset / (self.half as f64 * self.dt)) * self.scale
    }

    /// The target at rows `half..n − half`: `−∫ φ' x dt` by the samples.
    pub fn target(&self, x: &[f64]) -> Vec<f64> {
        let n = x.len();
        (self.half..n - self.half)
            .map(|k| {
                self.sample_weights
                    .iter()
                    .zip(&x[k - self.half..])
                    .map(|(w, v)| w * v)
                    .sum()
            })
            .collect()
    }

    /// Standard-deviation gain of the target on white sample noise of unit variance.
    pub fn target_noise_gain(&self) -> f64 {
        self.sample_weights
            .iter()
            .map(|w| w * w)
            .sum::<f64>()
            .sqrt()
    }

    /// Standard-deviation gain of `∫ φ a dt` on white noise of unit variance per sample of `a`.
    pub fn model_noise_gain(&self) -> f64 {
        (-(self.half as i64)..=self.half as i64)
            .map(|j| (self.weight(j as f64 * self.dt) * self.dt).powi(2))
            .sum::<f64>()
            .sqrt()
    }

    /// The model side at rows `half..n − half` of a signal given at `substeps` points per sample
    /// interval (at the interval's sub-interval midpoints; `(n − 1) · substeps` values).
    pub fn integrate(&self, values: &[f64], substeps: usize) -> Vec<f64> {
        let n = values.len() / substeps + 1;
        let h = self.dt / substeps as f64;
        let mut weights: Vec<f64> = (0..2 * self.half * substeps)
            .map(|i| self.weight((i as f64 + 0.5) * h - self.half as f64 * self.dt) * h)
            .collect();
        let total: f64 = weights.iter().sum();
        for w in &mut weights {
            *w /= total;
        }
        (self.half..n - self.half)
            .map(|k| {
                let start = (k - self.half) * substeps;
                weights
                    .iter()
                    .zip(&values[start..])
                    .map(|(w, v)| w * v)
                    .sum()
            })
            .collect()
    }
}

impl WeakForm {
    /// `∫ φ x dt` at rows `half..n − half` of a signal given at the rows themselves.
    pub fn integrate_rows(&self, values: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let mut weights: Vec<f64> = (-(self.half as i64)..=self.half as i64)
            .map(|j| self.weight(j as f64 * self.dt))
            .collect();
        let total: f64 = weights.iter().sum();
        for w in &mut weights {
            *w /= total;
        }
        (self.half..values.len().saturating_sub(self.half))
            .map(|k| {
                let mut out = [0.0; 3];
                for (w, v) in weights.iter().zip(&values[k - self.half..]) {
                    for c in 0..3 {
                        out[c] += w * v[c];
                    }
                }
                out
            })
            .collect()
    }
}

/// Robust standard deviation of the white noise on a smooth signal, from its fourth differences
/// (`Δ⁴` of white noise has variance 70 σ²; the median of χ²₁ is 0.4549).
pub fn white_noise_sigma(x: &[f64]) -> f64 {
    if x.len() < 5 {
        return 0.0;
    }
    let fourth: Vec<f64> = x
        .windows(5)
        .map(|w| w[0] - 4.0 * w[1] + 6.0 * w[2] - 4.0 * w[3] + w[4])
        .collect();
    white_noise_sigma_of_fourth_differences(&fourth)
}

/// [`white_noise_sigma`] from fourth differences already taken (of a signal that is not a plain
/// series, such as the attitude).
pub fn white_noise_sigma_of_fourth_differences(fourth: &[f64]) -> f64 {
    let squares: Vec<f64> = fourth.iter().map(|d| d * d).collect();
    (median(squares) / (70.0 * 0.4549)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Both sides of the weak form agree on a smooth signal with content up to a few Hz, and the
    /// model side integrates a sampled acceleration to the same value.
    #[test]
    fn both_sides_measure_the_same_functional() {
        let dt = 0.02;
        let form = TestFunction::default().at_interval(dt).unwrap();
        assert_eq!(form.half, 10);
        let f = |t: f64| (2.1 * t).sin() + 0.3 * (17.0 * t + 0.4).cos() + 0.05 * t * t;
        let df = |t: f64| 2.1 * (2.1 * t).cos() - 0.3 * 17.0 * (17.0 * t + 0.4).sin() + 0.1 * t;
        let n = 300;
        let x: Vec<f64> = (0..n).map(|k| f(k as f64 * dt)).collect();
        let substeps = 10;
        let h = dt / substeps as f64;
        let slopes: Vec<f64> = (0..(n - 1) * substeps)
            .map(|i| df((i as f64 + 0.5) * h))
            .collect();
        let target = form.target(&x);
        let model = form.integrate(&slopes, substeps);
        assert_eq!(target.len(), n - 20);
        assert_eq!(model.len(), target.len());
        for (a, b) in target.iter().zip(&model) {
            // The derivative reaches 5.4: agreement to 1e-4 of it.
            assert!((a - b).abs() < 5.4e-4, "{a} vs {b}");
        }
        // A constant has no derivative; a unit slope gives 1
        let ramp: Vec<f64> = (0..50).map(|k| 3.0 + k as f64 * dt).collect();
        assert!(form.target(&ramp).iter().all(|v| (v - 1.0).abs() < 1e-12));
        let constant = vec![2.5; 10 * 49];
        assert!(
            form.integrate(&constant, 10)
                .iter()
                .all(|v| (v - 2.5).abs() < 1e-12)
        );
        assert!(form.target_noise_gain() > 0.0 && form.model_noise_gain() > 0.0);
    }

    #[test]
    fn a_support_of_too_few_samples_is_refused() {
        assert!(TestFunction::default().at_interval(0.1).is_err());
        assert!(TestFunction::default().at_interval(f64::NAN).is_err());
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
