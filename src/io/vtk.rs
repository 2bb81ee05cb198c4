//! VTK for ParaView and pyvista: one state as XML PolyData (`.vtp`), the
//! centreline as one polyline with its fields as point data; a run as a
//! collection (`.pvd`) of one `.vtp` per state, the state's index as time.
//!
//! The points are the centreline's: r(0), the nodes x_1..x_N (at s = (i − ½)h)
//! and r(1). Point data, per point:
//! - `s`: arc length;
//! - `tube_radius`: the rod's radius (ParaView's Tube filter, "vary radius by
//!   scalar"; pyvista's `tube(scalars="tube_radius")`);
//! - `d1`, `d2`, `d3`: the material frame (at a node, the mean of its two
//!   edges', squared up to the mean tangent; at r(0), r(1) the clamps' edges');
//! - `strains`: (u1, u2, u3) at the nodes (the discrete curvatures and twist of
//!   the vertices), at r(0) and r(1) the nearest node's;
//! - `n`, `m`: internal force and moment in the lab frame, and
//!   `n_material`, `m_material` their components on (d1, d2, d3): at r(0) and
//!   r(1) the clamps' edges' own (centred there), at a node the mean of its
//!   two edges' (centred half a segment either side).

use crate::analysis::profile::Profile;
use crate::io::error::{IoError, Result};
use crate::model::rod::{RodModel, RodState};
use nalgebra::Vector3;
use vtkio::model::{
    Attribute, Attributes, ByteOrder, DataArray, DataSet, ElementType, IOBuffer, PolyDataPiece,
    Version, VertexNumbers, Vtk,
};

/// The names of the point data arrays, in the order written.
pub const POINT_DATA: [&str; 10] = [
    "s",
    "tube_radius",
    "d1",
    "d2",
    "d3",
    "strains",
    "n",
    "m",
    "n_material",
    "m_material",
];

/// The state as VTK PolyData (a model of the rod whose radius is 2/√S).
pub fn polydata(model: &RodModel, state: &RodState, title: &str) -> Vtk {
    let n = state.segments();
    let profile = Profile::of(model, state);
    let (points, arc) = state.centreline();
    let count = points.len();
    let v = |a: [f64; 3]| Vector3::new(a[0], a[1], a[2]);
    // the edges either side of centreline point k (k = 0 and k = N + 1: the
    // clamps' edges, centred on r(0) and r(1))
    let sides = |k: usize| (k.saturating_sub(1), k.min(n));
    let mut d = [
        Vec::with_capacity(3 * count),
        Vec::with_capacity(3 * count),
        Vec::with_capacity(3 * count),
    ];
    let mut strains = Vec::with_capacity(3 * count);
    let mut lab = [Vec::with_capacity(3 * count), Vec::with_capacity(3 * count)];
    let mut material = [Vec::with_capacity(3 * count), Vec::with_capacity(3 * count)];
    for k in 0..count {
        let (a, b) = sides(k);
        let frame = |j: usize| profile.directors[j].map(v);
        let (fa, fb) = (frame(a), frame(b));
        let t = (fa[2] + fb[2]).normalize();
        let d1 = fa[0] + fb[0];
        let d1 = (d1 - d1.dot(&t) * t).normalize();
        for (out, e) in d.iter_mut().zip([d1, t.cross(&d1), t]) {
            out.extend_from_slice(e.as_slice());
        }
        strains.extend_from_slice(&profile.strains[k.clamp(1, n) - 1]);
        for (i, field) in [&profile.force, &profile.moment].into_iter().enumerate() {
            let (ca, cb) = (v(field[a]), v(field[b]));
            let mean = 0.5 * (ca + cb);
            material[i].extend_from_slice(mean.as_slice());
            // each edge's components on its own frame, then averaged
            let world =
                |f: &[Vector3<f64>; 3], c: Vector3<f64>| c[0] * f[0] + c[1] * f[1] + c[2] * f[2];
            let w = 0.5 * (world(&fa, ca) + world(&fb, cb));
            lab[i].extend_from_slice(w.as_slice());
        }
    }
    let radius = 2.0 / model.stretching_stiffness.sqrt();
    let scalar = |name: &str, values: Vec<f64>| {
        Attribute::DataArray(DataArray {
            name: name.into(),
            elem: ElementType::Scalars {
                num_comp: 1,
                lookup_table: None,
            },
            data: IOBuffer::F64(values),
        })
    };
    let vector = |name: &str, values: Vec<f64>| {
        Attribute::DataArray(DataArray {
            name: name.into(),
            elem: ElementType::Vectors,
            data: IOBuffer::F64(values),
        })
    };
    let [d1, d2, d3] = d;
    let [n_lab, m_lab] = lab;
    let [n_mat, m_mat] = material;
    let point = vec![
        scalar("s", arc),
        scalar("tube_radius", vec![radius; count]),
        vector("d1", d1),
        vector("d2", d2),
        vector("d3", d3),
        Attribute::DataArray(DataArray {
            name: "strains".into(),
            elem: ElementType::Generic(3),
            data: IOBuffer::F64(strains),
        }),
        vector("n", n_lab),
        vector("m", m_lab),
        Attribute::DataArray(DataArray {
            name: "n_material".into(),
            elem: ElementType::Generic(3),
            data: IOBuffer::F64(n_mat),
        }),
        Attribute::DataArray(DataArray {
            name: "m_material".into(),
            elem: ElementType::Generic(3),
            data: IOBuffer::F64(m_mat),
        }),
    ];
    Vtk {
        version: Version::new_xml(1, 0),
        title: title.into(),
        byte_order: ByteOrder::LittleEndian,
        file_path: None,
        data: DataSet::inline(PolyDataPiece {
            points: IOBuffer::F64(points.iter().flat_map(|p| [p.x, p.y, p.z]).collect()),
            lines: Some(VertexNumbers::XML {
                connectivity: (0..count as u64).collect(),
                offsets: vec![count as u64],
            }),
            data: Attributes {
                point,
                cell: vec![],
            },
            ..Default::default()
        }),
    }
}

/// The `.vtp` file of a state (XML, its arrays base64-encoded binary).
pub fn vtp(
    model: &RodModel,
    state: &RodState,
    title: &str,
    path: &std::path::Path,
) -> Result<Vec<u8>> {
    let mut bytes = Vec::new();
    polydata(model, state, title)
        .write_xml(&mut bytes)
        .map_err(|e| IoError::Recording {
            path: path.into(),
            reason: format!("cannot encode VTK PolyData ({e})"),
        })?;
    Ok(bytes)
}

/// A ParaView collection (`.pvd`) of `(time, file)` pairs, the files named
/// relative to the collection.
pub fn collection(parts: &[(f64, String)]) -> String {
    use std::fmt::Write as _;
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" \
         byte_order=\"LittleEndian\">\n  <Collection>\n",
    );
    for (t, file) in parts {
        let file = file
            .replace('&', "&amp;")
            .replace('"', "&quot;")
            .replace('<', "&lt;");
        let _ = writeln!(
            s,
            "    <DataSet timestep=\"{t}\" group=\"\" part=\"0\" file=\"{file}\"/>"
        );
    }
    s.push_str("  </Collection>\n</VTKFile>\n");
    s
}
