//! Writing an analysis: `mismatch.json`, `mismatch.svg` (residual per channel before and after,
//! located windows shaded) and `mismatch.md` (plain words).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use plotters::prelude::*;

use crate::analysis::{Analysis, Report, check_finite};
use crate::error::{MismatchError, Result, io_error};
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
    std::fs::write(&markdown, markdown_text(analysis)).map_err(io_error(&markdown))?;
    Ok(())
}

fn units(channel: usize) -> &'static str {
    if channel < 3 { "m/s²" } else { "rad/s²" }
}

/// The span of an axis drawn from `lo` to `hi`, when it can be drawn: both ends finite and `lo` below
/// `hi` by a finite, normal (not subnormal) difference. Plotting libraries compute tick marks by
/// dividing such spans, and loop forever on infinite ones.
fn drawable(lo: f64, hi: f64) -> bool {
    let span = hi - lo;
    lo.is_finite() && hi.is_finite() && span.is_normal() && span > 0.0
}

/// Each channel's plotted range; the error says what cannot be drawn.
fn drawable_ranges(analysis: &Analysis) -> std::result::Result<Vec<(f64, f64)>, String> {
    let problem = &analysis.problem;
    let channels = problem.channels;
    let time = &problem.time;
    if time.is_empty()
        || analysis.before.len() != time.len()
        || analysis.after.len() != time.len()
        || channels > CHANNEL_NAMES.len()
    {
        return Err(format!(
            "{} times, {} and {} residual rows for {channels} channels",
            time.len(),
            analysis.before.len(),
            analysis.after.len()
        ));
    }
    if !drawable(time[0], time[time.len() - 1]) || time.iter().any(|t| !t.is_finite()) {
        return Err(format!(
            "the time axis from {} to {} s cannot be drawn",
            time[0],
            time[time.len() - 1]
        ));
    }
    let mut ranges = Vec::with_capacity(channels);
    for c in 0..channels {
        let values = analysis.before.iter().chain(&analysis.after).map(|r| r[c]);
        let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
        let margin = 0.05 * (hi - lo).max(1e-9);
        let (lo, hi) = (lo - margin, hi + margin);
        let finite = analysis
            .before
            .iter()
            .chain(&analysis.after)
            .all(|r| r[c].is_finite());
        if !finite || !drawable(lo, hi) {
            return Err(format!(
                "the residual of {} is not finite or spans no drawable range ({lo} to {hi})",
                CHANNEL_NAMES[c]
            ));
        }
        ranges.push((lo, hi));
    }
    let windows_drawable = analysis
        .report
        .windows
        .iter()
        .all(|w| w.t_start.is_finite() && w.t_end.is_finite());
    if !windows_drawable {
        return Err("a located window has a non-finite time".to_string());
    }
    Ok(ranges)
}

/// The figure: one panel per channel. Fails, without drawing, unless the data are finite and every
/// axis spans a drawable range (finite ends, a normal positive span).
pub fn write_figure(analysis: &Analysis, path: &Path) -> Result<()> {
    let plot_error = |e: &dyn std::fmt::Display| MismatchError::Plot {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let ranges = drawable_ranges(analysis).map_err(|message| plot_error(&message))?;
    let problem = &analysis.problem;
    let channels = problem.channels;
    let time = &problem.time;
    let root = SVGBackend::new(path, (1100, 60 + 190 * channels as u32)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| plot_error(&e))?;
    let (title, body) = root.split_vertically(50);
    title
        .titled(
            "Weak-form residual (recording − model): nominal model in grey, with the found effects in blue; located windows shaded; held-out part right of the dashed line",
            ("sans-serif", 15),
        )
        .map_err(|e| plot_error(&e))?;
    let panels = body.split_evenly((channels, 1));
    let (t0, t1) = (time[0], time[time.len() - 1]);
    let split_time = time[problem.split.min(time.len() - 1)];
    for (c, panel) in panels.iter().enumerate() {
        let (lo, hi) = ranges[c];
        let mut chart = ChartBuilder::on(panel)
            .margin(8)
            .x_label_area_size(28)
            .y_label_area_size(60)
            .caption(
                format!("{} ({})", CHANNEL_NAMES[c], units(c)),
                ("sans-serif", 14),
            )
            .build_cartesian_2d(t0..t1, lo..hi)
            .map_err(|e| plot_error(&e))?;
        chart
            .configure_mesh()
            .x_desc("t (s)")
            .light_line_style(WHITE)
            .draw()
            .map_err(|e| plot_error(&e))?;
        for window in analysis
            .report
            .windows
            .iter()
            .filter(|w| w.channel == CHANNEL_NAMES[c])
        {
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(window.t_start, lo), (window.t_end, hi)],
                    RGBColor(255, 200, 200).mix(0.5).filled(),
                )))
                .map_err(|e| plot_error(&e))?;
        }
        chart
            .draw_series(LineSeries::new(
                time.iter().zip(&analysis.before).map(|(t, r)| (*t, r[c])),
                RGBColor(150, 150, 150).stroke_width(1),
            ))
            .map_err(|e| plot_error(&e))?
            .label("nominal model")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 15, y)], RGBColor(150, 150, 150)));
        chart
            .draw_series(LineSeries::new(
                time.iter().zip(&analysis.after).map(|(t, r)| (*t, r[c])),
                RGBColor(30, 90, 200).stroke_width(1),
            ))
            .map_err(|e| plot_error(&e))?
            .label("with found effects")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 15, y)], RGBColor(30, 90, 200)));
        chart
            .draw_series(DashedLineSeries::new(
                [(split_time, lo), (split_time, hi)],
                4,
                4,
                BLACK.stroke_width(1),
            ))
            .map_err(|e| plot_error(&e))?;
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(|e| plot_error(&e))?;
    }
    root.present().map_err(|e| plot_error(&e))?;
    Ok(())
}

/// The report in plain words.
pub fn markdown_text(analysis: &Analysis) -> String {
    let mut md = String::new();
    header_markdown(&analysis.report, &mut md);
    disagreement_markdown(analysis, &mut md);
    effects_markdown(&analysis.report, &mut md);
    candidates_markdown(&analysis.report, &mut md);
    fit_markdown(&analysis.report, &mut md);
    md
}

/// The title, the comparison and the frame of the body rates.
fn header_markdown(report: &Report, md: &mut String) {
    let _ = writeln!(md, "# Sim-to-real mismatch: {}\n", report.recording);
    let _ = writeln!(
        md,
        "Nominal model: `{}`. The recording's velocity and body rate are compared with what the nominal model predicts from the recorded attitude and commands in the weak form: both weighted by the same smooth test function over ±0.2 s, so that a right model leaves only noise. Every mean squared error below is of that weak-form residual.\n",
        report.model
    );
    let frame = match report.rate_frame.used {
        data::RateFrame::Body => "the body frame",
        data::RateFrame::World => "the world frame (converted to body rates)",
    };
    let _ = writeln!(
        md,
        "The `w` column was read in {frame}: it matches the rate implied by the recorded attitude with an RMS error of {:.4} rad/s in the body frame and {:.4} rad/s in the world frame.\n",
        report.rate_frame.body_rms, report.rate_frame.world_rms
    );
}

/// The channels against their noise floors and the stretches that disagree.
fn disagreement_markdown(analysis: &Analysis, md: &mut String) {
    let report = &analysis.report;
    let _ = writeln!(md, "## Where the model and the recording disagree\n");
    let _ = writeln!(
        md,
        "| channel | residual RMS | noise floor | significant |\n|---|---|---|---|"
    );
    for c in &report.channels {
        let _ = writeln!(
            md,
            "| {} | {:.4} | {:.4} | {} |",
            c.name,
            c.residual_rms,
            c.noise_floor,
            if c.significant { "yes" } else { "no" }
        );
    }
    if analysis.problem.channels == 3 {
        let _ = writeln!(
            md,
            "\nThe model has no mixer, so it predicts no torques: only the translational channels are compared."
        );
    }
    if report.windows.is_empty() {
        let _ = writeln!(
            md,
            "\nNo stretch of the flight disagrees by more than {:.1} times the noise floor.",
            report.settings.window_factor
        );
    } else {
        let _ = writeln!(
            md,
            "\nStretches where the residual exceeds {:.1} times the noise floor (1 s moving RMS):\n",
            report.settings.window_factor
        );
        for w in &report.windows {
            let _ = writeln!(
                md,
                "- {} from {:.1} s to {:.1} s",
                w.channel, w.t_start, w.t_end
            );
        }
    }
}

/// The evidence rule, the effects named and those not named, what remains unexplained.
fn effects_markdown(report: &Report, md: &mut String) {
    let _ = writeln!(md, "\n## What is missing from the model\n");
    let rule = report.settings.evidence;
    let _ = writeln!(
        md,
        "An effect is named only when, with the others refitted without it, it passes four tests: on the fit part, its likelihood ratio (corrected for the correlation of neighbouring rows) exceeds the {} quantile of χ², it lowers the noise-normalised residual by at least {} per row and channel, and by at least {} when the two {} s blocks that gain most are left out (not one transient); and it lowers the held-out residual by at least {:.0}%.\n",
        rule.significance,
        rule.min_gain,
        rule.min_trimmed_gain,
        report.settings.block_s,
        100.0 * rule.min_heldout_reduction
    );
    if report.effects.is_empty() {
        let _ = writeln!(
            md,
            "Nothing: no candidate term explains the residual clearly better than noise."
        );
    } else {
        for e in &report.effects {
            let _ = writeln!(
                md,
                "- **{}** — {} It accounts for {:.0}% of the nominal model's (noise-normalised) residual; without it the held-out residual is {:.0}% higher (likelihood ratio {:.0} against {:.1}, gain {:.2} per row and channel, {:.2} without its two largest blocks).",
                e.id,
                e.description,
                100.0 * e.explained_fraction,
                100.0 * (e.evidence.heldout_without / e.evidence.heldout_with.max(1e-300) - 1.0),
                e.evidence.likelihood_ratio,
                e.evidence.likelihood_ratio_threshold,
                e.evidence.fit_gain,
                e.evidence.trimmed_gain
            );
        }
    }
    for d in &report.selection.dropped {
        let _ = writeln!(
            md,
            "- not named: {} (likelihood ratio {:.1} against {:.1}, gain {:.3}, {:.3} without its two largest blocks, held-out reduction {:.1}%): below the evidence rule.",
            d.id,
            d.likelihood_ratio,
            d.likelihood_ratio_threshold,
            d.fit_gain,
            d.trimmed_gain,
            100.0 * d.heldout_reduction
        );
    }
    if report.unexplained.is_empty() {
        let _ = writeln!(
            md,
            "\nWith the effects named, no stretch of the flight disagrees by more than {:.1} times the noise floor.",
            report.settings.window_factor
        );
    } else {
        let _ = writeln!(
            md,
            "\nA significant residual remains that no effect of the vocabulary explains:\n"
        );
        for w in &report.unexplained {
            let _ = writeln!(
                md,
                "- unexplained residual on {}, {:.1}–{:.1} s",
                w.channel, w.t_start, w.t_end
            );
        }
    }
}

/// Every candidate with its selection frequency, and the command-rate alternatives.
fn candidates_markdown(report: &Report, md: &mut String) {
    let _ = writeln!(
        md,
        "\nCandidates and how often each was chosen in {} bootstrap resamples:\n",
        report.selection.settings.resamples
    );
    for c in &report.selection.candidates {
        let terms: Vec<String> = c
            .candidate
            .terms
            .iter()
            .map(|t| format!("`{}` = {} [{}]", t.name, t.formula, t.units))
            .collect();
        let _ = writeln!(
            md,
            "- {} ({}): {:.0}%{}",
            c.candidate.id,
            terms.join(", "),
            100.0 * c.selection_frequency,
            if c.kept { ", kept" } else { "" }
        );
    }
    if let Some(timing) = &report.selection.alternatives.timing {
        let _ = writeln!(
            md,
            "\nThe command-rate term was resolved by fitting a pure delay, a first-order motor lag and both exactly; noise-normalised fit errors: {}. The smallest was kept, then judged by the evidence rule.",
            serde_json::Value::Object(timing.clone())
        );
    }
}

/// The fit and held-out errors before and after.
fn fit_markdown(report: &Report, md: &mut String) {
    let fit = &report.fit;
    let reduction = |before: f64, after: f64| 100.0 * (1.0 - after / before.max(1e-300));
    let _ = writeln!(md, "\n## Does the fit improve?\n");
    let _ = writeln!(
        md,
        "The parameters were fitted on {:.1}–{:.1} s and checked on the held-out {:.1}–{:.1} s.\n",
        fit.t_start, fit.t_end, fit.heldout.t_start, fit.heldout.t_end
    );
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
