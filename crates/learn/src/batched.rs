//! The hot path: forward, backward and Pearlmutter's R-operator over a whole batch at once.
//!
//! Each layer is a matrix product over the batch (batch × width, row-major, [`crate::kernels`]);
//! values and tangents live in separate arrays (no dual scalar); every buffer is allocated once
//! in a [`ModelWorkspace`] and reused across calls. The generic scalar code of `network.rs` is the
//! reference these passes are tested against (to ~1e-12) and finite differences check both.
//!
//! Notation for one network with layers l = 0 … L−1: h₀ = X, z_l = h_l·W_l + b_l,
//! h_{l+1} = GELU(z_l) for hidden layers, output z_{L−1}. Backward: δ_l = ∂L/∂z_l,
//! ∂L/∂W_l = h_lᵀ·δ_l, e_l = δ_l·W_lᵀ = ∂L/∂h_l, δ_{l−1} = e_l ⊙ GELU′(z_{l−1}).
//! R-operator along a direction V (same layout as θ): Rz_l = Rh_l·W_l + h_l·V_l + Vb_l,
//! Rh_{l+1} = GELU′(z_l) ⊙ Rz_l; R(∂L/∂W_l) = Rh_lᵀ·δ_l + h_lᵀ·Rδ_l,
//! Rδ_{l−1} = (Rδ_l·W_lᵀ + δ_l·V_lᵀ) ⊙ GELU′(z_{l−1}) + e_l ⊙ GELU″(z_{l−1}) ⊙ Rz_{l−1}.
//! The Hessian-vector product of the loss is H·V = R(∇L).

use crate::kernels::{
    Strides, column_sums, dispatched, gelu_layer, hadamard, matmul, matmul_with_bias,
    r_delta_through_gelu, transpose,
};
use crate::network::Architecture;

/// Batches below this size form δ·Wᵀ without transposing W (the transposes would cost more).
const TRANSPOSE_FROM_BATCH: usize = 8;

/// Buffers of one network for one batch size.
#[derive(Clone, Debug, Default)]
struct NetworkWorkspace {
    sizes: Vec<usize>,
    /// Offset of W_l in the network's parameters (b_l follows W_l).
    offsets: Vec<usize>,
    /// h_1 … h_{L−1}, then the output z_{L−1}: `values[l]` is the output of layer l.
    values: Vec<Vec<f64>>,
    /// GELU′(z_l), GELU″(z_l) of the hidden layers.
    first: Vec<Vec<f64>>,
    second: Vec<Vec<f64>>,
    /// δ_l.
    deltas: Vec<Vec<f64>>,
    /// e_l = δ_l·W_lᵀ for l ≥ 1 (index l − 1).
    back: Vec<Vec<f64>>,
    /// Rz_l and Rh_{l+1} (index l), Rδ_l.
    r_pre: Vec<Vec<f64>>,
    r_values: Vec<Vec<f64>>,
    r_deltas: Vec<Vec<f64>>,
    /// W_lᵀ and V_lᵀ for l ≥ 1 (index l).
    weights_transposed: Vec<Vec<f64>>,
    direction_transposed: Vec<Vec<f64>>,
    /// Scratch for small batches (δ_lᵀ, then (δ·Wᵀ)ᵀ).
    scratch: Vec<f64>,
    scratch_out: Vec<f64>,
}

impl NetworkWorkspace {
    fn new(sizes: Vec<usize>) -> Self {
        let layers = sizes.len() - 1;
        let mut offsets = Vec::with_capacity(layers);
        let mut offset = 0;
        for layer in sizes.windows(2) {
            offsets.push(offset);
            offset += (layer[0] + 1) * layer[1];
        }
        let weights_transposed: Vec<Vec<f64>> = sizes
            .windows(2)
            .map(|layer| vec![0.0; layer[0] * layer[1]])
            .collect();
        Self {
            offsets,
            values: vec![Vec::new(); layers],
            first: vec![Vec::new(); layers - 1],
            second: vec![Vec::new(); layers - 1],
            deltas: vec![Vec::new(); layers],
            back: vec![Vec::new(); layers - 1],
            r_pre: vec![Vec::new(); layers],
            r_values: vec![Vec::new(); layers - 1],
            r_deltas: vec![Vec::new(); layers],
            direction_transposed: weights_transposed.clone(),
            weights_transposed,
            scratch: Vec::new(),
            scratch_out: Vec::new(),
            sizes,
        }
    }

    fn layers(&self) -> usize {
        self.sizes.len() - 1
    }

    /// Sizes every per-batch buffer for `batch` rows.
    fn resize(&mut self, batch: usize) {
        let layers = self.layers();
        for l in 0..layers {
            let width = batch * self.sizes[l + 1];
            self.values[l].resize(width, 0.0);
            self.deltas[l].resize(width, 0.0);
            if l + 1 < layers {
                self.first[l].resize(width, 0.0);
                self.second[l].resize(width, 0.0);
            }
            if l >= 1 {
                self.back[l - 1].resize(batch * self.sizes[l], 0.0);
            }
        }
        self.resize_r(batch);
    }

    /// Sizes the R-operator's buffers (Rz, Rh, Rδ) for `batch` rows.
    fn resize_r(&mut self, batch: usize) {
        let layers = self.layers();
        for l in 0..layers {
            let width = batch * self.sizes[l + 1];
            self.r_pre[l].resize(width, 0.0);
            self.r_deltas[l].resize(width, 0.0);
            if l + 1 < layers {
                self.r_values[l].resize(width, 0.0);
            }
        }
    }

    /// Swaps this network's R-operator buffers (Rz, Rh, Rδ, Vᵀ) with `other`'s z/h, GELU′, δ and
    /// Wᵀ buffers (the same shapes per layer).
    fn swap_r_buffers(&mut self, other: &mut NetworkWorkspace) {
        std::mem::swap(&mut self.r_pre, &mut other.values);
        std::mem::swap(&mut self.r_values, &mut other.first);
        std::mem::swap(&mut self.r_deltas, &mut other.deltas);
        std::mem::swap(
            &mut self.direction_transposed,
            &mut other.weights_transposed,
        );
    }

    fn weights<'a>(&self, parameters: &'a [f64], l: usize) -> (&'a [f64], &'a [f64]) {
        let (fan_in, fan_out) = (self.sizes[l], self.sizes[l + 1]);
        let start = self.offsets[l];
        parameters[start..start + (fan_in + 1) * fan_out].split_at(fan_in * fan_out)
    }

    /// The input of layer l: X for l = 0, else h_l.
    fn input<'a>(&'a self, inputs: &'a [f64], l: usize) -> &'a [f64] {
        if l == 0 { inputs } else { &self.values[l - 1] }
    }

    /// The forward pass; GELU″ is kept only `with_second` (for a later Hessian-vector product).
    fn forward(&mut self, parameters: &[f64], inputs: &[f64], batch: usize, with_second: bool) {
        let layers = self.layers();
        for l in 0..layers {
            let (fan_in, fan_out) = (self.sizes[l], self.sizes[l + 1]);
            let (weights, biases) = self.weights(parameters, l);
            let mut z = std::mem::take(&mut self.values[l]);
            let input = self.input(inputs, l);
            matmul_with_bias(
                batch,
                fan_out,
                fan_in,
                input,
                Strides {
                    row: fan_in,
                    depth: 1,
                },
                weights,
                fan_out,
                &mut z,
                fan_out,
                false,
                Some(biases),
            );
            if l + 1 < layers {
                let second = with_second.then_some(self.second[l].as_mut_slice());
                gelu_layer(&mut z, &mut self.first[l], second);
            }
            self.values[l] = z;
        }
    }

    /// out (batch × fan_in) = delta (batch × fan_out) · W_lᵀ, `weights_t` = W_lᵀ when available.
    #[allow(clippy::too_many_arguments)]
    fn times_transposed(
        scratch: &mut Vec<f64>,
        scratch_out: &mut Vec<f64>,
        batch: usize,
        fan_in: usize,
        fan_out: usize,
        delta: &[f64],
        weights: &[f64],
        weights_t: Option<&[f64]>,
        out: &mut [f64],
        accumulate: bool,
    ) {
        if let Some(weights_t) = weights_t {
            matmul(
                batch,
                fan_in,
                fan_out,
                delta,
                Strides {
                    row: fan_out,
                    depth: 1,
                },
                weights_t,
                fan_in,
                out,
                fan_in,
                accumulate,
            );
            return;
        }
        // outᵀ (fan_in × batch) = W_l (fan_in × fan_out) · deltaᵀ (fan_out × batch).
        scratch.resize(fan_out * batch, 0.0);
        transpose(batch, fan_out, delta, scratch);
        scratch_out.resize(fan_in * batch, 0.0);
        matmul(
            fan_in,
            batch,
            fan_out,
            weights,
            Strides {
                row: fan_out,
                depth: 1,
            },
            scratch,
            batch,
            scratch_out,
            batch,
            false,
        );
        for b in 0..batch {
            let row = &mut out[b * fan_in..(b + 1) * fan_in];
            for (j, target) in row.iter_mut().enumerate() {
                let value = scratch_out[j * batch + b];
                *target = if accumulate { *target + value } else { value };
            }
        }
    }

    /// Writes ∂L/∂θ of this network into `gradient`, given δ_{L−1} in `deltas[L−1]`.
    fn backward(&mut self, parameters: &[f64], inputs: &[f64], batch: usize, gradient: &mut [f64]) {
        let layers = self.layers();
        let transposed = batch >= TRANSPOSE_FROM_BATCH;
        for l in (0..layers).rev() {
            let (fan_in, fan_out) = (self.sizes[l], self.sizes[l + 1]);
            let start = self.offsets[l];
            let (weight_gradient, bias_gradient) =
                gradient[start..start + (fan_in + 1) * fan_out].split_at_mut(fan_in * fan_out);
            let delta = &self.deltas[l];
            matmul(
                fan_in,
                fan_out,
                batch,
                self.input(inputs, l),
                Strides {
                    row: 1,
                    depth: fan_in,
                },
                delta,
                fan_out,
                weight_gradient,
                fan_out,
                false,
            );
            column_sums(delta, fan_out, bias_gradient);
            if l == 0 {
                break;
            }
            let (weights, _) = self.weights(parameters, l);
            if transposed {
                transpose(fan_in, fan_out, weights, &mut self.weights_transposed[l]);
            }
            let mut back = std::mem::take(&mut self.back[l - 1]);
            Self::times_transposed(
                &mut self.scratch,
                &mut self.scratch_out,
                batch,
                fan_in,
                fan_out,
                &self.deltas[l],
                weights,
                transposed.then_some(self.weights_transposed[l].as_slice()),
                &mut back,
                false,
            );
            hadamard(&mut self.deltas[l - 1], &back, &self.first[l - 1]);
            self.back[l - 1] = back;
        }
    }

    /// Rz_l and Rh_l along `direction` (this network's part of V).
    fn r_forward(&mut self, parameters: &[f64], direction: &[f64], inputs: &[f64], batch: usize) {
        let layers = self.layers();
        for l in 0..layers {
            let (fan_in, fan_out) = (self.sizes[l], self.sizes[l + 1]);
            let (weights, _) = self.weights(parameters, l);
            let (direction_weights, direction_biases) = self.weights(direction, l);
            let mut r_pre = std::mem::take(&mut self.r_pre[l]);
            let row_major = Strides {
                row: fan_in,
                depth: 1,
            };
            matmul_with_bias(
                batch,
                fan_out,
                fan_in,
                self.input(inputs, l),
                row_major,
                direction_weights,
                fan_out,
                &mut r_pre,
                fan_out,
                false,
                Some(direction_biases),
            );
            if l >= 1 {
                matmul(
                    batch,
                    fan_out,
                    fan_in,
                    &self.r_values[l - 1],
                    row_major,
                    weights,
                    fan_out,
                    &mut r_pre,
                    fan_out,
                    true,
                );
            }
            if l + 1 < layers {
                hadamard(&mut self.r_values[l], &self.first[l], &r_pre);
            }
            self.r_pre[l] = r_pre;
        }
    }

    /// Writes R(∂L/∂θ) of this network into `product`, given Rδ_{L−1} in `r_deltas[L−1]`
    /// (after `forward`, `backward` and `r_forward` at the same point).
    fn r_backward(
        &mut self,
        parameters: &[f64],
        direction: &[f64],
        inputs: &[f64],
        batch: usize,
        product: &mut [f64],
    ) {
        let layers = self.layers();
        let transposed = batch >= TRANSPOSE_FROM_BATCH;
        for l in (0..layers).rev() {
            let (fan_in, fan_out) = (self.sizes[l], self.sizes[l + 1]);
            let start = self.offsets[l];
            let (weight_product, bias_product) =
                product[start..start + (fan_in + 1) * fan_out].split_at_mut(fan_in * fan_out);
            let transposed_input = Strides {
                row: 1,
                depth: fan_in,
            };
            matmul(
                fan_in,
                fan_out,
                batch,
                self.input(inputs, l),
                transposed_input,
                &self.r_deltas[l],
                fan_out,
                weight_product,
                fan_out,
                false,
            );
            if l >= 1 {
                matmul(
                    fan_in,
                    fan_out,
                    batch,
                    &self.r_values[l - 1],
                    transposed_input,
                    &self.deltas[l],
                    fan_out,
                    weight_product,
                    fan_out,
                    true,
                );
            }
            column_sums(&self.r_deltas[l], fan_out, bias_product);
            if l == 0 {
                break;
            }
            let (weights, _) = self.weights(parameters, l);
            let (direction_weights, _) = self.weights(direction, l);
            if transposed {
                transpose(
                    fan_in,
                    fan_out,
                    direction_weights,
                    &mut self.direction_transposed[l],
                );
            }
            // r_back = Rδ_l·W_lᵀ + δ_l·V_lᵀ (W_lᵀ is still in place from `backward`).
            let mut r_back = std::mem::take(&mut self.r_deltas[l - 1]);
            Self::times_transposed(
                &mut self.scratch,
                &mut self.scratch_out,
                batch,
                fan_in,
                fan_out,
                &self.r_deltas[l],
                weights,
                transposed.then_some(self.weights_transposed[l].as_slice()),
                &mut r_back,
                false,
            );
            Self::times_transposed(
                &mut self.scratch,
                &mut self.scratch_out,
                batch,
                fan_in,
                fan_out,
                &self.deltas[l],
                direction_weights,
                transposed.then_some(self.direction_transposed[l].as_slice()),
                &mut r_back,
                true,
            );
            r_delta_through_gelu(
                &mut r_back,
                &self.first[l - 1],
                &self.second[l - 1],
                &self.back[l - 1],
                &self.r_pre[l - 1],
            );
            self.r_deltas[l - 1] = r_back;
        }
    }
}

/// Reusable buffers for forward, backward and Hessian-vector passes of one [`Architecture`]
/// on batches of any size (buffers grow to the largest batch seen).
#[derive(Clone, Debug)]
pub struct ModelWorkspace {
    architecture: Architecture,
    library: NetworkWorkspace,
    selection: NetworkWorkspace,
    batch: usize,
    inputs: Vec<f64>,
    /// y, batch × I.
    prediction: Vec<f64>,
    /// ∂L/∂y of the last backward pass.
    prediction_gradient: Vec<f64>,
    /// Whether the stored ∂L/∂y is the mean squared error's (required by the Hessian product).
    mse_backward: bool,
    /// Whether forward passes keep GELU″ (the Hessian product needs it; a workspace that only
    /// ever takes gradients can skip it).
    keeps_curvature: bool,
}

impl ModelWorkspace {
    /// Empty buffers for `architecture`.
    pub fn new(architecture: &Architecture) -> Self {
        Self {
            architecture: architecture.clone(),
            library: NetworkWorkspace::new(architecture.library_sizes()),
            selection: NetworkWorkspace::new(architecture.selection_sizes()),
            batch: 0,
            inputs: Vec::new(),
            prediction: Vec::new(),
            prediction_gradient: Vec::new(),
            mse_backward: false,
            keeps_curvature: true,
        }
    }

    /// These buffers for gradients only: forward passes skip GELU″, and
    /// [`Self::hessian_vector_product`] panics. Values and gradients are the same to the bit.
    pub fn for_gradients_only(mut self) -> Self {
        self.keeps_curvature = false;
        self
    }

    /// Exchanges this workspace's Hessian-product buffers with `other`'s forward and backward
    /// buffers (values, GELU′, δ, transposed weights), for a caller that has finished with `other`'s last pass: a
    /// Hessian-vector product between two exchanges then runs in memory the cache already holds
    /// instead of in buffers of its own. Calling it twice restores both.
    pub(crate) fn exchange_hessian_buffers(&mut self, other: &mut ModelWorkspace) {
        assert_eq!(
            self.architecture, other.architecture,
            "exchange between workspaces of one architecture"
        );
        self.library.swap_r_buffers(&mut other.library);
        self.selection.swap_r_buffers(&mut other.selection);
    }

    /// The architecture these buffers serve.
    pub fn architecture(&self) -> &Architecture {
        &self.architecture
    }

    /// Runs both networks on `inputs` (batch × (I+U), row-major) and forms y = Θ·ℰᵀ.
    pub fn forward(&mut self, parameters: &[f64], inputs: &[f64]) -> &[f64] {
        let architecture = &self.architecture;
        assert_eq!(parameters.len(), architecture.parameter_count(), "θ length");
        assert_eq!(inputs.len() % architecture.input_dim, 0, "input width");
        let batch = inputs.len() / architecture.input_dim;
        self.batch = batch;
        self.mse_backward = false;
        self.inputs.clear();
        self.inputs.extend_from_slice(inputs);
        self.library.resize(batch);
        self.selection.resize(batch);
        let split = architecture.library_parameter_count();
        let curvature = self.keeps_curvature;
        self.library
            .forward(&parameters[..split], inputs, batch, curvature);
        self.selection
            .forward(&parameters[split..], inputs, batch, curvature);
        let (basis, states) = (architecture.basis_count(), architecture.state_dim);
        self.prediction.resize(batch * states, 0.0);
        product_forward(
            &self.library.values[self.library.layers() - 1],
            &self.selection.values[self.selection.layers() - 1],
            [basis, states],
            &mut self.prediction,
        );
        &self.prediction
    }

    /// The predictions of the last forward pass, batch × I.
    pub fn prediction(&self) -> &[f64] {
        &self.prediction
    }

    /// Θ (batch × K) and ℰ (batch × I·K) of the last forward pass.
    pub fn library_and_selection(&self) -> (&[f64], &[f64]) {
        (
            &self.library.values[self.library.layers() - 1],
            &self.selection.values[self.selection.layers() - 1],
        )
    }

    /// ∂L/∂θ into `gradient` given ∂L/∂y (batch × I) at the last forward pass.
    pub fn backward(
        &mut self,
        parameters: &[f64],
        prediction_gradient: &[f64],
        gradient: &mut [f64],
    ) {
        assert_eq!(
            prediction_gradient.len(),
            self.prediction.len(),
            "∂L/∂y size"
        );
        assert_eq!(gradient.len(), parameters.len(), "gradient length");
        self.prediction_gradient.clear();
        self.prediction_gradient
            .extend_from_slice(prediction_gradient);
        self.mse_backward = false;
        self.backward_stored(parameters, gradient);
    }

    fn backward_stored(&mut self, parameters: &[f64], gradient: &mut [f64]) {
        let (basis, states) = (self.architecture.basis_count(), self.architecture.state_dim);
        let batch = self.batch;
        let library_layers = self.library.layers();
        let selection_layers = self.selection.layers();
        product_backward(
            &self.library.values[library_layers - 1],
            &self.selection.values[selection_layers - 1],
            &self.prediction_gradient,
            [basis, states, batch],
            &mut self.library.deltas[library_layers - 1],
            &mut self.selection.deltas[selection_layers - 1],
        );
        let split = self.architecture.library_parameter_count();
        let (library_gradient, selection_gradient) = gradient.split_at_mut(split);
        self.library
            .backward(&parameters[..split], &self.inputs, batch, library_gradient);
        self.selection.backward(
            &parameters[split..],
            &self.inputs,
            batch,
            selection_gradient,
        );
    }

    /// Mean squared error on (inputs, targets) and its gradient into `gradient`; keeps what
    /// [`Self::hessian_vector_product`] needs.
    pub fn mse_and_gradient(
        &mut self,
        parameters: &[f64],
        inputs: &[f64],
        targets: &[f64],
        gradient: &mut [f64],
    ) -> f64 {
        self.forward(parameters, inputs);
        assert_eq!(targets.len(), self.prediction.len(), "target size");
        let scale = 2.0 / targets.len() as f64;
        let mut loss = 0.0;
        self.prediction_gradient.clear();
        for (&y, &t) in self.prediction.iter().zip(targets) {
            let residual = y - t;
            loss += residual * residual;
            self.prediction_gradient.push(residual * scale);
        }
        self.backward_stored(parameters, gradient);
        self.mse_backward = true;
        loss / targets.len() as f64
    }

    /// H(θ)·v of the mean squared error, into `product`, at the point and batch of the last
    /// [`Self::mse_and_gradient`] (whose stored passes it reuses).
    pub fn hessian_vector_product(
        &mut self,
        parameters: &[f64],
        direction: &[f64],
        product: &mut [f64],
    ) {
        assert!(
            self.mse_backward,
            "hessian_vector_product needs a preceding mse_and_gradient"
        );
        assert!(
            self.keeps_curvature,
            "hessian_vector_product on a workspace made for gradients only"
        );
        assert_eq!(direction.len(), parameters.len(), "direction length");
        assert_eq!(product.len(), parameters.len(), "product length");
        let architecture = &self.architecture;
        let (basis, states, batch) = (
            architecture.basis_count(),
            architecture.state_dim,
            self.batch,
        );
        let split = architecture.library_parameter_count();
        // The R buffers may have been exchanged with a workspace of another batch size.
        self.library.resize_r(batch);
        self.selection.resize_r(batch);
        self.library.r_forward(
            &parameters[..split],
            &direction[..split],
            &self.inputs,
            batch,
        );
        self.selection.r_forward(
            &parameters[split..],
            &direction[split..],
            &self.inputs,
            batch,
        );
        let library_last = self.library.layers() - 1;
        let selection_last = self.selection.layers() - 1;
        let scale = 2.0 / self.prediction.len() as f64;
        let theta_all = &self.library.values[library_last];
        let selection_all = &self.selection.values[selection_last];
        let r_theta_all = &self.library.r_pre[library_last];
        let r_selection_all = &self.selection.r_pre[selection_last];
        let r_d_theta_all = &mut self.library.r_deltas[library_last];
        let r_d_selection_all = &mut self.selection.r_deltas[selection_last];
        product_r_backward(
            [theta_all, selection_all, r_theta_all, r_selection_all],
            &self.prediction_gradient,
            [basis, states, batch],
            scale,
            r_d_theta_all,
            r_d_selection_all,
        );
        let (library_product, selection_product) = product.split_at_mut(split);
        self.library.r_backward(
            &parameters[..split],
            &direction[..split],
            &self.inputs,
            batch,
            library_product,
        );
        self.selection.r_backward(
            &parameters[split..],
            &direction[split..],
            &self.inputs,
            batch,
            selection_product,
        );
    }
}

dispatched! {
    /// y_bi = Σ_k Θ_bk·ℰ_b,ik.
    fn product_forward(theta_all: &[f64], selection_all: &[f64], sizes: [usize; 2], out: &mut [f64]) {
        let [basis, states] = sizes;
        for ((theta, selection), y) in theta_all
            .chunks_exact(basis)
            .zip(selection_all.chunks_exact(states * basis))
            .zip(out.chunks_exact_mut(states))
        {
            for (coefficients, value) in selection.chunks_exact(basis).zip(y) {
                *value = dot(theta, coefficients);
            }
        }
    }
}

dispatched! {
    /// δΘ_bk = Σ_i g_bi·ℰ_b,ik and δℰ_b,ik = g_bi·Θ_bk, with `sizes` = [K, I, batch]. The k go
    /// in blocks of 8 whose sums over i stay in registers (summed in i order, as one i at a time).
    fn product_backward(
        theta_all: &[f64],
        selection_all: &[f64],
        prediction_gradient: &[f64],
        sizes: [usize; 3],
        d_theta_all: &mut [f64],
        d_selection_all: &mut [f64],
    ) {
        let [basis, states, batch] = sizes;
        let width = states * basis;
        for b in 0..batch {
            let rows = ProductRows::of_row(b, [basis, states], [theta_all, selection_all, prediction_gradient]);
            let d_theta = &mut d_theta_all[b * basis..(b + 1) * basis];
            let d_selection = &mut d_selection_all[b * width..(b + 1) * width];
            let mut start = 0;
            while start + 8 <= basis {
                product_backward_block::<8>(&rows, start, d_theta, d_selection);
                start += 8;
            }
            while start < basis {
                product_backward_block::<1>(&rows, start, d_theta, d_selection);
                start += 1;
            }
        }
    }
}

/// One row b of the product y = Θ·ℰᵀ: Θ_b (K), ℰ_b (I × K) and ∂L/∂y_b (I).
struct ProductRows<'a> {
    basis: usize,
    theta: &'a [f64],
    selection: &'a [f64],
    gradient: &'a [f64],
}

impl<'a> ProductRows<'a> {
    /// Row b of Θ (batch × K), ℰ (batch × I·K) and ∂L/∂y (batch × I); `sizes` = [K, I].
    #[inline(always)]
    fn of_row(b: usize, sizes: [usize; 2], all: [&'a [f64]; 3]) -> Self {
        let [basis, states] = sizes;
        let [theta, selection, gradient] = all;
        let width = states * basis;
        Self {
            basis,
            theta: &theta[b * basis..(b + 1) * basis],
            selection: &selection[b * width..(b + 1) * width],
            gradient: &gradient[b * states..(b + 1) * states],
        }
    }
}

/// Columns start..start + LANES of [`product_backward`] for one row.
#[inline(always)]
fn product_backward_block<const LANES: usize>(
    rows: &ProductRows,
    start: usize,
    d_theta: &mut [f64],
    d_selection: &mut [f64],
) {
    let theta: &[f64; LANES] = rows.theta[start..start + LANES].try_into().expect("block");
    let mut sums = [0.0; LANES];
    for (state, &g) in rows.gradient.iter().enumerate() {
        let offset = state * rows.basis + start;
        let coefficients: &[f64; LANES] = rows.selection[offset..offset + LANES]
            .try_into()
            .expect("block");
        let d_coefficients: &mut [f64; LANES] = (&mut d_selection[offset..offset + LANES])
            .try_into()
            .expect("block");
        for lane in 0..LANES {
            sums[lane] += g * coefficients[lane];
            d_coefficients[lane] = g * theta[lane];
        }
    }
    d_theta[start..start + LANES].copy_from_slice(&sums);
}

dispatched! {
    /// The R-operator through y = Θ·ℰᵀ and the mean squared error: R(∂L/∂y) = scale·Ry with
    /// Ry_bi = Σ_k RΘ_bk·ℰ_b,ik + Θ_bk·Rℰ_b,ik, then RδΘ and Rδℰ. `values` = [Θ, ℰ, RΘ, Rℰ],
    /// `sizes` = [K, I, batch]. The updates go in blocks of 8 k, as in [`product_backward`].
    fn product_r_backward(
        values: [&[f64]; 4],
        prediction_gradient: &[f64],
        sizes: [usize; 3],
        scale: f64,
        r_d_theta_all: &mut [f64],
        r_d_selection_all: &mut [f64],
    ) {
        let [theta_all, selection_all, r_theta_all, r_selection_all] = values;
        let [basis, states, batch] = sizes;
        let width = states * basis;
        let mut r_gradient = vec![0.0; states];
        for b in 0..batch {
            let rows = ProductRows::of_row(b, [basis, states], [theta_all, selection_all, prediction_gradient]);
            let r_theta = &r_theta_all[b * basis..(b + 1) * basis];
            let r_selection = &r_selection_all[b * width..(b + 1) * width];
            for (state, r_g) in r_gradient.iter_mut().enumerate() {
                let cols = state * basis..(state + 1) * basis;
                *r_g = scale
                    * (dot(r_theta, &rows.selection[cols.clone()])
                        + dot(rows.theta, &r_selection[cols]));
            }
            let r_rows = ProductRows {
                basis,
                theta: r_theta,
                selection: r_selection,
                gradient: &r_gradient,
            };
            let r_d_theta = &mut r_d_theta_all[b * basis..(b + 1) * basis];
            let r_d_selection = &mut r_d_selection_all[b * width..(b + 1) * width];
            let mut start = 0;
            while start + 8 <= basis {
                product_r_backward_block::<8>([&rows, &r_rows], start, r_d_theta, r_d_selection);
                start += 8;
            }
            while start < basis {
                product_r_backward_block::<1>([&rows, &r_rows], start, r_d_theta, r_d_selection);
                start += 1;
            }
        }
    }
}

/// Columns start..start + LANES of [`product_r_backward`] for one row: `rows` = [(Θ, ℰ, g),
/// (RΘ, Rℰ, R(∂L/∂y))].
#[inline(always)]
fn product_r_backward_block<const LANES: usize>(
    rows: [&ProductRows; 2],
    start: usize,
    r_d_theta: &mut [f64],
    r_d_selection: &mut [f64],
) {
    let [rows, r_rows] = rows;
    let block = start..start + LANES;
    let theta: &[f64; LANES] = rows.theta[block.clone()].try_into().expect("block");
    let r_theta: &[f64; LANES] = r_rows.theta[block].try_into().expect("block");
    let mut sums = [0.0; LANES];
    for (state, (&g, &r_g)) in rows.gradient.iter().zip(r_rows.gradient).enumerate() {
        let offset = state * rows.basis + start;
        let block = offset..offset + LANES;
        let coefficients: &[f64; LANES] = rows.selection[block.clone()].try_into().expect("block");
        let r_coefficients: &[f64; LANES] =
            r_rows.selection[block.clone()].try_into().expect("block");
        let r_d_coefficients: &mut [f64; LANES] =
            (&mut r_d_selection[block]).try_into().expect("block");
        for lane in 0..LANES {
            sums[lane] += r_g * coefficients[lane] + g * r_coefficients[lane];
            r_d_coefficients[lane] = r_g * theta[lane] + g * r_theta[lane];
        }
    }
    r_d_theta[start..start + LANES].copy_from_slice(&sums);
}

/// Σ a_i·b_i in index order.
#[inline(always)]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0, |sum, (&x, &y)| sum + x * y)
}
