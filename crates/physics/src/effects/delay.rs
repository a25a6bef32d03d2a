//! `delay`: the vehicle responds to its commands `delay_s` late.

use serde::{Deserialize, Serialize};

use super::{
    ChannelGroup, Effect, EffectId, EffectKind, InvalidParameter, ParameterValue, Screening, Term,
    Timing, require,
};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Delay {
    pub delay_s: f64,
}

impl Effect for Delay {
    fn id(&self) -> EffectId {
        EffectId::Delay
    }

    fn values(&self) -> Vec<(&'static str, ParameterValue)> {
        vec![("delay_s", ParameterValue::Number(self.delay_s))]
    }

    fn check(&self) -> Result<(), InvalidParameter> {
        require(
            self.delay_s.is_finite() && self.delay_s >= 0.0,
            "delay.delay_s",
            "must be a non-negative number",
        )
    }

    fn describe(&self, _gravity_m_s2: f64) -> String {
        format!(
            "The vehicle responds to its commands {:.1} ms late.",
            1000.0 * self.delay_s
        )
    }

    fn timing(&self) -> Option<(Timing, f64)> {
        Some((Timing::CommandDelay, self.delay_s))
    }
}

impl EffectKind for Delay {
    const ID: EffectId = EffectId::Delay;
    const NEUTRAL: Self = Self { delay_s: 0.0 };
    const ACTS_ON: ChannelGroup = ChannelGroup::Both;

    fn from_numbers(numbers: &[f64]) -> Self {
        Self {
            delay_s: numbers[0],
        }
    }

    /// A delay beyond 0.3 s is not the actuator delay the name stands for.
    fn fit_range(_index: usize) -> (f64, f64) {
        (0.0, 0.3)
    }

    fn typical(_index: usize) -> f64 {
        0.01
    }

    /// 2.5 ms, an eighth of a 50 Hz sample interval: the profile only starts the fit, which then
    /// moves freely within the range.
    fn profile_step(_index: usize) -> Option<f64> {
        Some(0.0025)
    }

    /// The first-order timing signature a delay shares with a motor lag: the command's rate,
    /// perturbed by a quarter of the sample interval.
    fn screening(sample_interval_s: f64) -> Option<Screening<Self>> {
        let step = sample_interval_s / 4.0;
        Some(Screening {
            terms: vec![Term::new(
                "command_rate",
                "−d/dt (R e3 T / m, J⁻¹ τ)",
                "m/s³, rad/s³",
                "delay or lag time constant (s)",
            )],
            perturbations: vec![(Self { delay_s: step }, step)],
        })
    }

    fn fit_starts() -> Vec<Vec<f64>> {
        vec![vec![0.04], vec![0.1], vec![0.16]]
    }
}
