//! The networks of a formulation of the flight logs.

use data::Formulation;

use crate::config::LearnConfig;
use crate::network::Architecture;

/// The architecture of `formulation` under `config`.
pub fn architecture(formulation: Formulation, config: &LearnConfig) -> Architecture {
    Architecture {
        input_dim: formulation.input_names().len(),
        state_dim: formulation.state_dim(),
        basis_per_input: config.basis_per_input,
        hidden: config.hidden_layers.clone(),
    }
}
