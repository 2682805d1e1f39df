"""``<special><relaxationzones>``: DualSPHysics's relaxation zones (JRelaxZones; format
``doc/xml_format/_FmtXML_RelaxationZones.xml``; Altomare et al. 2018, Applied Ocean Research 81,
15-33), read into plain dicts that :mod:`sphdvi.sph.relaxzones` turns into zones.

* ``<rzwaves_regular>``: regular waves (``waveorder`` 1 or 2, ``waveheight``, ``waveperiod``,
  ``depth``, ``swl``, ``phase`` in π, ``ramp`` in periods) relaxed into the fluid within
  ``width``/2 of ``center`` along x.
* ``<rzwaves_spectrum>``: irregular waves of a JONSWAP or Pierson-Moskowitz sea (the options of a
  ``<piston_spectrum>``: ``spectrum``, ``discretization``, ``peakcoef``, ``waves``, ``randomseed``,
  ``serieini``, ``ramptime``), first order: DualSPHysics's relaxation kernels sum linear waves only,
  so ``waveorder`` 2 is warned about and generated to first order.
* ``<rzwaves_uniform>``: a uniform velocity (``<velocity value>`` or a ``<velocitytimes>`` table)
  along the ``<domainbox>``'s ``<direction>``, in that box (``<point>``, ``<size>``, optional
  ``<rotateaxis>``).
* Every zone: ``start`` (0), ``duration`` (0: to the end), ``coefdt`` (1000; 0: the weight is not
  multiplied by dt), ``<function psi beta>`` (0.9, 1); the wave zones ``coefdir`` (1, 0, 0) and
  ``driftcorrection`` (0; 1 subtracts the whole Stokes drift).
* The wave zones' ``<savemotion>`` (``periods``/``periodsteps`` or ``time``/``timedt``, ``xpos``,
  ``zpos``), and a spectrum's ``<saveserie>``/``<saveseriewaves>``, as a paddle's
  (:mod:`sphdvi.io.paddle_motion`).

Refused: ``<rzwaves_external_1d>`` (velocities from another model's files, whose layout the format
does not document).
"""
from .inout_xml import read_rotation, table_rows
from .wavepaddles_xml import _read_spectrum_options, _value_children, read_theory_outputs, wave_validity_warnings

COMMON = {"start": "num", "duration": "num", "coefdt": "num", "function": "raw"}
WAVES = {**COMMON, "waveorder": "int", "waveheight": "num", "waveperiod": "num", "depth": "num", "swl": "num",
         "center": "vec", "width": "num", "savemotion": "raw", "coefdir": "vec", "driftcorrection": "num"}
REGULAR = {**WAVES, "phase": "num", "ramp": "num"}
SPECTRUM = {**WAVES, "spectrum": "str", "discretization": "str", "peakcoef": "num", "waves": "int",
            "randomseed": "int", "serieini": "raw", "ramptime": "num", "saveserie": "raw", "saveseriewaves": "raw",
            "calcserielength": "raw"}
UNIFORM = {**COMMON, "domainbox": "raw", "velocity": "num", "velocitytimes": "raw"}
KINDS = {"rzwaves_regular": REGULAR, "rzwaves_spectrum": SPECTRUM, "rzwaves_uniform": UNIFORM}


def read_relaxationzones(reader, el) -> list:
    """``<special><relaxationzones>`` -> a list of zone dicts, in the file's order (module docstring)."""
    out = []
    for c in reader.children(el):
        if c.tag == "rzwaves_external_1d":
            raise reader.error(c, "<rzwaves_external_1d> is not supported by sphdvi (it reads velocities from "
                                  "another model's files, whose layout DualSPHysics's format does not document)",
                               "<rzwaves_regular>, <rzwaves_spectrum> or <rzwaves_uniform>")
        if c.tag not in KINDS:
            raise reader.error(c, f"unknown relaxation zone <{c.tag}>",
                               "<rzwaves_regular>, <rzwaves_spectrum> or <rzwaves_uniform>")
        required = ("domainbox",) if c.tag == "rzwaves_uniform" else (
            "waveheight", "waveperiod", "depth", "swl", "center", "width") + (
            ("spectrum",) if c.tag == "rzwaves_spectrum" else ())
        d = {"type": c.tag, "line": c.sourceline}
        d.update(_value_children(reader, c, KINDS[c.tag], required=required))
        _read_common(reader, c, d)
        if c.tag == "rzwaves_uniform":
            _read_uniform(reader, c, d)
        else:
            _read_waves(reader, c, d)
        out.append(d)
    return out


def _read_common(reader, c, d: dict) -> None:
    """start (0), duration (0), coefdt (1000), ``<function psi beta>`` (0.9, 1), checked."""
    for k, default in (("start", 0.0), ("duration", 0.0), ("coefdt", 1000.0)):
        d.setdefault(k, default)
        if d[k] < 0:
            raise reader.error(reader.child(c, k), f"<{k}> value={d[k]:g} is negative", f"{k} >= 0")
    fun = reader.child(c, "function")
    d.pop("function", None)
    d["psi"] = reader.num(fun, "psi", 0.9) if fun is not None else 0.9
    d["beta"] = reader.num(fun, "beta", 1.0) if fun is not None else 1.0
    if not (d["psi"] > 0 and d["beta"] > 0):
        raise reader.error(fun, f"<function psi={d['psi']:g} beta={d['beta']:g}>", "psi > 0 and beta > 0")
    from ..sph.relaxzones import weight_constants
    if not weight_constants(d["psi"], d["beta"])[1] > 1e-12:
        raise reader.error(fun, f"<function psi={d['psi']:g} beta={d['beta']:g}> gives a weight that does not "
                           "fall from the centre to the edges", "psi and beta like 0.9 and 1 (DualSPHysics's default)")


def _read_waves(reader, c, d: dict) -> None:
    """The wave zones' options, with DualSPHysics's defaults and checks; the wave theory is built
    once here, so that a wave that has none fails at gencase."""
    spectral = c.tag == "rzwaves_spectrum"
    d.setdefault("waveorder", 1)
    if d["waveorder"] not in (1, 2):
        raise reader.error(reader.child(c, "waveorder"), f"waveorder {d['waveorder']}", "1 or 2")
    for k in ("depth", "waveheight", "waveperiod", "width"):
        if not d[k] > 0:
            raise reader.error(reader.child(c, k), f"<{k}> must be positive", f"{k} > 0")
    if spectral and d["waveorder"] == 2:
        reader.warn(reader.child(c, "waveorder"), "a <rzwaves_spectrum> generates first-order waves (DualSPHysics's "
                    "relaxation zones sum linear waves only): waveorder 2 is ignored")
        d["waveorder"] = 1
    d["coefdir"] = d.get("coefdir", [1.0, 0.0, 0.0])
    if not all(0.0 <= v <= 1.0 for v in d["coefdir"]):
        raise reader.error(reader.child(c, "coefdir"), f"<coefdir> is {d['coefdir']}", "coefficients within [0, 1]")
    if d["coefdir"][1]:
        reader.warn(reader.child(c, "coefdir"), "<coefdir y> has no effect: the zone's waves run along x and move "
                    "the fluid in x and z only")
    d.setdefault("driftcorrection", 0.0)
    if not 0.0 <= d["driftcorrection"] <= 1.0:
        raise reader.error(reader.child(c, "driftcorrection"), f"<driftcorrection> value={d['driftcorrection']:g}",
                           "a coefficient within [0, 1] (0 off, 1 the whole Stokes drift)")
    if spectral:
        _read_spectrum_options(reader, c, d)
    else:
        d.setdefault("phase", 0.0)
        d.setdefault("ramp", 0.0)
    for k in ("ramp", "ramptime"):
        if d.get(k, 0.0) < 0:
            raise reader.error(reader.child(c, k), f"<{k}> value={d[k]:g} is negative", f"{k} >= 0")
    read_theory_outputs(reader, c, d, spectral)
    try:
        from ..sph.relaxzones import wave_theory
        wave_theory(d)
    except (ArithmeticError, ValueError) as exc:
        raise reader.error(c, f"cannot compute the zone's waves: {exc}", "a wave period and depth of a real wave") \
            from None
    for message in wave_validity_warnings(d["waveheight"], d["waveperiod"], d["depth"], d["waveorder"],
                                          "significant height Hs and peak period Tp" if spectral else ""):
        reader.warn(c, message)


def _read_uniform(reader, c, d: dict) -> None:
    """``<domainbox>`` (``<point>``, ``<size>`` > 0, ``<direction>`` not zero, optional
    ``<rotateaxis angle anglesunits>`` with ``<point1>``, ``<point2>``) and the velocity: a
    ``<velocitytimes>`` table of ``<timevalue time v>`` rows (linear between rows, held beyond them)
    where given, else ``<velocity value>`` (required then)."""
    box = reader.child(c, "domainbox")
    reader.check_children(box, {"point", "size", "direction", "rotateaxis"})
    shape = {"point": reader.vec3(reader.child(box, "point", True)).tolist(),
             "size": reader.vec3(reader.child(box, "size", True)).tolist(),
             "direction": reader.vec3(reader.child(box, "direction", True)).tolist()}
    if not all(s > 0 for s in shape["size"]):
        raise reader.error(reader.child(box, "size"), f"<size> is {shape['size']}", "three sizes > 0 (in 2D too: the "
                           "box must hold the particles' y)")
    if not any(shape["direction"]):
        raise reader.error(reader.child(box, "direction"), "<direction> is the zero vector",
                           "the direction of the imposed velocity")
    rot = reader.child(box, "rotateaxis")
    if rot is not None:
        shape["rotation"] = read_rotation(reader, rot, 3, shape)
    d["domainbox"] = shape
    lis = reader.child(c, "velocitytimes")
    if lis is not None:
        rows = table_rows(reader, lis, ("v",))
        d["velocitytimes"] = rows
        if "velocity" in d:
            reader.warn(reader.child(c, "velocity"), "<velocity> is ignored: <velocitytimes> gives the velocity")
            del d["velocity"]
    elif "velocity" not in d:
        raise reader.error(c, "missing <velocity> or <velocitytimes>", "<velocity value=\"0.3\"/> or a "
                           "<velocitytimes> table of <timevalue time v/> rows")
