//! The names of the effects of the vocabulary ([`crate::Effects`]): one typed id per effect, in the
//! documented order. An id's spelling (`linear_drag`, …) is an output contract: it is the effect's
//! key in every JSON file and what every report prints, so [`EffectId`] serialises, displays and
//! parses as exactly that spelling.

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

/// One effect of the vocabulary (see [`crate::Effects`] for its parameters and physics).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EffectId {
    LinearDrag,
    QuadraticDrag,
    Wind,
    ThrustScale,
    MotorLag,
    GroundEffect,
    TorqueBias,
    InertiaScale,
    Delay,
    ThrustMap,
    ThrustTilt,
    RotorDrag,
    TranslationalLift,
    DragLag,
    WindGradient,
}

impl EffectId {
    /// Every effect, in the documented order.
    pub const ALL: [EffectId; 15] = [
        Self::LinearDrag,
        Self::QuadraticDrag,
        Self::Wind,
        Self::ThrustScale,
        Self::MotorLag,
        Self::GroundEffect,
        Self::TorqueBias,
        Self::InertiaScale,
        Self::Delay,
        Self::ThrustMap,
        Self::ThrustTilt,
        Self::RotorDrag,
        Self::TranslationalLift,
        Self::DragLag,
        Self::WindGradient,
    ];

    /// The id as files and reports spell it (`linear_drag`).
    pub const fn name(self) -> &'static str {
        match self {
            Self::LinearDrag => "linear_drag",
            Self::QuadraticDrag => "quadratic_drag",
            Self::Wind => "wind",
            Self::ThrustScale => "thrust_scale",
            Self::MotorLag => "motor_lag",
            Self::GroundEffect => "ground_effect",
            Self::TorqueBias => "torque_bias",
            Self::InertiaScale => "inertia_scale",
            Self::Delay => "delay",
            Self::ThrustMap => "thrust_map",
            Self::ThrustTilt => "thrust_tilt",
            Self::RotorDrag => "rotor_drag",
            Self::TranslationalLift => "translational_lift",
            Self::DragLag => "drag_lag",
            Self::WindGradient => "wind_gradient",
        }
    }

    /// The effect spelled `text`; the error lists every known id.
    pub fn parse(text: &str) -> Result<Self, UnknownEffectId> {
        Self::ALL
            .into_iter()
            .find(|id| id.name() == text)
            .ok_or_else(|| UnknownEffectId {
                given: text.to_string(),
            })
    }
}

impl fmt::Display for EffectId {
    /// The name; width and alignment (`{:<20}`) apply as to a string.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.pad(self.name())
    }
}

impl FromStr for EffectId {
    type Err = UnknownEffectId;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        Self::parse(text)
    }
}

/// A name that is not an effect id.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("unknown effect id {given:?}; the known ids are {}", known_ids())]
pub struct UnknownEffectId {
    pub given: String,
}

/// Every id, in order, separated by commas.
fn known_ids() -> String {
    EffectId::ALL.map(EffectId::name).join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The serialised, displayed and parsed spellings are one and the same.
    #[test]
    fn every_id_reads_back_as_it_is_written() {
        for id in EffectId::ALL {
            assert_eq!(
                serde_json::to_string(&id).unwrap(),
                format!("\"{}\"", id.name())
            );
            assert_eq!(
                serde_json::from_str::<EffectId>(&format!("\"{id}\"")).unwrap(),
                id
            );
            assert_eq!(id.to_string(), id.name());
            assert_eq!(id.name().parse::<EffectId>(), Ok(id));
        }
        assert_eq!(format!("[{:<8}]", EffectId::Wind), "[wind    ]");
    }

    #[test]
    fn an_unknown_id_is_an_error_listing_the_known_ones() {
        let error = "drag".parse::<EffectId>().unwrap_err();
        assert_eq!(error.given, "drag");
        let message = error.to_string();
        assert!(
            message.starts_with("unknown effect id \"drag\";"),
            "{message}"
        );
        for id in EffectId::ALL {
            assert!(message.contains(id.name()), "{message}");
        }
        assert!(EffectId::parse("Wind").is_err() && EffectId::parse("").is_err());
    }
}
