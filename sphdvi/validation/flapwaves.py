"""W3: waves from a measured flap motion against measured wave gauges, ``cases/flapwaves2d``.

The flume of Hadzic et al. (2005) ("Computation of flow-induced motion of floating bodies", Appl.
Math. Modelling 29:1196) as DualSPHysics's CaseFloatingWavesVal sets it up, without the floating box:
a flap hinged at the bottom turns by the recorded angle history and sends a group of waves down
0.4 m of water.  The run-time gauges WP1 (x = 1.16 m) and WP2 (x = 2.66 m) stand at the
experiment's wave probes.  Per probe, over the experiment's record up to the end of the run: the
correlation of the SPH elevation with the measured one, the rms of each and the lag that
correlates best, all on a uniform time grid (the experiment's samples are digitised along the
curve: bunched on its steep flanks, sparse at its crests, some at one time, so a mean over them
weights the flanks, and a phase lag alone changed such an rms by up to 14 %).  The elevation is
taken from the still level each gauge reads before the waves arrive (t <= 0.5 s: the flap has
turned less than 0.06 degrees), which removes the gauge's offset of its own surface criterion.  Turned the other way, the flap would send the waves out inverted:
the correlation is also a check of the sense of ``<mvrotfile>``.
"""
from __future__ import annotations

import os

import numpy as np

from .runs import gauge_table

DATA = "floating_box_waves_hadzic_2005"
EXP_FILE = "EXP_FloatingWavesVal_Hadzic_et_al_2005.txt"
PROBES = {"WP1": 0, "WP2": 1}       # gauge name -> probe column pair in the experiment's file
STILL_UNTIL = 0.5                   # s: the gauges' still level is their mean before this time
MAX_LAG = 0.3                       # s: the lags searched for the best correlation
GRID_DT = 0.001                     # s: the uniform time grid the records are compared on


def load_probe(reference_dir: str, probe: int) -> tuple[np.ndarray, np.ndarray]:
    """(time [s], value) of record ``probe`` of the experiment: 0 / 1 the wave probes at x = 1.16 /
    2.66 m (elevation [m]), 2 / 3 / 4 the box's heave [m], roll [degrees] and sway [m] (the file pairs
    a time column with each record; the records differ in length; the roll's times are rounded to
    10 ms, so some repeat or step back: use them as sample times, not as an ordered axis)."""
    t, z = [], []
    path = os.path.join(reference_dir, DATA, EXP_FILE)
    with open(path, encoding="latin-1") as f:          # its header holds a cp1252 dash
        lines = f.read().splitlines()[2:]
    for line in lines:
        cols = line.split("\t")
        a, b = cols[2 * probe:2 * probe + 2] if len(cols) >= 2 * probe + 2 else ("", "")
        if a.strip() and b.strip():
            t.append(float(a))
            z.append(float(b))
    return np.asarray(t), np.asarray(z)


def gauge_elevation(outdir: str, name: str, still_until: float = STILL_UNTIL) -> tuple[np.ndarray, np.ndarray]:
    """(time, elevation above the still level: the mean before ``still_until``) of the run-time gauge ``name``."""
    g = gauge_table(outdir, "SWL", name)
    t, z = g[:, 0], g[:, 3]
    return t, z - z[t <= still_until].mean()


def time_ordered(t: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(t, v) sorted by time (stable), the values of a repeated time replaced by their mean: a
    record that can be interpolated (the roll's times are rounded to 10 ms, up to four samples of
    a steep flank share one and some step back)."""
    order = np.argsort(t, kind="stable")
    t, v = np.asarray(t, float)[order], np.asarray(v, float)[order]
    times, which = np.unique(t, return_inverse=True)
    return times, np.bincount(which, weights=v) / np.bincount(which)


def probe_scores(t_sph, z_sph, t_exp, z_exp) -> dict:
    """Correlation, rms ratio − 1, range (largest less smallest) ratio − 1, best lag [s] (SPH
    behind the experiment is positive) and the correlation at that lag, over the experiment's
    span within the SPH record.  Correlations and rms are taken on a uniform grid (GRID_DT) of
    that span, both records interpolated to it (the experiment's by :func:`time_ordered`), so
    that each instant weighs the same; the range over the experiment's samples themselves."""
    sel = (t_exp >= t_sph[0]) & (t_exp <= t_sph[-1] - MAX_LAG)
    te, ze = t_exp[sel], z_exp[sel]
    tu, zu = time_ordered(te, ze)
    grid = np.arange(tu[0], tu[-1] + 0.5 * GRID_DT, GRID_DT)
    ge, gs = np.interp(grid, tu, zu), np.interp(grid, t_sph, z_sph)
    lags = np.arange(-MAX_LAG, MAX_LAG + 1e-9, 0.005)
    corr = np.array([np.corrcoef(np.interp(grid + lag, t_sph, z_sph), ge)[0, 1] for lag in lags])
    k = int(np.argmax(corr))
    rms_e, rms_s = float(np.sqrt(np.mean(ge ** 2))), float(np.sqrt(np.mean(gs ** 2)))
    zs = np.interp(te, t_sph, z_sph)
    return {"corr": float(np.corrcoef(gs, ge)[0, 1]), "rms": rms_s / rms_e - 1.0,
            "range": float(np.ptp(zs) / np.ptp(ze)) - 1.0, "lag": float(lags[k]),
            "corr_lag": float(corr[k]), "rms_exp": rms_e, "rms_sph": rms_s,
            "t0": float(tu[0]), "t1": float(tu[-1])}


def wave_scores(outdir: str, reference_dir: str) -> dict:
    """Per probe (``WP1_corr``, ``WP1_rms``, ``WP1_lag`` ...), and ``corr_min`` / ``rms_max`` over both."""
    out: dict = {}
    for name, probe in PROBES.items():
        s = probe_scores(*gauge_elevation(outdir, name), *load_probe(reference_dir, probe))
        out.update({f"{name}_{k}": v for k, v in s.items()})
    out["corr_min"] = min(out[f"{n}_corr"] for n in PROBES)
    out["rms_max"] = max(abs(out[f"{n}_rms"]) for n in PROBES)
    return out
