//! `quadratic_drag`: aerodynamic drag growing with the square of the airspeed:
//! `a = −c |v − w_air| (v − w_air)`, `c` in 1/m.

use serde::{Deserialize, Serialize};

use super::{
    ChannelGroup, Effect, EffectId, EffectKind, InvalidParameter, ParameterValue, Screening, Term,
    require,
};
use crate::vector::{Mat3, Vec3, norm, scale};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct QuadraticDrag {
    pub c: f64,
}

impl Effect for QuadraticDrag {
    fn id(&self) -> EffectId {
        EffectId::QuadraticDrag
    }

    fn values(&self) -> Vec<(&'static str, ParameterValue)> {
        vec![("c", ParameterValue::Number(self.c))]
    }

    fn check(&self) -> Result<(), InvalidParameter> {
        require(
            self.c.is_finite() && self.c >= 0.0,
            "quadratic_drag.c",
            "must be a finite non-negative number",
        )
    }

    fn describe(&self, _gravity_m_s2: f64) -> String {
        format!(
            "Aerodynamic drag growing with the square of the airspeed, c = {:.4} 1/m (at 5 m/s airspeed about {:.2} m/s²).",
            self.c,
            25.0 * self.c
        )
    }

    fn air_drag(&self, _rotation: &Mat3, relative: Vec3) -> Option<Vec3> {
        Some(scale(relative, self.c * norm(relative)))
    }
}

impl EffectKind for QuadraticDrag {
    const ID: EffectId = EffectId::QuadraticDrag;
    const NEUTRAL: Self = Self { c: 0.0 };
    const ACTS_ON: ChannelGroup = ChannelGroup::Translational;

    fn from_numbers(numbers: &[f64]) -> Self {
        Self { c: numbers[0] }
    }

    fn fit_range(_index: usize) -> (f64, f64) {
        (0.0, f64::INFINITY)
    }

    fn typical(_index: usize) -> f64 {
        0.01
    }

    fn screening(_sample_interval_s: f64) -> Option<Screening<Self>> {
        Some(Screening {
            terms: vec![Term::new("air_drag", "−|v| v", "m²/s²", "c (1/m)")],
            perturbations: vec![(Self { c: 1.0 }, 1.0)],
        })
    }

    fn fit_starts() -> Vec<Vec<f64>> {
        vec![vec![0.02]]
    }
}
