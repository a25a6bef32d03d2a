//! How a motor command becomes rotor thrust: the command is scaled to `u ∈ [0, 1]`
//! ([`CommandScale`]), a thrust curve gives `n(u, V)` ([`ThrustCurve`]), and the rotor's thrust is
//! `thrust_coefficient_n · n` (docs/vehicles.md, "Command maps").

use serde::{Deserialize, Serialize};

use crate::error::{PhysicsError, Result, readable};

/// The full scale of a 16-bit motor command (the Crazyflie's `motorPower`).
pub const FRACTION_FULL_SCALE: f64 = 65536.0;

/// The largest power of the command or the voltage a polynomial term may have.
pub const MAX_POLYNOMIAL_POWER: u32 = 4;

/// How the logged command maps to `u ∈ [0, 1]` (values outside are clipped: a motor does not go
/// beyond its limits).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum CommandScale {
    /// Already normalised: PX4's `actuator_motors` control (0 to 1).
    Normalised,
    /// A pulse width in µs between `min_us` (u = 0) and `max_us` (u = 1), as PX4's
    /// `actuator_outputs` with `PWM_MAIN_MINn`/`PWM_MAIN_MAXn`.
    PwmMicroseconds { min_us: f64, max_us: f64 },
    /// An integer command as a fraction of 65536 (u = command / 65536).
    Fraction65536,
}

/// One term `coefficient · u^command_power · (V / reference_voltage_v)^voltage_power`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PolynomialTerm {
    pub command_power: u32,
    pub voltage_power: u32,
    pub coefficient: f64,
}

/// The rotor's thrust, in units of its thrust coefficient, at scaled command `u`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum ThrustCurve {
    /// PX4's thrust model (`THR_MDL_FAC` = `factor`): `n = (1 − f) u + f u²`; 0 is linear in the
    /// command, 1 quadratic.
    ThrustModel { factor: f64 },
    /// A polynomial in the command and the battery voltage: `n = Σ c · u^i · (V / V_ref)^j`,
    /// clipped at 0 (a rotor pushes, never pulls).
    VoltagePolynomial {
        reference_voltage_v: f64,
        terms: Vec<PolynomialTerm>,
    },
    /// Measured `[u, n]` points, `u` strictly increasing and `n` never decreasing; linear
    /// between points, the end values beyond them.
    Table { points: Vec<[f64; 2]> },
}

/// Bisection steps of [`ThrustCurve::command_for`]: the command to within 2⁻⁵² of its range.
const COMMAND_BISECTIONS: usize = 52;

/// The command → rotor thrust map shared by a vehicle's rotors.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CommandMap {
    pub command: CommandScale,
    pub thrust: ThrustCurve,
}

impl CommandScale {
    /// `u ∈ [0, 1]` of a command.
    pub fn scaled(&self, command: f64) -> f64 {
        let u = match *self {
            Self::Normalised => command,
            Self::PwmMicroseconds { min_us, max_us } => (command - min_us) / (max_us - min_us),
            Self::Fraction65536 => command / FRACTION_FULL_SCALE,
        };
        u.clamp(0.0, 1.0)
    }

    /// The command of `u ∈ [0, 1]`: the inverse of [`CommandScale::scaled`] inside the range.
    pub fn unscaled(&self, u: f64) -> f64 {
        match *self {
            Self::Normalised => u,
            Self::PwmMicroseconds { min_us, max_us } => min_us + u * (max_us - min_us),
            Self::Fraction65536 => u * FRACTION_FULL_SCALE,
        }
    }

    fn check(&self) -> Result<()> {
        if let Self::PwmMicroseconds { min_us, max_us } = *self {
            for (name, value) in [("min_us", min_us), ("max_us", max_us)] {
                if !(0.0..=1e5).contains(&value) {
                    return Err(invalid(
                        &format!("command_map.command.{name}"),
                        format!(
                            "{} is not a pulse width in µs (0 to 100000)",
                            readable(value)
                        ),
                    ));
                }
            }
            if max_us <= min_us {
                return Err(invalid(
                    "command_map.command.max_us",
                    format!(
                        "{} must exceed min_us {}",
                        readable(max_us),
                        readable(min_us)
                    ),
                ));
            }
        }
        Ok(())
    }
}

impl ThrustCurve {
    /// Whether the curve needs the battery voltage.
    pub fn needs_voltage(&self) -> bool {
        matches!(self, Self::VoltagePolynomial { .. })
    }

    /// `n(u, V)`; `None` when the curve needs a voltage and none is given.
    pub fn relative_thrust(&self, u: f64, battery_v: Option<f64>) -> Option<f64> {
        match self {
            Self::ThrustModel { factor } => Some((1.0 - factor) * u + factor * u * u),
            Self::VoltagePolynomial {
                reference_voltage_v,
                terms,
            } => {
                let v = battery_v? / reference_voltage_v;
                let sum: f64 = terms
                    .iter()
                    .map(|t| {
                        t.coefficient
                            * u.powi(t.command_power as i32)
                            * v.powi(t.voltage_power as i32)
                    })
                    .sum();
                Some(sum.max(0.0))
            }
            Self::Table { points } => Some(interpolate(points, u)),
        }
    }

    /// The smallest `u ∈ [0, 1]` whose thrust reaches `n` at `battery_v`, by bisection (a curve a
    /// vehicle flies rises with its command): 0 when no thrust is asked, 1 when even the full
    /// command falls short; `None` when the curve needs a voltage and none is given.
    pub fn command_for(&self, n: f64, battery_v: Option<f64>) -> Option<f64> {
        let thrust = |u: f64| self.relative_thrust(u, battery_v);
        if thrust(1.0)? <= n {
            return Some(1.0);
        }
        let (mut low, mut high) = (0.0, 1.0);
        if thrust(low)? >= n {
            return Some(low);
        }
        for _ in 0..COMMAND_BISECTIONS {
            let middle = 0.5 * (low + high);
            if thrust(middle)? < n {
                low = middle;
            } else {
                high = middle;
            }
        }
        Some(high)
    }

    fn check(&self) -> Result<()> {
        match self {
            Self::ThrustModel { factor } => {
                if !(0.0..=1.0).contains(factor) {
                    return Err(invalid(
                        "command_map.thrust.factor",
                        format!("{} is outside [0, 1]", readable(*factor)),
                    ));
                }
            }
            Self::VoltagePolynomial {
                reference_voltage_v,
                terms,
            } => {
                if !(reference_voltage_v.is_finite() && *reference_voltage_v > 0.0) {
                    return Err(invalid(
                        "command_map.thrust.reference_voltage_v",
                        format!(
                            "{} is not a positive voltage",
                            readable(*reference_voltage_v)
                        ),
                    ));
                }
                if terms.is_empty() {
                    return Err(invalid("command_map.thrust.terms", "no term".to_string()));
                }
                for (k, term) in terms.iter().enumerate() {
                    let field = format!("command_map.thrust.terms[{k}]");
                    if term.command_power.max(term.voltage_power) > MAX_POLYNOMIAL_POWER {
                        return Err(invalid(
                            &field,
                            format!("a power above {MAX_POLYNOMIAL_POWER}"),
                        ));
                    }
                    if !term.coefficient.is_finite() {
                        return Err(invalid(
                            &format!("{field}.coefficient"),
                            "not finite".into(),
                        ));
                    }
                }
            }
            Self::Table { points } => check_table(points)?,
        }
        Ok(())
    }
}

impl CommandMap {
    /// PX4's motors: normalised commands through `THR_MDL_FAC`'s blend.
    pub fn px4(thrust_model_factor: f64) -> Self {
        Self {
            command: CommandScale::Normalised,
            thrust: ThrustCurve::ThrustModel {
                factor: thrust_model_factor,
            },
        }
    }

    /// Checks every number (names the field of a bad one).
    pub fn check(&self) -> Result<()> {
        self.command.check()?;
        self.thrust.check()
    }

    /// The command whose relative thrust is `n` at `battery_v` ([`ThrustCurve::command_for`]).
    pub fn command_for(&self, n: f64, battery_v: Option<f64>) -> Option<f64> {
        Some(
            self.command
                .unscaled(self.thrust.command_for(n, battery_v)?),
        )
    }

    /// The thrust of a rotor with coefficient `thrust_coefficient_n` at `command`, N; an error
    /// when the map needs the battery voltage and `battery_v` is `None`.
    pub fn rotor_thrust(
        &self,
        thrust_coefficient_n: f64,
        command: f64,
        battery_v: Option<f64>,
    ) -> Result<f64> {
        let u = self.command.scaled(command);
        let n = self.thrust.relative_thrust(u, battery_v).ok_or_else(|| {
            invalid(
                "command_map.thrust",
                "a voltage polynomial needs the battery voltage, and none was given".into(),
            )
        })?;
        Ok(thrust_coefficient_n * n)
    }
}

/// Linear interpolation in a checked table (`u` increasing), the end values beyond it.
fn interpolate(points: &[[f64; 2]], u: f64) -> f64 {
    let after = points.partition_point(|p| p[0] <= u);
    match after {
        0 => points[0][1],
        k if k == points.len() => points[k - 1][1],
        k => {
            let [u0, n0] = points[k - 1];
            let [u1, n1] = points[k];
            n0 + (n1 - n0) * (u - u0) / (u1 - u0)
        }
    }
}

fn check_table(points: &[[f64; 2]]) -> Result<()> {
    if points.len() < 2 {
        return Err(invalid(
            "command_map.thrust.points",
            format!("{} points; a table needs at least 2", points.len()),
        ));
    }
    for (k, point) in points.iter().enumerate() {
        let field = format!("command_map.thrust.points[{k}]");
        if !point.iter().all(|v| v.is_finite()) || point[1] < 0.0 {
            return Err(invalid(
                &field,
                "expected finite [command, thrust] with thrust ≥ 0".into(),
            ));
        }
        if k > 0 && point[0] <= points[k - 1][0] {
            return Err(invalid(
                &field,
                format!(
                    "command {} does not increase (the point before has {})",
                    readable(point[0]),
                    readable(points[k - 1][0])
                ),
            ));
        }
        if k > 0 && point[1] < points[k - 1][1] {
            return Err(invalid(
                &field,
                format!(
                    "thrust {} decreases (the point before has {}): a thrust table must be monotone",
                    readable(point[1]),
                    readable(points[k - 1][1])
                ),
            ));
        }
    }
    Ok(())
}

pub(super) fn invalid(field: &str, message: String) -> PhysicsError {
    PhysicsError::Description {
        field: field.to_string(),
        message,
    }
}
