"""The mDBC normals a case sets itself, as GenCase's ``<normals>`` and DualSPHysics's
``<special><initialize>`` define them.

A normal N is the vector from a boundary particle to the boundary surface; the ghost node
of mDBC is r + 2N (English et al. 2022, "Modified dynamic boundary conditions (mDBC) for
general-purpose SPH"). Each operation selects boundary particles (fixed, moving and
floating: its ``mkbound`` list, every one without a list; its ``onlypos`` box) and sets
their N from a surface it describes:

* ``set``: one vector for all.
* ``plane``: the foot of the perpendicular on the plane (point, normal); within
  ``maxdisth`` h of it. Without a point (``auto``), the plane lies ``limitdist`` dp in front
  of the outermost particles of each listed mk along the normal.
* ``sphere`` and ``cylinder`` (two end centres, radius, optional end caps): the nearest
  point of the surface, for particles inside it (``inside``) or outside it.
* ``parts``: the normals sphdvi derives from the particle arrangement
  (:func:`sphdvi.case.normals.boundary_normals`), within ``maxdisth`` h.
* ``geometry``: the nearest point of a triangle surface (GenCase's ``norgeometry`` over the
  ``GeometryForNormals`` shapes drawn dp/2 in front of the walls), within ``distanceh`` h;
  in 2D the surface is cut by the particles' plane and the nearest point is on the cut.

With ``clear`` (the default), selected particles out of reach of the surface lose any
normal an earlier operation gave them (they keep DBC). The operations run in document
order, so a later one overrides an earlier one where both reach.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .mkrange import parse_mk_range
from .normals import _cell_span, _grid_keys

AXIS_TOLERANCE = 1e-7       # a plane normal this close to an axis is that axis (DualSPHysics's test)


def unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=np.float64)
    n = float(np.linalg.norm(v))
    if n == 0.0:
        raise ValueError("the vector is zero")
    return v / n


def selection(op: dict, pos: np.ndarray, ptype: np.ndarray, mkbound: np.ndarray) -> np.ndarray:
    """The boundary particles ``op`` acts on: its mkbound list (all without one), inside its
    onlypos box (bounds inclusive; a missing bound is open)."""
    sel = np.asarray(ptype) != 3
    listed = str(op.get("mkbound") or "").strip()
    if listed:
        sel &= np.isin(mkbound, np.asarray(parse_mk_range(listed), dtype=np.int64))
    return sel & onlypos_mask(pos, op.get("onlypos"))


def onlypos_mask(pos: np.ndarray, box: dict | None) -> np.ndarray:
    """The particles inside an ``onlypos`` box ({"posmin": [...], "posmax": [...]}, bounds
    inclusive, None an open side); all of them without a box."""
    inside = np.ones(len(pos), dtype=bool)
    for k in range(3):
        lo, hi = (box["posmin"][k], box["posmax"][k]) if box else (None, None)
        if lo is not None:
            inside &= pos[:, k] >= lo
        if hi is not None:
            inside &= pos[:, k] <= hi
    return inside


def _write(normals, sel, reached, vectors, clear: bool) -> None:
    """N of the selected particles that the surface reaches; zero for the others with ``clear``."""
    hit = sel.copy()
    hit[sel] = reached
    normals[hit] = vectors[reached]
    if clear:
        normals[sel & ~hit] = 0.0


def _reach(maxdisth: float, h: float) -> float:
    """``maxdisth`` h, a particle at that distance included (with 1e-9 of it for round-off: two
    mirror walls reached the same rows only on one side); no limit for maxdisth <= 0
    (DualSPHysics)."""
    return maxdisth * h * (1.0 + 1e-9) if maxdisth > 0 else np.inf


def plane_point_auto(normal: np.ndarray, shown: np.ndarray, whole: np.ndarray, limit: float) -> np.ndarray:
    """The point of an ``auto`` plane for one mk: at the middle of the extent of its particles
    that the onlypos box keeps (``shown``), ``limit`` in front of them along ``normal``: of
    their bounding box's face for a normal along an axis, of the farthest of all the mk's
    particles (``whole``) otherwise (DualSPHysics's JDsInitializeOp_BoundNormalPlane)."""
    lo, hi = shown.min(axis=0), shown.max(axis=0)
    mid = 0.5 * (lo + hi)
    for k in range(3):
        for sign in (1.0, -1.0):
            axis = np.zeros(3)
            axis[k] = sign
            if np.all(np.abs(normal - axis) <= AXIS_TOLERANCE):
                point = mid.copy()
                point[k] = hi[k] + limit if sign > 0 else lo[k] - limit
                return point
    ahead = float(np.max((whole - mid) @ normal))
    return mid + normal * (ahead + limit)


def apply_plane(normals, op, pos, ptype, sel, mkbound, dp, h) -> None:
    n = unit(op["normal"])
    reach = _reach(op["maxdisth"], h)
    if op.get("point") is not None:
        groups = [(sel, np.asarray(op["point"], dtype=np.float64))]
    else:
        groups = []
        for v in parse_mk_range(str(op.get("mkbound") or "")):
            group = sel & (mkbound == v)
            if group.any():
                whole = pos[(np.asarray(ptype) != 3) & (mkbound == v)]
                groups.append((group, plane_point_auto(n, pos[group], whole, op["limitdist"] * dp)))
    for group, point in groups:
        depth = (pos[group] - point) @ n
        _write(normals, group, np.abs(depth) <= reach, -depth[:, None] * n[None, :], op["clear"])


def apply_sphere(normals, op, pos, sel, h) -> None:
    c = np.asarray(op["center"], dtype=np.float64)
    radius = float(op["radius"])
    reach = _reach(op["maxdisth"], h)
    r = pos[sel]
    off = r - c
    dist = np.linalg.norm(off, axis=1)
    to_surface = radius - dist                      # > 0 inside
    if op["inside"]:
        reached = (to_surface > 0) & (to_surface <= reach)
    else:
        reached = (to_surface < 0) & (-to_surface <= reach)
    with np.errstate(invalid="ignore", divide="ignore"):
        foot = c + off * (radius / np.where(dist > 0, dist, 1.0))[:, None]
    _write(normals, sel, reached, foot - r, op["clear"])


def apply_cylinder(normals, op, pos, sel, h) -> None:
    """The nearest point of a cylinder's surface (side, and the end caps ``limit1`` at
    center1 and ``limit2`` at center2): inside it, the nearer of the side and the nearer
    cap, the rim where the two are equally near (within h/100); outside it, the side, the
    cap plane or the rim that the particle lies beyond."""
    c1 = np.asarray(op["center1"], dtype=np.float64)
    c2 = np.asarray(op["center2"], dtype=np.float64)
    radius = float(op["radius"])
    reach = _reach(op["maxdisth"], h)
    tol = 0.01 * h
    out1 = unit(c1 - c2)                            # out through cap 1
    out2 = -out1                                    # out through cap 2
    r = pos[sel]
    d_cap1 = (r - c1) @ out2                        # along the axis from cap 1; > 0 on its inner side
    axis_pt = c1 + d_cap1[:, None] * out2[None, :]
    radial = r - axis_pt
    rdist = np.linalg.norm(radial, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        side = axis_pt + radial * (radius / np.where(rdist > 0, rdist, 1.0))[:, None]
    d_side = radius - rdist                         # > 0 inside the side
    d_cap2 = (r - c2) @ out1                        # > 0 on the inner side of cap 2
    foot = np.full_like(r, np.nan)
    if op["inside"]:
        inside = (d_side > 0) & (d_cap1 > 0) & (d_cap2 > 0)
        near = inside & ((d_side <= reach) | (d_cap1 <= reach) | (d_cap2 <= reach))
        nearer1 = d_cap1 <= d_cap2
        for this_cap, cap_d, out, limited in ((near & nearer1, d_cap1, out1, op["limit1"]),
                                              (near & ~nearer1, d_cap2, out2, op["limit2"])):
            if not limited:                         # an open end: the side only
                pick = this_cap & (d_side <= reach)
                foot[pick] = side[pick]
                continue
            rim = this_cap & (np.abs(d_side - cap_d) <= tol)
            to_side = this_cap & ~rim & (d_side < cap_d)
            to_cap = this_cap & ~rim & ~to_side
            foot[rim] = side[rim] + out * cap_d[rim, None]
            foot[to_side] = side[to_side]
            foot[to_cap] = r[to_cap] + out * cap_d[to_cap, None]
    else:
        beyond = (d_side < 0) | (d_cap1 < 0) | (d_cap2 < 0)
        near = beyond & (((d_side < 0) & (-d_side <= reach)) | ((d_cap1 < 0) & (-d_cap1 <= reach))
                         | ((d_cap2 < 0) & (-d_cap2 <= reach)))
        out_side = near & (d_side < 0)
        rim1 = out_side & (d_cap1 < 0)
        rim2 = out_side & ~rim1 & (d_cap2 < 0)
        flank = out_side & ~rim1 & ~rim2
        cap1 = near & ~out_side & (d_cap1 < 0)
        cap2 = near & ~out_side & ~cap1 & (d_cap2 < 0)
        foot[rim1] = side[rim1] + out1 * d_cap1[rim1, None]
        foot[rim2] = side[rim2] + out2 * d_cap2[rim2, None]
        foot[flank] = side[flank]
        foot[cap1] = r[cap1] + out1 * d_cap1[cap1, None]
        foot[cap2] = r[cap2] + out2 * d_cap2[cap2, None]
    reached = ~np.isnan(foot[:, 0])
    _write(normals, sel, reached, np.where(reached[:, None], foot - r, 0.0), op["clear"])


# ------------------------------------------------------------------ triangle surfaces
@njit(cache=True)
def _dot(u, v):
    return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]


@njit(cache=True)
def _nearest_on_triangle(p, a, b, c):
    """The point of triangle abc nearest to p, from the Voronoi region of p (vertex, edge or
    face) found with the dot products of its offsets along the two edges from a."""
    ab = b - a
    ac = c - a
    ap = p - a
    d1 = _dot(ab, ap)
    d2 = _dot(ac, ap)
    if d1 <= 0.0 and d2 <= 0.0:
        return a.copy()
    bp = p - b
    d3 = _dot(ab, bp)
    d4 = _dot(ac, bp)
    if d3 >= 0.0 and d4 <= d3:
        return b.copy()
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        return a + ab * (d1 / (d1 - d3))
    cp = p - c
    d5 = _dot(ab, cp)
    d6 = _dot(ac, cp)
    if d6 >= 0.0 and d5 <= d6:
        return c.copy()
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        return a + ac * (d2 / (d2 - d6))
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and d4 - d3 >= 0.0 and d5 - d6 >= 0.0:
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))
    total = va + vb + vc
    return a + ab * (vb / total) + ac * (vc / total)


@njit(cache=True)
def _nearest_on_segment(p, a, b):
    ab = b - a
    len2 = _dot(ab, ab)
    if len2 == 0.0:
        return a.copy()
    t = min(max(_dot(p - a, ab) / len2, 0.0), 1.0)
    return a + ab * t


@njit(cache=True)
def _nearest_surface(pos, pmk, own, prims, prim_mk, segments, reach):
    """For each particle, the vector to the nearest primitive (triangles, or segments stored
    as (a, b, b)) within ``reach``, zero where none is, and whether one is. A particle with
    ``own`` set only sees primitives of its mk ``pmk``."""
    n = pos.shape[0]
    out = np.zeros((n, 3))
    found = np.zeros(n, np.bool_)
    if n == 0:
        return out, found
    best = np.full(n, reach * reach)
    lo = np.empty(3)
    hi = np.empty(3)
    for k in range(3):
        lo[k] = pos[:, k].min() - reach
        hi[k] = pos[:, k].max() + reach
    inv = 1.0 / reach
    nx = int((hi[0] - lo[0]) * inv) + 1
    ny = int((hi[1] - lo[1]) * inv) + 1
    nz = int((hi[2] - lo[2]) * inv) + 1
    keys = _grid_keys(pos, inv, lo, nx, ny)
    order = np.argsort(keys)
    sorted_keys = keys[order]
    cmin = np.empty(3, np.int64)
    cmax = np.empty(3, np.int64)
    ncell = (nx, ny, nz)
    for t in range(prims.shape[0]):
        a = prims[t, 0]
        b = prims[t, 1]
        c = prims[t, 2]
        for k in range(3):
            pmin = min(a[k], b[k], c[k]) - reach
            pmax = max(a[k], b[k], c[k]) + reach
            cmin[k] = max(int(np.floor((pmin - lo[k]) * inv)), 0)
            cmax[k] = min(int(np.floor((pmax - lo[k]) * inv)), ncell[k] - 1)
        for iz in range(cmin[2], cmax[2] + 1):
            for iy in range(cmin[1], cmax[1] + 1):
                for ix in range(cmin[0], cmax[0] + 1):
                    s, e = _cell_span(sorted_keys, ix, iy, iz, nx, ny)
                    for q in range(s, e):
                        i = order[q]
                        if own[i] and pmk[i] != prim_mk[t]:
                            continue
                        p = pos[i]
                        if segments:
                            f = _nearest_on_segment(p, a, b)
                        else:
                            f = _nearest_on_triangle(p, a, b, c)
                        d = f - p
                        d2 = _dot(d, d)
                        if d2 < best[i] or (not found[i] and d2 <= best[i]):
                            best[i] = d2
                            found[i] = True
                            out[i] = d
    return out, found


@njit(cache=True)
def _plane_cuts(tris, y0, tol):
    t_count = tris.shape[0]
    segs = np.zeros((t_count, 3, 3))
    src = np.zeros(t_count, np.int64)
    m = 0
    for t in range(t_count):
        v = tris[t]
        d = np.empty(3)
        on = np.zeros(3, np.bool_)
        for k in range(3):
            d[k] = v[k, 1] - y0
            on[k] = abs(d[k]) <= tol
        non = on[0] + on[1] + on[2]
        a = np.empty(3)
        b = np.empty(3)
        if non == 3:                            # in the plane: a face (no cut) or a flat wall
            e1 = v[1] - v[0]
            e2 = v[2] - v[0]
            cx = e1[1] * e2[2] - e1[2] * e2[1]
            cy = e1[2] * e2[0] - e1[0] * e2[2]
            cz = e1[0] * e2[1] - e1[1] * e2[0]
            if np.sqrt(cx * cx + cy * cy + cz * cz) > tol * tol:
                continue
            best = -1.0
            for i in range(3):
                j = (i + 1) % 3
                w = v[j] - v[i]
                ln = w[0] * w[0] + w[1] * w[1] + w[2] * w[2]
                if ln > best:
                    best = ln
                    a[:] = v[i]
                    b[:] = v[j]
        else:
            ends = np.empty((3, 3))
            ne = 0
            for k in range(3):
                if on[k]:
                    ends[ne] = v[k]
                    ne += 1
            for i in range(3):
                j = (i + 1) % 3
                if not on[i] and not on[j] and d[i] * d[j] < 0.0:
                    w = d[i] / (d[i] - d[j])
                    ends[ne] = v[i] + w * (v[j] - v[i])
                    ne += 1
            if ne < 2:                          # no cut, or a vertex touching the plane
                continue
            a[:] = ends[0]
            b[:] = ends[1]
        a[1] = y0
        b[1] = y0
        segs[m, 0] = a
        segs[m, 1] = b
        segs[m, 2] = b
        src[m] = t
        m += 1
    return segs[:m].copy(), src[:m].copy()


def plane_cuts(tris: np.ndarray, y0: float, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """The segments where the plane y = y0 cuts the triangles (T, 3, 3): (S, 3, 3) rows
    (a, b, b) and the index of the triangle of each. A triangle lying in the plane is left
    out (a face parallel to a 2D case's plane has no cut), unless it has no area (a wall
    drawn with no depth: its longest edge); so is one that touches it at a vertex only."""
    return _plane_cuts(np.ascontiguousarray(tris, dtype=np.float64), float(y0), float(tol))


# a normal shorter than this many h is a particle on the surface (rounding noise of a zero vector)
ON_SURFACE_H = 1e-9


def apply_geometry(normals, op, pos, sel, mkbound, h, is2d, posy2d, triangles, tri_mk) -> dict:
    """N to the nearest point of the triangle surface within ``distanceh`` h. Where the
    surface carries the mk it was drawn with (sphdvi's and GenCase's shape files), a
    particle whose mkbound drew part of it sees that part only; the others see all of it.
    ``maxsizeh`` (GenCase's maximum normal size, in h; 0: none) leaves a particle whose normal
    would be longer without one.  A particle on the surface (closer than ON_SURFACE_H h) has
    no normal either: its direction is undefined (noise of order 1e-16 m otherwise gave it a
    ghost node on itself).  Returns mkbound -> how many selected particles lie on the surface."""
    reach = op["distanceh"] * h
    if op.get("maxsizeh", 0.0) > 0:
        reach = min(reach, op["maxsizeh"] * h)
    tris = np.ascontiguousarray(triangles, dtype=np.float64).reshape(-1, 3, 3)
    mk = np.full(len(tris), -1, np.int64) if tri_mk is None else np.asarray(tri_mk, dtype=np.int64)
    if is2d:
        prims, src = plane_cuts(tris, posy2d, 1e-9 * max(1.0, float(np.abs(tris).max(initial=1.0))))
        prim_mk = mk[src]
    else:
        area = np.linalg.norm(np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]), axis=1)
        keep = area > 0.0
        prims, prim_mk = tris[keep], mk[keep]
    r = np.ascontiguousarray(pos[sel], dtype=np.float64)
    pmk = np.ascontiguousarray(mkbound[sel], dtype=np.int64)
    own = np.isin(pmk, prim_mk[prim_mk >= 0]) if tri_mk is not None else np.zeros(len(r), bool)
    if not len(prims):
        normals[sel] = 0.0
        return {}
    vec, found = _nearest_surface(r, pmk, own, np.ascontiguousarray(prims), np.ascontiguousarray(prim_mk),
                                  bool(is2d), float(reach))
    off = np.linalg.norm(vec, axis=1) > ON_SURFACE_H * h
    _write(normals, sel, off, vec, True)
    mks, counts = np.unique(pmk[found & ~off], return_counts=True)
    return {int(m): int(c) for m, c in zip(mks, counts)}


def apply_normal_ops(normals: np.ndarray, ops: list, pos: np.ndarray, ptype: np.ndarray,
                     mkbound: np.ndarray, *, dp: float, h: float, is2d: bool, posy2d: float = 0.0,
                     geometry=None, computed=None, on_surface: list | None = None) -> list:
    """Apply ``ops`` (dicts of :mod:`sphdvi.case.normals_xml`) in order to ``normals`` (N, 3),
    in place. ``geometry(op)`` gives a geometry op's (triangles, their mk or None);
    ``computed()`` the normals derived from the particles (for ``parts``). Returns the ops
    that selected no particle; appends to ``on_surface`` (op, {mkbound: count}) for each
    geometry op whose surface passes through particles (:func:`apply_geometry`)."""
    pos = np.asarray(pos, dtype=np.float64)
    empty = []
    for op in ops:
        sel = selection(op, pos, ptype, mkbound)
        if not sel.any():
            empty.append(op)
            continue
        kind = op["kind"]
        if kind == "set":
            normals[sel] = np.asarray(op["normal"], dtype=np.float64)
        elif kind == "plane":
            apply_plane(normals, op, pos, ptype, sel, mkbound, dp, h)
        elif kind == "sphere":
            apply_sphere(normals, op, pos, sel, h)
        elif kind == "cylinder":
            apply_cylinder(normals, op, pos, sel, h)
        elif kind == "parts":
            vec = computed()[sel]
            _write(normals, sel, np.linalg.norm(vec, axis=1) <= _reach(op["maxdisth"], h), vec, True)
        elif kind == "geometry":
            tris, tri_mk = geometry(op)
            through = apply_geometry(normals, op, pos, sel, mkbound, h, is2d, posy2d, tris, tri_mk)
            if through and on_surface is not None:
                on_surface.append((op, through))
        else:
            raise ValueError(f"unknown normals operation {kind!r}")
        if is2d:
            normals[sel, 1] = 0.0
    return empty
