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


def read_visco_table(path: str) -> np.ndarray:
    """``ViscoTime``: rows (time [s], Visco) -> (n, 2) array, as DualSPHysics's
    JDsViscoInput reads it (at least two rows; linear interpolation in between, the
    end values outside); times must rise and values be finite and >= 0."""
    a = read_columns(path, 2, "ViscoTime")[:, :2].copy()
    if a.shape[0] < 2:
        raise CaseError("ViscoTime: fewer than two (time, visco) rows", file=path,
                        expected="at least two lines 'time[s] visco'")
    if np.any(np.diff(a[:, 0]) < 0):
        raise CaseError("ViscoTime: times decrease", file=path, expected="rising times")
    if np.any(~np.isfinite(a)) or np.any(a[:, 1] < 0):
        raise CaseError("ViscoTime: values must be finite and >= 0", file=path,
                        expected="viscosity values >= 0")
    return a


def read_dt_table(path: str) -> np.ndarray:
    """``DtFixedFile``: rows (time [s], dt [ms]) -> (n, 2) array of (time, dt [s]),
    as DualSPHysics's JSphDtFixed reads it (at least two rows, times rising,
    dt > 0; linear interpolation in between, the end values outside)."""
    a = read_columns(path, 2, "DtFixedFile")[:, :2].copy()
    if a.shape[0] < 2:
        raise CaseError("DtFixedFile: fewer than two (time, dt) rows", file=path,
                        expected="at least two lines 'time[s] dt[ms]'")
    if np.any(np.diff(a[:, 0]) < 0):
        raise CaseError("DtFixedFile: times decrease", file=path, expected="rising times")
    if np.any(~np.isfinite(a)) or np.any(a[:, 1] <= 0):
        raise CaseError("DtFixedFile: dt must be finite and > 0", file=path,
                        expected="dt values in milliseconds > 0")
    a[:, 1] *= 1e-3
    return a
