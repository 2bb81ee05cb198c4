#!/usr/bin/env python3
"""PyElastica: the Appendix D knot (K2 = K3 = 3, z* = 0.115, delta = 0.05,
phi/2pi = 0.802) as a static equilibrium reached by damped dynamics.

The rod: N elements on s in [0, 1] (paper scalings: B = diag(1, K2, K3),
stretch and shear stiffness 640000 = 16/h^2 for h = 0.005, as knotrod's
scene), natural shape straight, rest length 1/N per element. Start: the
paper's shooting data (n0, m0) integrated from s = 0 (nodes r(i/N), element
directors the frame at the element's middle). Clamps: nodes 0, 1 and
N-1, N and elements 0 and N-1 held (the first and last element along the
clamp's axis e3, their frames the clamp frames: identity at s = 0, the turn
by phi about z at s = 1).

Relaxed with PyElastica's PositionVerlet and AnalyticalLinearDamper until
n(0), m(0) (material components, extrapolated to s = 0 from the two first free
elements / Voronoi points) change by less than --tol over a check interval.

usage: appendix_d.py --n 100 [--tol 1e-6] [--damping 40]  -> JSON on stdout
"""
import argparse
import os
import json
import sys
import time

import numpy as np
from scipy.integrate import solve_ivp

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from paper_rod import K2, K3, ZSTAR, DELTA, PHI0_OVER_2PI, N0, M0, rhs  # noqa: E402

PHI = 2 * np.pi * PHI0_OVER_2PI
STIFF = 640000.0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=100)
    ap.add_argument("--tol", type=float, default=1e-6)
    ap.add_argument("--damping", type=float, default=40.0)
    ap.add_argument("--cfl", type=float, default=0.5)
    ap.add_argument("--max-time", type=float, default=20.0)
    a = ap.parse_args()
    t_start = time.perf_counter()

    import elastica as ea
    from importlib.metadata import version

    N = a.n
    h = 1.0 / N
    y0 = np.concatenate([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], N0, M0])
    s_nodes = np.linspace(0, 1, N + 1)
    s_mid = (s_nodes[:-1] + s_nodes[1:]) / 2
    sol = solve_ivp(rhs, (0, 1), y0, method="DOP853", rtol=1e-12, atol=1e-12, dense_output=True)
    pos = sol.sol(s_nodes)[0:3].copy()
    fr = sol.sol(s_mid)
    directors = np.zeros((3, 3, N))
    for k in range(3):
        directors[k] = fr[3 + 3 * k:6 + 3 * k]
    # clamps: first and last element along e3 with the clamp frames
    rstar = np.array([-DELTA * np.cos(PHI / 2), -DELTA * np.sin(PHI / 2), ZSTAR])
    pos[:, 0], pos[:, 1] = 0.0, [0, 0, h]
    pos[:, N], pos[:, N - 1] = rstar, rstar - [0, 0, h]
    # each element's d3 along its edge (a Cosserat rod's start has no shear),
    # d1 the shooting frame's made normal to it
    tang = np.diff(pos, axis=1)
    tang /= np.linalg.norm(tang, axis=0)
    d1 = directors[0] - np.sum(directors[0] * tang, axis=0) * tang
    d1 /= np.linalg.norm(d1, axis=0)
    directors = np.stack([d1, np.cross(tang.T, d1.T).T, tang])
    directors[:, :, 0] = np.eye(3)
    c, s = np.cos(PHI), np.sin(PHI)
    directors[:, :, N - 1] = [[c, s, 0], [-s, c, 0], [0, 0, 1]]

    radius = 0.0025
    area = np.pi * radius ** 2
    density = 1.0 / area  # mass per unit length 1
    rod = ea.CosseratRod.straight_rod(
        N, np.zeros(3), np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0]), 1.0, radius,
        density, youngs_modulus=STIFF / area, shear_modulus=STIFF / area,
        position=pos, directors=directors)
    # the paper's model: straight, rest length 1/N, B = diag(1, K2, K3)
    rod.rest_lengths[:] = h
    rod.rest_voronoi_lengths[:] = h
    rod.rest_kappa[:] = 0.0
    rod.rest_sigma[:] = 0.0
    rod.bend_matrix[:] = np.diag([1.0, K2, K3])[:, :, None]
    rod.shear_matrix[:] = np.diag([STIFF, STIFF, STIFF])[:, :, None]

    # mass scaling for statics: rotational inertia h^2 per unit length, so
    # the shear-rotation mode (sqrt(GA / rho I)) is no stiffer than the
    # stretching waves across one element (it sets no smaller step)
    J = h * h * h  # per element
    rod.mass_second_moment_of_inertia[:] = (J * np.eye(3))[:, :, None]
    rod.inv_mass_second_moment_of_inertia[:] = (np.eye(3) / J)[:, :, None]

    class Sim(ea.BaseSystemCollection, ea.Constraints, ea.Damping):
        pass

    # explicit step: stretching / twisting waves across one element
    wave = np.sqrt(STIFF / 1.0)
    dt = a.cfl * h / wave
    sim = Sim()
    sim.append(rod)
    sim.constrain(rod).using(ea.FixedConstraint, constrained_position_idx=(0, 1, -2, -1),
                             constrained_director_idx=(0, -1))
    sim.dampen(rod).using(ea.AnalyticalLinearDamper, uniform_damping_constant=a.damping, time_step=dt)
    sim.finalize()
    stepper = ea.PositionVerlet()

    def ends():
        n = rod.internal_stress  # material-frame force per element (3, N)
        m = rod.internal_couple  # material-frame couple per interior node (3, N-1)
        # element 0 is held whole by the clamp (no strain): n from elements 1, 2
        # (s = 1.5h, 2.5h), m from the Voronoi points at s = h, 2h
        return np.concatenate([2.5 * n[:, 1] - 1.5 * n[:, 2], 2 * m[:, 0] - m[:, 1]])

    t, steps = 0.0, 0
    check = max(int(0.01 / dt), 1)
    prev = None
    t_setup = time.perf_counter() - t_start
    converged = False
    while t < a.max_time:
        for _ in range(check):
            t = stepper.step(sim, t, dt)
        steps += check
        cur = ends()
        if not np.all(np.isfinite(cur)):
            break
        if prev is not None and np.abs(cur - prev).max() < a.tol * max(1.0, np.abs(cur).max()):
            converged = True
            break
        prev = cur
    out = dict(tool="PyElastica", version=version("pyelastica"), n=N, dt=dt, steps=steps,
               sim_time=t, converged=converged, setup_seconds=t_setup,
               seconds=time.perf_counter() - t_start, n0=cur[:3].tolist(), m0=cur[3:].tolist(),
               damping=a.damping, tol=a.tol)
    print(json.dumps(out))


if __name__ == "__main__":
    main()
