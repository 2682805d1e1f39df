"""IO4: laminar open-channel flow down a slope between an inlet and an outlet
(``cases/inout2d/CaseOpenChannel2D_Def.xml``; the set-up of DualSPHysics's
examples/inletoutlet/02_OpenChannel).

A film of depth H on a bed inclined at angle theta, kinematic viscosity nu, no slip at the bed
(z = 0) and no stress at the free surface (z = H), is in steady uniform flow with

    u(z) = (g sin theta / nu) (H z - z^2 / 2),     q = (g sin theta / nu) H^3 / 3        (1)

(the half of a plane Poiseuille profile).  :func:`profile_error` scores a run: the fluid's
x-velocity at 2.5 < x < 3.5 m over the outputs 2 <= t <= 3 s, averaged in rows of dp
(the lattice's rows), against (1); and the flow rate sum(u dz) over the same rows against q.
"""
from __future__ import annotations

import numpy as np

G_SIN = 0.855       # g sin(5 deg) [m/s^2], the case's gravity along x
NU = 0.0534         # [m^2/s]
DEPTH = 1.0         # [m]


def u_exact(z):
    """Eq. (1)."""
    z = np.asarray(z, float)
    return G_SIN / NU * (DEPTH * z - 0.5 * z * z)


def q_exact() -> float:
    return G_SIN / NU * DEPTH ** 3 / 3.0


def profile_error(outdir: str, t0: float = 2.0, t1: float = 3.0, x0: float = 2.5, x1: float = 3.5) -> dict:
    """{"rows": [(z, u mean, u exact)], "max_rel": max |u - u_exact| / u_exact(H), "q_rel": flow rate
    error / q, "dp": the row spacing} of a run in ``outdir``."""
    from ..io.vtkhdf import read_step, step_times
    path = f"{outdir}/particles.vtkhdf"
    times = step_times(path)
    zs, us = [], []
    for k, t in enumerate(times):
        if not (t0 - 1e-9 <= t <= t1 + 1e-9):
            continue
        s = read_step(path, k)
        sel = (s["Type"] == 3) & (s["points"][:, 0] > x0) & (s["points"][:, 0] < x1)
        zs.append(s["points"][sel, 2])
        us.append(s["Vel"][sel, 0])
    if not zs:
        raise ValueError(f"{outdir}: no output between t = {t0} and {t1} s")
    z = np.concatenate(zs)
    u = np.concatenate(us)
    first = read_step(path, 0)
    fl = first["Type"] == 3
    dp = float(np.min(np.diff(np.unique(np.round(first["points"][fl, 2], 9)))))
    rows = np.floor(z / dp).astype(int)
    out = []
    for r in np.unique(rows):
        if r < 0 or (r + 0.5) * dp > DEPTH:
            continue
        m = rows == r
        zc = (r + 0.5) * dp
        out.append((zc, float(u[m].mean()), float(u_exact(zc))))
    rel = max(abs(a - b) for _, a, b in out) / float(u_exact(DEPTH))
    q = sum(a for _, a, _ in out) * dp
    return {"rows": out, "max_rel": rel, "q_rel": q / q_exact() - 1.0, "dp": dp}
