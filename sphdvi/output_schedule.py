"""When a run writes its outputs: every TimeOut, or DualSPHysics's ``<special><timeout>``.

``<timeout><tout time="t_i" timeout="dt_i"/>...</timeout>`` (DualSPHysics's JTimeOut) sets the
output interval piecewise: from ``t_i`` on, outputs are ``dt_i`` apart, counted from ``t_i``
(t_i + dt_i, t_i + 2 dt_i, ...), and the next row's time ``t_(i+1)`` is itself an output; before
the first row's time the next output is that time.  A case uses it to write often only around
the events it studies (the impacts of a sloshing tank) and seldom in between.  Without it,
outputs are TimeOut apart: the times (k+1) TimeOut, computed exactly as the loop always has.

After an output the run asks for the first scheduled time after the clock (``first_after``, as
DualSPHysics's ``GetNextTime(TimeStep)``: a step longer than the interval skips the times it
jumped over), with a tolerance, so that a step that ends a round-off short of an output time
cannot schedule that output twice.
"""
from __future__ import annotations

import math


class OutputSchedule:
    """Output times from rows (time, interval): ``after(s)`` is the output after the scheduled
    time ``s``; ``nth(k)`` the time of output k (output 0 at t = 0)."""

    def __init__(self, rows):
        rows = [(float(t), float(dt)) for t, dt in rows]
        if not rows:
            raise ValueError("an output schedule needs at least one row")
        for i, (t, dt) in enumerate(rows):
            if t < 0 or not dt > 0 or (i and t <= rows[i - 1][0]):
                raise ValueError(f"output schedule row {i}: time {t:g}, interval {dt:g}: expected times >= 0 "
                                 "that rise and intervals > 0")
        self.rows = rows
        self.uniform = len(rows) == 1 and rows[0][0] == 0.0
        self.smallest = min(dt for _, dt in rows)

    @classmethod
    def every(cls, tout: float) -> "OutputSchedule":
        return cls([(0.0, tout)])

    def after(self, s: float) -> float:
        """The first output time after the scheduled output time ``s``."""
        if self.uniform:
            tout = self.rows[0][1]
            return (math.floor(s / tout + 0.5) + 1) * tout
        i = self._row(s)
        if i < 0:
            return self.rows[0][0]
        t0, dt = self.rows[i]
        nxt = t0 + (math.floor((s - t0) / dt + 0.5) + 1) * dt
        if i + 1 < len(self.rows):
            nxt = min(nxt, self.rows[i + 1][0])
        return nxt

    def first_after(self, t: float, tolerance: float = 0.0) -> float:
        """The first output time after the clock time ``t`` (a resumed run's next output after
        its last one, which may be off the schedule: a run ended at a TimeMax between two outputs
        and extended).  A ``t`` within ``tolerance`` of a scheduled time counts as that time."""
        if self.uniform:
            tout = self.rows[0][1]
            k = math.floor(t / tout)
            if t >= (k + 1) * tout - tolerance:      # at the next scheduled time, to round-off
                k += 1
            return (k + 1) * tout
        s = 0.0
        while s <= t + tolerance:
            s = self.after(s)
        return s

    def nth(self, k: int) -> float:
        """The time of output ``k`` (0: the start)."""
        if self.uniform:
            return k * self.rows[0][1]
        t = 0.0
        for _ in range(k):
            t = self.after(t)
        return t

    def _row(self, s: float) -> int:
        """The row whose interval holds ``s`` (-1 before the first row), a scheduled time equal
        to a row's start to round-off counting as in that row."""
        i = -1
        for j, (t0, _) in enumerate(self.rows):
            if s >= t0 - 1e-12 * max(1.0, t0):
                i = j
        return i
