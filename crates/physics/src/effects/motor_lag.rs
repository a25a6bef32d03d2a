//! `motor_lag`: each actuator follows its command with a first-order lag of time constant
//! `tau_s`.

use serde::{Deserialize, Serialize};

use super::{
    ChannelGroup, Effect, EffectId, EffectKind, InvalidParameter, ParameterValue, Timing, require,
};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotorLag {
    pub tau_s: f64,
}

impl Effect for MotorLag {
    fn id(&self) -> EffectId {
        EffectId::MotorLag
    }

    fn values(&self) -> Vec<(&'static str, ParameterValue)> {
        vec![("tau_s", ParameterValue::Number(self.tau_s))]
    }

    fn check(&self) -> Result<(), InvalidParameter> {
        require(
            self.tau_s.is_finite() && self.tau_s >= 0.0,
            "motor_lag.tau_s",
            "must be a non-negative number",
        )
    }

    fn describe(&self, _gravity_m_s2: f64) -> String {
        format!(
            "Each motor reaches its commanded speed with a first-order lag of time constant {:.1} ms.",
            1000.0 * self.tau_s
        )
    }

    fn timing(&self) -> Option<(Timing, f64)> {
        Some((Timing::ActuatorLag, self.tau_s))
    }
}

impl EffectKind for MotorLag {
    const ID: EffectId = EffectId::MotorLag;
    const NEUTRAL: Self = Self { tau_s: 0.0 };
    const ACTS_ON: ChannelGroup = ChannelGroup::Both;

    fn from_numbers(numbers: &[f64]) -> Self {
        Self { tau_s: numbers[0] }
    }

    /// A lag beyond 0.2 s is not the physics the name stands for.
    fn fit_range(_index: usize) -> (f64, f64) {
        (0.0, 0.2)
    }

    fn typical(_index: usize) -> f64 {
        0.01
    }

    /// 2.5 ms, an eighth of a 50 Hz sample interval: the profile only starts the fit, which then
    /// moves freely within the range.
    fn profile_step(_index: usize) -> Option<f64> {
        Some(0.0025)
    }
}
