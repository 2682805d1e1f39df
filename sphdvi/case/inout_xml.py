"""``<special><inout>``: DualSPHysics's inlet/outlet zones (JSphInOut, JSphInOutZone,
JSphInOutPoints, JSphInOutVel, JSphInOutZsurf; format ``doc/xml_format/_FmtXML_InOut.xml``,
v5 form), read into plain dicts that :mod:`sphdvi.sph.inout` turns into buffer zones.

Read as DualSPHysics v5 reads them:

* ``<inout>``: ``<determlimit value>`` (1e+3: zeroth order; 1e-3 first order),
  ``<useboxlimit value>`` (true); ``<memoryresize>``, ``<extrapolatemode>`` and
  ``<useboxlimit><freecentre>`` are accepted and have no effect (sphdvi grows its arrays as
  needed and extrapolates in double precision).
* ``<inoutzone>``: ``<refilling value>`` 0 simple full, 1 simple below zsurf, 2 advanced;
  ``<inputtreatment value>`` 0 no changes, 1 convert fluid, 2 remove fluid; ``<layers value>``
  1-250 (all three required, as v5); the zone, one of ``<zone2d>``/``<zone3d>`` with
  ``<particles mkfluid direction>`` (left, right, front, back, top, bottom or custom with
  ``<direction>``), ``<line>`` (2D: ``<point>``, ``<point2>``, optional ``<direction>``,
  ``<rotate>``), ``<box>`` (3D: ``<point>``, ``<size>`` with one zero component,
  ``<direction>``, optional ``<rotateaxis>``) or ``<circle>`` (3D: ``<point>``,
  ``<radius v>``, ``<direction>``, optional ``<rotateaxis>``).
* ``<imposevelocity mode>``: 0 fixed (``<velocity v>``, ``<velocity2 v v2 z z2>`` linear in z,
  ``<velocity3 v v2 v3 z z2 z3>`` parabolic in z), 1 variable (``<velocitytimes>``,
  ``<velocitytimes2>``, ``<velocitytimes3>`` of ``<timevalue>`` rows, or ``<velocityfile>``,
  ``<velocityfile2>``, ``<velocityfile3>``), 2 extrapolated.  Refused: 3 (interpolated from a
  grid or mesh file), ``<jetcircle>``, ``<flowvelocity active="true">``.
* ``<imposerhop mode>``: 0 rho0, 1 hydrostatic (from zsurf), 2 extrapolated.
* ``<imposezsurf mode>``: 0 fixed ``<zsurf value>``, 1 variable (``<zsurftimes>`` or
  ``<zsurffile>``), 2 calculated (``<zsurfmin value>``, ``<zsurffit value|valuedp>``); each with
  ``<remove value>``; ``<savevtk>`` accepted, no effect.

v4's elements (``<userefilling>``, ``<convertfluid>``, ``<zsurf>``/``<zbottom>`` in
``<imposerhop>``) are refused as v5 refuses them.
"""
import math

import numpy as np

from ..errors import CaseError
from .datafiles import check_rising_times, read_columns

ZONE_CHILDREN = {"refilling", "inputtreatment", "layers", "zone2d", "zone3d", "imposevelocity", "imposerhop",
                 "imposezsurf"}
DIRECTIONS = {"top": (0, 0, 1), "bottom": (0, 0, -1), "right": (1, 0, 0), "left": (-1, 0, 0),
              "back": (0, 1, 0), "front": (0, -1, 0)}
# velocity profiles and the columns of one row of each: v values, then z values
PROFILES = {"": ("v",), "2": ("v", "v2", "z", "z2"), "3": ("v", "v2", "v3", "z", "z2", "z3")}
PROFILE_NAMES = {"": "uniform", "2": "linear", "3": "parabolic"}


def read_inout(reader, el) -> dict:
    """``<special><inout>`` -> {"determlimit", "useboxlimit", "zones": [...]} (module docstring)."""
    reader.check_children(el, {"memoryresize", "useboxlimit", "determlimit", "extrapolatemode", "inoutzone",
                               "userefilling"})
    for attr in ("resizetime", "reuseids"):
        reader.mark(el, attr)
    old = reader.child(el, "userefilling")
    if old is not None:
        raise reader.error(old, "<userefilling> is not supported by the current inlet/outlet version "
                                "(DualSPHysics v5 refuses it too)", "<refilling value> in each <inoutzone>")
    box = reader.child(el, "useboxlimit")
    if box is not None:
        reader.check_children(box, {"freecentre"})
        for c in reader.children(box):
            reader.mark(c, "x", "y", "z")
    mem = reader.child(el, "memoryresize")
    if mem is not None:
        reader.mark(mem, "size0", "size")
    mode = reader.child(el, "extrapolatemode")
    out = {"determlimit": reader.child_value(el, "determlimit", 1e3, nonnegative=True),
           "useboxlimit": reader.boolean(box, "value", True) if box is not None else True,
           "extrapolatemode": int(reader.integer(mode, "value", lo=1, hi=3)) if mode is not None else 1,
           "zones": []}
    zones = reader.children(el, "inoutzone")
    if not zones:
        raise reader.error(el, "<inout> has no <inoutzone>", "one or more <inoutzone> elements")
    for z in zones:
        out["zones"].append(_read_zone(reader, z, len(out["zones"])))
    return out


def _read_zone(reader, z, index: int) -> dict:
    for tag, instead in (("convertfluid", "<inputtreatment value>"), ("userefilling", "<refilling value>")):
        old = reader.child(z, tag)
        if old is not None:
            raise reader.error(old, f"<{tag}> is not supported by the current inlet/outlet version "
                                    "(DualSPHysics v5 refuses it too)", instead)
    reader.check_children(z, ZONE_CHILDREN)
    zone = {"index": index, "line": z.sourceline,
            "refilling": _choice(reader, z, "refilling", 3),
            "inputtreatment": _choice(reader, z, "inputtreatment", 3),
            "layers": int(reader.integer(reader.child(z, "layers", True), "value", lo=1, hi=250))}
    shapes = [c for c in (reader.child(z, "zone2d"), reader.child(z, "zone3d")) if c is not None]
    if len(shapes) != 1:
        raise reader.error(z, "an <inoutzone> needs one <zone2d> or <zone3d>", "<zone2d> (2D) or <zone3d> (3D)")
    zone["dim"] = 2 if shapes[0].tag == "zone2d" else 3
    zone["shape"] = _read_shape(reader, shapes[0], zone["dim"])
    zone["velocity"] = _read_velocity(reader, reader.child(z, "imposevelocity", True))
    zone["rhop"] = _read_rhop(reader, reader.child(z, "imposerhop"))
    zone["zsurf"] = _read_zsurf(reader, reader.child(z, "imposezsurf"))
    _check_zone(reader, z, zone)
    return zone


def _choice(reader, z, tag: str, n: int) -> int:
    return int(reader.integer(reader.child(z, tag, True), "value", lo=0, hi=n - 1))


def _read_shape(reader, el, dim: int) -> dict:
    kids = [c for c in reader.children(el) if not c.tag.startswith("_")]
    allowed = {"particles", "line"} if dim == 2 else {"particles", "box", "circle"}
    if len(kids) != 1 or kids[0].tag not in allowed:
        raise reader.error(el, f"<{el.tag}> needs exactly one zone definition",
                           "one of " + ", ".join(f"<{a}>" for a in sorted(allowed)))
    c = kids[0]
    shape = {"kind": c.tag, "line": c.sourceline}
    if c.tag == "particles":
        reader.check_children(c, {"direction", "rotate"} if dim == 2 else {"direction", "rotateaxis"})
        shape["mkfluid"] = int(reader.integer(c, "mkfluid", lo=0))
        name = reader.text_attr(c, "direction", choices=set(DIRECTIONS) | {"custom"}).lower()
        if name == "custom":
            d = reader.child(c, "direction", True)
            shape["direction"] = _direction(reader, d, dim)
        else:
            if reader.child(c, "direction") is not None:
                raise reader.error(reader.child(c, "direction"), "<direction> is only read with direction=\"custom\"",
                                   "direction=\"custom\" or no <direction>")
            shape["direction"] = list(map(float, DIRECTIONS[name]))
            if dim == 2 and shape["direction"][1] != 0:
                raise reader.error(c, f"direction=\"{name}\" is along y, which a 2D case does not have",
                                   "left, right, top or bottom")
    elif c.tag == "line":
        reader.check_children(c, {"point", "point2", "direction", "rotate"})
        p1, p2 = (reader.child(c, t, True) for t in ("point", "point2"))
        shape["point"] = [reader.num(p1, "x"), 0.0, reader.num(p1, "z")]
        shape["point2"] = [reader.num(p2, "x"), 0.0, reader.num(p2, "z")]
        if np.allclose(shape["point"], shape["point2"]):
            raise reader.error(c, "<point> and <point2> are the same point", "two different points")
        d = reader.child(c, "direction")
        if d is not None:
            shape["direction"] = _direction(reader, d, 2)
        else:       # DualSPHysics: the line's normal (-vz, 0, vx)
            v = np.subtract(shape["point2"], shape["point"])
            shape["direction"] = (np.array([-v[2], 0.0, v[0]]) / np.linalg.norm(v)).tolist()
    elif c.tag == "box":
        reader.check_children(c, {"point", "size", "direction", "rotateaxis"})
        shape["point"] = reader.vec3(reader.child(c, "point", True)).tolist()
        size = reader.vec3(reader.child(c, "size", True))
        if np.count_nonzero(size) > 2 or np.any(size < 0):
            raise reader.error(reader.child(c, "size"), f"<size> is {size.tolist()}",
                               "sizes >= 0, one of them zero (the zone is a rectangle)")
        shape["size"] = size.tolist()
        shape["direction"] = _direction(reader, reader.child(c, "direction", True), 3)
    else:
        reader.check_children(c, {"point", "radius", "direction", "rotateaxis"})
        shape["point"] = reader.vec3(reader.child(c, "point", True)).tolist()
        shape["radius"] = reader.num(reader.child(c, "radius", True), "v", positive=True)
        shape["direction"] = _direction(reader, reader.child(c, "direction", True), 3)
    rot = reader.child(c, "rotate") if dim == 2 else reader.child(c, "rotateaxis")
    if rot is not None:
        shape["rotation"] = read_rotation(reader, rot, dim, shape)
    return shape


def _direction(reader, d, dim: int) -> list:
    v = np.array([reader.num(d, "x"), reader.num(d, "y", 0.0) if dim == 3 else 0.0, reader.num(d, "z")])
    n = float(np.linalg.norm(v))
    if n == 0.0:
        raise reader.error(d, "the direction vector is zero", "a non-zero vector into the fluid")
    return (v / n).tolist()


def _angle(reader, rot) -> float:
    units = reader.text_attr(rot, "anglesunits", "degrees", choices={"degrees", "radians"}).lower()
    a = reader.num(rot, "angle", 0.0)
    return a if units == "radians" else math.radians(a)


def read_rotation(reader, rot, dim: int, shape: dict) -> dict:
    """2D ``<rotate angle [centerx centerz] anglesunits>`` (about y through the centre, the first
    point by default; the particles' origin for ``<particles>``), 3D ``<rotateaxis angle
    anglesunits>`` with ``<point1>``, ``<point2>`` (JSphInOutPoints::ReadRotate2D/3D)."""
    angle = _angle(reader, rot)
    if dim == 2:
        reader.check_children(rot, set())
        if reader.has(rot, "centerx") or reader.has(rot, "centerz"):
            centre = [reader.num(rot, "centerx"), 0.0, reader.num(rot, "centerz")]
        else:
            centre = list(shape.get("point", [0.0, 0.0, 0.0]))
        return {"angle": angle, "p1": centre, "p2": [centre[0], 1.0, centre[2]]}
    reader.check_children(rot, {"point1", "point2"})
    p1, p2 = (reader.vec3(reader.child(rot, t, True)).tolist() for t in ("point1", "point2"))
    if np.allclose(p1, p2):
        raise reader.error(rot, "<point1> and <point2> of <rotateaxis> are the same point", "two different points")
    return {"angle": angle, "p1": p1, "p2": p2}


def table_rows(reader, lis, cols: tuple) -> list:
    rows = []
    for t in reader.children(lis, "timevalue"):
        rows.append([reader.num(t, "time")] + [reader.num(t, k) for k in cols])
    if not rows:
        raise reader.error(lis, f"<{lis.tag}> has no <timevalue> rows", "<timevalue time=.. v=../> rows")
    times = [r[0] for r in rows]
    bad = np.flatnonzero(np.diff(times) < 0)
    if bad.size:
        raise reader.error(lis, f"<{lis.tag}>: time {times[bad[0] + 1]:g} after {times[bad[0]]:g}",
                           "non-decreasing times")
    return rows


def _file_rows(reader, f, ncols: int, what: str) -> list:
    path = reader.resolve_path(f, "file")
    try:
        a = read_columns(path, ncols + 1, what)[:, :ncols + 1]
        if a.shape[0] < 1:
            raise CaseError(f"{what}: no data rows", file=path, expected=f"rows of {ncols + 1} numbers")
        check_rising_times(a[:, 0].tolist(), list(range(1, a.shape[0] + 1)), what, path)
    except CaseError as exc:
        where = path + (f":{exc.line}" if exc.line else "")
        raise reader.error(f, f"{where}: {exc.message}", exc.expected) from None
    return a.tolist()


def _read_velocity(reader, el) -> dict:
    mode = int(reader.integer(el, "mode", 0, lo=0, hi=3))
    if mode == 3:
        raise reader.error(el, "<imposevelocity mode=\"3\"> (velocity interpolated from a grid or mesh data file) "
                               "is not supported by sphdvi", "mode 0 (fixed), 1 (variable) or 2 (extrapolated)")
    flow = reader.child(el, "flowvelocity")
    if flow is not None:
        reader.mark(flow, "units", "ratio")
        if reader.boolean(flow, "active", False):
            raise reader.error(flow, "<flowvelocity active=\"true\"> (a flow rate instead of a velocity) is not "
                                     "supported by sphdvi", "a velocity in m/s")
    if mode == 2:
        for c in reader.children(el):
            if c.tag != "flowvelocity" and not c.tag.startswith("_"):
                # DualSPHysics v5 reads no child in mode 2 and ignores any (examples/inletoutlet/03_ReverseFlow
                # keeps a <velocity> there)
                reader.warn(c, f"<{c.tag}> is ignored: <imposevelocity mode=\"2\"> extrapolates the velocity")
                for a in c.keys():
                    reader.mark(c, a)
        return {"mode": 2}
    if mode == 0:
        reader.check_children(el, {"velocity", "velocity2", "velocity3", "jetcircle", "flowvelocity"})
        if reader.child(el, "jetcircle") is not None:
            raise reader.error(reader.child(el, "jetcircle"), "<jetcircle> is not supported by sphdvi",
                               "<velocity>, <velocity2> or <velocity3>")
        found = [s for s in PROFILES if reader.child(el, "velocity" + s) is not None]
        if len(found) > 1:
            raise reader.error(el, "several velocity definitions", "one of <velocity>, <velocity2>, <velocity3>")
        suffix = found[0] if found else ""
        v = reader.child(el, "velocity" + suffix, True)
        reader.mark(v, "time")
        row = [0.0] + [reader.num(v, k) for k in PROFILES[suffix]]
        rows = [row]
    else:
        reader.check_children(el, {"velocitytimes", "velocitytimes2", "velocitytimes3", "velocityfile",
                                   "velocityfile2", "velocityfile3", "flowvelocity"})
        found = [(kind, s) for kind in ("times", "file") for s in PROFILES
                 if reader.child(el, "velocity" + kind + s) is not None]
        if len(found) != 1:
            raise reader.error(el, "no variable velocity definition" if not found else "several velocity definitions",
                               "one of <velocitytimes[2|3]> or <velocityfile[2|3]>")
        kind, suffix = found[0]
        c = reader.child(el, "velocity" + kind + suffix)
        cols = PROFILES[suffix]
        rows = (table_rows(reader, c, cols) if kind == "times"
                else _file_rows(reader, c, len(cols), f"<velocityfile{suffix}>"))
    prof = {"mode": mode, "profile": PROFILE_NAMES[suffix], "rows": rows}
    for r in rows:
        zs = r[1 + len(PROFILES[suffix]) // 2:] if suffix else []
        if suffix and len(set(zs)) != len(zs):
            raise reader.error(el, f"the {PROFILE_NAMES[suffix]} profile's z values {zs} repeat",
                               "different z values")
    return prof


def _read_rhop(reader, el) -> dict:
    if el is None:
        return {"mode": 0}
    reader.check_children(el, {"zsurf", "zbottom"})
    for tag in ("zsurf", "zbottom"):
        if reader.child(el, tag) is not None:
            raise reader.error(reader.child(el, tag), f"<{tag}> in <imposerhop> is not supported by the current "
                               "inlet/outlet version (DualSPHysics v5 refuses it too)",
                               "<imposezsurf mode=\"0\"><zsurf value/></imposezsurf>")
    return {"mode": int(reader.integer(el, "mode", 0, lo=0, hi=2))}


def _read_zsurf(reader, el) -> dict:
    if el is None:
        return {"mode": None, "remove": False}
    mode = int(reader.integer(el, "mode", 0, lo=0, hi=2))
    out = {"mode": mode, "remove": reader.boolean(reader.child(el, "remove"), "value")
           if reader.child(el, "remove") is not None else False}
    if reader.child(el, "zbottom") is not None:
        reader.warn(reader.child(el, "zbottom"), "<zbottom> is ignored (DualSPHysics v5 ignores it too)")
        reader.mark(reader.child(el, "zbottom"), "value")
    sv = reader.child(el, "savevtk")
    if sv is not None:
        reader.mark(sv, "value")
    if mode == 0:
        reader.check_children(el, {"remove", "zsurf", "zbottom"})
        out["rows"] = [[0.0, reader.child_value(el, "zsurf")]]
    elif mode == 1:
        reader.check_children(el, {"remove", "savevtk", "zsurftimes", "zsurffile", "zbottom"})
        lis, f = reader.child(el, "zsurftimes"), reader.child(el, "zsurffile")
        if (lis is None) == (f is None):
            raise reader.error(el, "no variable zsurf definition" if lis is None else "several zsurf definitions",
                               "one of <zsurftimes> or <zsurffile>")
        out["rows"] = table_rows(reader, lis, ("zsurf",)) if lis is not None else _file_rows(reader, f, 1,
                                                                                                "<zsurffile>")
    else:
        reader.check_children(el, {"remove", "savevtk", "zsurfmin", "zsurffit", "zsurf", "zbottom"})
        if reader.child(el, "zsurf") is not None:
            reader.warn(reader.child(el, "zsurf"), "<zsurf> is ignored with mode 2 (DualSPHysics v5 ignores it too)")
            reader.mark(reader.child(el, "zsurf"), "value")
        out["zsurfmin"] = reader.child_value(el, "zsurfmin", None)
        fit = reader.child(el, "zsurffit")
        out["fit"] = {"valuedp": 0.5}
        if fit is not None:
            if reader.has(fit, "value") == reader.has(fit, "valuedp"):
                raise reader.error(fit, "<zsurffit> needs one of value or valuedp", "value=\"m\" or valuedp=\"n\"")
            out["fit"] = {k: reader.num(fit, k) for k in ("value", "valuedp") if reader.has(fit, k)}
    return out


def _check_zone(reader, z, zone: dict) -> None:
    """DualSPHysics's JSphInOutZone::CheckConfig errors (its warnings: see sphdvi.sph.inout)."""
    zs, vel = zone["zsurf"], zone["velocity"]
    if zone["rhop"]["mode"] == 1 and zs["mode"] is None:
        raise reader.error(z, "hydrostatic density (<imposerhop mode=\"1\">) needs a free-surface level",
                           "an <imposezsurf> element")
    if zs["mode"] in (1, 2) and zone["refilling"] == 1:
        raise reader.error(z, "refilling 1 (simple below zsurf) with a variable or calculated zsurf "
                              "(DualSPHysics: \"RefillingMode==SimpleZsurf is invalid\")", "refilling 0 or 2")
    if zs["mode"] in (1, 2) and zone["refilling"] == 0 and zs["remove"]:
        raise reader.error(z, "refilling 0 with a variable or calculated zsurf and <remove value=\"true\">",
                           "refilling 2, or remove false")
    behaviour = velocity_behaviour(vel)
    if zone["refilling"] in (0, 1) and behaviour == "reverse":
        raise reader.error(z, "refilling 0/1 (simple) is invalid for a velocity that changes sign (reverse flow)",
                           "refilling 2 (advanced)")
    if behaviour in ("reverse", "outlet") and zone["inputtreatment"] in (0, 2):
        what = "no changes" if zone["inputtreatment"] == 0 else "remove fluid"
        raise reader.error(z, f"inputtreatment {zone['inputtreatment']} ({what}) is invalid for an outflow",
                           "inputtreatment 1 (convert fluid)")


def velocity_behaviour(vel: dict) -> str:
    """inlet (velocities >= 0 into the fluid), outlet (<= 0), reverse (both) or unknown
    (extrapolated): JSphInOutVel::DefineBehaviour."""
    if vel["mode"] == 2:
        return "unknown"
    n = {"uniform": 1, "linear": 2, "parabolic": 3}[vel["profile"]]
    values = [v for r in vel["rows"] for v in r[1:1 + n]]
    lo, hi = min(values), max(values)
    if lo >= 0 and hi >= 0:
        return "inlet"
    if lo <= 0 and hi <= 0:
        return "outlet"
    return "reverse"



def read_boundcorr(reader, el) -> dict:
    """``<special><boundcorr>`` (DualSPHysics's JSphBoundCorr, "used in combination with InOut"):
    the density of the listed fixed or moving walls extrapolated from the fluid at each particle's
    ghost node mirrored through a limit plane (:func:`sphdvi.sph.inout.boundcorr_normals`).
    ``<determlimit value>`` (1e+3, as JSphBoundCorr::ReadXml's default: zeroth order; 1e-3 first
    order), ``<extrapolatemode>`` accepted, no effect; each ``<mkzone mkbound>`` (a list of values
    and ranges) with ``<autoconfig direction>`` (the plane dp/2 beyond the mk's particles on that
    side), ``<limitpoint>`` + ``<direction>``, or ``<autolimitpoint dpfactor>`` + ``<direction>`` (the
    plane dpfactor dp beyond the particle furthest along the direction)."""
    from .mkrange import parse_mk_range
    reader.check_children(el, {"determlimit", "extrapolatemode", "mkzone"})
    mode = reader.child(el, "extrapolatemode")
    if mode is not None:
        reader.integer(mode, "value", lo=1, hi=3)
    out = {"determlimit": reader.child_value(el, "determlimit", 1e3, nonnegative=True), "zones": []}
    seen = set()
    for z in reader.children(el, "mkzone"):
        reader.check_children(z, {"autoconfig", "limitpoint", "direction", "autolimitpoint"})
        text = reader.text_attr(z, "mkbound")
        try:
            mks = parse_mk_range(text)
        except ValueError as exc:
            raise reader.error(z, f"mkbound=\"{text}\": {exc}", "mkbound values and ranges such as 2,4-6") from None
        again = sorted(seen & set(mks))
        if again:
            raise reader.error(z, f"mkbound {again[0]} is in two <mkzone> (DualSPHysics: \"An input already exists "
                                  "for the same mkbound.\")", "each mkbound in one <mkzone>")
        seen |= set(mks)
        zone = {"mkbound": mks, "line": z.sourceline}
        auto = reader.child(z, "autoconfig")
        if auto is not None:
            name = reader.text_attr(auto, "direction", choices=set(DIRECTIONS)).lower()
            zone["auto"] = name
            zone["direction"] = list(map(float, DIRECTIONS[name]))
        else:
            d = reader.vec3(reader.child(z, "direction", True))
            if not np.any(d):
                raise reader.error(reader.child(z, "direction"), "the direction is zero", "a vector to the fluid")
            zone["direction"] = (d / np.linalg.norm(d)).tolist()
            lim = reader.child(z, "autolimitpoint")
            if lim is not None:
                zone["dpfactor"] = reader.num(lim, "dpfactor", 0.5)
            else:
                zone["limitpoint"] = reader.vec3(reader.child(z, "limitpoint", True)).tolist()
        out["zones"].append(zone)
    if not out["zones"]:
        raise reader.error(el, "<boundcorr> has no <mkzone>", "one or more <mkzone mkbound> elements")
    return out
