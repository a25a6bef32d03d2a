//! `linear_drag`: drag linear in the velocity relative to the air, per body axis (the rotors'
//! induced drag at low speed): `a = −R diag(d) Rᵀ (v − w_air)`, `d` in 1/s.

use serde::{Deserialize, Serialize};

use super::{
    AXES, ChannelGroup, Effect, EffectId, EffectKind, InvalidParameter, ParameterValue, Screening,
    Term, require, vec3,
};
use crate::vector::{Mat3, Vec3, hadamard, mat_t_vec, mat_vec};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinearDrag {
    pub d: Vec3,
}

impl Effect for LinearDrag {
    fn id(&self) -> EffectId {
        EffectId::LinearDrag
    }

    fn values(&self) -> Vec<(&'static str, ParameterValue)> {
        vec![("d", ParameterValue::Vector(self.d.to_vec()))]
    }

    fn check(&self) -> Result<(), InvalidParameter> {
        require(
            self.d.iter().all(|x| x.is_finite() && *x >= 0.0),
            "linear_drag.d",
            "must be three finite non-negative numbers",
        )
    }

    fn describe(&self, _gravity_m_s2: f64) -> String {
        let d = self.d;
        format!(
            "Rotor drag: a force against the velocity along each body axis, d = [{:.3}, {:.3}, {:.3}] 1/s (at 2 m/s forward flight about {:.2} m/s² of deceleration).",
            d[0],
            d[1],
            d[2],
            2.0 * d[0].max(d[1])
        )
    }

    fn air_drag(&self, rotation: &Mat3, relative: Vec3) -> Option<Vec3> {
        let body = mat_t_vec(rotation, relative);
        Some(mat_vec(rotation, hadamard(self.d, body)))
    }
}

impl EffectKind for LinearDrag {
    const ID: EffectId = EffectId::LinearDrag;
    const NEUTRAL: Self = Self { d: [0.0; 3] };
    const ACTS_ON: ChannelGroup = ChannelGroup::Translational;

    fn from_numbers(numbers: &[f64]) -> Self {
        Self { d: vec3(numbers) }
    }

    fn fit_range(_index: usize) -> (f64, f64) {
        (0.0, f64::INFINITY)
    }

    fn typical(_index: usize) -> f64 {
        0.1
    }

    fn screening(_sample_interval_s: f64) -> Option<Screening<Self>> {
        let terms = AXES
            .iter()
            .map(|a| {
                Term::new(
                    &format!("rotor_drag_{a}"),
                    &format!("−R e_{a} e_{a}ᵀ Rᵀ v"),
                    "m/s",
                    &format!("d{a} (1/s)"),
                )
            })
            .collect();
        let perturbations = (0..3)
            .map(|i| {
                let mut d = [0.0; 3];
                d[i] = 1.0;
                (Self { d }, 1.0)
            })
            .collect();
        Some(Screening {
            terms,
            perturbations,
        })
    }
}
