"""``<special><chrono>``, the Chrono section of a case, as DualSPHysics's JChronoObjects reads
it: bodies (their mkbound, collision model file and material), links (hinge, spherical, point-line,
linear spring, coulomb damping, pulley, and the other DualSPHysics links), the solver and time
stepper settings, ``<scaleforce>``; and the checks across the case (:func:`check_chrono_case`).
Called by :mod:`sphdvi.case.reader`."""
from __future__ import annotations

import os

import numpy as np

from ..errors import CaseError
from .mkrange import range_filter_attr


def _check_modelfile(reader, el, modelfile: str, body_id: str) -> None:
    """A chrono body's collision ``modelfile``: GenCase's own shapes (AutoActual, AutoDp, a
    ``*_Actual.vtk`` / ``*_Dp.vtk`` it wrote) pass; a mesh file must exist, as DualSPHysics loads
    it, and is warned about: sphdvi builds every collision shape from the body's particles."""
    low = modelfile.strip().lower()
    if low in ("autoactual", "autodp") or low.endswith(("_actual.vtk", "_dp.vtk")):
        return
    path = os.path.normpath(os.path.join(reader.base_dir, modelfile))
    if not os.path.isfile(path):
        raise reader.error(el, f"modelfile '{modelfile}' not found (looked for {path})",
                           "an existing .obj/.vtk file, or AutoActual / AutoDp (the shape GenCase drew)")
    reader.warn(el, f"modelfile '{modelfile}': sphdvi does not read collision meshes; body '{body_id}' collides "
                    "through spheres at its boundary particles, as with AutoActual")


def read_chrono(reader, el) -> dict:
    """``<special><chrono>`` as DualSPHysics's JChronoObjects::ReadXml reads it: bodies (one per
    mkbound of a range, an mkbound in one body only), links (DualSPHysics's default names),
    collision settings, scale forces; options sphdvi does not apply are warned about."""
    allowed = {"savedata", "schemescale", "ompthreads", "collision", "bodyfixed", "bodyfloating",
               "bodymoving", "link_hinge", "link_spheric", "link_pointline", "link_linearspring",
               "link_coulombdamping", "link_pulley", "gravity", "timestepper", "scaleforce",
               "solver", "configfea", "nodes", "feafloating", "link_pointframe"}
    reader.check_children(el, allowed)
    out = {"savedata": -1.0, "schemescale": 1.0, "ompthreads": 1,
           "collision": {"activate": False, "distancedp": 0.5, "contactmethod": 0},
           "bodies": [], "links": []}
    for tag in ("configfea", "nodes", "feafloating", "link_pointframe"):
        c = el.find(tag)
        if c is not None:
            raise reader.error(c, f"<{tag}> (Chrono FEA) is not supported by sphdvi", "rigid bodies and links")
    if el.find("savedata") is not None:
        out["savedata"] = reader.child_value(el, "savedata")
        if out["savedata"] >= 0:
            reader.warn(reader.child(el, "savedata"), "<savedata> (DualSPHysics's ChronoExchange_mkbound_XX.csv, "
                        "ChronoBody_forces.csv, ChronoLink_forces.csv) is not written by sphdvi: bodies.csv and "
                        "links.csv hold the bodies' and links' data at each output")
    if el.find("schemescale") is not None:
        out["schemescale"] = reader.child_value(el, "schemescale", positive=True)
    if el.find("ompthreads") is not None:      # Chrono's threads (0 all cores, 1 one): no effect here
        out["ompthreads"] = int(reader.child_value(el, "ompthreads", lo=0))
    if el.find("solver") is not None:
        out["solver"] = _read_chrono_solver(reader, reader.child(el, "solver"))
    _read_chrono_timestepper(reader, reader.child(el, "timestepper"))
    grav = reader.child(el, "gravity")
    if grav is not None:      # in older DualSPHysics templates; v5.4's JChronoObjects::ReadXml does not read it
        reader.mark(grav, *grav.keys())
        reader.warn(grav, "<chrono><gravity> is not read (as DualSPHysics v5.4): the bodies feel the case's "
                          "<constantsdef><gravity>")
    out["collision"] = _read_chrono_collision(reader, reader.child(el, "collision"), out["collision"])
    ids, empty = _read_chrono_bodies(reader, el, out)
    for ln in reader.children(el):
        if not ln.tag.startswith("link_"):
            continue
        out["links"].append(_read_link(reader, ln, ids, empty))
    _name_chrono_links(reader, el, out["links"])
    scale = reader.child(el, "scaleforce")
    if scale is not None:
        out["scaleforce"] = _read_scaleforce(reader, scale, out["bodies"])
    return out


# <chrono><solver type>: Chrono's solver names (ChSolver::Type, DualSPHysics's JChronoData::TpSolverType
# BB/MINRES) -> (sphdvi's solver, what it replaces or None where it is that method)
_CHRONO_SOLVERS = {
    "bb": ("bb", None), "barzilaiborwein": ("bb", None), "spg": ("bb", None),
    "psor": ("psor", None), "pgs": ("psor", None), "sor": ("psor", None), "gs": ("psor", None),
    "apgd": ("apgd", None), "apgdref": ("apgd", None), "direct": ("direct", None),
    "minres": ("direct", "Chrono's MINRES (DualSPHysics's choice under SMC; bilateral rows only)"),
    "pminres": ("direct", "Chrono's projected MINRES"),
    "pjacobi": ("psor", "Chrono's projected Jacobi"), "pssor": ("psor", "Chrono's PSSOR (removed from Chrono)"),
    "sparselu": ("direct", "Chrono's sparse LU"), "sparseqr": ("direct", "Chrono's sparse QR"),
    "pardisomkl": ("direct", "Chrono's Pardiso"), "mumps": ("direct", "Chrono's MUMPS"),
    "gmres": ("direct", "Chrono's GMRES"), "bicgstab": ("direct", "Chrono's BiCGSTAB"),
    "admm": ("direct", "Chrono's ADMM"),
}


def _read_chrono_solver(reader, s) -> dict:
    """``<solver type maxiter tolerance>``: the multibody solver, an sphdvi extension (DualSPHysics v5.4's
    JChronoObjects::ReadXml has no <solver>: its line is commented out, and DSPHChronoLib picks Chrono's BB
    under NSC and MINRES under SMC, FunDSPHChrono::GetSolverChIxAuto, with Chrono's iteration settings).
    ``type`` a Chrono solver name (BB, the default; PSOR, APGD; MINRES and Chrono's linear solvers become
    sphdvi's ``direct`` solver, with a warning), ``maxiter`` the iteration limit (default 100),
    ``tolerance`` the residual (m/s) at which the iterations stop (default 1e-10), ``exactjoints`` (default
    true) whether BB, PSOR and APGD solve the islands of bodies linked only by joints (no contacts) exactly, as
    ``direct`` does (false: every row iterative; with ``direct`` it has no effect and is warned about).
    Other attributes get the reader's unknown-attribute warning."""
    out = {}
    if reader.has(s, "type"):
        raw = reader.text_attr(s, "type")
        key = raw.lower().replace("_", "").replace("-", "").replace(" ", "")
        if key not in _CHRONO_SOLVERS:
            raise reader.error(s, f"<solver type={raw!r}> is not a known solver",
                               "BB (DualSPHysics's), PSOR, APGD, MINRES or direct")
        out["type"], replaced = _CHRONO_SOLVERS[key]
        if replaced:
            reader.warn(s, f"<solver type=\"{raw}\">: {replaced} is not in sphdvi; its 'direct' solver is used "
                           "instead (joint rows by a dense Cholesky factorisation, contacts by a projected "
                           "gradient)")
    if reader.has(s, "maxiter"):
        out["maxiter"] = reader.integer(s, "maxiter", lo=1)
    if reader.has(s, "tolerance"):
        out["tolerance"] = reader.num(s, "tolerance", nonnegative=True)
    if reader.has(s, "exactjoints"):
        out["exactjoints"] = reader.boolean(s, "exactjoints")
        if out.get("type") == "direct":
            reader.warn(s, "<solver exactjoints>: the 'direct' solver solves every island exactly; "
                           "exactjoints only applies to BB, PSOR and APGD and is ignored")
    return out


def _read_chrono_timestepper(reader, ts) -> None:
    """``<timestepper value alpha>`` (DualSPHysics: 0 Euler implicit linearised, 1 HHT with
    ``alpha``, default -0.2; other values an error). sphdvi's multibody step is the former:
    HHT is warned about, ``alpha`` without HHT as DualSPHysics does."""
    if ts is None:
        return
    value = reader.integer(ts, "value", 0)
    if value not in (0, 1):
        raise reader.error(ts, f"timestepper value {value}", "0 (Euler implicit linearised) or 1 (HHT)")
    alpha = reader.num(ts, "alpha", -0.2)
    if value == 1:
        reader.warn(ts, f"HHT (timestepper 1, alpha {alpha:g}) is not supported by sphdvi: the Euler implicit "
                        "linearised stepper (timestepper 0) is used")
    elif ts.get("alpha") is not None and alpha != 0:
        reader.warn(ts, "'alpha' is only used by the HHT timestepper (value 1); ignored, as in DualSPHysics")


def _read_chrono_collision(reader, col, default: dict) -> dict:
    """``<collision activate>``: ``activate`` is mandatory and the children are read only when it
    is true (DualSPHysics's ReadXml: GetAttributeBool(collision, "activate", false))."""
    if col is None:
        return default
    if col.get("activate") is None:
        raise reader.error(col, "missing attribute 'activate'",
                           'activate="true" (Chrono collisions) or activate="false"')
    if not reader.boolean(col, "activate"):
        return dict(default)
    # <ompthreads> sits here in DualSPHysics v5.x's chrono examples (CaseExternalVelocity,
    # CaseBreakingWall): Chrono's thread count, 0 all cores, 1 one; read, no effect in sphdvi
    reader.check_children(col, {"distancedp", "contactmethod", "ompthreads"})
    if col.find("ompthreads") is not None:
        reader.child_value(col, "ompthreads", lo=0)
    return {"activate": True,
            "distancedp": reader.child_value(col, "distancedp", 0.5, nonnegative=True),
            "contactmethod": int(reader.child_value(col, "contactmethod", 0, lo=0, hi=1))}


def _read_chrono_bodies(reader, el, out: dict) -> tuple[dict, dict]:
    """The ``<body*>`` elements into ``out["bodies"]`` (one per mkbound, named id+mk for a list);
    returns ({body id: line}, {id of a body with mkbound="": line}). An id or an mkbound used twice
    is an error (JChronoData::CheckAddBodyError); no body at all a warning (DualSPHysics refuses it);
    mkbound="" a warning: DualSPHysics's JRangeFilter gives it no value, so ReadXml makes no body."""
    ids, owner, empty = {}, {}, {}
    for b in reader.children(el):
        if not b.tag.startswith("body"):
            continue
        kind = b.tag[4:]
        bid = reader.text_attr(b, "id")
        if b.get("mkbound") == "":
            reader.mark(b, *b.keys())
            reader.warn(b, f"body '{bid}' has an empty mkbound list: it defines no body and is skipped, as "
                           "DualSPHysics skips it (its mkbound range has no value); a link naming it is an error")
            empty[bid] = b.sourceline
            continue
        mks = _range_filter_mks(reader, b, "mkbound")
        if not mks:                     # e.g. mkbound="3-1" or "-3": JRangeFilter gives no value either
            reader.mark(b, *b.keys())
            reader.warn(b, f"body '{bid}' has no mkbound (mkbound=\"{b.get('mkbound')}\" gives none): it defines no "
                           "body and is skipped, as DualSPHysics skips it; a link naming it is an error")
            empty[bid] = b.sourceline
            continue
        names = [bid] if len(mks) == 1 else [f"{bid}{mk}" for mk in mks]
        for name, mk in zip(names, mks):
            if name in ids:
                raise reader.error(b, f"body id '{name}' is used twice (line {ids[name]})", "unique body ids")
            if mk in owner:
                raise reader.error(b, f"mkbound {mk} is already in use for the body '{owner[mk][0]}' (line "
                                      f"{owner[mk][1]})", "each mkbound in one <chrono> body only")
            ids[name], owner[mk] = b.sourceline, (name, b.sourceline)
            body = {"kind": kind, "id": name, "mkbound": mk, "line": b.sourceline,
                    "modelfile": reader.text_attr(b, "modelfile", None),
                    "modelnormal": reader.text_attr(b, "modelnormal", "original",
                                                    choices={"original", "invert", "twoface"}),
                    "imposefric": reader.boolean(b, "imposefric", False)}
            if kind == "moving":
                body["massbody"] = reader.num(b, "massbody", positive=True)
            if out["collision"]["activate"] and body["modelfile"]:
                _check_modelfile(reader, b, body["modelfile"], name)
            out["bodies"].append(body)
        if out["collision"]["activate"] and reader.boolean(b, "imposefric", False):
            reader.warn(b, "imposefric is not supported by sphdvi: the contacts of this body use the pair rule "
                           "(the smaller friction of the two bodies), not its own Kfric")
    if not out["bodies"]:
        reader.warn(el, "<chrono> defines no body: DualSPHysics refuses it (\"There are no defined bodies to use "
                        "Chrono.\"); sphdvi makes every <floating> a free body")
    return ids, empty


def _range_filter_mks(reader, el, attr: str) -> list:
    """A ``<chrono>`` mkbound list, read as DualSPHysics reads it with JRangeFilter
    (:func:`~sphdvi.case.mkrange.range_filter_attr`): ``" "`` is mkbound 0, ``"1,,3"`` 1 and 3, ``"1, ,3"``
    0, 1 and 3, ``"1-"`` 1, ``"-3"`` and ``"3-1"`` nothing, each warned; letters, decimals, signs an
    error. The list may come out empty (the caller says what that means)."""
    return range_filter_attr(reader, el, attr)


def _name_chrono_links(reader, el, links: list) -> None:
    """DualSPHysics's link names (JChronoObjects::ReadXml): ``Link_<id1>_<id2>``, ``Link_<id1>`` for a
    link to the ground, ``_2``, ``_3``... when taken; an explicit name used twice is an error
    (JChronoData::AddLink*). A ``link_pulley`` whose first body is in no ``link_hinge`` is warned
    about, as DualSPHysics does."""
    taken = {}
    elements = [ln for ln in reader.children(el) if ln.tag.startswith("link_")]
    hinged = {b for d in links if d["type"] == "hinge" for b in (d["idbody1"], d.get("idbody2")) if b}
    for ln, d in zip(elements, links):
        name = d["name"]
        if name is not None and name in taken:
            raise reader.error(ln, f"link name '{name}' is already in use (line {taken[name]})", "unique link names")
        if name is None:
            base = f"Link_{d['idbody1']}_{d['idbody2']}" if d.get("idbody2") else f"Link_{d['idbody1']}"
            name, num = base, 2
            while name in taken:
                name, num = f"{base}_{num}", num + 1
        d["name"] = name
        taken[name] = ln.sourceline
        if d["type"] == "pulley" and d["idbody1"] not in hinged:
            reader.warn(ln, f"the body '{d['idbody1']}' also should belong to a link_hinge (as DualSPHysics warns)")


def _read_scaleforce(reader, scale, bodies: list) -> list:
    """``<scaleforce><body mkbound="range" x y z/>``: per-axis factors of the fluid's force on the
    chrono body of each mkbound (JChronoObjects::ReadScaleForces; an mkbound of no body is an error
    there too). With no body listed every floating is one: checked at gencase (check_chrono_case)."""
    reader.check_children(scale, {"body"})
    known = {b["mkbound"] for b in bodies}
    out = []
    for b in reader.children(scale, "body"):
        mks = _range_filter_mks(reader, b, "mkbound")
        if not mks:                     # JChronoObjects::ReadScaleForces loops over no mkbound
            reader.mark(b, *b.keys())
            reader.warn(b, f"mkbound=\"{b.get('mkbound')}\" gives no mkbound: this <body> scales nothing, as in "
                           "DualSPHysics")
            continue
        bad = [mk for mk in mks if known and mk not in known]
        if bad:
            raise reader.error(b, f"mkbound {bad[0]} is not a <chrono> body", "the mkbound of a <chrono> body "
                               "(" + ", ".join(str(m) for m in sorted(known)) + ")")
        out.append({"mkbound": mks, "scale": reader.vec3(b).tolist(), "line": b.sourceline})
    return out


def check_chrono_case(reader, case) -> None:
    """What ``<chrono>`` needs from the rest of the case, checked at gencase as DualSPHysics does at
    start-up: with collisions on, each body with a ``modelfile`` has a material with Kfric and
    Restitution_Coefficient, and Young_Modulus and PoissonRatio under contactmethod 1 (SMC)
    (JChronoObjects::CheckParams: "Object mkbound=N - Value of Kfric is invalid."); a
    ``<scaleforce>`` mkbound is a floating's when the section lists no body."""
    chrono = case.special.get("chrono")
    if not chrono:
        return
    floating_mks = {mk for fd in case.floatings for mk in fd.mkbound}
    if not chrono["bodies"]:
        for item in chrono.get("scaleforce", []):
            bad = [mk for mk in item["mkbound"] if mk not in floating_mks]
            if bad:
                raise CaseError(f"<scaleforce> mkbound {bad[0]} is not a floating body", file=reader.file,
                                line=item["line"], element="body", expected="the mkbound of a <floating>")
    col = chrono["collision"]
    if not col["activate"]:
        return
    needed = [("kfric", "Kfric"), ("restitution", "Restitution_Coefficient")]
    if col["contactmethod"] == 1:
        needed += [("young", "Young_Modulus"), ("poisson", "PoissonRatio")]
    for body in chrono["bodies"]:
        if not body["modelfile"]:
            continue
        mk = body["mkbound"]
        combo = next((fd.property for fd in case.floatings if mk in fd.mkbound and fd.property), None)
        if combo is None:
            from ..mechanism import links_property      # every link naming the mkbound (GetProps)
            combo = links_property(mk, case.material_links)
        merged = {}
        for name in (combo or "").split("+"):
            mat = case.materials.get(name.strip())
            if mat is not None:
                merged.update({k: getattr(mat, k) for k, _ in needed if getattr(mat, k) is not None})
        missing = [label for key, label in needed if merged.get(key) is None]
        if missing:
            what = f"its property '{combo}' has no {' or '.join(missing)}" if combo else "it has no property"
            raise CaseError(f"chrono body '{body['id']}' (mkbound {mk}) collides (modelfile) but {what}: "
                            f"DualSPHysics stops (\"Object mkbound={mk} - Value of {missing[0]} is invalid.\")",
                            file=reader.file, line=body["line"], element="body" + body["kind"],
                            expected=", ".join(label for _, label in needed) + " in a <property> given to the mkbound "
                            "by <floating property=..> or <properties><links><link mkbound=..>")


LINK_SPECS = {
    "link_hinge": {"rotpoint": "vec", "rotvector": "vec", "stiffness": "coef", "damping": "coef"},
    "link_spheric": {"rotpoint": "vec", "stiffness": "coef", "damping": "coef"},
    "link_pointline": {"slidingvector": "vec", "rotpoint": "vec", "rotvector": "vec", "rotvector2": "vec",
                       "stiffness": "coef", "damping": "coef"},
    "link_linearspring": {"point_fb1": "vec", "point_fb2": "vec", "stiffness": "coef", "damping": "coef",
                          "rest_length": "num", "savevtk": "raw"},
    "link_coulombdamping": {"point_fb1": "vec", "point_fb2": "vec", "rest_length": "num", "damping": "num",
                            "savevtk": "raw"},
    "link_pulley": {"rotpoint": "vec", "rotvector": "vec", "radius": "num", "radius2": "num"},
}
LINK_REQUIRED = {
    "link_hinge": ("rotpoint", "rotvector"), "link_spheric": ("rotpoint",),
    "link_pointline": ("slidingvector", "rotpoint"), "link_linearspring": ("point_fb1", "point_fb2", "stiffness", "rest_length"),
    "link_coulombdamping": ("point_fb1", "point_fb2", "rest_length", "damping"), "link_pulley": ("rotpoint", "rotvector", "radius", "radius2"),
}


def _read_coef_file(reader, c, tag: str) -> dict:
    """A link's ``<stiffness file=..>`` / ``<damping file=..>`` table, read at gencase as DualSPHysics's
    JLinearValue::LoadFile reads it (JReadDatafile: ';', ',', spaces or tabs, '#' comments): at least
    two (time, value) rows, values finite and >= 0 -> {"times", "values", "file"}."""
    from .datafiles import _read_rows, check_rising_times
    path = reader.resolve_path(c, "file")
    try:
        a, lines = _read_rows(path, 2, f"<{tag}> table")
    except CaseError as exc:
        raise reader.error(c, f"{path}" + (f":{exc.line}" if exc.line else "") + f": {exc.message}",
                           exc.expected) from None
    if a.shape[0] < 2:
        found = "no data rows" if a.shape[0] == 0 else f"one data row (line {lines[0]})"
        raise reader.error(c, f"{path}: {found}", "at least two lines 'time value' (DualSPHysics: \"Cannot be "
                                                  "less than two values.\")")
    bad = np.flatnonzero(~np.isfinite(a[:, :2]).all(axis=1) | (a[:, 1] < 0))
    if bad.size:
        raise reader.error(c, f"{path}:{lines[bad[0]]}: {tag} {a[bad[0], 1]:g} at time {a[bad[0], 0]:g}",
                           f"finite {tag} values >= 0")
    try:
        check_rising_times(a[:, 0].tolist(), lines, f"<{tag}> table", path)
    except CaseError as exc:
        raise reader.error(c, f"{path}:{exc.line}: {exc.message}", exc.expected) from None
    return {"times": a[:, 0].tolist(), "values": a[:, 1].tolist(), "file": path}


# links that join two bodies, and what DualSPHysics says of one given the ground (idbody2 "NULL")
TWO_BODY_LINKS = {
    "link_linearspring": "it stops at the start of the run: \"Link without two bodies reference.\"",
    "link_coulombdamping": "it stops at the start of the run: \"Link without two bodies reference.\"",
    "link_pulley": "\"Link-Pulley uses two bodies.\"",
}


def _read_link(reader, ln, ids, empty=None) -> dict:
    """One ``<link_*>`` as JChronoObjects::ReadXml reads it: ``idbody1`` names a body, ``idbody2``
    another or, absent or "NULL", the ground; a name of no body (an empty one, or one whose
    mkbound list is empty: ``empty``) is an error there too ("idbody1 'x' is not found."). The
    ground is an error for the links of two bodies (:data:`TWO_BODY_LINKS`): DualSPHysics's
    SaveVtkScheme stops a spring or damper without a second body; a pulley's ReadXml check says it
    "uses two bodies" (its code lets idbody2="NULL" through to its closed-source Chrono library)."""
    spec = LINK_SPECS[ln.tag]
    d = {"type": ln.tag[5:], "line": ln.sourceline, "name": reader.text_attr(ln, "name", None)}
    for which in ("idbody1", "idbody2"):
        v = reader.text_attr(ln, which, None)
        null = which == "idbody2" and v == "NULL"
        if null:
            v = None                    # DualSPHysics's default: body 1 linked to the ground
        if v is None:
            if which == "idbody1":
                raise reader.error(ln, f"missing attribute '{which}'", "the id of a body defined in <chrono>")
            if ln.tag in TWO_BODY_LINKS:
                given = ('idbody2="NULL" (the ground)' if null else
                         'no idbody2 (DualSPHysics reads it as "NULL", the ground)')
                raise reader.error(ln, f"<{ln.tag}> joins two bodies but has {given}, which it cannot take "
                                       f"(DualSPHysics: {TWO_BODY_LINKS[ln.tag]})",
                                   "idbody2 naming a second body defined in <chrono> (for one held to the ground, "
                                   "a <bodyfixed> body): one of " + (", ".join(sorted(ids)) if ids else "(none)"))
        elif v in (empty or {}):
            raise reader.error(ln, f"{which}='{v}' names the body of line {empty[v]}, whose mkbound list is empty: "
                                   f"it defines no body (DualSPHysics stops too: \"{which} '{v}' is not found.\")",
                               "one of " + (", ".join(sorted(ids)) if ids else "(no bodies defined)"))
        elif v not in ids:
            raise reader.error(ln, f"{which}='{v}' names no body",
                               "one of " + (", ".join(sorted(ids)) if ids else "(no bodies defined)"))
        d[which] = v
    if d.get("idbody2") is not None and d["idbody2"] == d["idbody1"]:
        raise reader.error(ln, f"idbody1 and idbody2 are both '{d['idbody1']}'", "two different bodies")
    for c in reader.children(ln):
        if c.tag not in spec:
            raise reader.error(c, f"unknown element <{c.tag}> in <{ln.tag}>", "one of " + ", ".join(f"<{k}>" for k in sorted(spec)))
    for tag, kind in spec.items():
        c = reader.child(ln, tag)
        if c is None:
            if tag in LINK_REQUIRED[ln.tag]:
                raise reader.error(ln, f"missing <{tag}>", f"<{tag}> in <{ln.tag}>")
            continue
        if kind == "vec":
            d[tag] = reader.vec3(c).tolist()
        elif kind == "num":
            d[tag] = reader.num(c, "value", nonnegative=True)
        elif kind == "raw":
            d[tag] = {s.tag: s.get("value") for s in c}
            for s in c:
                reader.mark(s, "value")
        elif kind == "coef":
            if c.get("file") is not None:
                d[tag] = _read_coef_file(reader, c, tag)
            elif c.get("value") is not None:
                d[tag] = reader.num(c, "value", nonnegative=True)
            else:
                rows = [(reader.num(r, "time", nonnegative=True), reader.num(r, "value", nonnegative=True))
                        for r in reader.children(c)]
                if not rows:
                    raise reader.error(c, f"<{tag}> has no value", 'value=".." or a time table')
                if any(t2 < t1 for (t1, _), (t2, _) in zip(rows, rows[1:])):
                    raise reader.error(c, "times are not in increasing order", "non-decreasing times")
                d[tag] = {"times": [r[0] for r in rows], "values": [r[1] for r in rows]}
    for tag in ("rotvector", "slidingvector"):
        if tag in d and tag in LINK_REQUIRED[ln.tag] and np.linalg.norm(d[tag]) == 0:
            raise reader.error(ln, f"<{tag}> is the zero vector", "a non-zero direction")
    if d["type"] == "pulley" and (d["radius"] <= 0 or d["radius2"] <= 0):
        raise reader.error(ln, "pulley radii must be positive", "radius > 0 and radius2 > 0")
    return d
