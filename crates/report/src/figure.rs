//! The paper's qualitative figure: for each method, one panel per state derivative over the whole
//! flight, with the ground truth, the prediction on the adaptation (support) segment and the
//! prediction on the generalisation (query) segment. Written as SVG with real `<text>` elements
//! (no font is needed to produce it).

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use serde::{Deserialize, Serialize};

use crate::error::{ReportError, Result, write_text};

/// Ground truth colour (the paper's `#FFAA6B`).
pub const GROUND_TRUTH: RGBColor = RGBColor(0xFF, 0xAA, 0x6B);
/// Adaptation-segment prediction colour (the paper's `#EB3324`).
pub const ADAPTATION: RGBColor = RGBColor(0xEB, 0x33, 0x24);
/// Generalisation-segment prediction colour (the paper's `#3282F6`).
pub const GENERALISATION: RGBColor = RGBColor(0x32, 0x82, 0xF6);

const PANEL_WIDTH: u32 = 300;
const PANEL_HEIGHT: u32 = 210;
const PANELS_PER_ROW: usize = 3;
const HEADER_HEIGHT: u32 = 78;
const METHOD_GAP: u32 = 18;
const FONT: &str = "sans-serif";

/// What one panel shows on its vertical axis.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct OutputAxis {
    /// The derivative's symbol, e.g. `v̇x`.
    pub symbol: String,
    /// Its unit, e.g. `m/s²`.
    pub unit: String,
}

impl OutputAxis {
    /// The axis of a target named as the data crate names them (`vdot_x` … `wdot_z`); other names
    /// are shown as they are, without a unit.
    pub fn for_target(name: &str) -> Self {
        let (symbol, unit) = match name.split_once("dot_") {
            Some(("v", axis)) => (format!("v\u{307}{axis}"), "m/s²"),
            Some(("w", axis)) => (format!("ω\u{307}{axis}"), "rad/s²"),
            _ => (name.to_string(), ""),
        };
        OutputAxis {
            symbol,
            unit: unit.to_string(),
        }
    }

    fn label(&self) -> String {
        if self.unit.is_empty() {
            self.symbol.clone()
        } else {
            format!("{} [{}]", self.symbol, self.unit)
        }
    }
}

/// One method's prediction over the whole flight, one vector per output.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MethodTrace {
    /// The name shown above its panels, e.g. `SINDy`.
    pub method: String,
    /// `prediction[output][sample]`; samples before the split are the adaptation-segment
    /// prediction, from the split on the generalisation-segment prediction.
    pub prediction: Vec<Vec<f64>>,
    /// An optional band around the prediction (e.g. an ensemble's spread), drawn shaded.
    pub band: Option<Band>,
}

/// A band around a prediction, `lower[output][sample]` ≤ `upper[output][sample]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Band {
    pub lower: Vec<Vec<f64>>,
    pub upper: Vec<Vec<f64>>,
}

/// Everything one figure shows.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct QualitativeFigure {
    /// The formulation, e.g. `full`.
    pub table: String,
    /// The condition as the paper prints it.
    pub condition: String,
    /// Time of each sample, s.
    pub time: Vec<f64>,
    /// Index of the first generalisation (query) sample.
    pub split: usize,
    pub outputs: Vec<OutputAxis>,
    /// `truth[output][sample]`, the target the methods were scored against.
    pub truth: Vec<Vec<f64>>,
    pub methods: Vec<MethodTrace>,
}

impl QualitativeFigure {
    /// Checks that every series has one finite value per sample and the split lies inside.
    pub fn validate(&self) -> Result<()> {
        let invalid = |message: String| ReportError::Invalid {
            what: format!("figure {} {}", self.table, self.condition),
            message,
        };
        let n = self.time.len();
        if n < 2 || self.split == 0 || self.split >= n {
            return Err(invalid(format!(
                "split {} must lie inside the {n} samples",
                self.split
            )));
        }
        if self.outputs.is_empty() || self.methods.is_empty() {
            return Err(invalid("no output or no method to draw".to_string()));
        }
        let named_series = std::iter::once(("ground truth", &self.truth))
            .chain(
                self.methods
                    .iter()
                    .map(|m| (m.method.as_str(), &m.prediction)),
            )
            .chain(self.methods.iter().flat_map(|m| {
                m.band.iter().flat_map(move |b| {
                    [(m.method.as_str(), &b.lower), (m.method.as_str(), &b.upper)]
                })
            }));
        for (name, series) in named_series {
            if series.len() != self.outputs.len() {
                return Err(invalid(format!(
                    "{name} has {} outputs, expected {}",
                    series.len(),
                    self.outputs.len()
                )));
            }
            for (output, values) in series.iter().enumerate() {
                if values.len() != n {
                    return Err(invalid(format!(
                        "{name} {} has {} samples, expected {n}",
                        self.outputs[output].symbol,
                        values.len()
                    )));
                }
                if let Some(k) = values.iter().position(|v| !v.is_finite()) {
                    return Err(invalid(format!(
                        "{name} {} is not finite at sample {k}",
                        self.outputs[output].symbol
                    )));
                }
            }
        }
        Ok(())
    }

    fn columns(&self) -> usize {
        self.outputs.len().min(PANELS_PER_ROW)
    }

    fn rows(&self) -> usize {
        self.outputs.len().div_ceil(PANELS_PER_ROW)
    }

    /// Width and height of the SVG in pixels.
    pub fn size(&self) -> (u32, u32) {
        let methods = self.methods.len() as u32;
        let width = methods * self.columns() as u32 * PANEL_WIDTH + (methods - 1) * METHOD_GAP;
        let height = HEADER_HEIGHT + self.rows() as u32 * PANEL_HEIGHT;
        (width, height)
    }

    /// The figure as SVG text.
    pub fn render_svg(&self) -> Result<String> {
        self.validate()?;
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, self.size()).into_drawing_area();
            self.draw(&root).map_err(|message| ReportError::Plot {
                path: Path::new(&format!("{}_{}.svg", self.table, self.condition)).to_path_buf(),
                message,
            })?;
            root.present().map_err(|error| ReportError::Plot {
                path: Path::new(&format!("{}_{}.svg", self.table, self.condition)).to_path_buf(),
                message: error.to_string(),
            })?;
        }
        svg.push('\n');
        Ok(svg)
    }

    /// Writes the SVG to `path`.
    pub fn save_svg(&self, path: &Path) -> Result<()> {
        write_text(path, &self.render_svg()?)
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
    ) -> std::result::Result<(), String> {
        let text_error = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
        root.fill(&WHITE).map_err(text_error)?;
        let (width, height) = self.size();
        self.draw_header(root, width).map_err(text_error)?;
        let group_width = self.columns() as u32 * PANEL_WIDTH;
        for (index, method) in self.methods.iter().enumerate() {
            let left = index as u32 * (group_width + METHOD_GAP);
            let group = root
                .clone()
                .shrink((left, HEADER_HEIGHT), (group_width, height - HEADER_HEIGHT));
            self.draw_method(&group, method)?;
            if index > 0 {
                let x = (left - METHOD_GAP / 2) as i32;
                root.draw(&PathElement::new(
                    vec![(x, HEADER_HEIGHT as i32 - 40), (x, height as i32 - 4)],
                    BLACK.stroke_width(1),
                ))
                .map_err(text_error)?;
            }
            let title_x = (left + group_width / 2) as i32;
            root.draw_text(
                &format!("{} ({})", method.method, self.condition),
                &TextStyle::from((FONT, 16).into_font())
                    .color(&BLACK)
                    .pos(Pos::new(HPos::Center, VPos::Center)),
                (title_x, HEADER_HEIGHT as i32 - 24),
            )
            .map_err(text_error)?;
        }
        root.draw(&PathElement::new(
            vec![
                (0, HEADER_HEIGHT as i32 - 8),
                (width as i32, HEADER_HEIGHT as i32 - 8),
            ],
            BLACK.stroke_width(1),
        ))
        .map_err(text_error)?;
        Ok(())
    }

    /// Title on the left, the legend box on the right (as in the paper).
    fn draw_header<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        width: u32,
    ) -> std::result::Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let split_time = self.time[self.split];
        let title = format!(
            "{} dynamics, {}: adaptation on t < {split_time:.1} s, generalisation after",
            capitalised(&self.table),
            self.condition
        );
        root.draw_text(
            &title,
            &TextStyle::from((FONT, 13).into_font())
                .color(&RGBColor(0x44, 0x44, 0x44))
                .pos(Pos::new(HPos::Left, VPos::Center)),
            (10, 18),
        )?;
        let entries = [
            ("Ground Truth", GROUND_TRUTH),
            ("Adaptation", ADAPTATION),
            ("Generalization", GENERALISATION),
        ];
        // Text width estimated at 7.5 px per character of the 13 px sans-serif font.
        let entry_width = |label: &str| 28 + (7.5 * label.chars().count() as f64) as i32 + 18;
        let legend_width: i32 = 12 + entries.iter().map(|(l, _)| entry_width(l)).sum::<i32>();
        let left = width as i32 - legend_width - 8;
        root.draw(&Rectangle::new(
            [(left, 5), (left + legend_width, 31)],
            BLACK.stroke_width(1),
        ))?;
        let mut x = left + 12;
        for (label, colour) in entries {
            root.draw(&Rectangle::new([(x, 14), (x + 22, 22)], colour.filled()))?;
            root.draw_text(
                label,
                &TextStyle::from((FONT, 13).into_font())
                    .color(&BLACK)
                    .pos(Pos::new(HPos::Left, VPos::Center)),
                (x + 28, 18),
            )?;
            x += entry_width(label);
        }
        Ok(())
    }

    fn draw_method<DB: DrawingBackend>(
        &self,
        group: &DrawingArea<DB, Shift>,
        method: &MethodTrace,
    ) -> std::result::Result<(), String> {
        let panels = group.split_evenly((self.rows(), self.columns()));
        for (output, area) in panels.iter().enumerate().take(self.outputs.len()) {
            let band = method
                .band
                .as_ref()
                .map(|b| (b.lower[output].as_slice(), b.upper[output].as_slice()));
            self.draw_panel(area, output, &method.prediction[output], band)
                .map_err(|e| e.to_string())?;
        }
        Ok(())
    }

    fn draw_panel<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        output: usize,
        prediction: &[f64],
        band: Option<(&[f64], &[f64])>,
    ) -> std::result::Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
        let truth = &self.truth[output];
        let band_values = band.into_iter().flat_map(|(l, u)| l.iter().chain(u));
        let (low, high) = value_range(truth.iter().chain(prediction).chain(band_values));
        let (start, end) = (self.time[0], self.time[self.time.len() - 1]);
        let mut chart = ChartBuilder::on(area)
            .margin_top(8)
            .margin_right(12)
            .margin_bottom(4)
            .margin_left(4)
            .x_label_area_size(34)
            .y_label_area_size(54)
            .build_cartesian_2d(start..end, low..high)?;
        let decimals = label_decimals(high - low);
        chart
            .configure_mesh()
            .disable_mesh()
            .x_labels(6)
            .y_labels(5)
            .x_desc("t [s]")
            .y_desc(self.outputs[output].label())
            .label_style((FONT, 11))
            .axis_desc_style((FONT, 13))
            .x_label_formatter(&|t| format!("{t:.0}"))
            .y_label_formatter(&|v| format!("{v:.decimals$}"))
            .draw()?;
        // Consecutive samples that land on the same pixel draw nothing new: keep one (the SVG
        // backend writes integer coordinates, so this changes no pixel and shrinks the file).
        let points = |range: std::ops::Range<usize>, values: &[f64]| {
            let mut kept: Vec<(f64, f64)> = Vec::with_capacity(range.len());
            let mut last_pixel = None;
            for k in range {
                let point = (self.time[k], values[k]);
                let pixel = chart.backend_coord(&point);
                if last_pixel != Some(pixel) {
                    kept.push(point);
                    last_pixel = Some(pixel);
                }
            }
            kept
        };
        let n = self.time.len();
        // The band: one closed polygon per segment, lightly shaded in the segment's colour.
        let polygons: Vec<(Vec<(f64, f64)>, RGBColor)> = band
            .map(|(lower, upper)| {
                [(0..self.split, ADAPTATION), (self.split..n, GENERALISATION)]
                    .into_iter()
                    .map(|(range, colour)| {
                        let mut outline = points(range.clone(), upper);
                        let mut bottom = points(range, lower);
                        bottom.reverse();
                        outline.extend(bottom);
                        (outline, colour)
                    })
                    .collect()
            })
            .unwrap_or_default();
        let series = [
            (points(0..n, truth), GROUND_TRUTH),
            (points(0..self.split, prediction), ADAPTATION),
            (points(self.split..n, prediction), GENERALISATION),
        ];
        for (outline, colour) in polygons {
            chart.draw_series(std::iter::once(Polygon::new(
                outline,
                colour.mix(0.3).filled(),
            )))?;
        }
        for (line, colour) in series {
            chart.draw_series(LineSeries::new(line, colour.stroke_width(1)))?;
        }
        Ok(())
    }
}

fn capitalised(text: &str) -> String {
    let mut chars = text.chars();
    chars
        .next()
        .map(|first| first.to_uppercase().chain(chars).collect())
        .unwrap_or_default()
}

/// The vertical range of a panel: every value, padded by 5 % (and never empty).
fn value_range<'a>(values: impl Iterator<Item = &'a f64>) -> (f64, f64) {
    let (low, high) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(*v), hi.max(*v))
    });
    let pad = ((high - low) * 0.05).max(1e-6);
    (low - pad, high + pad)
}

/// Decimals needed for five tick labels over a span.
fn label_decimals(span: f64) -> usize {
    if span >= 10.0 {
        0
    } else if span >= 1.0 {
        1
    } else if span >= 0.1 {
        2
    } else {
        3
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn targets_get_symbols_and_units() {
        let axis = OutputAxis::for_target("wdot_z");
        assert_eq!(axis.symbol, "ω\u{307}z");
        assert_eq!(axis.unit, "rad/s²");
        assert_eq!(OutputAxis::for_target("vdot_y").label(), "v\u{307}y [m/s²]");
        assert_eq!(OutputAxis::for_target("thing").label(), "thing");
    }

    #[test]
    fn ranges_are_padded_and_never_empty() {
        let (low, high) = value_range([1.0, 3.0].iter());
        assert!((low - 0.9).abs() < 1e-12 && (high - 3.1).abs() < 1e-12);
        let (low, high) = value_range([2.0, 2.0].iter());
        assert!(low < 2.0 && high > 2.0);
    }
}
