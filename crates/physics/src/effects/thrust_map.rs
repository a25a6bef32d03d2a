//! `thrust_map`: the thrust does not follow the command in proportion:
//! `T_real / (m g) = k0 + k1 (x − 1) + k2 (x − 1)²` for a command asking `x = T / (m g)`.

use serde::{Deserialize, Serialize};

use super::{
    ChannelGroup, Effect, EffectId, EffectKind, InvalidParameter, ParameterValue, require, vec3,
};
use crate::vector::Vec3;

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ThrustMap {
    pub k: Vec3,
}

impl Effect for ThrustMap {
    fn id(&self) -> EffectId {
        EffectId::ThrustMap
    }

    fn values(&self) -> Vec<(&'static str, ParameterValue)> {
        vec![("k", ParameterValue::Vector(self.k.to_vec()))]
    }

    fn check(&self) -> Result<(), InvalidParameter> {
        let k = self.k;
        require(
            k.iter().all(|v| v.is_finite()) && k[0] > 0.0 && k[1] > 0.0,
            "thrust_map.k",
            "must be three finite numbers, the first two positive (thrust at hover and its slope)",
        )
    }

    fn describe(&self, _gravity_m_s2: f64) -> String {
        let k = self.k;
        format!(
            "The thrust does not follow the command in proportion: T / (m g) = {:.3} + {:.3} (x − 1) {:+.3} (x − 1)² for a command asking x m g (at hover {:+.1}%, its slope {:+.0}% from the model's).",
            k[0],
            k[1],
            k[2],
            100.0 * (k[0] - 1.0),
            100.0 * (k[1] - 1.0)
        )
    }

    fn thrust_curve(&self, x: f64) -> f64 {
        let k = self.k;
        k[0] + k[1] * (x - 1.0) + k[2] * (x - 1.0).powi(2)
    }
}

impl EffectKind for ThrustMap {
    const ID: EffectId = EffectId::ThrustMap;
    const NEUTRAL: Self = Self { k: [1.0, 1.0, 0.0] };
    const ACTS_ON: ChannelGroup = ChannelGroup::Translational;

    fn from_numbers(numbers: &[f64]) -> Self {
        Self { k: vec3(numbers) }
    }

    /// Thrust at hover and its slope positive; all within a factor of 20.
    fn fit_range(index: usize) -> (f64, f64) {
        if index < 2 {
            (0.05, 20.0)
        } else {
            (-20.0, 20.0)
        }
    }
}
