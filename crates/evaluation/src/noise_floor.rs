//! How much of a forward-difference target no model of the current sample can explain: an
//! estimate of its noise floor, per segment.
//!
//! The forward difference d[k] = (x[k+1] − x[k])/dt of a measured state x = s + e (white
//! measurement noise e of variance σ²) carries the noise (e[k+1] − e[k])/dt: variance 2σ²/dt², and
//! lag-one autocovariance −σ²/dt². The smooth part is estimated by a Savitzky–Golay derivative
//! (window 21, cubic, 0.4 s at 50 Hz: [`Derivative::SMOOTH`]); the residual r = d − d_SG holds the
//! noise plus any motion faster than that window. Two estimates, both as a mean over samples and
//! state dimensions (the unit of the tables' MSE):
//! - **upper** = mean r²: counts the fast motion as noise, so it bounds the noise from above (a
//!   model that captures fast motion, e.g. through the motor commands, can go below it);
//! - **lower** = max(0, −2·mean r[k]·r[k+1]): the noise's negative lag-one autocovariance (×2 gives
//!   its variance), from which positively correlated fast motion subtracts, so it is a lower bound
//!   for white noise (clipped to [0, upper]).

use faer::MatRef;
use report::NoiseFloor;
use sindy::Derivative;

/// Estimates the noise floor of the forward-difference targets of a segment's `states` (one row
/// per sample, one column per state), sampled every `dt` seconds. Both derivatives are computed
/// from the states (a segment's own targets are not needed).
pub fn forward_difference_noise_floor(
    states: MatRef<'_, f64>,
    dt: f64,
) -> sindy::Result<NoiseFloor> {
    let (n, dims) = (states.nrows(), states.ncols());
    let (mut square, mut lagged, mut pairs) = (0.0, 0.0, 0usize);
    for j in 0..dims {
        let state: Vec<f64> = states.col(j).iter().copied().collect();
        let forward = Derivative::Forward.apply(&state, dt)?;
        let smooth = Derivative::SMOOTH.apply(&state, dt)?;
        let residual: Vec<f64> = forward.iter().zip(&smooth).map(|(f, s)| f - s).collect();
        square += residual.iter().map(|r| r * r).sum::<f64>();
        lagged += residual.windows(2).map(|w| w[0] * w[1]).sum::<f64>();
        pairs += n - 1;
    }
    let upper = square / (n * dims) as f64;
    Ok(NoiseFloor {
        upper,
        lower: (-2.0 * lagged / pairs as f64).clamp(0.0, upper),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Mat;

    /// Three smooth states plus deterministic pseudo-random noise of standard deviation `sigma`.
    fn states(sigma: f64) -> Mat<f64> {
        let n = 4000;
        let dt = 0.02;
        let mut seed = 12345u64;
        let mut noise = || {
            // Sum of 12 uniforms − 6: close to a standard normal.
            (0..12)
                .map(|_| {
                    seed = seed
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    (seed >> 11) as f64 / (1u64 << 53) as f64
                })
                .sum::<f64>()
                - 6.0
        };
        Mat::from_fn(n, 3, |i, j| {
            (0.5 * i as f64 * dt + j as f64).sin() + sigma * noise()
        })
    }

    #[test]
    fn white_noise_lies_between_the_bounds() {
        let (sigma, dt) = (0.01, 0.02);
        let floor = forward_difference_noise_floor(states(sigma).as_ref(), dt).unwrap();
        let exact = 2.0 * sigma * sigma / (dt * dt);
        assert!(floor.lower <= floor.upper);
        assert!(
            floor.upper > 0.8 * exact && floor.upper < 1.2 * exact,
            "{floor:?} vs {exact}"
        );
        assert!(
            floor.lower > 0.7 * exact && floor.lower < 1.3 * exact,
            "{floor:?} vs {exact}"
        );
        let quiet = forward_difference_noise_floor(states(0.0).as_ref(), dt).unwrap();
        assert!(quiet.upper < 1e-3 * exact);
    }
}
