"""``<special><wavepaddles>``: the wave makers of a case as DualSPHysics reads them (regular
``<piston>`` and ``<flap>``, irregular ``<piston_spectrum>`` and ``<flap_spectrum>``, a focused group
``<piston_focused>``, ``<piston_solitary>``; active absorption ``<awas_zsurf>``), with the warnings on waves outside a
theory's range. Called by :mod:`sphdvi.case.reader`; :mod:`sphdvi.motion` generates the motion."""
from __future__ import annotations

import numpy as np

from ..errors import CaseError


def _value_children(reader, el, spec: dict, required=()) -> dict:
    """Children written as ``<tag value=..>`` (num/int/str/bool) or ``<tag x y z>`` (vec)."""
    out = {}
    for c in reader.children(el):
        if c.tag not in spec:
            raise reader.error(c, f"unknown element <{c.tag}> in <{el.tag}>", "one of " + ", ".join(f"<{k}>" for k in sorted(spec)))
    for tag, kind in spec.items():
        c = reader.child(el, tag)
        if c is None:
            if tag in required:
                raise reader.error(el, f"missing <{tag}>", f"<{tag}> in <{el.tag}>")
            continue
        if kind == "vec":
            out[tag] = reader.vec3(c).tolist()
        elif kind == "num":
            out[tag] = reader.num(c, "value")
        elif kind == "int":
            out[tag] = reader.integer(c, "value")
        elif kind == "bool":
            out[tag] = reader.boolean(c, "value")
        elif kind == "str":
            out[tag] = reader.text_attr(c, "value")
        elif kind == "raw":
            out[tag] = {k: c.get(k) for k in c.keys()}
            reader.mark(c, *c.keys())
        else:
            raise AssertionError(f"unknown kind {kind!r} of <{tag}>")
    return out


def read_wavepaddles(reader, el) -> list:
    spec_common = {"mkbound": "int", "start": "num", "duration": "num", "depth": "num", "waveorder": "int",
                   "waveheight": "num", "waveperiod": "num", "gainstroke": "num", "fixeddepth": "num",
                   "savemotion": "raw", "awas_zsurf": "raw"}
    spec_regular = {**spec_common, "phase": "num", "ramp": "num", "usefiledata": "raw"}
    spec_spectrum = {**spec_common, "spectrum": "str", "discretization": "str", "peakcoef": "num", "waves": "int",
                     "randomseed": "int", "serieini": "raw", "ramptime": "num", "saveserie": "raw",
                     "saveseriewaves": "raw", "calcserielength": "raw"}
    flap_geometry = {"variabledraft": "num", "flapaxis0": "vec", "flapaxis1": "vec"}
    spec_focused = {**spec_spectrum, "pistondir": "vec", "xf": "num", "fphase": "num", "maxwaveh": "raw",
                    "fpretime": "num", "fmovtime": "num", "fmovramp": "num"}
    for k in ("serieini", "saveserie", "saveseriewaves", "calcserielength"):
        del spec_focused[k]
    specs = {"piston": {**spec_regular, "pistondir": "vec"}, "flap": {**spec_regular, **flap_geometry},
             "piston_spectrum": {**spec_spectrum, "pistondir": "vec"},
             "flap_spectrum": {**spec_spectrum, **flap_geometry}, "piston_focused": spec_focused}
    out = []
    for c in reader.children(el):
        if c.tag == "piston_solitary":
            out.append(read_piston_solitary(reader, c))
            continue
        if c.tag not in specs:
            raise reader.error(c, f"<wavepaddles><{c.tag}> is not supported by sphdvi",
                               "<piston> or <flap> (regular waves), <piston_spectrum> or <flap_spectrum> "
                               "(irregular), <piston_focused> (a focused group), <piston_solitary> (solitary waves)")
        focused = c.tag == "piston_focused"
        spectral = c.tag.endswith("_spectrum") or focused
        d = {"type": c.tag, "line": c.sourceline}
        d.update(_value_children(reader, c, specs[c.tag], required=("mkbound", "depth", "waveheight", "waveperiod")
                                 + (("xf",) if focused else ())))
        d.setdefault("waveorder", 1)
        if d["waveorder"] not in (1, 2):
            raise reader.error(c, f"waveorder {d['waveorder']}", "1 or 2")
        for k in ("depth", "waveheight", "waveperiod"):
            if d[k] <= 0:
                raise reader.error(reader.child(c, k), f"<{k}> must be positive", f"{k} > 0")
        for k, what in (("start", "seconds"), ("duration", "seconds, 0: until the end"), ("ramp", "wave periods"),
                        ("ramptime", "seconds")):
            if d.get(k, 0.0) < 0:
                raise reader.error(reader.child(c, k), f"<{k}> value={d[k]:g} is negative", f"{k} >= 0 ({what})")
        if c.tag.startswith("flap") and d["waveorder"] == 2:
            # DualSPHysics's own example main/08_WavesFlap (CaseFlapBeach_REG) asks for it; its format
            # doc (_FmtXML_WavePaddles.xml) gives <waveorder> to pistons only, and its wave generation
            # (Altomare et al. 2017) is second order for pistons: the flap moves at first order
            reader.warn(reader.child(c, "waveorder"), f"second-order generation is for pistons (DualSPHysics's format "
                        f"gives a <{c.tag}> no <waveorder>): this flap generates first-order waves")
            d["waveorder"] = 1
        if c.tag.startswith("flap") and ("flapaxis0" not in d or "flapaxis1" not in d):
            raise reader.error(c, "missing <flapaxis0>/<flapaxis1>", "the two points of the hinge axis")
        if c.tag.startswith("flap") and not d.get("variabledraft", 0.0) > -d["depth"]:
            raise reader.error(reader.child(c, "variabledraft"), f"<variabledraft> value={d['variabledraft']:g} puts "
                               f"the hinge at or above the still water (depth {d['depth']:g} m)",
                               "the hinge's depth below the bottom (> 0) or above it (< 0, above -depth)")
        if c.tag.startswith("flap") and d["flapaxis0"] == d["flapaxis1"]:
            raise reader.error(reader.child(c, "flapaxis1"), f"<flapaxis0> and <flapaxis1> are the same point "
                               f"{d['flapaxis0']}, so they define no hinge axis", "two distinct points on the hinge axis")
        if c.tag.startswith("piston") and "pistondir" in d and not any(d["pistondir"]):
            raise reader.error(reader.child(c, "pistondir"), "<pistondir> is the zero vector",
                               "the direction of the piston's stroke, e.g. x=1 y=0 z=0")
        if focused:         # the defaults DualSPHysics's format gives a focused piston
            d.setdefault("discretization", "regular")
            d.setdefault("waves", 128)
        if spectral:
            _read_spectrum_options(reader, c, d)
        if focused:
            _read_focus_options(reader, c, d)
        if "awas_zsurf" in d:
            d["awas"] = _read_awas(reader, reader.child(c, "awas_zsurf"), d)
            del d["awas_zsurf"]
        if "usefiledata" in d:
            reader.warn(reader.child(c, "usefiledata"), "<usefiledata> is not implemented by sphdvi: the paddle "
                        "follows the regular-wave theory; <usefiledata> is ignored")
        read_theory_outputs(reader, c, d, spectral)
        if d.get("fixeddepth", 0.0):
            reader.warn(reader.child(c, "fixeddepth"), "<fixeddepth> (the fluid depth without the paddle) is not "
                        "implemented by sphdvi: the stroke follows <depth>; <fixeddepth> is ignored")
        d.setdefault("start", 0.0)
        d.setdefault("duration", 0.0)
        d.setdefault("gainstroke", 1.0)
        if not spectral:
            d.setdefault("phase", 0.0)
            d.setdefault("ramp", 0.0)
        if c.tag.startswith("piston"):
            d.setdefault("pistondir", [1.0, 0.0, 0.0])
        if "awas" in d:
            _check_awas_start(reader, c, d)
        try:       # the stroke from the wave theory: fails here, not at the first step of the run
            from ..motion import make_paddle
            make_paddle(d)
        except (ArithmeticError, ValueError, CaseError) as exc:
            raise reader.error(c, f"cannot compute the paddle's stroke: {exc}",
                               "a wave period and depth of a real wave") from None
        for message in wave_validity_warnings(d["waveheight"], d["waveperiod"], d["depth"], d["waveorder"],
                                              "significant height Hs and peak period Tp" if spectral else ""):
            reader.warn(c, message)
        out.append(d)
    return out


def wave_validity_warnings(height: float, period: float, depth: float, order: int = 1, of: str = "",
                           g: float = 9.81) -> list:
    """What DualSPHysics warns of a paddle's waves (L from the linear dispersion relation): they
    break for their steepness, H/L > 0.142 tanh(kd) (Miche 1944), or for the depth, H/d > 0.78
    (McCowan 1894); second-order generation stands outside its theory's range where the Ursell
    number H L²/d³ ≥ 8π²/3 (Madsen 1971). ``of``: what H and T are (irregular waves)."""
    import math
    from ..motion import wave_number
    k = wave_number(period, depth, g)
    length = 2 * math.pi / k
    what = f" (of the {of})" if of else ""
    out = []
    if height / length > 0.142 * math.tanh(k * depth):
        out.append(f"the waves break for their steepness{what}: H/L = {height / length:.3g} > 0.142 tanh(kd) = "
                   f"{0.142 * math.tanh(k * depth):.3g} (Miche 1944)")
    if height / depth > 0.78:
        out.append(f"the waves break for the depth{what}: H/d = {height / depth:.3g} > 0.78 (McCowan 1894)")
    ursell = height * length ** 2 / depth ** 3
    if order == 2 and ursell >= 8 * math.pi ** 2 / 3:
        out.append(f"second-order generation outside its range{what}: the Ursell number H L^2/d^3 = {ursell:.3g} >= "
                   f"8 pi^2/3 = {8 * math.pi ** 2 / 3:.3g} (Madsen 1971): the second-order term grows unphysical "
                   "in shallow water")
    return out


AWAS_SPEC = {"startawas": "num", "swl": "num", "elevation": "int", "gaugex": "raw", "gaugey": "num",
             "gaugezmin": "num", "gaugezmax": "num", "gaugedp": "num", "coefmasslimit": "num", "savedata": "int",
             "limitace": "num", "correction": "raw"}


def _read_awas(reader, el, paddle: dict) -> dict:
    """``<awas_zsurf>`` of a piston: active wave absorption (DualSPHysics's JWaveAwasZsurf; run by
    :class:`sphdvi.wave_absorption.PistonAbsorber`). Options with DualSPHysics's defaults: ``startawas``
    (the end of the ramp), ``swl`` (required), ``elevation`` 1 or 2 (2), ``gaugex`` value [m], valueh
    [h] or valuedp [dp] from the piston's face (5 dp), ``gaugey`` (required), ``gaugezmin``/``gaugezmax``
    (the domain's), ``gaugedp`` (0.1, in dp), ``coefmasslimit`` (the surface's kernel sum: 0.4 in 2D,
    0.5 in 3D), ``limitace`` (2: the acceleration limit in peak theoretical accelerations, 0 none),
    ``correction coefstroke coefperiod powerfunc`` (drift correction; off)."""
    if paddle["type"].startswith("flap"):
        raise reader.error(el, "active wave absorption (AWAS) is implemented for pistons only (as DualSPHysics)",
                           "<awas_zsurf> in a <piston> or <piston_spectrum>")
    direction = np.asarray(paddle.get("pistondir", [1.0, 0.0, 0.0]), float)
    if not (direction[0] > 0 and direction[1] == 0 and direction[2] == 0):
        raise reader.error(el, f"AWAS needs a piston moving along +x (pistondir {direction.tolist()})",
                           '<pistondir x="1" y="0" z="0"/> (as DualSPHysics)')
    a = _value_children(reader, el, AWAS_SPEC, required=("swl", "gaugey"))
    a.setdefault("elevation", 2)
    if a["elevation"] not in (1, 2):
        raise reader.error(reader.child(el, "elevation"), f"<elevation> value={a['elevation']}",
                           "1 (first-order) or 2 (second-order) target elevation")
    gx = reader.child(el, "gaugex")
    a["gaugex"] = {"unit": "dp", "value": 5.0}
    if gx is not None:
        given = [k for k in ("value", "valueh", "valuedp") if gx.get(k) is not None]
        if len(given) != 1:
            raise reader.error(gx, f"<gaugex> has {' and '.join(given) or 'no value'}",
                               "exactly one of value (m), valueh (times h) or valuedp (times dp)")
        a["gaugex"] = {"unit": {"value": "m", "valueh": "h", "valuedp": "dp"}[given[0]],
                       "value": reader.num(gx, given[0], positive=True)}
    a.setdefault("gaugedp", 0.1)
    for k in ("gaugedp", "coefmasslimit"):
        if k in a and not a[k] > 0:
            raise reader.error(reader.child(el, k), f"<{k}> value={a[k]:g}", f"{k} > 0")
    if "gaugezmin" in a and "gaugezmax" in a and not a["gaugezmax"] > a["gaugezmin"]:
        raise reader.error(reader.child(el, "gaugezmax"), f"<gaugezmax> {a['gaugezmax']:g} is not above <gaugezmin> "
                           f"{a['gaugezmin']:g}", "a vertical gauge line from gaugezmin up to gaugezmax")
    a.setdefault("limitace", 2.0)
    if a["limitace"] < 0:
        raise reader.error(reader.child(el, "limitace"), f"<limitace> value={a['limitace']:g}",
                           "a factor >= 0 of the peak theoretical acceleration (0: no limit)")
    corr = reader.child(el, "correction")
    a["correction"] = {"coefstroke": 0.0, "coefperiod": 0.0, "powerfunc": 1.0}
    if corr is not None:
        cc = {k: reader.num(corr, k, v) for k, v in a["correction"].items()}
        if cc["powerfunc"] < 1:
            raise reader.error(corr, f"powerfunc={cc['powerfunc']:g}", "powerfunc >= 1")
        if cc["coefstroke"] or cc["coefperiod"]:
            if cc["coefstroke"] < 1:
                raise reader.error(corr, f"coefstroke={cc['coefstroke']:g}",
                                   "coefstroke >= 1: the drift (in stroke amplitudes) that starts a correction")
            if not cc["coefperiod"] > 0:
                raise reader.error(corr, f"coefperiod={cc['coefperiod']:g}",
                                   "coefperiod > 0: the correction's duration in wave periods")
        a["correction"] = cc
    if a.get("savedata", 0):
        reader.warn(reader.child(el, "savedata"), "<savedata> (AWAS's CSV files) is not implemented by sphdvi: "
                    "no file is written; measure the surface with a <gauges> swl gauge")
    a.pop("savedata", None)
    return a


def _check_awas_start(reader, c, d: dict) -> None:
    """AWAS starts at ``startawas``, by default (and at the earliest) where the ramp ends."""
    ramp_end = d["start"] + (d.get("ramptime", 0.0) if d["type"].endswith("_spectrum")
                             else d.get("ramp", 0.0) * d["waveperiod"])
    a = d["awas"]
    if a.get("startawas") is None:
        a["startawas"] = ramp_end
    elif a["startawas"] < ramp_end - 1e-12:
        raise reader.error(reader.child(reader.child(c, "awas_zsurf"), "startawas"),
                           f"<startawas> {a['startawas']:g} s is before the end of the ramp ({ramp_end:g} s)",
                           f"startawas >= {ramp_end:g} s (as DualSPHysics: absorption begins after the ramp)")


def _read_spectrum_options(reader, c, d: dict) -> None:
    """The irregular-wave options of a ``<piston_spectrum>``/``<flap_spectrum>`` (in place, with
    DualSPHysics's defaults: stretched, γ 3.3, 50 waves; seed 0, serieini 0, ramptime 0)."""
    from ..wavespectra import DISCRETISATIONS, SPECTRA
    if "spectrum" not in d:
        raise reader.error(c, "missing <spectrum>", "<spectrum value=\"jonswap\"/> or \"pierson-moskowitz\"")
    d["spectrum"] = d["spectrum"].strip().lower()
    if d["spectrum"] not in SPECTRA:
        raise reader.error(reader.child(c, "spectrum"), f"unknown spectrum '{d['spectrum']}'", " or ".join(SPECTRA))
    d["discretization"] = d.get("discretization", "stretched").strip().lower()
    if d["discretization"] not in DISCRETISATIONS:
        raise reader.error(reader.child(c, "discretization"), f"unknown discretization '{d['discretization']}'",
                           ", ".join(DISCRETISATIONS))
    d.setdefault("peakcoef", 3.3)
    if d["peakcoef"] < 1:
        raise reader.error(reader.child(c, "peakcoef"), f"<peakcoef> value={d['peakcoef']:g}",
                           "a peak enhancement factor gamma >= 1 (1: Pierson-Moskowitz's shape)")
    d.setdefault("waves", 50)
    if d["waves"] < 1:
        raise reader.error(reader.child(c, "waves"), f"<waves> value={d['waves']}", "at least 1 wave")
    if d["waves"] < 2 and d["discretization"] == "cosstretched":
        raise reader.error(reader.child(c, "waves"), f"<waves> value={d['waves']} with the cosstretched "
                           "discretization, whose bins narrow towards fp from both sides",
                           "at least 2 waves (one below fp and one above), or another discretization")
    d.setdefault("randomseed", 0)
    d.setdefault("ramptime", 0.0)
    raw = d.pop("serieini", None)
    d["serieini"] = 0.0
    if raw is not None:
        el = reader.child(c, "serieini")
        d["serieini"] = reader.num(el, "value") if raw.get("value") is not None else 0.0
        if d["serieini"] < 0:
            raise reader.error(el, f"<serieini> value={d['serieini']:g} is negative", "a time >= 0 in the series [s]")
        if str(raw.get("autofit", "false")).strip().lower() in ("true", "1"):
            reader.warn(el, "<serieini autofit> is not needed by sphdvi: the paddle starts from where it is "
                            "drawn without a jump (the ramp of <ramptime> starts the series from rest; without "
                            "one the series less its value at serieini is played); autofit is ignored")


def _only_attributes(reader, el, allowed, where: str = "") -> None:
    """An attribute of ``el`` other than ``allowed`` (and the comments) is a case error naming it."""
    for k in el.keys():
        if k not in (*allowed, "comment") and not k.endswith("_comment"):
            raise reader.error(el, f"unknown attribute {k!r} of <{el.tag}>{where}", ", ".join(allowed))
    reader.mark(el, "comment")


def _read_savemotion(reader, c, d: dict, spectral: bool) -> list:
    """Every ``<savemotion>`` line of a paddle (DualSPHysics's format doc: each writes a file of the
    paddle's displacement and the theory's elevation and velocity): ``xpos`` (a coordinate along the
    paddle's direction, 0 by default), ``zpos`` (the depth of the velocity's point below the still
    water, as a negative z; none: no velocity); a regular paddle's ``periods`` and ``periodsteps``,
    an irregular or focused one's ``time`` and ``timedt`` (each by default from TimeMax and TimeOut)."""
    out = []
    timing = ("time", "timedt") if spectral else ("periods", "periodsteps")
    for el in reader.children(c, "savemotion"):
        _only_attributes(reader, el, (*timing, "xpos", "zpos"), f" in <{c.tag}>")
        e = {"line": el.sourceline, "xpos": reader.num(el, "xpos", 0.0)}
        if el.get("zpos") is not None:
            e["zpos"] = reader.num(el, "zpos")
            if not -d["depth"] <= e["zpos"] <= 0.0:
                raise reader.error(el, f"zpos={e['zpos']:g} is not in the water (depth {d['depth']:g} m)",
                                   f"-{d['depth']:g} <= zpos <= 0 (the point's z below the still water)")
        for k in timing:
            if el.get(k) is not None:
                e[k] = reader.integer(el, k, lo=1) if k == "periodsteps" else reader.num(el, k)
                if not e[k] > 0:
                    raise reader.error(el, f"{k}={e[k]:g}", f"{k} > 0")
        out.append(e)
    return out


def read_theory_outputs(reader, c, d: dict, spectral: bool) -> None:
    """A wave maker's outputs of its theory (in place): ``<savemotion>`` lines, and an irregular one's
    ``<calcserielength timemax>``, ``<saveserie>`` and ``<saveseriewaves>`` (a paddle's or a
    relaxation zone's)."""
    if "savemotion" in d:
        d["savemotion"] = _read_savemotion(reader, c, d, spectral)
    if "calcserielength" in d:
        el = reader.child(c, "calcserielength")
        reader.mark(el, "comment")
        d["calcserielength"] = reader.num(el, "timemax", positive=True)
    for k, attrs in (("saveserie", ("timemin", "timemax", "timedt", "xpos")),
                     ("saveseriewaves", ("timemin", "timemax", "xpos"))):
        if k in d:
            d[k] = _read_serie_window(reader, reader.child(c, k), attrs)


def _read_serie_window(reader, el, attrs) -> dict:
    """An irregular paddle's ``<saveserie timemin timemax timedt xpos>`` (the series over a window, written
    to a file) or ``<saveseriewaves timemin timemax xpos>`` (its waves by zero up-crossing): timemax
    required, timemin 0, timedt 0.05 s, xpos 0."""
    _only_attributes(reader, el, attrs)
    e = {"timemin": reader.num(el, "timemin", 0.0, nonnegative=True), "timemax": reader.num(el, "timemax"),
         "xpos": reader.num(el, "xpos", 0.0)}
    if "timedt" in attrs:
        e["timedt"] = reader.num(el, "timedt", 0.05)
        if not e["timedt"] > 0:
            raise reader.error(el, f"timedt={e['timedt']:g}", "timedt > 0")
    if not e["timemax"] > e["timemin"]:
        raise reader.error(el, f"timemax={e['timemax']:g} is not after timemin={e['timemin']:g}", "timemax > timemin")
    return e


def _read_focus_options(reader, c, d: dict) -> None:
    """The focus of a ``<piston_focused>`` (in place): ``xf``; ``fphase`` (degrees, 0); ``maxwaveh``
    ``nwaves`` (1000) or ``time`` (s; 0: not used), the sea state whose largest crest the group is, the
    time deciding when positive (the two on one element or on two, as DualSPHysics's format doc writes
    them); ``fpretime`` (5 s), ``fmovtime`` and ``fmovramp`` (0, 0), each checked."""
    d.setdefault("fphase", 0.0)
    d.setdefault("fpretime", 5.0)
    d.setdefault("fmovtime", 0.0)
    d.setdefault("fmovramp", 0.0)
    for k, what in (("fpretime", "seconds before the slowest group's arrival at the focus"),
                    ("fmovtime", "seconds after start; 0: the paddle never stops"),
                    ("fmovramp", "seconds of the final ramp")):
        if d[k] < 0:
            raise reader.error(reader.child(c, k), f"<{k}> value={d[k]:g} is negative", f"{k} >= 0 ({what})")
    if d["fmovramp"] > 0 and d["fmovtime"] <= 0:
        raise reader.error(reader.child(c, "fmovramp"), f"<fmovramp> value={d['fmovramp']:g} without <fmovtime>",
                           "a <fmovtime> (the end of the motion) for the final ramp to end at")
    d.pop("maxwaveh", None)
    nwaves, time = 1000, 0.0
    for el in reader.children(c, "maxwaveh"):       # DualSPHysics's format doc writes one of each
        reader.mark(el, *el.keys())
        if el.get("nwaves") is not None:
            nwaves = reader.integer(el, "nwaves")
            if nwaves < 2:
                raise reader.error(el, f"<maxwaveh> nwaves={nwaves}", "at least 2 waves")
        if el.get("time") is not None:
            time = reader.num(el, "time")
            if time < 0:
                raise reader.error(el, f"<maxwaveh> time={time:g} is negative",
                                   "a duration [s] (0: the number of waves nwaves decides)")
    d["maxwaveh"] = {"time": time} if time > 0 else {"nwaves": nwaves}


def read_piston_solitary(reader, c) -> dict:
    """``<piston_solitary>``: ``waves`` solitary waves (DualSPHysics's JWavePaddles format):
    ``theory`` (1 Rayleigh, 2 Boussinesq, 3 KdV; 2), ``start``, ``depth``, ``pistondir``,
    ``waveheight``, ``durationcoef`` (1) and for the n-th wave ``waveheightN``,
    ``durationcoefN`` and ``startcoefN`` (its start after the previous wave's, in that wave's
    durations), each defaulting to the previous wave's (startcoef2: 1)."""
    base = {"mkbound": "int", "theory": "int", "start": "num", "depth": "num", "pistondir": "vec",
            "durationcoef": "num", "waveheight": "num", "waves": "int", "savemotion": "raw"}
    allowed = set(base)
    n = 1
    wel = reader.child(c, "waves")
    if wel is not None:
        n = reader.integer(wel, "value", lo=1, hi=100)
    for k in range(2, n + 1):
        allowed |= {f"startcoef{k}", f"durationcoef{k}", f"waveheight{k}"}
    for e in reader.children(c):
        if e.tag not in allowed:
            hint = (f" (the case has <waves value=\"{n}\">)" if e.tag[-1:].isdigit() else "")
            raise reader.error(e, f"unknown element <{e.tag}> in <piston_solitary>{hint}",
                               "one of " + ", ".join(f"<{k}>" for k in sorted(base)) +
                               ", and <startcoefN>, <durationcoefN>, <waveheightN> for N = 2..waves")
    spec = dict(base)
    spec.update({k: "num" for k in allowed - set(base)})
    d = {"type": "piston_solitary", "line": c.sourceline}
    d.update(_value_children(reader, c, spec, required=("mkbound", "depth", "waveheight")))
    d.setdefault("theory", 2)
    if d["theory"] not in (1, 2, 3):
        raise reader.error(reader.child(c, "theory"), f"theory {d['theory']}",
                           "1 (Rayleigh), 2 (Boussinesq, Goring 1978) or 3 (KdV)")
    d.setdefault("start", 0.0)
    if d["start"] < 0:
        raise reader.error(reader.child(c, "start"), f"<start> value={d['start']:g} is negative", "start >= 0 [s]")
    if d["depth"] <= 0:
        raise reader.error(reader.child(c, "depth"), "<depth> must be positive", "depth > 0")
    d.setdefault("pistondir", [1.0, 0.0, 0.0])
    if not any(d["pistondir"]):
        raise reader.error(reader.child(c, "pistondir"), "<pistondir> is the zero vector",
                           "the direction of the piston's stroke, e.g. x=1 y=0 z=0")
    waves, prev = [], {"waveheight": d["waveheight"], "durationcoef": d.get("durationcoef", 1.0), "startcoef": 1.0}
    for k in range(1, n + 1):
        w = {key: d.pop(f"{key}{k}" if k > 1 else key, prev[key]) for key in ("waveheight", "durationcoef", "startcoef")}
        tag = lambda key: reader.child(c, f"{key}{k}" if k > 1 else key)   # noqa: E731
        if not w["waveheight"] > 0:
            raise reader.error(tag("waveheight"), f"wave height {w['waveheight']:g}", "a height > 0 [m]")
        if w["waveheight"] > 0.78 * d["depth"]:
            raise reader.error(tag("waveheight"), f"wave height {w['waveheight']:g} m in {d['depth']:g} m of water "
                               "breaks (H/h > 0.78)", "H/h below 0.78 (a solitary wave's limit)")
        if not w["durationcoef"] > 0:
            raise reader.error(tag("durationcoef"), f"duration coefficient {w['durationcoef']:g}", "a coefficient > 0")
        if k > 1 and not w["startcoef"] >= 0:
            raise reader.error(tag("startcoef"), f"start coefficient {w['startcoef']:g}", "a coefficient >= 0")
        waves.append(w)
        prev = w
    d["solitary"] = waves
    d["waves"] = n
    if "savemotion" in d:
        for el in reader.children(c, "savemotion"):
            reader.mark(el, *el.keys())
        reader.warn(reader.child(c, "savemotion"), "<savemotion> of a solitary-wave paddle is not implemented by "
                    "sphdvi: no file is written; <savemotion> is ignored")
        del d["savemotion"]
    d["duration"], d["gainstroke"] = 0.0, 1.0
    return d
