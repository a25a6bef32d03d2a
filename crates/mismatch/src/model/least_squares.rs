//! The nonlinear least-squares solver of the crate: Levenberg–Marquardt with bounds, for the fits
//! of one recording ([`crate::levenberg_marquardt`]) and the joint fit of a fleet
//! ([`crate::fleet`]'s vehicle and airs).
//!
//! It minimises `S(x) = ‖r(x)‖²` over parameters `x` within bounds `l ≤ x ≤ u` (each bound may be
//! infinite). From the start, projected onto the bounds, each iteration linearises `r` at `x`
//! (`r(x − s) ≈ r − J s`) and tries damped Gauss–Newton steps
//!
//! ```text
//! (JᵀJ + λ D) s = Jᵀ r,    D = diag(max((JᵀJ)ᵢᵢ, 10⁻¹²))    (Marquardt's scaling)
//! x' = P(x − s)                                             (P: projection onto the bounds)
//! ```
//!
//! With [`ActiveBounds::Hold`], a parameter on a bound that the step would cross is held there
//! (its row and column of the system replaced by `sᵢ = 0`) and the step solved again for the
//! others, which is Gauss–Newton on the free parameters once the active set settles. With
//! [`ActiveBounds::Project`] the trial point is only projected: while a bound is active the other
//! parameters move by steps meant for a point beyond it, and the fit crawls along the bound (on
//! the golden decay fit below, 40 iterations leave the decay rate 0.019 from SciPy's, where
//! holding converges to within 10⁻⁷ in 13). The crate's fits still project, as the loops this
//! module replaced did: holding would change their results.
//!
//! A trial `x'` is accepted when `S(x')` is finite and below `S(x)`; the damping `λ` then falls
//! (`λ ← max(λ / decrease, λ_min)`), and otherwise grows (`λ ← λ · increase`) for the next try.
//! The fit stops ([`Termination`]) when an accepted step lowers `S` by a relative amount
//! `(S − S') / S` of at most `tolerance` (converged), when none of `tries` damped steps lowers it,
//! after `iterations` linearisations, or at once when there is no parameter.
//!
//! A problem ([`LeastSquares`]) says how to evaluate its residual, sum its squares, linearise it
//! and solve for a damped step: a problem given only by its residual vector ([`DenseProblem`])
//! gets the forward-difference Jacobian and the dense normal equations above; the fleet's joint
//! fit solves the same equations through the Schur complement of its per-flight blocks.
//!
//! Golden tests (below) compare the solutions with SciPy's `least_squares` (trust-region
//! reflective) on three problems, one with a bound active at the solution
//! (`scripts/golden/least_squares.py`).

use faer::Mat;
use faer::linalg::solvers::Solve;

use crate::error::{MismatchError, Result};

/// A least-squares problem: `S(x) = ‖r(x)‖²` over bounded parameters.
pub trait LeastSquares {
    /// The residual at a point, as the sum of squares and the linearisation there use it.
    type Residual;
    /// What a damped step is solved from (e.g. `JᵀJ` and `Jᵀr`).
    type Linearisation;

    /// The number of parameters.
    fn dimension(&self) -> usize;

    /// The lower and upper bound of parameter `index` (infinite where there is none; lower ≤
    /// upper, neither NaN).
    fn bounds(&self, index: usize) -> (f64, f64);

    /// The residual at `x`.
    fn residual(&self, x: &[f64]) -> Self::Residual;

    /// `‖r‖²`.
    fn sum_of_squares(&self, residual: &Self::Residual) -> f64;

    /// The linearisation at `x`, whose residual is `residual`.
    fn linearise(&self, x: &[f64], residual: &Self::Residual) -> Self::Linearisation;

    /// The step `s` of `(JᵀJ + λD) s = Jᵀr` (the solver moves to `x − s`), zero for the `held`
    /// parameters and for the others solved with the held rows and columns left out; `None` when
    /// the system cannot be solved.
    fn damped_step(
        &self,
        linearisation: &Self::Linearisation,
        damping: f64,
        held: &[bool],
    ) -> Option<Vec<f64>>;
}

/// A problem given by its residual vector: the Jacobian by forward differences, the damped step
/// from the dense normal equations ([`NormalEquations`]).
pub trait DenseProblem {
    /// The number of parameters.
    fn dimension(&self) -> usize;

    /// The lower and upper bound of parameter `index`.
    fn bounds(&self, index: usize) -> (f64, f64);

    /// The residual vector at `x`.
    fn residual(&self, x: &[f64]) -> Vec<f64>;

    /// The forward-difference step of parameter `index` at `value`.
    fn difference_step(&self, index: usize, value: f64) -> f64;
}

/// `JᵀJ` and `Jᵀr` of a dense problem at a point.
#[derive(Clone, Debug)]
pub struct NormalEquations {
    normal: Mat<f64>,
    gradient: Mat<f64>,
}

impl NormalEquations {
    /// From the Jacobian by columns and the residual.
    pub fn new(jacobian: &[Vec<f64>], residual: &[f64]) -> Self {
        let gradient = Mat::from_fn(jacobian.len(), 1, |i, _| {
            jacobian[i].iter().zip(residual).map(|(a, b)| a * b).sum()
        });
        Self {
            normal: normal_matrix(jacobian),
            gradient,
        }
    }

    /// The solution of `(JᵀJ + λD) s = Jᵀr`, the `held` parameters' rows and columns replaced by
    /// `sᵢ = 0` (non-finite where the system is singular: the sum of squares at the trial point
    /// then rejects it, or the bounds hold it).
    pub fn damped_step(&self, damping: f64, held: &[bool]) -> Vec<f64> {
        let n = self.normal.nrows();
        let mut system = self.normal.clone();
        for i in 0..n {
            system[(i, i)] += damping * self.normal[(i, i)].max(1e-12);
        }
        let mut gradient = self.gradient.clone();
        hold(&mut system, &mut gradient, held);
        let step = system.full_piv_lu().solve(&gradient);
        (0..n)
            .map(|i| if held[i] { 0.0 } else { step[(i, 0)] })
            .collect()
    }
}

/// Replaces the rows and columns of the `held` unknowns of `system · s = rhs` by `sᵢ = 0`.
pub fn hold(system: &mut Mat<f64>, rhs: &mut Mat<f64>, held: &[bool]) {
    for (i, _) in held.iter().enumerate().filter(|(_, held)| **held) {
        for j in 0..system.nrows() {
            system[(i, j)] = 0.0;
            system[(j, i)] = 0.0;
        }
        system[(i, i)] = 1.0;
        rhs[(i, 0)] = 0.0;
    }
}

impl<P: DenseProblem> LeastSquares for P {
    type Residual = Vec<f64>;
    type Linearisation = NormalEquations;

    fn dimension(&self) -> usize {
        DenseProblem::dimension(self)
    }

    fn bounds(&self, index: usize) -> (f64, f64) {
        DenseProblem::bounds(self, index)
    }

    fn residual(&self, x: &[f64]) -> Vec<f64> {
        DenseProblem::residual(self, x)
    }

    fn sum_of_squares(&self, residual: &Vec<f64>) -> f64 {
        residual.iter().map(|r| r * r).sum()
    }

    fn linearise(&self, x: &[f64], residual: &Vec<f64>) -> NormalEquations {
        NormalEquations::new(&forward_jacobian(self, x, residual), residual)
    }

    fn damped_step(
        &self,
        linearisation: &NormalEquations,
        damping: f64,
        held: &[bool],
    ) -> Option<Vec<f64>> {
        Some(linearisation.damped_step(damping, held))
    }
}

/// The forward-difference Jacobian of `problem` at `x`, whose residual is `residual`: one column
/// per parameter, each a vector over the residual's elements.
pub fn forward_jacobian<P: DenseProblem + ?Sized>(
    problem: &P,
    x: &[f64],
    residual: &[f64],
) -> Vec<Vec<f64>> {
    (0..x.len())
        .map(|j| {
            let step = problem.difference_step(j, x[j]);
            let mut shifted = x.to_vec();
            shifted[j] += step;
            problem
                .residual(&shifted)
                .iter()
                .zip(residual)
                .map(|(a, b)| (a - b) / step)
                .collect()
        })
        .collect()
}

/// `JᵀJ` of a Jacobian given by columns.
pub fn normal_matrix(jacobian: &[Vec<f64>]) -> Mat<f64> {
    let k = jacobian.len();
    let mut normal = Mat::<f64>::zeros(k, k);
    for i in 0..k {
        for j in 0..=i {
            let v: f64 = jacobian[i]
                .iter()
                .zip(&jacobian[j])
                .map(|(a, b)| a * b)
                .sum();
            normal[(i, j)] = v;
            normal[(j, i)] = v;
        }
    }
    normal
}

/// Why a fit stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Termination {
    /// An accepted step lowered the sum of squares by a relative amount of at most the tolerance.
    Converged,
    /// None of the damped steps of an iteration lowered the sum of squares.
    NoImprovingStep,
    /// The iterations ran out while the steps still lowered the sum of squares.
    IterationLimit,
    /// There was no parameter to fit: the start is the solution.
    NothingToFit,
}

/// The outcome of a fit.
#[derive(Clone, Debug, PartialEq)]
pub struct Solution {
    /// The parameters, within their bounds.
    pub values: Vec<f64>,
    /// `‖r‖²` at `values`.
    pub sum_of_squares: f64,
    /// Linearisations made.
    pub iterations: usize,
    pub termination: Termination,
}

/// Levenberg–Marquardt settings, unchecked ([`LevenbergMarquardtParams::checked`] gives the
/// solver).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LevenbergMarquardtParams {
    /// The most linearisations (any number: none returns the projected start).
    pub iterations: usize,
    /// Damped steps tried per iteration before giving up (at least 1).
    pub tries: usize,
    /// λ at the start (finite, > 0).
    pub initial_damping: f64,
    /// The floor of λ after successes (finite, in (0, `initial_damping`]).
    pub min_damping: f64,
    /// λ's factor after a failed try (finite, > 1).
    pub increase: f64,
    /// λ's divisor after an accepted step (finite, > 1).
    pub decrease: f64,
    /// The relative decrease of `S` at or below which an accepted step ends the fit (finite, ≥ 0).
    pub tolerance: f64,
    /// What a step does with a parameter on a bound that it would cross.
    pub active_bounds: ActiveBounds,
}

/// What a step does with a parameter on a bound that it would cross.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ActiveBounds {
    /// Nothing: the trial point is projected onto the bounds (slow while a bound is active).
    Project,
    /// The parameter is held on its bound for the step and the step solved again for the others
    /// (until no held parameter is added): Gauss–Newton on the parameters that are free, as
    /// a projected Newton method with an active set does.
    Hold,
}

impl LevenbergMarquardtParams {
    /// The solver, every setting checked.
    pub fn checked(&self) -> Result<LevenbergMarquardt> {
        let invalid = |setting: &'static str, value: String, rule: &str| {
            Err(MismatchError::SolverSetting {
                setting,
                message: format!("{value} {rule}"),
            })
        };
        let finite_above = |x: f64, floor: f64| x.is_finite() && x > floor;
        if self.tries == 0 {
            return invalid("tries", "0".into(), "must be at least 1");
        }
        if !finite_above(self.initial_damping, 0.0) {
            return invalid(
                "initial_damping",
                self.initial_damping.to_string(),
                "must be finite and > 0",
            );
        }
        if !(finite_above(self.min_damping, 0.0) && self.min_damping <= self.initial_damping) {
            return invalid(
                "min_damping",
                self.min_damping.to_string(),
                "must be > 0 and at most initial_damping",
            );
        }
        for (setting, factor) in [("increase", self.increase), ("decrease", self.decrease)] {
            if !finite_above(factor, 1.0) {
                return invalid(setting, factor.to_string(), "must be finite and > 1");
            }
        }
        if !(self.tolerance.is_finite() && self.tolerance >= 0.0) {
            return invalid(
                "tolerance",
                self.tolerance.to_string(),
                "must be finite and ≥ 0",
            );
        }
        Ok(LevenbergMarquardt { settings: *self })
    }
}

/// Checked Levenberg–Marquardt settings: the solver.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LevenbergMarquardt {
    settings: LevenbergMarquardtParams,
}

impl LevenbergMarquardt {
    /// The damped step at `values`; with [`ActiveBounds::Hold`], solved again with each parameter
    /// on a bound that it would cross held, until none is added.
    fn step<P: LeastSquares + ?Sized>(
        &self,
        problem: &P,
        linearisation: &P::Linearisation,
        values: &[f64],
        damping: f64,
    ) -> Option<Vec<f64>> {
        let mut held = vec![false; values.len()];
        let mut step = problem.damped_step(linearisation, damping, &held)?;
        if self.settings.active_bounds == ActiveBounds::Project {
            return Some(step);
        }
        loop {
            let mut added = false;
            for (i, (value, s)) in values.iter().zip(&step).enumerate() {
                let (lower, upper) = problem.bounds(i);
                let crosses = (*value == lower && value - s < lower)
                    || (*value == upper && value - s > upper);
                if crosses && !held[i] {
                    held[i] = true;
                    added = true;
                }
            }
            if !added {
                return Some(step);
            }
            step = problem.damped_step(linearisation, damping, &held)?;
        }
    }

    /// The same solver with another iteration limit (every limit is valid).
    pub fn with_iterations(mut self, iterations: usize) -> Self {
        self.settings.iterations = iterations;
        self
    }

    /// Minimises `problem`'s sum of squares from `start` (projected onto the bounds first).
    pub fn run<P: LeastSquares + ?Sized>(&self, problem: &P, start: &[f64]) -> Solution {
        let settings = &self.settings;
        let project = |x: &mut [f64]| {
            for (i, v) in x.iter_mut().enumerate() {
                let (lower, upper) = problem.bounds(i);
                *v = v.clamp(lower, upper);
            }
        };
        let mut values = start.to_vec();
        project(&mut values);
        let mut residual = problem.residual(&values);
        let mut sum_of_squares = problem.sum_of_squares(&residual);
        let solution = |values, sum_of_squares, iterations, termination| Solution {
            values,
            sum_of_squares,
            iterations,
            termination,
        };
        if problem.dimension() == 0 {
            return solution(values, sum_of_squares, 0, Termination::NothingToFit);
        }
        let mut damping = settings.initial_damping;
        for iteration in 1..=settings.iterations {
            let linearisation = problem.linearise(&values, &residual);
            let mut decrease = None;
            for _ in 0..settings.tries {
                let Some(step) = self.step(problem, &linearisation, &values, damping) else {
                    damping *= settings.increase;
                    continue;
                };
                let mut trial: Vec<f64> = values.iter().zip(&step).map(|(v, s)| v - s).collect();
                project(&mut trial);
                let trial_residual = problem.residual(&trial);
                let trial_sum = problem.sum_of_squares(&trial_residual);
                if trial_sum.is_finite() && trial_sum < sum_of_squares {
                    decrease = Some((sum_of_squares - trial_sum) / sum_of_squares.max(1e-300));
                    values = trial;
                    residual = trial_residual;
                    sum_of_squares = trial_sum;
                    damping = (damping / settings.decrease).max(settings.min_damping);
                    break;
                }
                damping *= settings.increase;
            }
            let termination = match decrease {
                None => Termination::NoImprovingStep,
                Some(relative) if relative <= settings.tolerance => Termination::Converged,
                Some(_) => continue,
            };
            return solution(values, sum_of_squares, iteration, termination);
        }
        solution(
            values,
            sum_of_squares,
            settings.iterations,
            Termination::IterationLimit,
        )
    }
}

#[cfg(test)]
mod tests {
    use std::cell::RefCell;

    use super::*;

    /// A dense problem from a residual function and bounds, forward differences of 1e-7.
    struct Golden {
        residual: fn(&[f64]) -> Vec<f64>,
        bounds: Vec<(f64, f64)>,
    }

    impl DenseProblem for Golden {
        fn dimension(&self) -> usize {
            self.bounds.len()
        }

        fn bounds(&self, index: usize) -> (f64, f64) {
            self.bounds[index]
        }

        fn residual(&self, x: &[f64]) -> Vec<f64> {
            (self.residual)(x)
        }

        fn difference_step(&self, _: usize, value: f64) -> f64 {
            1e-7 * value.abs().max(1.0)
        }
    }

    const FREE: (f64, f64) = (f64::NEG_INFINITY, f64::INFINITY);

    fn decay(x: &[f64]) -> Vec<f64> {
        (0..21)
            .map(|k| {
                let t = 0.5 * k as f64;
                let data = 2.0 * (-0.7 * t).exp() + 0.3 + 0.05 * (3.0 * t).sin();
                x[0] * (-x[1] * t).exp() + x[2] - data
            })
            .collect()
    }

    fn rosenbrock(x: &[f64]) -> Vec<f64> {
        vec![10.0 * (x[1] - x[0] * x[0]), 1.0 - x[0]]
    }

    fn kowalik(x: &[f64]) -> Vec<f64> {
        const U: [f64; 11] = [
            4.0, 2.0, 1.0, 0.5, 0.25, 0.167, 0.125, 0.1, 0.0833, 0.0714, 0.0625,
        ];
        const Y: [f64; 11] = [
            0.1957, 0.1947, 0.1735, 0.16, 0.0844, 0.0627, 0.0456, 0.0342, 0.0323, 0.0235, 0.0246,
        ];
        U.iter()
            .zip(Y)
            .map(|(u, y)| x[0] * (u * u + x[1] * u) / (u * u + x[2] * u + x[3]) - y)
            .collect()
    }

    /// A tight tolerance, so that the solution is SciPy's to the accuracy of the differences.
    fn solver() -> LevenbergMarquardt {
        LevenbergMarquardtParams {
            iterations: 200,
            tries: 8,
            initial_damping: 1e-3,
            min_damping: 1e-9,
            increase: 10.0,
            decrease: 3.0,
            tolerance: 1e-12,
            active_bounds: ActiveBounds::Hold,
        }
        .checked()
        .unwrap()
    }

    fn assert_golden(solution: &Solution, x: &[f64], sum_of_squares: f64) {
        assert_eq!(solution.termination, Termination::Converged, "{solution:?}");
        for (found, golden) in solution.values.iter().zip(x) {
            assert!((found - golden).abs() < 1e-6, "{solution:?} against {x:?}");
        }
        let relative = (solution.sum_of_squares - sum_of_squares).abs() / sum_of_squares;
        assert!(relative < 1e-8, "{solution:?} against {sum_of_squares}");
    }

    // The golden values are `scripts/golden/least_squares.py`'s output with SciPy 1.17.1 (NumPy
    // 2.4.6): `scipy.optimize.least_squares`, method "trf", analytic Jacobians, tolerances 1e-15.

    #[test]
    fn a_bounded_decay_fit_ends_on_its_active_bound_as_in_scipy() {
        let problem = Golden {
            residual: decay,
            bounds: vec![(0.0, 10.0), (0.0, 5.0), (0.5, 2.0)],
        };
        let solution = solver().run(&problem, &[1.0, 1.0, 1.0]);
        assert_golden(
            &solution,
            &[1.8757807269739895, 0.9536726172626298, 0.5000000000000001],
            0.4818438824920588,
        );
        assert_eq!(solution.values[2], 0.5, "the bound holds exactly");
    }

    #[test]
    fn rosenbrock_with_a_bound_on_its_valley_is_solved_as_in_scipy() {
        let problem = Golden {
            residual: rosenbrock,
            bounds: vec![FREE, (1.5, f64::INFINITY)],
        };
        let solution = solver().run(&problem, &[2.0, 2.0]);
        assert_golden(
            &solution,
            &[1.2243707487363529, 1.5000000000000002],
            0.05042618789360711,
        );
    }

    #[test]
    fn projecting_onto_an_active_bound_crawls_along_it() {
        // The bounds as this crate's fits treat them (ActiveBounds::Project), their 40 iterations.
        let problem = Golden {
            residual: decay,
            bounds: vec![(0.0, 10.0), (0.0, 5.0), (0.5, 2.0)],
        };
        let projecting = crate::model::refine::RECORDING_FIT;
        let projected = projecting
            .checked()
            .unwrap()
            .run(&problem, &[1.0, 1.0, 1.0]);
        assert_eq!(projected.termination, Termination::IterationLimit);
        assert!(
            (projected.values[1] - 0.9536726172626298).abs() > 1e-3,
            "{projected:?}"
        );
        let holding = LevenbergMarquardtParams {
            active_bounds: ActiveBounds::Hold,
            ..projecting
        };
        let held = holding.checked().unwrap().run(&problem, &[1.0, 1.0, 1.0]);
        assert_eq!(held.termination, Termination::Converged);
        assert!(held.iterations < 40 && held.sum_of_squares < projected.sum_of_squares);
    }

    #[test]
    fn the_unbounded_kowalik_osborne_fit_is_solved_as_in_scipy() {
        let problem = Golden {
            residual: kowalik,
            bounds: vec![FREE; 4],
        };
        let solution = solver().run(&problem, &[0.25, 0.39, 0.415, 0.39]);
        assert_golden(
            &solution,
            &[
                0.19280693424771222,
                0.1912823361761711,
                0.1230565083277241,
                0.1360623341292103,
            ],
            0.0003075056038492374,
        );
    }

    #[test]
    fn running_out_of_iterations_is_reported_with_the_progress_so_far() {
        let problem = Golden {
            residual: kowalik,
            bounds: vec![FREE; 4],
        };
        let start = [0.25, 0.39, 0.415, 0.39];
        let solution = solver().with_iterations(2).run(&problem, &start);
        assert_eq!(solution.termination, Termination::IterationLimit);
        assert_eq!(solution.iterations, 2);
        let at_start: f64 = kowalik(&start).iter().map(|r| r * r).sum();
        assert!(solution.sum_of_squares < at_start);
        let converged = solver().run(&problem, &start);
        assert!(converged.sum_of_squares < solution.sum_of_squares);
    }

    /// A problem whose every damped step fails (its system is singular), recording the dampings
    /// it was asked for.
    struct Singular {
        dampings: RefCell<Vec<f64>>,
    }

    impl LeastSquares for Singular {
        type Residual = Vec<f64>;
        type Linearisation = ();

        fn dimension(&self) -> usize {
            1
        }

        fn bounds(&self, _: usize) -> (f64, f64) {
            FREE
        }

        fn residual(&self, x: &[f64]) -> Vec<f64> {
            vec![x[0] - 1.0]
        }

        fn sum_of_squares(&self, residual: &Vec<f64>) -> f64 {
            residual[0] * residual[0]
        }

        fn linearise(&self, _: &[f64], _: &Vec<f64>) {}

        fn damped_step(&self, _: &(), damping: f64, _: &[bool]) -> Option<Vec<f64>> {
            self.dampings.borrow_mut().push(damping);
            None
        }
    }

    #[test]
    fn a_fit_whose_every_step_fails_stops_where_it_started() {
        let problem = Singular {
            dampings: RefCell::new(Vec::new()),
        };
        let solution = solver().run(&problem, &[3.0]);
        assert_eq!(solution.termination, Termination::NoImprovingStep);
        assert_eq!((solution.values, solution.iterations), (vec![3.0], 1));
        assert_eq!(solution.sum_of_squares, 4.0);
        // Eight tries, the damping ten times larger after each.
        let expected: Vec<f64> = (0..8).map(|k| 1e-3 * 10f64.powi(k)).collect();
        let dampings = problem.dampings.borrow();
        assert_eq!(dampings.len(), expected.len());
        for (found, expected) in dampings.iter().zip(&expected) {
            assert!((found / expected - 1.0).abs() < 1e-12, "{dampings:?}");
        }
    }

    #[test]
    fn a_start_at_the_minimum_has_no_improving_step() {
        // r = (x − 2, x − 4): at x = 3 the gradient vanishes, every step is zero.
        let problem = Golden {
            residual: |x| vec![x[0] - 2.0, x[0] - 4.0],
            bounds: vec![FREE],
        };
        let solution = solver().run(&problem, &[3.0]);
        assert_eq!(solution.termination, Termination::NoImprovingStep);
        assert_eq!(solution.values, vec![3.0]);
    }

    #[test]
    fn without_parameters_the_start_is_the_solution() {
        let problem = Golden {
            residual: |_| vec![3.0, 4.0],
            bounds: Vec::new(),
        };
        let solution = solver().run(&problem, &[]);
        assert_eq!(solution.termination, Termination::NothingToFit);
        assert_eq!((solution.iterations, solution.sum_of_squares), (0, 25.0));
    }

    #[test]
    fn the_start_is_projected_onto_the_bounds() {
        let problem = Golden {
            residual: decay,
            bounds: vec![(0.0, 10.0), (0.0, 5.0), (0.5, 2.0)],
        };
        let solution = solver().with_iterations(0).run(&problem, &[-1.0, 1.0, 3.0]);
        assert_eq!(solution.termination, Termination::IterationLimit);
        assert_eq!(solution.values, vec![0.0, 1.0, 2.0]);
    }

    #[test]
    fn settings_out_of_range_are_refused_naming_the_setting() {
        let valid = LevenbergMarquardtParams {
            iterations: 0,
            tries: 1,
            initial_damping: 1e-3,
            min_damping: 1e-3,
            increase: 10.0,
            decrease: 3.0,
            tolerance: 0.0,
            active_bounds: ActiveBounds::Project,
        };
        assert!(valid.checked().is_ok());
        let cases = [
            ("tries", LevenbergMarquardtParams { tries: 0, ..valid }),
            (
                "initial_damping",
                LevenbergMarquardtParams {
                    initial_damping: 0.0,
                    ..valid
                },
            ),
            (
                "min_damping",
                LevenbergMarquardtParams {
                    min_damping: 1e-2,
                    ..valid
                },
            ),
            (
                "min_damping",
                LevenbergMarquardtParams {
                    min_damping: 0.0,
                    ..valid
                },
            ),
            (
                "increase",
                LevenbergMarquardtParams {
                    increase: 1.0,
                    ..valid
                },
            ),
            (
                "decrease",
                LevenbergMarquardtParams {
                    decrease: f64::NAN,
                    ..valid
                },
            ),
            (
                "tolerance",
                LevenbergMarquardtParams {
                    tolerance: -1e-9,
                    ..valid
                },
            ),
        ];
        for (setting, params) in cases {
            let message = params.checked().unwrap_err().to_string();
            assert!(message.contains(&format!("'{setting}'")), "{message}");
        }
    }
}
