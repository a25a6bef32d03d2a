//! The vocabulary of unmodelled effects, switchable one by one in the simulated plant and used by
//! the mismatch tool to model what it finds.
//!
//! An effect is one file of this folder: its parameters (a serde struct), what it changes in the
//! equations of motion ([`Effect`]'s hooks), its checks and plain-words description, and what the
//! analyses need of it ([`EffectKind`]: neutral values, fit ranges, screening terms, start values).
//! The registry below lists them; from that list come [`EffectId`], the set [`Effects`] (one optional
//! entry per effect, serialised as `{"<id>": {<parameters>}, ...}`) and [`EffectParameters`].
//! Adding an effect is one new file here plus one line in the registry.
//!
//! Ids and parameter names are an output contract.
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
//! | `axial_thrust_loss` | `c` | `T_real ×= max(0, 1 − c v_bz)`: less thrust climbing through the air (s/m) |
//! | `rotor_speed_drag` | `d: [horizontal, vertical]` | `a = −√f R diag(dh, dh, dv) Rᵀ (v − w_air)` (1/s): drag proportional to the rotor speed |
//! | `aerodynamic_torque` | `k: [x, y]` | `ω̇ += [kx v_by, −ky v_bx, 0]` (rad/s² per m/s): a drag acting above or below the centre of mass |
//!
//! How the hooks compose (the order of each sum and product is the registry's):
//! `a = [0, 0, −g] + g f R a_T − f Σ thrust drags − √f Σ speed drags + Σ air drags` with
//! `f = curve(T / m g) · Π gains` the real thrust over `m g` and `a_T` the thrust axis;
//! `ω̇ = J_real⁻¹ (τ − ω × J_real ω) + Σ biases + Σ air torques`.

mod registry;
#[cfg(test)]
mod tests;

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

pub use ground_effect::{GROUND_EFFECT_MAX_RATIO, ground_ratio};
pub use thrust_tilt::MAX_TILT_RAD;

// The registry: one line per effect, `TypeName file_name;` (the file name is its id).
registry::vocabulary! {
    LinearDrag linear_drag;
    QuadraticDrag quadratic_drag;
    Wind wind;
    ThrustScale thrust_scale;
    MotorLag motor_lag;
    GroundEffect ground_effect;
    TorqueBias torque_bias;
    InertiaScale inertia_scale;
    Delay delay;
    ThrustMap thrust_map;
    ThrustTilt thrust_tilt;
    RotorDrag rotor_drag;
    TranslationalLift translational_lift;
    DragLag drag_lag;
    WindGradient wind_gradient;
    AxialThrustLoss axial_thrust_loss;
    RotorSpeedDrag rotor_speed_drag;
    AerodynamicTorque aerodynamic_torque;
}

use crate::model::{NominalModel, angular_acceleration_with_inertia};
use crate::vector::{E3, Mat3, Vec3, add, mat_t_vec, mat_vec, scale, sub};

/// A parameter that is out of its range: the field (`linear_drag.d`) and what it must be.
pub type InvalidParameter = (String, String);

/// An effect with its parameters: what it changes in the equations of motion (each hook's default
/// leaves the term unchanged; `None` adds nothing), its checks and its description.
pub trait Effect: Send + Sync {
    /// The effect's id.
    fn id(&self) -> EffectId;
    /// Each parameter's name and value, in the order of the keys of its JSON.
    fn values(&self) -> Vec<(&'static str, ParameterValue)>;
    /// Checks the parameters' ranges; the error names the field (`linear_drag.d`).
    fn check(&self) -> Result<(), InvalidParameter>;
    /// One sentence in plain words, for a vehicle under gravity `gravity_m_s2`.
    fn describe(&self, gravity_m_s2: f64) -> String;

    /// Every number of the parameters, in order.
    fn numbers(&self) -> Vec<f64> {
        self.values()
            .iter()
            .flat_map(|(_, v)| v.numbers())
            .collect()
    }
    /// The air velocity (world, m/s) given the one the effects before it make: the uniform part
    /// when `position` is `None`, else at `position`.
    fn air_velocity(&self, air: Vec3, position: Option<Vec3>) -> Vec3 {
        let _ = position;
        air
    }
    /// The real thrust over `m g` as a function of the ratio `x` the effects before it give.
    fn thrust_curve(&self, x: f64) -> f64 {
        x
    }
    /// A factor on the thrust at a height above ground and a body-frame airspeed.
    fn thrust_gain(&self, height_above_ground: f64, air_body: Vec3) -> Option<f64> {
        let _ = (height_above_ground, air_body);
        None
    }
    /// The thrust axis in the body frame.
    fn thrust_axis(&self) -> Option<Vec3> {
        None
    }
    /// A deceleration per unit thrust ratio (world frame) at body-frame airspeed `air_body`.
    fn thrust_drag(&self, rotation: &Mat3, air_body: Vec3) -> Option<Vec3> {
        let _ = (rotation, air_body);
        None
    }
    /// A deceleration per unit rotor speed, `√f` (world frame), at body-frame airspeed `air_body`.
    fn speed_drag(&self, rotation: &Mat3, air_body: Vec3) -> Option<Vec3> {
        let _ = (rotation, air_body);
        None
    }
    /// A deceleration (world frame) from the velocity `relative` to the air.
    fn air_drag(&self, rotation: &Mat3, relative: Vec3) -> Option<Vec3> {
        let _ = (rotation, relative);
        None
    }
    /// The real inertia diagonal given the one the effects before it give.
    fn inertia(&self, inertia: Vec3) -> Vec3 {
        inertia
    }
    /// An angular acceleration added to the rigid body's (rad/s²).
    fn angular_bias(&self) -> Option<Vec3> {
        None
    }
    /// An angular acceleration (rad/s²) from the body-frame airspeed `air_body`.
    fn air_torque(&self, air_body: Vec3) -> Option<Vec3> {
        let _ = air_body;
        None
    }
    /// The signal that is late or lags, and by how much (s).
    fn timing(&self) -> Option<(Timing, f64)> {
        None
    }
}

/// What the registry and the analyses know of an effect's type, without its values.
pub trait EffectKind:
    Effect + Copy + std::fmt::Debug + PartialEq + Serialize + DeserializeOwned + 'static
{
    /// Its id.
    const ID: EffectId;
    /// The values that leave the nominal model unchanged (a start for a fit).
    const NEUTRAL: Self;
    /// The channels it acts on.
    const ACTS_ON: ChannelGroup;
    /// Whether its numbers are factors (1 leaves the model unchanged), whose errors are relative
    /// to `|value − 1|`.
    const FACTOR: bool = false;
    /// Whether it describes the air a flight met rather than the vehicle (a joint analysis of
    /// several flights fits it per flight).
    const DESCRIBES_THE_AIR: bool = false;
    /// Effects one of which must be present for it to act, and what to say when none is.
    const NEEDS: Option<Needs> = None;

    /// The parameters with these numbers, in the order of [`Effect::numbers`].
    fn from_numbers(numbers: &[f64]) -> Self;
    /// The range a fit keeps number `index` in.
    fn fit_range(index: usize) -> (f64, f64) {
        let _ = index;
        (f64::NEG_INFINITY, f64::INFINITY)
    }
    /// A typical magnitude of number `index`, for finite-difference steps.
    fn typical(index: usize) -> f64 {
        let _ = index;
        1.0
    }
    /// The terms the single-recording screen tries for it (none: not screened).
    fn screening(sample_interval_s: f64) -> Option<Screening<Self>> {
        let _ = sample_interval_s;
        None
    }
    /// Start values of a nonlinear fit of all its numbers (none: start at [`Self::NEUTRAL`]).
    fn fit_starts() -> Vec<Vec<f64>> {
        Vec::new()
    }
    /// The spacing of the grid a profile search tries number `index` on, across its
    /// [`Self::fit_range`] (none: not profiled; the range must then be finite).
    fn profile_step(index: usize) -> Option<f64> {
        let _ = index;
        None
    }
}

/// Effects one of which must be present for an effect to act.
#[derive(Clone, Copy, Debug)]
pub struct Needs {
    pub one_of: &'static [EffectId],
    /// The check's message when none is present.
    pub message: &'static str,
}

/// The channels an effect acts on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ChannelGroup {
    Translational,
    Angular,
    Both,
}

/// A signal that is late or lags.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Timing {
    /// The vehicle responds to its commands late.
    CommandDelay,
    /// Each actuator follows its command with a first-order lag.
    ActuatorLag,
    /// The velocity the air terms see lags the vehicle's by a first-order lag.
    AirLag,
}

/// One term of the single-recording screen's library.
#[derive(Clone, Debug, Serialize)]
pub struct Term {
    pub name: String,
    pub formula: String,
    /// Units of the term's column (an acceleration per unit coefficient).
    pub units: String,
    /// The coefficient and its units.
    pub coefficient: String,
}

impl Term {
    pub fn new(name: &str, formula: &str, units: &str, coefficient: &str) -> Self {
        Self {
            name: name.to_string(),
            formula: formula.to_string(),
            units: units.to_string(),
            coefficient: coefficient.to_string(),
        }
    }
}

/// An effect's screening terms: each term's column is the model's response to one perturbed
/// value of the effect, divided by the perturbation's step.
#[derive(Clone, Debug)]
pub struct Screening<E> {
    pub terms: Vec<Term>,
    pub perturbations: Vec<(E, f64)>,
}

/// Relative step of the screening derivatives of the factor effects.
pub const SCREENING_STEP: f64 = 1e-3;

/// The axes' names, for terms per axis.
pub(crate) const AXES: [&str; 3] = ["x", "y", "z"];

impl EffectId {
    /// The effects one of which must be present for this one to act (empty: it acts alone).
    pub fn needs_one_of(self) -> &'static [EffectId] {
        self.needs().map_or(&[], |needs| needs.one_of)
    }
}

/// One number of an effect's parameters: the effect and the number's index in its
/// [`Effect::numbers`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct EffectNumber {
    pub effect: EffectId,
    pub index: usize,
}

impl EffectNumber {
    pub const fn new(effect: EffectId, index: usize) -> Self {
        Self { effect, index }
    }

    /// Every number of effect `id`.
    pub fn all_of(id: EffectId) -> Vec<Self> {
        (0..id.neutral().numbers().len())
            .map(|index| Self::new(id, index))
            .collect()
    }

    /// The range a fit keeps it in.
    pub fn fit_range(self) -> (f64, f64) {
        self.effect.fit_range(self.index)
    }

    /// `value` within the fit range.
    pub fn clamp(self, value: f64) -> f64 {
        let (low, high) = self.fit_range();
        value.clamp(low, high)
    }

    /// A typical magnitude, for finite-difference steps.
    pub fn typical(self) -> f64 {
        self.effect.typical(self.index)
    }

    /// The grid a profile search tries it on: its fit range from the lower end in steps of
    /// [`EffectKind::profile_step`], both ends included (empty when it is not profiled).
    pub fn profile_grid(self) -> Vec<f64> {
        let Some(step) = self.effect.profile_step(self.index) else {
            return Vec::new();
        };
        let (low, high) = self.fit_range();
        let count = ((high - low) / step).round() as usize;
        (0..=count).map(|i| low + i as f64 * step).collect()
    }

    /// Its value when the effect is neutral.
    pub fn neutral(self) -> f64 {
        self.effect.neutral().numbers()[self.index]
    }

    /// A forward-difference step at `value`.
    pub fn step(self, value: f64) -> f64 {
        1e-4 * value.abs().max(self.typical())
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

/// `numbers` as a 3-vector (missing numbers are 0).
pub(crate) fn vec3(numbers: &[f64]) -> Vec3 {
    std::array::from_fn(|i| numbers.get(i).copied().unwrap_or(0.0))
}

/// `Err` naming `field` unless `ok`.
pub(crate) fn require(ok: bool, field: &str, message: &str) -> Result<(), InvalidParameter> {
    if ok {
        Ok(())
    } else {
        Err((field.to_string(), message.to_string()))
    }
}

/// The equations of motion with the effects present, composed through their hooks in the
/// registry's order (see the module documentation).
impl Effects {
    /// Checks every parameter's range and every effect's needs; the error names the effect and
    /// parameter.
    pub fn validate(&self) -> Result<(), InvalidParameter> {
        let mut result = Ok(());
        self.for_each(|effect| {
            if result.is_ok() {
                result = effect.check().and_then(|()| self.check_needs(effect.id()));
            }
        });
        result
    }

    fn check_needs(&self, id: EffectId) -> Result<(), InvalidParameter> {
        match id.needs() {
            Some(needs) if !needs.one_of.iter().any(|n| self.contains(*n)) => {
                Err((id.name().to_string(), needs.message.to_string()))
            }
            _ => Ok(()),
        }
    }

    /// The effects without `id`, and without every effect left without what it needs (the wind
    /// when no drag is left for it to act on).
    pub fn without(&self, id: EffectId) -> Effects {
        let mut out = *self;
        out.remove(id);
        for other in EffectId::ALL {
            if out.contains(other) && out.check_needs(other).is_err() {
                out.remove(other);
            }
        }
        out
    }

    /// The ids of the effects present, in vocabulary order.
    pub fn ids(&self) -> Vec<EffectId> {
        EffectId::ALL
            .into_iter()
            .filter(|id| self.contains(*id))
            .collect()
    }

    /// Sets number `number` of its effect, adding the effect at its neutral values if absent.
    pub fn set_number(&mut self, number: EffectNumber, value: f64) {
        let id = number.effect;
        let mut numbers = self
            .parameters(id)
            .unwrap_or_else(|| id.neutral())
            .numbers();
        numbers[number.index] = value;
        self.insert(EffectParameters::from_numbers(id, &numbers));
    }

    /// The air velocity (world, m/s) at the reference: the uniform part.
    pub fn air_velocity(&self) -> Vec3 {
        self.fold([0.0; 3], |air, e| e.air_velocity(air, None))
    }

    /// The air velocity at `position` (the uniform part without a gradient).
    pub fn air_velocity_at(&self, position: Vec3) -> Vec3 {
        self.fold([0.0; 3], |air, e| e.air_velocity(air, Some(position)))
    }

    /// The deceleration (world frame) of the air drags at attitude `rotation`, velocity
    /// `velocity` and position `position`.
    pub fn drag_acceleration(&self, rotation: &Mat3, velocity: Vec3, position: Vec3) -> Vec3 {
        let relative = sub(velocity, self.air_velocity_at(position));
        self.fold([0.0; 3], |a, e| match e.air_drag(rotation, relative) {
            Some(drag) => sub(a, drag),
            None => a,
        })
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
        let air_body = self.body_airspeed(rotation, velocity, position);
        self.translational_acceleration_in_air(
            model, rotation, velocity, position, air_body, thrust,
        )
    }

    /// [`Self::translational_acceleration`] with the body airspeed `air_body` already computed
    /// ([`Self::body_airspeed`] of the same attitude, velocity and position), for a caller that
    /// needs it for the angular acceleration too.
    pub fn translational_acceleration_in_air(
        &self,
        model: &NominalModel,
        rotation: &Mat3,
        velocity: Vec3,
        position: Vec3,
        air_body: Vec3,
        thrust: f64,
    ) -> Vec3 {
        let g = model.gravity_m_s2;
        let height_above_ground = position[2] - model.ground_height_m;
        let ratio = self.thrust_ratio(thrust / (model.mass_kg * g), height_above_ground, air_body);
        let axis = mat_vec(rotation, self.thrust_axis());
        let thrust_part = add([0.0, 0.0, -g], scale(axis, g * ratio));
        let thrust_part = self.fold(thrust_part, |a, e| {
            match e.thrust_drag(rotation, air_body) {
                Some(drag) => sub(a, scale(drag, ratio)),
                None => a,
            }
        });
        let thrust_part = self.fold(thrust_part, |a, e| match e.speed_drag(rotation, air_body) {
            Some(drag) => sub(a, scale(drag, ratio.max(0.0).sqrt())),
            None => a,
        });
        add(
            thrust_part,
            self.drag_acceleration(rotation, velocity, position),
        )
    }

    /// The real thrust over `m g` for a nominal thrust ratio `x = T / (m g)`: the thrust curve
    /// (or `x`) times every thrust gain.
    pub fn thrust_ratio(&self, x: f64, height_above_ground: f64, air_body: Vec3) -> f64 {
        let curve = self.fold(x, |x, e| e.thrust_curve(x));
        let gain = self.fold(1.0, |gain, e| {
            match e.thrust_gain(height_above_ground, air_body) {
                Some(factor) => gain * factor,
                None => gain,
            }
        });
        curve * gain
    }

    /// The thrust axis in the body frame (`e3` without a tilt).
    pub fn thrust_axis(&self) -> Vec3 {
        self.fold(E3, |axis, e| e.thrust_axis().unwrap_or(axis))
    }

    /// The real inertia diagonal.
    pub fn inertia(&self, model: &NominalModel) -> Vec3 {
        self.fold(model.inertia_kg_m2, |inertia, e| e.inertia(inertia))
    }

    /// The real angular acceleration `J_real⁻¹ (τ − ω × J_real ω) + Σ biases + Σ air torques`,
    /// with `air_body` the body-frame airspeed ([`Self::body_airspeed`]).
    pub fn angular_acceleration(
        &self,
        model: &NominalModel,
        rate: Vec3,
        torque: Vec3,
        air_body: Vec3,
    ) -> Vec3 {
        let base = angular_acceleration_with_inertia(self.inertia(model), rate, torque);
        let bias = self.fold([0.0; 3], |b, e| {
            let b = match e.angular_bias() {
                Some(extra) => add(b, extra),
                None => b,
            };
            match e.air_torque(air_body) {
                Some(extra) => add(b, extra),
                None => b,
            }
        });
        add(base, bias)
    }

    /// The body-frame airspeed `Rᵀ (v − w_air(p))` at attitude `rotation`, velocity `velocity` and
    /// position `position`.
    pub fn body_airspeed(&self, rotation: &Mat3, velocity: Vec3, position: Vec3) -> Vec3 {
        mat_t_vec(rotation, sub(velocity, self.air_velocity_at(position)))
    }

    /// The total of the effects' `timing` of this kind, s (0 without one).
    pub fn timing_s(&self, timing: Timing) -> f64 {
        self.fold(0.0, |total, e| match e.timing() {
            Some((kind, seconds)) if kind == timing => total + seconds,
            _ => total,
        })
    }

    /// Delay of the actuator response, s.
    pub fn delay_s(&self) -> f64 {
        self.timing_s(Timing::CommandDelay)
    }

    /// First-order lag time constant of the actuators, s.
    pub fn lag_s(&self) -> f64 {
        self.timing_s(Timing::ActuatorLag)
    }

    /// Time constant of the lag of the velocity the air terms see, s (0 without one).
    pub fn drag_lag_s(&self) -> f64 {
        self.timing_s(Timing::AirLag)
    }
}
