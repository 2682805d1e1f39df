"""``sphdvi gencase``: a case file becomes particles, constants, bodies and links.

The steps follow GenCase: read the definition, draw, resolve the constants
from the drawn fluid, read everything else (expressions can now use H, B...),
assemble the particle arrays in DualSPHysics order (fixed boundary, moving,
floating, fluid; by mk within each type), set the initial density and
velocities, compute floating-body mass properties, check the whole, and write
``<casename>.h5`` plus ``<casename>_All.vtp`` for ParaView.
"""
from __future__ import annotations

import math
import os
import re
from dataclasses import asdict, dataclass, field

import numpy as np

from .._version import __version__
from ..errors import CaseError, Warnings
from .constants import hydrostatic_density, resolve_constants
from .model import Body, Case, Constants
from ..io.atomic import make_folder
from .flexstruc_xml import check_flexstrucs
from .reader import (case_name_from_path, open_case, parse_domain_spec, read_constantsdef,
                     read_mkconfig, read_sections, check_periodic)

TYPE_FIXED, TYPE_MOVING, TYPE_FLOATING, TYPE_FLUID = 0, 1, 2, 3
TYPE_NAMES = {0: "Fixed boundary", 1: "Moving boundary", 2: "Floating", 3: "Fluid"}
DEFAULT_MAX_NODES = 200_000_000
F32_MAX = float(np.finfo(np.float32).max)    # DualSPHysics stores masses, velocities, densities as float


@dataclass
class GenCaseResult:
    case: Case
    constants: Constants
    particles: dict
    bodies: list
    domain: dict
    mkinfo: list
    warnings: Warnings
    primitives: list = field(default_factory=list)
    files: list = field(default_factory=list)
    normals: np.ndarray | None = None      # the mDBC normals the case defines (None: none)


def define_builtin_variables(reader, cdef, casename: str) -> None:
    v = reader.vars
    v.define("Rhop0", cdef.rhop0, constant=True)
    for i, c in enumerate("xyz"):
        v.define(f"Gravity_{c}", float(cdef.gravity[i]), constant=True)
    v.define("CaseName", casename, constant=True)


def define_computed_variables(reader, consts) -> None:
    """GenCase's variables known once the fluid is drawn: H (smoothing length), B, MassFluid,
    MassBound. A case that defined a variable of the same name keeps its own (its later
    expressions mean it), with a warning that the built-in is not defined."""
    for name, value in (("H", consts.h), ("B", consts.b), ("MassFluid", consts.massfluid),
                        ("MassBound", consts.massbound)):
        if name in reader.vars.values:
            reader.warnings.add(f"the case defines a variable '{name}' ({reader.vars.values[name]!r}); it is kept, so "
                                f"GenCase's built-in {name} ({value:.6g}) is not available to its expressions",
                                file=reader.file)
            continue
        reader.vars.define(name, value, constant=True)


def build_case(path: str, outdir: str | None = None, *, max_nodes: int = DEFAULT_MAX_NODES,
               warnings: Warnings | None = None, dp: float | None = None) -> GenCaseResult:
    """Read, draw and assemble a case (nothing is written).

    ``dp`` overrides ``<definition dp>`` (GenCase's ``-dp:`` option), for convergence studies.
    """
    warnings = warnings if warnings is not None else Warnings()
    root, reader, text = open_case(path, warnings)
    if dp is not None:
        definition = root.find("casedef/geometry/definition")
        if not (dp > 0 and math.isfinite(dp)):
            raise CaseError(f"--dp {dp} is not a positive number", file=path)
        definition.set("dp", repr(float(dp)))
    if outdir is not None:
        make_folder(outdir)
    casename = case_name_from_path(path)
    casedef = root.find("casedef")
    cdef = read_constantsdef(reader, casedef)
    boundcount, fluidcount = read_mkconfig(reader, casedef)
    define_builtin_variables(reader, cdef, casename)
    geometry = reader.child(casedef, "geometry", required=True)
    from .draw import run_geometry
    drawing = run_geometry(reader, geometry, casename=casename, outdir=outdir, max_nodes=max_nodes)
    check_dp(reader, geometry, drawing.dp, drawing.is2d, cdef.rhop0)
    if drawing.pos.shape[0] == 0:
        check_domain_has_nodes(reader, geometry, drawing)
        raise reader.error(geometry, "the geometry commands created no particles",
                           "drawing commands inside <mainlist> that create particles inside pointmin..pointmax")
    warn_no_fluid(drawing, reader)
    fluid_z = drawing.pos[drawing.is_fluid, 2]
    with np.errstate(over="ignore", invalid="ignore"):      # checked next
        consts = resolve_constants(cdef, drawing.dp, drawing.is2d, drawing.posy2d, fluid_z)
    check_constants(reader, casedef, consts, fluid=bool(fluid_z.size))
    if fluid_z.size and not consts.cs0 > 0:
        raise reader.error(casedef.find("constantsdef"), f"the speed of sound is zero: {_zero_sound_cause(cdef)}",
                           'a <speedsound value=".."/> or <b value=".."/> above 0, or coefsound, hswl and '
                           'speedsystem above 0')
    define_computed_variables(reader, consts)
    case = Case(name=casename, file=os.path.abspath(path), source=text, constantsdef=cdef,
                boundcount=boundcount, fluidcount=fluidcount)
    read_sections(case, root, reader)
    check_periodic(reader, root, case.parameters_set, case.parameters, consts.is2d)
    particles, mkinfo = assemble_particles(case, drawing, consts, reader)
    normals = case_normals(case, particles, consts, drawing, reader)
    bodies = floating_bodies(case, particles, consts, drawing.primitives, reader)
    apply_floating_velocities(particles, bodies, consts.is2d, case, reader)
    check_particle_values(particles, reader)
    domain = resolve_domain(case, particles, consts, reader)
    check_case(case, particles, bodies, mkinfo, domain, reader)
    if case.special.get("flexstrucs"):
        check_flexstrucs(case, particles, consts.is2d, reader)
    if case.special.get("inout"):
        check_inout(case.special["inout"], particles, consts.is2d, reader)
    if case.special.get("boundcorr"):
        check_boundcorr(case.special["boundcorr"], particles, reader)
    warn_gauges_outside(case.special.get("gauges"), domain, consts.is2d, reader)
    reader.warn_unread_attributes(root)
    return GenCaseResult(case=case, constants=consts, particles=particles, bodies=bodies, domain=domain,
                         mkinfo=mkinfo, warnings=warnings, primitives=list(drawing.primitives),
                         files=list(drawing.shape_files), normals=normals)


def _zero_sound_cause(cdef) -> str:
    """Which input made c0 = speedsound = coefsound·speedsystem, speedsystem = sqrt(|g|·hswl), zero."""
    if cdef.speedsound is not None:
        return "speedsound is 0"
    if cdef.coefsound == 0:
        return "coefsound is 0 (speedsound = coefsound·speedsystem)"
    if cdef.speedsystem is not None:
        return "speedsystem is 0 (speedsound = coefsound·speedsystem)"
    if cdef.hswl is not None:
        return "hswl is 0 (speedsystem = sqrt(|g|·hswl))"
    if not any(cdef.gravity):
        return "the gravity is 0 (speedsystem = sqrt(|g|·hswl))"
    return "the fluid has no height (hswl, auto, is max z - min z of the fluid)"


def check_domain_has_nodes(reader, geometry, drawing) -> None:
    """A domain narrower than dp on an axis holds no node there: GenCase places
    floor((pointmax - pointmin)/dp) nodes per axis (a 3D case with pointmax y = pointmin y + dp/2
    is empty; a 2D case gives pointmin and pointmax the same y)."""
    span = np.asarray(drawing.pointmax, float) - np.asarray(drawing.pointmin, float)
    for a, name in enumerate("xyz"):
        if a == 1 and drawing.is2d:
            continue
        if span[a] < drawing.dp * (1 - 1e-6):
            el = geometry.find("definition") if geometry.find("definition") is not None else geometry
            hint = "; for a 2D case give pointmin and pointmax the same y" if a == 1 else ""
            raise reader.error(el, f"the domain holds no node along {name}: pointmax - pointmin is "
                                   f"{float(span[a]):g} m, less than dp ({drawing.dp:g} m); GenCase places "
                                   f"floor((pointmax - pointmin)/dp) nodes per axis{hint}",
                               f"pointmax {name} at least one dp above pointmin {name}")


def check_dp(reader, geometry, dp: float, is2d: bool, rhop0: float) -> None:
    """A dp whose particle mass rhop0·dp³ (rhop0·dp² in 2D) is a finite float32, the precision
    DualSPHysics keeps masses in (GenCase's MassFluid/MassBound); dp=1e308 overflowed to an
    internal error."""
    ndim = 2 if is2d else 3
    limit = math.log10(F32_MAX) - math.log10(rhop0) if rhop0 <= F32_MAX else 300.0   # rhop0: check_constants
    if ndim * math.log10(dp) > limit:
        el = geometry.find("definition") if geometry.find("definition") is not None else geometry
        raise reader.error(el, f"dp={dp:g} is too large: a particle's mass rhop0·dp^{ndim} "
                               f"({rhop0:g}·{dp:g}^{ndim}) is beyond the float range ({F32_MAX:.3g})",
                           "dp, the distance between particles [m], of the size of the particles")


def check_constants(reader, casedef, consts: Constants, fluid: bool = True) -> None:
    """The resolved constants (rhop0, h, B, cs0, masses...) finite and within the float range
    DualSPHysics keeps them in (its StCteSph constants are float): an absurd <constantsdef> value
    (coefsound 1e300, or a gravity of 1e300 with a fluid: B overflows) is refused here, not left to
    overflow in the run. Without fluid the speed of sound and B are not used: a gravity of 1e306
    is left to the run, which stops on the body that goes out, with the cause."""
    sound = ("coefsound", "hswl", "speedsystem", "cs0", "b")
    order = ("rhop0", "gamma", "coefsound", "cflnumber", "hswl", "coefh", "speedsystem", "cs0", "h", "b")
    values = {k: getattr(consts, k) for k in order}          # the inputs first, then what comes of them
    values.update({k: v for k, v in consts.to_dict().items() if isinstance(v, float) and k not in values})
    values = {k: v for k, v in values.items() if fluid or k not in sound}
    for name, value in values.items():
        if not abs(value) <= F32_MAX:
            el = casedef.find("constantsdef") if casedef.find("constantsdef") is not None else casedef
            raise reader.error(el, f"{name} = {value:g} is not a finite number within the float range "
                                   f"({F32_MAX:.3g}) DualSPHysics keeps its constants in",
                               "constants of physical sizes (B = rhop0·cs0²/gamma, cs0 = coefsound·"
                               "sqrt(|g|·hswl), massfluid = rhop0·dp³ are computed from them)")


def check_particle_values(particles: dict, reader) -> None:
    """After the <initials>, the floating bodies and their velocities: every position, velocity,
    density and mass finite and within the float range the outputs keep (a <rotateaxis> about a
    zero axis gave NaN positions, a massbody of 1e300 an overflow warning and then a blow-up)."""
    for name, unit in (("pos", "m"), ("vel", "m/s"), ("rhop", "kg/m3"), ("mass", "kg")):
        a = np.asarray(particles[name], float)
        with np.errstate(invalid="ignore", over="ignore"):
            bad = ~(np.abs(a) <= F32_MAX)
        if bad.ndim > 1:
            bad = bad.any(axis=1)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            idp, mk = int(particles["idp"][i]), int(particles["mk"][i])
            raise CaseError(f"{int(bad.sum())} particle(s) get a {name} that is not a finite number within the float "
                            f"range ({F32_MAX:.3g}): particle {idp} (mk {mk}) has {np.asarray(a[i]).tolist()} {unit}",
                            file=reader.file,
                            expected="finite values: check the <initials>, <floatings> and <constantsdef> values "
                                     "of that mk")


def warn_no_fluid(drawing, reader) -> None:
    """Warn when fluid was drawn or filled (``setmkfluid`` + a drawing or fill command) but no
    fluid particle is left; cases without any fluid command stay silent."""
    fluid_cmds = [p for p in drawing.primitives if p.get("fluid")]
    if not fluid_cmds or drawing.count_fluid:
        return
    lines = sorted({p["line"] for p in fluid_cmds if p.get("line")})
    where = (f" (line{'s' if len(lines) > 1 else ''} {', '.join(map(str, lines[:10]))}"
             f"{', ...' if len(lines) > 10 else ''})") if lines else ""
    made = sum(int(p.get("nodes") or 0) for p in fluid_cmds)
    why = ("later drawing commands replaced all of them" if made else
           "they created none (a fill seed on a boundary or outside its box, a shape outside "
           "pointmin..pointmax, or drawpoints disabled)")
    reader.warnings.add(f"no fluid particles were created: the {len(fluid_cmds)} fluid "
                        f"command{'s' if len(fluid_cmds) > 1 else ''}{where} drew or filled "
                        f"fluid, but {why}; the case has no fluid",
                        file=reader.file, line=lines[0] if lines else None, element="geometry")


# ---------------------------------------------------------------------------
# particles
# ---------------------------------------------------------------------------
def bound_roles(case: Case) -> tuple[set, set]:
    """mkbound labels that float, and labels with an imposed motion (incl. wave paddles)."""
    floating = {mk for f in case.floatings for mk in f.mkbound}
    moving = {m["ref"] for m in case.motions}
    return floating, moving


def assemble_particles(case: Case, drawing, consts: Constants, reader):
    """Particle arrays in DualSPHysics order with types, global mk, density and velocity."""
    is_fluid = np.asarray(drawing.is_fluid, dtype=bool)
    label = np.asarray(drawing.mk, dtype=np.int64)
    bad = label[is_fluid & (label >= case.fluidcount)]
    if bad.size:
        raise CaseError(f"mkfluid {int(bad.max())} is not below fluidcount={case.fluidcount}", file=reader.file,
                        line=reader.line_of("casedef/mkconfig"), element="mkconfig",
                        expected="mkfluid < fluidcount (raise fluidcount in <mkconfig>)")
    bad = label[~is_fluid & (label >= case.boundcount)]
    if bad.size:
        raise CaseError(f"mkbound {int(bad.max())} is not below boundcount={case.boundcount}", file=reader.file,
                        line=reader.line_of("casedef/mkconfig"), element="mkconfig",
                        expected="mkbound < boundcount (raise boundcount in <mkconfig>)")
    floating, moving = bound_roles(case)
    both = floating & moving
    if both:
        raise CaseError(f"mkbound {sorted(both)} is both floating and moving", file=reader.file,
                        line=next((m["line"] for m in case.motions if m["ref"] in both), None), element="motion",
                        expected="a floating body or an imposed motion, not both")
    ptype = np.full(label.shape, TYPE_FIXED, dtype=np.uint8)
    ptype[is_fluid] = TYPE_FLUID
    if floating:
        ptype[~is_fluid & np.isin(label, list(floating))] = TYPE_FLOATING
    if moving:
        ptype[~is_fluid & np.isin(label, list(moving))] = TYPE_MOVING
    mk = np.where(is_fluid, label + 1, label + case.fluidcount + 1).astype(np.int32)
    order = np.lexsort((np.arange(label.size), mk, ptype))
    pos = np.ascontiguousarray(drawing.pos[order], dtype=np.float64)
    ptype, mk, label, is_fluid = ptype[order], mk[order], label[order], is_fluid[order]
    n = pos.shape[0]
    mass = np.where(is_fluid, consts.massfluid, consts.massbound).astype(np.float64)
    rhop = np.full(n, consts.rhop0)
    vel = np.zeros((n, 3))
    if is_fluid.any():
        rhop[is_fluid] = initial_fluid_density(pos[is_fluid], consts, case.constantsdef.rhopgradient)
    particles = {"pos": pos, "vel": vel, "rhop": rhop, "mass": mass, "type": ptype, "mk": mk,
                 "idp": np.arange(n, dtype=np.int64), "label": label}
    apply_initials(case, particles, consts, reader)
    mkinfo = []
    for t in (TYPE_FIXED, TYPE_MOVING, TYPE_FLOATING, TYPE_FLUID):
        for m in np.unique(mk[ptype == t]):
            sel = np.flatnonzero((ptype == t) & (mk == m))
            mkinfo.append({"type": int(t), "mk": int(m), "label": int(label[sel[0]]),
                           "begin": int(sel[0]), "count": int(sel.size)})
    return particles, mkinfo


def initial_fluid_density(pos: np.ndarray, consts: Constants, rhopgradient: int) -> np.ndarray:
    """rhopgradient 1: ρ0; 2: hydrostatic below the top of each particle's water column;
    3: hydrostatic below the highest fluid particle."""
    if rhopgradient == 1:
        return np.full(pos.shape[0], consts.rhop0)
    z = pos[:, 2]
    if rhopgradient == 3:
        top = np.full(z.shape, z.max())
    else:
        key_x = np.round((pos[:, 0] - pos[:, 0].min()) / consts.dp).astype(np.int64)
        key_y = np.round((pos[:, 1] - pos[:, 1].min()) / consts.dp).astype(np.int64)
        key = key_x * (key_y.max() + 1) + key_y
        uniq, inverse = np.unique(key, return_inverse=True)
        col_top = np.full(uniq.size, -np.inf)
        np.maximum.at(col_top, inverse, z)
        top = col_top[inverse]
    return hydrostatic_density(top - z, consts.rhop0, consts.gravity[2], consts.b, consts.gamma)


def _select(case, particles, item):
    """Particles named by an <initials> item (mkfluid/mkbound labels, optional onlypos box)."""
    ptype, label, pos = particles["type"], particles["label"], particles["pos"]
    sel = np.zeros(ptype.size, dtype=bool)
    if "mkfluid" in item:
        fluid = ptype == TYPE_FLUID
        sel |= fluid if item["mkfluid"] is None else fluid & np.isin(label, item["mkfluid"])
    if "mkbound" in item:
        sel |= (ptype != TYPE_FLUID) & np.isin(label, item["mkbound"])
    from .normal_ops import onlypos_mask
    return sel & onlypos_mask(pos, item.get("onlypos"))


def apply_initials(case: Case, particles: dict, consts: Constants, reader) -> None:
    """``<initials>``: velocities, densities, moves and rotations of selected particles; then the
    ``<fluidvelocity>`` items of ``<special><initialize>``."""
    pos, vel, rhop = particles["pos"], particles["vel"], particles["rhop"]
    items = list(case.initials) + list((case.special.get("initialize") or {}).get("velocity", []))
    for item in items:
        sel = _select(case, particles, item)
        if not sel.any():      # DualSPHysics (JDsInitializeOp_FluidVel::Run) reports "(0 particles)" and goes on
            tag = item.get("element", item["type"])
            reader.warnings.add(f"it selects no particles (none of its mkfluid/mkbound labels"
                                f"{' inside its onlypos box' if item.get('onlypos') else ''}): it sets nothing",
                                file=reader.file, line=item["line"], element=tag)
            continue
        kind = item["type"]
        if kind == "velocity":
            if "vel" in item:
                vel[sel] = item["vel"]
            else:
                d = np.asarray(item["direction"], float)
                norm = np.linalg.norm(d)
                if norm == 0:
                    raise CaseError("velocity <direction> is zero", file=reader.file, line=item["line"],
                                    element="velocity", expected="a non-zero direction")
                d = d / norm
                z = pos[sel, 2]
                p = item["params"]
                if item["profile"] == "velocity":
                    mag = np.full(z.shape, p["v"])
                elif item["profile"] == "velocity2":      # linear, extrapolated beyond z..z2
                    mag = p["v"] + (p["v2"] - p["v"]) * (z - p["z"]) / (p["z2"] - p["z"])
                else:
                    coef = np.polyfit([p["z"], p["z2"], p["z3"]], [p["v"], p["v2"], p["v3"]], 2)
                    mag = np.polyval(coef, z)
                vel[sel] = mag[:, None] * d[None, :]
        elif kind == "densityuniform":
            rhop[sel] = item["rhop"]
        elif kind == "densitygradient":
            p1, p2 = np.asarray(item["pos1"]), np.asarray(item["pos2"])
            axis = p2 - p1
            length2 = float(axis @ axis)
            s = np.clip((pos[sel] - p1) @ axis / length2, 0.0, 1.0) if length2 > 0 else 0.0
            rhop[sel] = item["rhop1"] + s * (item["rhop2"] - item["rhop1"])
        elif kind == "densitydepth":
            zs = item["posswl"][2] if item.get("posswl") else pos[sel, 2].max()
            g = item.get("gravity", consts.gravity)[2]
            r0 = item.get("rhop0", consts.rhop0)
            gam = item.get("gamma", consts.gamma)
            b = item.get("b", consts.b)
            rhop[sel] = hydrostatic_density(zs - pos[sel, 2], r0, g, b, gam)
        elif kind == "move":
            pos[sel] += np.asarray(item["move"])
        elif kind == "rotateaxis":
            p1, p2 = np.asarray(item["axisp1"]), np.asarray(item["axisp2"])
            # DualSPHysics's sense (JMatrix4::MatrixRot, as <rotateline> and <motion>): −angle
            # right-handed about axisp1 → axisp2, i.e. +angle about axisp2 → axisp1
            pos[sel] = rotate_about_axis(pos[sel], p2, p1, math.radians(item["angle_deg"]))


def case_normals(case: Case, particles: dict, consts: Constants, drawing, reader) -> np.ndarray | None:
    """The mDBC normals the case defines: ``<normals>`` (GenCase), then the boundnormal
    operations of ``<special><initialize>`` (the solver's), in document order
    (:mod:`sphdvi.case.normal_ops`). None when it defines none: the run then derives every
    boundary's normal from the particles. Warns of an operation that selects no boundary
    particle and of normals that reach no particle at all."""
    ops = list(case.normals) + list((case.special.get("initialize") or {}).get("normals", []))
    if not ops:
        return None
    import functools

    from .normal_ops import apply_normal_ops
    from .normals import boundary_normals
    pos, ptype = particles["pos"], particles["type"]
    mkbound = np.where(ptype != TYPE_FLUID, particles["label"], -1)
    normals = np.zeros_like(pos)
    through = []
    empty = apply_normal_ops(
        normals, ops, pos, ptype, mkbound, dp=consts.dp, h=consts.h, is2d=consts.is2d, posy2d=drawing.posy2d,
        geometry=lambda op: geometry_triangles(op, case.name, drawing, reader),
        computed=functools.cache(lambda: boundary_normals(pos, ptype, consts.dp, consts.is2d)), on_surface=through)
    for op, counts in through:
        reader.warnings.add(
            f"the normals geometry passes through {sum(counts.values())} boundary particles (mkbound "
            + ", ".join(f"{mk}: {n}" for mk, n in sorted(counts.items())) + "): a particle on the surface gets "
            "no normal, so mDBC leaves it DBC; draw the geometry dp/2 in front of the wall's face layer (the "
            "particles' surface), as GenCase's examples do", file=reader.file, line=op["line"], element=op["tag"])
    for op in empty:
        reader.warnings.add(f"<{op['tag']}> selects no boundary particle (mkbound '{op['mkbound'] or 'all'}'"
                            f"{' inside its onlypos box' if op.get('onlypos') else ''})",
                            file=reader.file, line=op["line"], element=op["tag"])
    if not np.any(normals[ptype != TYPE_FLUID]):
        reader.warnings.add("the case's normals reach no boundary particle: mDBC (Boundary=2) would have "
                            "nothing to correct, and a run with it stops", file=reader.file,
                            line=ops[0]["line"], element=ops[0]["tag"])
    return normals


SHAPE_SUFFIXES = ("_Actual", "_Dp")   # GenCase's names for a <shapeout>'s shapes as drawn / on the lattice


def geometry_triangles(op: dict, casename: str, drawing, reader) -> tuple:
    """The boundary triangles (T, 3, 3) of a ``norgeometry`` and the mk of each (None for a
    mesh file): a ``<shapeout>`` of this case (``[CaseName]_hdp_Actual.vtk`` names the shapes
    that ``<shapeout file="hdp">`` wrote), else a mesh file in the case folder."""
    text = re.sub(r"\[casename\]", lambda _: casename, op["file"], flags=re.IGNORECASE)
    stem, ext = os.path.splitext(os.path.basename(text.replace("\\", "/")))
    names = [stem] + [stem[: -len(s)] for s in SHAPE_SUFFIXES if stem.endswith(s)]
    names += [n[len(casename) + 1:] for n in names if n.startswith(casename + "_")]
    for name in names:
        if name in drawing.shape_sets:
            tris, mk, fluid = drawing.shape_sets[name]
            return tris[~fluid], mk[~fluid]
    base = os.path.normpath(os.path.abspath(reader.base_dir))
    path = os.path.normpath(os.path.join(base, text))
    where = dict(file=reader.file, line=op["line"], element=op["tag"])
    if os.path.commonpath([path, base]) != base:
        raise CaseError(f"geometryfile '{op['file']}' lies outside the case folder {base}",
                        expected="a <shapeout> of the case or a mesh file beside it", **where)
    if not os.path.isfile(path):
        raise CaseError(f"geometryfile '{op['file']}': no <shapeout file=\"{names[-1]}\"> in the geometry and no "
                        f"file {path}", expected="the shapes of a <shapeout> (e.g. file=\"[CaseName]_hdp_Actual.vtk\" "
                        "for <shapeout file=\"hdp\"/>) or a mesh file (STL, PLY, VTK)", **where)
    from .draw.meshfile import MeshError, read_triangles
    kind = {".stl": "stl", ".ply": "ply"}.get(ext.lower(), "vtk")
    try:
        return read_triangles(path, kind), None
    except (MeshError, OSError) as exc:
        raise CaseError(f"geometryfile '{op['file']}': {exc}", expected="a triangle mesh (STL, PLY, VTK)",
                        **where) from None


def rotate_about_axis(points: np.ndarray, p1, p2, angle: float) -> np.ndarray:
    """Rotate points by ``angle`` (rad, right-handed) about the line p1→p2 (Rodrigues' formula)."""
    k = np.asarray(p2, float) - np.asarray(p1, float)
    k = k / np.linalg.norm(k)
    r = points - p1
    c, s = math.cos(angle), math.sin(angle)
    return p1 + r * c + np.cross(k, r) * s + np.outer(r @ k, k) * (1 - c)


# ---------------------------------------------------------------------------
# floating bodies
# ---------------------------------------------------------------------------
def particle_inertia(pos: np.ndarray, center: np.ndarray, mpart: float) -> np.ndarray:
    """Inertia tensor of point masses about ``center``: Σ m [(r·r) I − r rᵀ], its diagonal
    summed as Σ m (y² + z²) ... so that it is never negative (Σ r·r − Σ x² left −3e-17 for a
    row of particles along x: DualSPHysics's chrono/01 CaseDemolisher, mkbound 3)."""
    r = pos - center
    out = -(r.T @ r)
    sq = np.einsum("ij,ij->j", r, r)             # Σ x², Σ y², Σ z²
    out[np.diag_indices(3)] = [sq[1] + sq[2], sq[0] + sq[2], sq[0] + sq[1]]
    return mpart * out


def _mk_list(values) -> str:
    """``[51, 52, 53, 60]`` -> ``"51-53, 60"``."""
    runs, out = [], []
    for v in sorted(values):
        if runs and v == runs[-1][1] + 1:
            runs[-1][1] = v
        else:
            runs.append([v, v])
    for a, b in runs:
        out.append(str(a) if a == b else f"{a}-{b}")
    return ", ".join(out)


def floating_bodies(case: Case, particles: dict, consts: Constants, primitives, reader) -> list:
    """Mass, centre and inertia of each floating mkbound, from its particles (as GenCase)."""
    bodies = []
    ptype, label, pos = particles["type"], particles["label"], particles["pos"]
    vol = consts.dp ** (2 if consts.is2d else 3)
    floating_drawn = set(np.unique(label[ptype == TYPE_FLOATING]).tolist())
    for fd in case.floatings:
        drawn = [mkb for mkb in fd.mkbound if mkb in floating_drawn]
        if not drawn:
            # GenCase passes over it where other <floating> elements made bodies (DualSPHysics's 14_DEM
            # CaseManyFloatings draws mkbound 1-2000 and has a <floating mkbound="2001-42000">)
            mkb = fd.mkbound[0] if len(fd.mkbound) == 1 else f"{fd.mkbound[0]}-{fd.mkbound[-1]}"
            if not floating_drawn:
                raise CaseError(f"floating mkbound {mkb} has no particles", file=reader.file, line=fd.line,
                                element="floating", expected="an mkbound drawn by the geometry commands")
            reader.warnings.add(f"floating mkbound {mkb} drew no particles: this <floating> makes no body (the "
                                "others do)", file=reader.file, line=fd.line, element="floating")
            continue
        missing = [mkb for mkb in fd.mkbound if mkb not in drawn]
        if missing:
            # GenCase applies a <floating> to the mk blocks the geometry drew: DualSPHysics's chrono
            # examples DamBreak1Cube ("51-53", 51 drawn) and ZipLine ("2-20", 2-11 drawn) rely on it
            reader.warnings.add(f"mkbound {_mk_list(missing)} of this <floating> drew no particles: it applies to "
                                f"mkbound {_mk_list(drawn)}", file=reader.file, line=fd.line, element="floating")
        for mkb in drawn:
            sel = np.flatnonzero((ptype == TYPE_FLOATING) & (label == mkb))
            count = int(sel.size)
            rhopbody = fd.rhopbody if fd.rhopbody is not None else (
                fd.relativeweight * consts.rhop0 if fd.relativeweight is not None else None)
            if fd.massbody is not None:
                massbody = fd.massbody
            else:
                massbody = rhopbody * vol * count
            if isinstance(fd.masspart, float):
                masspart = fd.masspart
            elif rhopbody is not None and fd.masspart is None:
                masspart = rhopbody * vol
            else:
                masspart = massbody / count
            if not (abs(massbody) <= F32_MAX and abs(masspart) <= F32_MAX):
                raise CaseError(f"floating mkbound {mkb}: a body mass of {massbody:g} kg ({masspart:g} kg a "
                                f"particle) is beyond the float range ({F32_MAX:.3g}) DualSPHysics keeps masses in",
                                file=reader.file, line=fd.line, element="floating",
                                expected="a massbody (or rhopbody) of a physical size")
            center = np.asarray(fd.center, float) if fd.center is not None else pos[sel].mean(axis=0)
            with np.errstate(over="ignore", invalid="ignore"):      # checked next
                inertia = np.asarray(fd.inertia, float) if fd.inertia is not None else \
                    particle_inertia(pos[sel], center, massbody / count)
            if not (np.abs(center) <= F32_MAX).all() or not (np.abs(inertia) <= F32_MAX).all():
                raise CaseError(f"floating mkbound {mkb}: its centre {center.tolist()} or inertia "
                                f"{np.asarray(inertia).tolist()} is not finite within the float range ({F32_MAX:.3g})",
                                file=reader.file, line=fd.line, element="floating",
                                expected="a <center> and <inertia> of physical sizes")
            particles["mass"][sel] = masspart
            analytic = analytic_properties(primitives, mkb, consts.is2d,
                                           rhopbody if rhopbody is not None else None, massbody)
            bodies.append(Body(mkbound=int(mkb), mk=int(particles["mk"][sel[0]]), begin=int(sel[0]), count=count,
                               mass=float(massbody), masspart=float(masspart), center=center.tolist(),
                               inertia=inertia.tolist(), translation_dof=list(fd.translation_dof),
                               rotation_dof=list(fd.rotation_dof), linearvelini=list(fd.linearvelini),
                               angularvelini=list(fd.angularvelini), property=fd.property, analytic=analytic,
                               linearvel=fd.linearvel, angularvel=fd.angularvel,
                               linearforce=fd.linearforce, angularforce=fd.angularforce))
    return bodies


def apply_floating_velocities(particles: dict, bodies: list, is2d: bool = False, case=None, reader=None) -> None:
    """Initial body velocities become the rigid velocity field v + ω × (r − c) of its particles,
    without their components along a locked degree of freedom (translationDOF / rotationDOF 0, and
    in 2D the y translation and the x, z rotations), which the multibody body drops too (System.add_body;
    DualSPHysics applies the constraints to the body's velocity); a velocity given along a locked
    DOF is warned about (``reader``), at the <floating> of ``case`` that sets it."""
    for b in bodies:
        tmask = np.asarray(b.translation_dof, float).copy()
        rmask = np.asarray(b.rotation_dof, float).copy()
        if is2d:
            tmask[1] = 0.0
            rmask[0] = rmask[2] = 0.0
        v0, w0 = np.asarray(b.linearvelini, float), np.asarray(b.angularvelini, float)
        v, w = v0 * tmask, w0 * rmask
        if reader is not None and (np.any(v != v0) or np.any(w != w0)):
            line = next((fd.line for fd in (case.floatings if case is not None else []) if b.mkbound in fd.mkbound),
                        None)
            lost = [f"linearvelini {'xyz'[k]}={v0[k]:g}" for k in range(3) if v[k] != v0[k]]
            lost += [f"angularvelini {'xyz'[k]}={w0[k]:g}" for k in range(3) if w[k] != w0[k]]
            reader.warnings.add(f"floating mkbound {b.mkbound}: the initial velocity along a locked degree of "
                                f"freedom is ignored ({', '.join(lost)}; translationDOF/rotationDOF 0"
                                + (", or out of the 2D plane" if is2d else "") + ")",
                                file=reader.file, line=line, element="floating")
        sl = slice(b.begin, b.begin + b.count)
        r = particles["pos"][sl] - np.asarray(b.center)
        particles["vel"][sl] = v + np.cross(w, r)


def analytic_properties(primitives, mkbound: int, is2d: bool, density, massbody) -> dict | None:
    """Mass and central inertia of a floating body drawn as exactly one solid primitive."""
    mine = [p for p in primitives if not p.get("fluid") and not p.get("void") and p.get("mk") == mkbound]
    if len(mine) != 1:
        return None
    prim = mine[0]
    later = primitives[next(i for i, p in enumerate(primitives) if p is prim) + 1:]
    if any(p.get("void") or p.get("redraws") for p in later):
        return None          # something may have been carved out of it, or redrawn
    shape, par = prim.get("shape"), prim.get("params", {})
    axes = np.eye(3)
    try:
        if shape == "box":
            size = np.abs(np.asarray(par["size"], float))
            axes = np.asarray(par.get("axes", np.eye(3)), float).T      # columns: the box edges
            if not np.allclose(axes.T @ axes, np.eye(3), atol=1e-9):
                return None      # sheared by a non-uniform scale after a rotation
            if is2d:
                volume = size[0] * size[2]
            else:
                volume = float(np.prod(size))
            sx, sy, sz = size
            if is2d:
                sy = 0.0         # a plate in the x-z plane, as its particles: I_xx + I_zz = I_yy
            diag = np.array([sy * sy + sz * sz, sx * sx + sz * sz, sx * sx + sy * sy]) / 12.0
        elif shape == "sphere":
            r = float(par["radius"])
            volume = math.pi * r * r if is2d else 4.0 / 3.0 * math.pi * r ** 3
            # in 2D a disc in the x-z plane: I_yy = m r²/2, I_xx = I_zz = m r²/4
            diag = np.array([0.25, 0.5, 0.25]) * r * r if is2d else np.full(3, 2.0 * r * r / 5.0)
        elif shape == "cylinder":
            r = float(par["radius"])
            p1, p2 = np.asarray(par["point1"], float), np.asarray(par["point2"], float)
            length = float(np.linalg.norm(p2 - p1))
            if is2d:
                axis = (p2 - p1) / max(length, 1e-300)
                if abs(abs(axis[1]) - 1.0) < 1e-9:      # across the plane: a disc, as a 2D sphere
                    volume = math.pi * r * r
                    diag = np.array([0.25, 0.5, 0.25]) * r * r
                elif abs(axis[1]) < 1e-9 and np.allclose(np.abs(axis), np.round(np.abs(axis))):
                    # along x or z: a rectangle of the length by the diameter in the x-z plane
                    sx, sz = (length, 2 * r) if abs(axis[0]) > 0.5 else (2 * r, length)
                    volume = sx * sz
                    diag = np.array([sz * sz, sx * sx + sz * sz, sx * sx]) / 12.0
                else:
                    return None
            else:
                volume = math.pi * r * r * length
                axis = (p2 - p1) / length
                if not np.allclose(np.abs(axis), np.round(np.abs(axis))):
                    return None
                ia = r * r / 2.0
                it = (3 * r * r + length * length) / 12.0
                diag = np.where(np.abs(axis) > 0.5, ia, it)
        else:
            return None
    except (KeyError, TypeError, ValueError):
        return None
    mass = density * volume if density is not None else massbody
    inertia = axes @ np.diag(mass * diag) @ axes.T
    return {"shape": shape, "volume": float(volume), "mass": float(mass), "inertia": inertia.tolist()}


# ---------------------------------------------------------------------------
# domain and checks
# ---------------------------------------------------------------------------
# DualSPHysics's BORDER_MAP (DualSphDef.h): the map's margin around the particles, in h
BORDER_MAP = 0.05


def resolve_domain(case: Case, particles: dict, consts: Constants, reader) -> dict:
    """Simulation domain as JSph::LoadCaseParticles builds MapRealPos: the particles' bounding
    box widened by BORDER_MAP*h (0.05 h) on each side of a non-periodic axis and by dp/2 on a
    periodic one (JPartsLoad4::CalculeLimits), then ``<simulationdomain>`` applied to that
    widened box (JSph::ResizeMapLimits: "default" is the widened limit, "default + x%" x % of
    the widened extent; a periodic axis keeps its widened box, whatever the rule)."""
    from ..sph.periodic import periodic_config
    pos = particles["pos"]
    lo, hi = pos.min(axis=0), pos.max(axis=0)
    periodic = periodic_config(case.parameters_set, case.parameters, consts.is2d)[0]
    border = np.array([0.5 * consts.dp if a in periodic else BORDER_MAP * consts.h for a in "xyz"])
    lo, hi = lo - border, hi + border
    extent = hi - lo
    posmin, posmax = lo.copy(), hi.copy()
    spec = case.simulationdomain
    for i, a in enumerate("xyz"):
        if a in periodic:
            if any(spec[k][i].replace(" ", "").lower() != "default" for k in ("posmin", "posmax")):
                reader.warn(reader.root.find("execution/parameters/simulationdomain"),
                            f"<simulationdomain> limits along the periodic axis {a} are ignored: the domain "
                            "there is the particles' extent plus dp/2 each side (as DualSPHysics)")
            continue
        posmin[i] = parse_domain_spec(spec["posmin"][i], lo[i], extent[i])
        posmax[i] = parse_domain_spec(spec["posmax"][i], hi[i], extent[i])
    if consts.is2d:
        posmin[1] = posmax[1] = consts.posy2d
    if np.any(posmax < posmin):
        raise CaseError(f"simulation domain is empty: posmin {posmin.tolist()} > posmax {posmax.tolist()}",
                        file=reader.file, line=reader.line_of("execution/parameters/simulationdomain"),
                        element="simulationdomain", expected="posmin <= posmax")
    return {"posmin": posmin.tolist(), "posmax": posmax.tolist()}


def check_inout(spec: dict, particles, is2d: bool, reader) -> None:
    """The inlet/outlet zones against the case: <zone2d> in 2D, <zone3d> in 3D, and a
    <particles mkfluid> zone's particles drawn (one plane of them: checked when the run builds it)."""
    fluid_labels = set(np.unique(particles["label"][particles["type"] == TYPE_FLUID]).tolist())
    for z in spec["zones"]:
        want = 2 if is2d else 3
        if z["dim"] != want:
            raise CaseError(f"inout zone {z['index']} is a <zone{z['dim']}d> in a {want}D case", file=reader.file,
                            line=z["line"], element="inoutzone", expected=f"<zone{want}d>")
        shape = z["shape"]
        if shape["kind"] == "particles" and shape["mkfluid"] not in fluid_labels:
            raise CaseError(f"inout zone {z['index']}: <particles mkfluid=\"{shape['mkfluid']}\">, which has no "
                            "particles", file=reader.file, line=shape["line"], element="particles",
                            expected="an mkfluid drawn by the geometry (a layer of fluid particles)")


def check_boundcorr(spec: dict, particles, reader) -> None:
    """Each <boundcorr> mkbound a fixed or moving boundary with particles (JSphBoundCorr::UpdateMkCode:
    "MkBound value is not a Mk fixed boundary valid")."""
    ptype, label = particles["type"], particles["label"]
    for z in spec["zones"]:
        for mk in z["mkbound"]:
            sel = (ptype != TYPE_FLUID) & (label == mk)
            if not sel.any() or np.any(ptype[sel] == 2):
                what = "has no particles" if not sel.any() else "is a floating body"
                raise CaseError(f"<boundcorr> mkzone mkbound {mk} {what}", file=reader.file, line=z["line"],
                                element="mkzone", expected="the mkbound of a fixed or moving boundary")


def _check_moored_floatings(case: Case, floating_labels: set, reader) -> None:
    """Every ``<moorings><mooredfloatings><floating mkbound>`` is a floating body of the case
    (JDsMooredFloatings: "Floating body used in mooring not found."), and gravity is along z
    (MoorDynPlus uses |g_z| only; DualSPHysics refuses g_z = 0 with moorings)."""
    moor = case.special["moorings"]
    for mkb in moor["floatings"]:
        if mkb not in floating_labels:
            el = next((f for f in reader.root.iterfind("execution/special/moorings/mooredfloatings/floating")
                       if reader.integer(f, "mkbound", lo=0) == mkb), None)
            raise CaseError(f"moored floating mkbound {mkb} is not a floating body (<mooredfloatings><floating "
                            f"mkbound=\"{mkb}\">)", file=reader.file,
                            line=el.sourceline if el is not None else moor["line"], element="floating",
                            expected=f'<floating mkbound="{mkb}" ...> in <casedef><floatings>, of a drawn mkbound'
                            + (" (floating mkbounds: " + ", ".join(map(str, sorted(floating_labels))) + ")"
                               if floating_labels else ""))
    gx, gy, gz = (float(g) for g in case.constantsdef.gravity)
    where = reader.root.find("casedef/constantsdef/gravity")
    if gz == 0:
        raise CaseError("gravity z is 0: the mooring lines' weight acts along z", file=reader.file,
                        line=getattr(where, "sourceline", None), element="gravity",
                        expected="a gravity with a z component (DualSPHysics refuses moorings without one)")
    if gx or gy:
        reader.warn(where, f"the mooring lines feel gravity |g_z| = {abs(gz):g} along -z only (MoorDynPlus ignores "
                    "gravity x and y)")


def check_case(case: Case, particles, bodies, mkinfo, domain, reader) -> None:
    """Semantic checks that need the particles (the reader already checked each element)."""
    pos, ptype, label = particles["pos"], particles["type"], particles["label"]
    lo, hi = np.asarray(domain["posmin"]), np.asarray(domain["posmax"])
    fluid = ptype == TYPE_FLUID
    tol = 1e-9 * max(1.0, float(np.abs(pos).max()))
    outside = fluid & np.any((pos < lo - tol) | (pos > hi + tol), axis=1)
    if outside.any():
        i = int(np.flatnonzero(outside)[0])
        raise CaseError(f"{int(outside.sum())} fluid particles lie outside the simulation domain "
                        f"(first at {pos[i].tolist()})", file=reader.file,
                        line=reader.line_of("execution/parameters/simulationdomain"), element="simulationdomain",
                        expected=f"posmin {lo.tolist()} <= fluid positions <= posmax {hi.tolist()}")
    bound_labels = set(np.unique(label[ptype != TYPE_FLUID]).tolist())
    for m in case.motions:
        if m["ref"] not in bound_labels:
            raise CaseError(f"motion of mkbound {m['ref']}, which has no particles", file=reader.file,
                            line=m["line"], element="objreal", expected="an mkbound drawn by the geometry")
    for wp in case.special.get("wavepaddles", []):
        if wp["mkbound"] not in {m["ref"] for m in case.motions}:
            raise CaseError(f"wave paddle mkbound {wp['mkbound']} has no <motion> object", file=reader.file,
                            line=wp["line"], element=wp["type"],
                            expected=f'<motion><objreal ref="{wp["mkbound"]}"> with an <mvnull>')
        _warn_paddle_depth(wp, pos, ptype, label, reader)
        if wp["type"] == "piston_focused":
            try:
                paddle = focused_paddle(wp, pos, ptype, label)
            except ValueError as exc:
                raise CaseError(str(exc), file=reader.file, line=wp["line"], element="xf",
                                expected="a focus in front of the piston, along its <pistondir>") from None
            _warn_focus_too_late(wp, paddle, case.parameters.get("TimeMax"), reader)
            water = pos[ptype == TYPE_FLUID] @ paddle.direction
            if water.size and paddle.xf > float(water.max()):
                reader.warnings.add(f"the focus xf={paddle.xf:g} m lies beyond the water drawn (it ends at "
                                    f"{float(water.max()):.4g} m along the piston's direction)",
                                    file=reader.file, line=wp.get("line"), element="xf")
    chrono = case.special.get("chrono")
    floating_labels = {b.mkbound for b in bodies}
    if case.special.get("moorings"):
        _check_moored_floatings(case, floating_labels, reader)
    if chrono:
        for b in chrono["bodies"]:
            if b["mkbound"] not in bound_labels:
                raise CaseError(f"chrono body '{b['id']}' uses mkbound {b['mkbound']}, which has no particles",
                                file=reader.file, line=b["line"], element="body" + b["kind"],
                                expected="an mkbound drawn by the geometry")
            if b["kind"] == "floating" and b["mkbound"] not in floating_labels:
                raise CaseError(f"chrono bodyfloating '{b['id']}' (mkbound {b['mkbound']}) is not in <floatings>",
                                file=reader.file, line=b["line"], element="bodyfloating",
                                expected=f'<floating mkbound="{b["mkbound"]}" ...> in <casedef><floatings>')
        if case.parameters.get("RigidAlgorithm") == 2:
            raise CaseError(DEM_WITH_CHRONO, file=reader.file, element="parameter",
                            line=reader.line_of("execution/parameters/parameter[@key='RigidAlgorithm']"),
                            expected="RigidAlgorithm 3 for the <chrono> section's bodies and links, or no <chrono> "
                            "section for the DEM")
        if case.parameters.get("RigidAlgorithm") not in (0, 3):
            reader.warn(None, "<special><chrono> is present but RigidAlgorithm is "
                        f"{case.parameters.get('RigidAlgorithm')}; sphdvi uses the DVI engine for the chrono bodies")
    elif case.parameters.get("RigidAlgorithm") == 2:
        _check_dem_materials(case, bound_labels, floating_labels, reader)
    elif case.parameters.get("RigidAlgorithm") == 3:
        raise CaseError("RigidAlgorithm=3 (Chrono) needs an <execution><special><chrono> section",
                        file=reader.file, line=reader.line_of("execution/parameters/parameter[@key='RigidAlgorithm']"),
                        element="parameter", expected="a <chrono> section or RigidAlgorithm 1")
    gauges = case.special.get("gauges")
    if gauges:
        for g in gauges["items"]:
            if g["type"] == "force":
                tgt = g.get("target", {}).get("mkbound")
                try:
                    mkb = int(float(tgt))
                except (TypeError, ValueError):
                    raise CaseError(f"force gauge '{g['name']}' has no valid <target mkbound>", file=reader.file,
                                    line=g["line"], element="force", expected='<target mkbound="N"/>') from None
                if mkb not in bound_labels:
                    raise CaseError(f"force gauge '{g['name']}' targets mkbound {mkb}, which has no particles",
                                    file=reader.file, line=g["line"], element="force",
                                    expected="an mkbound drawn by the geometry")
    fluid_labels = set(np.unique(label[fluid]).tolist())
    for acc in case.special.get("accinputs", []):
        missing = [mk for mk in acc["mkfluid"] if mk not in fluid_labels]
        if missing:
            raise CaseError(f"<accinput> for mkfluid {missing[0]}, which has no particles", file=reader.file,
                            line=acc["line"], element="accinput", expected="an mkfluid drawn by the geometry")
    if case.special.get("outputparts"):
        from .outputs_xml import check_outputparts
        check_outputparts(case.special["outputparts"], label, ptype, particles["mk"],
                          {b.mkbound: list(map(float, b.center)) for b in bodies}, case.fluidcount, reader.file)
    for link in case.material_links:
        for mk in link.get("mkbound", []):
            if mk not in bound_labels:
                reader.warn(None, f"<properties><link> line {link['line']}: mkbound {mk} has no particles")


def gauge_extent_points(g: dict) -> list:
    """The points that bound where a gauge samples: velocity its point, swl its line's ends,
    maxz its column's foot and top, mesh its first and last node (point + Σ size_k vec_k/|vec_k|)."""
    kind = g["type"]
    if kind == "velocity":
        return [g["point"]]
    if kind == "swl":
        return [g["point0"], g["point2"]]
    if kind == "maxz":
        return [g["point0"], np.add(g["point0"], [0.0, 0.0, g.get("height", 0.0)])]
    if kind == "mesh":
        from .gauge_spec import mesh_length
        far = np.asarray(g["point"], float).copy()
        for k in (1, 2, 3):
            v = np.asarray(g.get(f"vec{k}", np.eye(3)[k - 1]), float)
            n = np.linalg.norm(v)
            if n > 0:
                far += mesh_length(g.get(f"size{k}")) * v / n
        return [g["point"], far]
    return []


def focused_paddle(wp: dict, pos, ptype, label):
    """The :class:`sphdvi.motion.FocusedPaddle` of a ``<piston_focused>``, its face placed from the
    particles of its mkbound (ValueError: the focus is not in front of it)."""
    from ..motion import FocusedPaddle
    paddle = FocusedPaddle(wp)
    paddle.place_on(pos[(ptype != TYPE_FLUID) & (label == wp["mkbound"])])
    return paddle


def _warn_focus_too_late(wp: dict, paddle, tmax, reader) -> None:
    """A focused group that cannot form is warned about, with the times of sphdvi's rule: the paddle
    stopping (``duration``; ``fmovtime`` less its ``fmovramp``) before its last waves leave it (the
    fastest group's, which left at t_f − distance/c_g,max), or the run ending (TimeMax) before t_f."""
    tf = paddle.start + paddle.focus_time
    last = tf - paddle.distance / paddle.cg_max
    if paddle.duration > 0:
        stop = paddle.start + paddle.duration - paddle.fmovramp
        if stop < last:
            reader.warnings.add(f"the paddle stops moving at t = {stop:.4g} s (<fmovtime>/<duration>, less <fmovramp>), "
                                f"before the group's last (fastest) waves leave it at {last:.4g} s for the focus at "
                                f"t = {tf:.4g} s: the group does not form fully; give the paddle more time",
                                file=reader.file, line=wp.get("line"), element=wp["type"])
    if tmax is not None and tmax > 0 and tf > tmax:
        reader.warnings.add(f"the group focuses at t = {tf:.4g} s ({paddle.distance:.4g} m from the piston, "
                            f"<fpretime> plus the time the slowest of its waves takes to get there), after the run "
                            f"ends (TimeMax {tmax:g} s): move <xf> closer, or run longer",
                            file=reader.file, line=wp.get("line"), element=wp["type"])


def _warn_paddle_depth(wp: dict, pos, ptype, label, reader) -> None:
    """A wave paddle's <depth> sets the waves' theory (the stroke for a height and period); the
    water the case draws in front of the paddle (its top face minus its bottom face, within 10 dp
    of the paddle in x) differing by more than 10 % (and 2 dp) is warned about: the waves come
    out of another height than asked (a <depth> of 3 m in water 0.3 m deep passed silently)."""
    depth = wp.get("depth")
    paddle = pos[(ptype != TYPE_FLUID) & (label == wp["mkbound"])]
    fluid = pos[ptype == TYPE_FLUID]
    if depth is None or not paddle.size or not fluid.size:
        return
    dp = float(reader.vars.values.get("Dp", 0.0)) or 0.0
    if not dp > 0:
        return
    near = fluid[(fluid[:, 0] >= paddle[:, 0].min() - 10 * dp) & (fluid[:, 0] <= paddle[:, 0].max() + 10 * dp)]
    if not near.size:
        return
    drawn = float(near[:, 2].max() - near[:, 2].min()) + dp
    if abs(depth - drawn) > max(0.1 * drawn, 2 * dp):
        reader.warnings.add(f"<depth> {depth:g} m of the wave paddle (mkbound {wp['mkbound']}) differs from the water "
                            f"drawn in front of it, {drawn:.4g} m deep: the waves are made for the <depth> given",
                            file=reader.file, line=wp.get("line"), element=wp["type"])


def warn_gauges_outside(gauges, domain, is2d: bool, reader) -> None:
    """A gauge whose points lie outside the simulation domain records no fluid there (nor
    does DualSPHysics's): say so at gencase rather than leave the user an empty file.
    In 2D the y coordinate is not compared."""
    if not gauges:
        return
    lo, hi = np.asarray(domain["posmin"], float), np.asarray(domain["posmax"], float)
    axes = [0, 2] if is2d else [0, 1, 2]
    tol = 1e-9 * max(1.0, float(np.abs(np.r_[lo, hi]).max()))
    for g in gauges["items"]:
        pts = np.asarray(gauge_extent_points(g), float).reshape(-1, 3)
        if not pts.size:
            continue
        # a line or a mesh that reaches into the domain records there (a swl line from z = 0 at
        # a dp whose floor particles sit above 0 was warned about); one wholly outside, not
        pmin, pmax = pts.min(axis=0), pts.max(axis=0)
        if np.any(pmax[axes] < lo[axes] - tol) or np.any(pmin[axes] > hi[axes] + tol):
            what = (f"point {np.round(pts[0], 9).tolist()} lies" if len(pts) == 1 else
                    f"points {np.round(pmin, 9).tolist()} .. {np.round(pmax, 9).tolist()} lie")
            reader.warnings.add(f"{g['type']} gauge '{g['name']}': {what} outside the simulation domain "
                                f"{lo.tolist()} .. {hi.tolist()}; it records no fluid there",
                                file=reader.file, line=g.get("line"), element=g["type"])


#: RigidAlgorithm 2 with a <chrono> section: both would put contacts on the same bodies
DEM_WITH_CHRONO = ("RigidAlgorithm 2 (DEM contacts) with a <special><chrono> section: DualSPHysics takes the "
                   "<chrono> bodies under RigidAlgorithm 3 only, and sphdvi's multibody engine and the DEM would both "
                   "put contacts on the same bodies")


def _check_dem_materials(case, bound_labels, floating_labels, reader) -> None:
    """RigidAlgorithm 2 (DEM): every boundary block needs a material with Kfric,
    Restitution_Coefficient, Young_Modulus and PoissonRatio (JSph::LoadDemData stops the run
    without them); without floating bodies DualSPHysics switches DEM off, with a warning."""
    from ..mechanism import dem_material
    line = reader.line_of("execution/parameters/parameter[@key='RigidAlgorithm']")
    if not floating_labels:
        reader.warnings.add("RigidAlgorithm 2 (DEM) without floating bodies: no DEM contacts (DualSPHysics: \"The "
                            "use of DEM was disabled because there are no floating objects\")", file=reader.file,
                            line=line, element="parameter")
        return
    js = {"materials": {k: asdict(v) for k, v in case.materials.items()}, "material_links": case.material_links}
    for mkb in sorted(bound_labels):
        fd = next((f for f in case.floatings if mkb in f.mkbound), None)
        try:
            dem_material(int(mkb), js, fd.property if fd is not None and fd.property else None)
        except ValueError as exc:
            where = fd.line if fd is not None else next(
                (ln["line"] for ln in case.material_links if mkb in ln.get("mkbound", [])), line)
            raise CaseError(str(exc), file=reader.file, line=where, element="floating" if fd is not None else "link",
                            expected="a <property> with Kfric, Restitution_Coefficient, Young_Modulus and PoissonRatio "
                            "for every boundary block (fixed, moving and floating), by <floating property=..> or "
                            "<properties><links><link mkbound=..>") from None


# ---------------------------------------------------------------------------
# output
# ---------------------------------------------------------------------------
def write_outputs(result: GenCaseResult, outdir: str) -> list[str]:
    """Write ``<casename>.h5``, ``<casename>_All.vtp`` and, when the case defines mDBC normals,
    ``<casename>_Normals.vtp`` into ``outdir``."""
    from ..io.casefile import write_case_h5
    from ..io.vtkxml import write_normals_vtp, write_vtp_points
    make_folder(outdir)
    case, consts, p = result.case, result.constants, result.particles
    h5 = os.path.join(outdir, f"{case.name}.h5")
    chrono = case.special.get("chrono") or {}
    json_items = {
        "links": chrono.get("links", []), "chrono": chrono, "motions": case.motions,
        "materials": {k: asdict(v) for k, v in case.materials.items()},
        "material_links": case.material_links, "gauges": case.special.get("gauges", {}),
        "special": case.special, "initials": case.initials, "normals": case.normals,
        "bodies_extra": [asdict(b) for b in result.bodies], "mkinfo": result.mkinfo,
        "parameters_set": case.parameters_set, "constantsdef": asdict(case.constantsdef),
        "mkconfig": {"boundcount": case.boundcount, "fluidcount": case.fluidcount},
    }
    particles = {k: p[k] for k in ("pos", "vel", "rhop", "mass", "type", "mk", "idp")}
    write_case_h5(h5, casename=case.name, source_file=case.file, source_xml=case.source, version=__version__,
                  particles=particles, constants=consts.to_dict(), parameters=case.parameters,
                  domain=result.domain, bodies=result.bodies, json_items=json_items, normals=result.normals)
    vtp = os.path.join(outdir, f"{case.name}_All.vtp")
    press = consts.b * (np.power(p["rhop"] / consts.rhop0, consts.gamma) - 1.0)
    write_vtp_points(vtp, p["pos"], {"Idp": p["idp"].astype(np.int64), "Vel": p["vel"].astype(np.float32),
                                     "Rhop": p["rhop"].astype(np.float32), "Press": press.astype(np.float32),
                                     "Mass": p["mass"].astype(np.float32), "Type": p["type"],
                                     "Mk": p["mk"].astype(np.int32),
                                     **({"Normal": result.normals.astype(np.float32)}
                                        if result.normals is not None else {})})
    files = [h5, vtp]
    if result.normals is not None:
        files.append(write_normals_vtp(os.path.join(outdir, f"{case.name}_Normals.vtp"), p["pos"], p["type"], p["mk"],
                                       result.normals))
    return files + list(result.files)


def summary(result: GenCaseResult) -> str:
    """A GenCase-like report: particles per mk and type, constants, bodies, memory."""
    c, p, case = result.constants, result.particles, result.case
    n = p["pos"].shape[0]
    lines = [f"Case {case.name}: {'2D' if c.is2d else '3D'}, dp = {c.dp:g} m", "",
             f"{'type':<17}{'mk':>6}{'label':>7}{'particles':>11}"]
    for info in result.mkinfo:
        lbl = ("mkfluid " if info["type"] == TYPE_FLUID else "mkbound ") + str(info["label"])
        lines.append(f"{TYPE_NAMES[info['type']]:<17}{info['mk']:>6}{'':>2}{lbl:<12}{info['count']:>6}")
    counts = {t: int((p["type"] == t).sum()) for t in TYPE_NAMES}
    lines.append("")
    lines.append(f"Particles: {n} total = {counts[0]} fixed + {counts[1]} moving + {counts[2]} floating "
                 f"(boundary {counts[0] + counts[1] + counts[2]}) + {counts[3]} fluid")
    lines.append(f"h = {c.h:.6g} m   (coefh = {c.coefh:.6g})")
    lines.append(f"c0 = {c.cs0:.7g} m/s   (speedsystem {c.speedsystem:.6g} m/s, hswl {c.hswl:.6g} m)")
    lines.append(f"B = {c.b:.7g} Pa   gamma = {c.gamma:g}   rhop0 = {c.rhop0:g} kg/m3")
    unit = "kg/m" if c.is2d else "kg"
    lines.append(f"massfluid = {c.massfluid:.7g} {unit}   massbound = {c.massbound:.7g} {unit}")
    d = result.domain
    lo = ", ".join(f"{v:.6g}" for v in d["posmin"])
    hi = ", ".join(f"{v:.6g}" for v in d["posmax"])
    lines.append(f"Domain: ({lo}) - ({hi})   (particles + {BORDER_MAP:g} h each side, dp/2 on a periodic axis, "
                 "then <simulationdomain>)")
    for b in result.bodies:
        centre = ", ".join(f"{v:.6g}" for v in b.center)
        diag = ", ".join(f"{b.inertia[i][i]:.6g}" for i in range(3))
        lines.append(f"Floating mkbound {b.mkbound} (mk {b.mk}): {b.count} particles, mass {b.mass:.6g} {unit}, "
                     f"centre ({centre}), inertia diag ({diag})")
        if b.analytic:
            a = b.analytic
            diag = ", ".join(f"{a['inertia'][i][i]:.6g}" for i in range(3))
            lines.append(f"    analytic {a['shape']}: mass {a['mass']:.6g} {unit}, inertia diag ({diag})")
    for wp in case.special.get("wavepaddles", []):
        if wp.get("calcserielength"):
            from ..motion import SpectrumPaddle
            from ..wavespectra import repetition_period
            tmax = wp["calcserielength"]
            period = repetition_period(SpectrumPaddle(wp).components["f"], tmax)
            lines.append(f"Irregular series (mkbound {wp['mkbound']}): " + (
                f"repeats every {period:.6g} s" if period is not None else
                f"does not repeat within {tmax:g} s ({wp['discretization']} discretization)"))
        if wp["type"] == "piston_focused":
            f = focused_paddle(wp, p["pos"], p["type"], p["label"])
            second = f" (with its bound waves {f.focus_crest(2):.4g} m)" if f.second_order else ""
            lines.append(f"Focused group (mkbound {wp['mkbound']}): crest {f.crest:.4g} m{second} at x = {f.xf:g} m, "
                         f"t = {f.start + f.focus_time:.4g} s ({f.distance:.4g} m from the piston's face; "
                         f"{f.amp.size} waves, the largest crest of {f.nwaves:.4g})")
    if result.normals is not None:
        bound = np.asarray(p["type"]) != TYPE_FLUID
        has = bound & np.any(result.normals != 0.0, axis=1)
        labels = ", ".join(str(int(v)) for v in np.unique(p["label"][has])) or "none"
        lines.append(f"mDBC normals (the case's): {int(has.sum())} of {int(bound.sum())} boundary particles "
                     f"(mkbound {labels}); the others keep DBC with Boundary=2")
    mem = sum(np.asarray(p[k]).nbytes for k in ("pos", "vel", "rhop", "mass", "type", "mk", "idp"))
    lines.append(f"Memory: {mem / 1e6:.2f} MB of particle data ({mem / max(n, 1):.0f} bytes per particle)")
    return "\n".join(lines)
