//! The demo matrix on simulated recordings with concealed effects (`summary.md` and the terminal
//! table): the targets every cell is judged against ([`Targets`], recorded as they are in
//! `summary.json`), and [`DemoView`], what the summary says of the configurations and the cells
//! with names and numbers in place of the simulator's and the analysis's types.

use std::fmt::Write as _;

use serde::{Deserialize, Serialize};

/// The targets every cell is judged against (fixed before any run; recorded in the output).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Targets {
    /// Each parameter's relative error at most this (factor parameters relative to |k − 1|).
    pub parameters_within: f64,
    /// Held-out MSE with the effects at most this fraction of the nominal model's (cases with an
    /// effect) ...
    pub heldout_ratio_at_most: f64,
    /// ... or, when the noise alone keeps it above that (an effect at the level of the noise), at
    /// most this multiple of the noise level: the nominal model's held-out MSE on the same
    /// configuration's no-effect controls.
    pub heldout_noise_multiple_at_most: f64,
}

/// The simulator's jitter of a configuration.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JitterLine {
    /// RMS of the collective-thrust jitter over the mass, m/s², and of each body torque's over
    /// the axis's inertia, rad/s².
    pub translational_m_s2: f64,
    pub angular_rad_s2: f64,
    /// Lowest and highest frequency, Hz.
    pub band_hz: [f64; 2],
}

/// One configuration in words and numbers.
#[derive(Clone, Debug, PartialEq)]
pub struct ConfigurationLine<'a> {
    pub name: &'a str,
    /// What sets it apart.
    pub description: &'a str,
    pub vehicle: &'a str,
    pub controller_rate_hz: f64,
    pub log_rate_hz: f64,
    /// How the command is logged (`sample`, `held` …), and how late, s.
    pub command: &'a str,
    pub command_time_offset_s: f64,
    /// The gyro filter's cutoff, Hz.
    pub rate_low_pass_hz: Option<f64>,
    pub jitter: Option<JitterLine>,
    /// Noise standard deviations of the velocity (m/s) and the body rate (rad/s).
    pub velocity_noise_m_s: f64,
    pub rate_noise_rad_s: f64,
    pub trajectory: &'a str,
}

/// One parameter, true against found.
#[derive(Clone, Debug, PartialEq)]
pub struct ParameterLine<'a> {
    /// The effect's id and the parameter's name.
    pub effect: &'a str,
    pub parameter: &'a str,
    /// The values as compact JSON (`[1.25, 0.85, 1.15]`; `null` when not found).
    pub truth: String,
    pub found: String,
    /// The standard error the analysis reports for the found value, component by component.
    pub standard_error: Option<Vec<f64>>,
    /// Whether the true value lies within two standard errors of the found one.
    pub within_two_standard_errors: Option<bool>,
    pub relative_error: f64,
    /// The probability that an unbiased estimate scattering as the standard error says meets the
    /// parameter target.
    pub chance_within_target: Option<f64>,
}

/// One cell's outcome.
#[derive(Clone, Debug, PartialEq)]
pub struct CellLine<'a> {
    pub configuration: &'a str,
    pub case: &'a str,
    /// The ids of the concealed effects and of those found.
    pub true_effects: Vec<&'a str>,
    pub found_effects: Vec<&'a str>,
    pub named_exactly: bool,
    pub parameters: Vec<ParameterLine<'a>>,
    pub heldout_mse_before: f64,
    pub heldout_mse_after: f64,
    pub heldout_ratio: f64,
    /// Every target met; why not, in a few words.
    pub passed: bool,
    pub failures: &'a [String],
    /// The stretches reported as a residual no effect explains (false alarms here: every simulated
    /// effect is in the vocabulary).
    pub unexplained: &'a [String],
}

/// What the demo's summary says.
#[derive(Clone, Debug, PartialEq)]
pub struct DemoView<'a> {
    /// The manifest the run read, as given on the command line.
    pub manifest: String,
    pub targets: &'a Targets,
    pub configurations: Vec<ConfigurationLine<'a>>,
    /// Case names and purposes, in order.
    pub cases: &'a [(String, String)],
    /// Configuration by configuration, case by case.
    pub cells: Vec<CellLine<'a>>,
}

impl DemoView<'_> {
    fn cell(&self, configuration: &str, case: &str) -> Option<&CellLine<'_>> {
        self.cells
            .iter()
            .find(|c| c.configuration == configuration && c.case == case)
    }

    /// One line per cell, for the terminal.
    pub fn table_text(&self) -> String {
        let mut text = String::new();
        for c in &self.cells {
            let _ = writeln!(
                text,
                "{:<10} {:<34} {} found [{}] held-out MSE ×{:.3}{}",
                c.configuration,
                c.case,
                if c.passed { "OK  " } else { "MISS" },
                c.found_effects.join(", "),
                c.heldout_ratio,
                if c.failures.is_empty() {
                    String::new()
                } else {
                    format!(" ({})", c.failures.join("; "))
                }
            );
        }
        let passed = self.cells.iter().filter(|c| c.passed).count();
        let _ = writeln!(
            text,
            "{passed} of {} cells meet every target",
            self.cells.len()
        );
        text
    }

    /// The summary in Markdown: the configurations, the matrix, the totals, every cell's numbers.
    pub fn markdown(&self) -> String {
        let mut md = String::new();
        let _ = writeln!(
            md,
            "# Mismatch tool on simulated recordings with concealed effects\n"
        );
        let _ = writeln!(
            md,
            "Generated by `make mismatch-demo` (`learn mismatch --demo {}`). Every case (a set of effects the plant has, or none) is flown under every configuration. The closed-loop controller knows only the nominal model and has integral action, so the position follows the reference and the effects show only in the dynamics and the commands. The tool runs blind on each written CSV with only the configuration's nominal model and its logger description (`<work>/<configuration>/model.json`). MSEs are of the weak-form residual (m/s² and rad/s², all six channels) on the held-out last 30% of each flight.\n",
            self.manifest
        );
        let _ = writeln!(
            md,
            "A cell passes when the effects are named exactly (nothing missing, nothing extra; nothing on a no-effect control), every parameter is within {:.0}% (factor parameters relative to |k − 1|), and, with an effect, the held-out MSE is at most {} × the nominal model's or, for an effect at the level of the noise, at most {} × the noise level (the nominal model's held-out MSE on the configuration's no-effect control).\n",
            100.0 * self.targets.parameters_within,
            self.targets.heldout_ratio_at_most,
            self.targets.heldout_noise_multiple_at_most
        );
        self.configurations_markdown(&mut md);
        self.matrix_markdown(&mut md);
        self.details_markdown(&mut md);
        md
    }

    fn configurations_markdown(&self, md: &mut String) {
        let _ = writeln!(md, "## Configurations\n");
        let _ = writeln!(
            md,
            "| name | vehicle | controller / log rate | command logged | gyro filter | jitter (RMS, band) | noise (v, w) | trajectory | what sets it apart |\n|---|---|---|---|---|---|---|---|---|"
        );
        for c in &self.configurations {
            let _ = writeln!(
                md,
                "| {} | {} | {} / {} Hz | {}{} | {} | {} | {} m/s, {} rad/s | {} | {} |",
                c.name,
                c.vehicle,
                c.controller_rate_hz,
                c.log_rate_hz,
                c.command,
                if c.command_time_offset_s != 0.0 {
                    format!(", {:+} ms", 1000.0 * c.command_time_offset_s)
                } else {
                    String::new()
                },
                c.rate_low_pass_hz
                    .map(|f| format!("{f} Hz"))
                    .unwrap_or_else(|| "none".into()),
                c.jitter
                    .map(|j| format!(
                        "{} m/s², {} rad/s², {}–{} Hz",
                        j.translational_m_s2, j.angular_rad_s2, j.band_hz[0], j.band_hz[1]
                    ))
                    .unwrap_or_else(|| "none".into()),
                c.velocity_noise_m_s,
                c.rate_noise_rad_s,
                c.trajectory,
                c.description
            );
        }
    }

    fn matrix_markdown(&self, md: &mut String) {
        let names: Vec<&str> = self.configurations.iter().map(|c| c.name).collect();
        let _ = writeln!(md, "\n## The matrix\n");
        let _ = writeln!(
            md,
            "| case | purpose | {} |\n|---|---|{}",
            names.join(" | "),
            "---|".repeat(names.len())
        );
        for (case, purpose) in self.cases {
            let cells: Vec<String> = names
                .iter()
                .map(|configuration| match self.cell(configuration, case) {
                    Some(c) if c.passed => "✓".to_string(),
                    Some(c) => format!("✗ {}", c.failures.join("; ")),
                    None => "–".to_string(),
                })
                .collect();
            let _ = writeln!(md, "| {case} | {purpose} | {} |", cells.join(" | "));
        }
        let passed = self.cells.iter().filter(|c| c.passed).count();
        let controls: Vec<&CellLine> = self
            .cells
            .iter()
            .filter(|c| c.true_effects.is_empty())
            .collect();
        let clean = controls
            .iter()
            .filter(|c| c.found_effects.is_empty())
            .count();
        let named = self.cells.iter().filter(|c| c.named_exactly).count();
        let parameters: Vec<&ParameterLine> =
            self.cells.iter().flat_map(|c| &c.parameters).collect();
        let within = parameters
            .iter()
            .filter(|p| p.relative_error <= self.targets.parameters_within)
            .count();
        let _ = writeln!(
            md,
            "\n**{passed} of {} cells meet every target.** Named exactly: {named} of {}; parameters within {:.0}%: {within} of {} (of the true effects found); no-effect controls with nothing found: {clean} of {}.",
            self.cells.len(),
            self.cells.len(),
            100.0 * self.targets.parameters_within,
            parameters.len(),
            controls.len()
        );
        self.coverage_markdown(md);
        self.reach_markdown(md);
        self.unexplained_markdown(md);
    }

    /// One entry per configuration, `"<name> <line of its cells>"`, joined by commas.
    fn per_configuration(&self, line: impl Fn(&[&CellLine]) -> String) -> String {
        let entries: Vec<String> = self
            .configurations
            .iter()
            .map(|configuration| {
                let cells: Vec<&CellLine> = self
                    .cells
                    .iter()
                    .filter(|c| c.configuration == configuration.name)
                    .collect();
                format!("{} {}", configuration.name, line(&cells))
            })
            .collect();
        entries.join(", ")
    }

    /// How many cells report a residual that no effect explains: every simulated effect is in the
    /// vocabulary, so each such stretch is a false alarm of the report (not a target).
    fn unexplained_markdown(&self, md: &mut String) {
        let counts = self.per_configuration(|cells| {
            let flagged = cells.iter().filter(|c| !c.unexplained.is_empty()).count();
            format!("{flagged} of {}", cells.len())
        });
        let controls = self
            .cells
            .iter()
            .filter(|c| c.true_effects.is_empty() && !c.unexplained.is_empty())
            .count();
        let _ = writeln!(
            md,
            "\nEvery simulated effect is in the vocabulary, so a stretch reported as a residual no effect explains is a false alarm (not a target; listed per cell below). Cells with one: {counts}; controls with one: {controls}."
        );
    }

    /// How often the true value lies within two of the reported standard errors, per
    /// configuration: whether the uncertainty the tool reports can be trusted.
    fn coverage_markdown(&self, md: &mut String) {
        let counts = self.per_configuration(|cells| {
            let judged: Vec<bool> = cells
                .iter()
                .flat_map(|c| &c.parameters)
                .filter_map(|p| p.within_two_standard_errors)
                .collect();
            let within = judged.iter().filter(|w| **w).count();
            format!("{within} of {}", judged.len())
        });
        let _ = writeln!(
            md,
            "\nEvery parameter is reported with its standard error from the noise (± below). True values within two of them: {counts}; the rest are off by more than the noise explains (a systematic error of the comparison or the fit)."
        );
    }

    /// The probability, per configuration, that every parameter target would be met by unbiased
    /// estimates scattering as their standard errors say: how far the recordings' information
    /// reaches, whatever the estimates found (cells are separate flights, so the cells' chances
    /// multiply).
    fn reach_markdown(&self, md: &mut String) {
        let chances = self.per_configuration(|cells| {
            let parameters: Vec<&ParameterLine> =
                cells.iter().flat_map(|c| &c.parameters).collect();
            let known: Vec<f64> = parameters
                .iter()
                .filter_map(|p| p.chance_within_target)
                .collect();
            let unknown = parameters.len() - known.len();
            format!(
                "{:.2}{}",
                known.iter().product::<f64>(),
                if unknown > 0 {
                    format!(" ({unknown} without a standard error left out)")
                } else {
                    String::new()
                }
            )
        });
        let _ = writeln!(
            md,
            "\nHow far the recordings' information reaches: if every estimate were unbiased and scattered as its standard errors say (components independent), every parameter of a configuration would be within {:.0}% with probability {chances}. Well below 1, a configuration asks more than its flights determine, whatever the estimator.",
            100.0 * self.targets.parameters_within
        );
    }

    fn details_markdown(&self, md: &mut String) {
        let _ = writeln!(md, "\n## Every cell\n");
        let _ = writeln!(
            md,
            "| configuration | case | true effects | found | parameters (true → found, error) | held-out MSE nominal | with effects | ratio | unexplained |\n|---|---|---|---|---|---|---|---|---|"
        );
        for c in &self.cells {
            let parameters: Vec<String> = c
                .parameters
                .iter()
                .map(|p| {
                    format!(
                        "{}.{}: {} → {}{} ({:.1}%)",
                        p.effect,
                        p.parameter,
                        p.truth,
                        p.found,
                        p.standard_error
                            .as_ref()
                            .map(|e| format!(" ± {}", super::two_digit_list(e)))
                            .unwrap_or_default(),
                        100.0 * p.relative_error
                    )
                })
                .collect();
            let list = |v: &[&str]| {
                if v.is_empty() {
                    "none".to_string()
                } else {
                    v.join(", ")
                }
            };
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {:.5} | {:.5} | {:.3} | {} |",
                c.configuration,
                c.case,
                list(&c.true_effects),
                list(&c.found_effects),
                if parameters.is_empty() {
                    "–".to_string()
                } else {
                    parameters.join("; ")
                },
                c.heldout_mse_before,
                c.heldout_mse_after,
                c.heldout_ratio,
                if c.unexplained.is_empty() {
                    "–".to_string()
                } else {
                    c.unexplained.join(", ")
                }
            );
        }
        let _ = writeln!(
            md,
            "\nPer-cell outputs (recording, mismatch.json/svg/md) and each configuration's `model.json` are written under the demo's work directory (`target/mismatch-demo/<configuration>/<case>/`, not committed)."
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parameter(chance: Option<f64>) -> ParameterLine<'static> {
        ParameterLine {
            effect: "inertia_scale",
            parameter: "k",
            truth: "[1.25, 0.85, 1.15]".into(),
            found: "[1.25, 0.85, 1.15]".into(),
            standard_error: chance.map(|_| vec![0.01; 3]),
            within_two_standard_errors: chance.map(|_| true),
            relative_error: 0.01,
            chance_within_target: chance,
        }
    }

    fn cell(configuration: &'static str, chances: &[Option<f64>]) -> CellLine<'static> {
        CellLine {
            configuration,
            case: "inertia_scale",
            true_effects: vec!["inertia_scale"],
            found_effects: vec!["inertia_scale"],
            named_exactly: true,
            parameters: chances.iter().map(|c| parameter(*c)).collect(),
            heldout_mse_before: 1.0,
            heldout_mse_after: 0.1,
            heldout_ratio: 0.1,
            passed: true,
            failures: &[],
            unexplained: &[],
        }
    }

    fn configuration(name: &'static str) -> ConfigurationLine<'static> {
        ConfigurationLine {
            name,
            description: "",
            vehicle: "",
            controller_rate_hz: 500.0,
            log_rate_hz: 50.0,
            command: "sample",
            command_time_offset_s: 0.0,
            rate_low_pass_hz: None,
            jitter: None,
            velocity_noise_m_s: 0.005,
            rate_noise_rad_s: 0.008,
            trajectory: "",
        }
    }

    /// Cells are separate flights: a configuration's chances multiply; parameters without a
    /// standard error are counted, not guessed.
    #[test]
    fn the_reach_of_a_configuration_is_the_product_of_its_parameters_chances() {
        let targets = Targets {
            parameters_within: 0.1,
            heldout_ratio_at_most: 0.4,
            heldout_noise_multiple_at_most: 1.2,
        };
        let cases = [("inertia_scale".to_string(), "wrong inertia".to_string())];
        let view = DemoView {
            manifest: "demo.json".into(),
            targets: &targets,
            configurations: vec![configuration("A"), configuration("E")],
            cases: &cases,
            cells: vec![
                cell("A", &[Some(0.99)]),
                cell("E", &[Some(0.9), None]),
                cell("E", &[Some(0.5)]),
            ],
        };
        let mut md = String::new();
        view.reach_markdown(&mut md);
        assert!(
            md.contains(
                "within 10% with probability A 0.99, E 0.45 (1 without a standard error left out)."
            ),
            "{md}"
        );
    }
}
