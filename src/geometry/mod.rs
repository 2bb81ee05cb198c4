//! Pure geometry of curves: polylines, ray closures, distances, ribbons,
//! walls, writhe and knot type.

pub mod closure;
pub mod distance;
pub mod knot;
pub mod polyline;
pub mod ribbon;
pub mod walls;
pub mod writhe;
