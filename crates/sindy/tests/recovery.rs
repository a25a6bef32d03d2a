//! Exact recovery of known sparse systems from clean data: Lorenz (polynomial), a forced Duffing
//! oscillator with a control input, and a damped pendulum (needs the Fourier library), plus
//! simulation of the recovered models.

mod common;

use common::integrate;
use sindy::Derivative;
use sindy::{FeatureLibrary, LibrarySpec, Mat, OptimizerSpec, SindyParams, Trajectory};

fn trajectory(
    rows: &[Vec<f64>],
    h: f64,
    rhs: impl Fn(f64, &[f64]) -> Vec<f64>,
    state_dim: usize,
    control: impl Fn(f64) -> Vec<f64>,
) -> Trajectory {
    let n = rows.len();
    let time: Vec<f64> = (0..n).map(|k| k as f64 * h).collect();
    let states = Mat::from_fn(n, state_dim, |i, j| rows[i][j]);
    let derivatives = Mat::from_fn(n, state_dim, |i, j| rhs(time[i], &rows[i])[j]);
    let controls = time.iter().map(|&t| control(t)).collect::<Vec<_>>();
    let dim_u = controls[0].len();
    Trajectory::new(time, states)
        .unwrap()
        .with_controls(Mat::from_fn(n, dim_u, |i, j| controls[i][j]))
        .unwrap()
        .with_derivatives(derivatives)
        .unwrap()
}

fn lorenz(_: f64, x: &[f64]) -> Vec<f64> {
    vec![
        10.0 * (x[1] - x[0]),
        x[0] * (28.0 - x[2]) - x[1],
        x[0] * x[1] - 8.0 / 3.0 * x[2],
    ]
}

fn assert_model(model: &sindy::SindyModel, expected: &[(&str, &str, f64)], tolerance: f64) {
    let ours = model.coefficients();
    let mut seen = 0;
    for (i, state) in model.state_names().iter().enumerate() {
        for (j, feature) in model.feature_names().iter().enumerate() {
            let want = expected
                .iter()
                .find(|(s, f, _)| s == state && f == feature)
                .map_or(0.0, |e| e.2);
            if want != 0.0 {
                seen += 1;
            }
            assert!(
                (ours[(i, j)] - want).abs() <= tolerance * want.abs().max(1.0),
                "{state}' {feature}: {} vs {want}\n{}",
                ours[(i, j)],
                model.equations(4).join("\n")
            );
        }
    }
    assert_eq!(
        seen,
        expected.len(),
        "every expected term names a real feature"
    );
}

#[test]
fn lorenz_is_recovered_exactly_and_with_estimated_derivatives() {
    let h = 0.002;
    let rows = integrate(lorenz, &[-8.0, 8.0, 27.0], h, 5000);
    let exact = trajectory(&rows, h, lorenz, 3, |_| vec![]);
    let params = SindyParams::new(&["x", "y", "z"], &[]).optimizer(OptimizerSpec::stlsq(0.1));
    let expected = [
        ("x", "x", -10.0),
        ("x", "y", 10.0),
        ("y", "x", 28.0),
        ("y", "y", -1.0),
        ("y", "x*z", -1.0),
        ("z", "z", -8.0 / 3.0),
        ("z", "x*y", 1.0),
    ];
    assert_model(
        &params.fit(std::slice::from_ref(&exact)).unwrap(),
        &expected,
        1e-9,
    );
    assert_eq!(
        params
            .fit(std::slice::from_ref(&exact))
            .unwrap()
            .equations(3)[0],
        "x' = -10.000 x + 10.000 y"
    );

    // Without derivatives the model estimates them (central differences): close, same support.
    let mut estimated = exact;
    estimated.derivatives = None;
    let model = params
        .derivative(Derivative::Central)
        .fit(&[estimated.clone()])
        .unwrap();
    assert_model(&model, &expected, 2e-3);
    let score = model.score(&estimated).unwrap();
    assert!(score.r2 > 0.9999 && score.mse < 1e-2, "{score:?}");
}

#[test]
fn forced_duffing_with_a_control_input_is_recovered_and_simulated() {
    // ẍ + 0.2ẋ − x + x³ = 0.3u, u = cos(1.2t)
    let duffing = |t: f64, s: &[f64]| -> Vec<f64> {
        let u = (1.2 * t).cos();
        vec![s[1], -0.2 * s[1] + s[0] - s[0].powi(3) + 0.3 * u]
    };
    let h = 0.01;
    let rows = integrate(duffing, &[0.5, 0.0], h, 4000);
    let data = trajectory(&rows, h, duffing, 2, |t| vec![(1.2 * t).cos()]);
    let model = SindyParams::new(&["x", "v"], &["u"])
        .library(FeatureLibrary::from_spec(&LibrarySpec::parse("poly:3").unwrap()).unwrap())
        .optimizer(OptimizerSpec::stlsq(0.05))
        .fit(std::slice::from_ref(&data))
        .unwrap();
    let expected = [
        ("x", "v", 1.0),
        ("v", "v", -0.2),
        ("v", "x", 1.0),
        ("v", "x^3", -1.0),
        ("v", "u", 0.3),
    ];
    assert_model(&model, &expected, 1e-9);

    // RK4 with linearly interpolated control follows the true trajectory for 5 s.
    let steps = 500;
    let simulated = model
        .simulate(
            &rows[0],
            &data.time[..=steps],
            data.controls.as_ref().subrows(0, steps + 1),
        )
        .unwrap();
    let error = (0..=steps)
        .map(|k| (simulated[(k, 0)] - rows[k][0]).abs())
        .fold(0.0, f64::max);
    assert!(error < 1e-4, "simulation drifts by {error}");
}

#[test]
fn pendulum_needs_and_gets_the_fourier_library_from_two_trajectories() {
    // θ̈ = −9.81 sin θ − 0.1 θ̇, large swings so that sin θ differs from θ.
    let pendulum = |_: f64, s: &[f64]| vec![s[1], -9.81 * s[0].sin() - 0.1 * s[1]];
    let h = 0.005;
    let trajectories: Vec<Trajectory> = [[2.0, 0.0], [-1.0, 3.0]]
        .iter()
        .map(|x0| {
            trajectory(
                &integrate(pendulum, x0, h, 1500),
                h,
                pendulum,
                2,
                |_| vec![],
            )
        })
        .collect();
    let fourier = SindyParams::new(&["theta", "omega"], &[])
        .library(
            FeatureLibrary::from_spec(&LibrarySpec::parse("poly:1:noconstant+fourier:1").unwrap())
                .unwrap(),
        )
        .optimizer(OptimizerSpec::stlsq(0.05))
        .fit(&trajectories)
        .unwrap();
    let expected = [
        ("theta", "omega", 1.0),
        ("omega", "sin(theta)", -9.81),
        ("omega", "omega", -0.1),
    ];
    assert_model(&fourier, &expected, 1e-9);
    assert_eq!(
        fourier.equations(2)[1],
        "omega' = -0.10 omega - 9.81 sin(theta)"
    );

    // A cubic polynomial library cannot represent sin θ: its fit is visibly worse.
    let polynomial = SindyParams::new(&["theta", "omega"], &[])
        .optimizer(OptimizerSpec::stlsq(0.05))
        .library(FeatureLibrary::from_spec(&LibrarySpec::parse("poly:3").unwrap()).unwrap())
        .fit(&trajectories)
        .unwrap();
    let residual = |m: &sindy::SindyModel| m.score(&trajectories[0]).unwrap().mse;
    assert!(residual(&fourier) < 1e-18 && residual(&polynomial) > 1e-6);
}
