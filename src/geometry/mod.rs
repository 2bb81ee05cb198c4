//! Pure geometry of curves: polylines, ray closures, distances, walls, writhe
//! and knot type.

pub mod closure;
pub mod distance;
pub mod knot;
pub mod polyline;
pub mod walls;
pub mod writhe;
