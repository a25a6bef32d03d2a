//! A library too large to form whole (more than `LARGE_LIBRARY_ENTRIES` entries) is evaluated and
//! reduced by blocks of rows: the fit, the prediction and the score are those of the whole matrix,
//! for STLSQ and LASSO, and a non-finite feature is reported on its row.

use sindy::{
    FeatureLibrary, LARGE_LIBRARY_ENTRIES, LibrarySpec, Mat, OptimizerSpec, SindyError,
    SindyParams, Stlsq,
};

/// Smooth, well-conditioned inputs (7 columns) and targets that are sparse in the cubic library
/// plus a small non-polynomial part.
fn data(rows: usize) -> (Mat<f64>, Mat<f64>) {
    let inputs = Mat::from_fn(rows, 7, |i, j| {
        let t = i as f64 * 1e-3;
        0.3 * j as f64 - 0.8
            + (t * (0.7 + 0.31 * j as f64) + j as f64).sin()
            + 0.5 * (t * (1.9 + 0.17 * j as f64)).cos()
    });
    let targets = Mat::from_fn(rows, 3, |i, j| {
        let x = |k: usize| inputs[(i, k)];
        match j {
            0 => 1.5 * x(1) - 0.7 * x(0) * x(2) + 0.05 * (3.0 * x(4)).sin(),
            1 => -2.0 * x(3).powi(3) + 0.4 * x(5),
            _ => 0.9 - 1.1 * x(6) * x(0) * x(1) + 0.02 * (x(2) * 5.0).cos(),
        }
    });
    (inputs, targets)
}

fn params(optimizer: OptimizerSpec) -> SindyParams {
    let names = ["a", "b", "c"];
    let controls = ["p", "q", "r", "s"];
    SindyParams::new(&names, &controls)
        .library(FeatureLibrary::from_spec(&LibrarySpec::parse("poly:3").unwrap()).unwrap())
        .optimizer(optimizer)
}

#[test]
fn a_library_fitted_by_blocks_equals_the_whole_matrix_fit() {
    // 7 inputs, cubic: 120 features; 40,000 rows: 4.8 million entries.
    let (inputs, targets) = data(40_000);
    let library = FeatureLibrary::from_spec(&LibrarySpec::parse("poly:3").unwrap()).unwrap();
    assert!(inputs.nrows() * library.feature_count(7) > LARGE_LIBRARY_ENTRIES);
    let theta = library.transform(inputs.as_ref());
    for optimizer in [
        OptimizerSpec::stlsq(0.05),
        OptimizerSpec::Lasso { lambda: 2.0 },
    ] {
        let model = params(optimizer)
            .fit_matrices(inputs.as_ref(), targets.as_ref())
            .unwrap();
        let whole = match optimizer {
            OptimizerSpec::Lasso { lambda } => sindy::Lasso::new(lambda)
                .unwrap()
                .fit(theta.as_ref(), targets.as_ref(), &[])
                .unwrap(),
            _ => {
                Stlsq::new(0.05, 0.05, 20)
                    .unwrap()
                    .fit(theta.as_ref(), targets.as_ref())
                    .coefficients
            }
        };
        let ours = model.coefficients();
        let scale = whole.norm_max();
        let difference = (ours.to_owned() - &whole).norm_max();
        let tolerance = match optimizer {
            OptimizerSpec::Lasso { .. } => 1e-6,
            _ => 1e-10,
        };
        assert!(
            difference <= tolerance * scale,
            "{optimizer:?}: max |Δξ| {difference:e} (max |ξ| {scale})"
        );
        // The prediction by blocks is the product with the whole matrix.
        let predicted = model.predict_inputs(inputs.as_ref()).unwrap();
        let direct = &theta * ours.transpose();
        assert!((predicted - direct).norm_max() <= 1e-12 * scale.max(1.0) * 120.0);
    }
}

#[test]
fn a_non_finite_feature_of_a_large_library_names_its_row() {
    let (mut inputs, targets) = data(40_000);
    inputs[(33_333, 2)] = 1e200; // its cube overflows
    let error = params(OptimizerSpec::stlsq(0.05))
        .fit_matrices(inputs.as_ref(), targets.as_ref())
        .unwrap_err();
    match error {
        SindyError::NonFinite { what, row, .. } => {
            assert_eq!((what.as_str(), row), ("library", 33_333));
        }
        other => panic!("{other}"),
    }
}
