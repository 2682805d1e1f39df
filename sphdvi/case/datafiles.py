"""Plain data files a case refers to (DualSPHysics JReadDatafile conventions:
columns separated by ';', ',', spaces or tabs; '#' starts a comment)."""
import math

import numpy as np

from ..errors import CaseError


def _parse_value(token: str, allow_none: bool) -> float:
    """One field as JReadDatafile/JLinearValue::ReadNextDouble reads it: a number, or ``none``
    (any case: a free component, DBL_MAX there, NaN here) where ``allow_none``."""
    if allow_none and token.lower() == "none":
        return float("nan")
    return float(token)


def _read_rows(path: str, ncols: int, what: str, *, allow_none: bool = False,
               finite: bool = True) -> tuple[np.ndarray, list]:
    """Numeric rows of ``path`` and the line number of each (see :func:`read_columns`). A UTF-8
    byte-order mark (Excel's "CSV UTF-8", Notepad) is dropped: DualSPHysics's JReadDatafile keeps
    that first row (atof reads past it). ``finite``: a NaN or infinite value is an error naming its
    line (a ``none`` read where ``allow_none`` is the only NaN allowed)."""
    rows, lines = [], []
    try:
        with open(path, "rb") as fb:
            head = fb.read(4096)
        if b"\x00" in head:
            raise CaseError(f"{what}: not a text file (it holds NUL bytes)", file=path,
                            expected="a text file of numbers in columns")
        with open(path, encoding="utf-8-sig", errors="replace") as f:
            for lineno, line in enumerate(f, 1):
                text = line.split("#", 1)[0].replace(";", " ").replace(",", " ").split()
                if not text:
                    continue
                try:
                    vals = [_parse_value(v, allow_none) for v in text]
                except ValueError:
                    if not rows:      # a header line
                        continue
                    raise CaseError(f"{what}: '{line.strip()[:80]}' is not numeric", file=path,
                                    line=lineno, expected=f"{ncols} numbers per line") from None
                if len(vals) < ncols:
                    raise CaseError(f"{what}: {len(vals)} column(s)", file=path, line=lineno,
                                    expected=f"{ncols} numbers per line")
                if finite:
                    bad = next((t for t, v in zip(text, vals) if not math.isfinite(v)
                                and not (allow_none and t.lower() == "none")), None)
                    if bad is not None:
                        raise CaseError(f"{what}: '{bad}' in '{line.strip()[:80]}' is not a finite number",
                                        file=path, line=lineno, expected="finite numbers"
                                        + (" (or none for a free component)" if allow_none else ""))
                rows.append(vals)
                lines.append(lineno)
    except OSError as exc:
        raise CaseError(f"{what}: cannot read the file ({exc.strerror})", file=path,
                        expected="a readable file") from None
    k = min((len(r) for r in rows), default=ncols)
    return np.asarray([r[:k] for r in rows], float).reshape(-1, k), lines


def read_columns(path: str, ncols: int, what: str, *, allow_none: bool = False) -> np.ndarray:
    """Numeric rows of ``path``, each with at least ``ncols`` columns -> (n, k):
    k is the smallest column count over the rows; leading non-numeric lines
    are headers, a non-numeric line after the data is an error, and so is a NaN or
    infinite value (``none``, read as NaN, is allowed where ``allow_none``)."""
    return _read_rows(path, ncols, what, allow_none=allow_none)[0]


def check_rising_times(times, lines: list, what: str, path: str) -> None:
    """Times of a time table that do not go back (a repeated time is a step change), the rule of
    the inline tables and of DualSPHysics's JLinearValue::SetTimeValue ("New time values is lower
    than previous time"); its FindTime walks the times as sorted."""
    bad = np.flatnonzero(np.diff(np.asarray(times, float)) < 0)
    if bad.size:
        i = int(bad[0]) + 1
        raise CaseError(f"{what}: times are not in increasing order (time {times[i]:g} after {times[i - 1]:g} "
                        f"on line {lines[i - 1]})", file=path, line=lines[i], expected="non-decreasing times")


def read_vector_table(path: str, what: str, allow_none: bool = False) -> tuple[list, list]:
    """A ``<floating>`` driver's ``file`` (``<linearvel>``, ``<angularvel>``, ``<linearforce>``,
    ``<angularforce>``): rows time;x;y;z, as DualSPHysics's JLinearValue::LoadFile reads them (at
    least two rows; ``none`` for a free velocity component where ``allow_none``) -> (times, rows of
    [x|None, y|None, z|None]), the form of the inline table."""
    a, lines = _read_rows(path, 4, what, allow_none=allow_none)
    if a.shape[0] < 2:
        found = "no data rows" if a.shape[0] == 0 else f"one data row (line {lines[0]})"
        raise CaseError(f"{what}: {found}", file=path, expected="at least two lines 'time;x;y;z' "
                        "(DualSPHysics: \"Cannot be less than two values.\")")
    bad = np.flatnonzero(np.isnan(a[:, 0]))
    if bad.size:
        raise CaseError(f"{what}: the time is none", file=path, line=lines[bad[0]], expected="a time [s]")
    check_rising_times(a[:, 0].tolist(), lines, what, path)
    values = [[None if math.isnan(v) else float(v) for v in row[1:4]] for row in a]
    return a[:, 0].tolist(), values


def read_motion_table(path: str, ncols: int, columns: dict, what: str, reach: float | None = None) -> np.ndarray:
    """A DualSPHysics motion file (``mvrectfile``/``mvrotfile``, JMotionDataFile): rows of
    ``ncols`` numbers (the ``fields`` attribute), of which ``columns`` (name -> 0-based
    column, ``fieldtime`` among them) are used. Checked as DualSPHysics needs them: at
    least two rows, the used values finite, the times never going back. A repeated time is
    taken, as JMotionMovActive takes it (its look-up steps over a segment of zero length; the
    examples' 17_WaveRunup Mov_piston.dat opens with two rows at t = 0).

    ``reach``: the movement's duration, when known.  Rows after a time that goes back are left
    out when the rows before it already reach the first row's time + ``reach``: the movement
    never looks them up (DualSPHysics's look-up walks forward from the start and stops there;
    MoorDynPlus's example 03_WavesMoorings3D plays 30 s of a piston file that ends in stray rows
    going back from 49.575 to 35.48 s).  -> (n, ncols): the rows kept (:func:`unreached_rows`)."""
    return _motion_rows(path, ncols, columns, what, reach)[0]


def _motion_rows(path: str, ncols: int, columns: dict, what: str, reach: float | None) -> tuple:
    """:func:`read_motion_table`'s rows kept, with the line numbers of all the file's rows."""
    a, all_lines = _read_rows(path, ncols, what, finite=False)
    if a.shape[0] < 2:
        found = "no data rows" if a.shape[0] == 0 else f"one data row (line {all_lines[0]})"
        raise CaseError(f"{what}: {found}", file=path,
                        expected=f"at least two lines of {ncols} numbers (time and position)")
    keep = unreached_rows(a[:, columns.get("fieldtime", 0)], reach)
    a, lines = a[:keep, :ncols], all_lines[:keep]
    for name, col in sorted(columns.items(), key=lambda kv: kv[1]):
        bad = np.flatnonzero(~np.isfinite(a[:, col]))
        if bad.size:
            raise CaseError(f"{what}: column {col} ({name}) is {a[bad[0], col]}", file=path,
                            line=lines[bad[0]], expected="finite numbers")
    t = a[:, columns.get("fieldtime", 0)]
    bad = np.flatnonzero(np.diff(t) < 0)
    if bad.size:
        i = bad[0] + 1
        raise CaseError(f"{what}: time {t[i]:g} comes before {t[i - 1]:g} (line {lines[i - 1]})",
                        file=path, line=lines[i], expected="times that never go back (a repeated time is a step)")
    return a, all_lines


def unreached_rows(t, reach: float | None) -> int:
    """The number of leading rows of times ``t`` a movement of duration ``reach`` can look up,
    when its times go back only after the rows that reach ``t[0] + |reach|`` (all rows otherwise,
    and the check that follows refuses the file)."""
    t = np.asarray(t, float)
    back = np.flatnonzero(np.diff(t) < 0)
    if reach is None or not back.size:
        return len(t)
    i = int(back[0]) + 1
    return i if i >= 2 and t[i - 1] >= t[0] + abs(reach) else len(t)


# DualSPHysics's other names of ``mvrectfile`` (JMotion::ReadXml)
MOTION_FILE_ALIASES = {"mvfile": "mvrectfile", "mvpredef": "mvrectfile"}


#: an ``mvrotadvfile``'s angle columns, in the order of its ``axes``
EULER_FIELDS = ("fieldang1", "fieldang2", "fieldang3")
#: an ``mvpathfile``'s position and angle columns (by default columns 1-6, after the time)
PATH_FIELDS = ("fieldx", "fieldy", "fieldz", *EULER_FIELDS)


def motion_file_columns(tag: str, given: dict, ncols: int | None = None) -> tuple[int, dict]:
    """(number of columns, {fieldtime/fieldx/.../fieldang: 0-based column}) of a file movement
    (``tag`` ``mvrectfile``, ``mvrotfile`` or ``mvrotadvfile``) from the columns ``given``: time
    defaults to column 0, an ``mvrotfile``'s angle to 1 (DualSPHysics's layout), an
    ``mvrotadvfile``'s three angles to 1, 2, 3 when it names none (an angle it does not name
    stays 0); without ``fields`` (``ncols``) the file has as many columns as the last one used."""
    cols = dict(given)
    cols.setdefault("fieldtime", 0)
    if tag == "mvrotfile":
        cols.setdefault("fieldang", 1)
    if tag == "mvrotadvfile" and not any(k in cols for k in EULER_FIELDS):
        cols.update({k: i + 1 for i, k in enumerate(EULER_FIELDS)})
    if tag == "mvpathfile" and not any(k in cols for k in PATH_FIELDS):
        cols.update({k: i + 1 for i, k in enumerate(PATH_FIELDS)})
    return (int(ncols) if ncols else max(2, 1 + max(cols.values()))), cols


def read_motion_file(reader, m, tag: str, duration: float | None = None) -> dict:
    """Read and check the ``<file>`` of movement element ``m`` (``tag``: ``mvrectfile``, its
    aliases included, ``mvrotfile`` or ``mvrotadvfile``): ``fields`` is the number of columns of
    the file, ``fieldtime``, ``fieldx``, ``fieldy``, ``fieldz`` (``fieldang``; ``fieldang1``-``3``)
    0-based column indices,
    as DualSPHysics's JMotion reads them. The file is read and checked now."""
    f = reader.child(m, "file", True)
    path = reader.resolve_path(f, "name")
    names = {"mvrectfile": ("fieldtime", "fieldx", "fieldy", "fieldz"),
             "mvrotadvfile": ("fieldtime", *EULER_FIELDS),
             "mvpathfile": ("fieldtime", *PATH_FIELDS)}.get(tag, ("fieldtime", "fieldang"))
    given = {k: reader.integer(f, k, lo=0) for k in names if f.get(k) is not None}
    ncols, cols = motion_file_columns(tag, given,
                                      reader.integer(f, "fields", lo=2) if f.get("fields") is not None else None)
    for k, v in cols.items():
        if v >= ncols:
            raise reader.error(f, f"{k}={v} is not a column of a file of fields={ncols} columns "
                               "(columns are numbered from 0)", f"0 <= {k} < {ncols}")
        if k != "fieldtime" and v == cols["fieldtime"]:
            raise reader.error(f, f"{k}={v} is the time column (fieldtime={v})", f"{k} another column than fieldtime")
    if tag == "mvrectfile" and len(cols) == 1:
        reader.warn(f, "none of fieldx, fieldy, fieldz is given: the movement does not move the object")
    try:
        a, lines = _motion_rows(path, ncols, cols, "motion data", duration)
    except CaseError as exc:
        where = path + (f":{exc.line}" if exc.line else "")
        raise reader.error(f, f"{where}: {exc.message}", exc.expected) from None
    if len(a) < len(lines):
        t, n = a[:, cols["fieldtime"]], len(a)
        reader.warn(f, f"{path}:{lines[n]}: the time goes back after line {lines[n - 1]} ({t[-1]:g} s); the "
                    f"movement plays the file from {t[0]:g} s for {abs(duration):g} s and never reaches the rows "
                    f"from line {lines[n]} on: left out ({len(lines) - n} rows)")
    varying = [k for k, j in cols.items() if k != "fieldtime" and np.ptp(a[:, j]) > 0.0]
    return {"file": path, "fields": cols, "ncols": ncols, "reach": duration, "varying": varying}


def _time_table(path: str, what: str, name: str, unit: str, positive: bool) -> np.ndarray:
    """(time [s], value) rows of a DualSPHysics time-series file -> (n, 2): at least two
    rows, times rising, values finite and > 0 (``positive``) or >= 0."""
    a = read_columns(path, 2, what)[:, :2].copy()
    if a.shape[0] < 2:
        raise CaseError(f"{what}: fewer than two (time, {name}) rows", file=path,
                        expected=f"at least two lines 'time[s] {name}{unit}'")
    if np.any(np.diff(a[:, 0]) < 0):
        raise CaseError(f"{what}: times decrease", file=path, expected="rising times")
    bad = a[:, 1] <= 0 if positive else a[:, 1] < 0
    if np.any(~np.isfinite(a)) or np.any(bad):
        limit = "> 0" if positive else ">= 0"
        raise CaseError(f"{what}: {name} must be finite and {limit}", file=path,
                        expected=f"{name} values {limit}")
    return a


def read_visco_table(path: str) -> np.ndarray:
    """``ViscoTime``: rows (time [s], Visco) -> (n, 2) array, as DualSPHysics's
    JDsViscoInput reads it (linear interpolation in between, the end values outside)."""
    return _time_table(path, "ViscoTime", "visco", "", positive=False)


def read_dt_table(path: str) -> np.ndarray:
    """``DtFixedFile``: rows (time [s], dt [ms]) -> (n, 2) array of (time, dt [s]),
    as DualSPHysics's JSphDtFixed reads it (linear interpolation in between, the end
    values outside)."""
    a = _time_table(path, "DtFixedFile", "dt", "[ms]", positive=True)
    a[:, 1] *= 1e-3
    return a
