//! `inertia_scale`: the moments of inertia are `k` times the model's: `J_real = diag(k) J`.

use serde::{Deserialize, Serialize};

use super::{
    AXES, ChannelGroup, Effect, EffectId, EffectKind, InvalidParameter, ParameterValue,
    SCREENING_STEP, Screening, Term, require, vec3,
};
use crate::vector::{Vec3, hadamard};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InertiaScale {
    pub k: Vec3,
}

impl Effect for InertiaScale {
    fn id(&self) -> EffectId {
        EffectId::InertiaScale
    }

    fn values(&self) -> Vec<(&'static str, ParameterValue)> {
        vec![("k", ParameterValue::Vector(self.k.to_vec()))]
    }

    fn check(&self) -> Result<(), InvalidParameter> {
        require(
            self.k.iter().all(|x| x.is_finite() && *x > 0.0),
            "inertia_scale.k",
            "must be three positive numbers",
        )
    }

    fn describe(&self, _gravity_m_s2: f64) -> String {
        let k = self.k;
        format!(
            "The moments of inertia are [{:.3}, {:.3}, {:.3}] times the model's.",
            k[0], k[1], k[2]
        )
    }

    fn inertia(&self, inertia: Vec3) -> Vec3 {
        hadamard(self.k, inertia)
    }
}

impl EffectKind for InertiaScale {
    const ID: EffectId = EffectId::InertiaScale;
    const NEUTRAL: Self = Self { k: [1.0; 3] };
    const ACTS_ON: ChannelGroup = ChannelGroup::Angular;
    const FACTOR: bool = true;

    fn from_numbers(numbers: &[f64]) -> Self {
        Self { k: vec3(numbers) }
    }

    fn fit_range(_index: usize) -> (f64, f64) {
        (0.05, f64::INFINITY)
    }

    fn screening(_sample_interval_s: f64) -> Option<Screening<Self>> {
        let terms = AXES
            .iter()
            .map(|a| {
                Term::new(
                    &format!("torque_response_{a}"),
                    &format!("e_{a} e_{a}ᵀ J⁻¹ (τ − ω × J ω)"),
                    "rad/s²",
                    &format!("1/k{a} − 1 (1)"),
                )
            })
            .collect();
        let perturbations = (0..3)
            .map(|i| {
                let mut k = [1.0; 3];
                k[i] = 1.0 / (1.0 + SCREENING_STEP);
                (Self { k }, SCREENING_STEP)
            })
            .collect();
        Some(Screening {
            terms,
            perturbations,
        })
    }
}
