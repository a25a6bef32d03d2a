//! The whole analysis of one recording: compare, locate, explain, fit, judge the evidence, validate
//! on held-out data.

use std::collections::BTreeMap;

use data::FlightLog;
use physics::vector::Vec3;
use physics::{EffectId, EffectParameters, Effects, Logger, NominalModel, ParameterValue};
pub use report::mismatch::recording::{
    ChannelReport, Fit, Heldout, Mse, RateFrame, RateFrameReport, Window,
};
use serde::Serialize;
use sindy::stability::{Selection, SelectionSettings, stability_selection};
use sindy::weak_form::{TestFunction, white_noise_sigma};

use crate::command_samples::ActuatorLimits;
use crate::degenerate;
use crate::describe::describe;
use crate::error::{MismatchError, Result};
use crate::estimate::{self, Estimate, EstimateSettings};
use crate::evidence::{self, Evidence, EvidenceSettings, explained_fractions};
use crate::fit::{FitAlternatives, Screened, fit_parameters, profile_nonlinear};
use crate::forward;
use crate::least_squares::Termination;
use crate::library::{Candidate, build_library};
use crate::noise_reaction::{self, NoiseReaction};
use crate::problem::{CHANNEL_NAMES, Channels, Problem};
use crate::recording::Recording;
use crate::refine::{FitRows, StepBasis, effects_from};
use crate::simex::NoiseSources;

/// Settings of an analysis (recorded in the output).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct AnalysisSettings {
    /// The comparison's test function.
    pub test_function: TestFunction,
    /// Fraction of the analysed rows, at the end, held out from every fit and choice.
    pub heldout_fraction: f64,
    /// Length of the blocks that the selection and the evidence rule compare, s.
    pub block_s: f64,
    pub selection: SelectionSettings,
    pub evidence: EvidenceSettings,
    /// The final estimate of the named effects' parameters ([`crate::estimate`]).
    pub estimate: EstimateSettings,
    /// A channel is significant when its residual RMS exceeds this multiple of its noise floor.
    pub significance_factor: f64,
    /// A window is located where the moving RMS of the residual exceeds this multiple of the floor.
    pub window_factor: f64,
    /// Length of the moving RMS, s.
    pub window_s: f64,
    /// Shortest window reported, s.
    pub min_window_s: f64,
    pub iterations: usize,
    /// What to do with a recording without measurement noise ([`degenerate::check_noise`]).
    #[serde(skip)]
    pub noise_free: NoiseFree,
}

/// What [`analyze`] does with a recording whose noise floor is below the comparison's accuracy.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum NoiseFree {
    /// Refuse it: the evidence rule measures residuals in units of the noise.
    #[default]
    Refuse,
    /// Analyse it anyway, for development on noise-free simulations (the estimates are
    /// meaningful; the evidence, the windows and the significance are not).
    Analyse,
}

impl Default for AnalysisSettings {
    fn default() -> Self {
        Self {
            test_function: TestFunction::default(),
            heldout_fraction: 0.3,
            block_s: 1.0,
            selection: SelectionSettings::default(),
            evidence: EvidenceSettings::default(),
            estimate: EstimateSettings::default(),
            significance_factor: 2.0,
            window_factor: 2.5,
            window_s: 1.0,
            min_window_s: 0.5,
            iterations: 40,
            noise_free: NoiseFree::Refuse,
        }
    }
}

/// One effect found.
#[derive(Clone, Debug, Serialize)]
pub struct EffectReport {
    pub id: EffectId,
    /// The final estimate: all rows, robust weights ([`crate::estimate`]).
    pub parameters: EffectParameters,
    /// The standard error of each parameter, by name, in the parameters' shape (from the final
    /// estimate's Jacobian, the residual's variance and its autocorrelation); absent where the fit
    /// does not determine it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub standard_errors: Option<BTreeMap<&'static str, ParameterValue>>,
    /// The parameters fitted on the fit part only, with which the evidence rule judged the effect
    /// and the held-out part checked it.
    pub fit_part_parameters: EffectParameters,
    /// The bias the noise on the model's inputs left, measured and subtracted from `parameters`
    /// ([`crate::simex`]); absent when the commands are not samples of a faster controller.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub noise_bias: Option<EffectParameters>,
    pub description: String,
    /// This effect's share of the nominal model's noise-normalised residual sum of squares (fit
    /// part) that the fitted effects remove, in [0, 1]; the shares sum to the total removed.
    pub explained_fraction: f64,
    /// Why it is named ([`crate::evidence`]).
    pub evidence: Evidence,
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
    /// What the joint fit tried besides the model it kept.
    pub alternatives: FitAlternatives,
    /// The effects the evidence rule dropped, with their evidence when dropped.
    pub dropped: Vec<Evidence>,
}

/// Everything written to `mismatch.json`.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    pub recording: String,
    pub model: String,
    pub channels: Vec<ChannelReport>,
    /// Where the nominal model disagrees with the recording.
    pub windows: Vec<Window>,
    pub effects: Vec<EffectReport>,
    /// Where a significant residual remains that the effects found do not explain.
    pub unexplained: Vec<Window>,
    pub fit: Fit,
    /// Share of the (row, channel) residuals the final estimate downweighted.
    pub estimate_downweighted_fraction: f64,
    /// Times (s) of the command steps between samples whose place the final estimate left free.
    pub estimate_step_times: Vec<f64>,
    /// Why the solver stopped in the final estimate's last reweighting pass (absent when it fitted
    /// nothing).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub estimate_termination: Option<Termination>,
    /// The noises whose bias the final estimate measured and removed ([`crate::simex`]), when it did.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub estimate_noise_bias: Option<NoiseSources>,
    /// The limits the logged commands sat at, when any did (instantaneous samples are reconstructed
    /// through them: [`crate::command_samples`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub command_limits: Option<[ActuatorLimits; 4]>,
    pub rate_frame: RateFrameReport,
    /// How the recording's commands and rates were logged (from the model file).
    pub logger: Logger,
    /// What was taken out of sampled commands of a faster controller: their unfelt reaction to the
    /// logged noise (absent when nothing was).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub noise_reaction: Option<NoiseReaction>,
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

/// The stages of an analysis, in order (each pass goes through all of them).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// The weak-form comparison of the recording with the nominal model.
    Comparing,
    /// The candidate effects' columns, the nonlinear ones profiled.
    Candidates,
    /// Forward stepwise selection over block-bootstrap resamples (stability selection).
    Screening,
    /// The joint fit of the kept candidates.
    Fitting,
    /// The evidence rule, each effect refitted without it.
    Judging,
    /// The final estimate on all rows (robust weights, the noise's bias).
    Estimating,
}

impl Stage {
    /// What the stage does, for a progress line.
    pub fn describe(self) -> &'static str {
        match self {
            Self::Comparing => "comparing the recording with the model",
            Self::Candidates => "computing the candidate effects",
            Self::Screening => "screening the candidate effects",
            Self::Fitting => "fitting the kept effects",
            Self::Judging => "judging the evidence for each effect",
            Self::Estimating => "estimating the named effects on all rows",
        }
    }
}

/// Analyses a recording against a nominal model. `model_name` only labels the output.
pub fn analyze(
    log: &FlightLog,
    model: &NominalModel,
    model_name: &str,
    settings: &AnalysisSettings,
) -> Result<Analysis> {
    analyze_observed(log, model, model_name, settings, &|_, _| {})
}

/// [`analyze`], telling `observe` the pass (1, or 2 when the commands' reaction to the velocity
/// noise is removed) and the stage as each begins.
pub fn analyze_observed(
    log: &FlightLog,
    model: &NominalModel,
    model_name: &str,
    settings: &AnalysisSettings,
    observe: &dyn Fn(usize, Stage),
) -> Result<Analysis> {
    if log.len() > degenerate::MAX_ANALYSED_ROWS {
        return Err(MismatchError::TooLong {
            path: log.path.clone(),
            rows: log.len(),
        });
    }
    let recording = Recording::new(log, model, 40)?;
    let first = analyze_recording(recording, log, model, model_name, settings, &|stage| {
        observe(1, stage)
    })?;
    if first.problem.recording.noise_reaction.is_none() {
        return Ok(first);
    }
    // Sampled commands of a faster controller: with the effects identified, the model predicts the
    // velocity well enough to separate its noise, and the commands' unfelt reaction to it goes too.
    let mut recording = first.problem.recording.clone();
    let predicted = predicted_velocity_changes(&recording, model, &first.fitted);
    let prediction_noise = prediction_noise(&recording, model, &first.fitted);
    if !noise_reaction::remove_velocity(&mut recording, &predicted, prediction_noise) {
        return Ok(first);
    }
    analyze_recording(recording, log, model, model_name, settings, &|stage| {
        observe(2, stage)
    })
}

/// The model's velocity change over every row interval.
fn predicted_velocity_changes(
    recording: &Recording,
    model: &NominalModel,
    effects: &Effects,
) -> Vec<Vec3> {
    let prediction = forward::predict_substeps(recording, model, effects);
    prediction
        .translational
        .chunks(forward::SUBSTEPS)
        .enumerate()
        .map(|(k, accelerations)| {
            let h = (recording.time[k + 1] - recording.time[k]) / forward::SUBSTEPS as f64;
            std::array::from_fn(|a| h * accelerations.iter().map(|x| x[a]).sum::<f64>())
        })
        .collect()
}

/// The row-to-row noise of the model's velocity change: the white noise of the acceleration at
/// each row's logged attitude and command (which carry their own noise), times the interval.
fn prediction_noise(recording: &Recording, model: &NominalModel, effects: &Effects) -> Vec3 {
    let (accelerations, _) =
        forward::accelerations_at_rows(recording, &recording.commands, model, effects);
    std::array::from_fn(|a| {
        let series: Vec<f64> = accelerations.iter().map(|x| x[a]).collect();
        recording.dt * white_noise_sigma(&series)
    })
}

fn analyze_recording(
    recording: Recording,
    log: &FlightLog,
    model: &NominalModel,
    model_name: &str,
    settings: &AnalysisSettings,
    observe: &dyn Fn(Stage),
) -> Result<Analysis> {
    observe(Stage::Comparing);
    let problem = Problem::new(
        recording,
        model.clone(),
        settings.test_function,
        settings.heldout_fraction,
    )?;
    if settings.noise_free == NoiseFree::Refuse {
        degenerate::check_noise(&problem).map_err(|degeneracy| MismatchError::Degenerate {
            path: problem.recording.path.clone(),
            degeneracy,
        })?;
    }
    let block_rows = ((settings.block_s / problem.recording.dt).round() as usize).max(1);
    let before = problem.residual(&Effects::default());
    observe(Stage::Candidates);
    let (candidates, mut columns) = build_library(&problem);
    let wind_start = profile_nonlinear(&problem, &before, &candidates, &mut columns, block_rows);
    let groups: Vec<Vec<usize>> = candidates.iter().map(|c| c.columns.clone()).collect();
    let design = problem.design(&before, &columns, 0..problem.split, block_rows);
    observe(Stage::Screening);
    let selection = stability_selection(&design, &groups, &settings.selection);
    let screened = Screened {
        candidates: &candidates,
        columns: &columns,
        design: &design,
        selection: &selection,
    };
    observe(Stage::Fitting);
    let (set, alternatives) = fit_parameters(
        &problem,
        &screened,
        settings.iterations,
        block_rows,
        wind_start,
    );
    observe(Stage::Judging);
    let judgement = evidence::apply(
        &problem,
        set,
        &settings.evidence,
        settings.iterations / 2,
        block_rows,
    );
    // The model the evidence rule judged (fitted on the fit part) is the one the residuals and the
    // held-out check describe; the parameters reported are estimated again on all rows.
    let after = problem.residual(&judgement.set.effects());
    observe(Stage::Estimating);
    let estimate = estimate::estimate(
        &problem,
        &judgement.set,
        &settings.estimate,
        settings.iterations,
    );
    let effects = estimate.set.effects();
    let report = build_report(
        &problem,
        log,
        model_name,
        settings,
        Residuals {
            before: &before,
            after: &after,
        },
        Named {
            judgement: &judgement,
            estimate: &estimate,
        },
        Screen {
            candidates: &candidates,
            selection: &selection,
            alternatives,
        },
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

/// `residual` (all rows) without its components along the test functions' values at the command
/// steps the samples cannot place: a step misplaced within its interval is not a missing effect.
fn without_steps(problem: &Problem, residual: &[Channels], step_times: &[f64]) -> Vec<Channels> {
    let mut remaining = residual.to_vec();
    StepBasis::new(problem, &FitRows::plain(0..problem.rows()), step_times)
        .remove_from(&mut remaining);
    remaining
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

/// The variance of a series about its mean (0 for fewer than two values).
fn variance(values: impl Iterator<Item = f64>) -> f64 {
    let values: Vec<f64> = values.collect();
    if values.len() < 2 {
        return 0.0;
    }
    let mean = values.iter().sum::<f64>() / values.len() as f64;
    values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / values.len() as f64
}

/// The nominal and the fitted model's residuals.
struct Residuals<'a> {
    before: &'a [Channels],
    after: &'a [Channels],
}

/// The effects named: as the evidence rule judged them (fit part) and as finally estimated.
struct Named<'a> {
    judgement: &'a evidence::Judgement,
    estimate: &'a Estimate,
}

/// What the screen and the fit stage chose and tried.
struct Screen<'a> {
    candidates: &'a [Candidate],
    selection: &'a Selection,
    alternatives: FitAlternatives,
}

fn channel_reports(
    problem: &Problem,
    settings: &AnalysisSettings,
    residuals: &Residuals,
) -> Vec<ChannelReport> {
    let heldout_rows = problem.split..problem.rows();
    let channel_mse = |residual: &[Channels], c: usize| {
        residual[heldout_rows.clone()]
            .iter()
            .map(|r| r[c] * r[c])
            .sum::<f64>()
            / heldout_rows.len().max(1) as f64
    };
    let fit_rows = 0..problem.split;
    (0..problem.channels)
        .map(|c| {
            let floor = problem.noise_floor[c];
            let nominal = fit_rows
                .clone()
                .map(|row| problem.target[row][c] - residuals.before[row][c]);
            let signal_variance = variance(nominal);
            let model_noise_share = if signal_variance > 0.0 {
                problem.model_noise[c].powi(2) / signal_variance
            } else {
                0.0
            };
            let residual_rms = rms(residuals.before.iter().map(|r| r[c]));
            let residual_rms_after = rms(residuals.after.iter().map(|r| r[c]));
            ChannelReport {
                name: CHANNEL_NAMES[c].to_string(),
                residual_rms,
                noise_floor: floor,
                noise_floor_model_side: problem.model_noise[c],
                model_noise_share,
                significant: residual_rms > settings.significance_factor * floor,
                residual_rms_after,
                significant_after: residual_rms_after > settings.significance_factor * floor,
                heldout_mse_before: channel_mse(residuals.before, c),
                heldout_mse_after: channel_mse(residuals.after, c),
            }
        })
        .collect()
}

fn build_report(
    problem: &Problem,
    log: &FlightLog,
    model_name: &str,
    settings: &AnalysisSettings,
    residuals: Residuals,
    named: Named,
    screen: Screen,
) -> Report {
    let Named {
        judgement,
        estimate,
    } = named;
    let fit_rows = 0..problem.split;
    let heldout_rows = problem.split..problem.rows();
    let effects = estimate.set.effects();
    let fit_part = judgement.set.effects();
    let nominal_sse = problem.whitened_sse(residuals.before, fit_rows.clone());
    let fitted_sse = problem.whitened_sse(residuals.after, fit_rows.clone());
    let shares = explained_fractions(&judgement.evidence, nominal_sse, fitted_sse);
    let errors = effects_from(&estimate.set.parameters, &estimate.standard_errors);
    let biases = estimate
        .noise_bias
        .as_ref()
        .map(|b| effects_from(&estimate.set.parameters, &b.bias));
    let effect_reports = judgement
        .evidence
        .iter()
        .zip(shares)
        .map(|(evidence, share)| EffectReport {
            id: evidence.id,
            parameters: effects
                .parameters(evidence.id)
                .expect("a named effect is in the fitted set"),
            standard_errors: errors.parameters(evidence.id).and_then(|p| {
                let values = p.values();
                let finite = values
                    .iter()
                    .all(|(_, v)| v.numbers().iter().all(|x| x.is_finite()));
                finite.then(|| values.into_iter().collect())
            }),
            fit_part_parameters: fit_part
                .parameters(evidence.id)
                .expect("a named effect is in the judged set"),
            noise_bias: biases.as_ref().and_then(|b| b.parameters(evidence.id)),
            description: describe(evidence.id, &effects, problem.model.gravity_m_s2),
            explained_fraction: share,
            evidence: evidence.clone(),
        })
        .collect();
    let t = |row: usize| problem.time[row.min(problem.rows() - 1)];
    let form = &problem.weak_form;
    Report {
        recording: log.path.display().to_string(),
        model: model_name.to_string(),
        channels: channel_reports(problem, settings, &residuals),
        windows: locate_windows(problem, residuals.before, settings),
        effects: effect_reports,
        unexplained: locate_windows(
            problem,
            &without_steps(problem, residuals.after, &estimate.step_times),
            settings,
        ),
        fit: Fit {
            before: Mse { mse: problem.mse(residuals.before, fit_rows.clone()) },
            after: Mse { mse: problem.mse(residuals.after, fit_rows.clone()) },
            heldout: Heldout {
                before: Mse { mse: problem.mse(residuals.before, heldout_rows.clone()) },
                after: Mse { mse: problem.mse(residuals.after, heldout_rows.clone()) },
                t_start: t(heldout_rows.start),
                t_end: t(heldout_rows.end - 1),
            },
            comparison: format!(
                "weak form: the recorded velocity and body rate against the model's acceleration, both weighted by the test function (1 - s^2)^{} over ±{} s ({} rows each side), so a right model leaves only noise",
                form.function.power, form.function.half_width_s, form.half
            ),
            t_start: t(0),
            t_end: t(fit_rows.end - 1),
        },
        estimate_downweighted_fraction: estimate.downweighted_fraction,
        estimate_step_times: estimate.step_times.clone(),
        estimate_termination: estimate.termination,
        estimate_noise_bias: estimate.noise_bias.as_ref().map(|b| b.sources),
        command_limits: (problem.recording.samples.rows_held() > 0)
            .then_some(problem.recording.command_limits),
        rate_frame: RateFrameReport {
            used: match problem.recording.rate_frame {
                data::RateFrame::Body => RateFrame::Body,
                data::RateFrame::World => RateFrame::World,
            },
            body_rms: problem.recording.rate_frame_errors.0,
            world_rms: problem.recording.rate_frame_errors.1,
        },
        logger: problem.model.logger,
        noise_reaction: problem.recording.noise_reaction.clone(),
        selection: SelectionReport {
            method: "forward stepwise selection of candidate groups scored by time-blocked cross-validation on the noise-normalised residual, kept when chosen in enough block-bootstrap resamples (stability selection); the kept effects fitted jointly with the exact model; each then kept only when the evidence rule holds for it".to_string(),
            settings: settings.selection,
            candidates: screen
                .candidates
                .iter()
                .enumerate()
                .map(|(g, candidate)| CandidateReport {
                    candidate: candidate.clone(),
                    selection_frequency: screen.selection.frequencies[g],
                    chosen_on_data: screen.selection.chosen_on_data.contains(&g),
                    kept: screen.selection.kept.contains(&g),
                })
                .collect(),
            alternatives: screen.alternatives,
            dropped: judgement.dropped.clone(),
        },
        settings: *settings,
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
