//! The LeARN model: two fully connected GELU networks and their product.
//!
//! - the library Θ(X; ψ): X ∈ ℝ^{I+U} ↦ K = P·(I+U) learned basis-function values;
//! - the selection ℰ(X; φ): X ↦ I·K values, read row-major as the I×K feature-selection matrix;
//! - the prediction y = Θ(X; ψ)·ℰ(X; φ)ᵀ ∈ ℝ^I, one value per state derivative.
//!
//! Basis index k = j·P + p stands for "basis function m_{p+1} attached to input feature j" (the
//! analogue of SINDy's sin(x_j), cos(x_j) for P = 2). Parameters are one flat vector θ = [ψ; φ]; each
//! layer stores its weights row-major (fan-in × fan-out) followed by its biases. The public passes run
//! on the batched hot path ([`crate::ModelWorkspace`]); the generic passes here (over [`Scalar`]: gradients
//! in `f64`, Hessian-vector products on [`Dual`] numbers) are the reference they are tested against.
//!
//! [`Dual`]: crate::Dual

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::batched::ModelWorkspace;
use crate::scalar::Scalar;

/// Layer sizes of both networks and the dimensions of the problem.
///
/// Θ(X; ψ) maps X ∈ ℝ^{I+U} to K = P·(I+U) basis values, ℰ(X; φ) to I·K values read row-major as
/// the I×K selection matrix, and y = Θ·ℰᵀ. Basis index k = j·P + p is m_{p+1} attached to input j.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Architecture {
    /// Number of inputs I + U.
    pub input_dim: usize,
    /// Number of states I (= outputs).
    pub state_dim: usize,
    /// Learned basis functions per input feature, P.
    pub basis_per_input: usize,
    /// Hidden layer widths, the paper's [12, 16, 24, 48].
    pub hidden: Vec<usize>,
}

/// The paper's hidden layer widths.
pub const PAPER_HIDDEN: [usize; 4] = [12, 16, 24, 48];

impl Architecture {
    /// Number of learned basis functions K = P·(I+U).
    pub fn basis_count(&self) -> usize {
        self.basis_per_input * self.input_dim
    }

    /// Layer sizes of Θ: [I+U, hidden…, K].
    pub fn library_sizes(&self) -> Vec<usize> {
        self.sizes(self.basis_count())
    }

    /// Layer sizes of ℰ: [I+U, hidden…, I·K].
    pub fn selection_sizes(&self) -> Vec<usize> {
        self.sizes(self.state_dim * self.basis_count())
    }

    fn sizes(&self, output: usize) -> Vec<usize> {
        let mut sizes = vec![self.input_dim];
        sizes.extend(&self.hidden);
        sizes.push(output);
        sizes
    }

    /// Number of parameters of Θ (ψ), which come first in θ.
    pub fn library_parameter_count(&self) -> usize {
        mlp_parameter_count(&self.library_sizes())
    }

    /// Total number of parameters |θ| = |ψ| + |φ|.
    pub fn parameter_count(&self) -> usize {
        self.library_parameter_count() + mlp_parameter_count(&self.selection_sizes())
    }

    /// PyTorch's default `Linear` initialisation, U(−1/√fan_in, 1/√fan_in) for weights and biases,
    /// drawn from ChaCha8 seeded with `seed`.
    pub fn initial_parameters(&self, seed: u64) -> Vec<f64> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut parameters = Vec::with_capacity(self.parameter_count());
        for sizes in [self.library_sizes(), self.selection_sizes()] {
            for layer in sizes.windows(2) {
                let bound = 1.0 / (layer[0] as f64).sqrt();
                for _ in 0..(layer[0] + 1) * layer[1] {
                    parameters.push(rng.random_range(-bound..bound));
                }
            }
        }
        parameters
    }
}

fn mlp_parameter_count(sizes: &[usize]) -> usize {
    sizes.windows(2).map(|l| (l[0] + 1) * l[1]).sum()
}

/// Intermediate values of one network on a batch, kept for the backward pass.
struct MlpTape<T> {
    /// h_0 (the input), h_1, …, h_{L−1}: the inputs of each layer.
    layer_inputs: Vec<Vec<T>>,
    /// GELU′(z) of the hidden layers' pre-activations z_0 … z_{L−2}.
    activation_derivatives: Vec<Vec<T>>,
    /// The (linear) output, batch × last size.
    output: Vec<T>,
}

#[inline(always)]
fn mlp_forward<T: Scalar>(
    sizes: &[usize],
    parameters: &[T],
    input: Vec<T>,
    batch: usize,
) -> MlpTape<T> {
    let layers = sizes.len() - 1;
    let mut layer_inputs = Vec::with_capacity(layers);
    let mut activation_derivatives = Vec::with_capacity(layers - 1);
    let mut current = input;
    let mut offset = 0;
    for layer in 0..layers {
        let (fan_in, fan_out) = (sizes[layer], sizes[layer + 1]);
        let weights = &parameters[offset..offset + fan_in * fan_out];
        let biases = &parameters[offset + fan_in * fan_out..offset + (fan_in + 1) * fan_out];
        offset += (fan_in + 1) * fan_out;
        let mut z = Vec::with_capacity(batch * fan_out);
        for row in current.chunks_exact(fan_in) {
            let start = z.len();
            z.extend_from_slice(biases);
            let out = &mut z[start..];
            for (i, &h) in row.iter().enumerate() {
                let weight_row = &weights[i * fan_out..(i + 1) * fan_out];
                for (o, &w) in out.iter_mut().zip(weight_row) {
                    *o += h * w;
                }
            }
        }
        layer_inputs.push(current);
        if layer + 1 == layers {
            return MlpTape {
                layer_inputs,
                activation_derivatives,
                output: z,
            };
        }
        let mut derivatives = Vec::with_capacity(z.len());
        current = z
            .iter()
            .map(|&v| {
                let (value, derivative) = v.gelu_and_derivative();
                derivatives.push(derivative);
                value
            })
            .collect();
        activation_derivatives.push(derivatives);
    }
    unreachable!("a network has at least one layer")
}

/// Σ a_i·b_i with four independent partial sums (so that the loop pipelines and vectorises).
#[inline(always)]
fn dot<T: Scalar>(a: &[T], b: &[T]) -> T {
    let mut partial = [T::default(); 4];
    let (a_chunks, b_chunks) = (a.chunks_exact(4), b.chunks_exact(4));
    let (a_rest, b_rest) = (a_chunks.remainder(), b_chunks.remainder());
    for (x, y) in a_chunks.zip(b_chunks) {
        for lane in 0..4 {
            partial[lane] += x[lane] * y[lane];
        }
    }
    let mut sum = (partial[0] + partial[1]) + (partial[2] + partial[3]);
    for (&x, &y) in a_rest.iter().zip(b_rest) {
        sum += x * y;
    }
    sum
}

/// Accumulates the parameter gradient of one network into `gradient`, given dL/d(output).
#[inline(always)]
fn mlp_backward<T: Scalar>(
    sizes: &[usize],
    parameters: &[T],
    tape: &MlpTape<T>,
    output_gradient: Vec<T>,
    gradient: &mut [T],
) {
    let layers = sizes.len() - 1;
    let mut offsets = Vec::with_capacity(layers);
    let mut offset = 0;
    for layer in sizes.windows(2) {
        offsets.push(offset);
        offset += (layer[0] + 1) * layer[1];
    }
    let mut delta = output_gradient;
    for layer in (0..layers).rev() {
        let (fan_in, fan_out) = (sizes[layer], sizes[layer + 1]);
        let offset = offsets[layer];
        let (weight_gradient, bias_gradient) =
            gradient[offset..offset + (fan_in + 1) * fan_out].split_at_mut(fan_in * fan_out);
        let inputs = &tape.layer_inputs[layer];
        for (row, delta_row) in inputs.chunks_exact(fan_in).zip(delta.chunks_exact(fan_out)) {
            for (i, &h) in row.iter().enumerate() {
                let target = &mut weight_gradient[i * fan_out..(i + 1) * fan_out];
                for (g, &d) in target.iter_mut().zip(delta_row) {
                    *g += h * d;
                }
            }
            for (g, &d) in bias_gradient.iter_mut().zip(delta_row) {
                *g += d;
            }
        }
        if layer == 0 {
            break;
        }
        let weights = &parameters[offset..offset + fan_in * fan_out];
        let derivatives = &tape.activation_derivatives[layer - 1];
        let mut previous = Vec::with_capacity(derivatives.len());
        for (delta_row, derivative_row) in delta
            .chunks_exact(fan_out)
            .zip(derivatives.chunks_exact(fan_in))
        {
            for (i, &derivative) in derivative_row.iter().enumerate() {
                let weight_row = &weights[i * fan_out..(i + 1) * fan_out];
                previous.push(dot(weight_row, delta_row) * derivative);
            }
        }
        delta = previous;
    }
}

/// Both networks evaluated on a batch.
pub(crate) struct ModelTape<T> {
    library: MlpTape<T>,
    selection: MlpTape<T>,
    /// y, batch × I, row-major.
    pub prediction: Vec<T>,
    batch: usize,
}

impl Architecture {
    /// Runs both networks on `inputs` (batch × (I+U), row-major) and forms y = Θ·ℰᵀ.
    #[inline(always)]
    fn forward_portable<T: Scalar>(&self, parameters: &[T], inputs: &[f64]) -> ModelTape<T> {
        let batch = inputs.len() / self.input_dim;
        let split = self.library_parameter_count();
        let input: Vec<T> = inputs.iter().map(|&x| T::constant(x)).collect();
        let library = mlp_forward(
            &self.library_sizes(),
            &parameters[..split],
            input.clone(),
            batch,
        );
        let selection = mlp_forward(&self.selection_sizes(), &parameters[split..], input, batch);
        let basis = self.basis_count();
        let mut prediction = Vec::with_capacity(batch * self.state_dim);
        for (theta, selection_row) in library
            .output
            .chunks_exact(basis)
            .zip(selection.output.chunks_exact(self.state_dim * basis))
        {
            for coefficients in selection_row.chunks_exact(basis) {
                let mut y = T::default();
                for (&t, &e) in theta.iter().zip(coefficients) {
                    y += t * e;
                }
                prediction.push(y);
            }
        }
        ModelTape {
            library,
            selection,
            prediction,
            batch,
        }
    }

    /// The gradient of a loss with respect to θ, given dL/dy (batch × I) at a forward pass.
    #[inline(always)]
    fn backward_portable<T: Scalar>(
        &self,
        parameters: &[T],
        tape: &ModelTape<T>,
        prediction_gradient: &[T],
    ) -> Vec<T> {
        let basis = self.basis_count();
        let width = self.state_dim * basis;
        let mut library_gradient = vec![T::default(); tape.batch * basis];
        let mut selection_gradient = vec![T::default(); tape.batch * width];
        for b in 0..tape.batch {
            let theta = &tape.library.output[b * basis..(b + 1) * basis];
            let selection = &tape.selection.output[b * width..(b + 1) * width];
            let d_theta = &mut library_gradient[b * basis..(b + 1) * basis];
            let d_selection = &mut selection_gradient[b * width..(b + 1) * width];
            for state in 0..self.state_dim {
                let g = prediction_gradient[b * self.state_dim + state];
                let coefficients = &selection[state * basis..(state + 1) * basis];
                for k in 0..basis {
                    d_theta[k] += g * coefficients[k];
                    d_selection[state * basis + k] = g * theta[k];
                }
            }
        }
        let split = self.library_parameter_count();
        let mut gradient = vec![T::default(); parameters.len()];
        let (library_part, selection_part) = gradient.split_at_mut(split);
        mlp_backward(
            &self.library_sizes(),
            &parameters[..split],
            &tape.library,
            library_gradient,
            library_part,
        );
        mlp_backward(
            &self.selection_sizes(),
            &parameters[split..],
            &tape.selection,
            selection_gradient,
            selection_part,
        );
        gradient
    }

    /// Runs both networks on `inputs` (batch × (I+U), row-major) and forms y = Θ·ℰᵀ (reference).
    pub(crate) fn forward<T: Scalar>(&self, parameters: &[T], inputs: &[f64]) -> ModelTape<T> {
        self.forward_portable(parameters, inputs)
    }

    /// The gradient of a loss with respect to θ, given dL/dy (batch × I) at a forward pass
    /// (reference).
    pub(crate) fn backward<T: Scalar>(
        &self,
        parameters: &[T],
        tape: &ModelTape<T>,
        prediction_gradient: &[T],
    ) -> Vec<T> {
        self.backward_portable(parameters, tape, prediction_gradient)
    }

    /// Predictions y for each row of `inputs` (batch × (I+U)), batch × I row-major.
    pub fn predict(&self, parameters: &[f64], inputs: &[f64]) -> Vec<f64> {
        ModelWorkspace::new(self)
            .forward(parameters, inputs)
            .to_vec()
    }

    /// [`Self::predict`] by the generic reference code.
    pub fn reference_predict(&self, parameters: &[f64], inputs: &[f64]) -> Vec<f64> {
        self.forward(parameters, inputs).prediction
    }

    /// Θ(X) (batch × K) and ℰ(X) (batch × I·K, each row the I×K matrix row-major) for each row.
    pub fn library_and_selection(
        &self,
        parameters: &[f64],
        inputs: &[f64],
    ) -> (Vec<f64>, Vec<f64>) {
        let mut workspace = ModelWorkspace::new(self);
        workspace.forward(parameters, inputs);
        let (library, selection) = workspace.library_and_selection();
        (library.to_vec(), selection.to_vec())
    }

    /// Mean squared error over all samples and outputs, and its gradient with respect to θ.
    pub fn loss_and_gradient(
        &self,
        parameters: &[f64],
        inputs: &[f64],
        targets: &[f64],
    ) -> (f64, Vec<f64>) {
        let mut gradient = vec![0.0; parameters.len()];
        let loss =
            ModelWorkspace::new(self).mse_and_gradient(parameters, inputs, targets, &mut gradient);
        (loss, gradient)
    }

    /// [`Self::loss_and_gradient`] by the generic reference code: with `f64` the gradient, with
    /// [`crate::Dual`] numbers (θ + ε·v) the Hessian-vector product in the tangents.
    pub fn reference_loss_and_gradient<T: Scalar>(
        &self,
        parameters: &[T],
        inputs: &[f64],
        targets: &[f64],
    ) -> (T, Vec<T>) {
        let tape = self.forward(parameters, inputs);
        let scale = 2.0 / targets.len() as f64;
        let mut loss = T::default();
        let residual_gradient: Vec<T> = tape
            .prediction
            .iter()
            .zip(targets)
            .map(|(&y, &t)| {
                let residual = y - T::constant(t);
                loss += residual * residual;
                residual.scale(scale)
            })
            .collect();
        let gradient = self.backward(parameters, &tape, &residual_gradient);
        (loss.scale(1.0 / targets.len() as f64), gradient)
    }

    /// Mean squared error of the model on (inputs, targets).
    pub fn loss(&self, parameters: &[f64], inputs: &[f64], targets: &[f64]) -> f64 {
        mean_squared_error(&self.predict(parameters, inputs), targets)
    }
}

/// Mean over all entries of (a − b)².
pub fn mean_squared_error(predictions: &[f64], targets: &[f64]) -> f64 {
    predictions
        .iter()
        .zip(targets)
        .map(|(p, t)| (p - t) * (p - t))
        .sum::<f64>()
        / targets.len() as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_sizes_and_parameter_count() {
        let architecture = Architecture {
            input_dim: 10,
            state_dim: 6,
            basis_per_input: 2,
            hidden: PAPER_HIDDEN.to_vec(),
        };
        assert_eq!(architecture.library_sizes(), vec![10, 12, 16, 24, 48, 20]);
        assert_eq!(
            architecture.selection_sizes(),
            vec![10, 12, 16, 24, 48, 120]
        );
        let expected = (11 * 12 + 13 * 16 + 17 * 24 + 25 * 48) * 2 + 49 * 20 + 49 * 120;
        assert_eq!(architecture.parameter_count(), expected);
        assert_eq!(architecture.initial_parameters(3).len(), expected);
        assert_eq!(
            architecture.initial_parameters(3),
            architecture.initial_parameters(3)
        );
        assert_ne!(
            architecture.initial_parameters(3),
            architecture.initial_parameters(4)
        );
    }

    #[test]
    fn prediction_is_library_times_selection_transposed() {
        let architecture = Architecture {
            input_dim: 3,
            state_dim: 2,
            basis_per_input: 2,
            hidden: vec![4],
        };
        let parameters = architecture.initial_parameters(1);
        let inputs = [0.3, -0.2, 1.1, -0.7, 0.5, 0.05];
        let (theta, selection) = architecture.library_and_selection(&parameters, &inputs);
        let y = architecture.predict(&parameters, &inputs);
        let k = architecture.basis_count();
        for b in 0..2 {
            for i in 0..2 {
                let expected: f64 = (0..k)
                    .map(|j| theta[b * k + j] * selection[b * 2 * k + i * k + j])
                    .sum();
                assert!((y[b * 2 + i] - expected).abs() < 1e-15);
            }
        }
    }
}
