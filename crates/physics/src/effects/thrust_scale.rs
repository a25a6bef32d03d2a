//! `thrust_scale`: the rotors produce `k` times the thrust the model assumes: `T_real = k T`.

use serde::{Deserialize, Serialize};

use super::{
    ChannelGroup, Effect, EffectId, EffectKind, InvalidParameter, ParameterValue, SCREENING_STEP,
    Screening, Term, require,
};
use crate::vector::Vec3;

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ThrustScale {
    pub k: f64,
}

impl Effect for ThrustScale {
    fn id(&self) -> EffectId {
        EffectId::ThrustScale
    }

    fn values(&self) -> Vec<(&'static str, ParameterValue)> {
        vec![("k", ParameterValue::Number(self.k))]
    }

    fn check(&self) -> Result<(), InvalidParameter> {
        require(
            self.k.is_finite() && self.k > 0.0,
            "thrust_scale.k",
            "must be a positive number",
        )
    }

    fn describe(&self, _gravity_m_s2: f64) -> String {
        format!(
            "The rotors produce {:.3} times the thrust the model assumes ({:+.1}%).",
            self.k,
            100.0 * (self.k - 1.0)
        )
    }

    fn thrust_gain(&self, _height_above_ground: f64, _air_body: Vec3) -> Option<f64> {
        Some(self.k)
    }
}

impl EffectKind for ThrustScale {
    const ID: EffectId = EffectId::ThrustScale;
    const NEUTRAL: Self = Self { k: 1.0 };
    const ACTS_ON: ChannelGroup = ChannelGroup::Translational;
    const FACTOR: bool = true;

    fn from_numbers(numbers: &[f64]) -> Self {
        Self { k: numbers[0] }
    }

    fn fit_range(_index: usize) -> (f64, f64) {
        (0.05, f64::INFINITY)
    }

    fn screening(_sample_interval_s: f64) -> Option<Screening<Self>> {
        Some(Screening {
            terms: vec![Term::new("thrust", "R e3 T / m", "m/s²", "k − 1 (1)")],
            perturbations: vec![(
                Self {
                    k: 1.0 + SCREENING_STEP,
                },
                SCREENING_STEP,
            )],
        })
    }
}
