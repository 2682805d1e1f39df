"""Error against resolution and run time for a sweep over dp (``sphdvi sweep converge``;
conventions.md §4.2 point 5).

Each run of the sweep wrote a time series (a column of a CSV in its folder: a gauge file,
bodies.csv, a ``measure --csv`` output). Within a group of runs that differ only in dp:

* against a reference signal (an analytic or measured series): the error of run k is the norm of
  f_k − f_ref at the reference's times (f_k linearly interpolated there), over the times both cover;
* without one: the difference of run k to the next finer run k+1, at the finer run's times
  (the successive differences of Roache's grid-convergence practice).

The observed order between levels follows from three successive errors or differences.  With a
reference, p = ln(e_k/e_{k+1}) / ln(dp_k/dp_{k+1}).  Without one, the differences
d_k = ||f_k − f_{k+1}|| of three levels give p by the fixed-point iteration of Celik et al. (2008,
J. Fluids Eng. 130, 078001, eqs. 3–4) for refinement ratios r_k = dp_k/dp_{k+1} that differ:
p = |ln(d_k/d_{k+1}) + q(p)| / ln r_{k+1}, q(p) = ln((r_{k+1}^p − 1)/(r_k^p − 1)) (q = 0 when they are equal):
for f_k = f + C dp_k^p, d_k/d_{k+1} = r_{k+1}^p (r_k^p − 1)/(r_{k+1}^p − 1).

Pure numpy; no files are written here.
"""
from __future__ import annotations

import math

import numpy as np

from .errors import InputError

NORMS = ("rms", "max", "end")


def column_index(header, name: str, what: str, path: str) -> int:
    """The column ``name`` of ``header``: the exact header, else the header without its unit
    (``"swlz [m]"`` answers ``swlz``), case-insensitively; InputError listing the columns."""
    for i, h in enumerate(header):
        if h == name:
            return i
    bare = [h.split(" [", 1)[0].strip().lower() for h in header]
    want = name.split(" [", 1)[0].strip().lower()
    if want in bare:
        return bare.index(want)
    raise InputError(f"{path}: no {what} '{name}'; its columns: {', '.join(header)}")


def time_column(header, name: str | None, path: str) -> int:
    """The time column: ``name`` when given, else the column called ``time`` (any unit, any case)."""
    if name:
        return column_index(header, name, "time column", path)
    try:
        return column_index(header, "time", "time column", path)
    except InputError:
        raise InputError(f"{path}: no column named 'time'; give --time-column (its columns: "
                         f"{', '.join(header)})") from None


def series(header, rows, column: str, path: str, *, time_name: str | None = None, where=()) -> tuple:
    """(t, f): the time and ``column`` of a CSV's rows, those matching every ``where`` (column, value)
    pair kept (e.g. ``body=floating50`` in bodies.csv); sorted by time, repeated times dropped
    (the last row of a time wins, as a resumed run's file may repeat one).  InputError for a
    column that is not there, a value that is not a number, or no row left."""
    it = time_column(header, time_name, path)
    ic = column_index(header, column, "column", path)
    filters = [(column_index(header, k, "column", path), v) for k, v in where]
    t, f = [], []
    for no, r in enumerate(rows, 2):
        if any(j >= len(r) or r[j].strip() != v for j, v in filters):
            continue
        try:
            t.append(float(r[it]))
            f.append(float(r[ic]))
        except (ValueError, IndexError):
            raise InputError(f"{path}:{no}: expected numbers in columns '{header[it]}' and '{header[ic]}'") from None
    if not t:
        raise InputError(f"{path}: no rows" + (" match " + ", ".join(f"{header[j]}={v}" for j, v in filters)
                                                if filters else ""))
    t, f = np.asarray(t), np.asarray(f)
    order = np.argsort(t, kind="stable")
    t, f = t[order], f[order]
    keep = np.append(t[1:] != t[:-1], True)
    return t[keep], f[keep]


def _window(t, tmin, tmax):
    lo = -np.inf if tmin is None else tmin
    hi = np.inf if tmax is None else tmax
    return (t >= lo) & (t <= hi)


def signal_error(t, f, t_ref, f_ref, norm: str, tmin=None, tmax=None, relative=False) -> float:
    """||f − f_ref|| at the times ``t_ref`` inside [tmin, tmax] that ``t`` also covers (f linearly
    interpolated there): ``rms``, ``max`` or ``end`` (|f − f_ref| at the last such time).
    ``relative``: divided by the same norm of f_ref.  NaN when no time is shared."""
    inside = _window(t_ref, tmin, tmax) & (t_ref >= t[0]) & (t_ref <= t[-1])
    if not inside.any():
        return math.nan
    tr, fr = t_ref[inside], f_ref[inside]
    d = np.interp(tr, t, f) - fr
    if norm == "rms":
        e, scale = np.sqrt(np.mean(d * d)), np.sqrt(np.mean(fr * fr))
    elif norm == "max":
        e, scale = np.abs(d).max(), np.abs(fr).max()
    elif norm == "end":
        e, scale = abs(d[-1]), abs(fr[-1])
    else:
        raise ValueError(f"norm {norm!r}: expected one of {', '.join(NORMS)}")
    if relative:
        return float(e / scale) if scale > 0 else math.nan
    return float(e)


def order_from_errors(dp, err) -> list:
    """Observed order between successive levels against a reference: ln(e_k/e_{k+1}) / ln(dp_k/dp_{k+1})
    (NaN where an error is 0, NaN or the dps are equal); one value fewer than levels."""
    out = []
    for k in range(len(dp) - 1):
        e0, e1, r = err[k], err[k + 1], dp[k] / dp[k + 1]
        ok = e0 > 0 and e1 > 0 and r != 1 and math.isfinite(e0) and math.isfinite(e1)
        out.append(math.log(e0 / e1) / math.log(r) if ok else math.nan)
    return out


def order_from_differences(d0: float, d1: float, r0: float, r1: float, iterations: int = 100) -> float:
    """Observed order from the differences d0 = ||f_k − f_{k+1}|| and d1 = ||f_{k+1} − f_{k+2}|| of three
    levels with refinement ratios r0 = dp_k/dp_{k+1} (the coarser pair), r1 = dp_{k+1}/dp_{k+2} (Celik et
    al. 2008, eqs. 3–4, monotone convergence: s = 1): p = |ln(d0/d1) + q(p)| / ln r1,
    q(p) = ln((r1^p − 1)/(r0^p − 1)), by fixed-point iteration from q = 0.  NaN when the differences do not
    fall (d1 ≥ d0 with equal ratios: no convergence to read), one is 0 or NaN, or the iteration does
    not settle."""
    if not (d0 > 0 and d1 > 0 and math.isfinite(d0) and math.isfinite(d1)) or r0 <= 1 or r1 <= 1:
        return math.nan
    lr = math.log(d0 / d1)
    if lr <= 0 and r0 == r1:
        return math.nan
    p = abs(lr) / math.log(r1)
    for _ in range(iterations):
        try:
            q = math.log((r1 ** p - 1.0) / (r0 ** p - 1.0))
        except (ValueError, ZeroDivisionError, OverflowError):
            return math.nan
        new = abs(lr + q) / math.log(r1)
        if abs(new - p) <= 1e-12 * max(1.0, abs(p)):
            return new
        p = new
    return math.nan


def group_levels(keys, runs, dp_key: str = "dp"):
    """The runs grouped by their values of every varied key but ``dp_key``, each group's indices
    sorted from the coarsest dp to the finest: [(other values as a dict, [index, ...]), ...] in the
    order the groups first appear; InputError when dp is not varied or a group repeats a dp."""
    if dp_key not in keys:
        raise InputError(f"the sweep does not vary {dp_key} (its keys: {', '.join(keys)}): a convergence study "
                         f"needs runs at several {dp_key}; make one with 'sphdvi sweep new ... --vary {dp_key}=A,B,C'")
    j = keys.index(dp_key)
    groups: dict[tuple, list[int]] = {}
    for i, values in enumerate(runs):
        other = tuple(v for k, v in zip(keys, values) if k != dp_key)
        groups.setdefault(other, []).append(i)
    out = []
    for other, idx in groups.items():
        dps = [float(runs[i][j]) for i in idx]
        if len(set(dps)) != len(dps):
            raise InputError(f"runs {', '.join(str(i) for i in idx)} repeat a {dp_key} with the same other values: "
                             "each level of a convergence study needs its own dp")
        idx = [i for _, i in sorted(zip(dps, idx), key=lambda x: -x[0])]
        out.append(({k: v for k, v in zip([k for k in keys if k != dp_key], other)}, idx))
    return out


def level_errors(dps, signals, norm: str, reference=None, tmin=None, tmax=None, relative=False):
    """Per level (coarse to fine; ``signals`` (t, f) pairs, None for a level without data): the error
    against ``reference`` (t, f), or without one the difference to the next finer level with data
    (NaN for the finest); and the observed order of each level with the next ones (NaN where it
    cannot be read). Returns (errors, orders), lists as long as ``dps``."""
    n = len(dps)
    err = [math.nan] * n
    have = [k for k in range(n) if signals[k] is not None]
    if reference is not None:
        for k in have:
            err[k] = signal_error(*signals[k], *reference, norm, tmin, tmax, relative)
        sel = [k for k in have if math.isfinite(err[k])]
        orders = [math.nan] * n
        for a, b in zip(sel, sel[1:]):
            orders[a] = order_from_errors([dps[a], dps[b]], [err[a], err[b]])[0]
        return err, orders
    for a, b in zip(have, have[1:]):
        err[a] = signal_error(*signals[a], *signals[b], norm, tmin, tmax, relative)
    orders = [math.nan] * n
    for a, b, c in zip(have, have[1:], have[2:]):
        orders[a] = order_from_differences(err[a], err[b], dps[a] / dps[b], dps[b] / dps[c])
    return err, orders
