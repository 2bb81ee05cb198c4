//! The convergence plot of `knotrod verify`: the discrete rod's relative
//! distance from the continuum solution against N, log–log, with the slope
//! N⁻² beside it.

use crate::io::error::{IoError, Result};
use crate::io::plot::plot_error;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// One curve: its label and (N, relative error) points.
pub type Series = (String, Vec<(f64, f64)>);

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, series: &[Series]) -> Result<()>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(plot_error)?;
    let points: Vec<(f64, f64)> = series
        .iter()
        .flat_map(|(_, p)| p.iter().copied())
        .filter(|(x, y)| *x > 0.0 && *y > 0.0 && y.is_finite())
        .collect();
    if points.is_empty() {
        return Err(IoError::Plot(
            "nothing to plot: no finite positive errors".into(),
        ));
    }
    let (x0, x1) = points.iter().fold((f64::INFINITY, 0.0f64), |(a, b), p| {
        (a.min(p.0), b.max(p.0))
    });
    let (y0, y1) = points.iter().fold((f64::INFINITY, 0.0f64), |(a, b), p| {
        (a.min(p.1), b.max(p.1))
    });
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "discrete rod against the continuum solution",
            ("sans-serif", 18),
        )
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(60)
        .build_cartesian_2d(
            (x0 / 1.2..x1 * 1.2).log_scale(),
            (y0 / 3.0..y1 * 3.0).log_scale(),
        )
        .map_err(plot_error)?;
    chart
        .configure_mesh()
        .x_desc("N")
        .y_desc("relative distance")
        .y_label_formatter(&|y| format!("{y:.0e}"))
        .draw()
        .map_err(plot_error)?;
    let legend = series.len() <= 8;
    for (k, (label, p)) in series.iter().enumerate() {
        let colour = Palette99::pick(k).to_rgba();
        let line = chart
            .draw_series(LineSeries::new(p.iter().copied(), colour.stroke_width(2)))
            .map_err(plot_error)?;
        if legend {
            line.label(label.clone()).legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
        }
        chart
            .draw_series(p.iter().map(|&q| Circle::new(q, 3, colour.filled())))
            .map_err(plot_error)?;
    }
    // the slope of a second-order method through the first curve's start
    if let Some((_, p)) = series.iter().find(|(_, p)| !p.is_empty()) {
        let (n, e) = p[0];
        chart
            .draw_series(LineSeries::new(
                [(n, e * 2.0), (x1, e * 2.0 * (n / x1).powi(2))],
                BLACK.stroke_width(1),
            ))
            .map_err(plot_error)?
            .label("N⁻²")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(plot_error)?;
    root.present().map_err(plot_error)?;
    Ok(())
}

/// Write the plot as `path` (SVG).
pub fn convergence_plot(path: &Path, series: &[Series]) -> Result<()> {
    // the SVG backend measures its labels with a registered font
    if !crate::io::plot::font_available() {
        return Err(IoError::Plot("no font to draw the labels with".into()));
    }
    crate::io::plot::write_svg(path, (900, 600), |root| draw(root, series))
}
