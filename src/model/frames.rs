//! Small 3-vector algebra generic over the scalar, so that the same stencil code
//! runs on `f64` and on dual numbers (exact derivatives by forward-mode AD).

pub use crate::linalg::jet::Scalar;

/// A 3-vector of scalars.
pub type V3<T> = [T; 3];

/// Lift a constant `f64` vector into the scalar type.
#[inline]
pub fn lift<T: Scalar>(v: &nalgebra::Vector3<f64>) -> V3<T> {
    [T::from(v[0]), T::from(v[1]), T::from(v[2])]
}

/// a + b
#[inline]
pub fn add<T: Scalar>(a: V3<T>, b: V3<T>) -> V3<T> {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// a - b
#[inline]
pub fn sub<T: Scalar>(a: V3<T>, b: V3<T>) -> V3<T> {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// s a
#[inline]
pub fn scale<T: Scalar>(s: T, a: V3<T>) -> V3<T> {
    [s * a[0], s * a[1], s * a[2]]
}

/// a · b
#[inline]
pub fn dot<T: Scalar>(a: V3<T>, b: V3<T>) -> T {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// a × b
#[inline]
pub fn cross<T: Scalar>(a: V3<T>, b: V3<T>) -> V3<T> {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// |a|
#[inline]
pub fn norm<T: Scalar>(a: V3<T>) -> T {
    dot(a, a).sqrt()
}

/// Parallel transport of `a` (perpendicular to the unit vector `t`) to the unit
/// vector `t_new`: the rotation about t × t_new taking t to t_new, applied to a.
#[inline]
pub fn parallel_transport<T: Scalar>(a: V3<T>, t: V3<T>, t_new: V3<T>) -> V3<T> {
    let c = dot(t, t_new);
    let k = dot(a, t_new) / (c + 1.0);
    sub(a, scale(k, add(t, t_new)))
}

/// Rotate `a` (perpendicular to the unit axis `t`) by `angle` about `t`.
#[inline]
pub fn rotate_about<T: Scalar>(a: V3<T>, t: V3<T>, angle: T) -> V3<T> {
    let (s, c) = angle.sin_cos();
    add(scale(c, a), scale(s, cross(t, a)))
}

/// Signed angle from `a` to `b` about the axis `t` (both perpendicular to t).
#[inline]
pub fn signed_angle<T: Scalar>(a: V3<T>, b: V3<T>, t: V3<T>) -> T {
    dot(cross(a, b), t).atan2(dot(a, b))
}

/// Material directors (d1, d2) of an edge with tangent `t`, reference director
/// `a1` and material angle `theta`.
#[inline]
pub fn material_directors<T: Scalar>(t: V3<T>, a1: V3<T>, theta: T) -> (V3<T>, V3<T>) {
    let a2 = cross(t, a1);
    let (s, c) = theta.sin_cos();
    (
        add(scale(c, a1), scale(s, a2)),
        sub(scale(c, a2), scale(s, a1)),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transport_maps_frame_to_frame() {
        let t: [f64; 3] = [0.0, 0.0, 1.0];
        let a: [f64; 3] = [1.0, 0.0, 0.0];
        let tn = {
            let v: [f64; 3] = [0.3, -0.4, 0.8];
            let n = norm(v);
            scale(1.0 / n, v)
        };
        let p = parallel_transport(a, t, tn);
        assert!((norm(p) - 1.0).abs() < 1e-14);
        assert!(dot(p, tn).abs() < 1e-14);
        // transporting back recovers a
        let q = parallel_transport(p, tn, t);
        assert!(norm(sub(q, a)) < 1e-14);
        // the transport rotation does not spin about t: a rotated about t
        // transports to the same rotation of p about tn
        let ar = rotate_about(a, t, 0.7);
        let pr = parallel_transport(ar, t, tn);
        assert!((signed_angle(p, pr, tn) - 0.7).abs() < 1e-13);
    }
}
