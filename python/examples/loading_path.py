"""A quasi-static loading path: the Appendix D knot's clamp turned down past
the pitchfork S and back (scenes/loading_hysteresis.toml). The rod jumps off
the branch on the way down and does not come back: hysteresis.

    python python/examples/loading_path.py [N]
"""

import pathlib
import sys

import numpy as np

import knotrod

ROOT = pathlib.Path(__file__).resolve().parents[2]


def main(segments: int = 60) -> knotrod.Branch:
    path = knotrod.loading(ROOT / "scenes/loading_hysteresis.toml", segments=segments)
    cols = path.columns()
    print(f"{len(path)} steps, φ/2π from {cols['phi_over_2pi'][0]:.3f} to {cols['phi_over_2pi'].min():.3f} and back")
    for e in path.events:
        print(f"  {e.kind:<13} leg {e.branch}  φ/2π = {e.phi_over_2pi:.4f}  {e.detail}")
    start, end = path.points[0], path.points[-1]
    print(f"  Tw at the start {start.twist:.4f}, back at the same clamps {end.twist:.4f}")
    print(f"  largest node distance between them: {np.abs(start.nodes - end.nodes).max():.3f}")
    return path


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 60)
