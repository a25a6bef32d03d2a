//! `aerodynamic_torque`: a torque from the air, linear in the body-frame airspeed, as a drag acting
//! at a height above (or below) the centre of mass gives: `ω̇ += [kx v_by, −ky v_bx, 0]` with
//! `v_b = Rᵀ (v − w_air)`, `k` in rad/s² per m/s. A drag `c v_b` (N per m/s) acting a height `h`
//! above the centre of mass gives `k = h c / J` on each axis: positive above, negative below.

use serde::{Deserialize, Serialize};

use super::{
    ChannelGroup, Effect, EffectId, EffectKind, InvalidParameter, ParameterValue, Screening,
    Term, require,
};
use crate::vector::Vec3;

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AerodynamicTorque {
    pub k: [f64; 2],
}

impl Effect for AerodynamicTorque {
    fn id(&self) -> EffectId {
        EffectId::AerodynamicTorque
    }

    fn values(&self) -> Vec<(&'static str, ParameterValue)> {
        vec![("k", ParameterValue::Vector(self.k.to_vec()))]
    }

    fn check(&self) -> Result<(), InvalidParameter> {
        require(
            self.k.iter().all(|v| v.is_finite()),
            "aerodynamic_torque.k",
            "must be two finite numbers",
        )
    }

    fn describe(&self, _gravity_m_s2: f64) -> String {
        let k = self.k;
        let place = |v: f64| if v >= 0.0 { "above" } else { "below" };
        format!(
            "A torque from the air linear in the body-frame airspeed: {:.3} rad/s² per m/s about x from the sideways airspeed and {:.3} about y from the forward one, as a drag acting {} (roll) and {} (pitch) the centre of mass gives (at 5 m/s about {:.2} rad/s²).",
            k[0],
            k[1],
            place(k[0]),
            place(k[1]),
            5.0 * k[0].abs().max(k[1].abs())
        )
    }

    fn air_torque(&self, air_body: Vec3) -> Option<Vec3> {
        Some([self.k[0] * air_body[1], -self.k[1] * air_body[0], 0.0])
    }
}

impl EffectKind for AerodynamicTorque {
    const ID: EffectId = EffectId::AerodynamicTorque;
    const NEUTRAL: Self = Self { k: [0.0; 2] };
    const ACTS_ON: ChannelGroup = ChannelGroup::Angular;

    fn from_numbers(numbers: &[f64]) -> Self {
        Self {
            k: [numbers[0], numbers[1]],
        }
    }

    fn typical(_index: usize) -> f64 {
        0.1
    }

    fn screening(_sample_interval_s: f64) -> Option<Screening<Self>> {
        let terms = vec![
            Term::new("air_torque_x", "e_x (Rᵀ v)_y", "m/s", "kx (rad/s² per m/s)"),
            Term::new("air_torque_y", "−e_y (Rᵀ v)_x", "m/s", "ky (rad/s² per m/s)"),
        ];
        let perturbations = vec![
            (Self { k: [1.0, 0.0] }, 1.0),
            (Self { k: [0.0, 1.0] }, 1.0),
        ];
        Some(Screening {
            terms,
            perturbations,
        })
    }
}
