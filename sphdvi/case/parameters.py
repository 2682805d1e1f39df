"""The ``<execution><parameters>`` keys of DualSPHysics v5.4, with their defaults.

Source of the keys and defaults: DualSPHysics ``doc/xml_format/_FmtXML__Parameters.xml``
and ``../shared/design/case-format.md`` §2.8. A key written with a leading ``#``
is disabled, as in DualSPHysics. Unknown keys are an error (DualSPHysics ignores
them silently, which hides typos such as ``Visc``).
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Param:
    kind: str          # "int", "float", "str"
    default: object
    doc: str
    choices: tuple = ()
    lo: float | None = None
    hi: float | None = None
    positive: bool = False     # the value must be > 0 as well (``lo`` is inclusive)


PARAMETERS: dict[str, Param] = {
    # DualSPHysics reads SavePosDouble as "!= 0" (JSph::LoadConfigParameters): any integer is valid
    "SavePosDouble": Param("int", 0, "save positions in double precision (sphdvi always does)"),
    "SaveExtraParts": Param("str", "", "DualSPHysics: outputs with the extra restart data"),
    "Boundary": Param("int", 1, "boundary method 1:DBC, 2:mDBC", (1, 2)),
    "BoundaryMethod": Param("int", None, "not a DualSPHysics key (it reads 'Boundary'), found in case files "
                            "written by other tools; ignored, as DualSPHysics ignores it"),
    "SlipMode": Param("int", 1, "mDBC slip mode 1:DBC vel=0, 2:no-slip, 3:free slip", (1, 2, 3)),
    "MDBCCorrector": Param("int", None, "mDBC correction also in the Symplectic corrector (DualSPHysics "
                           "v5.0-5.2 key; not set: as v5.4, 0 with SlipMode 1, 1 with SlipMode 2, 3)", (0, 1)),
    "MDBCFastSingle": Param("int", 1, "mDBC matrix solve in single precision (DualSPHysics GPU only; "
                            "the CPU solves in double precision)", (0, 1)),
    "MdbcFastSingle": Param("int", 1, "sphdvi's earlier spelling of MDBCFastSingle", (0, 1)),
    "MdbcThreshold": Param("float", 0.0, "mDBC kernel-sum threshold (SlipMode 1 only)", (), 0.0, 1.0),
    "MdbcGhostVelocity": Param("int", 1, "sphdvi: mDBC SlipMode 2, 3 ghost-node velocity 1:first-order "
                               "corrected, 0:Shepard average (DualSPHysics v5.4)", (0, 1)),
    "MdbcMkbound": Param("str", "", "sphdvi: the mkbound list ('0-3,7') of the boundaries and floating bodies "
                         "mDBC acts on, the others keeping DBC (empty: every one with a normal, from the "
                         "case's <normals> and <initialize>, or from the particles when it defines none)"),
    "NoPenetration": Param("int", 0, "mDBC no-penetration correction (SlipMode 2, 3 only)", (0, 1)),
    "StepAlgorithm": Param("int", 1, "1:Verlet, 2:Symplectic", (1, 2)),
    "VerletSteps": Param("int", 40, "Verlet: steps between Euler steps (0: Euler every step)", (), 0, 1e9),
    "Kernel": Param("int", 2, "1:cubic spline, 2:Wendland", (1, 2)),
    "ViscoTreatment": Param("int", 1, "1:artificial, 2:laminar+SPS, 3:laminar", (1, 2, 3)),
    "Visco": Param("float", 0.01, "viscosity value (alpha or kinematic viscosity)", (), 0.0, 1e6),
    "ViscoLaminarEta": Param("float", 0.1, "sphdvi: regulariser eta/h of the laminar term r^2/(r^2+eta^2) "
                             "(DualSPHysics 0.1; 0: the exact Morris operator)", (), 0.0, 1.0),
    "ViscoTime": Param("str", "", "file of (time [s], Visco) rows: Visco as a function of time, set at the "
                       "start of each step (linear in between, the end values outside)"),
    "ViscoBoundFactor": Param("float", 1.0, "multiplier of Visco for fluid-boundary pairs", (), 0.0, 1e6),
    "DensityDT": Param("int", 0, "density diffusion 0:none, 1:Molteni, 2:Fourtakas, 3:Fourtakas full", (0, 1, 2, 3)),
    "DensityDTvalue": Param("float", 0.1, "density diffusion coefficient delta", (), 0.0, 1.0),
    "Shifting": Param("int", 0, "0:none, 1:ignore bound, 2:ignore fixed, 3:full, 4:full advanced", (0, 1, 2, 3, 4)),
    "ShiftCoef": Param("float", -2.0, "shifting coefficient", (), -1e6, 0.0),
    "ShiftTFS": Param("float", 0.0, "free-surface threshold of div r (0: no free-surface detection; "
                      "typically 1.5 in 2D, 2.75 in 3D)", (), 0.0, 1e6),
    "ShiftAdvCoef": Param("float", -0.01, "advanced shifting coefficient", (), -1e6, 0.0),
    "ShiftAdvALE": Param("int", 0, "advanced shifting ALE correction", (0, 1)),
    "ShiftAdvNCPress": Param("int", 0, "advanced shifting non-conservative pressure", (0, 1)),
    "RigidAlgorithm": Param("int", 1, "0:collision-free, 1:SPH, 2:DEM, 3:Chrono", (0, 1, 2, 3)),
    "FtPause": Param("float", 0.0, "time to freeze floatings at the start [s]", (), 0.0, 1e9),
    "FtIgnoreRadius": Param("int", 0, "periodic run with a floating body whose radius (1.2 x its particles' "
                            "largest distance from its centre) reaches a periodic length: 0 stops, 1 warns", (0, 1)),
    "FtSaveAce": Param("int", 0, "save floating accelerations (debug)", (0, 1)),
    "CoefDtMin": Param("float", 0.05, "DtMin = CoefDtMin*h/c0", (), 0.0, 1.0),
    "DtIni": Param("float", 0.0, "initial dt [s] (0: h/c0)", (), 0.0, 1e3),
    "DtMin": Param("float", 0.0, "minimum dt [s] (0: CoefDtMin*h/c0)", (), 0.0, 1e3),
    "DtFixed": Param("float", 0.0, "fixed dt [s] (0: variable)", (), 0.0, 1e3),
    "DtFixedFile": Param("str", "NONE", "file of dt values [ms] (NONE: disabled)"),
    "DtAllParticles": Param("int", 0, "dt from all particles (1) or fluid/floating only (0)", (0, 1)),
    "TimeMax": Param("float", 1.0, "simulated time [s]", (), 0.0, 1e12),
    "TimeOut": Param("float", 0.01, "output interval [s]", (), 0.0, 1e12, positive=True),
    "TimeOutExtra": Param("float", None, "interval of the extra floating-body outputs (bodies.csv, "
                          "links.csv) between the outputs [s] (0: every step; negative, DualSPHysics's "
                          "default -1, or not set: none)", (), -1e12, 1e12),
    "RhopOutMin": Param("float", 700.0, "minimum valid density [kg/m3]", (), 0.0, 1e9),
    "RhopOutMax": Param("float", 1300.0, "maximum valid density [kg/m3]", (), 0.0, 1e9),
    "PartsOutMax": Param("float", 1.0, "deprecated: fraction of fluid allowed out", (), 0.0, 1.0),
    # DualSPHysics reads WrnPartsOut as "!= 0"
    "WrnPartsOut": Param("int", 1, "warn about excluded particles (0: no; any other value: yes)"),
    "MinFluidStop": Param("float", 0.0, "stop when the fluid fraction falls below this", (), 0.0, 1.0),
    "XPeriodicIncY": Param("float", 0.0, "periodic X: increment of Y"),
    "XPeriodicIncZ": Param("float", 0.0, "periodic X: increment of Z"),
    "YPeriodicIncX": Param("float", 0.0, "periodic Y: increment of X"),
    "YPeriodicIncZ": Param("float", 0.0, "periodic Y: increment of Z"),
    "ZPeriodicIncX": Param("float", 0.0, "periodic Z: increment of X"),
    "ZPeriodicIncY": Param("float", 0.0, "periodic Z: increment of Y"),
    "XYPeriodic": Param("int", 0, "periodic in X and Y", (0, 1)),
    "XZPeriodic": Param("int", 0, "periodic in X and Z", (0, 1)),
    "YZPeriodic": Param("int", 0, "periodic in Y and Z", (0, 1)),
    "IncZ": Param("float", 0.0, "deprecated: increase of the domain in +Z (fraction)", (), 0.0, 1e3),
    "DomainFixed": Param("str", "", "deprecated: fixed domain xmin:ymin:zmin:xmax:ymax:zmax"),
    "DomainFixedXmin": Param("float", None, "deprecated fixed domain limit"),
    "DomainFixedXmax": Param("float", None, "deprecated fixed domain limit"),
    "DomainFixedYmin": Param("float", None, "deprecated fixed domain limit"),
    "DomainFixedYmax": Param("float", None, "deprecated fixed domain limit"),
    "DomainFixedZmin": Param("float", None, "deprecated fixed domain limit"),
    "DomainFixedZmax": Param("float", None, "deprecated fixed domain limit"),
    "DeltaSPH": Param("float", 0.0, "deprecated: use DensityDT=1 and DensityDTvalue", (), 0.0, 1.0),
    "PosDouble": Param("int", 0, "deprecated precision option", (0, 1, 2)),
    "DivCleaning": Param("int", 0, "divergence cleaning (optional build of DualSPHysics v5.4): not supported, 0 only",
                         (0, 1)),
    "DivCleanKp": Param("float", 0.0, "coefficient of divergence cleaning (no effect: not supported)"),
}

DEPRECATED = {"PartsOutMax", "IncZ", "DomainFixed", "DeltaSPH", "PosDouble"} | {
    k for k in PARAMETERS if k.startswith("DomainFixed")}


# accepted for DualSPHysics's files, without effect here: warned when set to another value
NO_EFFECT = {
    "FtSaveAce": "DualSPHysics's debug output of floating accelerations",
    "SaveExtraParts": "sphdvi's restart.h5 always holds the whole state, written at every output",
    "DivCleanKp": "the coefficient of divergence cleaning, which sphdvi does not implement",
    "SavePosDouble": "sphdvi always keeps and writes positions in double precision",
    "BoundaryMethod": "it is not a DualSPHysics key: DualSPHysics reads 'Boundary' (1 DBC, 2 mDBC) and ignores "
                      "this one, and so does sphdvi; set 'Boundary' to choose the boundary method",
}

# values of a key that DualSPHysics accepts and sphdvi does not implement: an error that says
# what to use instead (checked before ``choices``, which leave these values out)
REJECTED_VALUES: dict = {}

# <constantsdef> entries that are sometimes given as parameters (DualSPHysics's -cfl option
# changes the constant): their place in the case file
CONSTANTS = frozenset({"cflnumber", "gamma", "rhop0", "coefsound", "speedsystem", "speedsound", "coefh", "hdp",
                       "coefhdp", "hswl", "gravity", "lattice", "eps", "h", "b", "massbound", "massfluid"})


#: keys of DualSPHysics's separate multiphase non-Newtonian build (DualSPHysics-NNewtonian,
#: examples/mphase_nnewtonian, doc/xml_format/_FmtXML_MphaseNNewtonian.xml), not of DualSPHysics v5.4
NNEWTONIAN_KEYS = {"RheologyTreatment", "VelocityGradientType", "RelaxationDt"}
NNEWTONIAN_TEXT = ("DualSPHysics's separate multiphase non-Newtonian build (DualSPHysics-NNewtonian, "
                   "examples/mphase_nnewtonian), whose rheology sphdvi does not model")


def other_build_hint(key: str) -> str | None:
    """For a key of another DualSPHysics build than v5.4 (the non-Newtonian one): what it is."""
    if key.strip() in NNEWTONIAN_KEYS:
        return f"parameter '{key.strip()}' belongs to {NNEWTONIAN_TEXT}"
    return None


def constant_hint(key: str) -> str | None:
    """For a key that is a <constantsdef> constant (e.g. CFLnumber): where it belongs."""
    name = key.strip().lower()
    if name not in CONSTANTS:
        return None
    return (f"'{key}' is a constant of the case, not an execution parameter: set <{name} value=\"...\" /> "
            "in <constantsdef> and run gencase again")


def parameter_warnings(key: str, value) -> list[str]:
    """The warnings a key given with ``value`` deserves (deprecated in DualSPHysics, no effect
    in sphdvi); the same texts as the case reader's."""
    out = []
    if key in DEPRECATED:
        out.append(f"parameter '{key}' is deprecated in DualSPHysics")
    if key in NO_EFFECT and value != PARAMETERS[key].default:
        out.append(f"parameter '{key}' has no effect in sphdvi ({NO_EFFECT[key]})")
    return out


def check_consistency(params: dict) -> None:
    """The checks that involve several parameters (raises ValueError); the case reader and
    ``sphdvi run --set`` apply the same ones."""
    lo, hi = params.get("RhopOutMin", 700.0), params.get("RhopOutMax", 1300.0)
    if lo is not None and hi is not None and lo >= hi:
        raise ValueError(f"RhopOutMin ({lo}) >= RhopOutMax ({hi}); expected RhopOutMin < RhopOutMax")

# DualSPHysics options sphdvi does not implement: any value but the default is an error
NOT_SUPPORTED = {
    "DivCleaning": "divergence cleaning (an optional build feature of DualSPHysics v5.4) is not implemented in sphdvi",
}


def check_supported(key: str, value) -> None:
    """Raise ValueError when ``value`` switches on an option sphdvi does not implement."""
    if key in NOT_SUPPORTED and value != PARAMETERS[key].default:
        raise ValueError(f"{key}={value} is not supported: {NOT_SUPPORTED[key]}")

# the deprecated domain keys: they shape the domain that gencase writes
DOMAIN_KEYS = ("IncZ", "DomainFixed", "DomainFixedXmin", "DomainFixedYmin", "DomainFixedZmin",
               "DomainFixedXmax", "DomainFixedYmax", "DomainFixedZmax")


def apply_delta_sph(params: dict, set_keys) -> None:
    """The deprecated ``DeltaSPH`` as DualSPHysics reads it: a value > 0 selects Molteni's
    density diffusion (DensityDT 1) with that coefficient; given with DensityDT it is an
    error (raises ValueError)."""
    if "DeltaSPH" not in set_keys:
        return
    if "DensityDT" in set_keys:
        raise ValueError("the parameters 'DeltaSPH' and 'DensityDT' cannot be combined; use only DensityDT")
    value = float(params.get("DeltaSPH") or 0.0)
    if value > 0:
        params["DensityDT"] = 1
        params["DensityDTvalue"] = value


def domain_from_deprecated(params: dict, set_keys, domain: dict) -> dict:
    """The deprecated domain keys as DualSPHysics v5.4 applies them (JSph::LoadConfigParameters):
    ``IncZ`` v raises the domain's top by v times its height (``default + 100 v %``);
    ``DomainFixed`` "xmin:ymin:zmin:xmax:ymax:zmax" fixes all six limits (and replaces IncZ);
    ``DomainFixedXmin`` ... fix one each.  Combined with a ``<simulationdomain>`` that is not
    all default they are an error (raises ValueError).  Returns the domain specification."""
    used = [k for k in DOMAIN_KEYS if k in set_keys and params.get(k) is not None
            and not (k == "IncZ" and not params[k])]
    if not used:
        return domain
    if any(spec != "default" for which in ("posmin", "posmax") for spec in domain[which]):
        raise ValueError(f"{used[0]} cannot be combined with a <simulationdomain> in <parameters>; "
                         "use only <simulationdomain>")
    out = {"posmin": ["default"] * 3, "posmax": ["default"] * 3}
    if "IncZ" in used:
        out["posmax"][2] = f"default + {100.0 * float(params['IncZ']):.12g}%"
    if "DomainFixed" in used:
        parts = str(params["DomainFixed"]).replace(",", ":").split(":")
        try:
            values = [float(v) for v in parts]
        except ValueError:
            values = []
        if len(values) != 6:
            raise ValueError(f"DomainFixed={params['DomainFixed']!r}: expected six numbers "
                             "xmin:ymin:zmin:xmax:ymax:zmax")
        out = {"posmin": [f"{v:.17g}" for v in values[:3]], "posmax": [f"{v:.17g}" for v in values[3:]]}
    for key in used:
        if key.startswith("DomainFixed") and key != "DomainFixed":
            axis = "xyz".index(key[11].lower())
            out["posmin" if key.endswith("min") else "posmax"][axis] = f"{float(params[key]):.17g}"
    return out


def default_parameters() -> dict:
    """All keys with their DualSPHysics defaults (``None`` where the default is 'not set')."""
    return {k: p.default for k, p in PARAMETERS.items()}


def coerce(key: str, value):
    """Convert a value (number or text) to the key's type and check its range.

    Returns the converted value or raises ValueError with the expected form.
    """
    spec = PARAMETERS[key]
    if spec.kind == "str":
        return str(value)
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"'{value}' is not a number") from None
    if number != number or number in (float("inf"), float("-inf")):
        raise ValueError(f"'{value}' is not finite")
    if spec.kind == "int":
        if number != int(number):
            raise ValueError(f"'{value}' is not an integer")
        number = int(number)
    if (key, number) in REJECTED_VALUES:
        raise ValueError(REJECTED_VALUES[(key, number)])
    if spec.choices and number not in spec.choices:
        raise ValueError(f"{number} is not one of {', '.join(str(c) for c in spec.choices)}")
    if spec.lo is not None and number < spec.lo:
        raise ValueError(f"{number} is below {spec.lo}")
    if spec.positive and not number > 0:
        raise ValueError(f"{number} is not > 0 ({key} must be positive)")
    if spec.hi is not None and number > spec.hi:
        raise ValueError(f"{number} is above {spec.hi}")
    return number


def closest_key(key: str) -> str | None:
    """The known key most like ``key`` (for 'did you mean' hints)."""
    import difflib
    # 0.75: typos (VerletStep, Shiftcoef) hint; unrelated keys (PeriodicDomain, ShepardSteps) do not
    match = difflib.get_close_matches(key, PARAMETERS.keys(), n=1, cutoff=0.75)
    if match:
        return match[0]
    lower = {k.lower(): k for k in PARAMETERS}
    return lower.get(key.lower())
