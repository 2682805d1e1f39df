"""Collision detection: shapes, sort-and-sweep broad phase, narrow phase.

Shapes (local frame of the shape, attached to a body with an offset pose):

=========  =========================================  ===========================
type       dims                                       notes
=========  =========================================  ===========================
SPHERE     (r, -, -)                                   analytic
BOX        half extents (hx, hy, hz)                   a hull of 6 faces (box–box,
                                                       box–hull as hull–hull)
CAPSULE    (r, half length, -) along local z           segment + radius
CYLINDER   (r, half length, -) along local z           exact SDF, rim samples
PLANE      -                                           half-space z_local ≤ 0 is
                                                       solid, normal = local +z
HULL       -                                           convex hull of vertices:
                                                       vertices + facet planes
CLOUD      (r, lattice spacing, -)                     particle cloud: smooth
                                                       surface (cloud_surface)
=========  =========================================  ===========================

Generic narrow phase ("samples against signed distance"): every shape has body
fixed sample points with a radius (sphere centre, capsule axis points, box/hull
vertices, cylinder rim points, cloud particles) and a signed distance function
(exact inside; exact or a lower bound outside — the hull's max-of-planes).  A
contact is created for each sample of one shape whose distance to the other
shape, minus its radius, is below the envelope.  Exact special cases:
sphere/capsule pairs (closest points between segments), cylinder–plane (exact rim
support point per cap), cylinder–box/hull (:func:`_cylinder_polytope`: separating axes;
the cylinder's exact support line or cap clipped to the polytope's face, or the polytope's
vertices and edges against the cylinder's exact surface), and box/hull pairs, box–box
included (separating-axis test over face normals and the cross products of the classes of
parallel edges: culls separated pairs and adds the edge–edge contact when an edge pair is
the axis of least penetration; the edge pairs are skipped above 4096 pairs of classes).
Particle clouds are searched through a body-frame cell grid
(O(1) per query) and collided as a smooth surface, not a union of spheres (DualSPHysics's
Chrono collides a triangle mesh): only surface particles are kept; a flat face's particle
is its tangent plane r in front of it, an edge or corner particle its sphere
(:func:`_cloud_query`); of two clouds, every sample of the smaller is tested against the
other's surface and the other's edge and corner particles against the smaller's faces.
A sphere against a cloud is its centre against the cloud's surface (one contact: the tangent
plane of a face, the sphere of an edge or corner particle; :func:`_sphere_vs_cloud`); a
capsule's axis points and a cylinder's rim points (and its exact deepest rim point per cap,
:func:`_cylinder_cloud_support`) against the cloud's flat faces, the cloud's edge and corner
particles against the capsule's or cylinder's exact surface.  Polytope pairs (box/hull,
box–box included) with a face axis of least penetration get a clipped face-face manifold of
≤ 4 points (:func:`_polytope_manifold`).  Limitations:
cylinder–cylinder and cylinder–capsule rely on 16 rim samples per cap (no exact
rim–edge contact); cylinder–box/hull has no rim–edge separating axis (a rim against an
edge is the edge's point nearest the axis against the exact surface); a cloud's staircase
(sloping or curved lattice surface) is collided as spheres; no rolling/spinning friction.
"""
import math

import numpy as np
from numba import njit

from ._math import cross
from ._vec import col, mat_t_vec, mat_vec, row3, v_add, v_cross, v_dot, v_scale, v_sub

SPHERE = 0
BOX = 1
CAPSULE = 2
CYLINDER = 3
PLANE = 4
HULL = 5
CLOUD = 6
SHAPE_NAMES = {"sphere": SPHERE, "box": BOX, "capsule": CAPSULE, "cylinder": CYLINDER,
               "plane": PLANE, "hull": HULL, "convex": HULL, "mesh": HULL, "cloud": CLOUD,
               "spherecloud": CLOUD}


# ------------------------------------------------------------------ transforms
@njit(cache=True)
def shape_world_poses(sh_body, sh_pos, sh_R, pos, Rb, w_pos, w_R):
    """World pose of each shape: its body's pose composed with the shape's offset (element
    loops: nothing allocated)."""
    for s in range(sh_body.shape[0]):
        b = sh_body[s]
        if b < 0:
            for i in range(3):
                w_pos[s, i] = sh_pos[s, i]
                for j in range(3):
                    w_R[s, i, j] = sh_R[s, i, j]
            continue
        for i in range(3):
            w_pos[s, i] = pos[b, i] + (Rb[b, i, 0] * sh_pos[s, 0] + Rb[b, i, 1] * sh_pos[s, 1]
                                       + Rb[b, i, 2] * sh_pos[s, 2])
            for j in range(3):
                w_R[s, i, j] = (Rb[b, i, 0] * sh_R[s, 0, j] + Rb[b, i, 1] * sh_R[s, 1, j]
                                + Rb[b, i, 2] * sh_R[s, 2, j])


@njit(cache=True)
def shape_aabbs(sh_type, sh_dims, samp_off, samp_cnt, samp_pts, samp_rad, w_pos, w_R,
                margin, lo, hi):
    for s in range(sh_type.shape[0]):
        t = sh_type[s]
        R = w_R[s]
        c = w_pos[s]
        if t == PLANE:
            for k in range(3):
                lo[s, k] = -1e300
                hi[s, k] = 1e300
            continue
        if t == SPHERE:
            for k in range(3):
                ext = sh_dims[s, 0]
                lo[s, k] = c[k] - ext - margin
                hi[s, k] = c[k] + ext + margin
            continue
        if t == BOX or t == CAPSULE or t == CYLINDER:
            if t == BOX:
                hx, hy, hz = sh_dims[s, 0], sh_dims[s, 1], sh_dims[s, 2]
                rr = 0.0
            elif t == CAPSULE:
                hx, hy, hz = 0.0, 0.0, sh_dims[s, 1]
                rr = sh_dims[s, 0]
            else:
                hx, hy, hz = sh_dims[s, 0], sh_dims[s, 0], sh_dims[s, 1]
                rr = 0.0
            for k in range(3):
                ext = abs(R[k, 0]) * hx + abs(R[k, 1]) * hy + abs(R[k, 2]) * hz + rr
                lo[s, k] = c[k] - ext - margin
                hi[s, k] = c[k] + ext + margin
            continue
        # hull / cloud: bound of the transformed samples
        for k in range(3):
            lo[s, k] = 1e300
            hi[s, k] = -1e300
        r = samp_rad[s]
        for p in range(samp_off[s], samp_off[s] + samp_cnt[s]):
            wp = c + R @ samp_pts[p]
            for k in range(3):
                if wp[k] - r < lo[s, k]:
                    lo[s, k] = wp[k] - r
                if wp[k] + r > hi[s, k]:
                    hi[s, k] = wp[k] + r
        for k in range(3):
            lo[s, k] -= margin
            hi[s, k] += margin


# ----------------------------------------------------------------- broad phase
@njit(cache=True)
def broad_phase(lo, hi, sh_body, sh_type, body_active, pairs, w_pos, w_R, env):
    """Sort-and-sweep along the axis of largest spread of the AABB centres;
    planes are paired with every shape whose AABB reaches below them (tested
    exactly in the narrow phase).  Returns the number of pairs (pairs may be
    too small: then the count is still returned and the caller grows it)."""
    ns = sh_type.shape[0]
    idx = np.empty(ns, np.int64)
    nfin = 0
    for s in range(ns):
        if sh_type[s] != PLANE:
            idx[nfin] = s
            nfin += 1
    idx = idx[:nfin]
    axis = 0
    if nfin > 1:
        best = -1.0
        for k in range(3):
            m = 0.0
            m2 = 0.0
            for q in range(nfin):
                cc = 0.5 * (lo[idx[q], k] + hi[idx[q], k])
                m += cc
                m2 += cc * cc
            var = m2 / nfin - (m / nfin) ** 2
            if var > best:
                best = var
                axis = k
    keys = np.empty(nfin)
    for q in range(nfin):
        keys[q] = lo[idx[q], axis]
    order = idx[np.argsort(keys)]
    cap = pairs.shape[0]
    npair = 0
    for q in range(nfin):
        s = order[q]
        bs = sh_body[s]
        his = hi[s, axis]
        for q2 in range(q + 1, nfin):
            t = order[q2]
            if lo[t, axis] > his:
                break
            bt = sh_body[t]
            if bt == bs:
                continue
            if not (body_active[bs] if bs >= 0 else False) and not (body_active[bt] if bt >= 0 else False):
                continue
            ok = True
            for k in range(3):
                if lo[t, k] > hi[s, k] or lo[s, k] > hi[t, k]:
                    ok = False
                    break
            if ok:
                if npair < cap:
                    pairs[npair, 0] = s
                    pairs[npair, 1] = t
                npair += 1
    for s in range(ns):
        if sh_type[s] != PLANE:
            continue
        bs = sh_body[s]
        n0, n1, n2 = w_R[s, 0, 2], w_R[s, 1, 2], w_R[s, 2, 2]
        off = n0 * w_pos[s, 0] + n1 * w_pos[s, 1] + n2 * w_pos[s, 2]
        for q in range(nfin):
            t = idx[q]
            bt = sh_body[t]
            if bt == bs:
                continue
            if not (body_active[bs] if bs >= 0 else False) and not (body_active[bt] if bt >= 0 else False):
                continue
            # lowest point of the AABB along the plane normal
            dmin = (n0 * (hi[t, 0] if n0 < 0.0 else lo[t, 0]) + n1 * (hi[t, 1] if n1 < 0.0 else lo[t, 1])
                    + n2 * (hi[t, 2] if n2 < 0.0 else lo[t, 2])) - off
            if dmin > env:
                continue
            if npair < cap:
                pairs[npair, 0] = s
                pairs[npair, 1] = t
            npair += 1
    return npair


# ---------------------------------------------------------- signed distances
@njit(cache=True)
def sdf_local(t, dims, q, s, samp_off, samp_cnt, samp_pts, pl_off, pl_cnt, planes,
              cg_meta, cg_start, reach, samp_nrm, xflag, plane_only):
    """Signed distance and outward unit gradient (tuple) of shape s at the
    local point q (tuple).  A particle cloud is its smooth surface
    (:func:`_cloud_query`, for a sample of flag ``xflag``); only particles
    near ``reach`` are searched (body-frame cell grid); beyond, ``reach − r``
    is returned."""
    if t == SPHERE:
        n = math.sqrt(q[0] ** 2 + q[1] ** 2 + q[2] ** 2)
        if n < 1e-14:
            return -dims[0], (0.0, 0.0, 1.0)
        return n - dims[0], (q[0] / n, q[1] / n, q[2] / n)
    if t == PLANE:
        return q[2], (0.0, 0.0, 1.0)
    if t == BOX:
        d0 = abs(q[0]) - dims[0]
        d1 = abs(q[1]) - dims[1]
        d2 = abs(q[2]) - dims[2]
        if d0 > 0.0 or d1 > 0.0 or d2 > 0.0:
            e0 = max(d0, 0.0)
            e1 = max(d1, 0.0)
            e2 = max(d2, 0.0)
            n = math.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
            return n, (math.copysign(e0, q[0]) / n, math.copysign(e1, q[1]) / n,
                       math.copysign(e2, q[2]) / n)
        if d0 >= d1 and d0 >= d2:
            return d0, (math.copysign(1.0, q[0]), 0.0, 0.0)
        if d1 >= d2:
            return d1, (0.0, math.copysign(1.0, q[1]), 0.0)
        return d2, (0.0, 0.0, math.copysign(1.0, q[2]))
    if t == CAPSULE:
        zc = min(max(q[2], -dims[1]), dims[1])
        v0, v1, v2 = q[0], q[1], q[2] - zc
        n = math.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
        if n < 1e-14:
            return -dims[0], (1.0, 0.0, 0.0)
        return n - dims[0], (v0 / n, v1 / n, v2 / n)
    if t == CYLINDER:
        rho = math.sqrt(q[0] ** 2 + q[1] ** 2)
        if rho < 1e-14:
            rx, ry = 1.0, 0.0
        else:
            rx, ry = q[0] / rho, q[1] / rho
        dr = rho - dims[0]
        dz = abs(q[2]) - dims[1]
        sz = math.copysign(1.0, q[2])
        if dr > 0.0 or dz > 0.0:
            er = max(dr, 0.0)
            ez = max(dz, 0.0)
            n = math.sqrt(er * er + ez * ez)
            return n, (er * rx / n, er * ry / n, ez * sz / n)
        if dr > dz:
            return dr, (rx, ry, 0.0)
        return dz, (0.0, 0.0, sz)
    if t == HULL:
        best = -1e300
        g = (0.0, 0.0, 1.0)
        for p in range(pl_off[s], pl_off[s] + pl_cnt[s]):
            d = planes[p, 0] * q[0] + planes[p, 1] * q[1] + planes[p, 2] * q[2] + planes[p, 3]
            if d > best:
                best = d
                g = (planes[p, 0], planes[p, 1], planes[p, 2])
        return best, g
    # CLOUD: the smooth particle surface (see _cloud_query)
    return _cloud_query(q, s, dims, samp_off, samp_pts, samp_nrm, cg_meta, cg_start, reach,
                        xflag, plane_only)


@njit(cache=True)
def _scan_cells(q, s, samp_off, samp_pts, cg_meta, cg_start, kin, kout, best, bj):
    """Nearest particle of cloud s to q over the grid cells whose Chebyshev distance
    from q's cell lies in (kin, kout] (kin = -1: all of them); returns (d², index)."""
    ox, oy, oz, cs = cg_meta[s, 0], cg_meta[s, 1], cg_meta[s, 2], cg_meta[s, 3]
    nx, ny, nz = int(cg_meta[s, 4]), int(cg_meta[s, 5]), int(cg_meta[s, 6])
    base = int(cg_meta[s, 7])
    ix = int(math.floor((q[0] - ox) / cs))
    iy = int(math.floor((q[1] - oy) / cs))
    iz = int(math.floor((q[2] - oz) / cs))
    off = samp_off[s]
    for cx in range(max(ix - kout, 0), min(ix + kout, nx - 1) + 1):
        for cy in range(max(iy - kout, 0), min(iy + kout, ny - 1) + 1):
            for cz in range(max(iz - kout, 0), min(iz + kout, nz - 1) + 1):
                if max(abs(cx - ix), max(abs(cy - iy), abs(cz - iz))) <= kin:
                    continue
                cell = base + (cx * ny + cy) * nz + cz
                for p in range(off + cg_start[cell], off + cg_start[cell + 1]):
                    v0 = q[0] - samp_pts[p, 0]
                    v1 = q[1] - samp_pts[p, 1]
                    v2 = q[2] - samp_pts[p, 2]
                    d2 = v0 * v0 + v1 * v1 + v2 * v2
                    if d2 < best:
                        best = d2
                        bj = p
    return best, bj


@njit(cache=True)
def _cloud_query(q, s, dims, samp_off, samp_pts, samp_nrm, cg_meta, cg_start, reach, xflag,
                 plane_only):
    """Signed distance and outward unit normal of a particle cloud's surface at the local
    point q (in place of the triangle mesh DualSPHysics's Chrono collides, JChronoObjects:
    modelfile AutoActual): the nearest surface particle j (interior particles are not in the
    cloud) gives the surface.  Flat j (``samp_nrm[j, 3]`` 1 = one-sided, 2 = two-sided sheet):
    its tangent plane, dims[0] (r) in front of the particle along its normal n_j, so that two
    flat faces touch at a layer distance of exactly r1 + r2 whatever the lateral alignment of
    the particles, with a constant normal; beyond the particle's patch (lateral distance over
    dims[1]/√2, only past the rim of a face) it is rounded.  Feature j (edge, corner, curved or
    irregular particle): its sphere of radius r, taken only when the querying sample is itself
    a feature (``xflag`` 0) and not ``plane_only``; a flat sample against a feature is the
    reverse query's (feature sample against the other body's plane).  No contact: reach − r."""
    r = dims[0]
    sp = dims[1] if dims[1] > 0.0 else 2.0 * r
    R = reach + sp
    cs = cg_meta[s, 3]
    kr = int(math.ceil(R / cs))
    k0 = min(kr, 2)
    best, bj = _scan_cells(q, s, samp_off, samp_pts, cg_meta, cg_start, -1, k0, R * R, -1)
    if k0 < kr and best > (k0 * cs) ** 2:
        best, bj = _scan_cells(q, s, samp_off, samp_pts, cg_meta, cg_start, k0, kr, best, bj)
    return _cloud_surface_at(q, bj, best, r, sp, reach, samp_pts, samp_nrm, xflag, plane_only)


@njit(cache=True)
def _cloud_surface_at(q, bj, best, r, sp, reach, samp_pts, samp_nrm, xflag, plane_only):
    """The cloud surface of :func:`_cloud_query` at q given its nearest surface particle bj
    (−1: none within reach) at the squared distance ``best``."""
    none = (reach - r, (0.0, 0.0, 1.0))
    if bj < 0:
        return none
    v0 = q[0] - samp_pts[bj, 0]
    v1 = q[1] - samp_pts[bj, 1]
    v2 = q[2] - samp_pts[bj, 2]
    fl = samp_nrm[bj, 3]
    if fl > 0.5:
        n0, n1, n2 = samp_nrm[bj, 0], samp_nrm[bj, 1], samp_nrm[bj, 2]
        h = v0 * n0 + v1 * n1 + v2 * n2
        if fl > 1.5 and h < 0.0:
            n0, n1, n2, h = -n0, -n1, -n2, -h
        if h <= 0.0:
            return h - r, (n0, n1, n2)
        lat = math.sqrt(max(best - h * h, 0.0))
        e = lat - sp * 0.7072
        if e <= 0.0:
            return h - r, (n0, n1, n2)
        t0 = (v0 - h * n0) / lat
        t1 = (v1 - h * n1) / lat
        t2 = (v2 - h * n2) / lat
        d = math.sqrt(h * h + e * e)
        return d - r, ((h * n0 + e * t0) / d, (h * n1 + e * t1) / d, (h * n2 + e * t2) / d)
    if plane_only or xflag > 0.5:
        return none
    d = math.sqrt(best)
    if d < 1e-14:
        return -r, (0.0, 0.0, 1.0)
    return d - r, (v0 / d, v1 / d, v2 / d)


@njit(cache=True)
def _sphere_vs_cloud(ssp, scl, bsp, bcl, swap, nc, cap, env, keybase, sh_dims, samp_off,
                     samp_cnt, samp_pts, samp_nrm, cg_meta, cg_start, w_pos, w_R, lo, hi,
                     c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key):
    """A sphere against a particle cloud's smooth surface (:func:`_cloud_query`): the
    sphere's centre queries the cloud's nearest surface particle, whose tangent plane (a
    flat face's particle) or sphere (an edge or corner) the sphere touches: one contact, as
    a sphere on a plane over a face, whatever the lattice under it.  The nearest particle
    is searched in the cloud's cell grid, or over its particles where that grid region
    (the sphere's radius in cells) would hold more cells than the cloud has particles.
    ``swap``: the sphere is the pair's second shape."""
    c = row3(w_pos, ssp)
    rad = sh_dims[ssp, 0]
    for k in range(3):
        if c[k] + rad < lo[scl, k] or c[k] - rad > hi[scl, k]:
            return nc
    RO = w_R[scl]
    q = mat_t_vec(RO, v_sub(c, row3(w_pos, scl)))
    dims = sh_dims[scl]
    r = dims[0]
    sp = dims[1] if dims[1] > 0.0 else 2.0 * r
    reach = rad + r + max(env, 0.0) + 1e-12
    Rq = reach + sp
    cs = cg_meta[scl, 3]
    kr = int(math.ceil(Rq / cs))
    if (2.0 * kr + 1.0) ** 3 > samp_cnt[scl]:
        best = Rq * Rq
        bj = -1
        for p in range(samp_off[scl], samp_off[scl] + samp_cnt[scl]):
            d0 = q[0] - samp_pts[p, 0]
            d1 = q[1] - samp_pts[p, 1]
            d2 = q[2] - samp_pts[p, 2]
            dd = d0 * d0 + d1 * d1 + d2 * d2
            if dd < best:
                best = dd
                bj = p
    else:
        k0 = min(kr, 2)
        best, bj = _scan_cells(q, scl, samp_off, samp_pts, cg_meta, cg_start, -1, k0, Rq * Rq,
                               -1)
        if k0 < kr and best > (k0 * cs) ** 2:
            best, bj = _scan_cells(q, scl, samp_off, samp_pts, cg_meta, cg_start, k0, kr, best,
                                   bj)
    phi, gl = _cloud_surface_at(q, bj, best, r, sp, reach, samp_pts, samp_nrm, 0.0, False)
    gap = phi - rad
    if gap >= env:
        return nc
    gw = mat_vec(RO, gl)
    pt = v_sub(c, v_scale(gw, 0.5 * (rad + phi)))
    key = keybase + (1 if swap else 0)
    return _emit_sided(nc, cap, swap, bsp, bcl, ssp, scl, pt, gw, gap, key,
                       c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key)


# ------------------------------------------------------------- contact output
@njit(cache=True)
def _emit(nc, cap, ba, bb, sa, sb, pt, n, gap, key, c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key):
    if nc < cap:
        c_a[nc] = ba
        c_b[nc] = bb
        c_sa[nc] = sa
        c_sb[nc] = sb
        for k in range(3):
            c_pt[nc, k] = pt[k]
            c_n[nc, k] = n[k]
        c_gap[nc] = gap
        c_key[nc] = key
    return nc + 1


@njit(cache=True)
def closest_segments(p1, q1, p2, q2):
    """Closest points between segments [p1,q1] and [p2,q2] (Ericson §5.1.9)."""
    d1 = q1 - p1
    d2 = q2 - p2
    r = p1 - p2
    a = d1 @ d1
    e = d2 @ d2
    f = d2 @ r
    if a <= 1e-20 and e <= 1e-20:
        return p1.copy(), p2.copy()
    if a <= 1e-20:
        s = 0.0
        t = min(max(f / e, 0.0), 1.0)
    else:
        c = d1 @ r
        if e <= 1e-20:
            t = 0.0
            s = min(max(-c / a, 0.0), 1.0)
        else:
            bq = d1 @ d2
            den = a * e - bq * bq
            s = min(max((bq * f - c * e) / den, 0.0), 1.0) if den > 1e-20 else 0.0
            t = (bq * s + f) / e
            if t < 0.0:
                t = 0.0
                s = min(max(-c / a, 0.0), 1.0)
            elif t > 1.0:
                t = 1.0
                s = min(max((bq - c) / a, 0.0), 1.0)
    return p1 + d1 * s, p2 + d2 * t


@njit(cache=True)
def _segment_of(t, dims, c, R):
    if t == CAPSULE:
        ax = R[:, 2] * dims[1]
        return c - ax, c + ax
    return c.copy(), c.copy()


@njit(cache=True, inline="always")
def _emit_t(nc, cap, ba, bb, sa, sb, pt, n, gap, key, c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key):
    """_emit for tuple vectors."""
    if nc < cap:
        c_a[nc] = ba
        c_b[nc] = bb
        c_sa[nc] = sa
        c_sb[nc] = sb
        for k in range(3):
            c_pt[nc, k] = pt[k]
            c_n[nc, k] = n[k]
        c_gap[nc] = gap
        c_key[nc] = key
    return nc + 1


@njit(cache=True, inline="always")
def _emit_sided(nc, cap, swap, bx, by, sx, sy, pt, n, gap, key, c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key):
    """Emit a contact found between shape sx (body bx) and shape sy (body by), ``n`` pointing from sy
    to sx, in the pair's own order: (sy, sx) with ``n`` when the pair was swapped, else (sx, sy)
    with −n (the normal always from the pair's first shape to its second)."""
    if swap:
        return _emit_t(nc, cap, by, bx, sy, sx, pt, n, gap, key, c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key)
    return _emit_t(nc, cap, bx, by, sx, sy, pt, v_scale(n, -1.0), gap, key,
                   c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key)


@njit(cache=True)
def _closest_segments_t(p1, q1, p2, q2):
    """Closest points between segments [p1,q1] and [p2,q2] (tuples)."""
    d1 = v_sub(q1, p1)
    d2 = v_sub(q2, p2)
    r = v_sub(p1, p2)
    a = v_dot(d1, d1)
    e = v_dot(d2, d2)
    f = v_dot(d2, r)
    if a <= 1e-20 and e <= 1e-20:
        return p1, p2
    if a <= 1e-20:
        s = 0.0
        t = min(max(f / e, 0.0), 1.0)
    else:
        c = v_dot(d1, r)
        if e <= 1e-20:
            t = 0.0
            s = min(max(-c / a, 0.0), 1.0)
        else:
            bq = v_dot(d1, d2)
            den = a * e - bq * bq
            s = min(max((bq * f - c * e) / den, 0.0), 1.0) if den > 1e-20 else 0.0
            t = (bq * s + f) / e
            if t < 0.0:
                t = 0.0
                s = min(max(-c / a, 0.0), 1.0)
            elif t > 1.0:
                t = 1.0
                s = min(max((bq - c) / a, 0.0), 1.0)
    return v_add(p1, v_scale(d1, s)), v_add(p2, v_scale(d2, t))


@njit(cache=True)
def _samples_vs_sdf(sp, so, bp, bo, swap, nc, cap, env, keybase,
                    sh_type, sh_dims, samp_off, samp_cnt, samp_pts, samp_rad,
                    pl_off, pl_cnt, planes, cg_meta, cg_start, w_pos, w_R, lo, hi, sh_body,
                    c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key, samp_nrm, features_only):
    """Samples of shape sp (radius ρ) against the SDF of shape so.  The contact
    normal is −∇φ_so (from sp to so); ``swap`` reverses the pair order so that
    the normal is always from the pair's first shape to its second.
    ``features_only``: only the feature samples of a cloud (edges, corners),
    against the flat surface of the other cloud (the reverse query)."""
    cP = row3(w_pos, sp)
    RP = w_R[sp]
    cO = row3(w_pos, so)
    RO = w_R[so]
    rho = samp_rad[sp]
    to = sh_type[so]
    dims = sh_dims[so]
    reach = rho + dims[0] + max(env, 0.0) + 1e-12
    for p in range(samp_off[sp], samp_off[sp] + samp_cnt[sp]):
        xflag = samp_nrm[p, 3]
        if features_only and xflag > 0.5:
            continue
        x = v_add(cP, mat_vec(RP, row3(samp_pts, p)))
        # AABB cull against the other shape
        out = False
        for k in range(3):
            if x[k] + rho < lo[so, k] or x[k] - rho > hi[so, k]:
                out = True
                break
        if out:
            continue
        ql = mat_t_vec(RO, v_sub(x, cO))
        phi, gl = sdf_local(to, dims, ql, so, samp_off, samp_cnt, samp_pts,
                            pl_off, pl_cnt, planes, cg_meta, cg_start, reach, samp_nrm, xflag,
                            features_only)
        gap = phi - rho
        if gap >= env:
            continue
        gw = mat_vec(RO, gl)
        pt = v_sub(x, v_scale(gw, 0.5 * (rho + phi)))
        key = keybase + (p - samp_off[sp]) * 2 + (1 if swap else 0)
        nc = _emit_sided(nc, cap, swap, bp, bo, sp, so, pt, gw, gap, key,
                         c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key)
    return nc


@njit(cache=True)
def _cylinder_plane_support(sc, sp, bc, bpl, nc, cap, env, keybase, sh_dims, w_pos, w_R,
                            c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key):
    """Exact deepest rim point of each cap of a cylinder against a plane (the
    rim samples alone would make a lying cylinder roll like a polygon)."""
    n = col(w_R[sp], 2)                      # plane normal (world)
    a = col(w_R[sc], 2)                      # cylinder axis (world)
    an = v_dot(a, n)
    if abs(an) > 0.999:
        return nc
    rdir = v_sub(v_scale(a, an), n)          # −n projected on the cap plane
    rdir = v_scale(rdir, 1.0 / math.sqrt(v_dot(rdir, rdir)))
    c = row3(w_pos, sc)
    p0 = row3(w_pos, sp)
    R = sh_dims[sc, 0]
    H = sh_dims[sc, 1]
    for side in range(2):
        sg = 1.0 if side == 0 else -1.0
        x = v_add(v_add(c, v_scale(a, sg * H)), v_scale(rdir, R))
        gap = v_dot(v_sub(x, p0), n)
        if gap < env:
            pt = v_sub(x, v_scale(n, 0.5 * gap))
            # pair order: cylinder first, normal from cylinder to plane = −n
            nc = _emit_t(nc, cap, bc, bpl, sc, sp, pt, v_scale(n, -1.0), gap,
                         keybase + 1000000 + side, c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key)
    return nc


@njit(cache=True)
def _cylinder_cloud_support(sc, scl, bc, bcl, swap, nc, cap, env, keybase, sh_dims, samp_off,
                            samp_pts, samp_nrm, cg_meta, cg_start, w_pos, w_R,
                            c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key):
    """Exact deepest rim point of each cap of a cylinder against a particle cloud's flat face
    (as :func:`_cylinder_plane_support` against a plane): the face is the tangent plane of
    the cloud's surface particle nearest the cap's centre (:func:`_cloud_query`, flat faces
    only), the rim point deepest along its normal is queried again; a cap parallel to the face
    is left to the rim samples.  ``swap``: the cylinder is the pair's second shape."""
    RO = w_R[scl]
    cO = row3(w_pos, scl)
    dims = sh_dims[scl]
    a = mat_t_vec(RO, col(w_R[sc], 2))                 # axis, cloud frame
    c = mat_t_vec(RO, v_sub(row3(w_pos, sc), cO))      # centre, cloud frame
    R = sh_dims[sc, 0]
    H = sh_dims[sc, 1]
    reach = R + H + dims[0] + max(env, 0.0) + 1e-12
    for side in range(2):
        cc = v_add(c, v_scale(a, H if side == 0 else -H))
        phi0, g = _cloud_query(cc, scl, dims, samp_off, samp_pts, samp_nrm, cg_meta, cg_start,
                               reach, 1.0, True)
        if phi0 >= reach - dims[0]:
            continue                                  # no flat face within reach
        an = v_dot(a, g)
        if abs(an) > 0.999:
            continue
        rdir = v_sub(v_scale(a, an), g)               # −g projected on the cap plane
        rdir = v_scale(rdir, 1.0 / math.sqrt(v_dot(rdir, rdir)))
        x = v_add(cc, v_scale(rdir, R))
        phi, gx = _cloud_query(x, scl, dims, samp_off, samp_pts, samp_nrm, cg_meta, cg_start,
                               dims[0] + max(env, 0.0) + 1e-12, 1.0, True)
        if phi >= env:
            continue
        gw = mat_vec(RO, gx)
        pt = v_sub(v_add(cO, mat_vec(RO, x)), v_scale(gw, 0.5 * phi))
        key = keybase + 1000000 + 2 * side + (1 if swap else 0)
        nc = _emit_sided(nc, cap, swap, bc, bcl, sc, scl, pt, gw, phi, key,
                         c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key)
    return nc


@njit(cache=True, inline="always")
def _inner_ball(s, samp_off, samp_cnt, samp_pts, pl_off, pl_cnt, planes):
    """Centre (the vertex centroid, shape frame) and radius (its distance to the nearest
    face plane, ≥ 0) of a ball inside the convex polytope s."""
    m0 = 0.0
    m1 = 0.0
    m2 = 0.0
    n = samp_cnt[s]
    for i in range(samp_off[s], samp_off[s] + n):
        m0 += samp_pts[i, 0]
        m1 += samp_pts[i, 1]
        m2 += samp_pts[i, 2]
    f = 1.0 / max(n, 1)
    m0 *= f
    m1 *= f
    m2 *= f
    r = 1e300
    for p in range(pl_off[s], pl_off[s] + pl_cnt[s]):
        r = min(r, -(planes[p, 0] * m0 + planes[p, 1] * m1 + planes[p, 2] * m2 + planes[p, 3]))
    return (m0, m1, m2), max(r, 0.0)


@njit(cache=True)
def _support_edge(rep, ne, off, ed_rep, edges, W, L, ext, tol):
    """First edge of the parallel class ``rep`` whose two vertices (world, W) lie at the
    extreme ``ext`` of the polytope along L (within tol); −1: none (L meets the class at a
    vertex only)."""
    for e in range(rep, ne):
        if ed_rep[off + e] != rep:
            continue
        v0 = edges[off + e, 0]
        v1 = edges[off + e, 1]
        if (abs(L[0] * W[v0, 0] + L[1] * W[v0, 1] + L[2] * W[v0, 2] - ext) <= tol
                and abs(L[0] * W[v1, 0] + L[1] * W[v1, 1] + L[2] * W[v1, 2] - ext) <= tol):
            return e
    return -1


@njit(cache=True, inline="always")
def _polytope_sat(sa, sb, env, samp_off, samp_cnt, samp_pts, pl_off, pl_cnt, planes, edges,
                  ed_off, ed_cnt, ed_rep, cls_cnt, w_pos, w_R, wa, wb):
    """Separating-axis test of two convex polytopes (box/hull) over the face
    normals of both and the cross products of their edges (one per pair of classes of
    parallel edges, ``ed_rep``: a box has 3 × 3).  Returns
    (separation, edge a, edge b, axis, face side, face plane): the edge pair is set (≥ 0)
    when an edge–edge axis is the axis of least penetration (its supporting edges); the
    face (side 0: of sa, 1: of sb; its index in ``planes``) is the face axis of least
    penetration (a face of sb only where it beats sa's best by a relative 1e-9, so that a
    face-face rest does not swap the reference face with round-off), for the face-face
    manifold (:func:`_polytope_manifold`).  ``cls_cnt``: per shape, its number of classes of
    parallel edges; edge pairs are skipped for hulls with more than 4096 pairs of classes (a
    64-sided prism has 33 classes: 1,089 pairs)."""
    na = samp_cnt[sa]
    nbv = samp_cnt[sb]
    Ra = w_R[sa]
    Rb_ = w_R[sb]
    ca = row3(w_pos, sa)
    cb = row3(w_pos, sb)
    for i in range(na):
        x = v_add(ca, mat_vec(Ra, row3(samp_pts, samp_off[sa] + i)))
        wa[i, 0] = x[0]
        wa[i, 1] = x[1]
        wa[i, 2] = x[2]
    for i in range(nbv):
        x = v_add(cb, mat_vec(Rb_, row3(samp_pts, samp_off[sb] + i)))
        wb[i, 0] = x[0]
        wb[i, 1] = x[1]
        wb[i, 2] = x[2]
    # a ball inside each polytope (about its vertex centroid m, radius: the distance to the
    # nearest face plane) bounds every axis's separation from above:
    # sep(L) ≤ L·(m_b − m_a) − r_a − r_b; an axis bounded below the bar is skipped
    ma, rin_a = _inner_ball(sa, samp_off, samp_cnt, samp_pts, pl_off, pl_cnt, planes)
    mb, rin_b = _inner_ball(sb, samp_off, samp_cnt, samp_pts, pl_off, pl_cnt, planes)
    ma = v_add(ca, mat_vec(Ra, ma))
    mb = v_add(cb, mat_vec(Rb_, mb))
    slack = 1e-9 * (1.0 + rin_a + rin_b)
    best_face = -1e300
    fside = 0
    fplane = -1
    for side in range(2):
        s = sa if side == 0 else sb
        R = Ra if side == 0 else Rb_
        c = ca if side == 0 else cb
        W = wb if side == 0 else wa
        nw = nbv if side == 0 else na
        for p in range(pl_off[s], pl_off[s] + pl_cnt[s]):
            n = mat_vec(R, (planes[p, 0], planes[p, 1], planes[p, 2]))
            off = v_dot(n, c) - planes[p, 3]
            # a face whose depth falls to the best so far (and below the envelope) can
            # neither separate nor win: skipped on the balls' bound, else its vertex loop
            # stops there (same result)
            bar = best_face + (1e-9 * (1.0 + abs(best_face)) if side == 1 else 0.0)
            stop = min(bar, env)
            if side == 0:
                ub = v_dot(n, mb) - off - rin_b
            else:
                ub = v_dot(n, ma) - off - rin_a
            if ub <= stop - slack:
                continue
            m = 1e300
            low = False
            for i in range(nw):
                d = n[0] * W[i, 0] + n[1] * W[i, 1] + n[2] * W[i, 2] - off
                if d < m:
                    m = d
                    if m <= stop:
                        low = True
                        break
            if low:
                continue
            if m > bar:
                best_face = m
                fside = side
                fplane = p
            if m > env:
                return m, -1, -1, (0.0, 0.0, 0.0), fside, fplane
    best_edge = -1e300
    bea = -1
    beb = -1
    bL = (0.0, 0.0, 0.0)
    nea = ed_cnt[sa]
    neb = ed_cnt[sb]
    if cls_cnt[sa] * cls_cnt[sb] > 4096:
        return best_face, -1, -1, bL, fside, fplane
    T = v_sub(cb, ca)
    scale2 = 1e300
    for i in range(na):
        d = v_sub(row3(wa, i), ca)
        scale2 = min(scale2, v_dot(d, d))
    scale = math.sqrt(scale2)
    tol = 1e-9 * (1.0 + scale)
    # an edge axis wins only above this (the return below); one that falls to it (and below
    # the envelope) stops its vertex loop
    win = best_face + 0.05 * abs(best_face) + 1e-6 * (1.0 + scale)
    oa = ed_off[sa]
    ob = ed_off[sb]
    mdiff = v_sub(mb, ma)
    rin_ab = rin_a + rin_b
    for i in range(nea):
        if ed_rep[oa + i] != i:
            continue                 # one axis per class of parallel edges
        da = v_sub(row3(wa, edges[oa + i, 1]), row3(wa, edges[oa + i, 0]))
        for j in range(neb):
            if ed_rep[ob + j] != j:
                continue
            db = v_sub(row3(wb, edges[ob + j, 1]), row3(wb, edges[ob + j, 0]))
            L = v_cross(da, db)
            ln = math.sqrt(v_dot(L, L))
            if ln < 1e-9 * math.sqrt(v_dot(da, da) * v_dot(db, db)) + 1e-300:
                continue
            L = v_scale(L, 1.0 / ln)
            if v_dot(L, T) < 0.0:
                L = v_scale(L, -1.0)
            # the balls inside bound the separation: sep ≤ L·(mb − ma) − rin_a − rin_b; an
            # axis that cannot reach the winning bar (nor the envelope) is skipped
            if v_dot(L, mdiff) - rin_ab <= min(win, env) - slack:
                continue
            maxa = -1e300
            for k in range(na):
                d = L[0] * wa[k, 0] + L[1] * wa[k, 1] + L[2] * wa[k, 2]
                if d > maxa:
                    maxa = d
            stop = maxa + min(win, env)
            minb = 1e300
            low = False
            for k in range(nbv):
                d = L[0] * wb[k, 0] + L[1] * wb[k, 1] + L[2] * wb[k, 2]
                if d < minb:
                    minb = d
                    if minb <= stop:
                        low = True
                        break
            if low:
                continue
            sep = minb - maxa
            if sep > env:
                return sep, -1, -1, L, fside, fplane
            if sep <= best_edge or sep <= win:
                continue
            # only edges that actually support the axis: the first of each class
            ia = _support_edge(i, nea, oa, ed_rep, edges, wa, L, maxa, tol)
            if ia < 0:
                continue
            jb = _support_edge(j, neb, ob, ed_rep, edges, wb, L, minb, tol)
            if jb < 0:
                continue
            best_edge = sep
            bea = ia
            beb = jb
            bL = L
    if bea >= 0 and best_edge > win:
        return best_edge, bea, beb, bL, fside, fplane
    return max(best_face, best_edge), -1, -1, bL, fside, fplane


# contact keys of the face-face manifold (pair-local, below the edge-edge key 999999): a
# vertex of either polytope, or the crossing of an edge of one with an edge of the other; the
# same physical point keeps its key whichever face is the reference (warm start)
_VKEY0 = 1 << 19
_EKEY0 = _VKEY0 + (1 << 18)
_EKEY_MOD = 200000


@njit(cache=True)
def _vertex_key(s, v, s_lo):
    """Key of vertex v of shape s (s_lo: the pair's lower shape index)."""
    return _VKEY0 + (0 if s == s_lo else 1 << 17) + (v & ((1 << 17) - 1))


@njit(cache=True)
def _crossing_key(lab, j, sr, si, s_lo, fr_off, fi_off, nref_v, fv_idx, fv_edge, ned_r, ned_i,
                  ei_base):
    """Key of a clipped point: the crossing of the current polygon edge (label ``lab``: ≥ 0
    the incident face's edge lab, < 0 the reference face's edge −lab−1) with the reference
    face's side plane j.  Two reference edges meet at a reference vertex.  ned_r, ned_i: the
    edge counts of the reference and incident shapes.  ``ei_base`` ≥ 0: the incident polygon
    is a cylinder's (:func:`_cylinder_polytope`), its edge lab is the incident edge
    ei_base + lab."""
    if lab < 0:
        j1 = -lab - 1
        if (j1 + 1) % nref_v == j:
            return _vertex_key(sr, fv_idx[fr_off + j], s_lo)
        if (j + 1) % nref_v == j1:
            return _vertex_key(sr, fv_idx[fr_off + j1], s_lo)
        return _EKEY0 + _EKEY_MOD + ((j1 * 61 + j) % 9973)
    er = fv_edge[fr_off + j]
    ei = ei_base + lab if ei_base >= 0 else fv_edge[fi_off + lab]
    if er < 0 or ei < 0:
        return _EKEY0 + _EKEY_MOD + 9973 + ((lab * 61 + j) % 9973)
    if sr == s_lo:
        return _EKEY0 + (np.int64(er) * ned_i + ei) % _EKEY_MOD
    return _EKEY0 + (np.int64(ei) * ned_r + er) % _EKEY_MOD


@njit(cache=True)
def _area_tri(a, b, c, n):
    """Signed area of the triangle abc projected on the plane of unit normal n."""
    return 0.5 * v_dot(v_cross(v_sub(b, a), v_sub(c, a)), n)


@njit(cache=True)
def _hull_area4(a, b, c, p, n):
    """Area of the convex hull of four points projected on the plane of normal n: the
    largest of the four triangles and of the three quadrilaterals' shoelace areas."""
    t0 = _area_tri(a, b, c, n)
    t1 = _area_tri(a, b, p, n)
    t2 = _area_tri(a, p, c, n)
    t3 = _area_tri(p, b, c, n)
    best = max(max(abs(t0), abs(t1)), max(abs(t2), abs(t3)))
    best = max(best, abs(t0 - t2))     # quadrilateral a b c p
    best = max(best, abs(t1 + t2))     # a b p c
    return max(best, abs(t0 - t1))     # a p b c


# columns of the face-face manifold's work arrays (a row per polygon point): fw (float) the
# point (two buffers, the clipping alternates them), its gap, a score, and the output (point,
# gap); iw (int) its key and label (two buffers each), the candidate list, the kept flag and
# the output key
_FP = 0
_FGAP = 6
_FSC = 7
_FOUT = 8
_NFW = 12
_IKEY = 0
_ILAB = 2
_ICAND = 4
_IUSED = 5
_IOUT = 6
_NIW = 7


@njit(cache=True)
def _pick(fw, iw, ncand, tol, pb):
    """Index (a row of the work arrays) of the unused candidate of largest score; those within
    ``tol`` of the best are tied and the lowest key wins (a choice that does not flip with
    round-off, for the warm start).  pb: the column of the points' keys."""
    best = -1e300
    for m in range(ncand):
        q = iw[m, _ICAND]
        if iw[q, _IUSED] == 0 and fw[q, _FSC] > best:
            best = fw[q, _FSC]
    pick = -1
    for m in range(ncand):
        q = iw[m, _ICAND]
        if iw[q, _IUSED] != 0 or fw[q, _FSC] < best - tol:
            continue
        if pick < 0 or iw[q, pb] < iw[pick, pb]:
            pick = q
    return pick


@njit(cache=True)
def _reduce4(fw, iw, ncand, nref, ext, pc, pb):
    """Contact reduction to four points (as Bullet's persistent manifold): the deepest point,
    the one farthest from it, the one that maximises the triangle's area, then the one that
    maximises the area of the four points' convex hull (all in the reference plane).
    Marks them used.  pc, pb: the columns of the points and of their keys."""
    for m in range(ncand):
        q = iw[m, _ICAND]
        iw[q, _IUSED] = 0
        fw[q, _FSC] = -fw[q, _FGAP]
    i0 = _pick(fw, iw, ncand, 1e-5 * ext, pb)
    iw[i0, _IUSED] = 1
    p0 = (fw[i0, pc], fw[i0, pc + 1], fw[i0, pc + 2])
    for m in range(ncand):
        q = iw[m, _ICAND]
        d = v_sub((fw[q, pc], fw[q, pc + 1], fw[q, pc + 2]), p0)
        h = v_dot(d, nref)
        fw[q, _FSC] = v_dot(d, d) - h * h
    i1 = _pick(fw, iw, ncand, 1e-6 * ext * ext, pb)
    iw[i1, _IUSED] = 1
    p1 = (fw[i1, pc], fw[i1, pc + 1], fw[i1, pc + 2])
    for m in range(ncand):
        q = iw[m, _ICAND]
        fw[q, _FSC] = abs(_area_tri(p0, p1, (fw[q, pc], fw[q, pc + 1], fw[q, pc + 2]), nref))
    i2 = _pick(fw, iw, ncand, 1e-6 * ext * ext, pb)
    iw[i2, _IUSED] = 1
    p2 = (fw[i2, pc], fw[i2, pc + 1], fw[i2, pc + 2])
    for m in range(ncand):
        q = iw[m, _ICAND]
        fw[q, _FSC] = _hull_area4(p0, p1, p2, (fw[q, pc], fw[q, pc + 1], fw[q, pc + 2]), nref)
    i3 = _pick(fw, iw, ncand, 1e-6 * ext * ext, pb)
    iw[i3, _IUSED] = 1


@njit(cache=True, inline="always")
def _polytope_manifold(s1, s2, fside, fplane, env, planes, pl_off, pl_cnt, fv_off, fv_cnt,
                       fv_idx, fv_edge, ed_cnt, w_pos, w_R, wa, wb, fw, iw):
    """Face-face contact manifold of two convex polytopes (box/hull), as Chrono's and
    Bullet's polyhedral clipping (Bullet: btPolyhedralContactClipping::clipHullAgainstHull):
    the reference face is the SAT face axis of least penetration (``fplane`` of side
    ``fside``), the incident face the other polytope's face most anti-parallel to it; the
    incident polygon is clipped against the reference face's side planes (Sutherland–
    Hodgman), the points below the reference face plus the envelope are kept and reduced to
    four (:func:`_reduce4`).  Each point is placed halfway between the faces and keyed by
    what it is (a vertex, or an edge of one crossing an edge of the other:
    :func:`_crossing_key`), so that its key persists from step to step.  Returns (k, normal
    from s1 to s2): the points are rows 0..k−1 of fw[:, _FOUT:_FOUT + 3] (gap: column
    _FOUT + 3; key: iw[:, _IOUT]).  fw, iw: work arrays (≥ n_incident + n_reference rows)."""
    if fside == 0:
        sr = s1
        si = s2
        Wr = wa
        Wi = wb
    else:
        sr = s2
        si = s1
        Wr = wb
        Wi = wa
    s_lo = min(s1, s2)
    Rr = w_R[sr]
    nref = mat_vec(Rr, (planes[fplane, 0], planes[fplane, 1], planes[fplane, 2]))
    offr = v_dot(nref, row3(w_pos, sr)) - planes[fplane, 3]
    nab = nref if fside == 0 else v_scale(nref, -1.0)
    # incident face: the most anti-parallel (nref in the incident shape's frame)
    nl = mat_t_vec(w_R[si], nref)
    finc = -1
    dbest = 1e300
    for p in range(pl_off[si], pl_off[si] + pl_cnt[si]):
        d = planes[p, 0] * nl[0] + planes[p, 1] * nl[1] + planes[p, 2] * nl[2]
        if d < dbest:
            dbest = d
            finc = p
    if finc < 0:
        return 0, nab
    fr_off = fv_off[fplane]
    nrv = fv_cnt[fplane]
    fi_off = fv_off[finc]
    niv = fv_cnt[finc]
    ned_r = ed_cnt[sr]
    ned_i = ed_cnt[si]
    for k in range(niv):
        v = fv_idx[fi_off + k]
        for c in range(3):
            fw[k, _FP + c] = Wi[v, c]
        iw[k, _IKEY] = _vertex_key(si, v, s_lo)
        iw[k, _ILAB] = k
    k = _clip_to_face(niv, nrv, fr_off, fv_idx, Wr, nref, offr, env, fw, iw, sr, si, s_lo,
                      fi_off, fv_edge, ned_r, ned_i, -1, True)
    return k, nab


@njit(cache=True, inline="always")
def _clip_to_face(npoly, nrv, fr_off, fv_idx, Wr, nref, offr, env, fw, iw, sr, si, s_lo, fi_off,
                  fv_edge, ned_r, ned_i, ei_base, reduce):
    """Clipping and reduction of :func:`_polytope_manifold` (also the cylinder's,
    :func:`_cylinder_polytope`): the incident polygon (rows 0..npoly−1 of fw[:, 0:3], keys
    iw[:, _IKEY], labels iw[:, _ILAB]) clipped against the side planes of the reference face
    (fv_idx[fr_off:fr_off + nrv] of the world vertices Wr, outward normal nref, plane
    nref·x = offr), its points below the face plus the envelope reduced to four (all of them
    unless ``reduce``); returns their count k (output columns as :func:`_polytope_manifold`'s).
    ``ei_base``: see :func:`_crossing_key`."""
    ext = 0.0
    pc = 0                           # the current polygon's buffer (0 or 1: fw columns 0 / 3)
    mcl = fw.shape[0]
    for j in range(nrv):
        a = row3(Wr, fv_idx[fr_off + j])
        e = v_sub(row3(Wr, fv_idx[fr_off + (j + 1) % nrv]), a)
        ln_e = math.sqrt(v_dot(e, e))
        ext = max(ext, ln_e)
        pn = v_cross(e, nref)
        ln = math.sqrt(v_dot(pn, pn))
        if ln <= 1e-300:
            continue
        pn = v_scale(pn, 1.0 / ln)
        off = v_dot(pn, a)
        eps = 1e-9 * ln_e          # a vertex on a side plane within round-off counts as inside
        c0 = 3 * pc
        c1 = 3 - c0
        dmax = -1e300
        for q in range(npoly):
            dq = fw[q, c0] * pn[0] + fw[q, c0 + 1] * pn[1] + fw[q, c0 + 2] * pn[2] - off
            fw[q, _FSC] = dq
            dmax = max(dmax, dq)
        if dmax <= eps:
            continue               # all inside this side plane: the polygon stays
        nt = 0
        for q in range(npoly):
            if nt + 2 > mcl:
                break              # (only a degenerate polygon could outgrow n_inc + n_ref)
            q2 = q + 1 if q + 1 < npoly else 0
            dp = fw[q, _FSC]
            dq = fw[q2, _FSC]
            inp = dp <= eps
            inq = dq <= eps
            if inp:
                for c in range(3):
                    fw[nt, c1 + c] = fw[q, c0 + c]
                iw[nt, _IKEY + 1 - pc] = iw[q, _IKEY + pc]
                iw[nt, _ILAB + 1 - pc] = iw[q, _ILAB + pc]
                nt += 1
            if inp != inq:
                f = min(max(dp / (dp - dq), 0.0), 1.0)
                for c in range(3):
                    fw[nt, c1 + c] = fw[q, c0 + c] + (fw[q2, c0 + c] - fw[q, c0 + c]) * f
                lab = iw[q, _ILAB + pc]
                iw[nt, _IKEY + 1 - pc] = _crossing_key(lab, j, sr, si, s_lo, fr_off, fi_off, nrv,
                                                       fv_idx, fv_edge, ned_r, ned_i,
                                                       ei_base)
                iw[nt, _ILAB + 1 - pc] = -(j + 1) if inp else lab
                nt += 1
        npoly = nt
        pc = 1 - pc
        if npoly == 0:
            return 0
    # points below the reference face + envelope (coincident ones once)
    c0 = 3 * pc
    ncand = 0
    tol2 = (1e-9 * ext) ** 2
    for q in range(npoly):
        g = nref[0] * fw[q, c0] + nref[1] * fw[q, c0 + 1] + nref[2] * fw[q, c0 + 2] - offr
        fw[q, _FGAP] = g
        if g >= env:
            continue
        dup = False
        for m in range(ncand):
            r = iw[m, _ICAND]
            d0 = fw[q, c0] - fw[r, c0]
            d1 = fw[q, c0 + 1] - fw[r, c0 + 1]
            d2 = fw[q, c0 + 2] - fw[r, c0 + 2]
            if d0 * d0 + d1 * d1 + d2 * d2 <= tol2:
                dup = True
                break
        if not dup:
            iw[ncand, _ICAND] = q
            ncand += 1
    if ncand > 4 and reduce:
        _reduce4(fw, iw, ncand, nref, ext, c0, _IKEY + pc)
    else:
        for m in range(ncand):
            iw[iw[m, _ICAND], _IUSED] = 1
    # the kept points, halfway between the faces, into rows 0..k-1 of the output columns
    k = 0
    for m in range(ncand):
        q = iw[m, _ICAND]
        if iw[q, _IUSED] == 0:
            continue
        g = fw[q, _FGAP]
        for c in range(3):
            fw[k, _FOUT + c] = fw[q, c0 + c] - 0.5 * g * nref[c]
        fw[k, _FOUT + 3] = g
        iw[k, _IOUT] = iw[q, _IKEY + pc]
        k += 1
    return k


# a cylinder against a polytope: its cap is the incident polygon when the cap's normal is
# within this cosine of the reference face's (standing on its end), else the generator line
# of its support along the face normal (lying or tilted); the cap polygon has _CYL_RIM points
_CYL_FLAT = 0.999
_CYL_RIM = 16
_CYL_NED = 2 * _CYL_RIM + 2      # incident edge labels: caps 0..2·_CYL_RIM−1, the line after
_CYL_EKEY = _EKEY0 + _EKEY_MOD + 2 * 9973    # keys of the polytope's edge points


@njit(cache=True, inline="always")
def _cyl_extent(a, L, R, H):
    """Half extent of a cylinder (axis a, radius R, half length H) along the unit axis L:
    its support function about the centre, H|a·L| + R√(1 − (a·L)²)."""
    al = v_dot(a, L)
    return H * abs(al) + R * math.sqrt(max(1.0 - al * al, 0.0))


@njit(cache=True, inline="always")
def _cyl_axis_sep(L, c, a, R, H, W, nv):
    """Separation of a cylinder and a polytope (world vertices W[:nv]) along the unit axis L,
    the larger of its two orientations."""
    lo = 1e300
    hi = -1e300
    for i in range(nv):
        d = L[0] * W[i, 0] + L[1] * W[i, 1] + L[2] * W[i, 2]
        lo = min(lo, d)
        hi = max(hi, d)
    cc = v_dot(L, c)
    ext = _cyl_extent(a, L, R, H)
    return max(lo - (cc + ext), (cc - ext) - hi)


@njit(cache=True)
def _cylinder_polytope(sc, sp, bc, bp, swap, nc, cap, env, keybase, sh_dims, samp_off,
                       samp_cnt, samp_pts, pl_off, pl_cnt, planes, edges, ed_off, ed_cnt, ed_rep,
                       fv_off, fv_cnt, fv_idx, fv_edge, w_pos, w_R, wa, fw, iw,
                       c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key):
    """A cylinder against a box or hull, exactly (Chrono, through Bullet, collides the exact
    cylinder with a box or hull by GJK–EPA; DualSPHysics's bodies are triangle meshes): a
    separating-axis test over the polytope's face normals, the
    cylinder's cap normals, the cross products of its axis with the polytope's edge
    directions, and the radial directions of the polytope's edges parallel to the axis and
    of its vertices beside the curved surface.  A face of the polytope that is the axis of
    least penetration is a plane for the cylinder's exact support along −n (as
    :func:`_cylinder_plane_support`): the generator line of its deepest rim points (one
    point for a tilted cylinder, two for one lying on the face, so that it neither rocks
    nor rolls as a polygon) or, standing on its end (its axis within 2.6° of the normal, as
    :func:`_cylinder_plane_support`), its cap (its _CYL_RIM rim points, all kept: four of
    them, changing as the cap tilts, let a wobbling cylinder rock on); that line or cap
    polygon is clipped to the face (:func:`_clip_to_face`, so that a cylinder
    lying across the face's edge rests on the part on the face).  Otherwise (a cylinder
    axis, or nothing on the face) the polytope's vertices and its edges' points nearest the
    cylinder's axis against the cylinder's exact signed distance (:func:`_cyl_sdf_contact`;
    an edge along the axis: the ends of its part beside the curved surface; an edge across a
    cap: the ends of its chord of the cap's disc, against the cap).  ``swap``: the cylinder
    is the pair's second shape."""
    c = row3(w_pos, sc)
    Rc = w_R[sc]
    a = col(Rc, 2)
    R = sh_dims[sc, 0]
    H = sh_dims[sc, 1]
    Rp = w_R[sp]
    cp = row3(w_pos, sp)
    nv = samp_cnt[sp]
    for i in range(nv):
        x = v_add(cp, mat_vec(Rp, row3(samp_pts, samp_off[sp] + i)))
        wa[i, 0] = x[0]
        wa[i, 1] = x[1]
        wa[i, 2] = x[2]
    s_lo = min(sc, sp)
    # the polytope's faces: the cylinder's deepest point along −n against the face plane
    best_face = -1e300
    fplane = -1
    for p in range(pl_off[sp], pl_off[sp] + pl_cnt[sp]):
        n = mat_vec(Rp, (planes[p, 0], planes[p, 1], planes[p, 2]))
        off = v_dot(n, cp) - planes[p, 3]
        sep = v_dot(n, c) - _cyl_extent(a, n, R, H) - off
        if sep > env:
            return nc
        if sep > best_face:
            best_face = sep
            fplane = p
    # the cylinder's axes
    best_cyl = -1e300
    for sg in range(2):
        sep = _cyl_axis_sep(v_scale(a, 1.0 if sg == 0 else -1.0), c, a, R, H, wa, nv)
        if sep > env:
            return nc
        best_cyl = max(best_cyl, sep)
    oe = ed_off[sp]
    ne = ed_cnt[sp]
    for i in range(ne):
        if ed_rep[oe + i] != i:
            continue
        v0 = row3(wa, edges[oe + i, 0])
        d = v_sub(row3(wa, edges[oe + i, 1]), v0)
        L = v_cross(a, d)
        ln = math.sqrt(v_dot(L, L))
        if ln > 1e-9 * math.sqrt(v_dot(d, d)):
            sep = _cyl_axis_sep(v_scale(L, 1.0 / ln), c, a, R, H, wa, nv)
            if sep > env:
                return nc
            best_cyl = max(best_cyl, sep)
            continue
        # edges parallel to the axis: the radial direction of each
        for j in range(i, ne):
            if ed_rep[oe + j] != i:
                continue
            r = v_sub(row3(wa, edges[oe + j, 0]), c)
            r = v_sub(r, v_scale(a, v_dot(a, r)))
            ln = math.sqrt(v_dot(r, r))
            if ln <= 1e-12 * (R + H):
                continue
            sep = _cyl_axis_sep(v_scale(r, 1.0 / ln), c, a, R, H, wa, nv)
            if sep > env:
                return nc
            best_cyl = max(best_cyl, sep)
    reach = R + max(env, 0.0)
    for i in range(nv):
        r = v_sub(row3(wa, i), c)
        h = v_dot(a, r)
        if abs(h) > H:
            continue
        r = v_sub(r, v_scale(a, h))
        ln = math.sqrt(v_dot(r, r))
        if ln >= reach or ln <= 1e-12 * (R + H):
            continue
        sep = _cyl_axis_sep(v_scale(r, 1.0 / ln), c, a, R, H, wa, nv)
        if sep > env:
            return nc
        best_cyl = max(best_cyl, sep)
    win = best_face + 0.05 * abs(best_face) + 1e-6 * (1.0 + R + H)
    if best_cyl <= win and fplane >= 0:
        # the polytope's face is the reference: the cylinder's support line or cap, clipped
        n = mat_vec(Rp, (planes[fplane, 0], planes[fplane, 1], planes[fplane, 2]))
        offr = v_dot(n, cp) - planes[fplane, 3]
        an = v_dot(a, n)
        if abs(an) >= _CYL_FLAT:
            sgc = -1.0 if an > 0.0 else 1.0          # the cap that faces the face
            base = 0 if sgc < 0.0 else _CYL_RIM
            u = col(Rc, 0)
            w = col(Rc, 1)
            cc = v_add(c, v_scale(a, sgc * H))
            for k in range(_CYL_RIM):
                th = 2.0 * math.pi * k / _CYL_RIM
                x = v_add(cc, v_add(v_scale(u, R * math.cos(th)), v_scale(w, R * math.sin(th))))
                for q in range(3):
                    fw[k, _FP + q] = x[q]
                iw[k, _IKEY] = _vertex_key(sc, base + k, s_lo)
                iw[k, _ILAB] = k
            npoly = _CYL_RIM
        else:
            rdir = v_sub(v_scale(a, an), n)           # −n projected on the cap plane
            rdir = v_scale(rdir, R / math.sqrt(v_dot(rdir, rdir)))
            base = 2 * _CYL_RIM
            for k in range(2):
                x = v_add(v_add(c, v_scale(a, H if k == 0 else -H)), rdir)
                for q in range(3):
                    fw[k, _FP + q] = x[q]
                iw[k, _IKEY] = _vertex_key(sc, base + k, s_lo)
                iw[k, _ILAB] = k
            npoly = 2
        k = _clip_to_face(npoly, fv_cnt[fplane], fv_off[fplane], fv_idx, wa, n, offr, env, fw,
                          iw, sp, sc, s_lo, 0, fv_edge, ed_cnt[sp], _CYL_NED, base, False)
        for m in range(k):
            pt = (fw[m, _FOUT], fw[m, _FOUT + 1], fw[m, _FOUT + 2])
            nc = _emit_sided(nc, cap, swap, bc, bp, sc, sp, pt, n, fw[m, _FOUT + 3],
                             keybase + iw[m, _IOUT], c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key)
        if k > 0:
            return nc
    # the polytope's vertices and edge points against the cylinder's signed distance
    for i in range(nv):
        nc = _cyl_sdf_contact(row3(wa, i), _vertex_key(sp, i, s_lo), sc, sp, bc, bp, swap, nc,
                              cap, env, keybase, c, Rc, R, H,
                              c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key)
    p0 = v_sub(c, v_scale(a, H))
    p1 = v_add(c, v_scale(a, H))
    for i in range(ne):
        e0 = row3(wa, edges[oe + i, 0])
        e1 = row3(wa, edges[oe + i, 1])
        d = v_sub(e1, e0)
        dd = v_dot(d, d)
        if dd <= 1e-300:
            continue
        key = _CYL_EKEY + (3 * i) % 42000
        ad = v_dot(a, d)
        if ad * ad >= (1.0 - 1e-6) * dd:
            # an edge along the axis: the ends of its part beside the curved surface (a line
            # contact), against the curved surface
            h0 = v_dot(a, v_sub(e0, c))
            ta = (-H - h0) / ad
            tb = (H - h0) / ad
            t_lo = max(min(ta, tb), 0.0)
            t_hi = min(max(ta, tb), 1.0)
            if t_lo >= t_hi:
                continue
            # its deepest point between the caps (a lateral contact only where the curved
            # surface is nearer than the caps: not an edge standing on a cap)
            h_lo = h0 + t_lo * ad
            h_hi = h0 + t_hi * ad
            dax = H if h_lo * h_hi <= 0.0 else H - min(abs(h_lo), abs(h_hi))
            for m in range(2):
                tt = min(ta, tb) if m == 0 else max(ta, tb)
                if not (1e-9 < tt < 1.0 - 1e-9):
                    continue
                x = v_add(e0, v_scale(d, tt))
                rel = v_sub(x, c)
                rr = v_sub(rel, v_scale(a, v_dot(a, rel)))
                rho = math.sqrt(v_dot(rr, rr))
                g = rho - R
                if g >= env or rho <= 1e-14 or -g > dax:
                    continue
                nw = v_scale(rr, 1.0 / rho)           # radial (cylinder → polytope)
                pt = v_sub(x, v_scale(nw, 0.5 * g))
                nc = _emit_sided(nc, cap, swap, bc, bp, sc, sp, pt, v_scale(nw, -1.0), g,
                                 keybase + key + 1 + m, c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key)
            continue
        x1, x2 = _closest_segments_t(e0, e1, p0, p1)
        t = v_dot(v_sub(x1, e0), d) / dd
        if 1e-9 < t < 1.0 - 1e-9:
            nc = _cyl_sdf_contact(x1, key, sc, sp, bc, bp, swap, nc, cap, env, keybase, c, Rc,
                                  R, H, c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key)
        # an edge lying across a cap (parallel to it, nearer the cap than the curved
        # surface): the ends of its chord of the cap's disc, against the cap's plane
        if ad * ad > 1e-6 * dd:
            continue
        rel = v_sub(x1, c)
        h = v_dot(a, rel)
        rr = v_sub(rel, v_scale(a, h))
        if H - abs(h) >= R - math.sqrt(v_dot(rr, rr)):
            continue
        # |perp(e0 + t d − c)|² = R²: a quadratic in t (d ⟂ a)
        r0 = v_sub(e0, c)
        r0 = v_sub(r0, v_scale(a, v_dot(a, r0)))
        bq = v_dot(r0, d) / dd
        disc = bq * bq - (v_dot(r0, r0) - R * R) / dd
        if disc <= 0.0:
            continue
        sq = math.sqrt(disc)
        sgn = 1.0 if h >= 0.0 else -1.0
        for m in range(2):
            tt = -bq + (sq if m == 1 else -sq)
            if not (1e-9 < tt < 1.0 - 1e-9):
                continue
            x = v_add(e0, v_scale(d, tt))
            g = sgn * v_dot(a, v_sub(x, c)) - H
            if g >= env:
                continue
            nw = v_scale(a, sgn)                     # outward cap normal (cylinder → polytope)
            pt = v_sub(x, v_scale(nw, 0.5 * g))
            nc = _emit_sided(nc, cap, swap, bc, bp, sc, sp, pt, v_scale(nw, -1.0), g,
                             keybase + key + 1 + m, c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key)
    return nc


@njit(cache=True, inline="always")
def _cyl_sdf_contact(x, key, sc, sp, bc, bp, swap, nc, cap, env, keybase, c, Rc, R, H,
                     c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key):
    """A point x of a polytope (world) against the cylinder's exact signed distance
    (:func:`sdf_local`): a contact when it is within the envelope, its normal the distance's
    gradient (from the cylinder to the polytope)."""
    q = mat_t_vec(Rc, v_sub(x, c))
    rho = math.sqrt(q[0] * q[0] + q[1] * q[1])
    if rho < 1e-14:
        rx, ry = 1.0, 0.0
    else:
        rx, ry = q[0] / rho, q[1] / rho
    dr = rho - R
    dz = abs(q[2]) - H
    sz = math.copysign(1.0, q[2])
    if dr > 0.0 or dz > 0.0:
        er = max(dr, 0.0)
        ez = max(dz, 0.0)
        phi = math.sqrt(er * er + ez * ez)
        gl = (er * rx / phi, er * ry / phi, ez * sz / phi)
    elif dr > dz:
        phi = dr
        gl = (rx, ry, 0.0)
    else:
        phi = dz
        gl = (0.0, 0.0, sz)
    if phi >= env:
        return nc
    gw = mat_vec(Rc, gl)
    pt = v_sub(x, v_scale(gw, 0.5 * phi))
    return _emit_sided(nc, cap, swap, bc, bp, sc, sp, pt, v_scale(gw, -1.0), phi, keybase + key,
                       c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key)


@njit(cache=True)
def _point_like(t):
    return t == SPHERE or t == CLOUD


@njit(cache=True)
def narrow_phase(npair, pairs, env, sh_body, sh_type, sh_dims, samp_off, samp_cnt,
                 samp_pts, samp_rad, pl_off, pl_cnt, planes, cg_meta, cg_start, edges, ed_off,
                 ed_cnt, w_pos, w_R, lo, hi, c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key,
                 samp_nrm, fv_off, fv_cnt, fv_idx, fv_edge, ed_rep):
    """All contacts of the candidate pairs with gap < env.  Returns the count
    (which may exceed the capacity: the caller then grows and calls again).
    ``samp_nrm``: per sample, a cloud particle's outward normal and flag
    (:func:`cloud_surface`; zero for other shapes' samples); ``fv_*``: the face polygons
    of the box/hull planes (System._face_polygons); ``ed_rep``: per box/hull edge, the
    shape-local index of the first edge parallel to it (System._edge_classes)."""
    cap = c_a.shape[0]
    nc = 0
    ns = sh_type.shape[0]
    maxv = 8
    for s in range(ns):
        if sh_type[s] == HULL and samp_cnt[s] > maxv:
            maxv = samp_cnt[s]
    wa = np.empty((maxv, 3))
    wb = np.empty((maxv, 3))
    maxf = 4
    for p in range(fv_cnt.shape[0]):
        maxf = max(maxf, fv_cnt[p])
    for s in range(ns):
        if sh_type[s] == CYLINDER:
            maxf = max(maxf, _CYL_RIM)   # a cylinder's cap polygon (_cylinder_polytope)
            break
    mcl = 2 * maxf + 4               # a clipped polygon: ≤ incident + reference vertices
    # the polytope pairs read each shape's offsets and counts from one row (one cache line,
    # not six: the shapes of successive pairs are far apart in memory)
    meta = np.empty((ns, 7), np.int32)
    for s in range(ns):
        meta[s, 0] = samp_off[s]
        meta[s, 1] = samp_cnt[s]
        meta[s, 2] = pl_off[s]
        meta[s, 3] = pl_cnt[s]
        meta[s, 4] = ed_off[s]
        meta[s, 5] = ed_cnt[s]
        ncls = 0                     # classes of parallel edges (_polytope_sat)
        for e in range(ed_cnt[s]):
            if ed_rep[ed_off[s] + e] == e:
                ncls += 1
        meta[s, 6] = ncls
    m_soff = meta[:, 0]
    m_scnt = meta[:, 1]
    m_poff = meta[:, 2]
    m_pcnt = meta[:, 3]
    m_eoff = meta[:, 4]
    m_ecnt = meta[:, 5]
    m_ccnt = meta[:, 6]
    fw = np.empty((mcl, _NFW))
    iw = np.zeros((mcl, _NIW), np.int64)
    # pairs in the order of their shapes (the sweep's order visits shapes far apart in memory)
    pkey = np.empty(npair, np.int64)
    for q in range(npair):
        pkey[q] = np.int64(min(pairs[q, 0], pairs[q, 1])) * ns + max(pairs[q, 0], pairs[q, 1])
    order = np.argsort(pkey)
    for qq in range(npair):
        q = order[qq]
        s1 = pairs[q, 0]
        s2 = pairs[q, 1]
        # canonical order: lower type first (plane last for the sample loop)
        t1 = sh_type[s1]
        t2 = sh_type[s2]
        if t1 == PLANE:
            s1, s2 = s2, s1
            t1, t2 = t2, t1
        b1 = sh_body[s1]
        b2 = sh_body[s2]
        keybase = (np.int64(min(s1, s2)) * ns + max(s1, s2)) * 1048576
        if (t1 == SPHERE or t1 == CAPSULE) and (t2 == SPHERE or t2 == CAPSULE):
            p1, q1 = _segment_of(t1, sh_dims[s1], w_pos[s1], w_R[s1])
            p2, q2 = _segment_of(t2, sh_dims[s2], w_pos[s2], w_R[s2])
            x1, x2 = closest_segments(p1, q1, p2, q2)
            dv = x2 - x1
            dist = math.sqrt(dv @ dv)
            gap = dist - sh_dims[s1, 0] - sh_dims[s2, 0]
            if gap < env:
                if dist > 1e-14:
                    n = dv / dist
                else:
                    n = np.array([0.0, 0.0, 1.0])
                pt = x1 + n * (sh_dims[s1, 0] + 0.5 * gap)
                nc = _emit(nc, cap, b1, b2, s1, s2, pt, n, gap, keybase,
                           c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key)
            continue
        if ((t1 == CYLINDER and (t2 == BOX or t2 == HULL))
                or (t2 == CYLINDER and (t1 == BOX or t1 == HULL))):
            sw = t2 == CYLINDER
            scy = s2 if sw else s1
            spo = s1 if sw else s2
            bcy = b2 if sw else b1
            bpo = b1 if sw else b2
            nc = _cylinder_polytope(scy, spo, bcy, bpo, sw, nc, cap, env, keybase, sh_dims,
                                    m_soff, m_scnt, samp_pts, m_poff, m_pcnt, planes, edges,
                                    m_eoff, m_ecnt, ed_rep, fv_off, fv_cnt, fv_idx, fv_edge,
                                    w_pos, w_R, wa, fw, iw,
                                    c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key)
            continue
        if (t1 == BOX or t1 == HULL) and (t2 == BOX or t2 == HULL):
            sep, ea, eb, L, fside, fplane = _polytope_sat(s1, s2, env, m_soff, m_scnt,
                                                          samp_pts, m_poff, m_pcnt, planes,
                                                          edges, m_eoff, m_ecnt, ed_rep, m_ccnt,
                                                          w_pos, w_R, wa, wb)
            if sep > env:
                continue  # a separating axis: no contact (also removes SDF lower-bound ghosts)
            if ea < 0 and fplane >= 0:
                k, nab = _polytope_manifold(s1, s2, fside, fplane, env, planes, m_poff, m_pcnt,
                                            fv_off, fv_cnt, fv_idx, fv_edge, m_ecnt, w_pos, w_R,
                                            wa, wb, fw, iw)
                for m in range(k):
                    nc = _emit_t(nc, cap, b1, b2, s1, s2,
                                 (fw[m, _FOUT], fw[m, _FOUT + 1], fw[m, _FOUT + 2]), nab,
                                 fw[m, _FOUT + 3], keybase + iw[m, _IOUT],
                                 c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key)
                if k > 0:
                    continue   # the face-face manifold (else: the vertex-face samples below)
            if ea >= 0:
                pa0 = row3(wa, edges[ed_off[s1] + ea, 0])
                pa1 = row3(wa, edges[ed_off[s1] + ea, 1])
                pb0 = row3(wb, edges[ed_off[s2] + eb, 0])
                pb1 = row3(wb, edges[ed_off[s2] + eb, 1])
                x1, x2 = _closest_segments_t(pa0, pa1, pb0, pb1)
                pt = v_scale(v_add(x1, x2), 0.5)
                nc = _emit_t(nc, cap, b1, b2, s1, s2, pt, L, sep, keybase + 999999,
                             c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key)
        if t1 == CYLINDER and t2 == PLANE:
            nc = _cylinder_plane_support(s1, s2, b1, b2, nc, cap, env, keybase, sh_dims, w_pos,
                                         w_R, c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key)
        if (t1 == SPHERE and t2 == CLOUD) or (t1 == CLOUD and t2 == SPHERE):
            sw = t2 == SPHERE
            nc = _sphere_vs_cloud(s2 if sw else s1, s1 if sw else s2, b2 if sw else b1,
                                  b1 if sw else b2, sw, nc, cap, env, keybase, sh_dims,
                                  samp_off, samp_cnt, samp_pts, samp_nrm, cg_meta, cg_start,
                                  w_pos, w_R, lo, hi, c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap,
                                  c_key)
            continue
        if (((t1 == CAPSULE or t1 == CYLINDER) and t2 == CLOUD)
                or (t1 == CLOUD and (t2 == CAPSULE or t2 == CYLINDER))):
            # the shape's samples (a capsule's axis points, a cylinder's rim points) against
            # the cloud's flat faces (tangent planes), the cloud's edge and corner particles
            # against the shape's exact surface (_samples_vs_sdf, features_only)
            sw = t1 == CLOUD
            sx = s2 if sw else s1
            scl = s1 if sw else s2
            bx = b2 if sw else b1
            bcl = b1 if sw else b2
            nc = _samples_vs_sdf(sx, scl, bx, bcl, sw, nc, cap, env, keybase, sh_type, sh_dims,
                                 samp_off, samp_cnt, samp_pts, samp_rad, pl_off, pl_cnt, planes,
                                 cg_meta, cg_start, w_pos, w_R, lo, hi, sh_body,
                                 c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key, samp_nrm, True)
            nc = _samples_vs_sdf(scl, sx, bcl, bx, not sw, nc, cap, env, keybase, sh_type,
                                 sh_dims, samp_off, samp_cnt, samp_pts, samp_rad, pl_off, pl_cnt,
                                 planes, cg_meta, cg_start, w_pos, w_R, lo, hi, sh_body,
                                 c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key, samp_nrm, True)
            if sh_type[sx] == CYLINDER:
                nc = _cylinder_cloud_support(sx, scl, bx, bcl, sw, nc, cap, env, keybase,
                                             sh_dims, samp_off, samp_pts, samp_nrm, cg_meta,
                                             cg_start, w_pos, w_R,
                                             c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key)
            continue
        pl1 = _point_like(t1)
        pl2 = _point_like(t2)
        rev_a = False
        rev_b = False
        if pl1 and pl2:
            # of two clouds, every sample of the smaller against the other's smooth
            # surface, and the other's feature samples (edges, corners) against the
            # smaller's flat faces
            if t2 == CLOUD and samp_cnt[s1] > samp_cnt[s2]:
                dir_a = False
                dir_b = True
                rev_a = t1 == CLOUD and t2 == CLOUD
            else:
                dir_a = True
                dir_b = False
                rev_b = t1 == CLOUD and t2 == CLOUD
        else:
            dir_a = t1 != PLANE and (pl1 or not pl2)
            dir_b = t2 != PLANE and (pl2 or not pl1)
        if dir_a or rev_a:
            nc = _samples_vs_sdf(s1, s2, b1, b2, False, nc, cap, env, keybase,
                                 sh_type, sh_dims, samp_off, samp_cnt, samp_pts, samp_rad,
                                 pl_off, pl_cnt, planes, cg_meta, cg_start, w_pos, w_R, lo,
                                 hi, sh_body,
                                 c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key, samp_nrm, rev_a)
        if dir_b or rev_b:
            nc = _samples_vs_sdf(s2, s1, b2, b1, True, nc, cap, env, keybase,
                                 sh_type, sh_dims, samp_off, samp_cnt, samp_pts, samp_rad,
                                 pl_off, pl_cnt, planes, cg_meta, cg_start, w_pos, w_R, lo,
                                 hi, sh_body,
                                 c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, c_key, samp_nrm, rev_b)
    return nc


@njit(cache=True)
def contact_materials(nc, c_sa, c_sb, sh_mat, mat_mu, mat_e, c_mu, c_e):
    """Pair rule (Chrono's default composition): μ = min(μ1, μ2), e = min(e1, e2)."""
    for i in range(nc):
        m1 = sh_mat[c_sa[i]]
        m2 = sh_mat[c_sb[i]]
        c_mu[i] = min(mat_mu[m1], mat_mu[m2])
        c_e[i] = min(mat_e[m1], mat_e[m2])


@njit(cache=True)
def match_warm_start(nc, c_key, prev_keys_sorted, prev_gamma3, out_gamma3):
    """Warm start: copy last step's contact impulses for persistent keys."""
    npk = prev_keys_sorted.shape[0]
    for i in range(nc):
        out_gamma3[i, 0] = 0.0
        out_gamma3[i, 1] = 0.0
        out_gamma3[i, 2] = 0.0
        if npk == 0:
            continue
        j = np.searchsorted(prev_keys_sorted, c_key[i])
        if j < npk and prev_keys_sorted[j] == c_key[i]:
            for k in range(3):
                out_gamma3[i, k] = prev_gamma3[j, k]


# ------------------------------------------------------------- SMC (penalty)
@njit(cache=True)
def smc_forces(nc, c_a, c_b, c_sa, c_sb, c_pt, c_n, c_gap, sh_mat, sh_rad, mat_mu, mat_e,
               mat_E, mat_nu, pos, Rb, vel, omega_b, inv_mass, force, torque_w, use_hertz):
    """Smooth contact forces (Hertz, or Hooke when use_hertz is False).

    E* = 1/((1−ν1²)/E1 + (1−ν2²)/E2), R* = R1R2/(R1+R2), δ = −gap,
    Hertz: k_n = (4/3)E*√(R*δ), F_n = k_n δ − γ_n v_n with the damping
    γ_n = −2√(5/6) β √(S_n m*), S_n = 2E*√(R*δ), β = ln e/√(ln²e + π²)
    (Tsuji-type, as in Chrono's SMC Hertz model).  Hooke: k_n = E* R*.
    Tangential: Coulomb-capped viscous friction F_t = −min(μF_n, γ_t|v_t|) t̂
    with γ_t = γ_n (no tangential displacement history)."""
    for i in range(nc):
        gap = c_gap[i]
        if gap >= 0.0:
            continue
        delta = -gap
        a = c_a[i]
        bb = c_b[i]
        m1 = sh_mat[c_sa[i]]
        m2 = sh_mat[c_sb[i]]
        Es = 1.0 / ((1.0 - mat_nu[m1] ** 2) / mat_E[m1] + (1.0 - mat_nu[m2] ** 2) / mat_E[m2])
        R1 = sh_rad[c_sa[i]]
        R2 = sh_rad[c_sb[i]]
        Rs = R1 * R2 / (R1 + R2)
        ma = 1.0 / inv_mass[a] if (a >= 0 and inv_mass[a] > 0.0) else 0.0
        mb = 1.0 / inv_mass[bb] if (bb >= 0 and inv_mass[bb] > 0.0) else 0.0
        if ma > 0.0 and mb > 0.0:
            ms = ma * mb / (ma + mb)
        else:
            ms = ma + mb
        e = min(mat_e[m1], mat_e[m2])
        mu = min(mat_mu[m1], mat_mu[m2])
        n = c_n[i]
        P = c_pt[i]
        # relative velocity of b w.r.t. a at P
        vr = np.zeros(3)
        if bb >= 0:
            vr += vel[bb] + cross(Rb[bb] @ omega_b[bb], P - pos[bb])
        if a >= 0:
            vr -= vel[a] + cross(Rb[a] @ omega_b[a], P - pos[a])
        vn = vr @ n
        vt = vr - vn * n
        lne = math.log(max(e, 1e-6))
        beta = lne / math.sqrt(lne * lne + math.pi * math.pi)
        if use_hertz:
            sq = math.sqrt(Rs * delta)
            kn = 4.0 / 3.0 * Es * sq
            Sn = 2.0 * Es * sq
        else:
            kn = Es * Rs
            Sn = kn
        gn = -2.0 * math.sqrt(5.0 / 6.0) * beta * math.sqrt(Sn * ms)
        Fn = kn * delta - gn * vn
        if Fn < 0.0:
            Fn = 0.0
        vtn = math.sqrt(vt @ vt)
        F = Fn * n
        if vtn > 1e-12:
            ft = min(mu * Fn, gn * vtn)
            F = F - ft * vt / vtn
        # F acts on b, −F on a
        if bb >= 0:
            force[bb] += F
            torque_w[bb] += cross(P - pos[bb], F)
        if a >= 0:
            force[a] -= F
            torque_w[a] -= cross(P - pos[a], F)


# ------------------------------------------------------------ cloud surface
FLAT_TOL = 0.05      # flat: the lattice neighbours lie within this × spacing of the tangent plane
SHIFT_MIN = 0.15     # surface: the neighbours' centroid is off the particle by this × spacing


def _pair_sums(i, w, n):
    """Per particle sums of the rows of w (pairs (i, ·)): bincount per column."""
    w = w.reshape(w.shape[0], -1)
    return np.stack([np.bincount(i, weights=w[:, k], minlength=n) for k in range(w.shape[1])], axis=1)


def cloud_surface(points, radius, plane_normal=None):
    """Surface particles of a particle cloud and their outward normals (set-up, once).

    DualSPHysics's Chrono collides a body as a triangle mesh of its surface (JChronoObjects,
    modelfile AutoActual/AutoDp): flat faces, whatever the particles' lateral alignment.  This
    gives a cloud the same smooth surface, from the particles alone (s = the lattice spacing,
    the median nearest-neighbour distance):

    - surface: the centroid of the neighbours within 1.8 s is more than SHIFT_MIN·s off the
      particle (a face, edge or corner of a filled body), or the neighbours within 1.2 s form a
      single layer (a one-layer wall or floor); the other particles are interior and are dropped;
    - flat: the surface neighbours within 1.2 s (a lattice's first neighbours; a face's particle
      next to an edge keeps only those of its face), less those more than s/2 along the centroid
      offset (the layer behind a plate's particle), span a plane through the particle within
      FLAT_TOL·s: its normal n (least eigenvector of their covariance) is the face's;
      and the neighbours' centroid is not off the particle along the face (the rim of a
      one-layer sheet is not flat);
    - side: n points to the side with no particle along the normal line (within 0.5 s of it,
      0.5..1.5 s away); open on both sides: a two-sided sheet; on neither: a feature;
    - the rest (edges, corners, curved or irregular surfaces) are features, collided as spheres.

    ``plane_normal``: the normal of a 2-D case's plane (all particles in it): normals are then
    taken in that plane.  Returns (surface points (m, 3), (m, 4): normal and flag, s), flag
    1 = flat one-sided, 2 = flat two-sided, 0 = feature (normal unused)."""
    from scipy.spatial import cKDTree
    P = np.asarray(points, float).reshape(-1, 3)
    n = P.shape[0]
    out = np.zeros((n, 4))
    if n < 4:
        return P.copy(), out, 2.0 * radius
    tree = cKDTree(P)
    dnn = tree.query(P, k=2)[0][:, 1]
    s = float(np.median(dnn[dnn > 0])) if np.any(dnn > 0) else 2.0 * radius
    pr = tree.query_pairs(1.8 * s, output_type="ndarray")
    if pr.shape[0] == 0:
        return P.copy(), out, s
    I = np.concatenate([pr[:, 0], pr[:, 1]])
    J = np.concatenate([pr[:, 1], pr[:, 0]])
    D = P[J] - P[I]
    dist = np.sqrt((D * D).sum(axis=1))
    aug = np.zeros((3, 3))
    if plane_normal is not None:
        g = np.asarray(plane_normal, float)
        g = g / np.linalg.norm(g)
        aug = 100.0 * s * s * np.outer(g, g)     # normals in the plane

    def fit(mask):
        """Least-eigenvector normal of the offsets D[mask] per particle, eigenvalues."""
        Dm, Im = D[mask], I[mask]
        M = np.empty((n, 3, 3))
        for a in range(3):
            for b in range(a, 3):
                M[:, a, b] = M[:, b, a] = np.bincount(Im, weights=Dm[:, a] * Dm[:, b], minlength=n)
        lam, vec = np.linalg.eigh(M + aug)
        return lam, vec[:, :, 0]

    cnt = np.bincount(I, minlength=n)
    shift = _pair_sums(I, D, n) / np.maximum(cnt, 1)[:, None]
    near = dist < 1.2 * s
    lam, _ = fit(near)
    sheet = (lam[:, 0] < 1e-3 * s * s) & (lam[:, 1] > 0.5 * s * s)
    surf = ((np.sqrt((shift * shift).sum(axis=1)) > SHIFT_MIN * s) | sheet | (cnt < 4)
            | (lam[:, 1] < 1e-3 * s * s))
    # flatness of the surface neighbourhood: off a sheet, only the neighbours across the
    # centroid's direction (not the layer behind the particle: a two-layer plate stays flat)
    smag = np.sqrt((shift * shift).sum(axis=1))
    nc = shift / np.maximum(smag, 1e-300)[:, None]
    across = (smag[I] <= SHIFT_MIN * s) | (np.abs((D * nc[I]).sum(axis=1)) < 0.5 * s)
    ns = near & surf[J] & across
    lam, nrm = fit(ns)
    dev = np.zeros(n)
    np.maximum.at(dev, I[ns], np.abs((D[ns] * nrm[I[ns]]).sum(axis=1)))
    tang = shift - (shift * nrm).sum(axis=1)[:, None] * nrm      # off-centre along the face: a rim
    flat = (surf & (np.bincount(I[ns], minlength=n) >= 2) & (lam[:, 1] > 0.5 * s * s) & (dev < FLAT_TOL * s)
            & (np.sqrt((tang * tang).sum(axis=1)) < SHIFT_MIN * s))
    # sidedness: a particle on the normal line 0.5..1.5 s away closes that side
    h = (D * nrm[I]).sum(axis=1)
    lat2 = dist * dist - h * h
    online = (lat2 < 0.25 * s * s) & (np.abs(h) > 0.5 * s) & (np.abs(h) < 1.5 * s)
    plus = np.bincount(I[online & (h > 0)], minlength=n) > 0
    minus = np.bincount(I[online & (h < 0)], minlength=n) > 0
    sign = np.where(minus & ~plus, 1.0, np.where(plus & ~minus, -1.0, 1.0))
    out[:, :3] = nrm * sign[:, None]
    out[:, 3] = np.where(flat & (plus ^ minus), 1.0, np.where(flat & ~plus & ~minus, 2.0, 0.0))
    out[out[:, 3] == 0.0, :3] = 0.0
    return P[surf].copy(), out[surf].copy(), s

