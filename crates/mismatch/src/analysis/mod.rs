//! The whole analysis of one recording: compare, locate, explain, fit, judge the evidence, validate
//! on held-out data; its files ([`files`]).

pub(crate) mod files;

use std::collections::BTreeMap;

use data::FlightLog;
use physics::vector::Vec3;
use physics::{EffectId, EffectParameters, Effects, Logger, NominalModel, ParameterValue};
pub use report::mismatch::recording::{
    ChannelReport, Fit, Heldout, Mse, RateFrame, RateFrameReport, StampedTiming, Window,
};
use serde::Serialize;
use sindy::stability::{Selection, SelectionSettings, stability_selection};

use crate::error::{MismatchError, Result};
use crate::explain::confounds::{self, Confound, Separate, Separation, StandIn};
use crate::explain::describe::describe;
use crate::explain::evidence::{self, Evidence, explained_fractions};
use crate::explain::fit::{
    BelowResolution, FitAlternatives, Screened, fit_parameters, leave_out_below_resolution,
    profile_nonlinear,
};
use crate::explain::library::{Candidate, build_library};
use crate::improve::estimate::{self, Estimate};
use crate::improve::simex::NoiseSources;
use crate::locate::forward;
use crate::locate::problem::{CHANNEL_NAMES, Channels, Problem};
use crate::locate::response::{AngularResponse, angular_response};
use crate::locate::windows::{Residuals, channel_reports, locate_windows, without_steps};
use crate::model::least_squares::Termination;
use crate::model::refine::effects_from;
use crate::recording::Recording;
use crate::recording::command_samples::ActuatorLimits;
use crate::recording::content::{self, LogContent};
use crate::recording::degenerate;
use crate::recording::noise_reaction::{self, NoiseReaction};
use crate::settings::{AnalysisRecord, CheckedSettings, NoiseFree};

/// One effect found.
#[derive(Clone, Debug, Serialize)]
pub struct EffectReport {
    pub id: EffectId,
    /// The final estimate: all rows, robust weights ([`crate::improve::estimate`]).
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
    /// ([`crate::improve::simex`]); absent when the commands are not samples of a faster controller.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub noise_bias: Option<EffectParameters>,
    pub description: String,
    /// This effect's share of the nominal model's noise-normalised residual sum of squares (fit
    /// part) that the fitted effects remove, in [0, 1]; the shares sum to the total removed.
    pub explained_fraction: f64,
    /// Why it is named ([`crate::explain::evidence`]).
    pub evidence: Evidence,
}

/// A named effect that a stand-in explains as well on this recording
/// ([`crate::explain::confounds`]): kept in the fitted model, not named.
#[derive(Clone, Debug, Serialize)]
pub struct NotSeparableReport {
    #[serde(flatten)]
    pub effect: EffectReport,
    /// The effects fitted in its place, each with how much worse it explains the recording.
    pub stand_ins: Vec<StandIn>,
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
    /// Effects the evidence rule named that a stand-in replaced (a wind a vehicle effect explains
    /// as well, any effect one explains better): not named, the stand-in fitted in its place
    /// ([`crate::explain::confounds`]).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub replaced: Vec<Confound>,
    /// Every named effect that has stand-ins, tested against each of them
    /// ([`crate::explain::confounds`]).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub separation_tests: Vec<Confound>,
    /// Delays and motor lags the fit found shorter than the log resolves: left out.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub below_resolution: Vec<BelowResolution>,
}

/// Everything written to `mismatch.json`.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    pub recording: String,
    pub model: String,
    pub channels: Vec<ChannelReport>,
    /// Where the nominal model disagrees with the recording.
    pub windows: Vec<Window>,
    /// The effects named.
    pub effects: Vec<EffectReport>,
    /// Effects that explain the residual but that another effect explains as well on this
    /// recording: fitted, not named.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub not_separable: Vec<NotSeparableReport>,
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
    /// The noises whose bias the final estimate measured and removed ([`crate::improve::simex`]), when it did.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub estimate_noise_bias: Option<NoiseSources>,
    /// The limits the logged commands sat at, when any did (instantaneous samples are reconstructed
    /// through them: [`crate::recording::command_samples`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub command_limits: Option<[ActuatorLimits; 4]>,
    pub rate_frame: RateFrameReport,
    /// The time stamps, when they are not evenly spaced.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_stamps: Option<StampedTiming>,
    /// The response of the angular channels to the model's torques, when it showed they say
    /// nothing about the recording and only the translational channels were compared
    /// ([`crate::locate::response`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub uninformative_torques: Option<AngularResponse>,
    /// How often each signal brings a new value, when some signal is held or interpolated
    /// between slower updates ([`crate::recording::content`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub log_content: Option<LogContent>,
    /// How the recording's commands and rates were logged (from the model file).
    pub logger: Logger,
    /// What was taken out of sampled commands of a faster controller: their unfelt reaction to the
    /// logged noise (absent when nothing was).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub noise_reaction: Option<NoiseReaction>,
    pub selection: SelectionReport,
    pub settings: AnalysisRecord,
}

/// The report with the data behind it (for figures and summaries).
#[derive(Clone, Debug)]
pub struct Analysis {
    pub report: Report,
    pub problem: Problem,
    pub before: Vec<Channels>,
    pub after: Vec<Channels>,
    /// The fitted model: the effects named and those not separable from a stand-in.
    pub fitted: Effects,
}

impl Analysis {
    /// The fitted effects that are named (the fitted model without the effects not separable
    /// from a stand-in).
    pub fn named(&self) -> Effects {
        self.report
            .not_separable
            .iter()
            .fold(self.fitted, |named, n| named.without(n.effect.id))
    }
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
    settings: &CheckedSettings,
) -> Result<Analysis> {
    analyze_observed(log, model, model_name, settings, &|_, _| {})
}

/// [`analyze`], telling `observe` the pass (1, or 2 when the commands' reaction to the velocity
/// noise is removed) and the stage as each begins.
pub fn analyze_observed(
    log: &FlightLog,
    model: &NominalModel,
    model_name: &str,
    settings: &CheckedSettings,
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
        recording.dt() * recording.white_noise_sigma(&series)
    })
}

fn analyze_recording(
    recording: Recording,
    log: &FlightLog,
    model: &NominalModel,
    model_name: &str,
    settings: &CheckedSettings,
    observe: &dyn Fn(Stage),
) -> Result<Analysis> {
    observe(Stage::Comparing);
    let problem = Problem::new(
        recording,
        model.clone(),
        settings.comparison.test_function,
        settings.comparison.heldout_fraction,
    )?;
    let (problem, uninformative_torques) = compared_where_informative(problem, settings)?;
    if settings.analysis.noise_free == NoiseFree::Refuse {
        degenerate::check_noise(&problem).map_err(|degeneracy| MismatchError::Degenerate {
            path: problem.recording.path.clone(),
            degeneracy,
        })?;
    }
    let block_rows = ((settings.analysis.block_s / problem.recording.dt()).round() as usize).max(1);
    let before = problem.residual(&Effects::default());
    observe(Stage::Candidates);
    let (candidates, mut columns) = build_library(&problem);
    let wind_start = profile_nonlinear(&problem, &before, &candidates, &mut columns, block_rows);
    let groups: Vec<Vec<usize>> = candidates.iter().map(|c| c.columns.clone()).collect();
    let design = problem.design(&before, &columns, 0..problem.split, block_rows);
    observe(Stage::Screening);
    let selection = stability_selection(&design, &groups, &settings.analysis.selection);
    let screened = Screened {
        candidates: &candidates,
        columns: &columns,
        design: &design,
        selection: &selection,
    };
    observe(Stage::Fitting);
    let (mut set, alternatives) = fit_parameters(
        &problem,
        &screened,
        settings.analysis.iterations,
        block_rows,
        wind_start,
    );
    let log_content = content::measure(log);
    let below_resolution = match log_content.as_ref().and_then(|c| c.timing_limit_s) {
        Some(limit) => {
            leave_out_below_resolution(&problem, &mut set, limit, settings.analysis.iterations)
        }
        None => Vec::new(),
    };
    observe(Stage::Judging);
    let judgement = evidence::apply(
        &problem,
        set,
        &settings.analysis.evidence,
        settings.analysis.iterations / 2,
        block_rows,
    );
    let separation = confounds::separate(
        &problem,
        judgement,
        &Separate {
            settings: &settings.analysis.evidence,
            iterations: settings.analysis.iterations / 2,
            block_rows,
        },
    );
    let judgement = &separation.judgement;
    // The model the evidence rule judged (fitted on the fit part) is the one the residuals and the
    // held-out check describe; the parameters reported are estimated again on all rows.
    let after = problem.residual(&judgement.set.effects());
    observe(Stage::Estimating);
    let estimate = estimate::estimate(
        &problem,
        &judgement.set,
        &settings.analysis.estimate,
        settings.analysis.iterations,
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
            separation: &separation,
            estimate: &estimate,
        },
        Screen {
            candidates: &candidates,
            selection: &selection,
            alternatives,
            below_resolution,
            log_content,
            uninformative_torques,
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

/// The problem as compared: without its angular channels when the model's torques say nothing
/// about the recorded angular accelerations ([`crate::locate::response`]), with the response that
/// showed it.
fn compared_where_informative(
    problem: Problem,
    settings: &CheckedSettings,
) -> Result<(Problem, Option<AngularResponse>)> {
    match angular_response(&problem, settings.analysis.evidence.significance) {
        Some(response) if !response.informative() => {
            let model = physics::NominalModel {
                compared_channels: physics::ComparedChannels::Translational,
                ..problem.model
            };
            let translational = Problem::new(
                problem.recording,
                model,
                settings.comparison.test_function,
                settings.comparison.heldout_fraction,
            )?;
            Ok((translational, Some(response)))
        }
        _ => Ok((problem, None)),
    }
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

/// The effects named: as the evidence rule judged them (fit part) and as finally estimated.
struct Named<'a> {
    separation: &'a Separation,
    estimate: &'a Estimate,
}

/// What the screen and the fit stage chose and tried.
struct Screen<'a> {
    candidates: &'a [Candidate],
    selection: &'a Selection,
    alternatives: FitAlternatives,
    below_resolution: Vec<BelowResolution>,
    /// What the log holds, which bounds what the fit may name.
    log_content: Option<LogContent>,
    /// The angular channels' response, when it left them out.
    uninformative_torques: Option<AngularResponse>,
}

fn build_report(
    problem: &Problem,
    log: &FlightLog,
    model_name: &str,
    settings: &CheckedSettings,
    residuals: Residuals,
    named: Named,
    screen: Screen,
) -> Report {
    let Named {
        separation,
        estimate,
    } = named;
    let judgement = &separation.judgement;
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
    let mut effect_reports: Vec<EffectReport> = judgement
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
    let not_separable = separation
        .not_separable
        .iter()
        .filter_map(|confound| {
            let at = effect_reports.iter().position(|e| e.id == confound.id)?;
            Some(NotSeparableReport {
                effect: effect_reports.remove(at),
                stand_ins: confound.stand_ins.clone(),
            })
        })
        .collect();
    let t = |row: usize| problem.time[row.min(problem.rows() - 1)];
    let form = &problem.weak_form;
    Report {
        recording: log.path.display().to_string(),
        model: model_name.to_string(),
        channels: channel_reports(problem, &settings.analysis.locate, &residuals),
        windows: locate_windows(problem, residuals.before, &settings.analysis.locate),
        effects: effect_reports,
        not_separable,
        unexplained: locate_windows(
            problem,
            &without_steps(problem, residuals.after, &estimate.step_times),
            &settings.analysis.locate,
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
        time_stamps: stamped_timing(problem),
        log_content: screen.log_content,
        uninformative_torques: screen.uninformative_torques,
        logger: problem.model.logger,
        noise_reaction: problem.recording.noise_reaction.clone(),
        selection: SelectionReport {
            method: "forward stepwise selection of candidate groups scored by time-blocked cross-validation on the noise-normalised residual, kept when chosen in enough block-bootstrap resamples (stability selection); the kept effects fitted jointly with the exact model; each then kept only when the evidence rule holds for it".to_string(),
            settings: settings.analysis.selection,
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
            replaced: separation.replaced.clone(),
            separation_tests: separation.tests.clone(),
            below_resolution: screen.below_resolution,
        },
        settings: settings.analysis_record(),
    }
}

/// What the report says of a recording's time stamps when they are not evenly spaced.
fn stamped_timing(problem: &Problem) -> Option<StampedTiming> {
    use statrs::statistics::{Data, OrderStatistics};
    let sampling = &problem.recording.sampling;
    if sampling.is_uniform() {
        return None;
    }
    let median = sampling.interval();
    let ratios: Vec<f64> = (0..sampling.len() - 1)
        .map(|k| sampling.interval_at(k) / median)
        .collect();
    let longest = ratios.iter().copied().fold(0.0, f64::max) * median;
    let mut ratios = Data::new(ratios);
    let gaps = sampling.gaps().len();
    Some(StampedTiming {
        median_interval_s: median,
        interval_ratio_percentiles: [ratios.percentile(1), ratios.percentile(99)],
        gaps,
        gap_factor: sindy::sampling::GAP_FACTOR,
        longest_interval_s: longest,
        segments: gaps + 1,
        compared_rows: problem.rows(),
        rows: sampling.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

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
