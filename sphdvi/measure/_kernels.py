"""Compiled gather loops of the measurement tools (numba, ``cache=True``, serial).

Every loop runs over *measurement points* (or target particles) and gathers
the particles of the 3x3 (2D, x-z plane) or 3x3x3 (3D) cells around them from
a counting-sorted cell list of cell size 2h; there is no loop over particles
in Python.  Sums are serial, so results are bitwise reproducible and the
run-time gauges and ``sphdvi measure`` give the same numbers for the same
particles.

Kernels (support 2h, q = r/h), as in DualSPHysics:

* cubic spline (Monaghan & Lattanzio 1985), ``kind=1``:
  W = a (1 - 1.5 q^2 + 0.75 q^3) for q < 1, a/4 (2 - q)^3 for 1 <= q < 2;
* Wendland C2 (Wendland 1995), ``kind=2``: W = a (1 - q/2)^4 (2q + 1).
"""
import math

import numpy as np
from numba import njit

from ..sph.cells import bounding_box  # noqa: F401  (re-exported for the measurement tools)
from ..sph.kernels import kernel_alpha, kernel_fac, kernel_w  # noqa: F401
from ..sph.linalg import solve_pivoted


@njit(cache=True)
def _cell_of(x, y, z, pmin, inv_cs, ncx, ncy, ncz, is2d):
    """Cell coordinates (cx, cy, cz) of a position, not clamped (may lie outside)."""
    cx = int(math.floor((x - pmin[0]) * inv_cs))
    cz = int(math.floor((z - pmin[2]) * inv_cs))
    cy = 0
    if not is2d:
        cy = int(math.floor((y - pmin[1]) * inv_cs))
    return cx, cy, cz


@njit(cache=True)
def sort_into_cells(pos, pmin, inv_cs, ncx, ncy, ncz, is2d, order, cell_start):
    """Counting sort of the particles by cell (x fastest, stable).

    ``order[k]`` is the index of the k-th sorted particle; the particles of
    cell c are ``order[cell_start[c]:cell_start[c+1]]``.  The grid must cover
    every particle (it is built from their bounding box).
    """
    n = pos.shape[0]
    ncells = ncx * ncy * ncz
    cell = np.empty(n, np.int64)
    cell_start[:] = 0
    for i in range(n):
        cx, cy, cz = _cell_of(pos[i, 0], pos[i, 1], pos[i, 2], pmin, inv_cs, ncx, ncy, ncz, is2d)
        cx = min(max(cx, 0), ncx - 1)
        cy = min(max(cy, 0), ncy - 1)
        cz = min(max(cz, 0), ncz - 1)
        c = (cz * ncy + cy) * ncx + cx
        cell[i] = c
        cell_start[c + 1] += 1
    for c in range(ncells):
        cell_start[c + 1] += cell_start[c]
    cursor = cell_start[:ncells].copy()
    for i in range(n):
        c = cell[i]
        order[cursor[c]] = i
        cursor[c] += 1


@njit(cache=True)
def _stencil(cx, cy, cz, ncx, ncy, ncz, is2d):
    """Clipped cell ranges around (cx, cy, cz); empty ranges when outside the grid."""
    xlo = max(cx - 1, 0)
    xhi = min(cx + 1, ncx - 1)
    zlo = max(cz - 1, 0)
    zhi = min(cz + 1, ncz - 1)
    ylo = 0
    yhi = 0
    if not is2d:
        ylo = max(cy - 1, 0)
        yhi = min(cy + 1, ncy - 1)
    return xlo, xhi, ylo, yhi, zlo, zhi


@njit(cache=True)
def _dist2(is2d, x, y, z, pos, j):
    dx = x - pos[j, 0]
    dz = z - pos[j, 2]
    if is2d:
        return dx * dx + dz * dz
    dy = y - pos[j, 1]
    return dx * dx + dy * dy + dz * dz


# ---------------------------------------------------------------------------------
# interpolation at points
# ---------------------------------------------------------------------------------
@njit(cache=True)
def interpolate_points(points, spos, svol, sfields, cell_start, pmin, inv_cs, ncx, ncy, ncz, is2d,
                       kind, h, alpha, order, out, ksum):
    """Kernel interpolation of ``sfields`` (sorted particles) at ``points``.

    ``ksum[p] = sum_b V_b W(x_p - x_b)`` (V_b = m_b/rho_b: the kernel sum,
    MeasureTool's sum_wab_vol).  ``order=0``: Shepard-normalised value
    ``sum_b V_b f_b W / ksum``.  ``order=1``: first-order moving-least-squares
    correction (value c0 of the local fit f ~ c0 + c.r weighted by V_b W),
    exact for linear fields; falls back to Shepard when the moment matrix is
    singular.  Points without neighbours get NaN.
    """
    npt = points.shape[0]
    nf = sfields.shape[1]
    nd = 3 if is2d else 4
    r2max = 4.0 * h * h
    inv_h = 1.0 / h
    a = np.zeros((4, 4))
    b = np.zeros((4, nf))
    phi = np.zeros(4)
    for p in range(npt):
        x = points[p, 0]
        y = points[p, 1]
        z = points[p, 2]
        cx, cy, cz = _cell_of(x, y, z, pmin, inv_cs, ncx, ncy, ncz, is2d)
        xlo, xhi, ylo, yhi, zlo, zhi = _stencil(cx, cy, cz, ncx, ncy, ncz, is2d)
        a[:, :] = 0.0
        b[:, :] = 0.0
        ks = 0.0
        for cz_ in range(zlo, zhi + 1):
            for cy_ in range(ylo, yhi + 1):
                row = (cz_ * ncy + cy_) * ncx
                if xlo > xhi:
                    continue
                for j in range(cell_start[row + xlo], cell_start[row + xhi + 1]):
                    r2 = _dist2(is2d, x, y, z, spos, j)
                    if r2 >= r2max:
                        continue
                    wv = kernel_w(kind, math.sqrt(r2) * inv_h, alpha) * svol[j]
                    ks += wv
                    if order == 0:
                        for k in range(nf):
                            b[0, k] += wv * sfields[j, k]
                    else:
                        phi[0] = 1.0
                        phi[1] = (spos[j, 0] - x) * inv_h
                        if is2d:
                            phi[2] = (spos[j, 2] - z) * inv_h
                        else:
                            phi[2] = (spos[j, 1] - y) * inv_h
                            phi[3] = (spos[j, 2] - z) * inv_h
                        for i in range(nd):
                            for m in range(nd):
                                a[i, m] += wv * phi[i] * phi[m]
                            for k in range(nf):
                                b[i, k] += wv * phi[i] * sfields[j, k]
        ksum[p] = ks
        if ks <= 0.0:
            for k in range(nf):
                out[p, k] = np.nan
            continue
        done = False
        if order == 1:
            b0 = b[0, :].copy()
            done = solve_pivoted(a, b, nd, b.shape[1], 1e-6 * ks) > 0.0
            if not done:
                b[0, :] = b0
        if done:
            for k in range(nf):
                out[p, k] = b[0, k]
        else:
            for k in range(nf):
                out[p, k] = b[0, k] / ks


@njit(cache=True)
def nearest_distance(points, spos, cell_start, pmin, inv_cs, ncx, ncy, ncz, is2d, rmax, out):
    """Distance from each point to the nearest sorted particle (``rmax`` when none is
    closer than one cell, i.e. only the 3^d stencil is searched)."""
    for p in range(points.shape[0]):
        x = points[p, 0]
        y = points[p, 1]
        z = points[p, 2]
        cx, cy, cz = _cell_of(x, y, z, pmin, inv_cs, ncx, ncy, ncz, is2d)
        xlo, xhi, ylo, yhi, zlo, zhi = _stencil(cx, cy, cz, ncx, ncy, ncz, is2d)
        best = rmax * rmax
        for cz_ in range(zlo, zhi + 1):
            for cy_ in range(ylo, yhi + 1):
                row = (cz_ * ncy + cy_) * ncx
                if xlo > xhi:
                    continue
                for j in range(cell_start[row + xlo], cell_start[row + xhi + 1]):
                    r2 = _dist2(is2d, x, y, z, spos, j)
                    if r2 < best:
                        best = r2
        out[p] = math.sqrt(best)


# ---------------------------------------------------------------------------------
# fluid force on boundary / floating particles (momentum equation, gather form)
# ---------------------------------------------------------------------------------
@njit(cache=True)
def _tensile(p, rho):
    """Monaghan (2000) tensile-correction coefficient (cubic kernel only)."""
    return p / (rho * rho) * (0.01 if p > 0.0 else -0.2)


@njit(cache=True)
def fluid_force(tpos, tvel, trho, tpress, tmass, spos, svel, srho, spress, smass, cell_start, pmin,
                inv_cs, ncx, ncy, ncz, is2d, kind, h, alpha, visco_kind, visco, cs0, wdp, eta2l, out):
    """Force of the fluid (sorted particles b) on each target particle a:

    F_a = m_a sum_b m_b [-(p_a + p_b)/(rho_a rho_b) - R_ab f^4 + Pi_ab] grad_a W_ab
          (+ laminar term),

    the pressure term of the DualSPHysics momentum equation (Crespo et al.
    2015 eq. 4) with the tensile correction R_ab f^4 when ``kind=1``
    (f = W/W(dp), ``wdp`` = 1/W(dp)), and viscosity ``visco_kind`` 1:
    artificial, Pi_ab = visco c0 h min(v_ab.r_ab, 0)/(r^2+eta^2) 2/(rho_a+rho_b);
    2 or 3: laminar (Lo & Shao 2002) m_b 4 nu r.gradW/((rho_a+rho_b)(r^2+eta_l^2)) v_ab
    (``eta2l`` = eta_l^2, ViscoLaminarEta h squared); 0: none.  ``visco`` is Visco x ViscoBoundFactor.  Writes ``out`` (T, 3).
    """
    r2max = 4.0 * h * h
    inv_h = 1.0 / h
    alpha_h2 = alpha / (h * h)
    eta2 = (0.1 * h) ** 2
    for a in range(tpos.shape[0]):
        x = tpos[a, 0]
        y = tpos[a, 1]
        z = tpos[a, 2]
        rhoa = trho[a]
        pa = tpress[a]
        tens_a = _tensile(pa, rhoa) if kind == 1 else 0.0
        cx, cy, cz = _cell_of(x, y, z, pmin, inv_cs, ncx, ncy, ncz, is2d)
        xlo, xhi, ylo, yhi, zlo, zhi = _stencil(cx, cy, cz, ncx, ncy, ncz, is2d)
        fx = 0.0
        fy = 0.0
        fz = 0.0
        for cz_ in range(zlo, zhi + 1):
            for cy_ in range(ylo, yhi + 1):
                row = (cz_ * ncy + cy_) * ncx
                if xlo > xhi:
                    continue
                for j in range(cell_start[row + xlo], cell_start[row + xhi + 1]):
                    r2 = _dist2(is2d, x, y, z, spos, j)
                    if r2 >= r2max or r2 < 1e-18:
                        continue
                    dx = x - spos[j, 0]
                    dy = 0.0 if is2d else y - spos[j, 1]
                    dz = z - spos[j, 2]
                    q = math.sqrt(r2) * inv_h
                    mfac = smass[j] * kernel_fac(kind, q, alpha_h2)
                    rhob = srho[j]
                    coef = -(pa + spress[j]) / (rhoa * rhob)
                    if kind == 1:
                        wr = kernel_w(1, q, alpha) * wdp
                        wr = wr * wr
                        coef -= (tens_a + _tensile(spress[j], rhob)) * (wr * wr)
                    dvx = tvel[a, 0] - svel[j, 0]
                    dvy = 0.0 if is2d else tvel[a, 1] - svel[j, 1]
                    dvz = tvel[a, 2] - svel[j, 2]
                    ir2e = 1.0 / (r2 + eta2)
                    if visco_kind == 1:
                        dot = dvx * dx + dvy * dy + dvz * dz
                        coef += visco * cs0 * h * min(dot * ir2e, 0.0) * 2.0 / (rhoa + rhob)
                    elif visco_kind >= 2:
                        vt = mfac * 4.0 * visco * r2 / ((r2 + eta2l) * (rhoa + rhob))
                        fx += vt * dvx
                        fy += vt * dvy
                        fz += vt * dvz
                    fx += coef * mfac * dx
                    fy += coef * mfac * dy
                    fz += coef * mfac * dz
        out[a, 0] = tmass[a] * fx
        out[a, 1] = 0.0 if is2d else tmass[a] * fy
        out[a, 2] = tmass[a] * fz


# ---------------------------------------------------------------------------------
# columns: free surface and bottom
# ---------------------------------------------------------------------------------
@njit(cache=True)
def first_drop_below(values, nsample, threshold, out_frac):
    """For each line of ``nsample`` samples (rows of ``values`` reshaped (L, nsample)):
    the first crossing from >= threshold to < threshold after the line has
    entered the fluid, as a fractional sample index (linear interpolation);
    -1 when the line never enters the fluid, nsample-1 when it never leaves."""
    nl = values.shape[0] // nsample
    for l in range(nl):
        base = l * nsample
        entered = False
        res = -1.0
        for k in range(nsample):
            v = values[base + k]
            if not entered:
                if v >= threshold:
                    entered = True
                    res = float(nsample - 1)
                continue
            if v < threshold:
                vp = values[base + k - 1]
                res = (k - 1) + (vp - threshold) / (vp - v)
                break
        out_frac[l] = res


@njit(cache=True, inline="always")
def _horizontal_d2(pos, j, points, p, is2d):
    """Squared horizontal distance of particle ``j`` from point ``p`` (x only in 2D)."""
    dx = pos[j, 0] - points[p, 0]
    d2 = dx * dx
    if not is2d:
        dy = pos[j, 1] - points[p, 1]
        d2 += dy * dy
    return d2


@njit(cache=True)
def column_top_below(points, zlim, pos, radius, is2d, out):
    """Highest particle z (of ``pos``) within horizontal distance ``radius`` of each
    point and below ``zlim[p]``; NaN when there is none."""
    r2 = radius * radius
    for p in range(points.shape[0]):
        best = -np.inf
        for j in range(pos.shape[0]):
            if _horizontal_d2(pos, j, points, p, is2d) <= r2 and pos[j, 2] < zlim[p] and pos[j, 2] > best:
                best = pos[j, 2]
        out[p] = best if best > -np.inf else np.nan


@njit(cache=True)
def column_lowest(points, pos, radius, is2d, out):
    """Lowest particle z (of ``pos``) within horizontal distance ``radius`` of each point;
    NaN when there is none."""
    r2 = radius * radius
    for p in range(points.shape[0]):
        best = np.inf
        for j in range(pos.shape[0]):
            if _horizontal_d2(pos, j, points, p, is2d) <= r2 and pos[j, 2] < best:
                best = pos[j, 2]
        out[p] = best if best < np.inf else np.nan


@njit(cache=True)
def column_max_z(points, zhi, pos, radius, is2d, out, idx):
    """Highest particle (of ``pos``) within horizontal distance ``radius`` of each
    point with point_z <= z <= zhi[p] (the maxz gauge); NaN / -1 when none.  The window
    is strict: JGaugeMaxZ::CalculeCpu searches whole cells instead, so it also sees fluid
    up to a cell or more below point_z or above zhi (:class:`MaxZGauge`)."""
    r2 = radius * radius
    for p in range(points.shape[0]):
        best = -np.inf
        bi = -1
        for j in range(pos.shape[0]):
            z = pos[j, 2]
            if z < points[p, 2] or z > zhi[p] or z <= best:
                continue
            if _horizontal_d2(pos, j, points, p, is2d) <= r2:
                best = z
                bi = j
        out[p] = best if bi >= 0 else np.nan
        idx[p] = bi
