//! Fitting the parameters of the selected effects with the exact forward model: linear estimates
//! from the screen, 1-D profile searches for the nonlinear parameters (delay, lag time constant,
//! ground-effect radius), then Levenberg–Marquardt on all parameters together (whitened residual,
//! fit rows only).

use std::sync::{Arc, LazyLock, Mutex};

use faer::Mat;
use faer::linalg::solvers::Solve;
use physics::{EffectNumber, Effects, QuadraticDrag, Wind};
use sindy::stability::BlockDesign;

use crate::locate::forward::WrenchTrace;
use crate::locate::problem::{Channels, Problem};
use crate::model::least_squares::{
    ActiveBounds, DenseProblem, LevenbergMarquardt, LevenbergMarquardtParams, Solution,
    forward_jacobian, normal_matrix,
};
use crate::model::weight;

/// Effects built from parameter values (absent parameters keep their effect absent; the other
/// numbers of a present effect are neutral).
pub fn effects_from(parameters: &[EffectNumber], values: &[f64]) -> Effects {
    let mut e = Effects::default();
    for (p, &v) in parameters.iter().zip(values) {
        e.set_number(*p, v);
    }
    e
}

/// The rows a fit uses, each channel of each row with a weight (all 1 without weights).
#[derive(Clone, Debug)]
pub struct FitRows<'a> {
    pub range: std::ops::Range<usize>,
    /// Per analysed row (indexed as the problem's rows, not from the range's start).
    pub weights: Option<&'a [Channels]>,
    /// Command steps whose place within their log interval is unknown: per step and channel, the
    /// residual's component along the test functions' value at the step is left out of the fit (a
    /// nuisance parameter, the step's time, profiled out). Built for these rows and weights.
    pub steps: Option<&'a StepBasis>,
}

impl FitRows<'_> {
    /// Rows `range`, unweighted.
    pub fn plain(range: std::ops::Range<usize>) -> FitRows<'static> {
        FitRows {
            range,
            weights: None,
            steps: None,
        }
    }
}

/// Whitened residual over the fit's rows, each element times the square root of its weight,
/// flattened.
fn whitened(problem: &Problem, residual: &[Channels], rows: &FitRows) -> Vec<f64> {
    let mut whitened: Vec<f64> = rows
        .range
        .clone()
        .flat_map(|k| {
            (0..problem.channels).map(move |c| {
                let scale = rows.weights.map_or(1.0, |w| w[k][c].sqrt());
                scale * residual[k][c] / problem.noise_floor[c]
            })
        })
        .collect();
    if let Some(steps) = rows.steps {
        steps.project_out(&mut whitened);
    }
    whitened
}

/// Per channel, an orthonormal basis of the (weighted) test functions' values at each step time
/// over a fit's rows: what misplacing a step within its interval changes. Built once per set of
/// rows and weights; [`FitRows::steps`] leaves these components out of the fit.
#[derive(Clone, Debug)]
pub struct StepBasis {
    channels: Vec<Vec<Vec<f64>>>,
}

impl StepBasis {
    /// The basis for `rows` (its weights) and the given step times (s).
    pub fn new(problem: &Problem, rows: &FitRows, step_times: &[f64]) -> Self {
        let channels = (0..problem.channels)
            .map(|c| {
                let mut basis: Vec<Vec<f64>> = Vec::new();
                for &t in step_times {
                    let mut column: Vec<f64> = rows
                        .range
                        .clone()
                        .map(|k| {
                            let weight = rows.weights.map_or(1.0, |w| w[k][c].sqrt());
                            weight * problem.weak_form.weight(t - problem.time[k])
                        })
                        .collect();
                    for b in &basis {
                        let along: f64 = column.iter().zip(b).map(|(x, y)| x * y).sum();
                        column.iter_mut().zip(b).for_each(|(x, y)| *x -= along * y);
                    }
                    let norm = column.iter().map(|x| x * x).sum::<f64>().sqrt();
                    if norm > 1e-12 {
                        column.iter_mut().for_each(|x| *x /= norm);
                        basis.push(column);
                    }
                }
                basis
            })
            .collect();
        Self { channels }
    }

    /// Removes the basis' components from a flattened whitened residual (row-major, `channels`
    /// values a row).
    fn project_out(&self, whitened: &mut [f64]) {
        let channels = self.channels.len();
        for (c, basis) in self.channels.iter().enumerate() {
            for b in basis {
                let along: f64 = (0..b.len())
                    .map(|i| b[i] * whitened[i * channels + c])
                    .sum();
                for (i, x) in b.iter().enumerate() {
                    whitened[i * channels + c] -= along * x;
                }
            }
        }
    }

    /// Removes the basis' components from a residual on the rows the basis was built for (whose
    /// first row is `residual[0]`; built unweighted): what remains once each step's place is free.
    pub fn remove_from(&self, residual: &mut [Channels]) {
        for (c, basis) in self.channels.iter().enumerate() {
            for b in basis {
                let along: f64 = b.iter().zip(residual.iter()).map(|(x, r)| x * r[c]).sum();
                for (x, r) in b.iter().zip(residual.iter_mut()) {
                    r[c] -= along * x;
                }
            }
        }
    }
}

/// Standard errors of fitted `values`: `√diag(scale · (JᵀJ)⁻¹)` with `J` the Jacobian of the
/// (weighted) whitened residual on the fit's rows, and `scale` the variance of a whitened residual
/// element times the residual's integrated autocorrelation (neighbouring rows share samples). NaN
/// where `JᵀJ` is singular.
pub fn standard_errors(
    problem: &Problem,
    parameters: &[EffectNumber],
    values: &[f64],
    rows: &FitRows,
    scale: f64,
) -> Vec<f64> {
    let (_, inverse) = linearised_covariance(problem, parameters, values, rows);
    errors_from(&inverse, scale)
}

/// How precisely the rows determine each fitted parameter, and where.
#[derive(Clone, Debug, PartialEq)]
pub struct Precision {
    /// As [`standard_errors`] gives them.
    pub standard_errors: Vec<f64>,
    /// Per parameter, the first and last of the fit's rows (indexed as the problem's) of the
    /// shortest stretch holding half of its weight ([`crate::model::weight`]); `None` where
    /// `JᵀJ` is singular.
    pub half_weight_rows: Vec<Option<(usize, usize)>>,
}

/// [`standard_errors`] and where each parameter's weight lies, from one Jacobian.
pub fn precision(
    problem: &Problem,
    parameters: &[EffectNumber],
    values: &[f64],
    rows: &FitRows,
    scale: f64,
) -> Precision {
    let (jacobian, inverse) = linearised_covariance(problem, parameters, values, rows);
    let k = parameters.len();
    let inverse_rows: Vec<Vec<f64>> = (0..k)
        .map(|i| (0..k).map(|j| inverse[(i, j)]).collect())
        .collect();
    let time = &problem.time[rows.range.clone()];
    let half_weight_rows = weight::row_weights(&jacobian, &inverse_rows, problem.channels)
        .into_iter()
        .map(|weights| {
            let (first, last) = weight::half_weight_rows(time, &weights?)?;
            Some((rows.range.start + first, rows.range.start + last))
        })
        .collect();
    Precision {
        standard_errors: errors_from(&inverse, scale),
        half_weight_rows,
    }
}

/// The Jacobian `J` of the fit's whitened residual at `values` (one column per parameter) and
/// `(JᵀJ)⁻¹`.
fn linearised_covariance(
    problem: &Problem,
    parameters: &[EffectNumber],
    values: &[f64],
    rows: &FitRows,
) -> (Vec<Vec<f64>>, Mat<f64>) {
    let fit = WhitenedFit::new(problem, parameters, rows);
    let residual = fit.residual(values);
    let jacobian = forward_jacobian(&fit, values, &residual);
    let k = parameters.len();
    let inverse = normal_matrix(&jacobian)
        .full_piv_lu()
        .solve(Mat::<f64>::identity(k, k));
    (jacobian, inverse)
}

/// `√(scale · inverseᵢᵢ)`, NaN where that is not a finite non-negative variance.
fn errors_from(inverse: &Mat<f64>, scale: f64) -> Vec<f64> {
    (0..inverse.nrows())
        .map(|i| {
            let variance = scale * inverse[(i, i)];
            if variance.is_finite() && variance >= 0.0 {
                variance.sqrt()
            } else {
                f64::NAN
            }
        })
        .collect()
}

/// The whitened residual of the fit's rows as a function of the parameters' values.
struct WhitenedFit<'a> {
    problem: &'a Problem,
    parameters: &'a [EffectNumber],
    rows: &'a FitRows<'a>,
    /// The commands' wrench of the last timing evaluated: most fits change no delay or motor lag.
    wrenches: Mutex<Option<Arc<WrenchTrace>>>,
}

impl<'a> WhitenedFit<'a> {
    fn new(problem: &'a Problem, parameters: &'a [EffectNumber], rows: &'a FitRows<'a>) -> Self {
        Self {
            problem,
            parameters,
            rows,
            wrenches: Mutex::new(None),
        }
    }

    /// The wrench trace for `effects`' timing: the last one when it serves, else a new one.
    fn wrenches_for(&self, effects: &Effects) -> Arc<WrenchTrace> {
        let last = self
            .wrenches
            .lock()
            .expect("no fit panics holding the trace");
        if let Some(trace) = last.as_ref().filter(|t| t.serves(effects)) {
            return trace.clone();
        }
        drop(last);
        let trace = Arc::new(WrenchTrace::new(
            &self.problem.recording,
            &self.problem.model,
            effects,
        ));
        *self
            .wrenches
            .lock()
            .expect("no fit panics holding the trace") = Some(trace.clone());
        trace
    }
}

impl DenseProblem for WhitenedFit<'_> {
    fn dimension(&self) -> usize {
        self.parameters.len()
    }

    fn bounds(&self, index: usize) -> (f64, f64) {
        self.parameters[index].fit_range()
    }

    fn residual(&self, values: &[f64]) -> Vec<f64> {
        let effects = effects_from(self.parameters, values);
        let wrenches = self.wrenches_for(&effects);
        let residual = self.problem.residual_with(&effects, &wrenches);
        whitened(self.problem, &residual, self.rows)
    }

    fn difference_step(&self, index: usize, value: f64) -> f64 {
        self.parameters[index].step(value)
    }
}

/// The settings of one recording's fits: 8 damped steps an iteration, converged when a step
/// lowers the sum of squares by at most 1e-9 of it (the values the fits were tuned with).
pub(crate) const RECORDING_FIT: LevenbergMarquardtParams = LevenbergMarquardtParams {
    iterations: 40,
    tries: 8,
    initial_damping: 1e-3,
    min_damping: 1e-9,
    increase: 10.0,
    decrease: 3.0,
    tolerance: 1e-9,
    active_bounds: ActiveBounds::Project,
};

/// The solver of one recording's fits ([`RECORDING_FIT`]).
static SOLVER: LazyLock<LevenbergMarquardt> = LazyLock::new(|| {
    RECORDING_FIT
        .checked()
        .expect("the single-recording solver's settings are valid")
});

/// Levenberg–Marquardt ([`crate::model::least_squares`]) on the (weighted) whitened residual of the
/// fit's rows, at most `iterations` linearisations, the parameters within their fit ranges.
pub fn levenberg_marquardt(
    problem: &Problem,
    parameters: &[EffectNumber],
    initial: &[f64],
    rows: &FitRows,
    iterations: usize,
) -> Solution {
    let fit = WhitenedFit::new(problem, parameters, rows);
    SOLVER.with_iterations(iterations).run(&fit, initial)
}

/// The fixed columns of a search (`columns[others]`: the linear screen's columns of the other
/// effects) on rows `range` in blocks of `block_rows`, with their block Gram matrices summed once
/// ([`sindy::stability::BlockDesign::with_leading_columns`]).
pub struct FixedColumns<'a> {
    columns: Vec<&'a Vec<Channels>>,
    design: BlockDesign,
    range: std::ops::Range<usize>,
    block_rows: usize,
}

impl<'a> FixedColumns<'a> {
    pub fn new(
        problem: &Problem,
        columns: &'a [Vec<Channels>],
        others: &[usize],
        range: std::ops::Range<usize>,
        block_rows: usize,
    ) -> Self {
        let columns: Vec<&Vec<Channels>> = others.iter().map(|&c| &columns[c]).collect();
        let design = problem.design_of(&[], &columns, range.clone(), block_rows);
        Self {
            columns,
            design,
            range,
            block_rows,
        }
    }
}

/// Whitened sum of squares of `residual` after regressing it on `extra` and the fixed columns.
pub fn projected_sse(
    problem: &Problem,
    residual: &[Channels],
    extra: &[&Vec<Channels>],
    fixed: &FixedColumns,
) -> f64 {
    let design = problem.design_with_fixed(residual, extra, fixed);
    let all: Vec<usize> = (0..design.parameters()).collect();
    if !extra.is_empty() {
        // Extra columns are physical effects with non-negative coefficients (drag): a negative
        // fit means the column does not help, so it is left out.
        let ones = vec![1.0; design.blocks()];
        let theta = design.solve(&ones, &all);
        if theta[..extra.len()].iter().any(|t| *t < 0.0) {
            return design.fitted_sse(&all[extra.len()..]);
        }
    }
    design.fitted_sse(&all)
}

impl Problem {
    /// [`Problem::design`] of `residual` on `extra` followed by the fixed columns, summing only
    /// what involves `extra` or `residual` (the same bits).
    fn design_with_fixed(
        &self,
        residual: &[Channels],
        extra: &[&Vec<Channels>],
        fixed: &FixedColumns,
    ) -> BlockDesign {
        let channels = self.channels;
        let samples = fixed.range.len() * channels;
        let start = fixed.range.start;
        BlockDesign::with_leading_columns(
            &fixed.design,
            samples,
            fixed.block_rows * channels,
            extra.len(),
            |i, x| {
                let (row, c) = (start + i / channels, i % channels);
                let scale = 1.0 / self.noise_floor[c];
                let all = extra.iter().chain(&fixed.columns);
                for (value, column) in x.iter_mut().zip(all) {
                    *value = column[row][c] * scale;
                }
                residual[row][c] * scale
            },
        )
    }
}

/// 1-D profile search of one nonlinear effect: for each grid value, the residual of the nominal
/// model plus that effect is regressed on `other_columns` (the linear screen's columns of the other
/// effects); returns the grid value with the smallest whitened error and that error.
pub fn profile_search(
    problem: &Problem,
    columns: &[Vec<Channels>],
    other_columns: &[usize],
    range: std::ops::Range<usize>,
    block_rows: usize,
    grid: &[f64],
    effect: impl Fn(f64) -> Effects + Sync,
) -> (f64, f64) {
    use rayon::prelude::*;
    // A grid over anything but a delay or a motor lag keeps the commands' wrench: traced once.
    let first = effect(grid[0]);
    let timing = |e: &Effects| (e.delay_s().to_bits(), e.lag_s().to_bits());
    let shared = grid
        .iter()
        .all(|&value| timing(&effect(value)) == timing(&first))
        .then(|| WrenchTrace::new(&problem.recording, &problem.model, &first));
    let fixed = FixedColumns::new(problem, columns, other_columns, range, block_rows);
    grid.par_iter()
        .map(|&value| {
            let effects = effect(value);
            let residual = match &shared {
                Some(wrenches) => problem.residual_with(&effects, wrenches),
                None => problem.residual(&effects),
            };
            let sse = projected_sse(problem, &residual, &[], &fixed);
            (value, sse)
        })
        .collect::<Vec<_>>()
        .into_iter()
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .expect("a non-empty grid")
}

/// The change of the matched prediction caused by `effects`, per analysed row.
pub fn effect_column(
    problem: &Problem,
    base: &[Channels],
    effects: &Effects,
    scale: f64,
) -> Vec<Channels> {
    column_from(problem, &problem.predict(effects), base, scale)
}

/// `(predicted − base) / scale` on the compared channels.
fn column_from(
    problem: &Problem,
    predicted: &[Channels],
    base: &[Channels],
    scale: f64,
) -> Vec<Channels> {
    predicted
        .iter()
        .zip(base)
        .map(|(p, b)| {
            let mut out = [0.0; 6];
            for c in 0..problem.channels {
                out[c] = (p[c] - b[c]) / scale;
            }
            out
        })
        .collect()
}

/// A quadratic drag of coefficient 1 in air moving at `w`.
pub fn unit_drag_in_wind(w: [f64; 3]) -> Effects {
    Effects {
        quadratic_drag: Some(QuadraticDrag { c: 1.0 }),
        wind: Some(Wind { w_air: w }),
        ..Effects::default()
    }
}

/// Air velocity that best explains `residual` with a free drag coefficient on the column
/// `−|v − w| (v − w)` next to the other columns: coordinate-wise searches, coarse then fine.
pub fn profile_wind(
    problem: &Problem,
    residual: &[Channels],
    columns: &[Vec<Channels>],
    others: &[usize],
    range: std::ops::Range<usize>,
    block_rows: usize,
) -> ([f64; 3], f64) {
    use rayon::prelude::*;
    let base = problem.predict(&Effects::default());
    // The drag in wind changes no delay or motor lag: the commands' wrench is traced once.
    let wrenches = WrenchTrace::new(
        &problem.recording,
        &problem.model,
        &unit_drag_in_wind([0.0; 3]),
    );
    let fixed = FixedColumns::new(problem, columns, others, range, block_rows);
    let score = |w: [f64; 3]| {
        let effects = unit_drag_in_wind(w);
        let column = column_from(
            problem,
            &problem.predict_with(&effects, &wrenches),
            &base,
            1.0,
        );
        projected_sse(problem, residual, &[&column], &fixed)
    };
    let mut best = ([0.0; 3], score([0.0; 3]));
    for (step, span) in [(0.5, 12), (0.1, 5), (0.02, 5)] {
        for _sweep in 0..2 {
            for axis in 0..3 {
                let candidates: Vec<([f64; 3], f64)> = (-span..=span)
                    .into_par_iter()
                    .map(|i| {
                        let mut w = best.0;
                        w[axis] += i as f64 * step;
                        (w, score(w))
                    })
                    .collect();
                for candidate in candidates {
                    if candidate.1 < best.1 {
                        best = candidate;
                    }
                }
            }
        }
    }
    best
}
