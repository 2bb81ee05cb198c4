"""The Figure 3 branch (scenes/fig3_kirchhoff.toml) through Python, for
comparison with the CLI (`knotrod run scenes/fig3_kirchhoff.toml`): the same
scene and N, every equilibrium brought back with its arrays. Not a timed
test; run it under farm-bench (docs/performance.md):

    farm-bench -n 5 --vs "target/release/knotrod run scenes/fig3_kirchhoff.toml --json /tmp/f3.json" \
        -- .venv/bin/python python/benchmarks/figure_3.py
"""

import pathlib
import sys

import knotrod

ROOT = pathlib.Path(__file__).resolve().parents[2]

if __name__ == "__main__":
    scene = knotrod.Scene.from_toml(sys.argv[1] if len(sys.argv) > 1 else ROOT / "scenes/fig3_kirchhoff.toml")
    branch = knotrod.branch(scene)
    print(f"{len(branch)} equilibria, {len(branch.events)} events")
