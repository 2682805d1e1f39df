"""4x4 affine matrices for the drawing transforms (move, rotate, rotateline, scale).

``<rotate>`` and ``<rotateline>`` turn the DualSPHysics way (:func:`rotation_line`), the
opposite of the right-hand rule about the axis they name; :func:`rotation_axis` is right-handed.

Like OpenGL and GenCase, each new transform is multiplied on the right of the
current matrix: after ``<move>`` then ``<rotate>``, a shape is first rotated
(about the origin) and then moved. Shapes are defined in their own frame and
drawn at ``M @ p``.
"""
from __future__ import annotations

import math

import numpy as np


def identity() -> np.ndarray:
    return np.eye(4)


def translation(v) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = v
    return m


def scaling(v) -> np.ndarray:
    return np.diag([float(v[0]), float(v[1]), float(v[2]), 1.0])


def rotation_axis(angle_deg: float, axis) -> np.ndarray:
    """Rotation by angle (degrees, right-hand rule) about an axis through the origin."""
    axis = np.asarray(axis, dtype=np.float64)
    n = float(np.linalg.norm(axis))
    if not n > 0:
        raise ValueError("rotation axis has zero length")
    x, y, z = axis / n
    a = math.radians(angle_deg)
    c, s = math.cos(a), math.sin(a)
    C = 1.0 - c
    r = np.array([
        [c + x * x * C, x * y * C - z * s, x * z * C + y * s],
        [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
        [z * x * C - y * s, z * y * C + x * s, c + z * z * C],
    ])
    # exact zeros/ones for multiples of 90 degrees keep lattice-aligned shapes exact
    r[np.abs(r) < 1e-15] = 0.0
    m = np.eye(4)
    m[:3, :3] = r
    return m


def rotation_line(angle_deg: float, p1, p2) -> np.ndarray:
    """GenCase's rotation by ``angle_deg`` about the line p1 -> p2 (``<rotateline>``; ``<rotate>``
    with p1 the origin and p2 its axis): DualSPHysics's JMatrix4::MatrixRot, which turns by
    **−angle** right-handed about p1 -> p2 (+angle about p2 -> p1).  DesignSPHysics, the
    DualSPHysics team's FreeCAD front end, writes FreeCAD's right-handed rotation (angle, axis a)
    as ``<rotate ang="angle" x="-ax" y="-ay" z="-az"/>``; sphdvi's ``<motion>`` turns the same way."""
    p1 = np.asarray(p1, dtype=np.float64)
    p2 = np.asarray(p2, dtype=np.float64)
    return translation(p1) @ rotation_axis(angle_deg, p1 - p2) @ translation(-p1)


def rotation_xyz(angles_deg) -> np.ndarray:
    """Rotation about x, then y, then z (fixed axes): Rz @ Ry @ Rx."""
    ax, ay, az = (float(a) for a in angles_deg)
    return (rotation_axis(az, (0, 0, 1)) @ rotation_axis(ay, (0, 1, 0))
            @ rotation_axis(ax, (1, 0, 0)))


def apply(m: np.ndarray, pts) -> np.ndarray:
    """Apply an affine matrix to points (..., 3)."""
    pts = np.asarray(pts, dtype=np.float64)
    return pts @ m[:3, :3].T + m[:3, 3]


def is_axis_aligned(m: np.ndarray) -> bool:
    """True if the linear part maps axes onto axes (a scaled, signed permutation)."""
    nz = m[:3, :3] != 0.0
    return bool(np.all(nz.sum(axis=0) == 1) and np.all(nz.sum(axis=1) == 1))


def inverse(m: np.ndarray) -> np.ndarray:
    """Inverse of an affine matrix; ValueError when it is singular."""
    det = float(np.linalg.det(m[:3, :3]))
    if not math.isfinite(det) or abs(det) < 1e-300:
        raise ValueError("transformation is singular or overflows (a scale of 0 or 1e308?)")
    return np.linalg.inv(m)


def uniform_scale(m: np.ndarray) -> float | None:
    """The scale factor if the linear part is a rotation times a uniform scale, else None."""
    lin = m[:3, :3]
    g = lin.T @ lin
    s2 = g[0, 0]
    if s2 <= 0 or not np.allclose(g, s2 * np.eye(3), rtol=1e-9, atol=1e-12 * s2):
        return None
    return math.sqrt(s2)
