//! The vocabulary of unmodelled effects, switchable one by one in the simulated plant and used by
//! the mismatch tool to model what it finds. Ids and parameter names are an output contract: each
//! effect is named by an [`EffectId`] (in the order of this table), which is also its key in
//! [`Effects`]' JSON.
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
//! | `thrust_map` | `k: [k0, k1, k2]` | `T_real / (m g) = k0 + k1 (x − 1) + k2 (x − 1)²`, `x = T / (m g)` |
//! | `thrust_tilt` | `angles_rad: [x, y]` | thrust along `R Rx(x) Ry(y) e3` instead of `R e3` |
//! | `rotor_drag` | `d: [horizontal, vertical]` | `a = −f R diag(dh, dh, dv) Rᵀ (v − w_air)` (1/s), `f = T_real / (m g)` |
//! | `translational_lift` | `c` | `T_real ×= 1 + c (v_bx² + v_by²)`, `v_b = Rᵀ (v − w_air)` (s²/m²) |
//! | `drag_lag` | `tau_s` | the velocity the air terms (drags, lift) see lags `v` by a first-order lag |
//! | `wind_gradient` | `per_m: 3 × 3`, `reference_m` | the air velocity varies in space: `w_air + G (p − p_ref)` |

use serde::{Deserialize, Serialize};

use crate::effect_id::EffectId;
use crate::model::{NominalModel, angular_acceleration_with_inertia};
use crate::vector::{E3, Mat3, Vec3, add, hadamard, mat_t_vec, mat_vec, norm, scale, sub};

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
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ThrustMap {
    pub k: Vec3,
}
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ThrustTilt {
    pub angles_rad: [f64; 2],
}
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RotorDrag {
    pub d: [f64; 2],
}
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TranslationalLift {
    pub c: f64,
}
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DragLag {
    pub tau_s: f64,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WindGradient {
    /// `∂w_air,i / ∂p_j`, 1/s (rows: air velocity component; columns: position coordinate).
    pub per_m: Mat3,
    /// Where the air velocity is `w_air`, m.
    pub reference_m: Vec3,
}

/// The largest thrust-axis tilt angle accepted, rad.
pub const MAX_TILT_RAD: f64 = 0.5;

/// One effect's parameters: serialises as that effect's entry in [`Effects`]' JSON.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum EffectParameters {
    LinearDrag(LinearDrag),
    QuadraticDrag(QuadraticDrag),
    Wind(Wind),
    ThrustScale(ThrustScale),
    MotorLag(MotorLag),
    GroundEffect(GroundEffect),
    TorqueBias(TorqueBias),
    InertiaScale(InertiaScale),
    Delay(Delay),
    ThrustMap(ThrustMap),
    ThrustTilt(ThrustTilt),
    RotorDrag(RotorDrag),
    TranslationalLift(TranslationalLift),
    DragLag(DragLag),
    WindGradient(WindGradient),
}

impl EffectParameters {
    /// The effect these parameters belong to.
    pub fn id(&self) -> EffectId {
        match self {
            Self::LinearDrag(_) => EffectId::LinearDrag,
            Self::QuadraticDrag(_) => EffectId::QuadraticDrag,
            Self::Wind(_) => EffectId::Wind,
            Self::ThrustScale(_) => EffectId::ThrustScale,
            Self::MotorLag(_) => EffectId::MotorLag,
            Self::GroundEffect(_) => EffectId::GroundEffect,
            Self::TorqueBias(_) => EffectId::TorqueBias,
            Self::InertiaScale(_) => EffectId::InertiaScale,
            Self::Delay(_) => EffectId::Delay,
            Self::ThrustMap(_) => EffectId::ThrustMap,
            Self::ThrustTilt(_) => EffectId::ThrustTilt,
            Self::RotorDrag(_) => EffectId::RotorDrag,
            Self::TranslationalLift(_) => EffectId::TranslationalLift,
            Self::DragLag(_) => EffectId::DragLag,
            Self::WindGradient(_) => EffectId::WindGradient,
        }
    }

    /// Each parameter's name and value, in the order of the keys of its JSON.
    pub fn values(&self) -> Vec<(&'static str, ParameterValue)> {
        use ParameterValue::{Matrix, Number, Vector};
        match *self {
            Self::LinearDrag(p) => vec![("d", Vector(p.d.to_vec()))],
            Self::QuadraticDrag(p) => vec![("c", Number(p.c))],
            Self::Wind(p) => vec![("w_air", Vector(p.w_air.to_vec()))],
            Self::ThrustScale(p) => vec![("k", Number(p.k))],
            Self::MotorLag(p) => vec![("tau_s", Number(p.tau_s))],
            Self::GroundEffect(p) => vec![("r_m", Number(p.r_m))],
            Self::TorqueBias(p) => vec![("b", Vector(p.b.to_vec()))],
            Self::InertiaScale(p) => vec![("k", Vector(p.k.to_vec()))],
            Self::Delay(p) => vec![("delay_s", Number(p.delay_s))],
            Self::ThrustMap(p) => vec![("k", Vector(p.k.to_vec()))],
            Self::ThrustTilt(p) => vec![("angles_rad", Vector(p.angles_rad.to_vec()))],
            Self::RotorDrag(p) => vec![("d", Vector(p.d.to_vec()))],
            Self::TranslationalLift(p) => vec![("c", Number(p.c))],
            Self::DragLag(p) => vec![("tau_s", Number(p.tau_s))],
            Self::WindGradient(p) => vec![
                (
                    "per_m",
                    Matrix(p.per_m.iter().map(|row| row.to_vec()).collect()),
                ),
                ("reference_m", Vector(p.reference_m.to_vec())),
            ],
        }
    }
}

/// One parameter's value: a number, a vector or a matrix (by rows). Serialises as its JSON value
/// and displays as compact JSON with a space after each comma (`[1.25, 0.85, 1.15]`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum ParameterValue {
    Number(f64),
    Vector(Vec<f64>),
    Matrix(Vec<Vec<f64>>),
}

impl ParameterValue {
    /// Every number, row by row.
    pub fn numbers(&self) -> Vec<f64> {
        match self {
            Self::Number(v) => vec![*v],
            Self::Vector(v) => v.clone(),
            Self::Matrix(rows) => rows.concat(),
        }
    }

    /// The same shape with `f` applied to every number.
    pub fn map(&self, f: impl Fn(f64) -> f64) -> Self {
        match self {
            Self::Number(v) => Self::Number(f(*v)),
            Self::Vector(v) => Self::Vector(v.iter().map(|x| f(*x)).collect()),
            Self::Matrix(rows) => Self::Matrix(
                rows.iter()
                    .map(|r| r.iter().map(|x| f(*x)).collect())
                    .collect(),
            ),
        }
    }
}

impl std::fmt::Display for ParameterValue {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let json = serde_json::to_string(self).map_err(|_| std::fmt::Error)?;
        f.write_str(&json.replace(',', ", "))
    }
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
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thrust_map: Option<ThrustMap>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thrust_tilt: Option<ThrustTilt>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotor_drag: Option<RotorDrag>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub translational_lift: Option<TranslationalLift>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drag_lag: Option<DragLag>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wind_gradient: Option<WindGradient>,
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
            if self.linear_drag.is_none()
                && self.quadratic_drag.is_none()
                && self.rotor_drag.is_none()
            {
                return bad(
                    "wind",
                    "needs a drag effect (linear_drag, quadratic_drag or rotor_drag) to act through",
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
        self.validate_vehicle_effects()
    }

    /// The checks of the effects found on real vehicles (`thrust_map` … `drag_lag`).
    fn validate_vehicle_effects(&self) -> Result<(), (String, String)> {
        let bad = |field: &str, message: &str| Err((field.to_string(), message.to_string()));
        if let Some(e) = self.thrust_map
            && !(e.k.iter().all(|v| v.is_finite()) && e.k[0] > 0.0 && e.k[1] > 0.0)
        {
            return bad(
                "thrust_map.k",
                "must be three finite numbers, the first two positive (thrust at hover and its slope)",
            );
        }
        if let Some(e) = self.thrust_tilt
            && !e
                .angles_rad
                .iter()
                .all(|a| a.is_finite() && a.abs() <= MAX_TILT_RAD)
        {
            return bad(
                "thrust_tilt.angles_rad",
                "must be two finite angles of at most 0.5 rad",
            );
        }
        if let Some(e) = self.rotor_drag
            && !e.d.iter().all(|v| v.is_finite() && *v >= 0.0)
        {
            return bad("rotor_drag.d", "must be two finite non-negative numbers");
        }
        if let Some(e) = self.translational_lift
            && !(e.c.is_finite() && e.c >= 0.0)
        {
            return bad(
                "translational_lift.c",
                "must be a finite non-negative number",
            );
        }
        if let Some(e) = self.drag_lag
            && !(e.tau_s.is_finite() && e.tau_s >= 0.0)
        {
            return bad("drag_lag.tau_s", "must be a non-negative number");
        }
        if let Some(e) = self.wind_gradient {
            let finite = e
                .per_m
                .iter()
                .flatten()
                .chain(&e.reference_m)
                .all(|v| v.is_finite());
            if !finite {
                return bad("wind_gradient", "must hold finite numbers");
            }
            if self.wind.is_none() {
                return bad(
                    "wind_gradient",
                    "needs a wind effect (its air velocity at the reference)",
                );
            }
        }
        Ok(())
    }

    /// The ids of the effects present, in vocabulary order.
    pub fn ids(&self) -> Vec<EffectId> {
        EffectId::ALL
            .into_iter()
            .filter(|id| self.contains(*id))
            .collect()
    }

    /// Whether effect `id` is present.
    pub fn contains(&self, id: EffectId) -> bool {
        match id {
            EffectId::LinearDrag => self.linear_drag.is_some(),
            EffectId::QuadraticDrag => self.quadratic_drag.is_some(),
            EffectId::Wind => self.wind.is_some(),
            EffectId::ThrustScale => self.thrust_scale.is_some(),
            EffectId::MotorLag => self.motor_lag.is_some(),
            EffectId::GroundEffect => self.ground_effect.is_some(),
            EffectId::TorqueBias => self.torque_bias.is_some(),
            EffectId::InertiaScale => self.inertia_scale.is_some(),
            EffectId::Delay => self.delay.is_some(),
            EffectId::ThrustMap => self.thrust_map.is_some(),
            EffectId::ThrustTilt => self.thrust_tilt.is_some(),
            EffectId::RotorDrag => self.rotor_drag.is_some(),
            EffectId::TranslationalLift => self.translational_lift.is_some(),
            EffectId::DragLag => self.drag_lag.is_some(),
            EffectId::WindGradient => self.wind_gradient.is_some(),
        }
    }

    /// The parameters of effect `id`, when present.
    pub fn parameters(&self, id: EffectId) -> Option<EffectParameters> {
        match id {
            EffectId::LinearDrag => self.linear_drag.map(EffectParameters::LinearDrag),
            EffectId::QuadraticDrag => self.quadratic_drag.map(EffectParameters::QuadraticDrag),
            EffectId::Wind => self.wind.map(EffectParameters::Wind),
            EffectId::ThrustScale => self.thrust_scale.map(EffectParameters::ThrustScale),
            EffectId::MotorLag => self.motor_lag.map(EffectParameters::MotorLag),
            EffectId::GroundEffect => self.ground_effect.map(EffectParameters::GroundEffect),
            EffectId::TorqueBias => self.torque_bias.map(EffectParameters::TorqueBias),
            EffectId::InertiaScale => self.inertia_scale.map(EffectParameters::InertiaScale),
            EffectId::Delay => self.delay.map(EffectParameters::Delay),
            EffectId::ThrustMap => self.thrust_map.map(EffectParameters::ThrustMap),
            EffectId::ThrustTilt => self.thrust_tilt.map(EffectParameters::ThrustTilt),
            EffectId::RotorDrag => self.rotor_drag.map(EffectParameters::RotorDrag),
            EffectId::TranslationalLift => self
                .translational_lift
                .map(EffectParameters::TranslationalLift),
            EffectId::DragLag => self.drag_lag.map(EffectParameters::DragLag),
            EffectId::WindGradient => self.wind_gradient.map(EffectParameters::WindGradient),
        }
    }

    /// Removes effect `id` (nothing else: an effect that needs it, as the wind needs a drag, stays).
    pub fn remove(&mut self, id: EffectId) {
        match id {
            EffectId::LinearDrag => self.linear_drag = None,
            EffectId::QuadraticDrag => self.quadratic_drag = None,
            EffectId::Wind => self.wind = None,
            EffectId::ThrustScale => self.thrust_scale = None,
            EffectId::MotorLag => self.motor_lag = None,
            EffectId::GroundEffect => self.ground_effect = None,
            EffectId::TorqueBias => self.torque_bias = None,
            EffectId::InertiaScale => self.inertia_scale = None,
            EffectId::Delay => self.delay = None,
            EffectId::ThrustMap => self.thrust_map = None,
            EffectId::ThrustTilt => self.thrust_tilt = None,
            EffectId::RotorDrag => self.rotor_drag = None,
            EffectId::TranslationalLift => self.translational_lift = None,
            EffectId::DragLag => self.drag_lag = None,
            EffectId::WindGradient => self.wind_gradient = None,
        }
    }

    /// Air velocity seen by the drag terms at the reference (zero without a wind effect).
    pub fn air_velocity(&self) -> Vec3 {
        self.wind.map(|w| w.w_air).unwrap_or([0.0; 3])
    }

    /// Air velocity at `position` (the same everywhere without a wind gradient).
    pub fn air_velocity_at(&self, position: Vec3) -> Vec3 {
        match self.wind_gradient {
            Some(g) => add(
                self.air_velocity(),
                mat_vec(&g.per_m, sub(position, g.reference_m)),
            ),
            None => self.air_velocity(),
        }
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

    /// Drag acceleration (world frame) at attitude `rotation`, velocity `velocity` and position
    /// `position`.
    pub fn drag_acceleration(&self, rotation: &Mat3, velocity: Vec3, position: Vec3) -> Vec3 {
        let mut a = [0.0; 3];
        let relative = sub(velocity, self.air_velocity_at(position));
        if let Some(drag) = self.linear_drag {
            let body = mat_t_vec(rotation, relative);
            a = sub(a, mat_vec(rotation, hadamard(drag.d, body)));
        }
        if let Some(drag) = self.quadratic_drag {
            a = sub(a, scale(relative, drag.c * norm(relative)));
        }
        a
    }

    /// The real translational acceleration at attitude `rotation` and position `position`, with
    /// the nominal thrust `thrust` (N) of the command: gravity, the thrust through the thrust
    /// effects along its axis, and the drags. `velocity` is what the air terms see (the vehicle's
    /// velocity, or its lagged value with a `drag_lag`).
    pub fn translational_acceleration(
        &self,
        model: &NominalModel,
        rotation: &Mat3,
        velocity: Vec3,
        position: Vec3,
        thrust: f64,
    ) -> Vec3 {
        let g = model.gravity_m_s2;
        let height_above_ground = position[2] - model.ground_height_m;
        let air_body = mat_t_vec(rotation, sub(velocity, self.air_velocity_at(position)));
        let ratio = self.thrust_ratio(thrust / (model.mass_kg * g), height_above_ground, air_body);
        let axis = mat_vec(rotation, self.thrust_axis());
        let mut a = add([0.0, 0.0, -g], scale(axis, g * ratio));
        if let Some(drag) = self.rotor_drag {
            let d = [drag.d[0], drag.d[0], drag.d[1]];
            a = sub(a, scale(mat_vec(rotation, hadamard(d, air_body)), ratio));
        }
        add(a, self.drag_acceleration(rotation, velocity, position))
    }

    /// The real thrust over `m g` for a nominal thrust ratio `x = T / (m g)`: the thrust map (or
    /// `x`), times the thrust scale, the ground factor and the translational lift at body-frame
    /// airspeed `air_body`.
    pub fn thrust_ratio(&self, x: f64, height_above_ground: f64, air_body: Vec3) -> f64 {
        let mapped = match self.thrust_map {
            Some(m) => m.k[0] + m.k[1] * (x - 1.0) + m.k[2] * (x - 1.0).powi(2),
            None => x,
        };
        let lift = self
            .translational_lift
            .map(|l| 1.0 + l.c * (air_body[0].powi(2) + air_body[1].powi(2)))
            .unwrap_or(1.0);
        mapped * self.thrust_factor(height_above_ground) * lift
    }

    /// The thrust axis in the body frame (`e3` without a tilt).
    pub fn thrust_axis(&self) -> Vec3 {
        match self.thrust_tilt {
            Some(t) => {
                let [x, y] = t.angles_rad;
                [y.sin(), -x.sin() * y.cos(), x.cos() * y.cos()]
            }
            None => E3,
        }
    }

    /// Time constant of the lag of the velocity the air terms see, s (0 without one).
    pub fn drag_lag_s(&self) -> f64 {
        self.drag_lag.map(|l| l.tau_s).unwrap_or(0.0)
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
        assert_eq!(
            effects.ids(),
            [EffectId::QuadraticDrag, EffectId::Wind, EffectId::Delay]
        );
        assert!(effects.validate().is_ok());
        assert!(serde_json::from_str::<Effects>(r#"{"drag": {"c": 1}}"#).is_err());
        let lonely_wind: Effects =
            serde_json::from_str(r#"{"wind": {"w_air": [1, 0, 0]}}"#).unwrap();
        assert_eq!(lonely_wind.validate().unwrap_err().0, "wind");
    }

    /// Every effect present at once (the parameters are only placeholders).
    fn every_effect() -> Effects {
        Effects {
            linear_drag: Some(LinearDrag { d: [0.1; 3] }),
            quadratic_drag: Some(QuadraticDrag { c: 0.1 }),
            wind: Some(Wind { w_air: [1.0; 3] }),
            thrust_scale: Some(ThrustScale { k: 0.9 }),
            motor_lag: Some(MotorLag { tau_s: 0.02 }),
            ground_effect: Some(GroundEffect { r_m: 0.3 }),
            torque_bias: Some(TorqueBias { b: [0.1; 3] }),
            inertia_scale: Some(InertiaScale { k: [1.1; 3] }),
            delay: Some(Delay { delay_s: 0.02 }),
            thrust_map: Some(ThrustMap { k: [1.0, 1.0, 0.0] }),
            thrust_tilt: Some(ThrustTilt {
                angles_rad: [0.01; 2],
            }),
            rotor_drag: Some(RotorDrag { d: [0.3, 0.1] }),
            translational_lift: Some(TranslationalLift { c: 0.001 }),
            drag_lag: Some(DragLag { tau_s: 0.2 }),
            wind_gradient: Some(WindGradient {
                per_m: [[0.0; 3]; 3],
                reference_m: [0.0; 3],
            }),
        }
    }

    /// Each id is the key of its effect in the JSON, and `contains`, `remove` and `ids` act on
    /// exactly that effect.
    #[test]
    fn the_ids_are_the_keys_of_the_effects() {
        let every = every_effect();
        assert_eq!(every.ids(), EffectId::ALL);
        let json = serde_json::to_value(every).unwrap();
        let mut keys: Vec<&str> = json
            .as_object()
            .unwrap()
            .keys()
            .map(|k| k.as_str())
            .collect();
        let mut names = EffectId::ALL.map(EffectId::name);
        keys.sort_unstable();
        names.sort_unstable();
        assert_eq!(keys, names);
        for id in EffectId::ALL {
            let mut without = every;
            without.remove(id);
            assert!(every.contains(id) && !without.contains(id));
            let json = serde_json::to_value(without).unwrap();
            assert!(json.get(id.name()).is_none(), "{id}");
            assert_eq!(json.as_object().unwrap().len(), EffectId::ALL.len() - 1);
        }
    }

    /// An effect's typed parameters serialise exactly as its entry in the set's JSON, and know
    /// their id; absent effects have none.
    #[test]
    fn typed_parameters_are_the_entries_of_the_set() {
        let every = every_effect();
        let json = serde_json::to_value(every).unwrap();
        for id in EffectId::ALL {
            let parameters = every.parameters(id).unwrap();
            assert_eq!(parameters.id(), id);
            assert_eq!(serde_json::to_value(parameters).unwrap(), json[id.name()]);
            assert!(Effects::default().parameters(id).is_none(), "{id}");
        }
    }

    /// The named values of each effect's parameters are its JSON entry's keys, in order, with its
    /// values; their display is the compact JSON of the value.
    #[test]
    fn named_values_are_the_entries_keys_and_values() {
        let every = every_effect();
        let json = serde_json::to_value(every).unwrap();
        for id in EffectId::ALL {
            let values = every.parameters(id).unwrap().values();
            let entry = json[id.name()].as_object().unwrap();
            let keys: Vec<&str> = entry.keys().map(|k| k.as_str()).collect();
            let names: Vec<&str> = values.iter().map(|(name, _)| *name).collect();
            assert_eq!(names, keys, "{id}");
            for (name, value) in &values {
                assert_eq!(
                    &serde_json::to_value(value).unwrap(),
                    &entry[*name],
                    "{id}.{name}"
                );
                assert_eq!(
                    value.to_string(),
                    entry[*name].to_string().replace(',', ", ")
                );
                assert_eq!(value.map(|x| x).numbers(), value.numbers());
            }
        }
        let matrix = ParameterValue::Matrix(vec![vec![1.0, 2.5], vec![3.0, 4.0]]);
        assert_eq!(matrix.numbers(), [1.0, 2.5, 3.0, 4.0]);
        assert_eq!(
            matrix.map(|x| 2.0 * x).to_string(),
            "[[2.0, 5.0], [6.0, 8.0]]"
        );
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
        let a = effects.drag_acceleration(&identity, [3.0, 0.0, 0.0], [0.0; 3]);
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

    fn model() -> NominalModel {
        NominalModel::from_json(
            r#"{"mass_kg": 2.0, "gravity_m_s2": 10.0, "inertia_kg_m2": [0.03, 0.03, 0.05], "thrust_source": "T_sp"}"#,
            std::path::Path::new("m.json"),
        )
        .unwrap()
    }

    const LEVEL: Mat3 = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

    /// The effects found on real vehicles, each on its own: a thrust map, a tilted thrust axis,
    /// rotor drag scaled by the thrust, translational lift, and air that varies in space.
    #[test]
    fn the_vehicle_effects_act_as_documented() {
        let m = model();
        let hover = 20.0;
        let map = Effects {
            thrust_map: Some(ThrustMap {
                k: [0.98, 1.2, 0.5],
            }),
            ..Effects::default()
        };
        // Asking 1.5 m g gives 0.98 + 1.2 · 0.5 + 0.5 · 0.25 = 1.705 m g.
        let a = map.translational_acceleration(&m, &LEVEL, [0.0; 3], [0.0, 0.0, 5.0], 1.5 * hover);
        assert!((a[2] - (10.0 * 1.705 - 10.0)).abs() < 1e-12, "{a:?}");
        let tilt = Effects {
            thrust_tilt: Some(ThrustTilt {
                angles_rad: [0.0, 0.1],
            }),
            ..Effects::default()
        };
        let a = tilt.translational_acceleration(&m, &LEVEL, [0.0; 3], [0.0, 0.0, 5.0], hover);
        assert!((a[0] - 10.0 * 0.1f64.sin()).abs() < 1e-12 && a[1].abs() < 1e-12);
        let drag = Effects {
            rotor_drag: Some(RotorDrag { d: [0.3, 0.6] }),
            wind: Some(Wind {
                w_air: [1.0, 0.0, 0.0],
            }),
            ..Effects::default()
        };
        // At twice the hover thrust the drag doubles: −2 · 0.3 · (3 − 1) edgewise, −2 · 0.6 · 1 axial.
        let a = drag.translational_acceleration(
            &m,
            &LEVEL,
            [3.0, 0.0, 1.0],
            [0.0, 0.0, 5.0],
            2.0 * hover,
        );
        assert!(
            (a[0] + 1.2).abs() < 1e-12 && (a[2] - (20.0 - 10.0 - 1.2)).abs() < 1e-12,
            "{a:?}"
        );
        let lift = Effects {
            translational_lift: Some(TranslationalLift { c: 0.01 }),
            ..Effects::default()
        };
        let a =
            lift.translational_acceleration(&m, &LEVEL, [3.0, 4.0, 0.0], [0.0, 0.0, 5.0], hover);
        assert!((a[2] - 10.0 * 0.25).abs() < 1e-12, "{a:?}");
        let field = Effects {
            quadratic_drag: Some(QuadraticDrag { c: 0.1 }),
            wind: Some(Wind {
                w_air: [2.0, 0.0, 0.0],
            }),
            wind_gradient: Some(WindGradient {
                per_m: [[0.0, 0.0, 0.5], [0.0; 3], [0.0; 3]],
                reference_m: [0.0, 0.0, 1.0],
            }),
            ..Effects::default()
        };
        // At 3 m the air moves at 2 + 0.5 · 2 = 3 m/s: a vehicle at rest feels −0.1 · 3 · (−3).
        assert_eq!(field.air_velocity_at([0.0, 0.0, 3.0]), [3.0, 0.0, 0.0]);
        let a = field.drag_acceleration(&LEVEL, [0.0; 3], [0.0, 0.0, 3.0]);
        assert!((a[0] - 0.9).abs() < 1e-12, "{a:?}");
        assert!(field.validate().is_ok());
        let without_wind = Effects {
            wind: None,
            ..field
        };
        assert_eq!(without_wind.validate().unwrap_err().0, "wind_gradient");
        let tilted_far = Effects {
            thrust_tilt: Some(ThrustTilt {
                angles_rad: [0.0, 0.9],
            }),
            ..Effects::default()
        };
        assert_eq!(
            tilted_far.validate().unwrap_err().0,
            "thrust_tilt.angles_rad"
        );
    }
}
