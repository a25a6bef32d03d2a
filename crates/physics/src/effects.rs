//! The vocabulary of unmodelled effects, switchable one by one in the simulated plant and used by
//! the mismatch tool to model what it finds. Ids and parameter names are an output contract.
//!
//! | id | parameters | physics (accelerations per unit mass, SI) |
//! |---|---|---|
//! | `linear_drag` | `d: [dx, dy, dz]` | `a = −R diag(d) Rᵀ (v − w_air)` (1/s) |
//! | `quadratic_drag` | `c` | `a = −c |v − w_air| (v − w_air)` (1/m) |
//! | `wind` | `w_air: [x, y, z]` | air velocity (m/s) seen by the drag terms |
//! | `thrust_scale` | `k` | `T_real = k T` |
//! | `motor_lag` | `tau_s` | each actuator follows its command with a first-order lag |
//! | `ground_effect` | `r_m` | `T_real = T / (1 − (r / 4z)²)`, `z` the height above ground |
//! | `torque_bias` | `b: [x, y, z]` | `ω̇ += b` (rad/s²) |
//! | `inertia_scale` | `k: [x, y, z]` | `J_real = diag(k) J` |
//! | `delay` | `delay_s` | the vehicle responds to its commands `delay_s` late |

use serde::{Deserialize, Serialize};

use crate::model::{NominalModel, angular_acceleration_with_inertia};
use crate::vector::{E3, Mat3, Vec3, add, hadamard, mat_t_vec, mat_vec, norm, scale, sub};

/// Every effect id of the vocabulary, in a fixed order.
pub const EFFECT_IDS: [&str; 9] = [
    "linear_drag",
    "quadratic_drag",
    "wind",
    "thrust_scale",
    "motor_lag",
    "ground_effect",
    "torque_bias",
    "inertia_scale",
    "delay",
];

/// The largest `(r / 4z)²` the ground-effect formula is evaluated at (the formula diverges at 1):
/// below `z = r / (4 √0.5)` the thrust gain is held at 2.
pub const GROUND_EFFECT_MAX_RATIO: f64 = 0.5;

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinearDrag {
    pub d: Vec3,
}
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct QuadraticDrag {
    pub c: f64,
}
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Wind {
    pub w_air: Vec3,
}
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ThrustScale {
    pub k: f64,
}
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotorLag {
    pub tau_s: f64,
}
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroundEffect {
    pub r_m: f64,
}
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TorqueBias {
    pub b: Vec3,
}
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InertiaScale {
    pub k: Vec3,
}
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Delay {
    pub delay_s: f64,
}

/// A set of effects; `None` means absent. Serialises as `{"<id>": {<parameters>}, ...}`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Effects {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub linear_drag: Option<LinearDrag>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quadratic_drag: Option<QuadraticDrag>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wind: Option<Wind>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thrust_scale: Option<ThrustScale>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motor_lag: Option<MotorLag>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ground_effect: Option<GroundEffect>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub torque_bias: Option<TorqueBias>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inertia_scale: Option<InertiaScale>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub delay: Option<Delay>,
}

impl Effects {
    /// Checks every parameter's range; the error names the effect and parameter.
    pub fn validate(&self) -> Result<(), (String, String)> {
        let bad = |field: &str, message: &str| Err((field.to_string(), message.to_string()));
        let finite3 = |v: &Vec3| v.iter().all(|x| x.is_finite());
        if let Some(e) = self.linear_drag
            && (!finite3(&e.d) || e.d.iter().any(|x| *x < 0.0))
        {
            return bad("linear_drag.d", "must be three finite non-negative numbers");
        }
        if let Some(e) = self.quadratic_drag
            && !(e.c.is_finite() && e.c >= 0.0)
        {
            return bad("quadratic_drag.c", "must be a finite non-negative number");
        }
        if let Some(e) = self.wind {
            if !finite3(&e.w_air) {
                return bad("wind.w_air", "must be three finite numbers");
            }
            if self.linear_drag.is_none() && self.quadratic_drag.is_none() {
                return bad(
                    "wind",
                    "needs a drag effect (linear_drag or quadratic_drag) to act through",
                );
            }
        }
        if let Some(e) = self.thrust_scale
            && !(e.k.is_finite() && e.k > 0.0)
        {
            return bad("thrust_scale.k", "must be a positive number");
        }
        if let Some(e) = self.motor_lag
            && !(e.tau_s.is_finite() && e.tau_s >= 0.0)
        {
            return bad("motor_lag.tau_s", "must be a non-negative number");
        }
        if let Some(e) = self.ground_effect
            && !(e.r_m.is_finite() && e.r_m >= 0.0)
        {
            return bad("ground_effect.r_m", "must be a non-negative number");
        }
        if let Some(e) = self.torque_bias
            && !finite3(&e.b)
        {
            return bad("torque_bias.b", "must be three finite numbers");
        }
        if let Some(e) = self.inertia_scale
            && (!finite3(&e.k) || e.k.iter().any(|x| *x <= 0.0))
        {
            return bad("inertia_scale.k", "must be three positive numbers");
        }
        if let Some(e) = self.delay
            && !(e.delay_s.is_finite() && e.delay_s >= 0.0)
        {
            return bad("delay.delay_s", "must be a non-negative number");
        }
        Ok(())
    }

    /// The ids of the effects present, in vocabulary order.
    pub fn ids(&self) -> Vec<&'static str> {
        let present = [
            self.linear_drag.is_some(),
            self.quadratic_drag.is_some(),
            self.wind.is_some(),
            self.thrust_scale.is_some(),
            self.motor_lag.is_some(),
            self.ground_effect.is_some(),
            self.torque_bias.is_some(),
            self.inertia_scale.is_some(),
            self.delay.is_some(),
        ];
        EFFECT_IDS
            .iter()
            .zip(present)
            .filter(|(_, p)| *p)
            .map(|(id, _)| *id)
            .collect()
    }

    /// Air velocity seen by the drag terms (zero without a wind effect).
    pub fn air_velocity(&self) -> Vec3 {
        self.wind.map(|w| w.w_air).unwrap_or([0.0; 3])
    }

    /// Factor multiplying the nominal thrust: `k / (1 − (r / 4z)²)`.
    pub fn thrust_factor(&self, height_above_ground: f64) -> f64 {
        let scale_factor = self.thrust_scale.map(|t| t.k).unwrap_or(1.0);
        scale_factor * self.ground_factor(height_above_ground)
    }

    /// `1 / (1 − (r / 4z)²)` (1 without ground effect), capped as documented at
    /// [`GROUND_EFFECT_MAX_RATIO`].
    pub fn ground_factor(&self, height_above_ground: f64) -> f64 {
        match self.ground_effect {
            Some(g) if g.r_m > 0.0 => 1.0 / (1.0 - ground_ratio(g.r_m, height_above_ground)),
            _ => 1.0,
        }
    }

    /// Drag acceleration (world frame) at attitude `rotation` and velocity `velocity`.
    pub fn drag_acceleration(&self, rotation: &Mat3, velocity: Vec3) -> Vec3 {
        let mut a = [0.0; 3];
        let relative = sub(velocity, self.air_velocity());
        if let Some(drag) = self.linear_drag {
            let body = mat_t_vec(rotation, relative);
            a = sub(a, mat_vec(rotation, hadamard(drag.d, body)));
        }
        if let Some(drag) = self.quadratic_drag {
            a = sub(a, scale(relative, drag.c * norm(relative)));
        }
        a
    }

    /// The real translational acceleration: nominal gravity and thrust with the thrust factor,
    /// plus drag.
    pub fn translational_acceleration(
        &self,
        model: &NominalModel,
        rotation: &Mat3,
        velocity: Vec3,
        height_above_ground: f64,
        thrust: f64,
    ) -> Vec3 {
        let thrust_real = thrust * self.thrust_factor(height_above_ground);
        let nominal = add(
            [0.0, 0.0, -model.gravity_m_s2],
            scale(mat_vec(rotation, E3), thrust_real / model.mass_kg),
        );
        add(nominal, self.drag_acceleration(rotation, velocity))
    }

    /// The real inertia diagonal `diag(k) J`.
    pub fn inertia(&self, model: &NominalModel) -> Vec3 {
        match self.inertia_scale {
            Some(s) => hadamard(s.k, model.inertia_kg_m2),
            None => model.inertia_kg_m2,
        }
    }

    /// The real angular acceleration `J_real⁻¹ (τ − ω × J_real ω) + b`.
    pub fn angular_acceleration(&self, model: &NominalModel, rate: Vec3, torque: Vec3) -> Vec3 {
        let base = angular_acceleration_with_inertia(self.inertia(model), rate, torque);
        add(base, self.torque_bias.map(|b| b.b).unwrap_or([0.0; 3]))
    }

    /// Delay of the actuator response, s.
    pub fn delay_s(&self) -> f64 {
        self.delay.map(|d| d.delay_s).unwrap_or(0.0)
    }

    /// First-order lag time constant of the actuators, s.
    pub fn lag_s(&self) -> f64 {
        self.motor_lag.map(|l| l.tau_s).unwrap_or(0.0)
    }
}

/// `(r / 4z)²` capped at [`GROUND_EFFECT_MAX_RATIO`] (also for z ≤ 0).
pub fn ground_ratio(r_m: f64, height_above_ground: f64) -> f64 {
    if height_above_ground <= 0.0 {
        return GROUND_EFFECT_MAX_RATIO;
    }
    (r_m / (4.0 * height_above_ground))
        .powi(2)
        .min(GROUND_EFFECT_MAX_RATIO)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_the_vocabulary_and_rejects_unknown_ids() {
        let effects: Effects = serde_json::from_str(
            r#"{"quadratic_drag": {"c": 0.05}, "wind": {"w_air": [2, 0, 0]}, "delay": {"delay_s": 0.03}}"#,
        )
        .unwrap();
        assert_eq!(effects.ids(), vec!["quadratic_drag", "wind", "delay"]);
        assert!(effects.validate().is_ok());
        assert!(serde_json::from_str::<Effects>(r#"{"drag": {"c": 1}}"#).is_err());
        let lonely_wind: Effects =
            serde_json::from_str(r#"{"wind": {"w_air": [1, 0, 0]}}"#).unwrap();
        assert_eq!(lonely_wind.validate().unwrap_err().0, "wind");
    }

    #[test]
    fn drag_opposes_the_relative_air_velocity() {
        let effects = Effects {
            quadratic_drag: Some(QuadraticDrag { c: 0.1 }),
            wind: Some(Wind {
                w_air: [1.0, 0.0, 0.0],
            }),
            linear_drag: Some(LinearDrag { d: [0.5, 0.5, 0.2] }),
            ..Effects::default()
        };
        let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let a = effects.drag_acceleration(&identity, [3.0, 0.0, 0.0]);
        // quadratic: −0.1·2·2 = −0.4; linear: −0.5·(3 − 1) = −1.0
        assert!((a[0] + 1.4).abs() < 1e-12 && a[1] == 0.0 && a[2] == 0.0);
    }

    #[test]
    fn ground_effect_grows_near_the_ground_and_is_capped() {
        let effects = Effects {
            ground_effect: Some(GroundEffect { r_m: 0.4 }),
            ..Effects::default()
        };
        assert!((effects.thrust_factor(0.4) - 1.0 / (1.0 - 1.0 / 16.0)).abs() < 1e-12);
        assert!(effects.thrust_factor(5.0) < 1.001);
        assert_eq!(effects.thrust_factor(0.0), 2.0);
    }
}
