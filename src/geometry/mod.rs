//! Geometry of centrelines: writhe, link, knot type of the ray closure, walls,
//! self-distance and distance to the clamps' rays.

pub mod closure;
pub mod contact;
pub mod distance;
pub mod knot;
pub mod polyline;
pub mod walls;
pub mod writhe;
