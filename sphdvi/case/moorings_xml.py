"""``<special><moorings>``: DualSPHysics's moored floatings (JDsMooredFloatings) and the
configuration of its mooring-line library MoorDynPlus (v5.4), read into one plain dict for the
lumped-mass line model of :mod:`sphdvi.moorings`.

* ``<moorings>``: ``<savevtk_lines>``, ``<savevtk_moorings>``, ``<savecsv_points>`` (value, true
  by default) and ``<savevtk_points>`` (false); ``<start value ramptime>`` (0, 0: the ramp of the
  force given to the bodies); ``<mooredfloatings>`` with one ``<floating mkbound>`` per moored
  floating (at least one; no repeats).
* ``<moordynplus>`` in the case file, or ``<moordynplus file="x.xml"/>`` naming a file (relative to
  the case file's folder) whose root is ``<moordynplus>``. DualSPHysics 5.0-5.2 files call it
  ``<moordyn>``: read as ``<moordynplus>``, with a warning (DualSPHysics 5.4 refuses it).
* ``<solverOptions>`` (required): ``<name value>`` items, their names in any case: waterDepth
  (required), freesurface, kBot, cBot, dtM (and its ``auto``), waveKin, writeUnits,
  frictionCoefficient, fricDamp, statDynFricScale, rho, cdScaleIC, dtIC, tmaxIC, threshIC, with
  MoorDynPlus's defaults (:data:`SOLVER`).
* ``<bodies>``: ``<body ref>`` (ref: the body's index when absent) with an optional ``<depth
  value>``; DualSPHysics addresses the bodies by the index of the moored floatings sorted by
  mkbound, so the refs must be the moored floatings' mkbounds, each once.
* ``<lines>`` (required): an optional ``<linedefault>`` and the ``<line>`` items (numbered 0, 1, ..
  in the file's order), whose ``<name value>`` items override the default's (:data:`LINE_PARAMS`):
  one of ``ea`` or ``e`` (EA = E·πD²/4), diameter and massDenInAir (required), ba, can, cat, cdn,
  cdt, breaktension, length and segments (required in effect), outputFlags, and on a line only
  ``depth`` (else its body's depth, else waterDepth). Each line has two ends, ``<fixconnection x y
  z>`` (an anchor) or ``<vesselconnection bodyref x y z>`` (a point of a body, in world coordinates
  at t = 0; the tags are matched by their first letters, "fix" and "vessel", in any case), each
  with an optional mass ``M`` and volume ``V``. End 0 (the "anchor", node 0) is the fixed end, or
  of two vessel ends the lower (the first listed on a tie); end 1 (the "fairlead") is node N.
  ``savedata`` (or v2020's ``output``): the line's columns in the MoorDynPlus CSV files.
* ``<savedata>`` (or its old name ``<output>``): ``<time starTime endTime dtOut>`` (sic; 0, to the
  end, the run's TimeOut) and the magnitudes ``<tension>``, ``<force>``, ``<velocity>``,
  ``<position>`` (on when present, unless ``value="false"``).
* ``<connects>``: free connection nodes, ``<connect conref x y z M V>`` with an optional
  ``<coeffini cda ca>`` (both then required; CdA and Ca 0 without it); a line's end ``<connect
  conref>`` hangs on one. M and V default to 0 (a warning: MoorDynPlus 2025 estimates them from the
  lines instead, with a volume of the wrong dimension and a NaN where the connect is no line's node
  N); MoorDynPlus 2020's ``<initialCoeffs>``/``<initialForce>`` are warned as not read (DualSPHysics
  5.4 ignores them). End order: a fixed end is node 0 and a connect node N; a vessel end is node N
  and a connect node 0; of two connects the lower is node 0. Refused: a line with one connect at
  both ends, an unknown or repeated conref; a connect no line uses is warned and left out (MoorDynPlus
  drops it silently).
* ``<waves>`` is accepted and not read, as MoorDynPlus does (a warning).
"""
import math

import numpy as np

from ..errors import CaseError
from .xmldoc import CaseReader, strip_disabled

MOORINGS_CHILDREN = {"moordynplus", "moordyn", "start", "savevtk_lines", "savevtk_moorings", "savecsv_points",
                     "savevtk_points", "mooredfloatings"}
SAVE_FLAGS = (("savevtk_lines", True), ("savevtk_moorings", True), ("savecsv_points", True),
              ("savevtk_points", False))
ROOT_CHILDREN = {"solverOptions", "waves", "bodies", "connects", "lines", "savedata", "output"}
#: ``<solverOptions>``: lower-case name -> (the name as written in the format, dict key, default, check)
SOLVER = {
    "waterdepth": ("waterDepth", "waterdepth", None, "positive"),
    "freesurface": ("freesurface", "freesurface", 0.0, None),
    "kbot": ("kBot", "kbot", 3.0e6, "positive"),
    "cbot": ("cBot", "cbot", 3.0e5, "positive"),
    "dtm": ("dtM", "dtm", 1e-4, "positive"),
    "wavekin": ("waveKin", "wavekin", 0, "integer"),
    "writeunits": ("writeUnits", None, "yes", "text"),
    "frictioncoefficient": ("frictionCoefficient", "friction", 0.0, "nonnegative"),
    "fricdamp": ("fricDamp", "fricdamp", 200.0, "nonnegative"),
    "statdynfricscale": ("statDynFricScale", "statdynfricscale", 1.0, "nonnegative"),
    "rho": ("rho", "rho", 1000.0, "positive"),
    "cdscaleic": ("cdScaleIC", "cdscaleic", 5.0, "positive"),
    "dtic": ("dtIC", "dtic", 1.0, "positive"),
    "tmaxic": ("tmaxIC", "tmaxic", 0.0, "nonnegative"),
    "threshic": ("threshIC", "threshic", 0.001, "nonnegative"),
}
#: ``<linedefault>``/``<line>`` items: lower-case name -> (name as written, dict key, default, check);
#: a None default is required (ea/e: one of them)
LINE_PARAMS = {
    "ea": ("ea", "ea", None, "positive"),
    "e": ("e", "e", None, "positive"),
    "diameter": ("diameter", "diameter", None, "positive"),
    "massdeninair": ("massDenInAir", "mass", None, "positive"),
    "ba": ("ba", "ba", -0.8, None),
    "can": ("can", "can", 1.0, "nonnegative"),
    "cat": ("cat", "cat", 0.0, "nonnegative"),
    "cdn": ("cdn", "cdn", 1.6, "nonnegative"),
    "cdt": ("cdt", "cdt", 0.05, "nonnegative"),
    "breaktension": ("breaktension", "breaktension", 0.0, "nonnegative"),
    "length": ("length", "length", None, "positive"),
    "segments": ("segments", "segments", None, "segments"),
    "outputflags": ("outputFlags", "outputflags", "-", "flags"),
    "depth": ("depth", "depth", None, "positive"),            # <line> only
}
LINE_KEYS = ("ea", "diameter", "mass", "ba", "can", "cat", "cdn", "cdt", "breaktension", "length", "segments",
             "depth", "outputflags")
OUTPUT_FLAGS = "-pvUDtcbs"
UNWRITTEN_FLAGS = "UDcb"       # accepted, warned: sphdvi.io.moorings_out writes p, v, t, s
SAVEDATA_CHILDREN = {"time", "tension", "force", "velocity", "position"}


def read_moorings(reader, el) -> dict:
    """``<special><moorings>`` -> the moorings dict (module docstring)."""
    reader.check_children(el, MOORINGS_CHILDREN)
    reader.check_no_repeats(el, MOORINGS_CHILDREN - {"moordyn"})
    out = {"line": el.sourceline}
    for tag, default in SAVE_FLAGS:
        c = reader.child(el, tag)
        out[tag] = reader.boolean(c, "value", default) if c is not None else default
    start = reader.child(el, "start")
    out["start"] = reader.num(start, "value", 0.0, nonnegative=True) if start is not None else 0.0
    out["ramptime"] = reader.num(start, "ramptime", 0.0, nonnegative=True) if start is not None else 0.0
    out["floatings"], floating_els = _read_floatings(reader, el)
    lib_reader, lib = _library_root(reader, el)
    out.update(_read_library(lib_reader, lib, floating_els))
    if lib_reader is not reader:
        lib_reader.warn_unread_attributes(lib)
    return out


def _read_floatings(reader, el):
    """``<mooredfloatings><floating mkbound>``: the mkbounds in the file's order and their elements."""
    lis = reader.child(el, "mooredfloatings")
    if lis is not None:
        reader.check_children(lis, {"floating"})
    items = reader.children(lis, "floating")
    if not items:
        raise reader.error(lis if lis is not None else el, "there are no moored floatings",
                           '<mooredfloatings><floating mkbound=".."/></mooredfloatings> naming each moored '
                           "floating body")
    mkbounds, els = [], {}
    for f in items:
        mk = reader.integer(f, "mkbound", lo=0)
        if mk in els:
            raise reader.error(f, f"floating mkbound={mk} is already configured (line {els[mk].sourceline})",
                               "each moored floating once")
        mkbounds.append(mk)
        els[mk] = f
    return mkbounds, els


def _library_root(reader, el):
    """The ``<moordynplus>`` element to read and the reader that names its file: the case's for the
    embedded form, one of the named file for ``file=``."""
    plus = reader.child(el, "moordynplus")
    legacy = reader.child(el, "moordyn")
    if plus is not None and legacy is not None:
        raise reader.error(legacy, "both <moordynplus> and <moordyn> are given",
                           "one <moordynplus> (<moordyn> is its DualSPHysics 5.0-5.2 name)")
    if plus is None and legacy is None:
        raise reader.error(el, "missing <moordynplus>", "a <moordynplus> section (or file=\"..\") configuring "
                           "the mooring lines")
    lib = plus if plus is not None else legacy
    if legacy is not None:
        reader.warn(legacy, "<moordyn> is the DualSPHysics 5.0-5.2 name of <moordynplus> (DualSPHysics 5.4 refuses "
                    "it): read as <moordynplus>")
    name = reader.text_attr(lib, "file", "")
    if not name:
        return reader, lib
    path = reader.resolve_path(lib, "file")
    if any(isinstance(c.tag, str) for c in lib):
        reader.warn(lib, f"the content of <{lib.tag}> is ignored: file=\"{name}\" gives the configuration")
    from .reader import load_xml_any       # (reader imports this module)
    root, _ = load_xml_any(path, reader)
    strip_disabled(root, path)
    sub = CaseReader(path, reader.vars, reader.warnings, base_dir=reader.base_dir)
    sub.root = root
    if root.tag == "moordyn":
        sub.warn(root, "<moordyn> is the DualSPHysics 5.0-5.2 name of <moordynplus> (DualSPHysics 5.4 refuses "
                 "it): read as <moordynplus>")
    elif root.tag != "moordynplus":
        raise sub.error(root, f"the root element of {name} is <{root.tag}>", "<moordynplus>")
    return sub, root


def _read_library(reader, lib, floating_els: dict) -> dict:
    """The ``<moordynplus>`` content: solver, bodies, lines, savedata."""
    reader.check_children(lib, ROOT_CHILDREN)
    reader.check_no_repeats(lib, ROOT_CHILDREN)
    reader.boolean(lib, "debug", False)
    connects = _read_connects(reader, reader.child(lib, "connects"))
    waves = reader.child(lib, "waves")
    if waves is not None:
        reader.warn(waves, "<waves> is not read (nor by MoorDynPlus): the mooring lines see still water")
    solver_el = reader.child(lib, "solverOptions", required=True)
    solver = _read_solver(reader, solver_el)
    bodies = _read_bodies(reader, lib, floating_els)
    lines_el = reader.child(lib, "lines", required=True)
    lines = _read_lines(reader, lines_el, solver, bodies, connects)
    connects = _used_connects(reader, connects, lines)
    attached = {e["body"] for ln in lines for e in ln["ends"] if e["body"] is not None}
    for mk, f in floating_els.items():
        if mk not in attached:
            reader.warn(f, f"no mooring line is attached to moored floating mkbound={mk}")
    saves = [c for c in reader.children(lib) if c.tag in ("savedata", "output")]
    if len(saves) > 1:
        raise reader.error(saves[1], "both <savedata> and <output> are given",
                           "one <savedata> (<output> is its old name)")
    return {"solver": solver, "bodies": [{k: b[k] for k in ("ref", "depth", "line")} for b in bodies],
            "lines": lines, "connects": connects, "savedata": _read_savedata(reader, saves[0]) if saves else None}


def _read_connects(reader, el) -> dict:
    """``<connects>``: conref -> {conref, pos, mass, volume, cda, ca, line, _el} in the file's order."""
    out = {}
    if el is None:
        return out
    for c in reader.children(el):
        if c.tag != "connect":
            raise reader.error(c, f"unknown element <{c.tag}> inside <connects>", '<connect conref x y z M V>')
        ref = reader.integer(c, "conref", lo=0)
        if ref in out:
            raise reader.error(c, f"conref={ref} is given twice (line {out[ref]['line']})", "one <connect> per conref")
        d = {"conref": ref, "pos": reader.vec3(c).tolist(), "line": c.sourceline, "_el": c}
        for key, attr in (("mass", "M"), ("volume", "V")):
            d[key] = reader.num(c, attr, 0.0, nonnegative=True)
        if c.get("M") is None or c.get("V") is None:
            absent = " and ".join(a for a in ("M", "V") if c.get(a) is None)
            reader.warn(c, f"connect conref={ref}: {absent} not given, taken as 0 (MoorDynPlus 2025 estimates them "
                        "from its lines, with a volume A L² of the wrong dimension)")
        reader.check_children(c, {"coeffini", "initialCoeffs", "initialForce", "forceini"})
        coef = reader.child(c, "coeffini")
        d["cda"] = reader.num(coef, "cda", nonnegative=True) if coef is not None else 0.0
        d["ca"] = reader.num(coef, "ca", nonnegative=True) if coef is not None else 0.0
        for old in ("initialCoeffs", "initialForce", "forceini"):
            if reader.child(c, old) is not None:
                reader.warn(reader.child(c, old), f"<{old}> is not read, as DualSPHysics 5.4's MoorDynPlus does not "
                            "read it (<coeffini cda ca> gives the drag area and added mass; no initial force)")
        out[ref] = d
    return out


def _used_connects(reader, connects: dict, lines: list) -> list:
    """The connects the lines use, in ``<connects>`` order; each line end's ``connect`` set to its
    place in that list (a connect no line uses is warned and left out, as MoorDynPlus drops it)."""
    used = {e["conref"] for ln in lines for e in ln["ends"] if e["kind"] == "connect"}
    out = []
    for ref, d in connects.items():
        if ref not in used:
            reader.warn(d["_el"], f"connect conref={ref} is used by no line: left out")
            continue
        d["index"] = len(out)
        out.append({k: v for k, v in d.items() if k not in ("_el", "index")})
    for ln in lines:
        for e in ln["ends"]:
            if e["kind"] == "connect":
                e["connect"] = connects[e["conref"]]["index"]
    return out


def _named_items(reader, el, table: dict, what: str) -> dict:
    """The ``<name value>`` children of ``el`` whose lower-case names are in ``table``: lower name ->
    element; an unknown or repeated name is an error."""
    found = {}
    for c in reader.children(el):
        key = c.tag.lower()
        if key not in table:
            raise reader.error(c, f"unknown {what} <{c.tag}> inside <{el.tag}>",
                               "one of " + ", ".join(f"<{table[k][0]}>" for k in table))
        if key in found:
            raise reader.error(c, f"<{c.tag}> is given twice inside <{el.tag}> (line {found[key].sourceline})",
                               "each option once")
        found[key] = c
    return found


def _value(reader, c, name: str, check):
    """The ``value`` of a ``<name value>`` item, of its kind, checked."""
    if check == "integer":
        return reader.integer(c, "value", lo=0)
    if check == "segments":
        return reader.integer(c, "value", lo=1)
    if check in ("text", "flags"):
        text = reader.text_attr(c, "value")
        if check == "flags":
            bad = [ch for ch in text if ch not in OUTPUT_FLAGS]
            if bad:
                raise reader.error(c, f"<{name} value=\"{text}\">: '{bad[0]}' is not an output flag",
                                   f"characters of \"{OUTPUT_FLAGS}\" (\"-\": no node output)")
            unwritten = sorted({ch for ch in text if ch in UNWRITTEN_FLAGS})
            if unwritten:
                reader.warn(c, f"<{name} value=\"{text}\">: sphdvi writes the node outputs p, v, t and s only, not "
                            + ", ".join(unwritten) + " (wave velocities, hydrodynamic forces, damping, seabed "
                            "contact)")
            return text or "-"
        return text
    value = reader.num(c, "value")
    if check == "positive" and not value > 0:
        raise reader.error(c, f"<{name} value={value:g}> is not positive", f"{name} > 0")
    if check == "nonnegative" and value < 0:
        raise reader.error(c, f"<{name} value={value:g}> is negative", f"{name} >= 0")
    return value


def _read_solver(reader, el) -> dict:
    """``<solverOptions>`` -> the solver dict (:data:`SOLVER`'s defaults)."""
    items = _named_items(reader, el, SOLVER, "solver option")
    if "waterdepth" not in items:
        raise reader.error(el, "missing <waterDepth>", '<waterDepth value=".."/>: the water depth (m) of the '
                           "seabed below freesurface")
    out = {}
    for key, (name, dkey, default, check) in SOLVER.items():
        value = _value(reader, items[key], name, check) if key in items else default
        if key == "writeunits" and value.strip().lower()[:1] not in ("y", "n"):
            raise reader.error(items[key], f"<writeUnits value=\"{value}\">", "yes or no")
        if dkey is not None:
            out[dkey] = value
        if key == "dtm":
            out["dtm_auto"] = reader.boolean(items[key], "auto", True) if key in items else True
    if out["wavekin"] > 0:
        reader.warn(items["wavekin"], f"waveKin={out['wavekin']}: no wave kinematics are used (nor by MoorDynPlus):"
                    " the mooring lines see still water")
    return out


def _read_bodies(reader, lib, floating_els: dict) -> list:
    """``<bodies><body ref>`` with their ``<depth>``; the refs must be the moored floatings'
    mkbounds, each once (DualSPHysics pairs them by index)."""
    lis = reader.child(lib, "bodies")
    bodies, by_ref = [], {}
    if lis is not None:
        reader.check_children(lis, {"body"})
        for k, b in enumerate(reader.children(lis, "body")):
            reader.check_children(b, {"depth"})
            reader.check_no_repeats(b, {"depth"})
            ref = reader.integer(b, "ref", k, lo=0)
            if ref in by_ref:
                raise reader.error(b, f"body ref={ref} is already defined (line {by_ref[ref]['line']})",
                                   "each body ref once")
            if ref not in floating_els:
                raise reader.error(b, f"body ref={ref} is not a moored floating",
                                   "a ref that is the mkbound of a <mooredfloatings><floating> ("
                                   + ", ".join(map(str, floating_els)) + ")")
            d = reader.child(b, "depth")
            body = {"ref": ref, "depth": _value(reader, d, "depth", "positive") if d is not None else None,
                    "line": b.sourceline, "el": b}
            bodies.append(body)
            by_ref[ref] = body
    for mk, f in floating_els.items():
        if mk not in by_ref:
            raise _floating_error(reader, lib, f, mk)
    return bodies


def _floating_error(reader, lib, f, mk) -> CaseError:
    """A moored floating without its ``<body>``: named at its ``<floating>`` when ``<moordynplus>``
    is in the case file, else at the named file's ``<bodies>`` (or root)."""
    text = f"moored floating mkbound={mk} has no <body ref=\"{mk}\"> in <moordynplus><bodies>"
    expected = f'<bodies><body ref="{mk}"/></bodies> in <moordynplus>: one body per moored floating'
    if f.getroottree().getroot() is lib.getroottree().getroot():
        return reader.error(f, text, expected)
    where = lib.find("bodies")
    return reader.error(where if where is not None else lib, text, expected)


def _line_items(reader, el, is_line: bool):
    """The parameter items of a ``<linedefault>`` or ``<line>`` (lower name -> (value, element))
    and, of a line, its connection elements."""
    params, conns, seen = {}, [], {}
    allowed = [v[0] for k, v in LINE_PARAMS.items() if is_line or k != "depth"]
    if is_line:
        allowed += ["fixconnection", "vesselconnection", "connect"]
    for c in reader.children(el):
        key = c.tag.lower()
        if is_line and (key.startswith("fix") or key.startswith("vessel") or key == "connect"):
            conns.append(c)
            continue
        if key not in LINE_PARAMS or (key == "depth" and not is_line):
            raise reader.error(c, f"unknown element <{c.tag}> inside <{el.tag}>",
                               "one of " + ", ".join(f"<{a}>" for a in allowed))
        if key in seen:
            raise reader.error(c, f"<{c.tag}> is given twice inside <{el.tag}> (line {seen[key].sourceline})",
                               "each parameter once")
        seen[key] = c
        params[key] = (_value(reader, c, LINE_PARAMS[key][0], LINE_PARAMS[key][3]), c)
    return params, conns


def _read_connection(reader, c, body_refs: dict, connects: dict) -> dict:
    """A ``<fixconnection x y z>`` or ``<vesselconnection bodyref x y z>`` (``M``, ``V``: 0), or a
    ``<connect conref>`` (at its connect's position)."""
    if c.tag.lower() == "connect":
        ref = reader.integer(c, "conref", lo=0)
        if ref not in connects:
            raise reader.error(c, f"conref={ref} is not a <connect> of <connects>",
                               "the conref of a <connects><connect> (" + (", ".join(map(str, connects)) or
                                                                          "none defined") + ")")
        return {"kind": "connect", "body": None, "conref": ref, "pos": list(connects[ref]["pos"]), "_el": c}
    vessel = c.tag.lower().startswith("vessel")
    end = {"kind": "vessel" if vessel else "fixed", "body": None}
    if vessel:
        end["body"] = reader.integer(c, "bodyref", lo=0)
        if end["body"] not in body_refs:
            raise reader.error(c, f"bodyref={end['body']} is not a <body ref> of <bodies>",
                               "the ref of a <bodies><body> (" + (", ".join(map(str, body_refs)) or "none defined")
                               + "): the mkbound of a moored floating")
    end["pos"] = reader.vec3(c).tolist()
    end["mass"] = reader.num(c, "M", 0.0, nonnegative=True)
    end["volume"] = reader.num(c, "V", 0.0, nonnegative=True)
    end["_el"] = c
    return end


def _read_lines(reader, el, solver: dict, bodies: list, connects: dict) -> list:
    """``<lines>``: ``<linedefault>`` and each ``<line>`` merged over it, checked; the ends ordered
    (node 0 first)."""
    reader.check_children(el, {"linedefault", "line"})
    reader.check_no_repeats(el, {"linedefault"})
    default_el = reader.child(el, "linedefault")
    defaults = _line_items(reader, default_el, False)[0] if default_el is not None else {}
    body_refs = {b["ref"]: b for b in bodies}
    items = reader.children(el, "line")
    if not items:
        raise reader.error(el, "no <line> is defined", "one or more <line> elements")
    out = []
    for k, line_el in enumerate(items):
        own, conns = _line_items(reader, line_el, True)
        merged = {**defaults, **own}
        d = {"id": k, "line": line_el.sourceline}
        if "ea" in merged and "e" in merged:
            late = merged["e"][1] if merged["e"][1].sourceline >= merged["ea"][1].sourceline else merged["ea"][1]
            raise reader.error(late, f"line {k} has both <ea> and <e>", "one of them (in <line> or <linedefault>): "
                               "<ea> the axial stiffness EA (N) or <e> Young's modulus E (Pa)")
        if "ea" not in merged and "e" not in merged:
            raise reader.error(line_el, f"line {k} has neither <ea> nor <e>", "one of them (in <line> or "
                               "<linedefault>): <ea> the axial stiffness EA (N) or <e> Young's modulus E (Pa)")
        for key in ("diameter", "massdeninair", "length", "segments"):
            if key not in merged:
                name = LINE_PARAMS[key][0]
                raise reader.error(line_el, f"line {k} has no <{name}>", f'<{name} value=".."/> in the <line> or '
                                   "in <linedefault>")
        for key, (name, dkey, default, _) in LINE_PARAMS.items():
            if key in ("ea", "e"):
                continue
            d[dkey] = merged[key][0] if key in merged else default
        d["ea"] = merged["ea"][0] if "ea" in merged else merged["e"][0] * math.pi * d["diameter"] ** 2 / 4.0
        saved = line_el.get("savedata")
        d["savedata"] = reader.boolean(line_el, "savedata" if saved is not None or line_el.get("output") is None
                                       else "output", True)
        if len(conns) != 2:
            raise reader.error(conns[2] if len(conns) > 2 else line_el,
                               f"line {k} has {len(conns)} connection element(s)",
                               "exactly two: <fixconnection x y z> (an anchor) or <vesselconnection bodyref x y z> "
                               "(a point of a moored floating), one per end")
        ends = [_read_connection(reader, c, body_refs, connects) for c in conns]
        kinds = {ends[0]["kind"], ends[1]["kind"]}
        if ends[0]["kind"] == ends[1]["kind"] == "connect" and ends[0]["conref"] == ends[1]["conref"]:
            raise reader.error(conns[1], f"line {k} hangs both its ends on connect conref={ends[0]['conref']}",
                               "two different connections")
        if ends[0]["kind"] == ends[1]["kind"] in ("vessel", "connect"):
            ends = ends if ends[0]["pos"][2] <= ends[1]["pos"][2] else ends[::-1]
        elif ends[1]["kind"] == "fixed" and ends[0]["kind"] != "fixed":
            ends = ends[::-1]
        elif kinds == {"vessel", "connect"} and ends[0]["kind"] == "vessel":
            ends = ends[::-1]                     # MoorDynPlus: the vessel end is node N
        if ends[1]["kind"] == "fixed":
            reader.warn(line_el, f"line {k} has two fixed ends: it moves no body")
        body = next((e["body"] for e in (ends[1], ends[0]) if e["body"] is not None), None)
        if d["depth"] is None:
            depth = body_refs[body]["depth"] if body is not None else None
            d["depth"] = depth if depth is not None else solver["waterdepth"]
        bed = solver["freesurface"] - d["depth"]
        if ends[0]["pos"][2] < bed - 1e-9 * max(1.0, abs(bed), d["depth"]):
            raise reader.error(ends[0]["_el"], f"line {k}'s anchor z={ends[0]['pos'][2]:g} lies below the seabed "
                               f"(z = freesurface - depth = {solver['freesurface']:g} - {d['depth']:g} = {bed:g})",
                               f"the anchor at or above the seabed z = freesurface - depth = {bed:g} (or a larger "
                               "depth: <line><depth>, <body><depth> or waterDepth)")
        span = float(np.linalg.norm(np.subtract(ends[1]["pos"], ends[0]["pos"])))
        if span == 0.0:
            raise reader.error(line_el, f"line {k}'s two ends are the same point {tuple(ends[0]['pos'])}",
                               "two connections at different points (the line's nodes start between them)")
        if d["length"] < span * (1.0 - 1e-9):            # not for a rounding error (0.6 vs 0.6000000000000001)
            reader.warn(line_el, f"line {k}'s length {d['length']:g} m is shorter than the distance between its ends "
                        f"({span:.6g} m): it starts taut, stretched by {100.0 * (span / d['length'] - 1.0):.3g} %")
        for e in ends:
            del e["_el"]
        d["ends"] = ends
        out.append({key: d[key] for key in ("id", "line", *LINE_KEYS, "savedata", "ends")})
    return out


def _read_savedata(reader, el) -> dict:
    """``<savedata>``: ``<time starTime endTime dtOut>`` and the magnitudes written."""
    reader.check_children(el, SAVEDATA_CHILDREN)
    reader.check_no_repeats(el, SAVEDATA_CHILDREN)
    out = {"start": 0.0, "end": None, "dtout": None}
    t = reader.child(el, "time")
    if t is not None:
        if t.get("startTime") is not None and t.get("starTime") is None:
            reader.mark(t, "startTime")
            reader.warn(t, "attribute 'startTime' is not read: DualSPHysics spells it starTime (the start is 0)")
        out["start"] = reader.num(t, "starTime", 0.0, nonnegative=True)
        end = reader.num(t, "endTime", 0.0, nonnegative=True)
        out["end"] = end if end > 0 else None
        if out["end"] is not None and out["end"] < out["start"]:
            raise reader.error(t, f"endTime={end:g} is before starTime={out['start']:g}",
                               "endTime >= starTime (or 0: to the end of the run)")
        out["dtout"] = reader.num(t, "dtOut", None, positive=True)
    for tag in ("tension", "force", "velocity", "position"):
        c = reader.child(el, tag)
        out[tag] = reader.boolean(c, "value", True) if c is not None else False
    return out
