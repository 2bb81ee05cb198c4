//! The Foxglove 3D scene of an equilibrium.

use crate::analysis::equilibrium::Equilibrium;
use crate::io::plot::class_colour;
use foxglove::messages::{
    Color, CubePrimitive, LinePrimitive, Point3, Pose, Quaternion, SceneEntity, SceneUpdate,
    Timestamp, Vector3 as FgVector3,
};

fn fg_point(p: &nalgebra::Vector3<f64>) -> Point3 {
    Point3 {
        x: p.x,
        y: p.y,
        z: p.z,
    }
}

fn colour(r: f64, g: f64, b: f64, a: f64) -> Color {
    Color { r, g, b, a }
}

fn identity_pose(at: nalgebra::Vector3<f64>) -> Pose {
    Pose {
        position: Some(FgVector3 {
            x: at.x,
            y: at.y,
            z: at.z,
        }),
        orientation: Some(Quaternion {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            w: 1.0,
        }),
    }
}

/// The Foxglove 3D scene of an equilibrium: the rod as a tube of its diameter
/// coloured like the paper's figures, d1 as short yellow segments, the clamps,
/// the rays and the two walls.
pub fn scene_update(e: &Equilibrium, diameter: f64, stamp: Option<Timestamp>) -> SceneUpdate {
    let c = class_colour(e);
    let rod_colour = colour(
        c.0 as f64 / 255.0,
        c.1 as f64 / 255.0,
        c.2 as f64 / 255.0,
        1.0,
    );
    let (points, _) = e.state.centreline();
    let entity = |id: &str| SceneEntity {
        timestamp: stamp,
        frame_id: "rod".into(),
        id: id.into(),
        frame_locked: true,
        ..Default::default()
    };
    let line = |kind: i32, pts: Vec<Point3>, thickness: f64, col: Color| LinePrimitive {
        r#type: kind,
        pose: Some(identity_pose(nalgebra::Vector3::zeros())),
        thickness,
        scale_invariant: false,
        points: pts,
        color: Some(col),
        ..Default::default()
    };
    let mut rod = entity("rod");
    rod.lines.push(line(
        0,
        points.iter().map(fg_point).collect(),
        diameter,
        rod_colour,
    ));
    // material frame: d1 at every edge midpoint, as the paper's yellow strip
    let n = e.state.segments();
    let len = 3.0 * diameter;
    let mut d1 = Vec::with_capacity(2 * n);
    for j in 1..n {
        let mid = 0.5 * (e.state.nodes[j] + e.state.nodes[j + 1]);
        let d = e.state.directors(j)[0];
        d1.push(fg_point(&mid));
        d1.push(fg_point(&(mid + len * d)));
    }
    let mut frame = entity("d1");
    frame
        .lines
        .push(line(2, d1, 0.3 * diameter, colour(0.95, 0.8, 0.1, 1.0)));
    let z_star = e.z_star;
    let end = e.state.end_point();
    let mut clamps = entity("clamps");
    let reach = 0.3;
    for at in [nalgebra::Vector3::zeros(), end] {
        clamps.cubes.push(CubePrimitive {
            pose: Some(identity_pose(at)),
            size: Some(FgVector3 {
                x: 2.0 * diameter,
                y: 2.0 * diameter,
                z: 4.0 * diameter,
            }),
            color: Some(colour(0.3, 0.3, 0.3, 1.0)),
        });
    }
    let grey = colour(0.5, 0.5, 0.5, 0.6);
    let mut rays = entity("rays");
    rays.lines.push(line(
        0,
        vec![
            fg_point(&nalgebra::Vector3::zeros()),
            Point3 {
                x: 0.0,
                y: 0.0,
                z: -reach,
            },
        ],
        diameter,
        grey,
    ));
    rays.lines.push(line(
        0,
        vec![
            fg_point(&end),
            Point3 {
                x: end.x,
                y: end.y,
                z: end.z + reach,
            },
        ],
        diameter,
        grey,
    ));
    let mut walls = entity("walls");
    for z in [0.0, z_star] {
        walls.cubes.push(CubePrimitive {
            pose: Some(identity_pose(nalgebra::Vector3::new(0.0, 0.0, z))),
            size: Some(FgVector3 {
                x: 0.5,
                y: 0.5,
                z: 0.0005,
            }),
            color: Some(colour(0.6, 0.7, 0.9, 0.15)),
        });
    }
    // contact points: red cubes whose size grows with the force
    let mut contacts = entity("contacts");
    let (_, arc) = e.state.centreline();
    let largest = e.contacts.iter().map(|c| c.force).fold(0.0, f64::max);
    for c in &e.contacts {
        let k = arc.partition_point(|a| *a <= c.s).clamp(1, arc.len() - 1);
        let t = ((c.s - arc[k - 1]) / (arc[k] - arc[k - 1]).max(1e-300)).clamp(0.0, 1.0);
        let at = points[k - 1] + t * (points[k] - points[k - 1]);
        let size = diameter * (1.5 + 2.0 * c.force / largest.max(1e-300));
        contacts.cubes.push(CubePrimitive {
            pose: Some(identity_pose(at)),
            size: Some(FgVector3 {
                x: size,
                y: size,
                z: size,
            }),
            color: Some(colour(0.9, 0.1, 0.1, 0.9)),
        });
    }
    SceneUpdate {
        deletions: vec![],
        entities: vec![rod, frame, clamps, rays, walls, contacts],
    }
}
