"""S12: a 2D box floating in still water (``cases/floatingbox2d/CaseFloatingBox2D_Def.xml``).

Archimedes: at equilibrium the displaced area equals m/ρ0 per metre of width, so the box's
draft below the free surface is m / (ρ0 w), w the box width (particle columns × dp) and the
free surface the top fluid node + dp/2. Scored after the settling time: the mean height of the
box's lowest particle centres against that equilibrium (in dp), the horizontal drift of the
box's centre (in dp) and the largest tilt (degrees).
"""
from __future__ import annotations

import os

import numpy as np


def draft_errors(outdir: str, settle: float = 1.0, x0: float = 0.5) -> dict:
    """``draft_dp`` (mean lowest-particle height − equilibrium, in dp, over outputs t ≥ settle),
    ``drift_dp`` (largest |x_centre − x0| in dp), ``tilt_deg`` (largest |tilt|)."""
    from ..io.vtkhdf import read_step, step_times
    from .runs import case_data
    data = case_data(outdir)
    dp = data["constants"]["dp"]
    rhop0 = data["constants"]["rhop0"]
    p = data["particles"]
    box = p["type"] == 2
    width = np.ptp(p["pos"][box, 0]) + dp
    surface = p["pos"][p["type"] == 3, 2].max() + dp / 2
    bottom_eq = surface - p["mass"][box].sum() / (rhop0 * width) + dp / 2   # lowest particle centre
    path = os.path.join(outdir, "particles.vtkhdf")
    zs, xs, tilt = [], [], []
    for k, t in enumerate(step_times(path)):
        if t < settle:
            continue
        s = read_step(path, k)
        pts = s["points"][s["Type"] == 2]
        zs.append(pts[:, 2].min())
        xs.append(pts[:, 0].mean())
        tilt.append(np.degrees(np.arctan(np.polyfit(pts[:, 0], pts[:, 2], 1)[0])))
    return {"draft_dp": float((np.mean(zs) - bottom_eq) / dp),
            "drift_dp": float(np.max(np.abs(np.array(xs) - x0)) / dp),
            "tilt_deg": float(np.max(np.abs(tilt))), "dp": dp}


def fluid_inside_box(outdir: str, settle: float = 0.0) -> dict:
    """Water inside a rectangular floating body: at each output from ``settle`` on, the fluid
    particles within the rectangle of the body's particle centres, taken in the body's own axes
    (the principal axes of its particles, so that a rolled box is measured as drawn). 2D (x, z).
    ``max_count`` and ``last_count`` of those particles, ``max_depth_dp``: how far the deepest
    one lies inside the outer particle row (dp)."""
    from ..io.vtkhdf import read_step, step_times
    from .runs import case_data
    dp = case_data(outdir)["constants"]["dp"]
    path = os.path.join(outdir, "particles.vtkhdf")
    counts, depth = [], 0.0
    for k, t in enumerate(step_times(path)):
        if t < settle:
            continue
        s = read_step(path, k)
        xz = s["points"][:, [0, 2]]
        body = xz[s["Type"] == 2]
        centre = body.mean(axis=0)
        axes = np.linalg.eigh(np.cov((body - centre).T))[1]
        local = (body - centre) @ axes
        lo, hi = local.min(axis=0), local.max(axis=0)
        fluid = (xz[s["Type"] == 3] - centre) @ axes
        inside = np.all((fluid > lo) & (fluid < hi), axis=1)
        counts.append(int(inside.sum()))
        if inside.any():
            depth = max(depth, float(np.minimum(fluid[inside] - lo, hi - fluid[inside]).min(axis=1).max()))
    return {"max_count": max(counts), "last_count": counts[-1], "max_depth_dp": depth / dp}


def slider_reactions(outdir: str, settle: float = 1.0, body: str = "box", link: str = "slider",
                     g: float = 9.81) -> dict:
    """TOLERANCES' coupled check (c), ``cases/floatingbox2d/CaseSliderBox2D_Def.xml``: a floating box
    on a vertical point-line link in still water. Over the outputs t ≥ ``settle``: the mean lateral
    reaction ``fx_w`` of the link on the box over the box's weight m g, its largest |fx| (``fx_max_w``),
    the mean torque about y over m g b/2 (``ty_wb``, b the box's width: the moment its weight makes
    at a corner), the largest drift off the line in x (``dx``, m) and the largest pitch (deg)."""
    from .runs import body_log, case_data
    data = case_data(outdir)
    dp = data["constants"]["dp"]
    p = data["particles"]
    box = p["type"] == 2
    weight = p["mass"][box].sum() * g
    width = np.ptp(p["pos"][box, 0]) + dp
    bodies, links = body_log(outdir, "bodies"), body_log(outdir, "links")
    rows = bodies[bodies["body"] == body]
    reac = links[links["link"] == link]
    late = reac["time"] >= settle
    return {"fx_w": float(reac["fx"][late].mean() / weight), "fx_max_w": float(np.abs(reac["fx"][late]).max() / weight),
            "ty_wb": float(reac["ty"][late].mean() / (weight * width / 2)),
            "dx": float(np.abs(rows["x"] - rows["x"][0]).max()), "pitch_deg": float(np.abs(rows["pitch"]).max())}
