"""C4: a floating box held down by two taut mooring lines in still water
(``cases/mooredbox2d/CaseMooredBox2D_Def.xml``), an analytic test of the lines' coupling.

At rest the lines pull the box down by ΣF_z and it floats deeper than without them by

    δ = −ΣF_z (L − b) / (ρ_w g b L)                                                        (1)

(2D, per metre of width: b the box's width, L the tank's; the water the box displaces raises the
level of the tank by b δ/(L − b), and the buoyancy grows by ρ_w g b times the box's sinking below
that level). The same case without its ``<moorings>`` gives the free box's level. SPH's boundary
particles keep the water about a particle's width off the box, so its buoyancy grows faster with
depth than eq. (1) says (at dp 0.02 by 16 %): δ is scored in dp, as the drafts of S12, and the
fluid's extra lift on the moored box (bodies.csv ffz) against the lines' pull. And each line, at
rest, is the elastic catenary between its anchor and where its fairlead settled: the force on the
fairlead is (−HF cos φ, −HF sin φ, −VF) of :func:`sphdvi.moorings.catenary.elastic_catenary` (the
lumped line's end node carries half a segment's weight, which the catenary's VF at the fairlead
includes).
"""
from __future__ import annotations

import glob
import math
import os

import numpy as np

from .runs import body_log, case_data

SETTLED_FROM = 3.0          # s: the last second of the 4 s run


def force_points(outdir: str) -> list:
    """The FtForcePoints_*.csv files of a run, each as an array of rows (Part, Time, Pos, Force, Vel)."""
    return [np.loadtxt(p, delimiter=";", skiprows=1, ndmin=2)
            for p in sorted(glob.glob(os.path.join(str(outdir), "FtForcePoints_ft*_pt*.csv")))]


def _late_mean(t, values, since):
    late = t >= since - 1e-9
    return np.mean(values[late], axis=0)


def equilibrium_errors(moored: str, free: str, since: float = SETTLED_FROM) -> dict:
    """``sink`` (δ of the runs, m), ``sink_expected`` (eq. (1) with the lines' mean force),
    ``sink_dp`` (their difference in dp: SPH's hydrostatics, as the drafts of S12),
    ``lift_error`` (the fluid's extra lift on the moored box, bodies.csv ffz, against the lines'
    pull, − 1: the box's books at rest), ``catenary_error`` (the largest relative difference of a
    fairlead's mean force from the elastic catenary at its mean position, over HF and VF),
    ``swing`` (the box's heave range over the window, m), ``drift`` (its mean x − the drawn x, m)."""
    case = case_data(moored)
    c = case["constants"]
    rho, g, dp = float(c["rhop0"]), float(np.linalg.norm(c["gravity"])), float(c["dp"])
    spec = case["json"]["special"]["moorings"]
    p = case["particles"]
    mkb = int(spec["floatings"][0])
    fluidcount = int(case["json"]["mkconfig"]["fluidcount"])
    box = (p["mk"].astype(int) - fluidcount - 1 == mkb) & (p["type"] != 3)
    width = float(np.ptp(p["pos"][box, 0])) + dp
    tank = float(np.ptp(p["pos"][p["type"] == 3, 0])) + dp
    rows_m, rows_f = body_log(moored), body_log(free)
    z_m = _late_mean(np.asarray(rows_m["time"], float), np.asarray(rows_m["z"], float), since)
    z_f = _late_mean(np.asarray(rows_f["time"], float), np.asarray(rows_f["z"], float), since)
    sink = float(z_f - z_m)
    lift = float(_late_mean(np.asarray(rows_m["time"], float), np.asarray(rows_m["ffz"], float), since)
                 - _late_mean(np.asarray(rows_f["time"], float), np.asarray(rows_f["ffz"], float), since))
    points = force_points(moored)
    fz = sum(float(_late_mean(a[:, 1], a[:, 7], since)) for a in points)
    expected = -fz * (tank - width) / (rho * g * width * tank)
    from ..moorings.catenary import elastic_catenary
    worst = 0.0
    for a, line in zip(points, spec["lines"]):
        anchor = np.asarray(line["ends"][0]["pos"], float)
        pos = _late_mean(a[:, 1], a[:, 2:5], since)
        force = _late_mean(a[:, 1], a[:, 5:8], since)
        dia = float(line["diameter"])
        w = (float(line["mass"]) - float(spec["solver"]["rho"]) * math.pi * dia * dia / 4) * g
        d = pos - anchor
        cat = elastic_catenary(math.hypot(d[0], d[1]), d[2], float(line["length"]), float(line["ea"]), w)
        horizontal = -math.copysign(1.0, d[0]) * force[0]
        worst = max(worst, abs(horizontal / cat["HF"] - 1), abs(-force[2] / cat["VF"] - 1))
    late = np.asarray(rows_m["time"], float) >= since - 1e-9
    return {"sink": sink, "sink_expected": expected, "sink_error": sink / expected - 1,
            "sink_dp": (sink - expected) / dp, "lift_error": lift / -fz - 1, "catenary_error": worst,
            "fz": fz, "swing": float(np.ptp(np.asarray(rows_m["z"], float)[late])),
            "drift": float(np.mean(np.asarray(rows_m["x"], float)[late]) - float(rows_m["x"][0])), "dp": dp}
