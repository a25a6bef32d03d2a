//! Scratch: time of one gradient (f64) and one Hessian-vector product (dual) at the paper's sizes.
use learn::{Architecture, Batch, PAPER_HIDDEN, hessian_vector_product};
use std::time::Instant;
fn main() {
    let architecture = Architecture {
        input_dim: 10,
        state_dim: 6,
        basis_per_input: 2,
        hidden: PAPER_HIDDEN.to_vec(),
    };
    let rows = 64;
    let batch = Batch {
        inputs: (0..rows * 10)
            .map(|i| ((i * 7919) % 13) as f64 / 6.0 - 1.0)
            .collect(),
        targets: (0..rows * 6)
            .map(|i| ((i * 31) % 7) as f64 / 3.0 - 1.0)
            .collect(),
    };
    let p = architecture.initial_parameters(0);
    let n = 200;
    let t = Instant::now();
    for _ in 0..n {
        std::hint::black_box(architecture.loss_and_gradient(&p, &batch.inputs, &batch.targets));
    }
    let grad = t.elapsed().as_secs_f64() / n as f64;
    let t = Instant::now();
    for _ in 0..n {
        std::hint::black_box(hessian_vector_product(&architecture, &p, &p, &batch));
    }
    let hvp = t.elapsed().as_secs_f64() / n as f64;
    let t = Instant::now();
    for _ in 0..n {
        std::hint::black_box(architecture.predict(&p, &batch.inputs));
    }
    let fwd = t.elapsed().as_secs_f64() / n as f64;
    println!(
        "forward {:.3} ms, gradient {:.3} ms, hvp {:.3} ms",
        fwd * 1e3,
        grad * 1e3,
        hvp * 1e3
    );
}
