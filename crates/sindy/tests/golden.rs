//! Parity with PySINDy's STLSQ and scikit-learn's LASSO on a fixed library matrix
//! (values from `scripts/golden/sindy_golden.py`, stored in `scripts/golden/sindy_golden.json`).

mod common;

use common::{golden, matrix};
use sindy::{Lasso, Stlsq, kkt_violation};

#[test]
fn stlsq_matches_pysindy_to_rounding() {
    let golden = golden("sindy_golden.json");
    let theta = matrix(&golden["library"]);
    let targets = matrix(&golden["targets"]);
    let cases = golden["stlsq"].as_array().unwrap();
    assert!(cases.len() >= 5);
    for case in cases {
        let stlsq = Stlsq::new(
            case["threshold"].as_f64().unwrap(),
            case["alpha"].as_f64().unwrap(),
            case["max_iter"].as_u64().unwrap() as usize,
        )
        .unwrap();
        let fit = stlsq.fit(theta.as_ref(), targets.as_ref());
        let expected = matrix(&case["coefficients"]);
        for i in 0..expected.nrows() {
            for j in 0..expected.ncols() {
                let (ours, theirs) = (fit.coefficients[(i, j)], expected[(i, j)]);
                assert_eq!(
                    ours == 0.0,
                    theirs == 0.0,
                    "support differs at ({i},{j}) in {case}"
                );
                assert!(
                    (ours - theirs).abs() < 1e-10,
                    "({i},{j}): {ours} vs {theirs} in {case}"
                );
            }
        }
        // PySINDy iterates all targets together until the last one stops changing.
        let iterations = fit.iterations.iter().max().copied().unwrap() as u64;
        assert_eq!(iterations, case["iterations"].as_u64().unwrap(), "{case}");
    }
}

#[test]
fn lasso_matches_scikit_learn_and_satisfies_kkt() {
    let golden = golden("sindy_golden.json");
    let theta = matrix(&golden["library"]);
    let targets = matrix(&golden["targets"]);
    let names = vec!["a".to_string(), "b".to_string(), "c".to_string()];
    for case in golden["lasso"].as_array().unwrap() {
        let lambda = case["lambda"].as_f64().unwrap();
        let ours = Lasso::new(lambda)
            .unwrap()
            .fit(theta.as_ref(), targets.as_ref(), &names)
            .unwrap();
        let expected = matrix(&case["coefficients"]);
        for i in 0..expected.nrows() {
            let row: Vec<f64> = (0..ours.ncols()).map(|j| ours[(i, j)]).collect();
            let target: Vec<f64> = (0..targets.nrows()).map(|k| targets[(k, i)]).collect();
            let violation = kkt_violation(theta.as_ref(), &target, &row, lambda);
            assert!(
                violation < 1e-8 * lambda.max(1.0),
                "KKT {violation} at λ={lambda}"
            );
            for j in 0..expected.ncols() {
                assert!(
                    (ours[(i, j)] - expected[(i, j)]).abs() < 1e-7,
                    "λ={lambda} ({i},{j}): {} vs {}",
                    ours[(i, j)],
                    expected[(i, j)]
                );
            }
        }
    }
}
