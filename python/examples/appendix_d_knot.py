"""The Appendix D knot of "Stable elastic knots with no self-contact" and
its stability: solved as a discrete rod from the paper's shooting data, its
scalars beside the paper's, and its lowest eigenvalues and ω².

    python python/examples/appendix_d_knot.py [N]
"""

import pathlib
import sys

import numpy as np

import knotrod

ROOT = pathlib.Path(__file__).resolve().parents[2]


def main(segments: int = 200) -> knotrod.Equilibrium:
    scene = knotrod.Scene.from_toml(ROOT / "scenes/appendix_d.toml")
    eq = knotrod.equilibrium(scene, segments=segments)
    print(f"Appendix D at N = {eq.segments}")
    print(f"  n(0) = {np.round(eq.n0, 3)}   paper [-24.743, 17.772, 37.145]")
    print(f"  m(0) = {np.round(eq.m0, 4)}   paper [7.5317, -8.71, 4.529]")
    print(f"  Tw = {eq.twist:.4f} (paper 0.107), link = {eq.link:.4f} (paper 3.802)")
    print(f"  knot {eq.knot_name}, walled {eq.walled}, stable {eq.stable}, good knot {eq.good_knot}")
    print(f"  lowest eigenvalues {np.round(eq.lowest_eigenvalues, 5)}")
    print(f"  lowest ω² {np.round(eq.omega_squared, 3)}")
    # the internal force is the same vector all along a weightless rod
    lab = np.einsum("ja,jab->jb", eq.force, eq.directors)
    print(f"  |n| along s: {np.linalg.norm(lab, axis=1).min():.4f} .. {np.linalg.norm(lab, axis=1).max():.4f}")
    return eq


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 200)
