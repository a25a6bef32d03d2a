//! Derivatives on the true time stamps: samples need not be evenly spaced (a logger's jitter,
//! dropped samples), except for Savitzky–Golay, which is refused with the sample off the grid.

use sindy::{
    Derivative, DifferentiationError, FeatureLibrary, LibrarySpec, Mat, OptimizerSpec, SindyParams,
    Trajectory,
};

/// Times from 0 with steps of `step` jittered by up to ±`jitter` of it (a fixed pattern).
fn jittered_times(n: usize, step: f64, jitter: f64) -> Vec<f64> {
    let mut time = vec![0.0];
    for k in 1..n {
        let wobble = ((k * 7919) % 1000) as f64 / 500.0 - 1.0;
        time.push(time[k - 1] + step * (1.0 + jitter * wobble));
    }
    time
}

#[test]
fn on_even_steps_the_estimate_is_the_uniform_one_bit_for_bit() {
    let time: Vec<f64> = (0..50).map(|k| k as f64 * 0.02).collect();
    let x: Vec<f64> = time.iter().map(|t| (3.0 * t).sin()).collect();
    for derivative in [Derivative::Forward, Derivative::Central, Derivative::SMOOTH] {
        let mean = (time[49] - time[0]) / 49.0;
        assert_eq!(
            derivative.apply_at_times(&x, &time).unwrap(),
            derivative.apply(&x, mean).unwrap(),
            "{derivative}"
        );
    }
}

#[test]
fn on_uneven_steps_differences_are_exact_on_low_degree_polynomials() {
    let time = jittered_times(40, 0.01, 0.4);
    let line: Vec<f64> = time.iter().map(|t| 2.0 - 3.0 * t).collect();
    let forward = Derivative::Forward.apply_at_times(&line, &time).unwrap();
    assert!(
        forward.iter().all(|d| (d + 3.0).abs() < 1e-9),
        "{forward:?}"
    );
    let parabola: Vec<f64> = time.iter().map(|t| 1.0 + t + 4.0 * t * t).collect();
    let central = Derivative::Central
        .apply_at_times(&parabola, &time)
        .unwrap();
    for (d, t) in central.iter().zip(&time) {
        assert!((d - (1.0 + 8.0 * t)).abs() < 1e-9, "at {t}: {d}");
    }
}

#[test]
fn savitzky_golay_refuses_uneven_steps_and_names_the_sample() {
    let mut time: Vec<f64> = (0..60).map(|k| k as f64 * 0.01).collect();
    for t in &mut time[31..] {
        *t += 0.004;
    }
    let x = vec![0.0; time.len()];
    match Derivative::SMOOTH.apply_at_times(&x, &time) {
        Err(DifferentiationError::NonUniformTime { sample, .. }) => assert_eq!(sample, 31),
        other => panic!("{other:?}"),
    }
    // Time stamps printed with a few digits are still a uniform grid.
    let rounded: Vec<f64> = (0..60)
        .map(|k| (k as f64 / 300.0 * 1e5).round() / 1e5)
        .collect();
    assert!(Derivative::SMOOTH.apply_at_times(&x, &rounded).is_ok());
}

/// ẋ = −0.5 x + u with u = sin(2t), integrated exactly enough (RK4, fine steps) and sampled at
/// `time`.
fn forced_decay(time: &[f64]) -> Trajectory {
    let fine = 200;
    let f = |t: f64, x: f64| -0.5 * x + (2.0 * t).sin();
    let mut x = 1.0;
    let mut states = vec![x];
    for w in time.windows(2) {
        let h = (w[1] - w[0]) / fine as f64;
        for i in 0..fine {
            let t = w[0] + i as f64 * h;
            let k1 = f(t, x);
            let k2 = f(t + h / 2.0, x + h / 2.0 * k1);
            let k3 = f(t + h / 2.0, x + h / 2.0 * k2);
            let k4 = f(t + h, x + h * k3);
            x += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        }
        states.push(x);
    }
    let n = time.len();
    Trajectory::new(time.to_vec(), Mat::from_fn(n, 1, |i, _| states[i]))
        .unwrap()
        .with_controls(Mat::from_fn(n, 1, |i, _| (2.0 * time[i]).sin()))
        .unwrap()
}

#[test]
fn a_fit_on_jittered_samples_recovers_the_coefficients() {
    // ±30% jitter: with one averaged step the central differences are off by tens of percent.
    let trajectories = [
        forced_decay(&jittered_times(800, 0.01, 0.3)),
        forced_decay(&jittered_times(500, 0.013, 0.3)),
    ];
    let model = SindyParams::new(&["x"], &["u"])
        .library(FeatureLibrary::from_spec(&LibrarySpec::parse("poly:1").unwrap()).unwrap())
        .optimizer(OptimizerSpec::stlsq(0.05))
        .derivative(Derivative::Central)
        .fit(&trajectories)
        .unwrap();
    let x = model.coefficient("x", "x").unwrap();
    let u = model.coefficient("x", "u").unwrap();
    assert!(
        (x + 0.5).abs() < 2e-3 && (u - 1.0).abs() < 2e-3,
        "{:?}",
        model.equations(4)
    );
    let pooled = model.score_all(&trajectories).unwrap();
    let first = model.score(&trajectories[0]).unwrap();
    assert!(pooled.r2 > 0.9999 && first.r2 > 0.9999, "{pooled:?}");
}

#[test]
fn a_streamed_fit_on_stamped_blocks_is_the_fit_of_the_whole_trajectory() {
    let trajectory = forced_decay(&jittered_times(3000, 0.01, 0.3));
    let params = SindyParams::new(&["x"], &["u"])
        .library(FeatureLibrary::from_spec(&LibrarySpec::parse("poly:2").unwrap()).unwrap())
        .optimizer(OptimizerSpec::stlsq(0.05))
        .derivative(Derivative::Central);
    let whole = params.fit(std::slice::from_ref(&trajectory)).unwrap();
    let rows = trajectory.time.len();
    let mean = (trajectory.time[rows - 1] - trajectory.time[0]) / (rows - 1) as f64;
    let streamed = params
        .fit_streamed(rows, mean, || {
            let trajectory = &trajectory;
            let mut start = 0;
            Ok(move || {
                let end = (start + 777).min(rows);
                let block = (start < end).then(|| sindy::RowBlock {
                    columns: vec![
                        trajectory
                            .states
                            .col(0)
                            .iter()
                            .skip(start)
                            .take(end - start)
                            .copied()
                            .collect(),
                        trajectory
                            .controls
                            .col(0)
                            .iter()
                            .skip(start)
                            .take(end - start)
                            .copied()
                            .collect(),
                    ],
                    time: Some(trajectory.time[start..end].to_vec()),
                });
                start = end;
                Ok(block)
            })
        })
        .unwrap();
    for (a, b) in whole
        .coefficients()
        .col_iter()
        .zip(streamed.model.coefficients().col_iter())
    {
        for (x, y) in a.iter().zip(b.iter()) {
            assert!((x - y).abs() < 1e-9 * (1.0 + x.abs()), "{x} {y}");
        }
    }
}
