//! VTK export: a state's `.vtp` reads back (vtkio) with its points and
//! point data, the fields it carries are the physics' (n constant along a
//! weightless rod, the frame orthonormal, the clamp force the equilibrium's),
//! and a recording exports as a `.pvd` time series.

use crate::common;
use knotrod::analysis::equilibrium::Equilibrium;
use knotrod::analysis::profile::Profile;
use knotrod::io::vtk::{POINT_DATA, vtp};
use nalgebra::Vector3;
use vtkio::model::{Attribute, DataSet, IOBuffer, Piece, VertexNumbers, Vtk};

/// Named point data arrays.
type PointData = Vec<(String, Vec<f64>)>;

/// The points, point data and lines of a `.vtp`'s bytes.
fn read_back(bytes: &[u8]) -> (Vec<f64>, PointData, VertexNumbers) {
    let vtk = Vtk::parse_xml(bytes).expect("a readable .vtp");
    let DataSet::PolyData { pieces, .. } = vtk.data else {
        panic!("PolyData expected")
    };
    let [Piece::Inline(piece)] = <[_; 1]>::try_from(pieces).expect("one piece") else {
        panic!("an inline piece expected")
    };
    let f64s = |b: IOBuffer| b.cast_into::<f64>().expect("numbers");
    let points = f64s(piece.points);
    let data = piece
        .data
        .point
        .into_iter()
        .map(|a| match a {
            Attribute::DataArray(d) => (d.name, f64s(d.data)),
            Attribute::Field { name, .. } => panic!("unexpected field {name}"),
        })
        .collect();
    (points, data, piece.lines.expect("the centreline as a line"))
}

fn field<'a>(data: &'a [(String, Vec<f64>)], name: &str) -> &'a [f64] {
    &data.iter().find(|(n, _)| n == name).unwrap().1
}

fn vectors(values: &[f64]) -> Vec<Vector3<f64>> {
    values
        .chunks_exact(3)
        .map(|c| Vector3::new(c[0], c[1], c[2]))
        .collect()
}

/// The Appendix D knot at N segments: its equilibrium and its `.vtp` read
/// back.
fn appendix_d(n: usize) -> (Equilibrium, Vec<f64>, PointData, VertexNumbers) {
    let scene = common::scene_at("scenes/appendix_d.toml", n);
    let (eqs, _) = common::run(&scene);
    let e = eqs.into_iter().next().unwrap();
    let model = scene.rod_model(None);
    let bytes = vtp(
        &model,
        &e.state,
        "Appendix D",
        std::path::Path::new("d.vtp"),
    )
    .unwrap();
    let (points, data, lines) = read_back(&bytes);
    (e, points, data, lines)
}

#[test]
fn a_state_reads_back_with_its_centreline_and_point_data() {
    let n = 40;
    let (e, points, data, lines) = appendix_d(n);
    let (centreline, arc) = e.state.centreline();
    assert_eq!(points.len(), 3 * (n + 2));
    for (p, q) in vectors(&points).iter().zip(&centreline) {
        assert_eq!(p, q, "points written at full precision");
    }
    let VertexNumbers::XML {
        connectivity,
        offsets,
    } = lines
    else {
        panic!("XML cells")
    };
    assert_eq!(connectivity, (0..(n + 2) as u64).collect::<Vec<_>>());
    assert_eq!(offsets, vec![(n + 2) as u64]);
    let names: Vec<&str> = data.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, POINT_DATA);
    assert_eq!(field(&data, "s"), arc.as_slice());
    // rod_diameter 0.005: the tube's radius
    assert!(
        field(&data, "tube_radius")
            .iter()
            .all(|r| (r - 0.0025).abs() < 1e-15)
    );
    // an orthonormal right-handed frame at every point, d3 along the line
    let d1 = vectors(field(&data, "d1"));
    let d2 = vectors(field(&data, "d2"));
    let d3 = vectors(field(&data, "d3"));
    for k in 0..n + 2 {
        assert!((d1[k].norm() - 1.0).abs() < 1e-12 && d1[k].dot(&d3[k]).abs() < 1e-12);
        assert!((d1[k].cross(&d2[k]) - d3[k]).norm() < 1e-12);
    }
    for k in 1..n + 1 {
        let chord = (centreline[k + 1] - centreline[k - 1]).normalize();
        assert!(chord.dot(&d3[k]) > 0.99, "d3 along the centreline at {k}");
    }
    // the strains of the nodes are the profile's vertices'
    let profile = Profile::of(
        &common::scene_at("scenes/appendix_d.toml", n).rod_model(None),
        &e.state,
    );
    let strains = field(&data, "strains");
    for i in 1..=n {
        assert_eq!(&strains[3 * i..3 * i + 3], &profile.strains[i - 1]);
    }
    // at r(0) the clamp's force in its frame is the equilibrium's n(0)
    let n_material = vectors(field(&data, "n_material"));
    assert!((n_material[0] - Vector3::from(e.n0)).norm() < 1e-9 * n_material[0].norm());
}

#[test]
fn the_internal_force_is_constant_along_a_weightless_rod() {
    // n' = 0 with no load along the rod. The discrete internal force at a cut
    // is minus the energy's derivative under a rigid translation of the part
    // cut off, so at an equilibrium it is the same vector at every cut, up to
    // the gradient Newton leaves (relative 1e-10 here): in the lab frame the
    // exported n is one vector (its material components turn with the frame)
    for n in [40, 80] {
        let (_, _, data, _) = appendix_d(n);
        let force = vectors(field(&data, "n"));
        let size = force[0].norm();
        assert!(size > 10.0, "the Appendix D knot is loaded: |n| = {size}");
        let spread = force
            .iter()
            .map(|f| (f - force[0]).norm())
            .fold(0.0, f64::max)
            / size;
        assert!(spread < 1e-7, "N = {n}: n varies by {spread:e} of |n|");
        let material = vectors(field(&data, "n_material"));
        let turn = material
            .iter()
            .map(|f| (f - material[0]).norm())
            .fold(0.0, f64::max)
            / size;
        assert!(
            turn > 0.5,
            "N = {n}: the material components turn with the knot"
        );
    }
}

#[test]
fn a_recording_exports_as_a_time_series_paraview_opens() {
    let dir = common::temp_dir("pvd");
    let sample = "recordings/samples/fig3_n60.mcap";
    let pvd = dir.join("fig3.pvd");
    common::knotrod_ok(&[
        "export",
        sample,
        "--format",
        "pvd",
        "--out",
        pvd.to_str().unwrap(),
    ]);
    let text = std::fs::read_to_string(&pvd).unwrap();
    let files: Vec<&str> = text
        .lines()
        .filter_map(|l| l.split("file=\"").nth(1)?.split('"').next())
        .collect();
    let states = knotrod::io::recording::read_recording(std::path::Path::new(sample))
        .unwrap()
        .scalars
        .len();
    assert_eq!(files.len(), states);
    assert!(text.contains("timestep=\"0\"") && text.contains("type=\"Collection\""));
    for f in [files[0], files[files.len() / 2], files[files.len() - 1]] {
        let (points, data, _) = read_back(&std::fs::read(dir.join(f)).unwrap());
        assert_eq!(points.len(), 3 * 62, "{f}: N = 60");
        assert_eq!(data.len(), POINT_DATA.len());
    }
    // one state to a file or to standard output; a series needs its name
    let one = common::knotrod(&["export", sample, "--index", "3", "--format", "vtp"]);
    assert!(one.status.success());
    assert!(one.stdout.starts_with(b"<VTKFile type=\"PolyData\""));
    let out = common::knotrod(&["export", sample, "--format", "pvd"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--out NAME.pvd"));
    std::fs::remove_dir_all(dir).unwrap();
}
