//! From the screen to a joint fit: the nonlinear candidates' columns at profiled parameters, then
//! the kept candidates' parameters fitted together with the exact model (Levenberg–Marquardt on the
//! fit rows), with the timing term resolved into a delay, a motor lag or both, and an air velocity
//! when a drag was kept.

use physics::{EffectId, EffectNumber, Effects};
use report::mismatch::recording::TimingScores;
use serde::Serialize;
use sindy::stability::{BlockDesign, Selection};

use crate::explain::library::{Candidate, CandidateId};
use crate::locate::problem::{Channels, Problem};
use crate::model::refine::{
    FitRows, effect_column, effects_from, levenberg_marquardt, profile_search, profile_wind,
    unit_drag_in_wind,
};

const GROUND_RADIUS: EffectNumber = EffectNumber::new(EffectId::GroundEffect, 0);
const DELAY: EffectNumber = EffectNumber::new(EffectId::Delay, 0);
const MOTOR_LAG: EffectNumber = EffectNumber::new(EffectId::MotorLag, 0);

/// Parameters and their values: a set of effects being fitted.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FittedSet {
    pub parameters: Vec<EffectNumber>,
    pub values: Vec<f64>,
}

impl FittedSet {
    /// The effects these values describe.
    pub fn effects(&self) -> Effects {
        effects_from(&self.parameters, &self.values)
    }

    /// The effect ids present, in order of first appearance.
    pub fn ids(&self) -> Vec<EffectId> {
        let mut ids: Vec<EffectId> = Vec::new();
        for p in &self.parameters {
            if !ids.contains(&p.effect) {
                ids.push(p.effect);
            }
        }
        ids
    }

    /// The set without the parameters of effect `id` (and without the effects left without what
    /// they need: the wind when no drag is left).
    pub fn without(&self, id: EffectId) -> Self {
        let left = self.effects().without(id);
        let (parameters, values) = self
            .parameters
            .iter()
            .zip(&self.values)
            .filter(|(p, _)| left.contains(p.effect))
            .map(|(p, v)| (*p, *v))
            .unzip();
        Self { parameters, values }
    }

    /// Refits all values by Levenberg–Marquardt on the fit rows; returns the whitened error.
    pub fn refit(&mut self, problem: &Problem, iterations: usize) -> f64 {
        let solution = levenberg_marquardt(
            problem,
            &self.parameters,
            &self.values,
            &FitRows::plain(0..problem.split),
            iterations,
        );
        self.values = solution.values;
        solution.sum_of_squares
    }
}

/// What the fit stage tried besides the chosen model (for the report).
#[derive(Clone, Debug, Default, Serialize)]
pub struct FitAlternatives {
    /// Whitened fit error of each timing explanation (`delay`, `motor_lag`, `both`), when the
    /// timing term was kept.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub timing: Option<TimingScores>,
    /// Whitened fit error without and with an air velocity, when a drag was kept.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub wind: Option<WindScores>,
}

/// Whitened fit errors of a drag in still air and with a fitted air velocity.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct WindScores {
    pub still_air: f64,
    pub with_wind: f64,
}

/// Replaces the screen columns of the nonlinear candidates by the exact effect at the parameters
/// a profile search finds next to all other columns: the ground-effect radius, the better of a
/// delay and a motor lag, and the air velocity of the quadratic drag. Returns that air velocity.
pub fn profile_nonlinear(
    problem: &Problem,
    before: &[Channels],
    candidates: &[Candidate],
    columns: &mut [Vec<Channels>],
    block_rows: usize,
) -> [f64; 3] {
    let range = 0..problem.split;
    let base = problem.predict(&Effects::default());
    let total = columns.len();
    let others_of = |candidate: &Candidate| -> Vec<usize> {
        (0..total)
            .filter(|c| !candidate.columns.contains(c))
            .collect()
    };
    let find = |id: CandidateId| candidates.iter().find(|c| c.id == id);
    if let Some(candidate) = find(CandidateId::GroundEffect) {
        let others = others_of(candidate);
        let radius = profiled_ground_radius(problem, columns, &others, block_rows);
        let effect = effects_from(&[GROUND_RADIUS], &[radius]);
        columns[candidate.columns[0]] = effect_column(problem, &base, &effect, radius * radius);
    }
    if let Some(candidate) = find(CandidateId::DelayOrMotorLag) {
        let others = others_of(candidate);
        let best = [DELAY, MOTOR_LAG]
            .into_iter()
            .map(|kind| {
                // Zero, the neutral value, has no column to fit.
                let grid: Vec<f64> = kind.profile_grid().into_iter().skip(1).collect();
                let (value, sse) = profile_search(
                    problem,
                    columns,
                    &others,
                    range.clone(),
                    block_rows,
                    &grid,
                    |v| effects_from(&[kind], &[v]),
                );
                (kind, value, sse)
            })
            .min_by(|a, b| a.2.total_cmp(&b.2))
            .expect("two kinds");
        columns[candidate.columns[0]] =
            effect_column(problem, &base, &effects_from(&[best.0], &[best.1]), best.1);
    }
    let mut wind = [0.0; 3];
    if let Some(candidate) = find(CandidateId::QuadraticDrag) {
        let others = others_of(candidate);
        let (w, _) = profile_wind(problem, before, columns, &others, range, block_rows);
        wind = w;
        columns[candidate.columns[0]] = effect_column(problem, &base, &unit_drag_in_wind(w), 1.0);
    }
    wind
}

/// Starting values of the kept linear candidates from the screen's joint least squares; the
/// ground-effect radius from its profile. The timing candidate is left to [`fit_timing`].
fn screen_estimates(
    problem: &Problem,
    candidates: &[&Candidate],
    columns: &[Vec<Channels>],
    design: &BlockDesign,
    block_rows: usize,
) -> FittedSet {
    let kept_columns: Vec<usize> = candidates.iter().flat_map(|c| c.columns.clone()).collect();
    let theta = design.solve(&vec![1.0; design.blocks()], &kept_columns);
    let coefficient = |column: usize| {
        theta[kept_columns
            .iter()
            .position(|c| *c == column)
            .expect("kept")]
    };
    let mut set = FittedSet::default();
    let mut push = |p: EffectNumber, v: f64| {
        set.parameters.push(p);
        set.values.push(v);
    };
    for candidate in candidates {
        let cols = &candidate.columns;
        match candidate.id {
            CandidateId::ThrustScale => push(
                EffectNumber::new(EffectId::ThrustScale, 0),
                1.0 + coefficient(cols[0]),
            ),
            CandidateId::LinearDrag => {
                for (i, &c) in cols.iter().enumerate() {
                    push(
                        EffectNumber::new(EffectId::LinearDrag, i),
                        coefficient(c).max(0.0),
                    );
                }
            }
            CandidateId::QuadraticDrag => push(
                EffectNumber::new(EffectId::QuadraticDrag, 0),
                coefficient(cols[0]).max(0.0),
            ),
            CandidateId::GroundEffect => {
                let others: Vec<usize> = kept_columns
                    .iter()
                    .copied()
                    .filter(|c| !cols.contains(c))
                    .collect();
                let radius = profiled_ground_radius(problem, columns, &others, block_rows);
                push(GROUND_RADIUS, radius);
            }
            CandidateId::TorqueBias | CandidateId::AerodynamicTorque => {
                let id = candidate.id.screened_effect();
                for (i, &c) in cols.iter().enumerate() {
                    push(EffectNumber::new(id, i), coefficient(c));
                }
            }
            CandidateId::InertiaScale => {
                for (i, &c) in cols.iter().enumerate() {
                    push(
                        EffectNumber::new(EffectId::InertiaScale, i),
                        1.0 / (1.0 + coefficient(c)).max(0.05),
                    );
                }
            }
            // Resolved into a delay, a motor lag or both by `fit_timing`.
            CandidateId::DelayOrMotorLag => {}
        }
    }
    set
}

/// The ground-effect radius of the grid that best explains the fit rows next to the columns
/// `others`.
fn profiled_ground_radius(
    problem: &Problem,
    columns: &[Vec<Channels>],
    others: &[usize],
    block_rows: usize,
) -> f64 {
    let (radius, _) = profile_search(
        problem,
        columns,
        others,
        0..problem.split,
        block_rows,
        // Without its zero, the neutral radius.
        &GROUND_RADIUS.profile_grid()[1..],
        |r| effects_from(&[GROUND_RADIUS], &[r]),
    );
    radius
}

/// What the screen produced: the candidates, their columns, the design and the selection.
pub struct Screened<'a> {
    pub candidates: &'a [Candidate],
    pub columns: &'a [Vec<Channels>],
    pub design: &'a BlockDesign,
    pub selection: &'a Selection,
}

/// Fits the kept candidates jointly. Returns the fitted set and what else was tried.
pub fn fit_parameters(
    problem: &Problem,
    screened: &Screened,
    iterations: usize,
    block_rows: usize,
    wind_start: [f64; 3],
) -> (FittedSet, FitAlternatives) {
    let Screened {
        candidates,
        columns,
        design,
        selection,
    } = screened;
    let (candidates, columns, design) = (*candidates, *columns, *design);
    let kept: Vec<&Candidate> = selection.kept.iter().map(|&g| &candidates[g]).collect();
    let mut alternatives = FitAlternatives::default();
    if kept.is_empty() {
        return (FittedSet::default(), alternatives);
    }
    let linear = screen_estimates(problem, &kept, columns, design, block_rows);
    let timing = kept.iter().any(|c| c.id == CandidateId::DelayOrMotorLag);
    let mut set = if timing {
        let others: Vec<usize> = kept
            .iter()
            .filter(|c| c.id != CandidateId::DelayOrMotorLag)
            .flat_map(|c| c.columns.clone())
            .collect();
        let (set, scores) = fit_timing(problem, columns, &others, &linear, iterations, block_rows);
        alternatives.timing = Some(scores);
        set
    } else {
        let mut set = linear.clone();
        set.refit(problem, iterations);
        set
    };
    let wind_acts_through = EffectId::Wind.needs_one_of();
    let has_drag = set
        .parameters
        .iter()
        .any(|p| wind_acts_through.contains(&p.effect));
    if has_drag {
        let still = set.refit(problem, 0);
        let mut with_wind = set.clone();
        with_wind
            .parameters
            .extend(EffectNumber::all_of(EffectId::Wind));
        with_wind.values.extend(wind_start);
        let windy = with_wind.refit(problem, iterations);
        alternatives.wind = Some(WindScores {
            still_air: still,
            with_wind: windy,
        });
        // The evidence rule decides whether the wind stays; here only whether it fits better.
        if windy < still {
            set = with_wind;
        }
    }
    (set, alternatives)
}

/// A delay or motor lag the fit found shorter than the log resolves, left out of the fitted set.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct BelowResolution {
    pub id: EffectId,
    /// Its fitted value, s.
    pub value_s: f64,
    /// The motor commands' effective interval, s ([`crate::recording::content`]).
    pub limit_s: f64,
}

/// Leaves out of `set` every delay and motor lag shorter than `limit_s` (a command's effect is
/// seen only as often as the command changes) and refits the rest; returns what was left out.
pub fn leave_out_below_resolution(
    problem: &Problem,
    set: &mut FittedSet,
    limit_s: f64,
    iterations: usize,
) -> Vec<BelowResolution> {
    let short: Vec<(EffectId, f64)> = set
        .parameters
        .iter()
        .zip(&set.values)
        .filter(|(p, v)| (**p == DELAY || **p == MOTOR_LAG) && **v < limit_s)
        .map(|(p, v)| (p.effect, *v))
        .collect();
    if short.is_empty() {
        return Vec::new();
    }
    for (id, _) in &short {
        *set = set.without(*id);
    }
    set.refit(problem, iterations);
    // A timing at zero is no timing: left out without a word.
    short
        .into_iter()
        .filter(|(_, value)| *value > 0.0)
        .map(|(id, value_s)| BelowResolution {
            id,
            value_s,
            limit_s,
        })
        .collect()
}

/// Resolves the timing term: a delay, a motor lag, or both, each started from its profile (both
/// from each single solution), fitted with the linear effects; returns the best fit and every
/// alternative's whitened error.
fn fit_timing(
    problem: &Problem,
    columns: &[Vec<Channels>],
    others: &[usize],
    linear: &FittedSet,
    iterations: usize,
    block_rows: usize,
) -> (FittedSet, TimingScores) {
    let mut singles = Vec::new();
    for kind in [DELAY, MOTOR_LAG] {
        let (start, _) = profile_search(
            problem,
            columns,
            others,
            0..problem.split,
            block_rows,
            &kind.profile_grid(),
            |v| effects_from(&[kind], &[v]),
        );
        let mut set = linear.clone();
        set.parameters.push(kind);
        set.values.push(start);
        let sse = set.refit(problem, iterations);
        singles.push((set, sse));
    }
    let delay = singles[0].0.values.last().copied().unwrap_or(0.0);
    let lag = singles[1].0.values.last().copied().unwrap_or(0.0);
    let mut best_both: Option<(FittedSet, f64)> = None;
    for (d, l) in [(delay, 0.0), (0.0, lag), (0.5 * delay, 0.5 * lag)] {
        let mut set = linear.clone();
        set.parameters.extend([DELAY, MOTOR_LAG]);
        set.values.extend([d, l]);
        let sse = set.refit(problem, iterations);
        if best_both.as_ref().is_none_or(|b| sse < b.1) {
            best_both = Some((set, sse));
        }
    }
    let both = best_both.expect("three starts");
    let scores = TimingScores {
        both: both.1,
        delay: singles[0].1,
        motor_lag: singles[1].1,
    };
    singles.push(both);
    let best = singles
        .into_iter()
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .expect("alternatives");
    (best.0, scores)
}
