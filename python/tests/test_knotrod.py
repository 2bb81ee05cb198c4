"""The Python package against the paper's numbers and the Rust tests'
checks (tests/paper_equilibria.rs, tests/continuation.rs, tests/knots.rs,
tests/recordings.rs), with the same tolerances at coarse N where they allow."""

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import knotrod

# the paper's Appendix D (../shared/reference/paper_targets.toml)
D_N0 = np.array([-24.743, 17.772, 37.145])
D_M0 = np.array([7.5317, -8.7100, 4.529])


def relative(a, b):
    return np.linalg.norm(np.asarray(a) - b) / np.linalg.norm(b)


def test_appendix_d_numbers(root):
    eq = knotrod.equilibrium(knotrod.Scene.from_toml(root / "scenes/appendix_d.toml"), segments=200)
    # the tolerances of tests/paper_equilibria.rs at N = 200
    assert eq.converged and eq.gradient_norm <= 1e-10
    assert eq.stable and eq.negative_eigenvalues == 0
    assert eq.walled and eq.good_knot and eq.knotted
    assert abs(eq.twist - 0.107) < 0.005
    assert relative(eq.n0, D_N0) < 0.02 and relative(eq.m0, D_M0) < 0.02
    assert abs(eq.link - 3.802) < 0.01
    assert eq.knot_name == "3_1" and eq.knot_determinant == 3
    assert len(eq.lowest_eigenvalues) == 4 and min(eq.lowest_eigenvalues) > 0
    assert min(eq.omega_squared) > 0
    # the arrays along s
    n = 200
    assert eq.nodes.shape == (n + 2, 3) and eq.s_nodes.shape == (n + 2,)
    assert eq.directors.shape == (n + 1, 3, 3) and eq.d3.shape == (n + 1, 3)
    assert eq.strains.shape == (n, 3) and eq.force.shape == (n + 1, 3)
    assert np.allclose(eq.force[0], eq.n0) and np.allclose(eq.moment[0], eq.m0)
    # orthonormal frames, d3 along the edges
    assert np.allclose(np.einsum("jab,jcb->jac", eq.directors, eq.directors), np.eye(3), atol=1e-12)
    edges = np.diff(eq.nodes, axis=0)
    assert np.allclose(eq.d3, edges / np.linalg.norm(edges, axis=1)[:, None])
    # the clamps: x(0) = 0 and x(1) = (-δ cos φ/2, -δ sin φ/2, z*)
    assert np.allclose(eq.nodes[:2].mean(axis=0), 0, atol=1e-12)
    phi = 2 * np.pi * 0.802
    assert np.allclose(eq.nodes[-2:].mean(axis=0), [-0.05 * np.cos(phi / 2), -0.05 * np.sin(phi / 2), 0.115])
    # Tw = (1/2π) ∫ u3 ds
    assert abs(eq.strains[:, 2].sum() / n / (2 * np.pi) - eq.twist) < 1e-9
    d = eq.to_dict()
    assert d["energy"] == eq.energy and d["nodes"] is eq.nodes


def test_figure_3_events(root):
    # the branch of tests/continuation.rs (figure_3_events_at_n_200)
    scene = knotrod.Scene.from_toml(root / "scenes/appendix_d.toml").with_(
        continuation={"parameter": "phi", "range": [0.745, 0.99], "direction": "both"},
        stability={"eigenvalues": 2},
    )
    seen = []
    b = knotrod.branch(scene, segments=200, progress=seen.append)
    assert len(seen) == len(b) > 20 and not b.interrupted
    w1, w2, x, s = (b.event(k) for k in ("W1", "W2", "X", "S"))
    assert (w1.kind, w2.kind, x.kind, s.kind) == ("wall", "wall", "crossing", "branch_point")
    assert abs(w1.phi_over_2pi - 0.774) < 0.005
    assert abs(w2.phi_over_2pi - 0.82) < 0.01
    assert abs(x.phi_over_2pi - 0.96) < 0.01
    assert 0.745 < s.phi_over_2pi < w1.phi_over_2pi
    assert s.detail.startswith("negative eigenvalues 0 → 1")
    # each bisected event says how closely it was located
    assert all(e.located_within is not None and e.located_within < 1e-8 for e in (w1, w2, x, s))
    # columns: one array per scalar, as pandas.DataFrame takes them
    cols = b.columns()
    assert all(len(v) == len(b) for v in cols.values())
    good = cols["good_knot"]
    assert good.dtype == bool and good.any()
    phis = cols["phi_over_2pi"][good]
    assert w1.phi_over_2pi - 0.01 < phis.min() and phis.max() < w2.phi_over_2pi + 0.01
    ev = b.to_dict()["events"]
    assert set(ev["label"]) >= {"W1", "W2", "X", "S"}
    json.dumps({k: v.tolist() for k, v in cols.items()})


def test_strip_equilibrium(root):
    eq = knotrod.equilibrium(root / "scenes/fig8_strip_knot.toml", segments=100)
    # the strip's constraint u2 = 0 holds, and it is the paper's good knot
    assert eq.max_u2 < 1e-9 and np.abs(eq.strains[:, 1]).max() < 1e-9
    assert eq.walled and eq.stable and eq.knot_name == "3_1" and eq.good_knot


def test_scene_from_keywords_and_dict_is_the_file(root):
    from_file = knotrod.Scene.from_toml(root / "scenes/appendix_d.toml")
    d = from_file.to_dict()
    from_dict = knotrod.Scene(d)
    from_kw = knotrod.Scene(model=d["model"], clamps=d["clamps"], initial=d["initial"], solver=d["solver"], stability=d["stability"])
    a = knotrod.equilibrium(from_file, segments=60)
    for other in (from_dict, from_kw):
        b = knotrod.equilibrium(other, segments=60)
        assert np.array_equal(a.nodes, b.nodes) and a.energy == b.energy


@pytest.mark.parametrize(
    "change, field",
    [
        ({"model": {"K2": -1.0}}, "model.K2"),
        ({"model": {"K2": "stiff"}}, "model.K2"),
        ({"model": {"segmnts": 10}}, "model.segmnts"),
        ({"clamps": {"z_star": float("nan")}}, "clamps.z_star"),
        ({"stability": {"eigenvalues": -1}}, "stability.eigenvalues"),
        ({"bogus": {"a": 1}}, "bogus"),
    ],
)
def test_bad_input_raises_scene_error_naming_the_field(root, change, field):
    d = knotrod.Scene.from_toml(root / "scenes/appendix_d.toml").to_dict()
    for section, values in change.items():
        d.setdefault(section, {}).update(values)
    with pytest.raises(knotrod.SceneError) as e:
        knotrod.Scene(d)
    assert e.value.field == field, str(e.value)
    assert field.split(".")[-1] in str(e.value)


def test_missing_section_and_bad_calls():
    with pytest.raises(knotrod.SceneError) as e:
        knotrod.Scene(model={"K2": 3.0, "K3": 3.0, "segments": 40})
    assert e.value.field == "clamps"
    with pytest.raises(knotrod.SceneError):
        knotrod.Scene.from_toml("/nonexistent/scene.toml")
    with pytest.raises(ValueError):
        knotrod.equilibrium({"model": {"K2": 3.0, "K3": 3.0, "segments": 40}, "clamps": {"z_star": 0.1, "delta": 0.05, "phi_over_2pi": 0.8}}, segments=2)
    with pytest.raises(ValueError):
        knotrod.knot_type([[0, 0, 0], [1, 0, 0]])
    with pytest.raises(knotrod.SceneError) as e:
        knotrod.loading({"model": {"K2": 3.0, "K3": 3.0, "segments": 40}, "clamps": {"z_star": 0.1, "delta": 0.05, "phi_over_2pi": 0.8}})
    assert e.value.field == "loading"


def test_a_failed_solve_is_a_solve_error():
    # a straight start pushed far: Newton is allowed one iteration
    scene = {
        "model": {"K2": 3.0, "K3": 3.0, "segments": 40},
        "clamps": {"z_star": 0.115, "delta": 0.05, "phi_over_2pi": 0.802},
        "solver": {"max_iterations": 1},
    }
    with pytest.raises(knotrod.SolveError) as e:
        knotrod.equilibrium(scene)
    assert e.value.reason and "converge" in e.value.reason


def test_knot_type_of_the_fixtures(root):
    curves = json.loads((root / "tests/fixtures/knots/curves.json").read_text())
    checked = knotted = 0
    for c in curves[::5]:
        reference = c.get("alexander_pyknotid") or c.get("alexander_topoly")
        if reference is None or (c.get("alexander_topoly") and c.get("alexander_pyknotid") and c["alexander_topoly"] != c["alexander_pyknotid"]):
            continue
        k = knotrod.knot_type(np.array(c["points"]), closed=True)
        assert k["alexander"] == reference and k["knot_determinant"] == c["determinant"], c["name"]
        if c.get("expected"):
            assert c["expected"] in k["knot_names"], c["name"]
        checked += 1
        knotted += k["knot_determinant"] > 1
    assert checked >= 50 and knotted >= 20
    # a trefoil closed by rays
    t = np.linspace(0, 2 * np.pi, 200, endpoint=False)
    trefoil = np.stack([np.sin(t) + 2 * np.sin(2 * t), np.cos(t) - 2 * np.cos(2 * t), -np.sin(3 * t)], axis=1)
    assert knotrod.knot_type(trefoil)["knot_name"] == "3_1"


def test_recording_read_back(root, tmp_path):
    scene = knotrod.Scene.from_toml(root / "scenes/appendix_d.toml").with_(
        continuation={"parameter": "phi", "range": [0.79, 0.83], "direction": "up"},
    )
    rec = tmp_path / "branch.mcap"
    b = knotrod.branch(scene, segments=40, record=rec)
    r = knotrod.read_recording(rec)
    assert len(r) == len(b) > 3
    assert r.metadata["scene"] == scene.text
    assert [e.label for e in r.events] == [e.label for e in b.events]
    for got, want in zip(r.states, b.points):
        assert np.allclose(got.nodes, want.nodes, atol=1e-12)
        assert np.allclose(got.force, want.force, rtol=1e-9, atol=1e-9)
        assert got.twist == pytest.approx(want.twist) and got.stable == want.stable
    assert len(r.to_dict()["scalars"]["twist"]) == len(b)


def test_loading_path_jumps(root):
    path = knotrod.loading(root / "scenes/loading_hysteresis.toml", segments=60)
    kinds = {e.kind for e in path.events}
    assert "jump" in kinds, kinds
    assert path.points[0].phi_over_2pi == pytest.approx(0.802)
    assert path.points[-1].phi_over_2pi == pytest.approx(0.802)


def test_a_progress_callback_that_raises_stops_the_run(root):
    scene = knotrod.Scene.from_toml(root / "scenes/fig3_kirchhoff.toml")

    def stop(point):
        if point["index"] == 3:
            raise RuntimeError("enough")

    with pytest.raises(RuntimeError, match="enough") as e:
        knotrod.branch(scene, segments=40, progress=stop)
    assert len(e.value.partial) == 4


def test_an_interrupted_branch_keeps_the_events_it_passed(root, tmp_path):
    # Figure 3 at N = 60 passes W2 and X going up in φ before its 40th point:
    # the partial branch and its recording keep them
    scene = knotrod.Scene.from_toml(root / "scenes/fig3_kirchhoff.toml")
    full = knotrod.branch(scene, segments=60)
    upto = [e for e in full.events if e.phi_over_2pi > 0.802 and e.branch == 0]
    assert {e.label for e in upto} >= {"W2", "X"}

    def stop(point):
        if point["index"] == 40:
            raise RuntimeError("enough")

    record = tmp_path / "partial.mcap"
    with pytest.raises(RuntimeError, match="enough") as e:
        knotrod.branch(scene, segments=60, progress=stop, record=str(record))
    partial = e.value.partial
    # the same events (labels are counted among those found: the partial's
    # only wall event is its W1)
    passed = {(ev.kind, round(ev.phi_over_2pi, 9)) for ev in partial.events if ev.label}
    assert {(ev.kind, round(ev.phi_over_2pi, 9)) for ev in upto if ev.label in ("W2", "X")} <= passed
    assert len(knotrod.read_recording(record).events) == len(partial.events)


CHILD = r"""
import signal, sys, knotrod
# a child started from a non-interactive shell's background job inherits
# SIGINT ignored, and Python then installs no KeyboardInterrupt handler
signal.signal(signal.SIGINT, signal.default_int_handler)
scene = knotrod.Scene.from_toml(sys.argv[1]).with_(continuation={"step": 0.0005, "max_step": 0.001})
def progress(point):
    print("point", point["index"], flush=True)
try:
    knotrod.branch(scene, segments=400, progress=progress, record=sys.argv[2])
except KeyboardInterrupt as e:
    print("interrupted", len(e.partial), e.partial.interrupted, flush=True)
    sys.exit(0)
print("finished", flush=True)
sys.exit(1)
"""


def test_ctrl_c_interrupts_a_long_branch_cleanly(root, tmp_path):
    rec = tmp_path / "interrupted.mcap"
    child = subprocess.Popen(
        [sys.executable, "-c", CHILD, str(root / "scenes/fig3_kirchhoff.toml"), str(rec)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    lines = []
    for line in child.stdout:
        lines.append(line.strip())
        if line.startswith("point 5"):
            child.send_signal(signal.SIGINT)
            break
    out, err = child.communicate(timeout=120)
    lines += out.split("\n")
    assert child.returncode == 0, (lines, err)
    done = [l for l in lines if l.startswith("interrupted")]
    assert done, (lines, err)
    count = int(done[0].split()[1])
    assert count >= 6 and done[0].endswith("True")
    # the recording was finalised with what was computed
    r = knotrod.read_recording(rec)
    assert len(r) == count


def test_branch_points_are_converted_on_access(root):
    scene = knotrod.Scene.from_toml(root / "scenes/appendix_d.toml").with_(
        continuation={"parameter": "phi", "range": [0.76, 0.83], "direction": "up"},
    )
    b = knotrod.branch(scene, segments=40)
    assert len(b) > 3 and not any(p._scalars_read or p._arrays_read for p in b.points)
    # the columns come from the Rust result, no point converted, and agree
    # with the points' own scalars
    cols = b.columns()
    assert not any(p._scalars_read for p in b.points)
    # a point: its scalars when first read, its arrays when first read, the
    # same objects after
    p = b.points[-1]
    assert p.segments == 40 and not p._scalars_read
    assert p.twist == cols["twist"][-1] and not p._arrays_read
    assert p.nodes is p.nodes and p.to_dict()["nodes"] is p.nodes
    assert b.points[-1] is p and p.d3.shape == (41, 3)
    # the points converted agree with the columns
    eager = knotrod.Branch([p.to_dict() for p in b.points], [e.to_dict() for e in b.events]).columns()
    assert list(cols) == list(eager)
    for k, v in cols.items():
        assert v.dtype == eager[k].dtype and np.array_equal(v, eager[k], equal_nan=True), k
    # pickled and copied whole
    import copy
    import pickle

    q = pickle.loads(pickle.dumps(b.points[1]))
    assert np.array_equal(q.force, b.points[1].force) and q.energy == b.points[1].energy
    assert copy.deepcopy(b.points[2]).link == b.points[2].link
    c = pickle.loads(pickle.dumps(b))
    assert np.array_equal(c.columns()["twist"], cols["twist"])
    with pytest.raises(AttributeError):
        b.points[0].no_such_field


def test_event_kinds_are_strings_and_an_enum(root):
    scene = knotrod.Scene.from_toml(root / "scenes/appendix_d.toml").with_(
        continuation={"parameter": "phi", "range": [0.76, 0.83], "direction": "up"},
    )
    w = knotrod.branch(scene, segments=40).event("W1")
    assert w.kind is knotrod.EventKind.WALL and w.kind == "wall"
    assert "wall" in {w.kind} and f"{w.kind:>5}" == " wall" and str(w.kind) == "wall"
    assert json.loads(json.dumps(w.to_dict()))["kind"] == "wall"
    assert knotrod.EventKind("branch_point") is knotrod.EventKind.BRANCH_POINT


def island_scene(root):
    """Figure 7-left at N = 40 with three lines and no polish: a quick map."""
    text = (root / "scenes/fig7_island_kirchhoff.toml").read_text()
    for a, b in [("segments = 100", "segments = 40"), ("lines = 27", "lines = 3"),
                 ("grid_columns = 91", "grid_columns = 11"), ("polish = true", "polish = false")]:
        assert a in text
        text = text.replace(a, b)
    return knotrod.Scene.from_text(text)


def test_map_walks_the_island_boundary_and_resumes_from_its_cache(root, tmp_path):
    seen = []
    m = knotrod.map(island_scene(root), progress=seen.append, cache=tmp_path)
    traced = m["traced"]
    # Figure 7-left: the island is bounded by W1, S, X and W2
    assert traced["closed"], traced["stopped"]
    assert sorted(p["label"] for p in traced["pieces"]) == ["S", "W1", "W2", "X"]
    assert 0.8 < traced["area"] / m["good_area"] < 1.2
    boundary = [s for s in seen if s["stage"] == "boundary"]
    lines = [s for s in seen if s["stage"] == "line"]
    assert len(boundary) > 50
    assert sorted(s["index"] for s in lines) == [0, 1, 2]
    # a rerun takes the walk and the lines from the cache
    again = []
    assert knotrod.map(island_scene(root), progress=again.append, cache=tmp_path) == m
    assert again == []


def test_an_interrupted_map_keeps_its_walk_and_lines(root):
    class Stop(Exception):
        pass

    def progress(item):
        if item["stage"] == "line":
            raise Stop()

    with pytest.raises(Stop) as stopped:
        knotrod.map(island_scene(root), progress=progress)
    partial = stopped.value.partial
    assert partial["traced"]["closed"]
    assert 1 <= len(partial["lines"]) <= 3


def test_verify_reports_each_solution_and_stops_on_an_exception(root):
    table = root / "scenes/verify/two_equilibria.toml"
    seen = []
    checks = knotrod.verify(table, segments=(20, 40, 80), progress=seen.append)
    assert sorted(c["index"] for c in seen) == sorted(c["index"] for c in checks)
    assert len(checks) >= 2

    class Stop(Exception):
        pass

    def stop(check):
        raise Stop()

    with pytest.raises(Stop) as stopped:
        knotrod.verify(table, segments=(20, 40, 80), progress=stop)
    assert 1 <= len(stopped.value.partial) <= len(checks)


def test_a_branch_restarts_from_an_equilibrium_handed_back(root):
    first = knotrod.branch(root / "scenes/fig3_kirchhoff.toml", segments=40)
    w1 = first.event("W1")
    # an equilibrium of W1's branch a little away from it, at its clamps,
    # restarts a solve and a branch
    near = min(
        (p for p in first.points if p.branch == w1.branch),
        key=lambda p: abs(p.phi_over_2pi - w1.phi_over_2pi - 0.02),
    )
    text = (root / "scenes/fig3_kirchhoff.toml").read_text().replace(
        "phi_over_2pi = 0.802", f"phi_over_2pi = {near.phi_over_2pi!r}"
    )
    scene = knotrod.Scene.from_text(text)
    again = knotrod.equilibrium(scene, start=near)
    assert again.segments == 40
    np.testing.assert_allclose(again.nodes, near.nodes, atol=1e-7)
    assert relative(again.twist, near.twist) < 1e-8
    restarted = knotrod.branch(scene, start=near)
    # the same wall, whatever the labels of a branch from another start
    walls = [e.phi_over_2pi for e in restarted.events if e.kind == "wall"]
    assert min(abs(p - w1.phi_over_2pi) for p in walls) < 1e-6
    with pytest.raises(knotrod.SceneError) as bad:
        knotrod.equilibrium(scene, start="{}")
    assert bad.value.field == "initial.file"


def test_vtk_export_and_pyvista(root, tmp_path):
    # the .vtp of an equilibrium (knotrod export --format vtp), from a solve,
    # a branch point and a recording alike; pyvista reads it when installed
    scene = knotrod.Scene.from_toml(root / "scenes/appendix_d.toml")
    eq = knotrod.equilibrium(scene, segments=40)
    data = eq.to_vtp(tmp_path / "d.vtp")
    assert data.startswith(b'<VTKFile type="PolyData"')
    assert (tmp_path / "d.vtp").read_bytes() == data
    assert "model_json" not in eq.scalars() and "model_json" not in eq.to_dict()
    rec = knotrod.read_recording(root / "recordings/samples/fig3_n60.mcap")
    assert rec.states[5].to_vtp().startswith(b'<VTKFile type="PolyData"')
    pv = pytest.importorskip("pyvista", reason="pyvista is not installed: Equilibrium.to_pyvista() untested")
    mesh = eq.to_pyvista()
    assert isinstance(mesh, pv.PolyData) and mesh.n_points == 42 and mesh.n_lines == 1
    for name in ["s", "tube_radius", "d1", "d2", "d3", "strains", "n", "m", "n_material", "m_material"]:
        assert name in mesh.point_data, name
    # the interior points are the nodes, their strains the vertices'
    np.testing.assert_array_equal(mesh.points[1:-1], eq.nodes[1:-1])
    np.testing.assert_array_equal(mesh.point_data["strains"][1:-1], eq.strains)
    assert np.allclose(mesh.point_data["tube_radius"], 0.0025)
    # a weightless rod carries one force vector along its length
    force = mesh.point_data["n"]
    assert np.abs(force - force[0]).max() < 1e-7 * np.linalg.norm(force[0])
    assert mesh.tube(scalars="tube_radius", absolute=True).n_points > 42
