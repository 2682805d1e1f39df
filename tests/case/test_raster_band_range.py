"""The planar-surface rule of sphdvi/case/draw/raster.py (a node belongs to a triangle when its
signed distance to the plane is within 1/2 and its projection within 1/2 of the triangle) was
applied only to the nodes within 0.5 of the triangle's bounding box. On a face oblique to the
lattice a node of the band lies up to ~0.71 beyond that box along an axis: 27 of 24,846 band
nodes of 200 random triangles were dropped (a helper's audit). The rule is now applied to every
node that can satisfy it; faces parallel to the lattice are unchanged."""
from __future__ import annotations

import numpy as np

from sphdvi.case.draw import kernels, raster
from sphdvi.case.draw.lattice import EPS, Lattice


def _nodes(pieces):
    out = set()
    for p in pieces:
        for idx in np.argwhere(p.mask):
            out.add(tuple(int(v) for v in idx + np.asarray(p.lo, dtype=np.int64)))
    return out


def _band_unclipped(lat, tri):
    """The same rule over a box 3 lattice units wider than the triangle on every side."""
    itri = np.ascontiguousarray(lat.to_index(tri.reshape(1, 3, 3)))
    lo = np.floor(itri.reshape(-1, 3).min(axis=0)).astype(np.int64) - 3
    hi = np.ceil(itri.reshape(-1, 3).max(axis=0)).astype(np.int64) + 3
    out = np.zeros(tuple(int(v) for v in hi - lo + 1), dtype=np.bool_)
    kernels.raster_triangles(itri, lo.astype(np.float64), out, -raster.SURFACE_HALF + EPS,
                             raster.SURFACE_HALF + EPS, raster.EDGE_REACH + EPS)
    return {tuple(int(v) for v in idx + lo) for idx in np.argwhere(out)}


def test_oblique_triangles_keep_every_band_node():
    lat = Lattice(1.0, (-20, -20, -20), (20, 20, 20))
    rng = np.random.default_rng(7)
    dropped = total = 0
    for _ in range(200):
        tri = rng.uniform(-6, 6, size=(3, 3))
        got = _nodes(raster.triangle_pieces(lat, tri[None]))
        want = _band_unclipped(lat, tri)
        dropped += len(want - got)
        total += len(want)
        assert got <= want
    assert total > 5000 and dropped == 0, (dropped, total)


def test_axis_aligned_face_unchanged():
    """A face in the plane x = 2.3 over y, z in [0, 4]: the node layer x = 2, y and z 0..4."""
    lat = Lattice(1.0, (-10, -10, -10), (10, 10, 10))
    quad = np.array([[[2.3, 0, 0], [2.3, 4, 0], [2.3, 4, 4]], [[2.3, 0, 0], [2.3, 4, 4], [2.3, 0, 4]]])
    got = _nodes(raster.triangle_pieces(lat, quad))
    origin = np.round(lat.to_index(np.zeros(3))).astype(int)
    want = {(int(origin[0]) + 2, int(origin[1]) + j, int(origin[2]) + k) for j in range(5) for k in range(5)}
    assert got == want
