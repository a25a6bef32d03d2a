//! The files of an analysis, rendered: `mismatch.json`, `mismatch.svg` (residual per channel
//! before and after, located windows shaded) and `mismatch.md` (plain words). The text and the
//! figure are rendered by the `report` crate ([`report::mismatch::recording`]) from the views this
//! module fills ([`Analysis::view`], [`Analysis::figure`]); the caller writes them (the `learn`
//! binary, into an output set).

use std::path::Path;

use physics::CommandLogging;
use report::mismatch::recording::{
    BelowResolutionLine, CandidateLine, CommandSampling, EstimateLine, EvidenceLine, EvidenceRule,
    Inseparable, LogContentView, NamedEffect, NoiseBiasLine, RecordingView, ResidualFigure,
    StandInLine, TermLine,
};

use crate::analysis::{Analysis, check_finite};
use crate::error::Result;
use crate::explain::confounds::StandIn;
use crate::explain::evidence::Evidence;
use crate::locate::problem::CHANNEL_NAMES;
use crate::recording::content::{LogContent, Signal};
use crate::recording::noise_reaction;

/// The names of an analysis's files in its folder, in the order of [`Analysis::render`].
pub const ANALYSIS_FILES: [&str; 3] = ["mismatch.json", "mismatch.svg", "mismatch.md"];

impl Analysis {
    /// The contents of the files [`ANALYSIS_FILES`] names, to be written in `dir` (which the
    /// figure's errors name). Fails, with nothing to write, unless every number of the analysis
    /// is finite and the figure can be drawn.
    pub fn render(&self, dir: &Path) -> Result<[String; 3]> {
        check_finite(self)?;
        let json = serde_json::to_string_pretty(&self.report).expect("the report serialises");
        let svg = self.figure_svg(&dir.join(ANALYSIS_FILES[1]))?;
        Ok([json + "\n", svg, self.view().markdown()])
    }

    /// The figure (one panel per channel), named `path` in errors. Fails unless the data are
    /// finite and every axis spans a drawable range (finite ends, a normal positive span).
    pub fn figure_svg(&self, path: &Path) -> Result<String> {
        Ok(self.figure().svg(path)?)
    }
}

/// The evidence for one effect as the report prints it.
fn evidence_line(evidence: &Evidence) -> EvidenceLine<'static> {
    EvidenceLine {
        id: evidence.id.name(),
        likelihood_ratio: evidence.likelihood_ratio,
        likelihood_ratio_threshold: evidence.likelihood_ratio_threshold,
        fit_gain: evidence.fit_gain,
        trimmed_gain: evidence.trimmed_gain,
        heldout_without: evidence.heldout_without,
        heldout_with: evidence.heldout_with,
        heldout_reduction: evidence.heldout_reduction,
    }
}

/// A stand-in as the report prints it.
fn stand_in_line(stand_in: &StandIn) -> StandInLine<'static> {
    let parameters = stand_in
        .parameters
        .values()
        .into_iter()
        .map(|(name, value)| {
            let numbers: Vec<String> = value.numbers().iter().map(|v| format!("{v:.3}")).collect();
            match numbers.as_slice() {
                [one] => format!("{name} = {one}"),
                many => format!("{name} = [{}]", many.join(", ")),
            }
        })
        .collect::<Vec<_>>()
        .join(", ");
    StandInLine {
        id: stand_in.id.name(),
        parameters,
        likelihood_ratio: stand_in.likelihood_ratio,
        likelihood_ratio_threshold: stand_in.likelihood_ratio_threshold,
        heldout_increase: stand_in.heldout_increase,
        explains_as_well: stand_in.explains_as_well,
        explains_better: stand_in.explains_better,
    }
}

/// What the log holds as the report prints it.
fn log_content_view(content: &LogContent) -> LogContentView<'static> {
    use data::ulog::ColumnPattern;
    LogContentView {
        row_rate_hz: content.row_rate_hz,
        signals: content
            .signals
            .iter()
            .map(|s| {
                let pattern = match s.pattern {
                    ColumnPattern::Fresh => "fresh",
                    ColumnPattern::Held => "held",
                    ColumnPattern::Interpolated => "interpolated",
                    ColumnPattern::Constant => "constant",
                };
                (s.signal.name(), pattern, s.effective_rate_hz)
            })
            .collect(),
        timing_limit_s: content.timing_limit_s,
    }
}

impl Analysis {
    /// What `mismatch.md` says: the report's plain parts borrowed, its effects, evidence and
    /// candidates by their names.
    pub fn view(&self) -> RecordingView<'_> {
        let report = &self.report;
        let settings = &report.settings;
        RecordingView {
            recording: &report.recording,
            model: &report.model,
            rate_frame: &report.rate_frame,
            time_stamps: report.time_stamps.as_ref(),
            log_content: report.log_content.as_ref().map(log_content_view),
            position_logged: !report.not_logged.contains(&Signal::Position),
            below_resolution: report
                .selection
                .below_resolution
                .iter()
                .map(|b| BelowResolutionLine {
                    id: b.id.name(),
                    value_s: b.value_s,
                    limit_s: b.limit_s,
                })
                .collect(),
            channels: &report.channels,
            translational_only: self.problem.channels == 3,
            angular_left_out: self.problem.model.compared_channels
                == physics::ComparedChannels::Translational
                && report.uninformative_torques.is_none(),
            uninformative_torques: report
                .uninformative_torques
                .map(|r| (r.response, r.standard_error)),
            window_factor: settings.analysis.locate.window_factor,
            windows: &report.windows,
            rule: EvidenceRule {
                significance: settings.analysis.evidence.significance,
                min_gain: settings.analysis.evidence.min_gain,
                min_trimmed_gain: settings.analysis.evidence.min_trimmed_gain,
                min_heldout_reduction: settings.analysis.evidence.min_heldout_reduction,
                block_s: settings.analysis.block_s,
            },
            effects: report
                .effects
                .iter()
                .map(|e| NamedEffect {
                    evidence: evidence_line(&e.evidence),
                    description: &e.description,
                    standard_errors: e
                        .standard_errors
                        .iter()
                        .flatten()
                        .map(|(name, value)| (*name, value.numbers()))
                        .collect(),
                    weight_spans: e
                        .weight_spans
                        .iter()
                        .flatten()
                        .map(|(name, spans)| {
                            (*name, spans.iter().map(|s| [s.start_s, s.end_s]).collect())
                        })
                        .collect(),
                    explained_fraction: e.explained_fraction,
                })
                .collect(),
            not_separable: report
                .not_separable
                .iter()
                .map(|n| Inseparable {
                    id: n.effect.id.name(),
                    description: &n.effect.description,
                    stand_ins: n.stand_ins.iter().map(stand_in_line).collect(),
                })
                .collect(),
            replaced: report
                .selection
                .replaced
                .iter()
                .map(|w| Inseparable {
                    id: w.id.name(),
                    description: "",
                    stand_ins: w.stand_ins.iter().map(stand_in_line).collect(),
                })
                .collect(),
            dropped: report.selection.dropped.iter().map(evidence_line).collect(),
            unexplained: &report.unexplained,
            resamples: report.selection.settings.resamples,
            candidates: report
                .selection
                .candidates
                .iter()
                .map(|c| CandidateLine {
                    id: c.candidate.id.name(),
                    terms: c
                        .candidate
                        .terms
                        .iter()
                        .map(|t| TermLine {
                            name: &t.name,
                            formula: &t.formula,
                            units: &t.units,
                        })
                        .collect(),
                    selection_frequency: c.selection_frequency,
                    kept: c.kept,
                })
                .collect(),
            timing: report.selection.alternatives.timing.as_ref(),
            fit: &report.fit,
            command_sampling: self.command_sampling(),
            rows_at_limit: self.problem.recording.samples.rows_held(),
            estimate: EstimateLine {
                huber_threshold: settings.analysis.estimate.huber_threshold,
                downweighted_fraction: report.estimate_downweighted_fraction,
                steps: report.estimate_step_times.len(),
                noise_bias: report.estimate_noise_bias.map(|sources| NoiseBiasLine {
                    pairs: settings.analysis.estimate.noise_bias.pairs,
                    seed: settings.analysis.estimate.noise_bias.seed,
                    rate: sources.rate,
                    attitude_estimate: sources.attitude_estimate,
                    command_samples: sources.command_samples,
                }),
            },
        }
    }

    /// How the commands were logged, from the model's logger (samples of a controller at least
    /// twice as fast as the log count as a faster controller's).
    fn command_sampling(&self) -> CommandSampling {
        let logger = &self.problem.model.logger;
        let steps_per_row = logger
            .controller_rate_hz
            .map(|rate| rate * self.problem.recording.dt());
        match (logger.command, steps_per_row) {
            (CommandLogging::Sample, None) => CommandSampling::RateUnknown,
            (CommandLogging::Sample, Some(steps_per_row))
                if steps_per_row >= noise_reaction::MIN_STEPS_PER_ROW =>
            {
                let removed = match &self.problem.recording.noise_reaction {
                    Some(reaction) if reaction.velocity => "attitude, position and velocity",
                    Some(_) => "attitude and position",
                    None => "",
                };
                CommandSampling::FasterController {
                    steps_per_row,
                    removed,
                }
            }
            _ => CommandSampling::NotSampled,
        }
    }

    /// What `mismatch.svg` draws: the residuals before and after, the windows, the held-out split.
    pub fn figure(&self) -> ResidualFigure<'_> {
        ResidualFigure {
            time: &self.problem.time,
            before: &self.before,
            after: &self.after,
            channels: self.problem.channels,
            names: &CHANNEL_NAMES,
            split: self.problem.split,
            windows: &self.report.windows,
        }
    }
}
