"""Mk lists as DualSPHysics writes them: ``"0-3,7"`` means 0, 1, 2, 3 and 7.

:func:`parse_mk_range` is the strict form (GenCase's lists, whose reader is not public, and sphdvi's
own ``MdbcMkbound``); the others read a list as the DualSPHysics class that reads it: JRangeFilter
(:func:`parse_range_filter`, :func:`range_filter_attr`: ``<chrono>``, ``<initialize>``), JDsAccInput
(:func:`accinput_mk_attr`), JCasePropLinks (:func:`prop_link_attr`) and JDsOutputPartsOp_Mk
(:func:`parse_filtermk`)."""
from __future__ import annotations

import re

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


# ---------------------------------------------------------------------------
# mk lists of a case, read as the DualSPHysics class that reads each one
# ---------------------------------------------------------------------------
LIST_FORM = 'mk values and ranges like "0-3,7"'


def range_filter_attr(reader, el, attr: str) -> list:
    """An mk list attribute read as DualSPHysics's JRangeFilter::Config reads it (the ``<chrono>`` body
    and ``<scaleforce>`` lists, ``<special><initialize>``'s, an ``<accinput>`` list): see
    :func:`parse_range_filter`. A list of blanks only (``" "``) is one item that atoi reads as 0.
    Each form read other than as written is warned about; letters, decimals, signs are an error.
    The list may come out empty (the caller says what that means)."""
    raw = reader.raw(el, attr, expected=LIST_FORM)                  # as written: blanks count
    if raw.strip().startswith("#"):
        raw = reader.text_attr(el, attr)                            # an expression's value
    if raw and not raw.strip():
        reader.warn(el, f"{attr}=\"{raw}\" (blanks only) is read as {attr} 0, as DualSPHysics reads it (its mk "
                        f"list parser turns the blank item into 0); write the {attr} you mean")
        return [0]
    try:
        mks, notes = parse_range_filter(raw)
    except ValueError as exc:
        raise reader.error(el, f"{attr}: {exc}", LIST_FORM) from None
    if notes:
        reader.warn(el, f"{attr}=\"{raw}\": " + "; ".join(notes) + ", as DualSPHysics's mk list parser (JRangeFilter) "
                        f"reads it, so the list is {format_mk_range(mks) or 'empty'}; write the {attr}s you mean")
    return mks


def prop_link_attr(reader, el, attr: str):
    """A ``<properties><links><link>`` list as DualSPHysics reads it: JCasePropLinks::AddLink drops every
    blank (``"1, ,3"`` is ``"1,,3"``) and drops the link whose list is then empty; GetProps reads the rest
    with JRangeFilter (:func:`parse_range_filter`). Returns the mk values, or None for a dropped link
    (warned). A blank inside a number (``"1 2"``, read as 12) is an error."""
    raw = reader.raw(el, attr, expected=LIST_FORM)
    if raw.strip().startswith("#"):
        raw = reader.text_attr(el, attr)
    if _blank_inside_number(raw):
        raise reader.error(el, f"{attr}=\"{raw}\": a blank inside a number (DualSPHysics drops every blank of a "
                               "<link> list, so it reads the digits as one number)", LIST_FORM)
    text = raw.replace(" ", "")
    if not text:
        reader.warn(el, f"{attr}=\"{raw}\" is empty: DualSPHysics drops this <link> (JCasePropLinks::AddLink), "
                        "and so does sphdvi; write the mks it links")
        return None
    try:
        mks, notes = parse_range_filter(text)
    except ValueError as exc:
        raise reader.error(el, f"{attr}: {exc}", LIST_FORM) from None
    if notes:
        reader.warn(el, f"{attr}=\"{raw}\": " + "; ".join(notes) + ", as DualSPHysics reads a <link> list (its blanks "
                        "dropped, then JRangeFilter), so the list is " + (format_mk_range(mks) or "empty")
                        + f"; write the {attr}s you mean")
    return mks


def _blank_inside_number(text: str) -> bool:
    """A digit, blanks, a digit: ``"1 2"`` (JCasePropLinks::AddLink would read 12)."""
    return re.search(r"[0-9] +[0-9]", text) is not None


def str_is_integer_number(text: str) -> bool:
    """DualSPHysics's fun::StrIsIntegerNumber: blanks (spaces, tabs), a sign, digits, blanks; a
    decimal part of zeros only (``"3.0"``) allowed; an empty or blank text counts as one (atoi: 0)."""
    point = text.rfind(".")
    if point > 0:
        if set(text[point + 1:]) <= {"0"}:
            text = text[:point]
        else:
            return False
    return re.fullmatch(r"[ \t]*([+-]?[0-9]+[ \t]*)?", text) is not None


def c_atoi(text: str) -> int:
    """C's atoi: leading blanks, a sign, the digits that follow (0 without any)."""
    m = re.match(r"\s*([+-]?[0-9]+)", text)
    return int(m.group(1)) if m else 0


def accinput_mk_attr(reader, el, attr: str) -> list:
    """``<accinput mkfluid>`` as JDsAccInput::ReadXml reads it: a single integer (fun::StrIsIntegerNumber:
    ``"3"``, ``"+3"``, ``"3.0"``; an empty or blank one is 0, warned) or an expression read as a 16-bit
    value (a negative one or one above 65535 an error); anything else a JRangeFilter list (see
    :func:`range_filter_attr`) that must give a value ("The mkfluid is invalid." otherwise)."""
    raw = reader.raw(el, attr, expected=LIST_FORM)
    if raw.strip().startswith("#"):
        return [reader.integer(el, attr, lo=0, hi=MAX_MK)]
    if str_is_integer_number(raw):
        value = c_atoi(raw)
        if not 0 <= value <= MAX_MK:
            raise reader.error(el, f"{attr}={raw!r} is not a 16-bit mk value", f"an integer 0 to {MAX_MK}")
        if not raw.strip():
            reader.warn(el, f"{attr}=\"{raw}\" is read as {attr} 0, as DualSPHysics reads it (JDsAccInput: an empty "
                            f"number is 0); write the {attr} you mean")
        return [value]
    mks = range_filter_attr(reader, el, attr)
    if not mks:
        raise reader.error(el, f"{attr}=\"{raw}\" gives no {attr} (DualSPHysics stops: \"The {attr} is invalid.\")",
                           LIST_FORM)
    return mks


def parse_filtermk(text: str) -> tuple[int, int, list[str]]:
    """An ``<outputparts><filtermk>`` value as JDsOutputPartsOp_Mk::ReadXmlExtra reads it: one mk ``a``
    or a range ``a-b`` (no commas), each read with atoi. Cut at each ``-`` as fun::StrSplitCount counts
    pieces, so ``a-`` is ``a`` alone, ``-b`` is ``0-b``, an empty value is 0, and ``b-a`` selects
    nothing. Returns (first, last, notes) with a note for each of these; ValueError for more than two
    pieces or what atoi would read as another number."""
    notes: list[str] = []
    pieces, rest = [], "" if text is None else str(text)
    while rest:
        piece, _, rest = rest.partition("-")
        pieces.append(piece)
    if len(pieces) > 2:
        raise ValueError(f"'{text}' has more than one '-'")
    if not pieces:
        notes.append("the empty value is read as 0")
        return 0, 0, notes
    if len(pieces) == 1:
        lo = _atoi_mk(pieces[0], "", text, text, notes)
        if text.endswith("-"):
            notes.append(f"'{text}' has no end value: read as {lo} alone")
        return lo, lo, notes
    blank_start = not pieces[0].strip()
    lo = 0 if blank_start else _atoi_mk(pieces[0], "start", text, text, notes)
    hi = _atoi_mk(pieces[1], "end", text, text, notes)
    if blank_start:
        notes.append(f"'{text}' has no start value: read as 0-{hi}")
    if text.endswith("-"):
        notes.append(f"the '-' ending '{text}' is ignored")
    if hi < lo:
        notes.append(f"'{text}' ends before it starts: it selects nothing")
    return lo, hi, notes
