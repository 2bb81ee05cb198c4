//! Pictures of configurations (`knotrod render`): the rod as a shaded tube of
//! its diameter with the paper's yellow stripe along d1 (Figure 2), a strip
//! as its ribbon, the two clamps, their rays and the walls z = 0 and z = z*,
//! seen along a chosen direction; several states side by side.
//!
//! [`picture`] says what to draw and from where, [`shapes`] turns a state into small planar faces in space, [`raster`]
//! projects, shades and paints them (tiny-skia for PNG, polygons for SVG),
//! [`source`] reads the states from a recording or a summary.

mod picture;
mod raster;
mod shapes;
pub mod source;

pub use picture::{Body, Picture, View};
pub use raster::{pixel_of, png, svg};
pub use source::{Pick, bodies};
