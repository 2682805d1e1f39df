"""S20: Turek & Hron's CSM3 (2006, "Proposal for numerical benchmarking of fluid-structure interaction
between an elastic object and laminar incompressible flow", in Fluid-Structure Interaction, LNCSE 53,
371-385): an elastic beam (plate 0.35 x 0.02 m free, rho 1000 kg/m^3, E 1.4 MPa, nu 0.4) clamped in a
rigid cylinder swings under its weight (g = 2 m/s^2) from rest; scored from a run of
``cases/flexstruc2d/CaseTurekHronCSM3_Def.xml`` (sphdvi's flexible structures).

The benchmark's point A, the middle of the beam's free end (0.6, 0.2), oscillates about a mean with an
amplitude and a frequency (the paper's finest level; mean ± amplitude [frequency]):

    u_x = −14.305 ± 14.305 mm,   u_y = −63.607 ± 65.160 mm   [1.0995 Hz]

(its coarse level: −14.279 ± 14.280, −63.541 ± 65.094 mm). The run's point A is the mean of the beam
particles nearest to (0.6, 0.2) (two, beside it, where the lattice is half a dp off the faces); its
vertical displacement is the benchmark's u_y. Mean and amplitude are half the sum and half the
difference of the extremes over the run; the frequency is 1/T from the times of successive deepest
points (1/(2 t_1) from the first alone: the beam starts at rest at its top).
"""
from __future__ import annotations

import os

import numpy as np

POINT_A = (0.6, 0.2)                    # m: x, z
#: (mean, amplitude) [m] and frequency [Hz] of Turek & Hron's finest level
REFERENCE = {"ux": (-14.305e-3, 14.305e-3), "uz": (-63.607e-3, 65.160e-3), "frequency": 1.0995}


def tip_series(outdir: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """(t, u_x, u_z, count): point A's displacement at every output of the run, from the mean of the
    beam particles nearest to A at t = 0 (``count`` of them)."""
    import h5py
    path = os.path.join(str(outdir), "particles.vtkhdf")
    with h5py.File(path, "r") as f:
        g = f["VTKHDF"]
        nsteps = int(g["Steps"].attrs["NSteps"])
        off = g["Steps/PointOffsets"][:nsteps]
        n = g["NumberOfPoints"][:nsteps]
        t = g["Steps/Values"][:nsteps]
        points, idp, mk = g["Points"], g["PointData/Idp"], g["PointData/Mk"]
        p0 = points[off[0]:off[0] + n[0]]
        i0 = idp[off[0]:off[0] + n[0]]
        m0 = mk[off[0]:off[0] + n[0]]
        d = np.hypot(p0[:, 0] - POINT_A[0], p0[:, 2] - POINT_A[1])
        d[m0 != m0.max()] = np.inf                       # the beam: the case's last mk
        tip = np.sort(i0[d <= d.min() + 1e-9])
        x0 = p0[np.isin(i0, tip)].mean(axis=0)
        u = np.empty((nsteps, 3))
        for k in range(nsteps):
            pk = points[off[k]:off[k] + n[k]]
            ik = idp[off[k]:off[k] + n[k]]
            u[k] = pk[np.isin(ik, tip)].mean(axis=0) - x0
    return t, u[:, 0], u[:, 2], int(tip.size)


def deepest_times(t: np.ndarray, uz: np.ndarray) -> np.ndarray:
    """Times of the local minima of u_z (the beam's deepest points), refined by a parabola through
    the three outputs around each."""
    out = []
    for k in range(1, len(uz) - 1):
        if uz[k] < uz[k - 1] and uz[k] <= uz[k + 1]:
            a, b, c = uz[k - 1], uz[k], uz[k + 1]
            den = a - 2 * b + c
            s = 0.5 * (a - c) / den if den != 0 else 0.0
            out.append(t[k] + s * (t[k + 1] - t[k]))
    return np.asarray(out)


def case_errors(outdir: str) -> dict:
    """Point A's mean and amplitude of u_x and u_z and the frequency, and their relative errors
    against Turek & Hron (keys ``uz_mean``, ``uz_amp``, ``ux_mean``, ``frequency``: errors; the
    measured values under ``*_value``)."""
    t, ux, uz, count = tip_series(outdir)
    mins = deepest_times(t, uz)
    if mins.size >= 2:
        freq = 1.0 / float(np.mean(np.diff(mins)))
    elif mins.size == 1:
        freq = 1.0 / (2.0 * float(mins[0]))
    else:
        freq = float("nan")
    out = {"tip_particles": count, "deepest_times": mins.tolist()}
    for name, u in (("ux", ux), ("uz", uz)):
        mean, amp = 0.5 * (u.max() + u.min()), 0.5 * (u.max() - u.min())
        rmean, ramp = REFERENCE[name]
        out[f"{name}_mean_value"], out[f"{name}_amp_value"] = float(mean), float(amp)
        out[f"{name}_mean"] = float(mean / rmean - 1.0)
        out[f"{name}_amp"] = float(amp / ramp - 1.0)
    out["frequency_value"] = freq
    out["frequency"] = freq / REFERENCE["frequency"] - 1.0
    return out
