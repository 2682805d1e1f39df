"""``<savemotion>``, ``<saveserie>``, ``<saveseriewaves>``: what a wave paddle's case asks to be written.

Each ``<savemotion>`` line of a wave paddle (``<piston>``, ``<flap>``, ``<piston_spectrum>``,
``<flap_spectrum>``, ``<piston_focused>``) writes ``PaddleMotion_mkbound<mk>_<n>.csv`` into OUT at the
run's start (n: the line's place among the paddle's ``<savemotion>`` lines, from 1): one row per
time from 0, ``;``-separated, of the paddle's displacement at the still-water level and its rate
(the ramps included, without an absorber's correction), a flap's angle, the theory's elevation at
``xpos`` and, with ``zpos``, its velocity there (:meth:`sphdvi.motion._Paddle.orbital_velocity`), both
to the paddle's ``waveorder`` (a second-order piston's with its bound waves).
DualSPHysics's format documents what such a file holds, not its name or columns: these are sphdvi's.

Times: a regular paddle's ``periods`` wave periods (TimeMax's worth by default) at ``periodsteps`` rows a
period (one per TimeOut by default); an irregular or focused one's ``time`` (TimeMax) at ``timedt``
(TimeOut).  ``xpos`` is a coordinate along the paddle's heading, counted from its front face at rest.

An irregular paddle's ``<saveserie timemin timemax timedt xpos>`` writes the same columns over that window
to ``PaddleSerie_mkbound<mk>.csv``; its ``<saveseriewaves timemin timemax xpos>`` the waves of the theory's
elevation there by zero up-crossing (start, period, height) to ``PaddleSerieWaves_mkbound<mk>.csv``.

A wave relaxation zone's lines (``<rzwaves_regular>``, ``<rzwaves_spectrum>``) write the same files
without the stroke's columns, named ``RelaxZone...`` (:func:`write_relaxzone_motions`)."""
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
    return time_grid(0.0, end, step)


def time_grid(start: float, end: float, step: float) -> np.ndarray:
    """start, start + step, ... up to ``end`` (within 1e-9 of a step)."""
    return start + np.arange(int(math.floor((end - start) / step + 1e-9)) + 1) * step


def motion_table(paddle, entry: dict, tmax: float, tout: float) -> tuple[list, np.ndarray]:
    """(column names, rows) of one ``<savemotion>`` line."""
    return theory_table(paddle, motion_times(paddle, entry, tmax, tout), entry)


def theory_elevation(paddle, distance: float, t: np.ndarray) -> np.ndarray:
    """The theory's elevation ``distance`` in front of the paddle at the times ``t``, to the order the
    paddle generates (``waveorder``: a second-order paddle's with its bound waves)."""
    return np.asarray(paddle.elevation(distance, t, order=paddle.spec.get("waveorder", 1)), float).reshape(-1)


def theory_table(paddle, t: np.ndarray, entry: dict) -> tuple[list, np.ndarray]:
    """(column names, rows) of the paddle's theory at the times ``t``: displacement, rate, a flap's
    angle, the elevation at ``entry["xpos"]`` and with ``entry["zpos"]`` the velocity there."""
    names, cols = ["time [s]"], [t]
    if getattr(paddle, "has_stroke", True):     # a relaxation zone has none
        x, v = np.array([paddle.theory_position(ti) for ti in t]).T.reshape(2, -1)
        names += ["stroke [m]", "stroke_vel [m/s]"]
        cols += [x, v]
        if paddle.kind == "flap":
            names.append("angle [deg]")
            cols.append(np.degrees(np.arctan2(x, paddle.hinge_depth)))
    distance = entry.get("xpos", 0.0) - paddle.face
    names.append("eta [m]")
    cols.append(theory_elevation(paddle, distance, t))
    if "zpos" in entry:
        u, w = paddle.orbital_velocity(distance, entry["zpos"], t)
        names += ["u [m/s]", "w [m/s]"]
        cols += [np.asarray(u, float).reshape(-1), np.asarray(w, float).reshape(-1)]
    return names, np.column_stack(cols)


def zero_upcrossing_waves(t: np.ndarray, eta: np.ndarray) -> np.ndarray:
    """The waves of a record by zero up-crossing (Goda 2000 §2.2): rows of (start time, period, height),
    each from one up-crossing of the mean level to the next (times interpolated linearly), its height
    the largest less the smallest elevation between them."""
    eta = np.asarray(eta, float) - float(np.mean(eta))
    i = np.flatnonzero((eta[:-1] < 0.0) & (eta[1:] >= 0.0))
    tc = t[i] - eta[i] * (t[i + 1] - t[i]) / (eta[i + 1] - eta[i])
    rows = [(tc[k], tc[k + 1] - tc[k], float(np.ptp(eta[i[k] + 1:i[k + 1] + 1])))
            for k in range(len(i) - 1)]
    return np.array(rows, float).reshape(-1, 3)


def serie_waves_table(paddle, entry: dict) -> tuple[list, np.ndarray]:
    """(column names, rows) of ``<saveseriewaves>``: the waves of the theory's elevation at ``xpos``
    over [timemin, timemax], sampled at Tp/200."""
    t = time_grid(entry["timemin"], entry["timemax"], float(paddle.spec["waveperiod"]) / 200.0)
    waves = zero_upcrossing_waves(t, theory_elevation(paddle, entry.get("xpos", 0.0) - paddle.face, t))
    return ["wave", "t_start [s]", "period [s]", "height [m]"], np.column_stack([np.arange(1, len(waves) + 1), waves])


def _write(outdir: str, name: str, names: list, rows: np.ndarray) -> None:
    lines = [";".join(names)] + [";".join(f"{v:.9g}" for v in row) for row in rows]
    write_text_atomic(os.path.join(outdir, name), "\n".join(lines) + "\n")


def _write_theory_files(outdir: str, maker, names: tuple, tmax: float, tout: float) -> list[str]:
    """The ``<savemotion>`` files, ``<saveserie>`` and ``<saveseriewaves>`` of one wave maker (a paddle or
    a relaxation zone); ``names``: (the n-th savemotion file's name as a function of n, the serie's file,
    the serie waves' file)."""
    motion_name, serie_name, waves_name = names
    written, spec = [], maker.spec
    for n, entry in enumerate(spec.get("savemotion") or [], start=1):
        written.append(motion_name(n))
        _write(outdir, written[-1], *motion_table(maker, entry, float(tmax), float(tout)))
    if spec.get("saveserie"):
        e = spec["saveserie"]
        t = time_grid(e["timemin"], e["timemax"], e["timedt"])
        written.append(serie_name)
        _write(outdir, written[-1], *theory_table(maker, t, e))
    if spec.get("saveseriewaves"):
        written.append(waves_name)
        _write(outdir, written[-1], *serie_waves_table(maker, spec["saveseriewaves"]))
    return written


def write_paddle_motions(outdir: str, motions, tmax: float, tout: float) -> list[str]:
    """Write the files of every paddle's ``<savemotion>`` lines, ``<saveserie>`` and ``<saveseriewaves>``
    (``motions``: a :class:`sphdvi.motion.MotionSet`, its paddles placed); the names written."""
    written = []
    for mkb, paddle in sorted(motions.paddles.items()):
        written += _write_theory_files(outdir, paddle, (lambda n, mkb=mkb: file_name(mkb, n),
                                                        f"PaddleSerie_mkbound{mkb}.csv",
                                                        f"PaddleSerieWaves_mkbound{mkb}.csv"), tmax, tout)
    return written


def write_relaxzone_motions(outdir: str, zones, tmax: float, tout: float) -> list[str]:
    """The same files of the wave relaxation zones (:class:`sphdvi.sph.relaxzones.WaveZone`, numbered from 1
    in the case's order): ``RelaxZoneMotion_<zone>_<n>.csv`` (time, the theory's elevation at ``xpos``
    and with ``zpos`` its velocity there, ``xpos`` a coordinate whose distance from the zone's centre
    counts), ``RelaxZoneSerie_<zone>.csv`` and ``RelaxZoneSerieWaves_<zone>.csv``."""
    written = []
    for zone in zones:
        if hasattr(zone, "theory"):
            z = zone.number
            written += _write_theory_files(outdir, zone, (lambda n, z=z: f"RelaxZoneMotion_{z}_{n}.csv",
                                                          f"RelaxZoneSerie_{z}.csv", f"RelaxZoneSerieWaves_{z}.csv"),
                                           tmax, tout)
    return written
