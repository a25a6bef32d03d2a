//! Judging each cell of the demo matrix against fixed targets, and the summary (its JSON; the
//! Markdown and the terminal table are rendered by the `report` crate, [`report::mismatch::demo`],
//! from the view [`DemoSummary::view`] fills).

use std::path::Path;

use physics::{
    ChannelGroup, EffectId, Effects, NominalModel, ParameterValue, Scenario, Trajectory,
};
pub use report::mismatch::demo::Targets;
use report::mismatch::demo::{CellLine, ConfigurationLine, DemoView, JitterLine, ParameterLine};
use serde::Serialize;

use crate::analysis::Analysis;

use super::DemoConfiguration;
use super::chance::chance_within;

/// The demo's targets.
pub const TARGETS: Targets = Targets {
    parameters_within: 0.10,
    heldout_ratio_at_most: 0.4,
    heldout_noise_multiple_at_most: 1.2,
};

/// One parameter, true against found.
#[derive(Clone, Debug, Serialize)]
pub struct ParameterCheck {
    pub effect: EffectId,
    pub parameter: String,
    pub truth: ParameterValue,
    /// Rounded to 4 decimals; `None` (null) when the fit has no such parameter.
    pub found: Option<ParameterValue>,
    /// The standard error the analysis reports for the found value (`None` when it has none).
    pub standard_error: Option<ParameterValue>,
    /// Whether every component of the true value lies within two standard errors of the found one.
    pub within_two_standard_errors: Option<bool>,
    /// The largest error of a component in its standard errors, `max |found − true| / error`.
    pub standard_errors_off: Option<f64>,
    /// |found − true| / |true| (vectors: Euclidean norms); for the factors `thrust_scale.k` and
    /// `inertia_scale.k`, relative to |true − 1|.
    pub relative_error: f64,
    /// The probability that an unbiased estimate scattering as the standard error says (components
    /// independent) is within the target ([`chance_within`]): what the recording's information
    /// allows, whatever this estimate found.
    pub chance_within_target: Option<f64>,
}

/// One cell's outcome.
#[derive(Clone, Debug, Serialize)]
pub struct CellOutcome {
    pub configuration: String,
    pub case: String,
    pub seed: u64,
    pub true_effects: Vec<EffectId>,
    pub found_effects: Vec<EffectId>,
    pub named_exactly: bool,
    pub parameters: Vec<ParameterCheck>,
    pub heldout_mse_before: f64,
    pub heldout_mse_after: f64,
    /// after / before.
    pub heldout_ratio: f64,
    /// The held-out MSE the cell had to reach (cells with an effect, once all cells are known).
    pub heldout_target: Option<f64>,
    /// Every target met.
    pub passed: bool,
    /// Why not, in a few words.
    pub failures: Vec<String>,
    /// The stretches the analysis reports as a residual no effect explains (`wdot_x 30.5–31.5 s`).
    /// Every simulated effect is in the vocabulary, so each is a false alarm; not a target.
    pub unexplained: Vec<String>,
}

impl CellOutcome {
    /// Judges an analysis of a recording with `truth` as its concealed effects.
    pub fn judge(
        configuration: &str,
        case: &str,
        seed: u64,
        truth: &Effects,
        analysis: &Analysis,
    ) -> Self {
        let report = &analysis.report;
        let true_effects = truth.ids();
        // Effects not separable from a stand-in are fitted but not named: not found.
        let named = analysis.named();
        let found_effects = named.ids();
        let standard_error = |id: EffectId, name: &str| {
            report
                .effects
                .iter()
                .find(|e| e.id == id)
                .and_then(|e| e.standard_errors.as_ref()?.get(name).cloned())
        };
        let parameters = compare_parameters(truth, &named, &standard_error);
        let (before, after) = (report.fit.heldout.before.mse, report.fit.heldout.after.mse);
        let ratio = after / before.max(1e-300);
        let mut failures = Vec::new();
        let missing: Vec<&EffectId> = true_effects
            .iter()
            .filter(|id| !found_effects.contains(id))
            .collect();
        let extra: Vec<&EffectId> = found_effects
            .iter()
            .filter(|id| !true_effects.contains(id))
            .collect();
        for id in &missing {
            failures.push(format!("missed {id}"));
        }
        for id in &extra {
            failures.push(format!("added {id}"));
        }
        for p in &parameters {
            if p.relative_error > TARGETS.parameters_within {
                let mut why: Vec<String> = p
                    .standard_errors_off
                    .map(|z| format!("{z:.1} standard errors"))
                    .into_iter()
                    .collect();
                why.extend(model_noise_note(p.effect, &report.channels));
                why.extend(p.chance_within_target.map(|chance| {
                    format!(
                        "within {:.0}% with probability {chance:.2} at its standard errors",
                        100.0 * TARGETS.parameters_within
                    )
                }));
                let why = if why.is_empty() {
                    String::new()
                } else {
                    format!(" ({})", why.join("; "))
                };
                failures.push(format!(
                    "{}.{} off by {:.0}%{why}",
                    p.effect,
                    p.parameter,
                    100.0 * p.relative_error
                ));
            }
        }
        Self {
            configuration: configuration.to_string(),
            case: case.to_string(),
            seed,
            named_exactly: missing.is_empty() && extra.is_empty(),
            true_effects,
            found_effects,
            parameters,
            heldout_mse_before: before,
            heldout_mse_after: after,
            heldout_ratio: ratio,
            heldout_target: None,
            passed: failures.is_empty(),
            failures,
            unexplained: report
                .unexplained
                .iter()
                .map(|w| format!("{} {:.1}–{:.1} s", w.channel, w.t_start, w.t_end))
                .collect(),
        }
    }

    /// Applies the held-out target, given the configuration's noise level (see [`Targets`]).
    fn judge_heldout(&mut self, noise_level: Option<f64>) {
        if self.true_effects.is_empty() {
            return;
        }
        let by_ratio = TARGETS.heldout_ratio_at_most * self.heldout_mse_before;
        let by_noise = noise_level.map_or(0.0, |n| TARGETS.heldout_noise_multiple_at_most * n);
        let target = by_ratio.max(by_noise);
        self.heldout_target = Some(target);
        if self.heldout_mse_after > target {
            self.failures.push(format!(
                "held-out MSE ×{:.2} of nominal, {:.2} of the noise level",
                self.heldout_ratio,
                noise_level.map_or(f64::NAN, |n| self.heldout_mse_after / n)
            ));
            self.passed = false;
        }
    }
}

/// The standard error reported for a parameter (effect, name), if any.
pub type StandardErrorOf<'a> = &'a dyn Fn(EffectId, &str) -> Option<ParameterValue>;

/// Relative errors of every parameter of every true effect that was found; the effects in the
/// alphabetical order of their ids, as in their JSON.
pub fn compare_parameters(
    truth: &Effects,
    found: &Effects,
    standard_error: StandardErrorOf,
) -> Vec<ParameterCheck> {
    let mut found_true: Vec<EffectId> = truth
        .ids()
        .into_iter()
        .filter(|id| found.contains(*id))
        .collect();
    found_true.sort_by_key(|id| id.name());
    found_true
        .into_iter()
        .flat_map(|id| parameter_checks(id, truth, found, standard_error))
        .collect()
}

/// The model-side noise share worth naming beside a factor that misses its target: the gain the
/// factor fits is smaller by up to its share, and 1% of `1/k` moves `k = 0.85` by 7% of `|k − 1|`.
const NOTED_MODEL_NOISE_SHARE: f64 = 0.01;

/// For a factor, the channel it acts through whose model-side noise is the largest share of the
/// model's value there, when that share is worth naming.
fn model_noise_note(effect: EffectId, channels: &[crate::ChannelReport]) -> Option<String> {
    if !effect.is_factor() {
        return None;
    }
    let acts_on = match effect.acts_on() {
        ChannelGroup::Translational => 0..3,
        ChannelGroup::Angular => 3..6,
        ChannelGroup::Both => 0..6,
    };
    let channel = channels
        .get(acts_on)?
        .iter()
        .max_by(|a, b| a.model_noise_share.total_cmp(&b.model_noise_share))?;
    (channel.model_noise_share >= NOTED_MODEL_NOISE_SHARE).then(|| {
        format!(
            "model-side noise {:.0}% on {}",
            100.0 * channel.model_noise_share,
            channel.name
        )
    })
}

/// One check per parameter of `effect`, from its true and found parameters.
fn parameter_checks(
    effect: EffectId,
    truth: &Effects,
    found: &Effects,
    standard_error: StandardErrorOf,
) -> Vec<ParameterCheck> {
    let reference = if effect.is_factor() { 1.0 } else { 0.0 };
    let found_values = found
        .parameters(effect)
        .map(|p| p.values())
        .unwrap_or_default();
    truth
        .parameters(effect)
        .map(|p| p.values())
        .unwrap_or_default()
        .into_iter()
        .map(|(name, value)| {
            let found_parameter = found_values
                .iter()
                .find(|(n, _)| *n == name)
                .map(|(_, v)| v);
            let found_value = found_parameter.map(|v| v.map(|x| (x * 1e4).round() / 1e4));
            let t = value.numbers();
            let f = found_parameter
                .map(ParameterValue::numbers)
                .unwrap_or_default();
            let difference: f64 = t
                .iter()
                .zip(&f)
                .map(|(a, b)| (a - b).powi(2))
                .sum::<f64>()
                .sqrt();
            let magnitude: f64 = t
                .iter()
                .map(|a| (a - reference).powi(2))
                .sum::<f64>()
                .sqrt();
            let error = standard_error(effect, name);
            let off = error.as_ref().and_then(|e| {
                let e = e.numbers();
                (e.len() == t.len() && f.len() == t.len()).then(|| {
                    (0..t.len())
                        .map(|i| (f[i] - t[i]).abs() / e[i])
                        .fold(0.0, f64::max)
                })
            });
            let within = off.map(|z| z <= 2.0);
            let limit = TARGETS.parameters_within * magnitude;
            let chance = error
                .as_ref()
                .map(ParameterValue::numbers)
                .filter(|e| e.len() == t.len())
                .and_then(|e| chance_within(limit, &e));
            ParameterCheck {
                effect,
                parameter: name.to_string(),
                truth: value,
                found: found_value,
                standard_error: error,
                within_two_standard_errors: within,
                standard_errors_off: off,
                relative_error: if f.len() == t.len() {
                    difference / magnitude.max(1e-300)
                } else {
                    f64::INFINITY
                },
                chance_within_target: chance,
            }
        })
        .collect()
}

/// One configuration in words and numbers.
#[derive(Clone, Debug, Serialize)]
pub struct ConfigurationSummary {
    pub name: String,
    pub description: String,
    pub vehicle: String,
    pub controller_rate_hz: f64,
    pub log_rate_hz: f64,
    pub logger: physics::Logger,
    pub jitter: Option<physics::Jitter>,
    pub noise: physics::Noise,
    pub trajectory: String,
}

/// A configuration's summary from its scenario and the model the tool is given.
pub fn describe_configuration(
    configuration: &DemoConfiguration,
    scenario: &Scenario,
    model: &NominalModel,
) -> ConfigurationSummary {
    let trajectory = match &scenario.trajectory {
        Trajectory::Figure8 {
            first, period_s, ..
        } => format!(
            "figure-8, ±{:.1} m every {period_s} s",
            first.iter().fold(0.0f64, |a, b| a.max(b.abs()))
        ),
        Trajectory::RandomWaypoints {
            count, segment_s, ..
        } => format!("{count} random waypoints, {segment_s} s each"),
    };
    ConfigurationSummary {
        name: configuration.name.clone(),
        description: configuration.description.clone(),
        vehicle: format!(
            "{} kg, inertia [{}, {}, {}] kg·m²",
            model.mass_kg, model.inertia_kg_m2[0], model.inertia_kg_m2[1], model.inertia_kg_m2[2]
        ),
        controller_rate_hz: scenario.controller_rate(),
        log_rate_hz: scenario.log_rate_hz,
        logger: model.logger,
        jitter: scenario.jitter,
        noise: scenario.noise,
        trajectory,
    }
}

/// All outcomes.
#[derive(Clone, Debug, Serialize)]
pub struct DemoSummary {
    pub targets: Targets,
    pub configurations: Vec<ConfigurationSummary>,
    /// Case names and purposes, in order.
    pub cases: Vec<(String, String)>,
    /// Configuration by configuration, case by case.
    pub cells: Vec<CellOutcome>,
}

impl DemoSummary {
    pub fn new(
        configurations: Vec<ConfigurationSummary>,
        cases: Vec<(String, String)>,
        mut cells: Vec<CellOutcome>,
    ) -> Self {
        for configuration in &configurations {
            let controls: Vec<f64> = cells
                .iter()
                .filter(|c| c.configuration == configuration.name && c.true_effects.is_empty())
                .map(|c| c.heldout_mse_before)
                .collect();
            let noise_level = (!controls.is_empty())
                .then(|| controls.iter().sum::<f64>() / controls.len() as f64);
            for cell in cells
                .iter_mut()
                .filter(|c| c.configuration == configuration.name)
            {
                cell.judge_heldout(noise_level);
            }
        }
        Self {
            targets: TARGETS,
            configurations,
            cases,
            cells,
        }
    }

    /// What the Markdown and the terminal table say: the configurations and the cells with the
    /// effects by their names, the rest borrowed; `manifest` names the manifest read.
    pub fn view(&self, manifest: &Path) -> DemoView<'_> {
        DemoView {
            manifest: manifest.display().to_string(),
            targets: &self.targets,
            configurations: self.configurations.iter().map(configuration_line).collect(),
            cases: &self.cases,
            cells: self.cells.iter().map(cell_line).collect(),
        }
    }

    /// The contents of the files [`super::SUMMARY_FILES`] names: the Markdown and the JSON, of a
    /// run of `manifest`.
    pub fn render(&self, manifest: &Path) -> [String; 2] {
        let json = serde_json::to_string_pretty(self).expect("serialises");
        [self.view(manifest).markdown(), json + "\n"]
    }
}

fn configuration_line(c: &ConfigurationSummary) -> ConfigurationLine<'_> {
    ConfigurationLine {
        name: &c.name,
        description: &c.description,
        vehicle: &c.vehicle,
        controller_rate_hz: c.controller_rate_hz,
        log_rate_hz: c.log_rate_hz,
        command: c.logger.command.name(),
        command_time_offset_s: c.logger.command_time_offset_s,
        rate_low_pass_hz: c.logger.rate_low_pass_hz,
        jitter: c.jitter.map(|j| JitterLine {
            translational_m_s2: j.translational_m_s2,
            angular_rad_s2: j.angular_rad_s2,
            band_hz: j.band_hz,
        }),
        velocity_noise_m_s: c.noise.velocity_m_s,
        rate_noise_rad_s: c.noise.rate_rad_s,
        trajectory: &c.trajectory,
    }
}

fn cell_line(c: &CellOutcome) -> CellLine<'_> {
    let names = |ids: &[EffectId]| ids.iter().map(|id| id.name()).collect();
    CellLine {
        configuration: &c.configuration,
        case: &c.case,
        true_effects: names(&c.true_effects),
        found_effects: names(&c.found_effects),
        named_exactly: c.named_exactly,
        parameters: c
            .parameters
            .iter()
            .map(|p| ParameterLine {
                effect: p.effect.name(),
                parameter: &p.parameter,
                truth: p.truth.to_string(),
                found: p
                    .found
                    .as_ref()
                    .map_or("null".to_string(), ToString::to_string),
                standard_error: p.standard_error.as_ref().map(ParameterValue::numbers),
                within_two_standard_errors: p.within_two_standard_errors,
                relative_error: p.relative_error,
                chance_within_target: p.chance_within_target,
            })
            .collect(),
        heldout_mse_before: c.heldout_mse_before,
        heldout_mse_after: c.heldout_mse_after,
        heldout_ratio: c.heldout_ratio,
        passed: c.passed,
        failures: &c.failures,
        unexplained: &c.unexplained,
    }
}
