//! Interpretability as the paper defines it: which input features dominate each output through the
//! feature-selection matrix ℰ, and an equation in the form `v̇x = 1.64·m1(v_x) + 0.24·m2(u_z)`.
//!
//! For output i and basis index k = j·P + p (basis function m_{p+1} attached to input feature j),
//! the coefficient ℰ_{ik}(X) varies with X; we report its mean and mean absolute value over the rows
//! of a flight. The importance of input feature j for output i is Σ_p mean|ℰ_{i,(j,p)}|. The equation
//! keeps the terms whose mean |coefficient| is at least `relative_threshold` of the largest one (at
//! most `max_terms`), each with its signed mean coefficient. As the paper says, this identifies
//! dominant inputs; it is not a closed form of m_p, which takes the whole X.

use crate::formulation::Formulation;
use serde::{Deserialize, Serialize};

use crate::network::Architecture;

/// One term m_p(x_j) of an output.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Term {
    /// p, 1-based: m1, m2, …
    pub basis: usize,
    /// The input feature x_j the term is attached to.
    pub input: String,
    /// Mean of ℰ_{i,(j,p)} over the flight.
    pub mean_coefficient: f64,
    /// Mean of |ℰ_{i,(j,p)}| over the flight.
    pub mean_abs_coefficient: f64,
}

/// Importance of one input feature for one output.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct InputImportance {
    pub input: String,
    /// Σ_p mean |ℰ_{i,(j,p)}|.
    pub mean_abs_coefficient: f64,
}

/// The explanation of one output.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct OutputExplanation {
    /// The target's column name, e.g. `vdot_x`.
    pub output: String,
    /// Inputs by decreasing importance.
    pub inputs: Vec<InputImportance>,
    /// The terms of the equation, by decreasing mean |coefficient|.
    pub terms: Vec<Term>,
    /// E.g. `v̇x = 1.64·m1(v_x) + 0.24·m2(u_z)`.
    pub equation: String,
}

/// The explanation of every output of a model over a flight or recording.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Explanation {
    /// The formulation of a flight model (absent for a model of CSV tasks).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub formulation: Option<Formulation>,
    /// Rows the statistics are taken over.
    pub samples: usize,
    pub outputs: Vec<OutputExplanation>,
}

/// Which terms make it into the equation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EquationRule {
    pub max_terms: usize,
    pub relative_threshold: f64,
}

impl Default for EquationRule {
    fn default() -> Self {
        Self {
            max_terms: 3,
            relative_threshold: 0.2,
        }
    }
}

/// Explains `parameters` of a flight model of `formulation` over `inputs` (standardised,
/// rows × (I+U), row-major).
pub fn explain(
    formulation: Formulation,
    architecture: &Architecture,
    parameters: &[f64],
    inputs: &[f64],
    rule: EquationRule,
) -> Explanation {
    let names = ModelNames {
        inputs: formulation
            .input_names()
            .into_iter()
            .map(str::to_string)
            .collect(),
        outputs: formulation.target_names(),
        output_scale: None,
    };
    Explanation {
        formulation: Some(formulation),
        ..explain_named(&names, architecture, parameters, inputs, rule)
    }
}

/// The names of a model's inputs and outputs, and the factor its outputs are multiplied by.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelNames {
    pub inputs: Vec<String>,
    pub outputs: Vec<String>,
    /// Per output (`None`: 1): the coefficients are reported multiplied by it, in the units of
    /// the targets.
    pub output_scale: Option<Vec<f64>>,
}

/// [`explain`] for any named inputs and outputs (a model of CSV tasks).
pub fn explain_named(
    names: &ModelNames,
    architecture: &Architecture,
    parameters: &[f64],
    inputs: &[f64],
    rule: EquationRule,
) -> Explanation {
    let (_, selection) = architecture.library_and_selection(parameters, inputs);
    let basis = architecture.basis_count();
    let per_input = architecture.basis_per_input;
    let width = architecture.state_dim * basis;
    let rows = selection.len() / width;
    let input_names = &names.inputs;
    let outputs = names
        .outputs
        .iter()
        .cloned()
        .enumerate()
        .map(|(state, output)| {
            let scale = names.output_scale.as_ref().map_or(1.0, |s| s[state]);
            let mut mean = vec![0.0; basis];
            let mut mean_abs = vec![0.0; basis];
            for row in selection.chunks_exact(width) {
                for (k, &e) in row[state * basis..(state + 1) * basis].iter().enumerate() {
                    mean[k] += scale * e / rows as f64;
                    mean_abs[k] += scale * e.abs() / rows as f64;
                }
            }
            let mut terms: Vec<Term> = (0..basis)
                .map(|k| Term {
                    basis: k % per_input + 1,
                    input: input_names[k / per_input].to_string(),
                    mean_coefficient: mean[k],
                    mean_abs_coefficient: mean_abs[k],
                })
                .collect();
            terms.sort_by(|a, b| b.mean_abs_coefficient.total_cmp(&a.mean_abs_coefficient));
            let mut inputs: Vec<InputImportance> = input_names
                .iter()
                .enumerate()
                .map(|(j, name)| InputImportance {
                    input: name.to_string(),
                    mean_abs_coefficient: mean_abs[j * per_input..(j + 1) * per_input].iter().sum(),
                })
                .collect();
            inputs.sort_by(|a, b| b.mean_abs_coefficient.total_cmp(&a.mean_abs_coefficient));
            let largest = terms.first().map_or(0.0, |t| t.mean_abs_coefficient);
            terms.retain(|t| t.mean_abs_coefficient >= rule.relative_threshold * largest);
            terms.truncate(rule.max_terms);
            let equation = equation(&output, &terms);
            OutputExplanation {
                output,
                inputs,
                terms,
                equation,
            }
        })
        .collect();
    Explanation {
        formulation: None,
        samples: rows,
        outputs,
    }
}

/// `vdot_x` → `v̇x`, `wdot_z` → `ω̇z`.
pub fn output_symbol(output: &str) -> String {
    match output.split_once("dot_") {
        Some(("v", axis)) => format!("v\u{307}{axis}"),
        Some(("w", axis)) => format!("ω\u{307}{axis}"),
        Some((state, axis)) => format!("{state}\u{307}{axis}"),
        None => output.to_string(),
    }
}

fn equation(output: &str, terms: &[Term]) -> String {
    let mut text = format!("{} =", output_symbol(output));
    for (n, term) in terms.iter().enumerate() {
        let c = term.mean_coefficient;
        let sign = match (n, c < 0.0) {
            (0, false) => " ",
            (0, true) => " −",
            (_, false) => " + ",
            (_, true) => " − ",
        };
        text.push_str(&format!(
            "{sign}{:.2}·m{}({})",
            c.abs(),
            term.basis,
            term.input
        ));
    }
    if terms.is_empty() {
        text.push_str(" 0");
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equations_read_like_the_paper() {
        let terms = vec![
            Term {
                basis: 1,
                input: "v_x".into(),
                mean_coefficient: 1.64,
                mean_abs_coefficient: 1.64,
            },
            Term {
                basis: 2,
                input: "u_z".into(),
                mean_coefficient: -0.24,
                mean_abs_coefficient: 0.3,
            },
        ];
        assert_eq!(
            equation("vdot_x", &terms),
            "v̇x = 1.64·m1(v_x) − 0.24·m2(u_z)"
        );
        assert_eq!(output_symbol("wdot_z"), "ω̇z");
    }
}
