//! `wind_gradient`: the air velocity varies in space, `w_air + G (p − p_ref)`; it needs a `wind`
//! (the air velocity at the reference).

use serde::{Deserialize, Serialize};

use super::{
    ChannelGroup, Effect, EffectId, EffectKind, InvalidParameter, Needs, ParameterValue, require,
    vec3,
};
use crate::vector::{Mat3, Vec3, add, mat_vec, sub};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WindGradient {
    /// `∂w_air,i / ∂p_j`, 1/s (rows: air velocity component; columns: position coordinate).
    pub per_m: Mat3,
    /// Where the air velocity is `w_air`, m.
    pub reference_m: Vec3,
}

impl Effect for WindGradient {
    fn id(&self) -> EffectId {
        EffectId::WindGradient
    }

    fn values(&self) -> Vec<(&'static str, ParameterValue)> {
        vec![
            (
                "per_m",
                ParameterValue::Matrix(self.per_m.iter().map(|row| row.to_vec()).collect()),
            ),
            (
                "reference_m",
                ParameterValue::Vector(self.reference_m.to_vec()),
            ),
        ]
    }

    fn check(&self) -> Result<(), InvalidParameter> {
        let finite = self
            .per_m
            .iter()
            .flatten()
            .chain(&self.reference_m)
            .all(|v| v.is_finite());
        require(finite, "wind_gradient", "must hold finite numbers")
    }

    fn describe(&self, _gravity_m_s2: f64) -> String {
        let g = self.per_m;
        let largest = g.iter().flatten().fold(0.0f64, |a, b| a.max(b.abs()));
        format!(
            "The air velocity is not uniform: it changes by up to {largest:.2} m/s per metre moved (gradient {}).",
            serde_json::to_string(&g).unwrap_or_default()
        )
    }

    fn air_velocity(&self, air: Vec3, position: Option<Vec3>) -> Vec3 {
        match position {
            Some(p) => add(air, mat_vec(&self.per_m, sub(p, self.reference_m))),
            None => air,
        }
    }
}

impl EffectKind for WindGradient {
    const ID: EffectId = EffectId::WindGradient;
    const NEUTRAL: Self = Self {
        per_m: [[0.0; 3]; 3],
        reference_m: [0.0; 3],
    };
    const ACTS_ON: ChannelGroup = ChannelGroup::Translational;
    const DESCRIBES_THE_AIR: bool = true;
    const NEEDS: Option<Needs> = Some(Needs {
        one_of: &[EffectId::Wind],
        message: "needs a wind effect (its air velocity at the reference)",
    });

    /// The gradient's rows, then the reference.
    fn from_numbers(numbers: &[f64]) -> Self {
        Self {
            per_m: std::array::from_fn(|i| vec3(&numbers[3 * i..3 * i + 3])),
            reference_m: vec3(&numbers[9..12]),
        }
    }
}
