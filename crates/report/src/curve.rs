//! Learning curves: an error against the number of samples a method was given, one line per
//! method, both axes logarithmic ([`CurveFigure`], SVG drawn with plotters as the paper's figure),
//! and the same numbers as a Markdown table ([`curve_markdown`]).

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::error::{ReportError, Result};

const WIDTH: u32 = 760;
const HEIGHT: u32 = 480;
const FONT: &str = "sans-serif";
/// Line colours, in series order (colour-blind safe: Okabe–Ito).
const COLOURS: [RGBColor; 6] = [
    RGBColor(0xD5, 0x5E, 0x00),
    RGBColor(0x00, 0x72, 0xB2),
    RGBColor(0x00, 0x9E, 0x73),
    RGBColor(0x88, 0x88, 0x88),
    RGBColor(0xCC, 0x79, 0xA7),
    RGBColor(0xE6, 0x9F, 0x00),
];

/// One method's line: its value at each of the figure's sample counts.
#[derive(Clone, Debug, PartialEq)]
pub struct CurveSeries {
    pub label: String,
    /// One value per entry of [`CurveFigure::samples`].
    pub values: Vec<f64>,
    /// Drawn dashed (a reference that uses no sample, e.g. a model before adaptation).
    pub dashed: bool,
}

/// A learning-curve figure.
#[derive(Clone, Debug, PartialEq)]
pub struct CurveFigure {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    /// The sample counts (x, increasing, positive).
    pub samples: Vec<usize>,
    pub series: Vec<CurveSeries>,
}

impl CurveFigure {
    fn validate(&self) -> Result<()> {
        let bad = |message: String| ReportError::Plot {
            path: std::path::PathBuf::from(&self.title),
            message,
        };
        if self.samples.is_empty() || self.samples.windows(2).any(|w| w[0] >= w[1]) {
            return Err(bad("sample counts must be increasing".to_string()));
        }
        if self.samples[0] == 0 {
            return Err(bad("sample counts must be positive (log axis)".to_string()));
        }
        for series in &self.series {
            if series.values.len() != self.samples.len() {
                return Err(bad(format!(
                    "series '{}' has the wrong length",
                    series.label
                )));
            }
            if series.values.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
                return Err(bad(format!(
                    "series '{}' has a value that is not a positive number (log axis)",
                    series.label
                )));
            }
        }
        Ok(())
    }

    /// The figure as SVG text (real `<text>` elements, no font needed).
    pub fn render_svg(&self) -> Result<String> {
        self.validate()?;
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, (WIDTH, HEIGHT)).into_drawing_area();
            self.draw(&root).map_err(|message| ReportError::Plot {
                path: std::path::PathBuf::from(&self.title),
                message,
            })?;
            root.present().map_err(|error| ReportError::Plot {
                path: std::path::PathBuf::from(&self.title),
                message: error.to_string(),
            })?;
        }
        svg.push('\n');
        Ok(svg)
    }

    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, plotters::coord::Shift>,
    ) -> std::result::Result<(), String> {
        let text_error = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
        root.fill(&WHITE).map_err(text_error)?;
        let values = self.series.iter().flat_map(|s| s.values.iter().copied());
        let low = values.clone().fold(f64::INFINITY, f64::min);
        let high = values.fold(f64::NEG_INFINITY, f64::max);
        let (x_low, x_high) = (
            self.samples[0] as f64 / 1.3,
            *self.samples.last().unwrap_or(&1) as f64 * 1.3,
        );
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, (FONT, 16))
            .margin(12)
            .x_label_area_size(42)
            .y_label_area_size(64)
            .build_cartesian_2d(
                (x_low..x_high)
                    .log_scale()
                    .with_key_points(self.samples.iter().map(|&n| n as f64).collect()),
                (low / 1.5..high * 1.5).log_scale(),
            )
            .map_err(text_error)?;
        chart
            .configure_mesh()
            .x_desc(&self.x_label)
            .y_desc(&self.y_label)
            .x_labels(8)
            .y_labels(8)
            .x_label_formatter(&|x| format!("{x:.0}"))
            .y_label_formatter(&|y| format!("{y:e}"))
            .label_style((FONT, 12))
            .light_line_style(RGBColor(0xEE, 0xEE, 0xEE))
            .draw()
            .map_err(text_error)?;
        for (index, series) in self.series.iter().enumerate() {
            let colour = COLOURS[index % COLOURS.len()];
            let points: Vec<(f64, f64)> = self
                .samples
                .iter()
                .zip(&series.values)
                .map(|(&n, &v)| (n as f64, v))
                .collect();
            let style = colour.stroke_width(2);
            let line = if series.dashed {
                chart.draw_series(DashedLineSeries::new(points.clone(), 6, 4, style))
            } else {
                chart.draw_series(LineSeries::new(points.clone(), style))
            };
            line.map_err(text_error)?
                .label(series.label.clone())
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2))
                });
            chart
                .draw_series(points.iter().map(|&p| Circle::new(p, 3, colour.filled())))
                .map_err(text_error)?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .label_font((FONT, 12))
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(text_error)?;
        root.draw_text(
            "log–log; each point: median over the test tasks",
            &TextStyle::from((FONT, 11).into_font())
                .color(&RGBColor(0x55, 0x55, 0x55))
                .pos(Pos::new(HPos::Right, VPos::Bottom)),
            (WIDTH as i32 - 8, HEIGHT as i32 - 4),
        )
        .map_err(text_error)?;
        Ok(())
    }
}

/// A Markdown table: one row per sample count, one column per series, the lowest value of each
/// row in bold when `bold_lowest`, numbers with four decimals (in scientific notation from 10⁴
/// on); `notes[i][row]` (if given and not empty) appended to that cell as ` (note)`.
pub fn curve_markdown(
    samples: &[usize],
    series: &[CurveSeries],
    notes: &[Vec<String>],
    bold_lowest: bool,
) -> String {
    let mut text = String::from("| support samples |");
    for s in series {
        text.push_str(&format!(" {} |", s.label));
    }
    text.push_str("\n|---:|");
    text.push_str(&"---:|".repeat(series.len()));
    text.push('\n');
    for (row, n) in samples.iter().enumerate() {
        let lowest = series
            .iter()
            .map(|s| s.values[row])
            .fold(f64::INFINITY, f64::min);
        text.push_str(&format!("| {n} |"));
        for (column, s) in series.iter().enumerate() {
            let value = s.values[row];
            let number = if value.abs() >= 1e4 {
                format!("{value:.3e}")
            } else {
                format!("{value:.4}")
            };
            let number = if bold_lowest && value == lowest {
                format!("**{number}**")
            } else {
                number
            };
            let note = notes
                .get(column)
                .and_then(|n| n.get(row))
                .filter(|n| !n.is_empty())
                .map_or(String::new(), |n| format!(" ({n})"));
            text.push_str(&format!(" {number}{note} |"));
        }
        text.push('\n');
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    fn figure() -> CurveFigure {
        CurveFigure {
            title: "curve".to_string(),
            x_label: "support samples".to_string(),
            y_label: "MSE".to_string(),
            samples: vec![20, 100, 1000],
            series: vec![
                CurveSeries {
                    label: "a".to_string(),
                    values: vec![1.0, 0.5, 0.1],
                    dashed: false,
                },
                CurveSeries {
                    label: "b".to_string(),
                    values: vec![2.0, 0.4, 0.01],
                    dashed: true,
                },
            ],
        }
    }

    #[test]
    fn the_figure_has_every_label_and_refuses_values_a_log_axis_cannot_show() {
        let svg = figure().render_svg().unwrap();
        // plotters writes each text on its own line between the tags.
        assert!(
            svg.starts_with("<svg") && svg.contains(">\ncurve\n</text>"),
            "{svg}"
        );
        assert!(
            svg.contains(">\na\n</text>") && svg.contains(">\nb\n</text>"),
            "{svg}"
        );
        let mut bad = figure();
        bad.series[0].values[1] = 0.0;
        assert!(bad.render_svg().is_err());
    }

    #[test]
    fn the_table_bolds_the_lowest_of_each_row() {
        let f = figure();
        let notes = vec![vec![String::new(), "2/3".to_string(), String::new()]];
        let text = curve_markdown(&f.samples, &f.series, &notes, true);
        assert!(text.contains("| 20 | **1.0000** | 2.0000 |"), "{text}");
        assert!(
            text.contains("| 100 | 0.5000 (2/3) | **0.4000** |"),
            "{text}"
        );
    }
}
