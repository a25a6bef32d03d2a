//! The whole analysis of one recording: compare, locate, explain, fit, judge the evidence, validate
//! on held-out data; its files ([`files`]); a recording longer than one analysis, in parts
//! ([`parts`]).

pub(crate) mod files;
pub mod parts;
mod report_json;

pub use report_json::{EffectReport, Report};
use report_json::{Named, Screen, build_report};

use data::FlightLog;
use physics::vector::Vec3;
use physics::{Effects, NominalModel};
pub use report::mismatch::recording::{ChannelReport, Fit, RateFrame, Window};
use sindy::stability::stability_selection;

use crate::error::{MismatchError, Result};
use crate::explain::confounds::{self, Separate};
use crate::explain::evidence;
use crate::explain::fit::{
    Screened, fit_parameters, leave_out_below_resolution, profile_nonlinear,
};
use crate::explain::library::build_library;
use crate::improve::estimate;
use crate::locate::forward;
use crate::locate::problem::{CHANNEL_NAMES, Channels, Problem};
use crate::locate::response::{AngularResponse, angular_response};
use crate::locate::windows::Residuals;
use crate::recording::Recording;
use crate::recording::content::{self, LogContent};
use crate::recording::degenerate;
use crate::recording::noise_reaction;
use crate::settings::{CheckedSettings, NoiseFree};

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
    // What the log holds is the same for both passes.
    let log_content = content::measure(log);
    let logged = Logged {
        log,
        content: log_content.as_ref(),
    };
    let recording = Recording::new(log, model, 40)?;
    let first = analyze_recording(recording, &logged, model, model_name, settings, &|stage| {
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
    analyze_recording(recording, &logged, model, model_name, settings, &|stage| {
        observe(2, stage)
    })
}

/// A log and what it holds ([`content::measure`]).
struct Logged<'a> {
    log: &'a FlightLog,
    content: Option<&'a LogContent>,
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
    logged: &Logged,
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
    let below_resolution = match logged.content.and_then(|c| c.timing_limit_s) {
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
        logged.log,
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
            log_content: logged.content.cloned(),
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
