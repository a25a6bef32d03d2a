//! Differentiation: derivative estimators on sampled signals (PySINDy's
//! `differentiation` module), the targets ẋ that SINDy regresses on.
//!
//! - forward difference: `(x[k+1] − x[k]) / dt`, the last sample backward `(x[n−1] − x[n−2]) / dt`;
//!   first order, error `dt/2·|x''|`. The paper's SINDy target.
//! - central difference: `(x[k+1] − x[k−1]) / (2 dt)`, second order (error `dt²/6·|x'''|`), with
//!   second-order one-sided differences at both ends.
//! - Savitzky–Golay: the derivative of a least-squares polynomial of degree `order` fitted over a
//!   window of `window` (odd) samples centred on each point; near the ends the polynomial fitted to
//!   the first (last) window is evaluated at the point itself (SciPy's `mode="interp"`). The
//!   order is at least 1 (a constant has no derivative) and at most
//!   [`MAX_SAVITZKY_GOLAY_ORDER`]; the window at most [`MAX_SAVITZKY_GOLAY_WINDOW`] samples (the
//!   cost is samples × window) and at most the samples of the signal.

use serde::{Deserialize, Serialize};

/// A derivative estimator that is misconfigured or given too few samples.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DifferentiationError {
    /// A name [`Derivative::parse`] does not know.
    #[error("unknown derivative '{0}' (known: forward, central, savgol, savgol:WINDOW:ORDER)")]
    UnknownName(String),
    /// A Savitzky–Golay window that is even, too short, or not longer than the order.
    #[error(
        "Savitzky-Golay derivative: window {window} must be odd, at least 3 and larger than the \
         order {order}"
    )]
    BadWindow { window: usize, order: usize },
    /// Samples whose spacing is not uniform, given to an estimator that needs a uniform grid.
    #[error(
        "derivative: sample {sample} is {step} s after the one before, the mean step is {mean} s: \
         the {estimator} estimator needs uniform samples (forward and central differences use \
         the true time stamps)"
    )]
    NonUniformTime {
        sample: usize,
        step: f64,
        mean: f64,
        estimator: Derivative,
    },
    /// A Savitzky–Golay order of 0: the polynomial is a constant, whose derivative is 0.
    #[error(
        "Savitzky-Golay derivative: order 0 fits a constant, whose derivative is 0 whatever the \
         data: the order must be at least 1"
    )]
    ZeroOrder,
    /// A Savitzky–Golay order whose polynomial the double-precision fit cannot resolve.
    #[error(
        "Savitzky-Golay derivative: order {order} is above {MAX_SAVITZKY_GOLAY_ORDER}, the highest \
         whose weights double precision computes accurately"
    )]
    OrderTooHigh { order: usize },
    /// A Savitzky–Golay window longer than the bound on its cost.
    #[error(
        "Savitzky-Golay derivative: window {window} is longer than {MAX_SAVITZKY_GOLAY_WINDOW} \
         samples (the cost grows with samples × window)"
    )]
    WindowTooLong { window: usize },
    /// A signal shorter than the estimator's stencil.
    #[error("derivative: {samples} samples, the {estimator} estimator needs at least {needed}")]
    TooFewSamples {
        samples: usize,
        estimator: Derivative,
        needed: usize,
    },
}

type Result<T> = std::result::Result<T, DifferentiationError>;

/// The longest Savitzky–Golay window: its cost is samples × window per signal, plus window² ×
/// order² for the end weights.
pub const MAX_SAVITZKY_GOLAY_WINDOW: usize = 1001;

/// The highest Savitzky–Golay order: up to it, the weights from the normal equations give the
/// derivative of a line to 1e-8 (relative) in every window up to [`MAX_SAVITZKY_GOLAY_WINDOW`]
/// (measured: 9e-9 at order 10, 1e-8 at 12, 3e-6 at 14, as the monomials' Gram matrix loses
/// its conditioning).
pub const MAX_SAVITZKY_GOLAY_ORDER: usize = 10;

/// How a derivative is estimated from samples.
///
/// JSON: `{"kind": "forward"}`, `{"kind": "central"}` or
/// `{"kind": "savitzky_golay", "window": 21, "order": 3}`; any other field is an error (also next
/// to `forward` and `central`, which serde would otherwise ignore in a unit variant).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", from = "DerivativeFields")]
pub enum Derivative {
    Forward,
    Central,
    SavitzkyGolay { window: usize, order: usize },
}

/// What a [`Derivative`] is read from: the same JSON, every variant a struct variant, so that
/// `deny_unknown_fields` applies to all of them.
#[derive(Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
enum DerivativeFields {
    Forward {},
    Central {},
    SavitzkyGolay { window: usize, order: usize },
}

impl From<DerivativeFields> for Derivative {
    fn from(fields: DerivativeFields) -> Self {
        match fields {
            DerivativeFields::Forward {} => Self::Forward,
            DerivativeFields::Central {} => Self::Central,
            DerivativeFields::SavitzkyGolay { window, order } => {
                Self::SavitzkyGolay { window, order }
            }
        }
    }
}

impl Derivative {
    /// The Savitzky–Golay estimator used for "smoothed derivative" references (window 21, cubic).
    pub const SMOOTH: Derivative = Derivative::SavitzkyGolay {
        window: 21,
        order: 3,
    };

    /// Parses `forward`, `central`, `savgol` (window 21, order 3) or `savgol:W:O`.
    pub fn parse(text: &str) -> Result<Self> {
        let unknown = || DifferentiationError::UnknownName(text.to_string());
        match text {
            "forward" => Ok(Self::Forward),
            "central" => Ok(Self::Central),
            "savgol" => Ok(Self::SMOOTH),
            other => {
                let rest = other.strip_prefix("savgol:").ok_or_else(unknown)?;
                let (w, o) = rest.split_once(':').ok_or_else(unknown)?;
                let window = w.parse().map_err(|_| unknown())?;
                let order = o.parse().map_err(|_| unknown())?;
                let estimator = Self::SavitzkyGolay { window, order };
                estimator.validate()?;
                Ok(estimator)
            }
        }
    }

    /// Checks the settings: a Savitzky–Golay order from 1 to [`MAX_SAVITZKY_GOLAY_ORDER`], its
    /// window odd, larger than the order and at most [`MAX_SAVITZKY_GOLAY_WINDOW`].
    pub fn validate(&self) -> Result<()> {
        let Self::SavitzkyGolay { window, order } = *self else {
            return Ok(());
        };
        if order == 0 {
            return Err(DifferentiationError::ZeroOrder);
        }
        if window % 2 == 0 || window <= order || window < 3 {
            return Err(DifferentiationError::BadWindow { window, order });
        }
        if order > MAX_SAVITZKY_GOLAY_ORDER {
            return Err(DifferentiationError::OrderTooHigh { order });
        }
        if window > MAX_SAVITZKY_GOLAY_WINDOW {
            return Err(DifferentiationError::WindowTooLong { window });
        }
        Ok(())
    }

    /// Minimum number of samples the estimator needs.
    pub fn min_samples(&self) -> usize {
        match *self {
            Self::Forward => 2,
            Self::Central => 3,
            Self::SavitzkyGolay { window, .. } => window,
        }
    }

    /// Estimates the derivative of `x` sampled every `dt` seconds.
    ///
    /// ```
    /// use sindy::Derivative;
    /// let x: Vec<f64> = (0..20).map(|k| (k as f64 * 0.1).powi(2)).collect();
    /// let dx = Derivative::Central.apply(&x, 0.1)?;
    /// assert!((dx[10] - 2.0).abs() < 1e-12); // d(t²)/dt at t = 1
    /// # Ok::<(), sindy::DifferentiationError>(())
    /// ```
    pub fn apply(&self, x: &[f64], dt: f64) -> Result<Vec<f64>> {
        self.validate()?;
        if x.len() < self.min_samples() {
            return Err(DifferentiationError::TooFewSamples {
                samples: x.len(),
                estimator: *self,
                needed: self.min_samples(),
            });
        }
        Ok(match *self {
            Self::Forward => forward(x, dt),
            Self::Central => central(x, dt),
            Self::SavitzkyGolay { window, order } => savitzky_golay(x, dt, window, order),
        })
    }

    /// Estimates the derivative of `x` sampled at the strictly increasing times `time`.
    ///
    /// Forward differences divide by each sample's own step, and central differences are the
    /// second-order three-point formulas of a non-uniform grid (NumPy's `gradient` with
    /// `edge_order=2`); on a grid uniform to rounding ([`UNIFORM_STEP_TOLERANCE`]) both are
    /// [`Derivative::apply`] with the mean step. Savitzky–Golay weights assume a uniform grid: it
    /// uses the mean step when every step is within [`SAVITZKY_GOLAY_STEP_TOLERANCE`] of it and
    /// is refused beyond, naming the first sample off the grid ([`Derivative::check_times`]).
    ///
    /// ```
    /// use sindy::Derivative;
    /// let time = [0.0, 0.1, 0.25, 0.3, 0.5, 0.55];
    /// let x: Vec<f64> = time.iter().map(|t| t * t).collect();
    /// let dx = Derivative::Central.apply_at_times(&x, &time)?;
    /// assert!(dx.iter().zip(&time).all(|(d, t)| (d - 2.0 * t).abs() < 1e-12)); // exact on t²
    /// # Ok::<(), sindy::DifferentiationError>(())
    /// ```
    pub fn apply_at_times(&self, x: &[f64], time: &[f64]) -> Result<Vec<f64>> {
        let n = x.len().min(time.len());
        let (x, time) = (&x[..n], &time[..n]);
        self.check_times(time)?;
        let mean = (time[n - 1] - time[0]) / (n - 1) as f64;
        if first_off_grid(time, UNIFORM_STEP_TOLERANCE).is_none() {
            return self.apply(x, mean);
        }
        Ok(match *self {
            Self::Forward => forward_at_times(x, time),
            Self::Central => central_at_times(x, time),
            Self::SavitzkyGolay { .. } => self.apply(x, mean)?,
        })
    }

    /// Whether the estimator can be applied at the times `time`: enough samples and, for
    /// Savitzky–Golay, every step within [`SAVITZKY_GOLAY_STEP_TOLERANCE`] of the mean step.
    pub fn check_times(&self, time: &[f64]) -> Result<()> {
        let n = time.len();
        if n < self.min_samples() {
            return Err(DifferentiationError::TooFewSamples {
                samples: n,
                estimator: *self,
                needed: self.min_samples(),
            });
        }
        if let Self::SavitzkyGolay { .. } = self
            && let Some(sample) = first_off_grid(time, SAVITZKY_GOLAY_STEP_TOLERANCE)
        {
            return Err(DifferentiationError::NonUniformTime {
                sample,
                step: time[sample] - time[sample - 1],
                mean: (time[n - 1] - time[0]) / (n - 1) as f64,
                estimator: *self,
            });
        }
        Ok(())
    }

    /// [`Derivative::apply_at_times`] to each column of `x` (one row per sample).
    pub fn apply_columns_at_times(
        &self,
        x: faer::MatRef<'_, f64>,
        time: &[f64],
    ) -> Result<faer::Mat<f64>> {
        columnwise(x, |column| self.apply_at_times(column, time))
    }

    /// [`Derivative::apply`] to each column of `x` (one row per sample, sampled every `dt`).
    pub fn apply_columns(&self, x: faer::MatRef<'_, f64>, dt: f64) -> Result<faer::Mat<f64>> {
        columnwise(x, |column| self.apply(column, dt))
    }
}

/// `derivative` of each column of `x`, as the columns of a matrix of the same shape.
fn columnwise(
    x: faer::MatRef<'_, f64>,
    derivative: impl Fn(&[f64]) -> Result<Vec<f64>>,
) -> Result<faer::Mat<f64>> {
    let mut derivatives = faer::Mat::zeros(x.nrows(), x.ncols());
    for j in 0..x.ncols() {
        let column: Vec<f64> = x.col(j).iter().copied().collect();
        for (i, value) in derivative(&column)?.into_iter().enumerate() {
            derivatives[(i, j)] = value;
        }
    }
    Ok(derivatives)
}

impl std::fmt::Display for Derivative {
    /// The form [`Derivative::parse`] reads: `forward`, `central` or `savgol:W:O`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Forward => write!(f, "forward"),
            Self::Central => write!(f, "central"),
            Self::SavitzkyGolay { window, order } => write!(f, "savgol:{window}:{order}"),
        }
    }
}

fn forward(x: &[f64], dt: f64) -> Vec<f64> {
    let n = x.len();
    let mut d: Vec<f64> = x.windows(2).map(|w| (w[1] - w[0]) / dt).collect();
    d.push((x[n - 1] - x[n - 2]) / dt);
    d
}

/// Largest relative deviation of a step from the mean step for which forward and central
/// differences use the mean step in [`Derivative::apply_at_times`]: rounding of the time stamps,
/// not jitter (the results are then those of [`Derivative::apply`] bit for bit).
pub const UNIFORM_STEP_TOLERANCE: f64 = 1e-6;

/// Largest relative deviation of a step from the mean step that Savitzky–Golay accepts (and
/// ignores, using the mean step): time stamps printed with a few digits, not a jittering logger.
pub const SAVITZKY_GOLAY_STEP_TOLERANCE: f64 = 0.01;

/// The first sample whose step from the one before deviates from the mean step by more than
/// `tolerance` of it.
fn first_off_grid(time: &[f64], tolerance: f64) -> Option<usize> {
    let n = time.len();
    let mean = (time[n - 1] - time[0]) / (n - 1) as f64;
    (1..n).find(|&k| ((time[k] - time[k - 1]) - mean).abs() > tolerance * mean.abs())
}

fn forward_at_times(x: &[f64], time: &[f64]) -> Vec<f64> {
    let n = x.len();
    let slope = |k: usize| (x[k + 1] - x[k]) / (time[k + 1] - time[k]);
    let mut d: Vec<f64> = (0..n - 1).map(slope).collect();
    d.push(slope(n - 2));
    d
}

/// The derivative at `time[at]` of the parabola through the samples `points` (three indices).
fn parabola_slope(x: &[f64], time: &[f64], points: [usize; 3], at: usize) -> f64 {
    // Lagrange form: the derivative of each basis polynomial at `time[at]`.
    let t = time[at];
    (0..3)
        .map(|i| {
            let (a, b, c) = (points[i], points[(i + 1) % 3], points[(i + 2) % 3]);
            let weight =
                ((t - time[b]) + (t - time[c])) / ((time[a] - time[b]) * (time[a] - time[c]));
            weight * x[a]
        })
        .sum()
}

fn central_at_times(x: &[f64], time: &[f64]) -> Vec<f64> {
    let n = x.len();
    (0..n)
        .map(|k| {
            let centre = k.clamp(1, n - 2);
            parabola_slope(x, time, [centre - 1, centre, centre + 1], k)
        })
        .collect()
}

fn central(x: &[f64], dt: f64) -> Vec<f64> {
    let n = x.len();
    let mut d = vec![0.0; n];
    for k in 1..n - 1 {
        d[k] = (x[k + 1] - x[k - 1]) / (2.0 * dt);
    }
    d[0] = (-3.0 * x[0] + 4.0 * x[1] - x[2]) / (2.0 * dt);
    d[n - 1] = (3.0 * x[n - 1] - 4.0 * x[n - 2] + x[n - 3]) / (2.0 * dt);
    d
}

/// Weights `w` such that `Σ_j w_j x[start + j]` is the derivative, at offset `at` (in samples from
/// `start`), of the degree-`order` least-squares polynomial through `window` samples.
fn savitzky_golay_weights(window: usize, order: usize, at: f64) -> Vec<f64> {
    // Polynomial in s = (j − centre); solve the normal equations (VᵀV) c = Vᵀ e and read the
    // derivative row d/ds [1, s, s², ...] at s = at − centre.
    let centre = (window - 1) as f64 / 2.0;
    let m = order + 1;
    let vandermonde =
        faer::Mat::<f64>::from_fn(window, m, |j, p| (j as f64 - centre).powi(p as i32));
    let s = at - centre;
    let derivative_row = faer::Mat::<f64>::from_fn(m, 1, |p, _| {
        if p == 0 {
            0.0
        } else {
            p as f64 * s.powi(p as i32 - 1)
        }
    });
    // weights = V (VᵀV)⁻¹ d
    let weights = crate::linalg::projection_weights(vandermonde.as_ref(), derivative_row.as_ref());
    (0..window).map(|j| weights[(j, 0)]).collect()
}

fn savitzky_golay(x: &[f64], dt: f64, window: usize, order: usize) -> Vec<f64> {
    let n = x.len();
    let half = window / 2;
    let interior = savitzky_golay_weights(window, order, half as f64);
    let mut d = vec![0.0; n];
    for k in half..n - half {
        d[k] = interior
            .iter()
            .zip(&x[k - half..=k + half])
            .map(|(w, v)| w * v)
            .sum::<f64>()
            / dt;
    }
    for k in 0..half {
        let head = savitzky_golay_weights(window, order, k as f64);
        d[k] = head
            .iter()
            .zip(&x[..window])
            .map(|(w, v)| w * v)
            .sum::<f64>()
            / dt;
        let tail = savitzky_golay_weights(window, order, (window - 1 - k) as f64);
        d[n - 1 - k] = tail
            .iter()
            .zip(&x[n - window..])
            .map(|(w, v)| w * v)
            .sum::<f64>()
            / dt;
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sine(n: usize, dt: f64) -> (Vec<f64>, Vec<f64>) {
        let t: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
        (
            t.iter().map(|t| (1.3 * t).sin()).collect(),
            t.iter().map(|t| 1.3 * (1.3 * t).cos()).collect(),
        )
    }

    fn max_error(a: &[f64], b: &[f64]) -> f64 {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn forward_difference_is_first_order() {
        let dt = 0.02;
        let (x, dx) = sine(500, dt);
        let d = Derivative::Forward.apply(&x, dt).unwrap();
        // |error| ≤ dt/2·max|x''| (interior) and dt·max|x''| at the backward last sample.
        let bound = dt * 1.3 * 1.3;
        assert!(max_error(&d, &dx) <= bound, "{}", max_error(&d, &dx));
        let halved = Derivative::Forward
            .apply(&sine(1000, dt / 2.0).0, dt / 2.0)
            .unwrap();
        let ratio = max_error(&d[..450], &dx[..450])
            / max_error(&halved[..900], &sine(1000, dt / 2.0).1[..900]);
        assert!(
            (ratio - 2.0).abs() < 0.1,
            "first order: error halves with dt ({ratio})"
        );
    }

    #[test]
    fn central_difference_is_second_order() {
        let dt = 0.02;
        let (x, dx) = sine(500, dt);
        let d = Derivative::Central.apply(&x, dt).unwrap();
        let interior = max_error(&d[1..499], &dx[1..499]);
        assert!(
            interior <= dt * dt / 6.0 * 1.3f64.powi(3) * 1.01,
            "{interior}"
        );
        // one-sided ends are second order too: error ≤ dt²/3·max|x'''|
        assert!(max_error(&d, &dx) <= dt * dt / 3.0 * 1.3f64.powi(3) * 1.01);
    }

    #[test]
    fn savitzky_golay_is_exact_on_polynomials_and_smooths_noise() {
        let dt = 0.02;
        let x: Vec<f64> = (0..200)
            .map(|k| {
                let t = k as f64 * dt;
                1.0 + 2.0 * t - 0.5 * t * t + 0.25 * t * t * t
            })
            .collect();
        let exact: Vec<f64> = (0..200)
            .map(|k| {
                let t = k as f64 * dt;
                2.0 - t + 0.75 * t * t
            })
            .collect();
        let d = Derivative::SMOOTH.apply(&x, dt).unwrap();
        assert!(max_error(&d, &exact) < 1e-8, "{}", max_error(&d, &exact));

        // On a noisy sine, the smoothed derivative is far closer to the truth than differences.
        let (clean, dx) = sine(1000, dt);
        let mut state = 12345u64;
        let noisy: Vec<f64> = clean
            .iter()
            .map(|v| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                v + 1e-3 * (((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5)
            })
            .collect();
        let smooth = Derivative::SMOOTH.apply(&noisy, dt).unwrap();
        let central = Derivative::Central.apply(&noisy, dt).unwrap();
        let rms = |d: &[f64]| {
            (d.iter().zip(&dx).map(|(a, b)| (a - b).powi(2)).sum::<f64>() / d.len() as f64).sqrt()
        };
        assert!(
            rms(&smooth) < 0.3 * rms(&central),
            "{} vs {}",
            rms(&smooth),
            rms(&central)
        );
    }

    #[test]
    fn parses_names_and_rejects_bad_windows() {
        assert_eq!(Derivative::parse("forward").unwrap(), Derivative::Forward);
        assert_eq!(
            Derivative::parse("savgol:11:2").unwrap(),
            Derivative::SavitzkyGolay {
                window: 11,
                order: 2
            }
        );
        assert!(Derivative::parse("savgol:10:2").is_err());
        assert!(
            Derivative::parse("spline")
                .unwrap_err()
                .to_string()
                .contains("spline")
        );
        assert!(Derivative::Central.apply(&[1.0, 2.0], 0.1).is_err());
    }

    #[test]
    fn unknown_fields_are_errors_in_every_kind() {
        let read = |text: &str| bounded_read::json::from_str::<Derivative>(text);
        assert_eq!(read(r#"{"kind": "forward"}"#).unwrap(), Derivative::Forward);
        assert_eq!(read(r#"{"kind": "central"}"#).unwrap(), Derivative::Central);
        assert_eq!(
            read(r#"{"kind": "savitzky_golay", "window": 21, "order": 3}"#).unwrap(),
            Derivative::SMOOTH
        );
        for text in [
            r#"{"kind": "forward", "window": 5}"#,
            r#"{"kind": "central", "order": 7}"#,
            r#"{"kind": "savitzky_golay", "window": 21, "order": 3, "mode": "interp"}"#,
        ] {
            let message = read(text).unwrap_err().to_string();
            assert!(message.contains("unknown field"), "{text}: {message}");
        }
        // Written as before.
        for derivative in [Derivative::Forward, Derivative::Central, Derivative::SMOOTH] {
            let text = serde_json::to_string(&derivative).unwrap();
            assert_eq!(read(&text).unwrap(), derivative, "{text}");
        }
        assert_eq!(
            serde_json::to_string(&Derivative::Forward).unwrap(),
            r#"{"kind":"forward"}"#
        );
    }

    #[test]
    fn too_few_samples_name_the_estimator_as_written() {
        let message = Derivative::SavitzkyGolay {
            window: 1001,
            order: 2,
        }
        .apply(&[0.0; 500], 0.01)
        .unwrap_err()
        .to_string();
        assert!(
            message.contains("500 samples, the savgol:1001:2 estimator needs at least 1001"),
            "{message}"
        );
        for text in ["forward", "central", "savgol:11:2"] {
            assert_eq!(Derivative::parse(text).unwrap().to_string(), text);
        }
    }

    /// Every setting `parse` accepts differentiates a line to its slope at every sample (the
    /// ends included); every one it refuses is a one-line message.
    #[test]
    fn every_accepted_savitzky_golay_setting_differentiates_a_line() {
        use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
        let config = Config {
            cases: 96,
            failure_persistence: None,
            ..Config::default()
        };
        let mut runner =
            TestRunner::new_with_rng(config, TestRng::from_seed(RngAlgorithm::ChaCha, &[10; 32]));
        let settings = (0usize..1_200, 0usize..16);
        runner
            .run(&settings, |(window, order)| {
                let text = format!("savgol:{window}:{order}");
                match Derivative::parse(&text) {
                    Ok(derivative) => {
                        let dt = 0.01;
                        let line: Vec<f64> =
                            (0..window + 7).map(|k| 3.0 - 2.0 * k as f64 * dt).collect();
                        let slope = derivative.apply(&line, dt).unwrap();
                        let error = max_error(&slope, &vec![-2.0; slope.len()]);
                        proptest::prop_assert!(error < 2e-8, "{text}: error {error}");
                    }
                    Err(error) => {
                        let message = error.to_string();
                        proptest::prop_assert!(
                            order == 0
                                || order > MAX_SAVITZKY_GOLAY_ORDER
                                || window % 2 == 0
                                || window <= order
                                || window > MAX_SAVITZKY_GOLAY_WINDOW,
                            "{text} refused: {message}"
                        );
                        proptest::prop_assert!(
                            message.starts_with("Savitzky-Golay derivative: ")
                                && !message.contains('\n'),
                            "{message}"
                        );
                    }
                }
                Ok(())
            })
            .unwrap();
    }

    #[test]
    fn order_zero_and_unbounded_windows_are_refused_by_name() {
        let message = |text: &str| Derivative::parse(text).unwrap_err().to_string();
        assert_eq!(
            message("savgol:5:0"),
            "Savitzky-Golay derivative: order 0 fits a constant, whose derivative is 0 whatever \
             the data: the order must be at least 1"
        );
        assert_eq!(
            message("savgol:99999:2"),
            "Savitzky-Golay derivative: window 99999 is longer than 1001 samples (the cost grows \
             with samples × window)"
        );
        assert_eq!(
            message("savgol:31:11"),
            "Savitzky-Golay derivative: order 11 is above 10, the highest whose weights double \
             precision computes accurately"
        );
        let json = r#"{"kind": "savitzky_golay", "window": 5, "order": 0}"#;
        let read: Derivative = bounded_read::json::from_str(json).unwrap();
        assert_eq!(read.validate(), Err(DifferentiationError::ZeroOrder));
    }
}
