//! The closed curve the paper uses: the rod extended from s = 0 along −e3 and
//! from s = 1 along +e3 by straight rays, joined by a loop far away.

use nalgebra::Vector3;

/// Ray closure of an open polyline whose first point is the s = 0 end and last
/// point the s = 1 end: rays of length `ray` along `bottom_dir` from the first
/// point and `top_dir` from the last, joined by a path at least about `ray`
/// minus the curve's extent away from the curve.
pub fn ray_closure(
    points: &[Vector3<f64>],
    bottom_dir: Vector3<f64>,
    top_dir: Vector3<f64>,
    ray: f64,
) -> Vec<Vector3<f64>> {
    let first = points[0];
    let last = *points.last().unwrap();
    let bottom = first + ray * bottom_dir.normalize();
    let top = last + ray * top_dir.normalize();
    // a side direction perpendicular to the mean ray axis
    // (rays in one direction, as for clamps facing the same way, have no
    // mean axis: take the rays' own)
    let spread = top_dir.normalize() - bottom_dir.normalize();
    let axis = if spread.norm() > 1e-9 {
        spread.normalize()
    } else {
        top_dir.normalize()
    };
    let side = super::normal_to(&axis);
    let mut closed = points.to_vec();
    closed.push(top);
    closed.push(top + ray * side);
    closed.push(bottom + ray * side);
    closed.push(bottom);
    closed
}

/// Largest distance of the polyline's points from its first point: sets the
/// ray length needed for a closure far from the curve.
pub fn extent(points: &[Vector3<f64>]) -> f64 {
    points
        .iter()
        .map(|p| (p - points[0]).norm())
        .fold(0.0, f64::max)
}

/// Length of rays that leave the curve's neighbourhood: twice its extent
/// plus the rod's length.
pub fn reach(points: &[Vector3<f64>]) -> f64 {
    2.0 * extent(points) + 1.0
}

/// Knot type of the closure by rays along −e3 from the first point and +e3
/// from the last (the paper's closure of a clamped rod).
pub fn closure_knot(
    points: &[Vector3<f64>],
) -> Result<crate::geometry::knot::KnotType, crate::geometry::knot::KnotError> {
    let e3 = Vector3::z();
    closure_knot_along(points, [-e3, e3])
}

/// Knot type of the closure by rays along `rays[0]` from the first point and
/// `rays[1]` from the last.
pub fn closure_knot_along(
    points: &[Vector3<f64>],
    rays: [Vector3<f64>; 2],
) -> Result<crate::geometry::knot::KnotType, crate::geometry::knot::KnotError> {
    crate::geometry::knot::knot_type(&ray_closure(points, rays[0], rays[1], reach(points)))
}
