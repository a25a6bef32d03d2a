//! Command jitter: a band-limited random disturbance added to the controller's commands (collective
//! thrust and body torques), as a real controller's commands wander within its bandwidth (setpoint
//! noise, estimator corrections). The logged commands include it, so it is not an unmodelled effect:
//! it only enriches what the recording contains.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::error::readable;

/// Sinusoids summed per channel.
const COMPONENTS: usize = 16;

/// Settings of the jitter (per unit mass and per unit inertia).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Jitter {
    /// RMS of the collective-thrust jitter divided by the mass, m/s².
    pub translational_m_s2: f64,
    /// RMS of each body-torque jitter divided by that axis's inertia, rad/s².
    pub angular_rad_s2: f64,
    /// Lowest and highest frequency, Hz.
    pub band_hz: [f64; 2],
}

/// The largest jitter accepted (RMS, m/s² and rad/s²).
pub const MAX_JITTER: f64 = 50.0;

impl Jitter {
    /// Checks the settings; the error names the field (without the `jitter.` prefix).
    pub fn validate(&self) -> Result<(), (String, String)> {
        for (name, value) in [
            ("translational_m_s2", self.translational_m_s2),
            ("angular_rad_s2", self.angular_rad_s2),
        ] {
            if !(value.is_finite() && (0.0..=MAX_JITTER).contains(&value)) {
                return Err((
                    name.into(),
                    format!(
                        "an RMS, must be between 0 and {MAX_JITTER}, found {}",
                        readable(value)
                    ),
                ));
            }
        }
        let [low, high] = self.band_hz;
        if !(low.is_finite() && high.is_finite() && low > 0.0 && high >= low && high <= 1000.0) {
            return Err((
                "band_hz".into(),
                format!(
                    "must be [low, high] with 0 < low ≤ high ≤ 1000 Hz, found [{}, {}]",
                    readable(low),
                    readable(high)
                ),
            ));
        }
        Ok(())
    }
}

/// The jitter as functions of time: `[thrust / m, τx / Jx, τy / Jy, τz / Jz]`.
#[derive(Clone, Debug)]
pub struct JitterSignal {
    /// Per channel: (amplitude, angular frequency, phase) of each component.
    components: [Vec<(f64, f64, f64)>; 4],
}

impl JitterSignal {
    /// Draws the components from `seed`.
    pub fn new(jitter: &Jitter, seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut channel = |rms: f64| -> Vec<(f64, f64, f64)> {
            let amplitude = rms * (2.0 / COMPONENTS as f64).sqrt();
            (0..COMPONENTS)
                .map(|_| {
                    let [low, high] = jitter.band_hz;
                    let f = low + (high - low) * rng.random::<f64>();
                    let phase = 2.0 * std::f64::consts::PI * rng.random::<f64>();
                    (amplitude, 2.0 * std::f64::consts::PI * f, phase)
                })
                .collect()
        };
        let translational = channel(jitter.translational_m_s2);
        Self {
            components: [
                translational,
                channel(jitter.angular_rad_s2),
                channel(jitter.angular_rad_s2),
                channel(jitter.angular_rad_s2),
            ],
        }
    }

    /// The four channels at time `t`.
    pub fn at(&self, t: f64) -> [f64; 4] {
        self.components.each_ref().map(|components| {
            components
                .iter()
                .map(|(a, omega, phase)| a * (omega * t + phase).sin())
                .sum()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_signal_has_the_asked_rms_and_band() {
        let jitter = Jitter {
            translational_m_s2: 0.5,
            angular_rad_s2: 2.0,
            band_hz: [1.0, 5.0],
        };
        jitter.validate().unwrap();
        let signal = JitterSignal::new(&jitter, 3);
        let n = 200_000;
        let dt = 0.001;
        let mut squares = [0.0; 4];
        for k in 0..n {
            let v = signal.at(k as f64 * dt);
            for i in 0..4 {
                squares[i] += v[i] * v[i];
            }
        }
        let rms: Vec<f64> = squares.iter().map(|s| (s / n as f64).sqrt()).collect();
        assert!((rms[0] / 0.5 - 1.0).abs() < 0.1, "{rms:?}");
        assert!((rms[2] / 2.0 - 1.0).abs() < 0.1, "{rms:?}");
        let bad = Jitter {
            band_hz: [5.0, 1.0],
            ..jitter
        };
        assert_eq!(bad.validate().unwrap_err().0, "band_hz");
    }
}
