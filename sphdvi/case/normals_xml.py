"""Reading the mDBC normal definitions of a case: GenCase's ``<casedef><normals>`` (norset,
norplane, norsphere, norcylinder, norparts, norgeometry; also the v5.0 form with
``<geometryfile>`` and ``<distanceh>`` directly inside) and the solver's
``<execution><special><initialize>`` (boundnormal_set, _plane, _sphere, _cylinder,
_parts, and fluidvelocity). Each becomes a plain dict that
:func:`sphdvi.case.normal_ops.apply_normal_ops` applies; the element names and defaults
are DualSPHysics's (``maxdisth`` 2, ``limitdist`` 0.5 dp, ``clear`` true, ``distanceh`` 2).
"""
from __future__ import annotations

from .mkrange import format_mk_range, parse_mk_range, range_filter_attr

GENCASE_TAGS = {"norset": "set", "norplane": "plane", "norsphere": "sphere", "norcylinder": "cylinder",
                "norparts": "parts", "norgeometry": "geometry"}
INITIALIZE_TAGS = {"boundnormal_set": "set", "boundnormal_plane": "plane", "boundnormal_sphere": "sphere",
                   "boundnormal_cylinder": "cylinder", "boundnormal_parts": "parts"}
CHILDREN = {
    "set": {"onlypos", "normal"},
    "plane": {"onlypos", "point", "limitdist", "normal", "maxdisth", "clear"},
    "sphere": {"onlypos", "center", "radius", "inside", "maxdisth", "clear"},
    "cylinder": {"onlypos", "center1", "center2", "radius", "inside", "limit1", "limit2", "maxdisth", "clear"},
    "parts": {"onlypos", "maxdisth"},
    "geometry": {"geometryfile", "distanceh", "maxsizeh", "svshapes"},
}


def _scalar_el(reader, el, tag, default, kind="num", **checks):
    """The ``v`` (or ``value``) attribute of child ``<tag>``: DualSPHysics's scalar elements."""
    c = reader.child(el, tag)
    if c is None:
        if default is None:
            raise reader.error(el, f"missing child element <{tag}>", f'<{tag} v="..."/>')
        return default
    attr = "v" if c.get("v") is not None or c.get("value") is None else "value"
    if kind == "bool":
        return reader.boolean(c, attr)
    return reader.num(c, attr, **checks)


def _vector(reader, el, tag):
    c = reader.child(el, tag, required=True)
    return reader.vec3(c).tolist()


def read_onlypos(reader, el):
    """``<onlypos><posmin x y z/><posmax x y z/></onlypos>`` of ``el``: {"posmin": [...], "posmax":
    [...]} with None for a bound not given (open), or None without the element."""
    box = reader.child(el, "onlypos")
    if box is None:
        return None
    reader.check_children(box, {"posmin", "posmax", "rem"})
    out = {}
    for tag in ("posmin", "posmax"):
        c = reader.child(box, tag)
        out[tag] = [reader.num(c, k) if c is not None and c.get(k) is not None else None for k in "xyz"]
    return out


def _mkbound(reader, el, required: bool) -> str:
    text = el.get("mkbound")
    reader.mark(el, "mkbound")
    if text is None or not text.strip():
        if required:
            raise reader.error(el, "missing attribute 'mkbound'", 'the mkbound values it applies to, e.g. mkbound="0-3,7"')
        return ""
    try:
        parse_mk_range(text)
    except ValueError as exc:
        raise reader.error(el, f"mkbound={text!r}: {exc}", 'mkbound values and ranges such as mkbound="0-3,7"') from None
    return text.strip()


def _initialize_mks(reader, el, attr: str, required: bool):
    """The mk list of a ``<special><initialize>`` operation as JDsInitializeOp_*::ReadXml reads it: an
    optional attribute (GetAttributeStr), none or empty meaning every boundary (fluid for
    ``mkfluid``), anything else a JRangeFilter list (:func:`~sphdvi.case.mkrange.range_filter_attr`).
    ``required`` (boundnormal_plane, whose Run loops over the list's values only): no list is no
    particle. Returns the list as ``"0-3,7"``, ``""`` for all, None for an operation that acts on no
    particle (warned: DualSPHysics runs it on nothing, sphdvi drops it)."""
    text = el.get(attr)
    reader.mark(el, attr)
    if not text:
        if not required:
            return ""
        reader.warn(el, f"no {attr} (or {attr}=\"\"): DualSPHysics's <{el.tag}> computes the normals of its listed "
                        f"{attr}s only, so it does nothing, nor does sphdvi; give the {attr}s, e.g. {attr}=\"0\"")
        return None
    mks = range_filter_attr(reader, el, attr)
    if not mks:
        reader.warn(el, f"{attr}=\"{text}\" gives no {attr}: this <{el.tag}> acts on no particle and is skipped, as "
                        "it does nothing in DualSPHysics")
        return None
    return format_mk_range(mks)


def _nonzero(reader, el, tag, vec):
    if not any(vec):
        raise reader.error(reader.child(el, tag), f"<{tag}> is the zero vector", "a non-zero direction")
    return vec


def read_normal_op(reader, el, kind: str, solver: bool = False) -> dict | None:
    """One normals operation (see the module docstring) as a dict: ``kind``, ``tag``,
    ``line``, ``mkbound`` (``""``: every boundary), ``onlypos`` and the kind's fields. ``solver``:
    an ``<initialize>`` one, whose mkbound list DualSPHysics reads with JRangeFilter (None: one that
    acts on no particle); GenCase's ``<normals>`` lists keep the strict form (GenCase's reader is
    not public)."""
    reader.check_children(el, CHILDREN[kind] | {"rem"})
    required = kind == "plane"
    mkbound = _initialize_mks(reader, el, "mkbound", required) if solver else _mkbound(reader, el, required)
    op = {"kind": kind, "tag": el.tag, "line": el.sourceline, "mkbound": mkbound}
    op["onlypos"] = read_onlypos(reader, el) if kind != "geometry" else None
    if kind in ("plane", "sphere", "cylinder", "parts"):
        op["maxdisth"] = _scalar_el(reader, el, "maxdisth", 2.0)
    if kind in ("plane", "sphere", "cylinder"):
        op["clear"] = _scalar_el(reader, el, "clear", True, "bool")
    if kind == "set":
        op["normal"] = _vector(reader, el, "normal")
    elif kind == "plane":
        op["normal"] = _nonzero(reader, el, "normal", _vector(reader, el, "normal"))
        point = reader.child(el, "point")
        auto = point is not None and reader.boolean(point, "auto", False)
        if point is None and not auto:
            raise reader.error(el, "missing child element <point>", '<point x=".." y=".." z=".."/> or <point auto="true"/>')
        op["point"] = None if auto else reader.vec3(point).tolist()
        limit = reader.child(el, "limitdist")            # <limitdist vdp="0.5"/>: in dp
        op["limitdist"] = 0.5 if limit is None else reader.num(limit, "vdp" if limit.get("v") is None else "v")
    elif kind == "sphere":
        op["center"] = _vector(reader, el, "center")
        op["radius"] = _scalar_el(reader, el, "radius", None, positive=True)
        op["inside"] = _scalar_el(reader, el, "inside", None, "bool")
    elif kind == "cylinder":
        op["center1"] = _vector(reader, el, "center1")
        op["center2"] = _vector(reader, el, "center2")
        if op["center1"] == op["center2"]:
            raise reader.error(reader.child(el, "center2"), "center2 is center1", "the two ends of the cylinder's axis")
        op["radius"] = _scalar_el(reader, el, "radius", None, positive=True)
        op["inside"] = _scalar_el(reader, el, "inside", None, "bool")
        op["limit1"] = _scalar_el(reader, el, "limit1", True, "bool")
        op["limit2"] = _scalar_el(reader, el, "limit2", True, "bool")
    elif kind == "geometry":
        geo = reader.child(el, "geometryfile", required=True)
        op["file"] = reader.text_attr(geo, "file")
        if not op["file"]:
            raise reader.error(geo, "empty file name", 'a shape file, e.g. file="[CaseName]_hdp_Actual.vtk"')
        op["distanceh"] = _scalar_el(reader, el, "distanceh", 2.0, positive=True)
        # GenCase v5.4: "Maximum allowed normal size (H*value) (disabled=0, default=0)"
        op["maxsizeh"] = _scalar_el(reader, el, "maxsizeh", 0.0)
        if op["maxsizeh"] < 0:
            raise reader.error(reader.child(el, "maxsizeh"), f"maxsizeh {op['maxsizeh']:g} is negative",
                               "0 (no limit) or a positive multiple of h")
        if reader.child(el, "svshapes") is not None:
            _scalar_el(reader, el, "svshapes", False, "bool")
    return None if mkbound is None else op          # read whole (its errors count), then dropped


def read_normals(reader, casedef) -> list:
    """``<casedef><normals>``: the operations in document order (v5.0's bare ``<geometryfile>``
    with ``<distanceh>`` beside it is one ``geometry`` operation)."""
    el = reader.child(casedef, "normals")
    if el is None:
        return []
    reader.check_children(el, set(GENCASE_TAGS) | {"geometryfile", "distanceh", "svshapes", "rem"})
    ops = []
    for c in reader.children(el):
        if c.tag in GENCASE_TAGS:
            ops.append(read_normal_op(reader, c, GENCASE_TAGS[c.tag]))
        elif c.tag == "geometryfile":
            op = {"kind": "geometry", "tag": "normals", "line": c.sourceline, "mkbound": "", "onlypos": None,
                  "file": reader.text_attr(c, "file"),
                  "distanceh": _scalar_el(reader, el, "distanceh", 2.0, positive=True)}
            ops.append(op)
        elif c.tag == "svshapes":      # GenCase's debug VTK of the shapes' normals: read, not written
            _scalar_el(reader, el, "svshapes", False, "bool")
    return ops


def read_initialize(reader, el) -> dict:
    """``<special><initialize>``: {"normals": [operations], "velocity": [<initials> velocity
    items]} in document order."""
    reader.check_children(el, set(INITIALIZE_TAGS) | {"fluidvelocity", "rem"})
    out = {"normals": [], "velocity": []}
    for c in reader.children(el):
        if c.tag in INITIALIZE_TAGS:
            op = read_normal_op(reader, c, INITIALIZE_TAGS[c.tag], solver=True)
            if op is not None:
                out["normals"].append(op)
        elif c.tag == "fluidvelocity":
            item = read_fluid_velocity(reader, c)
            if item is not None:
                out["velocity"].append(item)
    return out


def read_fluid_velocity(reader, el) -> dict | None:
    """``<fluidvelocity mkfluid>``: a velocity along ``<direction>``, uniform (``<velocity v>``),
    linear in z (``<velocity2 v v2 z z2>``) or parabolic (``<velocity3 ...>``); the item form
    of ``<initials><velocity>``. The mkfluid list as JDsInitializeOp_FluidVel reads it (none or
    empty: every fluid particle; see :func:`_initialize_mks`); None for one that gives no mkfluid."""
    reader.check_children(el, {"onlypos", "direction", "velocity", "velocity2", "velocity3", "rem"})
    item = {"type": "velocity", "element": el.tag, "line": el.sourceline}
    listed = _initialize_mks(reader, el, "mkfluid", False)
    item["mkfluid"] = parse_mk_range(listed) if listed else None    # None: every fluid particle
    box = read_onlypos(reader, el)
    if box is not None:
        item["onlypos"] = box
    item["direction"] = _nonzero(reader, el, "direction", _vector(reader, el, "direction"))
    item["profile"], item["params"] = read_velocity_profile(reader, el)
    return None if listed is None else item


VELOCITY_PROFILES = {"velocity": ("v",), "velocity2": ("v", "v2", "z", "z2"),
                     "velocity3": ("v", "v2", "v3", "z", "z2", "z3")}


def read_velocity_profile(reader, el) -> tuple:
    """The one velocity profile of ``el`` (``<fluidvelocity>``, or ``<initials><velocity>`` with a
    ``<direction>``): ``<velocity v>``, ``<velocity2 v v2 z z2>`` or ``<velocity3 v v2 v3 z z2 z3>``,
    every attribute required, the heights distinct (JDsInitializeOp_FluidVel::ReadXml; equal
    heights leave the line or parabola undefined). Returns (profile tag, {name: value})."""
    given = [t for t in VELOCITY_PROFILES if reader.child(el, t) is not None]
    if len(given) > 1:
        raise reader.error(reader.child(el, given[1]), "several velocity profiles", "one of <velocity>, <velocity2>, <velocity3>")
    if not given:
        raise reader.error(el, "missing velocity profile", '<velocity v=".."/>, <velocity2 .../> or <velocity3 .../>')
    p = reader.child(el, given[0])
    params = {k: reader.num(p, k) for k in VELOCITY_PROFILES[given[0]]}
    zs = [params[k] for k in ("z", "z2", "z3") if k in params]
    if len(set(zs)) < len(zs):
        raise reader.error(p, f"the heights z of <{given[0]}> repeat", "distinct heights z, z2 (, z3)")
    return given[0], params
