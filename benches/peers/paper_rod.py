"""The paper's Kirchhoff rod, shared by the peer scripts: K2 = K3 = 3, the
Figure 3 clamps (z* = 0.115, delta = 0.05, Appendix D at phi/2pi = 0.802),
the Appendix D shooting data and the right-hand side of (A.2) (state r, d1,
d2, d3 in lab components, n, m in material components; knotrod's
`rhs_loaded` without loads)."""
import numpy as np

K2 = K3 = 3.0
ZSTAR, DELTA, PHI0_OVER_2PI = 0.115, 0.05, 0.802
N0 = np.array([-24.743, 17.772, 37.145])
M0 = np.array([7.5317, -8.7100, 4.529])


def rhs(s, y):
    d1, d2, d3, n, m = y[3:6], y[6:9], y[9:12], y[12:15], y[15:18]
    u = np.array([m[0], m[1] / K2, m[2] / K3])
    return np.concatenate([d3, u[2] * d2 - u[1] * d3, u[0] * d3 - u[2] * d1,
                           u[1] * d1 - u[0] * d2, np.cross(n, u),
                           np.cross(m, u) + [n[1], -n[0], 0.0]])
