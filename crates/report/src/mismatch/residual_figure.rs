//! The figure of one analysis (`mismatch.svg`): the weak-form residual per channel before and after
//! the effects found, the located windows shaded, the held-out part right of a dashed line.

use std::path::Path;

use plotters::prelude::*;

use super::recording::Window;
use super::text;
use crate::error::{ReportError, Result};

/// What the figure draws, borrowed from the analysis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ResidualFigure<'a> {
    /// Time of each analysed row, s.
    pub time: &'a [f64],
    /// The nominal model's and the fitted model's residual per row (the first `channels` entries
    /// of each row are drawn).
    pub before: &'a [[f64; 6]],
    pub after: &'a [[f64; 6]],
    /// How many channels were analysed: the translational three (m/s²), then the angular three
    /// (rad/s²).
    pub channels: usize,
    /// The names of the channels, in that order (at least `channels` of them).
    pub names: &'a [&'a str],
    /// The first held-out row.
    pub split: usize,
    /// The located windows, shaded on their channel's panel.
    pub windows: &'a [Window],
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

impl ResidualFigure<'_> {
    /// Each channel's plotted range; the error says what cannot be drawn.
    fn drawable_ranges(&self) -> std::result::Result<Vec<(f64, f64)>, String> {
        let channels = self.channels;
        let time = self.time;
        if time.is_empty()
            || self.before.len() != time.len()
            || self.after.len() != time.len()
            || channels > self.names.len()
        {
            return Err(format!(
                "{} times, {} and {} residual rows for {channels} channels",
                time.len(),
                self.before.len(),
                self.after.len()
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
            let values = self.before.iter().chain(self.after).map(|r| r[c]);
            let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            });
            let margin = 0.05 * (hi - lo).max(1e-9);
            let (lo, hi) = (lo - margin, hi + margin);
            let finite = self
                .before
                .iter()
                .chain(self.after)
                .all(|r| r[c].is_finite());
            if !finite || !drawable(lo, hi) {
                return Err(format!(
                    "the residual of {} is not finite or spans no drawable range ({lo} to {hi})",
                    self.names[c]
                ));
            }
            ranges.push((lo, hi));
        }
        let windows_drawable = self
            .windows
            .iter()
            .all(|w| w.t_start.is_finite() && w.t_end.is_finite());
        if !windows_drawable {
            return Err("a located window has a non-finite time".to_string());
        }
        Ok(ranges)
    }

    /// The figure as SVG text, one panel per channel. Fails, without drawing, unless the data are
    /// finite and every axis spans a drawable range (finite ends, a normal positive span); `path`
    /// (where the caller writes it) only names the figure in the error.
    pub fn svg(&self, path: &Path) -> Result<String> {
        let plot_error = |message: String| ReportError::Plot {
            path: path.to_path_buf(),
            message,
        };
        let ranges = self.drawable_ranges().map_err(plot_error)?;
        let mut svg = String::new();
        {
            let size = (1100, 60 + 190 * self.channels as u32);
            let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
            self.draw(&root, &ranges).map_err(plot_error)?;
        }
        Ok(svg)
    }

    fn draw(
        &self,
        root: &DrawingArea<SVGBackend, plotters::coord::Shift>,
        ranges: &[(f64, f64)],
    ) -> std::result::Result<(), String> {
        root.fill(&WHITE).map_err(text)?;
        let (title, body) = root.split_vertically(50);
        title
            .titled(
                "Weak-form residual (recording − model): nominal model in grey, with the found effects in blue; located windows shaded; held-out part right of the dashed line",
                ("sans-serif", 15),
            )
            .map_err(text)?;
        let panels = body.split_evenly((self.channels, 1));
        for (c, panel) in panels.iter().enumerate() {
            self.draw_panel(panel, c, ranges[c])?;
        }
        root.present().map_err(text)?;
        Ok(())
    }

    /// One channel's panel.
    fn draw_panel(
        &self,
        panel: &DrawingArea<SVGBackend, plotters::coord::Shift>,
        c: usize,
        (lo, hi): (f64, f64),
    ) -> std::result::Result<(), String> {
        let time = self.time;
        let (t0, t1) = (time[0], time[time.len() - 1]);
        let split_time = time[self.split.min(time.len() - 1)];
        let mut chart = ChartBuilder::on(panel)
            .margin(8)
            .x_label_area_size(28)
            .y_label_area_size(60)
            .caption(
                format!("{} ({})", self.names[c], units(c)),
                ("sans-serif", 14),
            )
            .build_cartesian_2d(t0..t1, lo..hi)
            .map_err(text)?;
        chart
            .configure_mesh()
            .x_desc("t (s)")
            .light_line_style(WHITE)
            .draw()
            .map_err(text)?;
        for window in self.windows.iter().filter(|w| w.channel == self.names[c]) {
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(window.t_start, lo), (window.t_end, hi)],
                    RGBColor(255, 200, 200).mix(0.5).filled(),
                )))
                .map_err(text)?;
        }
        chart
            .draw_series(LineSeries::new(
                time.iter().zip(self.before).map(|(t, r)| (*t, r[c])),
                RGBColor(150, 150, 150).stroke_width(1),
            ))
            .map_err(text)?
            .label("nominal model")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 15, y)], RGBColor(150, 150, 150)));
        chart
            .draw_series(LineSeries::new(
                time.iter().zip(self.after).map(|(t, r)| (*t, r[c])),
                RGBColor(30, 90, 200).stroke_width(1),
            ))
            .map_err(text)?
            .label("with found effects")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 15, y)], RGBColor(30, 90, 200)));
        chart
            .draw_series(DashedLineSeries::new(
                [(split_time, lo), (split_time, hi)],
                4,
                4,
                BLACK.stroke_width(1),
            ))
            .map_err(text)?;
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(text)?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const NAMES: [&str; 6] = ["vdot_x", "vdot_y", "vdot_z", "wdot_x", "wdot_y", "wdot_z"];

    #[test]
    fn a_finite_figure_is_drawn_and_a_non_finite_one_is_refused() {
        let time: Vec<f64> = (0..50).map(|k| 0.02 * k as f64).collect();
        let before: Vec<[f64; 6]> = time.iter().map(|t| [t.sin(); 6]).collect();
        let after: Vec<[f64; 6]> = time.iter().map(|t| [0.5 * t.cos(); 6]).collect();
        let windows = [Window {
            channel: "wdot_y".to_string(),
            t_start: 0.2,
            t_end: 0.6,
        }];
        let figure = ResidualFigure {
            time: &time,
            before: &before,
            after: &after,
            channels: 6,
            names: &NAMES,
            split: 35,
            windows: &windows,
        };
        let svg = figure.svg(Path::new("f.svg")).unwrap();
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        assert!(svg.contains("wdot_z (rad/s²)") && svg.contains("vdot_x (m/s²)"));
        let mut nan = after.clone();
        nan[7][2] = f64::NAN;
        let error = ResidualFigure {
            after: &nan,
            ..figure
        }
        .svg(Path::new("f.svg"))
        .unwrap_err();
        assert!(
            error
                .to_string()
                .starts_with("f.svg: cannot draw the figure: the residual of vdot_z is not finite"),
            "{error}"
        );
        let error = ResidualFigure {
            channels: 7,
            ..figure
        }
        .svg(Path::new("f.svg"))
        .unwrap_err();
        assert!(error.to_string().contains("for 7 channels"), "{error}");
    }
}
