//! The meta-trained LeARN networks as a feature library, for closed-form adaptation and hybrid
//! libraries (fitted elsewhere, e.g. by `sindy`'s regressions).
//!
//! Instead of SGD steps on θ, closed-form adaptation keeps the networks frozen and fits linear
//! coefficients over their outputs on the support segment (as Neural-Fly adapts its coefficients
//! over a learned basis): ẋ_i ≈ b_i + Σ_k c_ik·f_k(X), with f either
//! - [`LearnedFeatures::Basis`]: the K learned basis functions Θ_k(X; ψ) (names `m{p}[{input}]`,
//!   basis k = j·P + p attached to input j), or
//! - [`LearnedFeatures::Terms`]: the I·K products Θ_k(X; ψ)·ℰ_ik(X; φ) whose sum over k is the
//!   network's prediction of output i (names `{output}:m{p}[{input}]`), so c_ik = 1 reproduces the
//!   meta-trained model.

use faer::Mat;
use serde::{Deserialize, Serialize};

use crate::model::MetaTrainedModel;
use crate::standardiser::row_major;

/// Which network outputs become features.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LearnedFeatures {
    Basis,
    Terms,
}

/// The learned features of every sample of raw `inputs` X = [x, u] (one row per sample, as the
/// model's inputs), one row per sample, and their names.
pub fn learned_features(
    model: &MetaTrainedModel,
    inputs: &Mat<f64>,
    features: LearnedFeatures,
) -> (Mat<f64>, Vec<String>) {
    let architecture = &model.architecture;
    let standardised = model.standardiser.apply(&row_major(inputs));
    let (library, selection) = architecture.library_and_selection(&model.parameters, &standardised);
    let (n, k, states) = (
        inputs.nrows(),
        architecture.basis_count(),
        architecture.state_dim,
    );
    let input_names = model.input_names();
    let basis_names: Vec<String> = (0..k)
        .map(|index| {
            let (input, p) = (
                index / architecture.basis_per_input,
                index % architecture.basis_per_input,
            );
            format!("m{}[{}]", p + 1, input_names[input])
        })
        .collect();
    match features {
        LearnedFeatures::Basis => (Mat::from_fn(n, k, |i, j| library[i * k + j]), basis_names),
        LearnedFeatures::Terms => {
            let outputs = model.output_names();
            let names = outputs
                .iter()
                .flat_map(|o| basis_names.iter().map(move |b| format!("{o}:{b}")))
                .collect();
            let theta = Mat::from_fn(n, states * k, |i, column| {
                let (output, basis) = (column / k, column % k);
                library[i * k + basis] * selection[i * states * k + output * k + basis]
            });
            (theta, names)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::formulation::Formulation;
    use crate::network::Architecture;
    use crate::standardiser::Standardiser;

    #[test]
    fn terms_sum_to_the_network_prediction() {
        let formulation = Formulation::Attitude;
        let architecture = Architecture {
            input_dim: 7,
            state_dim: 3,
            basis_per_input: 2,
            hidden: vec![5, 4],
        };
        let parameters = architecture.initial_parameters(3);
        let n = 9;
        // Three states, then four controls.
        let inputs = Mat::from_fn(n, 7, |i, j| {
            if j < 3 {
                (i as f64 * 0.3 + j as f64).sin()
            } else {
                1.0 + 0.1 * (i as f64 - (j - 3) as f64).cos()
            }
        });
        let model = MetaTrainedModel {
            format: crate::model::CHECKPOINT_FORMAT.to_string(),
            trained_on: crate::model::TrainedOn::Flights(crate::model::FlightTraining {
                formulation,
                protocol: "leave-condition-out".to_string(),
                held_out_condition: None,
            }),
            seed: 3,
            config: serde_json::from_str(include_str!("../../../experiments/learn.json")).unwrap(),
            architecture: architecture.clone(),
            standardiser: Standardiser::identity(7),
            parameters: parameters.clone(),
            data_files: Vec::new(),
            meta_loss_history: Vec::new(),
        };
        let (terms, names) = learned_features(&model, &inputs, LearnedFeatures::Terms);
        assert_eq!(terms.ncols(), 3 * 14);
        assert_eq!(names[15], "wdot_y:m2[w_x]");
        let prediction = model.predict(&row_major(&inputs));
        for i in 0..n {
            for output in 0..3 {
                let sum: f64 = (0..14).map(|b| terms[(i, output * 14 + b)]).sum();
                assert!((sum - prediction[i * 3 + output]).abs() < 1e-12);
            }
        }
        let (basis, _) = learned_features(&model, &inputs, LearnedFeatures::Basis);
        assert_eq!(basis.ncols(), 14);
    }
}
