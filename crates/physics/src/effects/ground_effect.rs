//! `ground_effect`: extra thrust near the ground, `T_real = T / (1 − (r / 4z)²)` with `z` the
//! height above ground and `r` (m) the rotor radius the formula assumes.

use serde::{Deserialize, Serialize};

use super::{
    ChannelGroup, Effect, EffectId, EffectKind, InvalidParameter, ParameterValue, Screening, Term,
    require,
};
use crate::vector::Vec3;

/// The largest `(r / 4z)²` the ground-effect formula is evaluated at (the formula diverges at 1):
/// below `z = r / (4 √0.5)` the thrust gain is held at 2.
pub const GROUND_EFFECT_MAX_RATIO: f64 = 0.5;

/// The radius of the screening perturbation, m (its column is per `r²`).
const SCREENING_RADIUS_M: f64 = 0.02;

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroundEffect {
    pub r_m: f64,
}

/// `(r / 4z)²` capped at [`GROUND_EFFECT_MAX_RATIO`] (also for z ≤ 0).
pub fn ground_ratio(r_m: f64, height_above_ground: f64) -> f64 {
    if height_above_ground <= 0.0 {
        return GROUND_EFFECT_MAX_RATIO;
    }
    (r_m / (4.0 * height_above_ground))
        .powi(2)
        .min(GROUND_EFFECT_MAX_RATIO)
}

impl Effect for GroundEffect {
    fn id(&self) -> EffectId {
        EffectId::GroundEffect
    }

    fn values(&self) -> Vec<(&'static str, ParameterValue)> {
        vec![("r_m", ParameterValue::Number(self.r_m))]
    }

    fn check(&self) -> Result<(), InvalidParameter> {
        require(
            self.r_m.is_finite() && self.r_m >= 0.0,
            "ground_effect.r_m",
            "must be a non-negative number",
        )
    }

    fn describe(&self, _gravity_m_s2: f64) -> String {
        let r = self.r_m;
        format!(
            "Extra thrust near the ground (ground effect), radius r = {r:.3} m: +{:.1}% thrust at 0.3 m height, +{:.2}% at 1.5 m.",
            100.0 * (1.0 / (1.0 - ground_ratio(r, 0.3)) - 1.0),
            100.0 * (1.0 / (1.0 - ground_ratio(r, 1.5)) - 1.0)
        )
    }

    fn thrust_gain(&self, height_above_ground: f64, _air_body: Vec3) -> Option<f64> {
        (self.r_m > 0.0).then(|| 1.0 / (1.0 - ground_ratio(self.r_m, height_above_ground)))
    }
}

impl EffectKind for GroundEffect {
    const ID: EffectId = EffectId::GroundEffect;
    const NEUTRAL: Self = Self { r_m: 0.0 };
    const ACTS_ON: ChannelGroup = ChannelGroup::Translational;

    fn from_numbers(numbers: &[f64]) -> Self {
        Self { r_m: numbers[0] }
    }

    /// A radius beyond 1 m is not the physics the name stands for.
    fn fit_range(_index: usize) -> (f64, f64) {
        (0.0, 1.0)
    }

    fn typical(_index: usize) -> f64 {
        0.1
    }

    /// 2 cm: the profile only starts the fit, which then moves freely within the range.
    fn profile_step(_index: usize) -> Option<f64> {
        Some(0.02)
    }

    fn screening(_sample_interval_s: f64) -> Option<Screening<Self>> {
        Some(Screening {
            terms: vec![Term::new(
                "ground_thrust",
                "R e3 T / (16 m z²)",
                "1/s²",
                "r² (m²)",
            )],
            perturbations: vec![(
                Self {
                    r_m: SCREENING_RADIUS_M,
                },
                SCREENING_RADIUS_M * SCREENING_RADIUS_M,
            )],
        })
    }
}
