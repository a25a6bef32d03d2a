//! Geometric tracking controller on SE(3) (Lee, Leok and McClamroch, 2010) with integral action on
//! the position and attitude errors. It knows only the nominal model (mass, inertia).

use serde::{Deserialize, Serialize};

use crate::model::NominalModel;
use crate::trajectory::Reference;
use crate::vector::{
    E3, Mat3, Vec3, add, column, cross, dot, hadamard, mat_mul, mat_vec, norm, scale, sub,
    transpose, vee,
};

/// Gains per unit mass (translational) and per unit inertia (rotational).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Gains {
    /// 1/s².
    pub position: f64,
    /// 1/s.
    pub velocity: f64,
    /// 1/s³.
    pub position_integral: f64,
    /// 1/s².
    pub attitude: f64,
    /// 1/s.
    pub rate: f64,
    /// 1/s³.
    pub attitude_integral: f64,
    /// Bound on each integral state (m·s and rad·s).
    pub integral_limit: f64,
}

impl Default for Gains {
    fn default() -> Self {
        Self {
            position: 6.0,
            velocity: 4.2,
            position_integral: 3.0,
            attitude: 144.0,
            rate: 16.8,
            attitude_integral: 150.0,
            integral_limit: 2.0,
        }
    }
}

impl Gains {
    /// Checks every gain; the error names the field (`position`, …). The proportional and
    /// derivative gains must be positive (without them the loop cannot be stable), the integral
    /// gains and the integral limit non-negative (0 switches the integral action off); all finite.
    pub fn validate(&self) -> Result<(), (String, String)> {
        let positive = [
            ("position", self.position),
            ("velocity", self.velocity),
            ("attitude", self.attitude),
            ("rate", self.rate),
        ];
        for (name, value) in positive {
            if !(value.is_finite() && value > 0.0) {
                return Err((
                    name.to_string(),
                    format!(
                        "must be a finite positive number, found {}",
                        crate::error::readable(value)
                    ),
                ));
            }
        }
        let non_negative = [
            ("position_integral", self.position_integral),
            ("attitude_integral", self.attitude_integral),
            ("integral_limit", self.integral_limit),
        ];
        for (name, value) in non_negative {
            if !(value.is_finite() && value >= 0.0) {
                return Err((
                    name.to_string(),
                    format!(
                        "must be a finite number ≥ 0, found {}",
                        crate::error::readable(value)
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// The state the controller sees (measured, possibly noisy).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeasuredState {
    pub position: Vec3,
    pub velocity: Vec3,
    pub rotation: Mat3,
    /// Body rate, rad/s.
    pub body_rate: Vec3,
}

/// What the controller asks for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControlOutput {
    /// Collective thrust, N.
    pub thrust: f64,
    /// Body torques, N·m.
    pub torque: Vec3,
    /// The attitude it steers towards (body to world).
    pub desired_rotation: Mat3,
}

/// The controller with its integral states.
#[derive(Clone, Debug)]
pub struct GeometricController {
    gains: Gains,
    mass: f64,
    gravity: f64,
    inertia: Vec3,
    position_integral: Vec3,
    attitude_integral: Vec3,
    /// The feed-forward attitude of the previous step (for the desired body rate).
    previous_feedforward: Option<Mat3>,
}

impl GeometricController {
    pub fn new(model: &NominalModel, gains: Gains) -> Self {
        Self {
            gains,
            mass: model.mass_kg,
            gravity: model.gravity_m_s2,
            inertia: model.inertia_kg_m2,
            position_integral: [0.0; 3],
            attitude_integral: [0.0; 3],
            previous_feedforward: None,
        }
    }

    /// The attitude that points the thrust along `force` with heading `yaw`.
    pub fn desired_rotation(force: Vec3, yaw: f64) -> Mat3 {
        let b3 = scale(force, 1.0 / norm(force).max(1e-9));
        let heading = [yaw.cos(), yaw.sin(), 0.0];
        let b2_raw = cross(b3, heading);
        let b2 = scale(b2_raw, 1.0 / norm(b2_raw).max(1e-9));
        let b1 = cross(b2, b3);
        [
            [b1[0], b2[0], b3[0]],
            [b1[1], b2[1], b3[1]],
            [b1[2], b2[2], b3[2]],
        ]
    }

    /// The force the position loop asks for, world frame (N).
    fn desired_force(&self, state: &MeasuredState, reference: &Reference) -> Vec3 {
        let g = &self.gains;
        let position_error = sub(state.position, reference.position);
        let velocity_error = sub(state.velocity, reference.velocity);
        let feedback = add(
            add(
                scale(position_error, -g.position),
                scale(velocity_error, -g.velocity),
            ),
            scale(self.position_integral, -g.position_integral),
        );
        scale(
            add(
                add(feedback, reference.acceleration),
                scale(E3, self.gravity),
            ),
            self.mass,
        )
    }

    /// The feed-forward command for a vehicle exactly on the reference (used to start a flight).
    pub fn initial_rotation(&self, reference: &Reference) -> Mat3 {
        let force = scale(
            add(reference.acceleration, scale(E3, self.gravity)),
            self.mass,
        );
        Self::desired_rotation(force, reference.yaw)
    }

    /// One control step of length `dt` (s).
    pub fn update(
        &mut self,
        state: &MeasuredState,
        reference: &Reference,
        dt: f64,
    ) -> ControlOutput {
        let g = self.gains;
        let position_error = sub(state.position, reference.position);
        self.position_integral = clamp(
            add(self.position_integral, scale(position_error, dt)),
            g.integral_limit,
        );
        let force = self.desired_force(state, reference);
        let rotation = &state.rotation;
        let thrust = dot(force, column(rotation, 2)).max(0.0);
        let desired = Self::desired_rotation(force, reference.yaw);
        let attitude_error = scale(
            vee(&mat_sub(
                &mat_mul(&transpose(&desired), rotation),
                &mat_mul(&transpose(rotation), &desired),
            )),
            0.5,
        );
        self.attitude_integral = clamp(
            add(self.attitude_integral, scale(attitude_error, dt)),
            g.integral_limit,
        );
        // Desired body rate from the reference alone (noise-free): backward difference of the
        // feed-forward attitude, expressed in the current body frame.
        let feedforward = self.initial_rotation(reference);
        let desired_rate = match self.previous_feedforward {
            Some(previous) => scale(vee(&mat_mul(&transpose(&previous), &feedforward)), 1.0 / dt),
            None => [0.0; 3],
        };
        self.previous_feedforward = Some(feedforward);
        let rate = state.body_rate;
        let rate_error = sub(
            rate,
            mat_vec(&mat_mul(&transpose(rotation), &desired), desired_rate),
        );
        let angular = add(
            add(
                scale(attitude_error, -g.attitude),
                scale(rate_error, -g.rate),
            ),
            scale(self.attitude_integral, -g.attitude_integral),
        );
        let torque = add(
            hadamard(self.inertia, angular),
            cross(rate, hadamard(self.inertia, rate)),
        );
        ControlOutput {
            thrust,
            torque,
            desired_rotation: desired,
        }
    }
}

fn clamp(v: Vec3, limit: f64) -> Vec3 {
    v.map(|x| x.clamp(-limit, limit))
}

fn mat_sub(a: &Mat3, b: &Mat3) -> Mat3 {
    let mut out = *a;
    for i in 0..3 {
        for j in 0..3 {
            out[i][j] -= b[i][j];
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gains_are_checked_for_sign_and_finiteness() {
        assert!(Gains::default().validate().is_ok());
        let off = Gains {
            position_integral: 0.0,
            attitude_integral: 0.0,
            integral_limit: 0.0,
            ..Gains::default()
        };
        assert!(off.validate().is_ok());
        let negative_limit = Gains {
            integral_limit: -1.0,
            ..Gains::default()
        };
        assert_eq!(negative_limit.validate().unwrap_err().0, "integral_limit");
        let zero_position = Gains {
            position: 0.0,
            ..Gains::default()
        };
        assert_eq!(zero_position.validate().unwrap_err().0, "position");
        let nan_rate = Gains {
            rate: f64::NAN,
            ..Gains::default()
        };
        assert_eq!(nan_rate.validate().unwrap_err().0, "rate");
        let negative_integral = Gains {
            attitude_integral: -150.0,
            ..Gains::default()
        };
        assert_eq!(
            negative_integral.validate().unwrap_err().0,
            "attitude_integral"
        );
    }

    #[test]
    fn desired_rotation_points_thrust_along_the_force_with_the_heading() {
        let force = [1.0, -2.0, 15.0];
        let r = GeometricController::desired_rotation(force, 0.4);
        let b3 = column(&r, 2);
        let unit = scale(force, 1.0 / norm(force));
        for i in 0..3 {
            assert!((b3[i] - unit[i]).abs() < 1e-12);
        }
        let rrt = mat_mul(&r, &transpose(&r));
        for i in 0..3 {
            for j in 0..3 {
                assert!((rrt[i][j] - if i == j { 1.0 } else { 0.0 }).abs() < 1e-12);
            }
        }
        // heading: b1 is the heading projected onto the plane normal to the thrust
        let heading = [0.4f64.cos(), 0.4f64.sin(), 0.0];
        assert!(dot(column(&r, 1), heading).abs() < 1e-12);
        assert!(dot(column(&r, 0), heading) > 0.9);
    }
}
