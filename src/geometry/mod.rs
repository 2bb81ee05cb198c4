//! Pure geometry of curves: polylines, ray closures, distances, ribbons,
//! walls, writhe and knot type.

pub mod closure;
pub mod distance;
pub mod knot;
pub mod polyline;
pub mod ribbon;
pub mod walls;
pub mod writhe;

use nalgebra::Vector3;

/// A unit vector normal to the unit vector `t`: x (or y, when t is near x)
/// with its component along t removed.
pub fn normal_to(t: &Vector3<f64>) -> Vector3<f64> {
    let trial = if t.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    (trial - trial.dot(t) * t).normalize()
}
