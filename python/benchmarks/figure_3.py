"""The Figure 3 branch (scenes/fig3_kirchhoff.toml) through Python, for
comparison with the CLI (`knotrod run scenes/fig3_kirchhoff.toml --json
/tmp/f3.json`): the same scene and N, and what drawing Figure 3 reads of it
(python/examples/figure_3.py): the points' columns, the events, and one
equilibrium's arrays. With ``--all`` every equilibrium's scalars and arrays
are read too (each point converted). Not a timed test; whole processes are
compared in docs/performance.md:

    .venv/bin/python python/benchmarks/figure_3.py [--all] [SCENE]
"""

import pathlib
import sys

import knotrod

ROOT = pathlib.Path(__file__).resolve().parents[2]

if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--all"]
    scene = knotrod.Scene.from_toml(args[0] if args else ROOT / "scenes/fig3_kirchhoff.toml")
    branch = knotrod.branch(scene)
    cols = branch.columns()
    labels = [e.label for e in branch.events if e.kind in (knotrod.EventKind.WALL, knotrod.EventKind.CROSSING)]
    start = branch.points[0]
    read = start.nodes.shape[0] + start.force.shape[0]
    if "--all" in sys.argv[1:]:
        read += sum(len(p.scalars()) + p.nodes.shape[0] + p.force.shape[0] for p in branch.points)
    print(f"{len(branch)} equilibria ({int(cols['good_knot'].sum())} good knots), {len(branch.events)} events {labels}, {read} values read")
