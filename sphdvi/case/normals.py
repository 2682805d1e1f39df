"""Boundary normals for mDBC (``Boundary=2``), computed from the particles.

DualSPHysics's GenCase computes a normal per boundary particle from the drawn
geometry: the vector N from the particle to the boundary surface, which lies
dp/2 in front of the outer particle layer; the ghost node is r + 2N. A case that
defines its normals (``<normals>``, ``<special><initialize>``) gets those
(:mod:`sphdvi.case.normal_ops`); for one that does not, or where it asks for them
from the parts (``norparts``), we derive them from the particle arrangement:

1. the neighbours j of boundary particle i (other boundary particles within 2 dp);
2. where the neighbours form a single layer (the smallest eigenvalue of their covariance
   is under a tenth of the next one) the direction is the normal of that layer (its
   eigenvector); otherwise (solid bodies, several wall layers, corners) it is
   −(mean of r_j − r_i) when that offset is clear, pointing away from the boundary's own
   mass, and the layer normal when it is not;
3. the sign is chosen to face the fluid: towards the nearest fluid particle within
   6 dp, or, with no fluid near, towards the centroid of all fluid particles; except
   on floating bodies: a body is wet on every side in time, so its normals point
   out of it, to the nearer of its surfaces along the direction where step 2's
   offset is not clear (facing the fluid on a tie, as on a one-layer plate), as
   GenCase's from the body's outline (the top rows of a floating box, dry at the
   start, would otherwise face the water under the box and point down through it);
4. N = n̂ · (k + 1/2) dp, k the number of boundary layers in front of the particle along n̂
   (found by stepping dp along n̂), so that the ghost node r + 2N lies in the fluid for
   every layer of a thick wall.

Particles of a boundary that never meets the fluid get a normal too; it is harmless.
"""
from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def _grid_keys(pos, inv, lo, nx, ny):
    n = pos.shape[0]
    keys = np.empty(n, np.int64)
    for i in range(n):
        ix = int((pos[i, 0] - lo[0]) * inv)
        iy = int((pos[i, 1] - lo[1]) * inv)
        iz = int((pos[i, 2] - lo[2]) * inv)
        keys[i] = (iz * ny + iy) * nx + ix
    return keys


@njit(cache=True)
def _cell_span(sorted_keys, ix, iy, iz, nx, ny):
    """The rows [a, b) of the key-sorted particles that lie in grid cell (ix, iy, iz)."""
    key = (iz * ny + iy) * nx + ix
    return np.searchsorted(sorted_keys, key), np.searchsorted(sorted_keys, key + 1)


@njit(cache=True)
def _normals_kernel(bpos, nb, fpos, dp, is2d, fcentroid, outward):
    """See the module docstring; brute force over sorted grid cells. The normals of the first
    ``nb`` rows of ``bpos``; the rows after them (periodic images) are neighbours only.
    ``outward[i]``: row i belongs to a floating body (its clear directions are not flipped)."""
    out = np.zeros((nb, 3))
    cell = 2.05 * dp      # a little over the search radius: rounding never hides a neighbour
    lo = np.empty(3)
    hi = np.empty(3)
    for k in range(3):
        lo[k] = bpos[:, k].min() - cell
        hi[k] = bpos[:, k].max() + cell
        if fpos.shape[0] > 0:
            lo[k] = min(lo[k], fpos[:, k].min() - cell)
            hi[k] = max(hi[k], fpos[:, k].max() + cell)
    inv = 1.0 / cell
    nx = int((hi[0] - lo[0]) * inv) + 1
    ny = int((hi[1] - lo[1]) * inv) + 1

    bkeys = _grid_keys(bpos, inv, lo, nx, ny)
    border = np.argsort(bkeys)
    bsorted = bkeys[border]
    fkeys = _grid_keys(fpos, inv, lo, nx, ny)
    forder = np.argsort(fkeys)
    fsorted = fkeys[forder]
    r2 = (2.0 * dp) ** 2 * 1.0001
    reach = 3            # fluid search radius about 6 dp = 3 cells
    for i in range(nb):
        ix = int((bpos[i, 0] - lo[0]) * inv)
        iy = int((bpos[i, 1] - lo[1]) * inv)
        iz = int((bpos[i, 2] - lo[2]) * inv)
        cnt = 0
        cx = 0.0
        cy = 0.0
        cz = 0.0
        cov = np.zeros((3, 3))
        for dz in range(-1, 2):
            for dy in range(-1, 2):
                for dx in range(-1, 2):
                    a, b = _cell_span(bsorted, ix + dx, iy + dy, iz + dz, nx, ny)
                    for q in range(a, b):
                        j = border[q]
                        if j == i:
                            continue
                        ddx = bpos[j, 0] - bpos[i, 0]
                        ddy = bpos[j, 1] - bpos[i, 1]
                        ddz = bpos[j, 2] - bpos[i, 2]
                        if ddx * ddx + ddy * ddy + ddz * ddz > r2:
                            continue
                        cnt += 1
                        cx += ddx
                        cy += ddy
                        cz += ddz
                        d = (ddx, ddy, ddz)
                        for u in range(3):
                            for v in range(3):
                                cov[u, v] += d[u] * d[v]
        n = np.zeros(3)
        if cnt > 0:
            cx /= cnt
            cy /= cnt
            cz /= cnt
        thin = True
        if cnt > 0:
            if is2d:                                # the x-z plane only
                c2 = np.empty((2, 2))
                c2[0, 0], c2[0, 1], c2[1, 0], c2[1, 1] = cov[0, 0], cov[0, 2], cov[2, 0], cov[2, 2]
                w, vecs = np.linalg.eigh(c2)
                n[0], n[1], n[2] = vecs[0, 0], 0.0, vecs[1, 0]
            else:
                w, vecs = np.linalg.eigh(cov)
                n[:] = vecs[:, 0]                   # normal of the local layer
            thin = w[0] < 0.1 * w[1]                # a single layer (line in 2D, sheet in 3D)
        else:
            n[2] = 1.0
        clear = not thin and cx * cx + cy * cy + cz * cz > (0.25 * dp) ** 2
        if clear:
            n[0], n[1], n[2] = -cx, -cy, -cz        # away from the boundary's own mass
        if is2d:
            n[1] = 0.0
        if outward[i]:
            # a floating body: out of it; where n is not clear, to the nearer surface along
            # it (a tie, as on a one-layer plate: face the fluid as a wall does)
            norm = np.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2])
            for k in range(3):
                out[i, k] = n[k] / norm
            if clear:
                continue
            ahead = _layers_along(bpos, i, 1.0, out, dp, lo, inv, nx, ny, bsorted, border)
            behind = _layers_along(bpos, i, -1.0, out, dp, lo, inv, nx, ny, bsorted, border)
            if ahead != behind:
                if behind < ahead:
                    for k in range(3):
                        out[i, k] = -out[i, k]
                continue
        # face the fluid
        best = 1e300
        tx = fcentroid[0] - bpos[i, 0]
        ty = fcentroid[1] - bpos[i, 1]
        tz = fcentroid[2] - bpos[i, 2]
        for dz in range(-reach, reach + 1):
            for dy in range(-reach, reach + 1):
                for dx in range(-reach, reach + 1):
                    a, b = _cell_span(fsorted, ix + dx, iy + dy, iz + dz, nx, ny)
                    for q in range(a, b):
                        j = forder[q]
                        ddx = fpos[j, 0] - bpos[i, 0]
                        ddy = fpos[j, 1] - bpos[i, 1]
                        ddz = fpos[j, 2] - bpos[i, 2]
                        d2 = ddx * ddx + ddy * ddy + ddz * ddz
                        if d2 < best:
                            best = d2
                            tx, ty, tz = ddx, ddy, ddz
        if n[0] * tx + n[1] * ty + n[2] * tz < 0.0:
            n[0], n[1], n[2] = -n[0], -n[1], -n[2]
        norm = np.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2])
        if norm > 0.0:
            for k in range(3):
                out[i, k] = n[k] / norm
    # distance to the surface: dp/2 in front of the last boundary layer along the normal
    for i in range(nb):
        layers = _layers_along(bpos, i, 1.0, out, dp, lo, inv, nx, ny, bsorted, border)
        for k in range(3):
            out[i, k] *= (0.5 + layers) * dp
    return out


@njit(cache=True)
def _layers_along(bpos, i, sign, unit, dp, lo, inv, nx, ny, bsorted, border):
    """The boundary layers in front of particle i along sign * unit[i] (steps of dp that
    land within 0.45 dp of a boundary particle, at most 8)."""
    tol2 = (0.45 * dp) ** 2
    layers = 0
    for step in range(1, 9):
        px = bpos[i, 0] + sign * step * dp * unit[i, 0]
        py = bpos[i, 1] + sign * step * dp * unit[i, 1]
        pz = bpos[i, 2] + sign * step * dp * unit[i, 2]
        ix = int((px - lo[0]) * inv)
        iy = int((py - lo[1]) * inv)
        iz = int((pz - lo[2]) * inv)
        hit = False
        for dz in range(-1, 2):
            for dy in range(-1, 2):
                for dx in range(-1, 2):
                    a, b = _cell_span(bsorted, ix + dx, iy + dy, iz + dz, nx, ny)
                    for q in range(a, b):
                        j = border[q]
                        ddx = bpos[j, 0] - px
                        ddy = bpos[j, 1] - py
                        ddz = bpos[j, 2] - pz
                        if ddx * ddx + ddy * ddy + ddz * ddz < tol2:
                            hit = True
        if not hit:
            break
        layers += 1
    return layers


# how far from a periodic end the images must reach: the fluid search (3 cells of 2.05 dp)
# and the layer count (8 dp along the normal, plus a cell)
PERIODIC_REACH = 9.0


def boundary_normals(pos: np.ndarray, ptype: np.ndarray, dp: float, is2d: bool,
                     periodicity=None) -> np.ndarray:
    """(N, 3) mDBC normals: N for boundary particles (types 0–2), zero for fluid.

    ``periodicity`` (:class:`sphdvi.sph.periodic.Periodicity`): the particles near a periodic
    end see the images of those across it, so a wall that runs through the periodic boundary
    keeps its plane normals there (without them its end columns get corner normals)."""
    pos = np.ascontiguousarray(pos, dtype=np.float64)
    bound = ptype != 3
    fpos = pos[~bound]
    centroid = fpos.mean(axis=0) if fpos.shape[0] else pos.mean(axis=0)
    bpos = pos[bound]
    nb = bpos.shape[0]
    if periodicity is not None and nb:
        src, disp = periodicity.ghosts(pos, PERIODIC_REACH * dp)
        image_bound = bound[src]
        bpos = np.concatenate([bpos, pos[src[image_bound]] + disp[image_bound]])
        fpos = np.concatenate([fpos, pos[src[~image_bound]] + disp[~image_bound]])
    out = np.zeros_like(pos)
    if nb:
        outward = np.ascontiguousarray(ptype[bound] == 2)
        out[bound] = _normals_kernel(np.ascontiguousarray(bpos), nb, np.ascontiguousarray(fpos), float(dp),
                                     bool(is2d), centroid, outward)
    return out


def keep_normals_of(normals: np.ndarray, mkbound: np.ndarray, ptype: np.ndarray,
                    mkbound_list: str) -> tuple[np.ndarray, list[int]]:
    """The normals with those of every boundary particle whose mkbound is not in
    ``mkbound_list`` (DualSPHysics's mk-list form, ``"0-3,7"``) set to zero: mDBC acts
    on the listed boundaries and floating bodies only, the others keep DBC (a particle
    without a normal is a DBC particle, as in DualSPHysics).  ``mkbound``: GenCase's
    mkbound of each particle (any value for fluid ones).  Returns the normals and the
    listed mkbounds that no boundary particle has.  Raises ValueError for a bad list."""
    from .mkrange import parse_mk_range
    wanted = np.asarray(parse_mk_range(mkbound_list), dtype=np.int64)
    bound = ptype != 3
    keep = bound & np.isin(mkbound, wanted)
    out = np.where(keep[:, None], normals, 0.0)
    present = set(np.unique(mkbound[bound]).tolist())
    return out, [int(m) for m in wanted if int(m) not in present]


def one_layer_mkbounds(normals: np.ndarray, ptype: np.ndarray, mkbound: np.ndarray, dp: float) -> list[int]:
    """The fixed and moving mkbounds whose particles with a normal all lie within 0.75 dp of the
    surface: walls one particle thick (the normal of a second layer is 1.5 dp long)."""
    length = np.linalg.norm(normals, axis=1)
    wall = (np.asarray(ptype) <= 1) & (length > 0)
    thin = []
    for mk in np.unique(mkbound[wall]):
        if length[wall & (mkbound == mk)].max() < 0.75 * dp:
            thin.append(int(mk))
    return thin


def mdbc_floating_mask(ptype: np.ndarray, mkbound: np.ndarray, params: dict,
                       normals: np.ndarray | None = None) -> np.ndarray:
    """The floating particles mDBC corrects: ``Boundary`` 2 (any ``SlipMode``), of the
    mkbounds ``MdbcMkbound`` lists (every floating body without a list).  The fluid sees each
    of them with the lattice's volume dp^d, its mass rho0 dp^d (``MassBound``), not its share of
    the body's mass: a boundary particle whose density is extrapolated from the water does not
    rise as a DBC particle's does to make up for a small mass, so a light body's particles would
    be a soft wall that the water slips through (S12's box, rho/rho0 0.5, flooded within 1 s).
    The body's mass and inertia stay the case's (the multibody system's). With ``normals``
    (the case's own, or the run's), only the particles that have one: mDBC corrects no other."""
    from .mkrange import parse_mk_range
    floating = np.asarray(ptype) == 2
    if int(params.get("Boundary", 1)) != 2:
        return np.zeros_like(floating)
    if normals is not None:
        floating = floating & np.any(np.asarray(normals) != 0.0, axis=1)
    listed = str(params.get("MdbcMkbound") or "").strip()
    if not listed:
        return floating
    return floating & np.isin(mkbound, np.asarray(parse_mk_range(listed), dtype=np.int64))
