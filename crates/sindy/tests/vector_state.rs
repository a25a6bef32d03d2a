//! faer's matrix products return with the upper halves of the vector registers in use, and the
//! scalar code after them (libm's `sin`/`cos` in the feature evaluation, measured ~20x slower)
//! pays for it until a `vzeroupper`. The crate clears that state in one place, after every faer
//! call (`linalg::kernels`); this checks, through the processor's own record (XGETBV with
//! ECX = 1: the state components in use), that every public entry point returns with it clear,
//! on the calling thread and on every rayon worker that did part of the work.
//!
//! One test function: the check reads the pool's threads, which another test running at the same
//! time could be using.

#![cfg(target_arch = "x86_64")]

use sindy::{
    Derivative, FeatureLibrary, Lasso, LibrarySpec, Mat, OptimizerSpec, Penalty, RegressionSpec,
    RowBlock, SindyParams, Stlsq, Trajectory, kkt_violation, least_squares,
};

/// XINUSE bits 2 (the upper halves of ymm0–15) and 6 (the upper halves of zmm0–15): what
/// `vzeroupper` clears and what slows SSE code down.
const UPPER_HALVES: u64 = (1 << 2) | (1 << 6);

/// Whether the processor can report the state in use (XGETBV with ECX = 1, CPUID.(0DH, 1):EAX[2]).
fn can_read_state() -> bool {
    if !(is_x86_feature_detected!("xsave") && is_x86_feature_detected!("avx")) {
        return false;
    }
    #[allow(unused_unsafe)]
    // SAFETY: CPUID leaf 0DH exists on every processor with XSAVE, checked above.
    let leaf = unsafe { std::arch::x86_64::__cpuid_count(0xd, 1) };
    leaf.eax & (1 << 2) != 0
}

#[target_feature(enable = "xsave")]
fn state_in_use() -> u64 {
    // SAFETY: XGETBV with ECX = 1 is supported (checked by `can_read_state` before any call).
    unsafe { std::arch::x86_64::_xgetbv(1) }
}

/// Records `after` in `failures` unless the upper halves are clear on this thread and on every
/// thread of rayon's pool.
fn check(failures: &mut Vec<String>, after: &str) {
    // SAFETY (both reads): only called once `can_read_state` held.
    let here = unsafe { state_in_use() } & UPPER_HALVES;
    let workers = rayon::broadcast(|_| unsafe { state_in_use() } & UPPER_HALVES);
    if here != 0 || workers.iter().any(|&w| w != 0) {
        failures.push(format!(
            "{after}: calling thread {here:#x}, rayon workers {workers:x?}"
        ));
    }
}

/// Smooth inputs (an offset and three sinusoids per column) and targets in the cubic library.
fn data(rows: usize, columns: usize) -> (Mat<f64>, Mat<f64>) {
    let inputs = Mat::from_fn(rows, columns, |i, j| {
        let t = i as f64 * 1e-3;
        (0..3)
            .map(|k| (0.3 + 0.2 * k as f64) * (t * (0.7 + 1.3 * (j + k) as f64) + j as f64).sin())
            .sum::<f64>()
            + 0.1 * j as f64
    });
    let targets = Mat::from_fn(rows, 3, |i, j| {
        let x = |k: usize| inputs[(i, k % columns)];
        match j {
            0 => 1.5 * x(1) - 0.7 * x(0) * x(2),
            1 => -2.0 * x(3).powi(3) + 0.4 * x(4),
            _ => 0.9 - 1.1 * x(5) * x(0),
        }
    });
    (inputs, targets)
}

fn params(optimizer: OptimizerSpec) -> SindyParams {
    SindyParams::new(&["a", "b", "c"], &["p", "q", "r", "s"])
        .library(FeatureLibrary::from_spec(&LibrarySpec::parse("poly:3").unwrap()).unwrap())
        .optimizer(optimizer)
}

#[test]
fn every_entry_point_leaves_the_upper_halves_clear() {
    if !can_read_state() {
        eprintln!("XGETBV with ECX = 1 is not supported: nothing to check");
        return;
    }
    let mut failures = Vec::new();
    check(&mut failures, "the test's start");
    let (small_inputs, small_targets) = data(2_000, 7);
    fitted_models(&mut failures, &small_inputs, &small_targets);
    trajectories(&mut failures, &small_inputs);
    let library = FeatureLibrary::from_spec(&LibrarySpec::parse("poly:2").unwrap()).unwrap();
    let theta = library.transform(small_inputs.as_ref());
    optimizers(&mut failures, &theta, &small_targets);
    regressions(&mut failures, &theta, &small_targets);
    assert!(
        failures.is_empty(),
        "upper halves left in use after:\n{}",
        failures.join("\n")
    );
}

/// SINDy models fitted and used on a small library (fitted whole) and a large one (reduced by row
/// blocks, in parallel).
fn fitted_models(failures: &mut Vec<String>, small_inputs: &Mat<f64>, small_targets: &Mat<f64>) {
    let (large_inputs, large_targets) = data(40_000, 7);
    for optimizer in [
        OptimizerSpec::stlsq(0.05),
        OptimizerSpec::Lasso { lambda: 2.0 },
    ] {
        let params = params(optimizer);
        let model = params
            .fit_matrices(small_inputs.as_ref(), small_targets.as_ref())
            .unwrap();
        check(failures, &format!("fit_matrices, {optimizer:?}"));
        model.predict_inputs(small_inputs.as_ref()).unwrap();
        check(failures, "predict_inputs");
        params
            .fit_and_predict(small_inputs.as_ref(), small_targets.as_ref())
            .unwrap();
        check(failures, "fit_and_predict");
        let large = params
            .fit_matrices(large_inputs.as_ref(), large_targets.as_ref())
            .unwrap();
        check(
            failures,
            &format!("fit_matrices on a large library, {optimizer:?}"),
        );
        large.predict_inputs(large_inputs.as_ref()).unwrap();
        check(failures, "predict_inputs on a large library");
    }
}

/// Trajectories: estimated derivatives (Savitzky–Golay solves for its weights), score, simulation,
/// and the streamed fit.
fn trajectories(failures: &mut Vec<String>, small_inputs: &Mat<f64>) {
    let rows = 3_000;
    let time: Vec<f64> = (0..rows).map(|k| k as f64 * 1e-3).collect();
    let states = Mat::from_fn(rows, 3, |i, j| small_inputs[(i % 2_000, j)]);
    let controls = Mat::from_fn(rows, 4, |i, j| small_inputs[(i % 2_000, 3 + j)]);
    let trajectory = Trajectory::new(time.clone(), states.clone())
        .unwrap()
        .with_controls(controls.clone())
        .unwrap();
    let params = params(OptimizerSpec::stlsq(0.05)).derivative(Derivative::SavitzkyGolay {
        window: 9,
        order: 3,
    });
    let model = params.fit(std::slice::from_ref(&trajectory)).unwrap();
    check(failures, "fit on a trajectory");
    model.score(&trajectory).unwrap();
    check(failures, "score");
    let column: Vec<f64> = (0..rows).map(|i| states[(i, 0)]).collect();
    Derivative::SavitzkyGolay {
        window: 9,
        order: 3,
    }
    .apply(&column, 1e-3)
    .unwrap();
    check(failures, "a Savitzky–Golay derivative");
    params
        .fit_streamed(rows, 1e-3, || {
            let (states, controls) = (&states, &controls);
            let mut next = 0;
            Ok(move || {
                if next == rows {
                    return Ok(None);
                }
                let end = (next + 1_000).min(rows);
                let mut columns: Vec<Vec<f64>> = (0..3)
                    .map(|j| (next..end).map(|i| states[(i, j)]).collect())
                    .collect();
                columns.extend((0..4).map(|j| (next..end).map(|i| controls[(i, j)]).collect()));
                next = end;
                Ok(Some(RowBlock {
                    columns,
                    time: None,
                }))
            })
        })
        .unwrap();
    check(failures, "fit_streamed");
}

/// The optimizers and the solver on a library matrix.
fn optimizers(failures: &mut Vec<String>, theta: &Mat<f64>, small_targets: &Mat<f64>) {
    let fit = Stlsq::new(0.05, 0.05, 20)
        .unwrap()
        .fit(theta.as_ref(), small_targets.as_ref());
    check(failures, "Stlsq::fit");
    let names = ["a", "b", "c"].map(String::from);
    let lasso = Lasso::new(1.0)
        .unwrap()
        .fit(theta.as_ref(), small_targets.as_ref(), &names)
        .unwrap();
    check(failures, "Lasso::fit");
    let target: Vec<f64> = (0..theta.nrows()).map(|i| small_targets[(i, 0)]).collect();
    let row: Vec<f64> = (0..theta.ncols()).map(|j| lasso[(0, j)]).collect();
    kkt_violation(theta.as_ref(), &target, &row, 1.0);
    check(failures, "kkt_violation");
    least_squares(theta.as_ref(), small_targets.as_ref());
    check(failures, "least_squares");
    let twin = Mat::from_fn(50, 2, |i, _| i as f64);
    least_squares(twin.as_ref(), small_targets.subrows(0, 50));
    check(failures, "least_squares on a rank-deficient matrix");
    assert_eq!(fit.coefficients.ncols(), theta.ncols());
}

/// Regularised regressions with cross-validation and bagging, and their predictions.
fn regressions(failures: &mut Vec<String>, theta: &Mat<f64>, small_targets: &Mat<f64>) {
    let penalties = [
        Penalty::Ridge {
            lambdas: vec![1e-4, 1e-2],
        },
        Penalty::Lasso {
            fractions: vec![1e-3, 1e-1],
        },
        Penalty::Stlsq {
            thresholds: vec![0.01, 0.1],
            alpha: 1e-6,
        },
    ];
    for penalty in penalties {
        let spec: RegressionSpec = serde_json::from_value(serde_json::json!({
            "penalty": penalty,
            "bagging": {"members": 3, "block": 100},
        }))
        .unwrap();
        let fit = spec.fit(theta.as_ref(), small_targets.as_ref(), 1).unwrap();
        check(failures, &format!("RegressionSpec::fit, {penalty:?}"));
        fit.ensemble(theta.as_ref()).unwrap();
        check(failures, "RegressionFit::ensemble");
        fit.predict(theta.as_ref());
        check(failures, "RegressionFit::predict");
    }
}
