"""An imposed acceleration against statics (``cases/acceltank2d``): water in a 2D tank that
feels a_x (``<accinputs>``, ramped, then held) settles with its free surface normal to the
effective gravity (a_x, 0, −g): slope a_x/g.  Scored from a run folder's particles.vtkhdf."""
from __future__ import annotations

import os

import numpy as np

from .sloshing import linear_period

LENGTH, DEPTH = 1.0, 0.3   # m: the tank and its water
SLOPE = 0.1                # a_x/g of the case
HELD_FROM = 4.5            # s: the ramp ends at 3.954 s (three sloshing periods)
WALL_MARGIN = 0.1          # m: columns this close to a wall are left out (the run-up at the walls)


def surface_slope(points: np.ndarray, ptype: np.ndarray, dp: float, length: float = LENGTH) -> float:
    """Least-squares slope of the tops of the fluid columns (width dp) between the margins."""
    fluid = ptype == 3
    x, z = points[fluid, 0], points[fluid, 2]
    col = np.round(x / dp).astype(int)
    keep = np.unique(col[(col * dp > WALL_MARGIN) & (col * dp < length - WALL_MARGIN)])
    tops = [z[col == c].max() for c in keep]
    return float(np.polyfit(keep * dp, tops, 1)[0])


def slope_history(outdir: str) -> tuple[np.ndarray, np.ndarray]:
    """(output times, free-surface slope at each)."""
    from ..io.vtkhdf import read_step, step_times
    from .runs import case_data
    path = os.path.join(str(outdir), "particles.vtkhdf")
    dp = float(case_data(outdir)["constants"]["dp"])
    times = step_times(path)
    slopes = np.empty(times.size)
    for k in range(times.size):
        s = read_step(path, k)
        slopes[k] = surface_slope(s["points"], s["Type"], dp)
    return times, slopes


def slope_errors(outdir: str) -> dict:
    """The steady slope once the acceleration is held, relative to a_x/g: the constant of a
    least-squares fit m + A cos ωt + B sin ωt (ω of the first sloshing mode), so that what is
    left of the sloshing does not bias it; the swing of the slope about it (relative to a_x/g);
    the slope before the acceleration grows (first output after t = 0)."""
    t, s = slope_history(outdir)
    sel = t >= HELD_FROM - 1e-9
    w = 2 * np.pi / linear_period(LENGTH, DEPTH)          # the tank's first sloshing mode
    basis = np.column_stack([np.ones(sel.sum()), np.cos(w * t[sel]), np.sin(w * t[sel])])
    m = float(np.linalg.lstsq(basis, s[sel], rcond=None)[0][0])
    return {"slope_mean": m / SLOPE - 1.0, "slope_swing": float((s[sel].max() - s[sel].min()) / SLOPE),
            "level_start": float(abs(s[1]) / SLOPE) if s.size > 1 else float("nan")}
