//! `wind`: the air moves at `w_air` (m/s, world frame); the drag terms act on the velocity
//! relative to it, so it needs one of them.

use serde::{Deserialize, Serialize};

use super::{
    ChannelGroup, Effect, EffectId, EffectKind, InvalidParameter, Needs, ParameterValue, require,
    vec3,
};
use crate::vector::{Vec3, add, norm};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Wind {
    pub w_air: Vec3,
}

impl Effect for Wind {
    fn id(&self) -> EffectId {
        EffectId::Wind
    }

    fn values(&self) -> Vec<(&'static str, ParameterValue)> {
        vec![("w_air", ParameterValue::Vector(self.w_air.to_vec()))]
    }

    fn check(&self) -> Result<(), InvalidParameter> {
        require(
            self.w_air.iter().all(|x| x.is_finite()),
            "wind.w_air",
            "must be three finite numbers",
        )
    }

    fn describe(&self, _gravity_m_s2: f64) -> String {
        let w = self.w_air;
        format!(
            "The drag acts on the velocity relative to air moving at [{:.2}, {:.2}, {:.2}] m/s (speed {:.2} m/s): there is wind.",
            w[0],
            w[1],
            w[2],
            norm(w)
        )
    }

    fn air_velocity(&self, air: Vec3, _position: Option<Vec3>) -> Vec3 {
        add(air, self.w_air)
    }
}

impl EffectKind for Wind {
    const ID: EffectId = EffectId::Wind;
    const NEUTRAL: Self = Self { w_air: [0.0; 3] };
    const ACTS_ON: ChannelGroup = ChannelGroup::Translational;
    const DESCRIBES_THE_AIR: bool = true;
    const NEEDS: Option<Needs> = Some(Needs {
        one_of: &[
            EffectId::LinearDrag,
            EffectId::QuadraticDrag,
            EffectId::RotorDrag,
            EffectId::RotorSpeedDrag,
        ],
        message: "needs a drag effect (linear_drag, quadratic_drag, rotor_drag or rotor_speed_drag) to act through",
    });

    fn from_numbers(numbers: &[f64]) -> Self {
        Self {
            w_air: vec3(numbers),
        }
    }
}
