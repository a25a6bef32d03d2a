//! The joint analysis's figure (`<model stem>.svg`): every flight's estimated horizontal wind speed
//! against the known one, in both roles, with the range the drag lag leaves open.

use std::path::Path;

use plotters::prelude::*;

use super::fleet::{FleetView, FlightWind};
use super::text;
use crate::error::{ReportError, Result};

impl FleetView<'_> {
    /// Estimated horizontal wind speed against the known one, both roles, as SVG text; `path`
    /// (where the caller writes it) only names the figure in the error.
    pub fn svg(&self, path: &Path) -> Result<String> {
        let plot_error = |message: String| ReportError::Plot {
            path: path.to_path_buf(),
            message,
        };
        let points: Vec<(&FlightWind, f64)> = self
            .flights
            .iter()
            .filter_map(|f| f.fan_speed_m_s.map(|s| (f, s)))
            .collect();
        let top = points
            .iter()
            .map(|(f, s)| f.horizontal_speed_m_s.max(*s))
            .fold(1.0, f64::max)
            .max(
                self.scale
                    .iter()
                    .flat_map(|s| s.flights.iter().map(|f| f.range().1))
                    .fold(0.0, f64::max),
            )
            * 1.1;
        if !top.is_finite() {
            return Err(plot_error("a wind speed is not finite".to_string()));
        }
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, (720, 620)).into_drawing_area();
            self.draw(&root, &points, top).map_err(plot_error)?;
        }
        Ok(svg)
    }

    fn draw(
        &self,
        root: &DrawingArea<SVGBackend, plotters::coord::Shift>,
        points: &[(&FlightWind, f64)],
        top: f64,
    ) -> std::result::Result<(), String> {
        root.fill(&WHITE).map_err(text)?;
        let mut chart = ChartBuilder::on(root)
            .margin(16)
            .caption(
                "Estimated against known wind speed (horizontal), every flight",
                ("sans-serif", 17),
            )
            .x_label_area_size(40)
            .y_label_area_size(50)
            .build_cartesian_2d(-0.5..top, -0.5..top)
            .map_err(text)?;
        chart
            .configure_mesh()
            .x_desc("known mean wind speed (m/s)")
            .y_desc("estimated (m/s)")
            .draw()
            .map_err(text)?;
        let band = RGBColor(225, 235, 245);
        chart
            .draw_series(std::iter::once(Polygon::new(
                vec![(0.0, -1.5), (top, top - 1.5), (top, top + 1.5), (0.0, 1.5)],
                band.filled(),
            )))
            .map_err(text)?
            .label("±1.5 m/s")
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 14, y + 5)], band.filled()));
        chart
            .draw_series(LineSeries::new(
                vec![(0.0, 0.0), (top, top)],
                BLACK.stroke_width(1),
            ))
            .map_err(text)?;
        if let Some(scale) = self.scale {
            let (low, high) = scale.lag_band_s;
            let grey = RGBColor(120, 120, 120);
            chart
                .draw_series(scale.flights.iter().filter_map(|f| {
                    let (a, b) = f.range();
                    f.fan_speed_m_s.map(|s| {
                        PathElement::new(vec![(s - 0.12, a), (s - 0.12, b)], grey.stroke_width(2))
                    })
                }))
                .map_err(text)?
                .label(format!(
                    "joint fit with the drag lag from {low:.1} to {high:.1} s"
                ))
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y - 6), (x, y + 6)], grey.stroke_width(2))
                });
        }
        for (role, color, dx) in [("fit", BLUE, -0.12), ("validation", RED, 0.12)] {
            chart
                .draw_series(
                    points.iter().filter(|(f, _)| f.role == role).map(|(f, s)| {
                        Circle::new((s + dx, f.horizontal_speed_m_s), 4, color.filled())
                    }),
                )
                .map_err(text)?
                .label(if role == "fit" {
                    "joint fit of all flights"
                } else {
                    "vehicle identified without the flight's condition"
                })
                .legend(move |(x, y)| Circle::new((x + 7, y), 4, color.filled()));
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .draw()
            .map_err(text)?;
        root.present().map_err(text)?;
        Ok(())
    }
}
