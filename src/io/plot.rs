//! Bifurcation diagrams in the paper's style: the (φ/2π, Tw) plane with
//! segments coloured green (good knot), blue (stable, knotted, not walled),
//! brown (unknotted), red (unstable), events labelled; below, the lowest ω²
//! and the minimum self-distance along the branches. SVG always; PNG when a
//! TrueType font is found for the labels.

use crate::analysis::class::Class;
use crate::analysis::equilibrium::Equilibrium;
use crate::analysis::event::Event;
use crate::io::error::{IoError, Result};
use crate::io::output::write_file;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Draw an SVG with `paint` in memory and write it to `path` atomically.
pub(crate) fn write_svg(
    path: &Path,
    size: (u32, u32),
    paint: impl FnOnce(DrawingArea<SVGBackend<'_>, Shift>) -> Result<()>,
) -> Result<()> {
    let mut text = String::new();
    paint(SVGBackend::with_string(&mut text, size).into_drawing_area())?;
    write_file(path, text.as_bytes())
}

/// Draw a PNG with `paint` in memory and write it to `path` atomically.
fn write_png(
    path: &Path,
    size: (u32, u32),
    paint: impl FnOnce(DrawingArea<BitMapBackend<'_>, Shift>) -> Result<()>,
) -> Result<()> {
    use image::ImageEncoder;
    let mut pixels = vec![0u8; size.0 as usize * size.1 as usize * 3];
    paint(BitMapBackend::with_buffer(&mut pixels, size).into_drawing_area())?;
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png)
        .write_image(&pixels, size.0, size.1, image::ColorType::Rgb8)
        .map_err(|e| IoError::Plot(format!("encoding {}: {e}", path.display())))?;
    write_file(path, &png)
}

/// The colour of an equilibrium's class.
pub fn class_colour(e: &Equilibrium) -> RGBColor {
    colour_of(Class::of(e.stable, e.knotted, e.good_knot))
}

/// The paper's colour of a class.
pub fn colour_of(class: Class) -> RGBColor {
    match class {
        Class::Unstable => RGBColor(210, 40, 40),
        Class::Unknotted => RGBColor(150, 95, 40),
        Class::Good => RGBColor(40, 160, 60),
        // stable, knotted, not walled (or touching); no point: white
        Class::StableUnwalled => RGBColor(40, 90, 200),
        Class::None => RGBColor(255, 255, 255),
    }
}

/// What a bifurcation diagram needs of one equilibrium.
#[derive(Clone, Debug)]
pub struct PlotPoint {
    /// φ/2π.
    pub phi_over_2pi: f64,
    /// Tw.
    pub twist: f64,
    /// Stable.
    pub stable: bool,
    /// Class colour.
    pub colour: RGBColor,
    /// Lowest ω².
    pub omega_squared: Option<f64>,
    /// Minimum self-distance.
    pub min_self_distance: f64,
    /// Branch.
    pub branch: usize,
    /// Leg.
    pub leg: usize,
}

impl From<&Equilibrium> for PlotPoint {
    fn from(e: &Equilibrium) -> Self {
        PlotPoint {
            phi_over_2pi: e.phi_over_2pi,
            twist: e.twist,
            stable: e.stable,
            colour: class_colour(e),
            omega_squared: e.omega_squared.first().copied(),
            min_self_distance: e.min_self_distance,
            branch: e.branch,
            leg: e.leg,
        }
    }
}

/// Polylines of the branches: (branch, leg) runs, each leg after the first
/// starting from its branch's first point.
fn legs(eqs: &[PlotPoint]) -> Vec<Vec<&PlotPoint>> {
    let mut out: Vec<((usize, usize), Vec<&PlotPoint>)> = Vec::new();
    for e in eqs {
        match out.iter_mut().find(|(k, _)| *k == (e.branch, e.leg)) {
            Some((_, v)) => v.push(e),
            None => {
                let mut v = Vec::new();
                if e.leg > 0
                    && let Some(first) = eqs.iter().find(|f| f.branch == e.branch)
                {
                    v.push(first);
                }
                v.push(e);
                out.push(((e.branch, e.leg), v));
            }
        }
    }
    out.into_iter().map(|(_, v)| v).collect()
}

pub(crate) fn font_available() -> bool {
    use std::sync::OnceLock;
    static OK: OnceLock<bool> = OnceLock::new();
    *OK.get_or_init(|| {
        let candidates = [
            "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
            "/usr/share/fonts/TTF/DejaVuSans.ttf",
            "/usr/share/fonts/dejavu/DejaVuSans.ttf",
            "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
        ];
        for c in candidates {
            if let Ok(bytes) = std::fs::read(c) {
                let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
                if plotters::style::register_font("sans-serif", FontStyle::Normal, bytes).is_ok() {
                    return true;
                }
            }
        }
        false
    })
}

fn draw<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    title: &str,
    eqs: &[PlotPoint],
    events: &[Event],
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)
        .map_err(|e| IoError::Plot(format!("{e:?}")))?;
    let (top, bottom) = root.split_vertically((root.dim_in_pixel().1 as f64 * 0.55) as u32);
    let (mid, low) = bottom.split_vertically(bottom.dim_in_pixel().1 / 2);
    let finite = |v: f64| v.is_finite();
    let xs: Vec<f64> = eqs.iter().map(|e| e.phi_over_2pi).collect();
    let (x0, x1) = bounds(&xs);
    let tw: Vec<f64> = eqs.iter().map(|e| e.twist).collect();
    let (y0, y1) = bounds(&tw);
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| IoError::Plot(format!("{e:?}"));
    let mut chart = ChartBuilder::on(&top)
        .caption(title, ("sans-serif", 18))
        .margin(8)
        .x_label_area_size(30)
        .y_label_area_size(50)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("φ/2π")
        .y_desc("Tw")
        .draw()
        .map_err(err)?;
    for leg in legs(eqs) {
        for w in leg.windows(2) {
            // a segment takes the class of its unstable end, if any
            let colour = if w[0].stable {
                w[1].colour
            } else {
                w[0].colour
            };
            chart
                .draw_series(LineSeries::new(
                    [
                        (w[0].phi_over_2pi, w[0].twist),
                        (w[1].phi_over_2pi, w[1].twist),
                    ],
                    colour.stroke_width(3),
                ))
                .map_err(err)?;
        }
    }
    for e in events.iter().filter(|e| !e.label.is_empty()) {
        chart
            .draw_series(std::iter::once(Circle::new(
                (e.phi_over_2pi, e.twist),
                4,
                BLACK.filled(),
            )))
            .map_err(err)?;
        chart
            .draw_series(std::iter::once(Text::new(
                e.label.clone(),
                (e.phi_over_2pi, e.twist),
                ("sans-serif", 14).into_font().color(&BLACK),
            )))
            .map_err(err)?;
    }
    // lowest ω² (signed log scale would hide the crossing: plot it linearly, clipped)
    let om: Vec<f64> = eqs
        .iter()
        .filter_map(|e| e.omega_squared)
        .filter(|v| finite(*v))
        .collect();
    let (o0, o1) = bounds(&om);
    let mut c2 = ChartBuilder::on(&mid)
        .margin(8)
        .x_label_area_size(25)
        .y_label_area_size(50)
        .build_cartesian_2d(x0..x1, o0..o1)
        .map_err(err)?;
    c2.configure_mesh()
        .y_desc("lowest ω²")
        .draw()
        .map_err(err)?;
    c2.draw_series(LineSeries::new([(x0, 0.0), (x1, 0.0)], BLACK.mix(0.4)))
        .map_err(err)?;
    for leg in legs(eqs) {
        let pts: Vec<(f64, f64)> = leg
            .iter()
            .filter_map(|e| e.omega_squared.map(|w| (e.phi_over_2pi, w)))
            .collect();
        c2.draw_series(LineSeries::new(pts, RGBColor(80, 80, 80).stroke_width(2)))
            .map_err(err)?;
    }
    let sd: Vec<f64> = eqs
        .iter()
        .map(|e| e.min_self_distance)
        .filter(|v| finite(*v))
        .collect();
    let (s0, s1) = bounds(&sd);
    let mut c3 = ChartBuilder::on(&low)
        .margin(8)
        .x_label_area_size(30)
        .y_label_area_size(50)
        .build_cartesian_2d(x0..x1, s0.min(0.0)..s1)
        .map_err(err)?;
    c3.configure_mesh()
        .x_desc("φ/2π")
        .y_desc("min self-distance")
        .draw()
        .map_err(err)?;
    for leg in legs(eqs) {
        let pts: Vec<(f64, f64)> = leg
            .iter()
            .filter(|e| e.min_self_distance.is_finite())
            .map(|e| (e.phi_over_2pi, e.min_self_distance))
            .collect();
        c3.draw_series(LineSeries::new(pts, RGBColor(40, 90, 200).stroke_width(2)))
            .map_err(err)?;
    }
    root.present().map_err(err)?;
    Ok(())
}

fn bounds(v: &[f64]) -> (f64, f64) {
    let lo = v
        .iter()
        .copied()
        .filter(|x| x.is_finite())
        .fold(f64::INFINITY, f64::min);
    let hi = v
        .iter()
        .copied()
        .filter(|x| x.is_finite())
        .fold(f64::NEG_INFINITY, f64::max);
    if !lo.is_finite() || !hi.is_finite() {
        return (0.0, 1.0);
    }
    let pad = 0.05 * (hi - lo).max(1e-9);
    (lo - pad, hi + pad)
}

/// Write the bifurcation diagram as `stem.svg` and (fonts permitting) `stem.png`.
/// Returns the files written.
pub fn bifurcation_diagram(
    stem: &Path,
    title: &str,
    eqs: &[PlotPoint],
    events: &[Event],
) -> Result<Vec<std::path::PathBuf>> {
    let mut written = Vec::new();
    let fonts = font_available();
    let svg = stem.with_extension("svg");
    write_svg(&svg, (900, 900), |root| draw(root, title, eqs, events))?;
    written.push(svg);
    if fonts {
        let png = stem.with_extension("png");
        write_png(&png, (900, 900), |root| draw(root, title, eqs, events))?;
        written.push(png);
    }
    Ok(written)
}

/// The island map: classified grid as dots (colours as in the diagrams) and
/// the boundary curves labelled, in the (value along the lines, swept parameter)
/// plane: (φ/2π, z*) for the paper's maps.
pub fn island_map(stem: &Path, map: &crate::study::map::Map) -> Result<Vec<std::path::PathBuf>> {
    let mut written = Vec::new();
    let fonts = font_available();
    let svg = stem.with_extension("svg");
    write_svg(&svg, (900, 700), |root| draw_map(root, map))?;
    written.push(svg);
    if fonts {
        let png = stem.with_extension("png");
        write_png(&png, (900, 700), |root| draw_map(root, map))?;
        written.push(png);
    }
    Ok(written)
}

/// A 3D map as stacked slices, one panel each (SVG, and PNG when a font is
/// available).
pub fn island_slices(
    stem: &Path,
    map: &crate::study::map::Map3,
) -> Result<Vec<std::path::PathBuf>> {
    let n = map.slices.len().max(1);
    let cols = n.min(4);
    let rows = n.div_ceil(cols);
    let size = (450 * cols as u32, 380 * rows as u32);
    let mut written = Vec::new();
    let svg = stem.with_extension("svg");
    write_svg(&svg, size, |root| draw_slices(root, map, (rows, cols)))?;
    written.push(svg);
    if font_available() {
        let png = stem.with_extension("png");
        write_png(&png, size, |root| draw_slices(root, map, (rows, cols)))?;
        written.push(png);
    }
    Ok(written)
}

/// The slices of a 3D map in a grid of (rows, columns) panels.
fn draw_slices<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    map: &crate::study::map::Map3,
    grid: (usize, usize),
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let err = |e| IoError::Plot(format!("{e:?}"));
    root.fill(&WHITE).map_err(err)?;
    for (area, m) in root.split_evenly(grid).into_iter().zip(&map.slices) {
        draw_map(area, m)?;
    }
    root.present().map_err(err)
}

fn draw_map<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    map: &crate::study::map::Map,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| IoError::Plot(format!("{e:?}"));
    root.fill(&WHITE).map_err(err)?;
    let (x0, x1) = bounds(&map.grid_along);
    let values: Vec<f64> = map.lines.iter().map(|l| l.value).collect();
    let (y0, y1) = bounds(&values);
    let mut chart = ChartBuilder::on(&root)
        .caption(format!("{}: good knots", map.scene), ("sans-serif", 18))
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(55)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc(map.along.symbol())
        .y_desc(map.parameter.symbol())
        .draw()
        .map_err(err)?;
    for (row, l) in map.grid.iter().zip(&map.lines) {
        for (c, x) in row.iter().zip(&map.grid_along) {
            if *c == Class::None {
                continue;
            }
            let col = colour_of(*c);
            chart
                .draw_series(std::iter::once(Circle::new((*x, l.value), 2, col.filled())))
                .map_err(err)?;
        }
    }
    for (name, pts) in &map.boundaries {
        // in order along the curve (traced walks fold; grid chains go by line)
        let pts: Vec<(f64, f64)> = pts.iter().map(|p| (p[1], p[0])).collect();
        chart
            .draw_series(LineSeries::new(pts.clone(), BLACK.stroke_width(2)))
            .map_err(err)?;
        if let Some(&(x, y)) = pts.get(pts.len() / 2) {
            chart
                .draw_series(std::iter::once(Text::new(
                    name.clone(),
                    (x, y),
                    ("sans-serif", 16).into_font().color(&BLACK),
                )))
                .map_err(err)?;
        }
    }
    root.present().map_err(err)?;
    Ok(())
}
