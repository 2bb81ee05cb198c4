//! Bifurcation diagrams in the paper's style: the (φ/2π, Tw) plane with
//! segments coloured green (good knot), blue (stable, knotted, not walled or
//! touching itself), brown (unknotted), red (unstable), events labelled;
//! below, the lowest ω² and the minimum self-distance along the branches.
//! SVG always; PNG when a TrueType font is found for the labels.

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
    /// z* (to name branches at several z*).
    pub z_star: f64,
    /// δ.
    pub delta: f64,
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
            z_star: e.z_star,
            delta: e.delta,
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

/// The paper's classes as the legend names them, in its order.
const LEGEND: [(Class, &str); 4] = [
    (Class::Good, "good knot"),
    (
        Class::StableUnwalled,
        "stable knot, unwalled or touching itself",
    ),
    (Class::Unknotted, "unknotted"),
    (Class::Unstable, "unstable"),
];

/// The title and, below it, the legend of the classes present (a line
/// sample in each class's colour and its name), centred in `head`.
fn draw_head<DB: DrawingBackend>(
    head: &DrawingArea<DB, Shift>,
    title: &str,
    present: &[RGBColor],
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let width = head.dim_in_pixel().0 as i32;
    let centred = |s: TextStyle<'static>| {
        s.pos(plotters::style::text_anchor::Pos::new(
            plotters::style::text_anchor::HPos::Center,
            plotters::style::text_anchor::VPos::Top,
        ))
    };
    head.draw(&Text::new(
        title.to_string(),
        (width / 2, 6),
        centred(("sans-serif", 18).into_font().color(&BLACK)),
    ))
    .map_err(plot_error)?;
    let font = ("sans-serif", 13).into_font().color(&BLACK);
    let entries: Vec<(RGBColor, &str, i32)> = LEGEND
        .iter()
        .map(|(c, name)| (colour_of(*c), *name))
        .filter(|(c, _)| present.contains(c))
        .map(|(c, name)| {
            let w = head
                .estimate_text_size(name, &font)
                .map_or(8 * name.len() as u32, |s| s.0);
            (c, name, w as i32)
        })
        .collect();
    let sample = 26;
    let gap = 22;
    let total: i32 = entries.iter().map(|e| sample + 6 + e.2).sum::<i32>()
        + gap * (entries.len() as i32 - 1).max(0);
    let mut x = (width - total) / 2;
    let y = 38;
    for (c, name, w) in entries {
        head.draw(&PathElement::new(
            vec![(x, y), (x + sample, y)],
            c.stroke_width(3),
        ))
        .map_err(plot_error)?;
        head.draw(&Text::new(
            name.to_string(),
            (x + sample + 6, y - 7),
            font.clone(),
        ))
        .map_err(plot_error)?;
        x += sample + 6 + w + gap;
    }
    Ok(())
}

/// A label to place beside a point (pixels), clear of the others.
struct Label {
    text: String,
    at: (i32, i32),
}

/// Write `labels` on `area` beside their points: each at the first of a few
/// positions around its point that stays inside `frame` (pixels: x0, y0, x1,
/// y1) and clear of the labels already placed and of every labelled point;
/// so no label is clipped at the frame or written over another.
fn place_labels<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    labels: &[Label],
    frame: (i32, i32, i32, i32),
    font: &TextStyle,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    type Rect = (i32, i32, i32, i32);
    let overlaps = |a: &Rect, b: &Rect| a.0 < b.2 && b.0 < a.2 && a.1 < b.3 && b.1 < a.3;
    let dots: Vec<Rect> = labels
        .iter()
        .map(|l| (l.at.0 - 5, l.at.1 - 5, l.at.0 + 5, l.at.1 + 5))
        .collect();
    let mut placed: Vec<Rect> = Vec::new();
    let mut written: Vec<(&str, (i32, i32))> = Vec::new();
    for l in labels {
        // the same event located on two branches at one point: named once
        let near = |p: &(i32, i32)| (p.0 - l.at.0).abs() + (p.1 - l.at.1).abs() < 8;
        if written.iter().any(|(t, p)| *t == l.text && near(p)) {
            continue;
        }
        written.push((&l.text, l.at));
        let (w, h) = area
            .estimate_text_size(&l.text, font)
            .map_or((8 * l.text.len() as i32, 14), |s| (s.0 as i32, s.1 as i32));
        let (x, y) = l.at;
        // beside the point first, then further up and down, a line at a time
        let mut offsets = vec![
            (7, -h - 3),
            (7, 3),
            (-w - 7, -h - 3),
            (-w - 7, 3),
            (-w / 2, -h - 8),
            (-w / 2, 8),
        ];
        for r in 1..8 {
            let step = r * (h + 2);
            for dx in [7, -w - 7, -w / 2] {
                offsets.push((dx, -h - 3 - step));
                offsets.push((dx, 3 + step));
            }
        }
        let inside =
            |r: &Rect| r.0 >= frame.0 && r.1 >= frame.1 && r.2 <= frame.2 && r.3 <= frame.3;
        let boxes: Vec<Rect> = offsets
            .iter()
            .map(|(dx, dy)| (x + dx, y + dy, x + dx + w, y + dy + h))
            .collect();
        let free = |r: &Rect| {
            inside(r)
                && !placed.iter().any(|p| overlaps(p, r))
                && !dots.iter().any(|d| overlaps(d, r))
        };
        // else the first inside the frame, else pushed into it
        let chosen = boxes
            .iter()
            .find(|r| free(r))
            .or_else(|| boxes.iter().find(|r| inside(r)))
            .copied()
            .unwrap_or_else(|| {
                let bx = (x + 7).clamp(frame.0, (frame.2 - w).max(frame.0));
                let by = (y - h - 3).clamp(frame.1, (frame.3 - h).max(frame.1));
                (bx, by, bx + w, by + h)
            });
        // on a white ground, so a curve under it does not cross it out
        area.draw(&Rectangle::new(
            [(chosen.0 - 2, chosen.1 - 1), (chosen.2 + 2, chosen.3 + 1)],
            WHITE.mix(0.8).filled(),
        ))
        .map_err(plot_error)?;
        area.draw(&Text::new(
            l.text.clone(),
            (chosen.0, chosen.1),
            font.clone(),
        ))
        .map_err(plot_error)?;
        placed.push(chosen);
    }
    Ok(())
}

/// The scale of the lowest ω² panel: a symmetric logarithm (linear within
/// ±c, logarithmic beyond, c three decades below the largest |ω²|) where the
/// values change sign or span decades, so the sign changes (S, folds) show
/// beside values in the thousands; else linear.
#[derive(Clone, Copy, Debug)]
struct SymLog {
    c: f64,
    linear: bool,
}

impl SymLog {
    fn for_values(v: &[f64]) -> SymLog {
        let top = v.iter().map(|x| x.abs()).fold(0.0, f64::max);
        let low = v.iter().map(|x| x.abs()).fold(f64::INFINITY, f64::min);
        let one_sign = v.iter().all(|x| *x > 0.0) || v.iter().all(|x| *x < 0.0);
        let c = if top > 0.0 {
            10f64.powf(top.log10().floor() - 3.0)
        } else {
            1.0
        };
        SymLog {
            c,
            linear: one_sign && top < 10.0 * low,
        }
    }
    fn to(&self, v: f64) -> f64 {
        if self.linear {
            return v;
        }
        v.signum() * (v.abs() / self.c).ln_1p() / std::f64::consts::LN_10
    }
    fn from(&self, t: f64) -> f64 {
        if self.linear {
            return t;
        }
        t.signum() * self.c * (t.abs() * std::f64::consts::LN_10).exp_m1()
    }
    /// The axis's ticks within (lo, hi) (transformed), in the order they
    /// are drawn (where they crowd, the first drawn stay): 0, the decades
    /// ±c·10^k, then ±2c·10^k and ±5c·10^k; or (linear) multiples of a round
    /// step, nearest zero first.
    fn ticks(&self, lo: f64, hi: f64) -> Vec<f64> {
        let mut keys = Vec::new();
        if self.linear {
            let raw = (hi - lo) / 5.0;
            let decade = 10f64.powf(raw.log10().floor());
            let step = [1.0, 2.0, 5.0, 10.0]
                .into_iter()
                .map(|m| m * decade)
                .find(|s| *s >= raw)
                .unwrap_or(10.0 * decade);
            let mut k = (lo / step).ceil();
            while k * step < hi {
                keys.push(k * step);
                k += 1.0;
            }
        } else {
            // zero, the decades, then 2 and 5 times them: where ticks
            // crowd, the first ones drawn are kept
            keys.push(0.0);
            for m in [1.0, 2.0, 5.0] {
                for k in 0..12 {
                    let v = m * self.c * 10f64.powi(k);
                    keys.extend([self.to(v), self.to(-v)]);
                }
            }
            keys.retain(|t| *t > lo && *t < hi);
            return keys;
        }
        keys.retain(|t| *t > lo && *t < hi);
        keys.sort_by(|a, b| a.abs().total_cmp(&b.abs()));
        keys
    }
}

/// A tick value, briefly: 3 significant digits, powers of ten as 1e4 past
/// four digits.
fn tick_text(v: f64) -> String {
    // an axis's zero comes as a rounding residue (−6e−17)
    if v.abs() < 1e-12 {
        return "0".into();
    }
    let a = v.abs();
    if (1e-3..1e4).contains(&a) {
        let digits = (2 - a.log10().floor() as i32).max(0) as usize;
        let s = format!("{v:.digits$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    } else {
        format!("{v:.0e}")
    }
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
    root.fill(&WHITE).map_err(plot_error)?;
    let mut present: Vec<RGBColor> = Vec::new();
    for e in eqs {
        if !present.contains(&e.colour) {
            present.push(e.colour);
        }
    }
    // branches at several values of a second parameter (Figure 6) are named
    // under the legend, in the order of their folds
    let names = branch_names(eqs);
    let (head, body) = root.split_vertically(if names.is_empty() { 56 } else { 76 });
    draw_head(&head, title, &present)?;
    if !names.is_empty() {
        head.draw(&Text::new(
            names,
            (head.dim_in_pixel().0 as i32 / 2, 54),
            ("sans-serif", 13).into_font().color(&BLACK).pos(
                plotters::style::text_anchor::Pos::new(
                    plotters::style::text_anchor::HPos::Center,
                    plotters::style::text_anchor::VPos::Top,
                ),
            ),
        ))
        .map_err(plot_error)?;
    }
    let (top, bottom) = body.split_vertically((body.dim_in_pixel().1 as f64 * 0.55) as u32);
    let (mid, low) = bottom.split_vertically(bottom.dim_in_pixel().1 / 2);
    let xs: Vec<f64> = eqs.iter().map(|e| e.phi_over_2pi).collect();
    let x = bounds(&xs);
    draw_twist_panel(&root, &top, x, eqs, events)?;
    draw_omega_panel(&root, &mid, x, eqs)?;
    draw_distance_panel(&low, x, eqs)?;
    root.present().map_err(plot_error)?;
    Ok(())
}

/// One width for the three panels' tick labels, so their x axes align.
const Y_LABEL_AREA: u32 = 78;

/// The (φ/2π, Tw) panel: the branches coloured by class, the events
/// marked and labelled (placed on `root`, clear of each other).
fn draw_twist_panel<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    top: &DrawingArea<DB, Shift>,
    (x0, x1): (f64, f64),
    eqs: &[PlotPoint],
    events: &[Event],
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let tw: Vec<f64> = eqs.iter().map(|e| e.twist).collect();
    let (y0, y1) = bounds(&tw);
    let mut chart = ChartBuilder::on(top)
        .margin(8)
        .margin_right(18)
        .x_label_area_size(34)
        .y_label_area_size(Y_LABEL_AREA)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(plot_error)?;
    chart
        .configure_mesh()
        .x_desc("φ/2π")
        .y_desc("Tw")
        .x_label_formatter(&|v| tick_text(*v))
        .y_label_formatter(&|v| tick_text(*v))
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(plot_error)?;
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
                .map_err(plot_error)?;
        }
    }
    let labelled: Vec<&Event> = events.iter().filter(|e| !e.label.is_empty()).collect();
    chart
        .draw_series(
            labelled
                .iter()
                .map(|e| Circle::new((e.phi_over_2pi, e.twist), 4, BLACK.filled())),
        )
        .map_err(plot_error)?;
    let labels: Vec<Label> = labelled
        .iter()
        .map(|e| Label {
            text: e.label.clone(),
            at: chart.backend_coord(&(e.phi_over_2pi, e.twist)),
        })
        .collect();
    let (px, py) = chart.plotting_area().get_pixel_range();
    place_labels(
        root,
        &labels,
        (px.start, py.start, px.end, py.end),
        &("sans-serif", 14).into_font().color(&BLACK),
    )
}

/// The lowest ω² panel on a symmetric log scale (its sign changes show),
/// its ticks drawn here on `root`: plotters would place them evenly in the
/// transformed value.
fn draw_omega_panel<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    mid: &DrawingArea<DB, Shift>,
    (x0, x1): (f64, f64),
    eqs: &[PlotPoint],
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let om: Vec<f64> = eqs
        .iter()
        .filter_map(|e| e.omega_squared)
        .filter(|v| v.is_finite())
        .collect();
    let log = SymLog::for_values(&om);
    let (o0, o1) = bounds(&om.iter().map(|v| log.to(*v)).collect::<Vec<_>>());
    let mut c2 = ChartBuilder::on(mid)
        .margin(8)
        .margin_right(18)
        .x_label_area_size(26)
        .y_label_area_size(Y_LABEL_AREA)
        .build_cartesian_2d(x0..x1, o0..o1)
        .map_err(plot_error)?;
    c2.configure_mesh()
        .y_desc(if log.linear {
            "lowest ω²"
        } else {
            "lowest ω² (symlog)"
        })
        .x_label_formatter(&|v| tick_text(*v))
        .y_labels(0)
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(plot_error)?;
    let tick_font =
        ("sans-serif", 12)
            .into_font()
            .color(&BLACK)
            .pos(plotters::style::text_anchor::Pos::new(
                plotters::style::text_anchor::HPos::Right,
                plotters::style::text_anchor::VPos::Center,
            ));
    let mut drawn: Vec<i32> = Vec::new();
    for tick in log.ticks(o0, o1) {
        // nearest zero first; a tick too close to one drawn is left out
        let (x, y) = c2.backend_coord(&(x0, tick));
        if drawn.iter().any(|d| (d - y).abs() < 14) {
            continue;
        }
        drawn.push(y);
        c2.draw_series(LineSeries::new(
            [(x0, tick), (x1, tick)],
            BLACK.mix(0.12).stroke_width(1),
        ))
        .map_err(plot_error)?;
        root.draw(&PathElement::new(vec![(x - 5, y), (x, y)], BLACK))
            .map_err(plot_error)?;
        root.draw(&Text::new(
            tick_text(log.from(tick)),
            (x - 8, y),
            tick_font.clone(),
        ))
        .map_err(plot_error)?;
    }
    if o0 < 0.0 && o1 > 0.0 {
        c2.draw_series(LineSeries::new(
            [(x0, 0.0), (x1, 0.0)],
            BLACK.mix(0.7).stroke_width(1),
        ))
        .map_err(plot_error)?;
    }
    for leg in legs(eqs) {
        // coloured by stability, as the diagram above
        for w in leg.windows(2) {
            let (Some(a), Some(b)) = (w[0].omega_squared, w[1].omega_squared) else {
                continue;
            };
            let colour = if a > 0.0 && b > 0.0 {
                RGBColor(60, 60, 60)
            } else {
                colour_of(Class::Unstable)
            };
            c2.draw_series(LineSeries::new(
                [
                    (w[0].phi_over_2pi, log.to(a)),
                    (w[1].phi_over_2pi, log.to(b)),
                ],
                colour.stroke_width(2),
            ))
            .map_err(plot_error)?;
        }
    }
    Ok(())
}

/// The least self-distance panel.
fn draw_distance_panel<DB: DrawingBackend>(
    low: &DrawingArea<DB, Shift>,
    (x0, x1): (f64, f64),
    eqs: &[PlotPoint],
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    let sd: Vec<f64> = eqs
        .iter()
        .map(|e| e.min_self_distance)
        .filter(|v| v.is_finite())
        .collect();
    let (s0, s1) = bounds(&sd);
    let mut c3 = ChartBuilder::on(low)
        .margin(8)
        .margin_right(18)
        .x_label_area_size(34)
        .y_label_area_size(Y_LABEL_AREA)
        .build_cartesian_2d(x0..x1, s0.min(0.0)..s1)
        .map_err(plot_error)?;
    c3.configure_mesh()
        .x_desc("φ/2π")
        .y_desc("min self-distance")
        .x_label_formatter(&|v| tick_text(*v))
        .y_label_formatter(&|v| tick_text(*v))
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(plot_error)?;
    for leg in legs(eqs) {
        let pts: Vec<(f64, f64)> = leg
            .iter()
            .filter(|e| e.min_self_distance.is_finite())
            .map(|e| (e.phi_over_2pi, e.min_self_distance))
            .collect();
        c3.draw_series(LineSeries::new(pts, RGBColor(40, 90, 200).stroke_width(2)))
            .map_err(plot_error)?;
    }
    Ok(())
}

/// When the branches lie at several z* (or δ), one each: their values in
/// the order of their turning points (least φ), e.g. "z* = 0.115, 0.15, 0.18
/// (branches from left to right)"; empty otherwise.
fn branch_names(eqs: &[PlotPoint]) -> String {
    let distinct = |f: fn(&PlotPoint) -> f64| {
        let mut v: Vec<f64> = eqs.iter().map(f).collect();
        v.sort_by(f64::total_cmp);
        v.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
        v.len()
    };
    let (name, of): (&str, fn(&PlotPoint) -> f64) = if distinct(|e| e.z_star) > 1 {
        ("z*", |e| e.z_star)
    } else if distinct(|e| e.delta) > 1 {
        ("δ", |e| e.delta)
    } else {
        return String::new();
    };
    let mut branches: Vec<usize> = eqs.iter().map(|e| e.branch).collect();
    branches.sort_unstable();
    branches.dedup();
    let mut turns: Vec<(f64, f64, f64)> = branches
        .into_iter()
        .filter_map(|b| {
            let on: Vec<&PlotPoint> = eqs.iter().filter(|e| e.branch == b).collect();
            let first = on.first()?;
            // a branch held at one value of the second parameter
            if on.iter().any(|e| (of(e) - of(first)).abs() > 1e-9) {
                return None;
            }
            let turn = on
                .iter()
                .min_by(|a, b| a.phi_over_2pi.total_cmp(&b.phi_over_2pi))?;
            let end = on
                .iter()
                .max_by(|a, b| a.phi_over_2pi.total_cmp(&b.phi_over_2pi))?;
            Some((turn.phi_over_2pi, of(first), end.twist))
        })
        .collect();
    turns.dedup_by(|a, b| (a.1 - b.1).abs() < 1e-9);
    if turns.len() < 2 {
        return String::new();
    }
    // by their turning points when they turn at distinct φ (Figure 6), else
    // (branches cut at one φ, Figure 8) by their height at the right end
    let folds: Vec<f64> = turns.iter().map(|t| t.0).collect();
    let (f0, f1) = (
        folds.iter().copied().fold(f64::INFINITY, f64::min),
        folds.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    );
    let spread = f1 - f0;
    let (x0, x1) = bounds(&eqs.iter().map(|e| e.phi_over_2pi).collect::<Vec<_>>());
    let order = if spread > 0.02 * (x1 - x0) {
        turns.sort_by(|a, b| a.0.total_cmp(&b.0));
        "branches from left to right"
    } else {
        turns.sort_by(|a, b| b.2.total_cmp(&a.2));
        "branches from top to bottom at the right"
    };
    let values: Vec<String> = turns.iter().map(|t| tick_text(t.1)).collect();
    format!("{name} = {} ({order})", values.join(", "))
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
    root.fill(&WHITE).map_err(plot_error)?;
    for (area, m) in root.split_evenly(grid).into_iter().zip(&map.slices) {
        draw_map(area, m)?;
    }
    root.present().map_err(plot_error)
}

fn draw_map<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    map: &crate::study::map::Map,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(plot_error)?;
    let mut present: Vec<RGBColor> = Vec::new();
    for c in map.grid.iter().flatten().filter(|c| **c != Class::None) {
        if !present.contains(&colour_of(*c)) {
            present.push(colour_of(*c));
        }
    }
    let (head, body) = root.split_vertically(56);
    draw_head(&head, &format!("{}: good knots", map.scene), &present)?;
    let (x0, x1) = bounds(&map.grid_along);
    let values: Vec<f64> = map.lines.iter().map(|l| l.value).collect();
    let (y0, y1) = bounds(&values);
    let mut chart = ChartBuilder::on(&body)
        .margin(10)
        .margin_right(18)
        .x_label_area_size(35)
        .y_label_area_size(62)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(plot_error)?;
    chart
        .configure_mesh()
        .x_desc(map.along.symbol())
        .y_desc(map.parameter.symbol())
        .x_label_formatter(&|v| tick_text(*v))
        .y_label_formatter(&|v| tick_text(*v))
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(plot_error)?;
    for (row, l) in map.grid.iter().zip(&map.lines) {
        for (c, x) in row.iter().zip(&map.grid_along) {
            if *c == Class::None {
                continue;
            }
            let col = colour_of(*c);
            chart
                .draw_series(std::iter::once(Circle::new((*x, l.value), 2, col.filled())))
                .map_err(plot_error)?;
        }
    }
    let mut labels = Vec::new();
    for (name, pts) in &map.boundaries {
        // in order along the curve (traced walks fold; grid chains go by line)
        let pts: Vec<(f64, f64)> = pts.iter().map(|p| (p[1], p[0])).collect();
        chart
            .draw_series(LineSeries::new(pts.clone(), BLACK.stroke_width(2)))
            .map_err(plot_error)?;
        if let Some(at) = pts.get(pts.len() / 2) {
            labels.push(Label {
                text: name.clone(),
                at: chart.backend_coord(at),
            });
        }
    }
    // the curves' names (S, X, W1, W2) beside them, inside the frame
    let (px, py) = chart.plotting_area().get_pixel_range();
    place_labels(
        &root,
        &labels,
        (px.start, py.start, px.end, py.end),
        &("sans-serif", 16).into_font().color(&BLACK),
    )?;
    root.present().map_err(plot_error)?;
    Ok(())
}

/// Several maps' islands on one plane, as the paper's Figure 10-right draws
/// them: the first map's polished boundary (else its traced one) as a
/// coloured region, the others' as curves, each named in the legend by its
/// `names` entry; `mark`, if given, a point drawn and named (a knot of
/// interest). SVG, and PNG when a font is available.
pub fn island_overlay(
    stem: &Path,
    title: &str,
    maps: &[(&str, &crate::study::map::Map)],
    mark: Option<(&str, [f64; 2])>,
) -> Result<Vec<std::path::PathBuf>> {
    let mut written = Vec::new();
    // the legend's layout measures its text: with the font registered
    let fonts = font_available();
    let svg = stem.with_extension("svg");
    write_svg(&svg, (900, 700), |root| {
        draw_overlay(root, title, maps, mark)
    })?;
    written.push(svg);
    if fonts {
        let png = stem.with_extension("png");
        write_png(&png, (900, 700), |root| {
            draw_overlay(root, title, maps, mark)
        })?;
        written.push(png);
    }
    Ok(written)
}

/// A map's island boundary, closed, as (value along, swept) points: the
/// polished one, else the traced one; None without a closed one.
fn island_outline(map: &crate::study::map::Map) -> Option<Vec<(f64, f64)>> {
    let t = map.traced.as_ref().filter(|t| t.closed)?;
    let mut pts: Vec<(f64, f64)> = match &t.polished {
        Some(p) => p.polygon(),
        None => t.polygon(),
    }
    .iter()
    .map(|p| (p[1], p[0]))
    .collect();
    if let Some(&first) = pts.first() {
        pts.push(first);
    }
    (pts.len() > 2).then_some(pts)
}

/// Colours of the overlaid curves after the region (distinct on white).
const CURVES: [RGBColor; 7] = [
    RGBColor(20, 20, 20),
    RGBColor(200, 40, 40),
    RGBColor(30, 80, 200),
    RGBColor(150, 90, 0),
    RGBColor(130, 50, 170),
    RGBColor(0, 140, 150),
    RGBColor(230, 120, 170),
];

fn draw_overlay<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    title: &str,
    maps: &[(&str, &crate::study::map::Map)],
    mark: Option<(&str, [f64; 2])>,
) -> Result<()>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(plot_error)?;
    let outlines = maps
        .iter()
        .map(|(name, m)| {
            let why = || {
                let walk = m.traced.as_ref().and_then(|t| t.stopped.clone());
                IoError::Plot(format!(
                    "{name}: the map has no closed boundary to draw ({})",
                    walk.unwrap_or_else(|| "no boundary traced".into())
                ))
            };
            island_outline(m).map(|o| (*name, o)).ok_or_else(why)
        })
        .collect::<Result<Vec<(&str, Vec<(f64, f64)>)>>>()?;
    let mut xs: Vec<f64> = outlines
        .iter()
        .flat_map(|o| o.1.iter().map(|p| p.0))
        .collect();
    let mut ys: Vec<f64> = outlines
        .iter()
        .flat_map(|o| o.1.iter().map(|p| p.1))
        .collect();
    if let Some((_, p)) = mark {
        xs.push(p[1]);
        ys.push(p[0]);
    }
    if xs.is_empty() {
        return Err(IoError::Plot("no map has a traced boundary to draw".into()));
    }
    let (x0, x1) = bounds(&xs);
    let (y0, y1) = bounds(&ys);
    let (along, swept) = (maps[0].1.along, maps[0].1.parameter);
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 18))
        .margin(12)
        .margin_right(20)
        .x_label_area_size(38)
        .y_label_area_size(62)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(plot_error)?;
    chart
        .configure_mesh()
        .x_desc(along.symbol())
        .y_desc(swept.symbol())
        .x_label_formatter(&|v| tick_text(*v))
        .y_label_formatter(&|v| tick_text(*v))
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(plot_error)?;
    let region = colour_of(Class::Good);
    for (k, (name, pts)) in outlines.iter().enumerate() {
        if k == 0 {
            chart
                .draw_series(std::iter::once(Polygon::new(pts.clone(), region.mix(0.45))))
                .map_err(plot_error)?
                .label(*name)
                .legend(move |(x, y)| {
                    Rectangle::new([(x, y - 6), (x + 20, y + 6)], region.mix(0.45).filled())
                });
        } else {
            let c = CURVES[(k - 1) % CURVES.len()];
            chart
                .draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))
                .map_err(plot_error)?
                .label(*name)
                .legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2))
                });
        }
    }
    if let Some((name, p)) = mark {
        chart
            .draw_series(std::iter::once(Cross::new(
                (p[1], p[0]),
                7,
                BLACK.stroke_width(2),
            )))
            .map_err(plot_error)?
            .label(name)
            .legend(|(x, y)| Cross::new((x + 10, y), 5, BLACK.stroke_width(2)));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.4))
        .label_font(("sans-serif", 14))
        .draw()
        .map_err(plot_error)?;
    root.present().map_err(plot_error)
}

/// A drawing backend's error as the plot's.
pub(crate) fn plot_error<E: std::fmt::Debug>(e: E) -> IoError {
    IoError::Plot(format!("{e:?}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_symmetric_log_keeps_signs_and_inverts() {
        let log = SymLog::for_values(&[-3500.0, 2.0, 900.0]);
        // three decades below the largest value
        assert_eq!(log.c, 1.0);
        for v in [-3500.0, -1.0, -1e-3, 0.0, 1e-3, 0.5, 2.0, 900.0] {
            let t = log.to(v);
            assert!(t.signum() * v.signum() >= 0.0, "{v}: sign kept");
            assert!((log.from(t) - v).abs() <= 1e-12 * v.abs().max(1.0), "{v}");
        }
        assert!(log.to(-1.0) < log.to(-1e-3) && log.to(1e-3) < log.to(1.0));
        // the ticks: 0 first, then ±{1, 2, 5}·c·10^k outwards, inside the
        // range only
        let ticks = log.ticks(log.to(-5000.0), log.to(2000.0));
        assert_eq!(ticks[0], 0.0);
        let values: Vec<f64> = ticks.iter().map(|t| log.from(*t).round()).collect();
        for v in [1.0, -1.0, 10.0, -20.0, 500.0, 1000.0, -2000.0] {
            assert!(values.contains(&v), "{v} in {values:?}");
        }
        assert!(!values.contains(&10000.0) && !values.contains(&5000.0));
        // one sign within a decade: linear, round ticks, no zero
        let log = SymLog::for_values(&[394.6, 787.8]);
        assert!(log.linear && log.to(500.0) == 500.0);
        let ticks = log.ticks(375.0, 808.0);
        assert_eq!(ticks, [400.0, 500.0, 600.0, 700.0, 800.0]);
    }

    #[test]
    fn tick_labels_are_brief() {
        for (v, text) in [
            (-6e-17, "0"),
            (0.0, "0"),
            (0.005, "0.005"),
            (-0.15, "-0.15"),
            (0.1150, "0.115"),
            (999.9999999, "1000"),
            (-3500.0, "-3500"),
            (12000.0, "1e4"),
        ] {
            assert_eq!(tick_text(v), text, "{v}");
        }
    }

    /// The labels an SVG holds: their text and top-left corners.
    fn texts(svg: &str) -> Vec<(String, i32, i32)> {
        svg.split("<text")
            .skip(1)
            .map(|t| {
                let attr = |name: &str| -> i32 {
                    let at = t.find(&format!(" {name}=\"")).unwrap() + name.len() + 3;
                    t[at..].split('"').next().unwrap().parse::<f64>().unwrap() as i32
                };
                let body = t.split('>').nth(1).unwrap().split('<').next().unwrap();
                (body.trim().to_string(), attr("x"), attr("y"))
            })
            .collect()
    }

    #[test]
    fn labels_stay_inside_the_frame_and_clear_of_each_other() {
        let frame = (20, 20, 380, 280);
        // crowded pairs, one at each corner of the frame, and one event
        // located twice at one point (named once)
        let points = [
            ("F1", (21, 150)),
            ("S", (24, 154)),
            ("W1", (379, 21)),
            ("W2", (376, 25)),
            ("X", (200, 279)),
            ("X2", (203, 276)),
            ("Q", (200, 150)),
            ("Q", (201, 151)),
        ];
        let labels: Vec<Label> = points
            .iter()
            .map(|(t, at)| Label {
                text: t.to_string(),
                at: *at,
            })
            .collect();
        let mut svg = String::new();
        {
            let root = SVGBackend::with_string(&mut svg, (400, 300)).into_drawing_area();
            let font = ("sans-serif", 14).into_font().color(&BLACK);
            place_labels(&root, &labels, frame, &font).unwrap();
            root.present().unwrap();
        }
        let placed = texts(&svg);
        assert_eq!(placed.len(), 7, "{placed:?}");
        assert_eq!(placed.iter().filter(|p| p.0 == "Q").count(), 1);
        // a label's box: its anchor is the top-left corner; glyphs about
        // 0.6 of the size wide when no font is at hand
        let boxes: Vec<(i32, i32, i32, i32)> = placed
            .iter()
            .map(|(t, x, y)| (*x, *y, x + 9 * t.chars().count() as i32, y + 14))
            .collect();
        for (b, p) in boxes.iter().zip(&placed) {
            assert!(
                b.0 >= frame.0 && b.1 >= frame.1 && b.2 <= frame.2 + 2 && b.3 <= frame.3 + 2,
                "{p:?} outside the frame"
            );
        }
        for i in 0..boxes.len() {
            for j in 0..i {
                let (a, b) = (boxes[i], boxes[j]);
                let overlap = a.0 < b.2 && b.0 < a.2 && a.1 < b.3 && b.1 < a.3;
                assert!(!overlap, "{:?} over {:?}", placed[i], placed[j]);
            }
        }
    }
}
