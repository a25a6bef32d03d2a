//! What `mismatch.json` holds ([`Report`]) and how an analysis's stages fill it ([`build_report`]).

use std::collections::BTreeMap;

use data::FlightLog;
use physics::{EffectId, EffectParameters, Logger, ParameterValue};
use report::mismatch::recording::{
    ChannelReport, Fit, Heldout, Mse, RateFrame, RateFrameReport, StampedTiming, Window,
};
use serde::Serialize;
use sindy::stability::{Selection, SelectionSettings};

use crate::explain::confounds::{Confound, Separation, StandIn};
use crate::explain::describe::describe;
use crate::explain::evidence::{Evidence, explained_fractions};
use crate::explain::fit::{BelowResolution, FitAlternatives};
use crate::explain::library::Candidate;
use crate::improve::estimate::Estimate;
use crate::improve::simex::NoiseSources;
use crate::locate::problem::Problem;
use crate::locate::response::AngularResponse;
use crate::locate::windows::{Residuals, channel_reports, locate_windows, without_steps};
use crate::model::least_squares::Termination;
use crate::model::refine::effects_from;
use crate::model::weight::WeightSpan;
use crate::recording::command_samples::ActuatorLimits;
use crate::recording::content::{LogContent, Signal};
use crate::recording::noise_reaction::NoiseReaction;
use crate::settings::{AnalysisRecord, CheckedSettings};

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
    /// Per parameter (and component), the shortest stretch of the recording whose rows hold half
    /// of the estimate's weight ([`crate::model::weight`]); absent where the fit does not
    /// determine it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub weight_spans: Option<BTreeMap<&'static str, Vec<WeightSpan>>>,
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
    pub command_limits: Option<Vec<ActuatorLimits>>,
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
    /// Signals the log does not hold (the position, which a layout may leave out).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub not_logged: Vec<Signal>,
    /// How the recording's commands and rates were logged (from the model file).
    pub logger: Logger,
    /// What was taken out of sampled commands of a faster controller: their unfelt reaction to the
    /// logged noise (absent when nothing was).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub noise_reaction: Option<NoiseReaction>,
    pub selection: SelectionReport,
    pub settings: AnalysisRecord,
}

/// The effects named: as the evidence rule judged them (fit part) and as finally estimated.
pub(super) struct Named<'a> {
    pub(super) separation: &'a Separation,
    pub(super) estimate: &'a Estimate,
}

/// What the screen and the fit stage chose and tried.
pub(super) struct Screen<'a> {
    pub(super) candidates: &'a [Candidate],
    pub(super) selection: &'a Selection,
    pub(super) alternatives: FitAlternatives,
    pub(super) below_resolution: Vec<BelowResolution>,
    /// What the log holds, which bounds what the fit may name.
    pub(super) log_content: Option<LogContent>,
    /// The angular channels' response, when it left them out.
    pub(super) uninformative_torques: Option<AngularResponse>,
}

pub(super) fn build_report(
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
    let spans = weight_spans(estimate);
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
            weight_spans: spans(evidence.id),
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
        command_limits: (problem.recording.samples.rows_held() > 0).then(|| {
            problem.recording.command_limits[..problem.model.actuator_count()].to_vec()
        }),
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
        not_logged: if problem.recording.position_logged {
            Vec::new()
        } else {
            vec![Signal::Position]
        },
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

/// Each named effect's weight spans by parameter name, in the parameters' shape (`None` unless
/// every component has one).
fn weight_spans(
    estimate: &Estimate,
) -> impl Fn(EffectId) -> Option<BTreeMap<&'static str, Vec<WeightSpan>>> {
    // One end of every parameter's span, NaN where it has none.
    let each = |pick: fn(&WeightSpan) -> f64| -> Vec<f64> {
        estimate
            .weight_spans
            .iter()
            .map(|s| s.as_ref().map_or(f64::NAN, pick))
            .collect()
    };
    let starts = effects_from(&estimate.set.parameters, &each(|s| s.start_s));
    let ends = effects_from(&estimate.set.parameters, &each(|s| s.end_s));
    move |id| {
        let (starts, ends) = (starts.parameters(id)?, ends.parameters(id)?);
        starts
            .values()
            .into_iter()
            .zip(ends.values())
            .map(|((name, start), (_, end))| {
                let spans: Vec<WeightSpan> = start
                    .numbers()
                    .iter()
                    .zip(end.numbers())
                    .map(|(&start_s, end_s)| WeightSpan { start_s, end_s })
                    .collect();
                let finite = spans
                    .iter()
                    .all(|s| s.start_s.is_finite() && s.end_s.is_finite());
                finite.then_some((name, spans))
            })
            .collect()
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
