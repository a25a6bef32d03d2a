//! A library too large to form whole (more than `LARGE_LIBRARY_ENTRIES` entries) is evaluated and
//! reduced by blocks of rows: the fit, the prediction and the score are those of the whole matrix,
//! for STLSQ and LASSO, and a non-finite feature is reported on its row.

use sindy::{
    FeatureLibrary, LARGE_LIBRARY_ENTRIES, LibrarySpec, Mat, OptimizerSpec, RowReduction,
    SindyError, SindyParams, Stlsq,
};

/// Smooth, well-conditioned inputs (7 columns: an offset and four sinusoids of distinct
/// frequencies each, as in the scaling bench) and targets that are sparse in the cubic library
/// plus a small non-polynomial part.
fn data(rows: usize) -> (Mat<f64>, Mat<f64>) {
    let inputs = Mat::from_fn(rows, 7, |i, j| {
        let t = i as f64 * 1e-3;
        (0..4)
            .map(|k| {
                let frequency = 0.2 + 0.37 * (4 * j + k) as f64 % 2.9;
                (0.3 + 0.2 * k as f64)
                    * (std::f64::consts::TAU * frequency * t + j as f64 + k as f64).sin()
            })
            .sum::<f64>()
            + 0.15 * j as f64
            - 0.4
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

/// The recording of `data` as states (the first 3 columns... of the inputs: 3 states) and
/// controls, fitted whole and streamed in blocks of an odd size: the same coefficients, bit for
/// bit, and the same score, for every derivative estimator.
#[test]
fn a_streamed_recording_fits_as_the_whole_one() {
    use sindy::{RowBlock, Trajectory};
    let rows = 45_001;
    let (inputs, _) = data(rows);
    let dt = 1e-3;
    let time: Vec<f64> = (0..rows).map(|k| k as f64 * dt).collect();
    let states = Mat::from_fn(rows, 3, |i, j| inputs[(i, j)]);
    let controls = Mat::from_fn(rows, 4, |i, j| inputs[(i, 3 + j)]);
    let trajectory = Trajectory::new(time.clone(), states.clone())
        .unwrap()
        .with_controls(controls.clone())
        .unwrap();
    for derivative in ["forward", "central", "savgol:9:3"] {
        let params = params(OptimizerSpec::stlsq(0.05))
            .derivative(sindy::Derivative::parse(derivative).unwrap());
        let whole = params.fit(std::slice::from_ref(&trajectory)).unwrap();
        let whole_score = whole.score(&trajectory).unwrap();
        let step = (time[rows - 1] - time[0]) / (rows - 1) as f64;
        let streamed = params
            .fit_streamed(rows, step, || {
                let (states, controls) = (&states, &controls);
                let mut next_row = 0;
                Ok(move || {
                    if next_row == rows {
                        return Ok(None);
                    }
                    let end = (next_row + 7_777).min(rows);
                    let mut columns = Vec::new();
                    for j in 0..3 {
                        columns.push((next_row..end).map(|i| states[(i, j)]).collect());
                    }
                    for j in 0..4 {
                        columns.push((next_row..end).map(|i| controls[(i, j)]).collect());
                    }
                    next_row = end;
                    Ok(Some(RowBlock {
                        columns,
                        time: None,
                    }))
                })
            })
            .unwrap();
        assert_eq!(streamed.rows, rows);
        assert_eq!(
            streamed.model.coefficients().to_owned(),
            whole.coefficients().to_owned(),
            "{derivative}"
        );
        // The score of the streamed fit is the reduced problem's: the same as reducing the whole
        // library and targets at once (and as predicting, up to the rounding of Θξ, which with
        // these near-collinear cubic features and large ξ is itself a few per cent).
        let mut y = Mat::zeros(rows, 3);
        for j in 0..3 {
            let column: Vec<f64> = (0..rows).map(|i| states[(i, j)]).collect();
            let estimate = sindy::Derivative::parse(derivative)
                .unwrap()
                .apply(&column, step)
                .unwrap();
            for (i, value) in estimate.into_iter().enumerate() {
                y[(i, j)] = value;
            }
        }
        let library = FeatureLibrary::from_spec(&LibrarySpec::parse("poly:3").unwrap()).unwrap();
        let theta = library.transform(inputs.as_ref());
        let reduced = sindy::Problem::reduced(theta.as_ref(), y.as_ref());
        let rss: f64 = reduced
            .residual_sum_of_squares(whole.coefficients())
            .iter()
            .sum();
        let (a, b) = (streamed.score, whole_score);
        let mse = rss / (3 * rows) as f64;
        assert!(
            (a.mse - mse).abs() <= 1e-12 * mse,
            "{derivative}: {a:?} {mse}"
        );
        assert!(
            (a.mse - b.mse).abs() <= 0.05 * b.mse,
            "{derivative}: {a:?} {b:?}"
        );
        assert_eq!(a.constant_states, b.constant_states);
    }
}

/// The rows of `inputs` (every column: states, then controls) in blocks of 7,777, from the first.
fn blocks_of(inputs: &Mat<f64>) -> impl FnMut() -> sindy::Result<Option<sindy::RowBlock>> + '_ {
    let mut next_row = 0;
    move || {
        let end = (next_row + 7_777).min(inputs.nrows());
        let columns = (0..inputs.ncols())
            .map(|j| (next_row..end).map(|i| inputs[(i, j)]).collect())
            .collect();
        let block = (next_row < end).then_some(sindy::RowBlock {
            columns,
            time: None,
        });
        next_row = end;
        Ok(block)
    }
}

/// `fit_streamed` of `inputs` (3 states, 4 controls) in blocks of 7,777 rows, within a pool of
/// `threads` threads.
fn streamed_in_pool(
    params: &SindyParams,
    inputs: &Mat<f64>,
    threads: usize,
) -> sindy::Result<sindy::StreamedFit> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| params.fit_streamed(inputs.nrows(), 1e-3, || Ok(blocks_of(inputs))))
}

/// Segments reduced by any number of workers, finishing in any order, are merged in row order:
/// the same coefficients, bit for bit, and the first fault in row order is the one named.
#[test]
fn a_streamed_fit_is_the_same_on_any_number_of_threads() {
    let rows = 4 * 32_768 + 1_001;
    let mut inputs = full_rank_inputs(rows);
    for reduction in [RowReduction::Gram, RowReduction::Householder] {
        let params = SindyParams::new(&["a", "b", "c"], &["p", "q", "r", "s"])
            .library(FeatureLibrary::from_spec(&LibrarySpec::parse("poly:2").unwrap()).unwrap())
            .optimizer(OptimizerSpec::stlsq(0.05))
            .reduction(reduction);
        let one = streamed_in_pool(&params, &inputs, 1).unwrap();
        assert_eq!(one.reduction.method, reduction);
        for threads in [2, 5] {
            let many = streamed_in_pool(&params, &inputs, threads).unwrap();
            assert_eq!(
                many.model.coefficients().to_owned(),
                one.model.coefficients().to_owned(),
                "{threads} threads, {reduction:?}"
            );
            assert_eq!(many.score.mse.to_bits(), one.score.mse.to_bits());
        }
    }
    // Faults in the fourth segment and in the second: the second's row is named.
    inputs[(3 * 32_768 + 5, 4)] = 1e200;
    inputs[(32_768 + 17, 5)] = 1e200;
    let params = SindyParams::new(&["a", "b", "c"], &["p", "q", "r", "s"])
        .library(FeatureLibrary::from_spec(&LibrarySpec::parse("poly:2").unwrap()).unwrap());
    for threads in [1, 2, 5] {
        match streamed_in_pool(&params, &inputs, threads).unwrap_err() {
            SindyError::NonFinite { row, .. } => assert_eq!(row, 32_768 + 17, "{threads}"),
            other => panic!("{other}"),
        }
    }
}

/// The inputs of [`data`] plus a pseudo-random part (a multiplicative hash of the position):
/// sinusoids of shared frequencies alone make the quadratic library rank-deficient.
fn full_rank_inputs(rows: usize) -> Mat<f64> {
    let (inputs, _) = data(rows);
    Mat::from_fn(rows, 7, |i, j| {
        let hash = ((i * 7 + j) as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        inputs[(i, j)] + 0.05 * (hash as f64 / 2f64.powi(64) - 0.5)
    })
}

/// `fit_streamed` of `inputs` in blocks of 7,777 rows, and how many times it opened them.
fn streamed_counting_opens(params: &SindyParams, inputs: &Mat<f64>) -> (sindy::StreamedFit, usize) {
    let mut opens = 0;
    let fit = params
        .fit_streamed(inputs.nrows(), 1e-3, || {
            opens += 1;
            Ok(blocks_of(inputs))
        })
        .unwrap();
    (fit, opens)
}

/// The rows are read once when their Gram matrix is kept, and again (by Householder QR, to the
/// same coefficients as a fit that uses it from the start) when it is refused.
#[test]
fn a_streamed_fit_reads_its_rows_again_only_when_the_gram_matrix_is_refused() {
    let rows = 2 * 32_768 + 99;
    let mut inputs = full_rank_inputs(rows);
    let params = SindyParams::new(&["a", "b", "c"], &["p", "q", "r", "s"])
        .library(FeatureLibrary::from_spec(&LibrarySpec::parse("poly:2").unwrap()).unwrap())
        .optimizer(OptimizerSpec::stlsq(0.05));
    let (fit, opens) = streamed_counting_opens(&params, &inputs);
    assert_eq!((opens, fit.reduction.method), (1, RowReduction::Gram));
    let condition = fit.reduction.gram_condition.unwrap();
    assert!(condition <= sindy::GRAM_CONDITION_LIMIT, "{condition}");
    let householder = params.clone().reduction(RowReduction::Householder);
    let (reference, opens) = streamed_counting_opens(&householder, &inputs);
    assert_eq!((opens, reference.reduction.gram_condition), (1, None));
    let difference = (fit.model.coefficients() - reference.model.coefficients()).norm_max();
    assert!(difference < 1e-9, "{difference}");

    // The last control nearly equal to the one before: the scaled condition number explodes.
    for i in 0..rows {
        inputs[(i, 6)] = inputs[(i, 5)] * (1.0 + 1e-5 * (i as f64 * 0.01).sin());
    }
    let (fit, opens) = streamed_counting_opens(&params, &inputs);
    assert_eq!(
        (opens, fit.reduction.method),
        (2, RowReduction::Householder)
    );
    assert!(fit.reduction.gram_condition.unwrap() > sindy::GRAM_CONDITION_LIMIT);
    let (reference, _) = streamed_counting_opens(&householder, &inputs);
    assert_eq!(
        fit.model.coefficients().to_owned(),
        reference.model.coefficients().to_owned()
    );
    assert_eq!(fit.score.mse.to_bits(), reference.score.mse.to_bits());
}

/// A noise-free recording of ẋ = −0.1 x + y, ẏ = −x − 0.1 y: a threshold that drops the −0.1
/// terms leaves a model whose residual the Gram matrix resolves (read once); one that keeps them
/// fits to the rounding of the derivatives, which the Gram matrix cannot resolve (read again).
#[test]
fn the_gram_matrix_is_judged_by_the_residual_of_the_chosen_model() {
    let rows = 40_000;
    let signal = Mat::from_fn(rows, 3, |i, j| {
        let t = i as f64 * 1e-3;
        let decay = (-0.1 * t).exp();
        [decay * t.cos(), -decay * t.sin(), (0.5 * t).sin()][j]
    });
    let fit = |threshold: f64| {
        let params =
            SindyParams::new(&["x", "y"], &["u"]).optimizer(OptimizerSpec::stlsq(threshold));
        streamed_counting_opens(&params, &signal)
    };
    let (sparse, opens) = fit(0.2);
    assert_eq!((opens, sparse.reduction.method), (1, RowReduction::Gram));
    assert_eq!(
        sparse.model.equations(2),
        vec!["x' = 1.01 y", "y' = -0.99 x"]
    );
    let (exact, opens) = fit(0.05);
    assert_eq!(
        (opens, exact.reduction.method),
        (2, RowReduction::Householder)
    );
    assert!(exact.reduction.gram_condition.unwrap() <= sindy::GRAM_CONDITION_LIMIT);
}
