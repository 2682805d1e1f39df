"""Per-step look-ups in time tables (motion files, DtFixedFile, ViscoTime, link and floating-body
tables): linear interpolation between rows, the end values outside, to the bit as ``np.interp``.

``np.interp(t, a[:, 0], a[:, 1])`` on the columns of an (n, k) table copies both strided columns
on every call (O(n) per look-up).  :class:`TimeTable` keeps the columns contiguous, read once, and
a cursor on the row last found: the run's time only moves forward, so the next look-up finds its
row next to it (O(1)); a time anywhere else (a resumed run, a predictor's earlier time) is found
by bisection (O(log n)).  DualSPHysics's JLinearValue::FindTime, JSphDtFixed::GetDt,
JDsViscoInput::GetVisco and JMotionMovActive's DfGetNewPos keep their last position the same way.
"""
from __future__ import annotations

import numpy as np

from .sph import _env  # noqa: F401  (OMP_WAIT_POLICY before numba)
from numba import njit


@njit(cache=True)
def find_row(xp, x, guess):
    """The row j of the non-decreasing times ``xp`` with xp[j] <= x < xp[j+1] (the last of repeated
    times), -1 before the first time, n - 1 at or after the last one (and for a NaN ``x``): numpy's
    binary_search_with_guess (np.interp's), looked for first at ``guess`` and the row after it."""
    n = xp.shape[0]
    if not (x >= xp[0]):
        return -1 if x < xp[0] else n - 1
    if x >= xp[n - 1]:
        return n - 1
    # xp[0] <= x < xp[n-1]: the answer lies in [0, n-2]
    g = min(max(guess, 0), n - 2)
    if xp[g] <= x:
        if x < xp[g + 1]:
            return g
        if g + 2 < n and x < xp[g + 2]:
            return g + 1
        lo, hi = g + 1, n - 1          # xp[lo] <= x < xp[hi]
    else:
        lo, hi = 0, g                  # xp[lo] <= x < xp[hi]
    while hi - lo > 1:
        mid = lo + ((hi - lo) >> 1)
        if x >= xp[mid]:
            lo = mid
        else:
            hi = mid
    return lo


@njit(cache=True)
def interp_at(xp, fp, x, j):
    """np.interp(x, xp, fp) for the row j that :func:`find_row` gave, in numpy's arithmetic
    (arr_interp): the end values outside, fp[j] at a table time, else slope (x - xp[j]) + fp[j]
    (from the other end of the segment where that is NaN)."""
    n = xp.shape[0]
    if x != x:
        return x if n > 1 else fp[0]
    if j < 0:
        return fp[0]
    if j >= n - 1:
        return fp[n - 1]
    if xp[j] == x:
        return fp[j]
    slope = (fp[j + 1] - fp[j]) / (xp[j + 1] - xp[j])
    r = slope * (x - xp[j]) + fp[j]
    if r != r:
        r = slope * (x - xp[j + 1]) + fp[j + 1]
        if r != r and fp[j] == fp[j + 1]:
            r = fp[j]
    return r


@njit(cache=True)
def _lookup(xp, cols, x, guess, out):
    """Each column of ``cols`` (k, n) at time x into out[:k] (:func:`interp_at`); the row found."""
    j = find_row(xp, x, guess)
    for c in range(cols.shape[0]):
        out[c] = interp_at(xp, cols[c], x, j)
    return j


class TimeTable:
    """A time table's times (n,) and value columns (k, n), kept contiguous, with a cursor on the
    row the last look-up found.  ``at(t)`` is each column at t, to the bit np.interp's."""

    __slots__ = ("times", "columns", "last", "_j", "_out")

    def __init__(self, times, values):
        self.times = np.ascontiguousarray(np.asarray(times, dtype=np.float64).reshape(-1))
        if self.times.size == 0:
            raise ValueError("a time table needs at least one row")
        v = np.asarray(values, dtype=np.float64).reshape(self.times.size, -1)
        self.columns = np.ascontiguousarray(v.T)
        self._j = 0
        self.last = 0           # the row the last look-up found (:meth:`row`)
        self._out = np.empty(self.columns.shape[0])

    @classmethod
    def of_rows(cls, a) -> "TimeTable":
        """The table of rows (time, value, ...) of an (n, 1 + k) array."""
        a = np.asarray(a, dtype=np.float64)
        return cls(a[:, 0], a[:, 1:])

    def row(self, t: float) -> int:
        """The row j with times[j] <= t < times[j + 1] (-1 before the table, n - 1 at its end or after)."""
        j = self.last = find_row(self.times, float(t), self._j)
        self._j = max(j, 0)
        return j

    def at(self, t: float) -> np.ndarray:
        """Every column at time t (the row found in ``last``): a work array that the next call
        overwrites."""
        j = self.last = _lookup(self.times, self.columns, float(t), self._j, self._out)
        self._j = max(j, 0)
        return self._out

    def value(self, t: float, col: int = 0) -> float:
        """Column ``col`` at time t (np.interp(t, times, column))."""
        return float(self.at(t)[col])
