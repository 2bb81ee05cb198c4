#!/usr/bin/env python3
"""AUTO-07p's Figure 3 branch as a shooting user has it: its own files.

The lean sibling of run_auto.py for `knotrod verify` (tests/auto.rs,
docs/verify/fig3_auto.md): no numpy or scipy, only AUTO-07p's Python
interface. In DIR it
  1. integrates (A.2) from the paper's 5-digit Appendix D start (n0, m0 at
     phi/2pi = 0.802) by classical RK4 (pure Python) into rod.dat, with the
     s = 1 mismatch G0 of that start;
  2. polishes it by the homotopy HOM 0 -> 1 of rod.f90 (conditions
     G(u(1)) - (1 - HOM) G0) at fixed phi/2pi = 0.802;
  3. with G0 set to 0 (the clamps' own s = 1 conditions), continues in PHI = PAR(1) = phi/2pi downward through W1 and the
     pitchfork S (AUTO's BP) to the fold (its LP), labelling every NPR-th
     step, and saves the result as s.NAME / b.NAME / d.NAME.

usage: fig3_labels.py --dir DIR [--ntst 50] [--npr 10] [--name fig3]
"""
import argparse
import contextlib
import io
import math
import os
import shutil
import sys

AUTO_DIR = os.environ.get("AUTO_DIR", "/usr/lib/auto-07p")
HERE = os.path.dirname(os.path.abspath(__file__))

K2 = K3 = 3.0
ZSTAR, DELTA, PHI0 = 0.115, 0.05, 0.802
N0 = [-24.743, 17.772, 37.145]
M0 = [7.5317, -8.7100, 4.529]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def rhs(y):
    """(A.2) as in rod.f90's FUNC: r, d1, d2, d3 (lab), n, m (material)."""
    d1, d2, d3, n, m = y[3:6], y[6:9], y[9:12], y[12:15], y[15:18]
    u = [m[0], m[1] / K2, m[2] / K3]
    out = list(d3)
    out += [u[2] * d2[i] - u[1] * d3[i] for i in range(3)]
    out += [u[0] * d3[i] - u[2] * d1[i] for i in range(3)]
    out += [u[1] * d1[i] - u[0] * d2[i] for i in range(3)]
    out += cross(n, u)
    mu = cross(m, u)
    out += [mu[0] + n[1], mu[1] - n[0], mu[2]]
    return out


def write_start(path, points=401, substeps=10):
    """rod.dat by RK4 (4000 steps: error far below the homotopy's reach);
    returns the s = 1 mismatch G0 (rod.f90's FB(13:18) at HOM = 1)."""
    y = [0.0] * 3 + [1.0, 0, 0, 0, 1.0, 0, 0, 0, 1.0] + N0 + M0
    h = 1.0 / ((points - 1) * substeps)
    rows = [(0.0, y)]
    for k in range(1, points):
        for _ in range(substeps):
            k1 = rhs(y)
            k2 = rhs([a + 0.5 * h * b for a, b in zip(y, k1)])
            k3 = rhs([a + 0.5 * h * b for a, b in zip(y, k2)])
            k4 = rhs([a + h * b for a, b in zip(y, k3)])
            y = [a + h / 6 * (b + 2 * c + 2 * d + e) for a, b, c, d, e in zip(y, k1, k2, k3, k4)]
        rows.append((k / (points - 1), y))
    with open(path, "w") as f:
        for s, v in rows:
            f.write(" ".join("%.15e" % x for x in [s] + v) + "\n")
    phi = 2 * math.pi * PHI0
    return [y[0] + DELTA * math.cos(phi / 2), y[1] + DELTA * math.sin(phi / 2), y[2] - ZSTAR,
            y[9], y[10], -math.sin(phi) * y[3] + math.cos(phi) * y[4]]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--dir", required=True)
    ap.add_argument("--ntst", type=int, default=50)
    ap.add_argument("--ncol", type=int, default=4)
    ap.add_argument("--npr", type=int, default=10, help="label every NPR-th step")
    ap.add_argument("--name", default="fig3")
    a = ap.parse_args()
    workdir = os.path.abspath(a.dir)
    os.makedirs(workdir, exist_ok=True)
    for f in ("rod.f90", "c.rod"):
        shutil.copy2(os.path.join(HERE, f), workdir)
    os.chdir(workdir)
    sys.path.insert(0, os.path.join(AUTO_DIR, "python"))
    import auto  # noqa: E402  (AUTO-07p's own Python interface)

    g0 = write_start(os.path.join(workdir, "rod.dat"))
    common = dict(e="rod", c="rod", NTST=a.ntst, NCOL=a.ncol)
    log = io.StringIO()
    with contextlib.redirect_stdout(log):
        auto.run(dat="rod", ICP=["HOM"], PAR=dict({"HOM": 0.0}, **{"G%d" % i: g0[i - 1] for i in range(1, 7)}),
                 DS=0.5, DSMAX=1.0, UZSTOP={"HOM": 1.0}, NPR=1000, sv="polish", **common)
        # G = 0 from here on: the s = 1 conditions are exactly the clamps'
        # whatever HOM the homotopy stopped at (its UZ is located to ~1e-5)
        auto.run(s="polish", IRS="UZ1", ICP=["PHI"], PAR={"G%d" % i: 0.0 for i in range(1, 7)},
                 DS=-0.01, STOP=["LP1"], UZSTOP={"PHI": 0.70}, NPR=a.npr, sv=a.name, **common)
    with open(os.path.join(workdir, "auto.log"), "w") as f:
        f.write(log.getvalue())
    for ext in ("s", "b"):
        if not os.path.exists(os.path.join(workdir, "%s.%s" % (ext, a.name))):
            sys.exit("AUTO-07p wrote no %s.%s (see %s/auto.log)" % (ext, a.name, workdir))
    print(os.path.join(workdir, "s." + a.name))


if __name__ == "__main__":
    main()
