//! A configuration as small planar faces in space: the tube (or ribbon), the
//! clamps as boxes, the rays as tubes of the rod's diameter (the paper's
//! cylindrical rays), the walls as translucent squares.

use super::picture::Body;
use nalgebra::Vector3;

/// Sides of the rod's tube: fine enough that flat-shaded faces read as round.
const TUBE_SIDES: usize = 24;
/// Sides of a ray's tube.
const RAY_SIDES: usize = 16;
/// The stripe along d1 spans this angle either side of d1 (radians): the
/// paper's yellow strip.
const STRIPE_HALF_ANGLE: f64 = 0.27;
/// The paper's yellow.
pub const STRIPE: [f64; 3] = [0.98, 0.82, 0.10];
/// Clamps and rays.
const STEEL: [f64; 3] = [0.45, 0.46, 0.50];
const RAY: [f64; 3] = [0.70, 0.70, 0.72];
/// The walls' tint and opacity.
const WALL: [f64; 3] = [0.45, 0.60, 0.90];
const WALL_ALPHA: f64 = 0.16;

/// Which slab between the walls a face lies in: the walls themselves are
/// painted between the slabs, so a face is tinted by a wall exactly when the
/// wall lies between it and the viewer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Slab {
    /// z < 0.
    Below,
    /// The wall z = 0.
    LowerWall,
    /// 0 < z < z*.
    Between,
    /// The wall z = z*.
    UpperWall,
    /// z > z*.
    Above,
}

/// What a face is.
#[derive(Clone, Copy, Debug)]
pub enum Shape {
    /// A planar quadrilateral, corners in order.
    Quad([Vector3<f64>; 4]),
    /// A sphere's outline (a contact point).
    Disc {
        /// Centre.
        centre: Vector3<f64>,
        /// Radius.
        radius: f64,
    },
}

/// One face.
#[derive(Clone, Copy, Debug)]
pub struct Face {
    /// Its shape.
    pub shape: Shape,
    /// Outward normal for shading (None: flat colour).
    pub normal: Option<Vector3<f64>>,
    /// Seen from either side (ribbons, walls): the normal is turned to the
    /// viewer and the back shows `back`.
    pub two_sided: bool,
    /// Colour (0..1).
    pub colour: [f64; 3],
    /// Colour of the back of a two-sided face.
    pub back: [f64; 3],
    /// Opacity.
    pub alpha: f64,
    /// Outlined (the walls' edges).
    pub outline: bool,
    /// Where it lies against the walls.
    pub slab: Slab,
}

impl Face {
    /// A shaded one-sided quad.
    fn solid(corners: [Vector3<f64>; 4], normal: Vector3<f64>, colour: [f64; 3]) -> Face {
        Face {
            shape: Shape::Quad(corners),
            normal: Some(normal),
            two_sided: false,
            colour,
            back: colour,
            alpha: 1.0,
            outline: false,
            slab: Slab::Between,
        }
    }

    /// Its centre.
    pub fn centre(&self) -> Vector3<f64> {
        match self.shape {
            Shape::Quad(c) => 0.25 * (c[0] + c[1] + c[2] + c[3]),
            Shape::Disc { centre, .. } => centre,
        }
    }
}

/// The faces of one body and the walls' heights, if the clamps are the
/// paper's (walls z = 0 and z = z*, rays along ∓z).
pub fn faces(body: &Body) -> Vec<Face> {
    let s = &body.state;
    let radius = 0.5 * body.diameter;
    let (points, _) = s.centreline();
    let frames = ring_frames(body);
    let mut out = Vec::with_capacity(points.len() * (TUBE_SIDES + 2) + 400);
    let colour = body.colour.map(|c| c as f64 / 255.0);
    match body.ribbon {
        Some(width) => ribbon(&points, &frames, width, colour, &mut out),
        None => tube(&points, &frames, radius, TUBE_SIDES, colour, true, &mut out),
    }
    // the extent of the rod, for the rays' reach and the walls' size
    let (lo, hi) = bounds(&points);
    let reach = 0.2 * (hi - lo).norm().max(10.0 * body.diameter);
    let c = &s.clamps;
    let r0 = points[0];
    let r1 = *points.last().expect("a centreline has its ends");
    let t0 = c.start_tangent();
    let t1 = c.end_tangent();
    let ray_radius = radius.max(0.5 * body.diameter);
    // a ray reaches past the rod's farthest point along it: a contact with
    // the ray is seen on it
    let beyond = |from: Vector3<f64>, along: Vector3<f64>| {
        let far = points
            .iter()
            .map(|p| (p - from).dot(&along))
            .fold(0.0, f64::max);
        far + reach
    };
    if s.clamps.ends.start.is_clamped() {
        straight_tube(r0, r0 - beyond(r0, -t0) * t0, ray_radius, &mut out);
        clamp_box(
            r0,
            c.start_frame().into_inner(),
            -1.0,
            body.diameter,
            &mut out,
        );
    }
    if s.clamps.ends.end.is_clamped() {
        straight_tube(r1, r1 + beyond(r1, t1) * t1, ray_radius, &mut out);
        clamp_box(r1, c.end_frame().into_inner(), 1.0, body.diameter, &mut out);
    }
    for p in &body.contacts {
        out.push(Face {
            shape: Shape::Disc {
                centre: *p,
                radius: 0.9 * body.diameter,
            },
            normal: None,
            two_sided: true,
            colour: [0.85, 0.08, 0.08],
            back: [0.85, 0.08, 0.08],
            alpha: 1.0,
            outline: false,
            slab: Slab::Between,
        });
    }
    if let Some(top) = walls(body) {
        for f in &mut out {
            let z = f.centre().z;
            f.slab = if z < 0.0 {
                Slab::Below
            } else if z > top {
                Slab::Above
            } else {
                Slab::Between
            };
        }
        let m = 0.15 * (hi - lo).x.max((hi - lo).y).max(0.05);
        let (x0, x1, y0, y1) = (lo.x - m, hi.x + m, lo.y - m, hi.y + m);
        for (z, slab) in [(0.0, Slab::LowerWall), (top, Slab::UpperWall)] {
            out.push(Face {
                shape: Shape::Quad([
                    Vector3::new(x0, y0, z),
                    Vector3::new(x1, y0, z),
                    Vector3::new(x1, y1, z),
                    Vector3::new(x0, y1, z),
                ]),
                normal: None,
                two_sided: true,
                colour: WALL,
                back: WALL,
                alpha: WALL_ALPHA,
                outline: true,
                slab,
            });
        }
    }
    out
}

/// The upper wall's height when the walls mean what the paper's do (the
/// paper's clamps: z = 0 and z = z* along the clamps' common axis).
pub fn walls(body: &Body) -> Option<f64> {
    let c = &body.state.clamps;
    (c.is_paper() && c.z_star > 0.0).then_some(c.z_star)
}

/// The frame (e1 along d1, e2, tangent) of each centreline point: at a node,
/// the mean of its two edges' directors, so the rings sit square to the
/// centreline.
fn ring_frames(body: &Body) -> Vec<[Vector3<f64>; 3]> {
    let s = &body.state;
    let n = s.segments();
    let edges: Vec<[Vector3<f64>; 3]> = (0..=n).map(|j| s.directors(j)).collect();
    (0..=n + 1)
        .map(|k| {
            let (a, b) = (&edges[k.saturating_sub(1)], &edges[k.min(n)]);
            let t = (a[2] + b[2]).normalize();
            let d = a[0] + b[0];
            let e1 = (d - d.dot(&t) * t).normalize();
            [e1, t.cross(&e1), t]
        })
        .collect()
}

/// A tube of `radius` along `points` with ring frames `frames`; with `stripe`
/// the faces within STRIPE_HALF_ANGLE of e1 are the paper's yellow.
fn tube(
    points: &[Vector3<f64>],
    frames: &[[Vector3<f64>; 3]],
    radius: f64,
    sides: usize,
    colour: [f64; 3],
    stripe: bool,
    out: &mut Vec<Face>,
) {
    let step = std::f64::consts::TAU / sides as f64;
    // faces centred on the angles q·step, so one face is centred on d1
    let corner = |k: usize, q: f64| {
        let a = (q - 0.5) * step;
        let [e1, e2, _] = frames[k];
        (points[k] + radius * (a.cos() * e1 + a.sin() * e2), a)
    };
    for k in 0..points.len() - 1 {
        for q in 0..sides {
            let (p00, a) = corner(k, q as f64);
            let (p01, _) = corner(k, q as f64 + 1.0);
            let (p10, _) = corner(k + 1, q as f64);
            let (p11, _) = corner(k + 1, q as f64 + 1.0);
            let mid = a + 0.5 * step;
            let normal = |f: &[Vector3<f64>; 3]| mid.cos() * f[0] + mid.sin() * f[1];
            let n = (normal(&frames[k]) + normal(&frames[k + 1])).normalize();
            let centred = mid.sin().atan2(mid.cos()).abs();
            let c = if stripe && centred < STRIPE_HALF_ANGLE {
                STRIPE
            } else {
                colour
            };
            out.push(Face::solid([p00, p01, p11, p10], n, c));
        }
    }
}

/// A ribbon of `width` along e1, centred on the centreline: the front (e2
/// towards the viewer) in the class colour, the back lighter, so its turns
/// read.
fn ribbon(
    points: &[Vector3<f64>],
    frames: &[[Vector3<f64>; 3]],
    width: f64,
    colour: [f64; 3],
    out: &mut Vec<Face>,
) {
    let back = colour.map(|c| 0.45 * c + 0.55);
    for k in 0..points.len() - 1 {
        let (a, b) = (0.5 * width * frames[k][0], 0.5 * width * frames[k + 1][0]);
        let n = (frames[k][1] + frames[k + 1][1]).normalize();
        let mut f = Face::solid(
            [
                points[k] - a,
                points[k] + a,
                points[k + 1] + b,
                points[k + 1] - b,
            ],
            n,
            colour,
        );
        f.two_sided = true;
        f.back = back;
        out.push(f);
    }
}

/// A ray: a tube from `from` to `to`, cut in pieces about as long as they are
/// wide so that sorting by depth orders them right against the rod.
fn straight_tube(from: Vector3<f64>, to: Vector3<f64>, radius: f64, out: &mut Vec<Face>) {
    let axis = to - from;
    let t = axis.normalize();
    let e1 = crate::geometry::normal_to(&t);
    let pieces = ((axis.norm() / (4.0 * radius)).ceil() as usize).clamp(1, 400);
    let points: Vec<Vector3<f64>> = (0..=pieces)
        .map(|i| from + axis * (i as f64 / pieces as f64))
        .collect();
    let frames = vec![[e1, t.cross(&e1), t]; points.len()];
    tube(&points, &frames, radius, RAY_SIDES, RAY, false, out);
}

/// A clamp: a box about the rod's end point `at`, in the clamp's frame
/// (columns d1, d2, d3), reaching `side` (−1 back, +1 forward) along d3.
fn clamp_box(
    at: Vector3<f64>,
    frame: nalgebra::Matrix3<f64>,
    side: f64,
    diameter: f64,
    out: &mut Vec<Face>,
) {
    let half = [1.8 * diameter, 1.8 * diameter, 2.5 * diameter];
    let centre = at + side * half[2] * frame.column(2).into_owned();
    let axis = |i: usize| frame.column(i).into_owned();
    for i in 0..3 {
        for sign in [-1.0, 1.0] {
            let (j, k) = ((i + 1) % 3, (i + 2) % 3);
            let n = sign * axis(i);
            let c = centre + half[i] * n;
            let (u, v) = (half[j] * axis(j), half[k] * axis(k));
            out.push(Face::solid(
                [c - u - v, c + u - v, c + u + v, c - u + v],
                n,
                STEEL,
            ));
        }
    }
}

/// The corners of the box holding `points`.
pub fn bounds(points: &[Vector3<f64>]) -> (Vector3<f64>, Vector3<f64>) {
    points.iter().fold(
        (
            Vector3::repeat(f64::INFINITY),
            Vector3::repeat(f64::NEG_INFINITY),
        ),
        |(lo, hi), p| (lo.inf(p), hi.sup(p)),
    )
}
