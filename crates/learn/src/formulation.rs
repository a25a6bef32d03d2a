//! The paper's three formulations as a model of the flights sees them: which states x are
//! identified from which inputs X = [x, u], and the networks of each ([`architecture`]). A flight
//! checkpoint records its formulation; how its columns are built from a flight log (which log
//! columns, with which scalings) is the `evaluation` crate's.
//!
//! | formulation | state x (I) | control u (U) | target |
//! |---|---|---|---|
//! | `Translational` | v (3) | R·[0, 0, T], T = raw `T_sp` (3) | v̇ |
//! | `Attitude` | ω (3) | motor speeds nᵢ = pwmᵢ/1000 (4) | ω̇ |
//! | `Full` | [v; ω] (6) | squared speeds nᵢ² = (pwmᵢ/1000)² (4) | [v̇; ω̇] |

use serde::{Deserialize, Serialize};

use crate::config::LearnConfig;
use crate::error::{LearnError, Result};
use crate::network::Architecture;

/// Which part of the quadrotor dynamics is identified.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Formulation {
    Translational,
    Attitude,
    Full,
}

const VELOCITY: [&str; 3] = ["v_x", "v_y", "v_z"];
const RATE: [&str; 3] = ["w_x", "w_y", "w_z"];
const THRUST_VECTOR: [&str; 3] = ["u_x", "u_y", "u_z"];
const MOTOR_SPEED: [&str; 4] = ["n_1", "n_2", "n_3", "n_4"];
const MOTOR_SPEED_SQUARED: [&str; 4] = ["n_1_sq", "n_2_sq", "n_3_sq", "n_4_sq"];

impl Formulation {
    /// The three formulations in the paper's order.
    pub const ALL: [Formulation; 3] = [Self::Translational, Self::Attitude, Self::Full];

    /// The lower-case name used in files and on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Translational => "translational",
            Self::Attitude => "attitude",
            Self::Full => "full",
        }
    }

    /// Parses a name as written by [`Formulation::name`].
    pub fn parse(name: &str) -> Result<Self> {
        Self::ALL
            .into_iter()
            .find(|f| f.name() == name)
            .ok_or_else(|| LearnError::UnknownFormulation {
                name: name.to_string(),
            })
    }

    /// Names of the state variables x.
    pub fn state_names(&self) -> Vec<&'static str> {
        match self {
            Self::Translational => VELOCITY.to_vec(),
            Self::Attitude => RATE.to_vec(),
            Self::Full => VELOCITY.iter().chain(&RATE).copied().collect(),
        }
    }

    /// Names of the control inputs u.
    pub fn control_names(&self) -> Vec<&'static str> {
        match self {
            Self::Translational => THRUST_VECTOR.to_vec(),
            Self::Attitude => MOTOR_SPEED.to_vec(),
            Self::Full => MOTOR_SPEED_SQUARED.to_vec(),
        }
    }

    /// Names of X = [x, u], the inputs of the identified models.
    pub fn input_names(&self) -> Vec<&'static str> {
        let mut names = self.state_names();
        names.extend(self.control_names());
        names
    }

    /// Names of the targets ẋ, as `vdot_x` … `wdot_z`.
    pub fn target_names(&self) -> Vec<String> {
        self.state_names()
            .iter()
            .map(|s| s.replacen('_', "dot_", 1))
            .collect()
    }

    /// Number of states I.
    pub fn state_dim(&self) -> usize {
        self.state_names().len()
    }

    /// Number of controls U.
    pub fn control_dim(&self) -> usize {
        self.control_names().len()
    }
}

/// The architecture of `formulation` under `config`.
pub fn architecture(formulation: Formulation, config: &LearnConfig) -> Architecture {
    Architecture {
        input_dim: formulation.input_names().len(),
        state_dim: formulation.state_dim(),
        basis_per_input: config.basis_per_input,
        hidden: config.hidden_layers.clone(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_consistent() {
        assert_eq!(Formulation::Full.input_names().len(), 10);
        assert_eq!(
            Formulation::Attitude.target_names(),
            vec!["wdot_x", "wdot_y", "wdot_z"]
        );
        assert_eq!(Formulation::parse("full").unwrap(), Formulation::Full);
        let error = Formulation::parse("rotational").unwrap_err().to_string();
        assert_eq!(
            error,
            "unknown formulation 'rotational' (known: translational, attitude, full)"
        );
    }
}
