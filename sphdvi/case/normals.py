"""Boundary normals for mDBC (``Boundary=2``), computed from the particles.

DualSPHysics's GenCase computes a normal per boundary particle from the drawn
geometry: the vector N from the particle to the boundary surface, which lies
dp/2 in front of the outer particle layer; the ghost node is r + 2N. A case that
defines its normals (``<normals>``, ``<special><initialize>``) gets those
(:mod:`sphdvi.case.normal_ops`); for one that does not, or where it asks for them
from the parts (``norparts``), we derive them from the particle arrangement.

Where the boundary particles lie on GenCase's lattice (every drawn shape does), the
surface is the one they fill: the boundary of the union of their dp cells. N is the
vector to the nearest point of an open (particle-free) cell, which is GenCase's outline
dp/2 in front of the wall for flat walls, edges and corners alike (the particles under a
corner point to the outline's corner, the floor beside it straight up):

1. a fixed or moving boundary looks at the open cells inside the particles' bounding box
   (a tank's outside is not water) on the side of the fluid: the vector to the surface must
   have a positive component towards the nearest fluid particle within 8 dp (an exact
   radius, so that the choice does not depend on the particles' order or on how a search grid
   falls on them), or, with no fluid near, towards the centroid of all fluid particles (the
   back layers of a thick wall or flap face the water, not the dry air behind them);
2. a floating body looks at every open cell around it: a body is wet on every side in time,
   so its normals point out of it (the top rows of a floating box, dry at the start, would
   otherwise face the water under the box and point down through it).

Of equally near points, one on a flat wall, then the one most towards the fluid. The lattice
surface of a curved or sloping wall is a staircase. So where the nearest point lies on a
face whose straight run is shorter than RUN_MIN faces along one of its axes (the steps of a
slope steeper than about 20 degrees or of a curve; a wall or a corner of two walls runs on),
where a particle's neighbours (other boundary particles within 2 dp) form a single layer
(the smallest eigenvalue of their covariance under a tenth of the next one) that is oblique
(its normal more than 15 degrees from every axis), on one-layer floating plates, and where
the particles are off the lattice, the normal is derived from the neighbours instead:

a. the direction is the normal of that layer (its eigenvector) on a single layer; otherwise
   −(mean of r_j − r_i) when that offset is clear, pointing away from the boundary's own mass,
   and the layer normal when it is not;
b. its sign faces the fluid as in 1, except on floating bodies, where it points out of the
   body, to the nearer of its surfaces along it (facing the fluid on a tie, as on a one-layer
   plate);
c. N = n̂ · (k + 1/2) dp, k the number of boundary layers in front of the particle along n̂
   (found by stepping dp along n̂), so that the ghost node r + 2N lies in the fluid for
   every layer of a thick wall;
d. on a fixed or moving boundary of several layers, where that N points away from the nearest
   open point or puts the ghost node in a boundary particle's cell, the lattice surface is
   used after all: the nearest point on flat walls (towards the fluid), else the nearest open
   point. That is the top of a tank's wall, where the neighbours are one-sided and the fluid
   may lie on one side of the tank only: GenCase draws its layers one dp higher each, a
   staircase, and the derived N pointed into the wall (ghost node inside it) or, 4.5 dp long,
   out of the tank (a ghost node never submerged: a wall particle switched off for ever
   with SlipMode 2, 3), differently on the two walls of a mirror-symmetric tank.

Particles of a boundary that never meets the fluid get a normal too; it is harmless.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

# a single layer whose normal is further than 15 degrees from every axis is a slope or a curve
# (its lattice surface a staircase): its normal comes from its neighbours
OBLIQUE_COS = float(np.cos(np.radians(15.0)))
# a face of the lattice surface in a straight run this long (in faces: it and those in line with it,
# both ways, along each of its axes) is part of a flat wall; the staircase of a slope steeper than
# about 20 degrees has shorter runs
RUN_MIN = 3
# the most cells of the lattice grid (bytes); a bigger scene derives every normal from the neighbours
MAX_LATTICE_CELLS = 200_000_000


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
def _toward_fluid(bpos, i, fpos, fsorted, forder, lo, inv, nx, ny, fcentroid, reach, rmax2):
    """The vector from boundary particle i to the nearest fluid particle within sqrt(``rmax2``)
    (``reach`` grid cells cover that radius), or to the centroid of all fluid particles when
    none is that near. An exact radius: which fluid particle counts does not depend on how the
    search grid falls on the particles (a mirror image of the scene gets the mirror image)."""
    ix = int((bpos[i, 0] - lo[0]) * inv)
    iy = int((bpos[i, 1] - lo[1]) * inv)
    iz = int((bpos[i, 2] - lo[2]) * inv)
    best = rmax2
    t = np.empty(3)
    for k in range(3):
        t[k] = fcentroid[k] - bpos[i, k]
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
                        t[0], t[1], t[2] = ddx, ddy, ddz
    return t


@njit(cache=True)
def _nearest_open_point(p, cell, solid, glo, ilo, ihi, origin, dp, is2d, floating, t, out, flat_only):
    """The nearest point to ``p`` of the open lattice cells (``solid`` False) within 9 cells of
    ``cell`` (p's lattice index): the cell boxes of side dp about origin + index * dp. A fixed
    boundary (not ``floating``) takes cells inside [ilo, ihi] (the particles' bounding box) whose
    point lies towards ``t`` (the fluid); of equally near points one on flat walls
    (:func:`_on_flat_walls`), then the one most along ``t``; with ``flat_only`` points on flat
    walls only. Writes the vector p -> point to ``out``; returns 2 when that point lies on flat
    walls, 1 when not, 0 when no open cell is that near."""
    tn = np.sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2])
    tol = 1e-9 * dp
    best = 1e300
    best_along = -2.0
    found = False
    flat = False
    cc_arr = np.zeros(3, np.int64)
    q_arr = np.zeros(3)
    v = np.empty(3)
    half = 0.5 * dp
    for r in range(1, 10):
        if found and (r - 0.5) * dp > best + tol:
            break
        ry = 0 if is2d else r
        for dz in range(-r, r + 1):
            for dy in range(-ry, ry + 1):
                for dx in range(-r, r + 1):
                    if max(abs(dx), abs(dy), abs(dz)) != r:
                        continue
                    c0, c1, c2 = cell[0] + dx, cell[1] + dy, cell[2] + dz
                    g0, g1, g2 = c0 - glo[0], c1 - glo[1], c2 - glo[2]
                    if (g0 < 0 or g1 < 0 or g2 < 0 or g0 >= solid.shape[0] or g1 >= solid.shape[1]
                            or g2 >= solid.shape[2] or solid[g0, g1, g2]):
                        continue
                    if not floating and (c0 < ilo[0] or c0 > ihi[0] or c1 < ilo[1] or c1 > ihi[1]
                                         or c2 < ilo[2] or c2 > ihi[2]):
                        continue
                    cc = (c0, c1, c2)
                    for k in range(3):
                        centre = origin[k] + cc[k] * dp
                        q = min(max(p[k], centre - half), centre + half)
                        v[k] = q - p[k]
                    if is2d:
                        v[1] = 0.0
                    along = v[0] * t[0] + v[1] * t[1] + v[2] * t[2]
                    if not floating and along <= 1e-6 * dp * tn:      # not towards the fluid (rounding aside)
                        continue
                    d = np.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
                    if d > best + tol:
                        continue
                    along = along / (d * tn) if d > 0.0 and tn > 0.0 else 0.0
                    cc_arr[0], cc_arr[1], cc_arr[2] = c0, c1, c2
                    for k in range(3):
                        q_arr[k] = p[k] + v[k]
                    is_flat = _on_flat_walls(solid, glo, cc_arr, q_arr, origin, dp, is2d)
                    if flat_only and not is_flat:
                        continue
                    if (d < best - tol or (is_flat and not flat)
                            or (is_flat == flat and along > best_along)):
                        best = min(best, d)
                        best_along = along
                        flat = is_flat
                        found = True
                        out[0], out[1], out[2] = v[0], v[1], v[2]
    if not found:
        return 0
    return 2 if flat else 1


@njit(cache=True)
def _is_solid(solid, glo, c0, c1, c2):
    g0, g1, g2 = c0 - glo[0], c1 - glo[1], c2 - glo[2]
    if g0 < 0 or g1 < 0 or g2 < 0 or g0 >= solid.shape[0] or g1 >= solid.shape[1] or g2 >= solid.shape[2]:
        return False
    return solid[g0, g1, g2]


@njit(cache=True)
def _run_along(solid, glo, cell, a, sgn, b):
    """The faces in line with the face of open ``cell`` towards the solid cell ``sgn`` along axis
    ``a``, along axis ``b`` (both ways, this one included, at most 2 RUN_MIN - 1): open cells
    with a solid cell beside them on the same side."""
    n = 1
    for direction in (1, -1):
        c = cell.copy()
        for _ in range(RUN_MIN):
            c[b] += direction
            beside = c.copy()
            beside[a] += sgn
            if _is_solid(solid, glo, c[0], c[1], c[2]) or not _is_solid(solid, glo, beside[0], beside[1], beside[2]):
                break
            n += 1
    return n


@njit(cache=True)
def _on_flat_walls(solid, glo, cell, q, origin, dp, is2d):
    """Whether the point ``q`` of open ``cell`` lies on flat walls of the lattice surface: every
    face of the cell that holds q and borders a solid cell runs straight for RUN_MIN faces or
    more along each of its axes (a wall, or a corner of two walls), not a staircase of a slope or
    a curve, whose steps are shorter."""
    faces = 0
    for a in range(3):
        if is2d and a == 1:
            continue
        for sgn in (-1, 1):
            plane = origin[a] + (cell[a] + 0.5 * sgn) * dp
            if abs(q[a] - plane) > 1e-9 * dp:
                continue
            beside = cell.copy()
            beside[a] += sgn
            if not _is_solid(solid, glo, beside[0], beside[1], beside[2]):
                continue
            faces += 1
            for b in range(3):
                if b == a or (is2d and b == 1):
                    continue
                if _run_along(solid, glo, cell, a, sgn, b) < RUN_MIN:
                    return False
    return faces > 0


@njit(cache=True)
def _normals_kernel(bpos, nb, fpos, dp, is2d, fcentroid, outward, lattice, solid, glo, ilo, ihi, origin):
    """See the module docstring; brute force over sorted grid cells. The normals of the first
    ``nb`` rows of ``bpos``; the rows after them (periodic images) are neighbours only.
    ``outward[i]``: row i belongs to a floating body. ``lattice``: the boundary particles lie
    on the lattice of ``origin`` and dp; then ``solid`` flags the cells they fill (index minus
    ``glo``) and [ilo, ihi] bound the cells of the particles' bounding box."""
    out = np.zeros((nb, 3))
    done = np.zeros(nb, np.bool_)            # N final (the lattice surface)
    near = np.zeros((nb, 3))                 # the nearest open point off flat walls (fixed boundaries)
    has_near = np.zeros(nb, np.bool_)
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
    # fluid search radius 8 dp (4 cells; exact, rounding aside: independent of the grid's alignment)
    reach = 4
    rmax2 = (8.0 * dp) ** 2 * (1.0 + 1e-9)
    lidx = np.zeros(3, np.int64)
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
        t = _toward_fluid(bpos, i, fpos, fsorted, forder, lo, inv, nx, ny, fcentroid, reach, rmax2)
        oblique = thin and max(abs(n[0]), abs(n[1]), abs(n[2])) < OBLIQUE_COS
        if lattice and not (thin and (oblique or outward[i])):
            for k in range(3):
                lidx[k] = int(np.rint((bpos[i, k] - origin[k]) / dp))
            if is2d:
                lidx[1] = 0
            v = np.zeros(3)
            found = _nearest_open_point(bpos[i], lidx, solid, glo, ilo, ihi, origin, dp, is2d, outward[i], t, v,
                                        False)
            if found == 2:
                out[i, :] = v
                done[i] = True
                continue
            if found == 1 and not outward[i] and not thin:
                near[i, :] = v
                has_near[i] = True
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
        if n[0] * t[0] + n[1] * t[1] + n[2] * t[2] < 0.0:
            n[0], n[1], n[2] = -n[0], -n[1], -n[2]
        norm = np.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2])
        if norm > 0.0:
            for k in range(3):
                out[i, k] = n[k] / norm
    # distance to the surface: dp/2 in front of the last boundary layer along the normal
    for i in range(nb):
        if done[i]:
            continue
        layers = _layers_along(bpos, i, 1.0, out, dp, lo, inv, nx, ny, bsorted, border)
        for k in range(3):
            out[i, k] *= (0.5 + layers) * dp
    # a neighbour-derived N that points away from the nearest open point or puts the ghost node
    # r + 2N inside the boundary (the end of a wall, where the neighbours are one-sided) gives way
    # to the lattice surface
    for i in range(nb):
        if not has_near[i]:
            continue
        dot = out[i, 0] * near[i, 0] + out[i, 1] * near[i, 1] + out[i, 2] * near[i, 2]
        if dot > -1e-6 * dp * dp and not _ghost_in_solid(bpos[i], out[i], solid, glo, origin, dp, is2d):
            continue
        t = _toward_fluid(bpos, i, fpos, fsorted, forder, lo, inv, nx, ny, fcentroid, reach, rmax2)
        for k in range(3):
            lidx[k] = int(np.rint((bpos[i, k] - origin[k]) / dp))
        if is2d:
            lidx[1] = 0
        v = np.zeros(3)
        if _nearest_open_point(bpos[i], lidx, solid, glo, ilo, ihi, origin, dp, is2d, False, t, v, True) == 2:
            out[i, :] = v                   # the nearest point on flat walls
        else:
            out[i, :] = near[i]
    return out


@njit(cache=True)
def _ghost_in_solid(p, nvec, solid, glo, origin, dp, is2d):
    """Whether the ghost node p + 2 ``nvec`` lies in a lattice cell that a boundary particle fills."""
    c0 = int(np.rint((p[0] + 2.0 * nvec[0] - origin[0]) / dp))
    c1 = 0 if is2d else int(np.rint((p[1] + 2.0 * nvec[1] - origin[1]) / dp))
    c2 = int(np.rint((p[2] + 2.0 * nvec[2] - origin[2]) / dp))
    return _is_solid(solid, glo, c0, c1, c2)


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
        grid = lattice_cells(bpos, fpos, float(dp), bool(is2d))
        lattice = grid is not None
        if grid is None:
            grid = (np.zeros((1, 1, 1), np.bool_), np.zeros(3, np.int64), np.zeros(3, np.int64),
                    np.zeros(3, np.int64), np.zeros(3))
        out[bound] = _normals_kernel(np.ascontiguousarray(bpos), nb, np.ascontiguousarray(fpos), float(dp),
                                     bool(is2d), centroid, outward, lattice, *grid)
    return out


def lattice_cells(bpos: np.ndarray, fpos: np.ndarray, dp: float, is2d: bool):
    """The lattice the boundary particles fill: (solid, glo, ilo, ihi, origin), with ``solid``
    a grid of cells (index minus ``glo``) that flags those holding a boundary particle, 10 cells
    beyond the particles' bounding box [ilo, ihi] (cell indices, fluid included) on each side
    (none across the plane of a 2D case). None when a boundary particle lies off the lattice
    of the first one (more than dp/1000 away: a body rotated off it, particles loaded from a
    file) or the grid would exceed MAX_LATTICE_CELLS."""
    origin = bpos[0].copy()
    rel = (bpos - origin) / dp
    idx = np.rint(rel)
    axes = [0, 2] if is2d else [0, 1, 2]
    if np.abs(rel - idx)[:, axes].max() > 1e-3:
        return None
    idx = idx.astype(np.int64)
    allrel = rel if not len(fpos) else np.vstack([rel, (fpos - origin) / dp])
    ilo = np.ceil(allrel.min(axis=0) - 1e-6).astype(np.int64)
    ihi = np.floor(allrel.max(axis=0) + 1e-6).astype(np.int64)
    margin = np.array([10, 0 if is2d else 10, 10])
    if is2d:
        idx[:, 1] = 0
        ilo[1] = ihi[1] = 0
    glo = ilo - margin
    shape = ihi - ilo + 1 + 2 * margin
    if np.prod(shape.astype(float)) > MAX_LATTICE_CELLS:
        return None
    solid = np.zeros(tuple(int(s) for s in shape), np.bool_)
    g = idx - glo
    solid[g[:, 0], g[:, 1], g[:, 2]] = True
    return solid, glo, ilo, ihi, origin


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


def layers_needed(h: float, dp: float) -> int:
    """Wall layers a fluid particle dp/2 off a wall reaches (kernel support 2h; its layers at
    dp, 2 dp, ... from it, each counted if it lies closer than 2h, where the kernel is 0): 2 in
    2D and 3 in 3D at coefh 1, 3 at h = 2 dp (DualSPHysics's examples/mdbc/04_Dambreak, hdp 2,
    three layers: its fourth would lie at 2h)."""
    return max(1, int(math.ceil(2.0 * h / dp - 1e-9)) - 1)


def thin_wall_mkbounds(pos: np.ndarray, normals: np.ndarray, ptype: np.ndarray, mkbound: np.ndarray,
                       dp: float, h: float, inward: np.ndarray | None = None) -> dict:
    """Fixed and moving mkbounds with a flat face thinner than the kernel's reach: mkbound ->
    (the fewest layers found behind a face particle, the number of such thin face particles).
    A face particle is a first-layer particle (normal dp/2 long) whose normal is along an axis;
    its wall is counted along -normal on the lattice, up to :func:`layers_needed` layers.  mDBC
    gives a wall the fluid's extrapolated pressure, and nothing makes up for a missing layer
    (DBC's densities rise until they do): water leaks through (a 3D tank with 2 layers on two
    sides, where the kernel reaches 3: 35 particles through by 1 s at low viscosity)."""
    need = layers_needed(h, dp)
    length = np.linalg.norm(normals, axis=1)
    wall = (np.asarray(ptype) <= 1) & (length > 0)
    if need < 2 or not wall.any():
        return {}
    # face particles with an axis-aligned normal (an edge or a corner is counted by its faces);
    # one whose ghost node lies in its own wall is not a face (:func:`ghosts_in_own_wall`)
    if inward is None:
        inward = ghosts_in_own_wall(pos, normals, ptype, mkbound, dp, h)
    face = np.flatnonzero(wall & (np.abs(length - 0.5 * dp) < 0.1 * dp) & ~inward)
    u = normals[face] / length[face, None]
    axis = np.argmax(np.abs(u), axis=1)
    along = np.abs(np.abs(u[np.arange(face.size), axis]) - 1.0) <= 1e-6
    face, u, axis = face[along], u[along], axis[along]
    if not face.size:
        return {}
    # the boundary particles as lattice cells, one integer code each, looked up layer by layer
    origin = pos[wall].min(axis=0)
    cells = np.round((pos[np.asarray(ptype) != 3] - origin) / dp).astype(np.int64)
    lo = cells.min(axis=0) - need
    span = cells.max(axis=0) + need - lo + 1

    def code(k):
        return ((k[:, 2] - lo[2]) * span[1] + (k[:, 1] - lo[1])) * span[0] + (k[:, 0] - lo[0])
    occupied = np.unique(code(cells))
    k0 = np.round((pos[face] - origin) / dp).astype(np.int64)
    step = np.zeros_like(k0)
    step[np.arange(face.size), axis] = -np.sign(u[np.arange(face.size), axis]).astype(np.int64)   # into the wall
    layers = np.ones(face.size, np.int64)
    going = np.ones(face.size, bool)
    for k in range(1, need):
        going &= np.isin(code(k0 + k * step), occupied, assume_unique=False)
        layers += going
    thin = layers < need
    out = {}
    for mk in np.unique(mkbound[face[thin]]):
        sel = thin & (mkbound[face] == mk)
        out[int(mk)] = (int(layers[sel].min()), int(sel.sum()))
    return out


def ghosts_in_own_wall(pos: np.ndarray, normals: np.ndarray, ptype: np.ndarray, mkbound: np.ndarray,
                       dp: float, h: float) -> np.ndarray:
    """The boundary particles whose ghost node r + 2N, where mDBC extrapolates the fluid's
    density and velocity (English et al. 2022), falls on a lattice node that a particle of the
    same mkbound holds.  Such normals come from a surface drawn behind the wall's face layer,
    not dp/2 in front of it (a solid box whose faces fall half-way between nodes, given as its
    own normals geometry; a tank's geometry on its first layer with pointref at dp/2; a
    <norplane> point behind the first layer): the layer in front of the surface gets normals
    dp/2 long pointing back into the wall, and the layer behind it ghost nodes on that layer.
    Only normals shorter than the kernel's reach 2h are tested (a particle deeper in the wall
    samples no fluid, whatever its normal), and only on the lattice (a ghost farther than dp/4
    from a node along an axis is not)."""
    ptype = np.asarray(ptype)
    length = np.linalg.norm(normals, axis=1)
    bound = ptype != 3
    out = np.zeros(len(pos), bool)
    tested = np.flatnonzero(bound & (length > 0) & (length < 2.0 * h))
    if not tested.size:
        return out
    origin = pos[bound].min(axis=0)
    rel = (pos[tested] + 2.0 * normals[tested] - origin) / dp
    ghost = np.rint(rel).astype(np.int64)
    near = np.all(np.abs(rel - ghost) < 0.25, axis=1)
    cells = np.rint((pos[bound] - origin) / dp).astype(np.int64)
    lo = np.minimum(cells.min(axis=0), ghost.min(axis=0))
    span = np.maximum(cells.max(axis=0), ghost.max(axis=0)) - lo + 1
    mks, mk_of = np.unique(np.asarray(mkbound)[bound], return_inverse=True)

    def code(k, m):
        return (((k[:, 2] - lo[2]) * span[1] + (k[:, 1] - lo[1])) * span[0] + (k[:, 0] - lo[0])) * len(mks) + m
    held = np.unique(code(cells, mk_of))
    mk_tested = np.searchsorted(mks, np.asarray(mkbound)[tested])
    out[tested] = near & np.isin(code(ghost, mk_tested), held)
    return out


def inward_normal_mkbounds(pos: np.ndarray, normals: np.ndarray, ptype: np.ndarray, mkbound: np.ndarray,
                           dp: float, h: float, inward: np.ndarray | None = None) -> dict:
    """mkbound -> how many of its particles have their ghost node in their own wall
    (:func:`ghosts_in_own_wall`; ``inward``: that mask, already computed)."""
    if inward is None:
        inward = ghosts_in_own_wall(pos, normals, ptype, mkbound, dp, h)
    mks, counts = np.unique(np.asarray(mkbound)[inward], return_counts=True)
    return {int(m): int(n) for m, n in zip(mks, counts)}


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
