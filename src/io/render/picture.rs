//! What a picture shows: the states (bodies), the viewpoint, the size.

use nalgebra::Vector3;

/// One configuration to draw.
#[derive(Clone, Debug)]
pub struct Body {
    /// The state.
    pub state: crate::model::rod::RodState,
    /// Diameter of the tube (the rod's, 4/√S for the circular rod of
    /// stretching stiffness S).
    pub diameter: f64,
    /// Draw a ribbon of this width along d1 instead of a tube (a strip).
    pub ribbon: Option<f64>,
    /// The class colour (the paper's: green good knot, blue stable knotted
    /// but unwalled or touching itself, brown unknotted, red unstable).
    pub colour: [u8; 3],
    /// Its name (an event's label, or the user's: A, B as in Figure 4).
    pub label: String,
    /// The lines written under it (its class, where it is).
    pub caption: String,
    /// Points of contact (drawn as red dots).
    pub contacts: Vec<Vector3<f64>>,
}

impl Body {
    /// The lines under the state: its caption, the first line led by its
    /// label.
    pub fn caption_lines(&self) -> Vec<String> {
        let mut lines: Vec<String> = self.caption.lines().map(str::to_string).collect();
        if !self.label.is_empty() {
            match lines.first_mut() {
                Some(first) if !first.is_empty() => *first = format!("{}: {first}", self.label),
                Some(first) => first.clone_from(&self.label),
                None => lines.push(self.label.clone()),
            }
        }
        lines
    }
}

/// Where the picture is seen from: the direction towards the viewer, by its
/// azimuth about z (from +x) and elevation above the plane z = 0, in degrees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// Azimuth, degrees.
    pub azimuth: f64,
    /// Elevation, degrees.
    pub elevation: f64,
}

impl View {
    /// Oblique, from a little above the upper wall: the knot, its clamps and
    /// both walls at once (the default).
    pub const OBLIQUE: View = View {
        azimuth: -65.0,
        elevation: 22.0,
    };
    /// From the side, level with the walls (edge-on): heights against the
    /// walls z = 0 and z = z*, the flip axis x across the picture.
    pub const SIDE: View = View {
        azimuth: -90.0,
        elevation: 0.0,
    };
    /// From above, along the clamps' axis: the knot's diagram.
    pub const TOP: View = View {
        azimuth: -90.0,
        elevation: 90.0,
    };

    /// `oblique`, `side`, `top` or `AZIMUTH,ELEVATION` in degrees.
    pub fn parse(text: &str) -> Result<View, String> {
        match text.trim() {
            "oblique" => return Ok(View::OBLIQUE),
            "side" => return Ok(View::SIDE),
            "top" => return Ok(View::TOP),
            _ => {}
        }
        let bad = || {
            format!(
                "--view {text:?}: give oblique, side, top or AZIMUTH,ELEVATION in degrees \
                 (e.g. -65,22)"
            )
        };
        let (a, e) = text.split_once(',').ok_or_else(bad)?;
        let a: f64 = a.trim().parse().map_err(|_| bad())?;
        let e: f64 = e.trim().parse().map_err(|_| bad())?;
        if !a.is_finite() || !(-90.0..=90.0).contains(&e) {
            return Err(format!(
                "--view {text:?}: the elevation is within -90..90 degrees and the azimuth finite"
            ));
        }
        Ok(View {
            azimuth: a,
            elevation: e,
        })
    }

    /// The unit vectors of the screen: right, up, and towards the viewer.
    pub fn axes(&self) -> [Vector3<f64>; 3] {
        let (a, e) = (self.azimuth.to_radians(), self.elevation.to_radians());
        let towards = Vector3::new(e.cos() * a.cos(), e.cos() * a.sin(), e.sin());
        let right = Vector3::new(-a.sin(), a.cos(), 0.0);
        [right, towards.cross(&right), towards]
    }
}

/// The size of the whole picture in pixels and where it is seen from.
#[derive(Clone, Copy, Debug)]
pub struct Picture {
    /// Width, pixels (the panels share it).
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// The viewpoint.
    pub view: View,
}

impl Picture {
    /// `WIDTHxHEIGHT`, each 64..=8000 pixels.
    pub fn parse_size(text: &str) -> Result<(u32, u32), String> {
        let bad = || format!("--size {text:?}: give WIDTHxHEIGHT in pixels, e.g. 1200x900");
        let (w, h) = text.split_once(['x', 'X']).ok_or_else(bad)?;
        let w: u32 = w.trim().parse().map_err(|_| bad())?;
        let h: u32 = h.trim().parse().map_err(|_| bad())?;
        if !(64..=8000).contains(&w) || !(64..=8000).contains(&h) {
            return Err(format!("--size {text:?}: each side is 64 to 8000 pixels"));
        }
        Ok((w, h))
    }
}
