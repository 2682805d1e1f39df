"""S11: the Taylor–Green vortex, a doubly periodic decaying flow with no free surface.

Taylor & Green (1937); the 2-D form used for SPH by Adami, Hu & Adams (2013) *J. Comput.
Phys.* 241:292 and Sun et al. (2017) *Comput. Phys. Commun.* 211:34. In the x–z plane of a
DualSPHysics 2-D case, on a square of side L periodic in x and z,

    u =  U e^{-βt} sin(kx) cos(kz),   w = −U e^{-βt} cos(kx) sin(kz),   k = 2π/L,  β = 2k²ν   (1)
    p = ρ0 U² e^{-2βt} (cos(2kx) + cos(2kz)) / 4                                               (2)

so the kinetic energy decays as E(t) = E(0) e^{-2βt} = E(0) exp(−16π²νt/L²).             (3)

The case file ``cases/taylorgreen2d/CaseTaylorGreen2D_Def.xml`` draws the fluid at rest;
:func:`impose_initial_field` writes (1) and (2) at t = 0 into its gencase file (the density
from (2) by the Tait equation, ρ = ρ0 (1 + p/B)^(1/γ)), and :func:`case_errors` scores a run:
the decay rate of E fitted over the outputs against 16π²ν/L² (TOLERANCES S11: within 5 % at
Re = 100 with 100² particles, with shifting). :data:`RESOLUTIONS` holds the ``--dp`` of the
runs at N = 25, 50 and 100 particles a side.

Why the case shifts, and strongly: particles carried by the flow are stretched apart along
the outflow of each stagnation point and pushed together along its inflow (strain rate kU).
On such a stretched lattice the SPH divergence Σ_b V_b v_ab·∇W_ab of a pure strain is not
zero: on a lattice stretched by 1.1-1.5 along the outflow it gives dρ/dt = +(0.03-0.06) ρ kU,
the same sign at every stagnation point, so the whole fluid compresses (+3 % mean density by
t = 0.15 s) and the pressure this builds drains the vortex. Fickian shifting (Shifting 1)
cannot undo a uniform stretch (∇C vanishes on any regular lattice); Shifting 4 with its ALE
and non-conservative pressure terms does, once its coefficient is large enough to keep pace
with the strain: the case file uses ShiftAdvCoef −0.2 (DualSPHysics's −0.01 lets the lattice
give way at t ≈ 0.2 s; the file lists the scan).
"""
from __future__ import annotations

import math
import os

import numpy as np

SIDE = 1.0          # L [m] (the case file's Side)
U0 = 1.0            # U [m/s]
NU = 0.01           # ν [m²/s]: Re = U L/ν = 100
FIT_FROM = 0.1      # the decay rate is fitted over the outputs t >= FIT_FROM (after the first acoustic period L/c0)


def decay_rate(nu: float = NU, side: float = SIDE) -> float:
    """Exponential decay rate of the kinetic energy, eq. (3): 16π²ν/L²."""
    return 16 * math.pi ** 2 * nu / side ** 2


def velocity(pos, t: float = 0.0, u0: float = U0, nu: float = NU, side: float = SIDE) -> np.ndarray:
    """The (N, 3) velocity of eq. (1) at the x–z positions ``pos`` (y component 0)."""
    pos = np.asarray(pos, dtype=float)
    k = 2 * math.pi / side
    amp = u0 * math.exp(-2 * k * k * nu * t)
    x, z = pos[:, 0], pos[:, 2]
    vel = np.zeros_like(pos)
    vel[:, 0] = amp * np.sin(k * x) * np.cos(k * z)
    vel[:, 2] = -amp * np.cos(k * x) * np.sin(k * z)
    return vel


def pressure(pos, rhop0: float, t: float = 0.0, u0: float = U0, nu: float = NU, side: float = SIDE) -> np.ndarray:
    """The pressure of eq. (2) at the x–z positions ``pos``."""
    pos = np.asarray(pos, dtype=float)
    k = 2 * math.pi / side
    amp = rhop0 * u0 * u0 * math.exp(-4 * k * k * nu * t) / 4
    return amp * (np.cos(2 * k * pos[:, 0]) + np.cos(2 * k * pos[:, 2]))


def lattice_side(case: dict) -> float:
    """L of a gencase file of the case: the extent of its fluid lattice along x plus dp."""
    p = case["particles"]
    x = p["pos"][p["type"] == 3, 0]
    return float(x.max() - x.min()) + float(case["constants"]["dp"])


def impose_initial_field(outdir: str, u0: float = U0) -> None:
    """Write the t = 0 field of eqs. (1)–(2) into the gencase file of ``outdir`` (atomically):
    the fluid particles' velocity and their density ρ0 (1 + p/B)^(1/γ) (Tait, p of eq. (2)).
    The side L is the extent of the fluid lattice plus dp, ν the case's ``Visco``."""
    import h5py

    from ..io.atomic import atomic_path
    from ..simulation import find_case_file
    from .runs import case_data

    path = find_case_file(str(outdir))
    case = case_data(outdir)
    c, p = case["constants"], case["particles"]
    fluid = p["type"] == 3
    pos = p["pos"]
    side = lattice_side(case)
    nu = float(case["parameters"]["Visco"])
    vel = p["vel"].copy()
    rhop = p["rhop"].copy()
    vel[fluid] = velocity(pos[fluid], 0.0, u0, nu, side)
    rhop0, b, gamma = float(c["rhop0"]), float(c["b"]), float(c["gamma"])
    rhop[fluid] = rhop0 * (1 + pressure(pos[fluid], rhop0, 0.0, u0, nu, side) / b) ** (1 / gamma)
    with atomic_path(path) as tmp:
        with open(path, "rb") as src, open(tmp, "wb") as dst:
            dst.write(src.read())
        with h5py.File(tmp, "r+") as f:
            f["particles/vel"][...] = vel
            f["particles/rhop"][...] = rhop


def _resolution(n: int) -> dict:
    return {"label": f"{n}x{n}", "n": n, "dp": SIDE / n, "scored": n >= 100}


#: the runs of the case file: ``sphdvi gencase CASE -o OUT --dp DP``, impose_initial_field, ``sphdvi run OUT``
RESOLUTIONS = [_resolution(n) for n in (25, 50, 100)]


def kinetic_energy_series(outdir: str) -> tuple[np.ndarray, np.ndarray]:
    """(times, E) of the fluid particles at every output of ``outdir``: E = Σ ½ m |v|²."""
    from ..io.vtkhdf import read_step, step_times
    from .runs import case_data

    case = case_data(outdir)
    mass = float(case["constants"]["massfluid"])
    path = os.path.join(str(outdir), "particles.vtkhdf")
    times = np.asarray(step_times(path), dtype=float)
    energy = np.empty(len(times))
    for k in range(len(times)):
        s = read_step(path, k)
        v = s["Vel"][s["Type"] == 3].astype(np.float64)
        energy[k] = 0.5 * mass * float(np.sum(v * v))
    return times, energy


def case_errors(outdir: str) -> dict:
    """Score a finished run of the Taylor–Green case file in ``outdir``. Returns

    ``rate_error``
        the decay rate of E fitted (least squares on ln E) over the outputs t ≥ FIT_FROM, over
        16π²ν/L² of eq. (3), minus 1 (negative: the SPH flow decays too slowly);
    ``energy_error``
        the largest |E/E_exact − 1| over the outputs (E_exact = E(0) of the run times (3));
    ``velocity_error``
        RMS of v − eq. (1) over the fluid particles at the last output, over the analytic
        amplitude U e^{−βt} at that time;
    ``monotone``
        E does not rise from one output to the next;

    and ``rate``, ``rate_exact``, ``n`` (particles a side), ``dp``, ``time`` (of the last
    output), ``fluid_lost`` and from run.json ``particles``, ``steps``, ``runtime_s``, ``status``."""
    from ..io.vtkhdf import read_step, step_times
    from .runs import case_data, run_info

    case = case_data(outdir)
    c, p = case["constants"], case["particles"]
    run_meta = run_info(outdir)
    par = dict(case["parameters"], **run_meta.get("parameters", {}))
    dp = float(c["dp"])
    side = lattice_side(case)
    nu = float(par["Visco"])
    times, energy = kinetic_energy_series(outdir)
    fit = times >= FIT_FROM - 1e-9
    rate = -float(np.polyfit(times[fit], np.log(energy[fit]), 1)[0]) if np.count_nonzero(fit) >= 2 else float("nan")
    exact = decay_rate(nu, side)
    path = os.path.join(str(outdir), "particles.vtkhdf")
    last = read_step(path, len(step_times(path)) - 1)
    f = last["Type"] == 3
    t = float(times[-1])
    amp = U0 * math.exp(-exact * t / 2)
    dv = last["Vel"][f].astype(np.float64) - velocity(last["points"][f], t, U0, nu, side)
    return {
        "rate": rate, "rate_exact": exact, "rate_error": rate / exact - 1,
        "energy_error": float(np.abs(energy / (energy[0] * np.exp(-exact * times)) - 1).max()),
        "velocity_error": float(np.sqrt(np.mean(np.sum(dv * dv, axis=1)))) / amp,
        "monotone": bool(np.all(np.diff(energy) <= 0)),
        "n": int(round(side / dp)), "dp": dp, "time": t,
        "fluid_lost": int(np.count_nonzero(p["type"] == 3) - np.count_nonzero(f)),
        "particles": run_meta.get("particles"), "steps": run_meta.get("steps"),
        "runtime_s": run_meta.get("runtime_s"), "status": run_meta.get("status"),
    }
