r"""Modified dynamic boundary conditions, mDBC (English et al. 2022).

Each boundary particle b carries a normal vector N_b pointing from the
particle to the boundary surface (DualSPHysics convention; |N_b| is the
distance to the surface).  Its ghost node g = r_b + 2 N_b lies inside the
fluid.  The fluid density and its gradient at g come from the first-order
consistent kernel interpolation (Liu & Liu 2006)

  [ sum V w        sum V w (r_j-g)^T   ] [rho_g     ]   [ sum m w  ]
  [ sum V grad w   sum V grad w (r_j-g)^T ] [grad rho_g] = [ sum m grad w ]

over the fluid particles j near g (V = m/rho, w = W(|g - r_j|), grad w its
gradient with respect to g), and the boundary particle gets
rho_b = rho_g + (r_b - g) . grad rho_g.  When the matrix is near-singular
(|det| below ``threshold``, 1e-3) the Shepard value sum m w / sum V w is
used; with a kernel sum sum V w at g not above ``MdbcThreshold`` (no fluid
there) the density is left as it is.  As with DBC the result
is clamped to rho >= rho0.  Particles with N_b = 0 keep plain DBC
behaviour.

Slip modes (``SlipMode``) set the velocity a boundary particle shows the
fluid (continuity, viscosity), from the velocity v_g interpolated at its
ghost node with the same corrected system (right-hand side sum V v w,
sum V v grad w) and the wall velocity v_w (the particle's own velocity):

* 1, DBC velocity: v_b = v_w;
* 2, no-slip: v_b = 2 v_w - v_g (the velocity is odd about the wall, so the
  interpolated velocity vanishes relative to the wall on the surface);
* 3, free-slip: v_b = v_w + u - 2 (u.n) n with u = v_g - v_w and n the unit
  normal (tangential velocity even, normal velocity odd about the wall).

``NoPenetration`` (slip modes 2 and 3) corrects the fluid particles next to
the walls, not the boundary particles: :mod:`sphdvi.sph.nopen`.
"""
import math

from . import _env  # noqa: F401
import numpy as np
from numba import njit, prange

from .interaction import tait_pressure
from .kernels import kernel_fac, kernel_w
from .linalg import solve_pivoted


@njit(cache=True)
def _packed_vel(nb, j, is2d, out):
    """Velocity (x, y, z) of packed particle j."""
    if is2d:
        out[0] = nb[j, 2]
        out[1] = 0.0
        out[2] = nb[j, 3]
    else:
        out[0] = nb[j, 3]
        out[1] = nb[j, 4]
        out[2] = nb[j, 5]


@njit(cache=True)
def _slip_velocity(slip, vw, vg, nx, ny, nz, bvel, i):
    """Velocity of boundary particle i seen by the fluid (module docstring)."""
    if slip == 2:
        for c in range(3):
            bvel[i, c] = 2.0 * vw[c] - vg[c]
        return
    nn = math.sqrt(nx * nx + ny * ny + nz * nz)
    ex = nx / nn
    ey = ny / nn
    ez = nz / nn
    ux = vg[0] - vw[0]
    uy = vg[1] - vw[1]
    uz = vg[2] - vw[2]
    un = ux * ex + uy * ey + uz * ez
    bvel[i, 0] = vw[0] + ux - 2.0 * un * ex
    bvel[i, 1] = vw[1] + uy - 2.0 * un * ey
    bvel[i, 2] = vw[2] + uz - 2.0 * un * ez


@njit(cache=True, error_model="numpy")
def _mdbc_range(i0, i1, kern, is2d, nb, ptype, oi, normals, cell_start, pmin, inv_cell,
                ncx, ncy, ncz, cst, threshold, ksum_min, rhop, slip, bvel):
    h = cst[0]
    r2max = cst[1]
    alpha = cst[3]
    alpha_h2 = cst[4]
    rhop0 = cst[10]
    dim = 2 if is2d else 3
    n = dim + 1
    a = np.zeros((4, 4))
    # right-hand sides: column 0 the density, columns 1-3 the velocity (slip modes 2, 3)
    b = np.zeros((4, 4))
    nrhs = 4 if slip > 1 else 1
    vw = np.zeros(3)
    vg = np.zeros(3)
    for i in range(i0, i1):
        if ptype[i] >= 2:
            continue
        if slip > 1:
            _packed_vel(nb, i, is2d, vw)
            for c in range(3):
                bvel[i, c] = vw[c]
        o = oi[i]   # row of particle i in normals and rhop
        nx = normals[o, 0]
        ny = normals[o, 1]
        nz = normals[o, 2]
        if nx == 0.0 and ny == 0.0 and nz == 0.0:
            continue
        if is2d:
            bx = nb[i, 0]
            by = 0.0
            bz = nb[i, 1]
        else:
            bx = nb[i, 0]
            by = nb[i, 1]
            bz = nb[i, 2]
        gx = bx + 2.0 * nx
        gy = by + 2.0 * ny
        gz = bz + 2.0 * nz
        cx = min(max(int((gx - pmin[0]) * inv_cell), 0), ncx - 1)
        cy = min(max(int((gy - pmin[1]) * inv_cell), 0), ncy - 1) if not is2d else 0
        cz = min(max(int((gz - pmin[2]) * inv_cell), 0), ncz - 1)
        for r in range(4):
            for cc in range(4):
                a[r, cc] = 0.0
                b[r, cc] = 0.0
        rs = int(cst[18])
        for z in range(max(cz - rs, 0), min(cz + rs, ncz - 1) + 1):
            for y in range(max(cy - rs, 0), min(cy + rs, ncy - 1) + 1):
                row = (z * ncy + y) * ncx
                for j in range(cell_start[row + max(cx - rs, 0)],
                               cell_start[row + min(cx + rs, ncx - 1) + 1]):
                    if ptype[j] != 3:
                        continue
                    if is2d:
                        dx = gx - nb[j, 0]
                        dy = 0.0
                        dz = gz - nb[j, 1]
                        mj = nb[j, 6]
                        vj = mj * nb[j, 7]
                    else:
                        dx = gx - nb[j, 0]
                        dy = gy - nb[j, 1]
                        dz = gz - nb[j, 2]
                        mj = nb[j, 8]
                        vj = mj * nb[j, 9]
                    r2 = dx * dx + dy * dy + dz * dz
                    if r2 >= r2max:
                        continue
                    q = math.sqrt(r2) / h
                    w = kernel_w(kern, q, alpha)
                    fac = kernel_fac(kern, q, alpha_h2) if r2 > 1e-18 else 0.0
                    # gradient with respect to g, and r_j - g
                    if is2d:
                        gw0 = fac * dx
                        gw1 = fac * dz
                        d0 = -dx
                        d1 = -dz
                        gw2 = 0.0
                        d2 = 0.0
                    else:
                        gw0 = fac * dx
                        gw1 = fac * dy
                        gw2 = fac * dz
                        d0 = -dx
                        d1 = -dy
                        d2 = -dz
                    a[0, 0] += vj * w
                    a[0, 1] += vj * w * d0
                    a[0, 2] += vj * w * d1
                    b[0, 0] += mj * w
                    a[1, 0] += vj * gw0
                    a[1, 1] += vj * gw0 * d0
                    a[1, 2] += vj * gw0 * d1
                    b[1, 0] += mj * gw0
                    a[2, 0] += vj * gw1
                    a[2, 1] += vj * gw1 * d0
                    a[2, 2] += vj * gw1 * d1
                    b[2, 0] += mj * gw1
                    if not is2d:
                        a[0, 3] += vj * w * d2
                        a[1, 3] += vj * gw0 * d2
                        a[2, 3] += vj * gw1 * d2
                        a[3, 0] += vj * gw2
                        a[3, 1] += vj * gw2 * d0
                        a[3, 2] += vj * gw2 * d1
                        a[3, 3] += vj * gw2 * d2
                        b[3, 0] += mj * gw2
                    if slip > 1:
                        _packed_vel(nb, j, is2d, vg)
                        for cc in range(3):
                            b[0, 1 + cc] += vj * w * vg[cc]
                            b[1, 1 + cc] += vj * gw0 * vg[cc]
                            b[2, 1 + cc] += vj * gw1 * vg[cc]
                            if not is2d:
                                b[3, 1 + cc] += vj * gw2 * vg[cc]
        if a[0, 0] <= ksum_min or a[0, 0] <= 0.0:
            continue
        # Shepard values, kept where the corrected system is near-singular
        rho = b[0, 0] / a[0, 0]
        for c in range(3):
            vg[c] = b[0, 1 + c] / a[0, 0]
        if solve_pivoted(a, b, n, nrhs, 0.0) >= threshold:
            if is2d:
                rho = b[0, 0] - 2.0 * (nx * b[1, 0] + nz * b[2, 0])
            else:
                rho = b[0, 0] - 2.0 * (nx * b[1, 0] + ny * b[2, 0] + nz * b[3, 0])
            for c in range(3):
                vg[c] = b[0, 1 + c]
        rhop[o] = max(rho, rhop0)
        if slip > 1:
            _slip_velocity(slip, vw, vg, nx, ny, nz, bvel, i)


@njit(cache=True, error_model="numpy")
def _refresh_packed(i0, i1, is2d, ptype, oi, rhop, cst, nb, slip, bvel):
    for i in range(i0, i1):
        if ptype[i] >= 2:
            continue
        rho = rhop[oi[i]]
        p = tait_pressure(rho, cst[16], cst[10], cst[17])
        if is2d:
            nb[i, 4] = rho
            nb[i, 5] = p
            nb[i, 7] = 1.0 / rho
            if slip > 1:
                nb[i, 2] = bvel[i, 0]
                nb[i, 3] = bvel[i, 2]
        else:
            nb[i, 6] = rho
            nb[i, 7] = p
            nb[i, 9] = 1.0 / rho
            if slip > 1:
                for c in range(3):
                    nb[i, 3 + c] = bvel[i, c]


@njit(cache=True, error_model="numpy")
def mdbc_serial(kern, is2d, nb, ptype, oi, normals, cell_start, pmin, inv_cell, ncx, ncy, ncz,
                cst, threshold, ksum_min, rhop, slip, bvel):
    """Set the density of every boundary particle with a normal (mDBC) and
    refresh its packed density and pressure (and, for slip modes 2 and 3, the
    velocity it shows the fluid; bvel (N, 3) is work space)."""
    n = nb.shape[0]
    _mdbc_range(0, n, kern, is2d, nb, ptype, oi, normals, cell_start, pmin, inv_cell, ncx, ncy,
                ncz, cst, threshold, ksum_min, rhop, slip, bvel)
    _refresh_packed(0, n, is2d, ptype, oi, rhop, cst, nb, slip, bvel)


@njit(cache=True, parallel=True, error_model="numpy")
def mdbc_parallel(kern, is2d, nb, ptype, oi, normals, cell_start, pmin, inv_cell, ncx, ncy, ncz,
                  cst, threshold, ksum_min, rhop, slip, bvel):
    """Threaded :func:`mdbc_serial`."""
    n = nb.shape[0]
    nchunk = (n + 511) // 512
    for c in prange(nchunk):
        _mdbc_range(c * 512, min(n, (c + 1) * 512), kern, is2d, nb, ptype, oi, normals,
                    cell_start, pmin, inv_cell, ncx, ncy, ncz, cst, threshold, ksum_min,
                    rhop, slip, bvel)
    for c in prange(nchunk):
        _refresh_packed(c * 512, min(n, (c + 1) * 512), is2d, ptype, oi, rhop, cst, nb, slip,
                        bvel)
