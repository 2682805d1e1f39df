"""S18: a hinged buoyant flap in still water, an analytic test of the two-way coupling with a
joint, scored from a run of ``cases/hingedflap2d/CaseHingedFlap2D_Def.xml``.

The flap (relative density 0.5) turns about a Chrono ``link_hinge`` on the y axis through
(Xh, Zh); the link's torsional spring K is at rest in the drawn pose, tilted by Theta0. With the
net buoyancy F = (ρ_w A − m) g acting at the centroid, a distance r_c from the hinge (a uniform
flap: the centre of buoyancy is the centre of mass), the tilt φ of the centroid from the
vertical through the hinge settles where the moments balance (TOLERANCES S18):

    F r_c sin φ = K (φ0 − φ)                                                           (1)

φ0 the drawn tilt of the centroid. A (= N dp², the area the flap's N particles fill), m and the
centroid come from the gencase file, so (1) is the equilibrium of the flap sphdvi was given,
whatever the lattice made of the drawn box. Small swings about it have the period

    T = 2π √((I_h + I_a) / (F r_c cos φ + K))                                          (2)

with I_h the flap's inertia about the hinge and I_a the water's added inertia, which is not
known in closed form: T(I_a = 0) is a lower bound. With the hinge's damper (the case file) the
flap creeps to (1); ``CaseHingedFlapSwing2D_Def.xml`` leaves the damper off, and
:func:`first_swing_period` times its first half-swing against the bound (at dp 0.04 the water
damps even that flap into a creep; at dp 0.02 it swings).

At rest the hinge also holds the net buoyancy: its vertical force on the flap is −F and its
horizontal force zero, and its torque is the spring's K (φ0 − φ): three more checks of the
fluid's load on the body.
"""
from __future__ import annotations

import math

import numpy as np

from .runs import body_log, case_data, run_info

SETTLED_FROM = 3.0          # t [s] from which the flap has settled (the run's last second)


def case_geometry(outdir: str) -> dict:
    """Hinge, spring, flap mass, area, centroid and inertia about the hinge, from the gencase
    file of ``outdir`` (the one floating body and its link_hinge)."""
    case = case_data(outdir)
    c = case["constants"]
    body = case["bodies"]
    dp, rho_w, g = float(c["dp"]), float(c["rhop0"]), -float(np.asarray(c["gravity"], dtype=float)[2])
    link = next(ln for ln in case["json"]["chrono"]["links"] if ln["type"] == "hinge")
    hinge = np.asarray(link["rotpoint"], dtype=float)
    count, mass = int(body["count"][0]), float(body["mass"][0])
    centre = np.asarray(body["center"][0], dtype=float)
    area = count * dp * dp
    r = centre - hinge
    inertia_y = float(body["inertia"][0][1][1])                 # about the centre of mass
    return {"hinge": hinge, "stiffness": float(link["stiffness"]), "mass": mass, "area": area, "centre": centre, "r_c": float(math.hypot(r[0], r[2])),
            "phi0": float(math.atan2(r[0], r[2])), "force": (rho_w * area - mass) * g,
            "inertia_hinge": inertia_y + mass * float(r[0] ** 2 + r[2] ** 2), "dp": dp}


def equilibrium_tilt(force: float, r_c: float, stiffness: float, phi0: float) -> float:
    """φ of eq. (1), F r_c sin φ = K (φ0 − φ), by Newton's method (signed like φ0)."""
    s = 1.0 if phi0 >= 0 else -1.0
    a0, phi = abs(phi0), abs(phi0) / 2
    for _ in range(50):
        f = force * r_c * math.sin(phi) - stiffness * (a0 - phi)
        step = f / (force * r_c * math.cos(phi) + stiffness)
        phi -= step
        if abs(step) < 1e-14:
            break
    return s * phi


def period_lower_bound(geo: dict, phi: float) -> float:
    """T of eq. (2) without the added inertia: 2π √(I_h / (F r_c cos φ + K))."""
    return 2 * math.pi * math.sqrt(geo["inertia_hinge"] / (geo["force"] * geo["r_c"] * math.cos(phi) + geo["stiffness"]))


def tilt_series(outdir: str, geo: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(t, φ, r) of the centroid about the hinge from bodies.csv (r its distance from the hinge)."""
    rows = body_log(outdir)
    dx, dz = rows["x"] - geo["hinge"][0], rows["z"] - geo["hinge"][2]
    return np.asarray(rows["time"], dtype=float), np.arctan2(dx, dz), np.hypot(dx, dz)


def first_swing_period(outdir: str) -> dict:
    """The swing of a run of ``CaseHingedFlapSwing2D_Def.xml`` (no damper): twice the time from
    the release (at rest) to the first turning point of φ once it has gone a tenth of the way to
    the equilibrium (the start's jitter is not a turn), against eq. (2) without added inertia.
    ``period``, ``period_bound``, ``turn_deg`` (φ at the turning point), ``equilibrium_deg``; nan
    when φ does not turn within the run."""
    geo = case_geometry(outdir)
    t, phi, _ = tilt_series(outdir, geo)
    eq = equilibrium_tilt(geo["force"], geo["r_c"], geo["stiffness"], geo["phi0"])
    moving = np.sign(eq - geo["phi0"])                 # the first swing heads for the equilibrium
    started = np.flatnonzero(np.abs(phi - geo["phi0"]) > 0.1 * abs(eq - geo["phi0"]))
    d = np.diff(phi)
    turns = np.flatnonzero(np.sign(d) == -moving)
    turns = turns[turns >= started[0]] if started.size else turns[:0]
    k = int(turns[0]) if turns.size else None
    return {"period": 2 * float(t[k]) if k is not None else math.nan,
            "period_bound": period_lower_bound(geo, eq),
            "turn_deg": math.degrees(float(phi[k])) if k is not None else math.nan,
            "equilibrium_deg": math.degrees(eq), "phi0_deg": math.degrees(geo["phi0"])}


def hinge_reaction(outdir: str, since: float) -> list:
    """Mean (fx, fz, ty) the hinge puts on the flap over t >= ``since`` (links.csv)."""
    rows = body_log(outdir, "links")
    late = np.asarray(rows["time"], dtype=float) >= since - 1e-9
    return [float(np.mean(rows[k][late])) for k in ("fx", "fz", "ty")]


def case_errors(outdir: str) -> dict:
    """Score a finished run: ``tilt_error`` (the settled tilt, the mean φ over t ≥ SETTLED_FROM,
    minus eq. (1), degrees), ``settled_deg`` and ``equilibrium_deg`` (φ), ``phi0_deg``, ``swing``
    (how far the settled tilt moved over the last second, degrees), ``hinge_drift`` (the largest
    change of the centroid's distance from the hinge, m: the joint holds), ``reaction_error`` (the
    settled hinge's vertical pull on the flap against −F: at rest it holds the net buoyancy,
    minus 1), ``reaction_x`` (its horizontal force over F: zero at rest), ``torque_error`` (its
    torque against the spring's K (φ0 − φ) at the settled tilt, minus 1) and ``period_bound``
    (eq. (2) without added inertia, for reference: with the damper the flap creeps), and from
    run.json ``particles``, ``steps``, ``runtime_s``, ``status``."""
    geo = case_geometry(outdir)
    t, phi, r = tilt_series(outdir, geo)
    late = t >= SETTLED_FROM - 1e-9
    settled = float(np.mean(phi[late]))
    eq = equilibrium_tilt(geo["force"], geo["r_c"], geo["stiffness"], geo["phi0"])
    meta = run_info(outdir)
    fx, fz, ty = hinge_reaction(outdir, SETTLED_FROM)
    spring = geo["stiffness"] * (geo["phi0"] - settled)
    return {"tilt_error": math.degrees(settled - eq), "settled_deg": math.degrees(settled),
            "reaction_error": -fz / geo["force"] - 1, "reaction_x": fx / geo["force"],
            "torque_error": abs(ty) / abs(spring) - 1 if spring else math.nan,
            "equilibrium_deg": math.degrees(eq), "phi0_deg": math.degrees(geo["phi0"]),
            "swing": math.degrees(float(np.ptp(phi[late]))) if late.any() else math.nan,
            "period_bound": period_lower_bound(geo, eq), "hinge_drift": float(np.max(np.abs(r - geo["r_c"]))),
            "dp": geo["dp"], "particles": meta.get("particles"), "steps": meta.get("steps"),
            "runtime_s": meta.get("runtime_s"), "status": meta.get("status")}
