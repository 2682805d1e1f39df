"""``DtInfo.csv`` and ``DtAllInfo.csv``: the time step of a run, as DualSPHysics's
``<special><savedt>`` (JSaveDt) writes them (``;``-separated, its column names).

* ``DtInfo.csv``: a row per ``interval`` of time from ``start`` to ``finish``, columns
  ``Time`` (the start of the interval's first step), ``Values`` (its steps), and the mean,
  smallest and largest of ``Dtf`` (the dt the step used), ``Dt1`` (CFL times the force
  condition sqrt(h/|a|max)) and ``Dt2`` (CFL times the CFL-viscous condition
  h/(max(c0, 10|v|max) + h max viscdt)); with ``fullinfo`` also of ``AceMax`` (m/s2),
  ``ViscDtMax`` (1/s) and ``VelMax`` (m/s).  A term that the step's dt did not come from
  (the first Symplectic step, whose dt is DtIni) is left out of the statistics; a column
  with none is empty.
* ``DtAllInfo.csv`` (``alldt``): ``Time [s];Dtf [s]``, a row per step.

The column names carry DualSPHysics's units (``Time [s]``, ``Dtf_mean [s]``, ``AceMax_mean [m/s^2]``,
``ViscDtMax_mean``, ``VelMax_mean [m/s]``).

Rows are appended at each output, which closes the interval in progress as DualSPHysics
does (its later steps start a row of their own, timed by their first step); a row is also
written when its interval ends and at the end of the run.  A resume cuts both files back to the rows
its checkpoint counted and goes on with the interval in progress (:meth:`DtLog.get_state`).
"""
from __future__ import annotations

import json
import math
import os

from .atomic import append_text, complete_lines, write_text_atomic

DTINFO_FILE = "DtInfo.csv"
DTALLINFO_FILE = "DtAllInfo.csv"
TERMS = ("Dtf", "Dt1", "Dt2")
FULL_TERMS = ("AceMax", "ViscDtMax", "VelMax")


UNITS = {"Dtf": " [s]", "Dt1": " [s]", "Dt2": " [s]", "AceMax": " [m/s^2]", "ViscDtMax": "", "VelMax": " [m/s]"}
DTALLINFO_HEADER = "Time [s];Dtf [s]"


def dtinfo_header(fullinfo: bool) -> str:
    """DualSPHysics's column names, units included (JDsSaveDt::SaveFileValues)."""
    names = TERMS + (FULL_TERMS if fullinfo else ())
    return "Time [s];Values;" + ";".join(f"{n}_{s}{UNITS[n]}" for n in names for s in ("mean", "min", "max"))


def _fmt(v: float) -> str:
    return f"{v:.12E}"


class DtLog:
    """The ``<savedt>`` outputs of a run (``spec``: the dict of its reader; ``tout``: the
    run's TimeOut, the interval when the case gives none)."""

    def __init__(self, outdir: str, spec: dict, tout: float, state: dict | None = None):
        self.start = float(spec.get("start") or 0.0)
        self.finish = math.inf if spec.get("finish") is None else float(spec["finish"])
        self.interval = float(spec.get("interval") or tout)
        self.fullinfo = bool(spec.get("fullinfo"))
        self.alldt = bool(spec.get("alldt"))
        self.nterms = len(TERMS) + (len(FULL_TERMS) if self.fullinfo else 0)
        self.path = os.path.join(outdir, DTINFO_FILE)
        self.all_path = os.path.join(outdir, DTALLINFO_FILE) if self.alldt else None
        self.header = dtinfo_header(self.fullinfo)
        self.rows: list[str] = []            # complete rows not yet written
        self.all_rows: list[str] = []
        self.t0 = 0.0                        # the interval in progress: its first step's time and count
        self.count = 0
        self.acc: list = []                  # per term [n, mean, min, max]
        self.written, self.all_written = 0, 0
        if state is None:
            write_text_atomic(self.path, self.header + "\n")
            if self.all_path:
                write_text_atomic(self.all_path, DTALLINFO_HEADER + "\n")
        else:
            self._resume(state)

    # -- the steps -----------------------------------------------------------------------
    def add(self, t: float, terms) -> None:
        """A step that started at time ``t``; ``terms``: Dtf, Dt1, Dt2 (and AceMax,
        ViscDtMax, VelMax)."""
        if not (self.start <= t <= self.finish):
            if t > self.finish and self.count:
                self._close_interval()
            return
        if self.count and self._interval(t) != self._interval(self.t0):
            self._close_interval()
        if not self.count:
            self.t0 = t
            self.acc = [[0, 0.0, math.inf, -math.inf] for _ in range(self.nterms)]
        self.count += 1
        for a, v in zip(self.acc, terms[:self.nterms]):
            v = float(v)
            if math.isfinite(v):
                a[0] += 1
                a[1] += (v - a[1]) / a[0]
                a[2], a[3] = min(a[2], v), max(a[3], v)
        if self.alldt:
            self.all_rows.append(f"{_fmt(t)};{_fmt(float(terms[0]))}\n")

    def _close_interval(self) -> None:
        cols = [_fmt(self.t0), str(self.count)]
        for n, mean, lo, hi in self.acc:
            cols += [_fmt(mean), _fmt(lo), _fmt(hi)] if n else ["", "", ""]
        self.rows.append(";".join(cols) + "\n")
        self.count = 0

    def _interval(self, t: float) -> int:
        return int(math.floor((t - self.start) / self.interval))

    # -- the files -----------------------------------------------------------------------
    def flush(self) -> None:
        """Append the rows at an output: as DualSPHysics's JDsSaveDt::SaveData, the interval in
        progress is closed there (its steps after the output start a row of their own), so that
        no row spans an output."""
        if self.count:
            self._close_interval()
        if self.rows:
            append_text(self.path, "".join(self.rows))
            self.written += len(self.rows)
            self.rows.clear()
        if self.all_rows:
            append_text(self.all_path, "".join(self.all_rows))
            self.all_written += len(self.all_rows)
            self.all_rows.clear()

    def close(self) -> None:
        """The end of the run: the interval in progress becomes a row too."""
        if self.count:
            self._close_interval()
        self.flush()

    # -- resume --------------------------------------------------------------------------
    def get_state(self) -> str:
        """What a resumed run needs (JSON): the rows written and the interval in progress."""
        return json.dumps({"written": self.written, "all_written": self.all_written, "t0": self.t0,
                           "count": self.count, "acc": self.acc})

    def _resume(self, text: str) -> None:
        st = json.loads(text)
        self.written, self.all_written = int(st["written"]), int(st["all_written"])
        self.t0, self.count, self.acc = float(st["t0"]), int(st["count"]), st["acc"]
        for path, header, n in ((self.path, self.header, self.written),
                                (self.all_path, DTALLINFO_HEADER, self.all_written)):
            if path is None:
                continue
            rows = complete_lines(path)[1:n + 1] if os.path.exists(path) else []
            write_text_atomic(path, header + "\n" + "".join(r + "\n" for r in rows))
            if path == self.path:
                self.written = len(rows)
            else:
                self.all_written = len(rows)
