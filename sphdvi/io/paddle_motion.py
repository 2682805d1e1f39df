"""``<savemotion>``: each line of a wave paddle (``<piston>``, ``<flap>``, ``<piston_spectrum>``,
``<flap_spectrum>``, ``<piston_focused>``) writes ``PaddleMotion_mkbound<mk>_<n>.csv`` into OUT at the
run's start (n: the line's place among the paddle's ``<savemotion>`` lines, from 1): one row per
time from 0, ``;``-separated, of the paddle's displacement at the still-water level and its rate
(the ramps included, without an absorber's correction), a flap's angle, the theory's elevation at
``xpos`` and, with ``zpos``, its velocity there (:meth:`sphdvi.motion._Paddle.orbital_velocity`).
DualSPHysics's format documents what such a file holds, not its name or columns: these are sphdvi's.

Times: a regular paddle's ``periods`` wave periods (TimeMax's worth by default) at ``periodsteps`` rows a
period (one per TimeOut by default); an irregular or focused one's ``time`` (TimeMax) at ``timedt``
(TimeOut).  ``xpos`` is a coordinate along the paddle's heading, counted from its front face at rest."""
from __future__ import annotations

import math
import os

import numpy as np

from .atomic import write_text_atomic

FILE_PREFIX = "PaddleMotion_"


def file_name(mkbound: int, n: int) -> str:
    return f"{FILE_PREFIX}mkbound{mkbound}_{n}.csv"


def motion_times(paddle, entry: dict, tmax: float, tout: float) -> np.ndarray:
    """The times of one ``<savemotion>`` line's rows."""
    if "time" in entry or "timedt" in entry or paddle.spec["type"].endswith(("_spectrum", "_focused")):
        end, step = entry.get("time", tmax), entry.get("timedt", tout)
    else:
        period = float(paddle.spec["waveperiod"])
        steps = entry.get("periodsteps") or max(1, round(period / tout))
        end, step = entry.get("periods", tmax / period) * period, period / steps
    return np.arange(int(math.floor(end / step + 1e-9)) + 1) * step


def motion_table(paddle, entry: dict, tmax: float, tout: float) -> tuple[list, np.ndarray]:
    """(column names, rows) of one ``<savemotion>`` line."""
    t = motion_times(paddle, entry, tmax, tout)
    x, v = np.array([paddle.theory_position(ti) for ti in t]).T.reshape(2, -1)
    names, cols = ["time [s]", "stroke [m]", "stroke_vel [m/s]"], [t, x, v]
    if paddle.kind == "flap":
        names.append("angle [deg]")
        cols.append(np.degrees(np.arctan2(x, paddle.hinge_depth)))
    distance = entry.get("xpos", 0.0) - paddle.face
    names.append("eta [m]")
    cols.append(np.asarray(paddle.elevation(distance, t), float).reshape(-1))
    if "zpos" in entry:
        u, w = paddle.orbital_velocity(distance, entry["zpos"], t)
        names += ["u [m/s]", "w [m/s]"]
        cols += [np.asarray(u, float).reshape(-1), np.asarray(w, float).reshape(-1)]
    return names, np.column_stack(cols)


def write_paddle_motions(outdir: str, motions, tmax: float, tout: float) -> list[str]:
    """Write the files of every paddle's ``<savemotion>`` lines (``motions``: a
    :class:`sphdvi.motion.MotionSet`, its paddles placed); the names written."""
    written = []
    for mkb, paddle in sorted(motions.paddles.items()):
        for n, entry in enumerate(paddle.spec.get("savemotion") or [], start=1):
            names, rows = motion_table(paddle, entry, float(tmax), float(tout))
            lines = [";".join(names)] + [";".join(f"{v:.9g}" for v in row) for row in rows]
            name = file_name(mkb, n)
            write_text_atomic(os.path.join(outdir, name), "\n".join(lines) + "\n")
            written.append(name)
    return written
