"""Shifting zones (``<special><shifting><shiftingzone>``): only the fluid particles
inside one of the zones are shifted, as DualSPHysics's JSphShifting::InitCpu /
RunCpu (a particle outside all of them gets no shift).

A zone is a box ``posref`` + a ``vecx`` + b ``vecy`` + c ``vecz``, 0 <= a, b, c <= 1
(boundaries included).  Zones whose edge vectors lie along the axes are tested as
min-max boxes (DualSPHysics's PosMax form, which also takes a zero size along an
axis, e.g. y in 2D: then the particles must lie in that plane); the others through
the inverse of the edge matrix (DualSPHysics's planes form).  The mask is applied to
grad C after the interaction, from the positions the interaction saw.
"""
import numpy as np

from . import _env  # noqa: F401
from numba import njit


def zone_arrays(zones):
    """(boxes (nb, 6): min xyz, max xyz; oblique (no, 12): posref, then the rows of the
    inverse edge matrix) of the zones, each a dict with ``posref`` and ``vecs`` (3 x 3,
    one edge vector per row).  A ValueError for an oblique zone of no volume."""
    boxes, oblique = [], []
    for z in zones:
        p0 = np.asarray(z["posref"], float)
        v = np.asarray(z["vecs"], float).reshape(3, 3)
        if not (v - np.diag(np.diag(v))).any():
            p1 = p0 + np.diag(v)
            boxes.append(np.concatenate([p0, p1]))
            continue
        if abs(np.linalg.det(v)) < 1e-12 * max(1.0, float(np.abs(v).max())) ** 3:
            raise ValueError(f"shiftingzone at {p0.tolist()}: vecx, vecy and vecz span no volume")
        oblique.append(np.concatenate([p0, np.linalg.inv(v.T).ravel()]))
    return np.array(boxes, float).reshape(-1, 6), np.array(oblique, float).reshape(-1, 12)


@njit(cache=True)
def _inside(x, y, z, boxes, oblique):
    """Whether the point lies in one of the zones."""
    for b in range(boxes.shape[0]):
        if (boxes[b, 0] <= x <= boxes[b, 3] and boxes[b, 1] <= y <= boxes[b, 4]
                and boxes[b, 2] <= z <= boxes[b, 5]):
            return True
    for o in range(oblique.shape[0]):
        dx = x - oblique[o, 0]
        dy = y - oblique[o, 1]
        dz = z - oblique[o, 2]
        ok = True
        for r in range(3):
            c = oblique[o, 3 + 3 * r] * dx + oblique[o, 4 + 3 * r] * dy + oblique[o, 5 + 3 * r] * dz
            if c < 0.0 or c > 1.0:
                ok = False
                break
        if ok:
            return True
    return False


@njit(cache=True)
def unshift_outside(pos, ptype, shiftpos, boxes, oblique):
    """Zero the shifting gradient of the fluid particles outside every zone."""
    for i in range(pos.shape[0]):
        if ptype[i] == 3 and not _inside(pos[i, 0], pos[i, 1], pos[i, 2], boxes, oblique):
            shiftpos[i, 0] = 0.0
            shiftpos[i, 1] = 0.0
            shiftpos[i, 2] = 0.0
