//! Projecting, shading and painting the faces: orthographic projection,
//! Lambert shading with a highlight from a light above the viewer's left
//! shoulder, back faces of the tube dropped, the rest painted far to near
//! within each slab between the walls (the painter's algorithm: every face is
//! small beside the picture, so its centre's depth orders it). PNG through
//! tiny-skia (anti-aliased; captions by plotters' font rendering), SVG as
//! polygons.

use super::picture::{Body, Picture};
use super::shapes::{Face, Shape, Slab, faces};
use crate::io::error::{IoError, Result};
use nalgebra::Vector3;

/// A face on the screen, ready to paint.
#[derive(Clone, Copy, Debug)]
enum Mark {
    /// A filled polygon.
    Polygon {
        /// Corners, pixels.
        corners: [(f32, f32); 4],
        /// Colour and opacity.
        rgba: [u8; 4],
        /// Outline width in pixels (0: none); an opaque face's outline is
        /// its own colour, closing the hairline seams anti-aliasing leaves
        /// between neighbours.
        edge: f32,
        /// The outline's colour.
        edge_rgba: [u8; 4],
    },
    /// A filled circle.
    Disc {
        /// Centre, pixels.
        centre: (f32, f32),
        /// Radius, pixels.
        radius: f32,
        /// Colour.
        rgba: [u8; 4],
    },
}

/// A line of text, its baseline's left end in pixels.
#[derive(Clone, Debug)]
struct Caption {
    at: (f32, f32),
    size: f32,
    text: String,
}

/// A panel's faces and the corners of their projection's bounding box.
type Panel = (Vec<Face>, (f64, f64), (f64, f64));

/// Where a panel's points go on the screen: x = mid.0 + (p·right − centre.0)
/// scale, y = mid.1 − (p·up − centre.1) scale.
#[derive(Clone, Copy, Debug)]
struct Placement {
    centre: (f64, f64),
    mid: (f32, f32),
    scale: f64,
    right: Vector3<f64>,
    up: Vector3<f64>,
}

impl Placement {
    fn screen(&self, p: &Vector3<f64>) -> (f32, f32) {
        let (u, v) = (p.dot(&self.right), p.dot(&self.up));
        (
            self.mid.0 + ((u - self.centre.0) * self.scale) as f32,
            self.mid.1 - ((v - self.centre.1) * self.scale) as f32,
        )
    }
}

/// Where the point `p` of the state in panel `panel` is drawn, in pixels from
/// the picture's top left corner.
pub fn pixel_of(
    bodies: &[Body],
    picture: &Picture,
    panel: usize,
    p: &Vector3<f64>,
) -> Option<(f32, f32)> {
    Some(lay_out(bodies, picture).2.get(panel)?.screen(p))
}

/// The marks and captions of the picture, in painting order, and each
/// panel's placement. The panels share one scale, so that states side by
/// side compare in size.
fn lay_out(bodies: &[Body], picture: &Picture) -> (Vec<Mark>, Vec<Caption>, Vec<Placement>) {
    let (w, h) = (picture.width as f32, picture.height as f32);
    let panels = bodies.len().max(1) as f32;
    let panel_width = w / panels;
    let captions_of: Vec<Vec<String>> = bodies.iter().map(Body::caption_lines).collect();
    let lines = captions_of.iter().map(Vec::len).max().unwrap_or(0);
    let longest = captions_of
        .iter()
        .flatten()
        .map(|l| l.chars().count())
        .max()
        .unwrap_or(0)
        .max(1);
    // a sans-serif character is about 0.55 of the font size wide
    let font = (h / 48.0)
        .min(0.92 * panel_width / (0.55 * longest as f32))
        .clamp(8.0, 26.0);
    let band = if lines > 0 {
        (lines as f32 + 0.6) * 1.25 * font
    } else {
        0.0
    };
    let [right, up, towards] = picture.view.axes();
    let light = (towards + 0.6 * up - 0.45 * right).normalize();
    let half = (light + towards).normalize();
    let project = |p: &Vector3<f64>| (p.dot(&right), p.dot(&up));
    let margin = 0.04 * panel_width.min(h - band);
    let room = (
        (panel_width - 2.0 * margin) as f64,
        (h - band - 2.0 * margin) as f64,
    );
    // each panel's faces and projected extent
    let panels: Vec<Panel> = bodies
        .iter()
        .map(|body| {
            let fs = faces(body);
            let mut lo = (f64::INFINITY, f64::INFINITY);
            let mut hi = (f64::NEG_INFINITY, f64::NEG_INFINITY);
            let mut grow = |p: (f64, f64), r: f64| {
                lo = (lo.0.min(p.0 - r), lo.1.min(p.1 - r));
                hi = (hi.0.max(p.0 + r), hi.1.max(p.1 + r));
            };
            for f in &fs {
                match f.shape {
                    Shape::Quad(c) => c.iter().for_each(|p| grow(project(p), 0.0)),
                    Shape::Disc { centre, radius } => grow(project(&centre), radius),
                }
            }
            (fs, lo, hi)
        })
        .collect();
    let scale = panels
        .iter()
        .map(|(_, lo, hi)| {
            let extent = ((hi.0 - lo.0).max(1e-9), (hi.1 - lo.1).max(1e-9));
            (room.0 / extent.0).min(room.1 / extent.1)
        })
        .fold(f64::INFINITY, f64::min);
    let mut marks = Vec::new();
    let mut captions = Vec::new();
    let mut placements = Vec::new();
    for (i, (fs, lo, hi)) in panels.iter().enumerate() {
        let x0 = i as f32 * panel_width;
        let placement = Placement {
            centre: (0.5 * (lo.0 + hi.0), 0.5 * (lo.1 + hi.1)),
            mid: (x0 + 0.5 * panel_width, 0.5 * (h - band)),
            scale,
            right,
            up,
        };
        placements.push(placement);
        let screen = |p: &Vector3<f64>| placement.screen(p);
        // far to near within a slab; the slabs from the far side of the
        // walls to the near side
        let order = |s: Slab| {
            let k = s as i32;
            if picture.view.elevation >= 0.0 { k } else { -k }
        };
        let mut keyed: Vec<(i32, f64, Mark)> = fs
            .iter()
            .filter_map(|f| {
                let rgba = shade(f, towards, light, half)?;
                // contact points are markers: on top of everything
                let key = if matches!(f.shape, Shape::Disc { .. }) {
                    i32::MAX
                } else {
                    order(f.slab)
                };
                Some((key, f.centre().dot(&towards), mark(f, rgba, &screen, scale)))
            })
            .collect();
        keyed.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
        marks.extend(keyed.into_iter().map(|(_, _, m)| m));
        for (k, line) in captions_of[i].iter().enumerate() {
            captions.push(Caption {
                at: (x0 + margin, h - band + (k as f32 + 1.0) * 1.25 * font),
                size: font,
                text: line.clone(),
            });
        }
    }
    (marks, captions, placements)
}

/// The colour of a face as the viewer sees it, or None for the back of a
/// tube (hidden by its front).
fn shade(
    f: &Face,
    towards: Vector3<f64>,
    light: Vector3<f64>,
    half: Vector3<f64>,
) -> Option<[u8; 4]> {
    let byte = |c: f64| (255.0 * c).round().clamp(0.0, 255.0) as u8;
    let Some(mut n) = f.normal else {
        let c = f.colour.map(byte);
        return Some([c[0], c[1], c[2], byte(f.alpha)]);
    };
    let mut colour = f.colour;
    if n.dot(&towards) < 0.0 {
        if !f.two_sided {
            // a little past the silhouette still shows where the tube bends
            if n.dot(&towards) < -0.3 {
                return None;
            }
        } else {
            n = -n;
            colour = f.back;
        }
    }
    let diffuse = n.dot(&light).max(0.0);
    let highlight = 0.28 * n.dot(&half).max(0.0).powi(28);
    let c = colour.map(|c| byte(c * (0.34 + 0.66 * diffuse) + highlight));
    Some([c[0], c[1], c[2], byte(f.alpha)])
}

/// A face's mark on the screen.
fn mark(
    f: &Face,
    rgba: [u8; 4],
    screen: &impl Fn(&Vector3<f64>) -> (f32, f32),
    scale: f64,
) -> Mark {
    match f.shape {
        Shape::Quad(c) => {
            let opaque = rgba[3] == 255;
            let (edge, edge_rgba) = if f.outline {
                (1.2, [60, 80, 130, 150])
            } else if opaque {
                (0.8, rgba)
            } else {
                (0.0, rgba)
            };
            Mark::Polygon {
                corners: c.map(|p| screen(&p)),
                rgba,
                edge,
                edge_rgba,
            }
        }
        Shape::Disc { centre, radius } => Mark::Disc {
            centre: screen(&centre),
            radius: (radius * scale) as f32,
            rgba,
        },
    }
}

/// The picture as PNG bytes.
pub fn png(bodies: &[Body], picture: &Picture) -> Result<Vec<u8>> {
    use tiny_skia::{Color, FillRule, LineJoin, Paint, PathBuilder, Pixmap, Stroke, Transform};
    let (marks, captions, _) = lay_out(bodies, picture);
    let mut pixmap = Pixmap::new(picture.width, picture.height)
        .ok_or_else(|| IoError::Plot("a picture of zero size".into()))?;
    pixmap.fill(Color::WHITE);
    let mut paint = Paint {
        anti_alias: true,
        ..Paint::default()
    };
    let stroke = |width: f32| Stroke {
        width,
        line_join: LineJoin::Round,
        ..Stroke::default()
    };
    let none = Transform::identity();
    for m in &marks {
        match *m {
            Mark::Polygon {
                corners,
                rgba,
                edge,
                edge_rgba,
            } => {
                let mut pb = PathBuilder::new();
                pb.move_to(corners[0].0, corners[0].1);
                for c in &corners[1..] {
                    pb.line_to(c.0, c.1);
                }
                pb.close();
                // a face seen edge-on has no area: nothing to paint
                let Some(path) = pb.finish() else { continue };
                paint.set_color_rgba8(rgba[0], rgba[1], rgba[2], rgba[3]);
                pixmap.fill_path(&path, &paint, FillRule::Winding, none, None);
                if edge > 0.0 {
                    let [r, g, b, a] = edge_rgba;
                    paint.set_color_rgba8(r, g, b, a);
                    pixmap.stroke_path(&path, &paint, &stroke(edge), none, None);
                }
            }
            Mark::Disc {
                centre,
                radius,
                rgba,
            } => {
                let Some(path) = PathBuilder::from_circle(centre.0, centre.1, radius.max(1.0))
                else {
                    continue;
                };
                paint.set_color_rgba8(rgba[0], rgba[1], rgba[2], rgba[3]);
                pixmap.fill_path(&path, &paint, FillRule::Winding, none, None);
            }
        }
    }
    // the background is opaque, so every pixel is: premultiplied RGBA is RGBA
    let mut rgb: Vec<u8> = pixmap
        .data()
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    if !captions.is_empty() && crate::io::plot::font_available() {
        write_captions(&mut rgb, picture, &captions)?;
    }
    encode_png(&rgb, picture)
}

/// Captions drawn on the RGB pixels with plotters' text (the diagrams' font).
fn write_captions(rgb: &mut [u8], picture: &Picture, captions: &[Caption]) -> Result<()> {
    use plotters::prelude::*;
    let root = BitMapBackend::with_buffer(rgb, (picture.width, picture.height)).into_drawing_area();
    for c in captions {
        let style = ("sans-serif", c.size as f64).into_font().color(&BLACK).pos(
            plotters::style::text_anchor::Pos::new(
                plotters::style::text_anchor::HPos::Left,
                plotters::style::text_anchor::VPos::Bottom,
            ),
        );
        root.draw(&Text::new(
            c.text.clone(),
            (c.at.0 as i32, c.at.1 as i32),
            style,
        ))
        .map_err(|e| IoError::Plot(format!("caption: {e:?}")))?;
    }
    root.present()
        .map_err(|e| IoError::Plot(format!("caption: {e:?}")))
}

fn encode_png(rgb: &[u8], picture: &Picture) -> Result<Vec<u8>> {
    use image::ImageEncoder;
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png)
        .write_image(rgb, picture.width, picture.height, image::ColorType::Rgb8)
        .map_err(|e| IoError::Plot(format!("encoding the picture: {e}")))?;
    Ok(png)
}

/// The picture as SVG text (the same marks as the PNG, as polygons).
pub fn svg(bodies: &[Body], picture: &Picture) -> String {
    use std::fmt::Write as _;
    let (marks, captions, _) = lay_out(bodies, picture);
    let (w, h) = (picture.width, picture.height);
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" \
         viewBox=\"0 0 {w} {h}\">\n<rect width=\"{w}\" height=\"{h}\" fill=\"white\"/>\n"
    );
    let colour = |c: [u8; 4]| format!("#{:02x}{:02x}{:02x}", c[0], c[1], c[2]);
    let opacity = |c: [u8; 4]| {
        if c[3] == 255 {
            String::new()
        } else {
            format!(" fill-opacity=\"{:.3}\"", c[3] as f32 / 255.0)
        }
    };
    for m in &marks {
        match *m {
            Mark::Polygon {
                corners,
                rgba,
                edge,
                edge_rgba,
            } => {
                s.push_str("<polygon points=\"");
                for (k, c) in corners.iter().enumerate() {
                    let sep = if k == 0 { "" } else { " " };
                    let _ = write!(s, "{sep}{:.1},{:.1}", c.0, c.1);
                }
                let _ = write!(s, "\" fill=\"{}\"{}", colour(rgba), opacity(rgba));
                if edge > 0.0 {
                    let _ = write!(
                        s,
                        " stroke=\"{}\" stroke-width=\"{edge}\" stroke-linejoin=\"round\"",
                        colour(edge_rgba)
                    );
                    if edge_rgba[3] < 255 {
                        let _ = write!(s, " stroke-opacity=\"{:.3}\"", edge_rgba[3] as f32 / 255.0);
                    }
                }
                s.push_str("/>\n");
            }
            Mark::Disc {
                centre,
                radius,
                rgba,
            } => {
                let _ = writeln!(
                    s,
                    "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"{:.1}\" fill=\"{}\"{}/>",
                    centre.0,
                    centre.1,
                    radius.max(1.0),
                    colour(rgba),
                    opacity(rgba)
                );
            }
        }
    }
    for c in &captions {
        let _ = writeln!(
            s,
            "<text x=\"{:.1}\" y=\"{:.1}\" font-family=\"sans-serif\" font-size=\"{:.1}\">{}</text>",
            c.at.0,
            c.at.1,
            c.size,
            escape(&c.text)
        );
    }
    s.push_str("</svg>\n");
    s
}

/// Text safe inside an XML element.
fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}
