//! Reference trajectories: a figure-8 (optionally with a low-altitude pass) and random waypoints
//! joined by minimum-jerk segments. Both give position, velocity, acceleration and yaw analytically.

use rand::{RngExt, SeedableRng};
use serde::{Deserialize, Serialize};

use crate::error::readable;
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
        /// Low-altitude passes (non-overlapping).
        #[serde(default)]
        low_passes: Vec<LowPass>,
        #[serde(default)]
        yaw_amplitude_rad: f64,
        #[serde(default = "default_yaw_period")]
        yaw_period_s: f64,
    },
}

/// Checks low passes: finite, within [`MAX_POSITION_M`], ramps that fit, in time order.
fn validate_low_passes(low_passes: &[LowPass]) -> Result<(), (String, String)> {
    let bad = |field: &str, message: String| Err((format!("trajectory.{field}"), message));
    let too_far = |v: &[f64]| v.iter().copied().find(|x| x.abs() > MAX_POSITION_M);
    let far_message = |x: f64| {
        format!(
            "a coordinate of {} m, farther than the {MAX_POSITION_M} m from the origin a flight may go",
            readable(x)
        )
    };
    for (i, pass) in low_passes.iter().enumerate() {
        let field = format!("low_passes[{i}]");
        let values = [pass.start_s, pass.end_s, pass.height_m, pass.ramp_s];
        if values.iter().any(|v| !v.is_finite()) {
            return bad(&field, "every number must be finite".into());
        }
        if let Some(x) = too_far(&[pass.height_m]) {
            return bad(&format!("{field}.height_m"), far_message(x));
        }
        if !(pass.ramp_s > 0.0 && pass.end_s - pass.start_s >= 2.0 * pass.ramp_s) {
            return bad(
                &field,
                "needs ramp_s > 0 and end_s − start_s ≥ 2 ramp_s".into(),
            );
        }
    }
    for (i, pair) in low_passes.windows(2).enumerate() {
        if pair[1].start_s < pair[0].end_s {
            return bad(
                &format!("low_passes[{}]", i + 1),
                "low passes must be in time order and not overlap".into(),
            );
        }
    }
    Ok(())
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

/// The most waypoints a random-waypoint trajectory may have (each is drawn up front).
pub const MAX_WAYPOINTS: usize = 100_000;

/// The farthest a reference may be from the origin, per coordinate, m (and the largest coordinate
/// of a trajectory's `center`, `first`, `second`, `box_min`, `box_max` and low-pass heights): a
/// kilometre, ten times inside the positions the data tools accept (`data::PLAUSIBLE_RANGES`,
/// ±1e4 m), which leaves room for the tracking error (the simulation stops beyond 20 m) and the
/// measurement noise.
pub const MAX_POSITION_M: f64 = 1000.0;

/// The fastest peak yaw rate `|yaw_amplitude_rad| · 2π / yaw_period_s` accepted, rad/s.
pub const MAX_YAW_RATE_RAD_S: f64 = std::f64::consts::PI;

impl Trajectory {
    /// Checks the settings (finite numbers, positions within [`MAX_POSITION_M`] per coordinate,
    /// positive periods and durations, ordered low passes, at most [`MAX_WAYPOINTS`] waypoints, a
    /// peak yaw rate of at most [`MAX_YAW_RATE_RAD_S`]); the error names the field.
    pub fn validate(&self) -> Result<(), (String, String)> {
        let bad = |field: &str, message: String| Err((format!("trajectory.{field}"), message));
        let finite3 = |v: &Vec3| v.iter().all(|x| x.is_finite());
        let too_far = |v: &[f64]| v.iter().copied().find(|x| x.abs() > MAX_POSITION_M);
        let far_message = |x: f64| {
            format!(
                "a coordinate of {} m, farther than the {MAX_POSITION_M} m from the origin a flight may go",
                readable(x)
            )
        };
        let (yaw_amplitude_rad, yaw_period_s) = match self {
            Self::Figure8 {
                center,
                first,
                second,
                period_s,
                low_passes,
                yaw_amplitude_rad,
                yaw_period_s,
            } => {
                for (name, v) in [("center", center), ("first", first), ("second", second)] {
                    if !finite3(v) {
                        return bad(name, "must be three finite numbers".into());
                    }
                    if let Some(x) = too_far(v) {
                        return bad(name, far_message(x));
                    }
                }
                if !(period_s.is_finite() && *period_s > 0.0) {
                    return bad(
                        "period_s",
                        format!("must be positive, found {}", readable(*period_s)),
                    );
                }
                validate_low_passes(low_passes)?;
                (*yaw_amplitude_rad, *yaw_period_s)
            }
            Self::RandomWaypoints {
                count,
                segment_s,
                box_min,
                box_max,
                low_passes,
                yaw_amplitude_rad,
                yaw_period_s,
                ..
            } => {
                validate_low_passes(low_passes)?;
                if *count < 2 {
                    return bad(
                        "count",
                        format!("needs at least 2 waypoints, found {count}"),
                    );
                }
                if *count > MAX_WAYPOINTS {
                    return bad(
                        "count",
                        format!("at most {MAX_WAYPOINTS} waypoints, found {count}"),
                    );
                }
                if !(segment_s.is_finite() && *segment_s > 0.0) {
                    return bad(
                        "segment_s",
                        format!("must be positive, found {}", readable(*segment_s)),
                    );
                }
                for (name, v) in [("box_min", box_min), ("box_max", box_max)] {
                    if !finite3(v) {
                        return bad(name, "must be three finite numbers".into());
                    }
                    if let Some(x) = too_far(v) {
                        return bad(name, far_message(x));
                    }
                }
                if (0..3).any(|i| box_max[i] < box_min[i]) {
                    return bad("box_max", "must not be below box_min".into());
                }
                (*yaw_amplitude_rad, *yaw_period_s)
            }
        };
        if !yaw_amplitude_rad.is_finite() {
            return bad("yaw_amplitude_rad", "must be a finite number".into());
        }
        if !(yaw_period_s.is_finite() && yaw_period_s > 0.0) {
            return bad(
                "yaw_period_s",
                format!("must be positive, found {}", readable(yaw_period_s)),
            );
        }
        let yaw_rate = yaw_amplitude_rad.abs() * 2.0 * std::f64::consts::PI / yaw_period_s;
        if yaw_rate > MAX_YAW_RATE_RAD_S {
            return bad(
                "yaw_period_s",
                format!(
                    "the peak yaw rate |yaw_amplitude_rad| · 2π / yaw_period_s is {yaw_rate:.3} rad/s, more than the {MAX_YAW_RATE_RAD_S:.3} rad/s (π) allowed"
                ),
            );
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
                apply_low_passes(
                    low_passes,
                    t,
                    &mut position,
                    &mut velocity,
                    &mut acceleration,
                );
                Reference {
                    position,
                    velocity,
                    acceleration,
                    yaw: yaw_at(t, *yaw_amplitude_rad, *yaw_period_s),
                }
            }
            Trajectory::RandomWaypoints {
                segment_s,
                low_passes,
                yaw_amplitude_rad,
                yaw_period_s,
                ..
            } => {
                let mut reference = self.waypoint_reference(t, *segment_s);
                reference.yaw = yaw_at(t, *yaw_amplitude_rad, *yaw_period_s);
                apply_low_passes(
                    low_passes,
                    t,
                    &mut reference.position,
                    &mut reference.velocity,
                    &mut reference.acceleration,
                );
                reference
            }
        }
    }

    /// The minimum-jerk waypoint reference at `t` (yaw 0).
    fn waypoint_reference(&self, t: f64, segment_s: f64) -> Reference {
        {
            {
                let last = self.waypoints.len() - 1;
                let index = ((t / segment_s).floor().max(0.0) as usize).min(last);
                let yaw = 0.0;
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

/// Blends the height of a reference into the low pass under way at `t`, if any.
fn apply_low_passes(
    low_passes: &[LowPass],
    t: f64,
    position: &mut Vec3,
    velocity: &mut Vec3,
    acceleration: &mut Vec3,
) {
    if let Some(pass) = low_passes.iter().find(|p| t < p.end_s) {
        let (b, db, ddb) = low_pass_blend(pass, t);
        let (f, df, ddf) = (position[2], velocity[2], acceleration[2]);
        let h = pass.height_m;
        position[2] = f * (1.0 - b) + b * h;
        velocity[2] = df * (1.0 - b) - f * db + db * h;
        acceleration[2] = ddf * (1.0 - b) - 2.0 * df * db - f * ddb + ddb * h;
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

    fn figure8() -> Trajectory {
        Trajectory::Figure8 {
            center: [0.0, 0.0, 1.5],
            first: [1.5, 0.0, 0.0],
            second: [0.0, 0.8, 0.3],
            period_s: 6.0,
            low_passes: Vec::new(),
            yaw_amplitude_rad: 0.3,
            yaw_period_s: 10.0,
        }
    }

    fn rejected_field(trajectory: Trajectory) -> String {
        trajectory.validate().unwrap_err().0
    }

    #[test]
    fn every_field_is_checked_and_named() {
        assert!(figure8().validate().is_ok());
        let Trajectory::Figure8 {
            center,
            first,
            second,
            period_s,
            low_passes,
            yaw_amplitude_rad,
            yaw_period_s,
        } = figure8()
        else {
            unreachable!()
        };
        let with = |f: &dyn Fn(&mut Trajectory)| {
            let mut t = Trajectory::Figure8 {
                center,
                first,
                second,
                period_s,
                low_passes: low_passes.clone(),
                yaw_amplitude_rad,
                yaw_period_s,
            };
            f(&mut t);
            rejected_field(t)
        };
        let pass = |start_s, end_s, height_m, ramp_s| LowPass {
            start_s,
            end_s,
            height_m,
            ramp_s,
        };
        macro_rules! field_of {
            ($name:ident, $value:expr) => {
                with(&|t| {
                    if let Trajectory::Figure8 { $name, .. } = t {
                        *$name = $value;
                    }
                })
            };
        }
        assert_eq!(field_of!(yaw_period_s, 0.0), "trajectory.yaw_period_s");
        assert_eq!(field_of!(yaw_period_s, -3.0), "trajectory.yaw_period_s");
        assert_eq!(field_of!(yaw_period_s, 0.01), "trajectory.yaw_period_s");
        assert_eq!(
            field_of!(yaw_amplitude_rad, f64::INFINITY),
            "trajectory.yaw_amplitude_rad"
        );
        assert_eq!(field_of!(period_s, 0.0), "trajectory.period_s");
        assert_eq!(field_of!(center, [0.0, f64::NAN, 1.0]), "trajectory.center");
        assert_eq!(
            field_of!(low_passes, vec![pass(1.0, 9.0, f64::NAN, 2.0)]),
            "trajectory.low_passes[0]"
        );
        assert_eq!(
            field_of!(
                low_passes,
                vec![pass(1.0, 9.0, 0.3, 2.0), pass(8.0, 20.0, 0.3, 2.0)]
            ),
            "trajectory.low_passes[1]"
        );
        let waypoints = |count, segment_s, yaw_period_s| Trajectory::RandomWaypoints {
            seed: 1,
            count,
            box_min: [-1.0, -1.0, 1.0],
            box_max: [1.0, 1.0, 2.0],
            segment_s,
            low_passes: Vec::new(),
            yaw_amplitude_rad: 0.5,
            yaw_period_s,
        };
        assert!(waypoints(5, 2.5, 7.0).validate().is_ok());
        assert_eq!(rejected_field(waypoints(1, 2.5, 7.0)), "trajectory.count");
        assert_eq!(
            rejected_field(waypoints(MAX_WAYPOINTS + 1, 2.5, 7.0)),
            "trajectory.count"
        );
        assert_eq!(
            rejected_field(waypoints(5, 0.0, 7.0)),
            "trajectory.segment_s"
        );
        assert_eq!(
            rejected_field(waypoints(5, 2.5, 0.0)),
            "trajectory.yaw_period_s"
        );
    }

    #[test]
    fn random_waypoints_are_reproducible_and_smooth() {
        let trajectory = Trajectory::RandomWaypoints {
            seed: 3,
            count: 5,
            box_min: [-2.0, -2.0, 1.0],
            box_max: [2.0, 2.0, 2.0],
            segment_s: 2.5,
            low_passes: Vec::new(),
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
