"""S1 hydrostatic tank and S2 still water (TOLERANCES.md §1): scoring a run of the case file.

The case ``cases/hydrostatic2d/CaseHydrostatic2D_Def.xml`` is a 2D tank 0.2 m wide holding
water H = 0.2 m deep at rest, behind three layers of DBC wall particles. Its exact solution is
the hydrostatic state

    u = 0,        p_ref(z) = ρ0 g (z_top − z)                                  (S1, S2)

with z_top the free surface, the highest fluid particle plus dp/2 (its half spacing), and the
total vertical force of the water on the tank equal to its weight

    F_z = −Σ_fluid m g   (per metre of width in 2D).

:func:`case_errors` reads a finished run (OUT/particles.vtkhdf and OUT/<casename>.h5 through
:class:`sphdvi.measure.post.RunOutput`) and returns, over the outputs in [0.7 T, T]
(T = TimeMax, 10 √(H/g) in the case file):

* ``rel_max``  = max_k |p̄(z_k) − p_ref(z_k)| / p_ref(z_k), p̄ the time average of the Shepard
  interpolation p(x) = Σ_b p_b V_b W(x − x_b) / Σ_b V_b W(x − x_b), V_b = m_b/ρ_b (the
  interpolation of ``sphdvi measure points``), at the probes (x_c, z_k) on the centre line;
* ``einf``     = max_k |p̄(z_k) − p_ref(z_k)| / (ρ0 g H);
* ``umax``     = max |u_a| / √(g H) over the fluid at the last output (S2);
* ``dzcm``     = (z_cm(last) − z_cm(0)) / dp, z_cm the mean height of the fluid particles;
* ``lost``     = fluid particles of the case file missing from the last output;
* H = z_top − z_bottom, z_bottom the lowest fluid particle − dp/2 (the wall face), 0.2 m;
* ``wall_force`` and ``bottom_force`` = −F̄_z / (Σ m g): the vertical fluid force on all wall
  particles, and on the bottom rows only (z below the bottom face), time-averaged, from the
  function of ``sphdvi measure forces`` (:func:`sphdvi.measure.post.step_force`):
  F_a = m_a Σ_b m_b [−(p_a + p_b)/(ρ_a ρ_b) + Π_ab] ∇_a W_ab over the fluid b.

``RESOLUTIONS`` lists the resolutions a convergence tool loops over (``--dp`` and ``--set``).
"""
from __future__ import annotations

import math

import numpy as np

from ..measure.core import FLUID
from .runs import run_info

#: probe heights [m] on the centre line: >= 1.5 h from the bottom and from the free surface
#: at H/dp = 20 (h = sqrt(2) dp), as in tests/sph/test_hydrostatic.py
PROBE_Z = tuple(float(z) for z in np.linspace(0.025, 0.175, 7))

#: H/dp 20 / 40 / 80 of the case file (``sphdvi run CASE -o OUT --dp DP --set ...``); one thread:
#: 3.5 s, 20 s, 160 s (599, 1959, 7079 particles). At H/dp 80 the tank has not settled at T
#: (max |u| 1.7e-3 sqrt(gH)); it meets S2 after ~21 sqrt(H/g), see the case file's header.
RESOLUTIONS = [
    {"label": "H/dp 20", "dp": 0.01, "set": []},
    {"label": "H/dp 40", "dp": 0.005, "set": []},
    {"label": "H/dp 80", "dp": 0.0025, "set": []},
]


def case_errors(outdir: str, probe_z=PROBE_Z, window=(0.7, 1.0)) -> dict:
    """S1/S2 figures of a finished run of the hydrostatic case in ``outdir`` (see the module
    docstring for the equations). ``window``: the averaging interval as fractions of
    T = TimeMax; the outputs with t in [window[0] T, window[1] T] are averaged.

    Returns rel_max, einf, err (per-probe (p̄ − p_ref)/(ρ0 g H)), p_mean, p_ref, probe_z, umax,
    urms, dzcm, lost, nfluid, wall_force, bottom_force, nout (outputs averaged), H, top, dp,
    T, and from run.json runtime_s, steps, particles."""
    from ..errors import InputError
    from ..measure.post import RunOutput, measure_points, step_force
    run = RunOutput(outdir)
    c = run.data["constants"]
    dp, rho0 = float(c["dp"]), float(c["rhop0"])
    g = -float(c["gravity"][2])
    p0 = run.data["particles"]
    fl0 = np.asarray(p0["type"]) == FLUID
    pos0 = np.asarray(p0["pos"], np.float64)[fl0]
    nfluid0 = int(fl0.sum())
    top = float(pos0[:, 2].max()) + 0.5 * dp            # free surface: top particle + dp/2
    bottom = float(pos0[:, 2].min()) - 0.5 * dp         # bottom face: lowest particle − dp/2
    H = top - bottom
    xc = 0.5 * float(pos0[:, 0].min() + pos0[:, 0].max())
    weight = float(np.sum(np.asarray(p0["mass"])[fl0])) * g

    T = float(run.params.get("TimeMax"))
    times = run.times()
    tol = 1e-6 * T
    inwin = np.flatnonzero((times >= window[0] * T - tol) & (times <= window[1] * T + tol))
    if inwin.size == 0:
        raise InputError(f"{outdir}: no output in [{window[0]} T, {window[1]} T] (T = {T:g} s); "
                         f"last output at {times[-1]:g} s")
    first, last = int(inwin[0]), int(inwin[-1])

    zs = np.asarray(probe_z, float)
    probes = np.stack([np.full_like(zs, xc), np.zeros_like(zs), zs], axis=1)
    table, _ = measure_points(run, probes, variables=("press",), first=first, last=last, wall_factor=0)
    p_mean = table.data.mean(axis=0)
    p_ref = rho0 * g * (top - zs)
    err = p_mean - p_ref

    fz_all, fz_bottom = [], []
    for snap in run.snapshots(arrays=("Vel", "Rhop", "Press"), first=first, last=last):
        grid = run.fluid_grid(snap)
        walls = snap.ptype != FLUID
        f, _ = step_force(run, snap, np.flatnonzero(walls), grid=grid)
        fz_all.append(f[2])
        f, _ = step_force(run, snap, np.flatnonzero(walls & (snap.pos[:, 2] < bottom)), grid=grid)
        fz_bottom.append(f[2])

    snap = next(run.snapshots(arrays=("Vel",), first=len(times) - 1))
    fl = snap.ptype == FLUID
    u = np.linalg.norm(np.asarray(snap.vel, np.float64)[fl], axis=1)
    zcm = float(np.mean(np.asarray(snap.pos, np.float64)[fl, 2]))
    info = run_info(outdir)
    return {
        "rel_max": float(np.max(np.abs(err) / p_ref)),
        "einf": float(np.max(np.abs(err)) / (rho0 * g * H)),
        "err": (err / (rho0 * g * H)).tolist(),
        "p_mean": p_mean.tolist(), "p_ref": p_ref.tolist(), "probe_z": zs.tolist(),
        "umax": float(u.max() / math.sqrt(g * H)) if u.size else float("nan"),
        "urms": float(np.sqrt(np.mean(u ** 2)) / math.sqrt(g * H)) if u.size else float("nan"),
        "dzcm": (zcm - float(pos0[:, 2].mean())) / dp,
        "lost": nfluid0 - int(fl.sum()), "nfluid": int(fl.sum()),
        "wall_force": -float(np.mean(fz_all)) / weight,
        "bottom_force": -float(np.mean(fz_bottom)) / weight,
        "nout": int(inwin.size), "H": H, "top": top, "dp": dp, "T": T, "t_last": float(times[-1]),
        "runtime_s": info.get("runtime_s"), "steps": info.get("steps"), "particles": info.get("particles"),
    }
