"""``<special>`` sections that choose what a run writes, as DualSPHysics reads them:

* ``<savedt>`` (DualSPHysics's JSaveDt): statistics of the time step in ``DtInfo.csv``
  every ``interval`` (and every step in ``DtAllInfo.csv`` with ``alldt``);
* ``<outputparts>`` (JDsOutputParts, v5.2 on): which particles the particle output holds,
  a preselection (all or none) followed by filters that add, delete or confirm particles
  by position (box, plane, sphere, cylinder, any of them following a floating body),
  type, mk, or by a nested group of filters.

Both become plain dicts for the case's JSON; :mod:`sphdvi.output_parts` and
:mod:`sphdvi.io.dtinfo` use them at run time.
"""
from __future__ import annotations

import numpy as np

from ..errors import CaseError
from .mkrange import parse_filtermk

OPERATIONS = ("add", "del", "confirm")
PARTICLE_TYPES = ("fixed", "moving", "floating", "fluid", "bound")
MAX_GROUP_LEVELS = 7          # DualSPHysics's limit on nested <filtergroup>


def read_savedt(reader, el) -> dict:
    """``<savedt>``: ``start`` (0), ``finish`` (none: to the end), ``interval`` (none: TimeOut),
    ``fullinfo`` and ``alldt`` (false)."""
    allowed = {"start", "finish", "interval", "fullinfo", "alldt"}
    for c in reader.children(el):
        if c.tag not in allowed:
            raise reader.error(c, f"unknown element <{c.tag}> in <savedt>",
                               "one of " + ", ".join(f"<{k}>" for k in sorted(allowed)))
    d = {"line": el.sourceline, "start": 0.0, "finish": None, "interval": None, "fullinfo": False, "alldt": False}
    c = reader.child(el, "start")
    if c is not None:
        d["start"] = reader.num(c, "value")
    c = reader.child(el, "finish")
    if c is not None:
        finish = reader.num(c, "value")
        d["finish"] = finish if finish > 0 else None      # DualSPHysics: 0 or less, no end
        if d["finish"] is not None and d["finish"] < d["start"]:
            raise reader.error(c, f"finish={finish:g} is before start={d['start']:g}",
                               "finish >= start (or 0: to the end of the run)")
    c = reader.child(el, "interval")
    if c is not None:
        interval = reader.num(c, "value")
        if interval == 0:
            raise reader.error(c, "interval=0", "a time > 0 between rows, or a negative value (or no <interval>) "
                               "for TimeOut")
        d["interval"] = interval if interval > 0 else None
    for key in ("fullinfo", "alldt"):
        c = reader.child(el, key)
        if c is not None:
            d[key] = reader.boolean(c, "value")
    return d


def read_outputparts(reader, el) -> dict:
    """``<outputparts preselection="all|none">`` with ``<ignore nparts>`` and filters."""
    d = _read_group(reader, el, level=0)
    d["line"] = el.sourceline
    ignore = reader.child(el, "ignore")
    d["ignore"] = reader.integer(ignore, "nparts", 0, lo=0) if ignore is not None else 0
    return d


def _read_group(reader, el, level: int) -> dict:
    presel = reader.text_attr(el, "preselection", choices=("all", "none")).lower()
    filters = []
    for c in reader.children(el):
        if c.tag == "ignore":
            if level:
                raise reader.error(c, "<ignore> inside a <filtergroup>", "<ignore> directly in <outputparts>")
            continue
        if c.tag not in FILTER_READERS:
            raise reader.error(c, f"unknown element <{c.tag}> in <{el.tag}>",
                               "<ignore> or one of " + ", ".join(f"<{k}>" for k in FILTER_READERS))
        f = {"kind": c.tag[len("filter"):], "line": c.sourceline,
             "operation": reader.text_attr(c, "operation", choices=OPERATIONS).lower(),
             "inverse": reader.boolean(c, "inverse", False)}
        if c.tag == "filtergroup":
            if level + 1 >= MAX_GROUP_LEVELS:
                raise reader.error(c, f"<filtergroup> nested {level + 1} deep",
                                   f"at most {MAX_GROUP_LEVELS - 1} levels of <filtergroup>")
            f.update(_read_group(reader, c, level + 1))
        else:
            f.update(FILTER_READERS[c.tag](reader, c))
        filters.append(f)
    return {"preselection": presel, "filters": filters}


def _check_children(reader, el, allowed: set) -> None:
    for c in reader.children(el):
        if c.tag not in allowed:
            raise reader.error(c, f"unknown element <{c.tag}> in <{el.tag}>",
                               "one of " + ", ".join(f"<{k}>" for k in sorted(allowed)))


def _ftfollow(reader, el) -> dict:
    """``<ftfollow mkbound="..."/>`` (or ``mk``): the floating body the filter moves with."""
    c = reader.child(el, "ftfollow")
    if c is None:
        return {"ftfollow": None}
    mkb = reader.integer(c, "mkbound", None, lo=0)
    mk = reader.integer(c, "mk", None, lo=1)
    if (mkb is None) == (mk is None):
        raise reader.error(c, "<ftfollow> needs one of mkbound and mk" + (" (not both)" if mkb is not None else ""),
                           'mkbound="N" (or mk="N") of a floating body')
    return {"ftfollow": {"mkbound": mkb} if mkb is not None else {"mk": mk}}


def _point(reader, el, tag: str, required: bool = True):
    c = reader.child(el, tag, required=required)
    return None if c is None else reader.vec3(c).tolist()


def _positive(reader, el, tag: str, attr: str = "v", required: bool = True):
    c = reader.child(el, tag, required=required)
    return None if c is None else reader.num(c, attr, positive=True)


def _read_pos(reader, el) -> dict:
    _check_children(reader, el, {"posmin", "posmax", "ftfollow"})
    d = _ftfollow(reader, el)
    for tag in ("posmin", "posmax"):
        c = reader.child(el, tag)
        d[tag] = [None if c is None else reader.num(c, k, None) for k in "xyz"]
    if all(v is None for v in d["posmin"] + d["posmax"]):
        raise reader.error(el, "<filterpos> limits nothing", '<posmin x="..."/> and/or <posmax .../>')
    lo = [-np.inf if v is None else v for v in d["posmin"]]
    hi = [np.inf if v is None else v for v in d["posmax"]]
    if any(a > b for a, b in zip(lo, hi)):
        raise reader.error(el, f"posmin {d['posmin']} is above posmax {d['posmax']}", "posmin <= posmax")
    return d


def _read_plane(reader, el) -> dict:
    _check_children(reader, el, {"point", "vector", "distance", "ftfollow"})
    d = _ftfollow(reader, el)
    d["point"] = _point(reader, el, "point")
    d["vector"] = _point(reader, el, "vector")
    if not np.any(d["vector"]):
        raise reader.error(reader.child(el, "vector"), "the plane's vector is zero", "the plane's normal vector")
    d["distance"] = _positive(reader, el, "distance", required=False)
    return d


def _read_sphere(reader, el) -> dict:
    _check_children(reader, el, {"centre", "radius", "ftfollow"})
    d = _ftfollow(reader, el)
    d["centre"] = _point(reader, el, "centre", required=d["ftfollow"] is None)   # a followed body's centre
    # JDsOutputPartsOp_Cylinder: <radius> is optional (DBL_MAX: the slab between the end planes)
    d["radius"] = _positive(reader, el, "radius") if reader.child(el, "radius") is not None else None
    return d


def _read_cylinder(reader, el) -> dict:
    _check_children(reader, el, {"point1", "point2", "radius", "ftfollow"})
    d = _ftfollow(reader, el)
    d["point1"], d["point2"] = _point(reader, el, "point1"), _point(reader, el, "point2")
    if np.allclose(d["point1"], d["point2"], rtol=0, atol=0):
        raise reader.error(el, "point1 equals point2", "the two ends of the cylinder's axis")
    # JDsOutputPartsOp_Cylinder: <radius> is optional (DBL_MAX: the slab between the end planes)
    d["radius"] = _positive(reader, el, "radius") if reader.child(el, "radius") is not None else None
    return d


def _read_type(reader, el) -> dict:
    _check_children(reader, el, {"type"})
    c = reader.child(el, "type", required=True)
    raw = reader.text_attr(c, "v")
    types = [t.strip().lower() for t in raw.split(",")]
    bad = [t for t in types if t not in PARTICLE_TYPES]
    if bad:
        raise reader.error(c, f"particle type '{bad[0]}' in v={raw!r}", "a list of " + ", ".join(PARTICLE_TYPES))
    return {"types": sorted(set(types))}


def _read_mk(reader, el) -> dict:
    _check_children(reader, el, {"mk", "mkbound", "mkfluid"})
    given = [tag for tag in ("mk", "mkbound", "mkfluid") if reader.child(el, tag) is not None]
    if len(given) != 1:
        raise reader.error(el, "<filtermk> needs one of <mk>, <mkbound> and <mkfluid>" +
                           (f" (it has {', '.join(given)})" if given else ""), '<mkbound v="20-25"/> for example')
    c = reader.child(el, given[0])
    raw = reader.text_attr(c, "v", "")
    try:
        lo, hi, notes = parse_filtermk(raw)
    except ValueError as exc:
        raise reader.error(c, f"v={raw!r} is not an mk value or range ({exc})",
                           'a value "10" or a range "10-15"') from None
    if notes:
        head = f"v=\"{raw}\": " + "; ".join(notes) if c.get("v") is not None else "no v: read as 0"
        chosen = "nothing" if hi < lo else f"{given[0]} {lo}" + ("" if lo == hi else f"-{hi}")
        reader.warn(c, head + f", as DualSPHysics reads it (JDsOutputPartsOp_Mk), so the filter selects {chosen}; "
                              f"write the {given[0]} you mean")
    return {"field": given[0], "lo": lo, "hi": hi}


FILTER_READERS = {"filterpos": _read_pos, "filterplane": _read_plane, "filtersphere": _read_sphere,
                  "filtercylinder": _read_cylinder, "filtertype": _read_type, "filtermk": _read_mk,
                  "filtergroup": None}


def check_outputparts(spec: dict, label: np.ndarray, ptype: np.ndarray, mk: np.ndarray, floating_mkbounds: dict,
                      fluidcount: int, file: str) -> None:
    """Semantic checks that need the particles: every mk a filter names is drawn (as
    DualSPHysics requires of a range's two ends), every followed body is a floating one
    (``floating_mkbounds``: mkbound -> initial centre, which the filter keeps; a sphere
    without a centre takes it)."""
    for f in _walk(spec["filters"]):
        if f["kind"] == "mk":
            if f["field"] == "mk":
                drawn = set(np.unique(mk).tolist())
            else:
                drawn = set(np.unique(label[(ptype == 3) == (f["field"] == "mkfluid")]).tolist())
            for v in {f["lo"], f["hi"]}:
                if v not in drawn:
                    raise CaseError(f"<filtermk> selects {f['field']} {v}, which has no particles", file=file,
                                    line=f["line"], element="filtermk", expected=f"a {f['field']} the geometry draws")
            _check_mk_range_type(f, label, ptype, mk, file)
        follow = f.get("ftfollow")
        if follow:
            mkb = follow.get("mkbound", follow.get("mk", 0) - fluidcount - 1)
            if mkb not in floating_mkbounds:
                what = f"mkbound {mkb}" if "mkbound" in follow else f"mk {follow['mk']} (mkbound {mkb})"
                raise CaseError(f"<ftfollow> {what} is not a floating body", file=file, line=f["line"],
                                element="filter" + f["kind"], expected="the mkbound of a body in <floatings>")
            follow["mkbound"] = mkb
            follow["centre0"] = list(floating_mkbounds[mkb])      # the filter moves as the centre does
            if f["kind"] == "sphere" and f["centre"] is None:
                f["centre"] = follow["centre0"]


def _check_mk_range_type(f: dict, label: np.ndarray, ptype: np.ndarray, mk: np.ndarray, file: str) -> None:
    """The two ends of a ``<filtermk>`` range are particles of one type (fixed, moving, floating or
    fluid), as JDsOutputPartsOp_Mk::ReadXmlExtra requires of the mk blocks of its ends ("The values
    of the mk range include different types of particles."): a range from fluid to boundary, or from
    a fixed to a floating mkbound, is refused at gencase. Their type is kept in ``f["ptype"]``: DualSPHysics
    selects the particle codes between the two ends' blocks, all of that type, so a block of another type
    whose mk lies inside the range is not selected."""
    from .gencase import TYPE_FIXED, TYPE_FLOATING, TYPE_FLUID, TYPE_MOVING
    if f["field"] == "mkfluid":
        f["ptype"] = TYPE_FLUID
        return
    names = {TYPE_FIXED: "fixed", TYPE_MOVING: "moving", TYPE_FLOATING: "floating", TYPE_FLUID: "fluid"}
    ends = {}
    for v in (f["lo"], f["hi"]):
        sel = (mk == v) if f["field"] == "mk" else ((ptype != TYPE_FLUID) & (label == v))
        ends[v] = names[int(ptype[sel][0])]
        f["ptype"] = int(ptype[sel][0])     # the selection keeps to it (output_parts._mk)
    if len(set(ends.values())) > 1:
        what = " and ".join(f"{f['field']} {v} is {t}" for v, t in ends.items())
        raise CaseError(f"<filtermk> range {f['field']} {f['lo']}-{f['hi']} includes different types of particles "
                        f"({what}): DualSPHysics stops (\"The values of the mk range include different types of "
                        f"particles.\")", file=file, line=f["line"], element="filtermk",
                        expected="a range whose two ends are of one type (fixed, moving, floating or fluid); "
                                 "one <filtermk> per type for the others")


def _walk(filters):
    for f in filters:
        yield f
        if f["kind"] == "group":
            yield from _walk(f["filters"])
