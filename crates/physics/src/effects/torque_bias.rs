//! `torque_bias`: a constant extra angular acceleration `b` (rad/s²): `ω̇ += b`.

use serde::{Deserialize, Serialize};

use super::{
    AXES, ChannelGroup, Effect, EffectId, EffectKind, InvalidParameter, ParameterValue, Screening,
    Term, require, vec3,
};
use crate::vector::Vec3;

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TorqueBias {
    pub b: Vec3,
}

impl Effect for TorqueBias {
    fn id(&self) -> EffectId {
        EffectId::TorqueBias
    }

    fn values(&self) -> Vec<(&'static str, ParameterValue)> {
        vec![("b", ParameterValue::Vector(self.b.to_vec()))]
    }

    fn check(&self) -> Result<(), InvalidParameter> {
        require(
            self.b.iter().all(|x| x.is_finite()),
            "torque_bias.b",
            "must be three finite numbers",
        )
    }

    fn describe(&self, _gravity_m_s2: f64) -> String {
        let b = self.b;
        format!(
            "A constant extra angular acceleration [{:.3}, {:.3}, {:.3}] rad/s² (a torque offset, e.g. an off-centre mass or a tilted motor).",
            b[0], b[1], b[2]
        )
    }

    fn angular_bias(&self) -> Option<Vec3> {
        Some(self.b)
    }
}

impl EffectKind for TorqueBias {
    const ID: EffectId = EffectId::TorqueBias;
    const NEUTRAL: Self = Self { b: [0.0; 3] };
    const ACTS_ON: ChannelGroup = ChannelGroup::Angular;

    fn from_numbers(numbers: &[f64]) -> Self {
        Self { b: vec3(numbers) }
    }

    fn typical(_index: usize) -> f64 {
        0.1
    }

    fn screening(_sample_interval_s: f64) -> Option<Screening<Self>> {
        let terms = AXES
            .iter()
            .map(|a| {
                Term::new(
                    &format!("torque_bias_{a}"),
                    &format!("e_{a}"),
                    "1",
                    &format!("b{a} (rad/s²)"),
                )
            })
            .collect();
        let perturbations = (0..3)
            .map(|i| {
                let mut b = [0.0; 3];
                b[i] = 1.0;
                (Self { b }, 1.0)
            })
            .collect();
        Some(Screening {
            terms,
            perturbations,
        })
    }
}
