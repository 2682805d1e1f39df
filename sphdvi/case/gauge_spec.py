"""Reading and checking ``<special><gauges>`` (DualSPHysics ``JGaugeSystem::ReadXml``).

Every field of every gauge is typed and range-checked here, at gencase, so the
run (:mod:`sphdvi.measure.gauges`) never meets an invalid gauge: a bad value is
a :class:`~sphdvi.errors.CaseError` (``file:line: <element>: ...; expected ...``,
exit code 2), not a failure minutes into a run.

The item dicts keep the layout :mod:`sphdvi.measure.gauges` consumes: points
and vectors as ``[x, y, z]``, ``computedt``/``outputdt``/``height``/``size*``
as floats, the multi-form elements as ``{attribute: number}`` (``pointdp``
``{"value"|"coefdp": v}``, ``masslimit`` ``{"value"|"coef": v}``, ``distlimit``
``{"value"|"coefdp"|"coefh": v}``), ``computetime``/``outputtime`` as
``{"start": t0, "end": t1}`` (a gauge's window inherits the attributes it
does not give from ``<default>``, as in DualSPHysics), ``target``
``{"mkbound": n}``, mesh ``outputdata``/``outputfmt`` ``{"value": "a,b"}``
(lower case, checked), ``kclimit`` and ``kcdummy`` ``{"value": v | "none"}``, mesh
``size<k>`` a float (``value``) or ``{"length", "distpt"}``.

What DualSPHysics means, and what is therefore checked:

* ``computedt``, ``outputdt`` >= 0 (0: every step); ``computetime`` /
  ``outputtime`` ``start <= end``;
* ``velocity`` needs ``<point>``; ``swl`` ``<point0>`` and ``<point2>`` (two
  distinct points); ``maxz`` ``<point0>``; ``force`` ``<target mkbound>``;
  ``mesh`` ``<point>``;
* ``pointdp``, ``masslimit``, ``distlimit``: exactly one of their attributes,
  > 0 (``JGaugeSystem`` rejects a non-positive pointdp, masslimit or distlimit);
  ``height`` > 0;
* mesh: ``<size<k> length=".." distpt=".."/>`` as DualSPHysics (the extent along
  ``vec<k>`` and the distance between its nodes, :func:`mesh_axis`), or sphdvi's
  older ``<size<k> value=".."/>`` (nodes dp apart); a zero ``vec<k>`` means "no
  extent along k" (DualSPHysics then reads no ``size<k>``), so it is accepted
  with a zero or absent ``size<k>`` and rejected with a positive one; length
  >= 0 (0: one node along that axis, the single-point pressure probes of the
  Lobovsky case), distpt > 0; ``outputdata`` among vel, veldir, rhop, zsurf
  (zsurf needs a column: ``size3`` > 0 along a non-zero ``vec3``; veldir a
  non-zero ``dirdat``); ``outputfmt`` among csv, bin; ``kclimit`` a number >= 0
  or ``none``, ``kcdummy`` a number or ``none``;
* the number of sample points of a gauge (swl line samples, mesh nodes, mesh
  zsurf samples) is at most :data:`MAX_GAUGE_POINTS`;
* names become file names (``Gauges<Type>_<name>.csv``): not empty, at most
  :data:`MAX_NAME_BYTES` bytes, no path separators, ``..``, control characters
  or the characters Windows forbids in file names; unique.
"""
from __future__ import annotations

import math

import numpy as np

MAX_GAUGE_POINTS = 1_000_000
MAX_NAME_BYTES = 100
NAME_FORBIDDEN = set('/\\:*?"<>|')
MESH_OUTPUTS = ("vel", "veldir", "rhop", "zsurf")
MESH_FORMATS = ("csv", "bin")
ZSURF_STEP = 0.25          # zsurf samples every ZSURF_STEP * dp along vec3 (measure.gauges.MeshGauge)
SWL_DEFAULT_COEFDP = 0.5   # pointdp when <pointdp> is absent: 0.5 dp

REQUIRED_CHILDREN = {"velocity": ("point",), "swl": ("point0", "point2"), "maxz": ("point0",),
                     "force": ("target",), "mesh": ("point",)}


def line_samples(length: float, step: float) -> float:
    """Samples of a line of ``length`` every ``step`` (``measure.core.surface_along_lines`` uses it).

    A float, so an absurd count is compared before it is turned into an int."""
    q = length / step
    return max(2.0, math.floor(q + 1e-9) + 1.0) if math.isfinite(q) else math.inf


def mesh_count(size: float, dp: float) -> float:
    """Nodes along one mesh axis of length ``size`` spaced ``dp`` (``measure.gauges.MeshGauge`` uses it)."""
    q = size / dp
    return math.floor(q + 1e-9) + 1.0 if math.isfinite(q) else math.inf


def mesh_axis(size, dp: float) -> tuple[float, float]:
    """(nodes, spacing) along one mesh axis from its ``<sizeK>``.

    DualSPHysics's form ``{"length": L, "distpt": d}``: ``floor((L + 0.01 d)/d) + 1`` nodes
    ``d`` apart when ``L >= d``, else one node (``JMeshData::MakeMeshPt``); sphdvi's older
    ``value`` form (a plain length): nodes ``dp`` apart."""
    if isinstance(size, dict):
        length, dist = float(size["length"]), float(size["distpt"])
        if not length >= dist:
            return 1.0, dist
        q = (length + 0.01 * dist) / dist
        return (math.floor(q) + 1.0 if math.isfinite(q) else math.inf), dist
    return mesh_count(float(size or 0.0), dp), dp


def zsurf_step(size3, dp: float) -> float:
    """The sampling step of a mesh gauge's zsurf column: its nodes (``distpt``) in DualSPHysics's
    form (``JGaugeMesh`` finds zsurf from the nodes' mass sums), ZSURF_STEP dp in the ``value`` form."""
    return float(size3["distpt"]) if isinstance(size3, dict) else ZSURF_STEP * dp


def mesh_length(size) -> float:
    """The length of a ``<sizeK>`` in either form."""
    return float(size["length"]) if isinstance(size, dict) else float(size or 0.0)


# ---------------------------------------------------------------------------------
# one field
# ---------------------------------------------------------------------------------
def _one_of(reader, c, attrs):
    """``{attr: v}`` for exactly one of ``attrs`` given on ``c``, v > 0."""
    given = [a for a in attrs if c.get(a) is not None]
    reader.mark(c, *attrs)
    choices = " or ".join(f'{a}=".."' for a in attrs)
    if len(given) != 1:
        what = "none of" if not given else "more than one of"
        raise reader.error(c, f"gives {what} " + ", ".join(attrs), f"exactly one of {choices}, > 0")
    a = given[0]
    return {a: reader.num(c, a, positive=True)}


def _window(reader, c, inherited):
    """``computetime``/``outputtime``: ``{"start", "end"}``, missing ones from ``<default>``."""
    if c.get("start") is None and c.get("end") is None:
        reader.mark(c, "start", "end")
        raise reader.error(c, "neither start nor end is given", 'start=".." and/or end=".." [s]')
    out = dict(inherited or {})
    for a in ("start", "end"):
        if c.get(a) is not None:
            out[a] = reader.num(c, a)
        else:
            reader.mark(c, a)
    if out.get("start", 0.0) > out.get("end", math.inf):
        raise reader.error(c, f"start={out.get('start', 0.0):g} is after end={out['end']:g}"
                           + ("" if c.get("start") is not None and c.get("end") is not None
                              else " (the other one from <default>)"), "start <= end")
    return out


def _outputdata(reader, c):
    raw = reader.text_attr(c, "value")
    items = [s.strip().lower() for s in raw.split(",") if s.strip()]
    bad = [s for s in items if s not in MESH_OUTPUTS]
    if bad or not items:
        what = "no output data" if not items else "unknown output data " + ", ".join(repr(b) for b in bad)
        raise reader.error(c, f"value={raw!r}: {what}",
                           "a comma-separated list of " + ", ".join(MESH_OUTPUTS))
    return {"value": ",".join(dict.fromkeys(items))}


def _outputfmt(reader, c):
    raw = reader.text_attr(c, "value")
    items = [s.strip().lower() for s in raw.split(",") if s.strip()]
    bad = [s for s in items if s not in MESH_FORMATS]
    if bad or not items:
        raise reader.error(c, f"value={raw!r} is not an output format", "csv and/or bin, comma-separated")
    if "bin" in items:
        reader.warn(c, "outputfmt bin: sphdvi writes the mesh gauge as CSV only")
    return {"value": ",".join(dict.fromkeys(items))}


def _number_or_none(reader, c, nonnegative):
    """``{"value": v | "none"}`` (``kclimit``, ``kcdummy``)."""
    raw = c.get("value")
    if raw is not None and raw.strip().lower() == "none":
        reader.mark(c, "value")
        return {"value": "none"}
    return {"value": reader.num(c, "value", nonnegative=nonnegative)}


def _mesh_size(reader, c):
    """``<sizeK length=".." distpt=".."/>`` (DualSPHysics: the extent along vecK and the distance
    between its nodes) or sphdvi's older ``<sizeK value=".."/>`` (nodes dp apart)."""
    has_value = c.get("value") is not None
    has_dual = c.get("length") is not None or c.get("distpt") is not None
    reader.mark(c, "value", "length", "distpt")
    if has_value and has_dual:
        raise reader.error(c, "gives value together with length/distpt",
                           'length=".." and distpt=".." (DualSPHysics), or value=".." (nodes dp apart)')
    if has_value:
        return reader.num(c, "value", nonnegative=True)
    if c.get("length") is None or c.get("distpt") is None:
        missing = "length" if c.get("length") is None else "distpt"
        raise reader.error(c, f"missing attribute '{missing}'",
                           'length=".." [m] and distpt=".." [m] (the distance between the nodes, > 0)')
    return {"length": reader.num(c, "length", nonnegative=True), "distpt": reader.num(c, "distpt", positive=True)}


def read_field(reader, c, kind, inherited=None):
    """The value of gauge child ``c`` of ``kind`` (the kinds of ``reader.GAUGE_COMMON/GAUGE_SPECS``)."""
    if kind == "bool":
        return reader.boolean(c, "value")
    if kind == "dt":
        return reader.num(c, "value", nonnegative=True)
    if kind == "window":
        return _window(reader, c, inherited)
    if kind == "vec":
        return reader.vec3(c).tolist()
    if kind == "positive":
        return reader.num(c, "value", positive=True)
    if kind == "size":
        return _mesh_size(reader, c)
    if kind == "count":
        return reader.integer(c, "value", lo=0, hi=2**31 - 1)
    if kind == "mkbound":
        return {"mkbound": reader.integer(c, "mkbound", lo=0, hi=65535)}
    if kind.startswith("oneof:"):
        return _one_of(reader, c, kind[6:].split(","))
    if kind == "outputdata":
        return _outputdata(reader, c)
    if kind == "outputfmt":
        return _outputfmt(reader, c)
    if kind == "kclimit":
        return _number_or_none(reader, c, nonnegative=True)
    if kind == "kcdummy":
        return _number_or_none(reader, c, nonnegative=False)
    raise AssertionError(f"unknown gauge field kind {kind!r}")


def read_fields(reader, el, spec: dict, inherited: dict) -> tuple[dict, dict]:
    """All children of ``el`` by ``spec`` (tag -> kind); returns (values, tag -> element)."""
    out, elements = {}, {}
    for c in reader.children(el):
        if c.tag not in spec:
            raise reader.error(c, f"unknown element <{c.tag}> in <{el.tag}>",
                               "one of " + ", ".join(f"<{k}>" for k in sorted(spec)))
        if c.tag in elements:
            raise reader.error(c, f"<{c.tag}> given twice in <{el.tag}>", f"one <{c.tag}>")
        elements[c.tag] = c
        out[c.tag] = read_field(reader, c, spec[c.tag], inherited.get(c.tag))
    return out, elements


# ---------------------------------------------------------------------------------
# names and whole gauges
# ---------------------------------------------------------------------------------
NAME_EXPECTED = (f"a name of 1 to {MAX_NAME_BYTES} bytes without / \\ : * ? \" < > |, '..' or control "
                 "characters (it becomes part of the file name Gauges<Type>_<name>.csv)")


def name_problem(name: str) -> str | None:
    """What is wrong with a gauge name as part of a file name, or None."""
    shown = name if len(name) <= 40 else name[:37] + "..."
    if not name:
        return "empty gauge name"
    if len(name.encode("utf-8")) > MAX_NAME_BYTES:
        return f"gauge name '{shown}' is {len(name.encode('utf-8'))} bytes long"
    bad = sorted({ch for ch in name if ch in NAME_FORBIDDEN or ord(ch) < 32 or ord(ch) == 127})
    if bad:
        return f"gauge name {shown!r} contains {', '.join(repr(b) for b in bad)}"
    if ".." in name:
        return f"gauge name '{shown}' contains '..'"
    if name != name.strip():
        return f"gauge name {shown!r} starts or ends with a space"
    return None


def check_name(reader, c, name: str) -> None:
    problem = name_problem(name)
    if problem:
        raise reader.error(c, problem, NAME_EXPECTED)


def case_dp(reader, el):
    """dp of the case (``<casedef><geometry><definition dp>``), None when it cannot be read."""
    from ..errors import CaseError
    root = el.getroottree().getroot()
    d = root.find("casedef/geometry/definition")
    if d is None or d.get("dp") is None:
        return None
    try:
        return reader.num(d, "dp", positive=True)
    except CaseError:
        return None


def _too_many(reader, el, what, n, expected):
    if n > MAX_GAUGE_POINTS:
        count = f"{n:.3g}" if n < 1e15 else "more than 1e15"
        raise reader.error(el, f"{what}: {count} sample points, more than {MAX_GAUGE_POINTS:,}",
                           expected)


def check_gauge(reader, c, d: dict, elements: dict, dp) -> None:
    """The checks that need several fields of one gauge (and dp for the sample counts)."""
    kind, name = c.tag, d["name"]
    for tag in REQUIRED_CHILDREN[kind]:
        if tag not in d:
            attrs = 'mkbound="N"' if tag == "target" else 'x=".." y=".." z=".."'
            raise reader.error(c, f"{kind} gauge '{name}' has no <{tag}>", f"<{tag} {attrs}/> in <{kind}>")
    if kind == "swl":
        if "point1" in d:       # DualSPHysics 5.4 runs a case with one (yupengxiang/DualSPHysics F5)
            reader.warn(elements["point1"], f"swl gauge '{name}': <point1> is not read (the gauge is the "
                                            "line from <point0> to <point2>); ignored")
            d.pop("point1")
        length = math.dist(d["point2"], d["point0"])
        if length == 0:
            raise reader.error(elements["point2"], f"swl gauge '{name}': <point2> equals <point0>",
                               "a line of positive length from <point0> to <point2>")
        pdp = d.get("pointdp", {})
        step = pdp["value"] if "value" in pdp else (dp * pdp.get("coefdp", SWL_DEFAULT_COEFDP) if dp else None)
        if step:
            _too_many(reader, elements.get("pointdp", c), f"swl gauge '{name}'", line_samples(length, step),
                      f"a larger <pointdp> (the line is {length:g} m long; at most {MAX_GAUGE_POINTS:,} "
                      "points along it)")
    elif kind == "mesh":
        outputs = d.get("outputdata", {}).get("value", "vel,rhop").split(",")
        vecs = {}
        for k in (1, 2, 3):
            default = [1.0 * (k == 1), 1.0 * (k == 2), 1.0 * (k == 3)]
            vecs[k] = np.linalg.norm(d.get(f"vec{k}", default))
            if vecs[k] == 0 and mesh_length(d.get(f"size{k}")) > 0:
                raise reader.error(elements[f"vec{k}"], f"mesh gauge '{name}': <vec{k}> is the zero vector but "
                                   f"<size{k}> is {mesh_length(d[f'size{k}']):g} long",
                                   f"a non-zero <vec{k}>, or no extent along it")
        if "zsurf" in outputs and (vecs[3] == 0 or mesh_length(d.get("size3")) <= 0):
            raise reader.error(elements.get("outputdata", c),
                               f"mesh gauge '{name}': zsurf needs a column to search the surface along",
                               "<size3 length> > 0 along a non-zero <vec3>")
        if "veldir" in outputs and "dirdat" in d and np.linalg.norm(d["dirdat"]) == 0:
            raise reader.error(elements["dirdat"], f"mesh gauge '{name}': <dirdat> is the zero vector",
                               "a non-zero direction for veldir (default 1,0,0)")
        if dp:
            counts = [mesh_axis(d.get(f"size{k}"), dp)[0] if vecs[k] > 0 else 1.0 for k in (1, 2, 3)]
            nodes = counts[0] * counts[1] * counts[2]
            _too_many(reader, c, f"mesh gauge '{name}'", nodes,
                      f"smaller <size1..3> or a larger distpt (at most {MAX_GAUGE_POINTS:,} nodes)")
            if "zsurf" in outputs:
                samples = counts[0] * counts[1] * line_samples(mesh_length(d["size3"]), zsurf_step(d["size3"], dp))
                _too_many(reader, c, f"mesh gauge '{name}' (zsurf)", samples,
                          "a smaller mesh, a shorter <size3> or a larger distpt along it")


def read_gauges(reader, el, common: dict, specs: dict) -> dict:
    """``<special><gauges>`` -> ``{"default": {...}, "items": [{"type", "name", "line", ...}]}``."""
    out = {"default": {}, "items": []}
    defaults = reader.children(el, "default")
    if len(defaults) > 1:
        raise reader.error(defaults[1], "<default> given twice in <gauges>", "one <default>")
    if defaults:
        out["default"], _ = read_fields(reader, defaults[0], common, {})
    dp = None
    names = set()
    for c in reader.children(el):
        if c.tag == "default":
            continue
        if c.tag not in specs:
            raise reader.error(c, f"unknown gauge <{c.tag}>", "velocity, swl, maxz, force or mesh")
        name = reader.text_attr(c, "name")
        check_name(reader, c, name)
        if name in names:
            raise reader.error(c, f"gauge name '{name}' used twice", "unique gauge names")
        names.add(name)
        d = {"type": c.tag, "name": name, "line": c.sourceline}
        values, elements = read_fields(reader, c, {**common, **specs[c.tag]}, out["default"])
        d.update(values)
        if dp is None:
            dp = case_dp(reader, el) or 0.0
        check_gauge(reader, c, d, elements, dp or None)
        if "output" not in d and "output" not in out["default"]:
            # an <output value="false"/> the case gives is the author's choice: no warning then
            reader.warn(c, f"gauge '{name}' writes no file: DualSPHysics's default is <output value=\"false\"/> "
                        "(add <output value=\"true\"/> to it or to <default>); sphdvi does not compute it")
        if d.get("savevtkpart", out["default"].get("savevtkpart", False)):
            reader.warn(c, f"gauge '{name}': <savevtkpart> has no effect: sphdvi writes no VTK file of a gauge"
                        + ("" if d.get("output", out["default"].get("output", False))
                           else " (and, with <output value=\"false\"/>, computes nothing for it)"))
        out["items"].append(d)
    return out
