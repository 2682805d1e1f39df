"""The options of ``sphdvi run`` (and of a sweep's runs) that change a case's parameters:
``--set KEY=VALUE``, ``--tmax``, ``--tout``, checked as the case reader checks the XML, and the
values a run reports in run.json (``resolved_parameters``)."""
from __future__ import annotations

import contextlib
import math
import os
import warnings

from .errors import InputError


def absolute_file_sets(sets) -> tuple:
    """``--set ViscoTime=FILE`` / ``--set DtFixedFile=FILE``: FILE, like every path on the command
    line, is relative to the current directory; it is made absolute here, so that run.json keeps
    a path that ``--resume`` finds from any directory (in the XML the value is relative to the
    case's folder, as DualSPHysics's DirCase).  Without ``--set`` nothing to do: the XML case
    reader (lxml, the schema; ~40 ms) is imported only when there are keys to look at."""
    if not sets:
        return ()
    from .case.reader import DATA_FILE_KEYS
    out = []
    for item in sets or ():
        key, sep, value = str(item).partition("=")
        value = value.strip()
        if sep and key.strip() in DATA_FILE_KEYS and value and value.upper() != "NONE":
            item = f"{key.strip()}={os.path.abspath(os.path.expanduser(value))}"
        out.append(item)
    return tuple(out)


# <constantsdef> constants that only the time stepping reads (the particles gencase draws do not
# depend on them): ``--set`` takes them; key (any letter case) -> the name in the parameters
RUN_CONSTANTS = {"cflnumber": "CFLnumber"}


def _run_constant(key: str, value: str) -> float:
    """``--set CFLnumber=V``: the case reader's check of <cflnumber> (a finite number, > 0, <= 10)."""
    try:
        number = float(value)
    except ValueError:
        raise InputError(f"--set {key}: '{value}' is not a number; expected a number > 0 (DualSPHysics's cases "
                         "use 0.2)") from None
    if not (math.isfinite(number) and 0 < number <= 10):
        raise InputError(f"--set {key}: {value}: expected a finite number > 0 and <= 10 (DualSPHysics's cases use 0.2)")
    return number


def conflicting_options(sets, tmax, tout) -> None:
    """--tmax with --set TimeMax (or --tout with --set TimeOut) of another value: InputError naming both
    (the option won silently before, and run.json's ``set`` still listed the other value)."""
    for option, key, value in (("--tmax", "TimeMax", tmax), ("--tout", "TimeOut", tout)):
        if value is None:
            continue
        for item in sets or ():
            name, _, given = (x.strip() for x in str(item).partition("="))
            with contextlib.suppress(ValueError):
                if name == key and float(given) != float(value):
                    raise InputError(f"{option} {float(value):g} and --set {key}={given} give {key} two values; "
                                     f"expected one of them")


def nested_key_hint(key: str) -> str | None:
    """A ``--set`` key with a dot or naming a <special> section (``special.shifting.mode``,
    ``gauges``): the message that such settings are edited in the case file; None otherwise.
    DualSPHysics's command line has no such keys either: its <special> sections are read from the XML."""
    from .case.reader import SPECIAL_KNOWN
    parts = [p for p in key.strip().lower().split(".") if p]
    sections = [p for p in parts if p in SPECIAL_KNOWN]
    if "." not in key and not sections and parts != ["special"]:
        return None
    where = f"<special><{sections[0]}>" if sections else ("<special>" if "special" in parts else "a nested element")
    hint = ""
    if "." not in key:
        from .case.parameters import closest_key
        close = closest_key(key)
        hint = f"; did you mean the parameter '{close}'?" if close else ""
    return (f"--set {key}: {where} is a section of the case file, not a --set key (--set takes the "
            f"<parameters> keys and CFLnumber): edit it in the case file and run gencase again (or sphdvi run "
            f"CASE.xml, which runs gencase){hint}")


def apply_overrides(params: dict, sets: list[str] | tuple = (), tmax=None, tout=None) -> dict:
    """``--set KEY=VALUE`` (a <parameters> key, or CFLnumber: :data:`RUN_CONSTANTS`), ``--tmax``,
    ``--tout``; raises InputError.

    The checks and warnings are the case reader's: each value as in the XML, then the
    checks across parameters (RhopOutMin < RhopOutMax) on the result; deprecated keys and
    keys without effect in sphdvi are warned about (``warnings.warn``)."""
    from .case.parameters import (DOMAIN_KEYS, PARAMETERS, apply_delta_sph, check_consistency, check_supported,
                                  closest_key, coerce, constant_hint, parameter_warnings)
    out = dict(params)
    given = []
    for item in sets or ():
        if "=" not in item:
            raise InputError(f"--set {item!r}: expected KEY=VALUE")
        key, value = (s.strip() for s in item.split("=", 1))
        if key.lower() in RUN_CONSTANTS:
            out[RUN_CONSTANTS[key.lower()]] = _run_constant(key, value)
            given.append(RUN_CONSTANTS[key.lower()])
            continue
        if key not in PARAMETERS:
            nested = nested_key_hint(key)
            if nested:
                raise InputError(nested)
            const = constant_hint(key)
            if const:
                raise InputError(f"--set {key}: {const} (gencase draws the particles with it: their masses, initial "
                                 "densities, h, B, c0; --set takes the <parameters> keys and CFLnumber)")
            hint = closest_key(key)
            raise InputError(f"--set: unknown parameter '{key}'" + (f"; did you mean '{hint}'?" if hint else ""))
        if key in DOMAIN_KEYS:
            raise InputError(f"--set {key}: it shapes the domain gencase writes; put it in the case file "
                             "(or better a <simulationdomain>) and run gencase again")
        try:
            out[key] = coerce(key, value)
            check_supported(key, out[key])
        except ValueError as exc:
            raise InputError(f"--set {key}: {exc}") from None
        for text in parameter_warnings(key, out[key]):
            warnings.warn(f"--set {key}: {text}")
        given.append(key)
    try:
        apply_delta_sph(out, given)
    except ValueError as exc:
        raise InputError(f"--set: {exc}") from None
    if str(out.get("MdbcMkbound") or "").strip() and str(out.get("Boundary", 1)).strip() != "2":
        warnings.warn(f"MdbcMkbound '{str(out['MdbcMkbound']).strip()}' does nothing: it picks the boundaries mDBC "
                      f"acts on, and Boundary is {out.get('Boundary', 1)} (DBC), not 2 (mDBC); add --set Boundary=2")
    for option, key, value in (("--tmax", "TimeMax", tmax), ("--tout", "TimeOut", tout)):
        if value is not None:
            try:
                out[key] = coerce(key, value)
            except ValueError as exc:
                raise InputError(f"{option} {value}: {exc}") from None
    if not out["TimeOut"] > 0:
        raise InputError(f"TimeOut is {out['TimeOut']}: it must be positive; give --tout or correct the case "
                         "file and run gencase again")
    try:
        check_consistency(out)
    except ValueError as exc:
        raise InputError(("--set: " if given else "case parameters: ") + str(exc)) from None
    return out


def resolved_parameters(params: dict, constants: dict, sph: bool, structure_cs: float = 0.0,
                        no_fluid: bool = False) -> dict:
    """run.json's ``parameters`` (the values the run uses), ``parameters_auto`` and ``constants``:
    DtIni and DtMin given as 0 resolved as DualSPHysics's JSph (DtIni = h/c0, DtMin =
    CoefDtMin h/c0; its Run.out prints those) and named in ``parameters_auto``; the earlier spelling
    MdbcFastSingle left out beside MDBCFastSingle; the case's constants (dp, h, B, c0, gamma, rhop0,
    masses, 2D, ...) with the CFLnumber the run uses (``--set CFLnumber``). With flexible structures whose
    sound speed ``structure_cs`` exceeds c0, or with no fluid (``no_fluid``), DtIni and DtMin come from that
    speed instead (JSph's LoadCaseConfig; sphdvi.sph.solver)."""
    out = {k: v for k, v in params.items() if k != "MdbcFastSingle"}
    auto = {}
    consts = dict(constants)
    if "CFLnumber" in params:
        consts["cflnumber"] = params["CFLnumber"]
    h, c0 = float(consts.get("h") or 0.0), float(consts.get("cs0") or 0.0)
    speed, name = c0, "c0"
    if structure_cs > 0 and (structure_cs > c0 or no_fluid):
        speed, name = structure_cs, "cs_structure"
    if sph and h > 0 and speed > 0:
        for key, formula, value in (("DtIni", f"h/{name}", h / speed),
                                    ("DtMin", f"CoefDtMin*h/{name}", float(params.get("CoefDtMin") or 0.0) * h / speed)):
            if not float(params.get(key) or 0.0):
                out[key], auto[key] = value, formula
    return {"parameters": out, "parameters_auto": auto, "constants": consts}
