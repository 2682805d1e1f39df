"""The text outputs of a run, and its progress display.

* ``run.json``: provenance and status, rewritten atomically;
* ``run.log`` / ``run.csv``: one line per output time (DualSPHysics's Run.out and
  RunPARTs.csv), appended;
* ``bodies.csv`` / ``links.csv``: one row per body and per link at every output (and
  TimeOutExtra) time, appended; a resume cuts them back to the restart time;
* ``excluded.csv``: one row per fluid particle the run removed (DualSPHysics's PartOut
  files), appended at each output, written from the first exclusion on;
* a progress line on a terminal, a log line every so often otherwise.
"""
from __future__ import annotations

import contextlib
import json
import os
import sys
import time as _time
import warnings

import numpy as np

from .atomic import append_text, complete_lines, write_text_atomic

RUN_CSV_HEADER = "part,time,steps,particles,excluded,dtmin,dtmax,walltime"
EXCLUDED_FILE = "excluded.csv"
EXCLUDED_HEADER = "time,idp,x,y,z,vx,vy,vz,rhop,reason"
PROGRESS_INTERVAL_S = 30.0      # between two progress lines when stderr is not a terminal


class RunFiles:
    """The small text outputs of a run: run.json rewritten atomically; run.log and run.csv
    appended a line at a time (a resume cuts run.csv back to its restart output)."""

    def __init__(self, outdir: str):
        self.outdir = outdir
        self.json_path = os.path.join(outdir, "run.json")
        self.log_path = os.path.join(outdir, "run.log")
        self.csv_path = os.path.join(outdir, "run.csv")
        self.meta: dict = {}
        self.on_start = None     # called once by start(): --overwrite deletes the earlier run's files then
        self.startup_warnings: list[str] = []   # said before run.log began: written at its head
        self.log_started = False

    def write_json(self, **updates) -> None:
        self.meta.update(updates)
        write_text_atomic(self.json_path, json.dumps(self.meta, indent=2, default=_jsonable) + "\n")

    def log(self, line: str) -> None:
        append_text(self.log_path, line + "\n")

    def csv(self, row: str) -> None:
        if not os.path.exists(self.csv_path):
            write_text_atomic(self.csv_path, RUN_CSV_HEADER + "\n")
        append_text(self.csv_path, row + "\n")

    def start(self) -> None:
        """A new run: run.log with the start-up warnings only, run.csv with its header only."""
        write_text_atomic(self.log_path, self._take_startup_warnings())
        write_text_atomic(self.csv_path, RUN_CSV_HEADER + "\n")
        if self.on_start is not None:
            self.on_start()
            self.on_start = None

    def load_existing(self, nparts: int) -> None:
        """On resume: the log and the CSV rows of the first ``nparts`` outputs, without what was
        written after the restart output (the run goes on from there and writes it again)."""
        lines = log_to_part(complete_lines(self.log_path), nparts - 1)
        write_text_atomic(self.log_path, "".join(line + "\n" for line in lines) + self._take_startup_warnings())
        rows = complete_lines(self.csv_path)[1:nparts + 1]
        write_text_atomic(self.csv_path, RUN_CSV_HEADER + "\n" + "".join(r + "\n" for r in rows))
        if os.path.exists(self.json_path):
            with open(self.json_path) as fh:
                try:
                    self.meta = json.load(fh)
                except json.JSONDecodeError:
                    self.meta = {}


    def _take_startup_warnings(self) -> str:
        self.log_started = True
        lines, self.startup_warnings = self.startup_warnings, []
        return "".join(f"WARNING: {w}\n" for w in lines)


@contextlib.contextmanager
def startup_warnings_logged(files: RunFiles):
    """The UserWarnings of a run's start-up (the --set checks, the initial density window,
    DtFixed below DtMin, thin mDBC walls, ...) shown as always and also kept for run.log, where
    :meth:`RunFiles.start` / :meth:`RunFiles.load_existing` write them (DualSPHysics's Run.out
    holds its warnings too).  Warnings after run.log began are the run loop's to log."""
    shown = warnings.showwarning

    def show(message, category, filename, lineno, file=None, line=None):
        if issubclass(category, UserWarning) and not files.log_started:
            files.startup_warnings.append(str(message))
        shown(message, category, filename, lineno, file, line)

    warnings.showwarning = show
    try:
        yield
    finally:
        warnings.showwarning = shown


def log_to_part(lines: list[str], part: int) -> list[str]:
    """run.log's lines up to output ``part``'s "Part NNNN" line and the WARNING lines written with
    it; all of them where that line is missing (a log of an older run)."""
    tag = f"Part {part:04d} "
    ends = [i for i, line in enumerate(lines) if line.startswith(tag)]
    if not ends:
        return lines
    end = ends[-1] + 1
    while end < len(lines) and lines[end].startswith("WARNING:"):
        end += 1
    return lines[:end]


def _jsonable(obj):
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    return str(obj)


class Progress:
    """A progress bar on a terminal (redrawn every 0.2 s); otherwise a line every ``interval``
    seconds (PROGRESS_INTERVAL_S: ``progress: t=.. s (..%) steps=.. particles=.. dt=.. s wall=.. s
    eta=.. s``, conventions.md's ``step t dt wall ETA particles``).  On a terminal a warning
    printed while the bar is drawn starts on a line of its own (the bar's line is cleared first;
    the next update draws the bar again below it)."""

    def __init__(self, tmax: float, quiet: bool, stream=None, interval: float | None = None,
                 counts: str = "particles"):
        self.tmax = tmax
        self.counts = counts            # what the count ``n`` of update() counts
        self.quiet = quiet
        self.stream = stream or sys.stderr
        self.tty = hasattr(self.stream, "isatty") and self.stream.isatty()
        self.interval = PROGRESS_INTERVAL_S if interval is None else interval
        self.last = 0.0
        self.t0 = _time.perf_counter()
        self.on_bar = False             # the cursor is at the end of the drawn bar
        self._shown = None
        if self.tty and not quiet:      # warnings clear the bar's line first
            self._shown = warnings.showwarning
            warnings.showwarning = self._show_warning

    def _show_warning(self, *args, **kwargs):
        self.clear_line()
        (self._shown or warnings._showwarning_orig)(*args, **kwargs)

    def clear_line(self) -> None:
        """Clear the bar's line (a terminal), so that what is printed next starts on it."""
        if self.on_bar:
            self.stream.write("\r\033[K")
            self.stream.flush()
            self.on_bar = False

    def update(self, t: float, steps: int, n: int, force: bool = False, dt: float | None = None) -> None:
        """Show the progress at time ``t`` after ``steps`` steps with ``n`` particles (or bodies);
        ``dt``: the last step's (None: no step yet)."""
        if self.quiet:
            return
        now = _time.perf_counter()
        if not force and now - self.last < (0.2 if self.tty else self.interval):
            return
        self.last = now
        frac = min(1.0, t / self.tmax) if self.tmax > 0 else 1.0
        wall = now - self.t0
        eta = wall * (1 - frac) / frac if frac > 0 else float("nan")
        dt_text = f"dt={dt:.3g} s" if dt else "dt=-"
        if self.tty:
            bar = "#" * int(30 * frac)
            self.stream.write(f"\r[{bar:<30}] {100 * frac:5.1f}%  t={t:.4f} s  steps={steps}  "
                              f"{self.counts}={n}  {dt_text}  eta={eta:6.0f} s \033[K")
            self.on_bar = True
        else:
            self.stream.write(f"progress: t={t:.5g} s ({100 * frac:.1f}%) steps={steps} {self.counts}={n} "
                              f"{dt_text} wall={wall:.1f} s eta={eta:.0f} s\n")
        self.stream.flush()

    def close(self):
        """End the bar's line and put the warning display back (called again: nothing)."""
        if self._shown is not None:
            if warnings.showwarning == self._show_warning:
                warnings.showwarning = self._shown
            self._shown = None
        if self.on_bar:
            self.stream.write("\n")
            self.on_bar = False


def _rows_until(path: str, resume_time: float | None) -> list[str]:
    """The complete data rows (with their newline) of a row file whose first column is the
    time, up to ``resume_time``; none for a new run (``resume_time`` None)."""
    if resume_time is None:
        return []
    from ..dvi.runner import csv_time
    # compare as printed: the row written at the restart time may have been rounded up in
    # its 9 digits, and must stay
    limit = float(csv_time(resume_time))
    return [line + "\n" for line in complete_lines(path)[1:] if line and float(line.split(",", 1)[0]) <= limit]


def _pad_rows(rows: list[str], ncols: int) -> list[str]:
    """Rows of a file an older sphdvi wrote with fewer columns (bodies.csv before its fluid-load
    columns) filled up with nan to the present header, so that a resumed run's file stays one table."""
    out = []
    for row in rows:
        missing = ncols - (row.count(",") + 1)
        out.append(row[:-1] + ",nan" * missing + "\n" if missing > 0 else row)
    return out


class BodyLog:
    """``bodies.csv`` and ``links.csv`` of a run with bodies (one row per body
    and per link at every output time, and at TimeOutExtra between outputs): the rows are
    appended at each output; a resume cuts the files back to the restart time, atomically.
    ``prepare``: called before each row (the loads on bodies held by FtPause, computed only
    for the rows: FloatingBodies.held_loads)."""

    def __init__(self, outdir: str, system, names, resume_time: float | None = None, prepare=None):
        from ..dvi.runner import BODIES_HEADER, LINKS_HEADER
        self.system, self.names = system, names
        self.prepare = prepare
        self.paths = (os.path.join(outdir, "bodies.csv"), os.path.join(outdir, "links.csv"))
        self.headers = (BODIES_HEADER, LINKS_HEADER)
        self.rows: tuple[list, list] = ([], [])        # rows not yet written
        for path, header in zip(self.paths, self.headers):
            rows = _pad_rows(_rows_until(path, resume_time), header.count(",") + 1)
            write_text_atomic(path, header + "\n" + "".join(rows))

    def record(self, flush: bool = True) -> None:
        """Add a row per body and link at the current time; append the pending rows to the
        files when ``flush`` (at every TimeOut output; TimeOutExtra rows wait in memory)."""
        from ..dvi.runner import csv_rows
        if self.prepare is not None:
            self.prepare()
        bodies, links = csv_rows(self.system, self.names)
        self.rows[0].extend(bodies)
        self.rows[1].extend(links)
        if flush:
            for path, rows in zip(self.paths, self.rows):
                if rows:
                    append_text(path, "".join(rows))
                    rows.clear()


class ExcludedLog:
    """``excluded.csv``: a row per fluid particle the run excluded (DualSPHysics's PartOut),
    columns :data:`EXCLUDED_HEADER`: the time of the end of the step that removed it, its id,
    its position, velocity and density at that moment and the reason (``rhop``: density
    outside RhopOutMin/RhopOutMax; ``position``: out of the domain; ``not finite``).  The
    file appears with the first exclusion; rows are appended at each output; a resume cuts
    them back to the restart time, atomically."""

    def __init__(self, outdir: str, resume_time: float | None = None):
        self.path = os.path.join(outdir, EXCLUDED_FILE)
        if resume_time is not None and os.path.exists(self.path):
            write_text_atomic(self.path, EXCLUDED_HEADER + "\n" + "".join(_rows_until(self.path, resume_time)))

    def record(self, events: list) -> None:
        """Append the rows of ``events`` (the solver's exclusion events: dicts of time, idp,
        pos, vel, rhop, reason)."""
        events = [ev for ev in events if len(ev["idp"])]
        if not events:
            return
        from ..dvi.runner import csv_time
        lines = []
        for ev in events:          # one event per step that excluded particles
            t = csv_time(ev["time"])
            pos, vel = np.asarray(ev["pos"], float), np.asarray(ev["vel"], float)
            cols = np.column_stack([pos, vel, np.asarray(ev["rhop"], float)])
            values = [",".join(f"{v:.9g}" for v in row) for row in cols.tolist()]
            lines.extend(f"{t},{int(i)},{v},{r}\n" for i, v, r in zip(ev["idp"], values, ev["reason"]))
        if not os.path.exists(self.path):
            write_text_atomic(self.path, EXCLUDED_HEADER + "\n")
        append_text(self.path, "".join(lines))
