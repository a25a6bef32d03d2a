//! `drag_lag`: the velocity the air terms (drags, lift) see lags the vehicle's by a first-order
//! lag of time constant `tau_s` (the wake and inflow take time to build up).

use serde::{Deserialize, Serialize};

use super::{
    ChannelGroup, Effect, EffectId, EffectKind, InvalidParameter, ParameterValue, Timing, require,
};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DragLag {
    pub tau_s: f64,
}

impl Effect for DragLag {
    fn id(&self) -> EffectId {
        EffectId::DragLag
    }

    fn values(&self) -> Vec<(&'static str, ParameterValue)> {
        vec![("tau_s", ParameterValue::Number(self.tau_s))]
    }

    fn check(&self) -> Result<(), InvalidParameter> {
        require(
            self.tau_s.is_finite() && self.tau_s >= 0.0,
            "drag_lag.tau_s",
            "must be a non-negative number",
        )
    }

    fn describe(&self, _gravity_m_s2: f64) -> String {
        format!(
            "The air forces follow the velocity with a first-order lag of {:.2} s (the wake and inflow take time to build up).",
            self.tau_s
        )
    }

    fn timing(&self) -> Option<(Timing, f64)> {
        Some((Timing::AirLag, self.tau_s))
    }
}

impl EffectKind for DragLag {
    const ID: EffectId = EffectId::DragLag;
    const NEUTRAL: Self = Self { tau_s: 0.0 };
    const ACTS_ON: ChannelGroup = ChannelGroup::Translational;

    fn from_numbers(numbers: &[f64]) -> Self {
        Self { tau_s: numbers[0] }
    }

    fn fit_range(_index: usize) -> (f64, f64) {
        (0.0, 2.0)
    }

    fn typical(_index: usize) -> f64 {
        0.01
    }

    fn fit_starts() -> Vec<Vec<f64>> {
        vec![vec![0.1], vec![0.3], vec![0.6]]
    }
}
