//! `thrust_tilt`: the thrust acts along `R Rx(x) Ry(y) e3` instead of `R e3` (a tilted or
//! uncalibrated thrust axis), angles in rad.

use serde::{Deserialize, Serialize};

use super::{
    ChannelGroup, Effect, EffectId, EffectKind, InvalidParameter, ParameterValue, require,
};
use crate::vector::Vec3;

/// The largest thrust-axis tilt angle accepted, rad.
pub const MAX_TILT_RAD: f64 = 0.5;

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ThrustTilt {
    pub angles_rad: [f64; 2],
}

impl Effect for ThrustTilt {
    fn id(&self) -> EffectId {
        EffectId::ThrustTilt
    }

    fn values(&self) -> Vec<(&'static str, ParameterValue)> {
        vec![(
            "angles_rad",
            ParameterValue::Vector(self.angles_rad.to_vec()),
        )]
    }

    fn check(&self) -> Result<(), InvalidParameter> {
        require(
            self.angles_rad
                .iter()
                .all(|a| a.is_finite() && a.abs() <= MAX_TILT_RAD),
            "thrust_tilt.angles_rad",
            "must be two finite angles of at most 0.5 rad",
        )
    }

    fn describe(&self, gravity_m_s2: f64) -> String {
        let [x, y] = self.angles_rad;
        let total = (x.cos() * y.cos()).acos();
        format!(
            "The thrust axis is tilted from the body z axis by {:.2}° about x and {:.2}° about y ({:.2}° in all; uncalibrated, that reads as a steady sideways force of {:.2} m/s²).",
            x.to_degrees(),
            y.to_degrees(),
            total.to_degrees(),
            gravity_m_s2 * total.sin()
        )
    }

    fn thrust_axis(&self) -> Option<Vec3> {
        let [x, y] = self.angles_rad;
        Some([y.sin(), -x.sin() * y.cos(), x.cos() * y.cos()])
    }
}

impl EffectKind for ThrustTilt {
    const ID: EffectId = EffectId::ThrustTilt;
    const NEUTRAL: Self = Self {
        angles_rad: [0.0; 2],
    };
    const ACTS_ON: ChannelGroup = ChannelGroup::Translational;

    fn from_numbers(numbers: &[f64]) -> Self {
        Self {
            angles_rad: [numbers[0], numbers[1]],
        }
    }

    fn fit_range(_index: usize) -> (f64, f64) {
        (-MAX_TILT_RAD, MAX_TILT_RAD)
    }

    fn typical(_index: usize) -> f64 {
        0.01
    }
}
