//! Writing an analysis: `mismatch.json`, `mismatch.svg` (residual per channel before and after,
//! located windows shaded) and `mismatch.md` (plain words). The text and the figure are rendered by
//! the `report` crate ([`report::mismatch::recording`]) from the views this module fills
//! ([`Analysis::view`], [`Analysis::figure`]).

use std::path::{Path, PathBuf};

use physics::CommandLogging;
use report::mismatch::recording::{
    CandidateLine, CommandSampling, EstimateLine, EvidenceLine, EvidenceRule, NamedEffect,
    NoiseBiasLine, RecordingView, ResidualFigure, TermLine,
};

use crate::analysis::{Analysis, check_finite};
use crate::error::{MismatchError, Result, io_error};
use crate::evidence::Evidence;
use crate::noise_reaction;
use crate::problem::CHANNEL_NAMES;

/// The three files of an analysis in `dir`.
pub fn output_paths(dir: &Path) -> [PathBuf; 3] {
    ["mismatch.json", "mismatch.svg", "mismatch.md"].map(|name| dir.join(name))
}

/// Fails if `dir` exists but is not a directory, or if any output file exists and `force` is off.
pub fn check_outputs(dir: &Path, force: bool) -> Result<()> {
    check_directory(dir)?;
    if force {
        return Ok(());
    }
    match output_paths(dir).into_iter().find(|p| p.exists()) {
        Some(path) => Err(MismatchError::Exists { path }),
        None => Ok(()),
    }
}

/// Checks every file a run will write (each with the option that places it), before any work,
/// as named files of an output set (see the `outputs` crate, the home of these checks): none is
/// one of the run's `inputs` (what each is, its path), whatever `force` says; each can be written
/// (not a directory, not below something that is not one); none exists unless `force`.
pub fn check_run_outputs(
    outputs: &[(PathBuf, &str)],
    inputs: &[(String, PathBuf)],
    force: bool,
) -> Result<()> {
    let mut set = outputs::OutputSet::new("mismatch");
    for (what, path) in inputs {
        set.input(what.clone(), path);
    }
    for (path, option) in outputs {
        set.file(path, option, outputs::Existing::from_force(force));
    }
    Ok(set.check()?)
}

/// Fails if `dir` exists but is not a directory (checked before any work that would write there).
pub fn check_directory(dir: &Path) -> Result<()> {
    if dir.exists() && !dir.is_dir() {
        return Err(MismatchError::Io {
            path: dir.to_path_buf(),
            source: std::io::Error::new(
                std::io::ErrorKind::NotADirectory,
                "exists and is not a directory",
            ),
        });
    }
    Ok(())
}

/// Writes the three files; fails before writing any of them unless every number of the analysis is
/// finite.
pub fn write_outputs(analysis: &Analysis, dir: &Path, force: bool) -> Result<()> {
    check_outputs(dir, force)?;
    check_finite(analysis)?;
    std::fs::create_dir_all(dir).map_err(io_error(dir))?;
    let [json, svg, markdown] = output_paths(dir);
    let text = serde_json::to_string_pretty(&analysis.report).expect("the report serialises");
    std::fs::write(&json, text + "\n").map_err(io_error(&json))?;
    write_figure(analysis, &svg)?;
    std::fs::write(&markdown, analysis.view().markdown()).map_err(io_error(&markdown))?;
    Ok(())
}

/// Writes the figure (one panel per channel). Fails, without writing, unless the data are finite
/// and every axis spans a drawable range (finite ends, a normal positive span).
pub fn write_figure(analysis: &Analysis, path: &Path) -> Result<()> {
    let svg = analysis.figure().svg(path)?;
    std::fs::write(path, svg).map_err(io_error(path))
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
            channels: &report.channels,
            translational_only: self.problem.channels == 3,
            window_factor: settings.window_factor,
            windows: &report.windows,
            rule: EvidenceRule {
                significance: settings.evidence.significance,
                min_gain: settings.evidence.min_gain,
                min_trimmed_gain: settings.evidence.min_trimmed_gain,
                min_heldout_reduction: settings.evidence.min_heldout_reduction,
                block_s: settings.block_s,
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
                    explained_fraction: e.explained_fraction,
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
                huber_threshold: settings.estimate.huber_threshold,
                downweighted_fraction: report.estimate_downweighted_fraction,
                steps: report.estimate_step_times.len(),
                noise_bias: report.estimate_noise_bias.map(|sources| NoiseBiasLine {
                    pairs: settings.estimate.noise_bias.pairs,
                    seed: settings.estimate.noise_bias.seed,
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
            .map(|rate| rate * self.problem.recording.dt);
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
