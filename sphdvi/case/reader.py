"""Read a whole DualSPHysics ``<case>`` document into :class:`~sphdvi.case.model.Case`.

The geometry commands are not executed here (that is :mod:`sphdvi.case.draw`);
everything else is parsed into typed data and checked. Order matters because
expressions can use variables: ``<predefinition>`` and the drawing commands
define them, and the constants (H, B, masses) exist only after drawing. The
gencase driver therefore calls :func:`open_case`, draws, resolves the
constants, then :func:`read_sections`.
"""
from __future__ import annotations

import math
import os

import numpy as np

from ..errors import CaseError
from .datafiles import read_dt_table, read_visco_table
from .expressions import ExpressionError
from .model import Case, ConstantsDef, FloatingDef, Material
from .chrono_xml import check_chrono_case, read_chrono
from .mkrange import accinput_mk_attr, parse_mk_range, prop_link_attr
from .normals_xml import read_initialize, read_normals, read_onlypos, read_velocity_profile
from .outputs_xml import read_outputparts, read_savedt
from .parameters import (NNEWTONIAN_TEXT, NOT_SUPPORTED, PARAMETERS, apply_delta_sph, check_consistency,
                         check_supported, closest_key, coerce, constant_hint, default_parameters,
                         domain_from_deprecated, other_build_hint, parameter_warnings)
from .schema import validate_structure
from .inout_xml import read_boundcorr, read_inout
from .flexstruc_xml import read_flexstrucs
from .moorings_xml import read_moorings
from .relaxzones_xml import read_relaxationzones
from .wavepaddles_xml import read_wavepaddles
from .xmldoc import CaseReader, load_xml, strip_disabled

CASEDEF_CHILDREN = {"constantsdef", "mkconfig", "geometry", "floatings", "initials", "motion",
                    "properties", "normals", "patterns", "vres"}
EXECUTION_CHILDREN = {"special", "parameters", "particles", "constants", "motion", "vres", "uservars", "vtkout"}
SPECIAL_SUPPORTED = {"accinputs", "chrono", "gauges", "wavepaddles", "damping", "shifting", "timeout", "initialize",
                     "savedt", "outputparts", "inout", "boundcorr", "relaxationzones",
                     "moorings", "flexstrucs"}
SPECIAL_KNOWN = SPECIAL_SUPPORTED | {
    "mlayerpistons", "boundextrap",
    "forcepoints", "vres", "nnphases", "temperature"}


def case_name_from_path(path: str) -> str:
    """``CaseDambreak_Def.xml`` -> ``CaseDambreak`` (GenCase's naming)."""
    base = os.path.basename(path)
    if base.lower().endswith(".xml"):
        base = base[:-4]
    if base.endswith("_Def"):
        base = base[:-4]
    return base or "case"


def open_case(path: str, warnings=None):
    """Parse the file, drop disabled elements and check the top-level structure.

    Returns ``(root, reader, source_text)``.
    """
    root, text = load_xml(path)
    strip_disabled(root, path)
    validate_structure(root, path)
    reader = CaseReader(path, warnings=warnings)
    reader.root = root            # for the lines of checks made after reading (gencase's)
    reader.mark(root)
    casedef = root.find("casedef")
    if casedef is None:
        raise reader.error(root, "missing <casedef>", "<case><casedef>...</casedef><execution>...</execution></case>")
    reader.check_children(root, {"casedef", "execution"})
    reader.check_children(casedef, CASEDEF_CHILDREN)
    execution = root.find("execution")
    if execution is not None:
        reader.check_children(execution, EXECUTION_CHILDREN)
    reader.mark(casedef)
    return root, reader, text


# ---------------------------------------------------------------------------
# constants
# ---------------------------------------------------------------------------
def read_constantsdef(reader: CaseReader, casedef) -> ConstantsDef:
    """``<constantsdef>``: explicit values, or ``None`` for ``auto="true"``."""
    el = reader.child(casedef, "constantsdef")
    c = ConstantsDef()
    if el is None:
        return c
    reader.check_children(el, {"lattice", "gravity", "rhop0", "rhopgradient", "hswl", "gamma",
                               "speedsystem", "coefsound", "speedsound", "coefh", "hdp",
                               "cflnumber", "h", "b", "massbound", "massfluid", "coefhdp",
                               "coefficient", "eps"})
    lat = reader.child(el, "lattice")
    if lat is not None:
        c.lattice_bound = _lattice(reader, lat, "bound")
        c.lattice_fluid = _lattice(reader, lat, "fluid")
    _read_eps(reader, el)
    g = reader.child(el, "gravity")
    if g is not None:
        c.gravity = reader.vec3(g).tolist()
    c.rhop0 = reader.child_value(el, "rhop0", 1000.0, positive=True)
    rg = reader.child(el, "rhopgradient")
    if rg is not None:
        c.rhopgradient = reader.integer(rg, "value", lo=1, hi=3)
    c.gamma = reader.child_value(el, "gamma", 7.0, positive=True)
    # the speed-of-sound inputs may be 0 where they are not used (a case with <b> or <speedsound>
    # given leaves coefsound, hswl and speedsystem unused); gencase refuses a c0 of 0 with fluid
    c.coefsound = reader.child_value(el, "coefsound", 20.0, nonnegative=True)
    c.cflnumber = reader.child_value(el, "cflnumber", 0.2, positive=True, hi=10.0)
    c.hswl = _auto_value(reader, el, "hswl", nonnegative=True)
    c.speedsystem = _auto_value(reader, el, "speedsystem", nonnegative=True)
    c.speedsound = _auto_value(reader, el, "speedsound", nonnegative=True)
    c.h = _auto_value(reader, el, "h", positive=True)
    c.b = _auto_value(reader, el, "b", positive=True)
    c.massbound = _auto_value(reader, el, "massbound", positive=True)
    c.massfluid = _auto_value(reader, el, "massfluid", positive=True)
    coefh = _coefh_element(reader, el)
    _warn_coefhdp(reader, el)
    hdp = reader.child(el, "hdp")
    if coefh is not None and hdp is not None:
        raise reader.error(hdp, f"both <{coefh.tag}> and <hdp> are given", "only one of them")
    if hdp is not None:
        c.hdp = reader.num(hdp, "value", positive=True, hi=100.0)
    elif coefh is not None:
        c.coefh = reader.num(coefh, "value", positive=True, hi=100.0)
    return c


def _lattice(reader, lat, attr: str) -> int:
    """``<lattice bound|fluid>``: 1, the cubic lattice, the only one sphdvi draws.  GenCase's
    lattice 2 (JCaseCtes::ReadXmlDef: any value but 1) is a staggered lattice with twice the
    particles (GenCase's log: a 9^3 block gives 1458): refused rather than drawn differently."""
    v = reader.integer(lat, attr, 1, lo=1, hi=2)
    if v != 1:
        raise reader.error(lat, f"{attr}=\"{v}\": GenCase's lattice 2 (a staggered lattice, twice "
                                "the particles) is not supported; sphdvi draws "
                                "the cubic lattice only", f'{attr}="1" (or no <lattice>)')
    return v


def _read_eps(reader, el) -> None:
    """``<eps value>`` (XSPH epsilon): read and unused, with DualSPHysics's warning when it is
    not 0 (JCaseCtes::ReadXmlDef reads it, JSph::LoadCaseConfig warns)."""
    eps = reader.child(el, "eps")
    if eps is not None and reader.num(eps, "value", 0.0) != 0.0:
        reader.warn(eps, "Eps value is not used (this correction was removed from DualSPHysics; "
                         "sphdvi ignores it too)")


def _warn_coefhdp(reader, el):
    """``<coefhdp>`` is no element DualSPHysics reads (JCaseCtes::ReadXmlDef takes h/dp from
    ``<hdp value>``; CoefHdp is its internal name): ignored, as there, but said."""
    wrong = reader.child(el, "coefhdp")
    if wrong is not None:
        reader.mark(wrong, *wrong.attrib)
        reader.warn(wrong, "<coefhdp> is ignored (DualSPHysics does not read it): "
                           "h = hdp*dp is given as <hdp value=\"...\"/>")


def _coefh_element(reader, el):
    """The element that gives coefh: ``<coefh>``, else ``<coefficient>``, its older name
    (JCaseCtes::ReadXmlDef reads <coefficient> when <coefh> is absent or 0).  Both given
    (coefh not 0): <coefh> is used and <coefficient> ignored, with a warning."""
    coefh = reader.child(el, "coefh")
    alias = reader.child(el, "coefficient")
    if alias is None:
        return coefh
    if coefh is None or reader.num(coefh, "value", 0.0) == 0.0:
        return alias
    reader.mark(alias, "value")
    reader.warn(alias, "<coefficient> is ignored: <coefh> is given (as DualSPHysics)")
    return coefh


def _auto_value(reader, parent, tag, **checks):
    el = reader.child(parent, tag)
    if el is None:
        return None
    auto = reader.boolean(el, "auto", False)
    if auto:
        reader.mark(el, "value")
        return None
    if el.get("value") is None:
        raise reader.error(el, f"<{tag}> has neither value nor auto=\"true\"", 'value="..." or auto="true"')
    return reader.num(el, "value", **checks)


#: the largest mk a case may number (DualSPHysics's CODE_MKRANGEMAX of its 4-byte particle codes)
MK_MAX = 65530


def read_mkconfig(reader: CaseReader, casedef) -> tuple[int, int]:
    el = reader.child(casedef, "mkconfig")
    if el is None:
        return 240, 9
    bc = reader.integer(el, "boundcount", 240, lo=1, hi=MK_MAX)
    fc = reader.integer(el, "fluidcount", 9, lo=1, hi=MK_MAX)
    if bc + fc > MK_MAX:
        raise reader.error(el, f"boundcount {bc} + fluidcount {fc} = {bc + fc} is above {MK_MAX}",
                           f"boundcount + fluidcount <= {MK_MAX} (the largest mk, DualSPHysics's CODE_MKRANGEMAX; "
                           "its 14_DEM CaseManyFloatings uses 65520 + 9)")
    for c in reader.children(el):
        if c.tag not in ("mkorientfluid", "mkorientbound"):
            raise reader.error(c, f"unknown element <{c.tag}> in <mkconfig>", "<mkorientfluid> or <mkorientbound>")
        reader.integer(c, "mk", lo=0)
        reader.text_attr(c, "orient")
    return bc, fc


# ---------------------------------------------------------------------------
# sections read after drawing (expressions may use H, B, MassFluid, ...)
# ---------------------------------------------------------------------------
def read_sections(case: Case, root, reader: CaseReader) -> None:
    """Read floatings, initials, motion, properties, normals and the execution block."""
    casedef = root.find("casedef")
    case.floatings = read_floatings(reader, casedef)
    case.initials = read_initials(reader, casedef)
    case.motions = read_motion(reader, casedef)
    case.materials, case.material_links = read_properties(reader, casedef, case.fluidcount)
    for fd in case.floatings:
        if fd.property is not None:
            fd.property = _check_property_names(reader, fd.property, case.materials, fd.line, "floating")
    case.normals = read_normals(reader, casedef)
    execution = root.find("execution")
    read_uservars(reader, execution)
    params, set_keys, domain = read_parameters(reader, execution)
    case.parameters, case.parameters_set, case.simulationdomain = params, set_keys, domain
    case.special = read_special(reader, execution)
    check_chrono_case(reader, case)
    check_shifting(reader, root, set_keys, case.special)


def _mk_list(reader, el, attr):
    raw = reader.text_attr(el, attr)
    try:
        return parse_mk_range(raw)
    except ValueError as exc:
        raise reader.error(el, f"{attr}: {exc}", 'mk values and ranges like "0-3,7"') from None


def _series(reader, el, item_tag, allow_none=False):
    """A time table ``<vel time x y z/>``... or ``file="x.csv"``; ``none`` marks a free component."""
    if el is None:
        return None
    if el.get("file") is not None:
        return _series_file(reader, el, allow_none)
    times, values = [], []
    for item in reader.children(el, item_tag):
        times.append(reader.num(item, "time", nonnegative=True))
        row = []
        for comp in "xyz":
            raw = item.get(comp)
            reader.mark(item, comp)
            if raw is not None and raw.strip().lower() == "none":
                if not allow_none:
                    raise reader.error(item, f"'{comp}=none' is not allowed here", "a number")
                row.append(None)
            else:
                row.append(reader.num(item, comp, 0.0))
        values.append(row)
    if not times:
        raise reader.error(el, f"no <{item_tag}> items and no file", f'<{item_tag} time=".." x=".." .../> items or file="..."')
    if any(t2 < t1 for t1, t2 in zip(times, times[1:])):
        raise reader.error(el, "times are not in increasing order", "non-decreasing times")
    return {"times": times, "values": values}


def _series_file(reader, el, allow_none: bool) -> dict:
    """A driver's ``file="x.csv"`` (rows time;x;y;z, ``none`` a free component where allowed), read
    and checked now as the inline table (JLinearValue::LoadFile) -> {"times", "values", "source"}."""
    from .datafiles import read_vector_table
    path = reader.resolve_path(el, "file")
    try:
        times, values = read_vector_table(path, f"<{el.tag}> file", allow_none)
    except CaseError as exc:
        raise reader.error(el, f"{path}{':' + str(exc.line) if exc.line else ''}: {exc.message}",
                           exc.expected) from None
    return {"times": times, "values": values, "source": path}


def read_floatings(reader, casedef) -> list:
    el = reader.child(casedef, "floatings")
    out = []
    if el is None:
        return out
    allowed = {"massbody", "masspart", "center", "inertia", "inertiafull", "translationDOF",
               "rotationDOF", "linearvelini", "angularvelini", "velini", "omegaini", "linearvel",
               "angularvel", "linearforce", "angularforce"}
    seen = {}
    for f in reader.children(el):
        if f.tag != "floating":
            raise reader.error(f, f"unknown element <{f.tag}> in <floatings>", "<floating>")
        reader.check_children(f, allowed)
        fd = FloatingDef(mkbound=_mk_list(reader, f, "mkbound"), line=f.sourceline or 0)
        for mk in fd.mkbound:
            if mk in seen:
                raise reader.error(f, f"mkbound {mk} is already floating (line {seen[mk]})", "each mkbound in one <floating>")
            seen[mk] = f.sourceline
        if f.get("rhopbody") is not None:
            fd.rhopbody = reader.num(f, "rhopbody", nonnegative=True)
            if fd.rhopbody == 0:
                fd.rhopbody = None
        if f.get("relativeweight") is not None:
            fd.relativeweight = reader.num(f, "relativeweight", positive=True)
        fd.property = reader.text_attr(f, "property", None)
        mb = reader.child(f, "massbody")
        if mb is not None:
            fd.massbody = reader.num(mb, "value", positive=True)
        mp = reader.child(f, "masspart")
        if mp is not None:
            raw = mp.get("value")
            if raw is not None and raw.strip() == "distributed_bodymass":
                reader.mark(mp, "value")
                fd.masspart = "distributed_bodymass"
            else:
                fd.masspart = reader.num(mp, "value", positive=True)
        sources = [s for s, v in (("rhopbody", fd.rhopbody), ("relativeweight", fd.relativeweight),
                                  ("massbody", fd.massbody)) if v is not None]
        if not sources:
            zero = " (rhopbody=\"0\" counts as not given, as in DualSPHysics)" if f.get("rhopbody") is not None else ""
            raise reader.error(f, "no mass given" + zero,
                               'one of rhopbody="..", relativeweight="..", or <massbody value=".."/>')
        if len(sources) > 1 and not (sources == ["rhopbody", "massbody"]):
            raise reader.error(f, "mass given more than once (" + ", ".join(sources) + ")",
                               "exactly one of rhopbody, relativeweight, massbody")
        c = reader.child(f, "center")
        if c is not None:
            fd.center = reader.vec3(c).tolist()
        ine = reader.child(f, "inertia")
        inf = reader.child(f, "inertiafull")
        if ine is not None and inf is not None:
            raise reader.error(inf, "both <inertia> and <inertiafull>", "only one")
        if ine is not None:
            fd.inertia = np.diag(reader.vec3(ine)).tolist()
        if inf is not None:
            rows = reader.children(inf, "values")
            if len(rows) != 3:
                raise reader.error(inf, f"{len(rows)} <values> rows", "3 rows v11 v12 v13 / v21.. / v31..")
            mat = [[reader.num(r, f"v{i + 1}{j + 1}") for j in range(3)] for i, r in enumerate(rows)]
            fd.inertia = mat
        for tag, attr in (("translationDOF", "translation_dof"), ("rotationDOF", "rotation_dof")):
            d = reader.child(f, tag)
            if d is not None:
                v = reader.vec3(d, missing=1.0)
                if not np.all(np.isin(v, (0.0, 1.0))):
                    raise reader.error(d, f"{tag} components must be 0 or 1", "0 (locked) or 1 (free)")
                setattr(fd, attr, [int(x) for x in v])
        if fd.inertia is not None:
            _check_inertia(reader, ine if ine is not None else inf, np.asarray(fd.inertia, float),
                           fd.rotation_dof, _definition_is_2d(reader, casedef))
        for tags, attr in ((("linearvelini", "velini"), "linearvelini"), (("angularvelini", "omegaini"), "angularvelini")):
            for tag in tags:
                d = reader.child(f, tag)
                if d is not None:
                    setattr(fd, attr, reader.vec3(d).tolist())
        fd.linearvel = _series(reader, reader.child(f, "linearvel"), "vel", allow_none=True)
        fd.angularvel = _series(reader, reader.child(f, "angularvel"), "vel", allow_none=True)
        fd.linearforce = _series(reader, reader.child(f, "linearforce"), "force")
        fd.angularforce = _series(reader, reader.child(f, "angularforce"), "force")
        out.append(fd)
    return out


def _check_inertia(reader, el, tensor, rotation_dof=(1, 1, 1), is2d=False):
    """A body's inertia tensor must be symmetric with no negative principal moment, and positive
    about each axis the body may rotate about: a principal moment below 1e-12 of the largest
    (dvi.system.ZERO_INERTIA) counts as zero and is refused when its axis has a free rotation
    (2D: only the rotation about y is free, so ``<inertia x="0" y="0.5" z="0"/>`` is fine; 3D:
    the axes ``<rotationDOF>`` leaves free).  (An inertia computed from the particles of a body
    drawn as a line is not refused: the run locks the rotation about it, with a warning.)"""
    scale = max(float(np.abs(tensor).max()), 1e-300)
    if np.abs(tensor - tensor.T).max() > 1e-9 * scale:
        raise reader.error(el, "inertia tensor is not symmetric", "v12 = v21, v13 = v31, v23 = v32")
    lam, axes = np.linalg.eigh(tensor)
    lowest = float(lam.min())
    if lowest < -1e-12 * scale:
        raise reader.error(el, f"inertia tensor has a negative principal moment ({lowest:g} kg m²)",
                           "moments of inertia >= 0")
    top = float(lam.max())
    free = np.asarray(rotation_dof, float) * (np.array([0.0, 1.0, 0.0]) if is2d else 1.0)
    for k in range(3):
        axis = axes[:, k]
        if (top > 0 and lam[k] > 1e-12 * top) or not np.any(np.abs(axis) * free > 1e-6):
            continue
        j = int(np.argmax(np.abs(axis)))
        name = "xyz"[j] if abs(axis[j]) > 1.0 - 1e-9 else "(" + ", ".join(f"{x:.3g}" for x in axis) + ")"
        raise reader.error(el, f"the principal moment of inertia about {name} is {max(lam[k], 0.0):g} kg m²: a "
                               "floating body needs a positive moment about each axis it may rotate about",
                           "positive moments about the free axes (in 2D I_yy), or that rotation locked with "
                           "<rotationDOF>")


def _definition_is_2d(reader, casedef) -> bool:
    """GenCase's 2D case: <definition> pointmin and pointmax with the same y."""
    d = casedef.find("geometry/definition") if casedef is not None else None
    ends = [d.find(t) for t in ("pointmin", "pointmax")] if d is not None else [None]
    if any(e is None for e in ends):
        return False
    return bool(reader.vec3(ends[0])[1] == reader.vec3(ends[1])[1])


def read_initials(reader, casedef) -> list:
    el = reader.child(casedef, "initials")
    out = []
    if el is None:
        return out
    for item in reader.children(el):
        tag = item.tag
        if tag not in ("velocity", "densityuniform", "densitygradient", "densitydepth", "move", "rotateaxis",
                       "velwave", "velmesh", "densitymesh", "moverandom"):
            raise reader.error(item, f"unknown initial condition <{tag}>",
                               "velocity, densityuniform, densitygradient, densitydepth, move, rotateaxis")
        if tag in ("velwave", "velmesh", "densitymesh", "moverandom"):
            raise reader.error(item, f"<{tag}> is not supported by sphdvi",
                               "velocity, densityuniform, densitygradient, densitydepth, move or rotateaxis")
        d = {"type": tag, "line": item.sourceline}
        if item.get("mkfluid") is not None:
            d["mkfluid"] = _mk_list(reader, item, "mkfluid")
        if item.get("mkbound") is not None:
            d["mkbound"] = _mk_list(reader, item, "mkbound")
        if "mkfluid" not in d and "mkbound" not in d:
            raise reader.error(item, "missing mkfluid or mkbound", 'mkfluid="..." or mkbound="..."')
        onlypos = read_onlypos(reader, item)
        if onlypos is not None:
            d["onlypos"] = onlypos
        if tag == "velocity":
            direction = reader.child(item, "direction")
            if direction is not None:
                d["direction"] = reader.vec3(direction).tolist()
                d["profile"], d["params"] = read_velocity_profile(reader, item)   # as <fluidvelocity>'s
            else:
                d["vel"] = reader.vec3(item).tolist()
        elif tag == "densityuniform":
            d["rhop"] = reader.num(item, "rhop", positive=True)
        elif tag == "densitygradient":
            p1, p2 = reader.child(item, "pos1", True), reader.child(item, "pos2", True)
            d["pos1"], d["rhop1"] = reader.vec3(p1).tolist(), reader.num(p1, "rhop", positive=True)
            d["pos2"], d["rhop2"] = reader.vec3(p2).tolist(), reader.num(p2, "rhop", positive=True)
        elif tag == "densitydepth":
            p = reader.child(item, "posswl")
            d["posswl"] = reader.vec3(p).tolist() if p is not None else None
            for t in ("gravity",):
                g = reader.child(item, t)
                if g is not None:
                    d[t] = reader.vec3(g).tolist()
            for t in ("rhop0", "gamma", "b"):
                if reader.child(item, t) is not None:
                    d[t] = reader.child_value(item, t, positive=True)
        elif tag == "move":
            d["move"] = reader.vec3(item).tolist()
        elif tag == "rotateaxis":
            units = reader.text_attr(item, "anglesunits", "degrees", choices={"degrees", "radians"})
            ang = reader.num(item, "angle")
            d["angle_deg"] = ang if units.lower() == "degrees" else float(np.degrees(ang))
            d["axisp1"] = reader.vec3(reader.child(item, "axisp1", True)).tolist()
            d["axisp2"] = reader.vec3(reader.child(item, "axisp2", True)).tolist()
            if not np.linalg.norm(np.subtract(d["axisp2"], d["axisp1"])) > 0:
                raise reader.error(item, "axisp1 equals axisp2: the rotation axis has no direction",
                                   "two different points axisp1 and axisp2")
        out.append(d)
    return out


MOVEMENTS = {
    "wait": (), "mvnull": (),
    "mvrect": ("vel",), "mvrectace": ("velini", "ace"),
    "mvrot": ("vel", "axisp1", "axisp2"), "mvrotace": ("ace", "velini", "axisp1", "axisp2"),
    "mvcir": ("vel", "ref", "axisp1", "axisp2"), "mvcirace": ("ace", "velini", "ref", "axisp1", "axisp2"),
    "mvrectsinu": ("freq", "ampl", "phase"), "mvrotsinu": ("freq", "ampl", "phase", "axisp1", "axisp2"),
    "mvcirsinu": ("freq", "ampl", "phase", "ref", "axisp1", "axisp2"),
    "mvrectfile": ("file",), "mvrotfile": ("file", "axisp1", "axisp2"),
    "mvrotadvfile": ("file",),          # and <center>, <intrinsic>, <axes>: _read_euler_axes
    "mvpathfile": ("file",),            # the same and <movecenter>
}


def read_motion(reader, casedef) -> list:
    """``<motion>``: one dict per ``objreal`` with its chain of movements (hierarchy flattened
    into ``parents``: the movements of enclosing ``<obj>`` elements, applied first)."""
    el = reader.child(casedef, "motion")
    out = []
    if el is None:
        return out
    refs = {}
    is2d = _definition_is_2d(reader, casedef)

    def walk(node, parents):
        for child in reader.children(node):
            if child.tag in ("objreal", "obj"):
                chain = _read_movement_chain(reader, child, is2d)
                if child.tag == "objreal":
                    ref = reader.integer(child, "ref", lo=0)
                    if ref in refs:
                        raise reader.error(child, f"mkbound {ref} has two motions (line {refs[ref]})", "one <objreal> per mkbound")
                    refs[ref] = child.sourceline
                    out.append({"ref": ref, "line": child.sourceline, "parents": parents, **chain})
                walk(child, parents + [chain])
            elif child.tag in MOVEMENTS or child.tag in ("mvfile", "mvpredef", "begin"):
                continue
            else:
                _refuse_unsupported_movement(reader, child)
                raise reader.error(child, f"unknown motion element <{child.tag}>",
                                   "objreal, obj, begin, " + ", ".join(sorted(MOVEMENTS)))
    walk(el, [])
    return out


def _refuse_unsupported_movement(reader, m) -> None:
    """DualSPHysics v5.4's file movements that sphdvi does not implement: a clear error."""
    if m.tag in UNSUPPORTED_MOVEMENTS:
        raise reader.error(m, f"<{m.tag}> ({UNSUPPORTED_MOVEMENTS[m.tag]}, DualSPHysics v5.4) is not supported by "
                           "sphdvi", "mvrectfile for positions from a file, mvrotfile for an angle about one axis, "
                           "mvrotadvfile for three Euler angles")


def _read_movement_chain(reader, obj, is2d=False):
    from .datafiles import MOTION_FILE_ALIASES as aliases, read_motion_file
    begins = [b for b in reader.children(obj) if b.tag == "begin"]
    movs, elements = {}, {}
    order = []
    for m in reader.children(obj):
        tag = aliases.get(m.tag, m.tag)
        if tag not in MOVEMENTS:
            if m.tag in ("begin", "obj", "objreal"):
                continue
            _refuse_unsupported_movement(reader, m)
            raise reader.error(m, f"unknown motion element <{m.tag}>",
                               "objreal, obj, begin, " + ", ".join(sorted([*MOVEMENTS, *aliases])))
        mid = reader.integer(m, "id", lo=1)        # JMotion::MovAdd: "The movement id must be greater than zero"
        if mid in movs:
            raise reader.error(m, f"movement id {mid} is used twice", "unique ids")
        d = _movement_timing(reader, m, tag)
        d.update(type=tag, id=mid)
        for part in MOVEMENTS[tag]:
            if part == "file":
                d.update(read_motion_file(reader, m, tag, d["duration"]))
                continue
            c = reader.child(m, part)
            if c is None:
                if part in ("phase", "velini"):
                    continue
                raise reader.error(m, f"missing <{part}>", f"<{part}> in <{m.tag}>")
            if c.get("ang") is not None:
                d[part] = reader.num(c, "ang")
            elif c.get("v") is not None:
                d[part] = reader.num(c, "v")
            else:
                d[part] = reader.vec3(c).tolist()
        if tag in ("mvrotadvfile", "mvpathfile"):
            d.update(_read_euler_axes(reader, m))
        if "axisp1" in d and "axisp2" in d:
            p1, p2 = np.asarray(d["axisp1"]), np.asarray(d["axisp2"])
            if not np.linalg.norm(p2 - p1) > 1e-12 * max(1.0, np.abs(p1).max(), np.abs(p2).max()):
                raise reader.error(reader.child(m, "axisp2"), f"<{m.tag}> id={mid}: axisp1 and axisp2 are the same "
                                   f"point {p1.tolist()}, so they define no rotation axis",
                                   "two distinct points on the axis")
        if is2d:
            _warn_dropped_y(reader, m, d)
        movs[mid] = d
        elements[mid] = m
        order.append(mid)
    for d in movs.values():
        if d["next"] is not None and d["next"] not in movs:
            raise reader.error(obj, f"movement {d['id']} continues with next={d['next']}, which does not exist",
                               "next naming an id of this object")
    chain = {"movements": [movs[i] for i in order]}
    events = [_read_begin(reader, b, movs) for b in begins]
    if not begins and order:
        # JMotion starts an object's movements only through its events (<begin>)
        reader.warn(obj, "movements without a <begin mov=\"..\" start=\"..\"/>: the object does not move "
                    "(DualSPHysics's JMotion runs a movement only from an event)")
    for event in events:
        _check_zero_loop(reader, movs, elements, event["mov"])
    if events:
        chain["begin"] = events[0]
        chain["events"] = events
        _check_concurrent_events(reader, begins, movs, events)
    return chain


UNSUPPORTED_MOVEMENTS: dict = {}         # tag -> what it is, for a movement sphdvi refuses


def _read_euler_axes(reader, m) -> dict:
    """An ``mvrotadvfile``'s ``<axes value="XYZ">`` (three of X, Y, Z, no two in a row the same: Tait-Bryan
    or proper Euler angles), ``<intrinsic value>`` (true: each turn about the axes as the earlier
    turns left them; false: about the fixed axes) and ``<center>`` (the point the object turns
    about; the origin when absent), as DualSPHysics's JMotionMovRotAdvFile writes them."""
    el = reader.child(m, "axes", True)
    axes = reader.text_attr(el, "value").strip().upper()
    if len(axes) != 3 or any(a not in "XYZ" for a in axes) or axes[0] == axes[1] or axes[1] == axes[2]:
        raise reader.error(el, f"axes value={axes!r}", "three of X, Y, Z, no two in a row the same (e.g. XYZ, ZYX, ZXZ)")
    intrinsic = reader.boolean(reader.child(m, "intrinsic", True), "value")
    c = reader.child(m, "center")
    center = reader.vec3(c).tolist() if c is not None else [0.0, 0.0, 0.0]
    known = ("file", "axes", "intrinsic", "center") + (("movecenter",) if m.tag == "mvpathfile" else ())
    for e in reader.children(m):
        if e.tag not in known:
            raise reader.error(e, f"unknown element <{e.tag}> in <{m.tag}>", ", ".join(f"<{k}>" for k in known))
    out = {"axes": axes, "intrinsic": intrinsic, "center": center}
    if m.tag == "mvpathfile":
        mc = reader.child(m, "movecenter")
        out["movecenter"] = reader.boolean(mc, "value") if mc is not None else True
    return out


def _movement_timing(reader, m, tag) -> dict:
    """``duration``, ``next`` and ``anglesunits`` of a movement as JMotion::ReadXml reads them:
    duration required (a negative one is a flash: the displacement of |duration| seconds at once;
    a wait's must be >= 0, JMotion::MovAddWait), next 0 or absent for none, anglesunits exactly
    ``degrees`` or ``radians``; an ``mvnull`` reads none of them (no time, no next: the chain ends)."""
    if tag == "mvnull":
        return {"duration": 0.0, "next": None, "anglesunits": "degrees"}
    duration = reader.num(m, "duration")
    if tag == "wait" and duration < 0:
        raise reader.error(m, f"<wait> with a negative duration ({duration:g})",
                           "duration >= 0 (DualSPHysics refuses negative waiting times)")
    nxt = reader.integer(m, "next", 0, lo=0)
    units = reader.text_attr(m, "anglesunits", "degrees")
    if units not in ("degrees", "radians"):
        raise reader.error(m, f"anglesunits={units!r} is not recognised", "degrees or radians (lower case)")
    return {"duration": duration, "next": nxt or None, "anglesunits": units}


def _warn_dropped_y(reader, m, d) -> None:
    """2D case: warn of a movement that would take the object out of the x-z plane; DualSPHysics
    keeps the moving particles' y (JDsMotion::ProcesTime zeroes a translation's y, MoveMatBound
    keeps y under a rotation), and so does sphdvi."""
    tag = d["type"]
    what = None
    if tag in ("mvrect", "mvrectace", "mvrectsinu"):
        parts = {"mvrect": ("vel",), "mvrectace": ("ace", "velini"), "mvrectsinu": ("ampl",)}[tag]
        bad = [p for p in parts if p in d and d[p][1] != 0]
        what = ", ".join(f"<{p}> y={d[p][1]:g}" for p in bad) or None
    elif tag in ("mvrectfile", "mvrotadvfile", "mvpathfile"):
        from .datafiles import EULER_FIELDS
        moving = d.get("varying", d.get("fields", {}))      # the columns whose values change
        parts = ["the file's y column (fieldy)"] if tag != "mvrotadvfile" and "fieldy" in moving else []
        if tag != "mvrectfile":
            turns = [a for a, f in zip(d["axes"], EULER_FIELDS) if a != "Y" and f in moving]
            parts += [f"angles about {' and '.join(sorted(set(turns)))} from the file"] if turns else []
        what = "; ".join(parts) or None
    elif "axisp1" in d:
        axis = np.asarray(d["axisp2"], float) - np.asarray(d["axisp1"], float)
        if abs(axis[0]) > 1e-12 * np.linalg.norm(axis) or abs(axis[2]) > 1e-12 * np.linalg.norm(axis):
            what = f"an axis not along y ({d['axisp1']} -> {d['axisp2']})"
    if what:
        reader.warn(m, f"2D case: <{m.tag}> id={d['id']} moves out of the x-z plane ({what}); its y component "
                       "is dropped, the moving particles keep their y (as DualSPHysics)")


def _read_begin(reader, begin, movs) -> dict:
    """One ``<begin mov start finish>`` of an object: an event starting the movement ``mov`` at
    ``start``, its chain stopped at ``finish`` (-1 or none: no end), as DualSPHysics's JMotion::EventAdd."""
    mov = reader.integer(begin, "mov", lo=0)
    if mov not in movs:
        raise reader.error(begin, f"mov={mov} names no movement", "an id of a movement of this object")
    start = reader.num(begin, "start", nonnegative=True)      # required, as JMotion::ReadXml
    finish = reader.num(begin, "finish", None) if begin.get("finish") is not None else None
    if finish is not None and finish < 0:
        finish = None            # DualSPHysics's finish="-1": no end
    if finish is not None and finish < start:
        raise reader.error(begin, f"finish={finish:g} comes before start={start:g}",
                           "finish >= start, or -1 (no end)")
    return {"mov": mov, "start": start, "finish": finish}


def _check_zero_loop(reader, movs, elements, first) -> None:
    """A loop of movements (next=) whose durations add up to 0 would never advance time: an error
    (a flash, duration < 0, takes no time)."""
    path, cur = [], first
    while cur is not None and cur not in path:
        path.append(cur)
        cur = movs[cur]["next"]
    if cur is not None and cur in path:
        loop = path[path.index(cur):]
        if sum(max(movs[i]["duration"], 0.0) for i in loop) <= 0:
            ids = " -> ".join(str(i) for i in loop + [cur])
            raise reader.error(elements[loop[-1]], f"the movements {ids} loop forever without advancing time "
                               "(their durations add up to 0)",
                               "a positive duration in the loop, or a movement without next")


_TURNING = {"mvrot", "mvrotace", "mvrotsinu", "mvrotfile", "mvrotadvfile", "mvpathfile"}


def _event_span(movs, event) -> tuple[float, float, bool]:
    """(start, end, turns) of an event: when its chain of movements runs (end: inf for a loop; a
    flash, duration < 0, takes no time) and whether one of its movements rotates the object."""
    path, cur, end = [], event["mov"], event["start"]
    while cur is not None and cur not in path:
        path.append(cur)
        end = end + max(movs[cur]["duration"], 0.0)
        cur = movs[cur]["next"]
    if cur is not None:
        end = np.inf
    if event["finish"] is not None:
        end = min(end, event["finish"])
    return event["start"], end, any(movs[i]["type"] in _TURNING for i in path)


def _check_concurrent_events(reader, begins, movs, events) -> None:
    """Several ``<begin>`` of one object are events that each run their own chain (DualSPHysics's
    JMotionObj::ProcesTime moves the object by every active chain's step in turn). sphdvi composes
    the chains' transforms in order of their start, which is DualSPHysics's motion where their
    times do not overlap or where the overlapping ones only translate (translations commute); two
    overlapping events one of which rotates make a motion that depends on the time step there."""
    spans = [_event_span(movs, e) for e in events]
    for i, (s1, e1, turn1) in enumerate(spans):
        for j in range(i + 1, len(spans)):
            s2, e2, turn2 = spans[j]
            if (turn1 or turn2) and s2 < e1 and s1 < e2:
                raise reader.error(begins[j] if j < len(begins) else begins[i],
                                   f"two <begin> events of this object run at the same time "
                                   f"({s1:g}-{e1:g} s and {s2:g}-{e2:g} s) and one of them rotates it: "
                                   "concurrent events with a rotation are not supported by sphdvi",
                                   "events whose times do not overlap (finish= or durations), or only "
                                   "translations (mvrect, mvrectace, mvrectsinu, mvrectfile, mvcir...) in "
                                   "overlapping ones")


MATERIAL_KEYS = {"Young_Modulus": "young", "PoissonRatio": "poisson",
                 "Restitution_Coefficient": "restitution", "Kfric": "kfric", "Sfric": "sfric"}


def _warn_near_material_key(reader, el, key: str) -> None:
    """A property value sphdvi does not read, spelt like one it does (``Kfrik``): warned, as it
    would leave the contact with the default value.  Other keys (a user's own) pass silently."""
    import difflib
    known = list(MATERIAL_KEYS) + [k + "_User" for k in MATERIAL_KEYS]
    hint = difflib.get_close_matches(key, known, n=1, cutoff=0.75)
    if hint:
        reader.warn(el, f"property value '{key}' is not read (did you mean '{hint[0]}'?); the contact uses "
                        f"the default for it")


def _read_material(reader, el, merge_into=None) -> Material:
    """A ``<property>``: values as child elements (``<Kfric value="0.3"/>``) or attributes
    (``Restitution_Coefficient_User="0.65"``); as in DualSPHysics, a ``*_User`` value
    overrides the plain one, wherever each is written.  ``merge_into``: an earlier property of
    the same name, whose values this one's join (JCaseProperties::ReadXmlProperty adds the
    values of a second <property> of a name to the first; a value both give is DualSPHysics's
    "Value already exists", a case error here)."""
    mat = Material(name=reader.text_attr(el, "name").replace(" ", ""))   # stored without spaces
    plain, user, given = {}, {}, {}
    if merge_into is not None:
        mat, plain, user, given = (merge_into, merge_into._plain, merge_into._user_values,
                                   merge_into._given)
    values = [(c, c.tag) for c in reader.children(el)] + [(el, k) for k in el.keys() if k != "name"]
    for owner, key in values:
        if key.lower() in given:
            raise reader.error(owner, f"property '{mat.name}' gives '{key}' a second time (first at line "
                                      f"{given[key.lower()]})",
                               "each value once in the <property> elements of one name")
        given[key.lower()] = owner.sourceline
        base = key.removesuffix("_User")
        if base in MATERIAL_KEYS:
            num = (reader.num(owner, "value", nonnegative=True) if owner is not el
                   else reader.num(el, key, nonnegative=True))
            (user if key.endswith("_User") else plain)[MATERIAL_KEYS[base]] = num
        else:
            _warn_near_material_key(reader, owner, key)
            if owner is el:
                mat.extra[key] = el.get(key)
                reader.mark(el, key)
            else:
                mat.extra[key] = {k: owner.get(k) for k in owner.keys()}
                reader.mark(owner, *owner.keys())
    for attr, value in {**plain, **user}.items():
        setattr(mat, attr, value)
    mat.user = sorted(user)
    if mat.poisson is not None and not (0.0 <= mat.poisson < 0.5):
        raise reader.error(el, f"PoissonRatio {mat.poisson} out of range", "0 <= nu < 0.5")
    if mat.restitution is not None and mat.restitution > 1.0:
        raise reader.error(el, f"Restitution_Coefficient {mat.restitution} above 1", "0 <= e <= 1")
    # what the next <property> of this name merges with (not stored in the case file)
    mat._plain, mat._user_values, mat._given = plain, user, given
    return mat


def read_properties(reader, casedef, fluidcount: int = 9):
    """``<properties>``: the materials by name (stored without spaces, found whatever the case,
    as JCaseProperties::AddProperty / GetIndexProperty) and the links (JCasePropLinks::ReadXml)."""
    el = reader.child(casedef, "properties")
    materials, links = {}, []
    if el is None:
        return materials, links
    for c in reader.children(el):
        if c.tag == "property":
            _read_property_into(reader, c, materials)
        elif c.tag == "propertyfile":
            path = reader.resolve_path(c, "file")
            section = reader.text_attr(c, "path", "")
            _read_property_file(reader, c, path, section, materials)
        elif c.tag == "links":
            for link in reader.children(c):
                if link.tag != "link":
                    raise reader.error(link, f"unknown element <{link.tag}>", "<link>")
                d = _read_link_mks(reader, link, fluidcount)
                if d is not None:                       # None: a link DualSPHysics drops (empty list)
                    links.append(d)
        else:
            raise reader.error(c, f"unknown element <{c.tag}> in <properties>", "property, propertyfile, links")
    for d in links:
        d["property"] = _check_property_names(reader, d["property"], materials, d["line"], "link")
    return materials, links


def _read_property_into(reader, el, materials: dict) -> None:
    """Read a ``<property>`` into ``materials``: a new name is stored (without spaces), one
    already there (whatever the case of its letters, as JCaseProperties::GetIndexProperty)
    takes this one's values as well, under its first spelling."""
    name = reader.text_attr(el, "name").replace(" ", "").lower()
    first = next((m for k, m in materials.items() if k.lower() == name), None)
    m = _read_material(reader, el, merge_into=first)
    materials.setdefault(m.name, m)


def _read_link_mks(reader, link, fluidcount: int) -> dict | None:
    """A ``<link>``'s particles, as JCasePropLinks::ReadXml: ``mkbound``, else ``mkfluid``, else
    ``mk`` (the global mk: GetProps matches it to the particle's mk, which is mkfluid + 1 for
    fluid and mkbound + fluidcount + 1 for boundaries, sphdvi's and GenCase's numbering). The list is
    read as JCasePropLinks reads it (:func:`~sphdvi.case.mkrange.prop_link_attr`): None for a link it
    drops (an empty list, or no property name: JCasePropLinks::AddLink keeps a link only when
    both are non-empty, blanks dropped; warned here, a likely mistake)."""
    d = {"property": reader.text_attr(link, "property"), "line": link.sourceline}
    given = [a for a in ("mkbound", "mkfluid", "mk") if link.get(a) is not None]
    if not given:
        raise reader.error(link, "missing mkbound, mkfluid or mk", 'mkbound="0" (or mkfluid=, or the global mk=)')
    if len(given) > 1:
        reader.mark(link, *given[1:])
        reader.warn(link, f"{given[0]} and {' and '.join(given[1:])} given: DualSPHysics reads {given[0]} "
                          f"only, and so does sphdvi")
    if not d["property"].replace(" ", "").replace("+", ""):
        reader.mark(link, given[0])
        reader.warn(link, f"property={link.get('property')!r} names no property: the link is dropped, as "
                          f"DualSPHysics drops it (JCasePropLinks::AddLink), and gives {given[0]} "
                          f"{link.get(given[0])!r} nothing")
        return None
    mks = prop_link_attr(reader, link, given[0])
    if mks is None:
        return None
    if given[0] != "mk":
        d[given[0]] = mks
        return d
    first_bound = fluidcount + 1
    bound = [mk - first_bound for mk in mks if mk >= first_bound]
    fluid = [mk - 1 for mk in mks if 1 <= mk < first_bound]
    if bound:
        d["mkbound"] = bound
    if fluid:
        d["mkfluid"] = fluid
    if len(bound) + len(fluid) < len(mks):
        reader.warn(link, "mk 0 is no particle's mk (fluids start at mk 1): it links nothing")
    return d


def _check_property_names(reader, combo: str, materials: dict, line: int, element: str) -> str:
    """Each name of a property (or a combination "A + B") of a <link> or a <floating> is defined
    (a floating's misspelt property fell back to the default material before); returns the
    combination with each name as defined: DualSPHysics drops the spaces and finds a property
    whatever the case of its letters (JCaseProperties::GetIndexProperty), so "Steel" is "steel"."""
    by_lower = {k.lower(): k for k in materials}
    names = []
    pieces = [n for n in combo.split("+") if n.replace(" ", "")] or [combo]   # "a+" is "a" (GetPropsSort)
    for name in pieces:
        key = by_lower.get(name.replace(" ", "").lower())
        if key is None:
            raise CaseError(f"property '{name.strip()}' is not defined", file=reader.file, line=line,
                            element=element, expected="a <property name> defined in <properties> or its propertyfile"
                            + (f" (defined: {', '.join(sorted(materials))})" if materials else ""))
        names.append(key)
    return "+".join(names)


def _read_property_file(reader, el, path, section, materials):
    """The ``<property>`` items of a ``<propertyfile>`` (under its dotted ``path``) into ``materials``."""
    sub_root, _ = load_xml_any(path, reader)
    strip_disabled(sub_root, path)
    node = sub_root
    parts = [p for p in section.split(".") if p]
    if parts and parts[0] == sub_root.tag:
        parts = parts[1:]
    for p in parts:
        nxt = node.find(p)
        if nxt is None:
            raise reader.error(el, f"path '{section}' not found in {os.path.basename(path)}",
                               "a dotted path of elements holding <property> items")
        node = nxt
    sub_reader = CaseReader(path, reader.vars, reader.warnings)
    for c in node.iter("property"):
        sub_reader.mark(c)
        _read_property_into(sub_reader, c, materials)


def load_xml_any(path, reader):
    """Parse an auxiliary XML file (any root element)."""
    from .xmldoc import parse_xml_text
    try:
        with open(path, "rb") as fh:
            raw = fh.read(64 * 1024 * 1024 + 1)
    except OSError as exc:
        raise CaseError(f"cannot read {path}: {exc.strerror}", file=reader.file) from None
    return parse_xml_text(raw.decode("utf-8", errors="replace"), path), None


# ---------------------------------------------------------------------------
# execution
# ---------------------------------------------------------------------------
def read_uservars(reader, execution) -> None:
    """``<execution><uservars>``: the ``<varnum name value>`` and ``<varstr name value>`` a GenCase
    output file carries (GenCase's exported variables, JCaseUserVars), which DualSPHysics defines
    before it evaluates the execution section's expressions (JSph::LoadConfigVars).  sphdvi has
    the case's own variables already; a listed variable it lacks is defined, one it has with
    another value keeps the case's value, with a warning.  (``<vtkout>``, GenCase's list of the
    shape files it wrote, is its record only, as ``<particles>`` and ``<constants>`` are: not read.)"""
    el = reader.child(execution, "uservars") if execution is not None else None
    if el is None:
        return
    for v in reader.children(el):
        if v.tag not in ("varnum", "varstr"):
            raise reader.error(v, f"unknown element <{v.tag}> in <uservars>", '<varnum name="N" value="1.5"/> '
                                                                               'or <varstr name="S" value="text"/>')
        name = reader.text_attr(v, "name").strip()
        value = reader.num(v, "value") if v.tag == "varnum" else reader.text_attr(v, "value")
        known = reader.vars.values.get(name)
        if known is None:
            try:
                reader.vars.define(name, value)
            except ExpressionError as exc:
                raise reader.error(v, str(exc), "a variable name: a letter or '_', then letters, digits, '_'") from None
        elif not _same_value(known, value):
            reader.warn(v, f"uservars: {name}={value!r} differs from the case's own {name}={known!r}; "
                           "the case's value is used")


def _same_value(a, b) -> bool:
    """Equal texts, or numbers (booleans as 0/1) equal to GenCase's printed precision."""
    if isinstance(a, str) or isinstance(b, str):
        return a == b
    return math.isclose(float(a), float(b), rel_tol=1e-9, abs_tol=1e-12)


def read_parameters(reader, execution):
    params = default_parameters()
    set_keys = []
    domain = {"posmin": ["default"] * 3, "posmax": ["default"] * 3}
    el = reader.child(execution, "parameters") if execution is not None else None
    if el is None:
        return params, set_keys, domain
    for p in reader.children(el):
        if p.tag == "simulationdomain":
            for which in ("posmin", "posmax"):
                c = reader.child(p, which)
                if c is not None:
                    domain[which] = [_domain_spec(reader, c, comp) for comp in "xyz"]
            continue
        if p.tag != "parameter":
            raise reader.error(p, f"unknown element <{p.tag}> in <parameters>", "<parameter key value> or <simulationdomain>")
        key = str(reader.raw(p, "key")).strip()
        if key.startswith("#"):
            reader.mark(p, "value")
            continue
        if key not in PARAMETERS:
            const = other_build_hint(key) or constant_hint(key)
            if const:
                raise reader.error(p, const)
            hint = closest_key(key)
            raise reader.error(p, f"unknown parameter key '{key}' (DualSPHysics skips a key it does not know; "
                                  "sphdvi stops, so that a misspelt key is not lost)",
                               f"'{hint}'" if hint else "a DualSPHysics parameter key (the list: sphdvi/case/parameters.py), "
                               f"or key=\"#{key}\" to keep it as a remark")
        if key in set_keys:
            reader.warn(p, f"parameter '{key}' given twice; the last value is used")
        raw = reader.raw(p, "value")
        spec = PARAMETERS[key]
        if key == "DtFixed" and not _is_number(raw):
            raise reader.error(p, f"parameter DtFixed: value={raw!r} is not a number (DtFixed is one dt in seconds; "
                                  "a file of dt values, as DualSPHysics before v5 took here, goes in DtFixedFile)",
                               "a number, or <parameter key=\"DtFixedFile\" value=\"FILE\" />")
        try:
            if spec.kind == "str":
                value = coerce(key, raw)
            else:
                value = coerce(key, reader.num(p, "value"))
            check_supported(key, value)
        except ValueError as exc:
            raise reader.error(p, f"parameter {key}: {exc}", _expected_for(key)) from None
        for text in parameter_warnings(key, value):
            reader.warn(p, text)
        if key in DATA_FILE_KEYS and str(value).strip() and str(value).upper() != "NONE":
            value = _checked_data_file(reader, p, DATA_FILE_KEYS[key])
        params[key] = value
        set_keys.append(key)
    try:
        apply_delta_sph(params, set_keys)
        domain = domain_from_deprecated(params, set_keys, domain)
    except ValueError as exc:
        raise reader.error(el, str(exc), "DualSPHysics v5.4's keys: DensityDT, <simulationdomain>") from None
    try:
        check_consistency(params)
    except ValueError as exc:
        raise reader.error(el, str(exc)) from None
    return params, set_keys, domain


def _is_number(raw) -> bool:
    """Whether a parameter's raw value reads as a number (or an expression, ``#...``)."""
    text = str(raw).strip()
    if text.startswith("#"):
        return True
    try:
        float(text)
    except ValueError:
        return False
    return True


def _expected_for(key):
    spec = PARAMETERS[key]
    if key in NOT_SUPPORTED:
        return f"{spec.default} (off) or no such parameter"
    if spec.choices:
        return "one of " + ", ".join(str(c) for c in spec.choices)
    rng = []
    if spec.positive:
        rng.append("> 0")
    elif spec.lo is not None:
        rng.append(f">= {spec.lo:g}")
    if spec.hi is not None:
        rng.append(f"<= {spec.hi:g}")
    return ("a number " + " and ".join(rng)) if rng else "a number"


DATA_FILE_KEYS = {"DtFixedFile": read_dt_table, "ViscoTime": read_visco_table}


def _checked_data_file(reader, p, read_table) -> str:
    """The absolute path of a parameter's data file (relative to the case), read once
    now so that a bad file is an error of the case, with its line."""
    path = reader.resolve_path(p, "value")
    try:
        read_table(path)
    except CaseError as exc:
        raise reader.error(p, f"{exc.message} ({path}" + (f", line {exc.line}" if exc.line else "") + ")",
                           exc.expected) from None
    return path


def _domain_spec(reader, el, comp) -> str:
    """Keep ``default``, ``default + 10%``, ``default - 2`` or a number; check the syntax now."""
    raw = el.get(comp)
    reader.mark(el, comp)
    if raw is None:
        return "default"
    text = raw.strip()
    try:
        parse_domain_spec(text, 0.0, 1.0)
    except ValueError as exc:
        raise reader.error(el, f"{comp}={raw!r}: {exc}", "'default', 'default +|- value[%]' or a number") from None
    return text


def parse_domain_spec(text: str, default: float, extent: float) -> float:
    """Evaluate a simulation-domain limit: ``default``, ``default + 50%``, ``default-2`` or a value."""
    import re
    s = text.replace(" ", "").lower()
    if s == "default":
        return default
    m = re.fullmatch(r"default([+-])([0-9.eE+-]+)(%?)", s)
    if m:
        amount = float(m.group(2))
        if m.group(3):
            amount = extent * amount / 100.0
        value = default + amount if m.group(1) == "+" else default - amount
    else:
        value = float(s)
    if value != value or value in (float("inf"), float("-inf")):
        raise ValueError("not finite")
    return value


def read_special(reader, execution) -> dict:
    out = {}
    el = reader.child(execution, "special") if execution is not None else None
    if el is None:
        return out
    for c in reader.children(el):
        if c.tag not in SPECIAL_KNOWN:
            raise reader.error(c, f"unknown special section <{c.tag}>", "one of " + ", ".join(sorted(SPECIAL_KNOWN)))
        if c.tag == "nnphases":
            raise reader.error(c, f"<special><nnphases> belongs to {NNEWTONIAN_TEXT}",
                               "supported: " + ", ".join(sorted(SPECIAL_SUPPORTED)))
        if c.tag == "boundextrap":
            raise reader.error(c, "<special><boundextrap> is the obsolete name of <boundcorr> (DualSPHysics refuses it: "
                               "\"The XML section 'boundextrap' is obsolete.\")", "<boundcorr> with the same content")
        if c.tag not in SPECIAL_SUPPORTED:
            raise reader.error(c, f"<special><{c.tag}> is not supported by sphdvi",
                               "supported: " + ", ".join(sorted(SPECIAL_SUPPORTED)))
        out[c.tag] = SPECIAL_READERS[c.tag](reader, c)
    return out


# the children of a gauge and their kinds (read and checked by case.gauge_spec.read_field)
GAUGE_COMMON = {"savevtkpart": "bool", "computedt": "dt", "computetime": "window", "output": "bool",
                "outputdt": "dt", "outputtime": "window"}
GAUGE_SPECS = {
    "velocity": {"point": "vec"},
    "swl": {"point0": "vec", "point1": "vec", "point2": "vec", "pointdp": "oneof:value,coefdp",
            "masslimit": "oneof:value,coef"},
    "maxz": {"point0": "vec", "height": "positive", "distlimit": "oneof:value,coefdp,coefh"},
    "force": {"target": "mkbound"},
    "mesh": {"point": "vec", "vec1": "vec", "vec2": "vec", "vec3": "vec", "size1": "size", "size2": "size",
             "size3": "size", "dirdat": "vec", "masslimit": "oneof:value,coef", "kclimit": "kclimit",
             "kcdummy": "kcdummy",
             "outputdata": "outputdata", "outputfmt": "outputfmt", "buffersize": "count"},
}


def read_gauges(reader, el) -> dict:
    """``<special><gauges>``: every field typed and range-checked at gencase (see case.gauge_spec)."""
    from .gauge_spec import read_gauges as read_checked
    return read_checked(reader, el, GAUGE_COMMON, GAUGE_SPECS)


def read_damping(reader, el) -> list:
    """``<special><damping>`` as JDsDamping::ReadXml: ``<dampingzone>`` (JDsDampingOp_Plane,
    with an optional ``<domain>``), ``<dampingbox>`` and ``<dampingcylinder>``
    (:mod:`sphdvi.sph.damping`)."""
    readers = {"dampingzone": _damping_plane, "dampingbox": _damping_box, "dampingcylinder": _damping_cylinder}
    out = []
    for c in reader.children(el):
        if c.tag not in readers:
            raise reader.error(c, f"unknown damping zone <{c.tag}>", "<dampingzone>, <dampingbox> or <dampingcylinder>")
        out.append(readers[c.tag](reader, c))
    return out


def _damping_common(reader, c, kind: str, shape: set) -> dict:
    """What every damping shape reads (JDsDampingOp_*::ReadXml): ``<overlimit>`` (0),
    ``<redumax>`` (10), ``<factorxyz>`` (each of x, y, z 1 when omitted), all >= 0."""
    reader.check_children(c, {"overlimit", "redumax", "factorxyz"} | shape)
    d = {"type": kind, "line": c.sourceline,
         "overlimit": reader.child_value(c, "overlimit", 0.0), "redumax": reader.child_value(c, "redumax", 10.0),
         "factorxyz": reader.vec3(reader.child(c, "factorxyz"), np.ones(3), missing=1.0).tolist()}
    for k in ("overlimit", "redumax"):
        if not d[k] >= 0:
            raise reader.error(reader.child(c, k), f"<{k}> is {d[k]:g}", f"{k} >= 0")
    if not all(v >= 0.0 for v in d["factorxyz"]):
        raise reader.error(reader.child(c, "factorxyz"), f"<factorxyz> is {d['factorxyz']}", "factors >= 0")
    return d


def _damping_plane(reader, c) -> dict:
    """``<dampingzone>``: ``<limitmin>``, ``<limitmax>`` and an optional ``<domain zmin zmax>``
    with ``<point1..4 x y>`` (the zone's lateral limits)."""
    d = _damping_common(reader, c, "zone", {"limitmin", "limitmax", "domain"})
    d["limitmin"], d["limitmax"] = (reader.vec3(reader.child(c, t, True)).tolist() for t in ("limitmin", "limitmax"))
    if np.allclose(d["limitmin"], d["limitmax"]):
        raise reader.error(c, "limitmin equals limitmax", "two different points")
    dom = reader.child(c, "domain")
    if dom is not None:
        names = ("point1", "point2", "point3", "point4")
        reader.check_children(dom, set(names))
        d["domain"] = {"zmin": reader.num(dom, "zmin"), "zmax": reader.num(dom, "zmax"),
                       "points": [[reader.num(p, "x"), reader.num(p, "y")]
                                  for p in (reader.child(dom, t, True) for t in names)]}
        if d["domain"]["zmin"] > d["domain"]["zmax"]:
            raise reader.error(dom, f"zmin={d['domain']['zmin']:g} is above zmax={d['domain']['zmax']:g}", "zmin <= zmax")
    return d


def _damping_box(reader, c) -> dict:
    """``<dampingbox>``: ``<directions value>`` (JDsDampingOp_Box::ReadXmlDirections: top,
    bottom, left, right, front, back, all, each +added or -removed; default all) and the
    ``<limitmin>`` / ``<limitmax>`` boxes (``<pointini>``, ``<pointend>``), the limitmin box
    inside the limitmax one."""
    from ..sph.damping import BOX_SIDES
    d = _damping_common(reader, c, "box", {"directions", "limitmin", "limitmax"})
    sides = [s[0] for s in BOX_SIDES]
    text = reader.child(c, "directions")
    words = reader.text_attr(text, "value").replace(",", " ").lower().split() if text is not None else []
    chosen = set(sides) if not words else set()
    for w in words:
        name = w.lstrip("+-")
        if name not in sides + ["all"]:
            raise reader.error(text, f"direction {w!r} is not valid", "top, bottom, left, right, front, back or all, "
                               "each optionally +/-")
        group = set(sides) if name == "all" else {name}
        chosen = chosen - group if w.startswith("-") else chosen | group
    if not chosen:
        raise reader.error(text, "no direction is active", "at least one of top, bottom, left, right, front, back")
    d["directions"] = [s for s in sides if s in chosen]
    for t in ("limitmin", "limitmax"):
        box = reader.child(c, t, True)
        reader.check_children(box, {"pointini", "pointend"})
        d[t] = [reader.vec3(reader.child(box, k, True)).tolist() for k in ("pointini", "pointend")]
        if not np.all(np.asarray(d[t][0]) <= d[t][1]):
            raise reader.error(box, f"<{t}>: pointini {d[t][0]} is above pointend {d[t][1]}", "pointini <= pointend")
    if not (np.all(np.asarray(d["limitmax"][0]) <= d["limitmin"][0])
            and np.all(np.asarray(d["limitmin"][1]) <= d["limitmax"][1])):
        raise reader.error(c, "the <limitmin> box is not inside the <limitmax> box", "limitmin inside limitmax")
    return d


def _damping_cylinder(reader, c) -> dict:
    """``<dampingcylinder>``: the axis ``<point1>``, ``<point2>`` and the radii
    ``<limitmin radius>`` <= ``<limitmax radius>``."""
    d = _damping_common(reader, c, "cylinder", {"point1", "point2", "limitmin", "limitmax"})
    d["point1"], d["point2"] = (reader.vec3(reader.child(c, t, True)).tolist() for t in ("point1", "point2"))
    d["limitmin"], d["limitmax"] = (reader.num(reader.child(c, t, True), "radius", nonnegative=True)
                                    for t in ("limitmin", "limitmax"))
    if d["limitmin"] > d["limitmax"]:
        raise reader.error(c, f"limitmin radius {d['limitmin']:g} is above limitmax radius {d['limitmax']:g}",
                           "limitmin <= limitmax")
    return d


def read_timeout(reader, el) -> list:
    """``<timeout><tout time="t" timeout="dt"/>...`` (DualSPHysics's JTimeOut): from time t on,
    outputs dt apart; rows [[t, dt], ...] with t >= 0 rising and dt > 0
    (:class:`sphdvi.output_schedule.OutputSchedule`)."""
    rows = []
    for c in reader.children(el):
        if c.tag != "tout":
            raise reader.error(c, f"<timeout><{c.tag}> is not a DualSPHysics output-time row",
                               '<tout time="t" timeout="dt"/> rows')
        t = reader.num(c, "time", nonnegative=True)
        dt = reader.num(c, "timeout", positive=True)
        if rows and not t > rows[-1][0]:
            raise reader.error(c, f"time={t:g} does not follow the row before (time={rows[-1][0]:g})",
                               "rows in rising time")
        rows.append([t, dt])
    if not rows:
        raise reader.error(el, "<timeout> has no <tout> row", '<tout time="0" timeout="dt"/> rows (or no <timeout>)')
    return rows


def read_shifting(reader, el) -> dict:
    """``<special><shifting>`` as JSphShifting::ReadXml: ``<mode>`` 0-3 (required),
    ``<coefficient>`` (-2) and ``<fsthreshold>`` (0), and the ``<shiftingzone>`` boxes
    (``posref`` + ``size``, or ``posref`` + ``vecx/vecy/vecz``, optionally turned by
    ``<rotateaxis>``), each stored as posref and its three edge vectors."""
    reader.check_children(el, {"mode", "coefficient", "fsthreshold", "shiftingzone"})
    mode = reader.child(el, "mode")
    if mode is None:
        raise reader.error(el, "<shifting> has no <mode>",
                           '<mode value="0..3"/> (0 none, 1 no bound, 2 no fixed, 3 full)')
    d = {"mode": int(reader.integer(mode, "value"))}
    if d["mode"] not in (0, 1, 2, 3):
        raise reader.error(mode, f"shifting mode {d['mode']} is not valid in <special><shifting>",
                           "0 (none), 1 (no bound), 2 (no fixed) or 3 (full); advanced shifting (4) is "
                           "Shifting=4 in <parameters>, without <special><shifting>")
    d["coefficient"] = reader.child_value(el, "coefficient", -2.0)
    d["fsthreshold"] = reader.child_value(el, "fsthreshold", 0.0, nonnegative=True)
    d["zones"] = [_shifting_zone(reader, c) for c in reader.children(el, "shiftingzone")] if d["mode"] else []
    return d


def _shifting_zone(reader, c) -> dict:
    """One ``<shiftingzone>``: its posref and edge vectors (JSphShifting::ReadXml)."""
    posref = reader.vec3(reader.child(c, "posref", True))
    if reader.child(c, "size") is not None:
        reader.check_children(c, {"posref", "size", "rotateaxis"})
        vecs = np.diag(reader.vec3(reader.child(c, "size")))
    else:
        reader.check_children(c, {"posref", "vecx", "vecy", "vecz", "rotateaxis"})
        vecs = np.array([reader.vec3(reader.child(c, t, True)) for t in ("vecx", "vecy", "vecz")])
    rot = reader.child(c, "rotateaxis")
    if rot is not None and reader.num(rot, "angle", 0.0):
        from .gencase import rotate_about_axis
        units = reader.text_attr(rot, "anglesunits", "degrees", choices={"degrees", "radians"})
        ang = reader.num(rot, "angle")
        ang = np.radians(ang) if units.lower() == "degrees" else ang
        reader.check_children(rot, {"point1", "point2"})
        p1, p2 = (reader.vec3(reader.child(rot, t, True)) for t in ("point1", "point2"))
        if not np.linalg.norm(p2 - p1) > 0:
            raise reader.error(rot, "point1 and point2 of <rotateaxis> are the same point", "two distinct points")
        # JMatrix4d::MatrixRot's sense, as <rotateaxis> of <initials> (sphdvi.case.gencase)
        pts = rotate_about_axis(np.vstack([posref, posref + vecs]), p2, p1, float(ang))
        posref, vecs = pts[0], pts[1:] - pts[0]
    oblique = (vecs - np.diag(np.diag(vecs))).any()
    if oblique and abs(np.linalg.det(vecs)) < 1e-12 * max(1.0, float(np.abs(vecs).max())) ** 3:
        raise reader.error(c, "vecx, vecy and vecz of <shiftingzone> span no volume",
                           "three independent edge vectors (or <size>)")
    return {"line": c.sourceline, "posref": posref.tolist(), "vecs": vecs.tolist()}


def check_shifting(reader, root, set_keys, special) -> None:
    """Shifting defined both in ``<parameters>`` (the Shifting key, any value) and in
    ``<special><shifting>`` is refused, as JSph::LoadCaseConfig does."""
    if "shifting" in special and "Shifting" in set_keys:
        el = root.find("execution/special/shifting")
        key = next((p for p in root.iterfind("execution/parameters/parameter") if p.get("key") == "Shifting"), None)
        line = getattr(key, "sourceline", None)
        raise reader.error(el, "Shifting is defined several times (in <special><shifting> and <execution><parameters>"
                           + (f", line {line}" if line else "") + ")",
                           "one of them: the Shifting parameter, or <special><shifting>")


def check_periodic(reader, root, set_keys, params, is2d) -> None:
    """The periodic keys as DualSPHysics reads them (:func:`sphdvi.sph.periodic.periodic_config`):
    a periodic y in a 2D case is an error; a pair key written with value 0 (it still switches
    periodicity on) and increments it resets are warned about."""
    from ..sph.periodic import PAIR_KEYS, periodic_config

    def element(key):
        return next((p for p in root.iterfind("execution/parameters/parameter") if p.get("key") == key), None)
    try:
        periodic_config(set_keys, params, is2d)
    except ValueError as exc:
        raise reader.error(element(str(exc).split(":")[0]), str(exc),
                           "periodicity along x and/or z only (a 2D case lies in the x-z plane)") from None
    pairs = [k for k, _ in PAIR_KEYS if k in set_keys]
    for key in pairs:
        if not params.get(key):
            reader.warn(element(key), f"{key}={params.get(key)}: DualSPHysics switches this periodicity on when the "
                                      "key is present, whatever its value (so does sphdvi); remove the key for none")
    incs = [k for k in set_keys if "PeriodicInc" in k]
    if pairs and incs:
        reader.warn(element(incs[0]), f"{', '.join(incs)} ignored: {pairs[-1]} resets the periodic increments to 0 "
                                      "(as DualSPHysics)")


ACC_COLUMNS = ("linx", "liny", "linz", "angx", "angy", "angz")


def read_accinputs(reader, el) -> list:
    """``<accinputs>``: imposed accelerations of fluid blocks (DualSPHysics's JDsAccInput):
    per ``<accinput mkfluid="...">`` the active ``<time start end>``, ``<acccentre>``,
    ``<globalgravity>`` and a table of (time, linear acceleration, angular acceleration)
    from ``<acctimes><timevalue .../>`` or an ``<acctimesfile>`` of 7 columns."""
    out, seen = [], {}
    for c in reader.children(el):
        if c.tag != "accinput":
            raise reader.error(c, f"<accinputs><{c.tag}> is not supported by sphdvi", "<accinput>")
        for old in ("mkfluid", "datafile"):
            if c.find(old) is not None:
                raise reader.error(c.find(old), f"<{old}> inside <accinput> is the format of DualSPHysics before "
                                   "v5.0", 'the mkfluid="..." attribute and <acctimes> or <acctimesfile value="...">')
        reader.check_children(c, {"time", "acccentre", "globalgravity", "acctimes", "acctimesfile"})
        if c.get("mkbound") is not None:
            raise reader.error(c, "an <accinput> on floating bodies (mkbound) is not supported by sphdvi",
                               'mkfluid="..." (imposed accelerations of fluid particles)')
        mks = accinput_mk_attr(reader, c, "mkfluid")
        for mk in mks:
            if mk in seen:
                raise reader.error(c, f"mkfluid {mk} already has an <accinput> (line {seen[mk]})",
                                   "one <accinput> per mkfluid")
            seen[mk] = c.sourceline
        tel = reader.child(c, "time")
        start = reader.num(tel, "start", 0.0) if tel is not None else 0.0
        end = reader.num(tel, "end", None) if tel is not None else None
        if end is not None and end < start:
            raise reader.error(tel, f"end={end:g} is before start={start:g}", "end >= start")
        out.append({"line": c.sourceline, "mkfluid": mks, "start": start, "end": end,
                    "centre": reader.vec3(reader.child(c, "acccentre", required=True)).tolist(),
                    "globalgravity": reader.boolean(reader.child(c, "globalgravity", required=True), "value"),
                    "table": _acc_table(reader, c).tolist()})
    return out


def _acc_table(reader, c) -> np.ndarray:
    """The (time, linx, liny, linz, angx, angy, angz) rows of one ``<accinput>``: from
    ``<acctimes>`` (missing values 0) or the ``<acctimesfile>``; two rows at least, times that do not
    decrease (two rows at one time: a step change of the acceleration, as JLinearValue)."""
    table_el, file_el = reader.child(c, "acctimes"), reader.child(c, "acctimesfile")
    if (table_el is None) == (file_el is None):
        raise reader.error(c, "<accinput> needs one of <acctimes> and <acctimesfile>" +
                           (" (not both)" if table_el is not None else ""),
                           "<acctimes> with <timevalue> rows, or <acctimesfile value=\"file\">")
    if table_el is not None:
        rows = [[reader.num(v, "time")] + [reader.num(v, k, 0.0) for k in ACC_COLUMNS]
                for v in reader.children(table_el, "timevalue")]
        where, place = table_el, ""
    else:
        from .datafiles import read_columns
        path = reader.resolve_path(file_el, "value")
        try:
            rows = read_columns(path, 7, "<acctimesfile>")[:, :7].tolist()
        except CaseError as exc:
            raise reader.error(file_el, f"{path}{':' + str(exc.line) if exc.line else ''}: {exc.message}",
                               exc.expected) from None
        where, place = file_el, f" in {path}"
    table = np.asarray(rows, float).reshape(-1, 7)
    if table.shape[0] < 2:
        raise reader.error(where, f"{table.shape[0]} row(s) of accelerations{place}",
                           "at least two (time, linx, liny, linz, angx, angy, angz) rows")
    if np.any(np.diff(table[:, 0]) < 0):     # a repeated time is a step (JLinearValue)
        row = int(np.flatnonzero(np.diff(table[:, 0]) < 0)[0]) + 1
        raise reader.error(where, f"the times of the accelerations go back (row {row + 1}: time {table[row, 0]:g} "
                           f"after {table[row - 1, 0]:g}){place}", "times that do not decrease (a repeated time "
                           "is a step change)")
    return table


SPECIAL_READERS = {"accinputs": read_accinputs, "chrono": read_chrono, "gauges": read_gauges,
                   "wavepaddles": read_wavepaddles, "damping": read_damping, "shifting": read_shifting,
                   "timeout": read_timeout, "initialize": read_initialize, "savedt": read_savedt,
                   "outputparts": read_outputparts, "inout": read_inout, "boundcorr": read_boundcorr,
                   "relaxationzones": read_relaxationzones, "moorings": read_moorings,
                   "flexstrucs": read_flexstrucs}
