//! The joint fit of one vehicle to several flights: vehicle parameters shared by every flight, one
//! constant air velocity per flight that is not calm, Levenberg–Marquardt on the weak-form
//! residuals of all of them. The normal equations have an arrow structure (the vehicle block is
//! dense, each flight's wind block touches only its flight), solved through the Schur complement of
//! the wind blocks, so a fit of thirty flights costs a few small solves per iteration.

use std::sync::LazyLock;

use faer::Mat;
use faer::linalg::solvers::Solve;
use physics::{EffectId, EffectNumber, Effects, Wind, WindGradient};
use rayon::prelude::*;

use crate::locate::problem::Problem;
use crate::model::least_squares::{
    ActiveBounds, LeastSquares, LevenbergMarquardt, LevenbergMarquardtParams, Termination, hold,
};

/// The vehicle numbers of effect `id`: all of its numbers, none for the effects that describe
/// the air (fitted per flight, see [`Air`]).
pub fn parameters_of(id: EffectId) -> Vec<EffectNumber> {
    if id.describes_the_air() {
        Vec::new()
    } else {
        EffectNumber::all_of(id)
    }
}

/// A vehicle: effects and their values; and whether the air of its flights may vary in space.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Vehicle {
    pub parameters: Vec<EffectNumber>,
    pub values: Vec<f64>,
    /// Each windy flight's air gets a gradient (`wind_gradient`) along the axes it flies.
    pub gradient: bool,
}

impl Vehicle {
    /// The effect ids present, in order of first appearance (`wind_gradient` last).
    pub fn ids(&self) -> Vec<EffectId> {
        let mut ids: Vec<EffectId> = Vec::new();
        for p in &self.parameters {
            if !ids.contains(&p.effect) {
                ids.push(p.effect);
            }
        }
        if self.gradient {
            ids.push(EffectId::WindGradient);
        }
        ids
    }

    /// Adds effect `id` at its neutral values, or `start` (nothing if present, or if `id` has no
    /// vehicle parameters: see `parameters_of`).
    pub fn with(&self, id: EffectId, start: Option<&[f64]>) -> Self {
        let mut out = self.clone();
        if self.ids().contains(&id) {
            return out;
        }
        if id == EffectId::WindGradient {
            out.gradient = true;
            return out;
        }
        for (i, p) in parameters_of(id).into_iter().enumerate() {
            out.parameters.push(p);
            out.values
                .push(start.and_then(|s| s.get(i).copied()).unwrap_or(p.neutral()));
        }
        out
    }

    /// Whether an air velocity acts on this vehicle (it has an effect the wind acts through).
    pub fn feels_wind(&self) -> bool {
        let acts_through = EffectId::Wind.needs_one_of();
        self.parameters
            .iter()
            .any(|p| acts_through.contains(&p.effect))
    }

    /// The effects of the vehicle in the air of `air` (none for still air).
    pub fn effects(&self, air: Option<&Air>) -> Effects {
        let mut e = Effects::default();
        for (p, &v) in self.parameters.iter().zip(&self.values) {
            e.set_number(*p, v);
        }
        if let Some(air) = air
            && self.feels_wind()
        {
            e.wind = Some(Wind {
                w_air: [air.values[0], air.values[1], air.values[2]],
            });
            if !air.axes.is_empty() {
                let mut per_m = [[0.0; 3]; 3];
                for (k, &axis) in air.axes.iter().enumerate() {
                    for c in 0..3 {
                        per_m[c][axis] = air.values[3 + 3 * k + c];
                    }
                }
                e.wind_gradient = Some(WindGradient {
                    per_m,
                    reference_m: air.reference_m,
                });
            }
        }
        e
    }
}

/// A flight's air: its velocity at `reference_m` and, along each position axis of `axes`, its
/// gradient (`values`: the velocity, then three components per axis).
#[derive(Clone, Debug, PartialEq)]
pub struct Air {
    pub values: Vec<f64>,
    pub axes: Vec<usize>,
    pub reference_m: [f64; 3],
}

impl Air {
    /// Still air (velocity zero) with room for a gradient along `axes` when `gradient`.
    pub fn still(reference_m: [f64; 3], axes: &[usize], gradient: bool) -> Self {
        let axes = if gradient { axes.to_vec() } else { Vec::new() };
        Self {
            values: vec![0.0; 3 + 3 * axes.len()],
            axes,
            reference_m,
        }
    }

    /// The velocity at the reference.
    pub fn velocity(&self) -> [f64; 3] {
        [self.values[0], self.values[1], self.values[2]]
    }
}

/// One flight in a joint fit: its comparison, whether its air is still, the rows fitted.
pub struct JointFlight<'a> {
    pub problem: &'a Problem,
    pub calm: bool,
    pub rows: std::ops::Range<usize>,
    /// Where its air velocity is taken, and the axes its air's gradient may be fitted along.
    pub reference_m: [f64; 3],
    pub axes: &'a [usize],
}

impl JointFlight<'_> {
    /// Still air for this flight, with room for the vehicle's structure.
    pub fn still_air(&self, vehicle: &Vehicle) -> Air {
        Air::still(self.reference_m, self.axes, vehicle.gradient)
    }
}

/// What the joint fit holds fixed.
#[derive(Clone, Debug)]
pub struct JointSettings {
    /// Parameters not fitted (kept at their values).
    pub fixed: Vec<EffectNumber>,
    /// Whether the vehicle is fitted at all (false: only the winds).
    pub fit_vehicle: bool,
    /// Noise scale per channel (the residual is divided by it).
    pub scale: [f64; 3],
    pub iterations: usize,
}

/// The outcome of a joint fit.
#[derive(Clone, Debug)]
pub struct JointFit {
    pub vehicle: Vehicle,
    /// Per flight: its air (still for calm flights or a vehicle without drag).
    pub airs: Vec<Air>,
    /// Why the solver stopped.
    pub termination: Termination,
}

fn scaled_residual(
    flight: &JointFlight,
    vehicle: &Vehicle,
    air: &Air,
    scale: &[f64; 3],
) -> Vec<f64> {
    let air = (!flight.calm).then_some(air);
    let residual = flight.problem.residual(&vehicle.effects(air));
    residual[flight.rows.clone()]
        .iter()
        .flat_map(|r| (0..3).map(move |c| r[c] / scale[c]))
        .collect()
}

/// Per flight: the scaled residual and its Jacobians with respect to the free vehicle parameters
/// and to the flight's air parameters (empty for calm flights).
type Linearisation = (Vec<f64>, Vec<Vec<f64>>, Vec<Vec<f64>>);

/// The linearisation of one flight, whose scaled residual is `base`.
fn linearise(
    flight: &JointFlight,
    (vehicle, air): (&Vehicle, &Air),
    base: Vec<f64>,
    free: &[usize],
    fit_air: bool,
    scale: &[f64; 3],
) -> Linearisation {
    let difference = |shifted: &[f64], step: f64| -> Vec<f64> {
        shifted
            .iter()
            .zip(&base)
            .map(|(a, b)| (a - b) / step)
            .collect()
    };
    let vehicle_columns = free
        .iter()
        .map(|&j| {
            let step = vehicle.parameters[j].step(vehicle.values[j]);
            let mut moved = vehicle.clone();
            moved.values[j] += step;
            difference(&scaled_residual(flight, &moved, air, scale), step)
        })
        .collect();
    let air_columns = if fit_air {
        (0..air.values.len())
            .map(|i| {
                let mut moved = air.clone();
                moved.values[i] += 1e-3;
                difference(&scaled_residual(flight, vehicle, &moved, scale), 1e-3)
            })
            .collect()
    } else {
        Vec::new()
    };
    (base, vehicle_columns, air_columns)
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The solver of the joint fit: 10 damped steps an iteration, converged when a step lowers the sum
/// of squares by at most 1e-7 of it (the values the joint fit was tuned with).
static SOLVER: LazyLock<LevenbergMarquardt> = LazyLock::new(|| {
    LevenbergMarquardtParams {
        iterations: 30,
        tries: 10,
        initial_damping: 1e-3,
        min_damping: 1e-9,
        increase: 10.0,
        decrease: 3.0,
        tolerance: 1e-7,
        active_bounds: ActiveBounds::Project,
    }
    .checked()
    .expect("the joint solver's settings are valid")
});

/// The joint fit as a least-squares problem. Its parameters: the free vehicle parameters, then
/// the air values of each flight whose air is fitted, in the flights' order.
struct JointProblem<'a> {
    flights: &'a [JointFlight<'a>],
    /// The vehicle and airs the parameters are written into (the rest held at these values).
    vehicle: &'a Vehicle,
    airs: &'a [Air],
    free: Vec<usize>,
    fit_air: Vec<bool>,
    scale: [f64; 3],
}

impl JointProblem<'_> {
    /// The parameters of the vehicle and airs.
    fn parameters(&self, vehicle: &Vehicle, airs: &[Air]) -> Vec<f64> {
        let fitted_airs = airs.iter().zip(&self.fit_air).filter(|(_, fit)| **fit);
        self.free
            .iter()
            .map(|&j| vehicle.values[j])
            .chain(fitted_airs.flat_map(|(air, _)| air.values.iter().copied()))
            .collect()
    }

    /// The vehicle and airs at parameters `x`.
    fn at(&self, x: &[f64]) -> (Vehicle, Vec<Air>) {
        let mut vehicle = self.vehicle.clone();
        for (&j, &v) in self.free.iter().zip(x) {
            vehicle.values[j] = v;
        }
        let mut rest = &x[self.free.len()..];
        let airs = self
            .airs
            .iter()
            .zip(&self.fit_air)
            .map(|(air, &fit)| {
                let mut air = air.clone();
                if fit {
                    let (values, others) = rest.split_at(air.values.len());
                    air.values.copy_from_slice(values);
                    rest = others;
                }
                air
            })
            .collect();
        (vehicle, airs)
    }
}

impl LeastSquares for JointProblem<'_> {
    /// Per flight, the scaled residual on its rows.
    type Residual = Vec<Vec<f64>>;
    type Linearisation = Vec<Linearisation>;

    fn dimension(&self) -> usize {
        let airs = self.airs.iter().zip(&self.fit_air).filter(|(_, fit)| **fit);
        self.free.len() + airs.map(|(air, _)| air.values.len()).sum::<usize>()
    }

    fn bounds(&self, index: usize) -> (f64, f64) {
        match self.free.get(index) {
            Some(&j) => self.vehicle.parameters[j].fit_range(),
            None => (f64::NEG_INFINITY, f64::INFINITY),
        }
    }

    fn residual(&self, x: &[f64]) -> Vec<Vec<f64>> {
        let (vehicle, airs) = self.at(x);
        self.flights
            .par_iter()
            .zip(&airs)
            .map(|(flight, air)| scaled_residual(flight, &vehicle, air, &self.scale))
            .collect()
    }

    fn sum_of_squares(&self, residual: &Vec<Vec<f64>>) -> f64 {
        let per_flight: Vec<f64> = residual
            .iter()
            .map(|r| r.iter().map(|v| v * v).sum::<f64>())
            .collect();
        per_flight.iter().sum()
    }

    fn linearise(&self, x: &[f64], residual: &Vec<Vec<f64>>) -> Vec<Linearisation> {
        let (vehicle, airs) = self.at(x);
        self.flights
            .par_iter()
            .enumerate()
            .map(|(f, flight)| {
                let base = residual[f].clone();
                let at = (&vehicle, &airs[f]);
                linearise(flight, at, base, &self.free, self.fit_air[f], &self.scale)
            })
            .collect()
    }

    fn damped_step(
        &self,
        parts: &Vec<Linearisation>,
        damping: f64,
        held: &[bool],
    ) -> Option<Vec<f64>> {
        // Only vehicle parameters have bounds: the airs' are never held.
        let held = &held[..self.free.len()];
        let (vehicle_step, air_steps) = solve_step(parts, self.free.len(), damping, held)?;
        Some(
            vehicle_step
                .into_iter()
                .chain(air_steps.into_iter().flatten())
                .collect(),
        )
    }
}

/// Fits the vehicle (its free parameters) and the air of the flights that are not calm.
pub fn fit(
    flights: &[JointFlight],
    start: &Vehicle,
    airs: &[Air],
    settings: &JointSettings,
) -> JointFit {
    let free: Vec<usize> = if settings.fit_vehicle {
        (0..start.parameters.len())
            .filter(|&j| !settings.fixed.contains(&start.parameters[j]))
            .collect()
    } else {
        Vec::new()
    };
    let fit_air: Vec<bool> = flights
        .iter()
        .map(|f| !f.calm && start.feels_wind())
        .collect();
    let problem = JointProblem {
        flights,
        vehicle: start,
        airs,
        free,
        fit_air,
        scale: settings.scale,
    };
    let solution = SOLVER
        .with_iterations(settings.iterations)
        .run(&problem, &problem.parameters(start, airs));
    let (vehicle, airs) = problem.at(&solution.values);
    JointFit {
        vehicle,
        airs,
        termination: solution.termination,
    }
}

/// One damped Gauss–Newton step for the vehicle and every flight's air, through the Schur
/// complement of the air blocks, the `held` vehicle parameters not moving. `None` when a system is
/// singular.
fn solve_step(
    parts: &[Linearisation],
    free: usize,
    damping: f64,
    held: &[bool],
) -> Option<(Vec<f64>, Vec<Vec<f64>>)> {
    let mut reduced = Mat::<f64>::zeros(free, free);
    let mut rhs = Mat::<f64>::zeros(free, 1);
    let mut blocks = Vec::with_capacity(parts.len());
    for (residual, vehicle_columns, air_columns) in parts {
        for i in 0..free {
            rhs[(i, 0)] += dot(&vehicle_columns[i], residual);
            for j in 0..free {
                reduced[(i, j)] += dot(&vehicle_columns[i], &vehicle_columns[j]);
            }
        }
        let m = air_columns.len();
        if m == 0 {
            blocks.push(None);
            continue;
        }
        let mut d = Mat::<f64>::zeros(m, m);
        let mut g = Mat::<f64>::zeros(m, 1);
        let mut b = Mat::<f64>::zeros(free, m);
        for a in 0..m {
            g[(a, 0)] = dot(&air_columns[a], residual);
            for c in 0..m {
                d[(a, c)] = dot(&air_columns[a], &air_columns[c]);
            }
            for i in 0..free {
                b[(i, a)] = dot(&vehicle_columns[i], &air_columns[a]);
            }
        }
        for a in 0..m {
            d[(a, a)] += damping * d[(a, a)].max(1e-12);
        }
        blocks.push(Some((d, g, b)));
    }
    for i in 0..free {
        reduced[(i, i)] += damping * reduced[(i, i)].max(1e-12);
    }
    // Eliminate each air block: S −= B D⁻¹ Bᵀ, r −= B D⁻¹ g.
    for (d, g, b) in blocks.iter().flatten() {
        let m = d.nrows();
        let lu = d.full_piv_lu();
        let d_inv_g = lu.solve(g);
        let d_inv_bt = lu.solve(b.transpose().to_owned());
        for i in 0..free {
            rhs[(i, 0)] -= (0..m).map(|a| b[(i, a)] * d_inv_g[(a, 0)]).sum::<f64>();
            for j in 0..free {
                reduced[(i, j)] -= (0..m).map(|a| b[(i, a)] * d_inv_bt[(a, j)]).sum::<f64>();
            }
        }
    }
    hold(&mut reduced, &mut rhs, held);
    let vehicle_step: Vec<f64> = if free > 0 {
        let solution = reduced.full_piv_lu().solve(&rhs);
        (0..free)
            .map(|i| if held[i] { 0.0 } else { solution[(i, 0)] })
            .collect()
    } else {
        Vec::new()
    };
    if vehicle_step.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let air_steps: Vec<Vec<f64>> = blocks
        .iter()
        .map(|block| match block {
            None => Vec::new(),
            Some((d, g, b)) => {
                let m = d.nrows();
                let mut rhs = g.clone();
                for a in 0..m {
                    rhs[(a, 0)] -= (0..free).map(|i| b[(i, a)] * vehicle_step[i]).sum::<f64>();
                }
                let solution = d.full_piv_lu().solve(&rhs);
                (0..m).map(|a| solution[(a, 0)]).collect()
            }
        })
        .collect();
    if air_steps.iter().flatten().any(|v| !v.is_finite()) {
        return None;
    }
    Some((vehicle_step, air_steps))
}

/// Scaled sum of squares of every flight on its rows, with the vehicle and airs given.
pub fn scaled_sse_on(
    flights: &[JointFlight],
    vehicle: &Vehicle,
    airs: &[Air],
    scale: &[f64; 3],
) -> Vec<f64> {
    flights
        .par_iter()
        .zip(airs)
        .map(|(f, a)| {
            scaled_residual(f, vehicle, a, scale)
                .iter()
                .map(|r| r * r)
                .sum::<f64>()
        })
        .collect()
}

/// Per-channel RMS of the residual over every flight's rows (raw units).
pub fn residual_rms(flights: &[JointFlight], vehicle: &Vehicle, airs: &[Air]) -> [f64; 3] {
    let sums: Vec<([f64; 3], usize)> = flights
        .par_iter()
        .zip(airs)
        .map(|(f, a)| {
            let r = scaled_residual(f, vehicle, a, &[1.0; 3]);
            let mut s = [0.0; 3];
            for (i, v) in r.iter().enumerate() {
                s[i % 3] += v * v;
            }
            (s, r.len() / 3)
        })
        .collect();
    let rows: usize = sums.iter().map(|s| s.1).sum();
    let mut out = [0.0; 3];
    for c in 0..3 {
        out[c] = (sums.iter().map(|s| s.0[c]).sum::<f64>() / rows.max(1) as f64)
            .sqrt()
            .max(1e-12);
    }
    out
}
