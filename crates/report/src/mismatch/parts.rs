//! A recording longer than one analysis, analysed in consecutive parts (`mismatch.md` and
//! `mismatch.svg` of `learn mismatch --recording` on a long recording): every part's effects and
//! held-out errors, and each effect's parameters pooled over the parts that named it, with how
//! much they vary between parts.

use std::fmt::Write as _;
use std::path::Path;

use plotters::prelude::*;
use serde::{Deserialize, Serialize};

use super::text;
use crate::error::{ReportError, Result};

/// One part's value of one parameter number, with its standard error when the part gave one.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PartValue {
    pub value: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub standard_error: Option<f64>,
}

/// One number of a parameter, pooled over the parts that named its effect.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PooledNumber {
    /// The inverse-variance weighted mean of the parts' values (their plain mean when a part gave
    /// no standard error).
    pub value: f64,
    /// The pooled value's standard error from the parts' (absent when a part gave none).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub standard_error: Option<f64>,
    /// Every part's value, in order; `None` where the part did not name the effect.
    pub per_part: Vec<Option<PartValue>>,
    /// `χ²` of the parts' values about the pooled one over its degrees of freedom (absent with
    /// fewer than two values or without standard errors).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub chi_square_per_dof: Option<f64>,
    /// The parts disagree by more than their noise: `χ²` beyond its 99.9 % quantile.
    pub varies: bool,
}

/// One parameter of a pooled effect: its name and numbers (a vector's in order).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PooledParameter {
    pub name: String,
    pub numbers: Vec<PooledNumber>,
}

/// An effect named in at least one part.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PooledEffect {
    pub id: String,
    /// How many of the analysed parts named it.
    pub named_in: usize,
    /// Named for the whole recording: in more than half of the analysed parts.
    pub named: bool,
    pub parameters: Vec<PooledParameter>,
}

/// One part as the summary lists it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PartLine {
    /// Data rows `[start, end)` of the analysed rows, counted from 0 (from the start of the
    /// `--rows` range when one was given).
    pub rows: [usize; 2],
    pub t_start: f64,
    pub t_end: f64,
    /// The effects the part named (empty when it named none or was not analysed).
    pub named: Vec<String>,
    /// Held-out MSE of the nominal model and of the part's fitted model (absent when refused).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub heldout: Option<[f64; 2]>,
    /// Why the part could not be analysed (a part where nothing moves, say).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub refused: Option<String>,
}

/// What the summary of a long recording shows.
#[derive(Clone, Debug)]
pub struct PartsView<'a> {
    pub recording: &'a str,
    pub model: &'a str,
    /// Data rows in the recording (or in the `--rows` range analysed).
    pub rows: usize,
    /// The most rows one part holds.
    pub part_rows: usize,
    pub parts: &'a [PartLine],
    pub effects: &'a [PooledEffect],
    /// Held-out MSE before and after, averaged over the analysed parts (weighted by their rows).
    pub heldout: Option<[f64; 2]>,
}

impl PartsView<'_> {
    /// The summary in Markdown; `figure` is the figure's file name, linked from the text.
    pub fn markdown(&self, figure: &str) -> String {
        let mut md = String::new();
        let analysed = self.parts.iter().filter(|p| p.refused.is_none()).count();
        let _ = writeln!(md, "# Mismatch analysis of a long recording, in parts\n");
        let _ = writeln!(
            md,
            "`{}` against `{}`: {} rows, analysed in {} consecutive parts of at most {} rows, each on its own (its own comparison, evidence and held-out last 30 %). An effect is named for the recording when more than half of the analysed parts name it ({analysed} parts analysed); its parameters are the inverse-variance mean over the parts that named it. A part's whole report is in `mismatch.json` (`parts[i].report`); its rows below are counted from the first row analysed.\n",
            self.recording,
            self.model,
            self.rows,
            self.parts.len(),
            self.part_rows
        );
        self.effects_markdown(&mut md, analysed);
        self.parts_markdown(&mut md);
        let _ = writeln!(md, "\n![each part's parameters]({figure})");
        md
    }

    fn effects_markdown(&self, md: &mut String, analysed: usize) {
        let _ = writeln!(md, "## The effects\n");
        if self.effects.is_empty() {
            let _ = writeln!(md, "No part named an effect.\n");
        } else {
            let _ = writeln!(
                md,
                "| effect | named in | parameter | pooled ± standard error | parts' range | χ²/dof | between parts |"
            );
            let _ = writeln!(md, "|---|---|---|---|---|---|---|");
            for effect in self.effects {
                let status = if effect.named {
                    format!("**{} of {analysed}**", effect.named_in)
                } else {
                    format!("{} of {analysed} (not named)", effect.named_in)
                };
                for parameter in &effect.parameters {
                    let _ = writeln!(
                        md,
                        "| {} | {status} | {} | {} | {} | {} | {} |",
                        effect.id,
                        parameter.name,
                        list(&parameter.numbers, pooled_text),
                        list(&parameter.numbers, range_text),
                        list(&parameter.numbers, |n| n
                            .chi_square_per_dof
                            .map_or("–".into(), |c| format!("{c:.1}"))),
                        if parameter.numbers.iter().any(|n| n.varies) {
                            "varies"
                        } else {
                            "consistent"
                        }
                    );
                }
            }
            let _ = writeln!(
                md,
                "\n\"varies\": the parts' values differ by more than their standard errors allow (χ² beyond its 99.9 % quantile): the effect changes over the recording (a battery that sags, a payload moved), or the standard errors, which cover the noise and not a bias, are too small.\n"
            );
        }
        if let Some([before, after]) = self.heldout {
            let _ = writeln!(
                md,
                "Held-out MSE, averaged over the analysed parts: {before:.5} with the nominal model, {after:.5} with each part's effects ({:+.1} %).\n",
                100.0 * (after / before - 1.0)
            );
        }
    }

    fn parts_markdown(&self, md: &mut String) {
        let _ = writeln!(md, "## Every part\n");
        let _ = writeln!(
            md,
            "| part | rows | time (s) | effects named | held-out MSE nominal → fitted |"
        );
        let _ = writeln!(md, "|---|---|---|---|---|");
        for (i, part) in self.parts.iter().enumerate() {
            let named = match &part.refused {
                Some(reason) => format!("not analysed: {reason}"),
                None if part.named.is_empty() => "none".into(),
                None => part.named.join(", "),
            };
            let heldout = part
                .heldout
                .map_or("–".into(), |[b, a]| format!("{b:.5} → {a:.5}"));
            let _ = writeln!(
                md,
                "| {} | {}:{} | {:.1}–{:.1} | {named} | {heldout} |",
                i + 1,
                part.rows[0],
                part.rows[1],
                part.t_start,
                part.t_end
            );
        }
    }

    /// Every pooled effect's parameter numbers against time, one panel per parameter: each part's
    /// value with ±2 standard errors, the pooled value as a line. `path` names the figure in errors.
    pub fn svg(&self, path: &Path) -> Result<String> {
        let plot_error = |message: String| ReportError::Plot {
            path: path.to_path_buf(),
            message,
        };
        let panels: Vec<(&PooledEffect, &PooledParameter)> = self
            .effects
            .iter()
            .flat_map(|e| e.parameters.iter().map(move |p| (e, p)))
            .collect();
        let height = 90 + 240 * panels.len().max(1) as u32;
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, (760, height)).into_drawing_area();
            self.draw(&root, &panels).map_err(plot_error)?;
        }
        Ok(svg)
    }

    fn draw(
        &self,
        root: &DrawingArea<SVGBackend, plotters::coord::Shift>,
        panels: &[(&PooledEffect, &PooledParameter)],
    ) -> std::result::Result<(), String> {
        root.fill(&WHITE).map_err(text)?;
        let root = root
            .titled(
                "Each part's parameters (±2 standard errors) and the pooled value",
                ("sans-serif", 17),
            )
            .map_err(text)?;
        if panels.is_empty() {
            root.draw(&Text::new(
                "no part named an effect",
                (40, 60),
                ("sans-serif", 15),
            ))
            .map_err(text)?;
            return root.present().map_err(text);
        }
        let t_end = self.parts.iter().map(|p| p.t_end).fold(f64::MIN, f64::max);
        let t_start = self
            .parts
            .iter()
            .map(|p| p.t_start)
            .fold(f64::MAX, f64::min);
        for (area, (effect, parameter)) in root.split_evenly((panels.len(), 1)).iter().zip(panels) {
            self.draw_panel(area, effect, parameter, (t_start, t_end))?;
        }
        root.present().map_err(text)
    }

    fn draw_panel(
        &self,
        area: &DrawingArea<SVGBackend, plotters::coord::Shift>,
        effect: &PooledEffect,
        parameter: &PooledParameter,
        (t_start, t_end): (f64, f64),
    ) -> std::result::Result<(), String> {
        let middles: Vec<f64> = self
            .parts
            .iter()
            .map(|p| 0.5 * (p.t_start + p.t_end))
            .collect();
        let (low, high) = value_range(parameter);
        let mut chart = ChartBuilder::on(area)
            .margin(12)
            .caption(
                format!("{}.{}", effect.id, parameter.name),
                ("sans-serif", 14),
            )
            .x_label_area_size(32)
            .y_label_area_size(60)
            .build_cartesian_2d(t_start..t_end, low..high)
            .map_err(text)?;
        chart
            .configure_mesh()
            .x_desc("time (s)")
            .draw()
            .map_err(text)?;
        for (k, number) in parameter.numbers.iter().enumerate() {
            let color = Palette99::pick(k).to_rgba();
            let dx =
                (k as f64 - 0.5 * (parameter.numbers.len() - 1) as f64) * 0.01 * (t_end - t_start);
            let points: Vec<(f64, PartValue)> = middles
                .iter()
                .zip(&number.per_part)
                .filter_map(|(t, v)| v.map(|v| (t + dx, v)))
                .collect();
            chart
                .draw_series(points.iter().filter_map(|(t, v)| {
                    v.standard_error.map(|s| {
                        PathElement::new(
                            vec![(*t, v.value - 2.0 * s), (*t, v.value + 2.0 * s)],
                            color.stroke_width(1),
                        )
                    })
                }))
                .map_err(text)?;
            chart
                .draw_series(
                    points
                        .iter()
                        .map(|(t, v)| Circle::new((*t, v.value), 3, color.filled())),
                )
                .map_err(text)?;
            chart
                .draw_series(LineSeries::new(
                    vec![(t_start, number.value), (t_end, number.value)],
                    color.stroke_width(1),
                ))
                .map_err(text)?;
        }
        Ok(())
    }
}

/// The numbers as `a` or `[a, b, c]`, each rendered by `f`.
fn list(numbers: &[PooledNumber], f: impl Fn(&PooledNumber) -> String) -> String {
    let texts: Vec<String> = numbers.iter().map(f).collect();
    match texts.as_slice() {
        [one] => one.clone(),
        many => format!("[{}]", many.join(", ")),
    }
}

fn pooled_text(number: &PooledNumber) -> String {
    match number.standard_error {
        Some(s) => format!("{:.4} ± {s:.2e}", number.value),
        None => format!("{:.4}", number.value),
    }
}

fn range_text(number: &PooledNumber) -> String {
    let values: Vec<f64> = number.per_part.iter().flatten().map(|v| v.value).collect();
    let low = values.iter().copied().fold(f64::INFINITY, f64::min);
    let high = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    format!("{low:.4}–{high:.4}")
}

/// The vertical range that holds every part's value ± 2 standard errors, padded; never empty.
fn value_range(parameter: &PooledParameter) -> (f64, f64) {
    let (mut low, mut high) = (f64::INFINITY, f64::NEG_INFINITY);
    for number in &parameter.numbers {
        for v in number.per_part.iter().flatten() {
            let s = 2.0 * v.standard_error.unwrap_or(0.0);
            low = low.min(v.value - s).min(number.value);
            high = high.max(v.value + s).max(number.value);
        }
    }
    let pad = 0.1 * (high - low).max(1e-3 * high.abs().max(low.abs()).max(1e-9));
    (low - pad, high + pad)
}
