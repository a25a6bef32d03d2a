//! Fitting a system from arrays, as with PySINDy: the Lorenz system sampled every 2 ms, its
//! derivatives estimated by central differences, a quadratic library and STLSQ; then STLSQ,
//! LASSO and ridge side by side on the library matrix itself.
//!
//! `cargo run -p sindy --example lorenz` prints the recovered equations, the fit's score, how
//! far a simulation of the fitted model drifts from the data over one second, and each
//! optimizer's number of terms and training error.

use sindy::{
    Derivative, FeatureLibrary, Lasso, LibrarySpec, Mat, Optimizer, OptimizerSpec, Problem, Ridge,
    SindyParams, Stlsq, Trajectory,
};

fn lorenz(x: &[f64; 3]) -> [f64; 3] {
    [
        10.0 * (x[1] - x[0]),
        x[0] * (28.0 - x[2]) - x[1],
        x[0] * x[1] - 8.0 / 3.0 * x[2],
    ]
}

/// Classic RK4 from `x0`, `steps` steps of `dt`.
fn integrate(x0: [f64; 3], dt: f64, steps: usize) -> Vec<[f64; 3]> {
    let mut states = vec![x0];
    let mut x = x0;
    let along =
        |x: &[f64; 3], d: &[f64; 3], h: f64| [x[0] + h * d[0], x[1] + h * d[1], x[2] + h * d[2]];
    for _ in 0..steps {
        let k1 = lorenz(&x);
        let k2 = lorenz(&along(&x, &k1, dt / 2.0));
        let k3 = lorenz(&along(&x, &k2, dt / 2.0));
        let k4 = lorenz(&along(&x, &k3, dt));
        for i in 0..3 {
            x[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
        states.push(x);
    }
    states
}

fn main() -> sindy::Result<()> {
    let dt = 0.002;
    let rows = integrate([-8.0, 8.0, 27.0], dt, 10_000);
    let time: Vec<f64> = (0..rows.len()).map(|k| k as f64 * dt).collect();
    let states = Mat::from_fn(rows.len(), 3, |i, j| rows[i][j]);
    let trajectory = Trajectory::new(time.clone(), states)?;

    let library = FeatureLibrary::from_spec(&LibrarySpec::parse("poly:2")?)?;
    let params = SindyParams::new(&["x", "y", "z"], &[])
        .library(library.clone())
        .optimizer(OptimizerSpec::stlsq(0.1))
        .derivative(Derivative::Central);
    let model = params.fit(std::slice::from_ref(&trajectory))?;
    for line in model.equations(3) {
        println!("{line}");
    }
    let score = model.score(&trajectory)?;
    println!("MSE {:.3e}, R² {:.6}", score.mse, score.r2);

    // One second of the fitted model from the first sample, against the data.
    let horizon = 500;
    let no_controls = Mat::<f64>::zeros(horizon, 0);
    let simulated = model.simulate(&rows[0], &time[..horizon], no_controls.as_ref())?;
    let drift = (0..horizon)
        .flat_map(|k| (0..3).map(move |j| (k, j)))
        .map(|(k, j)| (simulated[(k, j)] - rows[k][j]).abs())
        .fold(0.0, f64::max);
    println!("largest deviation of a 1 s simulation from the data: {drift:.3}");

    // The optimizers on the library matrix and the estimated derivatives, as PySINDy's
    // `optimizer.fit(Θ, ẋ)`: one problem, any optimizer. On these unscaled features LASSO keeps
    // many small terms where STLSQ's threshold removes them.
    let theta = library.transform(trajectory.states.as_ref());
    let derivatives = Derivative::Central.apply_columns(trajectory.states.as_ref(), dt)?;
    let problem = Problem::new(theta.as_ref(), derivatives.as_ref());
    let optimizers: [(&str, &dyn Optimizer); 3] = [
        ("STLSQ (threshold 0.1)", &Stlsq::new(0.1, 0.05, 20)?),
        ("LASSO (λ = 1000)", &Lasso::new(1000.0)?),
        ("ridge (α = 1)", &Ridge::new(1.0)?),
    ];
    for (name, optimizer) in optimizers {
        let xi = optimizer.solve(&problem)?;
        let terms = (0..xi.nrows())
            .flat_map(|i| (0..xi.ncols()).map(move |j| (i, j)))
            .filter(|&(i, j)| xi[(i, j)] != 0.0)
            .count();
        let residual: f64 = problem.residual_sum_of_squares(xi.as_ref()).iter().sum();
        let mse = residual / (3 * problem.rows()) as f64;
        println!(
            "{name}: {terms} of {} coefficients non-zero, MSE {mse:.3e}",
            xi.nrows() * xi.ncols()
        );
    }
    Ok(())
}
