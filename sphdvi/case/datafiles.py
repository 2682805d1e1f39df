"""Plain data files a case refers to (DualSPHysics JReadDatafile conventions:
columns separated by ';', ',', spaces or tabs; '#' starts a comment)."""
import numpy as np

from ..errors import CaseError


def read_columns(path: str, ncols: int, what: str) -> np.ndarray:
    """Numeric rows of ``path``, each with at least ``ncols`` columns -> (n, k):
    k is the smallest column count over the rows; leading non-numeric lines
    are headers, a non-numeric line after the data is an error."""
    rows = []
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            for lineno, line in enumerate(f, 1):
                text = line.split("#", 1)[0].replace(";", " ").replace(",", " ").split()
                if not text:
                    continue
                try:
                    vals = [float(v) for v in text]
                except ValueError:
                    if not rows:      # a header line
                        continue
                    raise CaseError(f"{what}: '{line.strip()}' is not numeric", file=path,
                                    line=lineno, expected=f"{ncols} numbers per line") from None
                if len(vals) < ncols:
                    raise CaseError(f"{what}: {len(vals)} column(s)", file=path, line=lineno,
                                    expected=f"{ncols} numbers per line")
                rows.append(vals)
    except OSError as exc:
        raise CaseError(f"{what}: cannot read the file ({exc.strerror})", file=path,
                        expected="a readable file") from None
    k = min((len(r) for r in rows), default=ncols)
    return np.asarray([r[:k] for r in rows], float).reshape(-1, k)


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
