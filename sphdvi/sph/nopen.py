r"""mDBC no-penetration correction (``NoPenetration=1``), as DualSPHysics v5.4.

DualSPHysics reads ``NoPenetration`` only with ``Boundary=2`` and ``SlipMode``
2 or 3 (its mDBC2 modes); with DBC or SlipMode 1 the key is ignored.  The
correction does not touch the boundary particles: it changes the velocity
and the displacement of the *fluid* particles that are about to cross the
wall surface.

Detection (in the fluid-boundary interaction of each step).  For a fluid
particle a and every fixed or moving boundary particle b with a normal N_b
(the vector from b to the wall surface, ghost node r_b + 2 N_b; DualSPHysics
stores 2 N_b), n_b = N_b / |N_b|, r_ab = r_a - r_b, d = n_b . r_ab (height
of a above b along the normal), u = (v_a - w_b) . n_b with w_b the wall
velocity of b, b contributes when

* |r_ab| < 1.25 dp (a is next to b),
* 2 |N_b| < 1.75 dp (b is in the first wall layer: |N_b| = dp/2),
* d < 1.5 |N_b| (a is less than |N_b|/2 in front of the surface, i.e.
  within dp/4 of it, or behind it),
* u < 0 (a approaches the wall),

the velocity change -f u n_b with f = 2.5 - 2 max(d / (2|N_b|), 0.25): f
grows linearly from 1 (normal relative velocity removed) where a is dp/4 in
front of the surface, through 1.5 on the surface, to 2 (normal relative
velocity reflected) from dp/4 behind it on.  The correction of a is the mean
Delta v_a of the contributions (none: no correction).

Integration.  A corrected component k (Delta v_a,k != 0; DualSPHysics's GPU
code) replaces what the step computed from the forces:

* Verlet (normal and Euler steps): v_k^{n+1} = v_k^n + Delta v_k,
  r_k^{n+1} = r_k^n + v_k^{n+1} dt (the shifting displacement of that
  component is dropped, as DualSPHysics);
* Symplectic, in the corrector (Delta v from the interaction at n+1/2):
  v_k^{n+1} = v_k^n + Delta v_k, r_k^{n+1} = r_k^n + v_k^{n+1} dt + the
  shifting displacement.  The predictor is not corrected.

Uncorrected components, and particles without a correction, keep the
integrator's values.  Floating particles are neither corrected nor act as
walls.

DualSPHysics's CPU code differs from its GPU code in two details: it replaces
all three components of a corrected particle (the zero ones lose their
acceleration for that step), and in the Verlet step it adds Delta v to
v^{n-1} instead of v^n.  The GPU form is followed here (see the module
tests, ``tests/sph/test_mdbc_nopenetration.py``).

The work array ``npshift`` (N, 7) holds per particle row: Delta v (3), a flag
(1 corrected, 0 not) and the position at the interaction (3; the Verlet
step restarts the corrected components from it).
"""
import math

from . import _env  # noqa: F401
import numpy as np
from numba import njit, prange

from .integrators import _out_code, _too_far

CHUNK = 256
NCOL = 7


@njit(cache=True, error_model="numpy")
def _mark_range(j0, j1, ptype, cell, oi, normals, ncx, ncy, ncz, rs, dp, near):
    """Flag the cells within ``rs`` cells of a first-layer wall particle."""
    nlim2 = (0.875 * dp) ** 2
    for j in range(j0, j1):
        if ptype[j] >= 2:
            continue
        ob = oi[j]
        n2 = normals[ob, 0] ** 2 + normals[ob, 1] ** 2 + normals[ob, 2] ** 2
        if n2 == 0.0 or n2 >= nlim2:
            continue
        c = cell[j]
        cx = c % ncx
        cy = (c // ncx) % ncy
        cz = c // (ncx * ncy)
        for z in range(max(cz - rs, 0), min(cz + rs, ncz - 1) + 1):
            for y in range(max(cy - rs, 0), min(cy + rs, ncy - 1) + 1):
                row = (z * ncy + y) * ncx
                for x in range(max(cx - rs, 0), min(cx + rs, ncx - 1) + 1):
                    near[row + x] = 1


@njit(cache=True, error_model="numpy")
def _detect_range(i0, i1, is2d, nb, ptype, cell, oi, normals, wallvel, pos, cell_start,
                  ncx, ncy, ncz, rs, dp, near, npshift):
    r2lim = (1.25 * dp) ** 2
    nlim = 0.875 * dp          # 2 |N| < 1.75 dp: first wall layer
    for i in range(i0, i1):
        if ptype[i] != 3:
            continue
        o = oi[i]
        npshift[o, 3] = 0.0
        if near[cell[i]] == 0:  # no first-layer wall particle within reach
            continue
        if is2d:
            xi = nb[i, 0]
            yi = 0.0
            zi = nb[i, 1]
            vxi = nb[i, 2]
            vyi = 0.0
            vzi = nb[i, 3]
        else:
            xi = nb[i, 0]
            yi = nb[i, 1]
            zi = nb[i, 2]
            vxi = nb[i, 3]
            vyi = nb[i, 4]
            vzi = nb[i, 5]
        c = cell[i]
        cx = c % ncx
        cy = (c // ncx) % ncy
        cz = c // (ncx * ncy)
        xlo = max(cx - rs, 0)
        xhi = min(cx + rs, ncx - 1)
        sx = 0.0
        sy = 0.0
        sz = 0.0
        cnt = 0
        for z in range(max(cz - rs, 0), min(cz + rs, ncz - 1) + 1):
            for y in range(max(cy - rs, 0), min(cy + rs, ncy - 1) + 1):
                row = (z * ncy + y) * ncx
                for j in range(cell_start[row + xlo], cell_start[row + xhi + 1]):
                    if ptype[j] >= 2:          # fixed and moving boundaries only
                        continue
                    if is2d:
                        dx = xi - nb[j, 0]
                        dy = 0.0
                        dz = zi - nb[j, 1]
                    else:
                        dx = xi - nb[j, 0]
                        dy = yi - nb[j, 1]
                        dz = zi - nb[j, 2]
                    r2 = dx * dx + dy * dy + dz * dz
                    if r2 >= r2lim or r2 < 1e-18:
                        continue
                    ob = oi[j]
                    nx = normals[ob, 0]
                    ny = normals[ob, 1]
                    nz = normals[ob, 2]
                    nn = math.sqrt(nx * nx + ny * ny + nz * nz)
                    if nn == 0.0 or nn >= nlim:
                        continue
                    ex = nx / nn
                    ey = ny / nn
                    ez = nz / nn
                    d = ex * dx + ey * dy + ez * dz
                    if d >= 1.5 * nn:
                        continue
                    un = ((vxi - wallvel[ob, 0]) * ex + (vyi - wallvel[ob, 1]) * ey
                          + (vzi - wallvel[ob, 2]) * ez)
                    if un >= 0.0:
                        continue
                    f = 2.5 - 2.0 * max(d / (2.0 * nn), 0.25)
                    sx -= f * un * ex
                    sy -= f * un * ey
                    sz -= f * un * ez
                    cnt += 1
        if cnt > 0:
            inv = 1.0 / cnt
            npshift[o, 0] = sx * inv
            npshift[o, 1] = sy * inv
            npshift[o, 2] = sz * inv
            npshift[o, 3] = 1.0
            for k in range(3):
                npshift[o, 4 + k] = pos[o, k]


@njit(cache=True, error_model="numpy")
def detect_serial(is2d, nb, ptype, cell, oi, normals, wallvel, pos, cell_start, ncx, ncy, ncz,
                  rs, dp, npshift):
    """Fill ``npshift`` (rows ``oi``) for every fluid row of the packed array ``nb``.

    ``ptype``, ``cell`` are per packed row; ``normals``, ``wallvel`` (the
    boundary particles' own velocities) and ``pos`` per particle row.  ``rs``
    is the stencil radius in cells that covers 1.25 dp."""
    n = nb.shape[0]
    near = np.zeros(ncx * ncy * ncz, np.uint8)
    _mark_range(0, n, ptype, cell, oi, normals, ncx, ncy, ncz, rs, dp, near)
    _detect_range(0, n, is2d, nb, ptype, cell, oi, normals, wallvel, pos, cell_start,
                  ncx, ncy, ncz, rs, dp, near, npshift)


@njit(cache=True, parallel=True, error_model="numpy")
def detect_parallel(is2d, nb, ptype, cell, oi, normals, wallvel, pos, cell_start, ncx, ncy,
                    ncz, rs, dp, npshift):
    """Threaded :func:`detect_serial`."""
    n = nb.shape[0]
    nchunk = (n + CHUNK - 1) // CHUNK
    near = np.zeros(ncx * ncy * ncz, np.uint8)
    for c in prange(nchunk):        # every writer stores 1: no race on the result
        _mark_range(c * CHUNK, min(n, (c + 1) * CHUNK), ptype, cell, oi, normals, ncx, ncy, ncz,
                    rs, dp, near)
    for c in prange(nchunk):
        _detect_range(c * CHUNK, min(n, (c + 1) * CHUNK), is2d, nb, ptype, cell, oi, normals,
                      wallvel, pos, cell_start, ncx, ncy, ncz, rs, dp, near, npshift)


@njit(cache=True, error_model="numpy")
def _recheck(i, pos, rhop, ip, out, start):
    """Exclusion code of particle i after its correction (``start``: the positions its step's
    displacement is measured from, for MovLimit); returns the change in flagged count."""
    old = out[i]
    moved = False
    for k in range(3):
        moved |= _too_far(pos[i, k] - start[i, k], ip[16])
    code = _out_code(pos[i, 0], pos[i, 1], pos[i, 2], rhop[i], ip[2], ip[3], ip[6] != 0.0,
                     ip[7], ip[8], ip[9], ip[10], ip[11], ip[12], moved)
    out[i] = code
    return (1 if code != 0 else 0) - (1 if old != 0 else 0)


@njit(cache=True, error_model="numpy")
def _verlet_range(i0, i1, pos, vel, vel_m1, rhop, ptype, npshift, ip, out):
    dt = ip[0]
    dn = 0
    for i in range(i0, i1):
        if ptype[i] != 3 or npshift[i, 3] == 0.0:
            continue
        for k in range(3):
            dv = npshift[i, k]
            if dv != 0.0:
                vn = vel_m1[i, k] + dv          # vel_m1 holds v^n after the Verlet step
                vel[i, k] = vn
                pos[i, k] = npshift[i, 4 + k] + vn * dt
        dn += _recheck(i, pos, rhop, ip, out, npshift[:, 4:7])
    return dn


@njit(cache=True, error_model="numpy")
def apply_verlet_serial(pos, vel, vel_m1, rhop, ptype, npshift, ip, out):
    """Correct the particles flagged in ``npshift`` after a Verlet (or Euler)
    step; returns the change in the number of particles flagged in ``out``."""
    return _verlet_range(0, pos.shape[0], pos, vel, vel_m1, rhop, ptype, npshift, ip, out)


@njit(cache=True, parallel=True, error_model="numpy")
def apply_verlet_parallel(pos, vel, vel_m1, rhop, ptype, npshift, ip, out):
    """Threaded :func:`apply_verlet_serial`."""
    n = pos.shape[0]
    dn = 0
    for c in prange((n + CHUNK - 1) // CHUNK):
        dn += _verlet_range(c * CHUNK, min(n, (c + 1) * CHUNK), pos, vel, vel_m1, rhop, ptype,
                            npshift, ip, out)
    return dn


@njit(cache=True, error_model="numpy")
def _sym_range(i0, i1, pos, vel, pos_pre, vel_pre, rhop, ptype, npshift, ip, out):
    dt = ip[0]
    dt05 = 0.5 * dt
    dn = 0
    for i in range(i0, i1):
        if ptype[i] != 3 or npshift[i, 3] == 0.0:
            continue
        for k in range(3):
            dv = npshift[i, k]
            if dv != 0.0:
                # shifting displacement of the corrector, kept
                sh = pos[i, k] - pos_pre[i, k] - (vel_pre[i, k] + vel[i, k]) * dt05
                vn = vel_pre[i, k] + dv
                vel[i, k] = vn
                pos[i, k] = pos_pre[i, k] + vn * dt + sh
        dn += _recheck(i, pos, rhop, ip, out, pos_pre)
    return dn


@njit(cache=True, error_model="numpy")
def apply_symplectic_serial(pos, vel, pos_pre, vel_pre, rhop, ptype, npshift, ip, out):
    """Correct the particles flagged in ``npshift`` after the Symplectic
    corrector; returns the change in the number of particles flagged in ``out``."""
    return _sym_range(0, pos.shape[0], pos, vel, pos_pre, vel_pre, rhop, ptype, npshift, ip, out)


@njit(cache=True, parallel=True, error_model="numpy")
def apply_symplectic_parallel(pos, vel, pos_pre, vel_pre, rhop, ptype, npshift, ip, out):
    """Threaded :func:`apply_symplectic_serial`."""
    n = pos.shape[0]
    dn = 0
    for c in prange((n + CHUNK - 1) // CHUNK):
        dn += _sym_range(c * CHUNK, min(n, (c + 1) * CHUNK), pos, vel, pos_pre, vel_pre, rhop,
                         ptype, npshift, ip, out)
    return dn
