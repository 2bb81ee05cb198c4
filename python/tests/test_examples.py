"""Every example of python/examples runs (at coarse N where it allows), and
the matplotlib one writes its PNG."""

import importlib.util
import pathlib

import pytest

EXAMPLES = pathlib.Path(__file__).resolve().parents[1] / "examples"


def load(name):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_every_example_is_tested():
    assert {p.stem for p in EXAMPLES.glob("*.py")} == {"appendix_d_knot", "figure_3", "verify_shooting", "loading_path"}


def test_appendix_d_knot(capsys):
    eq = load("appendix_d_knot").main(200)
    assert eq.good_knot and eq.stable
    assert "good knot True" in capsys.readouterr().out


def test_figure_3_writes_a_png(tmp_path):
    pytest.importorskip("matplotlib")
    png = load("figure_3").main(str(tmp_path / "figure_3.png"), 60)
    data = png.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 20_000


def test_verify_shooting(capsys):
    checks = load("verify_shooting").main(n=40)
    assert checks[0]["verdict"] == "Confirmed"
    # the second row is the other equilibrium, and not stable as claimed
    assert "DifferentEquilibrium" in checks[1]["verdict"]
    assert "REFUTED" in capsys.readouterr().out


def test_loading_path():
    path = load("loading_path").main(60)
    assert any(e.kind == "jump" for e in path.events)
