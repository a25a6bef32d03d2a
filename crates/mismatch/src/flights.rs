//! The analysis on the real Neural-Fly flights: the evaluation controller's flight at every wind
//! condition of the experiment's conditions file.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use data::ExperimentConditions;
use physics::NominalModel;

use crate::analysis::{AnalysisSettings, Report, analyze};
use crate::error::{MismatchError, Result, io_error};
use crate::output::{check_directory, check_run_outputs, output_paths, write_outputs};

/// The analysis of every condition's evaluation flight, read and checked, ready to run: which
/// flights are present, what the run reads and what it writes (so that a caller can check every
/// output before any work).
#[derive(Clone, Debug)]
pub struct FlightsPlan {
    conditions_path: PathBuf,
    conditions: ExperimentConditions,
    /// Per condition (in the file's order), its evaluation flight and whether it is present.
    flights: Vec<(PathBuf, bool)>,
    out: PathBuf,
}

impl FlightsPlan {
    /// Reads the conditions file and looks for each condition's evaluation flight under
    /// `data_dir`. Fails if `out` exists but is not a directory, or if not a single flight is
    /// present (the error names the data directory); a condition whose flight is missing is
    /// reported by [`FlightsPlan::run`] and skipped.
    pub fn load(conditions_path: &Path, data_dir: &Path, out: &Path) -> Result<Self> {
        let conditions = ExperimentConditions::load(conditions_path)?;
        check_directory(out)?;
        let flights: Vec<(PathBuf, bool)> = conditions
            .conditions
            .iter()
            .map(|condition| {
                let path =
                    conditions.flight_path(data_dir, condition, &conditions.evaluation_controller);
                let present = path.exists();
                (path, present)
            })
            .collect();
        if !flights.iter().any(|(_, present)| *present) {
            return Err(MismatchError::NoFlights {
                data_dir: data_dir.to_path_buf(),
                conditions: conditions_path.to_path_buf(),
                count: flights.len(),
                example: flights.first().map(|(path, _)| path.clone()),
            });
        }
        Ok(Self {
            conditions_path: conditions_path.to_path_buf(),
            conditions,
            flights,
            out: out.to_path_buf(),
        })
    }

    /// Every file the run reads, each with what it is: the conditions file and every present
    /// flight (the model is the caller's).
    pub fn inputs(&self) -> Vec<(String, PathBuf)> {
        let mut inputs = vec![(
            "the conditions file (--flights)".to_string(),
            self.conditions_path.clone(),
        )];
        for (condition, (path, present)) in self.conditions.conditions.iter().zip(&self.flights) {
            if *present {
                inputs.push((
                    format!("the {} evaluation flight", condition.name),
                    path.clone(),
                ));
            }
        }
        inputs
    }

    /// The summary, `out/neural-fly.md`.
    pub fn summary_path(&self) -> PathBuf {
        self.out.join("neural-fly.md")
    }

    /// Every file the run writes: the summary and the three files of each present flight's
    /// analysis, `out/neural-fly/<condition>/mismatch.{json,svg,md}`.
    pub fn outputs(&self) -> Vec<PathBuf> {
        let mut outputs = vec![self.summary_path()];
        for (condition, (_, present)) in self.conditions.conditions.iter().zip(&self.flights) {
            if *present {
                outputs.extend(output_paths(&self.condition_dir(&condition.name)));
            }
        }
        outputs
    }

    fn condition_dir(&self, name: &str) -> PathBuf {
        self.out.join("neural-fly").join(name)
    }

    /// Fails, before any work, if an output is one of the files the run reads ([`FlightsPlan::inputs`]
    /// and the nominal model at `model`), even with `force`; then if an output cannot be written,
    /// or (unless `force`) exists. See [`check_run_outputs`].
    pub fn check_outputs(&self, model: &Path, force: bool) -> Result<()> {
        let mut inputs = self.inputs();
        inputs.push(("the --model file".to_string(), model.to_path_buf()));
        let outputs: Vec<(PathBuf, &str)> =
            self.outputs().into_iter().map(|p| (p, "--out")).collect();
        check_run_outputs(&outputs, &inputs, force)
    }

    /// Analyses each present flight, writes `out/neural-fly/<condition>/mismatch.*` and
    /// `out/neural-fly.md`; returns one printed line per flight.
    pub fn run(&self, model: &NominalModel, model_name: &str, force: bool) -> Result<Vec<String>> {
        let conditions = &self.conditions;
        let mut rows: Vec<(String, String, Option<Report>)> = Vec::new();
        let mut lines = Vec::new();
        for (condition, (path, present)) in conditions.conditions.iter().zip(&self.flights) {
            if !present {
                lines.push(format!(
                    "{}: {} is missing, skipped",
                    condition.name,
                    path.display()
                ));
                rows.push((
                    condition.label().to_string(),
                    condition.wind_speed.clone(),
                    None,
                ));
                continue;
            }
            let dir = self.condition_dir(&condition.name);
            let log = data::FlightLog::read(path)?;
            let analysis = analyze(&log, model, model_name, &AnalysisSettings::default())?;
            write_outputs(&analysis, &dir, force)?;
            let report = analysis.report;
            let names: Vec<&str> = report.effects.iter().map(|e| e.id.as_str()).collect();
            lines.push(format!(
                "{}: effects [{}], held-out MSE {:.4} -> {:.4}",
                condition.name,
                names.join(", "),
                report.fit.heldout.before.mse,
                report.fit.heldout.after.mse
            ));
            rows.push((
                condition.label().to_string(),
                condition.wind_speed.clone(),
                Some(report),
            ));
        }
        let summary_path = self.summary_path();
        std::fs::create_dir_all(&self.out).map_err(io_error(&self.out))?;
        std::fs::write(
            &summary_path,
            markdown(&rows, model_name, &conditions.evaluation_controller),
        )
        .map_err(io_error(&summary_path))?;
        lines.push(format!("wrote {}", summary_path.display()));
        Ok(lines)
    }
}

/// `c |w_air|²` when quadratic drag (with or without wind) was found.
fn drag_at_rest(report: &Report) -> Option<f64> {
    let c = report
        .effects
        .iter()
        .find(|e| e.id == "quadratic_drag")?
        .parameters["c"]
        .as_f64()?;
    let wind = report
        .effects
        .iter()
        .find(|e| e.id == "wind")
        .and_then(|e| e.parameters["w_air"].as_array().cloned())
        .unwrap_or_default();
    let speed_squared: f64 = wind.iter().filter_map(|v| v.as_f64()).map(|v| v * v).sum();
    Some(c * speed_squared)
}

fn markdown(
    rows: &[(String, String, Option<Report>)],
    model_name: &str,
    controller: &str,
) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "# Mismatch tool on the Neural-Fly flights\n");
    let _ = writeln!(
        md,
        "Generated by `make mismatch-demo` (`learn mismatch --flights experiments/conditions.json --model {model_name}`): the `{controller}` figure-8 flight at every wind condition, analysed with the nominal model m = 2.644 kg, T = m g T_sp / hover_throttle (thrust only: the model has no mixer, so only the translational channels vdot_x, vdot_y, vdot_z are compared). Fit on the first 70% of each flight, MSEs of the residual against the smoothed (Savitzky-Golay 21/3) derivative, in (m/s²)². Per-flight reports and figures: `neural-fly/<condition>/mismatch.{{md,svg,json}}`.\n"
    );
    let _ = writeln!(
        md,
        "| condition | wind speed | significant channels | effects found (parameters) | drag at hover c·‖w_air‖² (m/s²) | held-out MSE nominal | with effects | reduction |\n|---|---|---|---|---|---|---|---|"
    );
    for (label, speed, report) in rows {
        let Some(report) = report else {
            let _ = writeln!(md, "| {label} | {speed} | flight missing | | | | | |");
            continue;
        };
        let significant: Vec<&str> = report
            .channels
            .iter()
            .filter(|c| c.significant)
            .map(|c| c.name.as_str())
            .collect();
        let effects: Vec<String> = report
            .effects
            .iter()
            .map(|e| {
                format!(
                    "{} {} ({:.0}%)",
                    e.id,
                    e.parameters.to_string().replace(',', ", "),
                    100.0 * e.explained_fraction
                )
            })
            .collect();
        let (before, after) = (report.fit.heldout.before.mse, report.fit.heldout.after.mse);
        let drag = drag_at_rest(report)
            .map(|d| format!("{d:.2}"))
            .unwrap_or_else(|| "–".into());
        let _ = writeln!(
            md,
            "| {label} | {speed} | {} | {} | {drag} | {before:.4} | {after:.4} | {:.1}% |",
            if significant.is_empty() {
                "none".into()
            } else {
                significant.join(", ")
            },
            if effects.is_empty() {
                "none".into()
            } else {
                effects.join("; ")
            },
            100.0 * (1.0 - after / before.max(1e-300))
        );
    }
    let _ = writeln!(
        md,
        "\nThe percentage after each effect is the share of the nominal model's noise-normalised residual (fit part) it removes.\n"
    );
    let _ = writeln!(md, "## In plain words\n");
    for (label, speed, report) in rows {
        let Some(report) = report else { continue };
        let _ = write!(md, "- **{label}** ({speed}): ");
        if report.effects.is_empty() {
            let _ = writeln!(md, "nothing beyond noise was found.");
        } else {
            let sentences: Vec<&str> = report
                .effects
                .iter()
                .map(|e| e.description.as_str())
                .collect();
            let _ = writeln!(md, "{}", sentences.join(" "));
        }
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("mismatch-flights-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("data/experiment")).unwrap();
        dir
    }

    fn conditions() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../experiments/conditions.json")
    }

    #[test]
    fn no_flight_at_all_is_an_error_naming_the_data_directory() {
        let dir = scratch("none");
        let data = dir.join("data");
        let error = FlightsPlan::load(&conditions(), &data, &dir.join("out")).unwrap_err();
        let message = error.to_string();
        assert!(
            matches!(error, MismatchError::NoFlights { .. }),
            "{message}"
        );
        assert!(
            message.starts_with(&format!("{}: ", data.display())),
            "{message}"
        );
        assert!(!message.contains('\n'), "{message}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Only the present flights are inputs and have outputs; an existing output of a later flight
    /// is refused by the check that comes before any analysis.
    #[test]
    fn the_plan_lists_the_present_flights_and_checks_every_output() {
        let dir = scratch("some");
        let data = dir.join("data");
        for condition in ["nowind", "70wind"] {
            std::fs::write(
                data.join(format!(
                    "experiment/custom_figure8_baseline_{condition}.csv"
                )),
                "",
            )
            .unwrap();
        }
        let out = dir.join("out");
        let plan = FlightsPlan::load(&conditions(), &data, &out).unwrap();
        let model = dir.join("quad.json");
        let inputs: Vec<PathBuf> = plan.inputs().into_iter().map(|(_, p)| p).collect();
        assert_eq!(
            inputs,
            [
                conditions(),
                data.join("experiment/custom_figure8_baseline_nowind.csv"),
                data.join("experiment/custom_figure8_baseline_70wind.csv"),
            ]
        );
        let outputs = plan.outputs();
        assert_eq!(outputs.len(), 1 + 2 * 3);
        assert_eq!(outputs[0], out.join("neural-fly.md"));
        assert!(outputs.contains(&out.join("neural-fly/70wind/mismatch.svg")));
        plan.check_outputs(&model, false).unwrap();
        std::fs::create_dir_all(out.join("neural-fly/70wind")).unwrap();
        std::fs::write(out.join("neural-fly/70wind/mismatch.svg"), "mine").unwrap();
        let error = plan.check_outputs(&model, false).unwrap_err();
        assert!(
            matches!(&error, MismatchError::Exists { path } if *path == out.join("neural-fly/70wind/mismatch.svg")),
            "{error}"
        );
        plan.check_outputs(&model, true).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
