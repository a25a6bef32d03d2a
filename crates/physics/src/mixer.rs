//! The mixer of a multirotor of `N` rotors: `[T, τx, τy, τz] = b0 · s²`, with `b0` 4 × N and `s_i`
//! rotor `i`'s normalised speed (`s_i² = n_i`, its thrust in units of its coefficient), and the
//! least-norm speeds for a wrench (the allocation a simulator's controller flies with).
//!
//! The speeds of every row are kept in an [`Actuators`] array of [`MAX_ACTUATORS`] entries whose
//! entries past the rotor count stay zero, so that per-row state needs no allocation.

use serde::ser::{Serialize, SerializeStruct, Serializer};

use crate::vehicle::{CommandMap, VehicleDescription};

/// At most this many actuators (rotors) a model drives.
pub const MAX_ACTUATORS: usize = data::MAX_MOTORS;

/// One row's actuator states: normalised rotor speeds (or `[T, 0, …]` with a thrust setpoint);
/// entries past the model's [`crate::NominalModel::actuator_count`] are zero.
pub type Actuators = [f64; MAX_ACTUATORS];

/// `values` (at most [`MAX_ACTUATORS`]) as actuator states, zero past them.
pub fn actuators(values: &[f64]) -> Actuators {
    let mut out = [0.0; MAX_ACTUATORS];
    out[..values.len()].copy_from_slice(values);
    out
}

/// The map from motor commands to thrust and torques.
#[derive(Clone, Debug, PartialEq)]
pub struct Mixer {
    pub pwm_offset: f64,
    pub pwm_scale: f64,
    /// `[T, τx, τy, τz] = b0 · s²`: 4 rows, a column per rotor (zero past `rotors`).
    b0: [Actuators; 4],
    rotors: usize,
    /// The least-norm allocation `b0ᵀ (b0 b0ᵀ)⁻¹` (`b0⁻¹` for four rotors), N × 4.
    allocation: [[f64; 4]; MAX_ACTUATORS],
    /// With a vehicle description: its command map, through which `s² = n(u, V)`.
    command_map: Option<CommandMap>,
}

/// As the model file writes it: `pwm_offset`, `pwm_scale` and `b0`'s 4 rows of N.
impl Serialize for Mixer {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let rows: Vec<&[f64]> = (0..4).map(|i| self.row(i)).collect();
        let mut mixer = serializer.serialize_struct("Mixer", 3)?;
        mixer.serialize_field("pwm_offset", &self.pwm_offset)?;
        mixer.serialize_field("pwm_scale", &self.pwm_scale)?;
        mixer.serialize_field("b0", &rows)?;
        mixer.end()
    }
}

impl Mixer {
    /// Builds a mixer of `rows` (4 rows of N columns, 4 ≤ N ≤ [`MAX_ACTUATORS`]); `None` for
    /// another N or when the rotors cannot set thrust and the three torques independently (rank
    /// below 4).
    pub fn new(pwm_offset: f64, pwm_scale: f64, rows: &[Vec<f64>; 4]) -> Option<Self> {
        let rotors = rows[0].len();
        if !(4..=MAX_ACTUATORS).contains(&rotors) || rows.iter().any(|r| r.len() != rotors) {
            return None;
        }
        let mut b0 = [[0.0; MAX_ACTUATORS]; 4];
        for (row, values) in b0.iter_mut().zip(rows) {
            row[..rotors].copy_from_slice(values);
        }
        let allocation = least_norm_allocation(&b0, rotors)?;
        Some(Self {
            pwm_offset,
            pwm_scale,
            b0,
            rotors,
            allocation,
            command_map: None,
        })
    }

    /// The mixer of a vehicle: `b0`'s columns are the allocation's times each rotor's thrust
    /// coefficient, and `s_i² = n_i(u_i, V)`; `None` beyond [`MAX_ACTUATORS`] rotors or when
    /// the allocation's rank is below 4.
    pub fn from_vehicle(vehicle: &VehicleDescription) -> Option<Self> {
        let rows = vehicle.allocation().rows();
        let b0: [Vec<f64>; 4] = std::array::from_fn(|r| {
            rows[r]
                .iter()
                .zip(&vehicle.rotors)
                .map(|(value, rotor)| value * rotor.thrust_coefficient_n)
                .collect()
        });
        let mut mixer = Self::new(0.0, 1.0, &b0)?;
        mixer.command_map = Some(vehicle.command_map.clone());
        Some(mixer)
    }

    /// How many rotors.
    pub fn rotors(&self) -> usize {
        self.rotors
    }

    /// Row `i` of `b0` (`T`, `τx`, `τy`, `τz`), a value per rotor.
    pub fn row(&self, i: usize) -> &[f64] {
        &self.b0[i][..self.rotors]
    }

    /// Whether the speeds need the battery voltage.
    pub fn needs_battery_voltage(&self) -> bool {
        self.command_map
            .as_ref()
            .is_some_and(|map| map.thrust.needs_voltage())
    }

    /// Normalised motor speeds `s_i = (pwm_i − pwm_offset) / pwm_scale`, clipped at 0 (through the
    /// command map with a vehicle: `s_i = √n_i(u_i, V)`, NaN without a voltage it needs), for the
    /// rotors' commands `pwm` (one per rotor; a rotor without one gets speed 0).
    pub fn speeds(&self, pwm: &[f64], battery_v: Option<f64>) -> Actuators {
        let mut out = [0.0; MAX_ACTUATORS];
        for (speed, &command) in out.iter_mut().zip(pwm.iter().take(self.rotors)) {
            *speed = match &self.command_map {
                Some(map) => map
                    .thrust
                    .relative_thrust(map.command.scaled(command), battery_v)
                    .map_or(f64::NAN, f64::sqrt),
                None => ((command - self.pwm_offset) / self.pwm_scale).max(0.0),
            };
        }
        out
    }

    /// Whether the commands come through a vehicle's command map (not `pwm_offset` and `pwm_scale`).
    pub fn has_command_map(&self) -> bool {
        self.command_map.is_some()
    }

    /// The motor commands of normalised speeds, one per rotor: `pwm_offset + pwm_scale · s`, or
    /// through a vehicle's command map the command whose thrust is `s²` at `battery_v` (NaN
    /// without a voltage the map needs).
    pub fn commands(&self, speeds: &Actuators, battery_v: Option<f64>) -> Vec<f64> {
        speeds[..self.rotors]
            .iter()
            .map(|s| match &self.command_map {
                Some(map) => map.command_for(s * s, battery_v).unwrap_or(f64::NAN),
                None => self.pwm_offset + self.pwm_scale * s,
            })
            .collect()
    }

    /// `[T, τx, τy, τz] = b0 · s²`.
    pub fn wrench(&self, speeds: &Actuators) -> [f64; 4] {
        let squared = speeds.map(|s| s * s);
        self.b0
            .map(|row| (0..self.rotors).map(|j| row[j] * squared[j]).sum())
    }

    /// `b0 · spread`: what variances `spread` of the speeds within a row add to the wrench.
    pub fn spread_wrench(&self, spread: &Actuators) -> [f64; 4] {
        self.b0
            .map(|row| (0..self.rotors).map(|j| row[j] * spread[j]).sum())
    }

    /// The speeds (clipped to [0, 1]) that produce a wrench `[T, τx, τy, τz]` as closely as the
    /// limits allow: the least-norm squared speeds, clipped.
    pub fn speeds_for(&self, wrench: &[f64; 4]) -> Actuators {
        let mut out = [0.0; MAX_ACTUATORS];
        for (speed, row) in out.iter_mut().zip(&self.allocation[..self.rotors]) {
            let squared: f64 = (0..4).map(|j| row[j] * wrench[j]).sum();
            *speed = squared.max(0.0).sqrt().min(1.0);
        }
        out
    }
}

/// `b0⁻¹` for four rotors; `b0ᵀ (b0 b0ᵀ)⁻¹` for more. `None` when the rank is below 4.
fn least_norm_allocation(b0: &[Actuators; 4], rotors: usize) -> Option<[[f64; 4]; MAX_ACTUATORS]> {
    let mut out = [[0.0; 4]; MAX_ACTUATORS];
    if rotors == 4 {
        let square: [[f64; 4]; 4] = std::array::from_fn(|i| std::array::from_fn(|j| b0[i][j]));
        out[..4].copy_from_slice(&invert4(&square)?);
        return Some(out);
    }
    let gram: [[f64; 4]; 4] = std::array::from_fn(|i| {
        std::array::from_fn(|k| (0..rotors).map(|j| b0[i][j] * b0[k][j]).sum())
    });
    let inverse = invert4(&gram)?;
    for (j, row) in out[..rotors].iter_mut().enumerate() {
        *row = std::array::from_fn(|k| (0..4).map(|i| b0[i][j] * inverse[i][k]).sum());
    }
    Some(out)
}

/// Inverse of a 4x4 matrix by Gauss–Jordan elimination with partial pivoting.
fn invert4(m: &[[f64; 4]; 4]) -> Option<[[f64; 4]; 4]> {
    let mut a = *m;
    let mut inv = [[0.0; 4]; 4];
    for (i, row) in inv.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    let magnitude = m.iter().flatten().fold(0.0f64, |acc, v| acc.max(v.abs()));
    for col in 0..4 {
        let pivot = (col..4).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[pivot][col].abs() <= 1e-12 * magnitude.max(f64::MIN_POSITIVE) {
            return None;
        }
        a.swap(col, pivot);
        inv.swap(col, pivot);
        let p = a[col][col];
        for j in 0..4 {
            a[col][j] /= p;
            inv[col][j] /= p;
        }
        for i in 0..4 {
            if i != col {
                let f = a[i][col];
                for j in 0..4 {
                    a[i][j] -= f * a[col][j];
                    inv[i][j] -= f * inv[col][j];
                }
            }
        }
    }
    Some(inv)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_hexarotor_flies_the_least_norm_speeds_of_a_wrench() {
        let hexa = VehicleDescription::hexa_x(0.25, 8.0, 0.016).unwrap();
        let mixer = Mixer::from_vehicle(&hexa).unwrap();
        assert_eq!(mixer.rotors(), 6);
        let speeds = actuators(&[0.6, 0.62, 0.58, 0.61, 0.59, 0.6]);
        let wrench = mixer.wrench(&speeds);
        let back = mixer.wrench(&mixer.speeds_for(&wrench));
        for i in 0..4 {
            assert!((back[i] - wrench[i]).abs() < 1e-9, "{back:?} {wrench:?}");
        }
        // A pure thrust is shared equally; the padding stays zero.
        let equal = mixer.speeds_for(&[6.0 * 8.0 * 0.25, 0.0, 0.0, 0.0]);
        assert!(
            equal[..6].iter().all(|s| (s - 0.5).abs() < 1e-12),
            "{equal:?}"
        );
        assert!(equal[6..].iter().all(|s| *s == 0.0));
    }

    #[test]
    fn rotors_without_a_command_spin_at_zero() {
        let hexa = VehicleDescription::hexa_x(0.17, 6.0, 0.016).unwrap();
        let from_vehicle = Mixer::from_vehicle(&hexa).unwrap();
        let rows: [Vec<f64>; 4] = std::array::from_fn(|i| from_vehicle.row(i).to_vec());
        let mixer = Mixer::new(1000.0, 1000.0, &rows).unwrap();
        assert_eq!(mixer.speeds(&[1500.0; 4], None), actuators(&[0.5; 4]));
    }

    #[test]
    fn a_rank_deficient_layout_has_no_mixer() {
        // Four rotors in a row cannot make a pitch torque.
        let rows = [
            vec![1.0; 4],
            vec![-0.3, -0.1, 0.1, 0.3],
            vec![0.0; 4],
            vec![0.01, -0.01, 0.01, -0.01],
        ];
        assert!(Mixer::new(1000.0, 1000.0, &rows).is_none());
    }
}
