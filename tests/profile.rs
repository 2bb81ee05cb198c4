//! The fields of an equilibrium along s (`analysis::profile`): the internal
//! force and moment at every edge agree with the clamp reactions, with the
//! balance laws of a weightless rod and with the constitutive law.

use knotrod::analysis::profile::Profile;
use knotrod::scene::Scene;
use knotrod::study::start::solve_scene;
use nalgebra::Vector3;
use std::path::Path;

#[test]
fn internal_loads_of_the_appendix_d_knot() {
    let scene = Scene::load(Path::new("scenes/appendix_d.toml")).unwrap();
    let n = 100;
    let eq = solve_scene(&scene, Some(n)).unwrap();
    let p = Profile::of(&scene.rod_model(Some(n)), &eq.state);
    assert_eq!(p.s_nodes.len(), n + 2);
    assert_eq!(
        (p.s_edges.len(), p.directors.len(), p.force.len()),
        (n + 1, n + 1, n + 1)
    );
    assert_eq!((p.s_vertices.len(), p.strains.len()), (n, n));
    // edge 0 of the paper's clamp is the clamp reaction
    for k in 0..3 {
        assert!((p.force[0][k] - eq.n0[k]).abs() < 1e-9 * (1.0 + eq.n0[k].abs()));
        assert!((p.moment[0][k] - eq.m0[k]).abs() < 1e-9 * (1.0 + eq.m0[k].abs()));
    }
    let lab = |j: usize, v: [f64; 3]| {
        let [d1, d2, d3] = p.directors[j].map(Vector3::from);
        d1 * v[0] + d2 * v[1] + d3 * v[2]
    };
    // weightless: n' = 0, the same force in the lab frame at every cut
    // (both halves, each cut from its own clamp)
    let n0 = lab(0, p.force[0]);
    for j in 0..=n {
        assert!(
            (lab(j, p.force[j]) - n0).norm() < 1e-6 * n0.norm(),
            "edge {j}"
        );
    }
    // m' + r' × n = 0: m(s) = m(0) − (r(s) − r(0)) × n
    let m0 = lab(0, p.moment[0]);
    for j in [n / 4, n / 2, n] {
        let r = 0.5 * (eq.state.nodes[j] + eq.state.nodes[j + 1]);
        let expected = m0 - r.cross(&n0);
        assert!(
            (lab(j, p.moment[j]) - expected).norm() < 1e-6 * m0.norm(),
            "edge {j}"
        );
    }
    // the constitutive law m = (u1, K2 u2, K3 u3) at the vertices, to O(h):
    // each vertex between the moments of its two edges
    let k = [1.0, 3.0, 3.0];
    let scale = m0.norm();
    for i in 1..=n {
        let u = p.strains[i - 1];
        for c in 0..3 {
            let mid = 0.5 * (p.moment[i - 1][c] + p.moment[i][c]);
            assert!(
                (k[c] * u[c] - mid).abs() < 0.05 * scale,
                "vertex {i} component {c}"
            );
        }
    }
}
