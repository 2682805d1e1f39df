"""Mk lists as DualSPHysics writes them: ``"0-3,7"`` means 0, 1, 2, 3 and 7."""
from __future__ import annotations

MAX_MK = 65535


def parse_mk_range(text: str) -> list[int]:
    """Parse a comma-separated list of mk values and inclusive ranges ``a-b``.

    Returns the sorted unique values. Raises ValueError with a short reason.
    """
    if text is None or not str(text).strip():
        raise ValueError("empty mk list")
    values: set[int] = set()
    for part in str(text).split(","):
        part = part.strip()
        if not part:
            raise ValueError(f"empty item in mk list '{text}'")
        if "-" in part[1:]:
            a, b = part.split("-", 1) if not part.startswith("-") else (part, "")
            lo, hi = _mk_int(a, text), _mk_int(b, text)
            if hi < lo:
                raise ValueError(f"range '{part}' ends before it starts")
            if hi - lo > MAX_MK:
                raise ValueError(f"range '{part}' is too long")
            values.update(range(lo, hi + 1))
        else:
            values.add(_mk_int(part, text))
    return sorted(values)


def _mk_int(token: str, whole: str) -> int:
    token = token.strip()
    if not token.isdigit():
        raise ValueError(f"'{token}' in mk list '{whole}' is not a non-negative integer")
    value = int(token)
    if value > MAX_MK:
        raise ValueError(f"mk {value} is larger than {MAX_MK}")
    return value


def format_mk_range(values) -> str:
    """Inverse of :func:`parse_mk_range`: ``[0,1,2,3,7] -> "0-3,7"``."""
    vals = sorted(set(int(v) for v in values))
    parts = []
    i = 0
    while i < len(vals):
        j = i
        while j + 1 < len(vals) and vals[j + 1] == vals[j] + 1:
            j += 1
        parts.append(str(vals[i]) if i == j else f"{vals[i]}-{vals[j]}")
        i = j + 1
    return ",".join(parts)
