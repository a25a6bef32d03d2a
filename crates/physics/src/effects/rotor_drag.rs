//! `rotor_drag`: drag proportional to the thrust and linear in the airspeed (the rotors' H-force):
//! `a = −f R diag(dh, dh, dv) Rᵀ (v − w_air)` with `f = T_real / (m g)`, `d` in 1/s.

use serde::{Deserialize, Serialize};

use super::{
    ChannelGroup, Effect, EffectId, EffectKind, InvalidParameter, ParameterValue, require,
};
use crate::vector::{Mat3, Vec3, hadamard, mat_vec};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RotorDrag {
    pub d: [f64; 2],
}

impl Effect for RotorDrag {
    fn id(&self) -> EffectId {
        EffectId::RotorDrag
    }

    fn values(&self) -> Vec<(&'static str, ParameterValue)> {
        vec![("d", ParameterValue::Vector(self.d.to_vec()))]
    }

    fn check(&self) -> Result<(), InvalidParameter> {
        check_coefficients(self.d, "rotor_drag.d")
    }

    fn describe(&self, _gravity_m_s2: f64) -> String {
        let d = self.d;
        format!(
            "Rotor drag proportional to the thrust and linear in the airspeed: {:.3} 1/s edgewise and {:.3} 1/s along the rotor axis (at hover thrust and 5 m/s edgewise airspeed about {:.2} m/s²).",
            d[0],
            d[1],
            5.0 * d[0]
        )
    }

    fn thrust_drag(&self, rotation: &Mat3, air_body: Vec3) -> Option<Vec3> {
        Some(edgewise_and_axial(self.d, rotation, air_body))
    }
}

/// `R diag(dh, dh, dv) v_b`: a rotor drag's deceleration per unit of what scales it (world frame).
pub(super) fn edgewise_and_axial(d: [f64; 2], rotation: &Mat3, air_body: Vec3) -> Vec3 {
    mat_vec(rotation, hadamard([d[0], d[0], d[1]], air_body))
}

/// A rotor drag's two coefficients are finite and non-negative; the error names `field`.
pub(super) fn check_coefficients(d: [f64; 2], field: &str) -> Result<(), InvalidParameter> {
    require(
        d.iter().all(|v| v.is_finite() && *v >= 0.0),
        field,
        "must be two finite non-negative numbers",
    )
}

impl EffectKind for RotorDrag {
    const ID: EffectId = EffectId::RotorDrag;
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
