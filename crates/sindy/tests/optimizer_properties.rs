//! Properties of the optimizers on random problems.

use proptest::prelude::*;
use proptest::test_runner::{FileFailurePersistence, RngSeed};
use sindy::{Lasso, Mat, Stlsq, kkt_violation, least_squares};

/// A deterministic pseudo-random n × p matrix with entries in [−1, 1] (SplitMix64 of `seed`).
fn random_matrix(n: usize, p: usize, seed: u64) -> Mat<f64> {
    let mut state = seed;
    Mat::from_fn(n, p, |_, _| {
        state = state.wrapping_add(0x9E3779B97F4A7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58476D1CE4E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D049BB133111EB);
        z ^= z >> 31;
        2.0 * (z >> 11) as f64 / (1u64 << 53) as f64 - 1.0
    })
}

fn column(m: &Mat<f64>, j: usize) -> Vec<f64> {
    (0..m.nrows()).map(|i| m[(i, j)]).collect()
}

proptest! {
    // A fixed seed: the same 48 cases on every run, so CI cannot pass or fail by the draw.
    #![proptest_config(ProptestConfig {
        cases: 48,
        rng_seed: RngSeed::Fixed(2026),
        failure_persistence: Some(Box::new(FileFailurePersistence::Off)),
        ..ProptestConfig::default()
    })]

    #[test]
    fn stlsq_recovers_sparse_coefficients_from_exact_data(
        seed in any::<u64>(),
        p in 3usize..9,
        mask in proptest::collection::vec(any::<bool>(), 9),
        magnitudes in proptest::collection::vec(0.5f64..3.0, 9),
        signs in proptest::collection::vec(any::<bool>(), 9),
    ) {
        let theta = random_matrix(80, p, seed);
        let truth: Vec<f64> = (0..p)
            .map(|j| if mask[j] { magnitudes[j] * if signs[j] { 1.0 } else { -1.0 } } else { 0.0 })
            .collect();
        let y = Mat::from_fn(80, 1, |i, _| (0..p).map(|j| theta[(i, j)] * truth[j]).sum());
        let fit = Stlsq::new(0.1, 0.05, 20).unwrap().fit(theta.as_ref(), y.as_ref());
        for (j, want) in truth.iter().enumerate() {
            prop_assert!((fit.coefficients[(0, j)] - want).abs() < 1e-9,
                "feature {j}: {} vs {want}", fit.coefficients[(0, j)]);
        }
        prop_assert!(fit.iterations[0] <= 20);
    }

    #[test]
    fn stlsq_result_is_least_squares_on_its_support(
        seed in any::<u64>(),
        threshold in 0.0f64..0.6,
        alpha in 0.0f64..2.0,
    ) {
        let theta = random_matrix(50, 6, seed);
        let y = random_matrix(50, 2, seed ^ 0xABCDEF);
        let fit = Stlsq::new(threshold, alpha, 20).unwrap().fit(theta.as_ref(), y.as_ref());
        let residual = &y - &theta * fit.coefficients.transpose();
        let gradient = theta.transpose() * &residual;
        for i in 0..2 {
            for j in 0..6 {
                if fit.coefficients[(i, j)] != 0.0 {
                    prop_assert!(gradient[(j, i)].abs() < 1e-9, "not optimal on the support");
                }
            }
        }
        if threshold == 0.0 {
            let full = least_squares(theta.as_ref(), y.as_ref());
            for i in 0..2 { for j in 0..6 {
                prop_assert!((full[(j, i)] - fit.coefficients[(i, j)]).abs() < 1e-9);
            }}
        }
    }

    #[test]
    fn lasso_satisfies_kkt_and_vanishes_above_the_critical_lambda(
        seed in any::<u64>(),
        fraction in 0.01f64..0.9,
    ) {
        lasso_is_optimal(seed, fraction)?;
    }
}

/// A case a random draw found in CI: the interior point left a 4·10⁻⁸ coefficient whose exact
/// value is zero, so the polish on that support flipped its sign and was refused.
#[test]
fn lasso_polish_drops_a_coefficient_the_interior_point_left_near_zero() {
    lasso_is_optimal(9360318926050116435, 0.32889343323934095).unwrap();
}

/// At `fraction` of the critical λ the LASSO satisfies its optimality conditions; just above the
/// critical λ every coefficient is zero.
fn lasso_is_optimal(seed: u64, fraction: f64) -> Result<(), TestCaseError> {
    let theta = random_matrix(60, 5, seed);
    let y = random_matrix(60, 1, seed.wrapping_mul(3) ^ 17);
    let correlations = theta.transpose() * &y;
    let critical = (0..5)
        .map(|j| correlations[(j, 0)].abs())
        .fold(0.0, f64::max);
    let names = vec!["y".to_string()];
    let lambda = fraction * critical;
    let xi = Lasso::new(lambda)
        .unwrap()
        .fit(theta.as_ref(), y.as_ref(), &names)
        .unwrap();
    let row: Vec<f64> = (0..5).map(|j| xi[(0, j)]).collect();
    let violation = kkt_violation(theta.as_ref(), &column(&y, 0), &row, lambda);
    prop_assert!(violation < 1e-7 * critical, "KKT violation {violation}");

    let zero = Lasso::new(1.01 * critical)
        .unwrap()
        .fit(theta.as_ref(), y.as_ref(), &names)
        .unwrap();
    prop_assert!((0..5).all(|j| zero[(0, j)].abs() < 1e-9 * critical));
    Ok(())
}
