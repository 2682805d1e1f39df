"""Primitive shapes: their nodes (via :mod:`raster`), world-frame parameters and a
triangle tessellation (for ``<shapeout>``).

Every builder takes the current transformation matrix ``m`` and returns
``(pieces, params, triangles)``.
"""
from __future__ import annotations

import math

import numpy as np

from . import raster
from . import transform as tf
from .lattice import EPS, Lattice

NSIDES = 24


# ---------------------------------------------------------------- helpers
def polygon_triangles(pts: np.ndarray) -> list[tuple[int, int, int]]:
    """Triangulate a planar simple polygon (ear clipping); falls back to a fan."""
    n = len(pts)
    if n < 3:
        return []
    # Newell normal, then project on the dominant plane
    nrm = np.zeros(3)
    for i in range(n):
        a, b = pts[i], pts[(i + 1) % n]
        nrm += np.array([(a[1] - b[1]) * (a[2] + b[2]), (a[2] - b[2]) * (a[0] + b[0]),
                         (a[0] - b[0]) * (a[1] + b[1])])
    if not np.linalg.norm(nrm) > 0:
        return []
    drop = int(np.argmax(np.abs(nrm)))
    keep = [i for i in range(3) if i != drop]
    p2 = pts[:, keep]
    # the projection is counter-clockwise when the normal points along keep[0] x keep[1]
    if nrm[drop] * (-1.0 if drop == 1 else 1.0) < 0:
        p2 = p2[:, ::-1]

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    idx = list(range(n))
    tris = []
    guard = 0
    while len(idx) > 3 and guard < 10 * n * n:
        guard += 1
        m = len(idx)
        for k in range(m):
            i0, i1, i2 = idx[(k - 1) % m], idx[k], idx[(k + 1) % m]
            if cross(p2[i0], p2[i1], p2[i2]) <= 0:
                continue
            ear = True
            for j in idx:
                if j in (i0, i1, i2):
                    continue
                if (cross(p2[i0], p2[i1], p2[j]) >= 0 and cross(p2[i1], p2[i2], p2[j]) >= 0
                        and cross(p2[i2], p2[i0], p2[j]) >= 0):
                    ear = False
                    break
            if ear:
                tris.append((i0, i1, i2))
                idx.pop(k)
                break
        else:
            break
    if len(idx) == 3:
        tris.append(tuple(idx))
    elif len(idx) > 3:  # not simple: fan the rest
        tris.extend((idx[0], idx[k], idx[k + 1]) for k in range(1, len(idx) - 1))
    return tris


def faces_to_triangles(verts: np.ndarray, faces) -> np.ndarray:
    tris = []
    for f in faces:
        for t in polygon_triangles(verts[list(f)]):
            tris.append(verts[[f[t[0]], f[t[1]], f[t[2]]]])
    return np.array(tris, dtype=np.float64).reshape(-1, 3, 3)


def face_edges(faces):
    edges = set()
    for f in faces:
        for i in range(len(f)):
            a, b = f[i], f[(i + 1) % len(f)]
            edges.add((min(a, b), max(a, b)))
    return sorted(edges)


def local_tol(m: np.ndarray, dp: float) -> float:
    """EPS lattice units expressed in the shape's own frame."""
    return reach_local(m, EPS * dp)


def reach_local(m: np.ndarray, reach: float) -> float:
    """A world distance ``reach`` in the frame of ``m`` (its smallest scale)."""
    sv = np.linalg.svd(m[:3, :3], compute_uv=False)
    return reach / max(float(sv.min()), 1e-300)


def drawn_faces(hidden, count: int) -> list[bool]:
    """Which of ``count`` faces are drawn: face i (0-based) is hidden when its GenCase number
    i + 1 is listed in ``hidden`` (the ``mask`` attribute; numbers beyond ``count`` hide nothing)."""
    return [(i + 1) not in hidden for i in range(count)]


# ---------------------------------------------------------------- box
BOX_FACES = {  # local corners of each face, outward order
    "left": (0, 2, 3, 1), "right": (4, 5, 7, 6), "front": (0, 1, 5, 4),
    "back": (2, 6, 7, 3), "bottom": (0, 4, 6, 2), "top": (1, 3, 7, 5)}


def box_corners(size) -> np.ndarray:
    sx, sy, sz = size
    return np.array([[x, y, z] for x in (0.0, sx) for y in (0.0, sy) for z in (0.0, sz)])


def _world_faces(full, faces) -> list:
    """The world faces of an axis-aligned box's local ``faces`` (axes may be permuted, a
    negative scale swaps sides)."""
    lin = full[:3, :3]
    out = []
    for f in faces:
        axis, side = raster.FACE_AXIS[f]
        waxis = int(np.argmax(np.abs(lin[:, axis])))
        if lin[waxis, axis] < 0:
            side = 1 - side
        out.append([n for n, (a, s) in raster.FACE_AXIS.items() if a == waxis and s == side][0])
    return out


def _box_pieces(lat: Lattice, full, size, solid: bool, faces, wire: bool, base=None) -> list:
    """Pieces of the box ``box_corners(size)`` under the transform ``full``. ``base`` (full,
    size): the box this one is a ``<layers>`` copy of; an axis-aligned copy is then the base's
    corners mapped to the lattice and moved there by the layer's offset, a whole number of dp or
    half (rounded to 1e-9 dp): each layer lies the same whole number of nodes from the first,
    whatever side of a half-way tie the first falls (moved in world coordinates, the F2_SLOT
    tank's face at 26.5 lattice units took node 27, its layer dp out, at 25.499999999999996,
    node 25: a wall with the layer between missing)."""
    verts = tf.apply(full, box_corners(size))
    pieces = []
    if tf.is_axis_aligned(full):
        corners, shift = verts, None
        if base is not None:
            corners = tf.apply(base[0], box_corners(base[1]))
            shift = (np.round((verts.min(axis=0) - corners.min(axis=0)) / lat.dp, 9),
                     np.round((verts.max(axis=0) - corners.max(axis=0)) / lat.dp, 9))
        pieces = raster.aligned_box_pieces(lat, corners.min(axis=0), corners.max(axis=0), solid,
                                           _world_faces(full, faces), wire, shift=shift)
    else:
        if solid:
            # the box widened by dp/2 along its own axes, (min - dp/2, max + dp/2] like GenCase
            tol = local_tol(full, lat.dp)
            half = 0.5 * lat.dp / np.maximum(np.linalg.norm(full[:3, :3], axis=0), 1e-300)
            lo = -half + tol
            hi = np.asarray(size, dtype=np.float64) + half + tol

            def cons(qx, qy, qz):
                return [(qx > lo[0]) & (qx <= hi[0]) & (qy > lo[1]) & (qy <= hi[1])
                        & (qz > lo[2]) & (qz <= hi[2])]
            pieces += raster.analytic_pieces(lat, full, lo, hi, cons, solid=True, shell_faces=())
        if faces:
            tris = faces_to_triangles(verts, [BOX_FACES[f] for f in faces])
            pieces += raster.triangle_pieces(lat, tris)
        if wire:
            segs = [verts[[a, b]] for a, b in face_edges(BOX_FACES.values())]
            pieces += raster.segment_pieces(lat, segs)
    return pieces


def draw_box(lat: Lattice, m, point, size, angles, *, solid: bool, faces, wire: bool,
             grow: float = 0.0):
    """A box with a corner at ``point`` and edges ``size`` (rotated by ``angles`` about
    ``point``), drawn ``grow`` outwards (``<layers>``): a solid box (or its wire frame) widened by
    ``grow`` on every side; each drawn face moved ``grow`` along its normal and widened by
    ``grow`` towards each neighbouring face that is drawn (not towards an open side), so the
    layers of a tank close its edges and corners and its walls do not rise at an open top.
    GenCase's records: a floor (``boxfill bottom``) with ``<layers vdp="0,1,2">``, 3 equal layers
    (a yzhao469/DualSPHysicsAgent_v1 run, GenCase v5.0: 3 x 470^2); a ``boxfill all`` 2D tank,
    closed rings of 1410 + 8k particles (feynman0406/DualSPHysicsGPT CaseSloshingHR, GenCase
    v5.4); an ``all^top`` 3D tank (yupengxiang/DualSPHysics F1_DUAL_FINITE_CENTER, GenCase v5.4:
    361,104, walls ending at their layer-0 top). An axis-aligned layer is placed on the lattice
    as a whole number of nodes from the first (:func:`_box_pieces`). The recorded shape
    (shapeout, ``norgeometry``) is the box widened on every side, with the faces drawn (all six
    for a solid box or a wire frame)."""
    full = m @ tf.translation(point)
    if angles is not None and np.any(angles != 0):
        full = full @ tf.rotation_xyz(angles)
    size = np.asarray(size, dtype=np.float64)
    pieces = []
    moved_faces = bool(grow) and bool(faces) and not solid and not wire
    base = (full, size)          # the box its <layers> copies are placed from
    if moved_faces:
        drawn = {raster.FACE_AXIS[f] for f in faces}
        for f in faces:
            axis, _ = raster.FACE_AXIS[f]
            lo, hi = np.zeros(3), size.copy()
            for a in range(3):
                if a == axis or (a, 0) in drawn:
                    lo[a] -= grow
                if a == axis or (a, 1) in drawn:
                    hi[a] += grow
            pieces += _box_pieces(lat, full @ tf.translation(lo), hi - lo, False, [f], False, base=base)
    if grow:
        full = full @ tf.translation([-grow] * 3)
        size = size + 2.0 * grow
    if not moved_faces:
        pieces = _box_pieces(lat, full, size, solid, faces, wire, base=base if grow else None)
    verts = tf.apply(full, box_corners(size))
    lin = full[:3, :3]
    edge_len = np.linalg.norm(lin, axis=0)
    params = {"vertices": verts.tolist(), "center": verts.mean(axis=0).tolist(),
              "size": (edge_len * np.abs(np.asarray(size, dtype=np.float64))).tolist(),
              "axes": (lin / np.where(edge_len > 0, edge_len, 1.0)).T.tolist(),
              "local_size": [abs(float(v)) for v in size], "matrix": full.tolist(),
              "axis_aligned": tf.is_axis_aligned(full)}
    if params["axis_aligned"]:
        params["min"] = verts.min(axis=0).tolist()
        params["max"] = verts.max(axis=0).tolist()
    # the recorded shape (shapeout, norgeometry) holds the faces drawn: an open tank's missing lid
    # is no wall for the normals of the particles under it (DualSPHysics's mdbc/04 CaseDamBreak3D
    # picks each box's faces for its normals geometry: all^bottom for the obstacle, all^top^right
    # for the tank)
    shown = list(BOX_FACES) if solid or wire or not faces else [f for f in BOX_FACES if f in faces]
    tris = faces_to_triangles(verts, [BOX_FACES[f] for f in shown])
    return pieces, params, tris


# ---------------------------------------------------------------- sphere / ellipsoid
def unit_sphere_triangles(n: int = NSIDES) -> np.ndarray:
    th = np.linspace(0, math.pi, n // 2 + 1)
    ph = np.linspace(0, 2 * math.pi, n + 1)
    P = np.stack([np.sin(th)[:, None] * np.cos(ph)[None, :],
                  np.sin(th)[:, None] * np.sin(ph)[None, :],
                  np.cos(th)[:, None] * np.ones_like(ph)[None, :]], axis=-1)
    tris = []
    for i in range(len(th) - 1):
        for j in range(len(ph) - 1):
            a, b, c, d = P[i, j], P[i + 1, j], P[i + 1, j + 1], P[i, j + 1]
            if i > 0:
                tris.append([a, b, d])
            if i < len(th) - 2:
                tris.append([b, c, d])
    return np.array(tris)


#: How far (in dp) beyond its surface a closed sphere, ellipsoid or cylinder is filled in ``full``
#: mode. GenCase's records: the 2D CaseBowling ball (drawcylinder r 0.25 m at dp 0.01, GenCase
#: v5.0.278c: 2061 particles, inertia v11 6.76028 kg m^2) and a RootSPHysicsV2_DB case (cylinders of
#: r 2 and 1 and a sphere of r 1 at dp 0.1, GenCase4 v4.0.062: 630 fixed, 1760 fluid) are the nodes
#: within r + t dp for every t in [0.56, 0.61] (within r: 1961, 610 and 1587). ``solid`` mode keeps
#: the nodes within r (no record tells), ``face`` the inner shell.
CURVED_FULL_REACH = 0.6


def draw_ellipsoid(lat: Lattice, m, center, radii, *, solid: bool, shell: bool, frame=None,
                   reach: float = 0.0):
    """An ellipsoid with semi-axes ``radii`` along the axes of ``frame`` (default: x, y, z); its
    volume drawn ``reach`` (world units) beyond its surface (``full`` mode, see CURVED_FULL_REACH)."""
    center = np.asarray(center, dtype=np.float64)
    radii = np.asarray(radii, dtype=np.float64)
    rot = m @ tf.translation(center) @ (frame if frame is not None else np.eye(4))
    full = rot @ tf.scaling(radii)
    drawn = rot @ tf.scaling(radii + reach_local(rot, reach)) if reach else full
    tol = local_tol(drawn, lat.dp)

    def cons(qx, qy, qz):
        return [qx * qx + qy * qy + qz * qz <= (1.0 + tol) ** 2]
    pieces = raster.analytic_pieces(lat, drawn, -np.ones(3), np.ones(3), cons, solid=solid,
                                    shell_faces=(0,) if shell else ())
    tris = tf.apply(full, unit_sphere_triangles())
    return pieces, full, tris


def draw_sphere(lat, m, center, radius, *, solid, shell, reach: float = 0.0):
    pieces, full, tris = draw_ellipsoid(lat, m, center, [radius] * 3, solid=solid, shell=shell,
                                        reach=reach)
    s = tf.uniform_scale(m)
    params = {"center": tf.apply(m, center).tolist(),
              "radius": float(radius * s) if s is not None else None,
              "local_radius": float(radius), "matrix": m.tolist()}
    return pieces, params, tris


def draw_ellipsoid_axes(lat, m, center, radii, *, solid, shell, frame=None, reach: float = 0.0):
    pieces, full, tris = draw_ellipsoid(lat, m, center, radii, solid=solid, shell=shell,
                                        frame=frame, reach=reach)
    lin = full[:3, :3]
    world_radii = np.linalg.norm(lin, axis=0)  # full = m @ T @ frame @ diag(radii)
    params = {"center": tf.apply(m, center).tolist(), "radii": world_radii.tolist(),
              "axes": (lin / world_radii).T.tolist(), "local_radii": [float(r) for r in radii],
              "matrix": full.tolist()}
    return pieces, params, tris


def frame_x_to(u) -> np.ndarray:
    """A rotation matrix taking the x axis onto the unit vector u."""
    u = np.asarray(u, dtype=np.float64)
    v = np.cross([1.0, 0.0, 0.0], u)
    s, cth = float(np.linalg.norm(v)), float(u[0])
    if s > 1e-15:
        return tf.rotation_axis(math.degrees(math.atan2(s, cth)), v)
    return tf.rotation_axis(180.0, (0, 0, 1)) if cth < 0 else np.eye(4)


def foci_ellipsoid(f1, f2, radius):
    """Centre, frame and semi-axes of the ellipsoid of revolution |p-f1|+|p-f2| <= 2*radius."""
    f1, f2 = np.asarray(f1, dtype=np.float64), np.asarray(f2, dtype=np.float64)
    c = 0.5 * float(np.linalg.norm(f2 - f1))
    if not radius > c:
        raise ValueError(f"radius {radius:g} must exceed half the distance between the two "
                         f"points ({c:g})")
    b = math.sqrt(radius * radius - c * c)
    frame = frame_x_to((f2 - f1) / (2 * c)) if c > 0 else np.eye(4)
    return 0.5 * (f1 + f2), frame, np.array([radius, b, b])


# ---------------------------------------------------------------- cylinder
def draw_cylinder(lat: Lattice, m, p1, p2, radius, *, solid: bool, shell: bool, mask=frozenset(),
                  reach: float = 0.0):
    """Cylinder of axis p1->p2. Faces (numbers listed in mask are hidden): 1 = cover at p1,
    2 = cover at p2, 3 = side (tube). ``shell`` draws the inner shell of the faces not hidden;
    the volume is drawn ``reach`` (world units) beyond the tube and the covers (``full`` mode,
    see CURVED_FULL_REACH)."""
    p1, p2 = np.asarray(p1, dtype=np.float64), np.asarray(p2, dtype=np.float64)
    L = float(np.linalg.norm(p2 - p1))
    if not L > 0:
        raise ValueError("the two points of the cylinder axis coincide")
    local = tf.translation(p1) @ frame_x_to((p2 - p1) / L)  # local x in [0, L] along the axis
    full = m @ local
    tol = local_tol(full, lat.dp) + (reach_local(full, reach) if reach else 0.0)

    def cons(qx, qy, qz):
        return [qx >= -tol, qx <= L + tol, qy * qy + qz * qz <= (radius + tol) ** 2]
    drawn = drawn_faces(mask, 3)
    shell_faces = tuple(i for i in range(3) if drawn[i]) if shell else ()
    pieces = raster.analytic_pieces(lat, full, np.array([-tol, -radius - tol, -radius - tol]),
                                    np.array([L + tol, radius + tol, radius + tol]), cons,
                                    solid=solid, shell_faces=shell_faces)
    ang = np.linspace(0, 2 * math.pi, NSIDES + 1)
    ring = np.stack([np.zeros_like(ang), radius * np.cos(ang), radius * np.sin(ang)], axis=1)
    tris = []          # the recorded shape: the faces not hidden (cover 1, cover 2, tube)
    for i in range(NSIDES):
        a0, a1 = ring[i], ring[i + 1]
        b0, b1 = a0 + [L, 0, 0], a1 + [L, 0, 0]
        tris += ([[a0, b0, b1], [a0, b1, a1]] if drawn[2] else []) + \
            ([[[0, 0, 0], a1, a0]] if drawn[0] else []) + ([[[L, 0, 0], b0, b1]] if drawn[1] else [])
    tris = tf.apply(full, np.array(tris).reshape(-1, 3, 3))
    s = tf.uniform_scale(m)
    w1, w2 = tf.apply(m, p1), tf.apply(m, p2)
    params = {"p1": w1.tolist(), "p2": w2.tolist(), "point1": w1.tolist(), "point2": w2.tolist(),
              "radius": float(radius * s) if s is not None else None,
              "local_radius": float(radius), "length": float(np.linalg.norm(w2 - w1)),
              "matrix": m.tolist()}
    return pieces, params, tris


# ---------------------------------------------------------------- polyhedra
def prism_faces(n: int):
    """Faces of a prism with base points 0..n-1 and top points n..2n-1."""
    faces = [tuple(range(n - 1, -1, -1)), tuple(range(n, 2 * n))]
    for i in range(n):
        j = (i + 1) % n
        faces.append((i, j, n + j, n + i))
    return faces


def pyramid_faces(n: int):
    """Faces of a pyramid with apex 0 and base points 1..n."""
    faces = [tuple(range(n, 0, -1))]
    for i in range(1, n + 1):
        j = i % n + 1
        faces.append((0, i, j))
    return faces


def draw_polyhedron(lat: Lattice, m, verts, faces, *, solid: bool, surface: bool, wire: bool,
                    mask=frozenset()):
    """A polyhedron: inside by parity, faces by triangles, edges by segments.

    Face ``i`` (0-based) is hidden when ``i + 1`` is listed in ``mask``; the wire edges are those
    of the faces drawn. The caller decides whether the inside is drawn (the closed shape's, the
    hidden faces included). The recorded triangles are those of the faces not hidden.
    """
    w = tf.apply(m, verts)
    drawn = drawn_faces(mask, len(faces))
    all_tris = faces_to_triangles(w, faces)
    pieces = []
    if solid:
        pieces += raster.triangle_pieces(lat, all_tris, surface=False, solid=True)
    if surface:
        shown = [f for f, d in zip(faces, drawn) if d]
        if shown:
            pieces += raster.triangle_pieces(lat, faces_to_triangles(w, shown))
    if wire:
        shown = [f for f, d in zip(faces, drawn) if d]
        pieces += raster.segment_pieces(lat, [w[[a, b]] for a, b in face_edges(shown)])
    params = {"vertices": w.tolist(), "faces": [list(f) for f in faces]}
    # the recorded shape (shapeout, norgeometry) holds the faces not hidden
    shown = [f for f, d in zip(faces, drawn) if d]
    return pieces, params, all_tris if len(shown) == len(faces) else faces_to_triangles(w, shown)


# ---------------------------------------------------------------- extrusions and beaches
def offset_polyline(pts: np.ndarray, vec: np.ndarray, offset: float) -> np.ndarray:
    """The open polyline ``pts`` moved ``offset`` along the normals of its extruded faces.

    Segment i sweeps the face (P_i, P_i+1, P_i+1 + e, P_i + e), whose normal is
    n_i = (P_i+1 - P_i) x e (GenCase's counter-clockwise rule for triangles). An inner
    point moves to where both faces it joins lie ``offset`` away (a mitred parallel curve,
    perpendicular to e), an end point along the normal of its own face; the ends are not
    lengthened. ``offset = 0`` returns the points unchanged.
    """
    pts = np.asarray(pts, dtype=np.float64)
    if offset == 0:
        return pts.copy()
    eu = vec / np.linalg.norm(vec)
    nrm = np.cross(pts[1:] - pts[:-1], eu)
    nrm /= np.linalg.norm(nrm, axis=1)[:, None]
    out = pts.copy()
    out[0] += offset * nrm[0]
    out[-1] += offset * nrm[-1]
    for k in range(1, len(pts) - 1):
        a, b = nrm[k - 1], nrm[k]
        if np.linalg.norm(np.cross(a, b)) < 1e-9:       # straight on (or folded back)
            out[k] += offset * b
            continue
        out[k] += np.linalg.solve(np.array([a, b, eu]), np.array([offset, offset, 0.0]))
    return out


def extrude_triangles(pts: np.ndarray, vec: np.ndarray) -> np.ndarray:
    """Triangles (2 per segment) of the open polyline ``pts`` swept by the vector ``vec``."""
    a, b = pts[:-1], pts[1:]
    t1 = np.stack([a, b, b + vec], axis=1)
    t2 = np.stack([a, b + vec, a + vec], axis=1)
    return np.stack([t1, t2], axis=1).reshape(-1, 3, 3)


def draw_extrude(lat: Lattice, m, pts, vec, *, wire: bool, offset: float = 0.0):
    """GenCase's ``<drawextrude closed="false">``: the open polyline ``pts`` swept by ``vec``
    (a surface of one quadrilateral per segment), moved ``offset`` along the face normals
    (``<layers>``, see :func:`offset_polyline`). The surface follows the planar-surface rule of
    :mod:`.raster`; ``wire`` draws the quadrilaterals' edges instead."""
    vec = np.asarray(vec, dtype=np.float64)
    loc = offset_polyline(pts, vec, offset)
    tris = tf.apply(m, extrude_triangles(loc, vec))
    if wire:
        w0, w1 = tf.apply(m, loc), tf.apply(m, loc + vec)
        segs = [np.array([w0[i], w0[i + 1]]) for i in range(len(loc) - 1)]
        segs += [np.array([w1[i], w1[i + 1]]) for i in range(len(loc) - 1)]
        segs += [np.array([w0[i], w1[i]]) for i in range(len(loc))]
        pieces = raster.segment_pieces(lat, segs)
    else:
        pieces = raster.triangle_pieces(lat, tris)
    world_vec = tf.apply(m, vec) - tf.apply(m, np.zeros(3))
    params = {"points": tf.apply(m, loc).tolist(), "extrude": world_vec.tolist(), "closed": False}
    return pieces, params, tris


def beach_prism(profile: np.ndarray, y_lo: float, y_hi: float) -> np.ndarray:
    """The prism vertices of GenCase's ``<drawbeach>``: the closed x-z profile at ``y_lo``
    (first polygon, face 1) then at ``y_hi`` (second polygon, face 2); faces 3... are the
    sides, the last one joining the last profile point to the first (:func:`prism_faces`)."""
    lo = np.array(profile, dtype=np.float64)
    hi = lo.copy()
    lo[:, 1] = y_lo
    hi[:, 1] = y_hi
    return np.concatenate([lo, hi])
