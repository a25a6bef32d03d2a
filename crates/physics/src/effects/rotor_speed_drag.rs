//! `rotor_speed_drag`: rotor drag proportional to the rotor speed and linear in the airspeed (the
//! blade-flapping and induced drag of Faessler et al. and of Gazebo's rotor model, each rotor
//! `−c |ω_i| v⊥`): `a = −√f R diag(dh, dh, dv) Rᵀ (v − w_air)` with `f = T_real / (m g)`, since the
//! rotors' speeds sum to about `√f` times their sum at hover when they share the thrust; `d` in 1/s
//! at hover thrust.

use serde::{Deserialize, Serialize};

use super::rotor_drag::{check_coefficients, edgewise_and_axial};
use super::{ChannelGroup, Effect, EffectId, EffectKind, InvalidParameter, ParameterValue};
use crate::vector::{Mat3, Vec3};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RotorSpeedDrag {
    pub d: [f64; 2],
}

impl Effect for RotorSpeedDrag {
    fn id(&self) -> EffectId {
        EffectId::RotorSpeedDrag
    }

    fn values(&self) -> Vec<(&'static str, ParameterValue)> {
        vec![("d", ParameterValue::Vector(self.d.to_vec()))]
    }

    fn check(&self) -> Result<(), InvalidParameter> {
        check_coefficients(self.d, "rotor_speed_drag.d")
    }

    fn describe(&self, _gravity_m_s2: f64) -> String {
        let d = self.d;
        format!(
            "Rotor drag proportional to the rotor speed and linear in the airspeed: {:.3} 1/s edgewise and {:.3} 1/s along the rotor axis at hover thrust, growing with the square root of the thrust (at 5 m/s edgewise airspeed about {:.2} m/s² at hover).",
            d[0],
            d[1],
            5.0 * d[0]
        )
    }

    fn speed_drag(&self, rotation: &Mat3, air_body: Vec3) -> Option<Vec3> {
        Some(edgewise_and_axial(self.d, rotation, air_body))
    }
}

impl EffectKind for RotorSpeedDrag {
    const ID: EffectId = EffectId::RotorSpeedDrag;
    const NEUTRAL: Self = Self { d: [0.0; 2] };
    const ACTS_ON: ChannelGroup = ChannelGroup::Translational;

    fn from_numbers(numbers: &[f64]) -> Self {
        Self {
            d: [numbers[0], numbers[1]],
        }
    }

    fn fit_range(_index: usize) -> (f64, f64) {
        (0.0, f64::INFINITY)
    }

    fn typical(_index: usize) -> f64 {
        0.1
    }

    fn fit_starts() -> Vec<Vec<f64>> {
        vec![vec![0.3, 0.1]]
    }
}
