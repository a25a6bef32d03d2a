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
//!
//! The operator works on a [`Sampling`]: evenly spaced samples share one set of weights; on
//! logged stamps every window has its own (a trapezoid on the stamps made exact on cubics), and
//! only the rows whose window spans no gap are centres ([`WeakForm::centres`]).

use serde::Serialize;

use std::sync::OnceLock;

use faer::Mat;

use crate::sampling::Sampling;
use crate::sampling::white_noise_sigma_of_fourth_differences;

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

    /// The operator on a recording's samples; the error says why its interval does not fit.
    pub fn on(&self, sampling: &Sampling) -> Result<WeakForm, String> {
        let dt = sampling.interval();
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
        let area: f64 = (-(half as i64)..=half as i64)
            .map(|j| self.shape(j as f64 / half as f64) * dt)
            .sum();
        let mut form = WeakForm {
            function: *self,
            half,
            dt,
            scale: 1.0 / area,
            sampling: sampling.clone(),
            centres: Vec::new(),
            windows: Vec::new(),
            even_weights: None,
            stamped_target: OnceLock::new(),
            stamped_model: OnceLock::new(),
        };
        match sampling {
            Sampling::Uniform { len, .. } => {
                let points: Vec<(f64, [f64; 2], f64)> = (-(half as i64)..=half as i64)
                    .map(|j| (j as f64 / half as f64, [j as f64, dt], dt))
                    .collect();
                form.even_weights = Some(form.derivative_weights(&points));
                form.centres = (half..len.saturating_sub(half)).collect();
                form.windows = form.centres.iter().map(|&k| (k - half, k + half)).collect();
            }
            Sampling::Stamped { time, .. } => {
                (form.centres, form.windows) = stamped_windows(time, sampling, half as f64 * dt);
            }
        }
        Ok(form)
    }
}

/// The rows whose window `[t_k − width, t_k + width]` lies within the stamps and spans no gap, and
/// each one's first and last sample: the last at or before `t_k − width`, the first at or after
/// `t_k + width` (so that the quadrature covers the whole support).
fn stamped_windows(
    time: &[f64],
    sampling: &Sampling,
    width: f64,
) -> (Vec<usize>, Vec<(usize, usize)>) {
    let slack = 1e-9 * sampling.interval();
    let n = time.len();
    let (mut centres, mut windows) = (Vec::new(), Vec::new());
    let (mut first, mut last) = (0usize, 0usize);
    // Prefix count of gaps: a window spans one when the count changes within it.
    let mut gaps_before = vec![0usize; n];
    for k in 1..n {
        gaps_before[k] = gaps_before[k - 1] + usize::from(sampling.is_gap(k - 1));
    }
    for k in 0..n {
        if time[k] - time[0] < width - slack {
            continue;
        }
        while time[k] - time[first + 1] >= width - slack {
            first += 1;
        }
        last = last.max(k);
        while last < n && time[last] - time[k] < width - slack {
            last += 1;
        }
        if last == n {
            break;
        }
        if gaps_before[last] == gaps_before[first] {
            centres.push(k);
            windows.push((first, last));
        }
    }
    (centres, windows)
}

/// Per-centre weights end to end, with where each centre's start (one more entry: the end).
#[derive(Clone, Debug, Default)]
struct Packed {
    values: Vec<f64>,
    starts: Vec<usize>,
}

impl Packed {
    fn of(parts: impl Iterator<Item = Vec<f64>>) -> Self {
        let mut packed = Self {
            values: Vec::new(),
            starts: vec![0],
        };
        for part in parts {
            packed.values.extend(part);
            packed.starts.push(packed.values.len());
        }
        packed
    }

    fn part(&self, index: usize) -> &[f64] {
        &self.values[self.starts[index]..self.starts[index + 1]]
    }
}

/// The test function on a recording's samples: the target's sample weights and the model side's
/// weight at any time, at the rows whose window fits ([`WeakForm::centres`]).
#[derive(Clone, Debug)]
pub struct WeakForm {
    pub function: TestFunction,
    /// Rows on each side of the centre at the nominal interval.
    pub half: usize,
    /// The nominal sample interval, s.
    pub dt: f64,
    /// `1 / ∫ φ dt` for the unscaled shape (by the quadrature at the nominal interval).
    scale: f64,
    sampling: Sampling,
    /// The rows the operator is evaluated at, in order: every row whose window lies inside the
    /// recording and spans no gap (`half..n − half` when evenly spaced).
    pub centres: Vec<usize>,
    /// Each centre's window: its first and last sample.
    windows: Vec<(usize, usize)>,
    /// When evenly spaced, the weights every centre shares: `ψ_j = −φ'(j dt) dt`, `j = −half … half`.
    even_weights: Option<Vec<f64>>,
    /// When stamped, each centre's target weights end to end, made at the first use.
    stamped_target: OnceLock<Packed>,
    /// When stamped, the number of points per interval and each centre's model-side weights end
    /// to end, made at the first use.
    stamped_model: OnceLock<(usize, Packed)>,
}

impl WeakForm {
    /// The scaled `φ` at `offset` seconds from the centre.
    pub fn weight(&self, offset: f64) -> f64 {
        self.function.shape(offset / (self.half as f64 * self.dt)) * self.scale
    }

    /// The sample weights `ψ_j ∝ −φ'(s_j) Δ_j` of the target from each sample's position in the
    /// support `s_j`, seconds from the centre `a_j · b_j` (multiplied in that order: evenly spaced,
    /// `j · dt`) and quadrature length `Δ_j`, scaled to be exact on a constant acceleration
    /// (`Σ ψ_j a_j b_j = 1`), as the model side is (its weights sum to 1): the two quadratures then
    /// differ only in terms of the curvature of the motion.
    fn derivative_weights(&self, points: &[(f64, [f64; 2], f64)]) -> Vec<f64> {
        let width = self.half as f64 * self.dt;
        let mut weights: Vec<f64> = points
            .iter()
            .map(|&(s, _, length)| -self.function.shape_slope(s) / width * self.scale * length)
            .collect();
        let ramp: f64 = weights
            .iter()
            .zip(points)
            .map(|(w, &(_, [a, b], _))| w * a * b)
            .sum();
        for w in &mut weights {
            *w /= ramp;
        }
        weights
    }

    /// The stamps of a stamped recording (`None` when evenly spaced).
    fn stamps(&self) -> Option<&[f64]> {
        match &self.sampling {
            Sampling::Stamped { time, .. } => Some(time),
            Sampling::Uniform { .. } => None,
        }
    }

    /// The target's sample weights at the `index`-th centre, from its window's first sample.
    fn target_weights(&self, index: usize) -> &[f64] {
        if let Some(weights) = &self.even_weights {
            return weights;
        }
        self.stamped_target
            .get_or_init(|| {
                Packed::of((0..self.centres.len()).map(|i| self.stamped_target_weights(i)))
            })
            .part(index)
    }

    /// [`Self::target_weights`] of a stamped form, computed.
    fn stamped_target_weights(&self, index: usize) -> Vec<f64> {
        let time = self.stamps().expect("stamped");
        let (k, (first, last)) = (self.centres[index], self.windows[index]);
        let width = self.half as f64 * self.dt;
        let points: Vec<(f64, [f64; 2], f64)> = (first..=last)
            .map(|j| {
                let offset = time[j] - time[k];
                let before = if j > first {
                    time[j] - time[j - 1]
                } else {
                    0.0
                };
                let after = if j < last { time[j + 1] - time[j] } else { 0.0 };
                (offset / width, [offset, 1.0], 0.5 * (before + after))
            })
            .collect();
        let mut weights = self.derivative_weights(&points);
        self.exact_on_cubics(&mut weights, &points);
        weights
    }

    /// Corrects stamped weights so that the target is exact on every cubic in time, as the
    /// evenly spaced trapezoid nearly is by symmetry: `Σ ψ_j τ_j^m = ∫ −φ'(τ) τ^m dτ` for
    /// `m = 0 … 3` (`0, 1, 0, 3 σ²`, `σ²` the second moment of the unit-area `φ`), by the smallest
    /// change weighted by `φ(s_j) Δ_j` (none at the support's ends). Jittered stamps otherwise
    /// leave the trapezoid's second-order error.
    fn exact_on_cubics(&self, weights: &mut [f64], points: &[(f64, [f64; 2], f64)]) {
        let width = self.half as f64 * self.dt;
        let second_moment = width * width / (2.0 * self.function.power as f64 + 3.0);
        let wanted = [0.0, 1.0, 0.0, 3.0 * second_moment];
        // Powers of τ / width keep the 4 × 4 system well scaled.
        let scaled = |m: usize| width.powi(m as i32);
        let mut gram = Mat::<f64>::zeros(4, 4);
        let mut rhs = Mat::<f64>::zeros(4, 1);
        for m in 0..4 {
            rhs[(m, 0)] = wanted[m] / scaled(m);
        }
        for (w, &(s, [a, b], length)) in weights.iter().zip(points) {
            let u = a * b / width;
            let powers = [1.0, u, u * u, u * u * u];
            let taper = self.function.shape(s) * length;
            for m in 0..4 {
                rhs[(m, 0)] -= w * powers[m];
                for l in 0..4 {
                    gram[(m, l)] += taper * powers[m] * powers[l];
                }
            }
        }
        let lambda = crate::linalg::ridge_from_gram(gram.as_ref(), rhs.as_ref(), 0.0);
        if (0..4).any(|m| !lambda[(m, 0)].is_finite()) {
            return;
        }
        for (w, &(s, [a, b], length)) in weights.iter_mut().zip(points) {
            let u = a * b / width;
            let taper = self.function.shape(s) * length;
            *w += taper
                * (0..4)
                    .map(|m| lambda[(m, 0)] * u.powi(m as i32))
                    .sum::<f64>();
        }
    }

    /// The target at the centres: `−∫ φ' x dt` by the samples.
    pub fn target(&self, x: &[f64]) -> Vec<f64> {
        (0..self.centres.len())
            .map(|index| {
                let first = self.windows[index].0;
                self.target_weights(index)
                    .iter()
                    .zip(&x[first..])
                    .map(|(w, v)| w * v)
                    .sum()
            })
            .collect()
    }

    /// Standard-deviation gain of the target on white sample noise of unit variance (the RMS over
    /// the centres when stamped).
    pub fn target_noise_gain(&self) -> f64 {
        let square = |weights: &[f64]| weights.iter().map(|w| w * w).sum::<f64>();
        match &self.even_weights {
            Some(weights) => square(weights).sqrt(),
            None => {
                let total: f64 = (0..self.centres.len())
                    .map(|index| square(self.target_weights(index)))
                    .sum();
                (total / self.centres.len().max(1) as f64).sqrt()
            }
        }
    }

    /// Standard-deviation gain of `∫ φ a dt` on white noise of unit variance per sample of `a`
    /// (at the nominal interval).
    pub fn model_noise_gain(&self) -> f64 {
        (-(self.half as i64)..=self.half as i64)
            .map(|j| (self.weight(j as f64 * self.dt) * self.dt).powi(2))
            .sum::<f64>()
            .sqrt()
    }

    /// Weights `φ(offset) · length` normalised to sum to one.
    fn mean_weights(&self, points: impl Iterator<Item = (f64, f64)>) -> Vec<f64> {
        let mut weights: Vec<f64> = points
            .map(|(offset, length)| self.weight(offset) * length)
            .collect();
        let total: f64 = weights.iter().sum();
        for w in &mut weights {
            *w /= total;
        }
        weights
    }

    /// The model side at the centres of a signal given at `substeps` points per sample interval
    /// (at the interval's sub-interval midpoints; `(n − 1) · substeps` values).
    pub fn integrate(&self, values: &[f64], substeps: usize) -> Vec<f64> {
        let (values, _) = values.as_chunks::<1>();
        (self.integrate_channels(values, substeps).into_iter())
            .map(|[value]| value)
            .collect()
    }

    /// [`Self::integrate`] of `K` signals at once (one array per point): each channel is summed in
    /// the same order, to the same value, as alone; the channels' sums run side by side.
    pub fn integrate_channels<const K: usize>(
        &self,
        values: &[[f64; K]],
        substeps: usize,
    ) -> Vec<[f64; K]> {
        let parts = substeps as f64;
        let even = self.stamps().is_none().then(|| {
            let h = self.dt / parts;
            let offset = self.half as f64 * self.dt;
            self.mean_weights(
                (0..2 * self.half * substeps).map(|i| ((i as f64 + 0.5) * h - offset, h)),
            )
        });
        let stamped = even.is_none().then(|| self.stamped_model_weights(substeps));
        // The value `Iterator::sum` starts from.
        let empty: f64 = std::iter::empty::<f64>().sum();
        (0..self.centres.len())
            .map(|index| {
                let first = self.windows[index].0;
                let weights = match (&even, stamped) {
                    (Some(weights), _) => weights.as_slice(),
                    (None, Some(packed)) => packed.part(index),
                    (None, None) => unreachable!("a form is even or stamped"),
                };
                let mut sums = [empty; K];
                for (w, value) in weights.iter().zip(&values[first * substeps..]) {
                    for (sum, v) in sums.iter_mut().zip(value) {
                        *sum += w * v;
                    }
                }
                sums
            })
            .collect()
    }

    /// Each centre's model-side weights on stamps at `substeps` points per interval (made once).
    fn stamped_model_weights(&self, substeps: usize) -> &Packed {
        let (made_for, packed) = self.stamped_model.get_or_init(|| {
            let time = self.stamps().expect("stamped");
            let parts = substeps as f64;
            let packed = Packed::of(self.centres.iter().zip(&self.windows).map(
                |(&k, &(first, last))| {
                    self.mean_weights((first..last).flat_map(|i| {
                        let h = (time[i + 1] - time[i]) / parts;
                        let start = time[i] - time[k];
                        (0..substeps).map(move |s| (start + (s as f64 + 0.5) * h, h))
                    }))
                },
            ));
            (substeps, packed)
        });
        assert_eq!(
            *made_for, substeps,
            "a stamped weak form integrates at one number of points per interval"
        );
        packed
    }

    /// `∫ φ x dt` at the centres of a signal given at the rows themselves.
    pub fn integrate_rows(&self, values: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let even = self.stamps().is_none().then(|| {
            // Evenly spaced: the common length cancels.
            self.mean_weights(
                (-(self.half as i64)..=self.half as i64).map(|j| (j as f64 * self.dt, 1.0)),
            )
        });
        (0..self.centres.len())
            .map(|index| {
                let (k, (first, last)) = (self.centres[index], self.windows[index]);
                let stamped;
                let weights = match (&even, self.stamps()) {
                    (Some(weights), _) => weights,
                    (None, Some(time)) => {
                        stamped = self.mean_weights((first..=last).map(|j| {
                            let before = if j > first {
                                time[j] - time[j - 1]
                            } else {
                                0.0
                            };
                            let after = if j < last { time[j + 1] - time[j] } else { 0.0 };
                            (time[j] - time[k], 0.5 * (before + after))
                        }));
                        &stamped
                    }
                    (None, None) => unreachable!("a form is even or stamped"),
                };
                let mut out = [0.0; 3];
                for (w, v) in weights.iter().zip(&values[first..]) {
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

#[cfg(test)]
mod tests {
    use super::*;

    fn even(dt: f64, len: usize) -> Sampling {
        Sampling::Uniform {
            start: 0.0,
            interval: dt,
            len,
        }
    }

    /// On jittered stamps with a dropped sample both sides still measure the same functional,
    /// and a gap removes the windows that span it; on even stamps taken as stamps the operator is
    /// the evenly spaced one.
    #[test]
    fn stamped_samples_give_the_same_functional() {
        let f = |t: f64| (2.1 * t).sin() + 0.3 * (7.0 * t + 0.4).cos();
        let df = |t: f64| 2.1 * (2.1 * t).cos() - 2.1 * (7.0 * t + 0.4).sin();
        let mut time: Vec<f64> = (0..600)
            .map(|k| k as f64 * 0.01 + 0.002 * (k as f64 * 2.399).sin())
            .collect();
        time.remove(200);
        // A gap of 0.1 s after sample 400.
        for t in &mut time[401..] {
            *t += 0.1;
        }
        let sampling = Sampling::new(&time);
        assert_eq!(sampling.gaps(), vec![400]);
        let form = TestFunction::default().on(&sampling).unwrap();
        assert_eq!(form.half, 20);
        assert!(form.centres.iter().all(|&k| {
            let t = time[k];
            !(t - 0.2 < time[401] && t + 0.2 > time[400])
        }));
        assert!(form.centres.len() > 500);
        let x: Vec<f64> = time.iter().map(|&t| f(t)).collect();
        let substeps = 10;
        let slopes: Vec<f64> = time
            .windows(2)
            .flat_map(|w| {
                let h = (w[1] - w[0]) / substeps as f64;
                (0..substeps).map(move |s| df(w[0] + (s as f64 + 0.5) * h))
            })
            .collect();
        let target = form.target(&x);
        let model = form.integrate(&slopes, substeps);
        let worst = target
            .iter()
            .zip(&model)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        // The trapezoid alone on these stamps: 1.8e-3.
        assert!(worst < 1e-4, "{worst}");
        let rows: Vec<[f64; 3]> = x.iter().map(|&v| [v, 2.0 * v, 1.0]).collect();
        let means = form.integrate_rows(&rows);
        assert!(means.iter().all(|m| (m[2] - 1.0).abs() < 1e-12));
        // Even stamps with a gap: the windows away from it are those of the fixed step.
        let mut time: Vec<f64> = (0..100).map(|k| k as f64 * 0.02).collect();
        time.extend((0..100).map(|k| 3.0 + k as f64 * 0.02));
        let stamped = TestFunction::default().on(&Sampling::new(&time)).unwrap();
        let uniform = TestFunction::default().on(&even(0.02, 100)).unwrap();
        let x: Vec<f64> = time.iter().map(|&t| f(t)).collect();
        let (a, b) = (stamped.target(&x), uniform.target(&x[..100]));
        assert_eq!(a.len(), 2 * b.len());
        for (u, v) in a.iter().zip(&b) {
            assert!((u - v).abs() < 1e-4, "{u} vs {v}");
        }
        let gains = (stamped.target_noise_gain(), uniform.target_noise_gain());
        assert!((gains.0 / gains.1 - 1.0).abs() < 1e-2, "{gains:?}");
    }

    /// Channels integrated together are each the channel integrated alone, bit for bit, on even
    /// and on jittered stamps.
    #[test]
    fn channels_integrated_together_equal_each_alone() {
        let jittered: Vec<f64> = (0..400)
            .map(|k| k as f64 * 0.02 + 0.005 * (k as f64 * 1.7).sin())
            .collect();
        for sampling in [even(0.02, 400), Sampling::new(&jittered)] {
            let form = TestFunction::default().on(&sampling).unwrap();
            let substeps = 10;
            let points: Vec<[f64; 3]> = (0..399 * substeps)
                .map(|i| {
                    let t = i as f64 * 1e-3;
                    [(3.1 * t).sin(), -0.0, 1e-3 * (t * 40.0).cos() + 7.0]
                })
                .collect();
            let together = form.integrate_channels(&points, substeps);
            for c in 0..3 {
                let alone: Vec<f64> = points.iter().map(|p| p[c]).collect();
                let alone = form.integrate(&alone, substeps);
                assert_eq!(alone.len(), together.len());
                for (a, t) in alone.iter().zip(&together) {
                    assert_eq!(a.to_bits(), t[c].to_bits());
                }
            }
        }
    }

    /// Both sides of the weak form agree on a smooth signal with content up to a few Hz, and the
    /// model side integrates a sampled acceleration to the same value.
    #[test]
    fn both_sides_measure_the_same_functional() {
        let dt = 0.02;
        let n = 300;
        let form = TestFunction::default().on(&even(dt, n)).unwrap();
        assert_eq!(form.half, 10);
        let f = |t: f64| (2.1 * t).sin() + 0.3 * (17.0 * t + 0.4).cos() + 0.05 * t * t;
        let df = |t: f64| 2.1 * (2.1 * t).cos() - 0.3 * 17.0 * (17.0 * t + 0.4).sin() + 0.1 * t;
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
        let short = TestFunction::default().on(&even(dt, 50)).unwrap();
        let ramp: Vec<f64> = (0..50).map(|k| 3.0 + k as f64 * dt).collect();
        assert!(short.target(&ramp).iter().all(|v| (v - 1.0).abs() < 1e-12));
        let constant = vec![2.5; 10 * 49];
        assert!(
            short
                .integrate(&constant, 10)
                .iter()
                .all(|v| (v - 2.5).abs() < 1e-12)
        );
        assert!(form.target_noise_gain() > 0.0 && form.model_noise_gain() > 0.0);
    }

    #[test]
    fn a_support_of_too_few_samples_is_refused() {
        assert!(TestFunction::default().on(&even(0.1, 100)).is_err());
        assert!(TestFunction::default().on(&even(f64::NAN, 100)).is_err());
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
