//! Whether the model's torques say anything about the recorded angular accelerations. The angular
//! channels compare the body-rate changes with the torques the model computes from the logged
//! commands. When the commands do not resolve the attitude loop (motor outputs logged at a few
//! hertz) or the model's rotor geometry is wrong, the predicted torques carry no information about
//! the recording, and an angular effect fitted there only fits noise: an inertia "a thousand times
//! the model's" is the model's torques switched off.
//!
//! The response of each angular channel to the model's prediction, `β = ⟨y, p⟩ / ⟨p, p⟩` on the fit
//! rows, has the standard error `√(κ s² / ⟨p, p⟩)` (`s²` the residual variance, `κ` its integrated
//! autocorrelation over the test function's support). The angular channels are compared only when
//! `β` is positive and `(β / SE)²` reaches the evidence rule's χ²₁ quantile on every axis.

use serde::Serialize;

use crate::explain::evidence::{chi_square_quantile, integrated_autocorrelation};
use crate::locate::problem::Problem;

/// The response of each angular channel to the model's predicted angular acceleration.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct AngularResponse {
    /// `β` per body axis (1 when the model's torques are right, 0 when they say nothing).
    pub response: [f64; 3],
    pub standard_error: [f64; 3],
    /// `(β / SE)²` must reach this (with `β > 0`) on every axis.
    pub threshold: f64,
}

impl AngularResponse {
    /// Whether the model's torques predict the recording on every axis.
    pub fn informative(&self) -> bool {
        (0..3).all(|a| {
            let (beta, error) = (self.response[a], self.standard_error[a]);
            beta > 0.0 && (beta / error.max(1e-300)).powi(2) >= self.threshold
        })
    }
}

/// The response of `problem`'s angular channels (none when it compares only the translational
/// ones). `significance` is the evidence rule's.
pub fn angular_response(problem: &Problem, significance: f64) -> Option<AngularResponse> {
    if problem.channels != 6 {
        return None;
    }
    let predicted = problem.predict(&physics::Effects::default());
    let rows = 0..problem.split;
    let mut response = [0.0; 3];
    let mut standard_error = [0.0; 3];
    for a in 0..3 {
        let c = 3 + a;
        let y: Vec<f64> = problem.target[rows.clone()].iter().map(|t| t[c]).collect();
        let p: Vec<f64> = predicted[rows.clone()].iter().map(|t| t[c]).collect();
        let pp: f64 = p.iter().map(|v| v * v).sum();
        if pp <= 0.0 {
            // The model predicts no angular acceleration on this axis: a response of 0.
            continue;
        }
        let beta = y.iter().zip(&p).map(|(y, p)| y * p).sum::<f64>() / pp;
        let residual: Vec<f64> = y.iter().zip(&p).map(|(y, p)| y - beta * p).collect();
        let variance =
            residual.iter().map(|r| r * r).sum::<f64>() / (residual.len().max(2) - 1) as f64;
        let kappa = integrated_autocorrelation(&residual, 2 * problem.weak_form.half)
            .unwrap_or(1.0)
            .max(1.0);
        response[a] = beta;
        standard_error[a] = (kappa * variance / pp).sqrt();
    }
    Some(AngularResponse {
        response,
        standard_error,
        threshold: chi_square_quantile(1, significance),
    })
}
