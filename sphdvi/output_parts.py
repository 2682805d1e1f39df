"""Which particles an output holds: ``<special><outputparts>`` (DualSPHysics's
JDsOutputParts).

A selection starts from all particles or none (``preselection``); each filter then tests
every particle (``ok``, negated by ``inverse``) and

* ``add``:     selected = selected or ok,
* ``confirm``: selected = selected and ok,
* ``del``:     selected = selected and not ok.

Tests: ``pos`` inside a box (limits left out are open); ``plane`` on the side of the
plane its vector points to, within ``distance`` (none: any); ``sphere`` within the
radius of the centre; ``cylinder`` between the two end planes and within the radius of
the axis; ``type`` one of fixed, moving, floating, fluid (bound: the first three);
``mk`` an mk (or mkbound, mkfluid) in a range; ``group`` a selection of its own, built the
same way.  A position filter with ``ftfollow`` moves with the floating body's centre (not
with its rotation), as DualSPHysics's.  Every ``ignore``-th output (0 included) holds all
particles.  Distances are true distances (the plane's vector need not be a unit vector).
"""
from __future__ import annotations

import numpy as np

TYPE_CODES = {"fixed": (0,), "moving": (1,), "floating": (2,), "fluid": (3,), "bound": (0, 1, 2)}


class OutputParts:
    """The selection of a case's ``<outputparts>`` (the dict its reader made)."""

    def __init__(self, spec: dict, fluidcount: int):
        self.spec = spec
        self.fluidcount = int(fluidcount)
        self.ignore = int(spec.get("ignore", 0))

    def applies_to(self, part: int) -> bool:
        """False for the outputs that keep every particle (every ``ignore``-th)."""
        return self.ignore <= 0 or part % self.ignore != 0

    def select(self, pos, ptype, mk, body_centres: dict | None = None) -> np.ndarray:
        """Boolean mask of the particles to write; ``body_centres``: mkbound -> the floating
        body's centre now (for filters that follow a body)."""
        return _group(self.spec, np.asarray(pos, float), np.asarray(ptype), np.asarray(mk).astype(np.int64),
                      self.fluidcount, body_centres or {})


def _group(spec, pos, ptype, mk, fluidcount, centres) -> np.ndarray:
    sel = np.full(pos.shape[0], spec["preselection"] == "all")
    for f in spec["filters"]:
        if f["kind"] == "group":
            ok = _group(f, pos, ptype, mk, fluidcount, centres)
        else:
            ok = TESTS[f["kind"]](f, pos, ptype, mk, fluidcount, _shift(f, centres))
        if f["inverse"] != (f["operation"] == "del"):
            ok = ~ok
        sel = sel | ok if f["operation"] == "add" else sel & ok
    return sel


def _shift(f, centres) -> np.ndarray:
    """How far the followed body's centre has moved from where it started."""
    follow = f.get("ftfollow")
    if not follow:
        return np.zeros(3)
    now = centres.get(follow["mkbound"])
    return np.zeros(3) if now is None else np.asarray(now, float) - np.asarray(follow["centre0"], float)


def _box(f, pos, ptype, mk, fluidcount, shift):
    lo = np.array([-np.inf if v is None else v for v in f["posmin"]]) + shift
    hi = np.array([np.inf if v is None else v for v in f["posmax"]]) + shift
    return np.all((pos >= lo) & (pos <= hi), axis=1)


def _plane(f, pos, ptype, mk, fluidcount, shift):
    n = np.asarray(f["vector"], float)
    n = n / np.linalg.norm(n)
    d = (pos - (np.asarray(f["point"], float) + shift)) @ n
    limit = np.inf if f["distance"] is None else f["distance"]
    return (d >= 0) & (d <= limit)


def _sphere(f, pos, ptype, mk, fluidcount, shift):
    r = pos - (np.asarray(f["centre"], float) + shift)
    return np.einsum("ij,ij->i", r, r) <= f["radius"] ** 2


def _cylinder(f, pos, ptype, mk, fluidcount, shift):
    p1 = np.asarray(f["point1"], float) + shift
    axis = np.asarray(f["point2"], float) - np.asarray(f["point1"], float)
    length = np.linalg.norm(axis)
    axis = axis / length
    r = pos - p1
    along = r @ axis
    radial = r - along[:, None] * axis
    inside = (along >= 0) & (along <= length)
    if f.get("radius") is None:         # no <radius>: the slab between the end planes (DualSPHysics)
        return inside
    return inside & (np.einsum("ij,ij->i", radial, radial) <= f["radius"] ** 2)


def _type(f, pos, ptype, mk, fluidcount, shift):
    codes = sorted({c for t in f["types"] for c in TYPE_CODES[t]})
    return np.isin(ptype, codes)


def _mk(f, pos, ptype, mk, fluidcount, shift):
    if f["field"] == "mk":
        value, kind = mk, np.ones(mk.shape, bool)
    elif f["field"] == "mkfluid":
        value, kind = mk - 1, ptype == 3
    else:
        value, kind = mk - fluidcount - 1, ptype != 3
    if f.get("ptype") is not None:
        # JDsOutputPartsOp_Mk: the codes between the ends' mk blocks, which are of the ends' type (a
        # floating mkbound 1 inside a range of fixed mkbounds 0-2 is not selected)
        kind = kind & (ptype == f["ptype"])
    return kind & (value >= f["lo"]) & (value <= f["hi"])


TESTS = {"pos": _box, "plane": _plane, "sphere": _sphere, "cylinder": _cylinder, "type": _type, "mk": _mk}
