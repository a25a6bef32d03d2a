//! `axial_thrust_loss`: the rotors lose thrust climbing through the air (more inflow through the
//! disc): `T_real ×= max(0, 1 − c v_bz)` with `v_b = Rᵀ (v − w_air)`, `c` in s/m (about
//! `1 / (2 v_h)` from momentum theory, `v_h` the induced velocity at hover).

use serde::{Deserialize, Serialize};

use super::{
    ChannelGroup, Effect, EffectId, EffectKind, InvalidParameter, ParameterValue, require,
};
use crate::vector::Vec3;

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxialThrustLoss {
    pub c: f64,
}

impl Effect for AxialThrustLoss {
    fn id(&self) -> EffectId {
        EffectId::AxialThrustLoss
    }

    fn values(&self) -> Vec<(&'static str, ParameterValue)> {
        vec![("c", ParameterValue::Number(self.c))]
    }

    fn check(&self) -> Result<(), InvalidParameter> {
        require(
            self.c.is_finite() && self.c >= 0.0,
            "axial_thrust_loss.c",
            "must be a finite non-negative number",
        )
    }

    fn describe(&self, _gravity_m_s2: f64) -> String {
        format!(
            "The rotors lose thrust climbing through the air: {:.1}% less at 1 m/s of axial airspeed, {:.1}% at 3 m/s (c = {:.4} s/m).",
            100.0 * self.c.min(1.0),
            100.0 * (3.0 * self.c).min(1.0),
            self.c
        )
    }

    fn thrust_gain(&self, _height_above_ground: f64, air_body: Vec3) -> Option<f64> {
        Some((1.0 - self.c * air_body[2]).max(0.0))
    }
}

impl EffectKind for AxialThrustLoss {
    const ID: EffectId = EffectId::AxialThrustLoss;
    const NEUTRAL: Self = Self { c: 0.0 };
    const ACTS_ON: ChannelGroup = ChannelGroup::Translational;

    fn from_numbers(numbers: &[f64]) -> Self {
        Self { c: numbers[0] }
    }

    fn fit_range(_index: usize) -> (f64, f64) {
        (0.0, 1.0)
    }

    fn typical(_index: usize) -> f64 {
        0.01
    }
}
