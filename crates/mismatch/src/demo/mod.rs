//! Proof on concealed effects, as a matrix: every case (a set of effects, or none) is flown under
//! every configuration (a simulator and logger setting: vehicle, controller and log rates, how the
//! command is logged, jitter, gyro filter, noise, trajectory). The closed loop keeps the position on
//! the reference, so an effect shows only in the dynamics and the control effort. The analysis runs
//! blind on each written CSV with only the configuration's nominal model (and its logger), and each
//! cell is judged against fixed targets (`summary.rs`). The caller writes every file: the work
//! folder's as the run goes ([`DemoPlan::run`] hands them over), the summary's at the end
//! ([`DemoSummary::render`]).

mod chance;
mod summary;
#[cfg(test)]
mod tests;

use std::path::{Path, PathBuf};

use physics::{Effects, NominalModel, Scenario, simulate};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::analysis::analyze;
use crate::analysis::files::ANALYSIS_FILES;
use crate::error::{MismatchError, Result, io_error};
use crate::settings::CheckedSettings;

pub use summary::{CellOutcome, DemoSummary, ParameterCheck, Targets, compare_parameters};

/// One simulator and logger setting: a scenario file (without effects) naming its vehicle model.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct DemoConfiguration {
    pub name: String,
    /// Scenario file, relative to the manifest.
    pub scenario: PathBuf,
    /// What sets this configuration apart.
    pub description: String,
}

/// One case: the effects the plant has.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct DemoCase {
    pub name: String,
    #[serde(default)]
    pub effects: Effects,
    /// What the case shows.
    pub purpose: String,
}

/// The manifest: configurations × cases, plus every pair of the cases listed in `pairs`.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct DemoManifest {
    pub configurations: Vec<DemoConfiguration>,
    pub cases: Vec<DemoCase>,
    /// Names of cases every pair of which is a further case `a+b` (pairs whose effects share an id
    /// are left out).
    #[serde(default)]
    pub pairs: Vec<String>,
}

fn load_manifest(path: &Path) -> Result<DemoManifest> {
    let text = bounded_read::read_json_text(path).map_err(io_error(path))?;
    let manifest: DemoManifest =
        bounded_read::json::from_str(&text).map_err(|e| MismatchError::Config {
            path: path.to_path_buf(),
            field: e.field,
            message: e.message,
        })?;
    manifest.validate(path)?;
    Ok(manifest)
}

/// Checks a name that becomes a directory: letters, digits, `_`, `-`, `+` and `.`, not starting
/// with `.`, without `..`, and not used before (ignoring case).
fn check_name(
    name: &str,
    field: String,
    seen: &mut std::collections::HashSet<String>,
    origin: &Path,
) -> Result<()> {
    let bad = |message: String| MismatchError::Config {
        path: origin.to_path_buf(),
        field: field.clone(),
        message,
    };
    if name.is_empty() {
        return Err(bad("must not be empty".into()));
    }
    let plain = name
        .chars()
        .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.' | '+'));
    if !plain || name.starts_with('.') || name.contains("..") {
        return Err(bad(format!(
            "{name:?} is not a plain directory name (letters, digits, '_', '-', '+' and '.'; no path separators, no leading '.', no '..')"
        )));
    }
    // Case-insensitive: the directories must differ on every file system.
    if !seen.insert(name.to_ascii_lowercase()) {
        return Err(bad(format!("{name:?} is used by an earlier entry")));
    }
    Ok(())
}

impl DemoManifest {
    /// Checks names (distinct plain directory names), effects, and that `pairs` names cases.
    pub fn validate(&self, origin: &Path) -> Result<()> {
        let bad = |field: String, message: String| MismatchError::Config {
            path: origin.to_path_buf(),
            field,
            message,
        };
        if self.configurations.is_empty() {
            return Err(bad(
                "configurations".into(),
                "the manifest lists none".into(),
            ));
        }
        if self.cases.is_empty() {
            return Err(bad("cases".into(), "the manifest lists no cases".into()));
        }
        let mut seen = std::collections::HashSet::new();
        for (i, configuration) in self.configurations.iter().enumerate() {
            check_name(
                &configuration.name,
                format!("configurations[{i}].name"),
                &mut seen,
                origin,
            )?;
        }
        let mut seen = std::collections::HashSet::new();
        for (i, case) in self.cases.iter().enumerate() {
            check_name(&case.name, format!("cases[{i}].name"), &mut seen, origin)?;
            case.effects
                .validate()
                .map_err(|(f, m)| bad(format!("cases[{i}].effects.{f}"), m))?;
        }
        for (i, name) in self.pairs.iter().enumerate() {
            if !self.cases.iter().any(|c| &c.name == name) {
                return Err(bad(
                    format!("pairs[{i}]"),
                    format!("{name:?} is not a case"),
                ));
            }
        }
        for (name, _, _) in self.pair_cases() {
            check_name(&name, "pairs".into(), &mut seen, origin)?;
        }
        Ok(())
    }

    /// The generated pairs: name, effects and purpose.
    fn pair_cases(&self) -> Vec<(String, Effects, String)> {
        let listed: Vec<&DemoCase> = self
            .pairs
            .iter()
            .filter_map(|name| self.cases.iter().find(|c| &c.name == name))
            .collect();
        let mut pairs = Vec::new();
        for (i, a) in listed.iter().enumerate() {
            for b in &listed[i + 1..] {
                let (ids_a, ids_b) = (a.effects.ids(), b.effects.ids());
                if ids_a.iter().any(|id| ids_b.contains(id)) {
                    continue;
                }
                let mut json = serde_json::to_value(a.effects).expect("serialises");
                let extra = serde_json::to_value(b.effects).expect("serialises");
                for (key, value) in extra.as_object().into_iter().flatten() {
                    json[key] = value.clone();
                }
                let effects: Effects = serde_json::from_value(json).expect("a union of effects");
                pairs.push((
                    format!("{}+{}", a.name, b.name),
                    effects,
                    "pair".to_string(),
                ));
            }
        }
        pairs
    }

    /// Every case, the listed ones then the pairs: name, effects, purpose.
    pub fn all_cases(&self) -> Vec<(String, Effects, String)> {
        self.cases
            .iter()
            .map(|c| (c.name.clone(), c.effects, c.purpose.clone()))
            .chain(self.pair_cases())
            .collect()
    }
}

/// One configuration read and checked: its scenario file, scenario and model, and the model the
/// tool is given (the nominal model with this configuration's logger).
#[derive(Clone, Debug)]
struct LoadedConfiguration {
    path: PathBuf,
    scenario: Scenario,
    model: NominalModel,
    model_for_tool: NominalModel,
}

/// A demo run read and checked, ready to run: the manifest, every configuration's scenario and
/// model, every cell, what the run reads and the files it hands over in the work folder.
#[derive(Clone, Debug)]
pub struct DemoPlan {
    manifest_path: PathBuf,
    manifest: DemoManifest,
    configurations: Vec<LoadedConfiguration>,
    cases: Vec<(String, Effects, String)>,
    work: PathBuf,
}

/// The summary's files in the `--out` folder, in the order of [`DemoSummary::render`].
pub const SUMMARY_FILES: [&str; 2] = ["summary.md", "summary.json"];

/// Where the run's work files go: called with a path below the work folder and the file's
/// contents (a configuration's `model.json`, a case's `recording.csv` and analysis), from several
/// cases at once; it writes the file, creating its folder.
pub type WriteFile<'a> = dyn Fn(&Path, &str) -> Result<()> + Sync + 'a;

impl DemoPlan {
    /// Reads and checks the manifest, every configuration's scenario (and its model) and every
    /// cell's scenario with its effects; the cells will be written below `work`.
    pub fn load(manifest_path: &Path, work: &Path) -> Result<Self> {
        let manifest = load_manifest(manifest_path)?;
        let base = manifest_path.parent().unwrap_or(Path::new("."));
        let cases = manifest.all_cases();
        let mut configurations = Vec::new();
        for (i, configuration) in manifest.configurations.iter().enumerate() {
            let path = base.join(&configuration.scenario);
            let (scenario, model) = Scenario::load(&path)?;
            if scenario.effects != Effects::default() {
                return Err(MismatchError::Config {
                    path: manifest_path.to_path_buf(),
                    field: format!("configurations[{i}].scenario"),
                    message: format!(
                        "{} has effects: a configuration's scenario has none, the cases add them",
                        path.display()
                    ),
                });
            }
            for (name, effects, _) in &cases {
                let cell = Scenario {
                    effects: *effects,
                    ..scenario.clone()
                };
                cell.validate(&path).map_err(|e| MismatchError::Config {
                    path: manifest_path.to_path_buf(),
                    field: format!("cases ({name})"),
                    message: format!("with configuration {:?}: {e}", configuration.name),
                })?;
            }
            let model_for_tool = NominalModel {
                logger: scenario.logger(),
                ..model.clone()
            };
            configurations.push(LoadedConfiguration {
                path,
                scenario,
                model,
                model_for_tool,
            });
        }
        Ok(Self {
            manifest_path: manifest_path.to_path_buf(),
            manifest,
            configurations,
            cases,
            work: work.to_path_buf(),
        })
    }

    /// Every file the run reads, each with what it is: the manifest, and each configuration's
    /// scenario and the model that scenario names.
    pub fn inputs(&self) -> Vec<(String, PathBuf)> {
        let mut inputs = vec![(
            "the demo manifest (--demo)".to_string(),
            self.manifest_path.clone(),
        )];
        for (configuration, loaded) in self
            .manifest
            .configurations
            .iter()
            .zip(&self.configurations)
        {
            inputs.push((
                format!(
                    "the scenario of demo configuration {:?}",
                    configuration.name
                ),
                loaded.path.clone(),
            ));
            inputs.push((
                format!("the model of demo configuration {:?}", configuration.name),
                loaded.scenario.model_path(&loaded.path),
            ));
        }
        inputs
    }

    /// Each configuration's directory, `work/<configuration>`.
    fn configuration_dir(&self, index: usize) -> PathBuf {
        self.work.join(&self.manifest.configurations[index].name)
    }

    /// Each cell's directory, `work/<configuration>/<case>`, configuration by configuration.
    pub fn case_dirs(&self) -> Vec<PathBuf> {
        (0..self.configurations.len())
            .flat_map(|i| {
                let dir = self.configuration_dir(i);
                self.cases.iter().map(move |(name, _, _)| dir.join(name))
            })
            .collect()
    }

    /// The files of the work directory: each configuration's `model.json` (the model the tool is
    /// given) and each cell's `recording.csv` and `mismatch.{json,svg,md}`.
    pub fn case_outputs(&self) -> Vec<PathBuf> {
        let models =
            (0..self.configurations.len()).map(|i| self.configuration_dir(i).join("model.json"));
        let cells = self.case_dirs().into_iter().flat_map(|dir| {
            std::iter::once("recording.csv")
                .chain(ANALYSIS_FILES)
                .map(move |name| dir.join(name))
        });
        models.chain(cells).collect()
    }

    /// Runs every cell and returns the summary. Every file of the work folder
    /// ([`DemoPlan::case_outputs`]) goes to `write`: each configuration's `model.json` first, then
    /// each cell's recording (which the analysis then reads back as written) and its analysis in
    /// `work/<configuration>/<case>/`.
    pub fn run(&self, write: &WriteFile, settings: &CheckedSettings) -> Result<DemoSummary> {
        for (i, loaded) in self.configurations.iter().enumerate() {
            let path = self.configuration_dir(i).join("model.json");
            write(&path, &(loaded.model_for_tool.to_json() + "\n"))?;
        }
        let cells: Vec<(usize, usize)> = (0..self.configurations.len())
            .flat_map(|c| (0..self.cases.len()).map(move |k| (c, k)))
            .collect();
        let outcomes: Vec<CellOutcome> = cells
            .par_iter()
            .map(|&(c, k)| {
                self.run_cell(c, k, write, settings)
                    .map_err(|e| MismatchError::Config {
                        path: self.manifest_path.clone(),
                        field: format!("configurations[{c}] × {}", self.cases[k].0),
                        message: format!("demo cell failed: {e}"),
                    })
            })
            .collect::<Result<_>>()?;
        Ok(DemoSummary::new(
            self.manifest
                .configurations
                .iter()
                .zip(&self.configurations)
                .map(|(c, l)| summary::describe_configuration(c, &l.scenario, &l.model_for_tool))
                .collect(),
            self.cases
                .iter()
                .map(|(name, _, purpose)| (name.clone(), purpose.clone()))
                .collect(),
            outcomes,
        ))
    }

    fn run_cell(
        &self,
        configuration: usize,
        case: usize,
        write: &WriteFile,
        settings: &CheckedSettings,
    ) -> Result<CellOutcome> {
        let loaded = &self.configurations[configuration];
        let (name, effects, _) = &self.cases[case];
        let scenario = Scenario {
            effects: *effects,
            seed: loaded.scenario.seed.wrapping_add(1000 * case as u64),
            ..loaded.scenario.clone()
        };
        let dir = self.configuration_dir(configuration).join(name);
        let csv = dir.join("recording.csv");
        let log = simulate(&loaded.model, &scenario, name)?;
        write(&csv, &log.csv_text())?;
        // Blind: the analysis sees only the CSV as written and the model file's contents.
        let recording = data::FlightLog::read_spaced(&csv, data::Spacing::Any)?;
        let model_name = self.configuration_dir(configuration).join("model.json");
        let analysis = analyze(
            &recording,
            &loaded.model_for_tool,
            &model_name.display().to_string(),
            settings,
        )?;
        for (name, contents) in ANALYSIS_FILES.iter().zip(analysis.render(&dir)?) {
            write(&dir.join(name), &contents)?;
        }
        Ok(CellOutcome::judge(
            &self.manifest.configurations[configuration].name,
            name,
            scenario.seed,
            effects,
            &analysis,
        ))
    }
}
