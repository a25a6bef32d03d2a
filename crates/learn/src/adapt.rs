//! Online adaptation on a new flight (equation online_adapt of the paper).
//!
//! Starting from the meta-trained θ, the support segment is visited in time order, `window`
//! consecutive samples per update (1 = the paper's one sample per step), for `passes` passes. Each
//! update takes one gradient step of size `step` on
//!
//! L_adapt = mean over the window of [ (1/I)·‖ẋ_t − f(X_t)‖² + λ·max(0, ‖f(X_t) − f_{t−1}‖₁ − L) ],
//!
//! where f_{t−1} is the prediction made for the previous sample by the parameters of that time, held
//! constant (the paper's f(X_{t−1}; φ_{t−1}, ψ_{t−1})). The first sample of each pass has no
//! predecessor and no regulariser. The squared error is averaged over the I outputs, as in the MSE.
//!
//! With `average_last_pass` (averaged SGD), the result is the mean of the parameters after each
//! update of the last pass rather than the last iterate.

use crate::averaging::IterateMean;
use crate::batched::ModelWorkspace;
use crate::config::AdaptationConfig;
use crate::network::Architecture;

/// Adapts `parameters` online on (inputs, targets), rows in time order; returns the adapted θ.
pub fn adapt_online(
    architecture: &Architecture,
    parameters: &[f64],
    inputs: &[f64],
    targets: &[f64],
    config: &AdaptationConfig,
) -> Vec<f64> {
    let (input_dim, output_dim) = (architecture.input_dim, architecture.state_dim);
    let rows = inputs.len() / input_dim;
    let mut parameters = parameters.to_vec();
    let mut workspace = ModelWorkspace::new(architecture);
    let mut gradient = vec![0.0; parameters.len()];
    let mut prediction_gradient = Vec::with_capacity(config.window.min(rows) * output_dim);
    let mut average = IterateMean::new(parameters.len(), config.average_last_pass);
    for pass in 0..config.passes {
        let last_pass = pass + 1 == config.passes;
        let mut previous: Option<Vec<f64>> = None;
        let mut start = 0;
        while start < rows {
            let end = (start + config.window).min(rows);
            let window_inputs = &inputs[start * input_dim..end * input_dim];
            let window_targets = &targets[start * output_dim..end * output_dim];
            let prediction_all = workspace.forward(&parameters, window_inputs);
            let count = (end - start) as f64;
            prediction_gradient.clear();
            for (row, (prediction, target)) in prediction_all
                .chunks_exact(output_dim)
                .zip(window_targets.chunks_exact(output_dim))
                .enumerate()
            {
                let predecessor = if row == 0 {
                    previous.as_deref()
                } else {
                    Some(&prediction_all[(row - 1) * output_dim..row * output_dim])
                };
                let active = predecessor.is_some_and(|before| {
                    let jump: f64 = prediction
                        .iter()
                        .zip(before)
                        .map(|(a, b)| (a - b).abs())
                        .sum();
                    jump > config.lipschitz_bound
                });
                for (i, (&y, &t)) in prediction.iter().zip(target).enumerate() {
                    let mut g = 2.0 * (y - t) / output_dim as f64;
                    if active && let Some(before) = predecessor {
                        g += config.lipschitz_weight * sign(y - before[i]);
                    }
                    prediction_gradient.push(g / count);
                }
            }
            let last = prediction_all[prediction_all.len() - output_dim..].to_vec();
            workspace.backward(&parameters, &prediction_gradient, &mut gradient);
            for (p, g) in parameters.iter_mut().zip(&gradient) {
                *p -= config.step * g;
            }
            if last_pass {
                average.add(&parameters);
            }
            previous = Some(last);
            start = end;
        }
    }
    average.finish(parameters)
}

/// The subgradient of |x| that is 0 at 0.
fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}
