//! The allocation (effectiveness) matrix of a vehicle: rotor thrusts (N) to `[T, τx, τy, τz]`
//! (N, N·m, body FLU, torques about the centre of mass), its rank and its pseudo-inverse.
//!
//! Rotor `i` with thrust `F` along unit axis `a`, lever arm `r` from the centre of mass, spin sign
//! `s` (−1 counter-clockwise) and ratio `km` gives `T = F a_z` and `τ = r × (F a) + s km F a`.
//! `T` is the thrust along body z; a tilted rotor's sideways force is not in these four rows.

use faer::Mat;

use super::VehicleDescription;
use crate::vector::{add, cross, scale};

/// Singular values below this fraction of the largest count as zero (rank, pseudo-inverse).
pub const RANK_TOLERANCE: f64 = 1e-10;

/// The allocation matrix `B` (4 × N) of a vehicle with its SVD-derived rank and pseudo-inverse.
#[derive(Clone, Debug)]
pub struct Allocation {
    matrix: Mat<f64>,
    singular_values: Vec<f64>,
    rank: usize,
    pseudo_inverse: Mat<f64>,
}

impl Allocation {
    /// The allocation of `vehicle`.
    pub fn of(vehicle: &VehicleDescription) -> Self {
        let arms = vehicle.lever_arms_m();
        let n = vehicle.rotors.len();
        let matrix = Mat::from_fn(4, n, |row, i| {
            let rotor = &vehicle.rotors[i];
            let a = rotor.axis;
            let torque = add(
                cross(arms[i], a),
                scale(a, rotor.spin.torque_sign() * rotor.moment_ratio_m),
            );
            match row {
                0 => a[2],
                _ => torque[row - 1],
            }
        });
        Self::from_matrix(matrix)
    }

    fn from_matrix(matrix: Mat<f64>) -> Self {
        let svd = matrix
            .svd()
            .expect("the SVD of a small finite matrix converges");
        let s = svd.S().column_vector();
        let singular_values: Vec<f64> = (0..s.nrows()).map(|k| s[k]).collect();
        let largest = singular_values.first().copied().unwrap_or(0.0);
        let kept: Vec<usize> = (0..singular_values.len())
            .filter(|&k| singular_values[k] > RANK_TOLERANCE * largest)
            .collect();
        // B⁺ = V Σ⁺ Uᵀ over the singular values kept.
        let (u, v) = (svd.U(), svd.V());
        let pseudo_inverse = Mat::from_fn(matrix.ncols(), 4, |i, j| {
            kept.iter()
                .map(|&k| v[(i, k)] * u[(j, k)] / singular_values[k])
                .sum()
        });
        Self {
            rank: kept.len(),
            matrix,
            singular_values,
            pseudo_inverse,
        }
    }

    /// `B` (4 × N): column `i` is rotor `i`'s `[T, τx, τy, τz]` per newton of its thrust.
    pub fn matrix(&self) -> &Mat<f64> {
        &self.matrix
    }

    /// The rows of `B` as plain vectors (`[T, τx, τy, τz]` in that order).
    pub fn rows(&self) -> [Vec<f64>; 4] {
        std::array::from_fn(|row| {
            (0..self.matrix.ncols())
                .map(|i| self.matrix[(row, i)])
                .collect()
        })
    }

    /// Singular values of `B`, largest first.
    pub fn singular_values(&self) -> &[f64] {
        &self.singular_values
    }

    /// How many of `T, τx, τy, τz` the rotors can set independently (4 for a controllable
    /// multirotor).
    pub fn rank(&self) -> usize {
        self.rank
    }

    /// `B⁺` (N × 4), the control allocation: the least-norm rotor thrusts for a wrench.
    pub fn pseudo_inverse(&self) -> &Mat<f64> {
        &self.pseudo_inverse
    }

    /// `[T, τx, τy, τz] = B · thrusts`.
    pub fn wrench(&self, thrusts: &[f64]) -> [f64; 4] {
        std::array::from_fn(|row| {
            thrusts
                .iter()
                .enumerate()
                .map(|(i, f)| self.matrix[(row, i)] * f)
                .sum()
        })
    }

    /// `B⁺ · wrench`: rotor thrusts (N) for a wrench, without limits (they may be negative).
    pub fn thrusts_for(&self, wrench: &[f64; 4]) -> Vec<f64> {
        (0..self.pseudo_inverse.nrows())
            .map(|i| {
                (0..4)
                    .map(|j| self.pseudo_inverse[(i, j)] * wrench[j])
                    .sum()
            })
            .collect()
    }
}
