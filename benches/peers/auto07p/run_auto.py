#!/usr/bin/env python3
"""AUTO-07p continuation of the paper's Kirchhoff rod knot (Appendix D start).

Runs, in a scratch directory:
  polish: the shooting start (n0, m0 of Appendix D, 5 digits) integrated from
          s = 0 to make rod.dat; a homotopy HOM 0 -> 1 in the s = 1 conditions
          at fixed phi/2pi = 0.802 turns it into a collocation solution;
  up:     continuation in PHI = phi/2pi upward to PHI = 0.97 (past X);
  down:   continuation downward through W1 and the pitchfork S to the fold LP.
Then reads AUTO's solution files and prints the events as JSON:
  LP, BP (AUTO's own detection), W1, W2 (interior extremum of z on a wall)
  and X (the centreline passing through itself), by post-processing.

usage: run_auto.py --ntst 100 [--ncol 4] [--dir /tmp/x] [--phase all|auto|post]
"""
import argparse
import contextlib
import io
import json
import os
import shutil
import sys
import time

import numpy as np

AUTO_DIR = os.environ.get("AUTO_DIR", "/usr/lib/auto-07p")
HERE = os.path.dirname(os.path.abspath(__file__))

sys.path.insert(0, os.path.join(HERE, ".."))
from paper_rod import DELTA, ZSTAR, PHI0_OVER_2PI as PHI0, N0, M0, rhs  # noqa: E402

# --------------------------------------------------------------------------
# the start: (A.2) integrated from s = 0 (the paper's shooting data)


def end_conditions(y1, phi_over_2pi):
    """The s = 1 conditions of rod.f90's BCND (FB(13:18)) at HOM = 1."""
    phi = 2 * np.pi * phi_over_2pi
    return np.array([y1[0] + DELTA * np.cos(phi / 2), y1[1] + DELTA * np.sin(phi / 2),
                     y1[2] - ZSTAR, y1[9], y1[10],
                     -np.sin(phi) * y1[3] + np.cos(phi) * y1[4]])


def write_start(path, points=401):
    from scipy.integrate import solve_ivp
    y0 = np.concatenate([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], N0, M0])
    s = np.linspace(0, 1, points)
    sol = solve_ivp(rhs, (0, 1), y0, method="DOP853", rtol=1e-12, atol=1e-12, t_eval=s)
    np.savetxt(path, np.column_stack([s, sol.y.T]), fmt="%.15e")
    return end_conditions(sol.y[:, -1], PHI0)


# --------------------------------------------------------------------------
# AUTO runs
def run_auto(ntst, ncol, workdir, npr=1):
    sys.path.insert(0, os.path.join(AUTO_DIR, "python"))
    import auto  # noqa: E402  (AUTO-07p's own Python interface)

    g0 = write_start(os.path.join(workdir, "rod.dat"))
    common = dict(e="rod", c="rod", NTST=ntst, NCOL=ncol)
    cont = dict(common, NPR=npr)
    log = io.StringIO()
    times = {}
    with contextlib.redirect_stdout(log):
        t = time.perf_counter()
        auto.run(dat="rod", ICP=["HOM"], PAR=dict({"HOM": 0.0}, **{"G%d" % i: float(g0[i - 1]) for i in range(1, 7)}),
                 DS=0.5, DSMAX=1.0, UZSTOP={"HOM": 1.0}, NPR=1000, sv="polish", **common)
        times["polish"] = time.perf_counter() - t
        t = time.perf_counter()
        auto.run(s="polish", IRS="UZ1", ICP=["PHI"], DS=0.01, UZSTOP={"PHI": 0.97}, sv="up", **cont)
        times["up"] = time.perf_counter() - t
        t = time.perf_counter()
        auto.run(s="polish", IRS="UZ1", ICP=["PHI"], DS=-0.01, STOP=["LP1"], UZSTOP={"PHI": 0.70},
                 sv="down", **cont)
        times["down"] = time.perf_counter() - t
    with open(os.path.join(workdir, "auto.log"), "w") as f:
        f.write(log.getvalue())
    return times


# --------------------------------------------------------------------------
# reading AUTO's solution file (s.NAME)
def read_solutions(path):
    """Every solution of an AUTO s-file: dicts with t, U (NDIM x points), par, itp, lab."""
    out = []
    with open(path) as f:
        lines = f.readlines()
    i = 0
    while i < len(lines):
        h = [int(v) for v in lines[i].split()]
        ibr, ntot, itp, lab, nfpr, isw, ntpl, nar, nrowpr, ntst, ncol, npar = h[:12]
        block = np.array(" ".join(lines[i + 1:i + 1 + nrowpr]).replace("D", "E").split(), float)
        sol = block[:ntpl * nar].reshape(ntpl, nar)
        out.append(dict(t=sol[:, 0], U=sol[:, 1:].T, par=block[-npar:], itp=itp, lab=lab,
                        ntst=ntst, ncol=ncol))
        i += 1 + nrowpr
    return out


def read_branch(path):
    """Every computed point of an AUTO b-file: (PT, TY, PAR(1)) rows."""
    rows = []
    with open(path) as f:
        for line in f:
            w = line.split()
            if len(w) < 5 or w[0] == "0":
                continue
            rows.append((int(w[1]), int(w[2]), float(w[4])))
    return rows


# --------------------------------------------------------------------------
# the events by post-processing (piecewise collocation polynomials)
class Piecewise:
    """The collocation solution: on each mesh interval, the Lagrange polynomial
    of degree NCOL through its NCOL + 1 stored points."""

    def __init__(self, t, U, ncol):
        self.t, self.U, self.ncol = t, U, ncol
        self.mesh = t[::ncol]
        self.cache = {}

    def interval(self, s):
        return min(max(np.searchsorted(self.mesh, s) - 1, 0), len(self.mesh) - 2)

    def coeffs(self, j):
        """Polynomial coefficients (in s - mesh[j]) of every component on interval j."""
        if j not in self.cache:
            idx = slice(j * self.ncol, (j + 1) * self.ncol + 1)
            x = self.t[idx] - self.mesh[j]
            V = np.vander(x, self.ncol + 1)
            self.cache[j] = np.linalg.solve(V, self.U[:, idx].T).T  # NDIM x (ncol+1)
        return self.cache[j]

    def eval(self, comps, s, deriv=0):
        j = self.interval(s)
        c = self.coeffs(j)[comps]
        x = s - self.mesh[j]
        if deriv:
            c = c[..., :-1] * np.arange(self.ncol, 0, -1)
        p = np.zeros(c.shape[:-1])
        for k in range(c.shape[-1]):
            p = p * x + c[..., k]
        return p


def bisect(f, a, b, tol=1e-14):
    fa = f(a)
    for _ in range(80):
        c = 0.5 * (a + b)
        fc = f(c)
        if (fc > 0) == (fa > 0):
            a, fa = c, fc
        else:
            b = c
        if b - a < tol:
            break
    return 0.5 * (a + b)


def wall_clearance(p, zstar):
    """Smallest clearance of an interior local extremum of z from its wall
    (minimum against z = 0, maximum against z = z*); negative outside."""
    dz = p.U[11]  # z' = d3z
    best = np.inf
    for i in range(1, len(p.t) - 2):
        if dz[i] == 0 or (dz[i] > 0) != (dz[i + 1] > 0):
            s = bisect(lambda x: p.eval(11, x), p.t[i], p.t[i + 1])
            z = p.eval(2, s)
            best = min(best, z if dz[i] < 0 else zstar - z)
    return best


def crossing_candidates(p, gap=0.05):
    """Local minima over s1 < s2 (s2 - s1 > gap) of |r(s1) - r(s2)|, refined
    on the polynomials, with the sign of (r2 - r1).(t1 x t2)."""
    r = p.U[0:3].T
    t = p.t
    D = np.linalg.norm(r[:, None, :] - r[None, :, :], axis=2)
    n = len(t)
    C = D[1:-1, 1:-1]
    ok = (t[None, 1:-1] - t[1:-1, None] > gap) & (C < 0.05)
    for di in (-1, 0, 1):
        for dj in (-1, 0, 1):
            ok &= C <= D[1 + di:n - 1 + di, 1 + dj:n - 1 + dj]
    out = []
    for i, j in zip(*np.nonzero(ok)):
        i, j = i + 1, j + 1
        s1, s2 = t[i], t[j]
        for _ in range(30):  # Newton on (r1 - r2).t1 = 0, (r1 - r2).t2 = 0
            r1, r2 = p.eval([0, 1, 2], s1), p.eval([0, 1, 2], s2)
            t1, t2 = p.eval([9, 10, 11], s1), p.eval([9, 10, 11], s2)
            k1, k2 = p.eval([9, 10, 11], s1, 1), p.eval([9, 10, 11], s2, 1)
            e = r1 - r2
            F = np.array([e @ t1, e @ t2])
            J = np.array([[t1 @ t1 + e @ k1, -t2 @ t1], [t1 @ t2, -t2 @ t2 + e @ k2]])
            ds = np.linalg.solve(J, -F)
            s1, s2 = s1 + ds[0], s2 + ds[1]
            if abs(ds).max() < 1e-13:
                break
        r1, r2 = p.eval([0, 1, 2], s1), p.eval([0, 1, 2], s2)
        t1, t2 = p.eval([9, 10, 11], s1), p.eval([9, 10, 11], s2)
        nrm = np.cross(t1, t2)
        out.append((s1, s2, float((r2 - r1) @ nrm / np.linalg.norm(nrm))))
    return out


def zero_by_inverse_interpolation(phis, gs, k):
    """phi where g = 0 between samples k and k + 1: cubic inverse
    interpolation through the (up to) four nearest samples."""
    lo, hi = max(k - 1, 0), min(k + 3, len(phis))
    x, y = np.array(gs[lo:hi]), np.array(phis[lo:hi])
    phi = 0.0
    for a in range(len(x)):
        w = np.prod([(0 - x[b]) / (x[a] - x[b]) for b in range(len(x)) if b != a])
        phi += w * y[a]
    return phi


def events(workdir, solutions=True):
    ev = {}
    for name in ("up", "down"):
        for pt, ty, phi in read_branch(os.path.join(workdir, "b." + name)):
            code = {5: "LP", 6: "BP"}.get(abs(ty) % 10)
            if code and code not in ev:
                ev[code] = phi
    for name in ("up", "down") if solutions else ():
        sols = read_solutions(os.path.join(workdir, "s." + name))
        sols = [s for s in sols if s["lab"] > 0]
        # order along the branch from the start (the first is phi = 0.802)
        phis, walls, cands = [], [], []
        for s in sols:
            p = Piecewise(s["t"], s["U"], s["ncol"])
            phis.append(s["par"][0])
            walls.append(wall_clearance(p, s["par"][1]))
            cands.append(crossing_candidates(p))
        walls = np.array(walls)
        for k in range(len(phis) - 1):
            if walls[k] * walls[k + 1] < 0:
                key = "W2" if name == "up" else "W1"
                ev.setdefault(key, zero_by_inverse_interpolation(phis, walls, k))
        # crossing: follow each candidate pair, by its (s1, s2), along the branch
        if name == "up":
            for k in range(len(phis) - 1):
                for (a1, a2, da) in cands[k]:
                    for (b1, b2, db) in cands[k + 1]:
                        if abs(a1 - b1) + abs(a2 - b2) < 0.05 and da * db < 0:
                            series = []
                            for c in cands:
                                near = [d for (c1, c2, d) in c if abs(c1 - a1) + abs(c2 - a2) < 0.1]
                                series.append(near[0] if near else np.nan)
                            ev.setdefault("X", zero_by_inverse_interpolation(phis, series, k))
    return ev


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--ntst", type=int, default=100)
    ap.add_argument("--ncol", type=int, default=4)
    ap.add_argument("--dir", default=None)
    ap.add_argument("--lean", action="store_true",
                    help="store no solutions (NPR huge): only AUTO's own LP and BP")
    ap.add_argument("--phase", default="all", choices=["all", "auto", "post", "compile"])
    a = ap.parse_args()
    workdir = os.path.abspath(a.dir or os.path.join(HERE, "out", "ntst%d" % a.ntst))
    os.makedirs(workdir, exist_ok=True)
    for f in ("rod.f90", "c.rod"):
        if not os.path.exists(os.path.join(workdir, f)) or \
                os.path.getmtime(os.path.join(workdir, f)) < os.path.getmtime(os.path.join(HERE, f)):
            shutil.copy2(os.path.join(HERE, f), workdir)
    os.chdir(workdir)
    result = {"ntst": a.ntst, "ncol": a.ncol, "lean": a.lean}
    if a.phase == "compile":
        sys.path.insert(0, os.path.join(AUTO_DIR, "python"))
        import auto
        with contextlib.redirect_stdout(io.StringIO()):
            auto.run(e="rod", c="rod", dat=None, NMX=1, ICP=["PHI"], NTST=4)  # builds rod.exe
        return
    if a.phase in ("all", "auto"):
        result["seconds"] = run_auto(a.ntst, a.ncol, workdir, 10**6 if a.lean else 1)
    if a.phase in ("all", "post"):
        t = time.perf_counter()
        result["events"] = events(workdir, not a.lean)
        start = read_solutions(os.path.join(workdir, "s.polish"))[-1]
        result["n0"] = start["U"][12:15, 0].tolist()
        result["m0"] = start["U"][15:18, 0].tolist()
        result["post_seconds"] = time.perf_counter() - t
    print(json.dumps(result))


if __name__ == "__main__":
    main()
