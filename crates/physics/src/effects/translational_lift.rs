//! `translational_lift`: the rotors give more thrust in edgewise airflow:
//! `T_real ×= 1 + c (v_bx² + v_by²)` with `v_b = Rᵀ (v − w_air)`, `c` in s²/m².

use serde::{Deserialize, Serialize};

use super::{
    ChannelGroup, Effect, EffectId, EffectKind, InvalidParameter, ParameterValue, require,
};
use crate::vector::Vec3;

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TranslationalLift {
    pub c: f64,
}

impl Effect for TranslationalLift {
    fn id(&self) -> EffectId {
        EffectId::TranslationalLift
    }

    fn values(&self) -> Vec<(&'static str, ParameterValue)> {
        vec![("c", ParameterValue::Number(self.c))]
    }

    fn check(&self) -> Result<(), InvalidParameter> {
        require(
            self.c.is_finite() && self.c >= 0.0,
            "translational_lift.c",
            "must be a finite non-negative number",
        )
    }

    fn describe(&self, _gravity_m_s2: f64) -> String {
        let c = self.c;
        format!(
            "Translational lift: the rotors give more thrust in edgewise airflow, by {:+.1}% at 5 m/s and {:+.1}% at 10 m/s (c = {c:.5} s²/m²).",
            100.0 * 25.0 * c,
            100.0 * 100.0 * c
        )
    }

    fn thrust_gain(&self, _height_above_ground: f64, air_body: Vec3) -> Option<f64> {
        Some(1.0 + self.c * (air_body[0].powi(2) + air_body[1].powi(2)))
    }
}

impl EffectKind for TranslationalLift {
    const ID: EffectId = EffectId::TranslationalLift;
    const NEUTRAL: Self = Self { c: 0.0 };
    const ACTS_ON: ChannelGroup = ChannelGroup::Translational;

    fn from_numbers(numbers: &[f64]) -> Self {
        Self { c: numbers[0] }
    }

    fn fit_range(_index: usize) -> (f64, f64) {
        (0.0, f64::INFINITY)
    }

    fn typical(_index: usize) -> f64 {
        0.001
    }
}
