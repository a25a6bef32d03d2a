//! The whole analysis of one recording: compare, locate, explain, fit, validate on held-out data.

use data::{Derivative, FlightLog, RateFrame};
use physics::{Effects, NominalModel};
use serde::Serialize;

use crate::error::{MismatchError, Result};
use crate::library::{Candidate, TIMING, build_library};
use crate::problem::{CHANNEL_NAMES, Channels, Problem};
use crate::recording::Recording;
use crate::refine::{
    Parameter, effect_column, effects_from, levenberg_marquardt, objective, profile_search,
    profile_wind,
};
use crate::selection::{Design, Selection, SelectionSettings, stability_selection};

/// Settings of an analysis (recorded in the output).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct AnalysisSettings {
    /// The smoothed derivative the residual and all MSEs are computed against.
    pub derivative: Derivative,
    /// Fraction of the analysed rows, at the end, held out from every fit and choice.
    pub heldout_fraction: f64,
    pub selection: SelectionSettings,
    /// A channel is significant when its residual RMS exceeds this multiple of its noise floor.
    pub significance_factor: f64,
    /// A window is located where the moving RMS of the residual exceeds this multiple of the floor.
    pub window_factor: f64,
    /// Length of the moving RMS, s.
    pub window_s: f64,
    /// Shortest window reported, s.
    pub min_window_s: f64,
    pub iterations: usize,
}

impl Default for AnalysisSettings {
    fn default() -> Self {
        Self {
            derivative: Derivative::SMOOTH,
            heldout_fraction: 0.3,
            selection: SelectionSettings::default(),
            significance_factor: 2.0,
            window_factor: 2.5,
            window_s: 1.0,
            min_window_s: 0.5,
            iterations: 40,
        }
    }
}

/// One analysed channel.
#[derive(Clone, Debug, Serialize)]
pub struct ChannelReport {
    pub name: String,
    pub residual_rms: f64,
    pub noise_floor: f64,
    pub significant: bool,
    pub heldout_mse_before: f64,
    pub heldout_mse_after: f64,
}

/// A stretch of time where one channel disagrees significantly.
#[derive(Clone, Debug, Serialize)]
pub struct Window {
    pub channel: String,
    pub t_start: f64,
    pub t_end: f64,
}

/// One effect found.
#[derive(Clone, Debug, Serialize)]
pub struct EffectReport {
    pub id: String,
    pub parameters: serde_json::Value,
    pub description: String,
    /// Share of the nominal model's noise-normalised residual sum of squares (fit part) that this
    /// effect removes, measured by leaving it out of the fitted model.
    pub explained_fraction: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct Mse {
    pub mse: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct Heldout {
    pub before: Mse,
    pub after: Mse,
    pub t_start: f64,
    pub t_end: f64,
}

/// Mean squared residuals (all analysed channels, raw units) before and after.
#[derive(Clone, Debug, Serialize)]
pub struct Fit {
    pub before: Mse,
    pub after: Mse,
    pub heldout: Heldout,
    /// What the MSEs are computed against.
    pub derivative: String,
    pub t_start: f64,
    pub t_end: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct CandidateReport {
    #[serde(flatten)]
    pub candidate: Candidate,
    pub selection_frequency: f64,
    pub chosen_on_data: bool,
    pub kept: bool,
}

#[derive(Clone, Debug, Serialize)]
pub struct SelectionReport {
    pub method: String,
    pub settings: SelectionSettings,
    pub candidates: Vec<CandidateReport>,
    /// Whitened fit errors of the two timing explanations, when the timing term was kept.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub timing_alternatives: Option<serde_json::Value>,
    /// Wind test: whitened gain per row and channel, and its t-statistic across folds.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub wind_test: Option<serde_json::Value>,
}

#[derive(Clone, Debug, Serialize)]
pub struct RateFrameReport {
    pub used: RateFrame,
    pub body_rms: f64,
    pub world_rms: f64,
}

/// Everything written to `mismatch.json`.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    pub recording: String,
    pub model: String,
    pub channels: Vec<ChannelReport>,
    pub windows: Vec<Window>,
    pub effects: Vec<EffectReport>,
    pub fit: Fit,
    pub rate_frame: RateFrameReport,
    pub selection: SelectionReport,
    pub settings: AnalysisSettings,
}

/// The report with the data behind it (for figures and summaries).
#[derive(Clone, Debug)]
pub struct Analysis {
    pub report: Report,
    pub problem: Problem,
    pub before: Vec<Channels>,
    pub after: Vec<Channels>,
    pub fitted: Effects,
}

/// Analyses a recording against a nominal model. `model_name` only labels the output.
pub fn analyze(
    log: &FlightLog,
    model: &NominalModel,
    model_name: &str,
    settings: &AnalysisSettings,
) -> Result<Analysis> {
    let min_rows = 8 * settings.derivative.min_samples().max(5);
    let recording = Recording::new(log, model, min_rows)?;
    let problem = Problem::new(
        recording,
        model.clone(),
        settings.derivative,
        settings.heldout_fraction,
    )?;
    let nominal = Effects::default();
    let before = problem.residual(&nominal);
    let fit_rows = 0..problem.split;

    let (candidates, mut columns) = build_library(&problem);
    let wind_start = profile_nonlinear(
        &problem,
        &before,
        &candidates,
        &mut columns,
        fit_rows.clone(),
        settings.selection.block_rows,
    );
    let groups: Vec<Vec<usize>> = candidates.iter().map(|c| c.columns.clone()).collect();
    let block_rows = settings.selection.block_rows;
    let design = Design::new(&problem, &before, &columns, fit_rows.clone(), block_rows);
    let selection = stability_selection(&design, &groups, &settings.selection);

    let fitted = fit_parameters(
        &problem,
        &candidates,
        &columns,
        &design,
        &selection,
        settings,
        wind_start,
    );
    let (effects, timing_alternatives, wind_test) = fitted;
    let after = problem.residual(&effects);
    let report = build_report(
        &problem,
        log,
        model_name,
        settings,
        &before,
        &after,
        &effects,
        &candidates,
        &selection,
        timing_alternatives,
        wind_test,
    );
    let analysis = Analysis {
        report,
        problem,
        before,
        after,
        fitted: effects,
    };
    check_finite(&analysis)?;
    Ok(analysis)
}

/// Fails, naming the recording and the first offending quantity, unless every number of an analysis
/// (the residuals behind the figure, the times and everything in the report) is finite: a recording
/// whose values overflow the comparison must not give NaN or infinite results, in the report or in a
/// figure.
pub(crate) fn check_finite(analysis: &Analysis) -> Result<()> {
    let problem = &analysis.problem;
    let non_finite = |what: String| MismatchError::NonFinite {
        path: problem.recording.path.clone(),
        what,
    };
    if let Some(t) = problem.time.iter().find(|t| !t.is_finite()) {
        return Err(non_finite(format!("time ({t})")));
    }
    for (name, residual) in [
        ("residual of the nominal model", &analysis.before),
        ("residual of the fitted model", &analysis.after),
    ] {
        for (row, r) in residual.iter().enumerate() {
            if let Some(c) = (0..problem.channels).find(|&c| !r[c].is_finite()) {
                let t = problem.time.get(row).copied().unwrap_or(f64::NAN);
                return Err(non_finite(format!(
                    "{name} in {} ({} at t = {t} s)",
                    CHANNEL_NAMES[c], r[c]
                )));
            }
        }
    }
    // serde_json writes a non-finite number as null, and the report has no other nulls.
    let report = serde_json::to_value(&analysis.report).expect("the report serialises");
    if let Some(field) = first_null(&report, String::new()) {
        return Err(non_finite(format!("{field} in the report")));
    }
    Ok(())
}

/// The path (`fit.before.mse`, `channels[0].residual_rms`) of the first null in a JSON value.
fn first_null(value: &serde_json::Value, path: String) -> Option<String> {
    match value {
        serde_json::Value::Null => Some(path),
        serde_json::Value::Array(items) => items
            .iter()
            .enumerate()
            .find_map(|(i, item)| first_null(item, format!("{path}[{i}]"))),
        serde_json::Value::Object(map) => map.iter().find_map(|(key, item)| {
            let inner = if path.is_empty() {
                key.clone()
            } else {
                format!("{path}.{key}")
            };
            first_null(item, inner)
        }),
        _ => None,
    }
}

/// Replaces the screen columns of the nonlinear candidates by the exact effect at the parameters
/// a profile search finds next to all other columns: the ground-effect radius, the better of a
/// delay and a motor lag, and the air velocity of the quadratic drag. Returns that air velocity.
fn profile_nonlinear(
    problem: &Problem,
    before: &[Channels],
    candidates: &[Candidate],
    columns: &mut [Vec<Channels>],
    range: std::ops::Range<usize>,
    block_rows: usize,
) -> [f64; 3] {
    let base = problem.predict(&Effects::default());
    let total = columns.len();
    let others_of = |candidate: &Candidate| -> Vec<usize> {
        (0..total)
            .filter(|c| !candidate.columns.contains(c))
            .collect()
    };
    let find = |id: &str| candidates.iter().find(|c| c.id == id);
    if let Some(candidate) = find("ground_effect") {
        let others = others_of(candidate);
        let grid: Vec<f64> = (1..=60).map(|i| i as f64 * 0.02).collect();
        let effect = |r: f64| effects_from(&[Parameter::GroundRadius], &[r]);
        let (radius, _) = profile_search(
            problem,
            columns,
            &others,
            range.clone(),
            block_rows,
            &grid,
            effect,
        );
        columns[candidate.columns[0]] =
            effect_column(problem, &base, &effect(radius), radius * radius);
    }
    if let Some(candidate) = find(TIMING) {
        let others = others_of(candidate);
        let grid: Vec<f64> = (1..=60).map(|i| i as f64 * 0.0025).collect();
        let best = [Parameter::Delay, Parameter::MotorLag]
            .into_iter()
            .map(|kind| {
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
    if let Some(candidate) = find("quadratic_drag") {
        let others = others_of(candidate);
        let (w, _) = profile_wind(problem, before, columns, &others, range.clone(), block_rows);
        wind = w;
        let effects = effects_from(
            &[
                Parameter::QuadraticDrag,
                Parameter::Wind(0),
                Parameter::Wind(1),
                Parameter::Wind(2),
            ],
            &[1.0, w[0], w[1], w[2]],
        );
        columns[candidate.columns[0]] = effect_column(problem, &base, &effects, 1.0);
    }
    wind
}

type FitOutcome = (
    Effects,
    Option<serde_json::Value>,
    Option<serde_json::Value>,
);

fn fit_parameters(
    problem: &Problem,
    candidates: &[Candidate],
    columns: &[Vec<Channels>],
    design: &Design,
    selection: &Selection,
    settings: &AnalysisSettings,
    wind_start: [f64; 3],
) -> FitOutcome {
    let fit_rows = 0..problem.split;
    let block_rows = settings.selection.block_rows;
    let kept: Vec<&Candidate> = selection.kept.iter().map(|&g| &candidates[g]).collect();
    if kept.is_empty() {
        return (Effects::default(), None, None);
    }
    let kept_columns: Vec<usize> = kept.iter().flat_map(|c| c.columns.clone()).collect();
    let ones = vec![1.0; design.blocks()];
    let theta = design.solve(&ones, &kept_columns);
    let coefficient = |column: usize| {
        theta[kept_columns
            .iter()
            .position(|c| *c == column)
            .expect("kept")]
    };
    let mut parameters = Vec::new();
    let mut values = Vec::new();
    let mut timing = false;
    for candidate in &kept {
        let others: Vec<usize> = kept_columns
            .iter()
            .copied()
            .filter(|c| !candidate.columns.contains(c))
            .collect();
        let cols = &candidate.columns;
        match candidate.id.as_str() {
            "thrust_scale" => {
                parameters.push(Parameter::ThrustScale);
                values.push(1.0 + coefficient(cols[0]));
            }
            "linear_drag" => {
                for (i, &c) in cols.iter().enumerate() {
                    parameters.push(Parameter::LinearDrag(i));
                    values.push(coefficient(c).max(0.0));
                }
            }
            "quadratic_drag" => {
                parameters.push(Parameter::QuadraticDrag);
                values.push(coefficient(cols[0]).max(0.0));
            }
            "ground_effect" => {
                let grid: Vec<f64> = (1..=60).map(|i| i as f64 * 0.02).collect();
                let (radius, _) = profile_search(
                    problem,
                    columns,
                    &others,
                    fit_rows.clone(),
                    block_rows,
                    &grid,
                    |r| effects_from(&[Parameter::GroundRadius], &[r]),
                );
                parameters.push(Parameter::GroundRadius);
                values.push(radius);
            }
            "torque_bias" => {
                for (i, &c) in cols.iter().enumerate() {
                    parameters.push(Parameter::TorqueBias(i));
                    values.push(coefficient(c));
                }
            }
            "inertia_scale" => {
                for (i, &c) in cols.iter().enumerate() {
                    parameters.push(Parameter::InertiaScale(i));
                    values.push(1.0 / (1.0 + coefficient(c)).max(0.05));
                }
            }
            id if id == TIMING => timing = true,
            other => unreachable!("unknown candidate {other}"),
        }
    }
    let screen_values = values.clone();
    let mut timing_alternatives = None;
    let (mut parameters, mut values, mut sse) = if timing {
        let others: Vec<usize> = kept
            .iter()
            .filter(|c| c.id != TIMING)
            .flat_map(|c| c.columns.clone())
            .collect();
        let grid: Vec<f64> = (0..=60).map(|i| i as f64 * 0.0025).collect();
        let mut best: Option<(Vec<Parameter>, Vec<f64>, f64)> = None;
        let mut scores = serde_json::Map::new();
        for kind in [Parameter::Delay, Parameter::MotorLag] {
            let (start, _) = profile_search(
                problem,
                columns,
                &others,
                fit_rows.clone(),
                block_rows,
                &grid,
                |v| effects_from(&[kind], &[v]),
            );
            let mut p = parameters.clone();
            let mut v = values.clone();
            p.push(kind);
            v.push(start);
            let (v, sse) =
                levenberg_marquardt(problem, &p, &v, fit_rows.clone(), settings.iterations);
            scores.insert(kind.effect_id().to_string(), serde_json::json!(sse));
            if best.as_ref().is_none_or(|b| sse < b.2) {
                best = Some((p, v, sse));
            }
        }
        timing_alternatives = Some(serde_json::Value::Object(scores));
        best.expect("two alternatives tried")
    } else {
        let (v, sse) = levenberg_marquardt(
            problem,
            &parameters,
            &values,
            fit_rows.clone(),
            settings.iterations,
        );
        (parameters.clone(), v, sse)
    };
    let mut wind_test = None;
    if parameters.contains(&Parameter::QuadraticDrag) {
        // The screen's drag column was already at the profiled air velocity: fit with wind, then
        // test whether still air explains the residual as well.
        let mut with_wind = parameters.clone();
        with_wind.extend([Parameter::Wind(0), Parameter::Wind(1), Parameter::Wind(2)]);
        // Two starts: the still-air fit, and the screen's estimates (the still-air fit may have
        // pushed the drag coefficient to its bound); both with the profiled air velocity.
        let starts = [values.clone(), {
            let mut v = values.clone();
            v[..screen_values.len()].copy_from_slice(&screen_values);
            v
        }];
        let (v, sse_wind) = starts
            .iter()
            .map(|start| {
                let mut start = start.clone();
                start.extend(wind_start);
                levenberg_marquardt(
                    problem,
                    &with_wind,
                    &start,
                    fit_rows.clone(),
                    settings.iterations,
                )
            })
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .expect("two starts");
        let count = (fit_rows.len() * problem.channels) as f64;
        let gain = (sse - sse_wind) / count;
        let t = fold_t_statistic(
            problem,
            &parameters,
            &values,
            &with_wind,
            &v,
            settings.selection.folds,
        );
        let accepted = gain >= settings.selection.min_gain && t >= settings.selection.min_t;
        wind_test = Some(serde_json::json!({"gain": gain, "t": t, "accepted": accepted}));
        if accepted {
            parameters = with_wind;
            values = v;
            sse = sse_wind;
        }
    }
    let _ = sse;
    let (parameters, values) = backward_elimination(problem, parameters, values, settings);
    (
        effects_from(&parameters, &values),
        timing_alternatives,
        wind_test,
    )
}

/// Drops, one at a time, the effect whose removal (with the others refitted) costs least, while
/// that cost fails the selection's own test (mean whitened gain per row and channel below
/// `min_gain`, or paired t over blocks below `min_t`). Catches terms the linear screen needed only
/// to patch a linearisation that the exact fit no longer needs.
fn backward_elimination(
    problem: &Problem,
    mut parameters: Vec<Parameter>,
    mut values: Vec<f64>,
    settings: &AnalysisSettings,
) -> (Vec<Parameter>, Vec<f64>) {
    let fit_rows = 0..problem.split;
    loop {
        let mut ids: Vec<&'static str> = parameters.iter().map(|p| p.effect_id()).collect();
        ids.dedup();
        if ids.len() < 2 {
            return (parameters, values);
        }
        let full = block_sse(
            problem,
            &effects_from(&parameters, &values),
            settings.selection.block_rows,
        );
        let mut weakest: Option<(f64, Vec<Parameter>, Vec<f64>)> = None;
        for id in ids {
            // Wind goes with its drag; wind alone has had its own test.
            let drop = |p: &Parameter| {
                p.effect_id() == id || (id == "quadratic_drag" && p.effect_id() == "wind")
            };
            let kept: Vec<(Parameter, f64)> = parameters
                .iter()
                .zip(&values)
                .filter(|(p, _)| !drop(p))
                .map(|(p, v)| (*p, *v))
                .collect();
            let (reduced_parameters, start): (Vec<Parameter>, Vec<f64>) = kept.into_iter().unzip();
            let (reduced_values, _) = levenberg_marquardt(
                problem,
                &reduced_parameters,
                &start,
                fit_rows.clone(),
                settings.iterations / 2,
            );
            let reduced = block_sse(
                problem,
                &effects_from(&reduced_parameters, &reduced_values),
                settings.selection.block_rows,
            );
            let gains: Vec<f64> = reduced
                .iter()
                .zip(&full)
                .map(|(r, f)| r.1 - f.1)
                .zip(&full)
                .map(|(g, f)| g / f.0)
                .collect();
            let mean = gains.iter().sum::<f64>() / gains.len() as f64;
            let sd = (gains.iter().map(|g| (g - mean).powi(2)).sum::<f64>()
                / (gains.len() - 1).max(1) as f64)
                .sqrt();
            let t = mean / (sd / (gains.len() as f64).sqrt()).max(1e-300);
            let passes = mean >= settings.selection.min_gain && t >= settings.selection.min_t;
            if !passes && weakest.as_ref().is_none_or(|w| mean < w.0) {
                weakest = Some((mean, reduced_parameters, reduced_values));
            }
        }
        match weakest {
            Some((_, p, v)) => {
                parameters = p;
                values = v;
            }
            None => return (parameters, values),
        }
    }
}

/// Per block of fit rows: (row × channel count, whitened sum of squares).
fn block_sse(problem: &Problem, effects: &Effects, block_rows: usize) -> Vec<(f64, f64)> {
    let residual = problem.residual(effects);
    (0..problem.split)
        .step_by(block_rows)
        .map(|start| {
            let end = (start + block_rows).min(problem.split);
            (
                ((end - start) * problem.channels) as f64,
                problem.whitened_sse(&residual, start..end),
            )
        })
        .collect()
}

/// Paired t-statistic of the per-fold whitened error difference between two fitted models.
fn fold_t_statistic(
    problem: &Problem,
    parameters_a: &[Parameter],
    values_a: &[f64],
    parameters_b: &[Parameter],
    values_b: &[f64],
    folds: usize,
) -> f64 {
    let rows = problem.split;
    let gains: Vec<f64> = (0..folds)
        .map(|f| {
            let range = f * rows / folds..(f + 1) * rows / folds;
            let a = objective(problem, parameters_a, values_a, range.clone());
            let b = objective(problem, parameters_b, values_b, range.clone());
            (a - b) / (range.len() * problem.channels).max(1) as f64
        })
        .collect();
    let mean = gains.iter().sum::<f64>() / folds as f64;
    let sd =
        (gains.iter().map(|g| (g - mean).powi(2)).sum::<f64>() / (folds - 1).max(1) as f64).sqrt();
    mean / (sd / (folds as f64).sqrt()).max(1e-300)
}

/// Windows where the centred moving RMS of a channel's residual exceeds `factor` × floor.
fn locate_windows(
    problem: &Problem,
    residual: &[Channels],
    settings: &AnalysisSettings,
) -> Vec<Window> {
    let rows = residual.len();
    let half = half_window_rows(settings.window_s, problem.recording.dt, rows);
    let mut windows = Vec::new();
    for c in 0..problem.channels {
        let threshold = (settings.window_factor * problem.noise_floor[c]).powi(2);
        let squares: Vec<f64> = residual.iter().map(|r| r[c] * r[c]).collect();
        let mut prefix = vec![0.0; rows + 1];
        for k in 0..rows {
            prefix[k + 1] = prefix[k] + squares[k];
        }
        let flagged: Vec<bool> = (0..rows)
            .map(|k| {
                let (a, b) = (k.saturating_sub(half), (k + half + 1).min(rows));
                (prefix[b] - prefix[a]) / (b - a) as f64 > threshold
            })
            .collect();
        let mut k = 0;
        while k < rows {
            if !flagged[k] {
                k += 1;
                continue;
            }
            let start = k;
            while k < rows && flagged[k] {
                k += 1;
            }
            let (t_start, t_end) = (problem.time[start], problem.time[k - 1]);
            if t_end - t_start >= settings.min_window_s {
                windows.push(Window {
                    channel: CHANNEL_NAMES[c].to_string(),
                    t_start,
                    t_end,
                });
            }
        }
    }
    windows
}

/// Half the length, in rows, of a moving window of `window_s` seconds at sample interval `dt`,
/// capped at `rows` (a window longer than the recording is the whole recording), so that the
/// window's row arithmetic cannot overflow however small `dt` is.
fn half_window_rows(window_s: f64, dt: f64, rows: usize) -> usize {
    (((window_s / dt) / 2.0).round() as usize).min(rows)
}

fn rms(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, count) = values.fold((0.0, 0usize), |(s, n), v| (s + v * v, n + 1));
    (sum / count.max(1) as f64).sqrt()
}

#[allow(clippy::too_many_arguments)]
fn build_report(
    problem: &Problem,
    log: &FlightLog,
    model_name: &str,
    settings: &AnalysisSettings,
    before: &[Channels],
    after: &[Channels],
    effects: &Effects,
    candidates: &[Candidate],
    selection: &Selection,
    timing_alternatives: Option<serde_json::Value>,
    wind_test: Option<serde_json::Value>,
) -> Report {
    let fit_rows = 0..problem.split;
    let heldout_rows = problem.split..problem.rows();
    let channel_mse = |residual: &[Channels], c: usize, range: std::ops::Range<usize>| {
        residual[range.clone()]
            .iter()
            .map(|r| r[c] * r[c])
            .sum::<f64>()
            / range.len().max(1) as f64
    };
    let channels = (0..problem.channels)
        .map(|c| {
            let residual_rms = rms(before.iter().map(|r| r[c]));
            ChannelReport {
                name: CHANNEL_NAMES[c].to_string(),
                residual_rms,
                noise_floor: problem.noise_floor[c],
                significant: residual_rms > settings.significance_factor * problem.noise_floor[c],
                heldout_mse_before: channel_mse(before, c, heldout_rows.clone()),
                heldout_mse_after: channel_mse(after, c, heldout_rows.clone()),
            }
        })
        .collect();
    let nominal_sse = problem.whitened_sse(before, fit_rows.clone());
    let full_sse = problem.whitened_sse(after, fit_rows.clone());
    let parameters = serde_json::to_value(effects).expect("effects serialise");
    let effect_reports = effects
        .ids()
        .into_iter()
        .map(|id| {
            let without = remove_effect(effects, id);
            let sse_without = problem.whitened_sse(&problem.residual(&without), fit_rows.clone());
            EffectReport {
                id: id.to_string(),
                parameters: parameters[id].clone(),
                description: describe(id, effects),
                explained_fraction: ((sse_without - full_sse) / nominal_sse.max(1e-300)).max(0.0),
            }
        })
        .collect();
    let derivative = match settings.derivative {
        Derivative::SavitzkyGolay { window, order } => format!(
            "Savitzky-Golay derivative (window {window}, order {order}) of the recorded velocity and body rate; the model's prediction is smoothed by the matched weights"
        ),
        other => format!("{other:?} derivative"),
    };
    let t = |row: usize| problem.time[row.min(problem.rows() - 1)];
    Report {
        recording: log.path.display().to_string(),
        model: model_name.to_string(),
        channels,
        windows: locate_windows(problem, before, settings),
        effects: effect_reports,
        fit: Fit {
            before: Mse { mse: problem.mse(before, fit_rows.clone()) },
            after: Mse { mse: problem.mse(after, fit_rows.clone()) },
            heldout: Heldout {
                before: Mse { mse: problem.mse(before, heldout_rows.clone()) },
                after: Mse { mse: problem.mse(after, heldout_rows.clone()) },
                t_start: t(heldout_rows.start),
                t_end: t(heldout_rows.end - 1),
            },
            derivative,
            t_start: t(0),
            t_end: t(fit_rows.end - 1),
        },
        rate_frame: RateFrameReport {
            used: problem.recording.rate_frame,
            body_rms: problem.recording.rate_frame_errors.0,
            world_rms: problem.recording.rate_frame_errors.1,
        },
        selection: SelectionReport {
            method: "forward stepwise selection of candidate groups scored by time-blocked cross-validation on the noise-normalised residual, kept when chosen in enough block-bootstrap resamples (stability selection)".to_string(),
            settings: settings.selection,
            candidates: candidates
                .iter()
                .enumerate()
                .map(|(g, candidate)| CandidateReport {
                    candidate: candidate.clone(),
                    selection_frequency: selection.frequencies[g],
                    chosen_on_data: selection.chosen_on_data.contains(&g),
                    kept: selection.kept.contains(&g),
                })
                .collect(),
            timing_alternatives,
            wind_test,
        },
        settings: *settings,
    }
}

/// The effects without one of them (wind goes with its drag).
pub fn remove_effect(effects: &Effects, id: &str) -> Effects {
    let mut e = *effects;
    match id {
        "linear_drag" => e.linear_drag = None,
        "quadratic_drag" => {
            e.quadratic_drag = None;
            e.wind = None;
        }
        "wind" => e.wind = None,
        "thrust_scale" => e.thrust_scale = None,
        "motor_lag" => e.motor_lag = None,
        "ground_effect" => e.ground_effect = None,
        "torque_bias" => e.torque_bias = None,
        "inertia_scale" => e.inertia_scale = None,
        "delay" => e.delay = None,
        _ => {}
    }
    if e.quadratic_drag.is_none() && e.linear_drag.is_none() {
        e.wind = None;
    }
    e
}

fn vector(v: [f64; 3], digits: usize) -> String {
    format!("[{:.digits$}, {:.digits$}, {:.digits$}]", v[0], v[1], v[2])
}

/// One sentence per effect, in plain words.
pub fn describe(id: &str, e: &Effects) -> String {
    match id {
        "linear_drag" => {
            let d = e.linear_drag.map(|x| x.d).unwrap_or_default();
            format!(
                "Rotor drag: a force against the velocity along each body axis, d = {} 1/s (at 2 m/s forward flight about {:.2} m/s² of deceleration).",
                vector(d, 3),
                2.0 * d[0].max(d[1])
            )
        }
        "quadratic_drag" => {
            let c = e.quadratic_drag.map(|x| x.c).unwrap_or_default();
            format!(
                "Aerodynamic drag growing with the square of the airspeed, c = {c:.4} 1/m (at 5 m/s airspeed about {:.2} m/s²).",
                25.0 * c
            )
        }
        "wind" => {
            let w = e.air_velocity();
            format!(
                "The drag acts on the velocity relative to air moving at {} m/s (speed {:.2} m/s): there is wind.",
                vector(w, 2),
                physics::vector::norm(w)
            )
        }
        "thrust_scale" => {
            let k = e.thrust_scale.map(|x| x.k).unwrap_or(1.0);
            format!(
                "The rotors produce {k:.3} times the thrust the model assumes ({:+.1}%).",
                100.0 * (k - 1.0)
            )
        }
        "motor_lag" => format!(
            "Each motor reaches its commanded speed with a first-order lag of time constant {:.1} ms.",
            1000.0 * e.lag_s()
        ),
        "ground_effect" => {
            let r = e.ground_effect.map(|x| x.r_m).unwrap_or_default();
            format!(
                "Extra thrust near the ground (ground effect), radius r = {r:.3} m: +{:.1}% thrust at 0.3 m height, +{:.2}% at 1.5 m.",
                100.0 * (1.0 / (1.0 - physics::ground_ratio(r, 0.3)) - 1.0),
                100.0 * (1.0 / (1.0 - physics::ground_ratio(r, 1.5)) - 1.0)
            )
        }
        "torque_bias" => format!(
            "A constant extra angular acceleration {} rad/s² (a torque offset, e.g. an off-centre mass or a tilted motor).",
            vector(e.torque_bias.map(|x| x.b).unwrap_or_default(), 3)
        ),
        "inertia_scale" => format!(
            "The moments of inertia are {} times the model's.",
            vector(e.inertia_scale.map(|x| x.k).unwrap_or([1.0; 3]), 3)
        ),
        "delay" => format!(
            "The vehicle responds to its commands {:.1} ms late.",
            1000.0 * e.delay_s()
        ),
        other => other.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_moving_window_cannot_overflow() {
        // 1 s at 50 Hz: 25 rows either side, as before.
        assert_eq!(half_window_rows(1.0, 0.02, 2500), 25);
        // Times × 1e-300: the window would be ~1e300 rows; capped at the recording.
        let rows = 2000;
        let half = half_window_rows(1.0, 2e-302, rows);
        assert_eq!(half, rows);
        let k = rows - 1;
        assert_eq!(
            (k.saturating_sub(half), (k + half + 1).min(rows)),
            (0, rows)
        );
        // A NaN interval gives a zero-row window, not a panic.
        assert_eq!(half_window_rows(1.0, f64::NAN, rows), 0);
    }

    #[test]
    fn nulls_are_found_with_their_path() {
        let value = serde_json::json!({"a": 1.0, "fit": {"before": {"mse": f64::INFINITY}}});
        assert_eq!(
            first_null(&value, String::new()).as_deref(),
            Some("fit.before.mse")
        );
        let value = serde_json::json!({"channels": [{"x": 1.0}, {"x": f64::NAN}]});
        assert_eq!(
            first_null(&value, String::new()).as_deref(),
            Some("channels[1].x")
        );
        assert_eq!(
            first_null(&serde_json::json!({"a": [1, 2]}), String::new()),
            None
        );
    }
}
