"""Compiled (numba) loops of the drawing: triangle surfaces, inside-by-parity and seed fill.

All coordinates here are lattice coordinates (node ``k`` at ``k``). Each kernel
works on a boolean sub-array ``out`` whose node (0,0,0) is lattice node ``lo``.
"""
from __future__ import annotations

import numpy as np
from numba import njit

_EPS = 1e-6
# tiny irrational offsets of the parity rays, so a ray never hits an edge or vertex exactly
_RAY_DX = 3.14159265e-7
_RAY_DY = 2.71828183e-7


@njit(cache=True)
def _seg_dist2(px, py, pz, ax, ay, az, bx, by, bz):
    ux, uy, uz = bx - ax, by - ay, bz - az
    L2 = ux * ux + uy * uy + uz * uz
    t = 0.0
    if L2 > 0.0:
        t = ((px - ax) * ux + (py - ay) * uy + (pz - az) * uz) / L2
        if t < 0.0:
            t = 0.0
        elif t > 1.0:
            t = 1.0
    dx = px - (ax + t * ux)
    dy = py - (ay + t * uy)
    dz = pz - (az + t * uz)
    return dx * dx + dy * dy + dz * dz


@njit(cache=True)
def _near_triangle(px, py, pz, ax, ay, az, bx, by, bz, cx, cy, cz, nxv, nyv, nzv,
                   e1x, e1y, e1z, e2x, e2y, e2z, d00, d01, d11, den, wlo, whi, dmax):
    """Is the node within the band (wlo, whi] of the plane and within dmax of the triangle?"""
    w = (px - ax) * nxv + (py - ay) * nyv + (pz - az) * nzv
    if w <= wlo or w > whi:
        return False
    qx, qy, qz = px - w * nxv, py - w * nyv, pz - w * nzv
    vx, vy, vz = qx - ax, qy - ay, qz - az
    d20 = vx * e1x + vy * e1y + vz * e1z
    d21 = vx * e2x + vy * e2y + vz * e2z
    v = (d11 * d20 - d01 * d21) / den
    u = (d00 * d21 - d01 * d20) / den
    if v >= 0.0 and u >= 0.0 and u + v <= 1.0:
        return True
    d2 = _seg_dist2(qx, qy, qz, ax, ay, az, bx, by, bz)
    d2 = min(d2, _seg_dist2(qx, qy, qz, bx, by, bz, cx, cy, cz))
    d2 = min(d2, _seg_dist2(qx, qy, qz, cx, cy, cz, ax, ay, az))
    return d2 <= dmax * dmax


@njit(cache=True)
def raster_triangles(tri, lo, out, wlo, whi, dmax, l1band=False):
    """Mark the nodes near triangles (T,3,3).

    A node is marked when its signed distance ``w`` to the triangle's plane is
    in (wlo, whi] and its projection lies within ``dmax`` of the triangle.
    Surfaces use (-1/2, 1/2] and 1/2 (one node layer, never a gap a 6-connected
    path can cross; edges reach the nearest node, like box faces); "on the
    surface" tests use a band of a few 1e-6. Only the nodes of the band are
    visited: the loop runs over the two axes most parallel to the plane and
    solves the band for the third.
    """
    shape = out.shape
    p = np.empty(3)
    for t in range(tri.shape[0]):
        ax, ay, az = tri[t, 0, 0], tri[t, 0, 1], tri[t, 0, 2]
        bx, by, bz = tri[t, 1, 0], tri[t, 1, 1], tri[t, 1, 2]
        cx, cy, cz = tri[t, 2, 0], tri[t, 2, 1], tri[t, 2, 2]
        e1x, e1y, e1z = bx - ax, by - ay, bz - az
        e2x, e2y, e2z = cx - ax, cy - ay, cz - az
        n = np.array([e1y * e2z - e1z * e2y, e1z * e2x - e1x * e2z, e1x * e2y - e1y * e2x])
        nn = np.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2])
        if not nn > 1e-12:
            continue
        n /= nn
        # l1band (2D cases): the band's half-widths times |nx| + |nz|, the plane's cut with the
        # y = const lattice as thick as a 4-connected digital line (y does not count); |ny| where
        # larger (a face lying in, or nearly in, the case's plane keeps a band about it)
        sc = max(abs(n[0]) + abs(n[2]), abs(n[1])) if l1band else 1.0
        wl, wh = wlo * sc, whi * sc
        h = dmax + max(-wl, wh)  # a marked node is within this distance of the triangle
        d00 = e1x * e1x + e1y * e1y + e1z * e1z
        d01 = e1x * e2x + e1y * e2y + e1z * e2z
        d11 = e2x * e2x + e2y * e2y + e2z * e2z
        den = d00 * d11 - d01 * d01
        # index ranges of the triangle's box widened by h, in sub-array indices
        r0 = np.empty(3, dtype=np.int64)
        r1 = np.empty(3, dtype=np.int64)
        r0[0] = max(int(np.ceil(min(ax, bx, cx) - h)) - lo[0], 0)
        r1[0] = min(int(np.floor(max(ax, bx, cx) + h)) - lo[0], shape[0] - 1)
        r0[1] = max(int(np.ceil(min(ay, by, cy) - h)) - lo[1], 0)
        r1[1] = min(int(np.floor(max(ay, by, cy) + h)) - lo[1], shape[1] - 1)
        r0[2] = max(int(np.ceil(min(az, bz, cz) - h)) - lo[2], 0)
        r1[2] = min(int(np.floor(max(az, bz, cz) + h)) - lo[2], shape[2] - 1)
        if r0[0] > r1[0] or r0[1] > r1[1] or r0[2] > r1[2]:
            continue
        # solve for the axis c where the normal is largest
        c = 0
        if abs(n[1]) > abs(n[c]):
            c = 1
        if abs(n[2]) > abs(n[c]):
            c = 2
        a_ = (c + 1) % 3
        b_ = (c + 2) % 3
        A = np.array([ax, ay, az])
        for i in range(r0[a_], r1[a_] + 1):
            p[a_] = float(i + lo[a_])
            for j in range(r0[b_], r1[b_] + 1):
                p[b_] = float(j + lo[b_])
                # w = s + n_c * (p_c - A_c) in (wlo, whi]
                s = (p[a_] - A[a_]) * n[a_] + (p[b_] - A[b_]) * n[b_]
                t0 = A[c] + (wl - s) / n[c]
                t1 = A[c] + (wh - s) / n[c]
                if t0 > t1:
                    t0, t1 = t1, t0
                k0 = max(int(np.floor(t0)) - lo[c], r0[c])
                k1 = min(int(np.ceil(t1)) - lo[c], r1[c])
                for k in range(k0, k1 + 1):
                    p[c] = float(k + lo[c])
                    if _near_triangle(p[0], p[1], p[2], ax, ay, az, bx, by, bz, cx, cy, cz,
                                      n[0], n[1], n[2], e1x, e1y, e1z, e2x, e2y, e2z,
                                      d00, d01, d11, den, wl, wh, dmax):
                        # (i, j, k) run along axes (c+1, c+2, c)
                        if c == 0:
                            out[k, i, j] = True
                        elif c == 1:
                            out[j, k, i] = True
                        else:
                            out[i, j, k] = True


@njit(cache=True)
def _ray_hit(px, py, ax, ay, bx, by, cx, cy):
    """Does the vertical ray at (px, py) cross the xy-projection of the triangle?"""
    d1 = (bx - ax) * (py - ay) - (by - ay) * (px - ax)
    d2 = (cx - bx) * (py - by) - (cy - by) * (px - bx)
    d3 = (ax - cx) * (py - cy) - (ay - cy) * (px - cx)
    return (d1 > 0 and d2 > 0 and d3 > 0) or (d1 < 0 and d2 < 0 and d3 < 0)


@njit(cache=True)
def _column_crossings(tri, lo, nx, ny, counts, start, zs, record):
    """Count (record=False) or store (record=True) the z crossings of every node column."""
    fill = np.zeros(nx * ny, dtype=np.int64)
    for t in range(tri.shape[0]):
        ax, ay, az = tri[t, 0, 0], tri[t, 0, 1], tri[t, 0, 2]
        bx, by, bz = tri[t, 1, 0], tri[t, 1, 1], tri[t, 1, 2]
        cx, cy, cz = tri[t, 2, 0], tri[t, 2, 1], tri[t, 2, 2]
        e1x, e1y, e1z = bx - ax, by - ay, bz - az
        e2x, e2y, e2z = cx - ax, cy - ay, cz - az
        nzv = e1x * e2y - e1y * e2x
        if nzv == 0.0:
            continue
        nxv = e1y * e2z - e1z * e2y
        nyv = e1z * e2x - e1x * e2z
        i0 = max(int(np.floor(min(ax, bx, cx))) - lo[0], 0)
        i1 = min(int(np.ceil(max(ax, bx, cx))) - lo[0], nx - 1)
        j0 = max(int(np.floor(min(ay, by, cy))) - lo[1], 0)
        j1 = min(int(np.ceil(max(ay, by, cy))) - lo[1], ny - 1)
        for i in range(i0, i1 + 1):
            px = float(i + lo[0]) + _RAY_DX
            for j in range(j0, j1 + 1):
                py = float(j + lo[1]) + _RAY_DY
                if not _ray_hit(px, py, ax, ay, bx, by, cx, cy):
                    continue
                c = i * ny + j
                if record:
                    zs[start[c] + fill[c]] = az - (nxv * (px - ax) + nyv * (py - ay)) / nzv
                    fill[c] += 1
                else:
                    counts[c] += 1


@njit(cache=True)
def parity_inside(tri, lo, out):
    """Mark nodes inside a closed triangle mesh (even-odd rule along z rays).

    Each (x, y) node column casts a ray along z; crossings are sorted and the
    nodes between crossing pairs (within 1e-6 of them) are inside. Columns with
    an odd number of crossings (an open mesh) fill only complete pairs.
    """
    nx, ny, nz = out.shape
    counts = np.zeros(nx * ny, dtype=np.int64)
    start = np.zeros(nx * ny + 1, dtype=np.int64)
    zs = np.empty(0, dtype=np.float64)
    _column_crossings(tri, lo, nx, ny, counts, start, zs, False)
    for c in range(nx * ny):
        start[c + 1] = start[c] + counts[c]
    zs = np.empty(start[nx * ny], dtype=np.float64)
    _column_crossings(tri, lo, nx, ny, counts, start, zs, True)
    for c in range(nx * ny):
        m = counts[c]
        if m < 2:
            continue
        i = c // ny
        j = c % ny
        col = np.sort(zs[start[c]:start[c] + m])
        for p in range(0, m - 1, 2):
            k0 = max(int(np.ceil(col[p] - _EPS)) - lo[2], 0)
            k1 = min(int(np.floor(col[p + 1] + _EPS)) - lo[2], nz - 1)
            for k in range(k0, k1 + 1):
                out[i, j, k] = True


@njit(cache=True)
def seed_fill(codes, fillable, seed, lo, hi, newcode, allowed):
    """Flood fill (6-connected) from ``seed`` through nodes whose code is fillable.

    Only nodes within the inclusive index box lo..hi where ``allowed`` (shaped as
    that box; empty for all of it) is True are visited. Every reached node gets
    ``newcode``. Returns the number of nodes filled.
    """
    if not fillable[codes[seed[0], seed[1], seed[2]]]:
        return 0
    if allowed.size == 0:
        visited = np.zeros((hi[0] - lo[0] + 1, hi[1] - lo[1] + 1, hi[2] - lo[2] + 1), dtype=np.bool_)
    elif not allowed[seed[0] - lo[0], seed[1] - lo[1], seed[2] - lo[2]]:
        return 0
    else:
        visited = ~allowed
    cap = 1024
    stack = np.empty((cap, 3), dtype=np.int64)
    stack[0, 0], stack[0, 1], stack[0, 2] = seed[0], seed[1], seed[2]
    top = 1
    visited[seed[0] - lo[0], seed[1] - lo[1], seed[2] - lo[2]] = True
    filled = 0
    while top > 0:
        top -= 1
        i, j, k = stack[top, 0], stack[top, 1], stack[top, 2]
        codes[i, j, k] = newcode
        filled += 1
        for d in range(6):
            a, b, c = i, j, k
            if d == 0:
                a -= 1
            elif d == 1:
                a += 1
            elif d == 2:
                b -= 1
            elif d == 3:
                b += 1
            elif d == 4:
                c -= 1
            else:
                c += 1
            if a < lo[0] or a > hi[0] or b < lo[1] or b > hi[1] or c < lo[2] or c > hi[2]:
                continue
            if visited[a - lo[0], b - lo[1], c - lo[2]]:
                continue
            if not fillable[codes[a, b, c]]:
                continue
            visited[a - lo[0], b - lo[1], c - lo[2]] = True
            if top == cap:
                cap *= 2
                bigger = np.empty((cap, 3), dtype=np.int64)
                bigger[:top] = stack[:top]
                stack = bigger
            stack[top, 0], stack[top, 1], stack[top, 2] = a, b, c
            top += 1
    return filled


@njit(cache=True)
def interpolate_on_triangles(px, py, pz, tri, xs, ys, z, found):
    """Linear (barycentric) interpolation of the heights pz of the points (px, py) over their
    triangles ``tri`` (T, 3) at the nodes (xs[i], ys[j]) of a grid (xs, ys increasing): z[j, i] and
    found[j, i] = True for every node inside a triangle or on its edges (1e-9 in barycentric terms);
    a node on a shared edge takes its first triangle's value (the same, the surface being
    continuous there)."""
    eps = 1e-9
    for t in range(tri.shape[0]):
        a, b, c = tri[t, 0], tri[t, 1], tri[t, 2]
        x0, y0, x1, y1, x2, y2 = px[a], py[a], px[b], py[b], px[c], py[c]
        det = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
        if det == 0.0:
            continue
        xmin, xmax = min(x0, x1, x2), max(x0, x1, x2)
        ymin, ymax = min(y0, y1, y2), max(y0, y1, y2)
        padx = eps * (xmax - xmin) + 1e-12 * (abs(xmin) + abs(xmax))
        pady = eps * (ymax - ymin) + 1e-12 * (abs(ymin) + abs(ymax))
        i0 = np.searchsorted(xs, xmin - padx)
        i1 = np.searchsorted(xs, xmax + padx, side="right")
        j0 = np.searchsorted(ys, ymin - pady)
        j1 = np.searchsorted(ys, ymax + pady, side="right")
        for j in range(j0, j1):
            y = ys[j]
            for i in range(i0, i1):
                if found[j, i]:
                    continue
                x = xs[i]
                l1 = ((x - x0) * (y2 - y0) - (x2 - x0) * (y - y0)) / det
                l2 = ((x1 - x0) * (y - y0) - (x - x0) * (y1 - y0)) / det
                l0 = 1.0 - l1 - l2
                if l0 >= -eps and l1 >= -eps and l2 >= -eps:
                    z[j, i] = l0 * pz[a] + l1 * pz[b] + l2 * pz[c]
                    found[j, i] = True
