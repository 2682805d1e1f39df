"""From a gencase output to the multibody engine: bodies, shapes, materials and links.

DualSPHysics's ``<special><chrono>`` section names the bodies (``bodyfixed``,
``bodyfloating``, ``bodymoving``) by mkbound; masses, centres and inertias come
from ``<floatings>`` (resolved by gencase from the particles). With
``<collision activate="true">`` a body with a ``modelfile`` collides through a
cloud of its own boundary particles, as the smooth surface DualSPHysics's Chrono
collides (the triangle mesh of ``modelfile="AutoActual"``): the surface
particles' tangent planes dp/2 in front of them on flat faces, spheres of radius
dp/2 at edges and corners (:func:`sphdvi.dvi.collision.cloud_surface`), so two
flat faces touch where their particle layers are one dp apart whatever the
particles' lateral alignment, with a collision envelope of ``distancedp``·dp.

Links map one to one: ``link_hinge`` → hinge, ``link_spheric`` → spherical,
``link_pointline`` → point-line (``rotvector``/``rotvector2`` lock rotations),
``link_linearspring`` → spring-damper, ``link_coulombdamping`` → Coulomb damper,
``link_pulley`` → pulley. Stiffness and damping tables become time tables (a point-line's act on
its rotations only). A ``<floating>`` the section does not list is a free body without links or
collision shape (DualSPHysics moves it with its own rigid-body update); ``<scaleforce>`` factors
are returned per body for the coupling.
In 2D cases bodies move in the x–z plane (y translation and x, z rotations locked).
A ``<floating>``'s ``<linearvel>``/``<angularvel>`` tables impose its velocity (a ``none``
component stays free) and ``<linearforce>``/``<angularforce>`` add an external force and
torque, both linearly interpolated in time and held beyond the table's ends.
"""
from __future__ import annotations

import numpy as np

from .bodychecks import body_sizes, startup_warnings
from .errors import CaseError

TYPE_FLOATING, TYPE_MOVING, TYPE_FLUID = 2, 1, 3


def _vector_series(spec, what, allow_none=True):
    """A ``<linearvel>``-style table ({"times", "values"} with None for a free component,
    or {"file"}, what an older case file holds: rows time;x;y;z, read as the case reader reads
    it, ``none`` a free component where ``allow_none``) -> t -> [x|None, y|None, z|None],
    linear in time and held beyond the ends; None when no table."""
    if spec is None:
        return None
    if "file" in spec:
        from .case.datafiles import read_vector_table
        spec = dict(zip(("times", "values"), read_vector_table(spec["file"], what, allow_none=allow_none)))
    times = np.asarray(spec["times"], float)
    values = np.asarray([[np.nan if c is None else c for c in row] for row in spec["values"]], float)
    free = np.isnan(values).any(axis=0)        # 'none' in any row: that component is free
    from .tables import TimeTable               # contiguous columns, a kept row: O(1) per step
    table = TimeTable(times, values)

    def at(t):
        row = table.at(t)
        return [None if free[k] else float(row[k]) for k in range(3)]
    return at


def _floating_drivers(fb, name):
    """(imposed_velocity, external_load) callables of a floating body's tables, or None."""
    lin = _vector_series(fb.get("linearvel"), f"<linearvel> of '{name}'")
    ang = _vector_series(fb.get("angularvel"), f"<angularvel> of '{name}'")
    force = _vector_series(fb.get("linearforce"), f"<linearforce> of '{name}'", allow_none=False)
    torque = _vector_series(fb.get("angularforce"), f"<angularforce> of '{name}'", allow_none=False)

    def imposed(t):
        return (lin(t) if lin else [None] * 3) + (ang(t) if ang else [None] * 3)

    def load(t):
        return (np.asarray(force(t) if force else [0.0] * 3, float),
                np.asarray(torque(t) if torque else [0.0] * 3, float))
    return (imposed if lin or ang else None), (load if force or torque else None)


def _table(v):
    """A stiffness/damping value: number, {"times","values"} or {"file"} → number or [[t, v], ...].
    The case reader reads a ``file=`` table at gencase (``{"file"}`` is what an older case file
    holds): read here the same way, as DualSPHysics's JLinearValue::LoadFile (JReadDatafile's
    separators and '#' comments, at least two rows)."""
    if v is None or isinstance(v, (int, float)):
        return v
    if "times" not in v:
        from .case.datafiles import read_columns
        data = read_columns(v["file"], 2, "stiffness/damping table")
        if data.shape[0] < 2:
            raise CaseError("stiffness/damping table: fewer than two (time, value) rows", file=v["file"],
                            expected="at least two lines 'time value' (DualSPHysics: \"Cannot be less than two "
                                     "values.\")")
        return data[:, :2].tolist()
    return [[t, x] for t, x in zip(v["times"], v["values"])]


def links_property(mkbound, links):
    """The property of an mkbound from every ``<link>`` that names it, as JCasePropLinks::GetProps:
    the links' properties joined in one combination (two links "a" and "b" are one link "a+b"),
    which :func:`_material_for` sorts and rids of repeats (GetPropsSort); None if no link names it."""
    combos = [ln["property"] for ln in links if mkbound in ln.get("mkbound", [])]
    return "+".join(combos) if combos else None


def _material_for(mkbound, case_json, body_property=None):
    """(name, contact spec) of an mkbound's property: the floating's own ``property``, else
    the properties of all the ``<link>`` elements naming the mkbound (:func:`links_property`).
    A combination ``"steel + userdef01"`` is read as DualSPHysics reads it
    (JCaseProperties::GetPropsSort, JSph::LoadDemData): the names sorted (as written, repeats
    dropped), each value taken from the first of them that has it, except that a ``*_User``
    value of any of them wins over the plain ones."""
    mats = case_json.get("materials", {})
    combo = body_property
    if combo is None:
        combo = links_property(mkbound, case_json.get("material_links", []))
    if combo is None:
        return None, None
    names = sorted({n.strip() for n in combo.split("+") if n.strip()})
    if not names or any(n not in mats for n in names):
        return None, None
    name = " + ".join(names)
    spec = {"name": name}
    for key, out in (("kfric", "friction"), ("restitution", "restitution"), ("young", "young"),
                     ("poisson", "poisson")):
        value = _first_value(key, [mats[n] for n in names])
        if value is not None:
            spec[out] = value
    return name, spec


DEM_KEYS = (("friction", "Kfric"), ("restitution", "Restitution_Coefficient"), ("young", "Young_Modulus"),
            ("poisson", "PoissonRatio"))


def dem_material(mkbound: int, case_json: dict, body_property=None) -> dict:
    """The DEM material of a boundary block (``RigidAlgorithm`` 2: JSph::LoadDemData), resolved as
    :func:`_material_for`: {friction, restitution, young, poisson, name}. Raises ValueError naming
    what is missing or out of range (DualSPHysics: "Object mk=.. (mkbound=..) - Value of Kfric is
    invalid."; sphdvi also refuses e = 0 and E = 0, where the model's damping or stiffness is infinite)."""
    name, spec = _material_for(mkbound, case_json, body_property)
    if spec is None:
        raise ValueError(f"mkbound {mkbound} has no property: DEM (RigidAlgorithm 2) needs its "
                         + ", ".join(label for _, label in DEM_KEYS))
    missing = [label for key, label in DEM_KEYS if spec.get(key) is None]
    if missing:
        raise ValueError(f"mkbound {mkbound}: its property '{name}' has no {' or '.join(missing)}, which DEM "
                         f"(RigidAlgorithm 2) needs (DualSPHysics: \"Value of {missing[0]} is invalid.\")")
    if not spec["restitution"] > 0.0:
        raise ValueError(f"mkbound {mkbound}: property '{name}' has Restitution_Coefficient 0, an infinite DEM damping")
    if not spec["young"] > 0.0:
        raise ValueError(f"mkbound {mkbound}: property '{name}' has Young_Modulus 0, an infinite DEM stiffness")
    return spec


def dem_table(data: dict):
    """The :class:`sphdvi.sph.dem.DemTable` of a case file read by :func:`sphdvi.io.casefile.read_case_h5`:
    the DEM material of every boundary block (fixed, moving, floating) and the floating bodies'
    masses. Raises CaseError for a block without a complete material."""
    from .sph.dem import DemTable
    js = data["json"]
    p = data["particles"]
    fluidcount = int(js["mkconfig"]["fluidcount"])
    mk = np.asarray(p["mk"], np.int64)
    mks = sorted(set(mk[np.asarray(p["type"]) != TYPE_FLUID].tolist()))
    bodies = {int(b["mkbound"]): b for b in js.get("bodies_extra", [])}
    mat_of_mk = np.full(int(mk.max()) + 1 if mk.size else 1, -1, np.int64)
    rows = []
    for k, m in enumerate(mks):
        mkb = m - fluidcount - 1
        body = bodies.get(mkb)
        try:
            spec = dem_material(mkb, js, body.get("property") if body else None)
        except ValueError as exc:
            raise CaseError(str(exc), element="properties", expected="a <property> with Kfric, "
                            "Restitution_Coefficient, Young_Modulus and PoissonRatio for every boundary block, given "
                            "by <floating property=..> or <properties><links><link mkbound=..>") from None
        mat_of_mk[m] = k
        tau = (1.0 - spec["poisson"] ** 2) / spec["young"]
        rows.append((tau, spec["restitution"], spec["friction"], float(body["mass"]) if body else 0.0, spec["name"]))
    tau, rest, kfric, mass, names = (list(c) for c in zip(*rows)) if rows else ([], [], [], [], [])
    return DemTable(mat_of_mk, tau, rest, kfric, mass, names)


def _first_value(key, props):
    """``key`` of the first property giving it as ``*_User``, else of the first giving it."""
    for user in (True, False):
        for m in props:
            if m.get(key) is not None and (key in m.get("user", ())) == user:
                return m[key]
    return None


def mechanism_from_case(data: dict, motions=None) -> dict:
    """Build the inputs of :func:`sphdvi.dvi.run_bodies` from a case file read by
    :func:`sphdvi.io.casefile.read_case_h5`.

    Returns ``{"bodies", "links", "materials", "system", "mkbounds", "scaleforce", "points", "sizes",
    "dp", "warnings"}`` where ``mkbounds[i]`` is the mkbound of body i, ``points[i]`` its particles,
    ``sizes[i]`` its size (:func:`sphdvi.bodychecks.body_sizes`) and ``warnings`` the start-up warnings
    on the bodies (:func:`sphdvi.bodychecks.startup_warnings`) for the run to give.
    """
    js = data["json"]
    chrono = js.get("chrono") or {}
    consts = data["constants"]
    p = data["particles"]
    dp, is2d = float(consts["dp"]), bool(consts["is2d"])
    label = p["mk"].astype(np.int64) - int(js["mkconfig"]["fluidcount"]) - 1
    bound = p["type"] != TYPE_FLUID
    floating = {int(b["mkbound"]): b for b in js.get("bodies_extra", [])}
    collision = chrono.get("collision", {"activate": False, "distancedp": 0.5, "contactmethod": 0})
    entries = _body_entries(chrono.get("bodies") or [], floating)
    materials, bodies, mkbounds, points = {}, [], [], []
    for entry in entries:
        mkb = int(entry["mkbound"])
        sel = bound & (label == mkb)
        pts = p["pos"][sel]
        if pts.shape[0] == 0:
            raise CaseError(f"body '{entry['id']}' (mkbound {mkb}) has no particles")
        kind = entry["kind"]
        body = {"name": entry["id"], "kind": "fixed" if kind == "fixed" else kind}
        fb = floating.get(mkb)
        if kind == "floating":
            if fb is None:
                raise CaseError(f"bodyfloating '{entry['id']}' (mkbound {mkb}) is not in <floatings>")
            body.update(mass=fb["mass"], inertia=np.asarray(fb["inertia"]), pos=fb["center"],
                        vel=fb["linearvelini"], omega=fb["angularvelini"],
                        translation_dof=list(fb["translation_dof"]), rotation_dof=list(fb["rotation_dof"]))
            if is2d:
                body["translation_dof"][1] = 0
                body["rotation_dof"][0] = body["rotation_dof"][2] = 0
            body["imposed_velocity"], body["external_load"] = _floating_drivers(fb, entry["id"])
        else:
            centre = pts.mean(axis=0)
            body.update(mass=float(entry.get("massbody") or 1.0), inertia=(1.0, 1.0, 1.0), pos=centre.tolist())
            if kind == "moving" and motions is not None and mkb in motions.mkbounds:
                body["motion"] = _motion_callable(motions, mkb, centre)
        shapes = []
        if collision.get("activate") and entry.get("modelfile"):
            name, spec = _material_for(mkb, js, fb.get("property") if fb else None)
            if spec is not None and name not in materials:
                materials[name] = spec
            centre = np.asarray(body["pos"], float)
            shape = {"shape": "cloud", "points": pts - centre, "radius": 0.5 * dp, "material": name}
            if is2d:
                shape["plane_normal"] = (0.0, 1.0, 0.0)     # surface normals in the x-z plane
            shapes.append(shape)
        body["shapes"] = shapes
        bodies.append(body)
        mkbounds.append(mkb)
        points.append(pts)
    links = [_link(ln, bodies) for ln in chrono.get("links", [])]
    g = consts["gravity"]
    system = {"gravity": tuple(g), "contactmethod": "smc" if collision.get("contactmethod") == 1 else "nsc",
              "envelope": float(collision.get("distancedp", 0.5)) * dp}
    solver = chrono.get("solver") or {}
    if solver.get("type"):
        system["solver"] = solver["type"].lower()
    if solver.get("maxiter") is not None:       # <solver maxiter tolerance> (sphdvi's; the reader's)
        system["max_iter"] = int(solver["maxiter"])
    if solver.get("tolerance") is not None:
        system["tol"] = float(solver["tolerance"])
    if solver.get("exactjoints") is not None:    # <solver exactjoints> (sphdvi's): joint-only islands exact
        system["exact_joints"] = bool(solver["exactjoints"])
    sizes = body_sizes(points, dp)
    return {"bodies": bodies, "links": links, "materials": list(materials.values()), "system": system,
            "mkbounds": mkbounds, "scaleforce": _scale_forces(chrono.get("scaleforce") or [], mkbounds),
            "points": points, "sizes": sizes, "dp": dp,
            "warnings": startup_warnings(bodies, sizes, mkbounds, system.get("solver", "bb"), is2d)}


def _body_entries(listed: list, floating: dict) -> list:
    """The multibody system's bodies: the ``<chrono>`` section's, then every ``<floating>`` it
    does not list as a plain free body (no links, no collision shape). DualSPHysics moves such a
    floating with its own rigid-body update (JSphCpuSingle::RunFloating, ``usechrono`` false:
    JChronoObjects::ConfigBodyFloating finds no ``<bodyfloating>``), which for a body that no link
    or Chrono contact touches is what a free body here does; its fluid loads stay its own."""
    entries = list(listed)
    taken = {int(e["mkbound"]) for e in listed}
    ids = {e["id"] for e in listed}
    for mk in sorted(floating):
        if mk in taken:
            continue
        name = f"floating{mk}"
        while name in ids:
            name += "_free"
        ids.add(name)
        entries.append({"kind": "floating", "id": name, "mkbound": mk, "modelfile": None})
    return entries


def _scale_forces(items: list, mkbounds: list) -> np.ndarray:
    """Per body, the per-axis factors of ``<scaleforce><body mkbound x y z/>`` (1 where none):
    DualSPHysics's JChronoObjects::ReadScaleForces (JChBody::SetScaleForce). Applied to the
    fluid's force on the body (coupling.FloatingBodies.loads); see there what is confirmed."""
    scale = np.ones((len(mkbounds), 3))
    row = {int(m): i for i, m in enumerate(mkbounds)}
    for item in items:
        for mk in (item["mkbound"] if isinstance(item["mkbound"], list) else [item["mkbound"]]):
            if int(mk) in row:
                scale[row[int(mk)]] = item["scale"]
    return scale


def _motion_callable(motions, mkb, centre):
    def motion(t):
        rig = motions.transform(mkb, t)
        x = rig.R @ centre + rig.d
        return rig.V + np.cross(rig.W, x - rig.c), rig.W
    return motion


def _link(ln: dict, bodies: list) -> dict:
    """One ``<link_*>`` as a multibody link. Its name is the reader's (DualSPHysics's default
    names, JChronoObjects::ReadXml); a case file written before gets ``Link_<id1>_<id2>`` or
    ``Link_<id1>`` (to the ground). A point-line's stiffness/damping is torsional, on its free
    rotations only (the DSPH format's "Torsional stiffness [Nm/rad]"): it slides freely."""
    kind = ln["type"]
    b1, b2 = ln["idbody1"], ln.get("idbody2")
    name = ln.get("name") or (f"Link_{b1}_{b2}" if b2 else f"Link_{b1}")
    out = {"body1": b1, "body2": b2, "name": name}
    if kind == "hinge":
        out.update(kind="hinge", point=ln["rotpoint"], axis=ln["rotvector"])
    elif kind == "spheric":
        out.update(kind="spherical", point=ln["rotpoint"])
    elif kind == "pointline":
        out.update(kind="pointline", point=ln["rotpoint"], axis=ln["slidingvector"])
        if ln.get("rotvector") and np.linalg.norm(ln["rotvector"]) > 0:
            out["rot_axis"] = ln["rotvector"]
        if ln.get("rotvector2") and np.linalg.norm(ln["rotvector2"]) > 0:
            out["rot_axis2"] = ln["rotvector2"]
    elif kind == "linearspring":
        out.update(kind="spring", point1=ln["point_fb1"], point2=ln["point_fb2"],
                   stiffness=_table(ln["stiffness"]), damping=_table(ln.get("damping", 0.0)) or 0.0,
                   rest_length=ln["rest_length"])
        return out
    elif kind == "coulombdamping":
        out.update(kind="coulombdamper", point1=ln["point_fb1"], point2=ln["point_fb2"], force=ln["damping"])
        return out
    elif kind == "pulley":
        out.update(kind="pulley", axis=ln["rotvector"], radius=ln["radius"], radius2=ln["radius2"])
        return out
    else:
        raise CaseError(f"link type {kind} is not supported")
    for key in ("stiffness", "damping"):
        if ln.get(key) is not None:
            value = _table(ln[key])
            out[key] = {"rx": value, "ry": value, "rz": value} if kind == "pointline" else value
    return out
