//! One recording against a nominal model (`mismatch.md`, and its figure [`ResidualFigure`]): the
//! plain parts of the analysis's results (channels, windows, the fit's errors, the rate frame),
//! which `mismatch.json` records as they are, and [`RecordingView`], what the Markdown says of the
//! rest (effects, evidence, candidates) with names and numbers in place of the analysis's types.

use std::fmt::Write as _;

use serde::{Deserialize, Serialize};

pub use super::residual_figure::ResidualFigure;

/// One analysed channel.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ChannelReport {
    pub name: String,
    /// RMS of the nominal model's residual over all analysed rows.
    pub residual_rms: f64,
    pub noise_floor: f64,
    /// The part of the noise floor on the model's side (noise in the commands and attitude it
    /// reads; the rest is the recorded velocity's or rate's own noise).
    pub noise_floor_model_side: f64,
    /// The model side's noise variance as a share of the variance of the nominal model's value on
    /// the fit part: the gain a factor fits through this channel (a thrust scale's `k`, an inertia
    /// scale's `1/k`) comes out smaller by up to about this share (errors in variables).
    pub model_noise_share: f64,
    /// Whether the nominal model's residual exceeds the noise floor significantly.
    pub significant: bool,
    /// RMS of the fitted model's residual.
    pub residual_rms_after: f64,
    /// Whether a significant residual remains with the effects found.
    pub significant_after: bool,
    pub heldout_mse_before: f64,
    pub heldout_mse_after: f64,
}

/// A stretch of time where one channel disagrees significantly.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Window {
    pub channel: String,
    pub t_start: f64,
    pub t_end: f64,
}

/// A mean squared error.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Mse {
    pub mse: f64,
}

/// The errors on the held-out part and where it lies.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Heldout {
    pub before: Mse,
    pub after: Mse,
    pub t_start: f64,
    pub t_end: f64,
}

/// Mean squared residuals (all analysed channels, raw units) before and after.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Fit {
    pub before: Mse,
    pub after: Mse,
    pub heldout: Heldout,
    /// What the MSEs are computed on.
    pub comparison: String,
    pub t_start: f64,
    pub t_end: f64,
}

/// The frame in which a recording's angular rate was read: `data`'s `RateFrame` as the report
/// names it (the report depends on no crate that reads or computes).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RateFrame {
    Body,
    World,
}

/// The frame the recording's body rates were read in, and how well each frame matches the rate
/// implied by the recorded attitude (RMS, rad/s).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RateFrameReport {
    pub used: RateFrame,
    pub body_rms: f64,
    pub world_rms: f64,
}

/// The time stamps of a recording that is not evenly spaced: every operator of the comparison
/// then works on the samples' own times, and no window spans a gap.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StampedTiming {
    /// The median sample interval, s.
    pub median_interval_s: f64,
    /// The 1st and 99th percentiles of each interval divided by the median one.
    pub interval_ratio_percentiles: [f64; 2],
    /// Intervals longer than `gap_factor` median intervals, which split the recording.
    pub gaps: usize,
    pub gap_factor: f64,
    pub longest_interval_s: f64,
    /// Stretches between gaps.
    pub segments: usize,
    /// Rows with a whole window of the comparison between gaps, at which it is made.
    pub compared_rows: usize,
    pub rows: usize,
}

/// What a recording holds when some signal is held or interpolated between slower updates.
#[derive(Clone, Debug, PartialEq)]
pub struct LogContentView<'a> {
    /// Rows per second over the log (the mean rate), Hz.
    pub row_rate_hz: f64,
    /// Each signal's name, how its rows relate (`held`, `interpolated`, `fresh`, `constant`) and
    /// its new values per second.
    pub signals: Vec<(&'a str, &'a str, f64)>,
    /// The shortest delay or motor lag the log resolves, s (when the commands are slower than
    /// the rows).
    pub timing_limit_s: Option<f64>,
}

/// A delay or motor lag fitted shorter than the log resolves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BelowResolutionLine<'a> {
    pub id: &'a str,
    pub value_s: f64,
    pub limit_s: f64,
}

/// The thresholds an effect passes to be named.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EvidenceRule {
    /// The χ² quantile the likelihood ratio must exceed.
    pub significance: f64,
    /// Least gain per row and channel on the fit part, in noise-floor units.
    pub min_gain: f64,
    /// Least gain over the fit and held-out blocks once the two that gain most are left out.
    pub min_trimmed_gain: f64,
    /// Least fractional reduction of the held-out residual.
    pub min_heldout_reduction: f64,
    /// Length of the blocks, s.
    pub block_s: f64,
}

/// The evidence for one effect: named, or dropped by the rule.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EvidenceLine<'a> {
    /// The effect's id as the outputs spell it (`linear_drag`).
    pub id: &'a str,
    pub likelihood_ratio: f64,
    pub likelihood_ratio_threshold: f64,
    pub fit_gain: f64,
    pub trimmed_gain: f64,
    /// Held-out noise-normalised sums of squares without and with the effect.
    pub heldout_without: f64,
    pub heldout_with: f64,
    pub heldout_reduction: f64,
}

/// One effect found: its evidence, in words, and its share of the residual removed.
#[derive(Clone, Debug, PartialEq)]
pub struct NamedEffect<'a> {
    pub evidence: EvidenceLine<'a>,
    pub description: &'a str,
    /// Each parameter's name and standard errors (empty when the fit does not determine them).
    pub standard_errors: Vec<(&'a str, Vec<f64>)>,
    /// Each parameter's name and, per component, the stretch (s) whose rows hold half of the
    /// estimate's weight (empty when the fit does not determine them).
    pub weight_spans: Vec<(&'a str, Vec<[f64; 2]>)>,
    pub explained_fraction: f64,
}

/// An effect that other effects of the vocabulary explain as well on this recording (the
/// separation test of each named effect against its stand-ins).
#[derive(Clone, Debug, PartialEq)]
pub struct Inseparable<'a> {
    /// The effect's id as the outputs spell it.
    pub id: &'a str,
    /// Its sentence with its fitted values.
    pub description: &'a str,
    pub stand_ins: Vec<StandInLine<'a>>,
}

/// One effect fitted in place of another, and how much worse it explains the recording.
#[derive(Clone, Debug, PartialEq)]
pub struct StandInLine<'a> {
    pub id: &'a str,
    /// Its fitted parameters (`tau_s = 0.031`).
    pub parameters: String,
    pub likelihood_ratio: f64,
    pub likelihood_ratio_threshold: f64,
    /// `1 − SSE(named) / SSE(stand-in)` on the held-out part.
    pub heldout_increase: f64,
    pub explains_as_well: bool,
    pub explains_better: bool,
}

impl StandInLine<'_> {
    /// `motor_lag (tau_s = 0.031): fit-part likelihood ratio 3.2 against 10.8, held-out residual 2% higher`:
    /// the stand-in's held-out residual against the named set's, `SSE(stand-in) / SSE(named) − 1`.
    fn text(&self) -> String {
        let change = self.heldout_increase / (1.0 - self.heldout_increase);
        format!(
            "{} ({}): fit-part likelihood ratio {:.1} against {:.1}, held-out residual {:.0}% {}",
            self.id,
            self.parameters,
            self.likelihood_ratio,
            self.likelihood_ratio_threshold,
            100.0 * change.abs(),
            if change >= 0.0 { "higher" } else { "lower" }
        )
    }
}

/// `[0.00, -0.12, 0.85]`: values to two decimals.
fn fixed_list(values: &[f64]) -> String {
    let texts: Vec<String> = values.iter().map(|v| format!("{v:.2}")).collect();
    format!("[{}]", texts.join(", "))
}

/// `name ± error` for each parameter, the errors to two significant digits: `k ± [0.0061, 0.016]`.
fn standard_errors_text(errors: &[(&str, Vec<f64>)]) -> String {
    errors
        .iter()
        .map(|(name, values)| format!("{name} ± {}", super::two_digit_list(values)))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Where each parameter's estimate rests: `k: 30.0–37.7 s, 36.2–37.7 s; d: 0.2–20.1 s`.
fn weight_spans_text(spans: &[(&str, Vec<[f64; 2]>)]) -> String {
    spans
        .iter()
        .map(|(name, spans)| {
            let stretches: Vec<String> = spans
                .iter()
                .map(|[start, end]| format!("{start:.1}–{end:.1} s"))
                .collect();
            format!("{name}: {}", stretches.join(", "))
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// One term of a candidate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TermLine<'a> {
    pub name: &'a str,
    pub formula: &'a str,
    pub units: &'a str,
}

/// One candidate of the library and how often the selection chose it.
#[derive(Clone, Debug, PartialEq)]
pub struct CandidateLine<'a> {
    /// The candidate's id (an effect's, or `delay_or_motor_lag`).
    pub id: &'a str,
    pub terms: Vec<TermLine<'a>>,
    pub selection_frequency: f64,
    pub kept: bool,
}

/// Noise-normalised fit errors of the three explanations of a timing term (serialised in this order).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct TimingScores {
    /// A delay and a motor lag together.
    pub both: f64,
    pub delay: f64,
    pub motor_lag: f64,
}

/// What `mismatch.md` says about one analysis.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordingView<'a> {
    pub recording: &'a str,
    pub model: &'a str,
    pub rate_frame: &'a RateFrameReport,
    /// When the recording is not evenly spaced, its time stamps.
    pub time_stamps: Option<&'a StampedTiming>,
    /// What the log holds, when some signal is slower than the rows.
    pub log_content: Option<LogContentView<'a>>,
    /// Whether the log holds the position (without it the ground effect is not looked for).
    pub position_logged: bool,
    /// Delays and motor lags fitted shorter than the log resolves (left out).
    pub below_resolution: Vec<BelowResolutionLine<'a>>,
    pub channels: &'a [ChannelReport],
    /// Only the translational channels were compared (the model predicts no torques).
    pub translational_only: bool,
    /// The model has a mixer, but its angular channels were left out by choice
    /// (`compared_channels`).
    pub angular_left_out: bool,
    /// The response (and its standard error) of each angular channel to the model's torques, when
    /// it showed they say nothing about the recording and the angular channels were left out.
    pub uninformative_torques: Option<([f64; 3], [f64; 3])>,
    /// A window is located where the moving RMS exceeds this multiple of the noise floor.
    pub window_factor: f64,
    /// Where the nominal model disagrees with the recording.
    pub windows: &'a [Window],
    pub rule: EvidenceRule,
    pub effects: Vec<NamedEffect<'a>>,
    /// Effects that passed the evidence rule but that a stand-in explains as well: fitted, not
    /// named.
    pub not_separable: Vec<Inseparable<'a>>,
    /// Effects that passed the evidence rule but that a stand-in replaced: a wind a vehicle effect
    /// explains as well, any effect one explains better.
    pub replaced: Vec<Inseparable<'a>>,
    /// The effects the evidence rule dropped.
    pub dropped: Vec<EvidenceLine<'a>>,
    /// Where a significant residual remains with the effects found.
    pub unexplained: &'a [Window],
    /// The number of bootstrap resamples of the selection.
    pub resamples: usize,
    pub candidates: Vec<CandidateLine<'a>>,
    /// Noise-normalised fit errors of the timing explanations, when the timing term was kept.
    pub timing: Option<&'a TimingScores>,
    pub fit: &'a Fit,
    /// How the commands were logged, as far as it bears on the model side's noise.
    pub command_sampling: CommandSampling,
    /// Rows whose instantaneous command sample sits at an actuator limit.
    pub rows_at_limit: usize,
    /// The final estimate's Huber threshold (robust standard deviations) and the share of the
    /// residuals it downweighted.
    pub estimate: EstimateLine,
}

/// How the reported parameters were estimated after the evidence rule.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EstimateLine {
    pub huber_threshold: f64,
    pub downweighted_fraction: f64,
    /// Command steps between samples whose time within their interval was left free.
    pub steps: usize,
    /// When the bias the noise on the model's inputs leaves was removed: how it was measured.
    pub noise_bias: Option<NoiseBiasLine>,
}

/// How the noise bias was measured (SIMEX): the pairs of draws, their seed and what was added.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NoiseBiasLine {
    pub pairs: usize,
    pub seed: u64,
    /// The logged rate's noise with its unfelt reaction to the commands.
    pub rate: bool,
    /// The error of the attitude noise's estimate, through the unfelt reaction removed with it.
    pub attitude_estimate: bool,
    /// The command samples' unfelt white noise.
    pub command_samples: bool,
}

/// Whether each row's command is an instantaneous sample, and of how fast a controller.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CommandSampling {
    /// Held from row to row or averaged over the period: what the vehicle received.
    NotSampled,
    /// Instantaneous samples; the controller's rate is not declared.
    RateUnknown,
    /// Instantaneous samples of a controller this many times faster than the log; `removed` names
    /// the logged noises whose unfelt reaction was taken out of the commands (empty: none).
    FasterController {
        steps_per_row: f64,
        removed: &'static str,
    },
}

/// A channel whose model-side noise is at least this share of its signal gets a note.
pub const MODEL_NOISE_NOTE_SHARE: f64 = 0.05;

impl RecordingView<'_> {
    /// The report in plain words (`mismatch.md`).
    pub fn markdown(&self) -> String {
        let mut md = String::new();
        self.header_markdown(&mut md);
        self.disagreement_markdown(&mut md);
        self.model_noise_markdown(&mut md);
        self.limits_markdown(&mut md);
        self.effects_markdown(&mut md);
        self.candidates_markdown(&mut md);
        self.fit_markdown(&mut md);
        md
    }

    /// The title, the comparison and the frame of the body rates.
    fn header_markdown(&self, md: &mut String) {
        let _ = writeln!(md, "# Sim-to-real mismatch: {}\n", self.recording);
        let _ = writeln!(
            md,
            "Nominal model: `{}`. The recording's velocity and body rate are compared with what the nominal model predicts from the recorded attitude and commands in the weak form: both weighted by the same smooth test function over ±0.2 s, so that a right model leaves only noise. Every mean squared error below is of that weak-form residual.\n",
            self.model
        );
        let frame = match self.rate_frame.used {
            RateFrame::Body => "the body frame",
            RateFrame::World => "the world frame (converted to body rates)",
        };
        let _ = writeln!(
            md,
            "The `w` column was read in {frame}: it matches the rate implied by the recorded attitude with an RMS error of {:.4} rad/s in the body frame and {:.4} rad/s in the world frame.\n",
            self.rate_frame.body_rms, self.rate_frame.world_rms
        );
        if let Some(stamps) = self.time_stamps {
            let [low, high] = stamps.interval_ratio_percentiles;
            let _ = writeln!(
                md,
                "The time stamps are not evenly spaced: the median interval is {:.4} s and 98% of the intervals lie between {low:.2} and {high:.2} times it; {} gaps longer than {} median intervals (the longest {:.3} s) split the recording into {} segments. Every operator works on the samples' own times, and the comparison is made at the {} of the {} rows whose window spans no gap.\n",
                stamps.median_interval_s,
                stamps.gaps,
                stamps.gap_factor,
                stamps.longest_interval_s,
                stamps.segments,
                stamps.compared_rows,
                stamps.rows
            );
        }
        if let Some(content) = &self.log_content {
            let slow: Vec<String> = content
                .signals
                .iter()
                .filter(|(_, pattern, _)| *pattern != "fresh")
                .map(|(name, pattern, rate)| {
                    format!("{name} {pattern} ({rate:.1} new values per second)")
                })
                .collect();
            let _ = write!(
                md,
                "**What the log holds.** The rows come at {:.1} Hz, but not every signal is new at every row: {}.",
                content.row_rate_hz,
                slow.join(", ")
            );
            if let Some(limit) = content.timing_limit_s {
                let _ = write!(
                    md,
                    " A command's effect is seen only as often as the command changes: a delay or a motor lag shorter than {:.0} ms cannot be identified from this log, and none shorter is named (logging the motor commands at the controller's rate, as PX4's high-rate logging profile does, would resolve them).",
                    1000.0 * limit
                );
            }
            let _ = writeln!(md, "\n");
        }
        if !self.position_logged {
            let _ = writeln!(
                md,
                "**No position in the log.** The ground effect, which needs the height, is not looked for, and the commands' reaction to position noise is not removed.\n"
            );
        }
    }

    /// The channels against their noise floors and the stretches that disagree.
    fn disagreement_markdown(&self, md: &mut String) {
        let _ = writeln!(md, "## Where the model and the recording disagree\n");
        let _ = writeln!(
            md,
            "| channel | residual RMS | noise floor | significant |\n|---|---|---|---|"
        );
        for c in self.channels {
            let _ = writeln!(
                md,
                "| {} | {:.4} | {:.4} | {} |",
                c.name,
                c.residual_rms,
                c.noise_floor,
                if c.significant { "yes" } else { "no" }
            );
        }
        if self.angular_left_out {
            let _ = writeln!(
                md,
                "\nThe model's `compared_channels` is \"translational\": its torques are not compared, only the translational channels."
            );
        } else if let Some((response, error)) = self.uninformative_torques {
            let _ = writeln!(
                md,
                "\nThe model's torques say nothing about the recorded angular accelerations: each angular channel's response to the model's prediction (1 when the torques are right, 0 when they are unrelated) is {} ± {} (x, y, z), not clearly positive on every axis. Commands that do not resolve the attitude loop (see what the log holds) or a wrong rotor geometry do this; any angular effect fitted there would only fit noise, so only the translational channels are compared.",
                fixed_list(&response),
                fixed_list(&error)
            );
        } else if self.translational_only {
            let _ = writeln!(
                md,
                "\nThe model has no mixer, so it predicts no torques: only the translational channels are compared."
            );
        }
        if self.windows.is_empty() {
            let _ = writeln!(
                md,
                "\nNo stretch of the flight disagrees by more than {:.1} times the noise floor.",
                self.window_factor
            );
        } else {
            let _ = writeln!(
                md,
                "\nStretches where the residual exceeds {:.1} times the noise floor (1 s moving RMS):\n",
                self.window_factor
            );
            for w in self.windows {
                let _ = writeln!(
                    md,
                    "- {} from {:.1} s to {:.1} s",
                    w.channel, w.t_start, w.t_end
                );
            }
        }
    }

    /// The channels where the model's own inputs are noisy enough to shrink a fitted factor.
    fn model_noise_markdown(&self, md: &mut String) {
        let noisy: Vec<String> = self
            .channels
            .iter()
            .filter(|c| c.model_noise_share >= MODEL_NOISE_NOTE_SHARE)
            .map(|c| format!("{:.0}% on {}", 100.0 * c.model_noise_share, c.name))
            .collect();
        let shares = match noisy.split_last() {
            Some((last, [])) => last.clone(),
            Some((last, rest)) => format!("{} and {last}", rest.join(", ")),
            None => return,
        };
        let _ = write!(
            md,
            "\n**Noise on the model's side.** The commands and attitude the model reads are noisy too: relative to the variance of the model's value, their noise's variance is {shares}. The gain a factor fits through such a channel (a thrust scale's k, an inertia scale's 1/k) comes out smaller by up to about that share, and its standard error does not include it (errors in variables; `docs/mismatch.md`, \"Noise in the model's inputs\"); the noise floor does include it, so a weak effect on such a channel may go unnamed."
        );
        let remedy = "Logging the mean command over each log period (`\"command\": \"period_mean\"`) or every command removes most of it.";
        let _ = match self.command_sampling {
            CommandSampling::NotSampled => Ok(()),
            CommandSampling::RateUnknown => write!(
                md,
                " If the rows hold instantaneous samples of a faster controller's commands (the model's logger does not say its rate), they carry its step-to-step reaction to its sensors' noise, which the vehicle averaged. {remedy}"
            ),
            CommandSampling::FasterController {
                steps_per_row,
                removed,
            } => {
                let removed = if removed.is_empty() {
                    String::new()
                } else {
                    format!(
                        " The share of its reaction to the logged {removed} noise that the vehicle did not feel was taken out of the commands before the comparison; the reaction to the rate noise stays."
                    )
                };
                write!(
                    md,
                    " Here the rows hold instantaneous samples of a controller {steps_per_row:.0} times faster than the log: each carries the controller's step-to-step reaction to its sensors' noise, which the vehicle averaged.{removed} {remedy}"
                )
            }
        };
        let _ = writeln!(md);
    }

    /// A note when instantaneous command samples sit at an actuator limit.
    fn limits_markdown(&self, md: &mut String) {
        if self.rows_at_limit == 0 {
            return;
        }
        let _ = writeln!(
            md,
            "\n**Actuators at a limit.** On {} rows a motor command sits at a limit of its range. Between the samples the model's command follows each rotor's thrust (the quantity the mixer is linear in), the demand beyond the limit continued from the neighbouring samples and clipped, as the rotor clipped it.",
            self.rows_at_limit
        );
    }

    /// The evidence rule, the effects named and those not named, what remains unexplained.
    fn effects_markdown(&self, md: &mut String) {
        let _ = writeln!(md, "\n## What is missing from the model\n");
        let rule = self.rule;
        let _ = writeln!(
            md,
            "An effect is named only when, with the others refitted without it, it passes four tests on the channels it acts on: on the fit part, its likelihood ratio (corrected for the correlation of neighbouring rows) exceeds the {} quantile of χ², it lowers the noise-normalised residual by at least {} per row and channel; over the {} s blocks of the fit and held-out parts, by at least {} when the two that gain most are left out (not one or two transients); and it lowers the held-out residual by at least {:.0}%.\n",
            rule.significance,
            rule.min_gain,
            rule.block_s,
            rule.min_trimmed_gain,
            100.0 * rule.min_heldout_reduction
        );
        if self.effects.is_empty() {
            let _ = writeln!(
                md,
                "Nothing: no candidate term explains the residual clearly better than noise."
            );
        } else {
            for e in &self.effects {
                let evidence = &e.evidence;
                let errors = if e.standard_errors.is_empty() {
                    String::new()
                } else {
                    format!(
                        " Standard errors: {}.",
                        standard_errors_text(&e.standard_errors)
                    )
                };
                let spans = if e.weight_spans.is_empty() {
                    String::new()
                } else {
                    format!(
                        " Half of each estimate's weight lies in the rows of {}.",
                        weight_spans_text(&e.weight_spans)
                    )
                };
                let _ = writeln!(
                    md,
                    "- **{}** — {}{}{} It accounts for {:.0}% of the nominal model's (noise-normalised) residual; without it the held-out residual is {:.0}% higher (likelihood ratio {:.0} against {:.1}, gain {:.2} per row and channel on the fit part, {:.2} over every block but its two largest).",
                    evidence.id,
                    e.description,
                    errors,
                    spans,
                    100.0 * e.explained_fraction,
                    100.0 * (evidence.heldout_without / evidence.heldout_with.max(1e-300) - 1.0),
                    evidence.likelihood_ratio,
                    evidence.likelihood_ratio_threshold,
                    evidence.fit_gain,
                    evidence.trimmed_gain
                );
            }
        }
        self.confounds_markdown(md);
        for b in &self.below_resolution {
            let _ = writeln!(
                md,
                "- not named: {} of {:.0} ms, shorter than the {:.0} ms between the motor commands' new values: below what the log resolves (left out of the fit).",
                b.id,
                1000.0 * b.value_s,
                1000.0 * b.limit_s
            );
        }
        for d in &self.dropped {
            let _ = writeln!(
                md,
                "- not named: {} (likelihood ratio {:.1} against {:.1}, gain {:.3}, {:.3} over every block but its two largest, held-out reduction {:.1}%): below the evidence rule.",
                d.id,
                d.likelihood_ratio,
                d.likelihood_ratio_threshold,
                d.fit_gain,
                d.trimmed_gain,
                100.0 * d.heldout_reduction
            );
        }
        self.unexplained_markdown(md);
    }

    /// The effects a stand-in explains as well, and a wind a vehicle effect replaced.
    fn confounds_markdown(&self, md: &mut String) {
        let as_well = |e: &Inseparable| -> String {
            e.stand_ins
                .iter()
                .filter(|s| s.explains_as_well)
                .map(|s| s.text())
                .collect::<Vec<_>>()
                .join("; ")
        };
        for e in &self.not_separable {
            let _ = writeln!(
                md,
                "- **not separable from this recording: {}** — {} Fitted in its place, with the others refitted, these explain the recording as well: {}. It stays in the fitted model; which of them is the physics, this recording cannot tell.",
                e.id,
                e.description,
                as_well(e)
            );
        }
        for named in &self.replaced {
            let better: Vec<String> = named
                .stand_ins
                .iter()
                .filter(|s| s.explains_better)
                .map(|s| s.text())
                .collect();
            if named.id == "wind" && better.is_empty() {
                let _ = writeln!(
                    md,
                    "- not named: wind — a vehicle effect explains the recording as well ({}). A flight's air is the weaker explanation of a residual the vehicle's own physics explains, so that effect was fitted in its place and judged by the evidence rule.",
                    as_well(named)
                );
            } else {
                let _ = writeln!(
                    md,
                    "- not named: {} — an effect that could stand in for it explains the recording better ({}), so it was fitted in its place and judged by the evidence rule.",
                    named.id,
                    better.join("; ")
                );
            }
        }
    }

    /// What remains unexplained with the effects named.
    fn unexplained_markdown(&self, md: &mut String) {
        let steps = match self.estimate.steps {
            0 => String::new(),
            n => format!(
                " (the residual that placing each of the {n} command steps between samples within its interval explains is left out)"
            ),
        };
        if self.unexplained.is_empty() {
            let _ = writeln!(
                md,
                "\nWith the effects named, no stretch of the flight disagrees by more than {:.1} times the noise floor{steps}.",
                self.window_factor
            );
        } else {
            let _ = writeln!(
                md,
                "\nA significant residual remains that no effect of the vocabulary explains{steps}:\n"
            );
            for w in self.unexplained {
                let _ = writeln!(
                    md,
                    "- unexplained residual on {}, {:.1}–{:.1} s",
                    w.channel, w.t_start, w.t_end
                );
            }
        }
    }

    /// Every candidate with its selection frequency, and the command-rate alternatives.
    fn candidates_markdown(&self, md: &mut String) {
        let _ = writeln!(
            md,
            "\nCandidates and how often each was chosen in {} bootstrap resamples:\n",
            self.resamples
        );
        for c in &self.candidates {
            let terms: Vec<String> = c
                .terms
                .iter()
                .map(|t| format!("`{}` = {} [{}]", t.name, t.formula, t.units))
                .collect();
            let _ = writeln!(
                md,
                "- {} ({}): {:.0}%{}",
                c.id,
                terms.join(", "),
                100.0 * c.selection_frequency,
                if c.kept { ", kept" } else { "" }
            );
        }
        if let Some(timing) = self.timing {
            let _ = writeln!(
                md,
                "\nThe command-rate term was resolved by fitting a pure delay, a first-order motor lag and both exactly; noise-normalised fit errors: {}. The smallest was kept, then judged by the evidence rule.{}",
                serde_json::to_string(timing).expect("numbers serialise"),
                if self.reports_a_timing() {
                    ""
                } else {
                    " It was fitted at zero (no lateness) and left out."
                }
            );
        }
    }

    /// Whether a delay or a motor lag is among the effects the report names, cannot separate,
    /// replaced, dropped or found below the log's resolution.
    fn reports_a_timing(&self) -> bool {
        let timing = |id: &str| id == "delay" || id == "motor_lag";
        self.effects.iter().any(|e| timing(e.evidence.id))
            || self.not_separable.iter().any(|e| timing(e.id))
            || self.replaced.iter().any(|e| timing(e.id))
            || self.dropped.iter().any(|e| timing(e.id))
            || self.below_resolution.iter().any(|e| timing(e.id))
    }

    /// The fit and held-out errors before and after.
    fn fit_markdown(&self, md: &mut String) {
        let fit = self.fit;
        let reduction = |before: f64, after: f64| 100.0 * (1.0 - after / before.max(1e-300));
        let _ = writeln!(md, "\n## Does the fit improve?\n");
        let _ = writeln!(
            md,
            "The effects were chosen with parameters fitted on {:.1}–{:.1} s and checked on the held-out {:.1}–{:.1} s (the table). The parameters reported above were then estimated on the whole recording, residuals beyond {} robust standard deviations counting linearly (Huber's loss; {:.1}% of the residuals were downweighted).\n",
            fit.t_start,
            fit.t_end,
            fit.heldout.t_start,
            fit.heldout.t_end,
            self.estimate.huber_threshold,
            100.0 * self.estimate.downweighted_fraction
        );
        if self.estimate.steps > 0 {
            let _ = writeln!(
                md,
                "The commands step between two samples {} time(s); no sample says when within the interval, so each step's time was left free (`estimate_step_times` in `mismatch.json`).\n",
                self.estimate.steps
            );
        }
        if let Some(line) = self.estimate.noise_bias {
            let NoiseBiasLine { pairs, seed, .. } = line;
            let noises = if line.rate && line.attitude_estimate {
                "the controller's reaction to the gyro noise, which the vehicle felt for one control step in a row, and the error of the removed reaction to the attitude noise (whose estimate is uncertain)"
            } else if line.rate {
                "the controller's reaction to the gyro noise, which the vehicle felt for one control step in a row"
            } else {
                "white noise (the controller's reaction to its sensors' noise, which the vehicle averaged over the row)"
            };
            let _ = writeln!(
                md,
                "The command samples carry {noises}. Such noise biases the parameters: adding it once more ({pairs} pairs of draws, seed {seed}) measured the bias, and it was subtracted (simulation and extrapolation; `noise_bias` in `mismatch.json`).\n"
            );
        }
        let _ = writeln!(
            md,
            "| part | MSE nominal | MSE with effects | reduction |\n|---|---|---|---|"
        );
        let _ = writeln!(
            md,
            "| fit | {:.5} | {:.5} | {:.1}% |",
            fit.before.mse,
            fit.after.mse,
            reduction(fit.before.mse, fit.after.mse)
        );
        let _ = writeln!(
            md,
            "| held out | {:.5} | {:.5} | {:.1}% |",
            fit.heldout.before.mse,
            fit.heldout.after.mse,
            reduction(fit.heldout.before.mse, fit.heldout.after.mse)
        );
        let _ = writeln!(md, "\nFigure: `mismatch.svg`.");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn channel(name: &str, rms: f64, significant: bool) -> ChannelReport {
        ChannelReport {
            name: name.to_string(),
            residual_rms: rms,
            noise_floor: 0.01,
            noise_floor_model_side: 0.002,
            model_noise_share: 0.01,
            significant,
            residual_rms_after: rms / 2.0,
            significant_after: false,
            heldout_mse_before: rms * rms,
            heldout_mse_after: rms * rms / 4.0,
        }
    }

    fn window(channel: &str, t_start: f64, t_end: f64) -> Window {
        Window {
            channel: channel.to_string(),
            t_start,
            t_end,
        }
    }

    fn evidence(id: &str, likelihood_ratio: f64) -> EvidenceLine<'_> {
        EvidenceLine {
            id,
            likelihood_ratio,
            likelihood_ratio_threshold: 16.27,
            fit_gain: 0.75,
            trimmed_gain: 0.5,
            heldout_without: 3.0,
            heldout_with: 2.0,
            heldout_reduction: 1.0 / 3.0,
        }
    }

    fn fit() -> Fit {
        let mse = |mse| Mse { mse };
        Fit {
            before: mse(0.5),
            after: mse(0.125),
            heldout: Heldout {
                before: mse(0.4),
                after: mse(0.2),
                t_start: 14.0,
                t_end: 20.0,
            },
            comparison: "weak form".to_string(),
            t_start: 0.2,
            t_end: 13.98,
        }
    }

    #[test]
    fn a_recording_with_an_effect_a_dropped_one_and_an_unexplained_stretch_reads_so() {
        let rate_frame = RateFrameReport {
            used: RateFrame::World,
            body_rms: 0.0123,
            world_rms: 0.00456,
        };
        let channels = [
            channel("vdot_x", 0.25, true),
            ChannelReport {
                model_noise_share: 0.125,
                ..channel("vdot_y", 0.005, false)
            },
        ];
        let (windows, unexplained) = ([window("vdot_x", 1.25, 7.5)], [window("vdot_x", 2.0, 2.75)]);
        let timing = TimingScores {
            both: 1.25,
            delay: 1.5,
            motor_lag: 2.0,
        };
        let fit = fit();
        let view = RecordingView {
            recording: "flight.csv",
            model: "model.json",
            rate_frame: &rate_frame,
            time_stamps: None,
            position_logged: false,
            log_content: Some(LogContentView {
                row_rate_hz: 50.0,
                signals: vec![
                    ("velocity", "fresh", 50.0),
                    ("motor commands", "held", 12.5),
                ],
                timing_limit_s: Some(0.08),
            }),
            below_resolution: vec![BelowResolutionLine {
                id: "delay",
                value_s: 0.03,
                limit_s: 0.08,
            }],
            channels: &channels,
            translational_only: true,
            angular_left_out: false,
            uninformative_torques: Some(([0.0006, -0.02, 0.23], [0.23, 0.24, 0.05])),
            window_factor: 2.5,
            windows: &windows,
            rule: EvidenceRule {
                significance: 0.999,
                min_gain: 0.25,
                min_trimmed_gain: 0.1,
                min_heldout_reduction: 0.15,
                block_s: 1.0,
            },
            effects: vec![NamedEffect {
                evidence: evidence("linear_drag", 120.4),
                description: "Drag.",
                standard_errors: vec![("d", vec![0.0123, 0.25, 3.0])],
                weight_spans: vec![("d", vec![[0.2, 20.14], [3.0, 4.46], [12.04, 12.96]])],
                explained_fraction: 0.625,
            }],
            not_separable: vec![Inseparable {
                id: "delay",
                description: "A delay of 30 ms.",
                stand_ins: vec![StandInLine {
                    id: "motor_lag",
                    parameters: "tau_s = 0.031".to_string(),
                    likelihood_ratio: 3.21,
                    likelihood_ratio_threshold: 10.83,
                    heldout_increase: -0.02,
                    explains_as_well: true,
                    explains_better: false,
                }],
            }],
            replaced: Vec::new(),
            dropped: vec![evidence("wind", 3.25)],
            unexplained: &unexplained,
            resamples: 40,
            candidates: vec![CandidateLine {
                id: "linear_drag",
                terms: vec![TermLine {
                    name: "drag_x",
                    formula: "−v_x",
                    units: "m/s",
                }],
                selection_frequency: 0.875,
                kept: true,
            }],
            timing: Some(&timing),
            fit: &fit,
            command_sampling: CommandSampling::FasterController {
                steps_per_row: 10.0,
                removed: "attitude, position and velocity",
            },
            rows_at_limit: 12,
            estimate: EstimateLine {
                huber_threshold: 2.5,
                downweighted_fraction: 0.0625,
                steps: 3,
                noise_bias: Some(NoiseBiasLine {
                    pairs: 4,
                    seed: 7,
                    rate: true,
                    attitude_estimate: false,
                    command_samples: false,
                }),
            },
        };
        let md = view.markdown();
        for line in [
            "# Sim-to-real mismatch: flight.csv\n",
            "The `w` column was read in the world frame (converted to body rates): it matches the rate implied by the recorded attitude with an RMS error of 0.0123 rad/s in the body frame and 0.0046 rad/s in the world frame.\n",
            "| vdot_x | 0.2500 | 0.0100 | yes |\n| vdot_y | 0.0050 | 0.0100 | no |\n",
            "\nThe model's torques say nothing about the recorded angular accelerations: each angular channel's response to the model's prediction (1 when the torques are right, 0 when they are unrelated) is [0.00, -0.02, 0.23] ± [0.23, 0.24, 0.05] (x, y, z), not clearly positive on every axis.",
            "(1 s moving RMS):\n\n- vdot_x from 1.2 s to 7.5 s\n",
            "- **linear_drag** — Drag. Standard errors: d ± [0.012, 0.25, 3.0]. Half of each estimate's weight lies in the rows of d: 0.2–20.1 s, 3.0–4.5 s, 12.0–13.0 s. It accounts for 62% of the nominal model's (noise-normalised) residual; without it the held-out residual is 50% higher (likelihood ratio 120 against 16.3, gain 0.75 per row and channel on the fit part, 0.50 over every block but its two largest).\n",
            "- **not separable from this recording: delay** — A delay of 30 ms. Fitted in its place, with the others refitted, these explain the recording as well: motor_lag (tau_s = 0.031): fit-part likelihood ratio 3.2 against 10.8, held-out residual 2% lower. It stays",
            "**What the log holds.** The rows come at 50.0 Hz, but not every signal is new at every row: motor commands held (12.5 new values per second). A command's effect is seen only as often as the command changes: a delay or a motor lag shorter than 80 ms cannot be identified from this log",
            "- not named: delay of 30 ms, shorter than the 80 ms between the motor commands' new values: below what the log resolves (left out of the fit).\n",
            "- not named: wind (likelihood ratio 3.2 against 16.3, gain 0.750, 0.500 over every block but its two largest, held-out reduction 33.3%): below the evidence rule.\n",
            "- unexplained residual on vdot_x, 2.0–2.8 s\n",
            "- linear_drag (`drag_x` = −v_x [m/s]): 88%, kept\n",
            "noise-normalised fit errors: {\"both\":1.25,\"delay\":1.5,\"motor_lag\":2.0}. The smallest was kept, then judged by the evidence rule.\n",
            "The effects were chosen with parameters fitted on 0.2–14.0 s and checked on the held-out 14.0–20.0 s (the table). The parameters reported above were then estimated on the whole recording, residuals beyond 2.5 robust standard deviations counting linearly (Huber's loss; 6.2% of the residuals were downweighted).\n",
            "The command samples carry the controller's reaction to the gyro noise, which the vehicle felt for one control step in a row. Such noise biases the parameters: adding it once more (4 pairs of draws, seed 7) measured the bias",
            "The commands step between two samples 3 time(s)",
            "\n**Actuators at a limit.** On 12 rows a motor command sits at a limit of its range.",
            "| fit | 0.50000 | 0.12500 | 75.0% |\n| held out | 0.40000 | 0.20000 | 50.0% |\n",
            "\n**Noise on the model's side.** The commands and attitude the model reads are noisy too: relative to the variance of the model's value, their noise's variance is 12% on vdot_y.",
            "samples of a controller 10 times faster than the log",
            "**No position in the log.** The ground effect, which needs the height, is not looked for",
        ] {
            assert!(md.contains(line), "missing {line:?} in\n{md}");
        }
        assert!(md.ends_with("\nFigure: `mismatch.svg`.\n"));
        // A timing term that no list accounts for was fitted at zero, and the report says so.
        let untimed = RecordingView {
            not_separable: Vec::new(),
            below_resolution: Vec::new(),
            ..view
        };
        let md = untimed.markdown();
        assert!(
            md.contains("The smallest was kept, then judged by the evidence rule. It was fitted at zero (no lateness) and left out.\n"),
            "{md}"
        );
    }

    /// A stand-in's held-out residual is said against the named set's: a stand-in that leaves
    /// 3.68 times less is 73% lower (never more than 100%), one that leaves twice as much 100%
    /// higher.
    #[test]
    fn a_stand_ins_held_out_residual_is_a_change_against_the_named_sets() {
        let line = |heldout_increase: f64| StandInLine {
            id: "rotor_speed_drag",
            parameters: "d = [0.350, 0.101]".to_string(),
            likelihood_ratio: -180.0,
            likelihood_ratio_threshold: 10.83,
            heldout_increase,
            explains_as_well: true,
            explains_better: true,
        };
        assert!(line(-2.68).text().ends_with("held-out residual 73% lower"));
        assert!(line(0.5).text().ends_with("held-out residual 100% higher"));
    }

    #[test]
    fn a_recording_that_agrees_with_its_model_says_so() {
        let rate_frame = RateFrameReport {
            used: RateFrame::Body,
            body_rms: 0.001,
            world_rms: 0.02,
        };
        let channels = [channel("vdot_x", 0.005, false)];
        let fit = fit();
        let view = RecordingView {
            recording: "calm.csv",
            model: "model.json",
            rate_frame: &rate_frame,
            time_stamps: None,
            log_content: None,
            position_logged: true,
            below_resolution: Vec::new(),
            channels: &channels,
            translational_only: false,
            angular_left_out: false,
            uninformative_torques: None,
            window_factor: 2.5,
            windows: &[],
            rule: EvidenceRule {
                significance: 0.999,
                min_gain: 0.25,
                min_trimmed_gain: 0.1,
                min_heldout_reduction: 0.15,
                block_s: 1.0,
            },
            effects: Vec::new(),
            not_separable: Vec::new(),
            replaced: Vec::new(),
            dropped: Vec::new(),
            unexplained: &[],
            resamples: 40,
            candidates: Vec::new(),
            timing: None,
            fit: &fit,
            command_sampling: CommandSampling::NotSampled,
            rows_at_limit: 0,
            estimate: EstimateLine {
                huber_threshold: 2.5,
                downweighted_fraction: 0.0,
                steps: 0,
                noise_bias: None,
            },
        };
        let md = view.markdown();
        assert!(md.contains("The `w` column was read in the body frame: "));
        assert!(!md.contains("no mixer"));
        assert!(md.contains(
            "\nNo stretch of the flight disagrees by more than 2.5 times the noise floor.\n"
        ));
        assert!(md.contains(
            "Nothing: no candidate term explains the residual clearly better than noise.\n"
        ));
        assert!(md.contains("\nWith the effects named, no stretch of the flight disagrees by more than 2.5 times the noise floor.\n"));
        assert!(!md.contains("command-rate"));
        assert!(!md.contains("Noise on the model's side"));
        assert!(!md.contains("Actuators at a limit"));
    }
}
