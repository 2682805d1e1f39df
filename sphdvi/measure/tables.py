"""Time-series tables of the measurement tools: CSV writing/reading and plots.

Default layout (``sep=','``): one header row ``time [s],name [unit],...`` then
one row per output time; empty fields are missing values (NaN).

DualSPHysics layout (``sep=';'``, like MeasureTool's ``-savecsv``): three rows
`` ;PosX [m]:;x0;x1...`` / PosY / PosZ with the point of each column (when the
columns belong to points), then ``Part;Time [s];name [unit];...`` and one row
``part;time;values`` per output time.
"""
from __future__ import annotations

import io
import math
import os
import re
from dataclasses import dataclass, field

import numpy as np

from ..io.atomic import atomic_path

_HEADER_RE = re.compile(r"^\s*(.*?)\s*(?:\[(.*)\])?\s*$")


@dataclass
class Table:
    """Columns of values against time (one row per output time)."""

    time: np.ndarray                         # (T,)
    names: list                              # C column names (no units)
    units: list                              # C units ("" when none)
    data: np.ndarray                         # (T, C), NaN = missing
    part: np.ndarray | None = None           # (T,) snapshot index
    positions: np.ndarray | None = None      # (C, 3) point of each column, or None
    title: str = ""
    notes: list = field(default_factory=list)

    def column(self, name: str) -> np.ndarray:
        return self.data[:, self.names.index(name)]

    def header_cells(self):
        return [f"{n} [{u}]" if u else n for n, u in zip(self.names, self.units)]


def _fmt(v: float) -> str:
    return "" if not math.isfinite(v) else f"{v:.9g}"


def table_text(t: Table, sep: str = ",") -> str:
    """The table as CSV text (see the module docstring for both layouts)."""
    buf = io.StringIO()
    dsph = sep == ";"
    if dsph and t.positions is not None:
        for k, axis in enumerate("XYZ"):
            buf.write(f" ;Pos{axis} [m]:;" + ";".join(_fmt(float(v)) for v in t.positions[:, k]) + "\n")
    head = (["Part", "Time [s]"] if dsph else ["time [s]"]) + t.header_cells()
    buf.write(sep.join(head) + "\n")
    part = t.part if t.part is not None else np.arange(t.time.shape[0])
    for i in range(t.time.shape[0]):
        cells = ([str(int(part[i]))] if dsph else []) + [f"{float(t.time[i]):.15g}"]
        cells += [_fmt(float(v)) for v in t.data[i]]
        buf.write(sep.join(cells) + "\n")
    return buf.getvalue()


def write_table(t: Table, path: str | None = None, sep: str = ",", stream=None) -> None:
    """Write to ``path`` atomically, or to ``stream`` (stdout) when ``path`` is None."""
    text = table_text(t, sep)
    if path is None:
        (stream or __import__("sys").stdout).write(text)
        return
    folder = os.path.dirname(os.path.abspath(path))
    os.makedirs(folder, exist_ok=True)
    with atomic_path(path) as tmp:
        with open(tmp, "w", encoding="utf-8", newline="\n") as fh:
            fh.write(text)


def _split_header(cell: str):
    m = _HEADER_RE.match(cell)
    name, unit = m.group(1), (m.group(2) or "")
    return name.rstrip(":"), unit


def read_table(path_or_text: str) -> Table:
    """Read a table written by :func:`write_table` (either layout) or a gauge file."""
    text = path_or_text
    if "\n" not in path_or_text and os.path.exists(path_or_text):
        with open(path_or_text, encoding="utf-8") as fh:
            text = fh.read()
    lines = [ln for ln in text.splitlines() if ln.strip()]
    sep = ";" if ";" in lines[0] else ","
    pos_rows = []
    while lines and lines[0].startswith(" ;Pos"):
        pos_rows.append([float(v) if v else np.nan for v in lines.pop(0).split(";")[2:]])
    head = [c for c in lines[0].split(sep)]
    dsph = head[0].strip().lower() == "part"
    first = 2 if dsph else 1
    names, units = zip(*(_split_header(c) for c in head[first:])) if len(head) > first else ((), ())
    rows = [ln.split(sep) for ln in lines[1:]]
    part = np.array([int(r[0]) for r in rows], np.int64) if dsph else None
    time = np.array([float(r[first - 1]) for r in rows])
    data = np.array([[float(v) if v.strip() else np.nan for v in r[first:]] for r in rows],
                    dtype=np.float64).reshape(len(rows), len(names))
    positions = np.array(pos_rows).T if pos_rows else None
    return Table(time, list(names), list(units), data, part, positions)


def plot_table(t: Table, path: str, title: str | None = None) -> None:
    """Draw every column against time, one panel per unit, into a PNG file."""
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        from ..errors import InputError
        raise InputError("--plot needs matplotlib (pip install matplotlib)") from None
    groups: dict = {}
    for i, u in enumerate(t.units):
        groups.setdefault(u, []).append(i)
    n = max(1, len(groups))
    fig, axes = plt.subplots(n, 1, figsize=(8, 2.6 * n + 0.6), sharex=True, squeeze=False)
    for ax, (unit, cols) in zip(axes[:, 0], groups.items()):
        for i in cols[:40]:
            ax.plot(t.time, t.data[:, i], label=t.names[i], lw=1.2)
        ax.set_ylabel(f"[{unit}]" if unit else "")
        ax.grid(True, alpha=0.3)
        if len(cols) <= 12:
            ax.legend(fontsize=7, ncol=min(4, len(cols)))
    axes[-1, 0].set_xlabel("time [s]")
    fig.suptitle(title or t.title or "")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
