//! Proof on concealed effects: simulate each case of a manifest (the closed loop keeps the position
//! on the reference, so the effect shows only in the dynamics and the control effort), run the
//! analysis blind on the written CSV with only the nominal model, and tabulate true against found.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use physics::{Effects, NominalModel, Scenario, simulate};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::analysis::{AnalysisSettings, analyze};
use crate::error::{MismatchError, Result, io_error};
use crate::output::{check_directory, check_run_outputs, output_paths, write_outputs};

/// One case of the manifest.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct DemoCase {
    pub name: String,
    /// Scenario file, relative to the manifest.
    pub scenario: PathBuf,
    /// What the case shows.
    pub purpose: String,
}

/// The manifest: the cases to run.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct DemoManifest {
    pub cases: Vec<DemoCase>,
}

/// One parameter, true against found.
#[derive(Clone, Debug, Serialize)]
pub struct ParameterCheck {
    pub effect: String,
    pub parameter: String,
    pub truth: serde_json::Value,
    pub found: serde_json::Value,
    /// |found − true| / |true| (vectors: Euclidean norms).
    pub relative_error: f64,
}

/// One case's outcome.
#[derive(Clone, Debug, Serialize)]
pub struct CaseOutcome {
    pub name: String,
    pub purpose: String,
    pub seed: u64,
    pub true_effects: Vec<String>,
    pub found_effects: Vec<String>,
    pub named_correctly: bool,
    pub parameters: Vec<ParameterCheck>,
    pub heldout_mse_before: f64,
    pub heldout_mse_after: f64,
    /// 1 − after / before.
    pub heldout_reduction: f64,
    pub windows: Vec<crate::analysis::Window>,
}

/// All outcomes.
#[derive(Clone, Debug, Serialize)]
pub struct DemoSummary {
    pub cases: Vec<CaseOutcome>,
    pub targets: serde_json::Value,
}

fn load_manifest(path: &Path) -> Result<DemoManifest> {
    let text = std::fs::read_to_string(path).map_err(io_error(path))?;
    let manifest: DemoManifest =
        data::json::from_str(&text).map_err(|e| MismatchError::Config {
            path: path.to_path_buf(),
            field: e.field,
            message: e.message,
        })?;
    manifest.validate(path)?;
    Ok(manifest)
}

impl DemoManifest {
    /// Checks the cases: at least one, and each name a distinct plain directory name (letters,
    /// digits, `_`, `-` and `.`, not starting with `.`, without `..`), since it names the case's
    /// directory under the work directory.
    pub fn validate(&self, origin: &Path) -> Result<()> {
        let bad = |field: String, message: String| MismatchError::Config {
            path: origin.to_path_buf(),
            field,
            message,
        };
        if self.cases.is_empty() {
            return Err(bad("cases".into(), "the manifest lists no cases".into()));
        }
        let mut seen = std::collections::HashSet::new();
        for (i, case) in self.cases.iter().enumerate() {
            let name = &case.name;
            let field = format!("cases[{i}].name");
            if name.is_empty() {
                return Err(bad(field, "must not be empty".into()));
            }
            let plain = name
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.'));
            if !plain || name.starts_with('.') || name.contains("..") {
                return Err(bad(
                    field,
                    format!(
                        "{name:?} is not a plain directory name (letters, digits, '_', '-' and '.'; no path separators, no leading '.', no '..')"
                    ),
                ));
            }
            // Case-insensitive: the directories must differ on every file system.
            if !seen.insert(name.to_ascii_lowercase()) {
                return Err(bad(field, format!("{name:?} is used by an earlier case")));
            }
        }
        Ok(())
    }
}

/// A demo run read and checked, ready to run: the manifest and every case's scenario and model,
/// what the run reads and what it writes (so that a caller can check every output before any
/// work).
#[derive(Clone, Debug)]
pub struct DemoPlan {
    manifest_path: PathBuf,
    manifest: DemoManifest,
    /// Per case: its scenario file, the scenario and its model.
    cases: Vec<(PathBuf, Scenario, NominalModel)>,
    work: PathBuf,
    out: PathBuf,
}

impl DemoPlan {
    /// Reads and checks the manifest and every case's scenario (and its model). Fails if `work` or
    /// `out` exists but is not a directory.
    pub fn load(manifest_path: &Path, work: &Path, out: &Path) -> Result<Self> {
        let manifest = load_manifest(manifest_path)?;
        check_directory(work)?;
        check_directory(out)?;
        let base = manifest_path.parent().unwrap_or(Path::new("."));
        let cases = manifest
            .cases
            .iter()
            .map(|case| {
                let path = base.join(&case.scenario);
                let (scenario, model) = Scenario::load(&path)?;
                Ok((path, scenario, model))
            })
            .collect::<Result<_>>()?;
        Ok(Self {
            manifest_path: manifest_path.to_path_buf(),
            manifest,
            cases,
            work: work.to_path_buf(),
            out: out.to_path_buf(),
        })
    }

    /// Every file the run reads, each with what it is: the manifest, and each case's scenario and
    /// the model that scenario names.
    pub fn inputs(&self) -> Vec<(String, PathBuf)> {
        let mut inputs = vec![(
            "the demo manifest (--demo)".to_string(),
            self.manifest_path.clone(),
        )];
        for (case, (path, scenario, _)) in self.manifest.cases.iter().zip(&self.cases) {
            inputs.push((
                format!("the scenario of demo case {:?}", case.name),
                path.clone(),
            ));
            inputs.push((
                format!("the model of demo case {:?}", case.name),
                scenario.model_path(path),
            ));
        }
        inputs
    }

    /// The summary files, `out/summary.md` and `out/summary.json`.
    pub fn summary_paths(&self) -> [PathBuf; 2] {
        [self.out.join("summary.md"), self.out.join("summary.json")]
    }

    /// Each case's directory, `work/<case>`.
    pub fn case_dirs(&self) -> Vec<PathBuf> {
        self.manifest
            .cases
            .iter()
            .map(|case| self.work.join(&case.name))
            .collect()
    }

    /// The files each case writes in its directory: `recording.csv` and the three files of its
    /// analysis (`mismatch.{json,svg,md}`).
    pub fn case_outputs(&self) -> Vec<PathBuf> {
        self.case_dirs()
            .iter()
            .flat_map(|dir| std::iter::once(dir.join("recording.csv")).chain(output_paths(dir)))
            .collect()
    }

    /// Fails, before any work, if the run would write over a file it reads: a case's directory
    /// that is a summary file (`work` and `out` may be the same directory), or any output that is
    /// one of [`DemoPlan::inputs`] (even with `force`); then if an output cannot be written, or
    /// (unless `force`) exists: the summaries (`--out`) and every case's files (`--work`). See
    /// [`check_run_outputs`].
    pub fn check_outputs(&self, force: bool) -> Result<()> {
        let summaries = self.summary_paths();
        for dir in self.case_dirs() {
            if let Some(summary) = summaries.iter().find(|s| data::paths::same_file(&dir, s)) {
                return Err(MismatchError::CaseDirectoryIsSummary {
                    path: summary.clone(),
                });
            }
        }
        let outputs: Vec<(PathBuf, &str)> = summaries
            .into_iter()
            .map(|p| (p, "--out"))
            .chain(self.case_outputs().into_iter().map(|p| (p, "--work")))
            .collect();
        check_run_outputs(&outputs, &self.inputs(), force)
    }

    /// Runs every case and writes `out/summary.md` and `out/summary.json`; each case writes its
    /// recording and analysis in `work/<case>/` (existing files replaced only with `force`).
    pub fn run(&self, force: bool) -> Result<DemoSummary> {
        let cases: Vec<CaseOutcome> = self
            .manifest
            .cases
            .par_iter()
            .zip(&self.cases)
            .enumerate()
            .map(|(i, (case, (_, scenario, model)))| {
                run_case(case, scenario, model, &self.work, force).map_err(|e| {
                    MismatchError::Config {
                        path: self.manifest_path.clone(),
                        field: format!("cases[{i}]"),
                        message: format!("demo case {:?} failed: {e}", case.name),
                    }
                })
            })
            .collect::<Result<_>>()?;
        let summary = DemoSummary {
            cases,
            targets: serde_json::json!({
                "named_correctly": "every case", "parameters_within": 0.10, "heldout_reduction_at_least": 0.60
            }),
        };
        let [markdown, json] = self.summary_paths();
        std::fs::create_dir_all(&self.out).map_err(io_error(&self.out))?;
        std::fs::write(
            &json,
            serde_json::to_string_pretty(&summary).expect("serialises") + "\n",
        )
        .map_err(io_error(&json))?;
        std::fs::write(&markdown, summary.markdown()).map_err(io_error(&markdown))?;
        Ok(summary)
    }
}

fn run_case(
    case: &DemoCase,
    scenario: &Scenario,
    model: &NominalModel,
    work: &Path,
    force: bool,
) -> Result<CaseOutcome> {
    let dir = work.join(&case.name);
    let csv = dir.join("recording.csv");
    let log = simulate(model, scenario, &case.name)?;
    if !force && csv.exists() {
        return Err(MismatchError::Exists { path: csv });
    }
    log.write_csv(&csv)?;
    // Blind: the analysis sees only the CSV as written and the nominal model.
    let recording = data::FlightLog::read(&csv)?;
    let analysis = analyze(
        &recording,
        model,
        &scenario.model.display().to_string(),
        &AnalysisSettings::default(),
    )?;
    write_outputs(&analysis, &dir, force)?;
    let report = &analysis.report;
    let true_effects: Vec<String> = scenario
        .effects
        .ids()
        .iter()
        .map(|s| s.to_string())
        .collect();
    let found_effects: Vec<String> = analysis
        .fitted
        .ids()
        .iter()
        .map(|s| s.to_string())
        .collect();
    let (before, after) = (report.fit.heldout.before.mse, report.fit.heldout.after.mse);
    Ok(CaseOutcome {
        name: case.name.clone(),
        purpose: case.purpose.clone(),
        seed: scenario.seed,
        named_correctly: true_effects == found_effects,
        parameters: compare_parameters(&scenario.effects, &analysis.fitted),
        true_effects,
        found_effects,
        heldout_mse_before: before,
        heldout_mse_after: after,
        heldout_reduction: 1.0 - after / before.max(1e-300),
        windows: report.windows.clone(),
    })
}

fn numbers(value: &serde_json::Value) -> Vec<f64> {
    match value {
        serde_json::Value::Number(n) => vec![n.as_f64().unwrap_or(f64::NAN)],
        serde_json::Value::Array(a) => a.iter().flat_map(numbers).collect(),
        _ => Vec::new(),
    }
}

/// Relative errors of every parameter of every true effect that was found.
pub fn compare_parameters(truth: &Effects, found: &Effects) -> Vec<ParameterCheck> {
    let truth_json = serde_json::to_value(truth).expect("serialises");
    let found_json = serde_json::to_value(found).expect("serialises");
    let mut checks = Vec::new();
    let Some(true_map) = truth_json.as_object() else {
        return checks;
    };
    for (effect, parameters) in true_map {
        let Some(found_parameters) = found_json.get(effect) else {
            continue;
        };
        for (name, value) in parameters.as_object().into_iter().flatten() {
            let found_value = found_parameters
                .get(name)
                .cloned()
                .unwrap_or(serde_json::Value::Null);
            let (t, f) = (numbers(value), numbers(&found_value));
            let difference: f64 = t
                .iter()
                .zip(&f)
                .map(|(a, b)| (a - b).powi(2))
                .sum::<f64>()
                .sqrt();
            let magnitude: f64 = t.iter().map(|a| a * a).sum::<f64>().sqrt();
            checks.push(ParameterCheck {
                effect: effect.clone(),
                parameter: name.clone(),
                truth: value.clone(),
                found: round_json(&found_value),
                relative_error: difference / magnitude.max(1e-300),
            });
        }
    }
    checks
}

fn round_json(value: &serde_json::Value) -> serde_json::Value {
    match value {
        serde_json::Value::Number(n) => {
            let v = n.as_f64().unwrap_or(f64::NAN);
            serde_json::json!((v * 1e4).round() / 1e4)
        }
        serde_json::Value::Array(a) => serde_json::Value::Array(a.iter().map(round_json).collect()),
        other => other.clone(),
    }
}

fn compact(value: &serde_json::Value) -> String {
    value.to_string().replace(',', ", ")
}

impl DemoSummary {
    /// The per-case table as plain text rows.
    pub fn table_text(&self) -> String {
        let mut text = String::new();
        for c in &self.cases {
            let worst = c
                .parameters
                .iter()
                .map(|p| p.relative_error)
                .fold(0.0, f64::max);
            let _ = writeln!(
                text,
                "{:<22} true [{}] found [{}] {} worst parameter error {:.1}% held-out MSE {:.5} -> {:.5} ({:.0}%)",
                c.name,
                c.true_effects.join(", "),
                c.found_effects.join(", "),
                if c.named_correctly { "OK " } else { "MISS" },
                100.0 * worst,
                c.heldout_mse_before,
                c.heldout_mse_after,
                100.0 * c.heldout_reduction
            );
        }
        text
    }

    /// The summary in Markdown.
    pub fn markdown(&self) -> String {
        let mut md = String::new();
        let _ = writeln!(
            md,
            "# Mismatch tool on simulated recordings with concealed effects\n"
        );
        let _ = writeln!(
            md,
            "Generated by `make mismatch-demo` (`learn mismatch --demo experiments/mismatch/demo.json`). Each case is a closed-loop flight of the simulated plant (nominal model plus the effects listed as true) under a geometric tracking controller with integral action that knows only the nominal model, so the position follows the reference and the effect shows only in the dynamics and the control effort. The tool ran blind on each written CSV with only the nominal model (`experiments/mismatch/demo-quad.json`). The MSEs are of the residual against the smoothed (Savitzky-Golay 21/3) derivative, over all six channels, on the held-out last 30% of the flight.\n"
        );
        let _ = writeln!(
            md,
            "Targets: every effect named correctly, nothing on the no-effect control, parameters within 10%, held-out MSE reduced by at least 60%.\n"
        );
        let _ = writeln!(
            md,
            "| case | purpose | true effects | found effects | named | parameters (true → found, error) | held-out MSE before | after | reduction |\n|---|---|---|---|---|---|---|---|---|"
        );
        for c in &self.cases {
            let parameters: Vec<String> = c
                .parameters
                .iter()
                .map(|p| {
                    format!(
                        "{}.{}: {} → {} ({:.1}%)",
                        p.effect,
                        p.parameter,
                        compact(&p.truth),
                        compact(&p.found),
                        100.0 * p.relative_error
                    )
                })
                .collect();
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {} | {:.5} | {:.5} | {:.1}% |",
                c.name,
                c.purpose,
                if c.true_effects.is_empty() {
                    "none".into()
                } else {
                    c.true_effects.join(", ")
                },
                if c.found_effects.is_empty() {
                    "none".into()
                } else {
                    c.found_effects.join(", ")
                },
                if c.named_correctly { "yes" } else { "**no**" },
                if parameters.is_empty() {
                    "–".into()
                } else {
                    parameters.join("; ")
                },
                c.heldout_mse_before,
                c.heldout_mse_after,
                100.0 * c.heldout_reduction
            );
        }
        let named = self.cases.iter().filter(|c| c.named_correctly).count();
        let parameters: Vec<&ParameterCheck> =
            self.cases.iter().flat_map(|c| &c.parameters).collect();
        let within = parameters
            .iter()
            .filter(|p| p.relative_error <= 0.10)
            .count();
        let with_effect: Vec<&CaseOutcome> = self
            .cases
            .iter()
            .filter(|c| !c.true_effects.is_empty())
            .collect();
        let reduced = with_effect
            .iter()
            .filter(|c| c.heldout_reduction >= 0.60)
            .count();
        let _ = writeln!(md, "\n## Against the targets\n");
        let _ = writeln!(
            md,
            "- Named correctly: {named} of {} cases.",
            self.cases.len()
        );
        let _ = writeln!(
            md,
            "- Parameters within 10%: {within} of {} (of the effects that were found).",
            parameters.len()
        );
        let _ = writeln!(
            md,
            "- Held-out MSE reduced by at least 60%: {reduced} of {} cases with an effect.",
            with_effect.len()
        );
        let misses: Vec<String> = self
            .cases
            .iter()
            .filter(|c| {
                !c.named_correctly
                    || c.parameters.iter().any(|p| p.relative_error > 0.10)
                    || (!c.true_effects.is_empty() && c.heldout_reduction < 0.60)
            })
            .map(|c| c.name.clone())
            .collect();
        if misses.is_empty() {
            let _ = writeln!(md, "- Every target is met in every case.");
        } else {
            let _ = writeln!(md, "- Cases that miss a target: {}.", misses.join(", "));
        }
        let _ = writeln!(
            md,
            "\nPer-case outputs (recording, mismatch.json/svg/md) are written under the demo's work directory (`target/mismatch-demo/<case>/`, not committed)."
        );
        md
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn manifest(names: &[&str]) -> DemoManifest {
        DemoManifest {
            cases: names
                .iter()
                .map(|name| DemoCase {
                    name: name.to_string(),
                    scenario: "scenarios/control.json".into(),
                    purpose: "test".into(),
                })
                .collect(),
        }
    }

    fn rejected(names: &[&str]) -> String {
        let error = manifest(names)
            .validate(Path::new("demo.json"))
            .unwrap_err()
            .to_string();
        assert!(
            error.starts_with("demo.json: field '") && !error.contains('\n'),
            "{error}"
        );
        error
    }

    #[test]
    fn case_names_must_be_distinct_plain_directory_names() {
        manifest(&["control", "linear_drag", "drag-2", "v1.5"])
            .validate(Path::new("demo.json"))
            .unwrap();
        assert!(rejected(&["control", ""]).contains("cases[1].name"));
        assert!(rejected(&["/tmp/x"]).contains("cases[0].name"));
        assert!(rejected(&["../../escape"]).contains("cases[0].name"));
        assert!(rejected(&["a/b"]).contains("cases[0].name"));
        assert!(rejected(&["a\\b"]).contains("cases[0].name"));
        assert!(rejected(&[".."]).contains("cases[0].name"));
        assert!(rejected(&["a..b"]).contains("cases[0].name"));
        assert!(rejected(&[".hidden"]).contains("cases[0].name"));
        let duplicate = rejected(&["control", "drag", "control"]);
        assert!(
            duplicate.contains("cases[2].name") && duplicate.contains("earlier case"),
            "{duplicate}"
        );
        assert!(rejected(&["Control", "control"]).contains("cases[1].name"));
        assert!(rejected(&[]).contains("field 'cases'"));
    }

    /// Every scenario is read and checked before any case is simulated: a bad second case leaves
    /// the work directory untouched and names its own file and field.
    #[test]
    fn a_bad_scenario_fails_before_any_case_runs() {
        let dir = std::env::temp_dir().join(format!("mismatch-demo-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let workspace = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        let good =
            std::fs::read_to_string(workspace.join("experiments/mismatch/scenarios/control.json"))
                .unwrap();
        let model = workspace.join("experiments/mismatch/demo-quad.json");
        let mut scenario: serde_json::Value = serde_json::from_str(&good).unwrap();
        scenario["model"] = serde_json::json!(model);
        std::fs::write(dir.join("good.json"), scenario.to_string()).unwrap();
        scenario["gains"] = serde_json::json!({"integral_limit": -1});
        std::fs::write(dir.join("bad.json"), scenario.to_string()).unwrap();
        std::fs::write(
            dir.join("demo.json"),
            r#"{"cases": [{"name": "good", "scenario": "good.json", "purpose": "p"},
                          {"name": "bad", "scenario": "bad.json", "purpose": "p"}]}"#,
        )
        .unwrap();
        let work = dir.join("work");
        let error = DemoPlan::load(&dir.join("demo.json"), &work, &dir.join("out"))
            .unwrap_err()
            .to_string();
        assert!(
            error.contains("bad.json: field 'gains.integral_limit'"),
            "{error}"
        );
        assert!(!work.exists(), "a case ran before the check");
        assert!(!dir.join("out").exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The plan names every file the demo reads and writes, and a user's file in a case directory
    /// is replaced only with `force`, refused before any case runs.
    #[test]
    fn the_plan_lists_inputs_and_outputs_and_protects_files_in_work() {
        let dir = std::env::temp_dir().join(format!("mismatch-demo-plan-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let workspace = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        std::fs::copy(
            workspace.join("experiments/mismatch/demo-quad.json"),
            dir.join("quad.json"),
        )
        .unwrap();
        let mut scenario: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(workspace.join("experiments/mismatch/scenarios/control.json"))
                .unwrap(),
        )
        .unwrap();
        scenario["model"] = serde_json::json!("quad.json");
        std::fs::write(dir.join("control.json"), scenario.to_string()).unwrap();
        std::fs::write(
            dir.join("demo.json"),
            r#"{"cases": [{"name": "control", "scenario": "control.json", "purpose": "p"}]}"#,
        )
        .unwrap();
        let (work, out) = (dir.join("work"), dir.join("out"));
        let plan = DemoPlan::load(&dir.join("demo.json"), &work, &out).unwrap();
        let inputs: Vec<PathBuf> = plan.inputs().into_iter().map(|(_, p)| p).collect();
        assert_eq!(
            inputs,
            [
                dir.join("demo.json"),
                dir.join("control.json"),
                dir.join("quad.json")
            ]
        );
        assert_eq!(
            plan.summary_paths(),
            [out.join("summary.md"), out.join("summary.json")]
        );
        let case = work.join("control");
        assert_eq!(
            plan.case_outputs(),
            [
                case.join("recording.csv"),
                case.join("mismatch.json"),
                case.join("mismatch.svg"),
                case.join("mismatch.md")
            ]
        );
        plan.check_outputs(false).unwrap();
        std::fs::create_dir_all(&case).unwrap();
        std::fs::write(case.join("mismatch.md"), "notes").unwrap();
        let error = plan.check_outputs(false).unwrap_err();
        assert!(
            matches!(&error, MismatchError::Exists { path } if *path == case.join("mismatch.md")),
            "{error}"
        );
        assert_eq!(
            std::fs::read_to_string(case.join("mismatch.md")).unwrap(),
            "notes"
        );
        assert!(!case.join("recording.csv").exists() && !out.exists());
        plan.check_outputs(true).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
