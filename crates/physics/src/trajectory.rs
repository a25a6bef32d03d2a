//! Reference trajectories: a figure-8 (optionally with a low-altitude pass) and random waypoints
//! joined by minimum-jerk segments. Both give position, velocity, acceleration and yaw analytically.

use rand::{RngExt, SeedableRng};
use serde::{Deserialize, Serialize};

use crate::vector::{Vec3, add, scale};

/// Where the vehicle should be at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Reference {
    pub position: Vec3,
    pub velocity: Vec3,
    pub acceleration: Vec3,
    /// Heading, rad.
    pub yaw: f64,
}

/// A stretch of the flight flown at a fixed low height (for ground effect in part of the flight).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LowPass {
    pub start_s: f64,
    pub end_s: f64,
    /// Height of the pass, m (the vertical motion of the pattern is faded out meanwhile).
    pub height_m: f64,
    /// Duration of the descent and of the climb, s.
    pub ramp_s: f64,
}

/// A reference trajectory.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Trajectory {
    /// `p(t) = center + first·sin(ωt) + second·sin(2ωt)`, ω = 2π / period.
    Figure8 {
        center: Vec3,
        first: Vec3,
        second: Vec3,
        period_s: f64,
        /// Low-altitude passes (non-overlapping).
        #[serde(default)]
        low_passes: Vec<LowPass>,
        #[serde(default)]
        yaw_amplitude_rad: f64,
        #[serde(default = "default_yaw_period")]
        yaw_period_s: f64,
    },
    /// `count` waypoints drawn uniformly in a box (from `seed`), each segment a minimum-jerk move of
    /// `segment_s` seconds that starts and ends at rest.
    RandomWaypoints {
        seed: u64,
        count: usize,
        box_min: Vec3,
        box_max: Vec3,
        segment_s: f64,
        #[serde(default)]
        yaw_amplitude_rad: f64,
        #[serde(default = "default_yaw_period")]
        yaw_period_s: f64,
    },
}

fn default_yaw_period() -> f64 {
    10.0
}

/// A trajectory checked and ready to evaluate.
#[derive(Clone, Debug)]
pub struct ReferenceGenerator {
    trajectory: Trajectory,
    waypoints: Vec<Vec3>,
}

impl Trajectory {
    /// Checks the settings; the error names the field.
    pub fn validate(&self) -> Result<(), (String, String)> {
        let bad = |field: &str, message: &str| Err((field.to_string(), message.to_string()));
        match self {
            Self::Figure8 {
                period_s,
                low_passes,
                ..
            } => {
                if !(period_s.is_finite() && *period_s > 0.0) {
                    return bad("trajectory.period_s", "must be positive");
                }
                for pass in low_passes {
                    if !(pass.ramp_s > 0.0 && pass.end_s - pass.start_s >= 2.0 * pass.ramp_s) {
                        return bad(
                            "trajectory.low_passes",
                            "each needs ramp_s > 0 and end_s − start_s ≥ 2 ramp_s",
                        );
                    }
                }
                for pair in low_passes.windows(2) {
                    if pair[1].start_s < pair[0].end_s {
                        return bad(
                            "trajectory.low_passes",
                            "must be in time order and not overlap",
                        );
                    }
                }
            }
            Self::RandomWaypoints {
                count,
                segment_s,
                box_min,
                box_max,
                ..
            } => {
                if *count < 2 {
                    return bad("trajectory.count", "needs at least 2 waypoints");
                }
                if !(segment_s.is_finite() && *segment_s > 0.0) {
                    return bad("trajectory.segment_s", "must be positive");
                }
                if (0..3).any(|i| box_max[i] < box_min[i]) {
                    return bad("trajectory.box_max", "must not be below box_min");
                }
            }
        }
        Ok(())
    }

    /// Prepares the trajectory (draws the waypoints).
    pub fn generator(&self) -> ReferenceGenerator {
        let waypoints = match self {
            Self::RandomWaypoints {
                seed,
                count,
                box_min,
                box_max,
                ..
            } => {
                let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(*seed);
                (0..*count)
                    .map(|_| {
                        let mut p = [0.0; 3];
                        for i in 0..3 {
                            p[i] = box_min[i] + (box_max[i] - box_min[i]) * rng.random::<f64>();
                        }
                        p
                    })
                    .collect()
            }
            Self::Figure8 { .. } => Vec::new(),
        };
        ReferenceGenerator {
            trajectory: self.clone(),
            waypoints,
        }
    }
}

/// Quintic smoothstep on [0, 1] and its first two derivatives.
fn smoothstep(x: f64) -> (f64, f64, f64) {
    if x <= 0.0 {
        return (0.0, 0.0, 0.0);
    }
    if x >= 1.0 {
        return (1.0, 0.0, 0.0);
    }
    (
        x * x * x * (10.0 - 15.0 * x + 6.0 * x * x),
        30.0 * x * x * (1.0 - 2.0 * x + x * x),
        60.0 * x * (1.0 - 3.0 * x + 2.0 * x * x),
    )
}

fn yaw_at(t: f64, amplitude: f64, period: f64) -> f64 {
    amplitude * (2.0 * std::f64::consts::PI * t / period).sin()
}

impl ReferenceGenerator {
    /// The reference at time `t` (s).
    pub fn at(&self, t: f64) -> Reference {
        match &self.trajectory {
            Trajectory::Figure8 {
                center,
                first,
                second,
                period_s,
                low_passes,
                yaw_amplitude_rad,
                yaw_period_s,
            } => {
                let omega = 2.0 * std::f64::consts::PI / period_s;
                let (s1, c1) = (omega * t).sin_cos();
                let (s2, c2) = (2.0 * omega * t).sin_cos();
                let mut position = add(add(*center, scale(*first, s1)), scale(*second, s2));
                let mut velocity = add(scale(*first, omega * c1), scale(*second, 2.0 * omega * c2));
                let mut acceleration = add(
                    scale(*first, -omega * omega * s1),
                    scale(*second, -4.0 * omega * omega * s2),
                );
                if let Some(pass) = low_passes.iter().find(|p| t < p.end_s) {
                    let (b, db, ddb) = low_pass_blend(pass, t);
                    let (f, df, ddf) = (position[2], velocity[2], acceleration[2]);
                    let h = pass.height_m;
                    position[2] = f * (1.0 - b) + b * h;
                    velocity[2] = df * (1.0 - b) - f * db + db * h;
                    acceleration[2] = ddf * (1.0 - b) - 2.0 * df * db - f * ddb + ddb * h;
                }
                Reference {
                    position,
                    velocity,
                    acceleration,
                    yaw: yaw_at(t, *yaw_amplitude_rad, *yaw_period_s),
                }
            }
            Trajectory::RandomWaypoints {
                segment_s,
                yaw_amplitude_rad,
                yaw_period_s,
                ..
            } => {
                let last = self.waypoints.len() - 1;
                let index = ((t / segment_s).floor().max(0.0) as usize).min(last);
                let yaw = yaw_at(t, *yaw_amplitude_rad, *yaw_period_s);
                if index >= last {
                    return Reference {
                        position: self.waypoints[last],
                        velocity: [0.0; 3],
                        acceleration: [0.0; 3],
                        yaw,
                    };
                }
                let (from, to) = (self.waypoints[index], self.waypoints[index + 1]);
                let x = (t - index as f64 * segment_s) / segment_s;
                let (s, ds, dds) = smoothstep(x);
                let delta = crate::vector::sub(to, from);
                Reference {
                    position: add(from, scale(delta, s)),
                    velocity: scale(delta, ds / segment_s),
                    acceleration: scale(delta, dds / (segment_s * segment_s)),
                    yaw,
                }
            }
        }
    }
}

/// Blend weight of the low pass (0 away from it, 1 during it) and its two time derivatives.
fn low_pass_blend(pass: &LowPass, t: f64) -> (f64, f64, f64) {
    let ramp = pass.ramp_s;
    if t < pass.start_s + ramp {
        let (s, ds, dds) = smoothstep((t - pass.start_s) / ramp);
        (s, ds / ramp, dds / (ramp * ramp))
    } else {
        let (s, ds, dds) = smoothstep((t - (pass.end_s - ramp)) / ramp);
        (1.0 - s, -ds / ramp, -dds / (ramp * ramp))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check_derivatives(generator: &ReferenceGenerator, times: &[f64]) {
        let h = 1e-5;
        for &t in times {
            let (a, b, c) = (generator.at(t - h), generator.at(t), generator.at(t + h));
            for i in 0..3 {
                let v = (c.position[i] - a.position[i]) / (2.0 * h);
                let acc = (c.velocity[i] - a.velocity[i]) / (2.0 * h);
                assert!((v - b.velocity[i]).abs() < 1e-6, "velocity at {t}");
                assert!(
                    (acc - b.acceleration[i]).abs() < 1e-5,
                    "acceleration at {t}"
                );
            }
        }
    }

    #[test]
    fn figure8_with_low_pass_has_consistent_derivatives() {
        let trajectory = Trajectory::Figure8 {
            center: [0.0, 0.0, 1.5],
            first: [1.5, 0.0, 0.0],
            second: [0.0, 0.8, 0.3],
            period_s: 6.0,
            low_passes: vec![
                LowPass {
                    start_s: 10.0,
                    end_s: 20.0,
                    height_m: 0.3,
                    ramp_s: 2.0,
                },
                LowPass {
                    start_s: 30.0,
                    end_s: 36.0,
                    height_m: 0.4,
                    ramp_s: 1.5,
                },
            ],
            yaw_amplitude_rad: 0.3,
            yaw_period_s: 10.0,
        };
        assert!(trajectory.validate().is_ok());
        let generator = trajectory.generator();
        check_derivatives(
            &generator,
            &[1.0, 10.7, 11.5, 15.0, 18.3, 19.1, 25.0, 30.5, 35.0],
        );
        assert!((generator.at(33.0).position[2] - 0.4).abs() < 1e-12);
        assert!((generator.at(15.0).position[2] - 0.3).abs() < 1e-12);
    }

    #[test]
    fn random_waypoints_are_reproducible_and_smooth() {
        let trajectory = Trajectory::RandomWaypoints {
            seed: 3,
            count: 5,
            box_min: [-2.0, -2.0, 1.0],
            box_max: [2.0, 2.0, 2.0],
            segment_s: 2.5,
            yaw_amplitude_rad: 0.0,
            yaw_period_s: 10.0,
        };
        let a = trajectory.generator();
        let b = trajectory.generator();
        assert_eq!(a.at(3.3), b.at(3.3));
        check_derivatives(&a, &[0.4, 3.3, 7.1, 9.9]);
        assert_eq!(a.at(100.0).velocity, [0.0; 3]);
    }
}
