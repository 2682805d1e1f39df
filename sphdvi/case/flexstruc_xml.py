"""``<special><flexstrucs>``: DualSPHysics v5.4's flexible structures (JSphFlexStruc; O'Connor and
Rogers 2021, J. Fluids Struct. 104, 103312), read into plain dicts for :mod:`sphdvi.sph.flexstruc`.

* ``<flexstrucs>``: one ``<flexstrucbody mkbound mkclamp>`` per body, in the file's order (a body
  with ``active="false"`` is left out, as everywhere), at most 16 ("Maximum number of flexible
  structure bodies has been reached."); an empty section (no active body) does nothing (a warning).
* ``mkbound``: the moving boundary (``<motion><objreal ref>``, its motion ignored: the structure
  solver moves those particles) that becomes the body; each once ("An input already exists for the
  same mkbound=%u.").
* ``mkclamp``: the boundary mks that hold the body (fixed or moving), one integer or a list of
  values and ranges (``"0-3,7"``), at most 8; none of them a flexible structure's mkbound.
* The children, each ``<tag value>``, at most once: ``<density>`` (kg/m³), ``<youngmod>`` (Pa),
  ``<poissratio>`` and ``<constitmodel>`` (1 plane strain, 2 plane stress: 2D; 3 St Venant-
  Kirchhoff: 3D) required, ``<hgfactor>`` (the hourglass correction, 0). DualSPHysics checks no
  range; sphdvi refuses density or youngmod <= 0, poissratio outside (-1, 0.5) (0.5 divides by zero
  in the sound speed) and hgfactor < 0.

Each body: ``{"mkbound", "mkclamp": [..], "density", "youngmod", "poissratio", "constitmodel",
"hgfactor", "line"}`` (the line of its ``<flexstrucbody>``).

What needs the drawn particles (the mkbound a moving boundary, the clamps boundaries) and the
parameters (:func:`flexstruc_parameter_problem`) is checked by :func:`check_flexstrucs`, at gencase.
"""
import numpy as np

from ..errors import CaseError
from .mkrange import MAX_MK, parse_mk_range

MAX_BODIES = 16                 # the body id sits in the code's low 4 bits (CODE_TYPE_FLEXSTRUCCLAMP_MASK)
MAX_CLAMPS = 8                  # StFlexStrucData.clampcode[MAX_NUM_MKCLAMP]
BODY_CHILDREN = {"density", "youngmod", "poissratio", "constitmodel", "hgfactor"}
MODELS = {1: "plane strain", 2: "plane stress", 3: "St Venant-Kirchhoff"}
#: the required children: what each is, for the message of a missing one
REQUIRED = {"density": "the structure's density [kg/m3]", "youngmod": "Young's modulus [Pa]",
            "poissratio": "Poisson's ratio", "constitmodel": "the constitutive model: 1 plane strain, 2 plane "
                                                             "stress (2D), 3 St Venant-Kirchhoff (3D)"}
#: the motions that leave a body where it is (any other is ignored: warned at gencase)
STILL_MOTIONS = {"mvnull", "wait"}
TYPE_FIXED, TYPE_MOVING, TYPE_FLOATING, TYPE_FLUID = 0, 1, 2, 3      # sphdvi.case.gencase's particle types


def read_flexstrucs(reader, el) -> list:
    """``<special><flexstrucs>`` -> a list of body dicts, in the file's order (module docstring)."""
    reader.check_children(el, {"flexstrucbody"})
    is2d = _case_is_2d(reader)
    bodies, els, seen = [], [], {}
    for index, c in enumerate(reader.children(el, "flexstrucbody")):
        if index == MAX_BODIES:
            raise reader.error(c, f"a {MAX_BODIES + 1}th <flexstrucbody> (DualSPHysics: \"Maximum number of "
                                  "flexible structure bodies has been reached.\")",
                               f"at most {MAX_BODIES} flexible structure bodies")
        d = _read_body(reader, c, index, is2d)
        if d["mkbound"] in seen:
            raise reader.error(c, f"flexible structure mkbound={d['mkbound']} is already configured (line "
                                  f"{seen[d['mkbound']]}; DualSPHysics: \"An input already exists for the same "
                                  f"mkbound={d['mkbound']}.\")", "each mkbound in one <flexstrucbody>")
        seen[d["mkbound"]] = c.sourceline
        bodies.append(d)
        els.append(c)
    _check_clamps_not_bodies(reader, bodies, els)
    if not bodies:
        reader.warn(el, "<flexstrucs> holds no active <flexstrucbody>: it does nothing")
    return bodies


def _case_is_2d(reader) -> bool:
    """Whether the case is 2D (GenCase's rule: ``<definition>`` pointmin and pointmax with the same y)."""
    from .reader import _definition_is_2d          # (reader imports this module)
    casedef = reader.root.find("casedef") if reader.root is not None else None
    return _definition_is_2d(reader, casedef)


def _read_body(reader, c, index: int, is2d: bool) -> dict:
    """One ``<flexstrucbody>``: its mks, its material and model, checked."""
    reader.check_children(c, BODY_CHILDREN)
    reader.check_no_repeats(c)
    for attr, what in (("mkbound", "the mkbound of the moving boundary that becomes the body"),
                       ("mkclamp", "the mkbound(s) of the boundary that holds the body")):
        if c.get(attr) is None:
            raise reader.error(c, f"missing attribute '{attr}'", f'{attr}=".." ({what})')
    d = {"mkbound": reader.integer(c, "mkbound", lo=0, hi=MAX_MK), "mkclamp": _read_mkclamp(reader, c)}
    d.update(_read_material(reader, c))
    _check_model(reader, c, d, index, is2d)
    d["line"] = c.sourceline
    return d


def _read_mkclamp(reader, c) -> list:
    """``mkclamp``: one mk, or a list of values and ranges (``"0-3,7"``), at most :data:`MAX_CLAMPS`
    mks (sorted, each once)."""
    raw = reader.raw(c, "mkclamp")
    if raw.strip().startswith("#"):
        return [reader.integer(c, "mkclamp", lo=0, hi=MAX_MK)]
    try:
        mks = parse_mk_range(raw)
    except ValueError as exc:
        raise reader.error(c, f"mkclamp: {exc}", 'an mkbound, or mk values and ranges like "0-3,7"') from None
    if len(mks) > MAX_CLAMPS:
        raise reader.error(c, f"mkclamp=\"{raw}\" names {len(mks)} mks", f"at most {MAX_CLAMPS} clamp mks per body "
                           "(DualSPHysics v5.4's limit)")
    return mks


def _read_material(reader, c) -> dict:
    """density, youngmod, poissratio, constitmodel (required) and hgfactor (0), range-checked."""
    for tag, what in REQUIRED.items():
        if reader.child(c, tag) is None:
            raise reader.error(c, f"missing <{tag}>", f'<{tag} value=".."/> ({what})')
    d = {"density": reader.num(reader.child(c, "density"), "value"),
         "youngmod": reader.num(reader.child(c, "youngmod"), "value"),
         "poissratio": reader.num(reader.child(c, "poissratio"), "value"),
         "constitmodel": reader.integer(reader.child(c, "constitmodel"), "value")}
    hg = reader.child(c, "hgfactor")
    d["hgfactor"] = reader.num(hg, "value") if hg is not None else 0.0
    for tag, ok, expected in (
            ("density", d["density"] > 0, "a density > 0 [kg/m3]"),
            ("youngmod", d["youngmod"] > 0, "a Young's modulus > 0 [Pa]"),
            ("poissratio", -1.0 < d["poissratio"] < 0.5, "a Poisson's ratio above -1 and below 0.5 (0.5, an "
                                                          "incompressible solid, gives an infinite sound speed)"),
            ("hgfactor", d["hgfactor"] >= 0, "an hourglass correction factor >= 0 (0: none)")):
        if not ok:
            raise reader.error(reader.child(c, tag), f"{tag} value={d[tag]:g} is out of range", expected)
    return d


def _check_model(reader, c, d: dict, index: int, is2d: bool) -> None:
    """constitmodel 1 or 2 in a 2D case, 3 in a 3D case (JSphFlexStruc, body ``index`` 0-based)."""
    el, model = reader.child(c, "constitmodel"), d["constitmodel"]
    if model not in MODELS:
        raise reader.error(el, f"constitmodel value={model} is not a constitutive model (DualSPHysics: "
                               f"\"Constitutive model for body {index} is not valid.\")",
                           "1 (plane strain) or 2 (plane stress) in 2D, 3 (St Venant-Kirchhoff) in 3D")
    if (model == 3) == is2d:
        dim = "2D" if is2d else "3D"
        raise reader.error(el, f"constitmodel value={model} ({MODELS[model]}) in a {dim} case (DualSPHysics: "
                               f"\"Constitutive model for body {index} is not valid for {dim} simulations.\")",
                           "1 (plane strain) or 2 (plane stress) in a 2D case" if is2d else
                           "3 (St Venant-Kirchhoff) in a 3D case")


def _check_clamps_not_bodies(reader, bodies: list, els: list) -> None:
    """No mkclamp is a flexible structure's mkbound (JSphFlexStruc::ConfigClampCode); ``els``: the
    bodies' elements."""
    mkbounds = {d["mkbound"] for d in bodies}
    for d, c in zip(bodies, els):
        for mk in d["mkclamp"]:
            if mk in mkbounds:
                raise reader.error(c, f"mkclamp {mk} is a flexible structure (DualSPHysics: \"MkClamp for "
                                         f"mkbound={d['mkbound']} cannot be a flexible structure.\")",
                                   "the mkbound of a fixed or moving boundary that is no <flexstrucbody>'s mkbound")


# ---------------------------------------------------------------------------
# checks against the parameters and the drawn particles
# ---------------------------------------------------------------------------
def flexstruc_parameter_problem(params: dict, periodic: bool) -> str | None:
    """DualSPHysics's refusal (JSph::LoadCaseConfig) of flexible structures with these resolved
    execution parameters, or None: periodic conditions, the original mDBC (Boundary 2 with SlipMode
    1), mDBC with Verlet (Boundary 2 with StepAlgorithm 1). A restart is not refused: sphdvi resumes
    a run with flexible structures."""
    mdbc = int(params.get("Boundary", 1)) == 2
    if periodic:
        return "Flexible structures are not allowed with periodic conditions."
    if mdbc and int(params.get("SlipMode", 1)) == 1:
        return "Flexible structures are not allowed with original mDBC (SlipMode=1)."
    if mdbc and int(params.get("StepAlgorithm", 1)) == 1:
        return "Flexible structures with mDBC are not allowed with Verlet."
    return None


#: what to change for each of flexstruc_parameter_problem's refusals
PARAMETER_FIXES = {
    "Flexible structures are not allowed with periodic conditions.":
        "no periodic keys (*PeriodicInc*, XYPeriodic, XZPeriodic, YZPeriodic) in a case with flexible structures",
    "Flexible structures are not allowed with original mDBC (SlipMode=1).":
        "with Boundary 2 (mDBC) SlipMode 2 (no-slip) or 3 (free slip), or Boundary 1 (DBC)",
    "Flexible structures with mDBC are not allowed with Verlet.":
        "with Boundary 2 (mDBC) StepAlgorithm 2 (Symplectic), or Boundary 1 (DBC)",
}


def check_flexstrucs(case, particles: dict, is2d: bool, reader) -> None:
    """The gencase checks of ``case.special["flexstrucs"]``: the parameters
    (:func:`flexstruc_parameter_problem`), each mkbound a drawn moving boundary (its motion, other
    than mvnull/wait, warned as ignored), each mkclamp a drawn boundary (a floating one warned)."""
    bodies = case.special.get("flexstrucs") or []
    if not bodies:
        return
    _check_parameters(case, is2d, reader)
    roles = _bound_roles(particles)
    motions = {m["ref"]: m for m in case.motions}
    for d in bodies:
        _check_body_mk(d, roles, reader)
        _warn_ignored_motion(d, motions.get(d["mkbound"]), reader)
        for mk in d["mkclamp"]:
            _check_clamp_mk(d, mk, roles, reader)


def _bound_roles(particles: dict) -> dict:
    """{drawn mkbound: its particles' type (fixed, moving or floating)}."""
    ptype, label = particles["type"], particles["label"]
    bound = ptype != TYPE_FLUID
    pairs = np.unique(np.stack([label[bound].astype(np.int64), ptype[bound].astype(np.int64)], axis=1), axis=0)
    return {int(mk): int(t) for mk, t in pairs}


def _check_parameters(case, is2d: bool, reader) -> None:
    """The parameters that DualSPHysics refuses with flexible structures: a CaseError at <flexstrucs>."""
    from ..sph.periodic import periodic_config
    periodic = bool(periodic_config(case.parameters_set, case.parameters, is2d)[0])
    problem = flexstruc_parameter_problem(case.parameters, periodic)
    if problem is not None:
        raise CaseError(f"DualSPHysics: \"{problem}\"", file=reader.file,
                        line=reader.line_of("execution/special/flexstrucs"), element="flexstrucs",
                        expected=PARAMETER_FIXES[problem])


def _check_body_mk(d: dict, roles: dict, reader) -> None:
    """The body's mkbound is a drawn moving boundary ("MkBound value for mkbound=%u is not a valid Mk
    moving boundary.")."""
    mk = d["mkbound"]
    role = roles.get(mk)
    if role == TYPE_MOVING:
        return
    why = {None: "has no particles", TYPE_FIXED: "is a fixed boundary (it has no <motion>)",
           TYPE_FLOATING: "is a floating body"}[role]
    raise CaseError(f"flexible structure mkbound {mk} {why} (DualSPHysics: \"MkBound value for mkbound={mk} is not "
                    "a valid Mk moving boundary.\")", file=reader.file, line=d["line"], element="flexstrucbody",
                    expected=f'a drawn mkbound with a motion, as DualSPHysics\'s examples: <motion><objreal ref="{mk}">'
                             '<begin mov="1" start="0" /><mvnull id="1" /></objreal></motion>')


def _warn_ignored_motion(d: dict, motion, reader) -> None:
    """A motion of the body's mkbound other than mvnull/wait is ignored (the structure solver moves
    those particles, as DualSPHysics): warned."""
    if motion is None:
        return
    chains = list(motion.get("parents", [])) + [motion]
    kinds = sorted({m["type"] for ch in chains for m in ch.get("movements", [])} - STILL_MOTIONS)
    if kinds:
        reader.warnings.add(f"the motion of flexible structure mkbound {d['mkbound']} ({', '.join(kinds)}) is ignored: "
                            "the structure solver moves its particles (as DualSPHysics); give it <mvnull>",
                            file=reader.file, line=motion["line"], element="objreal")


def _check_clamp_mk(d: dict, mk: int, roles: dict, reader) -> None:
    """A clamp mk is a drawn boundary ("MkClamp value for mkbound=%u is not a valid Mk boundary.");
    a floating one is warned (DualSPHysics makes clamp particles of fixed and moving ones only)."""
    role = roles.get(mk)
    if role is None:
        raise CaseError(f"mkclamp {mk} of flexible structure mkbound {d['mkbound']} has no boundary particles "
                        f"(DualSPHysics: \"MkClamp value for mkbound={d['mkbound']} is not a valid Mk boundary.\")",
                        file=reader.file, line=d["line"], element="flexstrucbody",
                        expected="the mkbound of a drawn fixed or moving boundary")
    if role == TYPE_FLOATING:
        reader.warnings.add(f"mkclamp {mk} of flexible structure mkbound {d['mkbound']} is a floating body: it clamps "
                            "nothing (DualSPHysics makes clamp particles of fixed and moving boundaries only)",
                            file=reader.file, line=d["line"], element="flexstrucbody")
