"""Turning shapes into sets of lattice nodes ("pieces" painted on the canvas).

Rules (lattice units, node ``k`` at ``k``; ``EPS`` = 1e-6):

* **Solid** (volume): nodes inside the shape, nodes on the boundary (within
  EPS) included. Boxes follow GenCase instead (checked against GenCase
  outputs): every node from the one nearest the min corner to the one nearest
  the max corner, i.e. the box widened by dp/2 (half-open: (min - dp/2,
  max + dp/2]); the same in the box's own frame when it is rotated.
* **Planar surfaces** (box faces, prism/pyramid faces, polygons, triangles,
  mesh files): a node belongs to a triangle when its signed distance to the
  plane is in (-1/2, 1/2] and its projection lies within 1/2 of the triangle.
  For an axis-aligned box this is the node layer nearest the face plane
  (a half-way tie as its floating-point value rounds), over the face's extent rounded to the nearest nodes,
  so the faces of a box meet without gaps.
* **Curved surfaces** (sphere, ellipsoid, cylinder): the inner shell, i.e. the
  inside nodes with a face-neighbour (4 in 2D, 6 in 3D) outside the shape. It is
  closed: no face-connected path leads from the interior to the outside
  without crossing it.
* **Lines**: one node per lattice step along the dominant axis (nearest nodes).
* **Points**: the nearest node.

Nodes outside the lattice are never drawn.
"""
from __future__ import annotations

import numpy as np

from . import transform as tf
from .lattice import EPS, Lattice, round_idx

SLAB_NODES = 2_000_000  # nodes evaluated at once by analytic shapes
SURFACE_HALF = 0.5      # half-width of the node band of a planar surface (lattice units)
EDGE_REACH = 0.5        # how far beyond its edges a planar face reaches (lattice units)


class Piece:
    """A set of nodes to paint: an index box, a boolean sub-array, or a list of nodes."""

    def __init__(self, kind, lo=None, hi=None, mask=None, nodes=None):
        self.kind, self.lo, self.hi, self.mask, self.nodes = kind, lo, hi, mask, nodes

    def paint(self, canvas, code: int) -> None:
        if self.kind == "box":
            canvas.paint_box(self.lo, self.hi, code)
        elif self.kind == "mask":
            canvas.paint(self.lo, self.mask, code)
        else:
            n = self.nodes
            canvas.codes[n[:, 0], n[:, 1], n[:, 2]] = code

    def count(self) -> int:
        if self.kind == "box":
            return int(np.prod(self.hi - self.lo + 1))
        if self.kind == "mask":
            return int(np.count_nonzero(self.mask))
        return int(len(self.nodes))


def box_piece(lat: Lattice, lo, hi):
    """A clipped index-box piece, or None when it misses the lattice."""
    r = lat.clip_range(lo, hi)
    return None if r is None else Piece("box", r[0], r[1])


# ---------------------------------------------------------------- axis-aligned box
FACE_AXIS = {"left": (0, 0), "right": (0, 1), "front": (1, 0), "back": (1, 1),
             "bottom": (2, 0), "top": (2, 1)}


def aligned_box_pieces(lat: Lattice, wmin, wmax, solid: bool, faces, wire: bool, shift=None):
    """Pieces of an axis-aligned box (world corners wmin <= wmax); ``shift`` (lo, hi), in
    lattice units, moves its corners after they are mapped to the lattice (a ``<layers>`` copy:
    see :func:`sphdvi.case.draw.shapes.draw_box`). A corner half-way
    between two nodes goes to the one the floating-point value rounds to, with no tolerance, as
    GenCase v5.4 does: relative to the lattice origin (pointref + k dp, in double), 0.005 at dp
    0.01 from pointmin -1 is 100.49999999999999 and takes node 100, 2.105 is 310.5 and takes
    311 (yupengxiang/DualSPHysics F1_DUAL_FINITE_INIT: 633,472 fluid at x 2.11-3.22, y 0-1,
    z 0-0.55, and 997,590 in all, GenCase's audit); an open tank's walls ending at z = 1.0 with
    pointref 0.005 (200.49999999999997) stop at 0.995 (F1_DUAL_FINITE_CENTER: 361,104)."""
    a = lat.to_index(np.asarray(wmin, dtype=np.float64))
    b = lat.to_index(np.asarray(wmax, dtype=np.float64))
    if shift is not None:
        a = a + shift[0]
        b = b + shift[1]
    pieces = []
    if solid:
        # GenCase: from the node nearest the min corner to the node nearest the max corner
        lo = [round_idx(v) for v in a]
        hi = [round_idx(v) for v in b]
        pieces.append(box_piece(lat, lo, hi))
    # faces span the nearest nodes of the box's extent, up to the layer of a drawn neighbouring face
    ext_lo = [round_idx(v) for v in a]
    ext_hi = [round_idx(v) for v in b]
    for face in faces:
        axis, side = FACE_AXIS[face]
        layer = round_idx(b[axis] if side else a[axis])
        lo, hi = list(ext_lo), list(ext_hi)
        lo[axis] = hi[axis] = layer
        pieces.append(box_piece(lat, lo, hi))
    if wire:
        ends = [(round_idx(a[i]), round_idx(b[i])) for i in range(3)]
        for axis in range(3):
            o1, o2 = [i for i in range(3) if i != axis]
            for e1 in ends[o1]:
                for e2 in ends[o2]:
                    lo, hi = list(ext_lo), list(ext_hi)
                    lo[o1] = hi[o1] = e1
                    lo[o2] = hi[o2] = e2
                    pieces.append(box_piece(lat, lo, hi))
    return [p for p in pieces if p is not None]


# ---------------------------------------------------------------- triangles
def world_range(lat: Lattice, pts, pad: float):
    """Domain-clipped index range covering points within pad (lattice units); None if empty."""
    pts = np.asarray(pts, dtype=np.float64).reshape(-1, 3)
    lo, hi = lat.bbox_range(pts.min(axis=0), pts.max(axis=0), pad)
    return lat.clip_range(lo, hi)


def triangle_pieces(lat: Lattice, tris, surface: bool = True, solid: bool = False):
    """Surface and/or inside (parity) nodes of world triangles (T,3,3)."""
    from . import kernels  # numba: imported only when a triangle is drawn
    tris = np.asarray(tris, dtype=np.float64).reshape(-1, 3, 3)
    if tris.shape[0] == 0:
        return []
    itri = np.ascontiguousarray(lat.to_index(tris))
    if not np.all(np.abs(itri) < 1e15):
        raise ValueError("triangle coordinates are not finite or lie absurdly far from the domain")
    # a node of the band lies up to SURFACE_HALF from the plane and EDGE_REACH beyond an edge:
    # on a face oblique to the lattice that is up to ~0.71 beyond the triangle's box along an
    # axis (a pad of 0.5 dropped 27 of 24,846 band nodes of 200 random triangles)
    # In 2D the band's half-width is SURFACE_HALF (|nx| + |nz|) (at most sqrt 2): an oblique line as thick as
    # a 4-connected digital line, as GenCase draws 2D cases (CaseBowling's 33.7-degree drawbeach,
    # GenCase v5.0.278c: 530 wall particles, 430 with the plain band); 3D faces keep the plain
    # band (GenCase4's RotatedBox, turned 40 degrees: 960 particles, 840 with the plain band, 1168
    # with the |n|_1 one)
    l1band = bool(lat.is2d)
    r = world_range(lat, tris, (SURFACE_HALF * (2 ** 0.5 if l1band else 1.0) + EDGE_REACH
                                if surface else 0.5) + EPS)
    if r is None:
        return []
    lo, hi = r
    out = np.zeros(tuple(int(v) for v in hi - lo + 1), dtype=np.bool_)
    if solid:
        # inside by parity, plus the nodes lying on the surface (within 2 EPS)
        kernels.parity_inside(itri, lo, out)
        kernels.raster_triangles(itri, lo, out, -2 * EPS, 2 * EPS, 2 * EPS)
    if surface:
        kernels.raster_triangles(itri, lo, out, -SURFACE_HALF + EPS, SURFACE_HALF + EPS,
                                 EDGE_REACH + EPS, l1band)
    return [Piece("mask", lo, mask=out)]


# ---------------------------------------------------------------- lines and points
def node_pieces(lat: Lattice, idx):
    """A piece of integer node indices (N,3), dropping those outside the lattice."""
    idx = np.asarray(idx, dtype=np.int64).reshape(-1, 3)
    shape = np.array(lat.shape)
    ok = np.all((idx >= 0) & (idx < shape), axis=1)
    idx = idx[ok]
    if idx.size == 0:
        return []
    return [Piece("nodes", nodes=np.unique(idx, axis=0))]


def nearest_nodes(lat: Lattice, pts) -> np.ndarray:
    q = lat.to_index(np.asarray(pts, dtype=np.float64).reshape(-1, 3))
    return np.floor(q + 0.5 + EPS).astype(np.int64)


def _clip_segment(ia, ib, shape):
    """Parametric range [t0, t1] of the segment ia->ib inside the box [-1, shape]; None if outside."""
    t0, t1 = 0.0, 1.0
    d = ib - ia
    for a in range(3):
        lo, hi = -1.0, float(shape[a])
        if d[a] == 0.0:
            if ia[a] < lo or ia[a] > hi:
                return None
            continue
        ta, tb = (lo - ia[a]) / d[a], (hi - ia[a]) / d[a]
        if ta > tb:
            ta, tb = tb, ta
        t0, t1 = max(t0, ta), min(t1, tb)
        if t0 > t1:
            return None
    return t0, t1


#: a line takes the nodes within this distance (in dp) of it: GenCase v4.0's records of
#: DualSPHysics's examples RedrawSimple (its oblique lines hold 157 nodes, taken with any reach
#: from 0.56 to 0.61 dp; a Bresenham line 127) and RedrawComplex (45-degree lines stay one node
#: wide: a reach below 1/sqrt(2))
LINE_REACH = 0.6
_NEIGHBOURS = np.array([(i, j, k) for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1)],
                       dtype=np.int64)


def _segment_dist2(q, pa, pb):
    """Squared distances of points q (N,3) to the segment pa-pb (lattice units)."""
    d = pb - pa
    dd = float(d @ d)
    t = np.zeros(len(q)) if dd == 0.0 else np.clip((q - pa) @ d / dd, 0.0, 1.0)
    r = q - (pa + t[:, None] * d)
    return np.einsum("ij,ij->i", r, r)


def segment_pieces(lat: Lattice, segs, chunk: int = 200_000):
    """Nodes of world segments (S,2,3): those within LINE_REACH dp of the segment.

    On an axis or a 45-degree diagonal through nodes this is one node per lattice step (a
    digital line, like Bresenham's); an oblique line takes a second node where it passes near
    the middle of two, as GenCase's do. Candidates are the 27 nodes around samples taken every
    dp/2 along the segment.
    """
    segs = np.asarray(segs, dtype=np.float64).reshape(-1, 2, 3)
    shape = np.array(lat.shape)
    found = []
    reach2 = LINE_REACH ** 2 + EPS
    for a, b in segs:
        ia, ib = lat.to_index(a), lat.to_index(b)
        r = _clip_segment(ia, ib, shape)
        if r is None:
            continue
        pa, pb = ia + r[0] * (ib - ia), ia + r[1] * (ib - ia)
        n = int(np.ceil(2.0 * np.linalg.norm(pb - pa) - EPS)) + 1
        for s0 in range(0, n, chunk):
            t = (np.arange(s0, min(s0 + chunk, n), dtype=np.float64) / max(n - 1, 1))[:, None]
            base = np.floor(pa + t * (pb - pa) + 0.5).astype(np.int64)
            cand = np.unique((base[:, None, :] + _NEIGHBOURS[None]).reshape(-1, 3), axis=0)
            ok = np.all((cand >= 0) & (cand < shape), axis=1)
            cand = cand[ok]
            cand = cand[_segment_dist2(cand.astype(np.float64), ia, ib) <= reach2]
            if len(cand):
                found.append(cand)
    if not found:
        return []
    return node_pieces(lat, np.unique(np.concatenate(found), axis=0))


def point_pieces(lat: Lattice, pts):
    return node_pieces(lat, nearest_nodes(lat, pts))


# ---------------------------------------------------------------- analytic shapes
def _shift_any(v: np.ndarray, axes) -> np.ndarray:
    """True where some face-neighbour (along the given axes) of the interior node is True."""
    core = tuple(slice(1, -1) if a in axes else slice(None) for a in range(3))
    out = np.zeros(v[core].shape, dtype=bool)
    for a in axes:
        for d in (-1, 1):
            sl = [slice(1, -1) if b in axes else slice(None) for b in range(3)]
            sl[a] = slice(1 + d, v.shape[a] - 1 + d)
            out |= v[tuple(sl)]
    return out


def analytic_pieces(lat: Lattice, matrix, local_min, local_max, constraints, *,
                    solid: bool, shell_faces):
    """Pieces of a shape given by inside constraints in its own frame.

    ``constraints(qx, qy, qz)`` returns one boolean array per face (True =
    on the inner side, boundary included). ``solid`` draws the inside nodes;
    ``shell_faces`` (indices of constraints) draws the inner shell attributed
    to those faces: inside nodes with a face-neighbour violating one of them.
    """
    corners = np.array([[x, y, z] for x in (local_min[0], local_max[0])
                        for y in (local_min[1], local_max[1]) for z in (local_min[2], local_max[2])])
    wc = tf.apply(matrix, corners)
    r = world_range(lat, wc, EPS)
    if r is None:
        return []
    lo, hi = r
    inv = tf.inverse(matrix)
    axes = (0, 2) if lat.is2d else (0, 1, 2)
    want_shell = bool(shell_faces)
    n_yz = int((hi[1] - lo[1] + 3) * (hi[2] - lo[2] + 3))
    slab = max(1, SLAB_NODES // max(n_yz, 1))
    pieces = []
    for x0 in range(int(lo[0]), int(hi[0]) + 1, slab):
        x1 = min(x0 + slab - 1, int(hi[0]))
        elo = np.array([x0, lo[1], lo[2]], dtype=np.int64)
        ehi = np.array([x1, hi[1], hi[2]], dtype=np.int64)
        for a in axes:
            elo[a] -= 1
            ehi[a] += 1
        X, Y, Z = lat.axis_coords(elo, ehi)
        if lat.is2d:
            Y = np.full_like(Y, lat.pointmin[1])
        qx = inv[0, 0] * X + inv[0, 1] * Y + inv[0, 2] * Z + inv[0, 3]
        qy = inv[1, 0] * X + inv[1, 1] * Y + inv[1, 2] * Z + inv[1, 3]
        qz = inv[2, 0] * X + inv[2, 1] * Y + inv[2, 2] * Z + inv[2, 3]
        cons = [np.broadcast_to(c, (X.shape[0], Y.shape[1], Z.shape[2]))
                for c in constraints(qx, qy, qz)]
        inside = cons[0].copy()
        for c in cons[1:]:
            inside &= c
        core = tuple(slice(1, -1) if a in axes else slice(None) for a in range(3))
        mask = inside[core].copy() if solid else np.zeros(inside[core].shape, dtype=bool)
        if want_shell:
            near_out = np.zeros(mask.shape, dtype=bool)
            for f in shell_faces:
                near_out |= _shift_any(~cons[f], axes)
            mask |= inside[core] & near_out
        if mask.any():
            pieces.append(Piece("mask", np.array([x0, lo[1], lo[2]], dtype=np.int64), mask=mask))
    return pieces
