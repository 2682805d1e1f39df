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


def parse_range_filter(text: str) -> tuple[list[int], list[str]]:
    """An mk list as DualSPHysics's JRangeFilter::Config reads it (the ``<chrono>`` mkbound lists):
    items split at each comma (fun::StrSplit: a trailing comma ends the list); an empty item is
    skipped; ``a``, ``a-b`` (nothing when b < a), ``a-b:step`` (nothing for step 0); a number read as
    atoi reads it, so a blank one is 0; ``a-`` is a alone, ``-b`` (no start) nothing.

    Returns (sorted unique values, notes): a note for each item read in a way its writer likely did
    not mean (a blank read as 0, an item or a range that gives nothing); ValueError for what atoi
    would read as some other number (letters, decimals, a sign), a value above :data:`MAX_MK`
    (DualSPHysics truncates it to 16 bits)."""
    values: set[int] = set()
    notes: list[str] = []
    rest = "" if text is None else str(text)
    while rest:
        item, _, rest = rest.partition(",")
        if not item:
            notes.append("an empty item (two commas in a row, or a leading one) is skipped")
            continue
        values.update(_range_filter_item(item, text, notes))
    return sorted(values), notes


def _range_filter_item(item: str, whole: str, notes: list) -> range:
    """The values of one JRangeFilter item: ``a``, ``a-b`` or ``a-b:step`` (see parse_range_filter)."""
    dash = item.find("-")
    if dash == 0:
        notes.append(f"'{item}' has no start value: it gives nothing")
        return range(0)
    first = item if dash < 0 else item[:dash]
    second = "" if dash < 0 else item[dash + 1:]
    step = ""
    colon = second.find(":")
    if colon > 0:
        second, step = second[:colon], second[colon + 1:]
    lo = _atoi_mk(first, "start" if dash > 0 else "", item, whole, notes)
    if not second:
        if dash > 0:
            notes.append(f"'{item}' has no end value: read as {lo} alone")
        return range(lo, lo + 1)
    hi = _atoi_mk(second, "end", item, whole, notes)
    by = _atoi_mk(step, "step", item, whole, notes) if step else 1
    if hi < lo or by == 0:
        notes.append(f"'{item}' " + ("ends before it starts" if hi < lo else "has a step of 0")
                     + ": it gives nothing")
        return range(0)
    return range(lo, hi + 1, by)


def _atoi_mk(token: str, part: str, item: str, whole: str, notes: list) -> int:
    """One number of a JRangeFilter item as C's atoi reads it: leading and trailing blanks ignored,
    a blank one 0 (noted); anything but digits a ValueError (atoi would read a number from its
    first characters alone)."""
    t = token.strip()
    if not t:
        notes.append(f"the blank {part} of '{item}' is read as 0" if part else f"the blank item '{item}' is read as 0")
        return 0
    if not (t.isascii() and t.isdigit()):
        raise ValueError(f"'{t}' in mk list '{whole}' is not a non-negative integer")
    value = int(t)
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
