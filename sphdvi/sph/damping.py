"""Damping zones (DualSPHysics ``<special><damping>``, JDsDamping): fluid velocities
reduced progressively towards an outflow end of the domain, to absorb waves.

Three shapes, as JDsDamping::ReadXml: ``<dampingzone>`` (a plane zone between two points,
optionally limited laterally by a ``<domain>``), ``<dampingbox>`` and ``<dampingcylinder>``.
Each gives the particles it holds a normalised distance f ∈ [0, 1] and reduces their
velocity once per step, per component, as JDsDampingOp_*::ComputeDampingCpu:

    v_i ← v_i · max(0, 1 − dt·redumax·f²·factor_i)

(the factor is not clamped; a multiplier below 0 stops the component instead of reversing it).
Only normal fluid particles are damped (not floating bodies).  Each shape is one compiled loop
over the particles (``_damp_plane``, ``_damp_box``, ``_damp_cylinder``), as ComputeDampingCpu;
``select`` keeps the zone's definition in numpy (what the tests check the loops against).
"""
import math

import numpy as np

from . import _env  # noqa: F401  (OMP_WAIT_POLICY before numba)
from numba import njit

from .state import FLUID


class _Zone:
    """What the three shapes share: redumax, overlimit, factorxyz and the reduction."""

    def __init__(self, spec: dict):
        self.overlimit = float(spec.get("overlimit", 0.0))
        self.redumax = float(spec.get("redumax", 10.0))
        self.factor = np.asarray(spec.get("factorxyz", [1.0, 1.0, 1.0]), float)
        self._geo = None        # the loop's geometry arguments, made at the first step

    def apply(self, state, dt: float) -> None:
        """Damp the fluid particles in the zone for a step of ``dt`` (one compiled loop)."""
        if self._geo is None:
            self._geo = self._geometry()
        self._kernel(state.pos, state.vel, state.ptype, float(dt) * self.redumax, self.factor, *self._geo)

    def select(self, pos: np.ndarray):
        """(mask of the positions in the zone, their normalised distance f)."""
        raise NotImplementedError


@njit(cache=True)
def _damp_row(vel, i, dtredu, f, factor):
    """v_i <- v_i max(0, 1 - dt redumax f^2 factor_k), per component (ComputeDampingCpu)."""
    redudt = dtredu * f * f
    for k in range(3):
        vel[i, k] *= max(0.0, 1.0 - redudt * factor[k])


@njit(cache=True)
def _damp_plane(pos, vel, ptype, dtredu, factor, p0, direc, length, reach, zrange, sides):
    """The fluid in a ``<dampingzone>`` (JDsDampingOp_Plane::ComputeDampingCpu): d along the
    zone's direction from limitmin, 0 < d <= L + overlimit, f = min(d / L, 1); with a
    ``<domain>`` (``sides`` not empty) zmin <= z <= zmax and a x + b y + c <= 0 for each side."""
    for i in range(pos.shape[0]):
        if ptype[i] != FLUID:
            continue
        x, y, z = pos[i, 0], pos[i, 1], pos[i, 2]
        d = (x - p0[0]) * direc[0] + (y - p0[1]) * direc[1] + (z - p0[2]) * direc[2]
        if not (d > 0.0 and d <= reach):
            continue
        if sides.shape[0]:
            if z < zrange[0] or z > zrange[1]:
                continue
            out = False
            for s in range(sides.shape[0]):
                if sides[s, 0] * x + sides[s, 1] * y + sides[s, 2] > 0.0:
                    out = True
            if out:
                continue
        _damp_row(vel, i, dtredu, min(d / length, 1.0), factor)


@njit(cache=True)
def _within(pos, i, lo, hi):
    for k in range(3):
        if not (pos[i, k] >= lo[k] and pos[i, k] <= hi[k]):
            return False
    return True


@njit(cache=True)
def _damp_box(pos, vel, ptype, dtredu, factor, min1, min2, max1, max2, over1, over2, size1, size2):
    """The fluid in a ``<dampingbox>`` (JDsDampingOp_Box::ComputeDampingCpu): inside the overlimit
    box and outside the limitmin box; f = 1 beyond the limitmax box, else the largest normalised
    distance from the limitmin box over the active sides."""
    for i in range(pos.shape[0]):
        if ptype[i] != FLUID or not _within(pos, i, over1, over2) or _within(pos, i, min1, min2):
            continue
        f = 1.0
        if _within(pos, i, max1, max2):
            f = 0.0
            for k in range(3):
                if size2[k]:
                    f = max(f, (pos[i, k] - min2[k]) / size2[k])
                if size1[k]:
                    f = max(f, (min1[k] - pos[i, k]) / size1[k])
        _damp_row(vel, i, dtredu, f, factor)


@njit(cache=True)
def _damp_cylinder(pos, vel, ptype, dtredu, factor, p1, axis, axis_len, vertical, rmin, dist, overlimit):
    """The fluid in a ``<dampingcylinder>`` (JDsDampingOp_Cylinder::ComputeDampingCpu): r the
    distance to the axis (horizontal for a vertical axis), 0 < r - rmin <= dist + overlimit,
    f = min((r - rmin) / dist, 1) (1 when dist <= 0)."""
    for i in range(pos.shape[0]):
        if ptype[i] != FLUID:
            continue
        rx, ry, rz = pos[i, 0] - p1[0], pos[i, 1] - p1[1], pos[i, 2] - p1[2]
        if vertical:
            r = math.hypot(rx, ry)
        else:
            cx = ry * axis[2] - rz * axis[1]
            cy = rz * axis[0] - rx * axis[2]
            cz = rx * axis[1] - ry * axis[0]
            r = math.sqrt(cx * cx + cy * cy + cz * cz) / axis_len
        vdis = r - rmin
        if not (vdis > 0.0 and vdis <= dist + overlimit):
            continue
        _damp_row(vel, i, dtredu, 1.0 if dist <= 0 else min(vdis / dist, 1.0), factor)


def reduction(redudt: np.ndarray, factor: np.ndarray) -> np.ndarray:
    """Per-particle, per-component velocity multiplier max(0, 1 − redudt·factor_i)
    (JDsDampingOp_*::ComputeDampingCpu of DualSPHysics v5.x)."""
    return np.maximum(0.0, 1.0 - redudt[:, None] * factor[None, :])


class DampingZone(_Zone):
    """``<dampingzone>`` (JDsDampingOp_Plane): from ``limitmin`` (no reduction) to
    ``limitmax`` (full) along the line between them, f = d / |limitmax − limitmin|, and
    f = 1 for ``overlimit`` beyond (0 < d ≤ L + overlimit); with a ``<domain>``, only
    particles with zmin ≤ z ≤ zmax inside its x-y quadrilateral."""

    def __init__(self, spec: dict):
        super().__init__(spec)
        self.p0 = np.asarray(spec["limitmin"], float)
        p1 = np.asarray(spec["limitmax"], float)
        self.length = float(np.linalg.norm(p1 - self.p0))
        self.dir = (p1 - self.p0) / self.length
        dom = spec.get("domain")
        self.zrange = (float(dom["zmin"]), float(dom["zmax"])) if dom else None
        self.sides = lateral_planes(dom["points"]) if dom else None

    _kernel = staticmethod(_damp_plane)

    def _geometry(self):
        sides = np.array(self.sides if self.sides is not None else np.zeros((0, 3)), float).reshape(-1, 3)
        zr = np.array(self.zrange if self.zrange is not None else (0.0, 0.0), float)
        return self.p0, self.dir, self.length, self.length + self.overlimit, zr, sides

    def select(self, pos):
        d = (pos - self.p0) @ self.dir
        inside = (d > 0) & (d <= self.length + self.overlimit)
        if self.sides is not None:
            z = pos[:, 2]
            inside &= (z >= self.zrange[0]) & (z <= self.zrange[1])
            for a, b, c in self.sides:
                inside &= a * pos[:, 0] + b * pos[:, 1] + c <= 0.0
        return inside, np.minimum(d[inside] / self.length, 1.0)


def lateral_planes(points) -> list:
    """The four vertical side planes (a, b, c: a·x + b·y + c ≤ 0 inside) of a damping
    ``<domain>``'s quadrilateral (JDsDampingOp_Plane::ComputeDomPlanes): points 2–4 sorted by
    the angle of (point1 − point), then the planes through consecutive points."""
    vp = [np.asarray(p, float) for p in points]
    angles = [0.0] + [math.degrees(math.atan2(vp[0][1] - p[1], vp[0][0] - p[0])) % 360.0 for p in vp[1:]]
    for c in (1, 2):
        for c2 in range(c + 1, 4):
            if angles[c] > angles[c2]:
                angles[c], angles[c2] = angles[c2], angles[c]
                vp[c], vp[c2] = vp[c2], vp[c]
    planes = []
    for i in range(4):
        p, q = vp[i], vp[(i + 1) % 4]
        a, b = q[1] - p[1], -(q[0] - p[0])         # normal (q − p) × ẑ, as fgeo::Plane3Pt
        planes.append((a, b, -(a * p[0] + b * p[1])))
    return planes


# the six sides of a <dampingbox>: (name, 0 for the low corner / 1 for the high one, axis)
BOX_SIDES = (("left", 0, 0), ("front", 0, 1), ("bottom", 0, 2), ("right", 1, 0), ("back", 1, 1), ("top", 1, 2))


class DampingBox(_Zone):
    """``<dampingbox>`` (JDsDampingOp_Box): no reduction inside the ``limitmin`` box, full
    outside the ``limitmax`` box (up to ``overlimit`` beyond it), and between them f the
    largest normalised distance from the limitmin box across the active ``directions``."""

    def __init__(self, spec: dict):
        super().__init__(spec)
        self.min1, self.min2 = (np.asarray(spec["limitmin"][k], float) for k in (0, 1))
        self.max1, self.max2 = (np.array(spec["limitmax"][k], float) for k in (0, 1))
        self.over1, self.over2 = self.max1 - self.overlimit, self.max2 + self.overlimit
        active = set(spec.get("directions", [s[0] for s in BOX_SIDES]))
        for name, hi, axis in BOX_SIDES:          # an inactive side: the zone stops at limitmin
            if name not in active:
                (self.max2 if hi else self.max1)[axis] = (self.min2 if hi else self.min1)[axis]
                (self.over2 if hi else self.over1)[axis] = (self.min2 if hi else self.min1)[axis]
        self.size1 = np.where(self.min1 - self.max1 > 0, self.min1 - self.max1, 0.0)
        self.size2 = np.where(self.max2 - self.min2 > 0, self.max2 - self.min2, 0.0)

    _kernel = staticmethod(_damp_box)

    def _geometry(self):
        return self.min1, self.min2, self.max1, self.max2, self.over1, self.over2, self.size1, self.size2

    def select(self, pos):
        def within(lo, hi):
            return np.all((pos >= lo) & (pos <= hi), axis=1)
        inside = within(self.over1, self.over2) & ~within(self.min1, self.min2)
        p = pos[inside]
        f = np.ones(p.shape[0])
        ramp = within(self.max1, self.max2)[inside]
        if ramp.any():
            q = p[ramp]
            g = np.zeros(q.shape[0])
            for axis in range(3):
                if self.size2[axis]:
                    g = np.maximum(g, (q[:, axis] - self.min2[axis]) / self.size2[axis])
                if self.size1[axis]:
                    g = np.maximum(g, (self.min1[axis] - q[:, axis]) / self.size1[axis])
            f[ramp] = g
        return inside, f


class DampingCylinder(_Zone):
    """``<dampingcylinder>`` (JDsDampingOp_Cylinder): f grows from the ``limitmin`` radius
    (0) to the ``limitmax`` radius (1) about the axis point1–point2, and stays 1 for
    ``overlimit`` beyond (the distance to the axis, horizontal when the axis is vertical)."""

    def __init__(self, spec: dict):
        super().__init__(spec)
        self.p1, self.p2 = np.asarray(spec["point1"], float), np.asarray(spec["point2"], float)
        self.rmin, self.rmax = float(spec["limitmin"]), float(spec["limitmax"])
        self.vertical = self.p1[0] == self.p2[0] and self.p1[1] == self.p2[1]

    _kernel = staticmethod(_damp_cylinder)

    def _geometry(self):
        axis = self.p2 - self.p1
        return (self.p1, axis, float(np.linalg.norm(axis)), bool(self.vertical), self.rmin, self.rmax - self.rmin,
                self.overlimit)

    def select(self, pos):
        rel = pos - self.p1
        if self.vertical:
            r = np.hypot(rel[:, 0], rel[:, 1])
        else:
            axis = self.p2 - self.p1
            r = np.linalg.norm(np.cross(rel, axis), axis=1) / np.linalg.norm(axis)
        dist = self.rmax - self.rmin
        vdis = r - self.rmin
        inside = (vdis > 0) & (vdis <= dist + self.overlimit)
        v = vdis[inside]
        f = np.ones_like(v) if dist <= 0 else np.minimum(v / dist, 1.0)
        return inside, f


ZONE_TYPES = {"zone": DampingZone, "box": DampingBox, "cylinder": DampingCylinder}


def damping_zones(specs) -> list:
    """The zones of a case's ``<special><damping>`` list (none: an empty list)."""
    return [ZONE_TYPES[z.get("type", "zone")](z) for z in specs or []]
