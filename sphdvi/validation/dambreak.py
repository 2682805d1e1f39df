"""S3: the 2D dam-break surge front against Martin & Moyce (1952), Table 2.

Column a wide and 2a high released on a dry bed; T = t √(2g/a), Z = x_front / a,
x measured from the left wall. The numerical front is the largest x of the fluid
particles at each output time, interpolated to the experimental T values.
"""
from __future__ import annotations

import math
import os

import numpy as np


FRONT_DATA = "dambreak2d_front_martin_moyce_1952"
#: the experiments' front records in the data folder, (file, header lines), all as (T, Z) with
#: T = t √(2g/a), Z = x/a: M&M Table 2 (a = 2.25 in), M&M Fig. 3 digitised for both column
#: sizes, and Koshizuka & Oka (1996), who repeated it with a = 0.146 m
FRONT_RECORDS = {
    "M&M Table 2": ("mm1952_table2_front.csv", 3),
    "M&M Fig. 3, a = 1.125 in": ("pysph_mm1952_fig3_a1.125in.csv", 2),
    "M&M Fig. 3, a = 2.25 in": ("pysph_mm1952_fig3_a2.25in.csv", 2),
    "Koshizuka & Oka 1996": ("pysph_koshizuka_oka_1996_exp.csv", 2),
}


def load_front_record(reference_dir: str, name: str = "M&M Table 2") -> np.ndarray:
    """(T, Z) pairs of one of :data:`FRONT_RECORDS`."""
    file, header = FRONT_RECORDS[name]
    return np.loadtxt(os.path.join(reference_dir, FRONT_DATA, file), delimiter=",", comments="#",
                      skiprows=header)


def load_martin_moyce(reference_dir: str) -> np.ndarray:
    """(T, Z) pairs of M&M Table 2."""
    return load_front_record(reference_dir, "M&M Table 2")


def front_history(outdir: str, x0: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """(times, front x − x0) from a run's particles.vtkhdf."""
    from ..io.vtkhdf import read_step, step_times
    path = os.path.join(outdir, "particles.vtkhdf")
    times = step_times(path)
    front = np.empty(times.size)
    for k in range(times.size):
        s = read_step(path, k)
        front[k] = s["points"][s["Type"] == 3, 0].max() - x0
    return times, front


def front_errors(times, front, ref, a: float = 1.0, g: float = 9.81, trange=(1.0, 3.0)):
    """Relative errors (Z_sph − Z_exp)/Z_exp at the experimental T in ``trange``, and the
    relative error of the front speed dZ/dT fitted over T ∈ [1.9, 3.0]."""
    T = np.asarray(times) * math.sqrt(2 * g / a)
    Z = np.asarray(front) / a
    sel = (ref[:, 0] >= trange[0]) & (ref[:, 0] <= trange[1])
    z_sph = np.interp(ref[sel, 0], T, Z)
    rel = (z_sph - ref[sel, 1]) / ref[sel, 1]
    late_ref = (ref[:, 0] >= 1.9) & (ref[:, 0] <= 3.0)
    late = (T >= 1.9) & (T <= 3.0)
    speed_exp = np.polyfit(ref[late_ref, 0], ref[late_ref, 1], 1)[0]
    speed_sph = np.polyfit(T[late], Z[late], 1)[0]
    return ref[sel, 0], rel, (speed_sph - speed_exp) / speed_exp


def front_start_delay(times, front, ref, a: float = 1.0, g: float = 9.81, trange=(1.0, 3.0),
                      max_delay: float = 0.6, resolution: float = 0.005):
    """The start delay ΔT of the experiment that best explains the SPH front's lead: the ΔT
    (grid of ``resolution`` up to ``max_delay``) that minimises max |Z_sph(T − ΔT) − Z_exp(T)| / Z_exp(T)
    over T ∈ ``trange``, and that smallest maximum relative error.  A front that runs the
    experiment's course, only earlier (its gate opened after t = 0, the column's tip held
    back at first), has a small error after the shift."""
    T = np.asarray(times) * math.sqrt(2 * g / a)
    Z = np.asarray(front) / a
    sel = (ref[:, 0] >= trange[0]) & (ref[:, 0] <= trange[1])
    best = (math.inf, 0.0)
    for delay in np.arange(0.0, max_delay + 0.5 * resolution, resolution):
        err = float(np.max(np.abs(np.interp(ref[sel, 0] - delay, T, Z) - ref[sel, 1]) / ref[sel, 1]))
        if err < best[0]:
            best = (err, float(delay))
    return best[1], best[0]


def load_column_height(reference_dir: str) -> np.ndarray:
    """(τ, H) pairs of M&M Table 6 as transcribed (τ = t √(g/a), H = h / (2a), h the height of
    the water at the left wall); the axis convention is the transcriber's, not checked against
    the original table (TOLERANCES S3), so it is reported, not tested."""
    path = os.path.join(reference_dir, "dambreak2d_front_martin_moyce_1952", "mm1952_table6_height.csv")
    return np.loadtxt(path, delimiter=",", comments="#", skiprows=4)


def column_height_history(outdir: str, dp: float) -> tuple[np.ndarray, np.ndarray]:
    """(times, height of the water at the left wall): the top of the fluid particles within
    1.5 dp of the leftmost one, plus dp/2, at each output."""
    from ..io.vtkhdf import read_step, step_times
    path = os.path.join(outdir, "particles.vtkhdf")
    times = step_times(path)
    height = np.empty(times.size)
    for k in range(times.size):
        s = read_step(path, k)
        p = s["points"][s["Type"] == 3]
        near = p[:, 0] < p[:, 0].min() + 1.5 * dp
        height[k] = p[near, 2].max() + 0.5 * dp
    return times, height


def column_height_errors(times, height, ref, a: float = 1.0, g: float = 9.81):
    """(τ of the table within the run, relative errors (H_sph − H_exp)/H_exp there)."""
    tau = np.asarray(times) * math.sqrt(g / a)
    sel = ref[:, 0] <= tau.max()
    h_sph = np.interp(ref[sel, 0], tau, np.asarray(height) / (2 * a))
    return ref[sel, 0], (h_sph - ref[sel, 1]) / ref[sel, 1]
